// gravcal kernels: the per-point loops of gravcal's own ICP fit (fit_icp(),
// icp.hpp), element by element.
//
// As in kernels/window.hpp: a scalar reference per kernel and, beside it,
// the vector code standing in for it (two elements per SSE2 instruction,
// the same operations on each element, never fused); the kernel table
// (kernels.hpp) chooses once.
//
// Header-only, standard headers only (and the intrinsics headers on x86).
#ifndef GRAVCAL_KERNELS_ICP_HPP
#define GRAVCAL_KERNELS_ICP_HPP

#include <cmath>
#include <cstddef>

#include "../simd.hpp"

namespace gravcal {
namespace kernels {

// icp_apply(v, t, n, o, s, to, out): out[i] = (v[i] + o) / (1 / s) + t[i] /
// (1 / to), t[i] = 0 where t is null (GGIR's operation order).
inline void icp_apply_tail(const double* v, const double* t, std::size_t i, std::size_t n,
                           double o, double is, double it, double* out) {
  for (; i < n; ++i) out[i] = (v[i] + o) / is + (t != nullptr ? t[i] : 0.0) / it;
}
inline void icp_apply_scalar(const double* v, const double* t, std::size_t n, double o, double s,
                             double to, double* out) {
  icp_apply_tail(v, t, 0, n, o, 1.0 / s, 1.0 / to, out);
}
#if defined(GRAVCAL_SSE2)
inline void icp_apply_sse2(const double* v, const double* t, std::size_t n, double o, double s,
                           double to, double* out) {
  const double is = 1.0 / s, it = 1.0 / to;
  const __m128d ov = _mm_set1_pd(o), sv = _mm_set1_pd(is), tv = _mm_set1_pd(it);
  std::size_t i = 0;
  for (; i + 2 <= n; i += 2) {
    const __m128d tt = t != nullptr ? _mm_loadu_pd(t + i) : _mm_setzero_pd();
    _mm_storeu_pd(out + i, _mm_add_pd(_mm_div_pd(_mm_add_pd(_mm_loadu_pd(v + i), ov), sv),
                                      _mm_div_pd(tt, tv)));
  }
  icp_apply_tail(v, t, i, n, o, is, it, out);
}
#endif
using IcpApplyFn = void (*)(const double*, const double*, std::size_t, double, double, double,
                            double*);
constexpr Variants<IcpApplyFn> icp_apply_variants = {icp_apply_scalar,
                                                     GRAVCAL_IF_SSE2(icp_apply_sse2), nullptr};

// icp_project(c0, c1, c2, n, p0, p1, p2): p = c / |c|, |c| = sqrt(c0^2 +
// c1^2 + c2^2).
inline void icp_project_tail(const double* c0, const double* c1, const double* c2, std::size_t i,
                             std::size_t n, double* p0, double* p1, double* p2) {
  for (; i < n; ++i) {
    const double r = std::sqrt(c0[i] * c0[i] + c1[i] * c1[i] + c2[i] * c2[i]);
    p0[i] = c0[i] / r;
    p1[i] = c1[i] / r;
    p2[i] = c2[i] / r;
  }
}
inline void icp_project_scalar(const double* c0, const double* c1, const double* c2,
                               std::size_t n, double* p0, double* p1, double* p2) {
  icp_project_tail(c0, c1, c2, 0, n, p0, p1, p2);
}
#if defined(GRAVCAL_SSE2)
inline void icp_project_sse2(const double* c0, const double* c1, const double* c2, std::size_t n,
                             double* p0, double* p1, double* p2) {
  std::size_t i = 0;
  for (; i + 2 <= n; i += 2) {
    const __m128d a = _mm_loadu_pd(c0 + i), b = _mm_loadu_pd(c1 + i), c = _mm_loadu_pd(c2 + i);
    const __m128d r = _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(a, a), _mm_mul_pd(b, b)),
                                             _mm_mul_pd(c, c)));
    _mm_storeu_pd(p0 + i, _mm_div_pd(a, r));
    _mm_storeu_pd(p1 + i, _mm_div_pd(b, r));
    _mm_storeu_pd(p2 + i, _mm_div_pd(c, r));
  }
  icp_project_tail(c0, c1, c2, i, n, p0, p1, p2);
}
#endif
using IcpProjectFn = void (*)(const double*, const double*, const double*, std::size_t, double*,
                              double*, double*);
constexpr Variants<IcpProjectFn> icp_project_variants = {
    icp_project_scalar, GRAVCAL_IF_SSE2(icp_project_sse2), nullptr};

// icp_sqrt(w, n, out): out[i] = sqrt(w[i]).
inline void icp_sqrt_scalar(const double* w, std::size_t n, double* out) {
  for (std::size_t i = 0; i < n; ++i) out[i] = std::sqrt(w[i]);
}
#if defined(GRAVCAL_SSE2)
inline void icp_sqrt_sse2(const double* w, std::size_t n, double* out) {
  std::size_t i = 0;
  for (; i + 2 <= n; i += 2) _mm_storeu_pd(out + i, _mm_sqrt_pd(_mm_loadu_pd(w + i)));
  for (; i < n; ++i) out[i] = std::sqrt(w[i]);
}
#endif
using IcpSqrtFn = void (*)(const double*, std::size_t, double*);
constexpr Variants<IcpSqrtFn> icp_sqrt_variants = {icp_sqrt_scalar, GRAVCAL_IF_SSE2(icp_sqrt_sse2),
                                                   nullptr};

