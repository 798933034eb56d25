// gravcal: streaming decoder for Parmay Matrix (MTX) .bin/.BIN files.
//
// Format (as GGIRread 1.2.0's readParmayMatrix() documents and reads it):
// - bytes 0-511: free text (remarks);
// - byte 512: "MDTC"; 516: the number of packets (int32, little-endian);
//   520: the accelerometer's range in g (int16); 522: the gyroscope's range;
// - then packets, each starting with "MDTCPACK"; a packet runs to the next
//   "MDTCPACK" (or the end of the file). At its byte 8 a CRC-32 (IEEE, as
//   zlib's) of its bytes from 12 to its end; at 12 the time of its first
//   sample and at 16 the time after its last (int32 s since 1970 UTC); at
//   20, 24, 28, 32 the counts of accelerometer, gyroscope, temperature and
//   heart-rate samples (int32); from 36 the samples in that order:
//   accelerometer x, y, z and gyroscope x, y, z as int16 (a value v is
//   v * range / 32767 for v >= 0, v * range / 32768 below), temperature as
//   two int16 in tenths of a degree (body surface, ambient), heart rate as
//   two int16.
// - the sampling rate is not stored: it is the nearest of 12.5, 25, 50 and
//   100 Hz to the count / duration of the first packet of 10 s or more.
//
// What the decoder gives is what GGIR gets from readParmayMatrix(): a packet's
// samples are spread evenly from its start to its end less one period (a
// packet that starts one second or more after the previous one ended is
// moved back to that end), and the samples of the whole file are
// resampled onto one grid, start + k / rate, k up to the span times the
// rate, linearly (option interpolation = 1) or to the nearest sample
// (interpolation = 2) as GGIRread::resample() does; the temperature (the
// ambient column, as GGIR uses it) onto the same grid, NA outside the
// temperature's own time span. GGIR reads the whole file in one call (the
// reader reads from its start to the file's end whatever the end asked),
// so the decoder's unit, one packet, only counts progress.
// No light: the format has no light sensor and readParmayMatrix() gives no
// light column (acceleration, gyroscope, temperatures, heart rate), so
// DeviceInfo::has_light stays false and SampleBuffer::light is not written.
//
// Damage: a packet whose CRC does not match is counted (bad_checksum). In
// GGIR-compatible mode (option compat = 1, the default) it stays in the
// data as GGIRread keeps it: acceleration (0, 0, 1) g for as many samples
// as it claims (and the file holds), temperature the mean of the
// neighbouring good packets'; compat = 0 skips it, samples and times, and
// gives every packet's samples at their times (from the packet's start to
// its end less one period), without the grid, so that what a skipped packet
// held is a gap (gaps, gap_seconds count the jumps of a second or more). A
// packet too short for its header, or with a negative count (GGIRread fails
// on it), is skipped (short_packet, bad_packet_counts); in compat = 1 a
// packet whose samples the file does not hold gives one row of NA (as
// GGIRread's reading of no values does), compat = 0 gives none. Nothing read
// from the file sizes memory: the packet table grows with the packets
// actually found (at least 36 bytes each), and samples are read through
// small fixed buffers.
//
// The file's packets and the cursors over their samples are
// decode_parmay_packets.hpp's (ParmayFile, ParmayStream); the resampling
// here is GGIR's grid walk (kernels/ggir_grid.hpp) with the weight clamped
// to [0, 1], as GGIRread resamples for readParmayMatrix().
//
// Not reproduced (GGIRread's behaviour in cases that real files do not
// show, each counted where seen): temperature times out of order
// (GGIRread sorts them: temperature_time_backwards), equal temperature
// times (averaged, but GGIRread also rounds every time to 15 digits then:
// temperature_duplicate_times).
#ifndef GRAVCAL_DECODE_PARMAY_HPP
#define GRAVCAL_DECODE_PARMAY_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/decoders/decode_parmay_packets.hpp"
#include "gravcal/kernels/kernels.hpp"

namespace gravcal {

class ParmayDecoder : public Decoder {
 public:
  // Samples one packet can hold is bounded by the file only; a unit (a
  // packet) is a count of progress, not a size to allocate for.
  static constexpr std::size_t kMaxSamplesPerUnit = 1u << 20;

  ParmayDecoder(ByteSource& src, const Options& opts)
      : rules_(ReadRules::of(opts)),
        run_loop_(opts.num("run_loop", 1) != 0),
        file_(src, rules_.compat, report_) {
    walk_.interp.nearest = rules_.nearest();
    walk_.interp.fused = rules_.fused;
  }

