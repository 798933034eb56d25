// gravcal: streaming decoder for Axivity .cwa files (AX3, AX6).
//
// Format (openmovement Docs/ax3/cwa.h, ax3-technical.md): a 1024-byte "MD"
// header block, then 512-byte "AX" data blocks. A data block holds up to 120
// samples: AX3 packed (one 32-bit word per sample: 3 x 10-bit signed + 2-bit
// exponent, eezzzzzz zzzzyyyy yyyyyyxx xxxxxxxx), or unpacked 16-bit signed
// axes (3 for AX3, 6 for AX6: gx gy gz ax ay az). The 16-bit little-endian
// word sum of a block is 0. One unit = one data block.
//
// Options: "compat" (default 1); with compat = 1 also "interpolation" (1,
// the default: linear; 2: nearest neighbour, readAxivity's
// interpolationType), "frequency_tol" (default 0.1, readAxivity's) and
// "r_long_double" (default 1: R's sum() accumulates in long double; 0: in
// double, an R without long double; see r_arith.hpp).
//  compat = 0: the samples at their own times, no resampling. Sample i of a
//    block is at start + i / f, start = T + frac / 65536 - offset / f (T the
//    packed RTC time, frac the block's fraction of a second, offset the
//    timestampOffset corrected as openmovement does for fractional blocks).
//    Each block's time is decoded on its own. Packed samples are scaled by
//    1/256 g (cwa.h: lightScale's scale bits are for unpacked data only).
//  compat = 1: what GGIR receives from GGIRread 1.2.0 readAxivity(start,
//    end, interpolationType, frequency_tol) called window after
//    window: read(out, B) is one call with start = the previous call's end
//    (first 0), end = start + B. Per window, as readAxivity does:
//    - the output grid is startTs + k / f_header (R's seq(): k * step, then
//      added; capped by the window's end time), startTs = the time of the
//      window's first good block, the end time = that of the first good
//      block at or after `end` (a seek ahead), or for the last window the
//      last good block's time + 3 blocks. Nothing but the header's block
//      length crosses windows: each window restarts grid and state.
//    - every block of the window is decoded with the rate, scale, axes and
//      fraction flag of the window's first good block (readAxivity reuses
//      its "parameters"), and its time from the RTC minute cache (a same-
//      minute block adds its seconds difference, +60 when they go back).
//    - block b's samples are spread evenly from its start to the next good
//      block's start and interpolated onto the grid (linearly, or to the
//      nearest neighbour: GGIRread::resample's ceil(u - 0.5) in place of
//      the weight u); when the next good block's sequence number is not
//      b's + 1 (a skipped block), or the observed rate is off by more than
//      frequency_tol (10 %), the grid points of b's span
//      are filled with the last output sample normalised to 1 g (or 0, 0, 1
//      when its norm is outside 0.8..1.2): "imputed", counted here.
//    - GGIRread's resample() computes w (v1 - v0) + v0 in C++, compiled by
//      the R it runs in: with option "resample_fused" = 1 (R/fp-build.R
//      sets it from what that R's compiler does) as one fused multiply-add.
//    - a window that starts with bad blocks skips them; a window whose end
//      block is bad extends over it (so the next window skips it again).
//    Where readAxivity stops with an error (and GGIR gets no samples for the
//    window) this decoder goes on instead: more than 20 bad blocks in a row,
//    a block with a good checksum but a bad header, count or packing, an
//    impossible date (R's as.POSIXct fails), an imputed gap over 3 days
//    (then the grid restarts at the next block, no imputation), an end time
//    before the start time or a window over 2^31 grid points (no cap). Date
//    conversion is UTC (GGIR's configtz = "" on a UTC machine). Seconds 60,
//    61 roll over and 62, 63 count as 0, as as.POSIXct parses them.
// In both modes temperature is (raw & 0x3ff) * 75 / 256 - 50 (GGIRread) and
// light (when asked: SampleBuffer::light) is the low 10 bits of the block's
// lightScale word, the light sensor's raw value (cwa.h's "raw units", not
// lux) as GGIRread gives it; every sample of a block, and in compat = 1
// every grid point of a block's span, imputed ones too, takes its block's
// value, as readAxivity fills its light column (and temperature). With
// light null, nothing is done for it. In both modes
// blocks with a zero rate byte (old firmware) carry their rate in the
// timestampOffset field and have no checksum (as GGIRread reads them).
//
// Damage: a block with a bad checksum or malformed content is skipped and
// counted ("bad_checksum", "bad_header", "bad_content", "bad_timestamp");
// a sequence number that does not follow (skipped blocks allowed for)
// counts "sequence_gaps"; a block that starts more than 1 s after the
// previous good block's end (plus the skipped blocks' span) is a gap (gaps,
// gap_seconds), more than 1 s before it counts "time_backwards"; a partial
// last block sets truncated. compat = 1 also counts "imputed_spans" and
// "imputed_samples" (what readAxivity filled in).
#ifndef GRAVCAL_DECODE_CWA_HPP
#define GRAVCAL_DECODE_CWA_HPP

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/kernels/kernels.hpp"
#include "gravcal/host/r_arith.hpp"

