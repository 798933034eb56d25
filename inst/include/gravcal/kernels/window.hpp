// gravcal kernels: the loops over a window's samples (stats_streaming.hpp,
// stats_r.hpp) and over a block's (ggir_blocks.hpp).
//
// Each kernel is a scalar reference (name_scalar) and, beside it, the
// vector code that stands in for it (name_sse2, name_avx2), with the same
// signature and the same results to the bit: integer work, or the same
// floating-point operations on the same values in the same order, never
// fused. Sums over a window are kept in four lanes by the sample's position
// (k & 3), each lane adding its own samples in order, so that two or four
// samples can go through one instruction; the lanes are joined by the
// caller as (0 + 1) + (2 + 3). Which variant runs is decided once, by the
// kernel table (kernels.hpp); tests/testthat/test-simd.R compares every
// variant with its reference.
//
// Header-only, standard headers only (and the intrinsics headers on x86).
#ifndef GRAVCAL_KERNELS_WINDOW_HPP
#define GRAVCAL_KERNELS_WINDOW_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "gravcal/kernels/simd.hpp"
#include "gravcal/mcu/stats_streaming.hpp"
#include "gravcal/mcu/window_cutter.hpp"

namespace gravcal {
namespace kernels {

// ---------------------------------------------------------------------------
// run_end(v, i, n): the end of the run of values with the same bits as v[i]
// (i < n), from i on.

inline std::size_t run_tail(const double* v, std::size_t j, std::size_t n, std::uint64_t bits) {
  while (j < n && std::memcmp(v + j, &bits, sizeof bits) == 0) ++j;
  return j;
}

inline std::size_t run_end_scalar(const double* v, std::size_t i, std::size_t n) {
  std::uint64_t bits;
  std::memcpy(&bits, v + i, sizeof bits);
  return run_tail(v, i + 1, n, bits);
}

#if defined(GRAVCAL_AVX2)
GRAVCAL_TARGET_AVX2 inline std::size_t run_end_avx2(const double* v, std::size_t i,
                                                    std::size_t n) {
  std::uint64_t bits;
  std::memcpy(&bits, v + i, sizeof bits);
  std::size_t j = i + 1;
  const __m256i b = _mm256_set1_epi64x(static_cast<long long>(bits));
  for (; j + 8 <= n; j += 8) {
    const __m256i a0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v + j));
    const __m256i a1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v + j + 4));
    const __m256i eq = _mm256_and_si256(_mm256_cmpeq_epi64(a0, b), _mm256_cmpeq_epi64(a1, b));
    if (_mm256_movemask_epi8(eq) != -1) break;
  }
  return run_tail(v, j, n, bits);
}
#endif

using RunEndFn = std::size_t (*)(const double*, std::size_t, std::size_t);
constexpr Variants<RunEndFn> run_end_variants = {run_end_scalar, nullptr,
                                                 GRAVCAL_IF_AVX2(run_end_avx2)};

// ---------------------------------------------------------------------------
// Shared by the window kernels.

// min, max and the all-zeros test of samples [k, m), continuing lo, hi,
// zero (in locals: through the pointers every step would be a store and a
// load).
inline void min_max_tail(const double* const* col, std::size_t k, std::size_t m, double* lo,
                         double* hi, bool& zero) {
  const double* x = col[0];
  const double* y = col[1];
  const double* z = col[2];
  double lo0 = lo[0], lo1 = lo[1], lo2 = lo[2], hi0 = hi[0], hi1 = hi[1], hi2 = hi[2];
  bool zr = zero;
  for (; k < m; ++k) {
    const double a = x[k], b = y[k], c = z[k];
    zr = zr | ((a == 0.0) & (b == 0.0) & (c == 0.0));
    lo0 = a < lo0 ? a : lo0;
    lo1 = b < lo1 ? b : lo1;
    lo2 = c < lo2 ? c : lo2;
    hi0 = a > hi0 ? a : hi0;
    hi1 = b > hi1 ? b : hi1;
    hi2 = c > hi2 ? c : hi2;
  }
  lo[0] = lo0;
  lo[1] = lo1;
  lo[2] = lo2;
  hi[0] = hi0;
  hi[1] = hi1;
  hi[2] = hi2;
  zero = zr;
}

// ---------------------------------------------------------------------------
// stream_window(x, y, z, t, m, o): a whole window of m >= 1 samples in one
// pass, the streaming arithmetic: per axis the sums of d and d^2, d = v -
// v[0] (the shifted data algorithm), in lanes; the norms' and the
// temperatures' sums in lanes (t may be null); min, max and whether some
// sample is all zeros. With a non-finite sample the sums are not finite
// (the caller's test) and min and max are not defined. The scalar
// reference is stream_window() of the microcontroller tier
// (stats_streaming.hpp).