  bool open() override {
    if (!file_.open()) {
      error_ = file_.error();
      return false;
    }
    info_.format = "parmay";
    info_.device = "Parmay Matrix";
    info_.sf = file_.sf();
    info_.has_temperature = file_.any_temp();
    info_.has_time = true;
    info_.range_g = static_cast<double>(file_.range());
    if (!file_.packets().empty()) info_.start_time = file_.packets()[0].t0;
    // GGIRread gives nothing when the header declares no packet
    if (rules_.compat && file_.declared() < 1) {
      report_.note("the header declares " + std::to_string(file_.declared()) +
                   " packets: no samples (as GGIRread)");
      finished_ = true;
    }
    acc_rows_.init(&file_, ParmayStream::kAcc);
    acc_times_.init(&file_, ParmayStream::kAcc);
    temp_rows_.init(&file_, ParmayStream::kTemp);
    temp_times_.init(&file_, ParmayStream::kTemp);
    walk_.grid.by = file_.by();
    return true;
  }

  std::int64_t read(SampleBuffer& out, std::int64_t max_units) override {
    std::int64_t units = 0;
    while (!out.full()) {
      if (rules_.compat && ((run_loop_ && run(out)) || next_points(out))) continue;
      if (finished_) break;
      if (chunk_.i >= chunk_.n) {
        // the next raw samples: the rest of a packet at most, so that a
        // call can stop at a packet's start
        if (chunk_.last) {
          finish();
          continue;
        }
        if (max_units >= 0 && units >= max_units && acc_rows_.at_packet_start()) break;
        units += fill_chunk();
        if (chunk_.n == 0) finish();
        continue;
      }
      const int i = chunk_.i++;
      const double v[3] = {chunk_.x[i], chunk_.y[i], chunk_.z[i]};
      if (!rules_.compat) {
        // gravcal's own reading: the samples at their times, no grid
        put(out, v, chunk_.t[i]);
        continue;
      }
      take(v, chunk_.t[i]);
    }
    report_.units = acc_rows_.packets_done;
    return units;
  }

  bool done() const override { return finished_ && held_n_ == 0; }

  std::size_t max_samples_per_unit() const override { return kMaxSamplesPerUnit; }

  // The packets as stored, for GGIR's QClog of them (readParmayMatrix()'s,
  // built in R): each one's times t0 and t1 (its header's, before any
  // move), its count of accelerometer samples and whether its checksum
  // matched (1, 0). The packets the decoder keeps: with compat = 0 not the
  // damaged ones, never those too short for a header or with a negative
  // count (GGIRread stops on those).
  UnitLog unit_log() const override {
    UnitLog log;
    log.names = {"t0", "t1", "n_acc", "checksum_pass"};
    log.columns.assign(4, std::vector<double>());
    for (auto& c : log.columns) c.reserve(file_.packets().size());
    for (const ParmayFile::Packet& p : file_.packets()) {
      log.columns[0].push_back(p.t0);
      log.columns[1].push_back(p.t1);
      log.columns[2].push_back(static_cast<double>(p.n_acc));
      log.columns[3].push_back(p.ok ? 1.0 : 0.0);
    }
    return log;
  }

 private:



  // Raw acceleration samples read ahead: rows and times, paired in order
  // as GGIRread pairs them (the two streams count a packet's samples each
  // its own way, see ParmayStream::rows()), at most the rest of one packet
  // of rows at a time.
  static constexpr int kChunk = ParmayStream::kMaxRows;
  struct Chunk {
    std::vector<double> buf = std::vector<double>(4 * kChunk);
    double* x = buf.data();
    double* y = x + kChunk;
    double* z = y + kChunk;
    double* t = z + kChunk;
    int n = 0, i = 0;
    bool last = false;  // the times (or rows) ended within this chunk
    Chunk() = default;
    Chunk(const Chunk&) = delete;  // x..t point into buf
    Chunk& operator=(const Chunk&) = delete;
  };

  // Fills the chunk; returns the packets the row stream moved past. An
  // empty chunk: the end.
  std::int64_t fill_chunk() {
    const std::int64_t before = acc_rows_.packets_done;
    const int rows = acc_rows_.next_rows(chunk_.x, chunk_.y, chunk_.z, kChunk);
    const int times = rows > 0 ? acc_times_.next_times(chunk_.t, rows) : 0;
    chunk_.n = times;
    chunk_.i = 0;
    chunk_.last = times < rows;
    return acc_rows_.packets_done - before;
  }


