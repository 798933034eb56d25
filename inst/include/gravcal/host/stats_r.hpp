// gravcal: window statistics in R's arithmetic (GGIR's numbers to the bit).
//
// Statistics policies for the window cutter (window_cutter.hpp) that give
// the numbers GGIR gets in R, to the last bit, so that GGIR's exact-equality
// rules (its duplicate-window filter) and thresholds decide the same way.
//
// RExactStats: means are differences of a running cumulative sum kept in
// long double and rounded to double at each window boundary (R's cumsum()
// followed by diff()), restarted by restart() where GGIR restarts its
// cumsum (each block it reads); the sd is R's var(): a two-pass mean with a
// correction pass, then the sum of squared deviations, all in long double
// (r_sd3(); the two-pass mean decided without its passes where a bound
// allows: r_var_means3(), kernels/r_mean.hpp). The caller lends the buffer
// that holds the open window's samples, so the core still allocates
// nothing.
//
// LazyRStats, its variant for GGIR's procedure: GGIR only compares the sds
// with its rest threshold and with the previous window's (its duplicate
// filter), so R's arithmetic runs only for those sds that such a comparison
// could tell from an sd in double, with bounds on both (fast_sd()); windows
// then reach the sink one window late (LazySd).
//
// R's accumulator: every policy and function here takes it as Acc, long
// double (RExactStats, LazyRStats) or double (for an R without long double;
// see r_arith.hpp). With Acc = double the kernels that replay long double
// (r_scan's vector variants, r_var_means3()) give way to the portable loops.
//
// A new window statistic of this arithmetic: its running sum here (add(),
// whole(), means()) and its field in WindowStats.
//
// Header-only, standard headers only, no heap.
#ifndef GRAVCAL_STATS_R_HPP
#define GRAVCAL_STATS_R_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "gravcal/kernels/kernels.hpp"
#include "gravcal/host/r_arith.hpp"
#include "gravcal/mcu/window_cutter.hpp"
#include "gravcal/mcu/window_stats.hpp"