#if defined(GRAVCAL_SSE2)
// lanes 0 and 1 (samples k, k + 1) in one register (suffix a), 2 and 3 in
// another (b); named registers, not arrays, so that all stay in registers
inline void stream_window_sse2(const double* x, const double* y, const double* z,
                               const double* t, std::size_t m, StreamSums& o) {
  const double* col[3] = {x, y, z};
  const double h[3] = {x[0], y[0], z[0]};
  double lo[3], hi[3];
  o = StreamSums();
  std::size_t k = 0;
  const __m128d zr = _mm_setzero_pd();
  const __m128d h0 = _mm_set1_pd(h[0]), h1 = _mm_set1_pd(h[1]), h2 = _mm_set1_pd(h[2]);
  __m128d s0a = zr, s0b = zr, s1a = zr, s1b = zr, s2a = zr, s2b = zr;
  __m128d q0a = zr, q0b = zr, q1a = zr, q1b = zr, q2a = zr, q2b = zr;
  __m128d na = zr, nb = zr, ta = zr, tb = zr, zacc = zr;
  __m128d lo0 = h0, lo1 = h1, lo2 = h2, hi0 = h0, hi1 = h1, hi2 = h2;
  for (; k + 4 <= m; k += 4) {
    const __m128d xa = _mm_loadu_pd(x + k), xb = _mm_loadu_pd(x + k + 2);
    const __m128d ya = _mm_loadu_pd(y + k), yb = _mm_loadu_pd(y + k + 2);
    const __m128d za = _mm_loadu_pd(z + k), zb = _mm_loadu_pd(z + k + 2);
    __m128d d = _mm_sub_pd(xa, h0);
    s0a = _mm_add_pd(s0a, d);
    q0a = _mm_add_pd(q0a, _mm_mul_pd(d, d));
    d = _mm_sub_pd(xb, h0);
    s0b = _mm_add_pd(s0b, d);
    q0b = _mm_add_pd(q0b, _mm_mul_pd(d, d));
    d = _mm_sub_pd(ya, h1);
    s1a = _mm_add_pd(s1a, d);
    q1a = _mm_add_pd(q1a, _mm_mul_pd(d, d));
    d = _mm_sub_pd(yb, h1);
    s1b = _mm_add_pd(s1b, d);
    q1b = _mm_add_pd(q1b, _mm_mul_pd(d, d));
    d = _mm_sub_pd(za, h2);
    s2a = _mm_add_pd(s2a, d);
    q2a = _mm_add_pd(q2a, _mm_mul_pd(d, d));
    d = _mm_sub_pd(zb, h2);
    s2b = _mm_add_pd(s2b, d);
    q2b = _mm_add_pd(q2b, _mm_mul_pd(d, d));
    lo0 = _mm_min_pd(lo0, _mm_min_pd(xa, xb));
    hi0 = _mm_max_pd(hi0, _mm_max_pd(xa, xb));
    lo1 = _mm_min_pd(lo1, _mm_min_pd(ya, yb));
    hi1 = _mm_max_pd(hi1, _mm_max_pd(ya, yb));
    lo2 = _mm_min_pd(lo2, _mm_min_pd(za, zb));
    hi2 = _mm_max_pd(hi2, _mm_max_pd(za, zb));
    na = _mm_add_pd(na, _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(xa, xa), _mm_mul_pd(ya, ya)),
                                               _mm_mul_pd(za, za))));
    nb = _mm_add_pd(nb, _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(xb, xb), _mm_mul_pd(yb, yb)),
                                               _mm_mul_pd(zb, zb))));
    zacc = _mm_or_pd(zacc, _mm_and_pd(_mm_and_pd(_mm_cmpeq_pd(xa, zr), _mm_cmpeq_pd(ya, zr)),
                                      _mm_cmpeq_pd(za, zr)));
    zacc = _mm_or_pd(zacc, _mm_and_pd(_mm_and_pd(_mm_cmpeq_pd(xb, zr), _mm_cmpeq_pd(yb, zr)),
                                      _mm_cmpeq_pd(zb, zr)));
    if (t != nullptr) {
      ta = _mm_add_pd(ta, _mm_loadu_pd(t + k));
      tb = _mm_add_pd(tb, _mm_loadu_pd(t + k + 2));
    }
  }
  _mm_storeu_pd(o.s[0], s0a);
  _mm_storeu_pd(o.s[0] + 2, s0b);
  _mm_storeu_pd(o.s[1], s1a);
  _mm_storeu_pd(o.s[1] + 2, s1b);
  _mm_storeu_pd(o.s[2], s2a);
  _mm_storeu_pd(o.s[2] + 2, s2b);
  _mm_storeu_pd(o.q[0], q0a);
  _mm_storeu_pd(o.q[0] + 2, q0b);
  _mm_storeu_pd(o.q[1], q1a);
  _mm_storeu_pd(o.q[1] + 2, q1b);
  _mm_storeu_pd(o.q[2], q2a);
  _mm_storeu_pd(o.q[2] + 2, q2b);
  _mm_storeu_pd(o.nrm, na);
  _mm_storeu_pd(o.nrm + 2, nb);
  _mm_storeu_pd(o.st, ta);
  _mm_storeu_pd(o.st + 2, tb);
  const __m128d lov[3] = {lo0, lo1, lo2}, hiv[3] = {hi0, hi1, hi2};
  for (int c = 0; c < 3; ++c) {
    double e[2];
    _mm_storeu_pd(e, lov[c]);
    lo[c] = e[0] < e[1] ? e[0] : e[1];
    _mm_storeu_pd(e, hiv[c]);
    hi[c] = e[0] > e[1] ? e[0] : e[1];
  }
  bool zero = _mm_movemask_pd(zacc) != 0;
  stream_tail(col, t, k, m, h, o, lo, hi, zero);
}
#endif

