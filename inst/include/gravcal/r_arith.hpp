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
