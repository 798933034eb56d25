// gravcal: GGIR's time-gap imputation, g.imputeTimegaps(): of ad hoc csv
// files as g.calibrate reads them (rmc.check4timegaps = TRUE), and of every
// block g.getmeta() reads from a format whose gaps it fills (.gt3x,
// ActiGraph csv; GgirTimegapsMode below).
//
// GGIR 3.3-9's read.myacc.csv() hands each block of lines it reads (one
// g.readaccfile() call: GGIR's block) to g.imputeTimegaps() with k = 0.25 s,
// the previous block's last value and time left at their defaults (g.calibrate
// passes neither: a gap between two blocks is not seen). Within the block, in
// the units already applied:
// * a sample with x = y = z = 0 is dropped, except the block's first (its x,
//   y, z become 0, 0, 1) and its last (kept, its x, y, z become those of the
//   sample before it once the gaps are filled);
// * between two samples left (times t1, t2) with t2 - t1 >= k, k raised to
//   2 / sf where that is larger, the first is repeated round((t2 - t1) * sf)
//   times (R's round(): half to even), at times t1 + j / sf; its x, y, z
//   divided by their norm first where the norm exceeds 1.005 (the norm from
//   R's rowSums(), summed in R's accumulator: `Acc`); every column repeated,
//   temperature included.
//
// * the times of the filled block as GGIR 3.3-9's imputeRaw() gives them:
//   each sample's run of copies at t1 + j / sf, except that where two
//   samples next to each other both start a gap (a single sample between
//   two gaps), GGIR puts the times of the second and the first sample
//   (x$time[(i + 1):i]) between their runs, so that every time after them
//   belongs to the sample two rows earlier, and the block's last times are
//   cut off (newTime[1:nrow(x)]); the samples' values are not moved. The
//   next block's PreviousLastTime is the block's last time so given.
//
// GgirTimegapsOf does this while the samples stream: one call of read() with
// max_units is one GGIR block (the call's units are returned once all its
// samples are given, as GgirResamplerOf does, so that it can sit under the
// resampler: GGIR resamples the imputed block). It holds one sample and the
// block's last zero sample, never a block. A gap of more than kMaxGapRows
// samples (about 11.6 days at 100 Hz, where GGIR would need gigabytes) is not
// filled but counted and noted ("timegaps_not_filled").
//
// What it forwards to the decoder it wraps (opening it, its report, its
// units) is ForwardingDecoder's (decode_forwarding.hpp), shared with the
// other decorator.
#ifndef GRAVCAL_DECODE_GGIR_TIMEGAPS_HPP
#define GRAVCAL_DECODE_GGIR_TIMEGAPS_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/decoders/decode_forwarding.hpp"

