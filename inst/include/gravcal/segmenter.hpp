// gravcal: streaming window statistics and rest rules.
//
// The segmenter cuts a sample stream into consecutive, non-overlapping windows
// of a fixed duration and gives, per window, the mean, standard deviation
// (n - 1), min, max and range of each axis, the mean of the per-sample vector
// norm and the mean temperature. Samples arrive in chunks of any size; the
// windows, and every bit of their statistics, are the same however the stream
// is split, because the state carried between chunks is the complete state of
// the open window.
//
// Window k holds the retained samples with stream index in
// [round(k L), round((k + 1) L)), L = duration * sampling rate, so a rate
// that does not give a whole number of samples per window (85.7 Hz) keeps the
// right duration on average. Samples whose x, y and z are all exactly zero
// (ActiGraph idle sleep) can be skipped before counting, as GGIR does.
//
// Two arithmetics give the statistics:
// - streaming (the default): sums about the first valid sample of the window
//   (shifted data algorithm), exact to rounding for the small variances of
//   rest windows, with no storage beyond a few sums; what a microcontroller
//   runs. Each sum is kept in four lanes by the sample's position in the
//   window (position mod 4) and the lanes are added as (0 + 1) + (2 + 3) when
//   the window closes, so that whole windows can be summed two samples per
//   instruction (SSE2) with the same result as sample by sample.
// - R-compatible (use_r_arithmetic()): the numbers GGIR gets in R, to the
//   last bit, so that GGIR's exact-equality rules (its duplicate-window
//   filter) and thresholds decide the same way. Means are differences of a
//   running cumulative sum kept in long double and rounded to double at each
//   window boundary (R's cumsum() followed by diff()), restarted by
//   new_block() where GGIR restarts its cumsum (each block it reads); the sd
//   is R's var(): a two-pass mean with a correction pass, then the sum of
//   squared deviations, all in long double (the two-pass mean decided
//   without its passes where a bound allows: r_var_means3(), r_arith.hpp).
//   The caller lends the buffer that
//   holds the open window's samples, so the core still allocates nothing.
//   GGIR's procedure only compares the sds with its rest threshold and
//   with the previous window's (its duplicate filter): lazy_r_sd() keeps
//   R's arithmetic for those sds that such a comparison could tell from an
//   sd in double, with bounds on both (fast_sd()), and the temperature's
//   running sum goes by runs of equal values (add_in_order()).
//
// Header-only, standard headers only, no heap.
#ifndef GRAVCAL_SEGMENTER_HPP
#define GRAVCAL_SEGMENTER_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "r_arith.hpp"
#include "simd.hpp"
// GRAVCAL_NO_SIMD: the portable loop only (the results are the same bits)
#if defined(__SSE2__) && !defined(GRAVCAL_NO_SIMD)
#define GRAVCAL_SSE2 1
#include <emmintrin.h>
#endif

#if defined(__GNUC__)
#define GRAVCAL_NOINLINE __attribute__((noinline))
#else
#define GRAVCAL_NOINLINE
#endif

namespace gravcal {

// Per-window results.
struct WindowStats {
  std::int64_t index;  // window number, from 0
  std::int64_t first;  // stream index (all samples pushed, skipped ones
                       // included) of the window's first retained sample
  std::int32_t n;      // retained samples in the window
  std::int32_t n_invalid;  // of which non-finite in x, y or z (not in stats)
  double mean[3];
  double sd[3];        // n - 1 denominator; NaN with fewer than 2 samples
  double min[3];
  double max[3];
  double mean_norm;    // mean of sqrt(x^2 + y^2 + z^2)
  double temperature;  // mean of finite temperatures, NaN if none
};

#if defined(GRAVCAL_AVX2)
// run_end()'s scan from j, eight values at a time.
GRAVCAL_TARGET_AVX2 inline std::size_t run_scan_avx2(const double* v, std::size_t j,
                                                     std::size_t n, std::uint64_t bits) {
  const __m256i b = _mm256_set1_epi64x(static_cast<long long>(bits));
  for (; j + 8 <= n; j += 8) {
    const __m256i a0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v + j));
    const __m256i a1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v + j + 4));
    const __m256i eq = _mm256_and_si256(_mm256_cmpeq_epi64(a0, b), _mm256_cmpeq_epi64(a1, b));
    if (_mm256_movemask_epi8(eq) != -1) break;
  }
  return j;
}
#endif

// The end of the run of values with the same bits as v[i], from i on (eight
// at a time with AVX2, four with SSE2).
inline std::size_t run_end(const double* v, std::size_t i, std::size_t n) {
  std::uint64_t bits;
  std::memcpy(&bits, v + i, sizeof bits);
  std::size_t j = i + 1;
#if defined(GRAVCAL_AVX2)
  if (use_avx2()) {
    j = run_scan_avx2(v, j, n, bits);
    while (j < n && std::memcmp(v + j, &bits, sizeof bits) == 0) ++j;
    return j;
  }
#endif
#if defined(GRAVCAL_SSE2)
  const __m128i b = _mm_set1_epi64x(static_cast<long long>(bits));
  for (; j + 4 <= n; j += 4) {
    const __m128i a0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(v + j));
    const __m128i a1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(v + j + 2));
    const __m128i eq = _mm_and_si128(_mm_cmpeq_epi32(a0, b), _mm_cmpeq_epi32(a1, b));
    if (_mm_movemask_epi8(eq) != 0xffff) break;
  }
#endif
  while (j < n && std::memcmp(v + j, &bits, sizeof bits) == 0) ++j;
  return j;
}

// for (k < n) s += v[k], in long double, to the bit, by runs of equal values
// (add_repeated(), r_arith.hpp): a temperature repeats over a page or a
// block of the file. b: the grid of s, kept between calls.
inline void add_in_order(long double& s, const double* v, std::size_t n, Binade& b) {
  std::size_t i = 0;
  while (i < n) {
    const std::size_t j = run_end(v, i, n);
    add_repeated(s, v[i], static_cast<std::uint64_t>(j - i), b);
    i = j;
  }
}

// The state of Segmenter::lazy_r_sd(), which the caller keeps (the core
// allocates nothing, and a segmenter without it stays small): the window
// held back, the window being closed, and the last window given out with
// means when the held one has none.
struct LazySd {
  // A window on its way to the sink, with what is known of its sds: R's
  // sd^2 of axis a lies in [lo2[a], hi2[a]] (one point when the sd is R's).
  struct Window {
    WindowStats s;
    bool fast = false;         // s.sd are in double, not R's (yet)
    bool na = false;           // no mean z or mean norm: GGIR's filter skips it
    double sd[3] = {0, 0, 0};  // the sds in double (fast_sd())
    long double lo2[3] = {0, 0, 0}, hi2[3] = {0, 0, 0};
    const double* col[3] = {nullptr, nullptr, nullptr};  // its samples
    std::size_t m = 0;
    long double w[3] = {0, 0, 0};  // their long double sums (R's first pass)
    bool has_w = false;
  };
  double max_sd = 0.0;     // the rest rule's threshold
  double* buf = nullptr;   // the held window's samples (ceil(L) + 1 per axis)
  Window cand;             // the window being closed
  Window held;             // the window held back
  bool held_on = false;
  long double ref_lo2[3] = {0, 0, 0}, ref_hi2[3] = {0, 0, 0};
  bool ref_on = false;     // the last window given out with means
};

