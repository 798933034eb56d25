// What R's compiler does, with the flags it compiles packages with, to
// GGIRread's resampling step u * (v1 - v0) + v0 (GGIRread::resample, C++
// compiled when GGIRread was installed): one fused multiply-add or two
// roundings. Unlike every other translation unit of gravcal this one does
// NOT include gravcal/mcu/fp_contract.hpp: it stands for another package's code,
// compiled as that package's is. GCC contracts by default (-ffp-contract=fast
// outside strict ISO mode), which fuses on processors whose base instruction
// set has a multiply-add (aarch64, ppc64le, s390x) and not on x86-64 without
// -mfma. R/fp-build.R reads it (ggir_resample_fused()) where GGIRread itself
// cannot be asked. The operands come from R, so nothing is folded.
#include <Rcpp.h>

// [[Rcpp::export(rng = false)]]
double gc_fp_probe_unpinned(Rcpp::NumericMatrix v, double u) {
  // GGIRread's shape: a weight times a difference of two matrix entries,
  // plus the first (NumericVector's checked v(i) would keep GCC from
  // contracting where GGIRread's matrix access does not)
  return u * (v(1, 0) - v(0, 0)) + v(0, 0);
}
