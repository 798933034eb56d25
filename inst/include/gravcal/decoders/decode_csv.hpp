// gravcal: decoder for csv files of samples: ActiGraph csv exports
// (ActiLife) and plain csv files with a header line naming the columns.
//
// ActiGraph csv (format "actigraph_csv", or "csv" when the first line names
// ActiGraph): 10 header lines ("------------ Data File Created By ActiGraph
// GT3X+ ActiLife v6.13.4 Firmware v3.2.1 date format M/d/yyyy at 30 Hz
// Filter Normal -----------", "Serial Number: ...", "Start Time HH:MM:SS",
// "Start Date <date in the header's date format>", "Epoch Period
// (hh:mm:ss) ...", ..., a line of dashes), then an optional column-name line,
// then rows [time stamp,] x, y, z in g (more columns in count exports).
// sf from "at N Hz" (else option sf, else the epoch period, else the time
// stamps); time per sample from the time stamp column ("M/d/yyyy
// HH:MM:SS.fff" in the header's date order, or ISO "2017-09-12T15:00:00Z"),
// else start + i / sf with i the data line's index.
//
// Plain csv (format "csv"): a header line naming the columns, in any order
// and case, blanks, dots and underscores ignored: x, y, z (also acc_x,
// accel_x, accelerometer_x, acceleration_x), optionally time (timestamp,
// datetime: numeric seconds since 1970 or date-time text) and temperature
// (temp). sf from option sf, else from time as gravcal's sf_from_time()
// (R/read.R): 1 / median step of the first 100000 time stamps, signif 6; for
// whole-second stamps, samples counted between the first and last change.
//
// Ad hoc csv (format "adhoc_csv", GGIR's rmc.* files): no detection; the
// layout comes in options: skip (lines before the data), col_x, col_y,
// col_z, col_temp, col_time (1-based; 0: none), time_div (1: the time
// column holds seconds, 1000: milliseconds; 0: text, not read: time is
// start_time + i / sf, unless time_format is given: text read by that
// strptime() format (%Y %y %m %d %H %M %S %OS %T and literal characters;
// time_utc_offset seconds subtracted: a zone of fixed offset), for GGIR's
// gap imputation, or time_iso = 1: ISO 8601 text as data.table::fread reads
// it into date-times, less time_utc_offset (csv_text::FreadDateTime; an
// Axivity csv export's text time)), time_offset (seconds added to numeric time), dec
// ("," for decimal commas), sf (required), and the units: acc_div (1000
// for mg), acc_scale, bit (1 unsigned, 2 signed) with bit_pow (2^bitrate)
// and bit_range, temp_unit (1 K, 2 F). Values are converted as GGIR's
// read.myacc.csv converts them, in its order and arithmetic: x / acc_div,
// then * acc_scale, then ((x / bit_pow) - 0.5) * 2 * bit_range (unsigned)
// or (x / (bit_pow / 2)) * bit_range (signed); temperature + 272.15 (K, as
// GGIR) or (t - 32) * (5 / 9) (F). The separator is learnt from the data
// lines (',', ';' or tab).
//
// Unit = one line after the header (and after the column-name line):
// read(out, B) consumes B lines and gives one sample for each good one.
// GGIR (g.readaccfile, 3.3.9) reads an ActiGraph csv as
// fread(skip = s, nrows = B, header = FALSE) with s = 10 (+1 when line 11 is
// a column-name line) and then s + B: successive read(out, B) give the same
// rows. Values equal fread's bit for bit with compat = 1 (its number parser,
// see decode_csv_text.hpp).
//
// Damage: a line that is blank, has too few or too many fields (a
// comma-decimal row), holds no number where a value should be, or is longer
// than 64 KiB is skipped and counted (blank_lines, short_lines, long_lines,
// non_numeric_lines, overlong_lines; the first ones with line numbers and
// byte offsets in the notes); every good line after it is kept. An
// unreadable time stamp keeps its sample with the time one step after the
// last (bad_timestamps); a jump forward in time stamps is a gap (gaps,
// gap_seconds), a step back is counted (time_backwards). A last line
// without line end is kept when it is whole (no_final_line_end), else
// skipped with truncated = true. CRLF, a UTF-8 BOM, blanks around fields and
// double-quoted fields are read as fread reads them. Semicolon-separated
// files (with decimal commas) are read: the separator is the one of ',', ';'
// and tab that splits the first data lines into a constant number of fields.
//
// Where fread (compat = 1) and the format (compat = 0) differ:
// * x, y, z columns: GGIR takes columns 2:4 whenever there are more than 3
//   (so of a count export without time stamps, axis 2, 3 and steps);
//   compat = 0 takes 2:4 only after a time stamp column, else 1:3.
// * line 11: GGIR takes it for a column-name line when its first field is
//   not a number, so a time-stamped export without column names loses its
//   first row (compat = 1 does the same); compat = 0 keeps a line 11 whose
//   first field is a time stamp.
// * numbers: fread's long double value (compat = 1), by the rule of the
//   installed data.table (option "fread_rule": 1 before 1.15.0, 2 from it;
//   see decode_csv_text.hpp), or correctly rounded (compat = 0).
// fread's own behaviour on damage is not reproduced in either mode: it stops
// its block at a malformed line (the rest of the block is lost), skips a
// malformed first line of a block and then reads one row of the next block
// twice, gives a block whose first lines have 2 fields as 2 columns (GGIR
// then ends the recording there), and makes a column with text character
// (GGIR stops with an error). Both modes keep every good line instead and
// keep the block boundaries (B lines per call), so a clean file gives
// exactly GGIR's blocks and a damaged one GGIR's blocks minus the damage.
// Empty fields and "NA" (NA in fread) make a line non-numeric here.
//
// Speed: a line whose fields are all plain numbers ([+-]digits[.digits],
// up to 18 digits) or text the layout does not parse as a number (a time
// stamp) is parsed where it lies in the read buffer, values of 1 to 4
// decimals looked up and a time column of numbers read as the values are
// (read_plain_as, number_stamp); any other line, damaged or unusual, goes
// through take_line() and the general parser. Both give the same samples,
// counters and notes (option fast = 0 takes every line through
// take_line(); tests/cpp/test_csv and the fuzzer compare the two).
#ifndef GRAVCAL_DECODE_CSV_HPP
#define GRAVCAL_DECODE_CSV_HPP

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/decoders/decode_csv_text.hpp"
#include "gravcal/decoders/line_reader.hpp"

