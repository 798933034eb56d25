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
//   runs.
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
  template <class Sink>
  void push(const double* x, const double* y, const double* z,
            const double* t, std::size_t n, Sink&& sink) {
    for (std::size_t i = 0; i < n; ++i) {
      const double xi = x[i], yi = y[i], zi = z[i];
      const std::int64_t at = seen_++;
      if (skip_zero_ && xi == 0.0 && yi == 0.0 && zi == 0.0) {
        ++skipped_zero_;
        continue;
      }
      if (n_ == 0) first_ = at;
      add(xi, yi, zi, t ? t[i] : NAN);
      ++retained_;
      if (retained_ == next_boundary_) {
        WindowStats s;
        close(s);
        sink(s);
      }
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

  void clear_window() {
    n_ = 0;
    n_invalid_ = 0;
    n_valid_ = 0;
    n_temp_ = 0;
    sum_norm_ = 0.0;
    sum_temp_ = 0.0;
    first_ = -1;
    for (int a = 0; a < 3; ++a) {
      shift_[a] = 0.0;
      sum_[a] = 0.0;
      sumsq_[a] = 0.0;
      min_[a] = INFINITY;
      max_[a] = -INFINITY;
    }
  }

  void add(double xi, double yi, double zi, double ti) {
    ++n_;
    if (std::isfinite(ti)) {
      sum_temp_ += ti;
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
    ++n_valid_;
    for (int a = 0; a < 3; ++a) {
      const double d = v[a] - shift_[a];
      sum_[a] += d;
      sumsq_[a] += d * d;
      if (v[a] < min_[a]) min_[a] = v[a];
      if (v[a] > max_[a]) max_[a] = v[a];
    }
    sum_norm_ += std::sqrt(xi * xi + yi * yi + zi * zi);
  }

  void close(WindowStats& s) {
    s.index = window_;
    s.first = first_;
    s.n = static_cast<std::int32_t>(n_);
    s.n_invalid = static_cast<std::int32_t>(n_invalid_);
    const double nv = static_cast<double>(n_valid_);
    for (int a = 0; a < 3; ++a) {
      if (n_valid_ > 0) {
        const double m = sum_[a] / nv;
        s.mean[a] = shift_[a] + m;
        s.min[a] = min_[a];
        s.max[a] = max_[a];
      } else {
        s.mean[a] = NAN;
        s.min[a] = NAN;
        s.max[a] = NAN;
      }
      if (n_valid_ > 1) {
        double ss = sumsq_[a] - sum_[a] * sum_[a] / nv;
        if (ss < 0.0) ss = 0.0;
        s.sd[a] = std::sqrt(ss / (nv - 1.0));
      } else {
        s.sd[a] = NAN;
      }
    }
    s.mean_norm = n_valid_ > 0 ? sum_norm_ / nv : NAN;
    s.temperature = n_temp_ > 0 ? sum_temp_ / static_cast<double>(n_temp_) : NAN;
    if (rbuf_ != nullptr) close_r(s);
    ++window_;
    next_boundary_ = boundary(window_ + 1);
    clear_window();
  }

  // Means from the rounded cumulative sums, sds as R's var() computes them.
  void close_r(WindowStats& s) {
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
    for (int a = 0; a < 3; ++a) {
      s.sd[a] = n_valid_ > 1
                    ? r_sd(rbuf_ + static_cast<std::size_t>(a) * rcap_, n_valid_)
                    : NAN;
    }
  }

  static double r_sd(const double* v, std::int64_t n) {
    const long double ln = static_cast<long double>(n);
    long double sum = 0.0L;
    for (std::int64_t k = 0; k < n; ++k) sum += v[k];
    long double m = sum / ln;
    if (std::isfinite(static_cast<double>(m))) {
      sum = 0.0L;
      for (std::int64_t k = 0; k < n; ++k) sum += (v[k] - m);
      m = m + sum / ln;
    }
    const long double mean = static_cast<double>(m);
    long double ss = 0.0L;
    for (std::int64_t k = 0; k < n; ++k) {
      const long double d = v[k] - mean;
      ss += d * d;
    }
    const double var = static_cast<double>(ss / static_cast<long double>(n - 1));
    return std::sqrt(var);
  }

  double L_;
  bool skip_zero_;
  double* rbuf_ = nullptr;
  std::size_t rcap_ = 0;
  long double csum_[5];
  double cprev_[5];
  std::int64_t window_, retained_, seen_, skipped_zero_, next_boundary_, first_;
  std::int64_t n_, n_invalid_, n_valid_, n_temp_;
  double shift_[3], sum_[3], sumsq_[3], min_[3], max_[3];
  double sum_norm_, sum_temp_;
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
