// The floating-point build, as R sees it when the package loads (R/build.R):
// whether this translation unit, compiled as every other one (the
// contraction pin first, then the same flags), fuses a * b + c, and whether
// -ffast-math was on. The operands come from R, so the compiler cannot fold
// the expression.
#include "gravcal/mcu/fp_contract.hpp"  // first, as in every translation unit

#include <Rcpp.h>

#include <cstring>

#include "gravcal/decoders/decode_csv_text.hpp"
#include "gravcal/host/r_arith.hpp"
#include "r_services.h"

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

// R's accumulator for the replays of R's arithmetic (r_services.h): set by
// R when the package loads, from capabilities("long.double"); returns the
// previous setting.
// [[Rcpp::export(rng = false)]]
bool gc_set_r_long_double(bool on) {
  bool& cur = gravcal_glue::r_long_double();
  const bool old = cur;
  cur = on;
  return old;
}

// R's mean(x) and sd(x) (na.rm = TRUE) as the core replays them, with R's
// accumulator long double (long_double) or double: for the load-time probe
// of R's own arithmetic (R/fp-build.R) and the tests.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector gc_r_mean_sd(Rcpp::NumericVector x, bool long_double) {
  const gravcal::RMeanSd r = gravcal::with_r_acc(long_double, [&](auto acc) {
    return gravcal::r_mean_sd<decltype(acc)>([&](auto&& f) {
      for (double v : x) f(v);
    });
  });
  return Rcpp::NumericVector::create(r.mean, r.sd);
}

// The csv decoder's value of each string by a number rule (0: correctly
// rounded; 1, 2: data.table's fread before and from 1.15.0; see
// decode_csv_text.hpp), NA where it is not a number: for the probe of the
// installed fread (R/fp-build.R) and the tests.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector gc_csv_numbers(Rcpp::CharacterVector s, int rule) {
  Rcpp::NumericVector out(s.size());
  for (R_xlen_t i = 0; i < s.size(); ++i) {
    const char* b = s[i];
    const char* e = b + std::strlen(b);
    double v = 0;
    out[i] = gravcal::csv_text::parse_number(b, e, '.', rule, v) ? v : NA_REAL;
  }
  return out;
}
