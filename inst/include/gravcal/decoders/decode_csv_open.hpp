// gravcal: the opening of a csv file of samples (the csv decoder,
// decode_csv.hpp, is built from this): its header read and the layout of its
// data lines learnt, before any data line is taken.
//
// CsvOpener reads what comes before the data and looks ahead at the first
// data lines without consuming them:
// * an ActiGraph csv export: the 10 header lines (device, serial number,
//   start date and time, "at N Hz", the epoch period), then line 11, which
//   is a column-name line or the first data line, and whether the data
//   lines start with a time stamp;
// * a plain csv: the line of column names, which says where x, y, z, time
//   and temperature are;
// * an ad hoc csv (or an Axivity csv export): `skip` lines skipped, the
//   columns as the options give them.
// It learns the separator (',', ';' or tab) and the decimal mark, fills in
// the decoder's CsvLayout and DeviceInfo, and chooses the sampling rate:
// option sf, else the header's, else from the time stamps (as gravcal's
// sf_from_time() in R/read.R). The top of decode_csv.hpp describes the
// formats and where the compat modes differ.
#ifndef GRAVCAL_DECODE_CSV_OPEN_HPP
#define GRAVCAL_DECODE_CSV_OPEN_HPP

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/decoders/decode_csv_text.hpp"
#include "gravcal/decoders/decode_csv_time.hpp"
#include "gravcal/decoders/line_reader.hpp"

namespace gravcal {

class CsvOpener {
 public:
  static constexpr int kActiGraphHeaderLines = 10;  // ActiLife's, as GGIR counts them
  static constexpr int kMaxFields = CsvLayout::kMaxFields;
  static constexpr int kLayoutLines = 64;           // data lines that tell the layout
  static constexpr std::size_t kSfLines = 100000;   // time stamps for sf, as sf_from_time()

  // The decoder's line reader, time stamps (their date-time reader, and
  // time_of() for sf from the time stamps), layout, device information and
  // error message, all of which must outlive this. `format`: "actigraph_csv"
  // (the ActiLife header is required), "csv" (either kind), "adhoc_csv" or
  // "axivity_csv". Options: sf; for an ad hoc csv skip and dec. `compat`:
  // read line 11 and the columns as GGIR does (see decode_csv.hpp).
  CsvOpener(LineReader& lines, CsvTimeStamps& times, CsvLayout& layout, DeviceInfo& info,
            std::string& error, const Options& opts, const std::string& format, bool compat)
      : lines_(lines), times_(times), dt_(times.date_times()), layout_(layout), info_(info),
        error_(error), want_actigraph_(format == "actigraph_csv"), compat_(compat) {
    sf_option_ = opts.num("sf", 0);
    opts_counts_ = opts.num("counts", 0);
    // an Axivity csv export (time stamp, x, y, z) is read by the same layout
    // options (R/formats.R gives them)
    adhoc_ = format == "adhoc_csv" || format == "axivity_csv";
    adhoc_format_ = format;
    if (adhoc_) {
      adhoc_skip_ = static_cast<std::int64_t>(opts.num("skip", 0));
      adhoc_dec_ = opts.str("dec", ".") == "," ? ',' : '.';
    }
  }

  // Reads the header and learns the layout; false (with the reason in the
  // error message) when the file is not a csv of samples this can read.
  bool open() { return adhoc_ ? open_adhoc() : open_header(); }