namespace gravcal {

class CsvDecoder : public Decoder {
 public:
  static constexpr int kActiGraphHeaderLines = 10;  // ActiLife's, as GGIR counts them
  static constexpr int kMaxFields = 64;             // fields looked at per line
  static constexpr int kLayoutLines = 64;           // data lines that tell the layout
  static constexpr std::size_t kSfLines = 100000;   // time stamps for sf, as sf_from_time()
  static constexpr double kGapSteps = 1.5;          // a step this many sample periods is a gap

  // `format`: "actigraph_csv" (the ActiLife header is required) or "csv"
  // (either kind). Options: compat (1: fread/GGIR, 0: the format),
  // fread_rule (with compat = 1: 1 or 2, data.table's rule for numbers), sf;
  // buffer (bytes of the read buffer, default 1 MiB) and fast (0: every
  // line through take_line(), none parsed in place; the same samples) for
  // tests and fuzzers.
  CsvDecoder(ByteSource& src, const Options& opts, const std::string& format = "csv")
      : lines_(src, buffer_bytes(opts)),
        want_actigraph_(format == "actigraph_csv"),
        rules_(ReadRules::of(opts)) {
    const double fr = opts.num("fread_rule", 1);
    number_rule_ = !rules_.compat ? csv_text::kCorrectlyRounded
                   : fr == 2 ? csv_text::kFreadDivide : csv_text::kFreadMultiply;
    sf_option_ = opts.num("sf", 0);
    fast_ = opts.num("fast", 1) != 0;
    // an Axivity csv export (time stamp, x, y, z) is read by the same layout
    // options (R/formats.R gives them)
    adhoc_ = format == "adhoc_csv" || format == "axivity_csv";
    adhoc_format_ = format;
    if (adhoc_) {
      adhoc_skip_ = static_cast<std::int64_t>(opts.num("skip", 0));
      const double c[5] = {opts.num("col_x", 1), opts.num("col_y", 2), opts.num("col_z", 3),
                           opts.num("col_temp", 0), opts.num("col_time", 0)};
      int* const to[5] = {&col_x_, &col_y_, &col_z_, &col_temp_, &col_time_};
      for (int i = 0; i < 5; ++i) *to[i] = c[i] >= 1 && c[i] <= kMaxFields ? static_cast<int>(c[i]) - 1 : -1;
      time_div_ = opts.num("time_div", 0);
      time_offset_ = opts.num("time_offset", 0);
      time_fmt_ = opts.str("time_format", "");
      time_iso_ = opts.num("time_iso", 0) != 0;
      time_utc_offset_ = opts.num("time_utc_offset", 0);
      zone_ = ZoneTable(opts);
      block_lines_ = static_cast<std::int64_t>(opts.num("block_lines", 0));
      // text time: not read (start_time + i / sf) unless a format is given
      if (!(time_div_ > 0) && time_fmt_.empty() && !time_iso_) col_time_ = -1;
      time_text_ = false;
      info_.start_time = opts.num("start_time", std::numeric_limits<double>::quiet_NaN());
      adhoc_dec_ = opts.str("dec", ".") == "," ? ',' : '.';
      acc_div_ = opts.num("acc_div", 1);
      acc_scale_ = opts.num("acc_scale", 1);
      bit_ = static_cast<int>(opts.num("bit", 0));
      bit_pow_ = opts.num("bit_pow", 1);
      bit_range_ = opts.num("bit_range", 1);
      temp_unit_ = static_cast<int>(opts.num("temp_unit", 0));
    }
  }

  bool open() override {
    if (!(adhoc_ ? open_adhoc() : open_header())) return false;
    info_.has_time = col_time_ >= 0 || (std::isfinite(info_.start_time) && info_.sf > 0);
    info_.has_temperature = col_temp_ >= 0;
    learn_roles();
    opened_ = true;
    done_ = lines_.exhausted();
    return true;
  }

  // the first line: an ActiGraph export's header or a plain csv's names
  bool open_header() {
    Line ln;
    if (!lines_.next(ln)) return fail(lines_.read_failed() ? "the file cannot be read" : "the file is empty");
    std::string first(ln.p, ln.n);
    if (first.compare(0, 3, "\xEF\xBB\xBF") == 0) first.erase(0, 3);  // UTF-8 BOM
    const bool actigraph = contains_nocase(first, "actigraph");
    if (!actigraph && want_actigraph_) {
      return fail("not an ActiGraph csv export: first line is \"" +
                  csv_text::excerpt(first.data(), first.size()) + "\"");
    }
    return actigraph ? open_actigraph(first) : open_plain(first);
  }

  std::int64_t read(SampleBuffer& out, std::int64_t max_units) override {
    if (!opened_) return 0;
    std::int64_t used = 0;
    Line ln;
    while ((max_units < 0 || used < max_units) && !out.full()) {
      // the lines of the common shape where they lie, then one line of
      // another shape (or one that needs more input) line by line
      if (plain_) {
        used += read_plain(out, max_units < 0 ? -1 : max_units - used);
        if ((max_units >= 0 && used >= max_units) || out.full()) break;
      }
      if (!lines_.next(ln)) break;
      ++used;
      ++report_.units;
      take_line(ln, out);
      ++index_;
    }
    done_ = lines_.exhausted();
    if (done_ && lines_.read_failed() && !report_.read_error) {
      report_.read_error = true;
      report_.note("read error at byte " + std::to_string(lines_.offset()) + ": the rest of the file is lost");
    }
    return used;
  }

  bool done() const override { return !opened_ || done_; }
  std::size_t max_samples_per_unit() const override { return 1; }
  // (GgirResamplerOf's interface: a csv read has no state across calls)
  void continue_call(bool) {}

 private:
  static std::size_t buffer_bytes(const Options& opts) {
    const double b = opts.num("buffer", static_cast<double>(LineReader::kBuffer));
    return b >= 1 && b <= static_cast<double>(LineReader::kBuffer)
               ? static_cast<std::size_t>(b) : LineReader::kBuffer;
  }

