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
// ggir_nearest_weight(u) (kernels/ggir_grid.hpp). GGIRread::resample is C++
// compiled by the R it runs in; where that compiler fused u (v[j] - v[j-1])
// + v[j-1] into one multiply-add (GCC's default on aarch64), `fused` does
// so too (kernels::ggir_lerp; R/fp-build.R finds out which).
//
// The stepping over the grid is GGIR's one grid walk (kernels/ggir_grid.hpp:
// a regular grid, the weight not clamped); the keep-last rule below is the
// resampler's own.
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
//
// And for GGIR's ad hoc csv files read with rmc.doresample = TRUE and a
// UNIX time column (GGIR's read.myacc.csv): the same per block, but the
// grid keeps its last point, which R's seq() clamps to the block's last
// time stamp (pmin(x, to)): `keep_last`.
//
// Light, where the inner decoder has it (GENEActiv), is resampled as the
// other columns are (GGIR's g.readaccfile resamples every column of
// readGENEActiv's data but time). It is asked of the inner decoder from the
// first read() whose buffer asks for it on: a caller that asks for light
// after its first read gets NaN for the samples resampled before.
//
// Grid points are made at most kGenBatch at a time, so that a long gap in
// the time stamps (which GGIR fills by interpolation) costs time, not
// memory; a gap of more than kMaxGapPoints grid points (about 11.6 days at
// 100 Hz, where GGIR would need gigabytes) is not filled but counted and
// noted ("resample_gaps_not_filled"), and a time stamp that is not a finite
// number, or lies more than 2^51 grid steps from 1970, is left out with its
// sample ("resample_bad_time"); but for Axivity csv exports (nan_stuck) a
// NaN time stamp (GGIR's NA, where force_tz() puts a stamp in an hour the
// zone's clocks skip) is read as GGIRread::resample() reads it: every grid
// point after the stamp before it NA, to the end of the block.
//
// What it forwards to the decoder it wraps (opening it, its report, its
// units) is ForwardingDecoder's (decode_forwarding.hpp), shared with the
// other decorator.
#ifndef GRAVCAL_DECODE_GGIR_RESAMPLE_HPP
#define GRAVCAL_DECODE_GGIR_RESAMPLE_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/decoders/decode_forwarding.hpp"
#include "gravcal/decoders/decode_geneactiv.hpp"
#include "gravcal/kernels/kernels.hpp"

namespace gravcal {

template <class Inner>
class GgirResamplerOf : public ForwardingDecoder<Inner, GgirResamplerOf<Inner>> {
  using Base = ForwardingDecoder<Inner, GgirResamplerOf<Inner>>;
  friend Base;  // add_own()
  using Base::inner_;
  using Base::info_;

 public:
  // grid_rate: the output rate (0: the inner decoder's); interpolation: 1
  // linear, 2 nearest neighbour (GGIR's interpolationType); fused: GGIRread's
  // multiply-add rounded once
  // nan_stuck: a time stamp that is NaN read as GGIRread::resample() reads
  // it (below: every grid point after the time stamp before it NaN, to the
  // call's end)
  explicit GgirResamplerOf(std::unique_ptr<Inner> inner, double grid_rate = 0,
                           int interpolation = 1, bool keep_last = false,
                           bool fused = false, bool nan_stuck = false)
      : Base(std::move(inner)), grid_rate_(grid_rate), keep_last_(keep_last),
        nan_stuck_(nan_stuck) {
    walk_.interp.nearest = interpolation == 2;
    walk_.interp.fused = fused;
  }

  bool open() override {
    if (!this->open_inner()) return false;
    const double rate = info_.sf;
    // R's round(): halves to even (12.5 Hz becomes 12), as nearbyint in
    // the default rounding mode
    active_ = grid_rate_ > 0 || (rate > 0 && rate != std::nearbyint(rate));
    if (active_) {
      info_.sf = grid_rate_ > 0 ? grid_rate_ : std::nearbyint(rate);
      walk_.grid.by = 1.0 / info_.sf;
      raw_.assign(kRawCols * kRawChunk, 0.0);
      // a wear flag is not resampled (GGIR's reader stops on a resampled
      // one: it is no longer TRUE/FALSE)
      info_.has_wear = false;
    }
    return true;
  }

  std::int64_t read(SampleBuffer& out, std::int64_t max_units) override {
    if (out.light != nullptr && info_.has_light) want_light_ = true;
    if (!active_) {
      const std::int64_t u = inner_->read(out, max_units);
      this->report_ = inner_->report();
      return u;
    }
    if (!in_call_ && head_ == ready_.size()) start_call(max_units);
    for (;;) {
      give(out);
      if (head_ < ready_.size()) break;  // out is full
      ready_.clear();
      head_ = 0;
      if (!in_call_) break;
      if (gen_active_) {
        generate();
        continue;
      }
      if (raw_at_ < raw_n_) {
        take(raw_at_++);
        continue;
      }
      // with no units left, a read still drains the samples of the last
      // page that did not fit; the call ends when nothing more comes
      if (inner_->done() || !refill()) end_call();
    }
    this->forward_report();
    return this->call_units(in_call_ || head_ < ready_.size());
  }

