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
//   squared deviations, all in long double. The caller lends the buffer that
//   holds the open window's samples, so the core still allocates nothing.
//
// Header-only, standard headers only, no heap.
#ifndef GRAVCAL_SEGMENTER_HPP
#define GRAVCAL_SEGMENTER_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
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
    WindowStats s;
    close(s, nullptr);
    sink(s);
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
      scan_r(x, y, z, t, m, r);
      // the running sums stay finite through windows of finite samples
      // (add() leaves out non-finite ones), so a non-finite sum here means
      // this window holds a non-finite value
      if ((skip_zero_ && r.zero) ||
          !std::isfinite(static_cast<double>(r.c[0] + r.c[1] + r.c[2] + r.c[3])) ||
          (t != nullptr && !std::isfinite(static_cast<double>(r.c[4])))) {
        return false;
      }
      for (int k = 0; k < 5; ++k) csum_[k] = r.c[k];
      a = StreamScan();  // sums replaced by close_r()
      for (int k = 0; k < 3; ++k) {
        wsum_[k] = r.w[k];
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
    WindowStats s;
    close(s, cols);
    sink(s);
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
    double lo[3], hi[3];
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
    o.zero = zero;
  }

  // R's cumsum(), one column at a time, continuing o.c, and the norm as
  // add() forms it; the window's own long double sums (the first pass of
  // R's sd) ride along. Scalar accumulators, so that they stay in x87
  // registers; min, max and temperature in a second loop.
  GRAVCAL_NOINLINE static void scan_r(const double* x, const double* y,
                                      const double* z, const double* t,
                                      std::size_t m, RScan& o) {
    long double c0 = o.c[0], c1 = o.c[1], c2 = o.c[2], c3 = o.c[3];
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
    o.c[0] = c0;
    o.c[1] = c1;
    o.c[2] = c2;
    o.c[3] = c3;
    o.w[0] = w0;
    o.w[1] = w1;
    o.w[2] = w2;
    const double h0 = x[0], h1 = y[0], h2 = z[0];
    double lo0 = h0, lo1 = h1, lo2 = h2, hi0 = h0, hi1 = h1, hi2 = h2;
    bool zero = false;
    long double c4 = o.c[4];
    for (std::size_t k = 0; k < m; ++k) {
      const double xi = x[k], yi = y[k], zi = z[k];
      zero |= (xi == 0.0) & (yi == 0.0) & (zi == 0.0);
      lo0 = xi < lo0 ? xi : lo0;
      lo1 = yi < lo1 ? yi : lo1;
      lo2 = zi < lo2 ? zi : lo2;
      hi0 = xi > hi0 ? xi : hi0;
      hi1 = yi > hi1 ? yi : hi1;
      hi2 = zi > hi2 ? zi : hi2;
      if (t != nullptr) c4 += t[k];
    }
    o.c[4] = c4;
    o.lo[0] = lo0;
    o.lo[1] = lo1;
    o.lo[2] = lo2;
    o.hi[0] = hi0;
    o.hi[1] = hi1;
    o.hi[2] = hi2;
    o.zero = zero;
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
      r_sd3(v, static_cast<std::size_t>(n_valid_), cols != nullptr ? wsum_ : nullptr,
            s.sd);
    } else {
      for (int a = 0; a < 3; ++a) s.sd[a] = NAN;
    }
  }

  // R's sd() of three columns of n (>= 2) values: the mean with R's
  // correction pass, then the sum of squared deviations, in long double. The
  // three columns go through each pass together (independent sums, so the
  // result is that of three separate calls). sum1: the first pass's sums
  // when the caller has them already, or null.
  static void r_sd3(const double* const* v, std::size_t n,
                    const long double* sum1, double* out) {
    const long double ln = static_cast<long double>(n);
    const double* a = v[0];
    const double* b = v[1];
    const double* c = v[2];
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
    {
      const long double m0 = m[0], m1 = m[1], m2 = m[2];
      for (std::size_t k = 0; k < n; ++k) {
        sa += (a[k] - m0);
        sb += (b[k] - m1);
        sc += (c[k] - m2);
      }
    }
    if (fin[0]) m[0] = m[0] + sa / ln;
    if (fin[1]) m[1] = m[1] + sb / ln;
    if (fin[2]) m[2] = m[2] + sc / ln;
    const long double ma = static_cast<double>(m[0]);
    const long double mb = static_cast<double>(m[1]);
    const long double mc = static_cast<double>(m[2]);
    sa = sb = sc = 0.0L;
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
  long double wsum_[3] = {0.0L, 0.0L, 0.0L};  // see whole_window()
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
