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
// Also: an sd from runs of equal values and when it is sure to be on the
// same side of a threshold as R's (runs_sd(), r_sd_below()), and repeated
// long double additions in closed form (add_repeated()), so that R's
// arithmetic runs only where its bits can matter.
//
// R's accumulators. R sums in its LDOUBLE type: long double, or double in
// an R configured with --disable-long-double (CRAN's "noLD" check; and on
// macOS arm64, where long double is double anyway). Every function here
// that replays R's sums takes the accumulator as a template parameter Acc
// (long double by default; double for an R without long double), which the
// R glue chooses once per call from capabilities("long.double") of the R it
// runs in (R/fp-build.R).
//
// Header-only, standard headers only.
#ifndef GRAVCAL_R_ARITH_HPP
#define GRAVCAL_R_ARITH_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

namespace gravcal {

// f(Acc()) with R's accumulator: long double when r_long_double (R's
// default), else double; the one place a run-time choice of R's arithmetic
// becomes a type.
template <class F>
decltype(auto) with_r_acc(bool r_long_double, F&& f) {
  if (r_long_double) return f(static_cast<long double>(0));
  return f(0.0);
}

struct RMeanSd {
  double mean = std::numeric_limits<double>::quiet_NaN();
  double sd = std::numeric_limits<double>::quiet_NaN();  // NaN with n < 2
  std::size_t n = 0;  // values that are not NaN
};

// mean(v, na.rm = TRUE) and sd(v, na.rm = TRUE) as R computes them, with
// R's accumulator Acc.
template <class Acc = long double, class Each>
RMeanSd r_mean_sd(Each&& each) {
  RMeanSd r;
  Acc s = 0.0;
  std::size_t n = 0;
  each([&](double a) {
    if (std::isnan(a)) return;
    s += a;
    ++n;
  });
  r.n = n;
  if (n == 0) return r;
  const Acc ln = static_cast<Acc>(n);
  Acc m = s / ln;
  if (std::isfinite(static_cast<double>(m))) {
    Acc c = 0.0;
    each([&](double a) {
      if (!std::isnan(a)) c += (a - m);
    });
    m += c / ln;
  }
  r.mean = static_cast<double>(m);
  if (n > 1) {
    Acc ss = 0.0;
    const Acc xm = r.mean;
    each([&](double a) {
      if (!std::isnan(a)) ss += (a - xm) * (a - xm);
    });
    r.sd = std::sqrt(static_cast<double>(ss / static_cast<Acc>(n - 1)));
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

// Whether R's sd() of the same values is below `thr` (1), not below (0), or
// too close to tell (-1), from runs_sd()'s result alone. Only when this is
// -1 need R's arithmetic be repeated (r_mean_sd()). Acc: R's accumulator,
// whose unit roundoff is u below (runs_sd()'s own sums, in long double, are
// at least as precise).
//
// Why the answer is R's. Let the n values a_i have true mean mu, true
// variance s2 = sum (a_i - mu)^2 / (n - 1) and M = max |a_i|, all finite;
// u = the unit roundoff of R's accumulator (2^-64 for x87's long double;
// 2^-53 where it is double), v = 2^-53 (double); standard bounds for
// recursive summation (Higham, Accuracy and Stability of Numerical
// Algorithms, 2nd ed., sec. 4.2; gamma_k = k u / (1 - k u)).
// - R's mean (r_mean_sd()): the sum is off by at most gamma_(n-1) n M, so
//   s / n by about n u M; the correction pass brings it to within
//   (2.1 n + 2) u M of mu, and rounding to double adds 1.01 v M (plus
//   2^-1075 when subnormal). So R's xm is within dR = (2 v + (4 n + 8) u) M
//   + 1e-300 of mu.
// - R's ss = sum (a_i - xm)^2 (non-negative terms, each with 2 roundings)
//   is within gamma_(n+2) of the exact sum, which is (n - 1) s2 + n (mu -
//   xm)^2; dividing by n - 1, rounding to double, sqrt() and squaring back
//   add u + 3 v. So sd_R^2 = (s2 + n / (n - 1) dR'^2) (1 + e), |dR'| <= dR,
//   |e| <= (n + 3) u + 3 v (times 1.02), n / (n - 1) <= 2.
// - runs_sd(): the mean is within (K + 1) u M (times 1.05) of mu, K runs;
//   the squared deviations times counts have 3 roundings each, their sum
//   K, the division 1: var = (s2 + n / (n - 1) dF^2) (1 + f), |dF| <= (K +
//   2) u M, |f| <= (K + 5) u (times 1.02).
// With eps = 4 (n + K + 16) u + 16 v >= |e|, |f| (and room for the rounding
// of the bounds themselves) and d2 = 2 max(dR, dF)^2:
//   s2 in [var / (1 + eps) - d2, var / (1 - eps)], so
//   sd_R^2 <= (var / (1 - eps) + d2) (1 + eps) = hi and
//   sd_R^2 >= (var / (1 + eps) - d2) (1 - eps) = lo.
// hi < thr^2 (1 - 1e-15) means sd_R < thr; lo > thr^2 (1 + 1e-15) means
// sd_R > thr; otherwise -1. The bounds need n u small, M and thr within
// [1e-100, 1e100] (M = 0 too), and no infinite value; outside that, -1.
// The margins are far wider than the errors seen in practice (about 1e-12
// relative for 4e6 values), so -1 happens only within about 1e-12 of thr.
template <class Acc = long double>
int r_sd_below(const RunsSd& r, double thr) {
  if (r.n < 2 || !r.finite) return -1;
  if (!(thr >= 1e-100 && thr <= 1e100)) return -1;
  if (r.max_abs > 1e100 || (r.max_abs != 0.0 && r.max_abs < 1e-100)) return -1;
  if (r.n > (std::uint64_t(1) << 40) || r.runs > (std::uint64_t(1) << 40)) return -1;
  // u: the unit roundoff of R's accumulator, 2^-64 where it is the x87's
  // 80-bit long double, 2^-53 where it is double (an R without long double;
  // macOS arm64); runs_sd()'s u is never larger
  const long double u = std::numeric_limits<Acc>::epsilon() / 2;
  const long double v = std::ldexp(1.0L, -53);
  const long double n = static_cast<long double>(r.n);
  const long double k = static_cast<long double>(r.runs);
  const long double M = r.max_abs;
  const long double eps = 4.0L * (n + k + 16.0L) * u + 16.0L * v;
  const long double dm = (2.0L * v + (4.0L * n + 4.0L * k + 16.0L) * u) * M + 1e-300L;
  const long double d2 = 2.0L * dm * dm;
  const long double hi = (r.var / (1.0L - eps) + d2) * (1.0L + eps) + 1e-300L;
  const long double lo = (r.var / (1.0L + eps) - d2) * (1.0L - eps) - 1e-300L;
  const long double t2 = static_cast<long double>(thr) * thr;
  if (hi < t2 * (1.0L - 1e-15L)) return 1;
  if (lo > t2 * (1.0L + 1e-15L)) return 0;
  return -1;
}

// The grid of the accumulator Acc around a value: |s| in [bottom, top) =
// [2^(e-1), 2^e) has spacing q = 2^(e - digits), digits Acc's.
template <class Acc = long double>
struct Binade {
  Acc q = 0, inv_q = 0, bottom = 0, top = 0;
  bool holds(Acc a) const { return a >= bottom && a < top; }
  void set(Acc s) {
    constexpr int digits = std::numeric_limits<Acc>::digits;
    int e = 0;
    std::frexp(s, &e);
    q = std::ldexp(Acc(1), e - digits);
    inv_q = std::ldexp(Acc(1), digits - e);
    bottom = std::ldexp(Acc(1), e - 1);
    top = std::ldexp(Acc(1), e);
  }
};

// add_repeated()'s closed form (see there): adds x to s j times, 0 < j <=
// k, as j additions would, and returns j; or returns 0 when the next
// addition must be a plain one. b: the grid of s, kept between calls.
template <class Acc>
std::uint64_t repeat_steps(Acc& s, double x, std::uint64_t k, Binade<Acc>& b) {
  if (x == 0.0 || s == 0.0 || !std::isfinite(x) || !std::isfinite(s)) return 0;
  const Acc a = std::fabs(s);
  if (!b.holds(a)) b.set(s);
  const Acc y = x * b.inv_q;  // exact: a power of 2
  if (!(std::fabs(y) < Acc(0x1p62))) return 0;
  const Acc n = static_cast<Acc>(std::llrint(y));
  if (std::fabs(y - n) == Acc(0.5)) return 0;  // a tie: the last bit of s decides
  const Acc r = n * b.q;                       // x on the grid of s
  // |s| may go from lo to hi (q inside the binade), in steps of |r|
  const Acc lo = b.bottom + b.q, hi = b.top - b.q;
  if (r == 0.0) return a >= lo && a <= hi ? k : 0;  // s does not move
  const Acc room = (s > 0) == (r > 0) ? hi - a : a - lo;
  if (!(room > 0)) return 0;
  const Acc step = std::fabs(r);
  std::uint64_t j = k;
  if (static_cast<Acc>(k) * step > room) {
    j = static_cast<std::uint64_t>(std::floor(room / step));
  }
  // room / step rounded: step back until s + j r is inside (j r is exact:
  // |j n| < 2^digits)
  while (j > 0) {
    const Acc t = std::fabs(s + static_cast<Acc>(j) * r);
    if (t >= lo && t <= hi) break;
    --j;
  }
  if (j > 0) s += static_cast<Acc>(j) * r;  // exact, see add_repeated()
  return j;
}

// s += x, k times, in Acc (R's accumulator), to the bit (as a loop of k additions
// would give it), in a few steps. Each addition rounds the exact s + x to
// the long double grid of s's binade: spacing q = 2^(e - digits) for |s| in
// [2^(e-1), 2^e). s is on that grid, so while s + x stays inside the
// binade the sum rounds to s + r, r = x rounded to the nearest multiple of
// q (the grid is the same after a shift by s), unless x is exactly half-way
// between two multiples, a tie that the last bit of s decides. So j
// additions give s + j r, exactly (a multiple of q inside the binade is
// representable, and so is j r), as long as |s + j r| stays in [2^(e-1) +
// q, 2^e - q]: every exact sum on the way is then inside the binade
// (|x - r| <= q / 2). At a tie, near the binade's edges, with s or x zero
// or not finite, and for fewer than 4 additions: plain additions.
template <class Acc>
void add_repeated(Acc& s, double x, std::uint64_t k, Binade<Acc>& b) {
  while (k > 0) {
    const std::uint64_t j = k < 4 ? 0 : repeat_steps(s, x, k, b);
    if (j == 0) {
      s += x;
      --k;
    } else {
      k -= j;
    }
  }
}

template <class Acc>
void add_repeated(Acc& s, double x, std::uint64_t k) {
  Binade<Acc> b;
  add_repeated(s, x, k, b);
}

// R's mean() of n contiguous values (no NaN handling: R's mean without
// na.rm gives NaN when any value is NaN, as this does), R's accumulator Acc.
template <class Acc = long double>
double r_mean(const double* v, std::size_t n) {
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  const Acc ln = static_cast<Acc>(n);
  Acc s = 0.0;
  for (std::size_t i = 0; i < n; ++i) s += v[i];
  Acc m = s / ln;
  if (std::isfinite(static_cast<double>(m))) {
    Acc t = 0.0;
    for (std::size_t i = 0; i < n; ++i) t += (v[i] - m);
    m += t / ln;
  }
  return static_cast<double>(m);
}

}  // namespace gravcal

#endif  // GRAVCAL_R_ARITH_HPP