  bool done() const override {
    return inner_->done() && !in_call_ && !gen_active_ && head_ == ready_.size() &&
           raw_at_ >= raw_n_;
  }
  // passing through (a whole rate): the inner decoder's times are these
  bool call_end_times(Decoder::CallEndTimes& t) const override {
    return !active_ && inner_->call_end_times(t);
  }

 private:
  static constexpr std::size_t kRawChunk = 4096;
  static constexpr std::size_t kGenBatch = 4096;
  static constexpr double kMaxGapPoints = 1e8;
  static constexpr double kMaxTimeSteps = 2251799813685248.0;  // 2^51
  static constexpr std::size_t kRawCols = 6;  // x, y, z, t, time, light
  static constexpr int kLight = 5;
  struct Point {
    std::int64_t k;
    double v[kRawCols];  // x, y, z, t, time, light
  };

  void start_call(std::int64_t max_units) {
    in_call_ = true;
    this->left_ = max_units;
    first_read_ = true;
    have_prev_ = false;
    have_interval_ = false;
    gen_active_ = false;
    stuck_ = false;
    last_nan_ = false;
    k_ = 0;
    pending_.clear();
  }

  // Raw samples of the current call from the inner decoder; false when it
  // gave nothing.
  bool refill() {
    raw_light_ = want_light_;
    SampleBuffer b = SampleBuffer::columns(raw_.data(), kRawChunk, true, true, raw_light_);
    inner_->continue_call(!first_read_);
    first_read_ = false;
    const std::int64_t u = this->read_inner(b);
    inner_->continue_call(false);
    raw_n_ = b.n;
    raw_at_ = 0;
    return b.n > 0 || u > 0;
  }

  // One raw sample: the grid points up to its time, interpolated from the
  // interval that ends at it.
  void take(std::size_t i) {
    for (std::size_t c = 0; c < kRawCols; ++c) cur_[c] = raw_[c * kRawChunk + i];
    if (!raw_light_) cur_[kLight] = std::numeric_limits<double>::quiet_NaN();
    // GGIRread::resample() on a NaN time stamp (nan_stuck): its search for
    // the interval of a grid point stops there (NaN compares false) and
    // stays, so every grid point past the time stamp before it is NA (the
    // stamp's NA carried), in every column, to the end of the call; a call
    // whose first or last time stamp is NaN is one GGIR's seq() of the grid
    // stops on (counted)
    last_nan_ = false;
    if (nan_stuck_ && std::isnan(cur_[4])) {
      if (!have_prev_) ++nan_edges_;
      stuck_ = true;
      last_nan_ = true;
      return;
    }
    // a time stamp so far from 1970 that one grid step is below its
    // resolution (beyond 2^51 steps: more than 700,000 years at 100 Hz)
    // has no grid around it: left out as a non-finite one is (the grid's
    // k and its points would stop moving, and the loops with them)
    if (!(std::fabs(cur_[4]) < kMaxTimeSteps * walk_.grid.by)) {
      ++bad_time_;
      return;
    }
    if (!have_prev_) {
      for (std::size_t c = 0; c < kRawCols; ++c) prev_[c] = cur_[c];
      walk_.grid.origin = cur_[4];
      have_prev_ = true;
      return;
    }
    if ((cur_[4] - prev_[4]) / walk_.grid.by > kMaxGapPoints) {
      // not filled: the grid goes on after the gap
      ++gaps_not_filled_;
      if (gap_notes_.size() < 5) {
        gap_notes_.push_back("time stamps jump by " + std::to_string(cur_[4] - prev_[4]) +
                             " s within a block; the gap is not filled by resampling");
      }
      double k = std::floor((cur_[4] - walk_.grid.origin) / walk_.grid.by);
      while (k > 0 && walk_.grid.at(k) > cur_[4]) k -= 1;
      while (walk_.grid.at(k) <= cur_[4]) k += 1;
      k_ = static_cast<std::int64_t>(k);
      end_interval();
      return;
    }
    gen_active_ = true;
    generate();
  }

  // Grid points up to cur_'s time, interpolated from the interval (prev_,
  // cur_], at most kGenBatch of them per call.
  void generate() {
    std::size_t made = 0;
    const bool ended = walk_.through(
        k_, cur_[4], [&](std::int64_t) { return made < kGenBatch; },
        [&](std::int64_t k, double g) GRAVCAL_GRID_POINT {
          pending_.push_back(point_at(k, g, prev_, cur_));
          ++made;
          return true;
        });
    if (ended) {
      gen_active_ = false;
      end_interval();
      return;
    }
    confirm_upto(cur_[4]);
  }