namespace gravcal {

// g.getmeta()'s use of g.imputeTimegaps() (GgirTimegapsMode::carry): each
// block is given the previous block's last sample and time (GGIR's
// PreviousLastValue and PreviousLastTime; at the first block 0, 0, 1 and
// none). A zero first sample takes the previous block's last x, y, z; a step
// of k or more from the previous block's last time to the block's first
// time is filled like any other, from a sample with the previous block's
// last x, y, z, the first sample's other columns, at the previous block's
// last time. Gaps of more than `limit_minutes` (g.getmeta's max(6 long
// epochs, 90 minutes), beyond which GGIR imputes whole epochs instead) are
// not filled but counted ("timegaps_over_limit", the longest in
// "timegap_longest_rows"); "timegap_rows" counts the rows of the gaps filled
// (GGIR's QClog timegaps_min, in rows), "timegap_rows_read" the rows the
// inner decoder gave (before the gaps were filled). An inner decoder without time stamps
// is given times 1 / sf apart from 0 in each block (GGIR counts from the
// clock then: only their differences matter). `clock`: the shift GGIR's
// reader adds to each time (the file's clock, read as UTC, read again in the
// analysis' time zone), as its changes: from second clock[2k] on (the
// floor of the time) the shift is clock[2k + 1] (NaN: that clock time does
// not exist in the zone, counted as "clock_time_missing"); before the first
// change, or empty: none. Times beyond the table's last change + its span
// are counted as "clock_table_exceeded".
//
// With `epoch_gaps`, a gap of more rows than the limit is imputed as GGIR
// 3.3-9 imputes it: the sample before it is repeated only up to the long
// epoch after it (short epochs from the sample's time of day to the next
// long epoch boundary, plus those from the boundary before the next
// sample's time of day; a fraction of a short epoch moved to a delay), and
// the rest of the gap, in short epochs, is reported by take_epoch_gaps() at
// the sample GGIR marks (the last repeat, less the delay) for g.getmeta() to
// impute as whole epochs. The times of day are read in the zone `local`
// (pairs: from this UTC second, this offset in seconds; empty: UTC), as R's
// as.POSIXlt() reads a number in the session's zone (GGIR's
// data.table::hour() on R 4.3 or later).
struct GgirTimegapsMode {
  bool carry = false;
  double limit_minutes = 0;  // > 0: gaps of more rows than limit_minutes * 60 * sf
  std::vector<double> clock;
  double clock_until = 0;    // the table holds up to this second
  bool epoch_gaps = false;
  double short_epoch = 5, long_epoch = 900;  // seconds (GGIR's windowsizes[1:2])
  std::vector<double> local;
  // put before the names of the counters (but "timegaps_not_filled"): a
  // filler under another (an ad hoc csv file's own, read.myacc.csv's, under
  // g.getmeta()'s) keeps its counts apart
  std::string counter_prefix;
};

template <class Inner, class Acc = long double>
class GgirTimegapsOf : public ForwardingDecoder<Inner, GgirTimegapsOf<Inner, Acc>> {
  using Base = ForwardingDecoder<Inner, GgirTimegapsOf<Inner, Acc>>;
  friend Base;  // add_own()
  using Base::inner_;
  using Base::info_;
  using EpochGap = Decoder::EpochGap;

 public:
  // sf: the rate GGIR imputes at (the layout's: rmc.sf or the header's; 0:
  // the inner decoder's)
  GgirTimegapsOf(std::unique_ptr<Inner> inner, double sf, GgirTimegapsMode mode = {})
      : Base(std::move(inner)), sf_(sf), mode_(std::move(mode)) {}

  bool open() override {
    if (!this->open_inner()) return false;
    if (!(sf_ > 0)) sf_ = info_.sf;
    by_ = 1.0 / sf_;
    k_ = 0.25;
    if (k_ < 2 / sf_) k_ = 2 / sf_;
    raw_.assign(kCols * kRawChunk, 0.0);
    inner_time_ = inner_->info().has_time;
    if (mode_.limit_minutes > 0) limit_rows_ = mode_.limit_minutes * 60 * sf_;
    return true;
  }

  std::int64_t read(SampleBuffer& out, std::int64_t max_units) override {
    if (!in_call_ && !pending()) {
      if (max_units == 0) return 0;
      start_call(max_units);
    }
    for (;;) {
      drain(out);
      if (pending()) break;  // out is full
      if (!in_call_) break;
      if (raw_at_ < raw_n_) {
        take_plain(out);
        if (out.full()) break;
        if (raw_at_ < raw_n_) take(raw_at_++);
        continue;
      }
      if (this->left_ == 0 || inner_->done() || !refill()) end_call();
    }
    this->forward_report();
    return this->call_units(in_call_ || pending());
  }

  bool done() const override {
    return inner_->done() && !in_call_ && !pending() && raw_at_ >= raw_n_;
  }
  std::vector<EpochGap> take_epoch_gaps() override {
    std::vector<EpochGap> out;
    out.swap(epoch_gaps_);
    return out;
  }
  // (GgirResamplerOf's interface: a call goes on until its units are read)
  void continue_call(bool) {}