#if defined(GRAVCAL_AVX2)
// the four lanes in one register each
GRAVCAL_TARGET_AVX2 inline void stream_window_avx2(const double* x, const double* y,
                                                   const double* z, const double* t,
                                                   std::size_t m, StreamSums& o) {
  const double* col[3] = {x, y, z};
  const double h[3] = {x[0], y[0], z[0]};
  double lo[3] = {h[0], h[1], h[2]}, hi[3] = {h[0], h[1], h[2]};
  o = StreamSums();
  const __m256d zr = _mm256_setzero_pd();
  const __m256d h0 = _mm256_set1_pd(h[0]), h1 = _mm256_set1_pd(h[1]), h2 = _mm256_set1_pd(h[2]);
  __m256d s0 = zr, s1 = zr, s2 = zr, q0 = zr, q1 = zr, q2 = zr, n = zr, st = zr, zacc = zr;
  __m256d lo0 = h0, lo1 = h1, lo2 = h2, hi0 = h0, hi1 = h1, hi2 = h2;
  std::size_t k = 0;
  for (; k + 4 <= m; k += 4) {
    const __m256d xa = _mm256_loadu_pd(x + k), ya = _mm256_loadu_pd(y + k),
                  za = _mm256_loadu_pd(z + k);
    __m256d d = _mm256_sub_pd(xa, h0);
    s0 = _mm256_add_pd(s0, d);
    q0 = _mm256_add_pd(q0, _mm256_mul_pd(d, d));
    d = _mm256_sub_pd(ya, h1);
    s1 = _mm256_add_pd(s1, d);
    q1 = _mm256_add_pd(q1, _mm256_mul_pd(d, d));
    d = _mm256_sub_pd(za, h2);
    s2 = _mm256_add_pd(s2, d);
    q2 = _mm256_add_pd(q2, _mm256_mul_pd(d, d));
    lo0 = _mm256_min_pd(lo0, xa);
    hi0 = _mm256_max_pd(hi0, xa);
    lo1 = _mm256_min_pd(lo1, ya);
    hi1 = _mm256_max_pd(hi1, ya);
    lo2 = _mm256_min_pd(lo2, za);
    hi2 = _mm256_max_pd(hi2, za);
    n = _mm256_add_pd(n, _mm256_sqrt_pd(_mm256_add_pd(
                             _mm256_add_pd(_mm256_mul_pd(xa, xa), _mm256_mul_pd(ya, ya)),
                             _mm256_mul_pd(za, za))));
    zacc = _mm256_or_pd(zacc, _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(xa, zr, _CMP_EQ_OQ),
                                                          _mm256_cmp_pd(ya, zr, _CMP_EQ_OQ)),
                                            _mm256_cmp_pd(za, zr, _CMP_EQ_OQ)));
    if (t != nullptr) st = _mm256_add_pd(st, _mm256_loadu_pd(t + k));
  }
  _mm256_storeu_pd(o.s[0], s0);
  _mm256_storeu_pd(o.s[1], s1);
  _mm256_storeu_pd(o.s[2], s2);
  _mm256_storeu_pd(o.q[0], q0);
  _mm256_storeu_pd(o.q[1], q1);
  _mm256_storeu_pd(o.q[2], q2);
  _mm256_storeu_pd(o.nrm, n);
  _mm256_storeu_pd(o.st, st);
  const __m256d lov[3] = {lo0, lo1, lo2}, hiv[3] = {hi0, hi1, hi2};
  for (int c = 0; c < 3; ++c) {
    double e[4];
    _mm256_storeu_pd(e, lov[c]);
    for (int l = 0; l < 4; ++l) lo[c] = e[l] < lo[c] ? e[l] : lo[c];
    _mm256_storeu_pd(e, hiv[c]);
    for (int l = 0; l < 4; ++l) hi[c] = e[l] > hi[c] ? e[l] : hi[c];
  }
  bool zero = _mm256_movemask_pd(zacc) != 0;
  stream_tail(col, t, k, m, h, o, lo, hi, zero);
}
#endif

using StreamWindowFn = void (*)(const double*, const double*, const double*, const double*,
                                std::size_t, StreamSums&);
constexpr Variants<StreamWindowFn> stream_window_variants = {
    stream_window, GRAVCAL_IF_SSE2(stream_window_sse2), GRAVCAL_IF_AVX2(stream_window_avx2)};

// ---------------------------------------------------------------------------
// lane_sums(v, n, s): the sums of three columns of n values in four lanes
// by position, added to s (r_scan's reference, and the segmenter's for a
// window taken sample by sample; an AVX2 version saved nothing measurable:
// bench/results/ab-kernels.md).

