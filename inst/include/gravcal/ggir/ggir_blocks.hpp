// gravcal: GGIR's block rules between a sample stream and the segmenter.
//
// GGIR's g.calibrate reads a recording in blocks (about 12 hours) and, per
// block: removes idle-sleep samples (x = y = z = 0), puts the samples carried
// from the previous block in front, keeps the whole hours and carries the
// rest to the next block, checks the temperature, and restarts its
// cumulative sums before cutting windows. GgirBlocks applies those rules to
// samples pushed in chunks of any size, holding back only what the rules
// need to see before a sample may go on (at most an hour and one sample), so
// that a block never has to be held in memory whole.
//
// Why an hour is enough: the whole hours of a block are `use = floor(LD /
// H) H` of its LD retained samples (H samples per hour), so a sample is used
// as soon as its hour is complete. The last retained sample waits for the
// next one (or the block's end), because of the first accident below.
//
// A block's last window may be held back by the segmenter
// (Segmenter::lazy_r_sd()); end_block() has it given out with the block.
//
// GGIR-compatible mode keeps GGIR's accidents (see ?calibrate):
// - a block that ends on a whole hour leaves the previous carry in place,
//   and it is put in front of the next block again;
// - a block with less than an hour is dropped, the carry left in place;
// - when a block's last sample is an idle-sleep zero, the last retained
//   sample takes the x, y, z of the one before it;
// - when 3600 sf is just below a whole number in double (33.3 Hz), the
//   hours are still whole numbers of samples (R's `1:use`), but the carry
//   is R's data[(use + 1):LD, ] from a fractional use: it starts with the
//   last used sample again and leaves out the block's last (shift_carry()).
// gravcal's own mode carries every leftover sample exactly once.
//
// The samples wait in one buffer per column, unflushed ones in [head_,
// tail_). A caller that produces samples (a decoder) writes them straight
// into it: space() gives where, commit() takes them, so that no sample is
// copied on the way to the segmenter. space() ends a write at most one
// sample past the current hour, so that when an hour goes on only a sample
// or so waits behind it, and moving the waiting samples to the front of the
// buffer costs nothing.
//
// With a Worker (async()), the segmenter takes each hour on the worker's
// thread while the caller writes the next hour behind it (a decoder's
// samples: the decode beside the windows' sums). The segmenter gets the
// same samples in the same order, so the windows are the same. The buffer
// then holds three hours, so that the hour being taken is never moved or
// written over: compact() waits for it only where it would be, as does
// any change to the waiting samples at the block's ends.
//
// The temperature checks need R's mean and sd of the block's used
// temperatures; they are kept run-length coded, in order, so that they cost
// a few bytes per run of equal values (device files repeat one temperature
// over a page or a block). The sd only decides whether the temperature
// varies (sd >= temp_min_sd): computed from the runs, it is R's decision
// except within rounding of the threshold, where compatible mode repeats
// R's arithmetic (r_arith.hpp, r_sd_below()).
#ifndef GRAVCAL_GGIR_BLOCKS_HPP
#define GRAVCAL_GGIR_BLOCKS_HPP

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "gravcal/host/big_array.hpp"
#include "gravcal/host/r_arith.hpp"
#include "gravcal/host/segmenter.hpp"
#include "gravcal/host/threads.hpp"

