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
#include "gravcal/kernels/kernels.hpp"

namespace gravcal {

// CRC-32 (IEEE 802.3, reflected, as zlib's crc32()), eight bytes a step
// ("slicing by 8": eight tables, the bytes taken one by one, so the same on
// any byte order), then byte by byte.
class Crc32 {
 public:
  static std::uint32_t update(std::uint32_t crc, const unsigned char* p, std::size_t n) {
    static const Table t;
    crc = ~crc;
    for (; n >= 8; n -= 8, p += 8) {
      const std::uint32_t lo = crc ^ (static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
                                      static_cast<std::uint32_t>(p[2]) << 16 |
                                      static_cast<std::uint32_t>(p[3]) << 24);
      crc = t.v[7][lo & 0xffu] ^ t.v[6][(lo >> 8) & 0xffu] ^ t.v[5][(lo >> 16) & 0xffu] ^
            t.v[4][lo >> 24] ^ t.v[3][p[4]] ^ t.v[2][p[5]] ^ t.v[1][p[6]] ^ t.v[0][p[7]];
    }
    for (std::size_t i = 0; i < n; ++i) crc = t.v[0][(crc ^ p[i]) & 0xffu] ^ (crc >> 8);
    return ~crc;
  }

 private:
  // v[0]: the CRC of one byte; v[k][b]: of byte b followed by k zero bytes.
  struct Table {
    std::uint32_t v[8][256];
    Table() {
      for (std::uint32_t i = 0; i < 256; ++i) {
        std::uint32_t c = i;
        for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        v[0][i] = c;
      }
      for (int k = 1; k < 8; ++k) {
        for (std::uint32_t i = 0; i < 256; ++i) v[k][i] = (v[k - 1][i] >> 8) ^ v[0][v[k - 1][i] & 0xffu];
      }
    }
  };
};

class ParmayDecoder : public Decoder {
 public:
  // Samples one packet can hold is bounded by the file only; a unit (a
  // packet) is a count of progress, not a size to allocate for.
  static constexpr std::size_t kMaxSamplesPerUnit = 1u << 20;

  ParmayDecoder(ByteSource& src, const Options& opts)
      : src_(src),
        rules_(ReadRules::of(opts)),
        run_loop_(opts.num("run_loop", 1) != 0) {}

  bool open() override {
    unsigned char h[524];
    if (!src_.seek(0) || read_full(src_, h, sizeof h) < sizeof h) {
      return fail("the file is shorter than a Matrix header (524 bytes)");
    }
    if (std::memcmp(h + 512, "MDTC", 4) != 0) {
      return fail("not a Matrix/Parmay file: no \"MDTC\" at byte 512");
    }
    declared_ = static_cast<std::int32_t>(le32(h + 516));
    range_ = static_cast<std::int16_t>(le16(h + 520));
    acc_unit_[0] = static_cast<double>(range_) / 32767.0;
    acc_unit_[1] = static_cast<double>(range_) / 32768.0;
    if (!index_packets()) return false;
    // the rate: the first packet of 10 s or more
    double observed = std::numeric_limits<double>::quiet_NaN();
    for (const Packet& p : packets_) {
      if (p.t1 - p.t0 >= 10) {
        observed = static_cast<double>(p.n_acc) / (p.t1 - p.t0);
        break;
      }
    }
    if (!std::isfinite(observed)) {
      return fail("no packet of 10 s or more to tell the sampling rate from");
    }
    const double rates[4] = {12.5, 25, 50, 100};
    sf_ = rates[0];
    for (double r : rates) {
      if (std::fabs(r - observed) < std::fabs(sf_ - observed)) sf_ = r;
    }
    by_ = 1.0 / sf_;
    for (const Packet& p : packets_) {
      if (p.n_temp > 0) any_temp_ = true;
      if (p.n_gyro > 0) any_gyro_ = true;
      if (p.n_heart > 0) any_heart_ = true;
    }
    info_.format = "parmay";
    info_.device = "Parmay Matrix";
    info_.sf = sf_;
    info_.has_temperature = any_temp_;
    info_.has_time = true;
    info_.range_g = static_cast<double>(range_);
    if (!packets_.empty()) info_.start_time = packets_[0].t0;
    // GGIRread gives nothing when the header declares no packet
    if (rules_.compat && declared_ < 1) {
      report_.note("the header declares " + std::to_string(declared_) +
                   " packets: no samples (as GGIRread)");
      finished_ = true;
    }
    acc_rows_.init(this, Stream::kAcc);
    acc_times_.init(this, Stream::kAcc);
    temp_rows_.init(this, Stream::kTemp);
    temp_times_.init(this, Stream::kTemp);
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
    for (auto& c : log.columns) c.reserve(packets_.size());
    for (const Packet& p : packets_) {
      log.columns[0].push_back(p.t0);
      log.columns[1].push_back(p.t1);
      log.columns[2].push_back(static_cast<double>(p.n_acc));
      log.columns[3].push_back(p.ok ? 1.0 : 0.0);
    }
    return log;
  }