// Each lane in a local of its own (sums kept in the array would wait on
// their own stores), four samples a step, in the same order.
inline void lane_sums(const double* const* v, std::size_t n, double (*s)[4]) {
  for (int a = 0; a < 3; ++a) {
    const double* x = v[a];
    double l0 = s[a][0], l1 = s[a][1], l2 = s[a][2], l3 = s[a][3];
    std::size_t j = 0;
    for (; j + 4 <= n; j += 4) {
      l0 += x[j];
      l1 += x[j + 1];
      l2 += x[j + 2];
      l3 += x[j + 3];
    }
    s[a][0] = l0;
    s[a][1] = l1;
    s[a][2] = l2;
    s[a][3] = l3;
    for (; j < n; ++j) s[a][j & 3] += x[j];
  }
}


// ---------------------------------------------------------------------------
// r_scan(x, y, z, m, c, want_w, o): a whole window of m >= 1 samples for
// R's arithmetic. c: R's running sums (cumsum()) of x, y, z and the norm
// sqrt(x^2 + y^2 + z^2) (each operation rounded to double, as R), in R's
// accumulator (long double; double in an R without long double: then the
// portable r_scan_scalar<double>() alone, called directly, not through the
// table), continued in sample order. want_w: also the window's own sums of
// x, y, z in that accumulator (the first pass of R's sd). Then min, max,
// whether some sample is all zeros, the columns' sums in four lanes (ls),
// and how many samples equal the one before them in x, y and z
// (count_repeats(), window_stats.hpp; in the vector variants nearly free
// beside the long double sums). With a non-finite sample c is not finite,
// and the rest is not defined.

template <class Acc>
struct RScanOutT {
  double lo[3] = {}, hi[3] = {}, ls[3][4] = {};
  Acc w[3] = {};
  bool zero = false;
  std::int64_t repeats = 0;
};
using RScanOut = RScanOutT<long double>;

// The running sums in scalar accumulators, so that they stay in x87
// registers; with want_w the window's sums ride along.
template <class Acc>
void r_cumsums(const double* x, const double* y, const double* z, std::size_t k,
               std::size_t m, Acc* c, bool want_w, RScanOutT<Acc>& o) {
  Acc c0 = c[0], c1 = c[1], c2 = c[2], c3 = c[3];
  if (want_w) {
    Acc w0 = 0.0, w1 = 0.0, w2 = 0.0;
    for (; k < m; ++k) {
      const double xi = x[k], yi = y[k], zi = z[k];
      c0 += xi;
      c1 += yi;
      c2 += zi;
      w0 += xi;
      w1 += yi;
      w2 += zi;
      const double sq = xi * xi + yi * yi;
      c3 += std::sqrt(sq + zi * zi);
    }
    o.w[0] = w0;
    o.w[1] = w1;
    o.w[2] = w2;
  } else {
    for (; k < m; ++k) {
      const double xi = x[k], yi = y[k], zi = z[k];
      c0 += xi;
      c1 += yi;
      c2 += zi;
      const double sq = xi * xi + yi * yi;
      c3 += std::sqrt(sq + zi * zi);
    }
  }
  c[0] = c0;
  c[1] = c1;
  c[2] = c2;
  c[3] = c3;
}

template <class Acc>
void r_scan_finish(const double* const* col, std::size_t m, double* lo, double* hi, bool zero,
                   RScanOutT<Acc>& o) {
  zero_signs(col, m, lo, hi);
  for (int a = 0; a < 3; ++a) {
    o.lo[a] = lo[a];
    o.hi[a] = hi[a];
  }
  o.zero = zero;
}

template <class Acc>
void r_scan_scalar(const double* x, const double* y, const double* z, std::size_t m, Acc* c,
                   bool want_w, RScanOutT<Acc>& o) {
  const double* col[3] = {x, y, z};
  o = RScanOutT<Acc>();
  r_cumsums(x, y, z, 0, m, c, want_w, o);
  lane_sums(col, m, o.ls);
  double lo[3] = {x[0], y[0], z[0]}, hi[3] = {x[0], y[0], z[0]};
  bool zero = false;
  min_max_tail(col, 0, m, lo, hi, zero);
  r_scan_finish(col, m, lo, hi, zero, o);
  o.repeats = count_repeats(x, y, z, m);
}

