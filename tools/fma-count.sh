#!/bin/sh
# Fused multiply-add instructions in a shared library (x86-64: vfmadd*,
# vfmsub*, vfnmadd*, vfnmsub*), in total and outside Eigen. Eigen's product
# kernels issue them on purpose (EIGEN_VECTORIZE_FMA, with -mfma or
# -march=native), whatever the contraction flags; they serve gravcal's own
# ICP fit, never the GGIR-compatible one (R's LINPACK, src/glue_ggir.cpp).
# Every other one is a contraction that gravcal/fp_contract.hpp should have
# stopped: the script fails and lists the functions that hold them.
#   sh tools/fma-count.sh path/to/gravcal.so
so=$1
objdump -d --no-show-raw-insn "$so" | awk -v so="$so" '
  /^[0-9a-f]+ <.*>:$/ { fn = $2; next }
  /\tvfn?m(add|sub)/ {
    n++
    if (fn !~ /^<_ZN[KVR]*5Eigen/) { other++; where[fn]++ }
  }
  END {
    printf "fused multiply-adds in %s: %d (Eigen'"'"'s kernels %d, elsewhere %d)\n", so, n, n - other, other
    for (f in where) printf "  %d in %s\n", where[f], f
    exit other > 0
  }'
