#!/bin/bash
# Two builds of gravcal on the same files, their runs interleaved (A, B, A,
# B, ...), so that a machine whose speed drifts (shared cores, frequency)
# affects both alike. Each run is bench/files-one.R in a process of its own.
#
#   bash bench/ab.sh <lib A> <lib B> <runs> <contender> <file>...
#
# <lib A>, <lib B>: R libraries holding the two builds (R CMD INSTALL -l);
# they may be the same library, with AB_ENV_A / AB_ENV_B set to what each
# side's process gets in its environment (for one build with a kernel
# forced to its scalar reference: AB_ENV_B="GRAVCAL_KERNELS=r_scan=scalar").
# A file's GGIR parameters (an ad hoc csv file's rmc.*, as bench/formats.R
# writes them) are read from <file>.params.rds, or <folder>.params.rds for
# a Movisens acc.bin, where that exists.
# AB_TIME=elapsed measures elapsed seconds in place of CPU seconds (for
# a change that adds a thread: the CPU adds up across threads).
# Prints, per file, the median CPU seconds of each and B's time over A's,
# and whether the two gave the same coefficients (exact hexadecimal) and
# status (for g.getmeta: the md5 of its epochs).
set -euo pipefail
libA=$1; libB=$2; runs=$3; contender=$4; shift 4
here=$(cd "$(dirname "$0")" && pwd)
field=8  # files-one.R's CPU seconds
[ "${AB_TIME:-cpu}" = elapsed ] && field=3
median() { sort -n | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
printf "| file | A (s) | B (s) | B / A | same coefficients |\n|---|---|---|---|---|\n"
for f in "$@"; do
  ta=(); tb=(); ca=""; cb=""
  params=-
  if [ -f "$f.params.rds" ]; then params=$f.params.rds
  elif [ -f "$(dirname "$f").params.rds" ]; then params=$(dirname "$f").params.rds; fi
  for ((i = 0; i < runs; i++)); do
    la=$(env ${AB_ENV_A:-} R_LIBS=$libA Rscript "$here/files-one.R" "$contender" "$f" "$params" | grep "^RESULT")
    lb=$(env ${AB_ENV_B:-} R_LIBS=$libB Rscript "$here/files-one.R" "$contender" "$f" "$params" | grep "^RESULT")
    ta+=("$(cut -f $field <<< "$la")"); tb+=("$(cut -f $field <<< "$lb")")
    ca=$(cut -f 6,7 <<< "$la"); cb=$(cut -f 6,7 <<< "$lb")
  done
  ma=$(printf "%s\n" "${ta[@]}" | median); mb=$(printf "%s\n" "${tb[@]}" | median)
  same=no; [ "$ca" = "$cb" ] && same=yes
  printf "| %s | %.3f | %.3f | %.2f | %s |\n" "$(basename "$f")" "$ma" "$mb" \
    "$(awk -v a="$ma" -v b="$mb" 'BEGIN {print b / a}')" "$same"
done