#if defined(GRAVCAL_SSE2)
// min, max, the zero test and the lanes two samples at a time: lanes 0 and 1
// in one register, 2 and 3 in another, taken by turns
inline void r_scan_sse2(const double* x, const double* y, const double* z, std::size_t m,
                        long double* c, bool want_w, RScanOut& o) {
  const double* col[3] = {x, y, z};
  o = RScanOut();
  r_cumsums(x, y, z, 0, m, c, want_w, o);
  double lo[3] = {x[0], y[0], z[0]}, hi[3];
  const __m128d zr = _mm_setzero_pd();
  __m128d lo0 = _mm_set1_pd(lo[0]), lo1 = _mm_set1_pd(lo[1]), lo2 = _mm_set1_pd(lo[2]);
  __m128d hi0 = lo0, hi1 = lo1, hi2 = lo2, zacc = zr;
  __m128d s0a = zr, s0b = zr, s1a = zr, s1b = zr, s2a = zr, s2b = zr;
  __m128i rep = _mm_setzero_si128();
  bool odd = false;  // whether lanes 2 and 3 come next
  std::size_t k = 0;
  for (; k + 2 <= m; k += 2) {
    const __m128d a = _mm_loadu_pd(x + k), b = _mm_loadu_pd(y + k), cc = _mm_loadu_pd(z + k);
    if (k > 0) {  // samples k, k + 1 equal to the one before (all-ones lanes: -1)
      const __m128d e = _mm_and_pd(_mm_and_pd(_mm_cmpeq_pd(a, _mm_loadu_pd(x + k - 1)),
                                              _mm_cmpeq_pd(b, _mm_loadu_pd(y + k - 1))),
                                   _mm_cmpeq_pd(cc, _mm_loadu_pd(z + k - 1)));
      rep = _mm_sub_epi64(rep, _mm_castpd_si128(e));
    }
    if (odd) {
      s0b = _mm_add_pd(s0b, a);
      s1b = _mm_add_pd(s1b, b);
      s2b = _mm_add_pd(s2b, cc);
    } else {
      s0a = _mm_add_pd(s0a, a);
      s1a = _mm_add_pd(s1a, b);
      s2a = _mm_add_pd(s2a, cc);
    }
    odd = !odd;
    lo0 = _mm_min_pd(a, lo0);
    lo1 = _mm_min_pd(b, lo1);
    lo2 = _mm_min_pd(cc, lo2);
    hi0 = _mm_max_pd(a, hi0);
    hi1 = _mm_max_pd(b, hi1);
    hi2 = _mm_max_pd(cc, hi2);
    zacc = _mm_or_pd(zacc, _mm_and_pd(_mm_and_pd(_mm_cmpeq_pd(a, zr), _mm_cmpeq_pd(b, zr)),
                                      _mm_cmpeq_pd(cc, zr)));
  }
  const __m128d lov[3] = {lo0, lo1, lo2}, hiv[3] = {hi0, hi1, hi2};
  for (int a = 0; a < 3; ++a) {
    double e[2];
    _mm_storeu_pd(e, lov[a]);
    lo[a] = e[0] < e[1] ? e[0] : e[1];
    _mm_storeu_pd(e, hiv[a]);
    hi[a] = e[0] > e[1] ? e[0] : e[1];
  }
  bool zero = _mm_movemask_pd(zacc) != 0;
  _mm_storeu_pd(o.ls[0], s0a);
  _mm_storeu_pd(o.ls[0] + 2, s0b);
  _mm_storeu_pd(o.ls[1], s1a);
  _mm_storeu_pd(o.ls[1] + 2, s1b);
  _mm_storeu_pd(o.ls[2], s2a);
  _mm_storeu_pd(o.ls[2] + 2, s2b);
  for (std::size_t j = k; j < m; ++j) {
    for (int a = 0; a < 3; ++a) o.ls[a][j & 3] += col[a][j];
  }
  min_max_tail(col, k, m, lo, hi, zero);
  r_scan_finish(col, m, lo, hi, zero, o);
  // the loop counted samples 2..k - 1; the first two and the tail here
  std::int64_t r[2];
  _mm_storeu_si128(reinterpret_cast<__m128i*>(r), rep);
  o.repeats = r[0] + r[1] + count_repeats(x, y, z, m < 2 ? m : 2) +
              count_repeats(x, y, z, m, k > 2 ? k : 2);
}
#endif