// icp_times(a, b, n, out): out[i] = a[i] b[i].
inline void icp_times_scalar(const double* a, const double* b, std::size_t n, double* out) {
  for (std::size_t i = 0; i < n; ++i) out[i] = a[i] * b[i];
}
#if defined(GRAVCAL_SSE2)
inline void icp_times_sse2(const double* a, const double* b, std::size_t n, double* out) {
  std::size_t i = 0;
  for (; i + 2 <= n; i += 2) {
    _mm_storeu_pd(out + i, _mm_mul_pd(_mm_loadu_pd(a + i), _mm_loadu_pd(b + i)));
  }
  for (; i < n; ++i) out[i] = a[i] * b[i];
}
#endif
using IcpTimesFn = void (*)(const double*, const double*, std::size_t, double*);
constexpr Variants<IcpTimesFn> icp_times_variants = {icp_times_scalar,
                                                     GRAVCAL_IF_SSE2(icp_times_sse2), nullptr};

// icp_fitted(b0, b1, b2, t, n, c): c = b0 + b1 c (+ b2 t where t is not
// null), in place.
inline void icp_fitted_tail(double b0, double b1, double b2, const double* t, std::size_t i,
                            std::size_t n, double* c) {
  for (; i < n; ++i) {
    double f = b0 + b1 * c[i];
    if (t != nullptr) f += b2 * t[i];
    c[i] = f;
  }
}
inline void icp_fitted_scalar(double b0, double b1, double b2, const double* t, std::size_t n,
                              double* c) {
  icp_fitted_tail(b0, b1, b2, t, 0, n, c);
}
#if defined(GRAVCAL_SSE2)
inline void icp_fitted_sse2(double b0, double b1, double b2, const double* t, std::size_t n,
                            double* c) {
  const __m128d v0 = _mm_set1_pd(b0), v1 = _mm_set1_pd(b1), v2 = _mm_set1_pd(b2);
  std::size_t i = 0;
  for (; i + 2 <= n; i += 2) {
    __m128d f = _mm_add_pd(v0, _mm_mul_pd(v1, _mm_loadu_pd(c + i)));
    if (t != nullptr) f = _mm_add_pd(f, _mm_mul_pd(v2, _mm_loadu_pd(t + i)));
    _mm_storeu_pd(c + i, f);
  }
  icp_fitted_tail(b0, b1, b2, t, i, n, c);
}
#endif
using IcpFittedFn = void (*)(double, double, double, const double*, std::size_t, double*);
constexpr Variants<IcpFittedFn> icp_fitted_variants = {icp_fitted_scalar,
                                                       GRAVCAL_IF_SSE2(icp_fitted_sse2), nullptr};

// icp_weights(c0, c1, c2, p0, p1, p2, n, max_weight, w, next, wd2): d2 =
// |c - p|^2; wd2 = w d2 (GGIR's statistic); next = min(1 / sqrt(d2),
// max_weight).
inline void icp_weights_tail(const double* c0, const double* c1, const double* c2,
                             const double* p0, const double* p1, const double* p2, std::size_t i,
                             std::size_t n, double max_weight, const double* w, double* next,
                             double* wd2) {
  for (; i < n; ++i) {
    const double a = c0[i] - p0[i], b = c1[i] - p1[i], c = c2[i] - p2[i];
    const double d2 = a * a + b * b + c * c;
    wd2[i] = w[i] * d2;
    const double wi = 1.0 / std::sqrt(d2);
    next[i] = wi < max_weight ? wi : max_weight;
  }
}
inline void icp_weights_scalar(const double* c0, const double* c1, const double* c2,
                               const double* p0, const double* p1, const double* p2,
                               std::size_t n, double max_weight, const double* w, double* next,
                               double* wd2) {
  icp_weights_tail(c0, c1, c2, p0, p1, p2, 0, n, max_weight, w, next, wd2);
}
#if defined(GRAVCAL_SSE2)
inline void icp_weights_sse2(const double* c0, const double* c1, const double* c2,
                             const double* p0, const double* p1, const double* p2, std::size_t n,
                             double max_weight, const double* w, double* next, double* wd2) {
  const __m128d one = _mm_set1_pd(1.0), mw = _mm_set1_pd(max_weight);
  std::size_t i = 0;
  for (; i + 2 <= n; i += 2) {
    const __m128d a = _mm_sub_pd(_mm_loadu_pd(c0 + i), _mm_loadu_pd(p0 + i));
    const __m128d b = _mm_sub_pd(_mm_loadu_pd(c1 + i), _mm_loadu_pd(p1 + i));
    const __m128d c = _mm_sub_pd(_mm_loadu_pd(c2 + i), _mm_loadu_pd(p2 + i));
    const __m128d d2 = _mm_add_pd(_mm_add_pd(_mm_mul_pd(a, a), _mm_mul_pd(b, b)),
                                  _mm_mul_pd(c, c));
    _mm_storeu_pd(wd2 + i, _mm_mul_pd(_mm_loadu_pd(w + i), d2));
    // min(a, b) is a < b ? a : b, as the scalar rule
    _mm_storeu_pd(next + i, _mm_min_pd(_mm_div_pd(one, _mm_sqrt_pd(d2)), mw));
  }
  icp_weights_tail(c0, c1, c2, p0, p1, p2, i, n, max_weight, w, next, wd2);
}
#endif
using IcpWeightsFn = void (*)(const double*, const double*, const double*, const double*,
                              const double*, const double*, std::size_t, double, const double*,
                              double*, double*);
constexpr Variants<IcpWeightsFn> icp_weights_variants = {
    icp_weights_scalar, GRAVCAL_IF_SSE2(icp_weights_sse2), nullptr};

}  // namespace kernels
}  // namespace gravcal

#endif  // GRAVCAL_KERNELS_ICP_HPP