 private:
  struct Packet {
    std::int64_t at = 0, end = 0;  // bytes [at, end) of the file
    double t0 = 0, t1 = 0;
    std::int32_t n_acc = 0, n_gyro = 0, n_temp = 0, n_heart = 0;
    bool ok = true;
  };

  bool fail(const std::string& why) {
    error_ = why;
    return false;
  }

  // Where every packet starts ("MDTCPACK"), its extent, header and CRC.
  bool index_packets() {
    static const unsigned char pat[8] = {'M', 'D', 'T', 'C', 'P', 'A', 'C', 'K'};
    std::vector<std::int64_t> starts;
    if (!src_.seek(0)) return fail("cannot move in the file");
    unsigned char buf[65536 + 8];
    std::size_t carry = 0;
    std::int64_t base = 0;  // file offset of buf[0]
    for (;;) {
      const std::size_t got = src_.read(buf + carry, 65536);
      const std::size_t n = carry + got;
      if (n >= 8) {
        const unsigned char* q = buf;
        const unsigned char* const last = buf + n - 8;  // the last place a pattern can start
        while (q <= last) {
          const void* m = std::memchr(q, 'M', static_cast<std::size_t>(last - q) + 1);
          if (m == nullptr) break;
          q = static_cast<const unsigned char*>(m);
          if (std::memcmp(q, pat, 8) == 0) starts.push_back(base + (q - buf));
          ++q;
        }
      }
      if (got == 0) {
        if (src_.failed()) report_.read_error = true;
        size_ = base + static_cast<std::int64_t>(n);
        break;
      }
      const std::size_t keep = n < 7 ? n : 7;
      std::memmove(buf, buf + n - keep, keep);
      base += static_cast<std::int64_t>(n - keep);
      carry = keep;
    }
    packets_.reserve(starts.size());
    for (std::size_t i = 0; i < starts.size(); ++i) {
      Packet p;
      p.at = starts[i];
      p.end = i + 1 < starts.size() ? starts[i + 1] : size_;
      if (p.end - p.at < 36) {
        report_.count("short_packet");
        ++report_.skipped;
        if (i + 1 == starts.size()) report_.truncated = true;
        note("a packet too short for its header", p.at);
        continue;
      }
      unsigned char hd[36];
      if (!read_at(p.at, hd, 36)) return fail("cannot read the file");
      const std::uint32_t stored = le32(hd + 8);
      p.t0 = static_cast<double>(static_cast<std::int32_t>(le32(hd + 12)));
      p.t1 = static_cast<double>(static_cast<std::int32_t>(le32(hd + 16)));
      p.n_acc = static_cast<std::int32_t>(le32(hd + 20));
      p.n_gyro = static_cast<std::int32_t>(le32(hd + 24));
      p.n_temp = static_cast<std::int32_t>(le32(hd + 28));
      p.n_heart = static_cast<std::int32_t>(le32(hd + 32));
      if (p.n_acc < 0 || p.n_gyro < 0 || p.n_temp < 0 || p.n_heart < 0) {
        // GGIRread cannot read such a packet either (a negative count)
        report_.count("bad_packet_counts");
        ++report_.skipped;
        note("a packet with a negative sample count", p.at);
        continue;
      }
      p.ok = crc_of(p.at + 12, p.end) == stored;
      if (!p.ok) {
        report_.count("bad_checksum");
        ++report_.skipped;
        note(rules_.compat ? "a packet with a bad checksum (kept as GGIRread keeps it: acceleration "
                       "(0, 0, 1), temperature of its neighbours)"
                     : "a packet with a bad checksum (skipped)",
             p.at);
        if (!rules_.compat) continue;
      }
      packets_.push_back(p);
    }
    for (std::size_t i = 1; i < packets_.size(); ++i) {
      const double gap = packets_[i].t0 - packets_[i - 1].t1;
      if (gap >= 1) {
        ++report_.gaps;
        report_.gap_seconds += gap;
      }
    }
    return true;
  }