  // ---- opening -----------------------------------------------------------

  bool fail(const std::string& why) {
    error_ = why;
    return false;
  }

  static bool contains_nocase(const std::string& s, const char* w) {
    const std::size_t n = std::strlen(w);
    for (std::size_t i = 0; i + n <= s.size(); ++i) {
      std::size_t k = 0;
      while (k < n && std::tolower(static_cast<unsigned char>(s[i + k])) == w[k]) ++k;
      if (k == n) return true;
    }
    return false;
  }

  // Text after `key` up to the first comma (ActiLife pads lines with commas).
  static bool value_after(const std::string& line, const char* key, std::string& v) {
    const std::size_t at = line.find(key);
    if (at == std::string::npos) return false;
    std::size_t b = at + std::strlen(key);
    std::size_t e = line.find(',', b);
    if (e == std::string::npos) e = line.size();
    while (b < e && line[b] == ' ') ++b;
    while (e > b && (line[e - 1] == ' ' || line[e - 1] == '\r')) --e;
    v = line.substr(b, e - b);
    return true;
  }

  // "... Created By ActiGraph GT3X+ ActiLife v6 ... date format M/d/yyyy at 30 Hz ..."
  void parse_first_line(const std::string& s) {
    info_.format = "actigraph_csv";
    const std::size_t by = s.find("By ");
    if (by != std::string::npos) {
      const std::size_t end = s.find(" ActiLife", by);
      if (end != std::string::npos) info_.device = s.substr(by + 3, end - by - 3);
    }
    std::string fmt;
    if (value_after(s, "date format ", fmt)) {
      date_format_ = fmt.substr(0, fmt.find(' '));
      dt_.set_order(csv_text::date_order_of(date_format_));
    }
    const std::size_t hz = s.find(" Hz");
    const std::size_t at = s.rfind(" at ", hz);
    if (hz != std::string::npos && at != std::string::npos) {
      double v = 0;
      std::string num = s.substr(at + 4, hz - at - 4);
      std::replace(num.begin(), num.end(), ',', '.');  // as GGIR reads it
      if (csv_text::parse_number(num.data(), num.data() + num.size(), '.', csv_text::kCorrectlyRounded, v) && v > 0) header_sf_ = v;
    }
  }

  void parse_header_line(const std::string& s) {
    std::string v;
    if (value_after(s, "Serial Number:", v)) info_.serial = v;
    if (value_after(s, "Start Time", v)) start_clock_ = v;
    if (value_after(s, "Start Date", v)) start_date_ = v;
    if (value_after(s, "Epoch Period (hh:mm:ss)", v)) {
      const char* p = v.data();
      double secs = 0;
      int fd = 0;
      if (csv_text::parse_clock(p, v.data() + v.size(), secs, fd)) epoch_ = secs;
    }
  }

  // ActiGraph's dynamic range by serial prefix (as GGIR's
  // get_nw_clip_block_params: CLE and NEO 6 g, MOS 8 g).
  void range_from_serial() {
    const std::string p = info_.serial.substr(0, 3);
    if (p == "CLE" || p == "NEO") info_.range_g = 6;
    if (p == "MOS") info_.range_g = 8;
  }

  bool open_actigraph(const std::string& first) {
    parse_first_line(first);
    Line ln;
    for (int i = 2; i <= kActiGraphHeaderLines; ++i) {
      if (!lines_.next(ln) || !ln.has_end) {
        return fail("header truncated at line " + std::to_string(i) + " (byte " +
                    std::to_string(lines_.offset()) + "): an ActiGraph csv has " +
                    std::to_string(kActiGraphHeaderLines) + " header lines");
      }
      parse_header_line(std::string(ln.p, ln.n));
    }
    range_from_serial();
    if (!start_date_.empty() && !start_clock_.empty()) {
      double t = 0;
      int fd = 0;
      const std::string s = start_date_ + " " + start_clock_;
      if (dt_.parse(s.data(), s.data() + s.size(), t, fd)) info_.start_time = t;
    }
    if (!learn_actigraph_layout()) return false;
    return choose_sf(header_sf_ > 0 ? header_sf_ : (epoch_ > 0 ? 1 / epoch_ : 0));
  }

  // Up to kLayoutLines + 1 lines from the bytes buffered ahead, unconsumed.
  std::vector<std::pair<const char*, std::size_t>> peek_lines() {
    std::vector<std::pair<const char*, std::size_t>> v;
    const char* p;
    std::size_t n;
    lines_.peek(p, n);
    const char* e = p + n;
    while (p < e && v.size() <= static_cast<std::size_t>(kLayoutLines)) {
      const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(e - p));
      const char* le = nl != nullptr ? static_cast<const char*>(nl) : e;
      std::size_t len = static_cast<std::size_t>(le - p);
      if (len > 0 && p[len - 1] == '\r') --len;
      v.emplace_back(p, len);
      if (nl == nullptr) break;
      p = le + 1;
    }
    return v;
  }

  // The separator that splits the lines into the same number (>= 3) of
  // fields most often; sets sep_, nfields_, dec_.
  bool learn_separator(const std::vector<std::pair<const char*, std::size_t>>& v, std::size_t from) {
    // ';' and tab first: a semicolon file with decimal commas splits at ','
    // too, but not into a constant number of fields
    const char seps[3] = {';', '\t', ','};
    int best = 0;
    csv_text::Field f[kMaxFields];
    for (char sep : seps) {
      std::vector<int> counts;
      for (std::size_t i = from; i < v.size(); ++i) {
        if (v[i].second > 0) counts.push_back(csv_text::split(v[i].first, v[i].second, sep, f, kMaxFields));
      }
      for (int c : counts) {
        const int agree = static_cast<int>(std::count(counts.begin(), counts.end(), c));
        if (c >= 3 && agree > best) { best = agree; sep_ = sep; nfields_ = c; }
      }
    }
    if (best == 0) return false;
    dec_ = '.';
    if (sep_ != ',') {
      for (std::size_t i = from; i < v.size(); ++i) {
        if (std::memchr(v[i].first, ',', v[i].second) != nullptr) dec_ = ',';
      }
    }
    return true;
  }

