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
// - Damage: compat 1 reads a page as the reference does (parse_page_ggir(),
//   the rules in geneactiv_ggir.hpp): ten lines a page whatever they hold
//   (a line missing or extra shifts every page after it, as there), the
//   temperature and rate from their lines as a stringstream reads them (a
//   garbled value as far as it reads, 0 where it does not, the call's value
//   kept where the line has no ':' or nothing after it), the hex line cut
//   into groups of 3 read by std::stoll (garbled digits read as far as they
//   go; the page ends at the first group with none: what came before it is
//   kept; a line too long gives more samples), and the time count closes up
//   after a page short of samples (each page starts where its samples
//   before end). Where the input ends inside a page's header lines, the
//   reference's strings keep what they held (std::getline leaves them): the
//   page gives the page before's samples again (none at a call's first
//   page), with what its cut line reads as temperature and rate. Nothing
//   is skipped; damaged_hex, damaged_page_header, misaligned_page and
//   truncated_page count what was read so, with notes. Where the reference
//   gives what gravcal does not reproduce, it is counted for R to refuse
//   (R/meta-formats.R): a rate of 0 Hz, whose times C++ does not define
//   (ggir_time_undefined: those times NaN; ggir_resampled_time_undefined
//   where the rate is not whole and GGIR resamples by them), a block whose
//   last page's rate changes GGIR's resampling or its file rate
//   (ggir_rate_mismatch), a first page time R does not read
//   (ggir_start_unread), a line longer than the reader keeps whose rest the
//   reference would read (ggir_not_reproduced). A call whose last page's
//   rate differs from its pages' before has its ends retimed
//   (call_end_times()).
//   compat 0 resynchronises on "Recorded Data", skips and counts a damaged
//   page whole (bad_hex, bad_page_header), and times later pages as if it
//   had been there (each page by its own Page Time); a final hex line cut
//   short keeps its whole 12-digit samples; a page header cut by the end of
//   the input drops the page.
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
// status bits dropped; compat 1, a damaged or cut hex line: its fourth
// group as std::stoll reads it, over 4, -63..1023, a value below 0 not
// mapped), for a "Device Model" other than
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
// hex line (3600 bytes; compat 1, a damaged line: its values as read) made
// while the reads ask for light: from open() to
// the first read() without light, and again from a read() with it. A page
// read before a caller starts asking has no copy: its light is NaN.
//
// max_units counts pages ("Recorded Data" units, damaged ones included, as
// the reference's page numbers do; compat 1: its pages of ten lines). GGIR's
// block k, readGENEActiv(start = s, end = s + B - 1) with s = (k - 1) * B +
// 1, is the k-th read(out, B) into a buffer of at least B * 300 samples
// (more where a damaged page gives more: up to kMaxPageSamples).
//
// Report counters: bad_hex, bad_page_header, truncated_page (skipped pages;
// compat 1: the pages read as the reference reads them, see Damage),
// stray_lines (lines outside any page, compat 0), bad_sequence,
// bad_page_time, time_backwards (pages with a readable sequence number
// and time), rate_changes; notes give the page number and byte offset.
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
#include "gravcal/decoders/geneactiv_ggir.hpp"
#include "gravcal/kernels/kernels.hpp"
#include "gravcal/decoders/line_reader.hpp"

namespace gravcal {

namespace geneactiv {

constexpr std::size_t kSamplesPerPage = 300;
constexpr std::size_t kDigitsPerSample = 12;  // x, y, z: 3 each; light+status: 3
constexpr std::size_t kDigitsPerPage = kSamplesPerPage * kDigitsPerSample;
constexpr std::size_t kDigitsXyz = 9;
constexpr int kPageHeaderLines = 8;           // between "Recorded Data" and hex
constexpr int kTemperatureLine = 5;           // the page's lines GGIRread reads a value from
constexpr int kFrequencyLine = 8;
constexpr std::size_t kMaxLine = 8192;        // longer lines are cut (and counted)
// samples a page can give (compat: GGIRread reads a hex line as long as it
// is; the reader's lines are cut at kMaxLine): a longer one is not read
constexpr std::size_t kMaxPageSamples = kMaxLine / kDigitsPerSample + 1;
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
constexpr const char* kPageTimeKey = "Page Time:";
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
  // what a page holds; a damaged page read as GGIRread reads it (compat)
  // may give more, up to kMaxPageSamples (a block store grows for them)
  std::size_t max_samples_per_unit() const override { return geneactiv::kSamplesPerPage; }
  bool call_end_times(CallEndTimes& t) const override;

