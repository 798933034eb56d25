// gravcal: the samples of one of GGIR part 1's blocks, held in the core.
//
// GGIR's g.getmeta() reads a recording in blocks of a day or more; each
// block is the previous block's last samples (the carry: those past its
// last whole long epoch), then the samples read. Its epoch signals
// (ggir_epochs.hpp) are computed over the block's first whole long epochs,
// and the rest is carried on. BlockStore holds that block as columns the
// decoder writes into directly, so that no block passes through R: R keeps
// GGIR's decisions (when a block is the last, the start, the gap between
// blocks), the store does what they ask.
//
// Memory, about the block's x, y and z and no more:
// * each axis is one array with room for the block's units at its
//   decoder's most samples per unit (up to kReserveRows rows: pages not
//   written are never touched); beyond that room (a larger bound, gaps
//   filled) a block is read in parts of a fixed size, then put together in
//   one array per axis of exactly its length (and room for two reads more),
//   each part freed as it is copied. The next blocks are read into those
//   arrays (their carry moved to the front). Nothing is sized by a number
//   read from the file.
// * temperature and light (a value per page in .cwa and GENEActiv files),
//   and an ad hoc csv file's wear flags, are kept as runs of one value (RunColumn), as plain values only when
//   their runs are short.
// * time stamps are kept as a column only when asked (GGIR's time-gap
//   imputation needs them); otherwise the block's first time and its last
//   two are kept, which is all GGIR's block logic reads.
#ifndef GRAVCAL_GGIR_BLOCK_STORE_HPP
#define GRAVCAL_GGIR_BLOCK_STORE_HPP

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "gravcal/host/big_array.hpp"
#include "gravcal/decoders/decode.hpp"
#include "gravcal/kernels/kernels.hpp"

namespace gravcal {
namespace ggir_part1 {

// A linear calibration in place, as gravcal's apply_model() computes it in
// R ("matrix" arithmetic): u = v + offset; a_i = K[i][0] u_0 + K[i][1] u_1
// + K[i][2] u_2, summed left to right, then + (t - meantemp) tempoffset_i.
// The same bits as R's vectorised expression (one rounding per operation).
// `t(i)`: the temperature of row i, asked in increasing i.
struct LinearModel {
  double K[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // K[row][column]
  double offset[3] = {0, 0, 0};
  bool temp = false;
  double meantemp = 0;
  double tempoffset[3] = {0, 0, 0};
};

template <class T>
void apply_linear(const LinearModel& m, double* x, double* y, double* z, T&& t, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    const double u[3] = {x[i] + m.offset[0], y[i] + m.offset[1], z[i] + m.offset[2]};
    const double dt = m.temp ? t(i) - m.meantemp : 0;
    double a[3];
    for (int r = 0; r < 3; ++r) {
      double s = m.K[r][0] * u[0];
      s = s + m.K[r][1] * u[1];
      s = s + m.K[r][2] * u[2];
      if (m.temp) s = s + dt * m.tempoffset[r];
      a[r] = s;
    }
    x[i] = a[0];
    y[i] = a[1];
    z[i] = a[2];
  }
}

// A column of doubles held as runs of one value (bit for bit: NaN runs
// too), or as plain values once its runs are short (more than one run per
// kPlainRun rows on average). at(i) reads any row; reads in increasing
// order are cheap (the run last read is remembered).
class RunColumn {
 public:
  static constexpr std::size_t kPlainRun = 8;

  std::size_t size() const { return n_; }
  bool plain() const { return plain_; }
  void clear() {
    plain_ = false;
    std::vector<double>().swap(v_);
    std::vector<std::size_t>().swap(end_);
    n_ = 0;
    hint_ = 0;
  }

  void push(const double* p, std::size_t k) {
    if (plain_) {
      v_.insert(v_.end(), p, p + k);
    } else {
      // a run at a time (the kernel run_end finds where it stops)
      const kernels::RunEndFn run_end = kernels::active().run_end;
      for (std::size_t i = 0; i < k;) {
        const std::size_t j = run_end(p, i, k);
        if (!end_.empty() && same(v_.back(), p[i])) {
          end_.back() = n_ + j;
        } else {
          v_.push_back(p[i]);
          end_.push_back(n_ + j);
        }
        i = j;
      }
    }
    n_ += k;
    if (!plain_ && end_.size() > 64 && end_.size() * kPlainRun > n_) to_plain();
  }

