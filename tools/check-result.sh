#!/usr/bin/env bash
# Reads R CMD check's results: fails unless the check is clean (no ERROR,
# WARNING or NOTE), and prints the test counts as "N passed, N failed".
set -euo pipefail
dir="$1"
log="$dir/00check.log"
[ -f "$log" ] || { echo "check-result: no $log"; exit 1; }
out="$dir/tests/testthat.Rout"
[ -f "$out" ] || out="$dir/tests/testthat.Rout.fail"
if [ -f "$out" ]; then
  line=$(grep -E '^\[ FAIL [0-9]+ \| WARN [0-9]+ \| SKIP [0-9]+ \| PASS [0-9]+ \]' "$out" | tail -n 1 || true)
  if [ -n "$line" ]; then
    fail=$(echo "$line" | sed -E 's/.*FAIL ([0-9]+).*/\1/')
    skip=$(echo "$line" | sed -E 's/.*SKIP ([0-9]+).*/\1/')
    pass=$(echo "$line" | sed -E 's/.*PASS ([0-9]+).*/\1/')
    grep -A3 -E '^── Skip|Skipped|SKIP' "$out" | grep -E 'Reason|skip' | head -20 || true
    echo "testthat: $pass passed, $fail failed, $skip skipped"
  fi
fi
status=$(grep -E '^Status:' "$log" | tail -n 1)
echo "R CMD check --as-cran: $status"
if [ "$status" != "Status: OK" ]; then
  grep -E -B2 -A12 '\.\.\. (ERROR|WARNING|NOTE)$' "$log" | head -80
  exit 1
fi