namespace gravcal {

// for (k < n) s += v[k], in Acc, to the bit, by runs of equal values
// (add_repeated(), r_arith.hpp): a temperature repeats over a page or a
// block of the file. b: the grid of s, kept between calls.
template <class Acc>
void add_in_order(Acc& s, const double* v, std::size_t n, Binade<Acc>& b) {
  std::size_t i = 0;
  while (i < n) {
    const std::size_t j = kernels::active().run_end(v, i, n);
    add_repeated(s, v[i], static_cast<std::uint64_t>(j - i), b);
    i = j;
  }
}

// R's sd() of three columns of n (>= 2) values: the mean with R's
// correction pass, then the sum of squared deviations, in Acc. The
// three columns go through each pass together (independent sums, so the
// result is that of three separate calls). The means come without R's
// two passes where r_var_means3() can decide them (the same doubles).
// sum1: the first pass's sums when the caller has them already, or null.
// t, tsum: when not null, the n temperatures are added to *tsum in order
// (in the second pass, an independent chain nearly free there, or by runs
// with add_in_order()).
// Whether r_var_means3() can decide R's means for the accumulator Acc (its
// bound is long double's: for Acc = double, never).
template <class Acc>
bool r_var_means_available() {
  return std::is_same<Acc, long double>::value && kernels::r_var_means_available();
}

template <class Acc>
#if defined(__GNUC__)
__attribute__((noinline))
#endif
void r_sd3(const double* const* v, std::size_t n, const Acc* sum1, const double* t, Acc* tsum,
           double* out) {
  const Acc ln = static_cast<Acc>(n);
  const double* a = v[0];
  const double* b = v[1];
  const double* c = v[2];
  double mean[3];
  if (r_var_means_available<Acc>() && kernels::active().r_var_means3(v, n, mean)) {
    if (t != nullptr && tsum != nullptr) {
      Binade<Acc> bt;
      add_in_order(*tsum, t, n, bt);
    }
  } else {
    Acc sa = 0.0, sb = 0.0, sc = 0.0;
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
    Acc m[3] = {sa / ln, sb / ln, sc / ln};
    const bool fin[3] = {std::isfinite(static_cast<double>(m[0])),
                         std::isfinite(static_cast<double>(m[1])),
                         std::isfinite(static_cast<double>(m[2]))};
    sa = sb = sc = 0.0;
    const Acc m0 = m[0], m1 = m[1], m2 = m[2];
    if (t != nullptr && tsum != nullptr) {
      Acc st = *tsum;
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
  const Acc ma = mean[0], mb = mean[1], mc = mean[2];
  Acc sa = 0.0, sb = 0.0, sc = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const Acc da = a[k] - ma, db = b[k] - mb, dc = c[k] - mc;
    sa += da * da;
    sb += db * db;
    sc += dc * dc;
  }
  const Acc d = static_cast<Acc>(n - 1);
  out[0] = std::sqrt(static_cast<double>(sa / d));
  out[1] = std::sqrt(static_cast<double>(sb / d));
  out[2] = std::sqrt(static_cast<double>(sc / d));
}

template <class Acc>
class RExactStatsT {
 public:
  RExactStatsT() { reset(); }

  // The buffer for the open window's samples: at least 3 * (ceil(L) + 1)
  // doubles, outliving the policy. Returns false (and changes nothing) when
  // it is too small.
  bool lend(double* buffer, std::size_t capacity, double samples_per_window) {
    const std::size_t per_axis = static_cast<std::size_t>(std::ceil(samples_per_window)) + 1u;
    if (buffer == nullptr || capacity < 3u * per_axis) return false;
    buf_ = buffer;
    cap_ = per_axis;
    return true;
  }
  std::size_t per_axis() const { return cap_; }

  // A non-finite x, y or z is left out of its window, unless
  // keep_nonfinite() is on: then it enters R's cumulative sums as in GGIR's
  // (a NaN read from a file: the means of its window and of every later
  // window up to restart() are NaN, the sds of its window too).
  void keep_nonfinite(bool on) { keep_nonfinite_ = on; }

  void add(double xi, double yi, double zi, double ti) {
    if (std::isfinite(ti)) {
      csum_[4] += ti;
      ++c_.n_temp;
    }
    if (!keep_nonfinite_ && !WindowCounts::finite(xi, yi, zi)) {
      ++c_.n_invalid;
      return;
    }
    const double v[3] = {xi, yi, zi};
    for (int a = 0; a < 3; ++a) {
      buf_[static_cast<std::size_t>(a) * cap_ + static_cast<std::size_t>(c_.n_valid)] = v[a];
      csum_[a] += v[a];
    }
    // R: sqrt(Gx^2 + Gy^2 + Gz^2), each operation rounded to double.
    const double sq = xi * xi + yi * yi;
    csum_[3] += std::sqrt(sq + zi * zi);
    c_.add_valid(v);
  }

  // A whole window with R's exact sds.
  bool whole(const double* x, const double* y, const double* z, const double* t, std::size_t m,
             bool skip_zero) {
    Scan r;
    if (!scan(x, y, z, m, skip_zero, r)) return false;
    return commit(t, m, r, true);
  }

  template <class Sink>
  void close(WindowStats& s, Sink& sink) {
    means(s);
    if (c_.n_valid > 1) {
      if (whole_) {
        for (int a = 0; a < 3; ++a) s.sd[a] = wsd_[a];
      } else {
        r_sd3<Acc>(buffer_cols().p, static_cast<std::size_t>(c_.n_valid), nullptr, nullptr,
                   nullptr, s.sd);
      }
    } else {
      for (int a = 0; a < 3; ++a) s.sd[a] = NAN;
    }
    clear();
    sink(s);
  }

  template <class Sink>
  void finish(Sink&) {}
  void end_push() {}

  // R's cumulative sums start again (GGIR's next block).
  void restart() {
    for (int c = 0; c < 5; ++c) {
      csum_[c] = 0.0;
      cprev_[c] = 0.0;
    }
  }

  void reset() {
    restart();
    clear();
  }

 protected:
  struct Cols {
    const double* p[3];
  };

  // A whole window's first look (the kernel r_scan): R's running sums, with
  // the window's own sums where r_var_means3() cannot decide R's means (the
  // first pass of R's sd, nearly free there); min, max, the zero test and
  // the lanes for fast_sd(). False when the window must go sample by
  // sample (a sample to skip, or a non-finite value: the running sums stay
  // finite through windows of finite samples, so a non-finite sum here
  // means this window holds a non-finite value).
  struct Scan {
    kernels::RScanOutT<Acc> o;
    Acc c[5];
    bool has_w;  // o.w holds the window's sums
    const double* cols[3];
  };
  bool scan(const double* x, const double* y, const double* z, std::size_t m, bool skip_zero,
            Scan& r) const {
    for (int k = 0; k < 5; ++k) r.c[k] = csum_[k];
    r.has_w = !r_var_means_available<Acc>();
    if constexpr (std::is_same<Acc, long double>::value) {
      kernels::active().r_scan(x, y, z, m, r.c, r.has_w, r.o);
    } else {
      kernels::r_scan_scalar<Acc>(x, y, z, m, r.c, r.has_w, r.o);
    }
    r.cols[0] = x;
    r.cols[1] = y;
    r.cols[2] = z;
    return !(skip_zero && r.o.zero) &&
           std::isfinite(static_cast<double>(r.c[0] + r.c[1] + r.c[2] + r.c[3]));
  }

  // The whole window taken: the sds (R's var()) when `exact`, with the
  // temperature's running sum riding along their second pass (a single
  // chain of additions is cheaper there); else the temperature's sum by
  // runs (add_in_order()). All before anything changes: a non-finite
  // temperature still sends the window to the sample-by-sample path.
  bool commit(const double* t, std::size_t m, Scan& r, bool exact) {
    if (exact && m > 1) {
      r_sd3<Acc>(r.cols, m, r.has_w ? r.o.w : nullptr, t, &r.c[4], wsd_);
    } else if (t != nullptr) {
      Binade<Acc> b;
      add_in_order(r.c[4], t, m, b);
    }
    if (t != nullptr && !std::isfinite(static_cast<double>(r.c[4]))) return false;
    for (int k = 0; k < 5; ++k) csum_[k] = r.c[k];
    c_.set_whole(m, t != nullptr, r.o.lo, r.o.hi, r.o.repeats);
    whole_ = true;
    return true;
  }

  // Counts, min, max; means from the rounded cumulative sums (R's diff() of
  // its cumsum()), then the sums become the next window's start.
  void means(WindowStats& s) {
    c_.fill(s);
    double c[5];
    for (int k = 0; k < 5; ++k) c[k] = static_cast<double>(csum_[k]);
    const double nv = static_cast<double>(c_.n_valid);
    for (int a = 0; a < 3; ++a) s.mean[a] = c_.n_valid > 0 ? (c[a] - cprev_[a]) / nv : NAN;
    s.mean_norm = c_.n_valid > 0 ? (c[3] - cprev_[3]) / nv : NAN;
    s.temperature = c_.n_temp > 0 ? (c[4] - cprev_[4]) / static_cast<double>(c_.n_temp) : NAN;
    for (int k = 0; k < 5; ++k) cprev_[k] = c[k];
  }

  Cols buffer_cols() const {
    Cols v;
    for (int a = 0; a < 3; ++a) v.p[a] = buf_ + static_cast<std::size_t>(a) * cap_;
    return v;
  }

  void clear() {
    c_ = WindowCounts();
    whole_ = false;
  }

  double* buf_ = nullptr;  // the open window's valid samples, by axis
  std::size_t cap_ = 0;    // per axis
  Acc csum_[5];            // R's cumsum() of x, y, z, the norm, the temperature
  double cprev_[5];        // ... rounded, at the last window boundary
  WindowCounts c_;
  bool whole_ = false;     // the open window came whole: its sds in wsd_
  double wsd_[3] = {0.0, 0.0, 0.0};
  bool keep_nonfinite_ = false;  // non-finite samples enter the sums (GGIR's)
};

// The state of LazyRStats, which the caller keeps (the core allocates
// nothing, and a segmenter without it stays small): the window held back,
// the window being closed, and the last window given out with means when
// the held one has none.
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
    long double w[3] = {0, 0, 0};  // their sums in R's accumulator (its first
                                   // pass; a double's sums are held exactly)
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

// R's arithmetic for what GGIR's procedure can see of the sds: the sd of a
// window is R's to the bit when the window may be at rest (its R sd below
// max_sd on every axis, the rest rule's threshold), and when GGIR's
// duplicate filter could find it equal to the sd of the window before (the
// last one with a mean z and a mean norm); otherwise it is an sd in double
// whose distance from R's is bounded (fast_sd()), and which is on the same
// side of max_sd and of the neighbours' sds as R's. Means are always R's.
// Windows reach the sink one window late: finish() gives the last one.
template <class Acc>
class LazyRStatsT : public RExactStatsT<Acc> {
  using Base = RExactStatsT<Acc>;
  using typename Base::Cols;
  using typename Base::Scan;
  using Base::buf_;
  using Base::c_;
  using Base::cap_;
  using Base::whole_;
  using Base::wsd_;

 public:
  // After lend(): the threshold, the caller's state and a buffer (3 *
  // (ceil(L) + 1) doubles, outliving the policy) for the samples of the
  // window held back. Returns false (and changes nothing) when the buffer
  // is too small, no buffer was lent, or max_sd is not positive and finite.
  bool lazy(double max_sd, LazySd* state, double* buffer, std::size_t capacity) {
    if (buf_ == nullptr || !(max_sd > 0) || !std::isfinite(max_sd)) return false;
    if (state == nullptr || buffer == nullptr || capacity < 3u * cap_) return false;
    *state = LazySd();
    state->max_sd = max_sd;
    state->buf = buffer;
    lz_ = state;
    return true;
  }

  // A whole window, with its sds in double where R's cannot matter.
  bool whole(const double* x, const double* y, const double* z, const double* t, std::size_t m,
             bool skip_zero) {
    Scan r;
    if (!this->scan(x, y, z, m, skip_zero, r)) return false;
    LazySd::Window& h = lz_->cand;
    const bool fast = fast_sd(r.cols, m, r.o.lo, r.o.hi, r.o.ls, h);
    if (!this->commit(t, m, r, !fast)) return false;
    h.fast = fast;
    if (fast) {
      for (int a = 0; a < 3; ++a) {
        h.col[a] = r.cols[a];
        h.w[a] = r.o.w[a];
      }
      h.m = m;
      h.has_w = r.has_w;
    }
    return true;
  }

  template <class Sink>
  void close(WindowStats& s, Sink& sink) {
    LazySd::Window& h = lz_->cand;
    h.s = s;
    this->means(h.s);
    if (c_.n_valid > 1) {
      if (whole_) {
        for (int a = 0; a < 3; ++a) h.s.sd[a] = h.fast ? h.sd[a] : wsd_[a];
      } else {
        // the same choice as whole() makes, on the same values
        const Cols v = this->buffer_cols();
        const std::size_t nv = static_cast<std::size_t>(c_.n_valid);
        double ls[3][4] = {};
        kernels::lane_sums(v.p, nv, ls);
        h.fast = fast_sd(v.p, nv, c_.min, c_.max, ls, h);
        if (h.fast) {
          for (int a = 0; a < 3; ++a) {
            h.s.sd[a] = h.sd[a];
            h.col[a] = v.p[a];
          }
          h.m = nv;
          h.has_w = false;
        } else {
          r_sd3<Acc>(v.p, nv, nullptr, nullptr, nullptr, h.s.sd);
        }
      }
    } else {
      h.fast = false;
      for (int a = 0; a < 3; ++a) h.s.sd[a] = NAN;
    }
    this->clear();
    deliver(h, sink);
  }

  // Gives the window held back.
  template <class Sink>
  void finish(Sink& sink) {
    if (lz_ == nullptr || !lz_->held_on) return;
    if (!lz_->held.na) keep_as_reference(lz_->held);
    lz_->held_on = false;
    sink(lz_->held.s);
  }

  // The held window's samples are the caller's: keep a copy.
  void end_push() {
    if (lz_ != nullptr && lz_->held_on && lz_->held.fast) keep_samples(lz_->held);
  }

  void reset() {
    Base::reset();
    if (lz_ != nullptr) {
      lz_->held_on = false;
      lz_->ref_on = false;
    }
  }

 private:
  // The sds of n (>= 2) samples in double: about the mean in double (ls:
  // the values summed in four lanes by position; lane_total() of them, over
  // n), the squared deviations summed in four lanes by position (sq_dev()). Error
  // bounds as r_sd_below()'s (r_arith.hpp), with u = 2^-53 and M = max |x|:
  // this sd^2 is (s2 + n / (n - 1) dF^2) (1 + f), |dF| <= (n / 4 + 4) u M
  // (each lane a recursive sum of at most n / 4 + 1 values, two levels
  // joining the lanes, one division), |f| <= (n + 4) u (times 1.01); R's
  // is (s2 + n / (n - 1) dR^2) (1 + e), |dR| <= (2 u + (4 n + 8) 2^-64) M,
  // |e| <= (n + 3) 2^-64 + 3 u (2^-53 for 2^-64 with Acc = double: still
  // within the bounds below). With eps = 4 (n + 16) u and dm = 4 (n + 8)
  // u M + 1e-300 (covering either side), R's sd^2 lies in [(v / (1 + eps) -
  // 2 dm^2) (1 - eps), (v / (1 - eps) + 2 dm^2) (1 + eps)], v this sd^2.
  // Returns true (the sds in double may stand) only when some axis is
  // surely above max_sd (the window is not at rest, whatever else) and the
  // bounds apply (n u small, M within [1e-100, 1e100] or 0); deliver() then
  // checks the neighbour.
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
    const double mu[3] = {lane_total(ls[0]) / dn, lane_total(ls[1]) / dn, lane_total(ls[2]) / dn};
    double q[3][4];
    sq_dev(v, n, mu, q);
    const long double u = std::ldexp(1.0L, -53);
    const long double eps = 4.0L * (ln + 16.0L) * u;
    const long double t2 = static_cast<long double>(lz_->max_sd) * lz_->max_sd;
    bool above = false;
    for (int a = 0; a < 3; ++a) {
      const double var = lane_total(q[a]) / static_cast<double>(n - 1);
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
    Acc w[3] = {static_cast<Acc>(h.w[0]), static_cast<Acc>(h.w[1]), static_cast<Acc>(h.w[2])};
    r_sd3<Acc>(h.col, h.m, h.has_w ? w : nullptr, nullptr, nullptr, h.s.sd);
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

  // A window kept in double whose samples are not the policy's to keep
  // (the caller's, or the open window's buffer): copied.
  void keep_samples(LazySd::Window& h) {
    if (h.col[0] == lz_->buf) return;
    for (int a = 0; a < 3; ++a) {
      double* d = lz_->buf + static_cast<std::size_t>(a) * cap_;
      std::memcpy(d, h.col[a], h.m * sizeof(double));
      h.col[a] = d;
    }
  }

  // A completed window, held back one window, so that a tie with the next
  // can still make the sds of both R's.
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
    if (z.held.fast && z.held.col[0] == buf_) keep_samples(z.held);
  }

  LazySd* lz_ = nullptr;
};

// R with long double (R's default)
using RExactStats = RExactStatsT<long double>;
using LazyRStats = LazyRStatsT<long double>;

}  // namespace gravcal

#endif  // GRAVCAL_STATS_R_HPP