 private:
  bool fail(const std::string& why) {
    error_ = why;
    return false;
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
      if (csv_text::parse_clock(p, v.data() + v.size(), secs, fd)) {
        epoch_ = secs;
        epoch_clock_ = v;
      }
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
    // An ActiLife epoch export: counts per epoch, not samples in g (GGIR's
    // g.inspectfile() stops on it, wanting "at N Hz"). Refused unless the
    // option `counts` asks for the values as they are (its tests read GGIR's
    // own count files as GGIR's reader does).
    if (epoch_ > 0 && !(header_sf_ > 0) && !(opts_counts_ > 0)) {
      return fail("an ActiLife epoch export (\"Epoch Period (hh:mm:ss) " + epoch_clock_ +
                  "\" and no \"at N Hz\" in the first line): counts per epoch, not samples in g; "
                  "export the raw samples instead (ActiLife's raw csv, or the .gt3x file)");
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
  // fields most often; sets layout_.sep, layout_.nfields, layout_.dec.
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
        if (c >= 3 && agree > best) { best = agree; layout_.sep = sep; layout_.nfields = c; }
      }
    }
    if (best == 0) return false;
    layout_.dec = '.';
    if (layout_.sep != ',') {
      for (std::size_t i = from; i < v.size(); ++i) {
        if (std::memchr(v[i].first, ',', v[i].second) != nullptr) layout_.dec = ',';
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
    return csv_text::parse_number(f.b, f.e, layout_.dec, csv_text::kCorrectlyRounded, v);
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
    csv_text::split(v[0].first, v[0].second, layout_.sep, f, kMaxFields);
    bool names = !is_number(f[0]);
    if (!compat_ && names && is_time(f[0])) names = false;
    if (names) {
      Line ln;
      lines_.next(ln);
    }
    const std::size_t d = names ? 1 : 0;
    const bool stamped = d < v.size() &&
                         csv_text::split(v[d].first, v[d].second, layout_.sep, f, kMaxFields) >= 1 &&
                         is_time(f[0]);
    const int x = compat_ ? (layout_.nfields > 3 ? 1 : 0) : (stamped ? 1 : 0);
    if (x + 3 > layout_.nfields) {
      return fail("data lines have " + std::to_string(layout_.nfields) +
                  " fields, too few for a time stamp, x, y, z");
    }
    layout_.col_x = x;
    layout_.col_time = (x == 1 && stamped) ? 0 : -1;
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
      if (c > best) { best = c; layout_.sep = sep; }
    }
    csv_text::Field f[kMaxFields];
    layout_.nfields = csv_text::split(first.data(), first.size(), layout_.sep, f, kMaxFields);
    int cols[3] = {-1, -1, -1};
    for (int i = 0; i < std::min(layout_.nfields, kMaxFields); ++i) {
      const std::string n = normal_name(f[i]);
      const int a = axis_of(n);
      if (a >= 0 && cols[a] < 0) cols[a] = i;
      if ((n == "time" || n == "timestamp" || n == "datetime") && layout_.col_time < 0) {
        layout_.col_time = i;
      }
      if ((n == "temperature" || n == "temp") && layout_.col_temp < 0) layout_.col_temp = i;
    }
    if (cols[0] < 0 || cols[1] < 0 || cols[2] < 0) {
      return fail("not a csv of samples: the first line names no x, y, z columns: \"" +
                  csv_text::excerpt(first.data(), first.size()) + "\"");
    }
    layout_.col_x = cols[0];
    layout_.col_y = cols[1];
    layout_.col_z = cols[2];
    const auto v = peek_lines();
    layout_.dec = '.';
    if (layout_.sep != ',') {
      for (const auto& l : v) if (std::memchr(l.first, ',', l.second) != nullptr) layout_.dec = ',';
    }
    if (layout_.col_time >= 0 && !v.empty() &&
        csv_text::split(v[0].first, v[0].second, layout_.sep, f, kMaxFields) > layout_.col_time) {
      layout_.time_text = !is_number(f[layout_.col_time]);
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
    if (adhoc_dec_ == ',' && layout_.sep == ',') {
      return fail("decimal commas (rmc.dec = \",\") in a file whose fields are separated by commas");
    }
    layout_.dec = adhoc_dec_;
    const int cols[6] = {layout_.col_x, layout_.col_y, layout_.col_z, layout_.col_temp, layout_.col_time,
                         layout_.col_wear};
    for (int c : cols) {
      if (c >= layout_.nfields) {
        return fail("column " + std::to_string(c + 1) + " asked for, but data lines have " +
                    std::to_string(layout_.nfields) + " fields");
      }
    }
    if (layout_.col_x < 0 || layout_.col_y < 0 || layout_.col_z < 0) return fail("no x, y, z columns given");
    if (!(sf_option_ > 0)) return fail("the sampling rate is unknown: no option sf");
    info_.sf = sf_option_;
    layout_.step = 1 / info_.sf;
    return true;
  }

  // sf: option sf, else the header's, else from the time stamps.
  bool choose_sf(double from_header) {
    if (layout_.col_x >= 0 && layout_.col_y < 0) {
      layout_.col_y = layout_.col_x + 1;
      layout_.col_z = layout_.col_x + 2;
    }
    double sf = sf_option_ > 0 ? sf_option_ : from_header;
    if (!(sf > 0) && layout_.col_time >= 0) sf = sf_from_time();
    if (!(sf > 0)) {
      return fail(info_.format == "csv" ? "the sampling rate is unknown: no time column and no option sf"
                                        : "no sampling rate in the header (\"at N Hz\") and no option sf");
    }
    info_.sf = sf;
    layout_.step = 1 / sf;
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
      if (ln.too_long || csv_text::split(ln.p, ln.n, layout_.sep, f, kMaxFields) != layout_.nfields) {
        continue;
      }
      double v;
      int fd;
      if (times_.time_of(f[layout_.col_time], v, fd)) t.push_back(v);
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

  LineReader& lines_;
  CsvTimeStamps& times_;
  csv_text::DateTimeParser& dt_;  // times_'s
  CsvLayout& layout_;
  DeviceInfo& info_;
  std::string& error_;
  bool want_actigraph_;
  bool compat_;
  double sf_option_ = 0;
  // header
  double header_sf_ = 0, epoch_ = 0, opts_counts_ = 0;
  std::string epoch_clock_;  // the header's epoch period as written
  std::string date_format_, start_date_, start_clock_;
  // ad hoc csv (format "adhoc_csv"): its layout, from options
  bool adhoc_ = false;
  std::string adhoc_format_;
  std::int64_t adhoc_skip_ = 0;
  char adhoc_dec_ = '.';
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_CSV_OPEN_HPP