class Segmenter {
 public:
  // samples_per_window: L = duration (s) * sampling rate (Hz), at least 1.
  // skip_zero: drop samples with x = y = z = 0 before windowing.
  Segmenter(double samples_per_window, bool skip_zero)
      : L_(samples_per_window < 1.0 ? 1.0 : samples_per_window),
        skip_zero_(skip_zero) {
    reset();
  }

  // Switch to R-compatible arithmetic (see above). `buffer` must hold
  // 3 * (ceil(L) + 1) doubles and outlive the segmenter; call before the
  // first push. Returns false (and changes nothing) when it is too small.
  bool use_r_arithmetic(double* buffer, std::size_t capacity) {
    const std::size_t per_axis =
        static_cast<std::size_t>(std::ceil(L_)) + 1u;
    if (buffer == nullptr || capacity < 3u * per_axis) return false;
    rbuf_ = buffer;
    rcap_ = per_axis;
    return true;
  }
  bool r_arithmetic() const { return rbuf_ != nullptr; }

  // R-compatible arithmetic for what GGIR's procedure can see of the sds
  // (call after use_r_arithmetic(); state: see LazySd): the sd of a window is R's to the bit
  // when the window may be at rest (its R sd below max_sd on every axis,
  // the rest rule's threshold), and when GGIR's duplicate filter could find
  // it equal to the sd of the window before (the last one with a mean z and
  // a mean norm); otherwise it is an sd in double whose distance from R's
  // is bounded (fast_sd()), and which is on the same side of max_sd and of
  // the neighbours' sds as R's. Means are always R's. Windows then reach
  // the sink one window late: finish() gives the last one (call it at the
  // end of each of GGIR's blocks). `buffer` (3 * (ceil(L) + 1) doubles,
  // outliving the segmenter) keeps the samples of the window held back.
  // Returns false (and changes nothing) when the buffer is too small, the
  // arithmetic is not R's, or max_sd is not positive and finite.
  bool lazy_r_sd(double max_sd, LazySd* state, double* buffer, std::size_t capacity) {
    if (rbuf_ == nullptr || !(max_sd > 0) || !std::isfinite(max_sd)) return false;
    if (state == nullptr || buffer == nullptr || capacity < 3u * rcap_) return false;
    *state = LazySd();
    state->max_sd = max_sd;
    state->buf = buffer;
    lz_ = state;
    return true;
  }

  // Gives the window held back by lazy_r_sd() (a no-op otherwise).
  template <class Sink>
  void finish(Sink&& sink) {
    if (lz_ == nullptr || !lz_->held_on) return;
    if (!lz_->held.na) keep_as_reference(lz_->held);
    lz_->held_on = false;
    sink(lz_->held.s);
  }

  // Restart the cumulative sums, as GGIR does at each block it reads. Only at
  // a window boundary (no open window); returns false otherwise.
  bool new_block() {
    if (n_ != 0) return false;
    for (int c = 0; c < 5; ++c) {
      csum_[c] = 0.0L;
      cprev_[c] = 0.0;
    }
    return true;
  }

  void reset() {
    for (int c = 0; c < 5; ++c) {
      csum_[c] = 0.0L;
      cprev_[c] = 0.0;
    }
    window_ = 0;
    retained_ = 0;
    seen_ = 0;
    skipped_zero_ = 0;
    next_boundary_ = boundary(1);
    if (lz_ != nullptr) {
      lz_->held_on = false;
      lz_->ref_on = false;
    }
    clear_window();
  }

  // Push a chunk of n samples. t may be null (no temperature). sink(stats) is
  // called once for every window completed by this chunk, in order.
  //
  // A window that lies whole inside the chunk is computed by one tight loop
  // over the caller's arrays (whole_window()); it falls back to the
  // sample-by-sample path when the window holds a skipped zero or a
  // non-finite value. Both paths add the same numbers in the same order, so
  // the results do not depend on which one ran, nor on the chunking.
  template <class Sink>
  void push(const double* x, const double* y, const double* z,
            const double* t, std::size_t n, Sink&& sink) {
    std::size_t i = 0;
    bool try_whole = true;
    while (i < n) {
      if (n_ == 0 && try_whole) {
        const std::int64_t need = next_boundary_ - retained_;
        if (need > 0 && static_cast<std::uint64_t>(need) <= n - i) {
          const std::size_t m = static_cast<std::size_t>(need);
          if (whole_window(x + i, y + i, z + i, t ? t + i : nullptr, m,
                           sink)) {
            i += m;
            continue;
          }
          try_whole = false;  // until this window closes
        }
      }
      if (step(x[i], y[i], z[i], t ? t[i] : NAN, sink)) try_whole = true;
      ++i;
    }
    // the held window's samples are the caller's: keep a copy
    if (lz_ != nullptr && lz_->held_on && lz_->held.fast) keep_samples(lz_->held);
  }

  // Samples in the open (incomplete) window; these are dropped at the end.
  std::int64_t pending() const { return n_; }
  std::int64_t windows() const { return window_; }
  std::int64_t retained() const { return retained_; }
  std::int64_t skipped_zero() const { return skipped_zero_; }

 private:
  std::int64_t boundary(std::int64_t k) const {
    return static_cast<std::int64_t>(std::llround(static_cast<double>(k) * L_));
  }

  // One sample; returns true when it completed a window.
  template <class Sink>
  bool step(double xi, double yi, double zi, double ti, Sink& sink) {
    const std::int64_t at = seen_++;
    if (skip_zero_ && xi == 0.0 && yi == 0.0 && zi == 0.0) {
      ++skipped_zero_;
      return false;
    }
    if (n_ == 0) first_ = at;
    add(xi, yi, zi, ti);
    ++retained_;
    if (retained_ != next_boundary_) return false;
    if (lz_ != nullptr) {
      LazySd::Window& h = lz_->cand;
      close(h.s, nullptr);  // close_r() fills in h
      deliver(h, sink);
    } else {
      WindowStats s;
      close(s, nullptr);
      sink(s);
    }
    return true;
  }