 private:
  static constexpr std::size_t kRawChunk = 4096;
  static constexpr std::size_t kCols = 6;  // x, y, z, t, time, wear
  static constexpr double kMaxGapRows = 1e8;
  // an epoch-level gap longer than this is not imputed (GGIR would build
  // its epochs in memory): 400 days
  static constexpr double kMaxEpochGapSeconds = 400 * 86400.0;
  struct Run {
    double v[kCols];
    std::int64_t n, j;  // copies to give, copies given
    bool pair = false;  // GGIR's two extra times before this run (see push())
    double pair_t[2] = {0, 0};
  };

  bool pending() const { return head_ < runs_.size(); }

  void start_call(std::int64_t max_units) {
    in_call_ = true;
    this->left_ = max_units;
    first_ = true;
    have_held_ = false;
    have_zero_ = false;
    runs_.clear();
    head_ = 0;
    synth_ = 0;
    // the block before gave its last time late (GGIR's time slip): that
    // time is its PreviousLastTime
    if (slipped_) plt_ = last_given_;
    slipped_ = false;
    slip_.clear();
    last_gap_ = false;
  }

  bool refill() {
    SampleBuffer b = SampleBuffer::columns(raw_.data(), kRawChunk, true, true);
    // (a wear flag is another column of the row: GGIR repeats and drops it
    // with the row's x, y, z)
    if (inner_->info().has_wear) b.wear = raw_.data() + 5 * kRawChunk;
    const std::int64_t u = this->read_inner(b);
    raw_n_ = b.n;
    raw_at_ = 0;
    rows_read_ += static_cast<std::int64_t>(b.n);
    double* time = raw_.data() + 4 * kRawChunk;
    if (!inner_time_) {
      for (std::size_t i = 0; i < b.n; ++i) time[i] = static_cast<double>(synth_++) / sf_;
    } else if (!mode_.clock.empty()) {
      for (std::size_t i = 0; i < b.n; ++i) time[i] = time[i] + clock_shift(time[i]);
    }
    return b.n > 0 || u > 0;
  }

  // GGIR's reader's shift of time t (see GgirTimegapsMode::clock)
  double clock_shift(double t) {
    const double f = std::floor(t);
    const std::vector<double>& c = mode_.clock;
    if (f >= mode_.clock_until) {
      ++clock_exceeded_;
      return 0;
    }
    if (f < c[0]) return 0;
    // the change in force: the last with c[2k] <= f (from the one before)
    if (!(clock_at_ < c.size() && c[clock_at_] <= f &&
          (clock_at_ + 2 >= c.size() || f < c[clock_at_ + 2]))) {
      std::size_t lo = 0, hi = c.size() / 2;  // changes [lo, hi)
      while (hi - lo > 1) {
        const std::size_t mid = (lo + hi) / 2;
        if (c[2 * mid] <= f) lo = mid;
        else hi = mid;
      }
      clock_at_ = 2 * lo;
    }
    const double d = c[clock_at_ + 1];
    if (std::isnan(d)) {
      ++clock_missing_;
      return 0;
    }
    return d;
  }

  void take(std::size_t i) {
    double s[kCols];
    for (std::size_t c = 0; c < kCols; ++c) s[c] = raw_[c * kRawChunk + i];
    const bool zero = s[0] == 0 && s[1] == 0 && s[2] == 0;
    if (first_) {
      first_ = false;
      if (zero) {
        // GGIR's PreviousLastValue: c(0, 0, 1), or g.getmeta()'s previous
        // block's last
        for (int c = 0; c < 3; ++c) s[c] = plv_[c];
      }
      if (mode_.carry && have_plt_ && s[4] - plt_ >= k_) {
        double p[kCols];
        for (std::size_t c = 0; c < kCols; ++c) p[c] = s[c];
        for (int c = 0; c < 3; ++c) p[c] = plv_[c];
        p[4] = plt_;
        hold(p);
        release(s[4]);
      }
      hold(s);
      return;
    }
    if (zero) {
      if (have_zero_) ++zeros_dropped_;
      for (std::size_t c = 0; c < kCols; ++c) zero_[c] = s[c];
      have_zero_ = true;
      return;
    }
    if (have_zero_) ++zeros_dropped_;
    have_zero_ = false;
    release(s[4]);
    hold(s);
  }

