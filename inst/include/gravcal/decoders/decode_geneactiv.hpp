// gravcal: streaming decoder for GENEActiv .bin files.
//
// Format (GENEActiv instructions, "Decoding .bin files"): text lines (CRLF in
// real files). A header of "Key:value" lines (device identity, capabilities,
// configuration with "Measurement Frequency:", "Time Zone:", calibration data
// "x gain:", "x offset:", ..., memory status "Number of Pages:"), then pages
// of ten lines: "Recorded Data", "Device Unique Serial Code:",
// "Sequence Number:", "Page Time:YYYY-MM-DD HH:MM:SS:mmm", "Unassigned:",
// "Temperature:", "Battery voltage:", "Device Status:",
// "Measurement Frequency:", and 3600 hex digits: 300 samples of 12 digits,
// x, y, z as 12-bit two's complement, then 10 bits light and 2 status bits.
// A value in g is (count * 100 - offset) / gain. Unit = one page.
//
// Option "compat" = 1 (default) gives GGIRread::readGENEActiv 1.2.0's output
// bit for bit (GGIR calls it with start = s, end = e, desiredtz = "",
// configtz = ""); compat = 0 gives the format's values. Differences:
// - Values: the reference stores x, y, z and temperature as float; compat 1
//   rounds them to float, compat 0 keeps doubles.
// - Time: the reference ignores every Page Time but the first page's; it
//   reads that one in the session's local time zone (TZ; not the header's
//   "Time Zone:"), counts whole milliseconds from it (each sample's offset
//   truncated to an integer ms, each page starting where the previous page's
//   last sample + 1 period truncates), restarts that count in every call, and
//   adds ((s - 1) * 300) / rate for a call from page s, with the rate of the
//   call's last page. So within a call a page lasts trunc(300000 / rate) ms
//   (3500 at 85.7 Hz), but a call from page s starts (s - 1) * 3500.58 ms
//   after page 1: on the real 85.7 Hz test file, page 11 starts 35.000 s
//   after page 1 read whole, 35.0058 s read from page 11 (14 s a day).
//   compat 1 does the same: a read() with max_units >= 0 that starts on a
//   page boundary is one reference call; with max_units < 0 the whole file
//   is one call (later such calls continue it). compat 0 times each page by
//   its own Page Time,
//   local time at the header's "Time Zone:" (GMT +hh:mm) turned into UTC,
//   plus i / rate.
// - End: the reference with end = 0 stops at the header's "Number of Pages"
//   (GGIR passes an explicit end, so it reads every page); we read every page.
// - Damage: the reference assumes a 59-line header and 10-line pages (a
//   missing line shifts every later page), decodes the hex digits before a
//   bad character (std::stoll stops there), keeps the samples before the
//   first undecodable group, and its time count closes up what was lost. We
//   resynchronise on "Recorded Data", skip and count a damaged page whole,
//   and time later pages as if it had been there (its 300 samples' worth).
//   A final hex line cut short keeps its samples whose x, y, z digits are
//   complete (compat 1: those with at least 10 digits, as the reference;
//   compat 0: whole 12-digit samples only).
//   A page header cut by the end of the input: the reference gives the
//   previous page's samples again (std::getline leaves its string as it
//   was); we drop the page.
// - Page times and sequence numbers are checked (the reference does not):
//   expected is the last good page + (units since) * 300 / rate. A jump in
//   both is a gap (gaps, gap_seconds); a lone page whose time is off while
//   its sequence number fits keeps its samples, timed as predicted
//   (bad_page_time), unless the next page confirms the new time (then a gap,
//   or time_backwards); a lone wrong sequence number is counted and mended
//   (bad_sequence). None of this changes compat 1 times.
//
// Light (when asked: SampleBuffer::light; the same in both modes) is what
// readGENEActiv gives: the sample's last 3 hex digits over 4 (10 bits, the 2
// status bits dropped; a final sample cut to 10 or 11 digits: the 1 or 2 it
// has, over 4, as std::stoll reads them), for a "Device Model" other than
// one ending in "1.1" mapped as GGIRread maps it (256..511: (l - 128) * 2,
// 512..767: (l - 320) * 4, 768..1023: (l - 656) * 16), then times Lux /
// Volts, the header's "Lux:" and "Volts:" values: lux. As readGENEActiv
// finds them: the first line of the file's first 69 (cut at a NUL; header
// lines only) that contains "Lux" (or "Volts", "Device Model"), read as a
// number once "Lux:" is taken out; NA where there is none, so every light
// value is NA. The
// number is read by strtod, the same as R's as.numeric() for the plain
// numbers of real headers; options "light_lux", "light_volts" and
// "light_model11" (R/decode.R gives R's own reading) replace what the
// decoder found. Light is decoded only when asked, from a copy of the page's
// hex line (3600 bytes) made while the reads ask for light: from open() to
// the first read() without light, and again from a read() with it. A page
// read before a caller starts asking has no copy: its light is NaN.
//
// max_units counts pages ("Recorded Data" units, damaged ones included, as
// the reference's page numbers do). GGIR's block k, readGENEActiv(start = s,
// end = s + B - 1) with s = (k - 1) * B + 1, is the k-th read(out, B) into a
// buffer of at least B * 300 samples.
//
// Report counters: bad_hex, bad_page_header, truncated_page (skipped pages),
// stray_lines (lines outside any page), bad_sequence, bad_page_time,
// time_backwards, rate_changes; notes give the page number and byte offset.
#ifndef GRAVCAL_DECODE_GENEACTIV_HPP
#define GRAVCAL_DECODE_GENEACTIV_HPP

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <limits>
#include <string>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/kernels/kernels.hpp"
#include "gravcal/decoders/line_reader.hpp"