namespace gravcal {

namespace cwa {

constexpr std::size_t header_bytes = 1024;
constexpr std::size_t block_bytes = 512;
constexpr int max_samples = 120;            // 480 data bytes / 4
constexpr int data_offset = 30;             // first sample byte
constexpr std::size_t buffer_blocks = 64;   // blocks read at once
constexpr int max_bad_run = 20;             // readAxivity maxAllowedCorruptBlocks
constexpr double frequency_tol = 0.1;       // GGIR's default frequency_tol
constexpr double frequency_log = 0.05;      // readAxivity logs a rate off by more than this
constexpr double max_impute_s = 259200.0;   // readAxivity refuses gaps over 3 days
constexpr double gap_tol_s = 1.0;           // a late block beyond this is a gap
constexpr double anchor_dt = 0.00001;       // readAxivity's first anchor, before the first sample
constexpr int hw_ax6 = 0x64;                // header hardware type of an AX6


inline bool leap_year(int y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

// The packed RTC time (YYYYYYMM MMDDDDDh hhhhmmmm mmssssss, year - 2000) as
// seconds since 1970 UTC; false for a date as.POSIXct cannot parse.
inline bool calendar(std::uint32_t coded, double& out) {
  static const int mdays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const int year = static_cast<int>((coded >> 26) & 0x3f) + 2000;
  const unsigned month = (coded >> 22) & 0x0f, day = (coded >> 17) & 0x1f;
  const unsigned hour = (coded >> 12) & 0x1f, minute = (coded >> 6) & 0x3f;
  unsigned sec = coded & 0x3f;
  if (month < 1 || month > 12 || day < 1 || hour > 23 || minute > 59) return false;
  const int dim = mdays[month - 1] + (month == 2 && leap_year(year) ? 1 : 0);
  if (static_cast<int>(day) > dim) return false;
  if (sec > 61) sec = 0;  // "%H:%M:%OS" fails, "%H:%M" parses the rest
  out = static_cast<double>(days_from_civil(year, month, day) * 86400 + hour * 3600 +
                            minute * 60 + sec);
  return true;
}

// How a block's samples and time are read: the block's own values, or those
// of a window's first block (readAxivity's reused "parameters").
struct Params {
  int axes = 3;
  double accel_scale = 1.0 / 256;
  double frequency = 0;
  bool fractional = false;  // deviceFractional's top bit: a fraction of a second
};

// What a block says, before its samples are scaled.
struct Header {
  std::uint32_t id = 0;      // sequenceId
  std::uint32_t coded = 0;   // packed RTC time
  int rate = 0;              // sample-rate code byte (0: old format)
  int count = 0;             // samples
  bool packed = true;
  int axes = 3;              // from numAxesBPS
  int scale_code = 0;        // lightScale >> 13
  int light = 0;             // lightScale & 0x3ff: the light sensor's raw value
  int offset26 = 0;          // timestampOffset (signed)
  unsigned ts_offset = 0;    // deviceFractional
  double temperature = 0;
  double own_frequency = 0;  // from the rate code (or offset26, old format)
};

enum class Status { ok, bad_checksum, bad_header, bad_content, bad_timestamp };

inline double rate_frequency(int rate) {
  return 3200.0 / static_cast<double>(1u << (15 - (rate & 15)));
}

// The sum of a block's 256 little-endian 16-bit words, modulo 2^16.
inline unsigned word_sum(const unsigned char* b) { return kernels::active().word_sum(b, block_bytes); }

// Checks a block and reads its header fields (GGIRread's order: checksum
// first, unless the rate byte is 0, then the "AX" tag and length).
inline Status parse_header(const unsigned char* b, Header& h) {
  h.rate = b[24];
  if (h.rate != 0) {
    if (word_sum(b) != 0) return Status::bad_checksum;
  }
  if (b[0] != 'A' || b[1] != 'X' || le16(b + 2) != block_bytes - 4) return Status::bad_header;
  const int packing = b[25] & 15;
  if (packing != 0 && packing != 2) return Status::bad_content;
  h.packed = packing == 0;
  h.axes = b[25] >> 4;
  h.ts_offset = le16(b + 4);
  h.id = le32(b + 10);
  h.coded = le32(b + 14);
  const unsigned light_scale = le16(b + 18);
  h.scale_code = static_cast<int>(light_scale >> 13);
  h.light = static_cast<int>(light_scale & 0x3ffu);
  h.temperature = (le16(b + 20) & 0x3ffu) * 75.0 / 256.0 - 50.0;
  h.offset26 = static_cast<std::int16_t>(le16(b + 26));
  h.count = le16(b + 28);
  h.own_frequency = h.rate == 0 ? h.offset26 : rate_frequency(h.rate);
  return Status::ok;
}

inline Params own_params(const Header& h) {
  Params p;
  p.axes = h.axes;
  p.accel_scale = std::ldexp(1.0, -(8 + h.scale_code));  // 1 / 2^(8 + code), exactly
  p.frequency = h.own_frequency;
  p.fractional = h.rate != 0 && (h.ts_offset & 0x8000u) != 0;
  return p;
}

// The block's sample count fits its layout under parameters p.
inline bool layout_ok(const Header& h, const Params& p) {
  if (p.axes != 3 && p.axes != 6) return false;
  if (h.packed && p.axes != 3) return false;
  const int cap = h.packed ? max_samples : 480 / (2 * p.axes);
  return h.count >= 1 && h.count <= cap;
}

// Seconds from the whole-second RTC time T to the block's first sample:
// frac / 65536 - (offset + floor(frac * floor(f) / 65536)) / f, in
// GGIRread's order of operations (T + frac / 65536 + shift).
inline double block_start(double T, const Header& h, const Params& p) {
  const double f = h.rate == 0 ? h.offset26 : p.frequency;
  double frac = 0, shift = 0;
  if (h.rate != 0) {
    shift = h.offset26;
    if (p.fractional) {
      frac = static_cast<double>((h.ts_offset & 0x7fffu) << 1);
      shift += std::floor(frac * std::floor(f) / 65536.0);
    }
  }
  return T + frac / 65536.0 + (-shift / f);
}

using kernels::signed10;

// Samples [from, from + n) of the block, in g, into three columns.
inline void scale_columns(const unsigned char* b, const Header& h, const Params& p,
                          double packed_scale, int from, int n, double* x, double* y,
                          double* z) {
  const unsigned char* d = b + data_offset;
  if (h.packed) {
    kernels::active().scale_packed(d + 4 * from, packed_scale, n, x, y, z);
    return;
  }
  const int acc = p.axes == 6 ? 3 : 0;
  double* col[3] = {x, y, z};
  for (int i = 0; i < n; ++i) {
    const unsigned char* s = d + 2 * ((from + i) * p.axes + acc);
    for (int a = 0; a < 3; ++a) {
      col[a][i] = static_cast<std::int16_t>(le16(s + 2 * a)) * p.accel_scale;
    }
  }
}

// A decoded block: header, index in the file, start time, samples (or,
// for compat = 0, its bytes: the samples go straight to the output).
struct Block {
  Header h;
  std::int64_t index = 0;
  double cal = 0;    // the RTC's calendar time read as UTC, seconds since 1970
  double rtc = 0;    // the RTC time in the zone (ZoneTable), whole seconds since 1970
  double start = 0;  // the first sample's time
  double frequency = 0;
  // samples by axis: xyz[a][i + 1] is sample i's; xyz[a][0] is free for
  // the value interpolation starts from (emit_span())
  double xyz[3][max_samples + 1];
  unsigned char bytes[block_bytes];
};

}  // namespace cwa

class CwaDecoder : public Decoder {
 public:
  CwaDecoder(ByteSource& src, const Options& opts)
      : src_(src),
        rules_(ReadRules::of(opts)),
        frequency_tol_(opts.num("frequency_tol", cwa::frequency_tol)),
        r_long_double_(opts.num("r_long_double", 1) != 0),
        zone_(opts) {}

