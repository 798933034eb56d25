#!/bin/sh
# Fused multiply-add instructions in a shared library, in total and outside
# Eigen: x86-64 vfmadd*, vfmsub*, vfnmadd*, vfnmsub*; aarch64 fmadd, fmsub,
# fnmadd, fnmsub (scalar) and fmla, fmls (vector). Eigen's product kernels
# issue them on purpose (EIGEN_VECTORIZE_FMA, with -mfma or -march=native,
# and always on aarch64), whatever the contraction flags; they serve
# gravcal's own ICP fit, never the GGIR-compatible one (R's LINPACK,
# src/glue_ggir.cpp). gc_fp_probe_unpinned (src/fp_probe_ggirread.cpp) is
# compiled without the pin on purpose: it shows what R's compiler does to
# GGIRread's code, and fuses where that compiler does. gravcal's replay of
# GGIRread's own arithmetic calls std::fma where R's compiler fused it
# (chosen when the package runs: kernels::ggir_lerp, GeneactivDecoder's
# ms_after), an instruction wherever the target has one, always through
# kernels::replay_fma, which is kept out of line: that function is counted
# apart. Every other one is a
# contraction that gravcal/mcu/fp_contract.hpp should have stopped: the script
# fails and lists the functions that hold them.
#   sh tools/fma-count.sh path/to/gravcal.so [objdump]
so=$1
objdump=${2:-objdump}
"$objdump" -d --no-show-raw-insn "$so" | awk -v so="$so" '
  /^[0-9a-f]+ <.*>:$/ { fn = $2; next }
  /\t(vfn?m(add|sub)|fn?m(add|sub)|fml[as])[a-z0-9.]*[ \t]/ {
    n++
    if (fn ~ /gc_fp_probe_unpinned/) { probe++; next }
    if (fn ~ /7kernels10replay_fma/) { replay++; next }
    if (fn !~ /^<_ZN[KVR]*5Eigen/) { other++; where[fn]++ }
  }
  END {
    printf "fused multiply-adds in %s: %d (Eigen'"'"'s kernels %d, the unpinned probe %d, GGIRread'"'"'s replay %d, elsewhere %d)\n",
      so, n, n - other - probe - replay, probe, replay, other
    for (f in where) printf "  %d in %s\n", where[f], f
    exit other > 0
  }'