#if defined(GRAVCAL_AVX2)
// min, max, the zero test and the lanes four samples at a time. Without
// want_w the running sums ride in the same loop, the four norms of a step by
// one square root instruction (x^2 + y^2, then + z^2, then the root: the
// scalar operations in their order): the long double sums are bound by the
// latency of their additions, which leaves room for the rest of the loop.
template <bool Sums>
GRAVCAL_TARGET_AVX2 inline std::size_t r_scan_loop_avx2(const double* x, const double* y,
                                                        const double* z, std::size_t m,
                                                        long double* c, double* lo, double* hi,
                                                        bool& zero, double (*ls)[4],
                                                        std::int64_t& repeats) {
  const __m256d zr = _mm256_setzero_pd();
  __m256i rep = _mm256_setzero_si256();
  __m256d lo0 = _mm256_set1_pd(lo[0]), lo1 = _mm256_set1_pd(lo[1]), lo2 = _mm256_set1_pd(lo[2]);
  __m256d hi0 = lo0, hi1 = lo1, hi2 = lo2, zacc = zr;
  __m256d s0 = zr, s1 = zr, s2 = zr;
  long double c0 = 0.0L, c1 = 0.0L, c2 = 0.0L, c3 = 0.0L;
  if (Sums) {
    c0 = c[0];
    c1 = c[1];
    c2 = c[2];
    c3 = c[3];
  }
  // unaligned stores to the locals: 64-bit Windows' GCC does not promise
  // a stack aligned to 32 bytes (GCC bug 54412)
  double nrm[4];
  std::size_t k = 0;
  for (; k + 4 <= m; k += 4) {
    const __m256d a = _mm256_loadu_pd(x + k), b = _mm256_loadu_pd(y + k),
                  cc = _mm256_loadu_pd(z + k);
    if (Sums) {
      const __m256d sq = _mm256_add_pd(_mm256_mul_pd(a, a), _mm256_mul_pd(b, b));
      _mm256_storeu_pd(nrm, _mm256_sqrt_pd(_mm256_add_pd(sq, _mm256_mul_pd(cc, cc))));
      for (int j = 0; j < 4; ++j) {
        c0 += x[k + j];
        c1 += y[k + j];
        c2 += z[k + j];
        c3 += nrm[j];
      }
    }
    s0 = _mm256_add_pd(s0, a);
    s1 = _mm256_add_pd(s1, b);
    s2 = _mm256_add_pd(s2, cc);
    lo0 = _mm256_min_pd(a, lo0);
    lo1 = _mm256_min_pd(b, lo1);
    lo2 = _mm256_min_pd(cc, lo2);
    hi0 = _mm256_max_pd(a, hi0);
    hi1 = _mm256_max_pd(b, hi1);
    hi2 = _mm256_max_pd(cc, hi2);
    zacc = _mm256_or_pd(zacc, _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(a, zr, _CMP_EQ_OQ),
                                                          _mm256_cmp_pd(b, zr, _CMP_EQ_OQ)),
                                            _mm256_cmp_pd(cc, zr, _CMP_EQ_OQ)));
    if (k > 0) {  // samples k..k + 3 equal to the one before (all-ones lanes: -1)
      const __m256d e = _mm256_and_pd(
          _mm256_and_pd(_mm256_cmp_pd(a, _mm256_loadu_pd(x + k - 1), _CMP_EQ_OQ),
                        _mm256_cmp_pd(b, _mm256_loadu_pd(y + k - 1), _CMP_EQ_OQ)),
          _mm256_cmp_pd(cc, _mm256_loadu_pd(z + k - 1), _CMP_EQ_OQ));
      rep = _mm256_sub_epi64(rep, _mm256_castpd_si256(e));
    }
  }
  {
    std::int64_t r[4];
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(r), rep);
    repeats = (r[0] + r[1]) + (r[2] + r[3]);
  }
  if (Sums) {
    c[0] = c0;
    c[1] = c1;
    c[2] = c2;
    c[3] = c3;
  }
  const __m256d lov[3] = {lo0, lo1, lo2}, hiv[3] = {hi0, hi1, hi2};
  for (int a = 0; a < 3; ++a) {
    double e[4];
    _mm256_storeu_pd(e, lov[a]);
    for (int l = 0; l < 4; ++l) lo[a] = e[l] < lo[a] ? e[l] : lo[a];
    _mm256_storeu_pd(e, hiv[a]);
    for (int l = 0; l < 4; ++l) hi[a] = e[l] > hi[a] ? e[l] : hi[a];
  }
  zero = _mm256_movemask_pd(zacc) != 0;
  _mm256_storeu_pd(ls[0], s0);
  _mm256_storeu_pd(ls[1], s1);
  _mm256_storeu_pd(ls[2], s2);
  return k;
}

GRAVCAL_TARGET_AVX2 inline void r_scan_avx2(const double* x, const double* y, const double* z,
                                            std::size_t m, long double* c, bool want_w,
                                            RScanOut& o) {
  const double* col[3] = {x, y, z};
  o = RScanOut();
  double lo[3] = {x[0], y[0], z[0]}, hi[3] = {x[0], y[0], z[0]};
  bool zero = false;
  std::size_t k;
  std::int64_t rep = 0;
  if (want_w) {
    r_cumsums(x, y, z, 0, m, c, true, o);
    k = r_scan_loop_avx2<false>(x, y, z, m, c, lo, hi, zero, o.ls, rep);
  } else {
    k = r_scan_loop_avx2<true>(x, y, z, m, c, lo, hi, zero, o.ls, rep);
    r_cumsums(x, y, z, k, m, c, false, o);
  }
  // the loop counted samples 4..k - 1; the first four and the tail here
  o.repeats = rep + count_repeats(x, y, z, m < 4 ? m : 4) + count_repeats(x, y, z, m, k > 4 ? k : 4);
  for (std::size_t j = k; j < m; ++j) {
    for (int a = 0; a < 3; ++a) o.ls[a][j & 3] += col[a][j];
  }
  min_max_tail(col, k, m, lo, hi, zero);
  r_scan_finish(col, m, lo, hi, zero, o);
}
#endif

using RScanFn = void (*)(const double*, const double*, const double*, std::size_t,
                         long double*, bool, RScanOut&);
constexpr Variants<RScanFn> r_scan_variants = {r_scan_scalar<long double>,
                                               GRAVCAL_IF_SSE2(r_scan_sse2),
                                               GRAVCAL_IF_AVX2(r_scan_avx2)};

// ---------------------------------------------------------------------------
// first_zero(x, y, z, n): where the first sample with x = y = z = 0 (an
// idle-sleep sample) is among n; n if none.