  bool open() override;
  std::int64_t read(SampleBuffer& out, std::int64_t max_units) override;
  bool done() const override { return done_; }
  std::size_t max_samples_per_unit() const override { return cwa::max_samples; }
  // compat = 1: readAxivity's QClog, a row per block it logs, in its order
  // over the windows read so far (see QcRow); "kind" 0: a bad checksum at a
  // window's start (its block numbers R's doubles), 1: within a window
  // (the next block's number a double), 2: a block whose successor's
  // number does not follow or whose rate is off by more than 5 % (both
  // numbers R's integers). Where readAxivity would stop instead of
  // logging, counted as "qclog_not_reproduced".
  UnitLog unit_log() const override;

 private:
  enum class Got { block, bad, end };

  // --- block input
  Got fetch(std::int64_t index, const unsigned char*& raw);
  bool refill();
  Got next_good(std::int64_t& index, std::int64_t stop, cwa::Block& b, bool own, bool count,
                bool log = false);
  bool decode(const unsigned char* raw, std::int64_t index, const cwa::Params* p,
              cwa::Block& b, bool count, bool keep_bytes = false);
  void skip(cwa::Status s, std::int64_t index);
  void log_bad_block(std::int64_t index, bool window_start);
  void check_time(const cwa::Block& b);
  void zone_check(const cwa::Block& b);

  // --- compat = 0
  std::int64_t read_raw(SampleBuffer& out, std::int64_t max_units);

  // --- compat = 1
  std::int64_t read_compat(SampleBuffer& out, std::int64_t max_units);
  bool start_window(std::int64_t max_units);
  double window_end_time(std::int64_t& end);
  void set_grid(double start_ts, double end_ts);
  bool step_window();
  double final_time();
  double minute_cache_time(const cwa::Block& b);
  void begin_span(double next_time, bool alone, bool final_block, bool seq_break);
  bool emit_span(SampleBuffer& out);
  double grid(std::int64_t k) const;

  ByteSource& src_;
  // the reading rules (compat, interpolation = 2: nearest, resample_fused),
  // read once
  const ReadRules rules_;
  double frequency_tol_;
  bool r_long_double_;  // R's accumulator: long double, else double
  ZoneTable zone_;  // GGIR's zone (compat = 1 only)
  bool done_ = false;
  std::int64_t n_blocks_ = -1;     // complete data blocks in the file; -1 unknown
  double header_f_ = 0;            // rate in the header (GGIR's grid rate)
  int block_length_ = 0;           // samples in the first good block (readAxivity header)

  // block buffer
  unsigned char buf_[cwa::buffer_blocks * cwa::block_bytes];
  std::int64_t buf_first_ = 0;     // index of the block at buf_[0]
  std::size_t buf_n_ = 0;          // whole blocks in buf_
  std::int64_t file_next_ = 0;     // index of the next block the source gives
  bool at_end_ = false;            // the source has no more whole blocks
  std::int64_t end_index_ = -1;    // index of the first missing block once known

  // gap reporting (both modes)
  std::int64_t counted_ = 0;       // blocks before this one are counted
  bool have_last_ = false;
  double last_end_ = 0, last_span_ = 0;
  std::int64_t last_index_ = 0;
  std::uint32_t last_id_ = 0;

  // compat = 0
  cwa::Block raw_;
  int raw_next_ = 0;               // next sample of raw_ to give
  bool raw_open_ = false;
  std::int64_t raw_index_ = 0;

  // compat = 1: the window
  cwa::Block blk_[2];
  int prev_ = 0;                   // blk_[prev_] is readAxivity's "previous"
  bool window_open_ = false;
  std::int64_t next_start_ = 0;    // nominal start of the next window
  std::int64_t win_units_ = 0;
  std::int64_t ii_ = 0, win_end_ = 0;
  cwa::Params wp_;
  double start_ts_ = 0, end_ts_ = 0, step_ = 0;
  std::int64_t nr_ = 0, pos_ = 0;
  double cache_ts_ = 0;            // RTC minute cache: timestamp, seconds, minute
  int cache_sec_ = 0;
  std::uint32_t cache_min_ = 0;
  bool first_iter_ = true;
  bool win_done_ = false, win_eof_ = false;
  int span_blk_ = 0;               // blk_ index of the block being written
  int bad_run_ = 0;
  double prev_start_ = 0;
  int prev_len_ = 0;
  double anchor_[3] = {0, 0, 0}, ianchor_[3] = {0, 0, 0};
  double anchor_t_ = 0, ianchor_t_ = 0;
  // the span being written
  bool span_open_ = false;
  bool regrid_ = false;
  bool impute_ = false;
  double raw_t_[cwa::max_samples + 2];
  int span_len_ = 0, source_ = 1;
  std::int64_t last_ = 0;
  double imputed_[3] = {0, 0, 1};