namespace gravcal {

namespace geneactiv {

constexpr std::size_t kSamplesPerPage = 300;
constexpr std::size_t kDigitsPerSample = 12;  // x, y, z: 3 each; light+status: 3
constexpr std::size_t kDigitsPerPage = kSamplesPerPage * kDigitsPerSample;
constexpr std::size_t kDigitsXyz = 9;
constexpr std::size_t kDigitsXyzCompat = 10;  // the reference needs 1 light digit
constexpr int kPageHeaderLines = 8;           // between "Recorded Data" and hex
constexpr std::size_t kMaxLine = 8192;        // longer lines are cut (and counted)
constexpr std::size_t kBufferBytes = 1u << 16;  // the line reader's buffer
constexpr int kMaxHeaderLines = 256;          // real headers have 59
constexpr double kMinRate = 0.1;              // Hz; real devices: 10..100
constexpr double kMaxRate = 10000.0;
constexpr double kMinGain = 1.0;              // counts per 100 g; real: ~25000
constexpr double kMaxGain = 1e7;
constexpr double kMaxOffset = 1e9;
constexpr int kCountRange = 4096;             // 12-bit counts
constexpr int kCountSigned = 2048;
constexpr double kCountScale = 100.0;         // g = (count * 100 - offset) / gain
constexpr double kMaxTimeZoneHours = 14.0;
constexpr int kLightHeaderLines = 69;          // readGENEActiv's readLines(filename, 69)
constexpr int kLightRange = 1024;              // 10-bit light

constexpr const char* kFirstLine = "Device Identity";
constexpr const char* kPageStart = "Recorded Data";
constexpr const char* kPageKeys[kPageHeaderLines] = {
    "Device Unique Serial Code:", "Sequence Number:", "Page Time:", "Unassigned:",
    "Temperature:", "Battery voltage:", "Device Status:", "Measurement Frequency:"};
enum PageKey { kSerial = 0, kSequence = 1, kTime = 2, kTemperature = 4, kFrequency = 7 };

// Hex digit values; 0x10 marks a byte that is not a hex digit.
using kernels::hex_table;


// A Page Time "YYYY-MM-DD HH:MM:SS:mmm" (":mmm" optional).
struct Stamp {
  int year = 0, month = 0, day = 0, hour = 0, min = 0, sec = 0, ms = 0;
  std::int64_t naive_ms() const {  // ms since 1970 of the fields read as UTC
    const std::int64_t d = days_from_civil(year, static_cast<unsigned>(month),
                                           static_cast<unsigned>(day));
    return ((d * 24 + hour) * 60 + min) * 60000 + sec * 1000 + ms;
  }
};

inline bool read_int(const char*& p, const char* end, int digits_min, int digits_max,
                     int& out) {
  int v = 0, k = 0;
  while (p < end && k < digits_max && *p >= '0' && *p <= '9') {
    v = v * 10 + (*p - '0');
    ++p;
    ++k;
  }
  out = v;
  return k >= digits_min;
}

inline bool parse_stamp(const char* p, const char* end, Stamp& s) {
  auto sep = [&](char c) { return p < end && *p++ == c; };
  if (!read_int(p, end, 4, 4, s.year) || !sep('-') || !read_int(p, end, 1, 2, s.month) ||
      !sep('-') || !read_int(p, end, 1, 2, s.day) || !sep(' ') ||
      !read_int(p, end, 1, 2, s.hour) || !sep(':') || !read_int(p, end, 1, 2, s.min) ||
      !sep(':') || !read_int(p, end, 1, 2, s.sec)) {
    return false;
  }
  s.ms = 0;
  if (p < end && *p == ':') {
    ++p;
    if (!read_int(p, end, 3, 3, s.ms)) return false;
  }
  while (p < end && (*p == ' ' || *p == '\0')) ++p;
  return p == end && s.month >= 1 && s.month <= 12 && s.day >= 1 && s.day <= 31 &&
         s.hour <= 23 && s.min <= 59 && s.sec <= 60;
}

// A number after "Key:" (trailing blanks allowed); strtod in the C locale,
// as std::istream >> double reads it.
inline bool parse_number(const char* p, const char* end, double& out) {
  char tmp[64];
  while (p < end && *p == ' ') ++p;
  while (end > p && (end[-1] == ' ' || end[-1] == '\0')) --end;
  const std::size_t n = static_cast<std::size_t>(end - p);
  if (n == 0 || n >= sizeof tmp) return false;
  std::memcpy(tmp, p, n);
  tmp[n] = '\0';
  char* stop = nullptr;
  out = std::strtod(tmp, &stop);
  return stop == tmp + n && std::isfinite(out);
}

// The first number of a header value ("100 Hz", "-8 to 8"): as istream >>.
inline bool parse_leading(const char* p, const char* end, double& out) {
  char tmp[64];
  const std::size_t n = static_cast<std::size_t>(end - p) < sizeof tmp - 1
                            ? static_cast<std::size_t>(end - p)
                            : sizeof tmp - 1;
  std::memcpy(tmp, p, n);
  tmp[n] = '\0';
  char* stop = nullptr;
  out = std::strtod(tmp, &stop);
  return stop != tmp && std::isfinite(out);
}

inline bool starts_with(const char* p, std::size_t n, const char* key) {
  const std::size_t k = std::strlen(key);
  return n >= k && std::memcmp(p, key, k) == 0;
}

inline bool is_line(const char* p, std::size_t n, const char* text) {
  while (n > 0 && (p[n - 1] == ' ' || p[n - 1] == '\0')) --n;
  return n == std::strlen(text) && std::memcmp(p, text, n) == 0;
}

// What readGENEActiv reads from its header for light (see the top of the
// file): the first of the first 69 lines to contain "Lux", "Volts" and
// "Device Model", as R's readLines() gives them (cut at a NUL).
class LightHeader {
 public:
  void line(const char* p, std::size_t n) {
    if (lines_++ >= kLightHeaderLines) return;
    const void* nul = std::memchr(p, '\0', n);
    if (nul != nullptr) n = static_cast<std::size_t>(static_cast<const char*>(nul) - p);
    const std::string s(p, n);
    if (!have_lux_ && s.find("Lux") != std::string::npos) {
      have_lux_ = true;
      lux = r_number(without(s, "Lux:"));
    }
    if (!have_volts_ && s.find("Volts") != std::string::npos) {
      have_volts_ = true;
      volts = r_number(without(s, "Volts:"));
    }
    if (!have_model_ && s.find("Device Model") != std::string::npos) {
      have_model_ = true;
      const std::string m = without(without(s, "Device Model:"), " ");
      model11 = m.size() >= 3 && m.compare(m.size() - 3, 3, "1.1") == 0;
    }
  }
  double lux = r_na_real(), volts = r_na_real();
  bool model11 = false;  // no "Device Model" line: grepl() of NA is FALSE