inline std::size_t first_zero_scalar(const double* x, const double* y, const double* z,
                                     std::size_t n) {
  std::size_t i = 0;
  while (i < n && !all_zero(x[i], y[i], z[i])) ++i;
  return i;
}

#if defined(GRAVCAL_SSE2)
inline std::size_t first_zero_sse2(const double* x, const double* y, const double* z,
                                   std::size_t n) {
  std::size_t i = 0;
  const __m128d zr = _mm_setzero_pd();
  for (; i + 8 <= n; i += 8) {
    __m128d any = zr;
    for (std::size_t k = i; k < i + 8; k += 2) {
      any = _mm_or_pd(any, _mm_and_pd(_mm_and_pd(_mm_cmpeq_pd(_mm_loadu_pd(x + k), zr),
                                                 _mm_cmpeq_pd(_mm_loadu_pd(y + k), zr)),
                                      _mm_cmpeq_pd(_mm_loadu_pd(z + k), zr)));
    }
    if (_mm_movemask_pd(any) != 0) break;
  }
  while (i < n && !all_zero(x[i], y[i], z[i])) ++i;
  return i;
}
#endif

#if defined(GRAVCAL_AVX2)
// Whether one of the eight samples at i is all zeros.
GRAVCAL_TARGET_AVX2 inline bool zero_in8_avx2(const double* x, const double* y, const double* z,
                                              std::size_t i) {
  const __m256d zr = _mm256_setzero_pd();
  const __m256d a = _mm256_and_pd(
      _mm256_and_pd(_mm256_cmp_pd(_mm256_loadu_pd(x + i), zr, _CMP_EQ_OQ),
                    _mm256_cmp_pd(_mm256_loadu_pd(y + i), zr, _CMP_EQ_OQ)),
      _mm256_cmp_pd(_mm256_loadu_pd(z + i), zr, _CMP_EQ_OQ));
  const __m256d b = _mm256_and_pd(
      _mm256_and_pd(_mm256_cmp_pd(_mm256_loadu_pd(x + i + 4), zr, _CMP_EQ_OQ),
                    _mm256_cmp_pd(_mm256_loadu_pd(y + i + 4), zr, _CMP_EQ_OQ)),
      _mm256_cmp_pd(_mm256_loadu_pd(z + i + 4), zr, _CMP_EQ_OQ));
  return _mm256_movemask_pd(_mm256_or_pd(a, b)) != 0;
}

// Where to go on from: a multiple of 8 before the first idle-sleep sample,
// or less than 8 from the end. Sixteen samples' x first: only where some x
// is 0 can a sample be all zeros, and then their eights are checked whole.
GRAVCAL_TARGET_AVX2 inline std::size_t zero_scan_avx2(const double* x, const double* y,
                                                      const double* z, std::size_t n) {
  std::size_t i = 0;
  const __m256d zr = _mm256_setzero_pd();
  for (; i + 16 <= n; i += 16) {
    const __m256d a = _mm256_or_pd(_mm256_cmp_pd(_mm256_loadu_pd(x + i), zr, _CMP_EQ_OQ),
                                   _mm256_cmp_pd(_mm256_loadu_pd(x + i + 4), zr, _CMP_EQ_OQ));
    const __m256d b = _mm256_or_pd(_mm256_cmp_pd(_mm256_loadu_pd(x + i + 8), zr, _CMP_EQ_OQ),
                                   _mm256_cmp_pd(_mm256_loadu_pd(x + i + 12), zr, _CMP_EQ_OQ));
    if (_mm256_movemask_pd(_mm256_or_pd(a, b)) == 0) continue;
    if (zero_in8_avx2(x, y, z, i)) return i;
    if (zero_in8_avx2(x, y, z, i + 8)) return i + 8;
  }
  for (; i + 8 <= n; i += 8) {
    if (zero_in8_avx2(x, y, z, i)) break;
  }
  return i;
}

GRAVCAL_TARGET_AVX2 inline std::size_t first_zero_avx2(const double* x, const double* y,
                                                       const double* z, std::size_t n) {
  std::size_t i = zero_scan_avx2(x, y, z, n);
  while (i < n && !all_zero(x[i], y[i], z[i])) ++i;
  return i;
}
#endif

using FirstZeroFn = std::size_t (*)(const double*, const double*, const double*, std::size_t);
constexpr Variants<FirstZeroFn> first_zero_variants = {
    first_zero_scalar, GRAVCAL_IF_SSE2(first_zero_sse2), GRAVCAL_IF_AVX2(first_zero_avx2)};

// ---------------------------------------------------------------------------
// order_next(w, n, v, down, &val, &count): over the n values of a running
// median's window (ggir_epochs.hpp rolling_median_range(); no NaN, in any
// order), the largest value below v (down) or the smallest above it (not
// down), and how many of the values equal it: the median's next value when
// it moves down or up. Where no value is below (above) v, val is -Inf
// (+Inf) and count how many values are that infinity. A zero is returned as
// +0 in every variant (the median finds a zero's sign itself, in time
// order); counts are exact, so every variant gives the reference's bits.