  void push_repeat(double value, std::size_t k) {
    for (std::size_t i = 0; i < k; ++i) push(&value, 1);
  }

  double at(std::size_t i) const {
    if (plain_) return v_[i];
    const std::size_t h = hint_;
    if (h < end_.size() && i < end_[h] && (h == 0 || end_[h - 1] <= i)) return v_[h];
    if (h + 1 < end_.size() && end_[h] <= i && i < end_[h + 1]) {
      hint_ = h + 1;
      return v_[h + 1];
    }
    hint_ = static_cast<std::size_t>(std::upper_bound(end_.begin(), end_.end(), i) - end_.begin());
    return v_[hint_];
  }

  // f(from, to, value) for the spans of rows [0, n) (n <= size()) whose
  // values have the same bits, in increasing order: the runs, or a plain
  // column's equal neighbours grouped.
  template <class F>
  void spans(std::size_t n, F&& f) const {
    if (n > n_) throw std::out_of_range("spans beyond the column");
    std::size_t a = 0;
    if (plain_) {
      while (a < n) {
        std::size_t b = a + 1;
        while (b < n && same(v_[b], v_[a])) ++b;
        f(a, b, v_[a]);
        a = b;
      }
      return;
    }
    for (std::size_t r = 0; r < end_.size() && a < n; ++r) {
      const std::size_t b = std::min(end_[r], n);
      if (b > a) f(a, b, v_[r]);
      a = b;
    }
  }

  // f(v) for the values of rows [from, to) (to <= size()): once per run,
  // or once per row of a plain column.
  template <class F>
  void values_in(std::size_t from, std::size_t to, F&& f) const {
    if (to > n_) throw std::out_of_range("rows beyond the column");
    if (plain_) {
      for (std::size_t i = from; i < to; ++i) f(v_[i]);
      return;
    }
    std::size_t r = static_cast<std::size_t>(std::upper_bound(end_.begin(), end_.end(), from) - end_.begin());
    for (std::size_t a = from; a < to && r < end_.size(); ++r) {
      f(v_[r]);
      a = end_[r];
    }
  }

  // A reader of the column's rows for a pass in increasing order: the run
  // last read is held in the reader (not in the column), so that a row of
  // the same run costs two comparisons; any other row is found by the next
  // run or a binary search.
  class Cursor {
   public:
    explicit Cursor(const RunColumn& c) : c_(&c) {}
    double operator()(std::size_t i) {
      if (c_->plain_) return c_->v_[i];
      if (i >= lo_ && i < hi_) return val_;
      seek(i);
      return val_;
    }
    // rows [from, to) into o[0, to - from), a run at a time
    void fill(std::size_t from, std::size_t to, double* o) {
      if (c_->plain_) {
        std::copy(c_->v_.begin() + static_cast<std::ptrdiff_t>(from),
                  c_->v_.begin() + static_cast<std::ptrdiff_t>(to), o);
        return;
      }
      for (std::size_t i = from; i < to;) {
        if (i < lo_ || i >= hi_) seek(i);
        const std::size_t stop = std::min(hi_, to);
        std::fill(o + (i - from), o + (stop - from), val_);
        i = stop;
      }
    }

   private:
    void seek(std::size_t i) {
      const std::vector<std::size_t>& end = c_->end_;
      std::size_t r;
      // the next run (hi_ is 0 until a run is held)
      if (hi_ > 0 && i >= hi_ && r_ + 1 < end.size() && i < end[r_ + 1]) {
        r = r_ + 1;
      } else {
        r = static_cast<std::size_t>(std::upper_bound(end.begin(), end.end(), i) - end.begin());
      }
      r_ = r;
      lo_ = r ? end[r - 1] : 0;
      hi_ = end[r];
      val_ = c_->v_[r];
    }
    const RunColumn* c_;
    std::size_t r_ = 0, lo_ = 1, hi_ = 0;
    double val_ = 0;
  };

  // rows [from, from + count) kept
  void keep(std::size_t from, std::size_t count) {
    RunColumn c;
    c.plain_ = plain_;
    for (std::size_t i = from; i < from + count;) {
      if (plain_) {
        c.push(v_.data() + from, count);
        break;
      }
      const double v = at(i);
      const std::size_t stop = std::min(end_[hint_], from + count);
      c.push_repeat_run(v, stop - i);
      i = stop;
    }
    swap(c);
  }

