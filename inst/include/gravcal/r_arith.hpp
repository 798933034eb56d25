// gravcal: R's mean() and sd() to the last bit, for the rules of GGIR's
// procedure that compare them with thresholds (GGIR computes them in R).
//
// R (src/main/summary.c, src/library/stats/src/cov.c) sums in long double,
// divides by n, and corrects the mean by a second pass over the deviations;
// the variance is the long double sum of squared deviations from the mean
// rounded to double, over n - 1. With na.rm = TRUE, NaN values are left
// out. The values are visited through `each(f)`, which calls f(value) for
// every value in order, so that they can lie anywhere (pieces of vectors,
// runs of a run-length code) without being copied.
//
// Header-only, standard headers only.
#ifndef GRAVCAL_R_ARITH_HPP
#define GRAVCAL_R_ARITH_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace gravcal {

struct RMeanSd {
  double mean = std::numeric_limits<double>::quiet_NaN();
  double sd = std::numeric_limits<double>::quiet_NaN();  // NaN with n < 2
  std::size_t n = 0;  // values that are not NaN
};

// mean(v, na.rm = TRUE) and sd(v, na.rm = TRUE) as R computes them.
template <class Each>
RMeanSd r_mean_sd(Each&& each) {
  RMeanSd r;
  long double s = 0.0L;
  std::size_t n = 0;
  each([&](double a) {
    if (std::isnan(a)) return;
    s += a;
    ++n;
  });
  r.n = n;
  if (n == 0) return r;
  const long double ln = static_cast<long double>(n);
  long double m = s / ln;
  if (std::isfinite(static_cast<double>(m))) {
    long double c = 0.0L;
    each([&](double a) {
      if (!std::isnan(a)) c += (a - m);
    });
    m += c / ln;
  }
  r.mean = static_cast<double>(m);
  if (n > 1) {
    long double ss = 0.0L;
    const long double xm = r.mean;
    each([&](double a) {
      if (!std::isnan(a)) ss += (a - xm) * (a - xm);
    });
    r.sd = std::sqrt(static_cast<double>(ss / static_cast<long double>(n - 1)));
  }
  return r;
}

// The sd of values given as runs (value, count), in one pass over the runs:
// the mean from the exact counts times the values, then the squared
// deviations times the counts, in long double (not R's bits). `each(f)`
// calls f(value, count) for every run in order; NaN values are left out
// (na.rm). sd is NaN with fewer than 2 values.
struct RunsSd {
  double sd = std::numeric_limits<double>::quiet_NaN();
  long double var = 0.0L;    // sd's square before rounding: ss / (n - 1)
  std::uint64_t n = 0;       // values that are not NaN
  std::uint64_t runs = 0;    // runs that are not NaN
  double max_abs = 0.0;      // largest |value|
  bool finite = true;        // no infinite value
};

template <class EachRun>
RunsSd runs_sd(EachRun&& each) {
  RunsSd r;
  long double sum = 0.0L;
  each([&](double v, std::uint64_t c) {
    if (std::isnan(v) || c == 0) return;
    sum += static_cast<long double>(v) * c;
    r.n += c;
    ++r.runs;
    if (!std::isfinite(v)) r.finite = false;
    if (std::fabs(v) > r.max_abs) r.max_abs = std::fabs(v);
  });
  if (r.n < 2) return r;
  const long double mean = sum / r.n;
  long double ss = 0.0L;
  each([&](double v, std::uint64_t c) {
    if (std::isnan(v) || c == 0) return;
    const long double d = v - mean;
    ss += d * d * c;
  });
  r.var = ss / (r.n - 1);
  r.sd = static_cast<double>(std::sqrt(r.var));
  return r;
}

// R's mean() of n contiguous values (no NaN handling: R's mean without
// na.rm gives NaN when any value is NaN, as this does).
inline double r_mean(const double* v, std::size_t n) {
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  const long double ln = static_cast<long double>(n);
  long double s = 0.0L;
  for (std::size_t i = 0; i < n; ++i) s += v[i];
  long double m = s / ln;
  if (std::isfinite(static_cast<double>(m))) {
    long double t = 0.0L;
    for (std::size_t i = 0; i < n; ++i) t += (v[i] - m);
    m += t / ln;
  }
  return static_cast<double>(m);
}

}  // namespace gravcal

#endif  // GRAVCAL_R_ARITH_HPP
