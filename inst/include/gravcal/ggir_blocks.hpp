// gravcal: GGIR's block rules between a sample stream and the segmenter.
//
// GGIR's g.calibrate reads a recording in blocks (about 12 hours) and, per
// block: removes idle-sleep samples (x = y = z = 0), puts the samples carried
// from the previous block in front, keeps the whole hours and carries the
// rest to the next block, checks the temperature, and restarts its
// cumulative sums before cutting windows. GgirBlocks applies those rules to
// samples pushed in chunks of any size, holding back only what the rules
// need to see before a sample may go on (at most two hours), so that a block
// never has to be held in memory whole.
//
// Why two hours are enough: the whole hours of a block are `use =
// floor(LD / H) H` of its LD retained samples (H samples per hour), and
// every sample but the last H can go on before LD is known, since
// LD - H < use. The last samples stay until the block ends.
//
// GGIR-compatible mode keeps GGIR's accidents (see ?calibrate):
// - a block that ends on a whole hour leaves the previous carry in place,
//   and it is put in front of the next block again;
// - a block with less than an hour is dropped, the carry left in place;
// - when a block's last sample is an idle-sleep zero, the last retained
//   sample takes the x, y, z of the one before it.
// gravcal's own mode carries every leftover sample exactly once.
//
// The temperature checks need R's mean and sd of the block's used
// temperatures (r_arith.hpp); they are kept run-length coded, in order, so
// that they cost a few bytes per run of equal values (device files repeat
// one temperature over a page or a block).
#ifndef GRAVCAL_GGIR_BLOCKS_HPP
#define GRAVCAL_GGIR_BLOCKS_HPP

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "r_arith.hpp"
#include "segmenter.hpp"

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
                             // used temperatures (R's, na.rm); NaN if < 2
};

class GgirBlocks {
 public:
  // per_hour: samples per hour (3600 sf); compat: GGIR's accidents;
  // temperature: the stream has a temperature column.
  GgirBlocks(Segmenter& seg, double per_hour, bool compat, bool temperature)
      : seg_(seg),
        H_(static_cast<std::int64_t>(std::floor(per_hour))),
        compat_(compat),
        temp_(temperature) {
    if (H_ < 1) H_ = 1;
  }

  // A new block from the reader: the carry goes in front.
  void begin_block() {
    info_ = GgirBlockInfo();
    pushed_ = 0;
    started_ = false;
    last_zero_ = false;
    first_.clear();
    runs_.clear();
    held_ = 0;
    const std::size_t k = carry_[0].size();
    reserve(k);
    for (int c = 0; c < columns(); ++c) {
      std::copy(carry_[c].begin(), carry_[c].end(), hold_[c].begin());
    }
    held_ = k;
    if (temp_) note_temperatures(hold_[3].data(), k);
    info_.ld = static_cast<std::int64_t>(k);
  }