  // `reps` copies of row `row` inserted after it
  void repeat_row(std::size_t row, std::size_t reps) {
    RunColumn c;
    c.plain_ = plain_;
    copy_rows(c, 0, row + 1);
    c.push_repeat_run(at(row), reps);
    copy_rows(c, row + 1, n_ - row - 1);
    swap(c);
  }

  void swap(RunColumn& o) {
    std::swap(plain_, o.plain_);
    v_.swap(o.v_);
    end_.swap(o.end_);
    std::swap(n_, o.n_);
    hint_ = 0;
    o.hint_ = 0;
  }

 private:
  static bool same(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

  void push_repeat_run(double v, std::size_t k) {
    if (k == 0) return;
    if (plain_) {
      v_.insert(v_.end(), k, v);
      n_ += k;
      return;
    }
    if (!end_.empty() && same(v_.back(), v)) {
      end_.back() += k;
    } else {
      v_.push_back(v);
      end_.push_back(n_ + k);
    }
    n_ += k;
  }

  void copy_rows(RunColumn& c, std::size_t from, std::size_t count) const {
    for (std::size_t i = from; i < from + count;) {
      if (plain_) {
        c.v_.insert(c.v_.end(), v_.begin() + static_cast<std::ptrdiff_t>(from),
                    v_.begin() + static_cast<std::ptrdiff_t>(from + count));
        c.n_ += count;
        return;
      }
      const double v = at(i);
      const std::size_t stop = std::min(end_[hint_], from + count);
      c.push_repeat_run(v, stop - i);
      i = stop;
    }
  }

  void to_plain() {
    std::vector<double> p(n_);
    std::size_t at = 0;
    for (std::size_t k = 0; k < end_.size(); ++k) {
      std::fill(p.begin() + static_cast<std::ptrdiff_t>(at), p.begin() + static_cast<std::ptrdiff_t>(end_[k]), v_[k]);
      at = end_[k];
    }
    v_.swap(p);
    std::vector<std::size_t>().swap(end_);
    plain_ = true;
    hint_ = 0;
  }

  bool plain_ = false;
  std::vector<double> v_;          // plain values, or each run's value
  std::vector<std::size_t> end_;   // each run's end (exclusive row)
  std::size_t n_ = 0;
  mutable std::size_t hint_ = 0;   // the run last read
};

class BlockStore {
 public:
  static constexpr int kX = 0, kY = 1, kZ = 2, kT = 3, kTime = 4, kLight = 5, kWear = 6, kCols = 7;
  // rows of a part a block is read into when the columns have no room: 40
  // MB a column, above the size from which allocators map memory of its
  // own (glibc: 32 MB at most), so that a part freed is memory given back,
  // not kept in the heap
  static constexpr std::size_t kPartRows = std::size_t{5} << 20;
  // the most rows a column is given room for before a block is read (256
  // MB): a block of `units` units bounded by its decoder's samples per
  // unit fits, unless time gaps are filled in it, and is written straight
  // into the columns: no parts, no copy into place, its memory touched
  // once. Pages the block does not fill are never touched (the allocator
  // maps them, the system backs them on first write).
  static constexpr std::size_t kReserveRows = std::size_t{1} << 25;

  BlockStore(bool temperature, bool time, bool light, bool wear = false) {
    has_[kX] = has_[kY] = has_[kZ] = true;
    has_[kT] = temperature;
    has_[kTime] = time;
    has_[kLight] = light;
    has_[kWear] = wear;
  }