inline void order_next_scalar(const double* w, std::size_t n, double v, bool down, double* val,
                              std::size_t* count) {
  double best = down ? -HUGE_VAL : HUGE_VAL;
  std::size_t c = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const double x = w[j];
    if (down ? x < v : x > v) {
      if (down ? x > best : x < best) {
        best = x;
        c = 1;
      } else if (x == best) {
        ++c;
      }
    }
  }
  *val = best == 0 ? 0.0 : best;
  *count = c;
}

#if defined(GRAVCAL_SSE2)
// Up is down on the values negated (the sign bit flipped: exact): x > v is
// -x < -v, and the smallest x above v is minus the largest -x below -v.
// Each lane keeps its largest value below and its count; the lanes are
// joined after (the largest, and the counts of the lanes that hold it).
inline void order_next_join(const double* b, const std::int64_t* c, int lanes, const double* w,
                            std::size_t j, std::size_t n, double v, bool down, double* val,
                            std::size_t* count) {
  double g = b[0];
  for (int l = 1; l < lanes; ++l) g = b[l] > g ? b[l] : g;
  std::size_t tot = 0;
  for (int l = 0; l < lanes; ++l) tot += b[l] == g ? static_cast<std::size_t>(c[l]) : 0;
  const double vs = down ? v : -v;
  for (; j < n; ++j) {  // the rest
    const double x = down ? w[j] : -w[j];
    if (x < vs) {
      if (x > g) {
        g = x;
        tot = 1;
      } else if (x == g) {
        ++tot;
      }
    }
  }
  const double r = down ? g : -g;
  *val = r == 0 ? 0.0 : r;
  *count = tot;
}

inline void order_next_sse2(const double* w, std::size_t n, double v, bool down, double* val,
                            std::size_t* count) {
  const __m128d sg = _mm_set1_pd(down ? 0.0 : -0.0);
  const __m128d vs = _mm_xor_pd(_mm_set1_pd(v), sg);
  const __m128i one = _mm_set1_epi64x(1);
  __m128d best = _mm_set1_pd(-HUGE_VAL);
  __m128i c = _mm_setzero_si128();
  std::size_t j = 0;
  for (; j + 2 <= n; j += 2) {
    const __m128d x = _mm_xor_pd(_mm_loadu_pd(w + j), sg);
    const __m128d in = _mm_cmplt_pd(x, vs);
    const __m128d gt = _mm_and_pd(in, _mm_cmpgt_pd(x, best));
    const __m128d eq = _mm_and_pd(in, _mm_cmpeq_pd(x, best));
    best = _mm_or_pd(_mm_and_pd(gt, x), _mm_andnot_pd(gt, best));
    const __m128i gi = _mm_castpd_si128(gt);
    c = _mm_sub_epi64(c, _mm_castpd_si128(eq));  // a true lane is -1
    c = _mm_or_si128(_mm_and_si128(gi, one), _mm_andnot_si128(gi, c));
  }
  double b[2];
  std::int64_t cl[2];
  _mm_storeu_pd(b, best);
  _mm_storeu_si128(reinterpret_cast<__m128i*>(cl), c);
  order_next_join(b, cl, 2, w, j, n, v, down, val, count);
}
#endif

#if defined(GRAVCAL_AVX2)
GRAVCAL_TARGET_AVX2 inline void order_next_avx2(const double* w, std::size_t n, double v, bool down,
                                                double* val, std::size_t* count) {
  const __m256d sg = _mm256_set1_pd(down ? 0.0 : -0.0);
  const __m256d vs = _mm256_xor_pd(_mm256_set1_pd(v), sg);
  const __m256i one = _mm256_set1_epi64x(1);
  __m256d best = _mm256_set1_pd(-HUGE_VAL);
  __m256i c = _mm256_setzero_si256();
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) {
    const __m256d x = _mm256_xor_pd(_mm256_loadu_pd(w + j), sg);
    const __m256d in = _mm256_cmp_pd(x, vs, _CMP_LT_OQ);
    const __m256d gt = _mm256_and_pd(in, _mm256_cmp_pd(x, best, _CMP_GT_OQ));
    const __m256d eq = _mm256_and_pd(in, _mm256_cmp_pd(x, best, _CMP_EQ_OQ));
    best = _mm256_blendv_pd(best, x, gt);
    c = _mm256_sub_epi64(c, _mm256_castpd_si256(eq));  // a true lane is -1
    c = _mm256_blendv_epi8(c, one, _mm256_castpd_si256(gt));
  }
  double b[4];
  std::int64_t cl[4];
  _mm256_storeu_pd(b, best);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(cl), c);
  order_next_join(b, cl, 4, w, j, n, v, down, val, count);
}
#endif

using OrderNextFn = void (*)(const double*, std::size_t, double, bool, double*, std::size_t*);
constexpr Variants<OrderNextFn> order_next_variants = {
    order_next_scalar, GRAVCAL_IF_SSE2(order_next_sse2), GRAVCAL_IF_AVX2(order_next_avx2)};

}  // namespace kernels
}  // namespace gravcal

#endif  // GRAVCAL_KERNELS_WINDOW_HPP
