// The floating-point build, as R sees it when the package loads (R/build.R):
// whether this translation unit, compiled as every other one (the
// contraction pin first, then the same flags), fuses a * b + c, and whether
// -ffast-math was on. The operands come from R, so the compiler cannot fold
// the expression.
#include "gravcal/fp_contract.hpp"  // first, as in every translation unit

#include <Rcpp.h>

// [[Rcpp::export(rng = false)]]
Rcpp::List gc_fp_probe(double a, double b, double c) {
#if defined(__FAST_MATH__)
  const bool fast_math = true;
#else
  const bool fast_math = false;
#endif
  return Rcpp::List::create(Rcpp::Named("value") = a * b + c,
                            Rcpp::Named("fast_math") = fast_math);
}
