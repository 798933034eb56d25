// gravcal kernels: the loops of the device decoders (decode_cwa.hpp,
// decode_geneactiv.hpp).
//
// As in kernels/window.hpp: a scalar reference per kernel and, beside it,
// the vector code standing in for it with the same signature and the same
// results to the bit; the kernel table (kernels.hpp) chooses once.
//
// Header-only, standard headers only (and the intrinsics headers on x86).
#ifndef GRAVCAL_KERNELS_DECODE_HPP
#define GRAVCAL_KERNELS_DECODE_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "gravcal/kernels/ggir_grid.hpp"
#include "gravcal/kernels/simd.hpp"

namespace gravcal {
namespace kernels {

// ---------------------------------------------------------------------------
// word_sum(b, n): the sum of n / 2 little-endian 16-bit words, modulo 2^16
// (n a multiple of 32; the .cwa block checksum).

inline unsigned word_sum_scalar(const unsigned char* b, std::size_t n) {
  unsigned sum = 0;
  for (std::size_t i = 0; i < n; i += 2) sum += static_cast<unsigned>(b[i] | (b[i + 1] << 8));
  return sum & 0xffffu;
}

#if defined(GRAVCAL_SSE2) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define GRAVCAL_WORD_SUM_SSE2 1
// eight lanes of 16 bits: the sum wraps the same way
inline unsigned word_sum_sse2(const unsigned char* b, std::size_t n) {
  __m128i a = _mm_setzero_si128(), c = a;
  for (std::size_t i = 0; i + 32 <= n; i += 32) {
    a = _mm_add_epi16(a, _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i)));
    c = _mm_add_epi16(c, _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i + 16)));
  }
  alignas(16) std::uint16_t w[8];
  _mm_store_si128(reinterpret_cast<__m128i*>(w), _mm_add_epi16(a, c));
  unsigned sum = 0;
  for (int l = 0; l < 8; ++l) sum += w[l];
  return sum & 0xffffu;
}
#endif

using WordSumFn = unsigned (*)(const unsigned char*, std::size_t);
#if defined(GRAVCAL_WORD_SUM_SSE2)
constexpr Variants<WordSumFn> word_sum_variants = {word_sum_scalar, word_sum_sse2, nullptr};
#else
constexpr Variants<WordSumFn> word_sum_variants = {word_sum_scalar, nullptr, nullptr};
#endif

// ---------------------------------------------------------------------------
// scale_packed(d, scale, n, x, y, z): n packed .cwa samples at d (32-bit
// little-endian words: 10-bit signed x, y, z, and a 2-bit exponent e) in g:
// signed10 times 2^e scale (scale a power of two, so that 8 scale is an exact
// double).

inline int signed10(std::uint32_t v) { return static_cast<int>((v & 0x3ffu) ^ 0x200u) - 0x200; }

inline void scale_packed_tail(const unsigned char* d, double scale, int i, int n, double* x,
                              double* y, double* z) {
  const double f[4] = {scale, 2 * scale, 4 * scale, 8 * scale};
  for (; i < n; ++i) {
    const unsigned char* p = d + 4 * i;
    const std::uint32_t v = static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
                            (static_cast<std::uint32_t>(p[2]) << 16) |
                            (static_cast<std::uint32_t>(p[3]) << 24);
    const double m = f[v >> 30];
    x[i] = signed10(v) * m;
    y[i] = signed10(v >> 10) * m;
    z[i] = signed10(v >> 20) * m;
  }
}

inline void scale_packed_scalar(const unsigned char* d, double scale, int n, double* x,
                                double* y, double* z) {
  scale_packed_tail(d, scale, 0, n, x, y, z);
}

