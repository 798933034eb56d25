#!/bin/bash
# What each vector kernel saves of a week's calibration: one build, each
# kernel's default variant (A) against its scalar reference forced by
# GRAVCAL_KERNELS (B), the runs interleaved by bench/ab.sh.
#
#   bash bench/ab-kernels.sh <lib> <runs> <dir> [<kernel>...]
#
# <dir> holds the week files of bench/files.R (typical-7d.cwa, .bin, .csv,
# .gt3x). With GRAVCAL_BASE=sse2, both sides run without the AVX2 variants
# (GRAVCAL_NO_AVX2=1): what the SSE2 variants save. With MODE=perf, each
# comparison is bench/kernel-share.sh's (CPU-time profiles: the time in the
# kernel's own functions and in gravcal's library) instead of bench/ab.sh's.
# Prints one table per kernel and contender.
set -euo pipefail
lib=$1; runs=$2; dir=$3; shift 3
here=$(cd "$(dirname "$0")" && pwd)
base=""
[ "${GRAVCAL_BASE:-}" = sse2 ] && base="GRAVCAL_NO_AVX2=1"
all=(r_scan r_var_means3 sq_dev lane_sums run_end first_zero stream_window word_sum
     scale_packed span_times cwa_interp hex_counts icp)
kernels=("$@")
[ ${#kernels[@]} -eq 0 ] && kernels=("${all[@]}")
week() { for e in "$@"; do printf '%s ' "$dir/typical-7d.$e"; done; }
gg="gravcal::g.calibrate"
lw='calibrate(method = "lightweight")'
cg='calibrate(method = "ggir")'
# the functions whose time a kernel's choice changes, in a profile (after
# gravcal::): its own (kernels/*.hpp); r_scan's scalar reference calls
# lane_sums'; r_var_means3 decides whether r_sd3() runs R's first passes
# and r_scan the window sums that feed them
symbols() {
  local k="kernels::"
  case $1 in
    run_end) echo "${k}run_(end|tail)" ;;
    stream_window) echo "${k}(stream_|zero_signs|min_max_tail|is_zero3)" ;;
    r_scan) echo "${k}(r_scan|r_cumsums|min_max_tail|zero_signs|lane_sums)" ;;
    r_var_means3) echo "${k}(r_var_means3|r_mean_detail|r_scan|r_cumsums)|(Segmenter::)?r_sd3" ;;
    first_zero) echo "${k}(first_zero|zero_scan|zero_in8)" ;;
    hex_counts) echo "${k}hex_" ;;
    icp*) echo "${k}icp_" ;;
    *) echo "${k}$1" ;;
  esac
}
one() {  # kernel(s) contender files...
  local k=$1 c=$2; shift 2
  local off=""
  for n in ${k//+/ }; do off="$off${off:+,}$n=scalar"; done
  echo; echo "### $k off: $c"; echo
  if [ "${MODE:-}" = perf ]; then
    GRAVCAL_BASE=${GRAVCAL_BASE:-} bash "$here/kernel-share.sh" "$lib" "$runs" "$k" "$(symbols "$k")" "$c" "$@"
  else
    AB_ENV_A="$base" AB_ENV_B="$base GRAVCAL_KERNELS=$off" bash "$here/ab.sh" "$lib" "$lib" "$runs" "$c" "$@"
  fi
}
for k in "${kernels[@]}"; do
  case $k in
    # R's arithmetic (g.calibrate): every format
    r_scan|r_var_means3|sq_dev|lane_sums|run_end|first_zero)
      one "$k" "$gg" $(week cwa bin csv gt3x) ;;
    # the streaming arithmetic (the lightweight method)
    stream_window) one "$k" "$lw" $(week cwa bin csv gt3x) ;;
    # the .cwa decoder; compatible mode (g.calibrate) and raw (lightweight)
    word_sum|scale_packed) one "$k" "$gg" $(week cwa); one "$k" "$lw" $(week cwa) ;;
    span_times|cwa_interp) one "$k" "$gg" $(week cwa) ;;
    # the GENEActiv decoder
    hex_counts) one "$k" "$gg" $(week bin); one "$k" "$lw" $(week bin) ;;
    # gravcal's own ICP fit (calibrate(method = "ggir")), its six loops together
    icp) one "icp_apply+icp_project+icp_sqrt+icp_times+icp_fitted+icp_weights" "$cg" $(week cwa bin) ;;
    *) echo "unknown kernel $k" >&2; exit 1 ;;
  esac
done