  // The block's samples, in chunks of any size; t may be null. sink(w) gets
  // each window the segmenter completes.
  template <class Sink>
  void push(const double* x, const double* y, const double* z, const double* t,
            std::size_t n, Sink&& sink) {
    reserve(held_ + n);
    double* hx = hold_[0].data() + held_;
    double* hy = hold_[1].data() + held_;
    double* hz = hold_[2].data() + held_;
    double* ht = temp_ ? hold_[3].data() + held_ : nullptr;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::size_t m = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (x[i] == 0.0 && y[i] == 0.0 && z[i] == 0.0) {
        ++info_.zeros;
        last_zero_ = true;
        continue;
      }
      last_zero_ = false;
      hx[m] = x[i];
      hy[m] = y[i];
      hz[m] = z[i];
      if (ht != nullptr) ht[m] = t != nullptr ? t[i] : nan;
      ++m;
    }
    if (ht != nullptr) note_temperatures(ht, m);
    held_ += m;
    info_.rows += static_cast<std::int64_t>(n);
    info_.ld += static_cast<std::int64_t>(m);
    // everything but the last H samples may go on
    const std::int64_t free = static_cast<std::int64_t>(held_) - H_;
    if (free >= H_) flush(static_cast<std::size_t>(free), sink);
  }

  // The block ends: the whole hours go on, the rest is carried.
  template <class Sink>
  GgirBlockInfo end_block(Sink&& sink) {
    const std::size_t n = held_;
    if (compat_ && last_zero_ && info_.ld >= 2 && n >= 2) {
      for (int c = 0; c < 3; ++c) hold_[c][n - 1] = hold_[c][n - 2];
    }
    const std::int64_t use = (info_.ld / H_) * H_;
    info_.used = use;
    if (use > 0) {
      flush(static_cast<std::size_t>(use - pushed_), sink);
      if (use != info_.ld) {
        take_carry(held_);
      } else if (!compat_) {
        for (int c = 0; c < 4; ++c) carry_[c].clear();
      }
      temperature_stats(use);
    } else if (!compat_) {
      take_carry(held_);
    }
    info_.carried = static_cast<std::int64_t>(carry_[0].size());
    return info_;
  }

 private:
  int columns() const { return temp_ ? 4 : 3; }

  // Room for k held samples. The hold never exceeds two hours plus one
  // chunk, so its storage stops growing after the first block.
  void reserve(std::size_t k) {
    if (hold_[0].size() >= k) return;
    const std::size_t cap = std::max(k, 2 * hold_[0].size());
    for (int c = 0; c < columns(); ++c) hold_[c].resize(cap);
  }

  // The block's temperatures in order: the first 10, and run-length coded.
  void note_temperatures(const double* t, std::size_t m) {
    for (std::size_t i = 0; i < m && first_.size() < 10; ++i) first_.push_back(t[i]);
    for (std::size_t i = 0; i < m; ++i) {
      if (!runs_.empty() && same(runs_.back().value, t[i])) {
        ++runs_.back().count;
      } else {
        runs_.push_back(Run{t[i], 1});
      }
    }
  }

  static bool same(double a, double b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
  }

  // The first k held samples go to the segmenter.
  template <class Sink>
  void flush(std::size_t k, Sink& sink) {
    if (k == 0) return;
    if (!started_) {
      seg_.new_block();  // GGIR restarts its sums with each block it reads
      started_ = true;
    }
    seg_.push(hold_[0].data(), hold_[1].data(), hold_[2].data(),
              temp_ ? hold_[3].data() : nullptr, k, sink);
    pushed_ += static_cast<std::int64_t>(k);
    for (int c = 0; c < columns(); ++c) {
      std::memmove(hold_[c].data(), hold_[c].data() + k, (held_ - k) * sizeof(double));
    }
    held_ -= k;
  }

  // The last k held samples become the carry.
  void take_carry(std::size_t k) {
    for (int c = 0; c < 4; ++c) {
      carry_[c].clear();
      if (c == 3 && !temp_) continue;
      carry_[c].assign(hold_[c].begin() + static_cast<std::ptrdiff_t>(held_ - k),
                       hold_[c].begin() + static_cast<std::ptrdiff_t>(held_));
    }
  }

  // R's mean of the first 10 and sd of the first `use` temperatures. The sd
  // only decides whether the temperature varies (sd >= 0.01): gravcal's own
  // mode takes it from the runs in one pass (exact sums of each run's count
  // times its value, deviations around the mean); compatible mode repeats
  // R's arithmetic value by value, so that a block at the threshold goes
  // GGIR's way.
  void temperature_stats(std::int64_t use) {
    if (!temp_) return;
    info_.first_mean = r_mean_sd([&](auto&& f) {
      for (double v : first_) f(v);
    }).mean;
    if (!compat_) {
      info_.temp_sd = runs_sd(use);
      return;
    }
    info_.temp_sd = r_mean_sd([&](auto&& f) {
      std::int64_t left = use;
      for (const Run& r : runs_) {
        for (std::int64_t i = 0; i < r.count && left > 0; ++i, --left) f(r.value);
        if (left == 0) break;
      }
    }).sd;
  }

  // sd of the first `use` run-coded temperatures, NaN ones left out (as
  // R's na.rm); NaN when fewer than 2.
  double runs_sd(std::int64_t use) const {
    long double sum = 0;
    std::int64_t n = 0, left = use;
    for (const Run& r : runs_) {
      const std::int64_t c = std::min(r.count, left);
      left -= c;
      if (!std::isnan(r.value)) {
        sum += static_cast<long double>(r.value) * c;
        n += c;
      }
      if (left == 0) break;
    }
    if (n < 2) return std::numeric_limits<double>::quiet_NaN();
    const long double mean = sum / n;
    long double ss = 0;
    left = use;
    for (const Run& r : runs_) {
      const std::int64_t c = std::min(r.count, left);
      left -= c;
      if (!std::isnan(r.value)) {
        const long double d = r.value - mean;
        ss += d * d * c;
      }
      if (left == 0) break;
    }
    return static_cast<double>(std::sqrt(ss / (n - 1)));
  }

  struct Run {
    double value;
    std::int64_t count;
  };

  Segmenter& seg_;
  std::int64_t H_;
  bool compat_;
  bool temp_;
  GgirBlockInfo info_;
  std::int64_t pushed_ = 0;
  bool started_ = false;
  bool last_zero_ = false;
  std::size_t held_ = 0;          // samples in hold_
  std::vector<double> hold_[4];   // retained, not yet given on (held_ used)
  std::vector<double> carry_[4];  // carried to the next block
  std::vector<double> first_;     // the block's first 10 temperatures
  std::vector<Run> runs_;         // the block's temperatures, run-length coded
};

}  // namespace gravcal

#endif  // GRAVCAL_GGIR_BLOCKS_HPP