#if defined(GRAVCAL_SSE2)
// four at a time: the same integer and the same product per value
inline void scale_packed_sse2(const unsigned char* d, double scale, int n, double* x, double* y,
                              double* z) {
  const double f[4] = {scale, 2 * scale, 4 * scale, 8 * scale};
  const __m128i m10 = _mm_set1_epi32(0x3ff), sign = _mm_set1_epi32(0x200);
  int i = 0;
  for (; i + 4 <= n; i += 4) {
    const __m128i w = _mm_loadu_si128(reinterpret_cast<const __m128i*>(d + 4 * i));
    alignas(16) std::int32_t e[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(e), _mm_srli_epi32(w, 30));
    const __m128d m01 = _mm_set_pd(f[e[1]], f[e[0]]), m23 = _mm_set_pd(f[e[3]], f[e[2]]);
    double* col[3] = {x + i, y + i, z + i};
    for (int a = 0; a < 3; ++a) {
      // signed10(v >> 10 a), four at a time
      const __m128i u = a == 0 ? w : _mm_srli_epi32(w, 10 * a);
      const __m128i v = _mm_sub_epi32(_mm_xor_si128(_mm_and_si128(u, m10), sign), sign);
      _mm_storeu_pd(col[a], _mm_mul_pd(_mm_cvtepi32_pd(v), m01));
      _mm_storeu_pd(col[a] + 2, _mm_mul_pd(_mm_cvtepi32_pd(_mm_shuffle_epi32(v, 0xee)), m23));
    }
  }
  scale_packed_tail(d, scale, i, n, x, y, z);
}
#endif

#if defined(GRAVCAL_AVX2)
// eight at a time: signed10(v) << e, an exact integer, times scale is
// signed10(v) times 2^e scale (both one rounding of the same exact value)
GRAVCAL_TARGET_AVX2 inline void scale_packed_avx2(const unsigned char* d, double scale, int n,
                                                  double* x, double* y, double* z) {
  const __m256i m10 = _mm256_set1_epi32(0x3ff), sign = _mm256_set1_epi32(0x200);
  const __m256d ps = _mm256_set1_pd(scale);
  int i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256i w = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(d + 4 * i));
    const __m256i e = _mm256_srli_epi32(w, 30);
    // the three axes written out (an array of the column pointers ends up
    // on the stack)
#define GRAVCAL_CWA_AXIS(U, OUT)                                                                 \
  {                                                                                              \
    const __m256i v = _mm256_sllv_epi32(                                                         \
        _mm256_sub_epi32(_mm256_xor_si256(_mm256_and_si256(U, m10), sign), sign), e);            \
    _mm256_storeu_pd(OUT, _mm256_mul_pd(_mm256_cvtepi32_pd(_mm256_castsi256_si128(v)), ps));      \
    _mm256_storeu_pd(OUT + 4,                                                                    \
                     _mm256_mul_pd(_mm256_cvtepi32_pd(_mm256_extracti128_si256(v, 1)), ps));      \
  }
    GRAVCAL_CWA_AXIS(w, x + i)
    GRAVCAL_CWA_AXIS(_mm256_srli_epi32(w, 10), y + i)
    GRAVCAL_CWA_AXIS(_mm256_srli_epi32(w, 20), z + i)
#undef GRAVCAL_CWA_AXIS
  }
  scale_packed_tail(d, scale, i, n, x, y, z);
}
#endif

using ScalePackedFn = void (*)(const unsigned char*, double, int, double*, double*, double*);
constexpr Variants<ScalePackedFn> scale_packed_variants = {
    scale_packed_scalar, GRAVCAL_IF_SSE2(scale_packed_sse2), GRAVCAL_IF_AVX2(scale_packed_avx2)};

// ---------------------------------------------------------------------------
// span_times(dst, len, start, spacing): dst[i + 1] = start + i spacing for
// i = 1 .. len - 1 (readAxivity's sample times of a block, as R's seq():
// the product rounded, then the sum, never fused).

inline void span_times_scalar(double* dst, int len, double start, double spacing) {
  for (int i = 1; i < len; ++i) {
    volatile double elapsed = i * spacing;  // rounded before the addition
    dst[i + 1] = start + elapsed;
  }
}

#if defined(GRAVCAL_AVX2)
GRAVCAL_TARGET_AVX2 inline void span_times_avx2(double* dst, int len, double start,
                                                double spacing) {
  const __m256d st = _mm256_set1_pd(start), sp = _mm256_set1_pd(spacing);
  const __m256d step = _mm256_setr_pd(0, 1, 2, 3);
  int i = 1;
  for (; i + 4 <= len; i += 4) {
    const __m256d iv = _mm256_add_pd(_mm256_set1_pd(static_cast<double>(i)), step);
    _mm256_storeu_pd(dst + i + 1, _mm256_add_pd(st, _mm256_mul_pd(iv, sp)));
  }
  for (; i < len; ++i) {
    const __m128d e = _mm_mul_sd(_mm_set_sd(static_cast<double>(i)), _mm_set_sd(spacing));
    _mm_store_sd(dst + i + 1, _mm_add_sd(_mm_set_sd(start), e));
  }
}
#endif

