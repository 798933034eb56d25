// gravcal kernels: R's var() means of a window without R's two passes.
//
// r_var_means3(v, n, mean): the three means R's var() subtracts from three
// columns of n values, or false when they cannot be decided here and R's
// passes must run (r_sd3(), stats_r.hpp). The scalar reference decides
// none (R's passes are the reference); the AVX2 variant decides most
// windows at rest, and where it does, its means are R's to the bit.
//
// Header-only, standard headers only (and the intrinsics headers on x86).
#ifndef GRAVCAL_KERNELS_R_MEAN_HPP
#define GRAVCAL_KERNELS_R_MEAN_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cmath>
#include <cstddef>
#include <limits>

#include "gravcal/kernels/simd.hpp"

namespace gravcal {
namespace kernels {

inline bool r_var_means3_scalar(const double* const*, std::size_t, double*) { return false; }

// The mean R's var() subtracts (two passes in long double, then rounded to
// double), decided without those passes where a bound allows: the exact
// mean is had to about 2^-76 relative by compensated sums (Knuth's
// two-sum, error-free, in four lanes), and R's long double mean can lie
// only within W of it. When every value in [xbar - W, xbar + W] rounds to
// the same double, that double is R's.
//
// The bound (v = 2^-64, the long double unit roundoff; u = 2^-53; n
// values, M the largest |x|). R's first pass m1 = fl(fl(sum x) / n) has
// |m1 - xbar| <= D1 = (n + 1) v M (1.01). Its second pass sums d_i =
// fl(x_i - m1) = (x_i - m1)(1 + e_i), |e_i| <= v, in order, so t = n (xbar
// - m1) + E with |E| <= n v (1.01) sum |x_i - m1| (a recursive sum's
// bound); sum |x_i - m1| <= sum |x_i - xb| + n |xb - m1|, the first summed
// here in double (within (n + 8) u of it), xb the compensated mean in
// double. R's mean is fl(m1 + fl(t / n)) = xbar + E / n plus two roundings:
// within (1 + v)^2 (v (1.01) sum |x_i - m1| + v D1) + v M of xbar. The
// compensated mean: lanes of Sum2 (Ogita, Rump & Oishi 2005, Prop. 4.5:
// within gamma_n^2 sum |x| before its final rounding), lanes joined by
// two-sums and a sum of the small parts (6 additions), then the long double
// sum and the division by n: within 3 (n u)^2 n M + 20 n u^2 M + 2.1 v M of
// xbar. W is the sum of both, times 1.25, and the two ends are widened for
// their own rounding. Requires 2 <= n <= 2^24 and M in [1e-100, 1e100];
// anything else (or a non-finite value): false, and the caller does R's
// passes. tests/cpp/test_core.cpp compares it with R's passes.
#if defined(GRAVCAL_AVX2) && defined(__x86_64__)
namespace r_mean_detail {
// The decision of r_var_means3_avx2() from the compensated sum (h + r: the
// lanes joined), M and the sum of |x_i - xb| by lanes, for n values.
inline bool decide_mean(long double xbar, double M, const double* dl, std::size_t n,
                        double* mean) {
  const long double N = static_cast<long double>(n);
  const long double v = std::ldexp(1.0L, -64), u = std::ldexp(1.0L, -53);
  const long double LM = M;
  const long double Wc = 3.0L * (N * u) * (N * u) * N * LM + 20.0L * N * u * u * LM + 2.1L * v * LM;
  const long double sabs = static_cast<long double>((dl[0] + dl[1]) + (dl[2] + dl[3]));
  const long double D1 = (N + 1.0L) * v * LM * 1.01L;
  // sum |x_i - m1| <= sum |x_i - xb| + n |xb - m1|, |xb - m1| <= u M + Wc + D1
  const long double dev = sabs * (1.0L + (N + 8.0L) * u * 1.01L) + N * (u * LM + Wc + D1);
  const long double Wr = v * 1.01L * dev + v * D1 + 1.01L * v * LM;
  long double W = 1.25L * (Wr + Wc);
  W += 2.1L * v * (std::fabs(xbar) + W);
  const double a = static_cast<double>(xbar - W), b = static_cast<double>(xbar + W);
  if (a != b) return false;
  *mean = a;
  return true;
}

// Sum2's lanes joined: h + r, the small parts summed (6 additions).
inline long double join_lanes(const double* sl, const double* cl) {
  double h = sl[0], r = (cl[0] + cl[1]) + (cl[2] + cl[3]);
  for (int l = 1; l < 4; ++l) {
    const double t = h + sl[l];
    const double z = t - h;
    r += (h - (t - z)) + (sl[l] - z);
    h = t;
  }
  if (!std::isfinite(h) || !std::isfinite(r)) return std::numeric_limits<long double>::quiet_NaN();
  return static_cast<long double>(h) + r;
}
}  // namespace r_mean_detail

// The three columns at once (independent chains, so that the additions'
// latencies overlap): true with all three means decided.
GRAVCAL_TARGET_AVX2 inline bool r_var_means3_avx2(const double* const* v, std::size_t n,
                                                  double* mean) {
  static_assert(std::numeric_limits<long double>::digits == 64, "x87 long double");
  if (n < 2 || n > (std::size_t(1) << 24)) return false;
  // named registers (arrays of them indexed in a loop end up on the stack)
  __m256d s0 = _mm256_setzero_pd(), s1 = s0, s2 = s0, c0 = s0, c1 = s0, c2 = s0;
  __m256d lo0 = _mm256_set1_pd(v[0][0]), lo1 = _mm256_set1_pd(v[1][0]),
          lo2 = _mm256_set1_pd(v[2][0]);
  __m256d hi0 = lo0, hi1 = lo1, hi2 = lo2;
#define GRAVCAL_TWO_SUM_STEP(A, S, C, LO, HI)                                            \
  {                                                                                      \
    const __m256d x = _mm256_loadu_pd(v[A] + k);                                         \
    const __m256d t = _mm256_add_pd(S, x);                                               \
    const __m256d z = _mm256_sub_pd(t, S);                                               \
    C = _mm256_add_pd(C, _mm256_add_pd(_mm256_sub_pd(S, _mm256_sub_pd(t, z)),            \
                                       _mm256_sub_pd(x, z)));                            \
    S = t;                                                                               \
    LO = _mm256_min_pd(LO, x);                                                           \
    HI = _mm256_max_pd(HI, x);                                                           \
  }
  std::size_t k = 0;
  for (; k + 4 <= n; k += 4) {
    GRAVCAL_TWO_SUM_STEP(0, s0, c0, lo0, hi0)
    GRAVCAL_TWO_SUM_STEP(1, s1, c1, lo1, hi1)
    GRAVCAL_TWO_SUM_STEP(2, s2, c2, lo2, hi2)
  }
#undef GRAVCAL_TWO_SUM_STEP
  const __m256d s[3] = {s0, s1, s2}, c[3] = {c0, c1, c2}, lo[3] = {lo0, lo1, lo2},
                hi[3] = {hi0, hi1, hi2};
  const std::size_t kv = k;
  long double xbar[3];
  double M[3], xb[3], mnv[3], mxv[3];
  for (int a = 0; a < 3; ++a) {
    double sl[4], cl[4], lol[4], hil[4];
    _mm256_storeu_pd(sl, s[a]);
    _mm256_storeu_pd(cl, c[a]);
    _mm256_storeu_pd(lol, lo[a]);
    _mm256_storeu_pd(hil, hi[a]);
    double mn = lol[0], mx = hil[0];
    for (int l = 1; l < 4; ++l) {
      mn = lol[l] < mn ? lol[l] : mn;
      mx = hil[l] > mx ? hil[l] : mx;
    }
    for (std::size_t j = kv; j < n; ++j) {
      const double x = v[a][j];
      double& sk = sl[j & 3];
      const double t = sk + x;
      const double z = t - sk;
      cl[j & 3] += (sk - (t - z)) + (x - z);
      sk = t;
      mn = x < mn ? x : mn;
      mx = x > mx ? x : mx;
    }
    const long double S = r_mean_detail::join_lanes(sl, cl);
    if (!std::isfinite(S) || !std::isfinite(mn) || !std::isfinite(mx)) return false;
    mnv[a] = mn;
    mxv[a] = mx;
    M[a] = std::fmax(std::fabs(mn), std::fabs(mx));
    if (!(M[a] <= 1e100) || M[a] < 1e-100) return false;
    xbar[a] = S / static_cast<long double>(n);
    xb[a] = static_cast<double>(xbar[a]);
  }
  // first with sum |x_i - xb| bounded by n max(xb - min, max - xb) (the
  // spread of the window, no pass over it; rounded up by (1 + 4 u)): most
  // windows at rest are decided so
  {
    double out[3];
    bool all = true;
    for (int a = 0; a < 3 && all; ++a) {
      const double dev = std::fmax(xb[a] - mnv[a], mxv[a] - xb[a]);
      const double dl[4] = {static_cast<double>(n) * dev * (1.0 + 0x1p-51), 0.0, 0.0, 0.0};
      all = dev >= 0.0 && r_mean_detail::decide_mean(xbar[a], M[a], dl, n, &out[a]);
    }
    if (all) {
      for (int a = 0; a < 3; ++a) mean[a] = out[a];
      return true;
    }
  }
  // else summed, in double, four lanes: each term and the sum of
  // nonnegative terms within (n + 8) u (relative)
  const __m256d absm = _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffffLL));
  const __m256d b0 = _mm256_set1_pd(xb[0]), b1 = _mm256_set1_pd(xb[1]), b2 = _mm256_set1_pd(xb[2]);
  __m256d d0 = _mm256_setzero_pd(), d1 = d0, d2 = d0;
  for (k = 0; k + 4 <= n; k += 4) {
    d0 = _mm256_add_pd(d0, _mm256_and_pd(_mm256_sub_pd(_mm256_loadu_pd(v[0] + k), b0), absm));
    d1 = _mm256_add_pd(d1, _mm256_and_pd(_mm256_sub_pd(_mm256_loadu_pd(v[1] + k), b1), absm));
    d2 = _mm256_add_pd(d2, _mm256_and_pd(_mm256_sub_pd(_mm256_loadu_pd(v[2] + k), b2), absm));
  }
  double dl[3][4];
  _mm256_storeu_pd(dl[0], d0);
  _mm256_storeu_pd(dl[1], d1);
  _mm256_storeu_pd(dl[2], d2);
  for (int a = 0; a < 3; ++a) {
    for (std::size_t j = k; j < n; ++j) dl[a][j & 3] += std::fabs(v[a][j] - xb[a]);
  }
  double out[3];
  for (int a = 0; a < 3; ++a) {
    if (!r_mean_detail::decide_mean(xbar[a], M[a], dl[a], n, &out[a])) return false;
  }
  for (int a = 0; a < 3; ++a) mean[a] = out[a];
  return true;
}

// One column (the tests' entry): r_var_means3_avx2() with it three times.
inline bool r_var_mean_avx2(const double* x, std::size_t n, double* mean) {
  const double* v[3] = {x, x, x};
  double m[3];
  if (!r_var_means3_avx2(v, n, m)) return false;
  *mean = m[0];
  return true;
}
#endif


using RVarMeans3Fn = bool (*)(const double* const*, std::size_t, double*);
#if defined(GRAVCAL_AVX2) && defined(__x86_64__)
constexpr Variants<RVarMeans3Fn> r_var_means3_variants = {r_var_means3_scalar, nullptr,
                                                          r_var_means3_avx2};
#else
constexpr Variants<RVarMeans3Fn> r_var_means3_variants = {r_var_means3_scalar, nullptr, nullptr};
#endif

}  // namespace kernels
}  // namespace gravcal

#endif  // GRAVCAL_KERNELS_R_MEAN_HPP