  // readAxivity's QClog (compat = 1)
  struct QcRow {
    int kind;  // 0, 1, 2: see unit_log()
    bool checksum_pass, imputed;
    double current, next, start, end, length_s, f_header, f_observed;
  };
  std::vector<QcRow> qclog_;
  std::vector<QcRow> qclog_pending_;  // bad blocks since the last good one in a window
  std::int32_t next_id_ = 0;  // the sequence number of the block after the span
  cwa::Status last_status_ = cwa::Status::ok;  // decode()'s last verdict
};

// ---------------------------------------------------------------------------
// Header and block input

inline bool CwaDecoder::open() {
  unsigned char h[cwa::header_bytes];
  const std::size_t got = read_full(src_, h, cwa::header_bytes);
  if (got >= 2 && !(h[0] == 'M' && h[1] == 'D')) {
    char tag[64];
    std::snprintf(tag, sizeof tag, "first two bytes are 0x%02x 0x%02x, not \"MD\"", h[0], h[1]);
    error_ = std::string("not an Axivity .cwa file: ") + tag;
    return false;
  }
  if (got < cwa::header_bytes) {
    error_ = src_.failed() ? "read error in the header at byte " + std::to_string(got)
                           : "header truncated at byte " + std::to_string(got);
    return false;
  }
  info_.format = "cwa";
  info_.device = h[4] == cwa::hw_ax6 ? "AX6" : "AX3";
  unsigned upper = le16(h + 11);
  if (upper == 0xffffu) upper = 0;
  info_.serial = std::to_string((static_cast<std::uint32_t>(upper) << 16) | le16(h + 5));
  report_.note("session id " + std::to_string(le32(h + 7)));
  header_f_ = h[36] != 0 ? cwa::rate_frequency(h[36]) : 0;
  info_.range_g = static_cast<double>(16 >> (h[36] >> 6));
  info_.has_temperature = true;
  info_.has_time = true;
  info_.has_light = true;
  const std::int64_t size = src_.size();
  if (size >= 0) {
    n_blocks_ = (size - static_cast<std::int64_t>(cwa::header_bytes)) /
                static_cast<std::int64_t>(cwa::block_bytes);
    if (n_blocks_ < 0) n_blocks_ = 0;
  }
  file_next_ = 0;
  // The first good block gives the block length, the start time and, when
  // the header has none, the rate (readAxivity's readHeader).
  std::int64_t i = 0;
  cwa::Block& b = blk_[0];
  if (next_good(i, -1, b, true, false) == Got::block) {
    block_length_ = b.h.count;
    info_.start_time = b.start;
    if (header_f_ <= 0) header_f_ = b.frequency;
  }
  info_.sf = header_f_;
  if (!src_.seek(static_cast<std::int64_t>(cwa::header_bytes))) {
    error_ = "cannot return to the first data block";
    return false;
  }
  buf_n_ = 0;
  buf_first_ = 0;
  file_next_ = 0;
  at_end_ = false;
  if (block_length_ == 0) done_ = true;
  return true;
}

// Refills the block buffer from the source at file_next_.
inline bool CwaDecoder::refill() {
  buf_first_ = file_next_;
  buf_n_ = 0;
  if (at_end_) return false;
  const std::size_t want = cwa::buffer_blocks * cwa::block_bytes;
  const std::size_t got = read_full(src_, buf_, want);
  buf_n_ = got / cwa::block_bytes;
  file_next_ += static_cast<std::int64_t>(buf_n_);
  if (got < want) {
    at_end_ = true;
    end_index_ = file_next_;
    if (src_.failed()) {
      if (!report_.read_error) report_.note("read error at byte " + std::to_string(src_.position()));
      report_.read_error = true;
    } else if (got % cwa::block_bytes != 0 && !report_.truncated) {
      report_.truncated = true;
      report_.note("file ends inside a block: " + std::to_string(got % cwa::block_bytes) +
                   " bytes after block " + std::to_string(end_index_));
    }
  }
  return buf_n_ > 0;
}

// The raw bytes of block `index`: from the buffer, by reading on, or by a
// seek when the index is elsewhere.
inline CwaDecoder::Got CwaDecoder::fetch(std::int64_t index, const unsigned char*& raw) {
  if (index < 0) return Got::end;
  if (end_index_ >= 0 && index >= end_index_) return Got::end;
  if (index >= buf_first_ && index < buf_first_ + static_cast<std::int64_t>(buf_n_)) {
    raw = buf_ + (index - buf_first_) * cwa::block_bytes;
    return Got::block;
  }
  if (index != file_next_) {
    const std::int64_t pos = static_cast<std::int64_t>(cwa::header_bytes) +
                             index * static_cast<std::int64_t>(cwa::block_bytes);
    if (!src_.seek(pos)) return Got::end;
    file_next_ = index;
    at_end_ = false;
  }
  if (!refill()) return Got::end;
  raw = buf_;
  return Got::block;
}

inline void CwaDecoder::skip(cwa::Status s, std::int64_t index) {
  static const char* names[] = {"ok", "bad_checksum", "bad_header", "bad_content", "bad_timestamp"};
  const int k = static_cast<int>(s);
  if (index < counted_) return;  // compat windows may visit a block twice
  counted_ = index + 1;
  ++report_.skipped;
  report_.count(names[k]);
  report_.note(std::string(names[k]) + " in block " + std::to_string(index) + " at byte " +
               std::to_string(cwa::header_bytes + static_cast<std::uint64_t>(index) * cwa::block_bytes));
}

// Decodes block `raw` with parameters p (null: its own), its time from the
// calendar. False (counted when `count`) when it is unusable.
inline bool CwaDecoder::decode(const unsigned char* raw, std::int64_t index, const cwa::Params* p,
                               cwa::Block& b, bool count, bool keep_bytes) {
  cwa::Status s = cwa::parse_header(raw, b.h);
  const cwa::Params own = cwa::own_params(b.h);
  const cwa::Params& use = p != nullptr ? *p : own;
  double T = 0;
  if (s == cwa::Status::ok) {
    const double f = b.h.rate == 0 ? b.h.offset26 : use.frequency;
    if (!cwa::layout_ok(b.h, use) || !(f > 0) || !std::isfinite(f)) s = cwa::Status::bad_content;
  }
  if (s == cwa::Status::ok && !cwa::calendar(b.h.coded, T)) s = cwa::Status::bad_timestamp;
  last_status_ = s;
  if (s != cwa::Status::ok) {
    if (count) skip(s, index);
    return false;
  }
  b.index = index;
  b.cal = T;
  b.rtc = rules_.compat ? T - zone_.offset(T) : T;
  b.frequency = b.h.rate == 0 ? b.h.offset26 : use.frequency;
  b.start = cwa::block_start(b.rtc, b.h, use);
  if (keep_bytes) {  // the caller scales the samples (scale_columns())
    std::memcpy(b.bytes, raw, cwa::block_bytes);
    return true;
  }
  const double packed_scale = rules_.compat ? use.accel_scale : 1.0 / 256;
  cwa::scale_columns(raw, b.h, use, packed_scale, 0, b.h.count, b.xyz[0] + 1, b.xyz[1] + 1,
                     b.xyz[2] + 1);
  return true;
}

// The first good block from `index` on (before `stop` unless negative) into
// b; index is left at it. Bad blocks are skipped (counted when `count`).
inline CwaDecoder::Got CwaDecoder::next_good(std::int64_t& index, std::int64_t stop,
                                             cwa::Block& b, bool own, bool count, bool log) {
  for (; stop < 0 || index < stop; ++index) {
    const unsigned char* raw = nullptr;
    if (fetch(index, raw) != Got::block) return Got::end;
    if (decode(raw, index, own ? nullptr : &wp_, b, count)) return Got::block;
    if (log) log_bad_block(index, true);
  }
  return Got::bad;
}

// readAxivity's QClog row of a block it skips (a bad checksum; it stops on
// any other damage, and on more than 20 bad blocks in a row): the block's
// place in the file and the next, zeros, not imputed. Within a window the
// row waits for the next good block: bad blocks at the file's end are
// never read by readAxivity (it ends the file at the last good block).
inline void CwaDecoder::log_bad_block(std::int64_t index, bool window_start) {
  if (last_status_ != cwa::Status::bad_checksum) {
    report_.count("qclog_not_reproduced");
    return;
  }
  const double i = static_cast<double>(index);
  const QcRow row{window_start ? 0 : 1, false, false, i, i + 1, 0, 0, 0, 0, 0};
  (window_start ? qclog_ : qclog_pending_).push_back(row);
}

inline Decoder::UnitLog CwaDecoder::unit_log() const {
  UnitLog log;
  log.names = {"kind", "checksum_pass", "blockID_current", "blockID_next", "start", "end",
               "blockLengthSeconds", "frequency_blockheader", "frequency_observed", "imputed"};
  log.columns.assign(log.names.size(), std::vector<double>());
  for (auto& c : log.columns) c.reserve(qclog_.size());
  for (const QcRow& r : qclog_) {
    const double v[] = {static_cast<double>(r.kind), r.checksum_pass ? 1.0 : 0.0, r.current, r.next,
                        r.start, r.end, r.length_s, r.f_header, r.f_observed, r.imputed ? 1.0 : 0.0};
    for (std::size_t k = 0; k < log.columns.size(); ++k) log.columns[k].push_back(v[k]);
  }
  return log;
}

// Counts good block b and reports a sequence break or a jump in time
// before it (once per block). Skipped blocks in between are assumed to have
// held the previous block's count of samples: they explain their own hole.
inline void CwaDecoder::check_time(const cwa::Block& b) {
  if (b.index < counted_) return;
  counted_ = b.index + 1;
  ++report_.units;
  if (have_last_) {
    const std::int64_t between = b.index - last_index_;
    if (b.h.id != 0 && static_cast<std::int64_t>(b.h.id) - static_cast<std::int64_t>(last_id_) != between) {
      report_.count("sequence_gaps");
      report_.note("sequence number " + std::to_string(b.h.id) + " after " +
                   std::to_string(last_id_) + " at block " + std::to_string(b.index));
    }
    const double d = b.start - (last_end_ + static_cast<double>(between - 1) * last_span_);
    if (d > cwa::gap_tol_s) {
      ++report_.gaps;
      report_.gap_seconds += d;
      report_.note("time gap of " + std::to_string(d) + " s before block " + std::to_string(b.index));
    } else if (d < -cwa::gap_tol_s) {
      report_.count("time_backwards");
      report_.note("time goes back " + std::to_string(-d) + " s at block " + std::to_string(b.index));
    }
  }
  have_last_ = true;
  last_id_ = b.h.id;
  last_index_ = b.index;
  last_span_ = b.h.count / b.frequency;
  last_end_ = b.start + last_span_;
}

inline std::int64_t CwaDecoder::read(SampleBuffer& out, std::int64_t max_units) {
  if (done_) return 0;
  return rules_.compat ? read_compat(out, max_units) : read_raw(out, max_units);
}

// ---------------------------------------------------------------------------
// compat = 0: every good block's samples at their own times

inline std::int64_t CwaDecoder::read_raw(SampleBuffer& out, std::int64_t max_units) {
  std::int64_t units = 0;
  while (!out.full()) {
    if (!raw_open_) {
      if (max_units >= 0 && units >= max_units) break;
      const unsigned char* raw = nullptr;
      if (fetch(raw_index_, raw) != Got::block) {
        done_ = true;
        break;
      }
      ++units;
      const std::int64_t i = raw_index_++;
      if (!decode(raw, i, nullptr, raw_, true, true)) continue;
      check_time(raw_);
      raw_open_ = true;
      raw_next_ = 0;
    }
    const double dt = 1.0 / raw_.frequency;
    const int n = static_cast<int>(std::min<std::size_t>(
        out.room(), static_cast<std::size_t>(raw_.h.count - raw_next_)));
    // straight from the block's bytes, column by column (what out.put()
    // would write, sample by sample), at 1/256 g (see the top of the file)
    cwa::scale_columns(raw_.bytes, raw_.h, cwa::own_params(raw_.h), 1.0 / 256, raw_next_, n,
                       out.x + out.n, out.y + out.n, out.z + out.n);
    if (out.t != nullptr) std::fill(out.t + out.n, out.t + out.n + n, raw_.h.temperature);
    if (out.light != nullptr) std::fill(out.light + out.n, out.light + out.n + n, raw_.h.light);
    if (out.time != nullptr) {
      for (int k = 0; k < n; ++k) out.time[out.n + k] = raw_.start + (raw_next_ + k) * dt;
    }
    out.n += static_cast<std::size_t>(n);
    raw_next_ += n;
    report_.samples += n;
    if (raw_next_ == raw_.h.count) raw_open_ = false;
  }
  return units;
}

// ---------------------------------------------------------------------------
// compat = 1: readAxivity's windows (see the top of this file)

// One read() is one readAxivity call of max_units blocks; when `out` fills
// first, read() returns 0 and the next calls finish the same window (their
// max_units ignored), the last of them returning the window's blocks.
inline std::int64_t CwaDecoder::read_compat(SampleBuffer& out, std::int64_t max_units) {
  if (!window_open_ && !start_window(max_units)) return 0;
  for (;;) {
    if (span_open_ && !emit_span(out)) return 0;
    if (!step_window()) break;
  }
  window_open_ = false;
  if (win_eof_ || (n_blocks_ >= 0 && next_start_ >= n_blocks_)) done_ = true;
  return win_units_;
}

// The grid time of point k: R's seq(from, to, by): from + k * by, capped at to.
inline double CwaDecoder::grid(std::int64_t k) const {
  volatile double e = static_cast<double>(k) * step_;  // no fused multiply-add
  const double t = start_ts_ + e;
  return t < end_ts_ ? t : end_ts_;
}

// seq(start, end, 1 / f)'s length less one (readAxivity drops the last
// point); no cap where seq() would fail.
inline void CwaDecoder::set_grid(double start_ts, double end_ts) {
  start_ts_ = start_ts;
  end_ts_ = end_ts;
  pos_ = 0;
  nr_ = std::numeric_limits<std::int64_t>::max();
  const double del = end_ts - start_ts;
  const double n = del / step_;
  if (!std::isfinite(end_ts) || !(n >= 0) || n > 2147483647.0) {
    if (std::isfinite(end_ts)) report_.note("window end time before its start: no grid cap");
    end_ts_ = std::numeric_limits<double>::infinity();
    return;
  }
  const double big = std::max(std::fabs(end_ts), std::fabs(start_ts));
  if (std::fabs(del) / big < 100 * std::numeric_limits<double>::epsilon()) {
    nr_ = 1;
    return;
  }
  nr_ = std::max<std::int64_t>(static_cast<std::int64_t>(n + 1e-10), 1);
}

// The window's end time (readAxivity's endTimestamp): the first good block
// from `end` on, or for the last window the last good block + 3 blocks.
// Infinite when readAxivity would stop or the file size is unknown.
inline double CwaDecoder::window_end_time(std::int64_t& end) {
  const double inf = std::numeric_limits<double>::infinity();
  if (n_blocks_ < 0) return inf;
  cwa::Block& b = blk_[1 - prev_];
  const unsigned char* raw = nullptr;
  if (end < n_blocks_) {
    const std::int64_t stop = std::min(n_blocks_, end + cwa::max_bad_run + 1);
    for (std::int64_t j = end; j < stop; ++j) {
      if (fetch(j, raw) != Got::block) return inf;
      if (decode(raw, j, nullptr, b, false)) {
        zone_check(b);
        return b.start;
      }
    }
    if (stop < n_blocks_) return inf;
  }
  const std::int64_t lo = std::max(next_start_ - win_units_, n_blocks_ - cwa::max_bad_run - 1);
  for (std::int64_t j = n_blocks_ - 1; j >= lo; --j) {
    if (fetch(j, raw) != Got::block) continue;
    if (decode(raw, j, nullptr, b, false)) {
      zone_check(b);
      const double step = 1.0 / header_f_;
      const double t = b.start + block_length_ * step;
      return t + 2 * block_length_ * step;
    }
  }
  return inf;
}

// Opens the window that starts at next_start_: its end, its first good
// block, its grid. False when there is no block left.
inline bool CwaDecoder::start_window(std::int64_t max_units) {
  const std::int64_t s = next_start_;
  const std::int64_t all = n_blocks_ >= 0 ? n_blocks_ : std::numeric_limits<std::int64_t>::max();
  if (s >= all || (end_index_ >= 0 && s >= end_index_) || max_units == 0) {
    if (max_units != 0) done_ = true;
    return false;
  }
  std::int64_t e = max_units < 0 || max_units > all - s ? all : s + max_units;
  next_start_ = e;
  win_units_ = e - s;
  step_ = 1.0 / header_f_;
  const double end_ts = window_end_time(e);
  window_open_ = true;
  win_done_ = false;
  win_eof_ = false;
  span_open_ = false;
  std::int64_t i = s;
  cwa::Block& b = blk_[prev_];
  const Got g = next_good(i, e, b, true, true, rules_.compat);
  if (i - s > cwa::max_bad_run) report_.count("qclog_not_reproduced");  // readAxivity stops
  if (g != Got::block) {  // readAxivity: "All requested blocks are corrupt"
    win_done_ = true;
    win_eof_ = g == Got::end;
    return true;
  }
  check_time(b);
  zone_check(b);
  wp_ = cwa::own_params(b.h);
  cache_ts_ = b.rtc;
  cache_sec_ = static_cast<int>(b.h.coded & 0x3f);
  cache_min_ = b.h.coded >> 6;
  ii_ = i + 1;
  win_end_ = e;
  first_iter_ = true;
  bad_run_ = 0;
  set_grid(b.start, end_ts);
  return true;
}

// A block whose time readAxivity converts without the minute before it
// (a window's first block, and the block its end time comes from): where
// its calendar minute is one whose offset in GGIR's zone depends on R's
// earlier conversions, counted ("zone_ambiguous"; R refuses the result).
inline void CwaDecoder::zone_check(const cwa::Block& b) {
  if (!rules_.compat || zone_.empty() || !zone_.ambiguous(b.cal)) return;
  report_.count("zone_ambiguous");
  report_.note("block " + std::to_string(b.index + 1) +
               ": its calendar time exists twice or not at all in GGIR's zone and starts or ends a "
               "block of GGIR's reading");
}

// readAxivity's time of a block in a window: the calendar when the RTC
// minute changes or the sequence restarts, else the cached time plus the
// change in seconds (+60 when the seconds go back).
inline double CwaDecoder::minute_cache_time(const cwa::Block& b) {
  const std::uint32_t minute = b.h.coded >> 6;
  const int sec = static_cast<int>(b.h.coded & 0x3f);
  if (b.h.id == 0 || minute != cache_min_ || cache_ts_ == 0) {
    cache_ts_ = b.rtc;
  } else {
    if (sec < cache_sec_) cache_sec_ -= 60;
    cache_ts_ += sec - cache_sec_;
  }
  cache_min_ = minute;
  cache_sec_ = sec;
  return cache_ts_;
}

// The time after the last block of the file: its start plus its length at
// the previous block's observed spacing (or its nominal rate when alone).
inline double CwaDecoder::final_time() {
  const cwa::Block& p = blk_[prev_];
  double next;
  if (first_iter_) {
    prev_start_ = p.start;
    next = prev_start_ + p.h.count / p.frequency;
  } else {
    volatile double duration = (p.start - prev_start_) / prev_len_ * p.h.count;
    next = duration + p.start;
  }
  prev_start_ = p.start;
  prev_len_ = p.h.count;
  return next;
}

// One step of readAxivity's block loop: reads block ii and opens the span of
// the previous good block. False once the window is finished.
inline bool CwaDecoder::step_window() {
  if (win_done_) return false;
  const unsigned char* raw = nullptr;
  span_blk_ = prev_;
  if (fetch(ii_, raw) != Got::block) {  // the file's last good block
    qclog_pending_.clear();
    const bool alone = first_iter_;
    begin_span(final_time(), alone, true, false);
    win_done_ = true;
    win_eof_ = true;
    return true;
  }
  cwa::Block& cur = blk_[1 - prev_];
  const std::int64_t i = ii_++;
  if (!decode(raw, i, &wp_, cur, true)) {
    log_bad_block(i, false);
    if (++bad_run_ > cwa::max_bad_run && bad_run_ == cwa::max_bad_run + 1) {
      report_.count("qclog_not_reproduced");
      report_.note("more than 20 bad blocks in a row before block " + std::to_string(i + 1) +
                   " (readAxivity stops here)");
    }
    return true;
  }
  bad_run_ = 0;
  qclog_.insert(qclog_.end(), qclog_pending_.begin(), qclog_pending_.end());
  qclog_pending_.clear();
  cur.start = cwa::block_start(minute_cache_time(cur), cur.h, wp_);
  check_time(cur);
  const cwa::Block& p = blk_[prev_];
  const bool seq_break = cur.h.id != 0 && static_cast<double>(static_cast<std::int32_t>(cur.h.id)) -
                                                  static_cast<std::int32_t>(p.h.id) != 1;
  prev_start_ = p.start;
  prev_len_ = p.h.count;
  next_id_ = static_cast<std::int32_t>(cur.h.id);
  begin_span(cur.start, false, false, seq_break);
  prev_ = 1 - prev_;
  if (regrid_) {  // a gap readAxivity would refuse: restart the grid here
    regrid_ = false;
    first_iter_ = true;
    set_grid(cur.start, end_ts_);
  }
  if (i >= win_end_) win_done_ = true;
  return true;
}

// readAxivity's span of the previous block: its samples' times from its
// start to next_time, the imputation test, the last grid point to fill.
inline void CwaDecoder::begin_span(double next_time, bool alone, bool final_block, bool seq_break) {
  const cwa::Block& p = blk_[span_blk_];
  const int len = prev_len_;
  const double spacing = alone ? 1.0 / p.frequency : (next_time - prev_start_) / len;
  raw_t_[1] = prev_start_;
  kernels::active().span_times(raw_t_, len, prev_start_, spacing);  // as R's seq()
  raw_t_[len + 1] = next_time;
  if (first_iter_) {
    for (int a = 0; a < 3; ++a) anchor_[a] = ianchor_[a] = p.xyz[a][1];
    anchor_t_ = ianchor_t_ = prev_start_ - cwa::anchor_dt;
    first_iter_ = false;
  }
  double observed = (len + 1.0) / (raw_t_[len] - anchor_t_);
  raw_t_[0] = ianchor_t_;
  if (final_block && alone) observed = p.frequency;
  const double bias = std::fabs(observed - p.frequency) / p.frequency;
  impute_ = (!final_block && seq_break) || bias > frequency_tol_;
  if (impute_ || bias > cwa::frequency_log) {
    // readAxivity's log of block p: after the file's last block, its
    // "next" is p itself (the block last read). (A window of one block
    // is never logged: its rate is taken as observed.)
    const double id = static_cast<double>(static_cast<std::int32_t>(p.h.id));
    const double next_id = final_block ? id : static_cast<double>(next_id_);
    const double end = final_block ? prev_start_ : next_time;
    qclog_.push_back({2, true, impute_, id, next_id, prev_start_, end, end - prev_start_,
                      p.frequency, observed});
  }
  std::int64_t last = std::min(pos_ + 200, nr_ - 1);
  if (raw_t_[len] > grid(last)) {
    const double add = std::floor((raw_t_[len] - grid(last)) * p.frequency);
    last = static_cast<std::int64_t>(
        std::min(static_cast<double>(last) + add, static_cast<double>(nr_ - 1)));
  }
  if (impute_ && static_cast<double>(last - pos_) > p.frequency * cwa::max_impute_s) {
    report_.count("gaps_not_imputed");
    report_.count("qclog_not_reproduced");
    report_.note("gap over 3 days after block " + std::to_string(p.index) +
                 " not imputed, grid restarted (readAxivity stops here)");
    regrid_ = true;
    span_open_ = false;
    return;
  }
  imputed_[0] = 0;
  imputed_[1] = 0;
  imputed_[2] = 1;
  if (impute_) {
    report_.count("imputed_spans");
    // R: sqrt(sum(v^2)), v^2 in double, sum() in R's accumulator
    const double norm = with_r_acc(r_long_double_, [&](auto acc) {
      decltype(acc) s = 0;
      for (int a = 0; a < 3; ++a) {
        const double q = anchor_[a] * anchor_[a];
        s += q;
      }
      return std::sqrt(static_cast<double>(s));
    });
    if (norm > 0.8 && norm < 1.2) {
      for (int a = 0; a < 3; ++a) imputed_[a] = anchor_[a] / norm;
    }
  }
  span_len_ = len;
  source_ = 1;
  last_ = last;
  span_open_ = true;
}

// Writes the open span's grid points into out; false when out filled first.
// A span that is not imputed: GGIRread's interpolation (the kernel
// cwa_interp); an imputed one: the imputed values.
inline bool CwaDecoder::emit_span(SampleBuffer& out) {
  cwa::Block& p = blk_[span_blk_];
  const int len = span_len_;
  const double lim = raw_t_[len];
  const bool impute = impute_;
  // an interval's left end is the sample before, or for the first the
  // value the span starts from
  for (int c = 0; c < 3; ++c) p.xyz[c][0] = ianchor_[c];
  // the span's grid points, as many as fit in out
  const std::int64_t room = static_cast<std::int64_t>(out.capacity - out.n);
  const std::int64_t stop = std::min(last_ + 1, pos_ + room);
  kernels::InterpOut o;
  o.x = out.x + out.n;
  o.y = out.y + out.n;
  o.z = out.z + out.n;
  o.t = out.t != nullptr ? out.t + out.n : nullptr;
  o.time = out.time != nullptr ? out.time + out.n : nullptr;
  std::int64_t given = 0;
  if (impute) {
    for (; pos_ + given < stop; ++given) {
      const double t = grid(pos_ + given);
      if (!(t < lim)) break;
      o.x[given] = anchor_[0] = imputed_[0];
      o.y[given] = anchor_[1] = imputed_[1];
      o.z[given] = anchor_[2] = imputed_[2];
      if (o.t != nullptr) o.t[given] = p.h.temperature;
      if (o.time != nullptr) o.time[given] = t;
      anchor_t_ = t;
    }
  } else {
    kernels::InterpSpan sp;
    sp.time = raw_t_;
    for (int c = 0; c < 3; ++c) sp.v[c] = p.xyz[c];
    sp.len = len;
    sp.lim = lim;
    sp.start = start_ts_;
    sp.step = step_;
    sp.end = end_ts_;
    sp.temp = p.h.temperature;
    sp.nearest = rules_.nearest();
    sp.fused = rules_.fused;
    // nearest neighbour (interpolationType = 2) or GGIRread's fused
    // multiply-add: the scalar reference only
    given = sp.nearest || sp.fused
                ? kernels::cwa_interp_scalar(sp, pos_, stop, source_, o, anchor_, anchor_t_)
                : kernels::active().cwa_interp(sp, pos_, stop, source_, o, anchor_, anchor_t_);
  }
  // light: the block's value on every point of its span, as temperature
  if (out.light != nullptr) std::fill(out.light + out.n, out.light + out.n + given, p.h.light);
  pos_ += given;
  out.n += static_cast<std::size_t>(given);
  report_.samples += given;
  if (impute) report_.count("imputed_samples", given);
  // out is full when the next grid point still lies in the span
  if (pos_ <= last_ && out.n >= out.capacity) {
    const double t = grid(pos_);
    if (impute ? t < lim : t <= lim) return false;
  }
  if (impute) {  // go on from the imputed output, not the raw samples
    ianchor_t_ = anchor_t_;
    for (int c = 0; c < 3; ++c) ianchor_[c] = anchor_[c];
  } else {
    ianchor_t_ = lim;
    for (int c = 0; c < 3; ++c) ianchor_[c] = p.xyz[c][len];
  }
  span_open_ = false;
  return true;
}

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_CWA_HPP
