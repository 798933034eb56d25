// gravcal: the streaming window statistics (what a microcontroller runs).
//
// A statistics policy for the window cutter (window_cutter.hpp): sums about
// the first valid sample of the window (shifted data algorithm), exact to
// rounding for the small variances of rest windows, with no storage beyond a
// few sums. Each sum is kept in four lanes by the sample's position in the
// window and joined as (0 + 1) + (2 + 3) (lane_total(), window_stats.hpp),
// so that a whole window can be summed four samples a step with the same
// bits as sample by sample.
//
// A new window statistic of this arithmetic: its sum here (add(), the
// whole-window loop stream_window(), fill()) and its field in WindowStats.
//
// Header-only, standard headers only, no heap (the microcontroller tier).
#ifndef GRAVCAL_STATS_STREAMING_HPP
#define GRAVCAL_STATS_STREAMING_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "gravcal/mcu/window_cutter.hpp"
#include "gravcal/mcu/window_stats.hpp"

namespace gravcal {

// A whole window's streaming sums: per axis the sums of d and d^2, d = v -
// v[0], in lanes; the norms' and the temperatures' sums in lanes; min, max
// and whether some sample is all zeros. With a non-finite sample the sums
// are not finite and min and max are not defined.
struct StreamSums {
  double s[3][4] = {}, q[3][4] = {}, lo[3] = {}, hi[3] = {}, nrm[4] = {}, st[4] = {};
  bool zero = false;
};

// Samples [k, m) sample by sample (as StreamingStats::add()), continuing o
// and lo, hi, zero; then o's min and max (zero_signs()) and zero test.
inline void stream_tail(const double* const* col, const double* t, std::size_t k, std::size_t m,
                        const double* h, StreamSums& o, double* lo, double* hi, bool& zero) {
  for (; k < m; ++k) {
    const int l = static_cast<int>(k & 3);
    const double xi = col[0][k], yi = col[1][k], zi = col[2][k];
    zero = zero || all_zero(xi, yi, zi);
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

// stream_window(x, y, z, t, m, o): the sums of a whole window of m >= 1
// samples (t may be null). An axis at a time, then the norms, the
// temperatures and the zero test, each lane in a local of its own (sums kept
// in the arrays would wait on their own stores), four samples a step, in
// the same order as sample by sample.
inline void stream_window(const double* x, const double* y, const double* z, const double* t,
                          std::size_t m, StreamSums& o) {
  const double* col[3] = {x, y, z};
  const std::size_t m4 = m & ~std::size_t(3);
  o = StreamSums();
  for (int a = 0; a < 3; ++a) {
    const double* v = col[a];
    const double h = v[0];
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0, q0 = 0.0, q1 = 0.0, q2 = 0.0, q3 = 0.0;
    // min and max by lanes too: the same values in any order, but a zero's
    // sign (zero_signs() in stream_tail())
    double lo[4] = {h, h, h, h}, hi[4] = {h, h, h, h};
    for (std::size_t k = 0; k < m4; k += 4) {
      const double d0 = v[k] - h, d1 = v[k + 1] - h, d2 = v[k + 2] - h, d3 = v[k + 3] - h;
      s0 += d0;
      q0 += d0 * d0;
      s1 += d1;
      q1 += d1 * d1;
      s2 += d2;
      q2 += d2 * d2;
      s3 += d3;
      q3 += d3 * d3;
      for (int l = 0; l < 4; ++l) {
        lo[l] = v[k + l] < lo[l] ? v[k + l] : lo[l];
        hi[l] = v[k + l] > hi[l] ? v[k + l] : hi[l];
      }
    }
    const double s4[4] = {s0, s1, s2, s3}, q4[4] = {q0, q1, q2, q3};
    o.lo[a] = h;
    o.hi[a] = h;
    for (int l = 0; l < 4; ++l) {
      o.s[a][l] = s4[l];
      o.q[a][l] = q4[l];
      o.lo[a] = lo[l] < o.lo[a] ? lo[l] : o.lo[a];
      o.hi[a] = hi[l] > o.hi[a] ? hi[l] : o.hi[a];
    }
  }
  double n0 = 0.0, n1 = 0.0, n2 = 0.0, n3 = 0.0;
  for (std::size_t k = 0; k < m4; k += 4) {
    n0 += std::sqrt(x[k] * x[k] + y[k] * y[k] + z[k] * z[k]);
    n1 += std::sqrt(x[k + 1] * x[k + 1] + y[k + 1] * y[k + 1] + z[k + 1] * z[k + 1]);
    n2 += std::sqrt(x[k + 2] * x[k + 2] + y[k + 2] * y[k + 2] + z[k + 2] * z[k + 2]);
    n3 += std::sqrt(x[k + 3] * x[k + 3] + y[k + 3] * y[k + 3] + z[k + 3] * z[k + 3]);
  }
  o.nrm[0] = n0;
  o.nrm[1] = n1;
  o.nrm[2] = n2;
  o.nrm[3] = n3;
  if (t != nullptr) {
    double t0 = 0.0, t1 = 0.0, t2 = 0.0, t3 = 0.0;
    for (std::size_t k = 0; k < m4; k += 4) {
      t0 += t[k];
      t1 += t[k + 1];
      t2 += t[k + 2];
      t3 += t[k + 3];
    }
    o.st[0] = t0;
    o.st[1] = t1;
    o.st[2] = t2;
    o.st[3] = t3;
  }
  bool zero = false;
  for (std::size_t k = 0; k < m4 && !zero; ++k) zero = all_zero(x[k], y[k], z[k]);
  const double h[3] = {x[0], y[0], z[0]};
  double lo[3] = {o.lo[0], o.lo[1], o.lo[2]}, hi[3] = {o.hi[0], o.hi[1], o.hi[2]};
  stream_tail(col, t, m4, m, h, o, lo, hi, zero);
}

// The whole-window loop: this header's scalar stream_window(); the
// segmenter (segmenter.hpp) plugs in the kernel table's choice.
struct ScalarStreamWindow {
  static void run(const double* x, const double* y, const double* z, const double* t,
                  std::size_t m, StreamSums& o) {
    stream_window(x, y, z, t, m, o);
  }
};

template <class Whole = ScalarStreamWindow>
class StreamingStatsT {
 public:
  StreamingStatsT() { clear(); }

  void add(double xi, double yi, double zi, double ti) {
    if (std::isfinite(ti)) sum_temp_[c_.n_temp++ & 3] += ti;
    if (!WindowCounts::finite(xi, yi, zi)) {
      ++c_.n_invalid;
      return;
    }
    const double v[3] = {xi, yi, zi};
    if (c_.n_valid == 0) {
      for (int a = 0; a < 3; ++a) shift_[a] = v[a];
    }
    const int lane = c_.add_valid(v);
    for (int a = 0; a < 3; ++a) {
      const double d = v[a] - shift_[a];
      sum_[a][lane] += d;
      sumsq_[a][lane] += d * d;
    }
    sum_norm_[lane] += std::sqrt(xi * xi + yi * yi + zi * zi);
  }

  // A whole window of m samples in one pass (Whole::run()); false
  // (nothing changed) for a sample to skip or a non-finite value.
  bool whole(const double* x, const double* y, const double* z, const double* t, std::size_t m,
             bool skip_zero) {
    StreamSums a;
    Whole::run(x, y, z, t, m, a);
    double all = lane_total(a.nrm);
    for (int k = 0; k < 3; ++k) all += lane_total(a.s[k]) + lane_total(a.q[k]);
    if ((skip_zero && a.zero) || !std::isfinite(all) ||
        (t != nullptr && !std::isfinite(lane_total(a.st)))) {
      return false;
    }
    c_.set_whole(m, t != nullptr, a.lo, a.hi, count_repeats(x, y, z, m));
    for (int k = 0; k < 3; ++k) {
      shift_[k] = k == 0 ? x[0] : k == 1 ? y[0] : z[0];
      for (int l = 0; l < 4; ++l) {
        sum_[k][l] = a.s[k][l];
        sumsq_[k][l] = a.q[k][l];
      }
    }
    for (int l = 0; l < 4; ++l) {
      sum_norm_[l] = a.nrm[l];
      sum_temp_[l] = a.st[l];
    }
    return true;
  }

  template <class Sink>
  void close(WindowStats& s, Sink& sink) {
    fill(s);
    clear();
    sink(s);
  }

  template <class Sink>
  void finish(Sink&) {}
  void end_push() {}
  void restart() {}
  void reset() { clear(); }

  // The open window's statistics.
  void fill(WindowStats& s) const {
    c_.fill(s);
    const double nv = static_cast<double>(c_.n_valid);
    for (int a = 0; a < 3; ++a) {
      s.mean[a] = c_.n_valid > 0 ? shift_[a] + lane_total(sum_[a]) / nv : NAN;
      if (c_.n_valid > 1) {
        const double sa = lane_total(sum_[a]);
        double ss = lane_total(sumsq_[a]) - sa * sa / nv;
        if (ss < 0.0) ss = 0.0;
        s.sd[a] = std::sqrt(ss / (nv - 1.0));
      } else {
        s.sd[a] = NAN;
      }
    }
    s.mean_norm = c_.n_valid > 0 ? lane_total(sum_norm_) / nv : NAN;
    s.temperature = c_.n_temp > 0 ? lane_total(sum_temp_) / static_cast<double>(c_.n_temp) : NAN;
  }

 private:
  void clear() {
    c_ = WindowCounts();
    for (int a = 0; a < 3; ++a) {
      shift_[a] = 0.0;
      for (int l = 0; l < 4; ++l) {
        sum_[a][l] = 0.0;
        sumsq_[a][l] = 0.0;
      }
    }
    for (int l = 0; l < 4; ++l) {
      sum_norm_[l] = 0.0;
      sum_temp_[l] = 0.0;
    }
  }

  WindowCounts c_;
  double shift_[3], sum_[3][4], sumsq_[3][4], sum_norm_[4], sum_temp_[4];  // lanes
};

using StreamingStats = StreamingStatsT<>;

// The streaming segmenter of the microcontroller tier.
using StreamSegmenter = WindowCutter<StreamingStats>;

}  // namespace gravcal

#endif  // GRAVCAL_STATS_STREAMING_HPP