  // ---- resampling onto the grid start + k / rate
  //
  // Grid point k (at g = start + k / rate) takes the first raw interval
  // (t[j-1], t[j]] with t[j] >= g. Points are made one at a time from the
  // current interval (so a long gap costs time, never memory); the grid has
  // floor((last - start) * rate) + 1 points, so a point is given once the
  // raw times so far reach that far (`confirmed_`): the few that the last
  // time does not confirm wait in `held_` (a ring; rounding makes at most
  // one or two) and are dropped at the end. next_points() and take() do
  // this point by point; run() does the same in one loop for the usual
  // case (the fuzzer compares the two, option run_loop).

  struct Point {
    std::int64_t k;
    double v[3];
  };
  using Walk = kernels::GridWalk<kernels::RegularGrid, kernels::ClampedWeight>;

  // One raw acceleration sample at time t: the next interval.
  void take(const double* v, double t) {
    if (!have_prev_) {
      walk_.grid.origin = t;
      have_prev_ = true;
    } else {
      have_interval_ = true;
    }
    for (int c = 0; c < 3; ++c) {
      prev_v_[c] = cur_v_[c];
      cur_v_[c] = v[c];
    }
    prev_t_ = cur_t_;
    cur_t_ = t;
    confirmed_ = std::floor((t - walk_.grid.origin) * file_.sf()) + 1;
  }

  // Gives grid points while the buffer has room: first the held ones the
  // raw times now confirm, then those of the current interval (held, in
  // order, while an earlier one is); false when it gave or held none (a
  // new raw sample is needed).
  // (The held points come first and only at first: once the head of
  // held_ is not confirmed, no later point is, as confirmed_ stays put
  // until take().)
  bool next_points(SampleBuffer& out) {
    bool any = false;
    while (!out.full() && held_n_ > 0 && static_cast<double>(held_[held_at_].k) < confirmed_) {
      const Point& p = held_[held_at_];
      put(out, p.v, walk_.grid.at(p.k));
      held_at_ = (held_at_ + 1) % kMaxHeld;
      --held_n_;
      any = true;
    }
    if (out.full() || !have_interval_ || finished_) return any;
    const bool ended = walk_.through(
        k_, cur_t_, [&](std::int64_t) { return !out.full(); },
        [&](std::int64_t k, double g) GRAVCAL_GRID_POINT {
          const double u = walk_.weight(g, prev_t_, cur_t_);
          double v[3];
          for (int c = 0; c < 3; ++c) v[c] = walk_.value(u, prev_v_[c], cur_v_[c]);
          any = true;
          if (held_n_ == 0 && static_cast<double>(k) < confirmed_) {
            put(out, v, g);
            return true;
          }
          if (held_n_ == kMaxHeld) {
            // raw times that ran backwards: the oldest held point is dropped
            held_at_ = (held_at_ + 1) % kMaxHeld;
            --held_n_;
            report_.count("grid_points_dropped");
          }
          Point& p = held_[(held_at_ + held_n_) % kMaxHeld];
          p.k = k;
          for (int c = 0; c < 3; ++c) p.v[c] = v[c];
          ++held_n_;
          return true;
        });
    if (ended) have_interval_ = false;
    return any;
  }

  // temp_at()'s arithmetic where the temperature's interval stays put
  // (run()'s copy of its state): mode 0 no temperature, 1 NA from here,
  // 2 interpolated between (tp_t, tp_v) and (tc_t, tc_v).
  struct TempSpan {
    int mode;
    double first, tp_t, tc_t, tp_v, tc_v;
    Walk walk;
    double na;
    // false where the interval must move (temp_at() then)
    bool at(double g, double* out) const {
      *out = na;
      if (mode != 2 || g < first) return true;
      if (tc_t < g) return false;
      *out = walk.value(walk.weight(g, tp_t, tc_t), tp_v, tc_v);
      return true;
    }
  };