namespace gravcal {

// What one block gave.
struct GgirBlockInfo {
  std::int64_t rows = 0;     // samples the reader gave, zeros included
  std::int64_t zeros = 0;    // idle-sleep samples removed
  std::int64_t ld = 0;       // carried in + retained
  std::int64_t used = 0;     // whole hours given to the segmenter
  std::int64_t carried = 0;  // samples carried to the next block
  double first_mean = std::numeric_limits<double>::quiet_NaN();  // mean of the
                             // first 10 used temperatures (R's, na.rm)
  double temp_sd = std::numeric_limits<double>::quiet_NaN();     // sd of the
                             // used temperatures (na.rm); NaN if < 2. In
                             // compatible mode on the same side of
                             // temp_min_sd as R's sd(), and R's to the bit
                             // when near it (temp_sd_exact)
  bool temp_sd_exact = false;  // temp_sd was computed in R's arithmetic
};

// Where the caller writes samples for commit(): columns x, y, z and t
// (null when the blocks have no temperature), room for `capacity` (>= 1).
struct BlockSpace {
  double* x = nullptr;
  double* y = nullptr;
  double* z = nullptr;
  double* t = nullptr;
  double* time = nullptr;   // null: the stage does not take time stamps
  double* light = nullptr;  // null: the stage does not take light
  std::size_t capacity = 0;
};

class GgirBlocks {
 public:
  // per_hour: samples per hour (3600 sf); compat: GGIR's accidents;
  // temperature: the stream has a temperature column; temp_min_sd: the
  // threshold the temperature's sd is compared with (GGIR: 0.01);
  // r_long_double: R's accumulator (r_arith.hpp) is long double, else double.
  GgirBlocks(Segmenter& seg, double per_hour, bool compat, bool temperature,
             double temp_min_sd = 0.01, bool r_long_double = true)
      : seg_(seg),
        Hd_(per_hour),
        H_(static_cast<std::int64_t>(per_hour + kRColonFuzz)),
        compat_(compat),
        temp_(temperature),
        temp_min_sd_(temp_min_sd),
        r_long_double_(r_long_double) {
    if (H_ < 1) H_ = 1;
    // 3600 sf just below a whole number in double (33.3 Hz: 119879.99...):
    // R's `1:use` still takes the whole number of rows (H_), and GGIR's
    // carry then starts at the last used row again (see end_block())
    // (H_ >= 2: the carry is then at most H_ samples, as space() needs)
    below_ = compat_ && per_hour < static_cast<double>(H_) && H_ >= 2;
  }

  ~GgirBlocks() { settle(); }
  GgirBlocks(const GgirBlocks&) = delete;
  GgirBlocks& operator=(const GgirBlocks&) = delete;

#ifndef GRAVCAL_NO_THREADS
  // The segmenter's hours on `w`'s thread (null: on the caller's). The
  // worker must outlive this object and the sinks given to it; the caller
  // calls settle() before a sink goes when it leaves by an exception
  // (read_ggir_block() does).
  void async(Worker* w) {
    settle();
    async_ = w;
  }
#endif
  // Waits for the hour the segmenter is taking, if any, and raises its
  // error (wait()), or forgets it (settle(): leaving by an exception).
  void wait() {
#ifndef GRAVCAL_NO_THREADS
    if (async_ != nullptr && job_from_ != kNoJob) {
      job_from_ = kNoJob;
      async_->wait();
    }
#endif
  }
  void settle() noexcept {
#ifndef GRAVCAL_NO_THREADS
    if (async_ != nullptr) async_->settle();
#endif
    job_from_ = kNoJob;
  }

  // A new block from the reader: the carry goes in front. Each
  // begin_block() is followed by end_block() before the next.
  void begin_block() {
    wait();
    info_ = GgirBlockInfo();
    pushed_ = 0;
    started_ = false;
    last_zero_ = false;
    first_.clear();
    runs_.clear();
    if (carry_in_hold_) {
      // compatible mode may need this carry again after the block
      if (compat_) {
        for (int c = 0; c < columns(); ++c) {
          carry_[c].assign(hold_[c].begin() + static_cast<std::ptrdiff_t>(head_),
                           hold_[c].begin() + static_cast<std::ptrdiff_t>(tail_));
        }
      }
    } else {
      head_ = tail_ = 0;
      const std::size_t k = carry_[0].size();
      grow(k);
      for (int c = 0; c < columns(); ++c) {
        std::copy(carry_[c].begin(), carry_[c].end(), hold_[c].begin());
      }
      tail_ = k;
      carry_in_hold_ = true;
    }
    const std::size_t k = tail_ - head_;
    if (temp_) note_temperatures(hold_[3].data() + head_, k);
    info_.ld = static_cast<std::int64_t>(k);
  }