  void note(const char* what, std::int64_t at) {
    report_.note(std::string(what) + " at byte " + std::to_string(at));
  }

  bool read_at(std::int64_t at, unsigned char* buf, std::size_t n) {
    return src_.seek(at) && read_full(src_, buf, n) == n;
  }

  std::uint32_t crc_of(std::int64_t from, std::int64_t to) {
    std::uint32_t crc = 0;
    unsigned char buf[65536];
    if (!src_.seek(from)) return ~crc;
    std::int64_t left = to - from;
    while (left > 0) {
      const std::size_t want = left < 65536 ? static_cast<std::size_t>(left) : 65536u;
      const std::size_t got = read_full(src_, buf, want);
      crc = Crc32::update(crc, buf, got);
      if (got < want) break;
      left -= static_cast<std::int64_t>(got);
    }
    return crc;
  }

  // The start of packet i's samples, moved back to the end of the previous
  // packet when it starts a second or more after it.
  double packet_start(std::size_t i) const {
    const double t0 = packets_[i].t0;
    if (i == 0 || !rules_.compat) return t0;
    const double gap = t0 - packets_[i - 1].t1;
    return gap >= 1 ? t0 - gap : t0;
  }

  // Sample j of n spread from `from` to `to` as R's seq(from, to,
  // length.out = n) gives it.
  static double spread(double from, double to, std::int64_t j, std::int64_t n) {
    if (n <= 1 || j == 0) return from;
    if (j == n - 1) return to;
    if (from == to) return from;
    const double n1 = static_cast<double>(n - 1);
    return from + static_cast<double>(j) * ((to - from) / n1);
  }

  // A cursor over one kind of samples (acceleration or temperature) or
  // over their times, packet by packet, reading through a small buffer.
  struct Stream {
    enum Kind { kAcc, kTemp };
    ParmayDecoder* d = nullptr;
    Kind kind = kAcc;
    std::size_t i = 0;       // packet
    std::int64_t j = 0;      // sample within it
    std::int64_t n = -1;     // samples of packet i (-1: not started)
    std::int64_t packets_done = 0;
    unsigned char buf[4096];
    std::int64_t buf_at = -1;
    std::size_t buf_n = 0;
    double imputed[2] = {0, 0};
    double t_from = 0, t_to = 0, t_step = 0;  // next_time(): packet i's spread