  bool has(int c) const { return has_[c]; }
  std::size_t size() const { return n_; }
  // x, y, z and time: arrays of size() values
  double* col(int c) { return has_[c] && !is_run(c) ? cols_[c].get() : nullptr; }
  const double* col(int c) const { return has_[c] && !is_run(c) ? cols_[c].get() : nullptr; }
  // temperature, light and the wear flag (nullptr when not kept)
  const RunColumn* runs(int c) const { return has_[c] && is_run(c) ? &runs_[run_of(c)] : nullptr; }
  double value(int c, std::size_t i) const { return is_run(c) ? runs(c)->at(i) : cols_[c][i]; }

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
  // the rows read. `want_time`: ask the decoder for time stamps. The
  // decoder writes into the columns while they have room (from the second
  // block on: they keep the first block's length and two reads more), then
  // into parts, put together with the columns at the block's exact length
  // (and room for two reads more).
  std::size_t read(Decoder& d, std::int64_t units, std::size_t chunk, bool want_time) {
    if (chunk == 0) throw std::invalid_argument("chunk must be positive");
    first_time_ = nan();
    std::int64_t left = units;
    const bool ask_time = want_time && d.info().has_time;
    const bool ask_t = has_[kT] && d.info().has_temperature;
    const bool ask_light = has_[kLight] && d.info().has_light;
    const bool ask_wear = has_[kWear] && d.info().has_wear;
    const bool col_time = ask_time && has_[kTime];
    const std::size_t part_rows = std::max(kPartRows, chunk);
    if (units > 0) {
      const double bound = static_cast<double>(units) * static_cast<double>(d.max_samples_per_unit()) +
                           2.0 * static_cast<double>(chunk);
      if (bound <= static_cast<double>(kReserveRows) && static_cast<std::size_t>(bound) > cap_) {
        grow(static_cast<std::size_t>(bound));
      }
    }
    // (not zeroed: the pages a part does not use are never touched)
    std::vector<BigArray> parts[kCols];
    std::vector<std::size_t> used;  // rows in each part
    std::vector<double> t_buf(ask_t ? chunk : 0), light_buf(ask_light ? chunk : 0),
        wear_buf(ask_wear ? chunk : 0), time_buf(ask_time && !col_time ? chunk : 0);
    std::size_t got_all = 0;
    for (;;) {
      SampleBuffer out;
      double* dst[kCols] = {};
      if (used.empty() && cap_ - n_ >= chunk) {
        for (int c = 0; c < kCols; ++c) {
          if (cols_[c]) dst[c] = cols_[c].get() + n_;
        }
      } else {
        if (used.empty() || part_rows - used.back() < chunk) {
          for (int c = 0; c < kCols; ++c) {
            if (c <= kZ || (c == kTime && has_[kTime])) parts[c].push_back(big_array(part_rows));
          }
          used.push_back(0);
        }
        for (int c = 0; c < kCols; ++c) {
          if (!parts[c].empty()) dst[c] = parts[c].back().get() + used.back();
        }
      }
      out.x = dst[kX];
      out.y = dst[kY];
      out.z = dst[kZ];
      if (ask_t) out.t = t_buf.data();
      if (ask_light) out.light = light_buf.data();
      if (ask_wear) out.wear = wear_buf.data();
      if (ask_time) out.time = col_time ? dst[kTime] : time_buf.data();
      out.time_ends_only = ask_time && !col_time;  // (only note_tail()'s and the first read)
      out.capacity = chunk;
      const std::int64_t u = d.read(out, left);
      const std::size_t got = out.n;
      if (got > 0) {
        if (has_[kTime] && !col_time) std::fill(dst[kTime], dst[kTime] + got, nan());
        if (used.empty()) {
          n_ += got;
        } else {
          used.back() += got;
        }
        if (has_[kT]) push_or_nan(runs_[run_of(kT)], out.t, got);
        if (has_[kLight]) push_or_nan(runs_[run_of(kLight)], out.light, got);
        if (has_[kWear]) push_or_nan(runs_[run_of(kWear)], out.wear, got);
        if (out.time != nullptr) {
          if (got_all == 0) first_time_ = out.time[0];
          note_tail(out.time, got);
        }
        got_all += got;
      }
      left -= u;
      if (got == 0 && u == 0) break;
      if (left <= 0 && got < chunk) break;
      if (d.done()) break;
    }
    if (!used.empty()) assemble(parts, used, 2 * chunk);
    // a decoder that times a block by what comes at its end (GENEActiv in
    // GGIR's mode) gives its ends' times as they stand now
    Decoder::CallEndTimes ends;
    if (ask_time && !col_time && got_all > 0 && d.call_end_times(ends)) {
      first_time_ = ends.first;
      for (int i = 0; i < ends.n_last; ++i) tail_time_[i] = ends.last[i];
    }
    return got_all;
  }

  // Rows appended from columns in memory (samples given to R), `k` rows.
  // Absent columns (nullptr) of a kept kind are NaN.
  void append(const double* const src[kCols], std::size_t k) {
    first_time_ = nan();
    if (n_ + k > cap_) grow(n_ + k);
    for (int c = 0; c < kCols; ++c) {
      if (!has_[c]) continue;
      if (is_run(c)) {
        push_or_nan(runs_[run_of(c)], src[c], k);
      } else if (src[c] != nullptr) {
        std::copy(src[c], src[c] + k, cols_[c].get() + n_);
      } else {
        std::fill(cols_[c].get() + n_, cols_[c].get() + n_ + k, nan());
      }
    }
    if (k > 0 && src[kTime] != nullptr) {
      first_time_ = src[kTime][0];
      note_tail(src[kTime], k);
    }
    n_ += k;
  }

