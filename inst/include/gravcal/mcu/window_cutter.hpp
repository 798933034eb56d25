// gravcal: the window cutter.
//
// Cuts a sample stream into consecutive, non-overlapping windows of a fixed
// duration and hands each window's samples to a statistics policy (Stats),
// which gives the window's statistics out (WindowStats). Samples arrive in
// chunks of any size; the windows, and every bit of their statistics, are
// the same however the stream is split, because the state carried between
// chunks is the complete state of the open window.
//
// Window k holds the retained samples with stream index in
// [round(k L), round((k + 1) L)), L = duration * sampling rate, so a rate
// that does not give a whole number of samples per window (85.7 Hz) keeps the
// right duration on average. Samples whose x, y and z are all exactly zero
// (ActiGraph idle sleep) can be skipped before counting, as GGIR does.
//
// A window that lies whole inside a chunk goes to the policy in one call
// (whole(), one tight loop over the caller's arrays); the policy may refuse
// it (a sample to skip, or a non-finite value), and then it goes sample by
// sample (add()). Both give the same numbers, so the results depend neither
// on which one ran nor on the chunking.
//
// A statistics policy (stats_streaming.hpp, stats_r.hpp) has:
//   void add(double x, double y, double z, double t)   one retained sample
//   bool whole(x, y, z, t, m, skip_zero)   m retained samples in one call, or
//                          false (changing nothing) for the sample path
//   void close(WindowStats& s, Sink& sink)   fills s's statistics (index,
//                          first and n are set), gives it out, clears
//   void finish(Sink& sink)   gives out what close() held back (if any)
//   void end_push()         the caller's arrays are about to go
//   void restart()          new_block(): at a window boundary
//   void reset()
// and keeps its counts, min and max in a WindowCounts.
//
// Header-only, standard headers only, no heap (the microcontroller tier).
#ifndef GRAVCAL_WINDOW_CUTTER_HPP
#define GRAVCAL_WINDOW_CUTTER_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "gravcal/mcu/window_stats.hpp"

namespace gravcal {

// An idle-sleep sample (ActiGraph): x, y and z exactly zero.
inline bool all_zero(double x, double y, double z) { return x == 0.0 && y == 0.0 && z == 0.0; }

// A zero minimum (maximum) of m samples as the sequential rule (v < lo ? v :
// lo from the first sample) leaves it: the first zero of the column, with
// its sign (a loop over lanes may have kept the other one). Any other value
// is the same in any order.
inline void zero_signs(const double* const* col, std::size_t m, double* lo, double* hi) {
  for (int a = 0; a < 3; ++a) {
    if (lo[a] == 0.0 || hi[a] == 0.0) {
      std::size_t j = 0;
      while (j < m && col[a][j] != 0.0) ++j;
      if (j < m && lo[a] == 0.0) lo[a] = col[a][j];
      if (j < m && hi[a] == 0.0) hi[a] = col[a][j];
    }
  }
}

// What every arithmetic keeps of the open window besides its sums: the
// counts, min and max (the sequential rule: v < min ? v : min).
struct WindowCounts {
  std::int64_t n_invalid = 0;  // samples with a non-finite x, y or z
  std::int64_t n_valid = 0;
  std::int64_t n_temp = 0;     // finite temperatures
  std::int64_t n_repeat = 0;   // valid samples equal to the valid one before
  double prev[3] = {0.0, 0.0, 0.0};  // the last valid sample
  double min[3] = {INFINITY, INFINITY, INFINITY};
  double max[3] = {-INFINITY, -INFINITY, -INFINITY};

  static bool finite(double x, double y, double z) {
    return std::isfinite(x) && std::isfinite(y) && std::isfinite(z);
  }

  // A valid sample's min and max; returns its lane (position & 3).
  int add_valid(const double* v) {
    if (n_valid > 0 && v[0] == prev[0] && v[1] == prev[1] && v[2] == prev[2]) ++n_repeat;
    for (int a = 0; a < 3; ++a) {
      prev[a] = v[a];
      if (v[a] < min[a]) min[a] = v[a];
      if (v[a] > max[a]) max[a] = v[a];
    }
    return static_cast<int>(n_valid++ & 3);
  }

