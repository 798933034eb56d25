// gravcal kernels: GGIR's calibration applied to a span of one axis.
//
// offset_divide(p, n, o, s, term, add): p[i] = (p[i] + o) / s, then, where
// `add`, + term: g.getmeta()'s scale() of the axis with centre -offset and
// scale 1 / scale, and a temperature term constant over the span (a
// device's temperature holds for a page). Every operation is one IEEE
// rounding in every variant (the vector lanes add and divide as the scalar
// code does), so the variants give the reference's bits; without `add`
// nothing is added (adding 0 would turn -0 into +0).
//
// Header-only, standard headers only (and the intrinsics headers on x86).
#ifndef GRAVCAL_KERNELS_APPLY_HPP
#define GRAVCAL_KERNELS_APPLY_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cstddef>

#include "gravcal/kernels/simd.hpp"

namespace gravcal {
namespace kernels {

inline void offset_divide_scalar(double* p, std::size_t n, double o, double s, double term,
                                 bool add) {
  if (add) {
    for (std::size_t i = 0; i < n; ++i) p[i] = (p[i] + o) / s + term;
  } else {
    for (std::size_t i = 0; i < n; ++i) p[i] = (p[i] + o) / s;
  }
}

#if defined(GRAVCAL_SSE2)
inline void offset_divide_sse2(double* p, std::size_t n, double o, double s, double term,
                               bool add) {
  const __m128d vo = _mm_set1_pd(o), vs = _mm_set1_pd(s), vt = _mm_set1_pd(term);
  std::size_t i = 0;
  if (add) {
    for (; i + 2 <= n; i += 2) {
      const __m128d v = _mm_div_pd(_mm_add_pd(_mm_loadu_pd(p + i), vo), vs);
      _mm_storeu_pd(p + i, _mm_add_pd(v, vt));
    }
  } else {
    for (; i + 2 <= n; i += 2) _mm_storeu_pd(p + i, _mm_div_pd(_mm_add_pd(_mm_loadu_pd(p + i), vo), vs));
  }
  offset_divide_scalar(p + i, n - i, o, s, term, add);  // the rest
}
#endif

#if defined(GRAVCAL_AVX2)
GRAVCAL_TARGET_AVX2 inline void offset_divide_avx2(double* p, std::size_t n, double o, double s,
                                                   double term, bool add) {
  const __m256d vo = _mm256_set1_pd(o), vs = _mm256_set1_pd(s), vt = _mm256_set1_pd(term);
  std::size_t i = 0;
  if (add) {
    for (; i + 4 <= n; i += 4) {
      const __m256d v = _mm256_div_pd(_mm256_add_pd(_mm256_loadu_pd(p + i), vo), vs);
      _mm256_storeu_pd(p + i, _mm256_add_pd(v, vt));
    }
  } else {
    for (; i + 4 <= n; i += 4) {
      _mm256_storeu_pd(p + i, _mm256_div_pd(_mm256_add_pd(_mm256_loadu_pd(p + i), vo), vs));
    }
  }
  offset_divide_scalar(p + i, n - i, o, s, term, add);  // the rest
}
#endif

using OffsetDivideFn = void (*)(double*, std::size_t, double, double, double, bool);
constexpr Variants<OffsetDivideFn> offset_divide_variants = {
    offset_divide_scalar, GRAVCAL_IF_SSE2(offset_divide_sse2), GRAVCAL_IF_AVX2(offset_divide_avx2)};

}  // namespace kernels
}  // namespace gravcal

#endif  // GRAVCAL_KERNELS_APPLY_HPP
