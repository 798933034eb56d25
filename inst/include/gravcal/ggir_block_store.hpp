// gravcal: the samples of one of GGIR part 1's blocks, held in the core.
//
// GGIR's g.getmeta() reads a recording in blocks of about a day; each block
// is the previous block's last samples (the carry: those past its last
// whole long epoch), then the samples read. Its epoch signals
// (ggir_epochs.hpp) are computed over the block's first whole long epochs,
// and the rest is carried on. BlockStore holds that block as columns the
// decoder writes into directly, so that no block passes through R: R keeps
// GGIR's decisions (when a block is the last, the start, the gap between
// blocks), the store does what they ask.
//
// Memory: the columns grow by a quarter as the decoder's samples come
// (never sized by a number read from the file), one column at a time, and
// keep their capacity from block to block: a block costs about 1.25 times
// its samples' columns. Time stamps are kept as a column only when asked
// (GGIR's time-gap imputation needs them); otherwise the block's first time
// and its last two are kept, which is all GGIR's block logic reads.
#ifndef GRAVCAL_GGIR_BLOCK_STORE_HPP
#define GRAVCAL_GGIR_BLOCK_STORE_HPP

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "decode.hpp"
#include "r_arith.hpp"

namespace gravcal {
namespace ggir_part1 {

// A linear calibration in place, as gravcal's apply_model() computes it in
// R ("matrix" arithmetic): u = v + offset; a_i = K[i][0] u_0 + K[i][1] u_1
// + K[i][2] u_2, summed left to right, then + (t - meantemp) tempoffset_i.
// The same bits as R's vectorised expression (one rounding per operation).
struct LinearModel {
  double K[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // K[row][column]
  double offset[3] = {0, 0, 0};
  bool temp = false;
  double meantemp = 0;
  double tempoffset[3] = {0, 0, 0};
};

inline void apply_linear(const LinearModel& m, double* x, double* y, double* z,
                         const double* t, std::size_t n) {
  if (m.temp && t == nullptr) throw std::runtime_error("the model's temperature term needs a temperature");
  for (std::size_t i = 0; i < n; ++i) {
    const double u[3] = {x[i] + m.offset[0], y[i] + m.offset[1], z[i] + m.offset[2]};
    double a[3];
    for (int r = 0; r < 3; ++r) {
      double s = m.K[r][0] * u[0];
      s = s + m.K[r][1] * u[1];
      s = s + m.K[r][2] * u[2];
      if (m.temp) {
        const double dt = t[i] - m.meantemp;
        s = s + dt * m.tempoffset[r];
      }
      a[r] = s;
    }
    x[i] = a[0];
    y[i] = a[1];
    z[i] = a[2];
  }
}

class BlockStore {
 public:
  static constexpr int kX = 0, kY = 1, kZ = 2, kT = 3, kTime = 4, kLight = 5, kCols = 6;

  BlockStore(bool temperature, bool time, bool light) {
    has_[kX] = has_[kY] = has_[kZ] = true;
    has_[kT] = temperature;
    has_[kTime] = time;
    has_[kLight] = light;
  }

  bool has(int c) const { return has_[c]; }
  std::size_t size() const { return n_; }
  double* col(int c) { return has_[c] ? cols_[c].data() : nullptr; }
  const double* col(int c) const { return has_[c] ? cols_[c].data() : nullptr; }

  // The times GGIR's block logic reads, whether or not a time column is
  // kept: the first row read by the last read(), and the store's last two
  // rows (NaN where there is none, or the decoder gives no time).
  double first_read_time() const { return first_time_; }
  double tail_time(std::size_t back) const {
    if (back >= n_) return nan();
    if (has_[kTime]) return cols_[kTime][n_ - 1 - back];
    return back < 2 ? tail_time_[back] : nan();
  }

  // One block from `d`: reads of at most `chunk` samples, appended, until
  // `units` units are read and the last read left room, or the decoder
  // gives nothing more (g.getmeta()'s rule for a native decoder). Returns
  // the rows read. `want_time`: ask the decoder for time stamps.
  std::size_t read(Decoder& d, std::int64_t units, std::size_t chunk, bool want_time) {
    if (chunk == 0) throw std::invalid_argument("chunk must be positive");
    const std::size_t before = n_;
    first_time_ = nan();
    std::int64_t left = units;
    std::vector<double> scratch_time;
    const bool time_col = has_[kTime];
    const bool ask_time = want_time && d.info().has_time;
    if (ask_time && !time_col) scratch_time.resize(chunk);
    for (;;) {
      reserve(n_ + chunk);
      SampleBuffer out;
      out.x = cols_[kX].data() + n_;
      out.y = cols_[kY].data() + n_;
      out.z = cols_[kZ].data() + n_;
      if (has_[kT] && d.info().has_temperature) out.t = cols_[kT].data() + n_;
      if (has_[kLight] && d.info().has_light) out.light = cols_[kLight].data() + n_;
      if (ask_time) out.time = time_col ? cols_[kTime].data() + n_ : scratch_time.data();
      out.capacity = chunk;
      const std::int64_t u = d.read(out, left);
      const std::size_t got = out.n;
      if (got > 0) {
        if (out.t == nullptr && has_[kT]) fill(kT, n_, got);
        if (out.light == nullptr && has_[kLight]) fill(kLight, n_, got);
        if (out.time != nullptr) {
          if (n_ == before) first_time_ = out.time[0];
          note_tail(out.time, got);
        } else if (time_col) {
          fill(kTime, n_, got);
        }
        n_ += got;
      }
      left -= u;
      if (got == 0 && u == 0) break;
      if (left <= 0 && got < chunk) break;
      if (d.done()) break;
    }
    return n_ - before;
  }

