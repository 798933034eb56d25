#!/usr/bin/env bash
# How much time decoding takes inside the calibration pipelines, against
# reading and decoding the same file alone (the read-once floor of
# bench/files.R): does decoding run as fast inside a calibration as by
# itself? (Issue 16: "decoding runs within 2 times the read-once floor".)
#
# Each contender runs in its own R process (bench/files-one.R) under
# `perf record` (software clock, 10 kHz); the samples that fall in the
# decoder's functions, zlib and the kernel's file reads are counted. The
# ratio of the counts is the ratio of the decoding time. Median of RUNS
# runs (default 3) each.
#
# Run from the package root with gravcal installed (R_LIBS) and perf on the
# PATH, after bench/files.R has written its files into GRAVCAL_BENCH_DATA
# (a week at 100 Hz of each format). Writes bench/results/decode-in-pipeline.md.
set -euo pipefail
data="${GRAVCAL_BENCH_DATA:-$(dirname "$(mktemp -u)")/gravcal-bench-files}"
runs="${RUNS:-3}"
out=bench/results/decode-in-pipeline.md
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
command -v perf > /dev/null || { echo "perf is needed (Debian: linux-perf)"; exit 1; }

declare -A rx
rx[cwa]='CwaDecoder|cwa::|_copy_to_iter|filemap_|ksys_read|vfs_read'
rx[bin]='Geneactiv|geneactiv::|strtod|str_to_mpn|round_and_return|__memchr|_copy_to_iter|filemap_|ksys_read|vfs_read'
rx[gt3x]='libz|Gt3x|gt3x::|WindowSource|_copy_to_iter|filemap_|ksys_read|vfs_read'
rx[csv]='Csv|csv_text::|csv::|LineReader|_copy_to_iter|filemap_|ksys_read|vfs_read'

samples() {  # contender file regex -> decoder samples of one run
  perf record -q -F 10000 -o "$tmp/p.data" Rscript bench/files-one.R "$1" "$2" > /dev/null 2>&1
  perf report -i "$tmp/p.data" --no-children --sort dso,symbol -F sample,dso,symbol --stdio \
    2> /dev/null | grep -E "$3" | awk '{s += $1} END {print s + 0}'
}
median() { sort -n | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }

{
  echo "# Decoding inside the pipelines against decoding alone"
  echo
  echo "Written by \`bench/decode-in-pipeline.sh\` on $(date -u +%Y-%m-%d); $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores."
  echo "Samples (10 kHz software clock, median of $runs runs) in the decoder's functions, zlib and the kernel's file reads, for a week at 100 Hz; the ratio is decoding's time inside the call over its time alone (the read-once floor of bench/files.R)."
  echo
  echo "gravcal::g.calibrate reads in GGIR-compatible mode (for .cwa that includes GGIRread's resampling onto a regular grid), so its floor is the decoder alone in that mode."
  echo
  echo "| file | alone | calibrate(method = \"ggir\") | ratio | calibrate(method = \"lightweight\") | ratio | alone, compatible mode | gravcal::g.calibrate | ratio |"
  echo "|---|---|---|---|---|---|---|---|---|"
} > "$tmp/report.md"

for f in cwa bin gt3x csv; do
  file="$data/typical-7d.$f"
  [ -f "$file" ] || { echo "missing $file (run bench/files.R first)"; exit 1; }
  cat "$file" > /dev/null
  row="| typical-7d.$f"
  base=""
  for c in 'decode (read-once floor of the decoder)' 'calibrate(method = "ggir")' \
           'calibrate(method = "lightweight")' 'decode, compatible mode' 'gravcal::g.calibrate'; do
    n=$(for r in $(seq "$runs"); do samples "$c" "$file" "${rx[$f]}"; done | median)
    if [ -z "$base" ] || [ "$c" = 'decode, compatible mode' ]; then
      base=$n
      row="$row | $n"
    else
      row="$row | $n | $(awk -v a="$n" -v b="$base" 'BEGIN {printf "%.2f", a / b}')"
    fi
    echo "$f: $c $n" >&2
  done
  echo "$row |" >> "$tmp/report.md"
done
cp "$tmp/report.md" "$out"
echo "wrote $out"