  // Room for at most `want` (>= 1) samples, to be written and then given
  // to commit().
  BlockSpace space(std::size_t want) {
    if (want < 1) want = 1;
    const std::size_t waiting = tail_ - head_;
    // to one sample past the current hour (waiting <= H always)
    const std::size_t rest = static_cast<std::size_t>(H_) + 1 - waiting;
    const std::size_t k = std::min(want, rest);
    if (tail_ + k > cap_) {
      compact();
      if (tail_ + k > cap_) grow(tail_ + k);
    }
    BlockSpace s;
    s.x = hold_[0].data() + tail_;
    s.y = hold_[1].data() + tail_;
    s.z = hold_[2].data() + tail_;
    s.t = temp_ ? hold_[3].data() + tail_ : nullptr;
    s.capacity = k;
    return s;
  }

  // The first n samples written at the last space() are the block's next
  // samples (has_t: their temperatures were written; if not, they are NaN).
  // sink(w) gets each window the segmenter completes.
  template <class Sink>
  void commit(std::size_t n, bool has_t, Sink&& sink) {
    double* px = hold_[0].data() + tail_;
    double* py = hold_[1].data() + tail_;
    double* pz = hold_[2].data() + tail_;
    double* pt = temp_ ? hold_[3].data() + tail_ : nullptr;
    if (pt != nullptr && !has_t) {
      std::fill(pt, pt + n, std::numeric_limits<double>::quiet_NaN());
    }
    if (n > 0) last_zero_ = is_zero(px[n - 1], py[n - 1], pz[n - 1]);
    const std::size_t m = drop_zeros(px, py, pz, pt, n);
    if (pt != nullptr) note_temperatures(pt, m);
    tail_ += m;
    info_.rows += static_cast<std::int64_t>(n);
    info_.zeros += static_cast<std::int64_t>(n - m);
    info_.ld += static_cast<std::int64_t>(m);
    // the hours before the last retained sample's are complete
    if (info_.ld >= 1) {
      const std::int64_t ready = ((info_.ld - 1) / H_) * H_;
      if (ready > pushed_) {
        flush(static_cast<std::size_t>(ready - pushed_), sink);
        // the next hour fits behind the few samples now waiting
        if (cap_ - tail_ < static_cast<std::size_t>(H_) + 1 - (tail_ - head_)) compact();
      }
    }
  }

  // The block's samples from the caller's arrays, in chunks of any size; t
  // may be null. sink(w) gets each window the segmenter completes.
  template <class Sink>
  void push(const double* x, const double* y, const double* z, const double* t,
            std::size_t n, Sink&& sink) {
    std::size_t i = 0;
    while (i < n) {
      const BlockSpace s = space(n - i);
      const std::size_t k = s.capacity;
      std::memcpy(s.x, x + i, k * sizeof(double));
      std::memcpy(s.y, y + i, k * sizeof(double));
      std::memcpy(s.z, z + i, k * sizeof(double));
      if (s.t != nullptr && t != nullptr) std::memcpy(s.t, t + i, k * sizeof(double));
      commit(k, t != nullptr, sink);
      i += k;
    }
  }

  // The block ends: the whole hours go on, the rest is carried.
  template <class Sink>
  GgirBlockInfo end_block(Sink&& sink) {
    wait();
    const std::int64_t use = (info_.ld / H_) * H_;
    info_.used = use;
    // GGIR's use = floor(LD / (3600 sf)) * (3600 sf) in double: below a
    // whole number when 3600 sf is (below_), and then its carry is
    // data[(use + 1):LD, ]: from the last used row, without the last row
    // (R's `:` from a fraction; down to row use - 1 when LD is use)
    bool shifted = false;
    double use_d = 0.0;
    if (below_ && use > 0) {
      use_d = std::floor(static_cast<double>(info_.ld) / Hd_) * Hd_;
      shifted = use_d < static_cast<double>(use) &&
                static_cast<std::int64_t>(use_d + kRColonFuzz) == use;
    }
    // the last retained sample has not gone on (see commit()); the one
    // before it may have
    if (compat_ && last_zero_ && use > 0 && info_.ld >= 2 && H_ >= 2) {
      const std::size_t last = tail_ - 1;
      for (int c = 0; c < 3; ++c) {
        hold_[c][last] = last > head_ ? hold_[c][last - 1] : before_[c];
      }
    }
    if (use > 0) {
      flush(static_cast<std::size_t>(use - pushed_), sink);
      wait();
      if (shifted) {
        shift_carry(use_d, use);
      } else if (compat_ && use == info_.ld) {
        // compatible mode: a block of whole hours leaves the previous carry
        drop_hold();
      }
      temperature_stats(use);
    } else if (compat_) {
      drop_hold();  // less than an hour: dropped, the previous carry stays
    }
    // otherwise the samples not used (all of them when use = 0) are the
    // carry, where they are
    seg_.finish(sink);  // the window a lazy segmenter holds back
    info_.carried = static_cast<std::int64_t>(
        carry_in_hold_ ? tail_ - head_ : carry_[0].size());
    return info_;
  }