using SpanTimesFn = void (*)(double*, int, double, double);
constexpr Variants<SpanTimesFn> span_times_variants = {span_times_scalar, nullptr,
                                                       GRAVCAL_IF_AVX2(span_times_avx2)};

// ---------------------------------------------------------------------------
// cwa_interp(s, pos, end_pos, source, o, a, at): GGIRread's linear
// interpolation of a block's samples onto the regular grid (a span that is
// not imputed). Grid point p lies at t = min(start + p step, end) (the
// product rounded, then the sum); points pos, pos + 1, ... before end_pos
// with t <= lim are written to o (offset 0 for pos), each from the interval
// (time[k - 1], time[k]] holding it, found by a search going on from
// `source`: w = (t - time[k - 1]) / (time[k] - time[k - 1]), then w (v[k] -
// v[k - 1]) + v[k - 1] per axis. Returns how many were written; source
// follows, and a (the last point's values) and at (its time) are set when
// any was. With s.nearest (interpolationType = 2), w becomes
// ggir_nearest_weight(w): the scalar reference only (the caller chooses it).
// With s.fused, w (v[k] - v[k - 1]) + v[k - 1] is one fused multiply-add
// (std::fma: rounded once), as GGIRread's own resample() computes it where
// R's compiler contracted it (GCC's default on aarch64; ggir_resample_fused
// in R/fp-build.R finds out): the scalar reference only, too.

struct InterpSpan {
  const double* time = nullptr;  // time[0] the point the span starts from, time[1..len] its samples'
  const double* v[3] = {nullptr, nullptr, nullptr};  // values likewise
  int len = 0;
  double lim = 0;  // time[len]
  double start = 0, step = 0, end = 0;
  double temp = 0;  // written to o.t when not null
  bool nearest = false;  // ggir_nearest_weight() on w (the scalar reference only)
  bool fused = false;    // std::fma for the value (the scalar reference only)
};

struct InterpOut {
  double* x = nullptr;
  double* y = nullptr;
  double* z = nullptr;
  double* t = nullptr;     // may be null
  double* time = nullptr;  // may be null
};

// The state in locals (the output columns could alias a and at, so the
// compiler would store and reload them every point), written back once.
inline std::int64_t cwa_interp_scalar(const InterpSpan& s, std::int64_t pos, std::int64_t end_pos,
                                      int& source, const InterpOut& o, double* a, double& at) {
  const double* T = s.time;
  const double* X = s.v[0];
  const double* Y = s.v[1];
  const double* Z = s.v[2];
  const double lim = s.lim, temp = s.temp;
  // the grid, weight and interpolation rules of the one grid walk
  // (ggir_grid.hpp); its stepping, GridWalk::through(), is not used: this
  // loop searches the interval afresh for every point, the reference its
  // AVX2 twin follows lane by lane and calls one point at a time. Its
  // interpolation rule is the span itself (s.nearest, s.fused, read where
  // they are, as this loop always read them: the same machine code)
  const GridWalk<CappedGrid, UnclampedWeight, const InterpSpan&> walk{{s.start, s.step, s.end}, s};
  double* const ox = o.x;
  double* const oy = o.y;
  double* const oz = o.z;
  double* const ot = o.t;
  double* const otime = o.time;
  double a0 = a[0], a1 = a[1], a2 = a[2], last = at;
  int src = source;
  std::int64_t k = 0;
  for (; pos + k < end_pos; ++k) {
    const double t = walk.grid.at(pos + k);
    if (!(t <= lim)) break;
    while (src < s.len && T[src] < t) ++src;
    const double w = walk.weight(t, T[src - 1], T[src]);
    a0 = walk.value(w, X[src - 1], X[src]);
    a1 = walk.value(w, Y[src - 1], Y[src]);
    a2 = walk.value(w, Z[src - 1], Z[src]);
    ox[k] = a0;
    oy[k] = a1;
    oz[k] = a2;
    if (ot != nullptr) ot[k] = temp;
    if (otime != nullptr) otime[k] = t;
    last = t;
  }
  source = src;
  a[0] = a0;
  a[1] = a1;
  a[2] = a2;
  at = last;
  return k;
}

