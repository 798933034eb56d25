// gravcal: GGIR's resampling of GENEActiv recordings at a rate that is not
// a whole number of Hz (85.7 Hz, for example).
//
// GGIR's g.readaccfile takes each block that GGIRread::readGENEActiv gives
// (one reader call: GGIR's block of pages) and, when the header's rate is
// not whole, interpolates it linearly onto the grid t1 + k / round(rate),
// from the block's first time stamp t1 to its last tn, as R's seq(t1, tn,
// by = 1 / round(rate)) gives it (k up to as.integer((tn - t1) / by +
// 1e-10)) and round() halving to even, less the grid's last point; every column, temperature included.
// A grid point g lies in the first interval (t[j-1], t[j]] of raw times
// with t[j] >= g (j >= 1), and takes u (v[j] - v[j-1]) + v[j-1] with u = (g
// - t[j-1]) / (t[j] - t[j-1]), as GGIRread::resample computes it; with
// GGIR's interpolationType = 2 (nearest neighbour) u is replaced by
// ggir_nearest_weight(u) (kernels/decode.hpp). GGIRread::resample is C++
// compiled by the R it runs in; where that compiler fused u (v[j] - v[j-1])
// + v[j-1] into one multiply-add (GCC's default on aarch64), `fused` does
// so too (kernels::ggir_lerp; R/fp-build.R finds out which).
//
// GgirResampler does this while the samples stream: a grid point is computed
// once its interval has arrived and given on once the grid is known to go
// beyond it (the block's last point is dropped), so it holds a few samples,
// never a block. Whole-Hz recordings pass through unchanged. Used only in
// GGIR-compatible mode (compat = 1); gravcal's own reads keep the samples
// as the device stored them.
//
// The same for Axivity csv exports (time stamp, x, y, z), which GGIR
// resamples block by block whatever their rate, onto the grid of the rate
// it found from the time stamps: GgirResamplerOf<CsvDecoder> with that
// `grid_rate` (> 0: always resample, at that rate). The inner decoder
// gives its time stamps and has continue_call() (one reader call in
// several reads; a no-op for csv).
#ifndef GRAVCAL_DECODE_GGIR_RESAMPLE_HPP
#define GRAVCAL_DECODE_GGIR_RESAMPLE_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "decode.hpp"
#include "decode_geneactiv.hpp"
#include "kernels.hpp"

namespace gravcal {

template <class Inner>
class GgirResamplerOf : public Decoder {
 public:
  // grid_rate: the output rate (0: the inner decoder's); interpolation: 1
  // linear, 2 nearest neighbour (GGIR's interpolationType); fused: GGIRread's
  // multiply-add rounded once
  explicit GgirResamplerOf(std::unique_ptr<Inner> inner, double grid_rate = 0,
                           int interpolation = 1, bool fused = false)
      : inner_(std::move(inner)),
        grid_rate_(grid_rate),
        nearest_(interpolation == 2),
        fused_(fused) {}

  bool open() override {
    const bool ok = inner_->open();
    info_ = inner_->info();
    error_ = inner_->error();
    report_ = inner_->report();
    if (!ok) return false;
    const double rate = info_.sf;
    // R's round(): halves to even (12.5 Hz becomes 12), as nearbyint in
    // the default rounding mode
    active_ = grid_rate_ > 0 || (rate > 0 && rate != std::nearbyint(rate));
    if (active_) {
      info_.sf = grid_rate_ > 0 ? grid_rate_ : std::nearbyint(rate);
      by_ = 1.0 / info_.sf;
      raw_.assign(kRawCols * kRawChunk, 0.0);
    }
    return true;
  }

  std::int64_t read(SampleBuffer& out, std::int64_t max_units) override {
    if (!active_) {
      const std::int64_t u = inner_->read(out, max_units);
      report_ = inner_->report();
      return u;
    }
    if (!in_call_ && head_ == ready_.size()) start_call(max_units);
    for (;;) {
      give(out);
      if (head_ < ready_.size()) break;  // out is full
      ready_.clear();
      head_ = 0;
      if (!in_call_) break;
      if (raw_at_ < raw_n_) {
        take(raw_at_++);
        continue;
      }
      // with no units left, a read still drains the samples of the last
      // page that did not fit; the call ends when nothing more comes
      if (inner_->done() || !refill()) end_call();
    }
    report_ = inner_->report();
    report_.samples = given_;
    // the call's units count once all its samples are given, so that a
    // caller reading a block of units gets the whole block
    if (in_call_ || head_ < ready_.size()) return 0;
    const std::int64_t u = call_units_;
    call_units_ = 0;
    return u;
  }