    void init(ParmayDecoder* dec, Kind k) {
      d = dec;
      kind = k;
    }
    bool at_packet_start() const { return n < 0 || j >= n; }
    int width() const { return kind == kAcc ? 6 : 4; }
    std::int64_t offset(const Packet& p) const {
      std::int64_t o = p.at + 36;
      if (kind == kTemp) {
        o += 6 * static_cast<std::int64_t>(p.n_acc) + 6 * static_cast<std::int64_t>(p.n_gyro);
      }
      return o;
    }
    std::int32_t count(const Packet& p) const { return kind == kAcc ? p.n_acc : p.n_temp; }
    // rows of packet p as GGIRread reads them: the count, or what the file
    // holds from there; none reads as one row (of NA, or of the damaged
    // packet's imputed values)
    std::int64_t rows(const Packet& p) const {
      const std::int32_t c = count(p);
      if (c < 0) return 0;
      const std::int64_t rem = d->size_ - offset(p);
      const std::int64_t words = rem > 0 ? rem / 2 : 0;
      const int per = width() / 2;
      const std::int64_t want = static_cast<std::int64_t>(c) * per;
      const std::int64_t r = (want < words ? want : words) / per;
      return r > 0 || !d->rules_.compat ? r : 1;
    }
    bool fetch(std::int64_t at, unsigned char* out, std::size_t k) {
      const std::int64_t end = at + static_cast<std::int64_t>(k);
      if (buf_at < 0 || at < buf_at || end > buf_at + static_cast<std::int64_t>(buf_n)) {
        if (!d->src_.seek(at)) return false;
        buf_n = read_full(d->src_, buf, sizeof buf);
        buf_at = at;
        if (buf_n < k) return false;
      }
      std::memcpy(out, buf + (at - buf_at), k);
      return true;
    }
    // next_row: the next row of values (acceleration: x, y, z in g; temperature: body,
    // ambient in degrees C); false at the end
    // Moves on to the packet holding the next row (a damaged packet's
    // imputed temperature set); false at the end.
    bool at_next_row() {
      while (n < 0 || j >= n) {
        if (n >= 0) {
          ++i;
          ++packets_done;
        }
        if (i >= d->packets_.size()) {
          n = 0;
          j = 0;
          return false;
        }
        n = rows(d->packets_[i]);
        j = 0;
        if (kind == kTemp && !d->packets_[i].ok) d->impute_temp(i, imputed);
      }
      return true;
    }
    bool next_row(double* v) {
      if (!at_next_row()) return false;
      const Packet& p = d->packets_[i];
      const std::int64_t r = j++;
      const double na = r_na_real();
      if (kind == kAcc) {
        if (!p.ok) {
          v[0] = 0;
          v[1] = 0;
          v[2] = 1;
          return true;
        }
        if (p.n_acc == 0 || r >= p.n_acc) {
          v[0] = v[1] = v[2] = na;
          return true;
        }
        unsigned char b[6];
        if (!fetch(offset(p) + 6 * r, b, 6)) {
          v[0] = v[1] = v[2] = na;
          return true;
        }
        for (int c = 0; c < 3; ++c) {
          const int w = static_cast<std::int16_t>(le16(b + 2 * c));
          v[c] = static_cast<double>(w) * d->acc_unit_[w < 0];
        }
        return true;
      }
      if (!p.ok) {
        v[0] = imputed[0];
        v[1] = imputed[1];
        return true;
      }
      if (p.n_temp == 0 || r >= p.n_temp) {
        v[0] = v[1] = na;
        return true;
      }
      unsigned char b[4];
      if (!fetch(offset(p) + 4 * r, b, 4)) {
        v[0] = v[1] = na;
        return true;
      }
      v[0] = static_cast<double>(static_cast<std::int16_t>(le16(b))) / 10;
      v[1] = static_cast<double>(static_cast<std::int16_t>(le16(b + 2))) / 10;
      return true;
    }
    // next_rows: up to `max` rows of acceleration (kind kAcc), all from one
    // packet, as next_row() gives them one by one; 0 at the end. A good
    // packet's rows that the file holds are read in one go.
    int next_rows(double* x, double* y, double* z, int max) {
      if (!at_next_row()) return 0;
      const Packet& p = d->packets_[i];
      std::int64_t m = n - j;
      if (m > max) m = max;
      int k = 0;
      if (p.ok && j + m <= p.n_acc) {
        unsigned char b[6 * kChunk];
        const std::int64_t at = offset(p) + 6 * j;
        const std::size_t got = d->src_.seek(at) ? read_full(d->src_, b, static_cast<std::size_t>(6 * m)) : 0;
        buf_at = -1;  // the source moved: fetch() reads afresh
        const double* unit = d->acc_unit_;
        const int whole = static_cast<int>(got / 6);
        for (; k < whole; ++k) {
          const unsigned char* r = b + 6 * k;
          const int wx = static_cast<std::int16_t>(le16(r));
          const int wy = static_cast<std::int16_t>(le16(r + 2));
          const int wz = static_cast<std::int16_t>(le16(r + 4));
          x[k] = static_cast<double>(wx) * unit[wx < 0];
          y[k] = static_cast<double>(wy) * unit[wy < 0];
          z[k] = static_cast<double>(wz) * unit[wz < 0];
        }
        j += k;
        const double na = r_na_real();
        for (; k < m; ++k, ++j) x[k] = y[k] = z[k] = na;  // not read: as fetch() failing
        return k;
      }
      for (double v[3]; k < m; ++k) {
        next_row(v);
        x[k] = v[0];
        y[k] = v[1];
        z[k] = v[2];
      }
      return k;
    }
    // next_time: the next time stamp; false at the end
    bool next_time(double* t) {
      while (n < 0 || j >= n) {
        if (n >= 0) ++i;
        if (i >= d->packets_.size()) {
          n = 0;
          j = 0;
          return false;
        }
        const std::int32_t c = count(d->packets_[i]);
        n = c > 0 ? c : 0;
        j = 0;
      }
      if (j == 0) {
        // the packet's spread, once per packet (spread()'s arithmetic)
        t_from = d->packet_start(i);
        t_to = d->packets_[i].t1 - d->by_;
        t_step = n > 1 ? (t_to - t_from) / static_cast<double>(n - 1) : 0;
      }
      const std::int64_t r = j++;
      if (n <= 1 || r == 0 || t_from == t_to) *t = t_from;
      else if (r == n - 1) *t = t_to;
      else *t = t_from + static_cast<double>(r) * t_step;
      return true;
    }
    // next_times: up to `max` times, as next_time() gives them one by one;
    // how many (fewer at the end)
    int next_times(double* t, int max) {
      int got = 0;
      while (got < max) {
        if (n < 0 || j >= n || j == 0) {
          // a packet's first time: next_time() sets its spread
          if (!next_time(t + got)) break;
          ++got;
          continue;
        }
        std::int64_t m = n - j;
        if (m > max - got) m = max - got;
        for (const std::int64_t e = j + m; j < e; ++j) {
          if (n <= 1 || t_from == t_to) t[got++] = t_from;
          else if (j == n - 1) t[got++] = t_to;
          else t[got++] = t_from + static_cast<double>(j) * t_step;
        }
      }
      return got;
    }
  };