 private:
  enum class Unit { none, good, skipped };
  struct Page {
    std::uint16_t raw[geneactiv::kMaxPageSamples][3];
    std::size_t count = 0;  // samples decoded
    double temperature = 0, freq = 0;
    double time_s = 0;      // compat 0: first sample, s since 1970 UTC
    std::int64_t base_ms = 0;  // compat 1: the reference's ms count at sample 0
    bool times_defined = true;  // compat 1: so are the reference's times of its samples
    std::int64_t seq = 0, stamp_ms = 0;
    geneactiv::Stamp stamp;
    bool stamped = false;  // compat 1: its sequence number and time read (for check_time())
    std::int64_t offset = 0;
    char hex[geneactiv::kDigitsPerPage];  // the hex line, for light
    std::size_t hex_n = 0;
    bool has_hex = false;  // hex holds the line (keep_hex_ when parsed)
    // compat 1, a hex line read by GGIRread's rules (geneactiv_ggir.hpp):
    // each sample's light value (-63..1023) in light_read
    std::int16_t light_read[geneactiv::kMaxPageSamples];
    bool has_light_read = false;
    // compat 1: the values its temperature and frequency lines read, before
    // the reference call they fall in resolves them (a value kept from
    // before is the call's); from_before: none of its header lines was
    // read (the input ended in its first line), so both read the lines'
    // string as the page before left it, whose reading is before_read;
    // repeat: its hex line was not read, so it holds the page before's
    geneactiv::FieldRead temp_read, freq_read, before_read;
    bool from_before = false, repeat = false;
    // compat 1: a line longer than the reader keeps whose rest GGIRread
    // would read (counted when the page is taken: ggir_not_reproduced)
    const char* overlong = nullptr;
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
  Unit parse_page_ggir();
  bool ggir_line();
  void settle_line();
  void ggir_hex_line(Page& pg);
  void start_line_seen();
  void start_from_page_time();
  void first_page_rate();
  Unit skip(const char* counter, const char* what, bool truncated);
  bool page_field(int k, const char* p, std::size_t n);
  bool decode_hex(const char* p, std::size_t n, bool complete);
  void accept(Unit u);
  void accept_ggir();
  void check_time();
  bool advance_chain(double freq, std::size_t count);
  void start_call();
  void check_call_rate();
  double call_start() const;
  double timed(double raw, double start) const;
  void not_reproduced(const char* counter, const std::string& why);
  // GGIR resamples the blocks (by their times): a rate that is not whole
  bool resampled() const { return header_rate_ != std::nearbyint(header_rate_); }
  void emit(SampleBuffer& out);
  void emit_light(const Page& p, std::size_t from, std::size_t k, double* light) const;
  void light_table();
  double light_per() const;
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
  bool chain_defined_ = true;  // the count is a defined integer
  bool continue_call_ = false;
  std::int64_t block_first_ = 0;  // pages before this reference call
  double block_rate_ = 0;
  bool have_anchor_ = false;
  double anchor_ = 0;           // first page's time, s (local time zone)
  double last_good_rate_ = 0;
  bool block_open_ = false;
  // compat 1: GGIRread's reading of the lines (geneactiv_ggir.hpp): whether
  // its stream has ended (a getline then leaves its string as it was), the
  // reading of the page header string as the last page left it, the
  // reference call's temperature and rate (a value kept from before is
  // theirs; 0 at the call's start), its pages read; the first of the first
  // 69 lines with "Page Time" (readGENEActiv's start), and whether it was
  // looked for
  bool stream_ended_ = false;
  geneactiv::FieldRead last_header_read_;
  double call_temp_ = 0, call_freq_ = 0;
  std::int64_t call_pages_ = 0;
  bool call_checked_ = false;  // check_call_rate() done
  std::string start_line_;
  bool have_start_line_ = false;
  // compat 1: the reference call's rows' times before its start is added
  // (NaN: not defined): its first row and its last two, for
  // call_end_times()
  std::int64_t call_rows_ = 0;
  double call_first_raw_ = 0;
  double call_tail_raw_[2] = {0, 0};
  bool call_timed_ = false;
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
    start_line_seen();
    if (!header_line(line_.p, line_.n)) return false;
  }
  if (!check_header()) return false;
  light_table();
  info_.has_temperature = true;
  info_.has_time = true;
  info_.has_light = true;
  next_unit_ = parse_page();
  have_next_ = true;
  if (rules_.compat) {
    start_from_page_time();
    first_page_rate();
  } else if (next_unit_ == Unit::good) {
    info_.start_time = next_->time_s;
  }
  return true;
}

// compat 1: GGIR takes the file's rate from its first page as
// readGENEActiv(start = 0, end = 1) reads it (g.inspectfile(): that page's
// rate, rounded); where that rounds to another than the header's rate,
// which gravcal takes, it is counted (ggir_rate_mismatch).
inline void GeneactivDecoder::first_page_rate() {
  const Page& p = *next_;
  const bool own = next_unit_ == Unit::good && !p.from_before;
  const double v = own && p.freq_read.kind == geneactiv::FieldRead::value ? p.freq_read.v : 0.0;
  if (std::nearbyint(v) == std::nearbyint(header_rate_)) return;
  report_.count("ggir_rate_mismatch");
  report_.note("the first page reads a rate of " + std::to_string(v) + " Hz, not the header's " +
               std::to_string(header_rate_) + " Hz: GGIR takes the file's rate from it");
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

// The hex line into next_->raw (compat 0); false when it is malformed. A
// line the input cut short keeps its whole samples (12 digits each).
inline bool GeneactivDecoder::decode_hex(const char* p, std::size_t n, bool complete) {
  using namespace geneactiv;
  const unsigned char* s = reinterpret_cast<const unsigned char*>(p);
  if (complete ? n != kDigitsPerPage : n > kDigitsPerPage) return false;
  const std::size_t whole = n / kDigitsPerSample;
  const unsigned bad = kernels::active().hex_counts(s, whole, n, next_->raw, kSamplesPerPage);
  next_->count = whole;
  next_->has_hex = keep_hex_;
  next_->has_light_read = false;
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
  if (rules_.compat) return parse_page_ggir();
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
// Pages as GGIRread reads them (compat 1; its rules: geneactiv_ggir.hpp)

// Its std::getline of the next line into line_: false when nothing comes
// (the input ended at a line's end, or the stream ended before: a getline
// then fails; the first that fails at the input's end empties its string,
// the later ones leave it as it was).
inline bool GeneactivDecoder::ggir_line() {
  if (stream_ended_) return false;
  if (!lines_.next(line_)) {
    stream_ended_ = true;
    return false;
  }
  start_line_seen();
  return true;
}

// After line_ is read: an overlong line skipped to its end, and the stream
// ended where the input ended inside the line.
inline void GeneactivDecoder::settle_line() {
  const bool ended = line_.too_long ? lines_.finish_overlong() : line_.has_end;
  if (!ended) stream_ended_ = true;
}

// The first of the file's first 69 lines that contains "Page Time" (as R's
// readLines() gives them: cut at a NUL), where readGENEActiv finds the
// recording's start.
inline void GeneactivDecoder::start_line_seen() {
  if (have_start_line_ || line_.number > geneactiv::kLightHeaderLines) return;
  std::size_t n = line_.n;
  const void* nul = std::memchr(line_.p, '\0', n);
  if (nul != nullptr) n = static_cast<std::size_t>(static_cast<const char*>(nul) - line_.p);
  const std::string s(line_.p, n);
  if (s.find("Page Time") == std::string::npos) return;
  have_start_line_ = true;
  start_line_ = s;
}

// readGENEActiv's start: that line with every "Page Time:" taken out, read
// as a time (see parse_stamp()); a start it cannot read is counted
// (ggir_start_unread: GGIR's times are then NA).
inline void GeneactivDecoder::start_from_page_time() {
  using namespace geneactiv;
  std::string v = start_line_;
  const std::size_t k = std::strlen(kPageTimeKey);
  for (std::size_t at = v.find(kPageTimeKey); at != std::string::npos; at = v.find(kPageTimeKey, at)) {
    v.erase(at, k);
  }
  Stamp st;
  have_anchor_ = true;
  if (have_start_line_ && parse_stamp(v.data(), v.data() + v.size(), st)) {
    anchor_ = anchor_time(st);
    info_.start_time = anchor_;
    return;
  }
  anchor_ = std::numeric_limits<double>::quiet_NaN();
  if (resampled()) report_.count("ggir_resampled_time_undefined");
  not_reproduced("ggir_start_unread",
                 have_start_line_ ? "the first page's time \"" + start_line_ +
                                        "\" does not read as a time: GGIR's times are NA"
                                  : "no \"Page Time\" in the file's first 69 lines: GGIR's times are NA");
}

inline void GeneactivDecoder::not_reproduced(const char* counter, const std::string& why) {
  if (report_.get(counter) == 0) note_at(why.c_str(), next_->offset);
  report_.count(counter);
}

// The hex line in line_ into pg: a line of 3600 hex digits by the decode
// kernel, any other by GGIRread's rules.
inline void GeneactivDecoder::ggir_hex_line(Page& pg) {
  using namespace geneactiv;
  const bool whole = !line_.too_long;
  const std::size_t size = line_.n + (line_.cr ? 1 : 0);  // std::getline keeps the '\r'
  pg.has_hex = false;
  pg.has_light_read = false;
  if (whole && line_.n == kDigitsPerPage) {
    const unsigned char* s = reinterpret_cast<const unsigned char*>(line_.p);
    const unsigned bad = kernels::active().hex_counts(s, kSamplesPerPage, line_.n, pg.raw, kMaxPageSamples);
    if ((bad & 0x10u) == 0) {
      pg.count = kSamplesPerPage;
      pg.has_hex = keep_hex_;
      if (keep_hex_) {
        std::memcpy(pg.hex, line_.p, line_.n);
        pg.hex_n = line_.n;
      }
      return;
    }
  }
  const HexRead r = read_hex_line(line_.p, size, size, whole, kMaxPageSamples, pg.raw, pg.light_read);
  pg.count = r.count;
  pg.has_light_read = true;
  if (r.unknown || r.full) {
    pg.overlong = "a hex line longer than the decoder reads, which GGIRread would read on";
    return;
  }
  if (!line_.has_end && line_.n < kDigitsPerPage) {
    report_.truncated = true;
    report_.count("truncated_page");
    note_at(("input ends inside the hex line: " + std::to_string(r.count) +
             " of 300 samples kept").c_str(), pg.offset);
    return;
  }
  report_.count("damaged_hex");
  if (!line_.has_end) report_.truncated = true;
  note_at(("hex line of " + std::to_string(line_.n) + " characters, not 3600 hex digits: " +
           std::to_string(r.count) + " samples read from it as GGIRread reads it" +
           (r.all_read ? "" : " (the rest lost at a group without a hex digit)")).c_str(),
          pg.offset);
}

// The next page as GGIRread reads it: its ten lines, whatever they hold.
// Only the temperature and frequency lines' values and the hex line count;
// the others are checked for the report (damaged_page_header,
// misaligned_page) and the sequence number and time read for
// check_time(). A page the input ends in keeps what GGIRread's strings
// hold then (see Page: from_before, repeat).
inline GeneactivDecoder::Unit GeneactivDecoder::parse_page_ggir() {
  using namespace geneactiv;
  Page& pg = *next_;
  if (!ggir_line()) return Unit::none;  // its loop's getline fails
  pg.offset = line_.offset;
  pg.count = 0;
  pg.has_hex = pg.has_light_read = false;
  pg.stamped = false;
  pg.repeat = false;
  pg.overlong = nullptr;
  const bool aligned = !line_.has_end || is_line(line_.p, line_.n, kPageStart);
  settle_line();
  // the eight header lines; `hdr`: the reading of the string std::getline
  // leaves, as it stands (the last line read, "" once the input has ended)
  FieldRead hdr = last_header_read_;
  bool own = false, damaged = false, seq_ok = false, time_ok = false;
  for (int k = 1; k <= kPageHeaderLines; ++k) {
    if (!stream_ended_) {
      own = true;
      if (!ggir_line()) {
        hdr = FieldRead::kept();
      } else {
        const bool whole = !line_.too_long;
        if (k == kTemperatureLine || k == kFrequencyLine || !line_.has_end || !whole) {
          hdr = read_field(line_.p, line_.n + (line_.cr ? 1 : 0), whole);
        }
        const bool field = whole && page_field(k - 1, line_.p, line_.n);
        if (k - 1 == kSequence) seq_ok = field;
        if (k - 1 == kTime) time_ok = field;
        if (!field && line_.has_end) damaged = true;
        settle_line();
      }
    }
    if (k == kTemperatureLine) pg.temp_read = hdr;
    if (k == kFrequencyLine) pg.freq_read = hdr;
    if ((k == kTemperatureLine || k == kFrequencyLine) && hdr.kind == FieldRead::unknown) {
      pg.overlong = "a page header line longer than the decoder reads, whose value GGIRread reads on";
    }
  }
  pg.from_before = !own;
  pg.before_read = last_header_read_;
  last_header_read_ = hdr;
  pg.stamped = seq_ok && time_ok;
  // the hex line
  const char* cut = nullptr;
  if (stream_ended_) {
    pg.repeat = true;  // std::getline leaves the string as it was
    cut = "input ends inside the page's header lines: the page before's samples given again "
          "(none at a block's first page), as GGIRread gives them";
  } else if (ggir_line()) {
    ggir_hex_line(pg);
    settle_line();
  } else {
    cut = "input ends before the page's hex line: no samples";  // the string emptied
  }
  if (cut != nullptr) {
    report_.truncated = true;
    report_.count("truncated_page");
    note_at(cut, pg.offset);
  }
  if (!aligned) {
    report_.count("misaligned_page");
    if (report_.get("misaligned_page") == 1) {
      note_at("page does not start with \"Recorded Data\": lines missing or extra before it, "
              "read ten lines a page as GGIRread reads them", pg.offset);
    }
  }
  if (damaged) {
    report_.count("damaged_page_header");
    note_at("page header line not as the format has it: read as GGIRread reads it", pg.offset);
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

// Whether a double converts to a 64-bit integer (C++ defines no other
// conversion: GGIRread's times of a rate of 0 Hz are NaN or infinite, and
// what its long then holds is the platform's).
inline bool fits_int64(double v) {
  return v >= -9223372036854775808.0 && v < 9223372036854775808.0;
}

// The reference's ms count after a page of `count` samples at `freq`: the
// last sample's time plus one period, truncated. False where the page's
// times are not defined (then neither is the count after it, for the rest
// of the call).
inline bool GeneactivDecoder::advance_chain(double freq, std::size_t count) {
  if (count == 0) return chain_defined_;
  if (!chain_defined_) return false;
  const double inv = 1.0 / freq;
  const double base = static_cast<double>(chain_ms_);
  const double last = ms_after(base, static_cast<double>(count - 1) * inv);
  const double next = ms_after(last, inv);
  const bool defined = fits_int64(ms_after(base, 0.0 * inv)) && fits_int64(last);
  if (!defined || !fits_int64(next)) {
    chain_defined_ = false;
  } else {
    chain_ms_ = static_cast<std::int64_t>(next);
  }
  return defined;
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
  if (rules_.compat) return accept_ggir();
  if (u == Unit::skipped) {
    ++report_.skipped;
    ++pages_seen_;
    return;
  }
  Page& p = *next_;
  check_time();
  if (p.freq != last_good_rate_ && report_.units > 0) {
    if (report_.get("rate_changes") == 0) note_at("measurement frequency changes", p.offset);
    report_.count("rate_changes");
  }
  last_good_rate_ = p.freq;
  ++report_.units;
  ++pages_seen_;
  std::swap(next_, cur_);
  emitted_ = 0;
  pending_ = true;
}

// Consumes the page in next_ as the reference call it falls in reads it
// (compat 1): its temperature and rate where its lines keep the call's,
// the page before's samples where it repeats them (none at the call's
// first page: GGIRread's strings start empty), its place in the call's
// time count.
inline void GeneactivDecoder::accept_ggir() {
  using geneactiv::FieldRead;
  Page& p = *next_;
  const bool first = call_pages_ == 0;
  auto resolve = [&](const FieldRead& own, double& held) {
    const FieldRead& r = !p.from_before ? own : first ? FieldRead::kept() : p.before_read;
    if (r.kind == FieldRead::value) held = r.v;
    return held;
  };
  p.temperature = static_cast<double>(static_cast<float>(resolve(p.temp_read, call_temp_)));
  p.freq = resolve(p.freq_read, call_freq_);
  if (p.repeat) {
    p.count = first ? 0 : cur_->count;
    if (p.count > 0) {
      std::memcpy(p.raw, cur_->raw, p.count * sizeof p.raw[0]);
      p.has_hex = cur_->has_hex;
      p.hex_n = cur_->hex_n;
      if (p.has_hex) std::memcpy(p.hex, cur_->hex, cur_->hex_n);
      p.has_light_read = cur_->has_light_read;
      if (p.has_light_read) std::memcpy(p.light_read, cur_->light_read, p.count * sizeof p.light_read[0]);
    }
  }
  if (p.overlong != nullptr) not_reproduced("ggir_not_reproduced", p.overlong);
  if (p.stamped) check_time();
  if (p.freq != last_good_rate_ && report_.units > 0) {
    if (report_.get("rate_changes") == 0) note_at("measurement frequency changes", p.offset);
    report_.count("rate_changes");
  }
  last_good_rate_ = p.freq;
  block_rate_ = p.freq;
  p.base_ms = chain_ms_;
  p.times_defined = advance_chain(p.freq, p.count);
  if (!p.times_defined) {
    if (report_.get("ggir_time_undefined") == 0) {
      note_at(("page read at " + std::to_string(p.freq) + " Hz: GGIRread's times of its samples "
               "(and of its call's after them) are not defined").c_str(), p.offset);
    }
    report_.count("ggir_time_undefined");
    // (where GGIR resamples the blocks by them: a rate that is not whole)
    if (resampled()) report_.count("ggir_resampled_time_undefined");
  }
  ++call_pages_;
  ++report_.units;
  ++pages_seen_;
  std::swap(next_, cur_);
  emitted_ = 0;
  pending_ = true;
}

// A new reference call (compat 1) from page pages_seen_ + 1: the call
// before's rate checked, the time count and GGIRread's values restarted.
inline void GeneactivDecoder::start_call() {
  check_call_rate();
  block_open_ = true;
  chain_ms_ = 0;
  chain_defined_ = true;
  block_first_ = pages_seen_;
  block_rate_ = last_good_rate_;
  call_temp_ = call_freq_ = 0;
  call_pages_ = 0;
  call_checked_ = false;
  call_rows_ = 0;
  call_timed_ = false;
}

// GGIR takes a call's rate (its last page's: readGENEActiv's SampleRate)
// to decide whether to resample the block, and stops where that rate,
// not whole, rounds to another than the file's: where the rate of a call
// that read pages differs from the file's so that GGIR would resample it
// otherwise than gravcal (which decides by the file's rate), or stop, it
// is counted (ggir_rate_mismatch). A whole rate that differs from a whole
// file rate changes only the call's times (call_end_times()).
inline void GeneactivDecoder::check_call_rate() {
  if (!rules_.compat || !block_open_ || call_pages_ == 0 || call_checked_) return;
  call_checked_ = true;
  const double s = block_rate_, h = header_rate_;
  const bool s_whole = s == std::nearbyint(s), h_whole = h == std::nearbyint(h);
  if (h_whole ? s_whole : s == h) return;
  report_.count("ggir_rate_mismatch");
  if (report_.get("ggir_rate_mismatch") == 1) {
    report_.note("the block of pages " + std::to_string(block_first_ + 1) + " to " +
                 std::to_string(block_first_ + call_pages_) + " ends on a page read at " +
                 std::to_string(s) + " Hz, not the file's " + std::to_string(h) +
                 " Hz: GGIR resamples such a block otherwise, or stops");
  }
}

// readGENEActiv's start of the current call: the recording's start plus
// ((s - 1) * 300) / rate for a call from page s, at the rate of the call's
// last page read so far.
inline double GeneactivDecoder::call_start() const {
  double start = anchor_;
  if (block_first_ > 0) {
    start += static_cast<double>(block_first_ * static_cast<std::int64_t>(geneactiv::kSamplesPerPage)) /
             block_rate_;
  }
  return start;
}

// A row's time from its ms count (raw, s; NaN: not defined) and the call's
// start: their sum, as readGENEActiv adds them; a start that is not finite
// (NA, or infinite: a call ending at 0 Hz) is every row's time whatever its
// count; and no row's time is defined where the call's first one is not
// (readGENEActiv adds it to every row).
inline double GeneactivDecoder::timed(double raw, double start) const {
  if (!std::isfinite(start)) return start;
  if (call_rows_ > 0 && std::isnan(call_first_raw_)) return call_first_raw_;
  return raw + start;
}

inline bool GeneactivDecoder::call_end_times(CallEndTimes& t) const {
  if (!rules_.compat || !call_timed_ || call_rows_ == 0) return false;
  const double start = call_start();
  t.first = timed(call_first_raw_, start);
  t.n_last = call_rows_ >= 2 ? 2 : 1;
  for (int i = 0; i < t.n_last; ++i) t.last[i] = timed(call_tail_raw_[i], start);
  return true;
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
      double v;
      if (!rules_.compat) {
        v = p.time_s + i / p.freq;
      } else if (!p.times_defined) {
        v = std::numeric_limits<double>::quiet_NaN();
      } else {
        // Unix ms as the reference: truncated to an integer, then / 1000
        const double t = ms_after(static_cast<double>(p.base_ms), i * inv);
        v = static_cast<double>(static_cast<std::int64_t>(t)) / 1000;
      }
      out.time[n + j] = v;
      return v;
    };
    if (rules_.compat && k > 0) {
      // the reference call's first row and last two, for call_end_times()
      if (call_rows_ == 0) call_first_raw_ = time_of(0);
      for (std::size_t j = k >= 2 ? k - 2 : 0; j < k; ++j) {
        call_tail_raw_[1] = call_tail_raw_[0];
        call_tail_raw_[0] = time_of(j);
      }
      call_timed_ = true;
    }
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
  if (rules_.compat) call_rows_ += static_cast<std::int64_t>(k);
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
  if (p.has_light_read) {  // compat 1: GGIRread's values of a damaged line
    const double per = light_per();
    for (std::size_t j = 0; j < k; ++j) {
      const int l = p.light_read[from + j];
      light[j] = l < 0 ? static_cast<double>(l) * per : light_lut_[l];
    }
    return;
  }
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

// Lux / Volts, from the header (or the options).
inline double GeneactivDecoder::light_per() const {
  const double lux = light_given_[0] ? light_opt_[0] : light_header_.lux;
  const double volts = light_given_[1] ? light_opt_[1] : light_header_.volts;
  return lux / volts;
}

// Each 10-bit value's light, as readGENEActiv computes it from the header's
// values (or those the options give); a value below 0 (compat 1: a damaged
// line's) is not mapped, only scaled.
inline void GeneactivDecoder::light_table() {
  const bool model11 = light_given_[2] ? light_opt_[2] != 0 : light_header_.model11;
  const double per = light_per();
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
// rate (rate of the call's last page) to its ms count / 1000 (timed()).
// A call read in several reads has its rows timed by the rate of the last
// page read so far; call_end_times() gives its ends as they stand at its
// end.
inline void GeneactivDecoder::finish_block(SampleBuffer& out, std::size_t n0) {
  if (!rules_.compat || out.time == nullptr || out.n == n0) return;
  const double start = call_start();
  if (!out.time_ends_only) {
    for (std::size_t i = n0; i < out.n; ++i) out.time[i] = timed(out.time[i], start);
    return;
  }
  // the rows emit() timed: the first, the last two (each once)
  const std::size_t last = out.n - 1;
  const std::size_t from = std::max(n0, out.n >= 2 ? out.n - 2 : 0);
  if (n0 == 0 && from > 0) out.time[0] = timed(out.time[0], start);
  for (std::size_t i = from; i <= last; ++i) out.time[i] = timed(out.time[i], start);
}

inline void GeneactivDecoder::finish_input() {
  if (done_) return;
  done_ = true;
  check_call_rate();
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
    start_call();  // a new reference call from page pages_seen_ + 1
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
  // the reference call's pages are all read: its rate is known
  if (rules_.compat && max_units >= 0 && units >= max_units) check_call_rate();
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