  bool done() const override {
    return inner_->done() && !in_call_ && head_ == ready_.size() && raw_at_ >= raw_n_;
  }

  std::size_t max_samples_per_unit() const override {
    return 2 * inner_->max_samples_per_unit();
  }

 private:
  static constexpr std::size_t kRawChunk = 4096;
  static constexpr std::size_t kRawCols = 5;  // x, y, z, t, time
  struct Point {
    std::int64_t k;
    double v[5];  // x, y, z, t, time
  };

  void start_call(std::int64_t max_units) {
    in_call_ = true;
    left_ = max_units;
    first_read_ = true;
    have_prev_ = false;
    k_ = 0;
    pending_.clear();
  }

  // Raw samples of the current call from the inner decoder; false when it
  // gave nothing.
  bool refill() {
    SampleBuffer b;
    b.x = raw_.data();
    b.y = b.x + kRawChunk;
    b.z = b.y + kRawChunk;
    b.t = b.z + kRawChunk;
    b.time = b.t + kRawChunk;
    b.capacity = kRawChunk;
    inner_->continue_call(!first_read_);
    first_read_ = false;
    const std::int64_t u = inner_->read(b, left_);
    inner_->continue_call(false);
    call_units_ += u;
    if (left_ > 0) left_ -= u;
    raw_n_ = b.n;
    raw_at_ = 0;
    return b.n > 0 || u > 0;
  }

  // One raw sample: the grid points up to its time, interpolated from the
  // interval that ends at it.
  void take(std::size_t i) {
    double cur[5];
    for (std::size_t c = 0; c < kRawCols; ++c) cur[c] = raw_[c * kRawChunk + i];
    if (!have_prev_) {
      for (int c = 0; c < 5; ++c) prev_[c] = cur[c];
      from_ = cur[4];
      have_prev_ = true;
      return;
    }
    for (;;) {
      const double g = from_ + static_cast<double>(k_) * by_;
      if (!(g <= cur[4])) break;
      Point p;
      p.k = k_++;
      double u = (g - prev_[4]) / (cur[4] - prev_[4]);
      if (nearest_) u = ggir_nearest_weight(u);
      for (int c = 0; c < 4; ++c) p.v[c] = kernels::ggir_lerp(u, prev_[c], cur[c], fused_);
      p.v[4] = g;
      pending_.push_back(p);
    }
    for (int c = 0; c < 5; ++c) prev_[c] = cur[c];
    last_ = cur[4];
    // a point is not the grid's last once the grid reaches the next one
    const double reach = (last_ - from_) / by_ + 1e-10;
    std::size_t m = 0;
    while (m < pending_.size() && static_cast<double>(pending_[m].k + 1) <= reach) ++m;
    confirm(m);
  }

  // The call ended: the grid runs to as.integer((tn - t1) / by + 1e-10); its
  // last point is dropped, as GGIR drops it.
  void end_call() {
    in_call_ = false;
    if (have_prev_) {
      const double n = std::floor((last_ - from_) / by_ + 1e-10);
      std::size_t m = 0;
      while (m < pending_.size() && static_cast<double>(pending_[m].k) < n) ++m;
      confirm(m);
    }
    pending_.clear();
  }

  void confirm(std::size_t m) {
    for (std::size_t i = 0; i < m; ++i) ready_.push_back(pending_[i]);
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(m));
  }

  void give(SampleBuffer& out) {
    while (head_ < ready_.size() && !out.full()) {
      const Point& p = ready_[head_++];
      out.put(p.v[0], p.v[1], p.v[2], p.v[3], p.v[4]);
      ++given_;
    }
  }

  std::unique_ptr<Inner> inner_;
  double grid_rate_ = 0.0;
  bool nearest_ = false;
  bool fused_ = false;
  bool active_ = false;
  double by_ = 0.0;
  std::vector<double> raw_;
  std::size_t raw_n_ = 0, raw_at_ = 0;
  bool in_call_ = false, first_read_ = true, have_prev_ = false;
  std::int64_t left_ = -1;
  std::int64_t call_units_ = 0;
  std::int64_t k_ = 0;
  double from_ = 0.0, last_ = 0.0;
  double prev_[5] = {0, 0, 0, 0, 0};
  std::vector<Point> pending_;  // computed, maybe the grid's last
  std::vector<Point> ready_;    // confirmed, not yet given
  std::size_t head_ = 0;
  std::int64_t given_ = 0;
};

using GgirResampler = GgirResamplerOf<GeneactivDecoder>;

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_GGIR_RESAMPLE_HPP