  // Raw acceleration samples read ahead: rows and times, paired in order
  // as GGIRread pairs them (the two streams count a packet's samples each
  // its own way, see Stream::rows()), at most the rest of one packet of
  // rows at a time.
  static constexpr int kChunk = 1024;
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

  // The temperature GGIRread gives a damaged packet: the mean of the last
  // row of the good packet before it and the first row of the good packet
  // after it (one of them when the other is missing).
  void impute_temp(std::size_t i, double* out) {
    const double na = r_na_real();
    double prev[2] = {na, na}, next[2] = {na, na};
    bool have_prev_packet = false;
    for (std::size_t k = i; k-- > 0;) {
      if (!packets_[k].ok) continue;
      have_prev_packet = true;
      if (packets_[k].n_temp > 0) temp_row(packets_[k], packets_[k].n_temp - 1, prev);
      break;
    }
    if (!have_prev_packet) {
      for (std::size_t k = 0; k < packets_.size(); ++k) {
        if (!packets_[k].ok) continue;
        if (packets_[k].n_temp > 0) temp_row(packets_[k], 0, prev);
        break;
      }
    }
    for (std::size_t k = i + 1; k < packets_.size(); ++k) {
      if (!packets_[k].ok) continue;
      if (packets_[k].n_temp > 0) temp_row(packets_[k], 0, next);
      break;
    }
    const bool p = !std::isnan(prev[0]), q = !std::isnan(next[0]);
    for (int c = 0; c < 2; ++c) {
      if (p && q) {
        out[c] = (prev[c] + next[c]) / 2;
      } else if (q) {
        out[c] = next[c];
      } else {
        out[c] = prev[c];  // NA when neither (GGIRread then keeps the packet's own)
      }
    }
    if (!p && !q) report_.count("temperature_not_imputed");
  }