  // take(), drain() and what they do for a sample that needs none of
  // take()'s cases (most of them), straight to out: the held sample is
  // given as release() queues it and drain() gives it (a run of one copy,
  // at its own time), and the sample is held in its place. Stops at a
  // sample that is zero or follows a zero, at a step of k_ or more from the
  // held sample (a gap), where times slip or runs are queued, and where out
  // is full; take() and drain() go on from there, so the samples, times
  // and counts are the same.
  void take_plain(SampleBuffer& out) {
    if (first_ || have_zero_ || !have_held_ || pending() || !slip_.empty()) return;
    const double* x = raw_.data();
    const double* y = x + kRawChunk;
    const double* z = y + kRawChunk;
    const double* tc = z + kRawChunk;
    const double* time = tc + kRawChunk;
    const double* wear = time + kRawChunk;
    while (raw_at_ < raw_n_ && !out.full()) {
      const std::size_t i = raw_at_;
      if (x[i] == 0 && y[i] == 0 && z[i] == 0) return;
      if (time[i] - held_[4] >= k_) return;  // release()'s gap (a NaN step is none)
      // push() of the held sample's run of one, then drain()'s copy j = 0
      last_gap_ = false;
      last_time_ = held_[4];
      ++queued_;
      const double t = held_[4] + 0.0 * by_;
      give(out, held_, t);
      last_given_ = t;
      ++this->given_;
      held_[0] = x[i];
      held_[1] = y[i];
      held_[2] = z[i];
      held_[3] = tc[i];
      held_[4] = time[i];
      held_[5] = wear[i];
      ++raw_at_;
    }
  }

  // a row given at time t: x, y, z, temperature (v[0..3]) and the wear
  // flag (v[5]) where asked
  static void give(SampleBuffer& out, const double* v, double t) {
    if (out.wear != nullptr) out.wear[out.n] = v[5];
    out.put(v[0], v[1], v[2], v[3], t);
  }

  void hold(const double* s) {
    for (std::size_t c = 0; c < kCols; ++c) held_[c] = s[c];
    have_held_ = true;
  }

  // A row of GGIR's filled block (its run of copies). GGIR's imputeRaw()
  // builds the times of the rows after a gap row i from x$time[(i + 1):(j -
  // 1)], j the next gap row: for j = i + 1 that is x$time[c(i + 1, i)], two
  // times too many, put before row j's run.
  void push(Run r) {
    const bool gap = r.n != 1;
    if (gap && last_gap_) {
      r.pair = true;
      r.pair_t[0] = r.v[4];
      r.pair_t[1] = last_time_;
    }
    last_gap_ = gap;
    last_time_ = r.v[4];
    runs_.push_back(r);
    queued_ += r.n;
  }

  // The zone's offset at UTC second t (GgirTimegapsMode::local).
  double local_offset(double t) {
    const std::vector<double>& z = mode_.local;
    if (z.empty() || t < z[0]) return 0;
    if (!(local_at_ < z.size() && z[local_at_] <= t && (local_at_ + 2 >= z.size() || t < z[local_at_ + 2]))) {
      std::size_t lo = 0, hi = z.size() / 2;
      while (hi - lo > 1) {
        const std::size_t mid = (lo + hi) / 2;
        if (z[2 * mid] <= t) lo = mid;
        else hi = mid;
      }
      local_at_ = 2 * lo;
    }
    return z[local_at_ + 1];
  }