  // A whole window of m samples at x, y, z (t may be null) in one pass, with
  // the same operations in the same order as add(). Changes nothing and
  // returns false if the window needs the sample-by-sample path (a sample to
  // skip, or a non-finite value).
  template <class Sink>
  bool whole_window(const double* x, const double* y, const double* z,
                    const double* t, std::size_t m, Sink& sink) {
    const double h0 = x[0], h1 = y[0], h2 = z[0];
    StreamScan a;
    RScan r;
    bool fast = false;
    if (rbuf_ == nullptr) {
      scan_stream(x, y, z, t, m, a);
      double all = lanes(a.nrm);
      for (int k = 0; k < 3; ++k) all += lanes(a.s[k]) + lanes(a.q[k]);
      if ((skip_zero_ && a.zero) || !std::isfinite(all) ||
          (t != nullptr && !std::isfinite(lanes(a.st)))) {
        return false;
      }
    } else {
      for (int k = 0; k < 5; ++k) r.c[k] = csum_[k];
      scan_r(x, y, z, m, r);
      // the running sums stay finite through windows of finite samples
      // (add() leaves out non-finite ones), so a non-finite sum here means
      // this window holds a non-finite value
      if ((skip_zero_ && r.zero) ||
          !std::isfinite(static_cast<double>(r.c[0] + r.c[1] + r.c[2] + r.c[3]))) {
        return false;
      }
      const double* cols[3] = {x, y, z};
      // lazy_r_sd(): an sd in double where R's cannot matter
      fast = lz_ != nullptr && fast_sd(cols, m, r.lo, r.hi, r.ls, lz_->cand);
      // the sds (R's var()), with the temperature's running sum riding
      // along their second pass (a single chain of additions is cheaper
      // there); for a window left with the sd in double, the temperature's
      // sum by runs (add_in_order()); all before anything changes: a
      // non-finite temperature still sends the window to the
      // sample-by-sample path
      if (!fast && m > 1) {
        r_sd3(cols, m, r.has_w ? r.w : nullptr, t, &r.c[4], wsd_);
      } else if (t != nullptr) {
        Binade b;
        add_in_order(r.c[4], t, m, b);
      }
      if (t != nullptr && !std::isfinite(static_cast<double>(r.c[4]))) return false;
      for (int k = 0; k < 5; ++k) csum_[k] = r.c[k];
      a = StreamScan();  // sums replaced by close_r()
      for (int k = 0; k < 3; ++k) {
        a.lo[k] = r.lo[k];
        a.hi[k] = r.hi[k];
      }
    }
    first_ = seen_;
    seen_ += static_cast<std::int64_t>(m);
    retained_ += static_cast<std::int64_t>(m);
    n_ = n_valid_ = static_cast<std::int64_t>(m);
    n_invalid_ = 0;
    n_temp_ = t != nullptr ? static_cast<std::int64_t>(m) : 0;
    shift_[0] = h0;
    shift_[1] = h1;
    shift_[2] = h2;
    for (int k = 0; k < 3; ++k) {
      for (int l = 0; l < 4; ++l) {
        sum_[k][l] = a.s[k][l];
        sumsq_[k][l] = a.q[k][l];
      }
      min_[k] = a.lo[k];
      max_[k] = a.hi[k];
    }
    for (int l = 0; l < 4; ++l) {
      sum_norm_[l] = a.nrm[l];
      sum_temp_[l] = a.st[l];
    }
    const double* cols[3] = {x, y, z};
    if (lz_ == nullptr) {
      WindowStats s;
      close(s, cols);
      sink(s);
      return true;
    }
    LazySd::Window& h = lz_->cand;
    h.fast = fast;
    close(h.s, cols);
    if (fast) {
      for (int k = 0; k < 3; ++k) {
        h.col[k] = cols[k];
        h.w[k] = r.w[k];
      }
      h.m = m;
      h.has_w = r.has_w;
    }
    deliver(h, sink);
    return true;
  }

  // The one-pass loops of whole_window(), kept out of line so that their
  // code does not depend on the caller's.
  struct StreamScan {
    double s[3][4] = {}, q[3][4] = {}, lo[3] = {}, hi[3] = {}, nrm[4] = {},
           st[4] = {};
    bool zero = false;
  };
  struct RScan {
    long double c[5], w[3];
    double lo[3], hi[3], ls[3][4];
    bool has_w;  // w holds the window's sums (scan_r() without r_var_means3())
    bool zero;
  };