 private:
  int columns() const { return temp_ ? 4 : 3; }

  static bool is_zero(double x, double y, double z) {
    return x == 0.0 && y == 0.0 && z == 0.0;
  }

  // Removes the idle-sleep samples among n in place; returns how many are
  // left.
  static std::size_t drop_zeros(double* x, double* y, double* z, double* t,
                                std::size_t n) {
    std::size_t i = kernels::active().first_zero(x, y, z, n);
    if (i == n) return n;
    std::size_t m = i;
    for (; i < n; ++i) {
      if (is_zero(x[i], y[i], z[i])) continue;
      x[m] = x[i];
      y[m] = y[i];
      z[m] = z[i];
      if (t != nullptr) t[m] = t[i];
      ++m;
    }
    return m;
  }

  // Room for k samples in each column, doubling, so that the buffer stops
  // growing after the first hour: it never needs more than H + 1. The
  // first step goes to 2^19 samples at once (all of an hour up to 145 Hz):
  // each step copies the samples and touches fresh memory.
  void grow(std::size_t k) {
    if (cap_ >= k) return;
    wait();  // (the columns move)
    const std::size_t hour = static_cast<std::size_t>(H_) + 1;
    if (async_ != nullptr) {
      cap_ = std::max(k, 3 * hour);  // at once: three hours (see the top)
    } else {
      const std::size_t most = std::max(k, hour);
      cap_ = std::min(std::max({k, 2 * cap_, std::size_t(1) << 19}), most);
    }
    for (int c = 0; c < columns(); ++c) hold_[c].resize(cap_);
  }

  // The waiting samples to the front of the buffer.
  void compact() {
    if (head_ == 0) return;
    const std::size_t k = tail_ - head_;
    // the waiting samples and the next hour behind them, [0, k + H + 1),
    // must not reach the hour the segmenter is taking
    if (job_from_ != kNoJob && job_from_ < k + static_cast<std::size_t>(H_) + 1) wait();
    for (int c = 0; c < columns(); ++c) {
      std::memmove(hold_[c].data(), hold_[c].data() + head_, k * sizeof(double));
    }
    head_ = 0;
    tail_ = k;
  }

  // GGIR's carry when its `use` is a fraction just below the rows used
  // (see end_block()): data[(use + 1):LD, ], R's `:` from a fraction, so
  // the values from + j (or from - j when from > LD) in double, each
  // truncated to a row. The rows are the last two given on (use - 1, use)
  // and the waiting ones (use + 1 ... LD).
  void shift_carry(double use_d, std::int64_t use) {
    const int nc = columns();
    const std::int64_t ld = info_.ld;
    const double from = use_d + 1.0, to = static_cast<double>(ld);
    const bool up = from <= to;
    const std::int64_t n =
        static_cast<std::int64_t>(std::fabs(to - from) + 1.0 + kRColonFuzz);
    std::vector<double> out[4];
    for (int c = 0; c < nc; ++c) out[c].resize(static_cast<std::size_t>(n));
    for (std::int64_t j = 0; j < n; ++j) {
      const double v = up ? from + static_cast<double>(j) : from - static_cast<double>(j);
      const std::int64_t row = static_cast<std::int64_t>(v);  // 1-based
      for (int c = 0; c < nc; ++c) {
        double x;
        if (row >= use + 1 && row <= ld) {
          x = hold_[c][head_ + static_cast<std::size_t>(row - use - 1)];
        } else if (row == use) {
          x = before_[c];
        } else {
          x = before2_[c];  // row use - 1 (from > LD only)
        }
        out[c][static_cast<std::size_t>(j)] = x;
      }
    }
    head_ = tail_ = 0;
    grow(static_cast<std::size_t>(n));
    for (int c = 0; c < nc; ++c) {
      std::copy(out[c].begin(), out[c].end(), hold_[c].begin());
    }
    tail_ = static_cast<std::size_t>(n);
  }

