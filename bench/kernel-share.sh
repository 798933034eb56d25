#!/bin/bash
# A vector kernel's share of a week's calibration, from CPU-time profiles:
# bench/files-one.R under `perf record -e cpu-clock`, with the kernel's
# default variant (on) and its scalar reference forced by GRAVCAL_KERNELS
# (off), runs alternating. The saving is measured twice: as the difference
# in the samples that fall in the kernel's own functions (the names
# matching <symbols>), and in all of gravcal's library (where a
# kernel's choice moves work elsewhere: r_var_means3 decides whether R's
# passes run). Either leaves out the rest of the process (R, and other
# programs' effect on it), which blurs the call's CPU time.
#
#   bash bench/kernel-share.sh <lib> <runs> <kernel[+kernel...]> <symbols> <contender> <file>...
#
# <symbols>: an extended regular expression for the functions whose time
# the kernel's choice changes (e.g. 'kernels::sq_dev').
#
# With GRAVCAL_BASE=sse2 both sides run without AVX2 (GRAVCAL_NO_AVX2=1).
# Prints a table: per file, the call's CPU seconds (median, on and off), the
# library's seconds (median, on and off), and the saving over the call's
# time on.
set -euo pipefail
lib=$1; runs=$2; kernel=$3; symbols=$4; contender=$5; shift 5
here=$(cd "$(dirname "$0")" && pwd)
freq=4000
base=""
[ "${GRAVCAL_BASE:-}" = sse2 ] && base="GRAVCAL_NO_AVX2=1"
off=""
for n in ${kernel//+/ }; do off="$off${off:+,}$n=scalar"; done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
# one run: prints "<call CPU seconds> <library seconds> <kernel seconds>"
one() {
  local envs=$1 f=$2
  local line
  line=$(env $envs R_LIBS=$lib perf record -q -e cpu-clock -F $freq -o "$tmp/p.data" \
           Rscript "$here/files-one.R" "$contender" "$f" 2> /dev/null | grep "^RESULT")
  local lib_samples
  lib_samples=$(perf report -i "$tmp/p.data" --no-children --sort dso --stdio -F sample,dso 2> /dev/null |
                  awk '/gravcal\.so/ {s += $1} END {print s + 0}')
  local k_samples
  k_samples=$(perf report -i "$tmp/p.data" --no-children --sort symbol --stdio -F sample,symbol 2> /dev/null |
                awk -v re="gravcal::($symbols)" '$0 ~ re {s += $1} END {print s + 0}')
  echo "$(cut -f 8 <<< "$line") $(awk -v s="$lib_samples" -v k="$k_samples" -v f=$freq 'BEGIN {print s / f, k / f}')"
}
printf "| file | call on (s) | call off (s) | library on (s) | library off (s) | kernel on (s) | kernel off (s) | saving / call on: kernel, library |\n"
printf "|---|---|---|---|---|---|---|---|\n"
for f in "$@"; do
  : > "$tmp/on"; : > "$tmp/off"
  for ((i = 0; i < runs; i++)); do
    one "$base" "$f" >> "$tmp/on"
    one "$base GRAVCAL_KERNELS=$off" "$f" >> "$tmp/off"
  done
  con=$(cut -d' ' -f1 "$tmp/on" | median); coff=$(cut -d' ' -f1 "$tmp/off" | median)
  lon=$(cut -d' ' -f2 "$tmp/on" | median); loff=$(cut -d' ' -f2 "$tmp/off" | median)
  kon=$(cut -d' ' -f3 "$tmp/on" | median); koff=$(cut -d' ' -f3 "$tmp/off" | median)
  printf "| %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %s |\n" "$(basename "$f")" "$con" "$coff" \
    "$lon" "$loff" "$kon" "$koff" \
    "$(awk -v a="$lon" -v b="$loff" -v ka="$kon" -v kb="$koff" -v c="$con" \
       'BEGIN {printf "%.1f %%, %.1f %%", 100 * (kb - ka) / c, 100 * (b - a) / c}')"
done