  // Grid point k at time g, interpolated between the raw samples lo and hi
  // (the interval (lo's time, hi's time]).
  Point point_at(std::int64_t k, double g, const double* lo, const double* hi) const {
    Point p;
    p.k = k;
    p.v[4] = g;
    if (stuck_) {
      // (R's NA: the NA time stamp's payload, carried through GGIRread's
      // arithmetic)
      const double nan = r_na_real();
      for (int c = 0; c < 4; ++c) p.v[c] = nan;
      p.v[kLight] = want_light_ ? nan : 0.0;
      return p;
    }
    const double u = walk_.weight(g, lo[4], hi[4]);
    for (int c = 0; c < 4; ++c) p.v[c] = walk_.value(u, lo[c], hi[c]);
    p.v[kLight] = want_light_ ? walk_.value(u, lo[kLight], hi[kLight]) : 0.0;
    return p;
  }

  void end_interval() {
    for (std::size_t c = 0; c < kRawCols; ++c) {
      prev2_[c] = prev_[c];
      prev_[c] = cur_[c];
    }
    have_interval_ = true;
    last_ = cur_[4];
    confirm_upto(last_);
  }

  // A point is not the grid's last once the grid reaches the next one
  // (with keep_last: a point the grid reaches is in it), the grid reaching
  // as far as time stamp t.
  void confirm_upto(double t) {
    const double reach = (t - walk_.grid.origin) / walk_.grid.by + 1e-10;
    const std::int64_t ahead = keep_last_ ? 0 : 1;
    std::size_t m = 0;
    while (m < pending_.size() && static_cast<double>(pending_[m].k + ahead) <= reach) ++m;
    confirm(m);
  }

  void add_own(Report& r) const {
    if (bad_time_ > 0) r.count("resample_bad_time", bad_time_);
    if (gaps_not_filled_ > 0) r.count("resample_gaps_not_filled", gaps_not_filled_);
    if (nan_edges_ > 0) {
      r.count("resample_nan_edge", nan_edges_);
      r.note("a block of GGIR's reading starts or ends with a time stamp that is NA, on which "
             "GGIR's resampling stops");
    }
    for (const auto& n : gap_notes_) r.note(n);
  }

  // The call ended: the grid runs to as.integer((tn - t1) / by + 1e-10); its
  // last point is dropped, as GGIR drops it.
  // With keep_last the grid's last point stays; where it lies beyond the
  // last time stamp (the 1e-10), R's seq() puts it at that time stamp, so
  // it is interpolated there, from the block's last interval.
  void end_call() {
    in_call_ = false;
    if (last_nan_) ++nan_edges_;
    if (have_prev_) {
      const double n = std::floor((last_ - walk_.grid.origin) / walk_.grid.by + 1e-10);
      std::size_t m = 0;
      if (keep_last_) {
        while (m < pending_.size() && static_cast<double>(pending_[m].k) <= n) ++m;
      } else {
        while (m < pending_.size() && static_cast<double>(pending_[m].k) < n) ++m;
      }
      confirm(m);
      if (keep_last_ && have_interval_ && static_cast<double>(k_) == n) {
        ready_.push_back(point_at(k_++, last_, prev2_, prev_));
      }
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
      if (out.light != nullptr) out.light[out.n] = p.v[kLight];
      out.put(p.v[0], p.v[1], p.v[2], p.v[3], p.v[4]);
      ++this->given_;
    }
  }

  double grid_rate_ = 0.0;
  bool keep_last_ = false;
  bool nan_stuck_ = false;
  bool stuck_ = false;     // a NaN time stamp seen in this call (nan_stuck_)
  bool last_nan_ = false;  // the call's last raw sample so far had a NaN time
  std::int64_t nan_edges_ = 0;
  bool active_ = false;
  bool want_light_ = false;  // light asked for (and the inner decoder has it)
  bool raw_light_ = false;   // the raw samples in raw_ have light
  // the grid, origin + k by (the origin the call's first time stamp), its
  // weights unclamped (GGIRread::resample's)
  kernels::GridWalk<kernels::RegularGrid, kernels::UnclampedWeight> walk_;
  std::vector<double> raw_;
  std::size_t raw_n_ = 0, raw_at_ = 0;
  bool in_call_ = false, first_read_ = true, have_prev_ = false, have_interval_ = false;
  bool gen_active_ = false;  // grid points of (prev_, cur_] still to make
  double cur_[kRawCols] = {0, 0, 0, 0, 0, 0};
  std::int64_t bad_time_ = 0, gaps_not_filled_ = 0;
  std::vector<std::string> gap_notes_;
  std::int64_t k_ = 0;
  double last_ = 0.0;
  double prev_[kRawCols] = {0, 0, 0, 0, 0, 0};
  double prev2_[kRawCols] = {0, 0, 0, 0, 0, 0};  // the sample before prev_
  std::vector<Point> pending_;  // computed, maybe the grid's last
  std::vector<Point> ready_;    // confirmed, not yet given
  std::size_t head_ = 0;
};

using GgirResampler = GgirResamplerOf<GeneactivDecoder>;

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_GGIR_RESAMPLE_HPP