  // Rows [from, n) replaced by `k` rows of `src`.
  void replace_tail(std::size_t from, const double* const src[kCols], std::size_t k) {
    if (from > n_) throw std::out_of_range("replace_tail beyond the block");
    for (int c = 0; c < kCols; ++c) {
      if (has_[c] && is_run(c)) runs_[run_of(c)].keep(0, from);
    }
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
    if (n_ + reps > cap_) grow(n_ + reps);
    for (int c = 0; c < kCols; ++c) {
      if (!has_[c]) continue;
      if (is_run(c)) {
        runs_[run_of(c)].repeat_row(last, reps);
        continue;
      }
      double* v = cols_[c].get();
      std::copy_backward(v + last + 1, v + n_, v + n_ + reps);
      std::fill(v + last + 1, v + last + 1 + reps, v[last]);
    }
    if (last + 1 == n_) tail_time_[1] = tail_time_[0];  // the repeated row is the last now
    n_ += reps;
  }

  // Rows [from, from + count) become the store (the start's shift, or the
  // carry after a block), moved to the front; the columns keep their room
  // for the next block.
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
      if (!has_[c]) continue;
      if (is_run(c)) {
        runs_[run_of(c)].keep(from, count);
      } else if (from > 0 && count > 0) {
        std::memmove(cols_[c].get(), cols_[c].get() + from, count * sizeof(double));
      }
    }
    n_ = count;
    if (n_ == 0) tail_time_[0] = tail_time_[1] = nan();
  }

 private:
  static double nan() { return std::numeric_limits<double>::quiet_NaN(); }
  static bool is_run(int c) { return c == kT || c == kLight || c == kWear; }
  // runs_'s index of a run column
  static int run_of(int c) { return c == kT ? 0 : c == kLight ? 1 : 2; }

  static void push_or_nan(RunColumn& r, const double* p, std::size_t k) {
    if (p != nullptr) {
      r.push(p, k);
    } else {
      r.push_repeat(nan(), k);
    }
  }

  // room for `rows` in every array column, exactly, one column at a time
  void grow(std::size_t rows) {
    for (int c = 0; c < kCols; ++c) {
      if (!has_[c] || is_run(c)) continue;
      BigArray v = big_array(rows);
      if (n_ > 0) std::copy(cols_[c].get(), cols_[c].get() + n_, v.get());
      cols_[c] = std::move(v);
    }
    cap_ = rows;
  }

  // the columns' n_ rows, then the first used[k] rows of each part k, in
  // arrays of exactly that length and `room` rows more; one column at a
  // time, each part freed once copied
  void assemble(std::vector<BigArray> parts[kCols],
                const std::vector<std::size_t>& used, std::size_t room) {
    std::size_t total = n_;
    for (std::size_t k = 0; k < used.size(); ++k) total += used[k];
    for (int c = 0; c < kCols; ++c) {
      if (!has_[c] || is_run(c)) continue;
      BigArray v = big_array(total + room);
      if (n_ > 0) std::copy(cols_[c].get(), cols_[c].get() + n_, v.get());
      cols_[c].reset();
      std::size_t at = n_;
      for (std::size_t k = 0; k < parts[c].size(); ++k) {
        std::copy(parts[c][k].get(), parts[c][k].get() + used[k], v.get() + at);
        at += used[k];
        parts[c][k].reset();
      }
      if (parts[c].empty()) std::fill(v.get() + n_, v.get() + total, nan());  // a time column the decoder did not fill
      cols_[c] = std::move(v);
    }
    n_ = total;
    cap_ = total + room;
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

  bool has_[kCols] = {};
  BigArray cols_[kCols];  // x, y, z, time (temperature, light, wear: runs_)
  RunColumn runs_[3];                      // temperature, light, wear
  std::size_t n_ = 0, cap_ = 0;
  double first_time_ = nan();
  // tail_time_[0]: the last row's time, [1]: the one before
  double tail_time_[2] = {nan(), nan()};
};

}  // namespace ggir_part1
}  // namespace gravcal

#endif  // GRAVCAL_GGIR_BLOCK_STORE_HPP
