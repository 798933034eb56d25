#!/usr/bin/env bash
# tools/timed.sh NAME CMD...: runs CMD, then prints and appends to
# _build/times.txt how long it took ("NAME 123 s rc 0"), so that make test
# reports each step's wall time. Exits with CMD's status.
name=$1; shift
start=$(date +%s)
"$@"; rc=$?
end=$(date +%s)
mkdir -p _build
printf '%s %d s rc %d\n' "$name" $((end - start)) $rc | tee -a _build/times.txt
exit $rc