#if defined(GRAVCAL_AVX2)
// Four points at a time while they lie in consecutive intervals (the usual
// case: grid and samples at the same rate): their times as the scalar
// loop's, the intervals as its search, the weights and values with its
// operations, four lanes at a time. Stops, with nothing of the four
// written, at four of which any is otherwise (past the span's end, in the
// same or a skipped interval); returns how many it wrote (a multiple of 4).
GRAVCAL_TARGET_AVX2 inline std::int64_t cwa_interp4_avx2(const InterpSpan& sp, std::int64_t pos,
                                                         std::int64_t end_pos, int& source,
                                                         const InterpOut& o, double* a,
                                                         double& at) {
  const __m256d start = _mm256_set1_pd(sp.start), step = _mm256_set1_pd(sp.step),
                end = _mm256_set1_pd(sp.end), limit = _mm256_set1_pd(sp.lim),
                lanes = _mm256_setr_pd(0, 1, 2, 3), tv = _mm256_set1_pd(sp.temp);
  const double* T = sp.time;
  const int len = sp.len;
  const std::int64_t pos0 = pos;
  int s = source;
  const double* X = sp.v[0];
  const double* Y = sp.v[1];
  const double* Z = sp.v[2];
  __m256d lx = _mm256_setzero_pd(), ly = lx, lz = lx, t = lx;
  for (; pos + 4 <= end_pos; pos += 4) {
    const __m256d pv = _mm256_add_pd(_mm256_set1_pd(static_cast<double>(pos)), lanes);
    __m256d u = _mm256_add_pd(start, _mm256_mul_pd(pv, step));
    u = _mm256_min_pd(u, end);  // u < end ? u : end
    if (_mm256_movemask_pd(_mm256_cmp_pd(u, limit, _CMP_LE_OQ)) != 0xf) break;
    // point j in (T[k + j - 1], T[k + j]]. Usually the search from s moves
    // exactly one on (k = s + 1): T[s] < u0 <= T[s + 1], which is lane 0 of
    // the checks below, so the guess is taken when all eight hold;
    // otherwise the search runs as the scalar loop's
    int k = s + 1;
    __m256d T1, T0;
    bool fits = k + 3 <= len;
    if (fits) {
      T1 = _mm256_loadu_pd(T + k);
      T0 = _mm256_loadu_pd(T + k - 1);
      fits = _mm256_movemask_pd(_mm256_cmp_pd(T1, u, _CMP_LT_OQ)) == 0 &&
             _mm256_movemask_pd(_mm256_cmp_pd(T0, u, _CMP_LT_OQ)) == 0xf;
    }
    if (!fits) {
      const double u0 = _mm256_cvtsd_f64(u);
      k = s;
      while (k < len && T[k] < u0) ++k;
      if (k + 3 > len) break;
      // and then each of the next three moves exactly one on
      T1 = _mm256_loadu_pd(T + k);
      T0 = _mm256_loadu_pd(T + k - 1);
      if (_mm256_movemask_pd(_mm256_cmp_pd(T1, u, _CMP_LT_OQ)) != 0) break;
      if ((_mm256_movemask_pd(_mm256_cmp_pd(T0, u, _CMP_LT_OQ)) & 0xe) != 0xe) break;
    }
    const __m256d w = _mm256_div_pd(_mm256_sub_pd(u, T0), _mm256_sub_pd(T1, T0));
    const std::int64_t at_o = pos - pos0;
    __m256d L = _mm256_loadu_pd(X + k - 1), R = _mm256_loadu_pd(X + k);
    lx = _mm256_add_pd(_mm256_mul_pd(w, _mm256_sub_pd(R, L)), L);
    _mm256_storeu_pd(o.x + at_o, lx);
    L = _mm256_loadu_pd(Y + k - 1);
    R = _mm256_loadu_pd(Y + k);
    ly = _mm256_add_pd(_mm256_mul_pd(w, _mm256_sub_pd(R, L)), L);
    _mm256_storeu_pd(o.y + at_o, ly);
    L = _mm256_loadu_pd(Z + k - 1);
    R = _mm256_loadu_pd(Z + k);
    lz = _mm256_add_pd(_mm256_mul_pd(w, _mm256_sub_pd(R, L)), L);
    _mm256_storeu_pd(o.z + at_o, lz);
    if (o.t != nullptr) _mm256_storeu_pd(o.t + at_o, tv);
    if (o.time != nullptr) _mm256_storeu_pd(o.time + at_o, u);
    s = k + 3;
    t = u;
  }
  if (pos > pos0) {
    double e[4];
    _mm256_storeu_pd(e, lx);
    a[0] = e[3];
    _mm256_storeu_pd(e, ly);
    a[1] = e[3];
    _mm256_storeu_pd(e, lz);
    a[2] = e[3];
    _mm256_storeu_pd(e, t);
    at = e[3];
    source = s;
  }
  return pos - pos0;
}