  // The block's waiting samples are not the carry: the saved one is.
  void drop_hold() {
    head_ = tail_ = 0;
    carry_in_hold_ = false;
  }

  // The block's temperatures in order: the first 10, and run-length coded.
  void note_temperatures(const double* t, std::size_t m) {
    std::size_t i = 0;
    for (; i < m && first_.size() < 10; ++i) first_.push_back(t[i]);
    i = 0;
    while (i < m) {
      std::uint64_t bits;
      std::memcpy(&bits, t + i, sizeof bits);
      if (runs_.empty() || runs_.back().bits != bits) {
        runs_.push_back(Run{bits, t[i], 0});
      }
      const std::size_t j = kernels::active().run_end(t, i, m);
      runs_.back().count += static_cast<std::int64_t>(j - i);
      i = j;
    }
  }

  // The first k waiting samples go to the segmenter.
  template <class Sink>
  void flush(std::size_t k, Sink& sink) {
    if (k == 0) return;
    if (!started_) {
      seg_.new_block();  // GGIR restarts its sums with each block it reads
      started_ = true;
    }
    const double* x = hold_[0].data() + head_;
    const double* y = hold_[1].data() + head_;
    const double* z = hold_[2].data() + head_;
    const double* t = temp_ ? hold_[3].data() + head_ : nullptr;
#ifndef GRAVCAL_NO_THREADS
    if (async_ != nullptr) {
      Segmenter& seg = seg_;
      wait();  // (the hour before: the segmenter takes them in order)
      if (async_->run([&seg, &sink, x, y, z, t, k] { seg.push(x, y, z, t, k, sink); })) {
        job_from_ = head_;
      } else {
        seg_.push(x, y, z, t, k, sink);  // no thread to be had
      }
    } else {
      seg_.push(x, y, z, t, k, sink);
    }
#else
    seg_.push(x, y, z, t, k, sink);
#endif
    for (int c = 0; c < columns(); ++c) {
      before2_[c] = k >= 2 ? hold_[c][head_ + k - 2] : before_[c];
      before_[c] = hold_[c][head_ + k - 1];
    }
    head_ += k;
    pushed_ += static_cast<std::int64_t>(k);
  }

  // Calls f(value, count) for the runs of the first `use` temperatures.
  template <class F>
  void each_run(std::int64_t use, F&& f) const {
    std::int64_t left = use;
    for (const Run& r : runs_) {
      if (left == 0) break;
      const std::int64_t c = std::min(r.count, left);
      left -= c;
      f(r.value, static_cast<std::uint64_t>(c));
    }
  }

  // R's mean of the first 10 and the sd of the first `use` temperatures.
  // The sd comes from the runs in one pass (exact products of each run's
  // count and value, deviations around the mean); gravcal's own mode takes
  // it as it is, compatible mode only when it is clearly on one side of the
  // threshold (r_sd_below()), and otherwise repeats R's arithmetic value by
  // value, so that a block at the threshold goes GGIR's way.
  void temperature_stats(std::int64_t use) {
    if (!temp_) return;
    with_r_acc(r_long_double_, [&](auto acc) { temperature_stats_in<decltype(acc)>(use); });
  }

