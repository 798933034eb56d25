// gravcal: the packets of a Parmay Matrix (MTX) .bin/.BIN file, and cursors
// over their samples (the format: decode_parmay.hpp).
//
// ParmayFile reads the header, finds every packet ("MDTCPACK"), checks its
// CRC and tells the sampling rate; ParmayStream reads one kind of samples
// (acceleration or temperature), or their times, packet by packet, as
// GGIRread's readParmayMatrix() pairs them. ParmayDecoder
// (decode_parmay.hpp) replays GGIRread's resampling over them.
#ifndef GRAVCAL_DECODE_PARMAY_PACKETS_HPP
#define GRAVCAL_DECODE_PARMAY_PACKETS_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "gravcal/decoders/decode.hpp"

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

// The packets of a Matrix file: its header, where each packet lies, its
// header and whether its CRC matched, and the sampling rate they tell.
// Counts what it finds damaged in the decoder's report.
class ParmayFile {
 public:
  struct Packet {
    std::int64_t at = 0, end = 0;  // bytes [at, end) of the file
    double t0 = 0, t1 = 0;
    std::int32_t n_acc = 0, n_gyro = 0, n_temp = 0, n_heart = 0;
    bool ok = true;
  };

  // compat: GGIRread's reading (damaged packets kept, late packets moved
  // back); report: the decoder's, which outlives this
  ParmayFile(ByteSource& src, bool compat, Report& report)
      : src_(src), compat_(compat), report_(report) {}

  // Reads the header and the packets and tells the rate; false, with the
  // reason in error(), when the file is not a readable Matrix file.
  bool open() {
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
    return true;
  }

  const std::string& error() const { return error_; }
  // the packets kept (see ParmayDecoder::unit_log())
  const std::vector<Packet>& packets() const { return packets_; }
  std::int32_t declared() const { return declared_; }  // packets, as the header says
  std::int16_t range() const { return range_; }        // g
  double sf() const { return sf_; }
  double by() const { return by_; }  // 1 / sf
  bool any_temp() const { return any_temp_; }

  // The start of packet i's samples, moved back to the end of the previous
  // packet when it starts a second or more after it.
  double packet_start(std::size_t i) const {
    const double t0 = packets_[i].t0;
    if (i == 0 || !compat_) return t0;
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

 private:
  friend class ParmayStream;

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
        note(compat_ ? "a packet with a bad checksum (kept as GGIRread keeps it: acceleration "
                       "(0, 0, 1), temperature of its neighbours)"
                     : "a packet with a bad checksum (skipped)",
             p.at);
        if (!compat_) continue;
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

  ByteSource& src_;
  const bool compat_;
  Report& report_;
  std::string error_;
  std::int32_t declared_ = 0;
  std::int16_t range_ = 0;
  // g per count, GGIRread's range / 32767 (counts >= 0) and range / 32768
  double acc_unit_[2] = {0, 0};
  std::int64_t size_ = 0;
  std::vector<Packet> packets_;
  double sf_ = 0, by_ = 0;
  bool any_temp_ = false, any_gyro_ = false, any_heart_ = false;
};

// A cursor over one kind of samples of a ParmayFile (acceleration or
// temperature) or over their times, packet by packet, reading through a
// small buffer.
class ParmayStream {
 public:
using Packet = ParmayFile::Packet;
// next_rows() reads at most this many rows at a time
static constexpr int kMaxRows = 1024;
  enum Kind { kAcc, kTemp };
  ParmayFile* d = nullptr;
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

  void init(ParmayFile* file, Kind k) {
    d = file;
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
    return r > 0 || !d->compat_ ? r : 1;
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
      unsigned char b[6 * kMaxRows];
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

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_PARMAY_PACKETS_HPP