  // Streaming sums about the first sample, in lanes by position (add()'s
  // arithmetic): with SSE2, lanes 0 and 1 in one register and 2 and 3 in
  // another; otherwise one lane at a time. Either way every lane adds its
  // own samples in order, so the results are the same bits.
  GRAVCAL_NOINLINE static void scan_stream(const double* x, const double* y,
                                           const double* z, const double* t,
                                           std::size_t m, StreamScan& o) {
    const double h[3] = {x[0], y[0], z[0]};
    const double* col[3] = {x, y, z};
    std::size_t k = 0;
    double lo[3] = {h[0], h[1], h[2]}, hi[3] = {h[0], h[1], h[2]};
    bool zero = false;
#if defined(GRAVCAL_AVX2)
    if (use_avx2()) {
      k = scan_stream_avx2(x, y, z, t, m, h, o, lo, hi, zero);
    } else
#endif
#if defined(GRAVCAL_SSE2)
    {
      // named registers, not arrays, so that all of them stay in registers;
      // suffix a: lanes 0 and 1 (samples k, k + 1), b: lanes 2 and 3
      const __m128d zr = _mm_setzero_pd();
      const __m128d h0 = _mm_set1_pd(h[0]), h1 = _mm_set1_pd(h[1]),
                    h2 = _mm_set1_pd(h[2]);
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
        na = _mm_add_pd(na, _mm_sqrt_pd(_mm_add_pd(
                                _mm_add_pd(_mm_mul_pd(xa, xa), _mm_mul_pd(ya, ya)),
                                _mm_mul_pd(za, za))));
        nb = _mm_add_pd(nb, _mm_sqrt_pd(_mm_add_pd(
                                _mm_add_pd(_mm_mul_pd(xb, xb), _mm_mul_pd(yb, yb)),
                                _mm_mul_pd(zb, zb))));
        zacc = _mm_or_pd(zacc, _mm_and_pd(_mm_and_pd(_mm_cmpeq_pd(xa, zr),
                                                     _mm_cmpeq_pd(ya, zr)),
                                          _mm_cmpeq_pd(za, zr)));
        zacc = _mm_or_pd(zacc, _mm_and_pd(_mm_and_pd(_mm_cmpeq_pd(xb, zr),
                                                     _mm_cmpeq_pd(yb, zr)),
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
      zero = _mm_movemask_pd(zacc) != 0;
    }
#endif
    for (; k < m; ++k) {
      const int l = static_cast<int>(k & 3);
      const double xi = x[k], yi = y[k], zi = z[k];
      zero = zero || (xi == 0.0 && yi == 0.0 && zi == 0.0);
      for (int a = 0; a < 3; ++a) {
        const double v = col[a][k];
        const double d = v - h[a];
        o.s[a][l] += d;
        o.q[a][l] += d * d;
        lo[a] = v < lo[a] ? v : lo[a];
        hi[a] = v > hi[a] ? v : hi[a];
      }
      o.nrm[l] += std::sqrt(xi * xi + yi * yi + zi * zi);
      if (t != nullptr) o.st[l] += t[k];
    }
    for (int a = 0; a < 3; ++a) {
      o.lo[a] = lo[a];
      o.hi[a] = hi[a];
    }
    zero_signs(col, m, o.lo, o.hi);
    o.zero = zero;
  }

#if defined(GRAVCAL_AVX2)
  // scan_stream()'s loop with the four lanes in one AVX2 register each:
  // the same operations on the same lanes (no fused multiply-add), so the
  // same bits. Returns the samples done (a multiple of 4).
  GRAVCAL_TARGET_AVX2 static std::size_t scan_stream_avx2(
      const double* x, const double* y, const double* z, const double* t, std::size_t m,
      const double* h, StreamScan& o, double* lo, double* hi, bool& zero) {
    const __m256d zr = _mm256_setzero_pd();
    const __m256d h0 = _mm256_set1_pd(h[0]), h1 = _mm256_set1_pd(h[1]),
                  h2 = _mm256_set1_pd(h[2]);
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
      zacc = _mm256_or_pd(
          zacc, _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(xa, zr, _CMP_EQ_OQ),
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
    zero = _mm256_movemask_pd(zacc) != 0;
    return k;
  }

  // min_max()'s loop, four samples at a time, with lane_sums()'s sums (the
  // same lanes in the same order). Sums: also scan_r()'s cumulative sums
  // (sum: x, y, z and the norm, long double, in sample order), the four
  // norms of a step by one square root instruction: the cumulative sums are
  // bound by the latency of their additions, which leaves room for the rest
  // of the loop, so the pass costs about what the sums alone did.
  template <bool Sums>
  GRAVCAL_TARGET_AVX2 static std::size_t min_max_avx2(const double* x, const double* y,
                                                      const double* z, std::size_t m,
                                                      double* lo, double* hi, bool& zero,
                                                      double (*ls)[4],
                                                      long double* sum = nullptr) {
    const __m256d zr = _mm256_setzero_pd();
    __m256d lo0 = _mm256_set1_pd(lo[0]), lo1 = _mm256_set1_pd(lo[1]), lo2 = _mm256_set1_pd(lo[2]);
    __m256d hi0 = lo0, hi1 = lo1, hi2 = lo2, zacc = zr;
    __m256d s0 = _mm256_loadu_pd(ls[0]), s1 = _mm256_loadu_pd(ls[1]), s2 = _mm256_loadu_pd(ls[2]);
    long double c0 = 0.0L, c1 = 0.0L, c2 = 0.0L, c3 = 0.0L;
    if (Sums) {
      c0 = sum[0];
      c1 = sum[1];
      c2 = sum[2];
      c3 = sum[3];
    }
    alignas(32) double nrm[4];
    std::size_t k = 0;
    for (; k + 4 <= m; k += 4) {
      const __m256d a = _mm256_loadu_pd(x + k), b = _mm256_loadu_pd(y + k),
                    c = _mm256_loadu_pd(z + k);
      if (Sums) {
        // scan_r()'s norm: x^2 + y^2, then + z^2, then the square root
        const __m256d sq = _mm256_add_pd(_mm256_mul_pd(a, a), _mm256_mul_pd(b, b));
        _mm256_store_pd(nrm, _mm256_sqrt_pd(_mm256_add_pd(sq, _mm256_mul_pd(c, c))));
        for (int j = 0; j < 4; ++j) {
          c0 += x[k + j];
          c1 += y[k + j];
          c2 += z[k + j];
          c3 += nrm[j];
        }
      }
      s0 = _mm256_add_pd(s0, a);
      s1 = _mm256_add_pd(s1, b);
      s2 = _mm256_add_pd(s2, c);
      lo0 = _mm256_min_pd(a, lo0);
      lo1 = _mm256_min_pd(b, lo1);
      lo2 = _mm256_min_pd(c, lo2);
      hi0 = _mm256_max_pd(a, hi0);
      hi1 = _mm256_max_pd(b, hi1);
      hi2 = _mm256_max_pd(c, hi2);
      zacc = _mm256_or_pd(
          zacc, _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(a, zr, _CMP_EQ_OQ),
                                            _mm256_cmp_pd(b, zr, _CMP_EQ_OQ)),
                              _mm256_cmp_pd(c, zr, _CMP_EQ_OQ)));
    }
    if (Sums) {
      sum[0] = c0;
      sum[1] = c1;
      sum[2] = c2;
      sum[3] = c3;
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

  // fast_sd()'s loop: the squared deviations of the four lanes by position
  // in one register per axis (the SSE2 loop's two), the same bits.
  GRAVCAL_TARGET_AVX2 static std::size_t sq_dev_avx2(const double* const* v, std::size_t n,
                                                     const double* mu, double (*q)[4]) {
    const __m256d m0 = _mm256_set1_pd(mu[0]), m1 = _mm256_set1_pd(mu[1]),
                  m2 = _mm256_set1_pd(mu[2]);
    const __m256d zr = _mm256_setzero_pd();
    __m256d q0 = zr, q1 = zr, q2 = zr;
    const double* x = v[0];
    const double* y = v[1];
    const double* z = v[2];
    std::size_t k = 0;
    for (; k + 4 <= n; k += 4) {
      __m256d d = _mm256_sub_pd(_mm256_loadu_pd(x + k), m0);
      q0 = _mm256_add_pd(q0, _mm256_mul_pd(d, d));
      d = _mm256_sub_pd(_mm256_loadu_pd(y + k), m1);
      q1 = _mm256_add_pd(q1, _mm256_mul_pd(d, d));
      d = _mm256_sub_pd(_mm256_loadu_pd(z + k), m2);
      q2 = _mm256_add_pd(q2, _mm256_mul_pd(d, d));
    }
    _mm256_storeu_pd(q[0], q0);
    _mm256_storeu_pd(q[1], q1);
    _mm256_storeu_pd(q[2], q2);
    return k;
  }
#endif

  // A zero minimum (maximum) as add()'s sequential rule leaves it: the
  // first zero of the column, with its sign (lanes may have kept the other
  // one). Any other value is the same in any order.
  static void zero_signs(const double* const* col, std::size_t m, double* lo, double* hi) {
    for (int a = 0; a < 3; ++a) {
      if (lo[a] == 0.0 || hi[a] == 0.0) {
        std::size_t j = 0;
        while (j < m && col[a][j] != 0.0) ++j;
        if (j < m && lo[a] == 0.0) lo[a] = col[a][j];
        if (j < m && hi[a] == 0.0) hi[a] = col[a][j];
      }
    }
  }

  // R's cumsum(), one column at a time, continuing o.c, and the norm as
  // add() forms it. Scalar accumulators, so that they stay in x87
  // registers; min, max and the zero test in a second loop (the
  // temperature's sum: r_sd3() or add_in_order()). Where r_var_means3()
  // cannot decide R's means, the window's own long double sums (the first
  // pass of R's sd) ride along, nearly free in this loop.
  GRAVCAL_NOINLINE static void scan_r(const double* x, const double* y,
                                      const double* z, std::size_t m, RScan& o) {
    o.has_w = !r_var_means_available();
#if defined(GRAVCAL_AVX2)
    if (!o.has_w && use_avx2()) {
      min_max(x, y, z, m, o, o.c);  // the sums ride in min_max()'s loop
      return;
    }
#endif
    long double c0 = o.c[0], c1 = o.c[1], c2 = o.c[2], c3 = o.c[3];
    if (o.has_w) {
      long double w0 = 0.0L, w1 = 0.0L, w2 = 0.0L;
      for (std::size_t k = 0; k < m; ++k) {
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
      for (std::size_t k = 0; k < m; ++k) {
        const double xi = x[k], yi = y[k], zi = z[k];
        c0 += xi;
        c1 += yi;
        c2 += zi;
        const double sq = xi * xi + yi * yi;
        c3 += std::sqrt(sq + zi * zi);
      }
    }
    o.c[0] = c0;
    o.c[1] = c1;
    o.c[2] = c2;
    o.c[3] = c3;
    min_max(x, y, z, m, o);
  }

  // min, max and whether some sample is all zeros. min and max are those of
  // the sequential rule (v < lo ? v : lo from the first sample, as add()):
  // the same value in any order, except that a zero minimum (maximum) is
  // the first zero met, with its sign, which a second look finds. Also the
  // columns' sums by lanes for fast_sd() (lane_sums()). sum: where AVX2 runs,
  // scan_r()'s four cumulative sums go on in the same loop (else null).
  static void min_max(const double* x, const double* y, const double* z,
                      std::size_t m, RScan& o, long double* sum = nullptr) {
    const double* col[3] = {x, y, z};
    double lo[3] = {x[0], y[0], z[0]}, hi[3] = {x[0], y[0], z[0]};
    bool zero = false;
    std::size_t k = 0;
    for (int a = 0; a < 3; ++a) {
      for (int l = 0; l < 4; ++l) o.ls[a][l] = 0.0;
    }
    (void)sum;  // only given where AVX2 runs
#if defined(GRAVCAL_AVX2)
    if (use_avx2()) {
      if (sum != nullptr) {
        k = min_max_avx2<true>(x, y, z, m, lo, hi, zero, o.ls, sum);
        long double c0 = sum[0], c1 = sum[1], c2 = sum[2], c3 = sum[3];
        for (std::size_t j = k; j < m; ++j) {
          const double xi = x[j], yi = y[j], zi = z[j];
          c0 += xi;
          c1 += yi;
          c2 += zi;
          const double sq = xi * xi + yi * yi;
          c3 += std::sqrt(sq + zi * zi);
        }
        sum[0] = c0;
        sum[1] = c1;
        sum[2] = c2;
        sum[3] = c3;
      } else {
        k = min_max_avx2<false>(x, y, z, m, lo, hi, zero, o.ls);
      }
      for (std::size_t j = k; j < m; ++j) {
        for (int a = 0; a < 3; ++a) o.ls[a][j & 3] += col[a][j];
      }
    } else
#endif
#if defined(GRAVCAL_SSE2)
    {
      const __m128d zr = _mm_setzero_pd();
      __m128d lo0 = _mm_set1_pd(lo[0]), lo1 = _mm_set1_pd(lo[1]), lo2 = _mm_set1_pd(lo[2]);
      __m128d hi0 = lo0, hi1 = lo1, hi2 = lo2, zacc = zr;
      // lane_sums()'s sums: lanes 0 and 1 in one register, 2 and 3 in another
      __m128d s0a = zr, s0b = zr, s1a = zr, s1b = zr, s2a = zr, s2b = zr;
      bool odd = false;  // whether lanes 2 and 3 come next
      for (; k + 2 <= m; k += 2) {
        const __m128d a = _mm_loadu_pd(x + k), b = _mm_loadu_pd(y + k),
                      c = _mm_loadu_pd(z + k);
        if (odd) {
          s0b = _mm_add_pd(s0b, a);
          s1b = _mm_add_pd(s1b, b);
          s2b = _mm_add_pd(s2b, c);
        } else {
          s0a = _mm_add_pd(s0a, a);
          s1a = _mm_add_pd(s1a, b);
          s2a = _mm_add_pd(s2a, c);
        }
        odd = !odd;
        lo0 = _mm_min_pd(a, lo0);
        lo1 = _mm_min_pd(b, lo1);
        lo2 = _mm_min_pd(c, lo2);
        hi0 = _mm_max_pd(a, hi0);
        hi1 = _mm_max_pd(b, hi1);
        hi2 = _mm_max_pd(c, hi2);
        zacc = _mm_or_pd(zacc, _mm_and_pd(_mm_and_pd(_mm_cmpeq_pd(a, zr),
                                                     _mm_cmpeq_pd(b, zr)),
                                          _mm_cmpeq_pd(c, zr)));
      }
      const __m128d lov[3] = {lo0, lo1, lo2}, hiv[3] = {hi0, hi1, hi2};
      for (int a = 0; a < 3; ++a) {
        double e[2];
        _mm_storeu_pd(e, lov[a]);
        lo[a] = e[0] < e[1] ? e[0] : e[1];
        _mm_storeu_pd(e, hiv[a]);
        hi[a] = e[0] > e[1] ? e[0] : e[1];
      }
      zero = _mm_movemask_pd(zacc) != 0;
      _mm_storeu_pd(o.ls[0], s0a);
      _mm_storeu_pd(o.ls[0] + 2, s0b);
      _mm_storeu_pd(o.ls[1], s1a);
      _mm_storeu_pd(o.ls[1] + 2, s1b);
      _mm_storeu_pd(o.ls[2], s2a);
      _mm_storeu_pd(o.ls[2] + 2, s2b);
      for (std::size_t j = k; j < m; ++j) {
        for (int a = 0; a < 3; ++a) o.ls[a][j & 3] += col[a][j];
      }
    }
#else
    lane_sums(col, m, o.ls);
#endif
    for (; k < m; ++k) {
      zero = zero || (x[k] == 0.0 && y[k] == 0.0 && z[k] == 0.0);
      for (int a = 0; a < 3; ++a) {
        const double v = col[a][k];
        lo[a] = v < lo[a] ? v : lo[a];
        hi[a] = v > hi[a] ? v : hi[a];
      }
    }
    zero_signs(col, m, lo, hi);
    for (int a = 0; a < 3; ++a) {
      o.lo[a] = lo[a];
      o.hi[a] = hi[a];
    }
    o.zero = zero;
  }

  // The sums of three columns in four lanes by position k & 3 (added to
  // s); the AVX2 loop adds the same lanes in the same order.
#if defined(GRAVCAL_AVX2)
  GRAVCAL_TARGET_AVX2 static std::size_t lane_sums_avx2(const double* const* v, std::size_t n,
                                                        double (*s)[4]) {
    __m256d s0 = _mm256_loadu_pd(s[0]), s1 = _mm256_loadu_pd(s[1]), s2 = _mm256_loadu_pd(s[2]);
    std::size_t k = 0;
    for (; k + 4 <= n; k += 4) {
      s0 = _mm256_add_pd(s0, _mm256_loadu_pd(v[0] + k));
      s1 = _mm256_add_pd(s1, _mm256_loadu_pd(v[1] + k));
      s2 = _mm256_add_pd(s2, _mm256_loadu_pd(v[2] + k));
    }
    _mm256_storeu_pd(s[0], s0);
    _mm256_storeu_pd(s[1], s1);
    _mm256_storeu_pd(s[2], s2);
    return k;
  }
#endif
  static void lane_sums(const double* const* v, std::size_t n, double (*s)[4]) {
    std::size_t k = 0;
#if defined(GRAVCAL_AVX2)
    if (use_avx2()) k = lane_sums_avx2(v, n, s);
#endif
    // each lane in a local of its own (sums kept in the array would wait
    // on their own stores), four samples a step, in the same order
    for (int a = 0; a < 3; ++a) {
      const double* x = v[a];
      double l0 = s[a][0], l1 = s[a][1], l2 = s[a][2], l3 = s[a][3];
      std::size_t j = k;
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

  // The sds of n (>= 2) samples in double, for lazy_r_sd(): about the mean
  // in double (ls: the values summed in four lanes by position,
  // lane_sums(); lanes() of them, over n), the squared deviations summed in four lanes by position
  // (two SSE2 registers per axis; the portable loop adds the same lanes),
  // so the same samples give the same bits on every path. Error bounds as
  // r_sd_below()'s (r_arith.hpp), with u = 2^-53 and M = max |x|: this
  // sd^2 is (s2 + n / (n - 1) dF^2) (1 + f), |dF| <= (n / 4 + 4) u M (each
  // lane a recursive sum of at most n / 4 + 1 values, two levels joining
  // the lanes, one division),
  // |f| <= (n + 4) u (times 1.01); R's is (s2 + n / (n - 1) dR^2) (1 + e),
  // |dR| <= (2 u + (4 n + 8) 2^-64) M, |e| <= (n + 3) 2^-64 + 3 u. With eps
  // = 4 (n + 16) u and dm = 4 (n + 8) u M + 1e-300 (covering either side),
  // R's sd^2 lies in [(v / (1 + eps) - 2 dm^2) (1 - eps), (v / (1 - eps) +
  // 2 dm^2) (1 + eps)], v this sd^2. Returns true (the sds in double may
  // stand) only when some axis is surely above max_sd (the window is not at
  // rest, whatever else) and the bounds apply (n u small, M within [1e-100,
  // 1e100] or 0); deliver() then checks the neighbour.
  bool fast_sd(const double* const* v, std::size_t n, const double* lo, const double* hi,
               const double (*ls)[4], LazySd::Window& h) const {
    if (n < 2 || n > (std::size_t(1) << 30)) return false;
    double M[3];
    for (int a = 0; a < 3; ++a) {
      M[a] = std::fmax(std::fabs(lo[a]), std::fabs(hi[a]));
      if (!(M[a] <= 1e100) || (M[a] != 0.0 && M[a] < 1e-100)) return false;
    }
    const long double ln = static_cast<long double>(n);
    const double dn = static_cast<double>(n);
    const double mu[3] = {lanes(ls[0]) / dn, lanes(ls[1]) / dn, lanes(ls[2]) / dn};
    double q[3][4] = {};
    std::size_t k = 0;
#if defined(GRAVCAL_AVX2)
    if (use_avx2()) {
      k = sq_dev_avx2(v, n, mu, q);
    } else
#endif
#if defined(GRAVCAL_SSE2)
    {
      const __m128d m0 = _mm_set1_pd(mu[0]), m1 = _mm_set1_pd(mu[1]), m2 = _mm_set1_pd(mu[2]);
      const __m128d zr = _mm_setzero_pd();
      __m128d q0a = zr, q0b = zr, q1a = zr, q1b = zr, q2a = zr, q2b = zr;
      const double* x = v[0];
      const double* y = v[1];
      const double* z = v[2];
      for (; k + 4 <= n; k += 4) {
        __m128d d = _mm_sub_pd(_mm_loadu_pd(x + k), m0);
        q0a = _mm_add_pd(q0a, _mm_mul_pd(d, d));
        d = _mm_sub_pd(_mm_loadu_pd(x + k + 2), m0);
        q0b = _mm_add_pd(q0b, _mm_mul_pd(d, d));
        d = _mm_sub_pd(_mm_loadu_pd(y + k), m1);
        q1a = _mm_add_pd(q1a, _mm_mul_pd(d, d));
        d = _mm_sub_pd(_mm_loadu_pd(y + k + 2), m1);
        q1b = _mm_add_pd(q1b, _mm_mul_pd(d, d));
        d = _mm_sub_pd(_mm_loadu_pd(z + k), m2);
        q2a = _mm_add_pd(q2a, _mm_mul_pd(d, d));
        d = _mm_sub_pd(_mm_loadu_pd(z + k + 2), m2);
        q2b = _mm_add_pd(q2b, _mm_mul_pd(d, d));
      }
      _mm_storeu_pd(q[0], q0a);
      _mm_storeu_pd(q[0] + 2, q0b);
      _mm_storeu_pd(q[1], q1a);
      _mm_storeu_pd(q[1] + 2, q1b);
      _mm_storeu_pd(q[2], q2a);
      _mm_storeu_pd(q[2] + 2, q2b);
    }
#endif
    for (; k < n; ++k) {
      for (int a = 0; a < 3; ++a) {
        const double d = v[a][k] - mu[a];
        q[a][k & 3] += d * d;
      }
    }
    const long double u = std::ldexp(1.0L, -53);
    const long double eps = 4.0L * (ln + 16.0L) * u;
    const long double t2 = static_cast<long double>(lz_->max_sd) * lz_->max_sd;
    bool above = false;
    for (int a = 0; a < 3; ++a) {
      const double var = lanes(q[a]) / static_cast<double>(n - 1);
      h.sd[a] = std::sqrt(var);
      const long double dm = 4.0L * (ln + 8.0L) * u * M[a] + 1e-300L;
      const long double d2 = 2.0L * dm * dm;
      h.hi2[a] = (var / (1.0L - eps) + d2) * (1.0L + eps);
      h.lo2[a] = (var / (1.0L + eps) - d2) * (1.0L - eps);
      if (h.lo2[a] > t2 * (1.0L + 1e-12L)) above = true;
    }
    return above;
  }

  // R's sds for a window kept in double.
  static void make_exact(LazySd::Window& h) {
    if (!h.fast) return;
    r_sd3(h.col, h.m, h.has_w ? h.w : nullptr, nullptr, nullptr, h.s.sd);
    h.fast = false;
    point_bounds(h);
  }

  static void point_bounds(LazySd::Window& h) {
    for (int a = 0; a < 3; ++a) {
      h.lo2[a] = h.hi2[a] = static_cast<long double>(h.s.sd[a]) * h.s.sd[a];
    }
  }

  // Whether R's sds of two windows could be equal on some axis (their
  // ranges touch, with room for the rounding of the values given out).
  static bool may_tie(const long double* lo_a, const long double* hi_a,
                      const long double* lo_b, const long double* hi_b) {
    for (int k = 0; k < 3; ++k) {
      const bool apart = hi_a[k] < lo_b[k] * (1.0L - 1e-12L) ||
                         hi_b[k] < lo_a[k] * (1.0L - 1e-12L);
      if (!apart) return true;
    }
    return false;
  }

  // The window kept as the one the next is compared with after it is
  // given out: its sds become R's.
  void keep_as_reference(LazySd::Window& h) {
    make_exact(h);
    for (int a = 0; a < 3; ++a) {
      lz_->ref_lo2[a] = h.lo2[a];
      lz_->ref_hi2[a] = h.hi2[a];
    }
    lz_->ref_on = true;
  }

  // A window kept in double whose samples are not the segmenter's to keep
  // (the caller's, or the open window's buffer): copied.
  void keep_samples(LazySd::Window& h) {
    if (h.col[0] == lz_->buf) return;
    for (int a = 0; a < 3; ++a) {
      double* d = lz_->buf + static_cast<std::size_t>(a) * rcap_;
      std::memcpy(d, h.col[a], h.m * sizeof(double));
      h.col[a] = d;
    }
  }

  // lazy_r_sd(): a completed window, held back one window, so that a tie
  // with the next can still make the sds of both R's.
  template <class Sink>
  void deliver(LazySd::Window& h, Sink& sink) {
    LazySd& z = *lz_;
    h.na = std::isnan(h.s.mean[2]) || std::isnan(h.s.mean_norm);
    if (!h.fast) point_bounds(h);
    if (!h.na) {
      // its neighbour in GGIR's filter: the held window, or the last one
      // given out with means (R's sds, see keep_as_reference())
      if (z.held_on && !z.held.na) {
        if (may_tie(z.held.lo2, z.held.hi2, h.lo2, h.hi2)) {
          make_exact(z.held);
          make_exact(h);
        }
      } else if (z.ref_on && may_tie(z.ref_lo2, z.ref_hi2, h.lo2, h.hi2)) {
        make_exact(h);
      }
    }
    if (z.held_on) {
      // a window without means: the held one stays the neighbour
      if (h.na && !z.held.na) keep_as_reference(z.held);
      sink(z.held.s);
    }
    if (!h.na) z.ref_on = false;
    z.held = h;
    z.held_on = true;
    // samples in the open window's buffer: keep a copy
    if (z.held.fast && z.held.col[0] == rbuf_) keep_samples(z.held);
  }

  void clear_window() {
    n_ = 0;
    n_invalid_ = 0;
    n_valid_ = 0;
    n_temp_ = 0;
    for (int l = 0; l < 4; ++l) {
      sum_norm_[l] = 0.0;
      sum_temp_[l] = 0.0;
    }
    first_ = -1;
    for (int a = 0; a < 3; ++a) {
      shift_[a] = 0.0;
      for (int l = 0; l < 4; ++l) {
        sum_[a][l] = 0.0;
        sumsq_[a][l] = 0.0;
      }
      min_[a] = INFINITY;
      max_[a] = -INFINITY;
    }
  }

  void add(double xi, double yi, double zi, double ti) {
    ++n_;
    if (std::isfinite(ti)) {
      sum_temp_[n_temp_ & 3] += ti;
      csum_[4] += ti;
      ++n_temp_;
    }
    if (!(std::isfinite(xi) && std::isfinite(yi) && std::isfinite(zi))) {
      ++n_invalid_;
      return;
    }
    const double v[3] = {xi, yi, zi};
    if (rbuf_ != nullptr) {
      for (int a = 0; a < 3; ++a) {
        rbuf_[static_cast<std::size_t>(a) * rcap_ + n_valid_] = v[a];
        csum_[a] += v[a];
      }
      // R: sqrt(Gx^2 + Gy^2 + Gz^2), each operation rounded to double.
      const double sq = xi * xi + yi * yi;
      csum_[3] += std::sqrt(sq + zi * zi);
    }
    if (n_valid_ == 0) {
      for (int a = 0; a < 3; ++a) shift_[a] = v[a];
    }
    const int lane = static_cast<int>(n_valid_ & 3);
    ++n_valid_;
    for (int a = 0; a < 3; ++a) {
      const double d = v[a] - shift_[a];
      sum_[a][lane] += d;
      sumsq_[a][lane] += d * d;
      if (v[a] < min_[a]) min_[a] = v[a];
      if (v[a] > max_[a]) max_[a] = v[a];
    }
    sum_norm_[lane] += std::sqrt(xi * xi + yi * yi + zi * zi);
  }

  static double lanes(const double* v) { return (v[0] + v[1]) + (v[2] + v[3]); }

  // cols: the window's samples per axis (whole_window()), or null for the
  // lent buffer.
  void close(WindowStats& s, const double* const* cols) {
    s.index = window_;
    s.first = first_;
    s.n = static_cast<std::int32_t>(n_);
    s.n_invalid = static_cast<std::int32_t>(n_invalid_);
    const double nv = static_cast<double>(n_valid_);
    for (int a = 0; a < 3; ++a) {
      if (n_valid_ > 0) {
        const double m = lanes(sum_[a]) / nv;
        s.mean[a] = shift_[a] + m;
        s.min[a] = min_[a];
        s.max[a] = max_[a];
      } else {
        s.mean[a] = NAN;
        s.min[a] = NAN;
        s.max[a] = NAN;
      }
      if (n_valid_ > 1) {
        const double sa = lanes(sum_[a]);
        double ss = lanes(sumsq_[a]) - sa * sa / nv;
        if (ss < 0.0) ss = 0.0;
        s.sd[a] = std::sqrt(ss / (nv - 1.0));
      } else {
        s.sd[a] = NAN;
      }
    }
    s.mean_norm = n_valid_ > 0 ? lanes(sum_norm_) / nv : NAN;
    s.temperature =
        n_temp_ > 0 ? lanes(sum_temp_) / static_cast<double>(n_temp_) : NAN;
    if (rbuf_ != nullptr) close_r(s, cols);
    ++window_;
    next_boundary_ = boundary(window_ + 1);
    clear_window();
  }

  // Means from the rounded cumulative sums, sds as R's var() computes them.
  void close_r(WindowStats& s, const double* const* cols) {
    double c[5];
    for (int k = 0; k < 5; ++k) c[k] = static_cast<double>(csum_[k]);
    if (n_valid_ > 0) {
      const double nv = static_cast<double>(n_valid_);
      for (int a = 0; a < 3; ++a) s.mean[a] = (c[a] - cprev_[a]) / nv;
      s.mean_norm = (c[3] - cprev_[3]) / nv;
    }
    if (n_temp_ > 0) {
      s.temperature = (c[4] - cprev_[4]) / static_cast<double>(n_temp_);
    }
    for (int k = 0; k < 5; ++k) cprev_[k] = c[k];
    if (n_valid_ > 1) {
      const double* v[3];
      for (int a = 0; a < 3; ++a) {
        v[a] = cols != nullptr ? cols[a]
                               : rbuf_ + static_cast<std::size_t>(a) * rcap_;
      }
      if (cols != nullptr) {
        // whole_window()'s: R's, or in double (lazy_r_sd())
        const bool fast = lz_ != nullptr && lz_->cand.fast;
        for (int a = 0; a < 3; ++a) s.sd[a] = fast ? lz_->cand.sd[a] : wsd_[a];
      } else if (lz_ != nullptr) {
        LazySd::Window& h = lz_->cand;
        // the same choice as whole_window() makes, on the same values
        const std::size_t nv = static_cast<std::size_t>(n_valid_);
        double ls[3][4] = {};
        lane_sums(v, nv, ls);
        h.fast = fast_sd(v, nv, min_, max_, ls, h);
        if (h.fast) {
          for (int a = 0; a < 3; ++a) {
            s.sd[a] = h.sd[a];
            h.col[a] = v[a];
          }
          h.m = nv;
          h.has_w = false;
        } else {
          r_sd3(v, nv, nullptr, nullptr, nullptr, s.sd);
        }
      } else {
        r_sd3(v, static_cast<std::size_t>(n_valid_), nullptr, nullptr, nullptr, s.sd);
      }
    } else {
      if (lz_ != nullptr) lz_->cand.fast = false;
      for (int a = 0; a < 3; ++a) s.sd[a] = NAN;
    }
  }

  // R's sd() of three columns of n (>= 2) values: the mean with R's
  // correction pass, then the sum of squared deviations, in long double. The
  // three columns go through each pass together (independent sums, so the
  // result is that of three separate calls). The means come without R's
  // two passes where r_var_means3() can decide them (the same doubles).
  // sum1: the first pass's sums when the caller has them already, or null.
  // t, tsum: when not null, the n temperatures are added to *tsum in order
  // (in the second pass, an independent chain nearly free there, or by runs
  // with add_in_order()).
  GRAVCAL_NOINLINE static void r_sd3(const double* const* v, std::size_t n,
                                     const long double* sum1, const double* t,
                                     long double* tsum, double* out) {
    const long double ln = static_cast<long double>(n);
    const double* a = v[0];
    const double* b = v[1];
    const double* c = v[2];
    double mean[3];
    if (r_var_means3(v, n, mean)) {
      if (t != nullptr && tsum != nullptr) {
        Binade bt;
        add_in_order(*tsum, t, n, bt);
      }
    } else {
      long double sa = 0.0L, sb = 0.0L, sc = 0.0L;
      if (sum1 != nullptr) {
        sa = sum1[0];
        sb = sum1[1];
        sc = sum1[2];
      } else {
        for (std::size_t k = 0; k < n; ++k) {
          sa += a[k];
          sb += b[k];
          sc += c[k];
        }
      }
      long double m[3] = {sa / ln, sb / ln, sc / ln};
      const bool fin[3] = {std::isfinite(static_cast<double>(m[0])),
                           std::isfinite(static_cast<double>(m[1])),
                           std::isfinite(static_cast<double>(m[2]))};
      sa = sb = sc = 0.0L;
      const long double m0 = m[0], m1 = m[1], m2 = m[2];
      if (t != nullptr && tsum != nullptr) {
        long double st = *tsum;
        for (std::size_t k = 0; k < n; ++k) {
          sa += (a[k] - m0);
          sb += (b[k] - m1);
          sc += (c[k] - m2);
          st += t[k];
        }
        *tsum = st;  // out of the registers before the third pass
      } else {
        for (std::size_t k = 0; k < n; ++k) {
          sa += (a[k] - m0);
          sb += (b[k] - m1);
          sc += (c[k] - m2);
        }
      }
      if (fin[0]) m[0] = m[0] + sa / ln;
      if (fin[1]) m[1] = m[1] + sb / ln;
      if (fin[2]) m[2] = m[2] + sc / ln;
      for (int k = 0; k < 3; ++k) mean[k] = static_cast<double>(m[k]);
    }
    const long double ma = mean[0], mb = mean[1], mc = mean[2];
    long double sa = 0.0L, sb = 0.0L, sc = 0.0L;
    for (std::size_t k = 0; k < n; ++k) {
      const long double da = a[k] - ma, db = b[k] - mb, dc = c[k] - mc;
      sa += da * da;
      sb += db * db;
      sc += dc * dc;
    }
    const long double d = static_cast<long double>(n - 1);
    out[0] = std::sqrt(static_cast<double>(sa / d));
    out[1] = std::sqrt(static_cast<double>(sb / d));
    out[2] = std::sqrt(static_cast<double>(sc / d));
  }

  double L_;
  bool skip_zero_;
  double* rbuf_ = nullptr;
  std::size_t rcap_ = 0;
  long double csum_[5];
  double wsd_[3] = {0.0, 0.0, 0.0};  // the sds whole_window() computed
  LazySd* lz_ = nullptr;      // lazy_r_sd()'s state, or null
  double cprev_[5];
  std::int64_t window_, retained_, seen_, skipped_zero_, next_boundary_, first_;
  std::int64_t n_, n_invalid_, n_valid_, n_temp_;
  double shift_[3], min_[3], max_[3];
  double sum_[3][4], sumsq_[3][4], sum_norm_[4], sum_temp_[4];  // lanes
};

// Rest rule of the lightweight method (Farago et al. 2024, Sec. II-B-1):
// max - min below `max_range` (paper: 0.12 g) on every axis in `axes`
// (bit 0 = x, 1 = y, 2 = z; the paper watches one axis, gravcal all three).
struct RangeRestRule {
  double max_range = 0.12;
  unsigned axes = 7u;
};

inline bool is_rest(const WindowStats& s, const RangeRestRule& r) {
  if (s.n_invalid > 0 || s.n < 2) return false;
  for (int a = 0; a < 3; ++a) {
    if (!(r.axes & (1u << a))) continue;
    if (!(s.max[a] - s.min[a] < r.max_range)) return false;
  }
  return true;
}

// Rest rule of GGIR (van Hees et al. 2014): sd below `max_sd` (13 mg) and
// |mean| below `max_abs_mean` (2 g, a clipping guard) on all three axes.
struct SdRestRule {
  double max_sd = 0.013;
  double max_abs_mean = 2.0;
};

inline bool is_rest(const WindowStats& s, const SdRestRule& r) {
  if (s.n_invalid > 0 || s.n < 2) return false;
  for (int a = 0; a < 3; ++a) {
    if (!(s.sd[a] < r.max_sd)) return false;
    if (!(std::fabs(s.mean[a]) < r.max_abs_mean)) return false;
  }
  return true;
}

}  // namespace gravcal

#endif  // GRAVCAL_SEGMENTER_HPP
