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
//   the window closes, so that whole windows can be summed several samples
//   per instruction (kernels/window.hpp) with the same result as sample by
//   sample.
// - R-compatible (use_r_arithmetic()): the numbers GGIR gets in R, to the
//   last bit, so that GGIR's exact-equality rules (its duplicate-window
//   filter) and thresholds decide the same way. Means are differences of a
//   running cumulative sum kept in long double and rounded to double at each
//   window boundary (R's cumsum() followed by diff()), restarted by
//   new_block() where GGIR restarts its cumsum (each block it reads); the sd
//   is R's var(): a two-pass mean with a correction pass, then the sum of
//   squared deviations, all in long double (the two-pass mean decided
//   without its passes where a bound allows: r_var_means3(),
//   kernels/r_mean.hpp).
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

#include "kernels.hpp"
#include "r_arith.hpp"

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

// for (k < n) s += v[k], in long double, to the bit, by runs of equal values
// (add_repeated(), r_arith.hpp): a temperature repeats over a page or a
// block of the file. b: the grid of s, kept between calls.
inline void add_in_order(long double& s, const double* v, std::size_t n, Binade& b) {
  std::size_t i = 0;
  while (i < n) {
    const std::size_t j = kernels::active().run_end(v, i, n);
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
    kernels::StreamSums a;
    kernels::RScanOut r;
    bool has_w = false;  // r.w holds the window's sums (for r_sd3())
    bool fast = false;
    if (rbuf_ == nullptr) {
      kernels::active().stream_window(x, y, z, t, m, a);
      double all = lanes(a.nrm);
      for (int k = 0; k < 3; ++k) all += lanes(a.s[k]) + lanes(a.q[k]);
      if ((skip_zero_ && a.zero) || !std::isfinite(all) ||
          (t != nullptr && !std::isfinite(lanes(a.st)))) {
        return false;
      }
    } else {
      // R's running sums, with the window's own sums where r_var_means3()
      // cannot decide R's means (the first pass of R's sd, nearly free
      // there); min, max, the zero test and the lanes for fast_sd()
      long double c[5];
      for (int k = 0; k < 5; ++k) c[k] = csum_[k];
      has_w = !kernels::r_var_means_available();
      kernels::active().r_scan(x, y, z, m, c, has_w, r);
      // the running sums stay finite through windows of finite samples
      // (add() leaves out non-finite ones), so a non-finite sum here means
      // this window holds a non-finite value
      if ((skip_zero_ && r.zero) ||
          !std::isfinite(static_cast<double>(c[0] + c[1] + c[2] + c[3]))) {
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
        r_sd3(cols, m, has_w ? r.w : nullptr, t, &c[4], wsd_);
      } else if (t != nullptr) {
        Binade b;
        add_in_order(c[4], t, m, b);
      }
      if (t != nullptr && !std::isfinite(static_cast<double>(c[4]))) return false;
      for (int k = 0; k < 5; ++k) csum_[k] = c[k];
      a = kernels::StreamSums();  // sums replaced by close_r()
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
      h.has_w = has_w;
    }
    deliver(h, sink);
    return true;
  }

  // The sds of n (>= 2) samples in double, for lazy_r_sd(): about the mean
  // in double (ls: the values summed in four lanes by position,
  // kernels::lane_sums() or the kernel r_scan; lanes() of them, over n),
  // the squared deviations summed in four lanes by position (sq_dev()). Error bounds as
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
    double q[3][4];
    sq_dev(v, n, mu, q);
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

  // The squared deviations (v[a][k] - mu[a])^2 of three columns of n
  // values, summed in four lanes by position into q, each lane in a local of
  // its own, four values a step. (Vector versions saved less than 5 % of a
  // week's calibration: bench/results/ab-kernels.md.)
  static void sq_dev(const double* const* v, std::size_t n, const double* mu, double (*q)[4]) {
    for (int a = 0; a < 3; ++a) {
      const double* x = v[a];
      const double m = mu[a];
      double l0 = 0.0, l1 = 0.0, l2 = 0.0, l3 = 0.0;
      std::size_t k = 0;
      for (; k + 4 <= n; k += 4) {
        const double d0 = x[k] - m, d1 = x[k + 1] - m, d2 = x[k + 2] - m, d3 = x[k + 3] - m;
        l0 += d0 * d0;
        l1 += d1 * d1;
        l2 += d2 * d2;
        l3 += d3 * d3;
      }
      double l[4] = {l0, l1, l2, l3};
      for (; k < n; ++k) {
        const double d = x[k] - m;
        l[k & 3] += d * d;
      }
      for (int j = 0; j < 4; ++j) q[a][j] = l[j];
    }
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
        kernels::lane_sums(v, nv, ls);
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
    if (kernels::active().r_var_means3(v, n, mean)) {
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