 private:
  // gsub(key, "", s, fixed)
  static std::string without(std::string s, const char* key) {
    const std::size_t k = std::strlen(key);
    for (std::size_t at = s.find(key); at != std::string::npos; at = s.find(key, at)) s.erase(at, k);
    return s;
  }
  // as.numeric() of a text: blanks around, strtod's number, else NA
  static double r_number(const std::string& s) {
    std::size_t a = 0, b = s.size();
    while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
    while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
    if (a == b) return r_na_real();
    const std::string t = s.substr(a, b - a);
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    return end == t.c_str() + t.size() ? v : r_na_real();
  }
  int lines_ = 0;
  bool have_lux_ = false, have_volts_ = false, have_model_ = false;
};

}  // namespace geneactiv

class GeneactivDecoder : public Decoder {
 public:
  // While set, read() continues the current reference call instead of
  // starting one at a page boundary, so that one call can be read in
  // several chunks (GgirResampler in decode_ggir_resample.hpp does).
  void continue_call(bool on) { continue_call_ = on; }
  GeneactivDecoder(ByteSource& src, const Options& opts)
      : lines_(src, geneactiv::kBufferBytes, geneactiv::kMaxLine),
        rules_(ReadRules::of(opts)) {
    info_.format = "geneactiv";
    static const char* const keys[3] = {"light_lux", "light_volts", "light_model11"};
    for (int i = 0; i < 3; ++i) {
      light_given_[i] = opts.has_num(keys[i]);
      light_opt_[i] = opts.num(keys[i], 0);
    }
  }

  bool open() override;
  std::int64_t read(SampleBuffer& out, std::int64_t max_units) override;
  bool done() const override { return done_; }
  std::size_t max_samples_per_unit() const override { return geneactiv::kSamplesPerPage; }

 private:
  enum class Unit { none, good, skipped };
  struct Page {
    std::uint16_t raw[geneactiv::kSamplesPerPage][3];
    std::size_t count = 0;  // samples decoded
    double temperature = 0, freq = 0;
    double time_s = 0;      // compat 0: first sample, s since 1970 UTC
    std::int64_t base_ms = 0;  // compat 1: the reference's ms count at sample 0
    std::int64_t seq = 0, stamp_ms = 0;
    geneactiv::Stamp stamp;
    std::int64_t offset = 0;
    char hex[geneactiv::kDigitsPerPage];  // the hex line, for light
    std::size_t hex_n = 0;
    bool has_hex = false;  // hex holds the line (keep_hex_ when parsed)
  };

  bool fail(const std::string& why) {
    error_ = why;
    return false;
  }
  bool header_line(const char* p, std::size_t n);
  bool calibration_line(const char* p, std::size_t n);
  bool check_header();
  bool recognise();
  Unit parse_page();
  Unit skip(const char* counter, const char* what, bool truncated);
  bool page_field(int k, const char* p, std::size_t n);
  bool decode_hex(const char* p, std::size_t n, bool complete);
  void accept(Unit u);
  void check_time();
  void advance_chain(double freq, std::size_t count);
  void emit(SampleBuffer& out);
  void emit_light(const Page& p, std::size_t from, std::size_t k, double* light) const;
  void light_table();
  void finish_block(SampleBuffer& out, std::size_t n0);
  void finish_input();
  void note_at(const char* what, std::int64_t offset);
  double anchor_time(const geneactiv::Stamp& s) const;