  // Rows appended from columns in memory (samples given to R), `k` rows.
  // Absent columns (nullptr) of a kept kind are NaN.
  void append(const double* const src[kCols], std::size_t k) {
    reserve(n_ + k);
    first_time_ = nan();
    for (int c = 0; c < kCols; ++c) {
      if (!has_[c]) continue;
      if (src[c] != nullptr) {
        std::copy(src[c], src[c] + k, cols_[c].begin() + static_cast<std::ptrdiff_t>(n_));
      } else {
        fill(c, n_, k);
      }
    }
    if (k > 0 && src[kTime] != nullptr) {
      first_time_ = src[kTime][0];
      note_tail(src[kTime], k);
    }
    n_ += k;
  }

  // Rows [from, n) replaced by `k` rows of `src` (R's imputation of the
  // rows read).
  void replace_tail(std::size_t from, const double* const src[kCols], std::size_t k) {
    if (from > n_) throw std::out_of_range("replace_tail beyond the block");
    n_ = from;
    tail_time_[0] = tail_time_[1] = nan();
    append(src, k);
  }

  // GGIR's fill of a gap between the carry (its last row `last`) and the
  // rows read after it: the last row's x, y, z divided by their norm (R's
  // sqrt(sum(v^2)), accumulator Acc), then the row repeated `reps` times
  // right after it, every column.
  template <class Acc>
  void fill_gap(std::size_t last, std::size_t reps) {
    if (last >= n_) throw std::out_of_range("fill_gap beyond the block");
    Acc s = 0;
    for (int c = kX; c <= kZ; ++c) {
      const double v = cols_[c][last];
      s += v * v;
    }
    const double norm = std::sqrt(static_cast<double>(s));
    for (int c = kX; c <= kZ; ++c) cols_[c][last] = cols_[c][last] / norm;
    if (reps == 0) return;
    reserve(n_ + reps);
    for (int c = 0; c < kCols; ++c) {
      if (!has_[c]) continue;
      std::vector<double>& v = cols_[c];
      const auto at = v.begin() + static_cast<std::ptrdiff_t>(last + 1);
      std::copy_backward(at, v.begin() + static_cast<std::ptrdiff_t>(n_),
                         v.begin() + static_cast<std::ptrdiff_t>(n_ + reps));
      std::fill(at, at + static_cast<std::ptrdiff_t>(reps), v[last]);
    }
    if (last + 1 == n_) tail_time_[1] = tail_time_[0];  // the repeated row is the last now
    n_ += reps;
  }

  // The first k rows dropped (the first block's start).
  void drop_front(std::size_t k) { keep(std::min(k, n_), n_ - std::min(k, n_)); }

  // Rows [from, from + count) become the store (the carry), the rest
  // dropped; the capacity stays for the next block.
  void keep(std::size_t from, std::size_t count) {
    if (from > n_ || count > n_ - from) throw std::out_of_range("keep beyond the block");
    if (from + count < n_) {
      // the carry's last row is one of the store's last two, or its time
      // is not known without a time column
      const std::size_t back = n_ - (from + count);
      const double t = back < 2 ? tail_time_[back] : nan();
      tail_time_[0] = t;
      tail_time_[1] = nan();
    }
    for (int c = 0; c < kCols; ++c) {
      if (!has_[c] || from == 0) continue;
      std::vector<double>& v = cols_[c];
      std::copy(v.begin() + static_cast<std::ptrdiff_t>(from),
                v.begin() + static_cast<std::ptrdiff_t>(from + count), v.begin());
    }
    n_ = count;
    if (n_ == 0) tail_time_[0] = tail_time_[1] = nan();
  }

 private:
  static double nan() { return std::numeric_limits<double>::quiet_NaN(); }

  void fill(int c, std::size_t from, std::size_t k) {
    std::fill(cols_[c].begin() + static_cast<std::ptrdiff_t>(from),
              cols_[c].begin() + static_cast<std::ptrdiff_t>(from + k), nan());
  }

  // the last two times of the rows just written (t[0..k))
  void note_tail(const double* t, std::size_t k) {
    if (k >= 2) {
      tail_time_[1] = t[k - 2];
      tail_time_[0] = t[k - 1];
    } else if (k == 1) {
      tail_time_[1] = tail_time_[0];
      tail_time_[0] = t[0];
    }
  }

  // room for `rows`, growing each kept column by at least a quarter, one at
  // a time (at most one column's old and new copies held at once)
  void reserve(std::size_t rows) {
    if (rows <= cap_) return;
    const std::size_t grown = cap_ + cap_ / 4;
    const std::size_t cap = std::max(rows, grown);
    for (int c = 0; c < kCols; ++c) {
      if (!has_[c]) continue;
      std::vector<double> v(cap);
      std::copy(cols_[c].begin(), cols_[c].begin() + static_cast<std::ptrdiff_t>(n_), v.begin());
      cols_[c].swap(v);
    }
    cap_ = cap;
  }

  bool has_[kCols] = {false, false, false, false, false, false};
  std::vector<double> cols_[kCols];
  std::size_t n_ = 0;
  std::size_t cap_ = 0;
  double first_time_ = nan();
  // tail_time_[0]: the last row's time, [1]: the one before
  double tail_time_[2] = {nan(), nan()};
};

}  // namespace ggir_part1
}  // namespace gravcal

#endif  // GRAVCAL_GGIR_BLOCK_STORE_HPP