  template <class Acc>
  void temperature_stats_in(std::int64_t use) {
    // gravcal's own mode leaves non-finite temperatures out (as the
    // windows' temperatures do); GGIR's R arithmetic keeps an Inf, whose sd
    // is NaN, and so drops the temperature of the whole recording
    const bool keep_all = compat_;
    info_.first_mean = r_mean_sd<Acc>([&](auto&& f) {
      for (double v : first_) {
        if (keep_all || std::isfinite(v)) f(v);
      }
    }).mean;
    const RunsSd fast = runs_sd([&](auto&& f) {
      each_run(use, [&](double v, std::uint64_t c) {
        if (keep_all || std::isfinite(v)) f(v, c);
      });
    });
    if (!compat_) {
      info_.temp_sd = fast.sd;
      return;
    }
    const int below = r_sd_below<Acc>(fast, temp_min_sd_);
    if (below >= 0 && (fast.sd < temp_min_sd_) == (below == 1)) {
      info_.temp_sd = fast.sd;
      return;
    }
    info_.temp_sd = r_mean_sd<Acc>([&](auto&& f) {
      each_run(use, [&](double v, std::uint64_t c) {
        for (std::uint64_t i = 0; i < c; ++i) f(v);
      });
    }).sd;
    info_.temp_sd_exact = true;
  }

  struct Run {
    std::uint64_t bits;  // the value's bits (runs of the same bits)
    double value;
    std::int64_t count;
  };

  // R's `:` takes floor(to - from + 1 + FLT_EPSILON) values
  static constexpr double kRColonFuzz = 1.1920928955078125e-07;

  static constexpr std::size_t kNoJob = static_cast<std::size_t>(-1);
#ifndef GRAVCAL_NO_THREADS
  Worker* async_ = nullptr;
#else
  void* async_ = nullptr;
#endif
  std::size_t job_from_ = kNoJob;  // where the hour the segmenter is taking starts
  Segmenter& seg_;
  double Hd_;                  // 3600 sf, in double
  std::int64_t H_;             // whole samples an hour, as R's `1:use` takes them
  bool compat_;
  bool temp_;
  double temp_min_sd_;
  bool r_long_double_;
  GgirBlockInfo info_;
  std::int64_t pushed_ = 0;    // the block's samples given to the segmenter
  bool started_ = false;
  bool last_zero_ = false;
  std::size_t head_ = 0;       // waiting samples: [head_, tail_) of hold_
  std::size_t tail_ = 0;
  std::size_t cap_ = 0;        // size of each hold_ column
  double before_[4] = {0.0, 0.0, 0.0, 0.0};   // x, y, z, t of the last sample given on
  double before2_[4] = {0.0, 0.0, 0.0, 0.0};  // and of the one before it
  bool below_ = false;         // compatible mode, 3600 sf just below H_
  bool carry_in_hold_ = true;  // the carry is the waiting samples (else carry_)
  BigVector hold_[4];        // x, y, z, temperature
  std::vector<double> carry_[4];  // compatible mode: the carry in front of
                                  // the block, kept for the next block
  std::vector<double> first_;     // the block's first 10 temperatures
  std::vector<Run> runs_;         // the block's temperatures, run-length coded
};

// GGIR's duplicate filter on its window table: col[1] to col[6] are its
// means and sds (col[0], the mean norm, is not compared). For each pair of
// consecutive selected rows rows[i], rows[i + 1] (0-based), i < n - 1, how
// many of the six hold equal values, the count taken as R's sum of logicals
// (NA when a compared value is NaN, and then equal to nothing). Returns the
// positions i where the count is `need` (GGIR drops those windows: 3 in
// compatible mode). The caller guarantees that every rows[i] is a row of
// every column.
inline std::vector<std::size_t> duplicate_cuts(const double* const* col,
                                               const std::size_t* rows, std::size_t n,
                                               int need) {
  std::vector<std::size_t> cut;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    int same = 0;
    bool na = false;
    for (std::size_t c = 1; c < 7 && !na; ++c) {
      const double a = col[c][rows[i]], b = col[c][rows[i + 1]];
      na = std::isnan(a) || std::isnan(b);
      same += a == b;
    }
    if (!na && same == need) cut.push_back(i);
  }
  return cut;
}

// The same on a column-major table of n_row rows and at least 7 columns.
inline std::vector<std::size_t> duplicate_cuts(const double* table, std::size_t n_row,
                                               const std::size_t* rows, std::size_t n,
                                               int need) {
  const double* col[7];
  for (std::size_t c = 0; c < 7; ++c) col[c] = table + c * n_row;
  return duplicate_cuts(col, rows, n, need);
}

}  // namespace gravcal

#endif  // GRAVCAL_GGIR_BLOCKS_HPP