  // The usual case of next_points() and take() in one loop, the state in
  // locals (the output columns could alias the members), the temperature's
  // interval not to move. A point the raw times do not yet confirm (about
  // every other one where samples and grid share the rate: a rounding
  // decides) is written at once all the same, and counted as unconfirmed
  // until a later raw time confirms it: no branch on that rounding. Points
  // leave in the order made, as held_ gives them, and one's temperature
  // does not depend on when it is given (temp_at()'s interval moves only
  // for a later time); the unconfirmed ones still at the end go back to
  // held_. Leaves the rest (the first sample, the temperature's next row,
  // more unconfirmed points than kMaxUnconfirmed, a new chunk) to
  // next_points(), take() and temp_at(), with the same arithmetic; false
  // when it did nothing. It takes the walk's grid, weight and
  // interpolation (walk_) but steps the grid itself, not through
  // GridWalk::through() as next_points() does: with through() and its
  // lambdas, this loop ran about 10% more instructions (callgrind, GCC 12
  // -O2: the lambdas' captured state left registers), and this is the
  // decoder's hot loop.
  bool run(SampleBuffer& out) {
    if (held_n_ != 0 || finished_ || !have_prev_) return false;
    const bool temp_cols = out.t != nullptr, time_col = out.time != nullptr;
    const double na = r_na_real();
    // the temperature: 0 none (NA), 1 NA from here, 2 interpolated
    int temp_mode = 0;
    if (file_.any_temp()) {
      if (!temp_started_) return false;
      temp_mode = temp_ended_ ? 1 : 2;
    }
    // the walk in a local, as the rest of the state
    const Walk walk = walk_;
    const TempSpan ts{temp_mode, temp_first_, tp_t_, tc_t_, tp_v_, tc_v_, walk, na};
    const double start = walk.grid.origin, sf = file_.sf();
    double prev_t = prev_t_, cur_t = cur_t_;
    double p0 = prev_v_[0], p1 = prev_v_[1], p2 = prev_v_[2];
    double c0 = cur_v_[0], c1 = cur_v_[1], c2 = cur_v_[2];
    bool interval = have_interval_;
    double kd = static_cast<double>(k_);
    int i = chunk_.i;
    const int n_raw = chunk_.n;
    std::size_t o = out.n;
    const std::size_t cap = out.capacity;
    bool progress = false;
    // k < confirmed_ (= floor(x) + 1, x = (cur_t - start) sf) is k <= x for
    // a whole k (false for x NaN either way)
    double x_conf = (cur_t - start) * sf;
    // the unconfirmed points: the last `unconf` written, from k = k_unconf
    int unconf = 0;
    double k_unconf = 0;
    for (;;) {
      while (interval && o < cap) {
        const double g = walk.grid.at(kd);
        if (!(g <= cur_t)) {
          interval = false;
          break;
        }
        if (unconf == kMaxUnconfirmed) goto leave;
        double temp;
        if (!ts.at(g, &temp)) goto leave;  // the next temperature row
        const double u = walk.weight(g, prev_t, cur_t);
        out.x[o] = walk.value(u, p0, c0);
        out.y[o] = walk.value(u, p1, c1);
        out.z[o] = walk.value(u, p2, c2);
        if (temp_cols) out.t[o] = temp;
        if (time_col) out.time[o] = g;
        ++o;
        // held_ would hold it: after an unconfirmed one, or not confirmed
        const bool hold = unconf > 0 || !(kd <= x_conf);
        k_unconf = unconf == 0 ? kd : k_unconf;
        unconf += hold;
        kd += 1;
        progress = true;
      }
      if (o >= cap || i >= n_raw) break;
      // take(): the next raw sample
      p0 = c0;
      p1 = c1;
      p2 = c2;
      c0 = chunk_.x[i];
      c1 = chunk_.y[i];
      c2 = chunk_.z[i];
      prev_t = cur_t;
      cur_t = chunk_.t[i];
      x_conf = (cur_t - start) * sf;
      interval = true;
      ++i;
      progress = true;
      // the unconfirmed points this time confirms, in order (at most two
      // without a branch)
      int c = (k_unconf <= x_conf) + (k_unconf + 1 <= x_conf);
      c = c < unconf ? c : unconf;
      unconf -= c;
      k_unconf += c;
      while (unconf > 0 && k_unconf <= x_conf) {
        --unconf;
        k_unconf += 1;
      }
    }
  leave:
    // the unconfirmed points back to held_, in order
    for (int h = 0; h < unconf; ++h) {
      const std::size_t at = o - static_cast<std::size_t>(unconf) + static_cast<std::size_t>(h);
      Point& p = held_[(held_at_ + held_n_) % kMaxHeld];
      p.k = static_cast<std::int64_t>(k_unconf) + h;
      p.v[0] = out.x[at];
      p.v[1] = out.y[at];
      p.v[2] = out.z[at];
      ++held_n_;
    }
    o -= static_cast<std::size_t>(unconf);
    report_.samples += static_cast<std::int64_t>(o - out.n);
    out.n = o;
    chunk_.i = i;
    k_ = static_cast<std::int64_t>(kd);
    have_interval_ = interval;
    prev_t_ = prev_t;
    cur_t_ = cur_t;
    confirmed_ = std::floor(x_conf) + 1;
    prev_v_[0] = p0;
    prev_v_[1] = p1;
    prev_v_[2] = p2;
    cur_v_[0] = c0;
    cur_v_[1] = c1;
    cur_v_[2] = c2;
    return progress;
  }