  // The bytes buffered ahead are all that is left of the input.
  bool lines_at_end() {
    const char* p;
    std::size_t n;
    lines_.peek(p, n);
    return lines_.input_ended() && (n == 0 || p[n - 1] != '\n');
  }

  bool is_number(const csv_text::Field& f) const {
    double v;
    return csv_text::parse_number(f.b, f.e, dec_, csv_text::kCorrectlyRounded, v);
  }
  bool is_time(const csv_text::Field& f) {
    double t;
    int fd;
    return dt_.parse(f.b, f.e, t, fd);
  }

  // Line 11 (column names or data) and the x, y, z and time columns.
  bool learn_actigraph_layout() {
    const auto v = peek_lines();
    if (v.empty()) return fail("no data lines after the " + std::to_string(kActiGraphHeaderLines) + " header lines");
    const std::size_t from = v.size() > 1 ? 1 : 0;
    if (!learn_separator(v, from)) {
      return fail("data lines do not have 3 fields (x, y, z): line " +
                  std::to_string(lines_.line_number() + 1 + from) + " is \"" +
                  csv_text::excerpt(v[from].first, v[from].second) + "\"" +
                  (from + 1 == v.size() && lines_at_end() ? " (the file ends there)" : ""));
    }
    csv_text::Field f[kMaxFields];
    csv_text::split(v[0].first, v[0].second, sep_, f, kMaxFields);
    bool names = !is_number(f[0]);
    if (!rules_.compat && names && is_time(f[0])) names = false;
    if (names) {
      Line ln;
      lines_.next(ln);
    }
    const std::size_t d = names ? 1 : 0;
    const bool stamped = d < v.size() && csv_text::split(v[d].first, v[d].second, sep_, f, kMaxFields) >= 1 &&
                         is_time(f[0]);
    const int x = rules_.compat ? (nfields_ > 3 ? 1 : 0) : (stamped ? 1 : 0);
    if (x + 3 > nfields_) return fail("data lines have " + std::to_string(nfields_) + " fields, too few for a time stamp, x, y, z");
    col_x_ = x;
    col_time_ = (x == 1 && stamped) ? 0 : -1;
    return true;
  }