// four at a time where they fit, one point the scalar way where not
GRAVCAL_TARGET_AVX2 inline std::int64_t cwa_interp_avx2(const InterpSpan& s, std::int64_t pos,
                                                        std::int64_t end_pos, int& source,
                                                        const InterpOut& o, double* a,
                                                        double& at) {
  std::int64_t done = 0;
  while (pos + done < end_pos) {
    InterpOut oo = o;
    oo.x += done;
    oo.y += done;
    oo.z += done;
    if (oo.t != nullptr) oo.t += done;
    if (oo.time != nullptr) oo.time += done;
    if (end_pos - (pos + done) >= 4) {
      const std::int64_t k = cwa_interp4_avx2(s, pos + done, end_pos, source, oo, a, at);
      if (k > 0) {
        done += k;
        continue;
      }
    }
    if (cwa_interp_scalar(s, pos + done, pos + done + 1, source, oo, a, at) == 0) break;
    ++done;
  }
  return done;
}
#endif

using CwaInterpFn = std::int64_t (*)(const InterpSpan&, std::int64_t, std::int64_t, int&,
                                     const InterpOut&, double*, double&);
constexpr Variants<CwaInterpFn> cwa_interp_variants = {cwa_interp_scalar, nullptr,
                                                       GRAVCAL_IF_AVX2(cwa_interp_avx2)};

// ---------------------------------------------------------------------------
// hex_counts(s, k, readable, raw, rows): GENEActiv's counts x, y, z of k
// samples of 12 hex digits each at s (digits 0-2, 3-5 and 6-8 of a sample;
// 9-11 are only checked) into raw[i][0..2]. Returns 0x10 when some of the
// k samples' 12 digits is not a hex digit (the counts are then not
// defined), else 0. readable: bytes that may be read at s (at least 12 k);
// rows: rows of raw (at least k).

// Hex digit values; 0x10 marks a byte that is not a hex digit.
struct HexTable {
  unsigned char v[256];
  HexTable() {
    for (int i = 0; i < 256; ++i) v[i] = 0x10;
    for (int i = 0; i < 10; ++i) v['0' + i] = static_cast<unsigned char>(i);
    for (int i = 0; i < 6; ++i) {
      v['A' + i] = static_cast<unsigned char>(10 + i);
      v['a' + i] = static_cast<unsigned char>(10 + i);
    }
  }
};
inline const HexTable& hex_table() {
  static const HexTable t;
  return t;
}

inline unsigned hex_counts_tail(const unsigned char* s, std::size_t i, std::size_t k,
                                std::uint16_t (*raw)[3]) {
  const unsigned char* h = hex_table().v;
  unsigned bad = 0;
  for (; i < k; ++i) {
    const unsigned char* p = s + 12 * i;
    for (int a = 0; a < 3; ++a) {
      const unsigned d0 = h[p[3 * a]], d1 = h[p[3 * a + 1]], d2 = h[p[3 * a + 2]];
      bad |= d0 | d1 | d2;
      raw[i][a] = static_cast<std::uint16_t>((d0 << 8) | (d1 << 4) | d2);
    }
    bad |= h[p[9]] | h[p[10]] | h[p[11]];
  }
  return bad & 0x10u;
}

inline unsigned hex_counts_scalar(const unsigned char* s, std::size_t k, std::size_t,
                                  std::uint16_t (*raw)[3], std::size_t) {
  return hex_counts_tail(s, 0, k, raw);
}