  void finish() {
    finished_ = true;
    held_n_ = 0;
  }

  void put(SampleBuffer& out, const double* v, double g) {
    const double temp = file_.any_temp() ? temp_at(g) : r_na_real();
    out.put(v[0], v[1], v[2], temp, g);
    ++report_.samples;
  }

  // The next usable temperature row (time, ambient): rows with a time and
  // both values, equal times averaged. False at the end.
  bool temp_raw(double* t, double* amb) {
    for (;;) {
      if (!temp_look_) {
        double v[2], tt;
        if (!temp_rows_.next_row(v) || !temp_times_.next_time(&tt)) return false;
        if (!std::isfinite(tt) || !std::isfinite(v[0]) || !std::isfinite(v[1])) continue;
        temp_look_ = true;
        look_t_ = tt;
        look_v_ = v[1];
      }
      // gather the rows of the same time
      double sum = look_v_;
      int cnt = 1;
      const double tt = look_t_;
      temp_look_ = false;
      for (;;) {
        double v[2], t2;
        if (!temp_rows_.next_row(v) || !temp_times_.next_time(&t2)) break;
        if (!std::isfinite(t2) || !std::isfinite(v[0]) || !std::isfinite(v[1])) continue;
        if (t2 == tt) {
          sum += v[1];
          ++cnt;
          continue;
        }
        if (t2 < tt) report_.count("temperature_time_backwards");
        temp_look_ = true;
        look_t_ = t2;
        look_v_ = v[1];
        break;
      }
      if (cnt > 1) report_.count("temperature_duplicate_times");
      *t = tt;
      *amb = cnt > 1 ? sum / cnt : sum;
      return true;
    }
  }

  // The temperature at grid time g, as GGIRread resamples it.
  double temp_at(double g) {
    const double na = r_na_real();
    if (!temp_started_) {
      temp_started_ = true;
      if (!temp_raw(&tp_t_, &tp_v_) || !temp_raw(&tc_t_, &tc_v_)) {
        temp_ended_ = true;  // fewer than two rows: all NA
        return na;
      }
      temp_first_ = tp_t_;
    }
    if (temp_ended_ || g < temp_first_) return na;
    while (tc_t_ < g) {
      double t, v;
      if (!temp_raw(&t, &v)) {
        temp_ended_ = true;
        return na;
      }
      tp_t_ = tc_t_;
      tp_v_ = tc_v_;
      tc_t_ = t;
      tc_v_ = v;
    }
    return walk_.value(walk_.weight(g, tp_t_, tc_t_), tp_v_, tc_v_);
  }

  // the reading rules (compat, interpolation, resample_fused), read once
  // (before file_, which takes compat)
  const ReadRules rules_;
  // run()'s loop (option run_loop; 0: next_points() and take() alone, the
  // point-by-point path the fuzzer compares it with)
  bool run_loop_ = true;
  ParmayFile file_;
  ParmayStream acc_rows_, acc_times_, temp_rows_, temp_times_;
  Chunk chunk_;
  bool finished_ = false;
  // acceleration resampling
  static constexpr std::size_t kMaxHeld = 64;
  static constexpr int kMaxUnconfirmed = 8;  // run(): at most this many (held_ takes them)
  bool have_prev_ = false, have_interval_ = false;
  // the grid walk: start + k / rate (start the first sample's time), the
  // weights clamped to [0, 1] (the temperature's too)
  Walk walk_;
  double prev_t_ = 0, cur_t_ = 0, confirmed_ = 0;
  double prev_v_[3] = {0, 0, 0}, cur_v_[3] = {0, 0, 0};
  std::int64_t k_ = 0;
  Point held_[kMaxHeld];  // a ring: held_n_ points from held_at_
  std::size_t held_at_ = 0, held_n_ = 0;
  // temperature resampling
  bool temp_started_ = false, temp_ended_ = false, temp_look_ = false;
  double temp_first_ = 0, look_t_ = 0, look_v_ = 0;
  double tp_t_ = 0, tp_v_ = 0, tc_t_ = 0, tc_v_ = 0;
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_PARMAY_HPP