  static std::string normal_name(const csv_text::Field& f) {
    std::string s;
    for (const char* p = f.b; p < f.e; ++p) {
      const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(*p)));
      if (c != ' ' && c != '_' && c != '.' && c != '"') s += c;
    }
    return s;
  }

  static int axis_of(const std::string& n) {
    static const char* const stems[] = {"", "acc", "accel", "accelerometer", "acceleration"};
    for (const char* st : stems) {
      for (int a = 0; a < 3; ++a) {
        if (n == std::string(st) + static_cast<char>('x' + a)) return a;
      }
    }
    return -1;
  }

  bool open_plain(const std::string& first) {
    info_.format = "csv";
    int best = 0;
    for (char sep : {',', ';', '\t'}) {
      const int c = static_cast<int>(std::count(first.begin(), first.end(), sep));
      if (c > best) { best = c; sep_ = sep; }
    }
    csv_text::Field f[kMaxFields];
    nfields_ = csv_text::split(first.data(), first.size(), sep_, f, kMaxFields);
    int cols[3] = {-1, -1, -1};
    for (int i = 0; i < std::min(nfields_, kMaxFields); ++i) {
      const std::string n = normal_name(f[i]);
      const int a = axis_of(n);
      if (a >= 0 && cols[a] < 0) cols[a] = i;
      if ((n == "time" || n == "timestamp" || n == "datetime") && col_time_ < 0) col_time_ = i;
      if ((n == "temperature" || n == "temp") && col_temp_ < 0) col_temp_ = i;
    }
    if (cols[0] < 0 || cols[1] < 0 || cols[2] < 0) {
      return fail("not a csv of samples: the first line names no x, y, z columns: \"" +
                  csv_text::excerpt(first.data(), first.size()) + "\"");
    }
    col_x_ = cols[0];
    col_y_ = cols[1];
    col_z_ = cols[2];
    const auto v = peek_lines();
    dec_ = '.';
    if (sep_ != ',') {
      for (const auto& l : v) if (std::memchr(l.first, ',', l.second) != nullptr) dec_ = ',';
    }
    if (col_time_ >= 0 && !v.empty() && csv_text::split(v[0].first, v[0].second, sep_, f, kMaxFields) > col_time_) {
      time_text_ = !is_number(f[col_time_]);
    }
    return choose_sf(0);
  }

  // Ad hoc csv: the lines before the data skipped, the separator learnt
  // from the data lines, the columns as the options give them.
  bool open_adhoc() {
    info_.format = adhoc_format_;
    // the lines before the data as GGIR's reads skip them (fread's count)
    if (lines_.skip_fread_lines(adhoc_skip_) < adhoc_skip_) {
      return fail(lines_.read_failed() ? "the file cannot be read"
                                       : "the file ends before its data (line " +
                                             std::to_string(adhoc_skip_ + 1) + ")");
    }
    const auto v = peek_lines();
    if (v.empty()) return fail("no data lines after line " + std::to_string(adhoc_skip_));
    if (!learn_separator(v, 0)) {
      return fail("data lines do not have 3 fields: line " + std::to_string(adhoc_skip_ + 1) + " is \"" +
                  csv_text::excerpt(v[0].first, v[0].second) + "\"");
    }
    if (adhoc_dec_ == ',' && sep_ == ',') {
      return fail("decimal commas (rmc.dec = \",\") in a file whose fields are separated by commas");
    }
    dec_ = adhoc_dec_;
    const int cols[5] = {col_x_, col_y_, col_z_, col_temp_, col_time_};
    for (int c : cols) {
      if (c >= nfields_) {
        return fail("column " + std::to_string(c + 1) + " asked for, but data lines have " +
                    std::to_string(nfields_) + " fields");
      }
    }
    if (col_x_ < 0 || col_y_ < 0 || col_z_ < 0) return fail("no x, y, z columns given");
    if (!(sf_option_ > 0)) return fail("the sampling rate is unknown: no option sf");
    info_.sf = sf_option_;
    step_ = 1 / info_.sf;
    return true;
  }

  // GGIR's conversions of an ad hoc csv's values (read.myacc.csv's order
  // and arithmetic; see the top of this file).
  GRAVCAL_CSV_INLINE double adhoc_acc(double a) const {
    if (acc_div_ != 1) a = a / acc_div_;
    if (acc_scale_ != 1) a = a * acc_scale_;
    if (bit_ == 1) {
      a = ((a / bit_pow_) - 0.5) * 2 * bit_range_;
    } else if (bit_ == 2) {
      a = (a / (bit_pow_ / 2)) * bit_range_;
    }
    return a;
  }
  GRAVCAL_CSV_INLINE double adhoc_temp(double t) const {
    if (temp_unit_ == 1) return t + 272.15;
    if (temp_unit_ == 2) return (t - 32) * (5.0 / 9.0);
    return t;
  }

  // sf: option sf, else the header's, else from the time stamps.
  bool choose_sf(double from_header) {
    if (col_x_ >= 0 && col_y_ < 0) {
      col_y_ = col_x_ + 1;
      col_z_ = col_x_ + 2;
    }
    double sf = sf_option_ > 0 ? sf_option_ : from_header;
    if (!(sf > 0) && col_time_ >= 0) sf = sf_from_time();
    if (!(sf > 0)) {
      return fail(info_.format == "csv" ? "the sampling rate is unknown: no time column and no option sf"
                                        : "no sampling rate in the header (\"at N Hz\") and no option sf");
    }
    info_.sf = sf;
    step_ = 1 / sf;
    return true;
  }

  bool time_of(const csv_text::Field& f, double& t, int& frac_digits) {
    if (adhoc_ && time_iso_) {
      // as fread reads it, less a fixed offset (a zone GGIR forces it into)
      frac_digits = 9;
      if (!iso_.parse(f.b, f.e, number_rule_, t)) return false;
      if (time_utc_offset_ != 0) t = t - time_utc_offset_;
      return true;
    }
    if (adhoc_ && !time_fmt_.empty()) {
      frac_digits = 9;  // taken as it is (no spreading of coarse stamps)
      return parse_formatted(f.b, f.e, t);
    }
    if (!time_text_) {
      frac_digits = 9;
      // the common shape (digits, a point, digits) by the plain scan, which
      // gives parse_number's value; any other shape by parse_number (the
      // field lies in a line, so a byte that ends the scan follows it)
      csv_text::PlainNumber pn;
      const char* e = csv_text::scan_plain_number(f.b, dec_, pn);
      if (e == f.e && f.b < f.e) {
        if (!csv_text::plain_value(pn, f.b, e, dec_, number_rule_, t)) return false;
      } else if (!csv_text::parse_number(f.b, f.e, dec_, number_rule_, t)) {
        return false;
      }
      if (adhoc_) {
        // (t / 1 is t: the division only for milliseconds and days)
        if (time_div_ != 1) t = t / time_div_;
        t = t + time_offset_;
      }
      return true;
    }
    return dt_.parse(f.b, f.e, t, frac_digits);
  }

  // A text time stamp by time_fmt_, as R's strptime() reads it (the
  // directives listed at the top; blanks in the format match any blanks;
  // text after the format ignored), in seconds since 1970 less
  // time_utc_offset_: R's as.POSIXct() in a zone of that fixed offset
  // (whole seconds plus the fraction of %OS).
  bool parse_formatted(const char* p, const char* e, double& t) const {
    int year = 1970, mon = 1, day = 1, hour = 0, min = 0;
    double sec = 0;
    auto num = [&](int width, int& v) {
      while (p < e && *p == ' ') ++p;
      int k = 0;
      v = 0;
      while (k < width && p < e && *p >= '0' && *p <= '9') v = 10 * v + (*p++ - '0'), ++k;
      return k > 0;
    };
    auto secs = [&](bool fraction) {
      while (p < e && *p == ' ') ++p;
      long double a = 0;
      int k = 0, dec = 0;
      while (p < e && *p >= '0' && *p <= '9' && (fraction || k < 2)) a = 10 * a + (*p++ - '0'), ++k;
      if (k == 0) return false;
      if (fraction && p < e && *p == '.') {
        for (++p; p < e && *p >= '0' && *p <= '9'; ++p, ++dec) a = 10 * a + (*p - '0');
      }
      long double f = 1;
      for (int i = 0; i < dec; ++i) f *= 10;
      sec = static_cast<double>(a / f);
      return sec >= 0 && sec <= 61;
    };
    const std::string& f = time_fmt_;
    for (std::size_t i = 0; i < f.size();) {
      const char c = f[i];
      if (c == '%') {
        if (++i >= f.size()) return false;
        const char d = f[i++];
        bool ok = true;
        int y2 = 0;
        switch (d) {
          case 'Y': ok = num(4, year); break;
          case 'y':
            ok = num(2, y2);
            year = y2 < 69 ? 2000 + y2 : 1900 + y2;
            break;
          case 'm': ok = num(2, mon); break;
          case 'd': ok = num(2, day); break;
          case 'H': ok = num(2, hour); break;
          case 'M': ok = num(2, min); break;
          case 'S': ok = secs(false); break;
          case 'T':
            ok = num(2, hour) && p < e && *p++ == ':' && num(2, min) && p < e && *p++ == ':' &&
                 secs(false);
            break;
          case 'O':
            if (i >= f.size() || f[i] != 'S') return false;
            ++i;
            while (i < f.size() && f[i] >= '0' && f[i] <= '9') ++i;
            ok = secs(true);
            break;
          case '%': ok = p < e && *p++ == '%'; break;
          default: return false;
        }
        if (!ok) return false;
      } else if (c == ' ' || c == '\t') {
        ++i;
        while (p < e && (*p == ' ' || *p == '\t')) ++p;
      } else {
        if (p >= e || *p != c) return false;
        ++p;
        ++i;
      }
    }
    static const int kDays[12] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    if (mon < 1 || mon > 12 || day < 1 || day > kDays[mon - 1] || hour > 24 || min > 59) return false;
    const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    if (mon == 2 && day == 29 && !leap) return false;
    // days since 1970-01-01 of the civil date (H. Hinnant's algorithm)
    const int y = mon <= 2 ? year - 1 : year;
    const int era = (y >= 0 ? y : y - 399) / 400;
    const int yoe = y - era * 400;
    const int doy = (153 * (mon + (mon > 2 ? -3 : 9)) + 2) / 5 + day - 1;
    const int doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    const double days = static_cast<double>(era) * 146097 + doe - 719468;
    const double whole = std::floor(sec);
    // the calendar read as UTC, less the zone's offset (whole seconds: exact)
    const double cal = days * 86400 + hour * 3600.0 + min * 60.0 + whole;
    const double base = cal - (zone_.empty() ? time_utc_offset_ : zone_.offset(cal));
    last_cal_ = cal;
    t = base + (sec - whole);
    return true;
  }

  // As sf_from_time() in R/read.R, on the first kSfLines time stamps; reads
  // them ahead and starts again (0 when they do not tell, or the source
  // cannot start again).
  double sf_from_time() {
    const std::int64_t pos = lines_.offset(), line = lines_.line_number();
    std::vector<double> t;
    t.reserve(std::min<std::size_t>(kSfLines, 4096));
    Line ln;
    csv_text::Field f[kMaxFields];
    while (t.size() < kSfLines && lines_.next(ln)) {
      if (ln.too_long || csv_text::split(ln.p, ln.n, sep_, f, kMaxFields) != nfields_) continue;
      double v;
      int fd;
      if (time_of(f[col_time_], v, fd)) t.push_back(v);
    }
    if (!lines_.rewind(pos, line)) return 0;
    if (t.size() < 2) return 0;
    std::vector<double> d(t.size() - 1);
    for (std::size_t i = 0; i + 1 < t.size(); ++i) d[i] = t[i + 1] - t[i];
    const double step = median(d);
    if (std::isfinite(step) && step > 0) return csv_text::signif(1 / step, 6);
    std::size_t first = 0, last = 0, k = 0;
    for (std::size_t i = 0; i + 1 < t.size(); ++i) {
      if (t[i + 1] - t[i] > 0) { if (k++ == 0) first = i; last = i; }
    }
    if (k < 2) return 0;
    const double sf = static_cast<double>(last - first) / (t[last + 1] - t[first + 1]);
    return std::isfinite(sf) && sf > 0 ? csv_text::signif(sf, 6) : 0;
  }

  // R's median: the mean of the two middle values of an even count.
  static double median(std::vector<double> d) {
    const std::size_t n = d.size(), h = n / 2;
    std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(h), d.end());
    const double hi = d[h];
    if (n % 2 == 1) return hi;
    const double lo = *std::max_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(h));
    return (lo + hi) / 2;
  }

  // ---- data lines -----------------------------------------------------------

  // What each field of a data line is for: kTime a time stamp read by
  // time_of(), kTimeNumber one that is a number (read as the values are).
  enum Role : unsigned char { kSkip, kX, kY, kZ, kTemp, kTime, kTimeNumber };

  // The role of each field; lines are parsed in place when every field has
  // one column at most (plain_ = 2 when the fields are x, y, z and no
  // more, the commonest layout, which has a loop of its own).
  void learn_roles() {
    plain_ = 0;
    if (!fast_ || nfields_ < 3 || nfields_ > kMaxFields) return;
    std::fill(role_, role_ + kMaxFields, kSkip);
    const int cols[5] = {col_x_, col_y_, col_z_, col_temp_, col_time_};
    const Role roles[5] = {kX, kY, kZ, kTemp, kTime};
    for (int i = 0; i < 5; ++i) {
      if (cols[i] < 0) continue;
      if (cols[i] >= nfields_ || role_[cols[i]] != kSkip) return;
      role_[cols[i]] = roles[i];
    }
    if (col_x_ < 0 || col_y_ < 0 || col_z_ < 0) return;
    // numeric time (time_of()'s plain number) is parsed in place too
    number_time_ = col_time_ >= 0 && !time_text_ && !(adhoc_ && (!time_fmt_.empty() || time_iso_)) &&
                   zone_.empty();
    if (number_time_) role_[col_time_] = kTimeNumber;
    plain_ = nfields_ == 3 && role_[0] == kX && role_[1] == kY && role_[2] == kZ ? 2 : 1;
    decimals_ = &csv_text::decimals(number_rule_);
  }

  std::int64_t read_plain(SampleBuffer& out, std::int64_t max_lines) {
    return plain_ == 2 ? read_plain_as<true>(out, max_lines) : read_plain_as<false>(out, max_lines);
  }

  // Lines parsed where they lie in the read buffer, up to the first that
  // is not of the common shape (or `max_lines`, or a full `out`); returns
  // the lines taken. Each gives what take_line() gives for it.
  template <bool kXyz>
  std::int64_t read_plain_as(SampleBuffer& out, std::int64_t max_lines) {
    const char* p0;
    const std::size_t n = lines_.whole_lines(p0);
    if (n == 0) return 0;
    const char* const end = p0 + n;
    const std::size_t first = out.n;
    const std::size_t most = max_lines >= 0 && static_cast<std::size_t>(max_lines) < out.room()
                                 ? static_cast<std::size_t>(max_lines) : out.room();
    const std::size_t last = first + most;
    const std::int64_t line0 = lines_.line_number(), offset0 = lines_.offset();
    double* const x = out.x;
    double* const y = out.y;
    double* const z = out.z;
    double* const temp = out.t;
    double* const time = out.time;
    const char* q = p0;
    std::size_t i = first;
    for (; i < last && q < end; ++i) {
      double v[kTimeNumber + 1];  // by role
      csv_text::Field tf{q, q};
      const char* nl = kXyz ? xyz_fields(q, v) : plain_fields(q, v, tf);
      if (nl == nullptr) break;
      double t = 0;
      if (!kXyz && number_time_) {
        t = number_stamp(v[kTimeNumber], line0 + static_cast<std::int64_t>(i - first) + 1, offset0 + (q - p0));
      } else if (!kXyz && col_time_ >= 0) {
        Line ln;
        ln.number = line0 + static_cast<std::int64_t>(i - first) + 1;
        ln.offset = offset0 + (q - p0);
        t = stamp_time(tf, ln);
      } else if (time != nullptr) {
        t = info_.start_time + static_cast<double>(index_ + static_cast<std::int64_t>(i - first)) / info_.sf;
      }
      if (adhoc_) {
        v[kX] = adhoc_acc(v[kX]);
        v[kY] = adhoc_acc(v[kY]);
        v[kZ] = adhoc_acc(v[kZ]);
        if (!kXyz) v[kTemp] = adhoc_temp(v[kTemp]);
      }
      x[i] = v[kX];
      y[i] = v[kY];
      z[i] = v[kZ];
      if (temp != nullptr) temp[i] = kXyz ? std::numeric_limits<double>::quiet_NaN() : v[kTemp];
      if (time != nullptr) time[i] = t;
      q = nl + 1;
    }
    const std::int64_t k = static_cast<std::int64_t>(i - first);
    out.n = i;
    lines_.consume(static_cast<std::size_t>(q - p0), k);
    report_.units += k;
    report_.samples += k;
    index_ += k;
    return k;
  }

  // stamp_time() of a time stamp that is a plain number, given its value as
  // read in place (line `number`, at byte `offset`): time_of()'s
  // conversion, and the checks with its resolution (time_of() gives 9
  // decimals: res 0, never coarse).
  GRAVCAL_CSV_INLINE double number_stamp(double s, std::int64_t number, std::int64_t offset) {
    if (adhoc_) {
      if (time_div_ != 1) s = s / time_div_;
      s = s + time_offset_;
    }
    if (s == last_stamp_) ++run_;
    else run_ = 0;
    last_stamp_ = s;
    if (std::isfinite(last_time_)) {
      const double dt = s - last_time_;
      if (dt > kGapSteps * step_ + 0.0 || dt < -(step_ / 2 + 0.0)) {
        Line ln;
        ln.number = number;
        ln.offset = offset;
        check_step(dt, 0, ln);
      }
    }
    last_time_ = s;
    return s;
  }

  // The value of the plain number (csv_text::scan_plain_number) at p when
  // the byte after it is `a` or `b` (the field ends there); returns that
  // byte's address, or nullptr.
  GRAVCAL_CSV_INLINE const char* plain_number(const char* p, char a, char b, double& v) const {
    csv_text::PlainNumber pn;
    const char* e = csv_text::scan_plain_number(p, dec_, pn);
    if (e == nullptr || (*e != a && *e != b)) return nullptr;
    if (pn.frac >= 1 && pn.frac <= csv_text::kTableDecimals && pn.acc < decimals_->limit[pn.frac]) {
      // a look-up instead of a long double product or a division; the sign
      // by a product with -1: exact, and -(+0) is -0, as above
      static constexpr double kSign[2] = {1.0, -1.0};
      v = decimals_->value[pn.frac][pn.acc] * kSign[pn.neg];
      return e;
    }
    return csv_text::plain_value(pn, p, e, dec_, number_rule_, v) ? e : nullptr;
  }

  // The fields of the data line at q (whole, ending in '\n') when they are
  // all of the common shape: every value a plain number that fills its
  // field, nfields_ fields. Puts the values in v (by role) and the time
  // field in tf, and returns the line's '\n'; nullptr for any other line
  // (take_line() decides).
  const char* plain_fields(const char* q, double* v, csv_text::Field& tf) const {
    v[kTemp] = std::numeric_limits<double>::quiet_NaN();
    const char* p = q;
    for (int i = 0; i < nfields_; ++i) {
      const Role r = static_cast<Role>(role_[i]);
      const bool last = i + 1 == nfields_;
      if (r == kSkip || r == kTime) {
        const char* fe = csv_text::field_end(p, sep_);
        if (r == kTime) tf = csv_text::Field{p, fe};
        p = fe;
      } else {
        p = last ? plain_number(p, '\n', '\r', v[r]) : plain_number(p, sep_, sep_, v[r]);
        if (p == nullptr) return nullptr;
      }
      if (!last) {
        if (*p != sep_) return nullptr;
        ++p;
      }
    }
    if (*p == '\r') {
      ++p;
    } else if (role_[nfields_ - 1] == kTime && p[-1] == '\r') {
      tf.e = p - 1;  // CRLF: the line ends before the '\r'
    }
    if (*p != '\n') return nullptr;
    if (col_time_ >= 0 && !number_time_) tf = csv_text::field_of(tf.b, tf.e);
    return p;
  }

  // The same for the fields x, y, z.
  GRAVCAL_CSV_INLINE const char* xyz_fields(const char* q, double* v) const {
    const char* p = plain_number(q, sep_, sep_, v[kX]);
    if (p == nullptr) return nullptr;
    p = plain_number(p + 1, sep_, sep_, v[kY]);
    if (p == nullptr) return nullptr;
    p = plain_number(p + 1, '\n', '\r', v[kZ]);
    if (p == nullptr) return nullptr;
    if (*p == '\r') ++p;
    return *p == '\n' ? p : nullptr;
  }

  void skip_line(const Line& ln, const char* kind, const char* what) {
    ++report_.skipped;
    const char* counter = kind;
    if (!ln.has_end) {
      report_.truncated = true;
      counter = "truncated_lines";
    }
    report_.count(counter);
    report_.note("line " + std::to_string(ln.number) + " (byte " + std::to_string(ln.offset) + "): " +
                 (ln.has_end ? what : "the file ends inside this line") + ": \"" +
                 csv_text::excerpt(ln.p, ln.n) + "\"");
  }

  static bool blank(const Line& ln) {
    for (std::size_t i = 0; i < ln.n; ++i) {
      if (ln.p[i] != ' ' && ln.p[i] != '\t') return false;
    }
    return true;
  }

  void take_line(const Line& ln, SampleBuffer& out) {
    if (ln.too_long) return skip_line(ln, "overlong_lines", "longer than 64 KiB");
    if (blank(ln)) return skip_line(ln, "blank_lines", "blank line");
    csv_text::Field f[kMaxFields];
    const int nf = csv_text::split(ln.p, ln.n, sep_, f, kMaxFields);
    if (nf < nfields_) return skip_line(ln, "short_lines", "too few fields");
    if (nf > nfields_) return skip_line(ln, "long_lines", "too many fields");
    double x, y, z, temp = std::numeric_limits<double>::quiet_NaN();
    if (!csv_text::parse_number(f[col_x_].b, f[col_x_].e, dec_, number_rule_, x) ||
        !csv_text::parse_number(f[col_y_].b, f[col_y_].e, dec_, number_rule_, y) ||
        !csv_text::parse_number(f[col_z_].b, f[col_z_].e, dec_, number_rule_, z) ||
        (col_temp_ >= 0 && !csv_text::parse_number(f[col_temp_].b, f[col_temp_].e, dec_, number_rule_, temp))) {
      return skip_line(ln, "non_numeric_lines", "a value is not a number");
    }
    if (!ln.has_end) {
      report_.count("no_final_line_end");
      report_.note("line " + std::to_string(ln.number) + " (byte " + std::to_string(ln.offset) +
                   "): the last line has no line end; kept");
    }
    const double t = col_time_ >= 0 ? stamp_time(f[col_time_], ln) : info_.start_time + static_cast<double>(index_) / info_.sf;
    if (adhoc_) {
      x = adhoc_acc(x);
      y = adhoc_acc(y);
      z = adhoc_acc(z);
      temp = adhoc_temp(temp);
    }
    out.put(x, y, z, temp, t);
    ++report_.samples;
  }

  // The time of a stamped line: its stamp (plus k / sf for the k-th line of
  // a stamp coarser than a sample period), checked against the last one.
  double stamp_time(const csv_text::Field& f, const Line& ln) {
    double s;
    int fd = 0;
    const bool ok = time_of(f, s, fd);
    // the first line of one of GGIR's blocks (block_lines lines from the
    // first data line): where its text time exists twice or not at all in
    // the zone, R's conversion of it depends on conversions before it
    if (ok && !zone_.empty() && block_lines_ > 0 && ln.number > adhoc_skip_ &&
        (ln.number - 1 - adhoc_skip_) % block_lines_ == 0 && zone_.ambiguous(last_cal_)) {
      report_.count("zone_ambiguous");
      report_.note("line " + std::to_string(ln.number) + ": its time exists twice or not at all in "
                   "GGIR's zone and starts a block of GGIR's reading");
    }
    if (!ok) {
      report_.count("bad_timestamps");
      report_.note("line " + std::to_string(ln.number) + " (byte " + std::to_string(ln.offset) +
                   "): unreadable time stamp; time from the line before");
      last_time_ += step_;
      return last_time_;
    }
    static const double kRes[10] = {1, 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 0};
    const double res = kRes[fd < 9 ? fd : 9];
    if (s == last_stamp_) ++run_;
    else run_ = 0;
    last_stamp_ = s;
    const bool coarse = res > kGapSteps * step_;
    const double t = coarse ? s + static_cast<double>(run_) * step_ : s;
    if (std::isfinite(last_time_)) check_step(t - last_time_, coarse ? 0 : res, ln);
    last_time_ = t;
    return t;
  }

  void check_step(double dt, double res, const Line& ln) {
    if (dt > kGapSteps * step_ + res) {
      gap(dt, ln);
    } else if (dt < -(step_ / 2 + res)) {
      backwards(dt, ln);
    }
  }
  // (the rare cases out of line: check_step() stays small enough to inline)