#if defined(GRAVCAL_SSE2)
// hex_table() for 16 bytes at once: their values into v (any value for a
// byte that is not a hex digit) and a mask, bit k set when byte k is not a
// hex digit. Signed byte comparisons: bytes from 0x80 on are below '0'.
inline int hex16(const unsigned char* s, unsigned char* v) {
  const __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i*>(s));
  const __m128i dg = _mm_and_si128(_mm_cmpgt_epi8(c, _mm_set1_epi8('0' - 1)),
                                   _mm_cmpgt_epi8(_mm_set1_epi8('9' + 1), c));
  const __m128i up = _mm_and_si128(_mm_cmpgt_epi8(c, _mm_set1_epi8('A' - 1)),
                                   _mm_cmpgt_epi8(_mm_set1_epi8('F' + 1), c));
  const __m128i lo = _mm_and_si128(_mm_cmpgt_epi8(c, _mm_set1_epi8('a' - 1)),
                                   _mm_cmpgt_epi8(_mm_set1_epi8('f' + 1), c));
  // '0'-'9': c - '0'; 'A'-'F': c - '0' - 7; 'a'-'f': c - '0' - 39
  const __m128i val = _mm_sub_epi8(
      _mm_sub_epi8(_mm_sub_epi8(c, _mm_set1_epi8('0')), _mm_and_si128(up, _mm_set1_epi8(7))),
      _mm_and_si128(lo, _mm_set1_epi8(39)));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(v), val);
  return _mm_movemask_epi8(_mm_or_si128(_mm_or_si128(dg, up), lo)) ^ 0xffff;
}

// Four samples (48 digits) at a time: the digits' values and whether each
// is a hex digit sixteen at a time (hex16()); then digit pairs p_j = d_2j
// d_2j+1 in 16-bit lanes, so that a sample's counts (digits 0-2, 3-5, 6-8
// of its 12, pairs p_0..p_5 from its first) are x = p_0 p_1 >> 4, y = (p_1
// & 15) p_2 and z = p_3 p_4 >> 4: lanes 0 and 3 of q_j = p_j << 4 | p_j+1
// >> 4 and lane 1 of r_j = (p_j & 15) << 8 | p_j+1.
inline unsigned hex_counts_sse2(const unsigned char* s, std::size_t k, std::size_t,
                                std::uint16_t (*raw)[3], std::size_t) {
  unsigned bad = 0;
  std::size_t i = 0;
  alignas(16) unsigned char v[48];
  for (; i + 4 <= k; i += 4) {
    const unsigned char* p = s + 12 * i;
    if ((hex16(p, v) | hex16(p + 16, v + 16) | hex16(p + 32, v + 32)) != 0) bad |= 0x10u;
    const __m128i lo8 = _mm_set1_epi16(0xff), lo4 = _mm_set1_epi16(0xf);
    __m128i pr[4];  // p_0..p_23, and zeros after
    for (int j = 0; j < 3; ++j) {
      const __m128i w = _mm_load_si128(reinterpret_cast<const __m128i*>(v + 16 * j));
      pr[j] = _mm_or_si128(_mm_slli_epi16(_mm_and_si128(w, lo8), 4), _mm_srli_epi16(w, 8));
    }
    pr[3] = _mm_setzero_si128();
    alignas(16) std::uint16_t q[24], r[24];
    for (int j = 0; j < 3; ++j) {
      // p_j+1 in lane j: this vector one lane on, the next one's first last
      const __m128i nx = _mm_or_si128(_mm_srli_si128(pr[j], 2), _mm_slli_si128(pr[j + 1], 14));
      _mm_store_si128(reinterpret_cast<__m128i*>(q + 8 * j),
                      _mm_or_si128(_mm_slli_epi16(pr[j], 4), _mm_srli_epi16(nx, 4)));
      _mm_store_si128(reinterpret_cast<__m128i*>(r + 8 * j),
                      _mm_or_si128(_mm_slli_epi16(_mm_and_si128(pr[j], lo4), 8), nx));
    }
    for (int j = 0; j < 4; ++j) {
      std::uint16_t* o = raw[i + static_cast<std::size_t>(j)];
      o[0] = q[6 * j];
      o[1] = r[6 * j + 1];
      o[2] = q[6 * j + 3];
    }
  }
  return bad | hex_counts_tail(s, i, k, raw);
}
#endif