  // GGIR's seconds into the day of time t, plus one (hour * 3600 + minute *
  // 60 + whole seconds + 1, in the zone `local`).
  double day_seconds(double t) {
    const double f = std::floor(t + local_offset(t));
    return f - 86400 * std::floor(f / 86400) + 1;
  }

  // A gap of `n` rows over the limit, after the held sample and before the
  // sample at time `next`: the rows GGIR repeats the held sample for; the
  // rest reported as whole short epochs at the sample GGIR marks.
  double epoch_gap_rows(double n, double next) {
    const double S = mode_.short_epoch, L = mode_.long_epoch;
    const double s1 = day_seconds(held_[4]);
    const double add1 = (L - (s1 - std::floor(s1 / L) * L)) / S;
    const double s2 = day_seconds(next);
    const double add2 = ((s2 - std::floor(s2 / L) * L) - 1) / S;
    const double add = add1 + add2;
    const double time2add = (add * sf_ * S) + 1;
    double remaining = ((n - time2add) / (sf_ * S)) + 1;
    double gap = time2add, delay = 0;
    const double decs = remaining - std::floor(remaining);
    if (decs > 0) {
      delay = decs * (sf_ * S);
      gap = gap + delay;
      remaining = remaining - (delay / (sf_ * S));
    }
    gap = std::nearbyint(gap);
    delay = std::nearbyint(delay);
    if (remaining > 1) {
      epoch_gaps_.push_back({queued_ + static_cast<std::int64_t>(gap - delay) - 1, remaining});
    }
    return gap;
  }

  // The held sample, repeated up to the time `next` of the sample after it.
  void release(double next) {
    Run r;
    for (std::size_t c = 0; c < kCols; ++c) r.v[c] = held_[c];
    r.n = 1;
    r.j = 0;
    const double dt = next - held_[4];
    if (dt >= k_) {
      const double n = std::nearbyint(dt * sf_);
      if (limit_rows_ > 0 && n > limit_rows_ && !mode_.epoch_gaps) {
        ++over_limit_;
        if (n > longest_) longest_ = n;
      } else if ((n > kMaxGapRows && !(limit_rows_ > 0 && n > limit_rows_)) ||
                 (limit_rows_ > 0 && n > limit_rows_ && dt > kMaxEpochGapSeconds)) {
        ++gaps_not_filled_;
        if (gap_notes_.size() < 5) {
          gap_notes_.push_back("time stamps jump by " + std::to_string(dt) +
                               " s within a block; the gap is not filled");
        }
      } else {
        ++gaps_;
        gap_rows_ += static_cast<std::int64_t>(n);
        const double rows = (limit_rows_ > 0 && n > limit_rows_) ? epoch_gap_rows(n, next) : n;
        rows_added_ += static_cast<std::int64_t>(rows) - 1;
        r.n = static_cast<std::int64_t>(rows);
        const Acc ss = static_cast<Acc>(r.v[0] * r.v[0]) + static_cast<Acc>(r.v[1] * r.v[1]) +
                       static_cast<Acc>(r.v[2] * r.v[2]);
        const double en = std::sqrt(static_cast<double>(ss));
        if ((std::fabs(en) - 1) > 0.005) {
          for (int c = 0; c < 3; ++c) r.v[c] = r.v[c] / en;
        }
      }
    }
    push(r);
    have_held_ = false;
  }

  // The block's end: its held sample, then its last sample when that was
  // zero (x, y, z of the sample given before it).
  void end_call() {
    in_call_ = false;
    if (have_held_) {
      if (have_zero_) {
        release(zero_[4]);
        Run r;
        for (std::size_t c = 0; c < kCols; ++c) r.v[c] = zero_[c];
        for (int c = 0; c < 3; ++c) r.v[c] = runs_.back().v[c];
        r.n = 1;
        r.j = 0;
        push(r);
      } else {
        release(held_[4]);
      }
    }
    have_zero_ = false;
    if (mode_.carry && !runs_.empty()) {
      // the block's last sample: the next block's PreviousLastValue and,
      // with time stamps of the file's, PreviousLastTime
      const Run& r = runs_.back();
      for (int c = 0; c < 3; ++c) plv_[c] = r.v[c];
      plt_ = r.v[4] + static_cast<double>(r.n - 1) * by_;
      have_plt_ = inner_time_;
    }
  }

