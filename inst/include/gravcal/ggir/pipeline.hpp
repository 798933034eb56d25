// gravcal: the one pump from a sample source into a stage.
//
// Every path from samples to windows goes through pump(): a source gives
// samples (a device decoder, or columns in memory), a stage takes them (the
// segmenter alone, GGIR's block rules in front of the segmenter, or a
// collector of samples), and the stage hands each completed window to a
// sink. The pump counts the source's units (decoder units: .cwa blocks,
// GENEActiv pages, csv lines, .gt3x seconds; samples for columns) so that a
// caller can cut the stream where GGIR cuts its blocks.
//
//   source --(units)--> pump --(samples)--> stage --(windows)--> sink
//
// A source either lends its samples where they are (Source::borrow(): R's
// columns, no copy) or writes them where the stage asks (Source::read():
// decoders, straight into the block rules' buffer). A stage offers both:
// push() for lent samples, space() and commit() for written ones.
//
// Standard headers only (decode.hpp's interfaces); no R.
#ifndef GRAVCAL_PIPELINE_HPP
#define GRAVCAL_PIPELINE_HPP

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/ggir/ggir_blocks.hpp"
#include "gravcal/host/segmenter.hpp"

namespace gravcal {

// Samples lent by a source: valid until the next call on that source.
struct Chunk {
  const double* x = nullptr;
  const double* y = nullptr;
  const double* z = nullptr;
  const double* t = nullptr;  // null: no temperature
  std::size_t n = 0;
};

class Source {
 public:
  virtual ~Source() = default;
  // Lends the next samples of at most `max_units` units (negative: no
  // limit), setting `units` to the units they hold. False when this source
  // does not lend (then read() must be used); true with c.n == 0 at the end.
  virtual bool borrow(Chunk& c, std::int64_t max_units, std::int64_t& units) {
    (void)c;
    (void)max_units;
    (void)units;
    return false;
  }
  // Writes samples into out (out.n counts them) from at most `max_units`
  // units; returns the units consumed (Decoder::read()'s contract).
  virtual std::int64_t read(SampleBuffer& out, std::int64_t max_units) = 0;
  virtual bool done() const = 0;
  virtual bool has_temperature() const = 0;
  // The source gives a light value per sample (written into
  // SampleBuffer::light when the stage asks for it).
  virtual bool has_light() const { return false; }
};

// A device decoder as a source.
class DecoderSource : public Source {
 public:
  explicit DecoderSource(Decoder& d) : d_(d) {}
  std::int64_t read(SampleBuffer& out, std::int64_t max_units) override {
    return d_.read(out, max_units);
  }
  bool done() const override { return d_.done(); }
  bool has_temperature() const override { return d_.info().has_temperature; }
  bool has_light() const override { return d_.info().has_light; }
  Decoder& decoder() { return d_; }

 private:
  Decoder& d_;
};

// Columns in memory (one unit a sample), lent where they are.
class ColumnsSource : public Source {
 public:
  ColumnsSource() = default;
  ColumnsSource(const double* x, const double* y, const double* z, const double* t,
                std::size_t n) {
    reset(x, y, z, t, n);
  }
  // New columns (the next block of a source that holds one at a time).
  void reset(const double* x, const double* y, const double* z, const double* t,
             std::size_t n) {
    x_ = x;
    y_ = y;
    z_ = z;
    t_ = t;
    n_ = n;
    pos_ = 0;
  }
  bool borrow(Chunk& c, std::int64_t max_units, std::int64_t& units) override {
    const std::size_t k = take(max_units);
    c.x = x_ + pos_;
    c.y = y_ + pos_;
    c.z = z_ + pos_;
    c.t = t_ != nullptr ? t_ + pos_ : nullptr;
    c.n = k;
    pos_ += k;
    units = static_cast<std::int64_t>(k);
    return true;
  }
  std::int64_t read(SampleBuffer& out, std::int64_t max_units) override {
    const std::size_t k = std::min(take(max_units), out.room());
    std::memcpy(out.x + out.n, x_ + pos_, k * sizeof(double));
    std::memcpy(out.y + out.n, y_ + pos_, k * sizeof(double));
    std::memcpy(out.z + out.n, z_ + pos_, k * sizeof(double));
    if (out.t != nullptr) {
      if (t_ != nullptr) {
        std::memcpy(out.t + out.n, t_ + pos_, k * sizeof(double));
      } else {
        std::fill(out.t + out.n, out.t + out.n + k, std::numeric_limits<double>::quiet_NaN());
      }
    }
    out.n += k;
    pos_ += k;
    return static_cast<std::int64_t>(k);
  }
  bool done() const override { return pos_ >= n_; }
  bool has_temperature() const override { return t_ != nullptr; }
  std::size_t remaining() const { return n_ - pos_; }

