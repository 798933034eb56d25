// gravcal: GGIR's time-gap imputation of ad hoc csv files
// (rmc.check4timegaps = TRUE).
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
// GgirTimegapsOf does this while the samples stream: one call of read() with
// max_units is one GGIR block (the call's units are returned once all its
// samples are given, as GgirResamplerOf does, so that it can sit under the
// resampler: GGIR resamples the imputed block). It holds one sample and the
// block's last zero sample, never a block. A gap of more than kMaxGapRows
// samples (about 11.6 days at 100 Hz, where GGIR would need gigabytes) is not
// filled but counted and noted ("timegaps_not_filled").
#ifndef GRAVCAL_DECODE_GGIR_TIMEGAPS_HPP
#define GRAVCAL_DECODE_GGIR_TIMEGAPS_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "decode.hpp"

namespace gravcal {

template <class Inner, class Acc = long double>
class GgirTimegapsOf : public Decoder {
 public:
  // sf: the rate GGIR imputes at (the layout's: rmc.sf or the header's)
  GgirTimegapsOf(std::unique_ptr<Inner> inner, double sf) : inner_(std::move(inner)), sf_(sf) {}

  bool open() override {
    const bool ok = inner_->open();
    info_ = inner_->info();
    error_ = inner_->error();
    report_ = inner_->report();
    if (!ok) return false;
    if (!(sf_ > 0)) sf_ = info_.sf;
    by_ = 1.0 / sf_;
    k_ = 0.25;
    if (k_ < 2 / sf_) k_ = 2 / sf_;
    raw_.assign(kCols * kRawChunk, 0.0);
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
        take(raw_at_++);
        continue;
      }
      if (left_ == 0 || inner_->done() || !refill()) end_call();
    }
    report_ = inner_->report();
    add_own(report_);
    report_.samples = given_;
    if (in_call_ || pending()) return 0;
    const std::int64_t u = call_units_;
    call_units_ = 0;
    return u;
  }

  bool done() const override {
    return inner_->done() && !in_call_ && !pending() && raw_at_ >= raw_n_;
  }
  std::size_t max_samples_per_unit() const override { return 2 * inner_->max_samples_per_unit(); }
  // (GgirResamplerOf's interface: a call goes on until its units are read)
  void continue_call(bool) {}

 private:
  static constexpr std::size_t kRawChunk = 4096;
  static constexpr std::size_t kCols = 5;  // x, y, z, t, time
  static constexpr double kMaxGapRows = 1e8;
  struct Run {
    double v[kCols];
    std::int64_t n, j;  // copies to give, copies given
  };

  bool pending() const { return head_ < runs_.size(); }

  void start_call(std::int64_t max_units) {
    in_call_ = true;
    left_ = max_units;
    first_ = true;
    have_held_ = false;
    have_zero_ = false;
    runs_.clear();
    head_ = 0;
  }

  bool refill() {
    SampleBuffer b = SampleBuffer::columns(raw_.data(), kRawChunk, true, true);
    const std::int64_t u = inner_->read(b, left_);
    call_units_ += u;
    if (left_ > 0) left_ -= u;
    raw_n_ = b.n;
    raw_at_ = 0;
    return b.n > 0 || u > 0;
  }

  void take(std::size_t i) {
    double s[kCols];
    for (std::size_t c = 0; c < kCols; ++c) s[c] = raw_[c * kRawChunk + i];
    const bool zero = s[0] == 0 && s[1] == 0 && s[2] == 0;
    if (first_) {
      first_ = false;
      if (zero) s[2] = 1;  // GGIR's PreviousLastValue c(0, 0, 1)
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

  void hold(const double* s) {
    for (std::size_t c = 0; c < kCols; ++c) held_[c] = s[c];
    have_held_ = true;
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
      if (n > kMaxGapRows) {
        ++gaps_not_filled_;
        if (gap_notes_.size() < 5) {
          gap_notes_.push_back("time stamps jump by " + std::to_string(dt) +
                               " s within a block; the gap is not filled");
        }
      } else {
        ++gaps_;
        rows_added_ += static_cast<std::int64_t>(n) - 1;
        r.n = static_cast<std::int64_t>(n);
        const Acc ss = static_cast<Acc>(r.v[0] * r.v[0]) + static_cast<Acc>(r.v[1] * r.v[1]) +
                       static_cast<Acc>(r.v[2] * r.v[2]);
        const double en = std::sqrt(static_cast<double>(ss));
        if ((std::fabs(en) - 1) > 0.005) {
          for (int c = 0; c < 3; ++c) r.v[c] = r.v[c] / en;
        }
      }
    }
    runs_.push_back(r);
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
        runs_.push_back(r);
      } else {
        release(held_[4]);
      }
    }
    have_zero_ = false;
  }

  void drain(SampleBuffer& out) {
    while (head_ < runs_.size() && !out.full()) {
      Run& r = runs_[head_];
      while (r.j < r.n && !out.full()) {
        const double j = static_cast<double>(r.j++);
        out.put(r.v[0], r.v[1], r.v[2], r.v[3], r.v[4] + j * by_);
        ++given_;
      }
      if (r.j == r.n) ++head_;
    }
    if (head_ == runs_.size()) {
      runs_.clear();
      head_ = 0;
    }
  }

  void add_own(Report& r) const {
    if (gaps_ > 0) r.count("timegaps_imputed", gaps_);
    if (rows_added_ > 0) r.count("timegap_samples_added", rows_added_);
    if (zeros_dropped_ > 0) r.count("timegaps_zero_samples_dropped", zeros_dropped_);
    if (gaps_not_filled_ > 0) r.count("timegaps_not_filled", gaps_not_filled_);
    for (const auto& n : gap_notes_) r.note(n);
  }

  std::unique_ptr<Inner> inner_;
  double sf_ = 0.0, by_ = 0.0, k_ = 0.25;
  std::vector<double> raw_;
  std::size_t raw_n_ = 0, raw_at_ = 0;
  bool in_call_ = false, first_ = true, have_held_ = false, have_zero_ = false;
  double held_[kCols] = {0, 0, 0, 0, 0};
  double zero_[kCols] = {0, 0, 0, 0, 0};
  std::vector<Run> runs_;
  std::size_t head_ = 0;
  std::int64_t left_ = -1, call_units_ = 0, given_ = 0;
  std::int64_t gaps_ = 0, rows_added_ = 0, zeros_dropped_ = 0;
  std::int64_t gaps_not_filled_ = 0;
  std::vector<std::string> gap_notes_;
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_GGIR_TIMEGAPS_HPP