  void drain(SampleBuffer& out) {
    while (head_ < runs_.size() && !out.full()) {
      Run& r = runs_[head_];
      while (r.j < r.n && !out.full()) {
        if (r.j == 0 && r.pair) {
          slip_.push_back(r.pair_t[0]);
          slip_.push_back(r.pair_t[1]);
          slipped_ = true;
        }
        const double j = static_cast<double>(r.j++);
        double t = r.v[4] + j * by_;
        if (!slip_.empty()) {
          // the block's times after a slip: each row takes the time two
          // rows earlier per slip (the extra times queued first)
          slip_.push_back(t);
          t = slip_.front();
          slip_.pop_front();
        }
        give(out, r.v, t);
        last_given_ = t;
        ++this->given_;
      }
      if (r.j == r.n) ++head_;
    }
    if (head_ == runs_.size()) {
      runs_.clear();
      head_ = 0;
    }
  }

  void add_own(Report& r) const {
    const std::string& p = mode_.counter_prefix;
    auto count = [&](const char* name, std::int64_t k) { r.count((p + name).c_str(), k); };
    if (gaps_ > 0) count("timegaps_imputed", gaps_);
    if (rows_added_ > 0) count("timegap_samples_added", rows_added_);
    if (zeros_dropped_ > 0) count("timegaps_zero_samples_dropped", zeros_dropped_);
    if (gaps_not_filled_ > 0) r.count("timegaps_not_filled", gaps_not_filled_);
    if (mode_.carry) {
      count("timegap_rows_read", rows_read_);
      count("timegap_rows", gap_rows_);
      count("timegaps_over_limit", over_limit_);
      count("timegap_longest_rows", static_cast<std::int64_t>(longest_));
      count("clock_time_missing", clock_missing_);
      count("clock_table_exceeded", clock_exceeded_);
    }
    for (const auto& n : gap_notes_) r.note(n);
  }

  double sf_ = 0.0, by_ = 0.0, k_ = 0.25;
  std::vector<double> raw_;
  std::size_t raw_n_ = 0, raw_at_ = 0;
  bool in_call_ = false, first_ = true, have_held_ = false, have_zero_ = false;
  double held_[kCols] = {0, 0, 0, 0, 0, 0};
  double zero_[kCols] = {0, 0, 0, 0, 0, 0};
  std::vector<Run> runs_;
  std::size_t head_ = 0;
  std::int64_t gaps_ = 0, rows_added_ = 0, zeros_dropped_ = 0;
  std::int64_t gaps_not_filled_ = 0;
  std::vector<std::string> gap_notes_;
  GgirTimegapsMode mode_;
  bool inner_time_ = true;
  std::int64_t synth_ = 0;
  double plv_[3] = {0, 0, 1};
  double plt_ = 0;
  bool have_plt_ = false;
  double limit_rows_ = 0, longest_ = 0;
  std::int64_t gap_rows_ = 0, over_limit_ = 0, clock_missing_ = 0, clock_exceeded_ = 0;
  std::int64_t rows_read_ = 0;
  std::size_t clock_at_ = 0, local_at_ = 0;
  std::int64_t queued_ = 0;  // rows put in runs_ so far (all calls)
  // GGIR's time slip (push()): the times queued ahead of the rows, whether
  // the block has one, the last row pushed (a gap row?, its time), the last
  // time given
  std::deque<double> slip_;
  bool slipped_ = false, last_gap_ = false;
  double last_time_ = 0, last_given_ = 0;
  std::vector<EpochGap> epoch_gaps_;
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_GGIR_TIMEGAPS_HPP