 private:
  std::size_t take(std::int64_t max_units) const {
    const std::size_t left = n_ - pos_;
    if (max_units < 0) return left;
    return std::min(left, static_cast<std::size_t>(max_units));
  }
  const double* x_ = nullptr;
  const double* y_ = nullptr;
  const double* z_ = nullptr;
  const double* t_ = nullptr;
  std::size_t n_ = 0;
  std::size_t pos_ = 0;
};

// What the stages below share: lent samples go straight to the target
// (the segmenter, or GGIR's block rules), with their temperature when the
// stage takes it.
template <class Target>
class ForwardStage {
 public:
  ForwardStage(Target& to, bool temperature) : to_(to), temp_(temperature) {}
  bool temperature() const { return temp_; }
  template <class Sink>
  void push(const double* x, const double* y, const double* z, const double* t,
            std::size_t n, Sink&& sink) {
    to_.push(x, y, z, temp_ ? t : nullptr, n, sink);
  }

 protected:
  Target& to_;
  bool temp_;
};

// The segmenter as a stage: written samples go through a fixed buffer of
// `chunk` samples.
class SegmenterStage : public ForwardStage<Segmenter> {
 public:
  static constexpr std::size_t chunk = 1u << 16;
  SegmenterStage(Segmenter& seg, bool temperature)
      : ForwardStage(seg, temperature), buf_((temperature ? 4u : 3u) * chunk) {}
  BlockSpace space(std::size_t want) {
    BlockSpace s;
    s.x = buf_.data();
    s.y = s.x + chunk;
    s.z = s.y + chunk;
    s.t = temp_ ? s.z + chunk : nullptr;
    s.capacity = std::min(std::max<std::size_t>(want, 1), chunk);
    return s;
  }
  template <class Sink>
  void commit(std::size_t n, bool has_t, Sink&& sink) {
    const BlockSpace s = space(chunk);
    to_.push(s.x, s.y, s.z, has_t ? s.t : nullptr, n, sink);
  }

 private:
  std::vector<double> buf_;
};

// GGIR's block rules as a stage: they lend their own buffer for written
// samples and feed their segmenter themselves.
class BlocksStage : public ForwardStage<GgirBlocks> {
 public:
  BlocksStage(GgirBlocks& blocks, bool temperature) : ForwardStage(blocks, temperature) {}
  BlockSpace space(std::size_t want) { return to_.space(want); }
  template <class Sink>
  void commit(std::size_t n, bool has_t, Sink&& sink) {
    to_.commit(n, has_t, sink);
  }
};

// A collector of samples (a whole recording read into memory), with the
// source's time stamps when `time` and its light when `light` (only for a
// source that has light: Source::has_light()), written `chunk` samples at a
// time.
class CollectStage {
 public:
  enum Column { kX, kY, kZ, kTemperature, kTime, kLight, kColumns };
  CollectStage(bool temperature, bool time, std::size_t chunk = SegmenterStage::chunk,
               bool light = false)
      : temp_(temperature), time_(time), light_(light), chunk_(std::max<std::size_t>(chunk, 1)) {}
  bool temperature() const { return temp_; }
  bool light() const { return light_; }
  BlockSpace space(std::size_t want) {
    if (want < 1) want = 1;
    const std::size_t k = std::min(want, chunk_);
    grow(n_ + k);
    BlockSpace s;
    s.x = col[kX].data() + n_;
    s.y = col[kY].data() + n_;
    s.z = col[kZ].data() + n_;
    s.t = temp_ ? col[kTemperature].data() + n_ : nullptr;
    s.time = time_ ? col[kTime].data() + n_ : nullptr;
    s.light = light_ ? col[kLight].data() + n_ : nullptr;
    s.capacity = k;
    return s;
  }
  template <class Sink>
  void commit(std::size_t n, bool has_t, Sink&&) {
    if (temp_ && !has_t) nan_fill(kTemperature, n);
    n_ += n;
    grow(n_);
  }
  // lent samples (columns in memory: no time stamps, no light)
  template <class Sink>
  void push(const double* x, const double* y, const double* z, const double* t,
            std::size_t n, Sink&& sink) {
    grow(n_ + n);
    const double* in[4] = {x, y, z, t};
    for (int c = 0; c < 4; ++c) {
      if (on(c) && in[c] != nullptr) std::copy(in[c], in[c] + n, col[c].begin() + static_cast<std::ptrdiff_t>(n_));
    }
    if (time_) nan_fill(kTime, n);
    if (light_) nan_fill(kLight, n);
    commit(n, t != nullptr, sink);
  }
  std::size_t size() const { return n_; }
  // x, y, z, temperature, time, light (Column)
  std::vector<double> col[kColumns];