  void temp_row(const Packet& p, std::int64_t r, double* out) {
    unsigned char b[4];
    const std::int64_t at = p.at + 36 + 6 * static_cast<std::int64_t>(p.n_acc) +
                            6 * static_cast<std::int64_t>(p.n_gyro) + 4 * r;
    if (at + 4 > size_ || !read_at(at, b, 4)) return;
    out[0] = static_cast<double>(static_cast<std::int16_t>(le16(b))) / 10;
    out[1] = static_cast<double>(static_cast<std::int16_t>(le16(b + 2))) / 10;
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

  // One raw acceleration sample at time t: the next interval.
  void take(const double* v, double t) {
    if (!have_prev_) {
      start_ = t;
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
    confirmed_ = std::floor((t - start_) * sf_) + 1;
  }

  // Gives grid points while the buffer has room: first the held ones the
  // raw times now confirm, then those of the current interval (held, in
  // order, while an earlier one is); false when it gave or held none (a
  // new raw sample is needed).
  bool next_points(SampleBuffer& out) {
    bool any = false;
    while (!out.full()) {
      if (held_n_ > 0 && static_cast<double>(held_[held_at_].k) < confirmed_) {
        const Point& p = held_[held_at_];
        put(out, p.v, start_ + static_cast<double>(p.k) * by_);
        held_at_ = (held_at_ + 1) % kMaxHeld;
        --held_n_;
        any = true;
        continue;
      }
      if (!have_interval_ || finished_) break;
      const double g = start_ + static_cast<double>(k_) * by_;
      if (!(g <= cur_t_)) {
        have_interval_ = false;
        break;
      }
      double u = (g - prev_t_) / (cur_t_ - prev_t_);
      if (u < 0 || u > 1) u = 0;
      if (rules_.nearest()) u = ggir_nearest_weight(u);
      double v[3];
      for (int c = 0; c < 3; ++c) v[c] = kernels::ggir_lerp(u, prev_v_[c], cur_v_[c], rules_.fused);
      const std::int64_t k = k_++;
      any = true;
      if (held_n_ == 0 && static_cast<double>(k) < confirmed_) {
        put(out, v, g);
        continue;
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
    }
    return any;
  }

  // temp_at()'s arithmetic where the temperature's interval stays put
  // (run()'s copy of its state): mode 0 no temperature, 1 NA from here,
  // 2 interpolated between (tp_t, tp_v) and (tc_t, tc_v).
  struct TempSpan {
    int mode;
    double first, tp_t, tc_t, tp_v, tc_v;
    bool nearest, fused;
    double na;
    // false where the interval must move (temp_at() then)
    bool at(double g, double* out) const {
      *out = na;
      if (mode != 2 || g < first) return true;
      if (tc_t < g) return false;
      double w = (g - tp_t) / (tc_t - tp_t);
      if (w < 0 || w > 1) w = 0;
      if (nearest) w = ggir_nearest_weight(w);
      *out = kernels::ggir_lerp(w, tp_v, tc_v, fused);
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
  // when it did nothing.
  bool run(SampleBuffer& out) {
    if (held_n_ != 0 || finished_ || !have_prev_) return false;
    const bool temp_cols = out.t != nullptr, time_col = out.time != nullptr;
    const double na = r_na_real();
    // the temperature: 0 none (NA), 1 NA from here, 2 interpolated
    int temp_mode = 0;
    if (any_temp_) {
      if (!temp_started_) return false;
      temp_mode = temp_ended_ ? 1 : 2;
    }
    const TempSpan ts{temp_mode, temp_first_, tp_t_, tc_t_, tp_v_, tc_v_,
                      rules_.nearest(), rules_.fused, na};
    const double start = start_, by = by_, sf = sf_;
    const bool nearest = rules_.nearest(), fused = rules_.fused;
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
        const double g = start + kd * by;
        if (!(g <= cur_t)) {
          interval = false;
          break;
        }
        if (unconf == kMaxUnconfirmed) goto leave;
        double temp;
        if (!ts.at(g, &temp)) goto leave;  // the next temperature row
        double u = (g - prev_t) / (cur_t - prev_t);
        if (u < 0 || u > 1) u = 0;
        if (nearest) u = ggir_nearest_weight(u);
        out.x[o] = kernels::ggir_lerp(u, p0, c0, fused);
        out.y[o] = kernels::ggir_lerp(u, p1, c1, fused);
        out.z[o] = kernels::ggir_lerp(u, p2, c2, fused);
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
    const double temp = any_temp_ ? temp_at(g) : r_na_real();
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
    double u = (g - tp_t_) / (tc_t_ - tp_t_);
    if (u < 0 || u > 1) u = 0;
    if (rules_.nearest()) u = ggir_nearest_weight(u);
    return kernels::ggir_lerp(u, tp_v_, tc_v_, rules_.fused);
  }

  ByteSource& src_;
  // the reading rules (compat, interpolation, resample_fused), read once
  const ReadRules rules_;
  // run()'s loop (option run_loop; 0: next_points() and take() alone, the
  // point-by-point path the fuzzer compares it with)
  bool run_loop_ = true;
  std::int32_t declared_ = 0;
  std::int16_t range_ = 0;
  // g per count, GGIRread's range / 32767 (counts >= 0) and range / 32768
  double acc_unit_[2] = {0, 0};
  std::int64_t size_ = 0;
  std::vector<Packet> packets_;
  double sf_ = 0, by_ = 0;
  bool any_temp_ = false, any_gyro_ = false, any_heart_ = false;
  Stream acc_rows_, acc_times_, temp_rows_, temp_times_;
  Chunk chunk_;
  bool finished_ = false;
  // acceleration resampling
  static constexpr std::size_t kMaxHeld = 64;
  static constexpr int kMaxUnconfirmed = 8;  // run(): at most this many (held_ takes them)
  bool have_prev_ = false, have_interval_ = false;
  double start_ = 0, prev_t_ = 0, cur_t_ = 0, confirmed_ = 0;
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