#if defined(GRAVCAL_AVX2)
// Two samples at a time (one in each 128-bit lane): each lane holds a
// sample's 12 digits and the next sample's first 4, which are not used (so
// 12 j + 4 bytes must be readable for j samples). The digits' values as
// hex16()'s; then a sample's counts are (d0 << 8) | (16 d1 + d2), (d3 << 8) |
// (16 d4 + d5) and (d6 << 8) | (16 d7 + d8): the pairs by one multiply-add of
// bytes, the high digits by a shuffle into the high bytes. Each sample's
// three counts are stored as 8 bytes at raw[i] (the last 2 bytes land on
// raw[j][0], so j + 1 rows are needed).
GRAVCAL_TARGET_AVX2 inline unsigned hex_pairs_avx2(const unsigned char* s, std::size_t k,
                                                   std::uint16_t (*raw)[3]) {
  const __m256i below0 = _mm256_set1_epi8('0' - 1), above9 = _mm256_set1_epi8('9' + 1);
  const __m256i belowA = _mm256_set1_epi8('A' - 1), aboveF = _mm256_set1_epi8('F' + 1);
  const __m256i belowa = _mm256_set1_epi8('a' - 1), abovef = _mm256_set1_epi8('f' + 1);
  const __m256i zero = _mm256_set1_epi8('0'), seven = _mm256_set1_epi8(7),
                thirty9 = _mm256_set1_epi8(39);
  // bytes (d1, d2), (d4, d5), (d7, d8) into 16-bit lanes 0-2, times (16, 1)
  const __m256i pairs = _mm256_setr_epi8(1, 2, 4, 5, 7, 8, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1,
                                         1, 2, 4, 5, 7, 8, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
  // d0, d3, d6 into the high bytes of lanes 0-2
  const __m256i highs = _mm256_setr_epi8(-1, 0, -1, 3, -1, 6, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1,
                                         -1, 0, -1, 3, -1, 6, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
  const __m256i weights = _mm256_set1_epi16(0x0110);  // bytes 16, 1
  unsigned bad = 0;
  for (std::size_t j = 0; j < k; j += 2, s += 24) {
    const __m256i c = _mm256_inserti128_si256(
        _mm256_castsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(s))),
        _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + 12)), 1);
    const __m256i dg = _mm256_and_si256(_mm256_cmpgt_epi8(c, below0), _mm256_cmpgt_epi8(above9, c));
    const __m256i up = _mm256_and_si256(_mm256_cmpgt_epi8(c, belowA), _mm256_cmpgt_epi8(aboveF, c));
    const __m256i lo = _mm256_and_si256(_mm256_cmpgt_epi8(c, belowa), _mm256_cmpgt_epi8(abovef, c));
    const __m256i val = _mm256_sub_epi8(
        _mm256_sub_epi8(_mm256_sub_epi8(c, zero), _mm256_and_si256(up, seven)),
        _mm256_and_si256(lo, thirty9));
    const unsigned ok = static_cast<unsigned>(
        _mm256_movemask_epi8(_mm256_or_si256(_mm256_or_si256(dg, up), lo)));
    bad |= ~ok & 0x0fff0fffu;  // each lane's own 12 digits
    const __m256i r = _mm256_or_si256(
        _mm256_maddubs_epi16(_mm256_shuffle_epi8(val, pairs), weights),
        _mm256_shuffle_epi8(val, highs));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(raw[j]), _mm256_castsi256_si128(r));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(raw[j + 1]), _mm256_extracti128_si256(r, 1));
  }
  return bad != 0 ? 0x10u : 0u;
}

GRAVCAL_TARGET_AVX2 inline unsigned hex_counts_avx2(const unsigned char* s, std::size_t k,
                                                    std::size_t readable,
                                                    std::uint16_t (*raw)[3], std::size_t rows) {
  // the samples whose 16-byte loads stay inside what is readable and whose
  // 8-byte stores stay inside raw, an even number of them
  std::size_t j = k;
  if (j > 0 && 12 * j + 4 > readable) --j;
  if (j + 1 > rows) j = rows > 0 ? rows - 1 : 0;
  j &= ~std::size_t(1);
  const unsigned bad = hex_pairs_avx2(s, j, raw);
  return bad | hex_counts_tail(s, j, k, raw);
}
#endif

using HexCountsFn = unsigned (*)(const unsigned char*, std::size_t, std::size_t,
                                 std::uint16_t (*)[3], std::size_t);
constexpr Variants<HexCountsFn> hex_counts_variants = {
    hex_counts_scalar, GRAVCAL_IF_SSE2(hex_counts_sse2), GRAVCAL_IF_AVX2(hex_counts_avx2)};

}  // namespace kernels
}  // namespace gravcal

#endif  // GRAVCAL_KERNELS_DECODE_HPP