 private:
  bool on(int c) const {
    return c < 3 || (c == kTemperature && temp_) || (c == kTime && time_) || (c == kLight && light_);
  }
  void grow(std::size_t n) {
    for (int c = 0; c < kColumns; ++c) {
      if (on(c)) col[c].resize(n);
    }
  }
  void nan_fill(int c, std::size_t n) {
    std::fill(col[c].begin() + static_cast<std::ptrdiff_t>(n_),
              col[c].begin() + static_cast<std::ptrdiff_t>(n_ + n),
              std::numeric_limits<double>::quiet_NaN());
  }
  bool temp_, time_, light_;
  std::size_t chunk_;
  std::size_t n_ = 0;
};

struct PumpResult {
  std::int64_t units = 0;    // source units consumed
  std::int64_t samples = 0;  // samples given to the stage
  bool done = false;         // the source has nothing more
  bool stopped = false;      // tick() asked to stop
};

// Moves at most `max_units` units (negative: to the end) from `src` into
// `stage`; `sink` gets the windows. tick() is called every few chunks and
// returns true to stop (an interrupt). Stops early, with every unit counted
// read and its samples given, or when the source is done.
template <class Stage, class Sink, class Tick>
PumpResult pump(Source& src, Stage& stage, std::int64_t max_units, Sink&& sink,
                Tick&& tick) {
  PumpResult r;
  std::int64_t left = max_units;
  int rounds = 0;
  const bool want_t = stage.temperature() && src.has_temperature();
  while (!src.done()) {
    std::int64_t u = 0;
    std::size_t n = 0;
    bool room_left = true;
    Chunk c;
    if (src.borrow(c, left, u)) {
      stage.push(c.x, c.y, c.z, want_t ? c.t : nullptr, c.n, sink);
      n = c.n;
    } else {
      const BlockSpace s = stage.space(SegmenterStage::chunk);
      SampleBuffer out;
      out.x = s.x;
      out.y = s.y;
      out.z = s.z;
      out.t = want_t ? s.t : nullptr;
      out.time = s.time;
      out.light = src.has_light() ? s.light : nullptr;  // only a stage that asks
      out.capacity = s.capacity;
      u = src.read(out, left);
      stage.commit(out.n, out.t != nullptr, sink);
      n = out.n;
      room_left = !out.full();
    }
    r.units += u;
    r.samples += static_cast<std::int64_t>(n);
    if (left > 0) left -= u;
    if (n == 0 && u == 0) break;  // nothing more for now
    // every unit asked for is read and all its samples given; a buffer that
    // filled part-way through the last unit has the next round (left == 0)
    // give the rest of it
    if (left == 0 && room_left) break;
    if ((++rounds & 31) == 0 && tick()) {
      r.stopped = true;
      break;
    }
  }
  r.done = src.done();
  return r;
}

// One of GGIR's blocks: `units` source units through the block rules
// (begin_block(), the pump, end_block()).
struct GgirBlockRead {
  GgirBlockInfo info;
  PumpResult pump;
};

template <class Sink, class Tick>
GgirBlockRead read_ggir_block(Source& src, GgirBlocks& blocks, BlocksStage& stage,
                              std::int64_t units, Sink&& sink, Tick&& tick) {
  GgirBlockRead r;
  blocks.begin_block();
  try {
    r.pump = pump(src, stage, units, sink, tick);
    r.info = blocks.end_block(sink);
  } catch (...) {
    blocks.settle();  // the segmenter done with `sink` before it goes
    throw;
  }
  return r;
}

}  // namespace gravcal

#endif  // GRAVCAL_PIPELINE_HPP