#if defined(__GNUC__)
  __attribute__((noinline))
#endif
  void gap(double dt, const Line& ln) {
    ++report_.gaps;
    report_.gap_seconds += dt - step_;
    report_.note("line " + std::to_string(ln.number) + " (byte " + std::to_string(ln.offset) +
                 "): time jumps " + std::to_string(dt) + " s");
  }
#if defined(__GNUC__)
  __attribute__((noinline))
#endif
  void backwards(double dt, const Line& ln) {
    report_.count("time_backwards");
    report_.note("line " + std::to_string(ln.number) + " (byte " + std::to_string(ln.offset) +
                 "): time goes back " + std::to_string(-dt) + " s");
  }

  LineReader lines_;
  csv_text::DateTimeParser dt_;
  bool want_actigraph_;
  // the reading rules (compat, interpolation, resample_fused), read once
  const ReadRules rules_;
  int number_rule_ = csv_text::kFreadMultiply;  // a csv_text::NumberRule
  bool fast_ = true;
  double sf_option_ = 0;
  bool opened_ = false, done_ = false;
  // header
  double header_sf_ = 0, epoch_ = 0;
  std::string date_format_, start_date_, start_clock_;
  // layout
  char sep_ = ',', dec_ = '.';
  int nfields_ = 0;
  int col_x_ = -1, col_y_ = -1, col_z_ = -1, col_time_ = -1, col_temp_ = -1;
  bool time_text_ = true;
  double step_ = 0;
  const csv_text::Decimals* decimals_ = nullptr;  // csv_text::decimals(number_rule_)
  unsigned char role_[kMaxFields] = {};  // a Role for each field
  int plain_ = 0;  // lines parsed in place: 0 no, 1 yes, 2 yes and they are x, y, z
  bool number_time_ = false;  // with a time column of numbers (role kTimeNumber)
  // position
  std::int64_t index_ = 0;  // data lines consumed
  double last_time_ = std::numeric_limits<double>::quiet_NaN();
  double last_stamp_ = std::numeric_limits<double>::quiet_NaN();
  std::int64_t run_ = 0;
  // ad hoc csv (format "adhoc_csv"): its layout and units, from options
  bool adhoc_ = false;
  std::string adhoc_format_;
  std::int64_t adhoc_skip_ = 0;
  char adhoc_dec_ = '.';
  double time_div_ = 0, time_offset_ = 0;
  std::string time_fmt_;  // text time stamps' strptime() format ("": not read)
  bool time_iso_ = false;  // text time stamps read as fread reads ISO 8601 date-times
  csv_text::FreadDateTime iso_;
  double time_utc_offset_ = 0;
  ZoneTable zone_;  // a zone whose offset changes (options tz_*), else time_utc_offset_
  std::int64_t block_lines_ = 0;  // lines in one of GGIR's blocks (option block_lines)
  mutable double last_cal_ = 0;   // the last text time read, as its calendar read as UTC
  double acc_div_ = 1, acc_scale_ = 1, bit_pow_ = 1, bit_range_ = 1;
  int bit_ = 0, temp_unit_ = 0;
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_CSV_HPP