  // A whole window of m valid samples with min lo and max hi, `repeats` of
  // them equal to the one before (count_repeats()).
  void set_whole(std::size_t m, bool temperature, const double* lo, const double* hi,
                 std::int64_t repeats) {
    n_invalid = 0;
    n_repeat = repeats;
    n_valid = static_cast<std::int64_t>(m);
    n_temp = temperature ? n_valid : 0;
    for (int a = 0; a < 3; ++a) {
      min[a] = lo[a];
      max[a] = hi[a];
    }
  }

  void fill(WindowStats& s) const {
    s.n_invalid = static_cast<std::int32_t>(n_invalid);
    s.n_repeat = n_repeat;
    for (int a = 0; a < 3; ++a) {
      s.min[a] = n_valid > 0 ? min[a] : NAN;
      s.max[a] = n_valid > 0 ? max[a] : NAN;
    }
  }
};

template <class Stats>
class WindowCutter {
 public:
  // samples_per_window: L = duration (s) * sampling rate (Hz), at least 1.
  // skip_zero: drop samples with x = y = z = 0 before windowing.
  WindowCutter(double samples_per_window, bool skip_zero)
      : L_(samples_per_window < 1.0 ? 1.0 : samples_per_window), skip_zero_(skip_zero) {
    reset();
  }

  Stats& stats() { return stats_; }
  const Stats& stats() const { return stats_; }
  double samples_per_window() const { return L_; }

  void reset() {
    window_ = 0;
    retained_ = 0;
    seen_ = 0;
    skipped_zero_ = 0;
    n_ = 0;
    first_ = -1;
    next_boundary_ = boundary(1);
    stats_.reset();
  }

  // At a window boundary only (no open window): the policy's restart (R's
  // cumulative sums, as GGIR at each block it reads); false otherwise.
  bool new_block() {
    if (n_ != 0) return false;
    stats_.restart();
    return true;
  }

  // Push a chunk of n samples. t may be null (no temperature). sink(stats) is
  // called once for every window given out, in order.
  template <class Sink>
  void push(const double* x, const double* y, const double* z, const double* t, std::size_t n,
            Sink&& sink) {
    std::size_t i = 0;
    bool try_whole = true;
    while (i < n) {
      if (n_ == 0 && try_whole) {
        const std::int64_t need = next_boundary_ - retained_;
        if (need > 0 && static_cast<std::uint64_t>(need) <= n - i) {
          const std::size_t m = static_cast<std::size_t>(need);
          if (stats_.whole(x + i, y + i, z + i, t ? t + i : nullptr, m, skip_zero_)) {
            first_ = seen_;
            seen_ += need;
            retained_ += need;
            n_ = need;
            close(sink);
            i += m;
            continue;
          }
          try_whole = false;  // until this window closes
        }
      }
      if (step(x[i], y[i], z[i], t ? t[i] : NAN, sink)) try_whole = true;
      ++i;
    }
    stats_.end_push();
  }

  // Gives what the policy held back (lazy R sds: the last window).
  template <class Sink>
  void finish(Sink&& sink) {
    stats_.finish(sink);
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
    if (skip_zero_ && all_zero(xi, yi, zi)) {
      ++skipped_zero_;
      return false;
    }
    if (n_ == 0) first_ = at;
    stats_.add(xi, yi, zi, ti);
    ++n_;
    ++retained_;
    if (retained_ != next_boundary_) return false;
    close(sink);
    return true;
  }

  template <class Sink>
  void close(Sink& sink) {
    WindowStats s;
    s.index = window_;
    s.first = first_;
    s.n = static_cast<std::int32_t>(n_);
    ++window_;
    next_boundary_ = boundary(window_ + 1);
    n_ = 0;
    first_ = -1;
    stats_.close(s, sink);
  }

  double L_;
  bool skip_zero_;
  std::int64_t window_ = 0, retained_ = 0, seen_ = 0, skipped_zero_ = 0, next_boundary_ = 0;
  std::int64_t first_ = -1, n_ = 0;
  Stats stats_;
};

}  // namespace gravcal

#endif  // GRAVCAL_WINDOW_CUTTER_HPP