  LineReader lines_;
  Line line_;  // the line lines_ gave last
  // the reading rules (compat, resample_fused), read once
  const ReadRules rules_;
  // GGIRread's reader is C++ compiled by the R it runs in: where that
  // compiler contracted its ms + s * 1000 into one fused multiply-add
  // (aarch64; option resample_fused, R/fp-build.R), so does ms_after()
  double ms_after(double ms, double seconds) const {
    return rules_.fused ? kernels::replay_fma(seconds, 1000.0, ms) : ms + seconds * 1000;
  }
  bool done_ = false;
  // calibration: value of each 12-bit count per axis
  double gain_[3] = {0, 0, 0};
  long offset_[3] = {0, 0, 0};
  bool have_gain_[3] = {false, false, false}, have_offset_[3] = {false, false, false};
  double lut_[3][geneactiv::kCountRange];
  // light: the header's values, then each 10-bit value's lux
  geneactiv::LightHeader light_header_;
  bool light_given_[3] = {false, false, false};  // options light_lux, light_volts, light_model11
  double light_opt_[3] = {0, 0, 0};
  bool keep_hex_ = true;  // copy each page's hex line: the reads ask for light
  double light_lut_[geneactiv::kLightRange];
  double header_rate_ = 0;
  double tz_ms_ = 0;
  long header_pages_ = -1;
  bool have_pages_line_ = false;
  // the page being parsed (next_) and the one being given (cur_)
  Page pages_[2];
  Page* next_ = &pages_[0];
  Page* cur_ = &pages_[1];
  Unit next_unit_ = Unit::none;
  bool have_next_ = false;
  std::size_t emitted_ = 0;
  bool pending_ = false;  // cur_ has samples not yet given
  std::int64_t pages_seen_ = 0;  // units consumed
  // time line check
  bool have_prev_ = false;
  std::int64_t prev_seq_ = 0, prev_units_ = 0;
  double prev_ms_ = 0, prev_freq_ = 0;
  bool have_candidate_ = false, have_seq_candidate_ = false;
  double candidate_ms_ = 0;
  std::int64_t seq_candidate_ = 0;
  // compat 1: the reference's per-call time count
  std::int64_t chain_ms_ = 0;
  bool continue_call_ = false;
  std::int64_t block_first_ = 0;  // pages before this reference call
  double block_rate_ = 0;
  bool have_anchor_ = false;
  double anchor_ = 0;           // first page's time, s (local time zone)
  double last_good_rate_ = 0;
  bool block_open_ = false;
};

// ---------------------------------------------------------------------------
// Header

inline bool GeneactivDecoder::recognise() {
  const char* c = nullptr;
  const std::size_t n = lines_.peek_at_least(c, 600);
  if (n == 0) return fail("empty file");
  const unsigned char* p = reinterpret_cast<const unsigned char*>(c);
  if (n >= 516 && std::memcmp(p + 512, "MDTC", 4) == 0) {
    return fail("not a GENEActiv file: it looks like a Matrix/Parmay file (\"MDTC\" at byte 512)");
  }
  if (geneactiv::starts_with(c, n, "GENEA/") || geneactiv::starts_with(c, n, "GENEA\r") ||
      geneactiv::starts_with(c, n, "GENEA\n")) {
    return fail("not a GENEActiv file: it looks like an older Genea file (first line \"GENEA...\")");
  }
  if (geneactiv::starts_with(c, n, geneactiv::kFirstLine)) return true;
  std::string first;
  for (std::size_t i = 0; i < n && i < 40 && p[i] != '\n' && p[i] != '\r'; ++i) {
    first += (p[i] >= 32 && p[i] < 127) ? static_cast<char>(p[i]) : '?';
  }
  return fail("not a GENEActiv file: first line is \"" + first + "\", not \"" +
              geneactiv::kFirstLine + "\"");
}

// A calibration line ("x gain:25875", "x offset:439"); false when bad.
inline bool GeneactivDecoder::calibration_line(const char* p, std::size_t n) {
  using geneactiv::starts_with;
  static const char* const gains[3] = {"x gain:", "y gain:", "z gain:"};
  static const char* const offsets[3] = {"x offset:", "y offset:", "z offset:"};
  const char* end = p + n;
  for (int a = 0; a < 3; ++a) {
    double v = 0;
    const bool gain = starts_with(p, n, gains[a]);
    if (!gain && !starts_with(p, n, offsets[a])) continue;
    const char* key = gain ? gains[a] : offsets[a];
    const bool ok = geneactiv::parse_leading(p + std::strlen(key), end, v) &&
                    (gain ? v >= geneactiv::kMinGain && v <= geneactiv::kMaxGain
                          : std::fabs(v) <= geneactiv::kMaxOffset);
    if (!ok) {
      return fail(std::string("bad calibration line \"") + key + "\" at byte " +
                  std::to_string(line_.offset));
    }
    if (gain) {
      gain_[a] = v;
      have_gain_[a] = true;
    } else {
      offset_[a] = static_cast<long>(v);  // std::istream >> int: the integer part
      have_offset_[a] = true;
    }
  }
  return true;
}

// One header line "Key:value"; false when a value the decoder needs is bad.
inline bool GeneactivDecoder::header_line(const char* p, std::size_t n) {
  using geneactiv::starts_with;
  if (!calibration_line(p, n)) return false;
  const char* end = p + n;
  auto value = [&](const char* key) { return p + std::strlen(key); };
  auto trimmed = [&](const char* key) {
    std::string s(value(key), end);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
    return s;
  };
  double v = 0;
  if (starts_with(p, n, "Device Unique Serial Code:") && info_.serial.empty()) {
    info_.serial = trimmed("Device Unique Serial Code:");
  } else if (starts_with(p, n, "Device Type:")) {
    info_.device = trimmed("Device Type:") + (info_.device.empty() ? "" : " " + info_.device);
  } else if (starts_with(p, n, "Device Model:")) {
    info_.device += (info_.device.empty() ? "" : " ") + trimmed("Device Model:");
  } else if (starts_with(p, n, "Measurement Frequency:")) {
    if (geneactiv::parse_leading(value("Measurement Frequency:"), end, v)) header_rate_ = v;
  } else if (starts_with(p, n, "Accelerometer Range:")) {
    // "-8 to 8": the full scale is the last number
    const std::string s(value("Accelerometer Range:"), end);
    const std::size_t k = s.find("to");
    if (k != std::string::npos &&
        geneactiv::parse_leading(s.c_str() + k + 2, s.c_str() + s.size(), v)) {
      info_.range_g = v;
    }
  } else if (starts_with(p, n, "Time Zone:")) {
    // "GMT +01:00"
    const std::string s = trimmed("Time Zone:");
    int h = 0, m = 0;
    char sign = '+';
    if (std::sscanf(s.c_str(), "GMT %c%d:%d", &sign, &h, &m) == 3 &&
        (sign == '+' || sign == '-') && h <= geneactiv::kMaxTimeZoneHours && m < 60) {
      tz_ms_ = (sign == '-' ? -1.0 : 1.0) * (h * 3600000.0 + m * 60000.0);
    } else {
      report_.note("header: time zone \"" + s + "\" not understood, taken as GMT");
    }
  } else if (starts_with(p, n, "Number of Pages:")) {
    have_pages_line_ = true;
    if (geneactiv::parse_leading(value("Number of Pages:"), end, v) && v >= 0 && v < 1e15) {
      header_pages_ = static_cast<long>(v);
    }
  }
  return true;
}

inline bool GeneactivDecoder::check_header() {
  static const char* const axes = "xyz";
  for (int a = 0; a < 3; ++a) {
    if (!have_gain_[a] || !have_offset_[a]) {
      return fail(std::string("header has no \"") + axes[a] + (have_gain_[a] ? " offset:" : " gain:") +
                  "\" line (calibration data)");
    }
  }
  if (!(header_rate_ >= geneactiv::kMinRate && header_rate_ <= geneactiv::kMaxRate)) {
    return fail("header has no usable \"Measurement Frequency:\"");
  }
  info_.sf = header_rate_;
  last_good_rate_ = header_rate_;
  block_rate_ = header_rate_;
  // value of every count, as the reference: (count * 100. - offset) / gain,
  // stored as float
  for (int a = 0; a < 3; ++a) {
    for (int u = 0; u < geneactiv::kCountRange; ++u) {
      const int c = u >= geneactiv::kCountSigned ? u - geneactiv::kCountRange : u;
      const double g = (c * geneactiv::kCountScale - static_cast<double>(offset_[a])) / gain_[a];
      lut_[a][u] = rules_.compat ? static_cast<double>(static_cast<float>(g)) : g;
    }
  }
  return true;
}

inline bool GeneactivDecoder::open() {
  if (!recognise()) return false;
  int k = 0;
  for (;; ++k) {
    if (!lines_.next(line_)) {
      if (lines_.read_failed()) return fail("read error in the header");
      if (!have_pages_line_) {
        return fail("header truncated at byte " + std::to_string(line_.offset + static_cast<std::int64_t>(line_.n)));
      }
      break;
    }
    if (!line_.has_end && !have_pages_line_) {
      return fail("header truncated at byte " + std::to_string(line_.offset + static_cast<std::int64_t>(line_.n)));
    }
    if (geneactiv::is_line(line_.p, line_.n, geneactiv::kPageStart)) {
      lines_.unread();
      break;
    }
    if (k >= geneactiv::kMaxHeaderLines) {
      return fail("no \"Recorded Data\" page within the first " +
                  std::to_string(geneactiv::kMaxHeaderLines) + " lines");
    }
    light_header_.line(line_.p, line_.n);
    if (!header_line(line_.p, line_.n)) return false;
  }
  if (!check_header()) return false;
  light_table();
  info_.has_temperature = true;
  info_.has_time = true;
  info_.has_light = true;
  next_unit_ = parse_page();
  have_next_ = true;
  if (next_unit_ == Unit::good) {
    info_.start_time = rules_.compat ? anchor_time(next_->stamp) : next_->time_s;
  }
  return true;
}

// ---------------------------------------------------------------------------
// Pages

inline void GeneactivDecoder::note_at(const char* what, std::int64_t offset) {
  report_.note(std::string(what) + " (page " + std::to_string(pages_seen_ + 1) + ", byte " +
               std::to_string(offset) + ")");
}

// A value of page header line k; false when it is not what the format says.
inline bool GeneactivDecoder::page_field(int k, const char* p, std::size_t n) {
  using namespace geneactiv;
  if (!starts_with(p, n, kPageKeys[k])) return false;
  const char* v = p + std::strlen(kPageKeys[k]);
  const char* end = p + n;
  double d = 0;
  switch (k) {
    case kSequence:
      if (!parse_number(v, end, d) || d < 0 || d > 1e15 || d != std::floor(d)) return false;
      next_->seq = static_cast<std::int64_t>(d);
      return true;
    case kTime:
      if (!parse_stamp(v, end, next_->stamp)) return false;
      next_->stamp_ms = next_->stamp.naive_ms();
      next_->time_s = (static_cast<double>(next_->stamp_ms) - tz_ms_) / 1000.0;
      return true;
    case kTemperature:
      if (!parse_number(v, end, d) || std::fabs(d) > 1000) return false;
      next_->temperature = rules_.compat ? static_cast<double>(static_cast<float>(d)) : d;
      return true;
    case kFrequency:
      if (!parse_number(v, end, d) || !(d >= kMinRate) || d > kMaxRate) return false;
      next_->freq = d;
      return true;
    default:
      return true;
  }
}

// The hex line into next_->raw; false when it is malformed. A line the input
// cut short (complete false) keeps its samples whose x, y, z are whole.
inline bool GeneactivDecoder::decode_hex(const char* p, std::size_t n, bool complete) {
  using namespace geneactiv;
  const unsigned char* h = hex_table().v;
  const unsigned char* s = reinterpret_cast<const unsigned char*>(p);
  if (complete ? n != kDigitsPerPage : n > kDigitsPerPage) return false;
  const std::size_t whole = n / kDigitsPerSample;
  unsigned bad = kernels::active().hex_counts(s, whole, n, next_->raw, kSamplesPerPage);
  s += whole * kDigitsPerSample;
  std::size_t count = whole;
  const std::size_t rest = n - whole * kDigitsPerSample;
  if (rest >= (rules_.compat ? kDigitsXyzCompat : kDigitsPerSample)) {
    for (int a = 0; a < 3; ++a) {
      const unsigned d0 = h[s[3 * a]], d1 = h[s[3 * a + 1]], d2 = h[s[3 * a + 2]];
      bad |= d0 | d1 | d2;
      next_->raw[count][a] = static_cast<std::uint16_t>((d0 << 8) | (d1 << 4) | d2);
    }
    for (std::size_t j = kDigitsXyz; j < rest; ++j) bad |= h[s[j]];
    ++count;
  }
  next_->count = count;
  next_->has_hex = keep_hex_;
  if (keep_hex_) {
    std::memcpy(next_->hex, p, n);
    next_->hex_n = n;
  }
  return (bad & 0x10u) == 0;
}

inline GeneactivDecoder::Unit GeneactivDecoder::skip(const char* counter, const char* what,
                                                     bool truncated) {
  if (truncated) report_.truncated = true;
  report_.count(counter);
  note_at(what, next_->offset);
  next_->count = 0;
  return Unit::skipped;
}

// Reads the next unit into next_. none: the input has ended.
inline GeneactivDecoder::Unit GeneactivDecoder::parse_page() {
  using namespace geneactiv;
  for (;;) {  // to the next "Recorded Data"
    if (!lines_.next(line_)) return Unit::none;
    if (is_line(line_.p, line_.n, kPageStart)) break;
    bool blank = true;
    for (std::size_t i = 0; i < line_.n && blank; ++i) {
      blank = line_.p[i] == ' ' || line_.p[i] == '\0';
    }
    if (!blank) {
      report_.count("stray_lines");
      if (report_.get("stray_lines") <= 3) note_at("line outside any page skipped", line_.offset);
    }
  }
  next_->offset = line_.offset;
  next_->count = 0;
  bool damaged = false;
  for (int k = 0; k <= kPageHeaderLines; ++k) {  // 8 header lines, then hex
    if (!lines_.next(line_)) return skip("truncated_page", "input ends inside a page", true);
    if (is_line(line_.p, line_.n, kPageStart)) {
      lines_.unread();
      return skip("bad_page_header", "page with a missing line skipped", false);
    }
    if (k == kPageHeaderLines) break;
    if (!line_.has_end) return skip("truncated_page", "input ends inside a page", true);
    if (!damaged && !page_field(k, line_.p, line_.n)) damaged = true;
  }
  if (damaged) return skip("bad_page_header", "page with a damaged header line skipped", false);
  const bool whole_line = line_.has_end;
  if (line_.too_long || !decode_hex(line_.p, line_.n, whole_line)) {
    if (!whole_line) return skip("truncated_page", "input ends inside a malformed hex line", true);
    return skip("bad_hex", "page with a malformed hex line skipped", false);
  }
  if (!whole_line && line_.n < kDigitsPerPage) {
    report_.truncated = true;
    report_.count("truncated_page");
    note_at(("input ends inside the hex line: " + std::to_string(next_->count) + " of 300 samples kept").c_str(),
            next_->offset);
    if (next_->count == 0) return Unit::skipped;
  }
  return Unit::good;
}

// ---------------------------------------------------------------------------
// Time

// A Page Time as R's as.POSIXlt(tz = "") then as.numeric() reads it: the
// fields in the local time zone (mktime), plus the fraction of the seconds
// "SS.mmm" as strtod reads them.
inline double GeneactivDecoder::anchor_time(const geneactiv::Stamp& s) const {
  std::tm tm{};
  tm.tm_year = s.year - 1900;
  tm.tm_mon = s.month - 1;
  tm.tm_mday = s.day;
  tm.tm_hour = s.hour;
  tm.tm_min = s.min;
  tm.tm_sec = s.sec;
  tm.tm_isdst = -1;
  const std::time_t t = std::mktime(&tm);
  char secs[16];
  std::snprintf(secs, sizeof secs, "%02d.%03d", s.sec % 100, s.ms % 1000);
  const double v = std::strtod(secs, nullptr);
  return static_cast<double>(t) + (v - std::floor(v));
}

// The reference's ms count after a page of `count` samples at `freq`: the
// last sample's time plus one period, truncated.
inline void GeneactivDecoder::advance_chain(double freq, std::size_t count) {
  if (count == 0) return;
  const double last = ms_after(static_cast<double>(chain_ms_),
                               static_cast<double>(count - 1) * (1.0 / freq));
  chain_ms_ = static_cast<std::int64_t>(ms_after(last, 1.0 / freq));
}

// Checks next_'s Page Time and Sequence Number against the last good page
// (expected: one page of 300 / rate later per unit since). A jump is a gap;
// a lone page whose time disagrees while its sequence number fits is timed
// as predicted (bad_page_time), unless the next page confirms the new time.
inline void GeneactivDecoder::check_time() {
  Page& p = *next_;
  double t = static_cast<double>(p.stamp_ms);
  if (have_prev_) {
    const std::int64_t k = pages_seen_ - prev_units_;
    const double page_ms = geneactiv::kSamplesPerPage * 1000.0 / prev_freq_;
    const double tol = 1000.0 / prev_freq_ + 1.0;
    const double expected = prev_ms_ + static_cast<double>(k) * page_ms;
    const double d = t - expected;
    const bool seq_ok = p.seq == prev_seq_ + k;
    bool jump = false;
    if (std::fabs(d) <= tol) {
      // a lone wrong number is counted and mended; a new numbering that
      // goes on from it is taken
      if (!seq_ok && !(have_seq_candidate_ && p.seq == seq_candidate_ + 1)) {
        report_.count("bad_sequence");
        note_at("sequence number out of order (page kept)", p.offset);
        have_seq_candidate_ = true;
        seq_candidate_ = p.seq;
        p.seq = prev_seq_ + k;
      } else {
        have_seq_candidate_ = false;
      }
      have_candidate_ = false;
    } else if (seq_ok && !(have_candidate_ && std::fabs(t - candidate_ms_ - page_ms) <= tol)) {
      report_.count("bad_page_time");
      note_at("page time out of line (page kept, timed as predicted)", p.offset);
      have_candidate_ = true;
      candidate_ms_ = t;
      t = expected;
      p.time_s = (t - tz_ms_) / 1000.0;
    } else {
      jump = true;
      have_candidate_ = false;
    }
    if (jump && d > 0) {
      ++report_.gaps;
      report_.gap_seconds += d / 1000.0;
      note_at(("gap of " + std::to_string(d / 1000.0) + " s").c_str(), p.offset);
    } else if (jump) {
      report_.count("time_backwards");
      note_at(("time goes back " + std::to_string(-d / 1000.0) + " s (page kept)").c_str(), p.offset);
    }
  }
  have_prev_ = true;
  prev_ms_ = t;
  prev_seq_ = p.seq;
  prev_units_ = pages_seen_;
  prev_freq_ = p.freq;
}

// Consumes the unit in next_.
inline void GeneactivDecoder::accept(Unit u) {
  if (u == Unit::skipped) {
    ++report_.skipped;
    if (rules_.compat) advance_chain(last_good_rate_, geneactiv::kSamplesPerPage);
    ++pages_seen_;
    return;
  }
  Page& p = *next_;
  check_time();
  if (p.freq != last_good_rate_ && report_.units > 0) {
    if (report_.get("rate_changes") == 0) note_at("measurement frequency changes", p.offset);
    report_.count("rate_changes");
  }
  if (!have_anchor_) {
    have_anchor_ = true;
    anchor_ = anchor_time(p.stamp);
    if (pages_seen_ > 0) {
      anchor_ -= static_cast<double>(pages_seen_ * static_cast<std::int64_t>(geneactiv::kSamplesPerPage)) / p.freq;
    }
  }
  last_good_rate_ = p.freq;
  block_rate_ = p.freq;
  p.base_ms = chain_ms_;
  if (rules_.compat) advance_chain(p.freq, p.count);
  ++report_.units;
  ++pages_seen_;
  std::swap(next_, cur_);
  emitted_ = 0;
  pending_ = true;
}

// Gives cur_'s samples until out is full.
inline void GeneactivDecoder::emit(SampleBuffer& out) {
  const Page& p = *cur_;
  std::size_t k = p.count - emitted_;
  if (k > out.room()) k = out.room();
  const std::size_t n = out.n;
  const double inv = 1.0 / p.freq;
  for (std::size_t j = 0; j < k; ++j) {
    const std::size_t i = emitted_ + j;
    out.x[n + j] = lut_[0][p.raw[i][0]];
    out.y[n + j] = lut_[1][p.raw[i][1]];
    out.z[n + j] = lut_[2][p.raw[i][2]];
  }
  if (out.t != nullptr) {
    for (std::size_t j = 0; j < k; ++j) out.t[n + j] = p.temperature;
  }
  if (out.light != nullptr) emit_light(p, emitted_, k, out.light + n);
  if (out.time != nullptr) {
    auto time_of = [&](std::size_t j) {
      const double i = static_cast<double>(emitted_ + j);
      if (rules_.compat) {
        // Unix ms as the reference: truncated to an integer, then / 1000
        const double t = ms_after(static_cast<double>(p.base_ms), i * inv);
        out.time[n + j] = static_cast<double>(static_cast<std::int64_t>(t)) / 1000;
      } else {
        out.time[n + j] = p.time_s + i / p.freq;
      }
    };
    if (!out.time_ends_only) {
      for (std::size_t j = 0; j < k; ++j) time_of(j);
    } else {
      // the buffer's first row, and this call's last two (the buffer's
      // last two when it is the read's last call, or its last and the
      // call before's last)
      if (n == 0 && k > 0) time_of(0);
      for (std::size_t j = k >= 2 ? k - 2 : 0; j < k; ++j) time_of(j);
    }
  }
  out.n += k;
  emitted_ += k;
  report_.samples += static_cast<std::int64_t>(k);
  if (emitted_ >= p.count) pending_ = false;
}

// Light of samples [from, from + k) of page p (see the top of the file).
inline void GeneactivDecoder::emit_light(const Page& p, std::size_t from, std::size_t k,
                                         double* light) const {
  using namespace geneactiv;
  const unsigned char* h = hex_table().v;
  if (!p.has_hex) {
    std::fill(light, light + k, std::numeric_limits<double>::quiet_NaN());
    return;
  }
  for (std::size_t j = 0; j < k; ++j) {
    const std::size_t at = (from + j) * kDigitsPerSample + kDigitsXyz;
    const std::size_t digits = p.hex_n - at < 3 ? p.hex_n - at : 3;  // 1 or 2: a cut last sample
    unsigned v = 0;
    for (std::size_t d = 0; d < digits; ++d) v = (v << 4) | h[static_cast<unsigned char>(p.hex[at + d])];
    light[j] = light_lut_[v >> 2];
  }
}

// Each 10-bit value's light, as readGENEActiv computes it from the header's
// values (or those the options give).
inline void GeneactivDecoder::light_table() {
  const double lux = light_given_[0] ? light_opt_[0] : light_header_.lux;
  const double volts = light_given_[1] ? light_opt_[1] : light_header_.volts;
  const bool model11 = light_given_[2] ? light_opt_[2] != 0 : light_header_.model11;
  const double per = lux / volts;
  for (int u = 0; u < geneactiv::kLightRange; ++u) {
    const double l = u;
    const double m = model11 ? l
                     : l < 256 ? l
                     : l < 512 ? (l - 128) * 2
                     : l < 768 ? (l - 320) * 4
                     : (l - 656) * 16;
    light_lut_[u] = m * per;
  }
}

// compat 1: the reference adds the first page's time and ((s - 1) * 300) /
// rate (rate of the call's last page) to its ms count / 1000.
inline void GeneactivDecoder::finish_block(SampleBuffer& out, std::size_t n0) {
  if (!rules_.compat || out.time == nullptr || out.n == n0) return;
  double start = anchor_;
  if (block_first_ > 0) {
    start += static_cast<double>(block_first_ * static_cast<std::int64_t>(geneactiv::kSamplesPerPage)) /
             block_rate_;
  }
  if (!out.time_ends_only) {
    for (std::size_t i = n0; i < out.n; ++i) out.time[i] = out.time[i] + start;
    return;
  }
  // the rows emit() timed: the first, the last two (each once)
  const std::size_t last = out.n - 1;
  const std::size_t from = std::max(n0, out.n >= 2 ? out.n - 2 : 0);
  if (n0 == 0 && from > 0) out.time[0] = out.time[0] + start;
  for (std::size_t i = from; i <= last; ++i) out.time[i] = out.time[i] + start;
}

inline void GeneactivDecoder::finish_input() {
  if (done_) return;
  done_ = true;
  if (lines_.read_failed()) {
    report_.read_error = true;
    report_.note("read error after byte " + std::to_string(line_.offset) + ": data end there");
  }
  if (header_pages_ >= 0 && header_pages_ != pages_seen_) {
    report_.note("header says " + std::to_string(header_pages_) + " pages, the file has " +
                 std::to_string(pages_seen_));
  }
}

inline std::int64_t GeneactivDecoder::read(SampleBuffer& out, std::int64_t max_units) {
  const std::size_t n0 = out.n;
  keep_hex_ = out.light != nullptr;
  std::int64_t units = 0;
  if (rules_.compat && !pending_ && !continue_call_ && (max_units >= 0 || !block_open_)) {
    // a new reference call from page pages_seen_ + 1
    block_open_ = true;
    chain_ms_ = 0;
    block_first_ = pages_seen_;
    block_rate_ = last_good_rate_;
  }
  for (;;) {
    if (pending_) {
      emit(out);
      if (pending_) break;  // out is full
    }
    if (max_units >= 0 && units >= max_units) break;
    if (!have_next_) {
      next_unit_ = parse_page();
      have_next_ = true;
    }
    if (next_unit_ == Unit::none) break;
    have_next_ = false;
    accept(next_unit_);
    ++units;
  }
  finish_block(out, n0);
  if (!pending_) {
    if (!have_next_) {
      next_unit_ = parse_page();
      have_next_ = true;
    }
    if (next_unit_ == Unit::none) finish_input();
  }
  return units;
}

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_GENEACTIV_HPP
