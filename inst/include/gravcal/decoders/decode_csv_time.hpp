// gravcal: the layout of a csv file's data lines, and the time stamps of
// those lines (the csv decoder, decode_csv.hpp, is built from these).
//
// CsvLayout holds what opening a csv file learns about its data lines (the
// separator, the decimal mark, which field is which) and the sample period;
// decode_csv_open.hpp fills it in, and the decoder and CsvTimeStamps read it.
//
// CsvTimeStamps turns the time field of a data line into seconds since 1970
// and follows the sequence of those times. A time field is read in one of
// four ways: as a number (plain csv, or an ad hoc csv's numeric column,
// divided by time_div or multiplied by time_mul, shifted by time_offset,
// less time_utc_offset), as a date-time in the
// ActiGraph header's date order, as text by an ad hoc csv's strptime()
// format (time_format), or as ISO 8601 text the way data.table::fread reads
// it (time_iso). The sequence of times is checked line by line: a stamp
// coarser than a sample period is spread over its lines (k / sf for the
// k-th line of the same stamp), a jump forward of more than 1.5 sample
// periods (plus the stamps' resolution) is a gap, a step back of more than
// half a period (plus the resolution) is counted, and an unreadable stamp
// takes the time one step after the last. The top of
// decode_csv.hpp describes these rules for each format.
#ifndef GRAVCAL_DECODE_CSV_TIME_HPP
#define GRAVCAL_DECODE_CSV_TIME_HPP

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/decoders/decode_csv_text.hpp"
#include "gravcal/decoders/line_reader.hpp"

namespace gravcal {

// What the opening of a csv file learnt about its data lines. Columns are
// 0-based field indices, -1 when the file has no such column.
struct CsvLayout {
  static constexpr int kMaxFields = 64;  // fields looked at per line
  char sep = ',', dec = '.';
  int nfields = 0;
  int col_x = -1, col_y = -1, col_z = -1, col_time = -1, col_temp = -1;
  int col_wear = -1;  // an ad hoc csv file's wear column (TRUE/FALSE)
  // the time column holds text (a date-time), not a number
  bool time_text = true;
  double step = 0;  // the sample period, 1 / sf
};

class CsvTimeStamps {
 public:
  static constexpr double kGapSteps = 1.5;  // a step this many sample periods is a gap

  // `adhoc`: the file is an ad hoc csv (or an Axivity csv export), whose
  // time options (time_div, time_offset, time_format, time_iso,
  // time_utc_offset, the zone tz_*, skip and block_lines) are read here.
  // `number_rule` is the csv_text::NumberRule numbers are read by. The
  // layout and the report belong to the decoder and must outlive this.
  CsvTimeStamps(const Options& opts, bool adhoc, int number_rule, const CsvLayout& layout, Report& report)
      : layout_(layout), report_(report), adhoc_(adhoc), number_rule_(number_rule) {
    if (adhoc_) {
      adhoc_skip_ = static_cast<std::int64_t>(opts.num("skip", 0));
      time_div_ = opts.num("time_div", 0);
      time_mul_ = opts.num("time_mul", 0);
      time_offset_ = opts.num("time_offset", 0);
      time_fmt_ = opts.str("time_format", "");
      time_iso_ = opts.num("time_iso", 0) != 0;
      time_utc_offset_ = opts.num("time_utc_offset", 0);
      zone_ = ZoneTable(opts);
      block_lines_ = static_cast<std::int64_t>(opts.num("block_lines", 0));
    }
  }

  // Which of GGIR's blocks (of block_lines lines after the skipped ones,
  // counted from 0) data line `line` (1-based, in the file) belongs to; 0
  // without blocks.
  std::int64_t block_of(std::int64_t line) const {
    if (block_lines_ <= 0 || line <= adhoc_skip_) return 0;
    return (line - 1 - adhoc_skip_) / block_lines_;
  }

  // The ActiGraph header's date-time reader (its date order is set from the
  // header's "date format").
  csv_text::DateTimeParser& date_times() { return dt_; }

  // An ad hoc csv's time column is read only when it holds numbers
  // (time_div) or text with a format (time_format or time_iso); otherwise
  // time is start_time + i / sf.
  bool reads_adhoc_time() const { return time_div_ > 0 || !time_fmt_.empty() || time_iso_; }

  // A time column of plain numbers needs nothing but number_stamp() (no
  // text format and no zone): the decoder may read it in place.
  bool plain_numbers() const { return !(adhoc_ && (!time_fmt_.empty() || time_iso_)) && zone_.empty(); }

  // The time in a field, in seconds since 1970, and the decimals of its
  // seconds (`frac_digits`: 9 where the resolution is not to be judged
  // from the text). False when the field is not a time.
  bool time_of(const csv_text::Field& f, double& t, int& frac_digits) {
    if (adhoc_ && time_iso_) {
      // as fread reads it, less the offset of the zone GGIR forces it into
      // (force_tz()'s table where that offset changes: NaN where the clock
      // time does not exist; else a fixed offset)
      frac_digits = 9;
      if (!iso_.parse(f.b, f.e, number_rule_, t)) return false;
      if (!zone_.empty()) t = t - zone_.offset(t);
      else if (time_utc_offset_ != 0) t = t - time_utc_offset_;
      return true;
    }
    if (adhoc_ && !time_fmt_.empty()) {
      frac_digits = 9;  // taken as it is (no spreading of coarse stamps)
      return parse_formatted(f.b, f.e, t);
    }
    if (!layout_.time_text) {
      frac_digits = 9;
      // the common shape (digits, a point, digits) by the plain scan, which
      // gives parse_number's value; any other shape by parse_number (the
      // field lies in a line, so a byte that ends the scan follows it)
      csv_text::PlainNumber pn;
      const char* e = csv_text::scan_plain_number(f.b, layout_.dec, pn);
      if (e == f.e && f.b < f.e) {
        if (!csv_text::plain_value(pn, f.b, e, layout_.dec, number_rule_, t)) return false;
      } else if (!csv_text::parse_number(f.b, f.e, layout_.dec, number_rule_, t)) {
        return false;
      }
      if (adhoc_) {
        t = adhoc_number(t);
        // (ActivPAL days in an hour the zone's clocks skip: force_tz()'s NA)
        if (std::isnan(t)) report_.count("time_not_existing");
      }
      return true;
    }
    return dt_.parse(f.b, f.e, t, frac_digits);
  }

  // An ad hoc csv's numeric time stamp `v` in seconds since 1970, in
  // GGIR's operations and order: v / time_div (milliseconds; v / 1 is v:
  // not taken), or v * time_mul (ActivPAL days: read.myacc.csv's
  // v * 86400), plus time_offset (the origin), less time_utc_offset (a
  // zone of fixed offset GGIR forces the stamps into: lubridate::force_tz()
  // on whole seconds, whose result is the rounded (t - offset) as well), or
  // less the offset of force_tz()'s zone table at that clock time (ActivPAL
  // days in a zone whose offset changes: NaN where the time does not exist).
  double adhoc_number(double v) const {
    if (time_mul_ != 0) v = v * time_mul_;
    else if (time_div_ != 1) v = v / time_div_;
    v = v + time_offset_;
    if (!zone_.empty()) return v - zone_.offset(v);
    if (time_utc_offset_ != 0) v = v - time_utc_offset_;
    return v;
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
      last_time_ += layout_.step;
      return last_time_;
    }
    static const double kRes[10] = {1, 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 0};
    const double res = kRes[fd < 9 ? fd : 9];
    if (s == last_stamp_) ++run_;
    else run_ = 0;
    last_stamp_ = s;
    const bool coarse = res > kGapSteps * layout_.step;
    const double t = coarse ? s + static_cast<double>(run_) * layout_.step : s;
    if (std::isfinite(last_time_)) check_step(t - last_time_, coarse ? 0 : res, ln);
    last_time_ = t;
    return t;
  }

  // stamp_time() of a time stamp that is a plain number, given its value as
  // read in place (line `number`, at byte `offset`): time_of()'s
  // conversion, and the checks with its resolution (time_of() gives 9
  // decimals: res 0, never coarse).
  GRAVCAL_CSV_INLINE double number_stamp(double s, std::int64_t number, std::int64_t offset) {
    if (adhoc_) s = adhoc_number(s);
    if (s == last_stamp_) ++run_;
    else run_ = 0;
    last_stamp_ = s;
    if (std::isfinite(last_time_)) {
      const double dt = s - last_time_;
      if (dt > kGapSteps * layout_.step + 0.0 || dt < -(layout_.step / 2 + 0.0)) {
        Line ln;
        ln.number = number;
        ln.offset = offset;
        check_step(dt, 0, ln);
      }
    }
    last_time_ = s;
    return s;
  }

 private:
  // A text time stamp by time_fmt_, as R's strptime() reads it (the
  // directives listed at the top of decode_csv.hpp; blanks in the format
  // match any blanks; text after the format ignored), in seconds since 1970
  // less time_utc_offset_: R's as.POSIXct() in a zone of that fixed offset
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

  void check_step(double dt, double res, const Line& ln) {
    if (dt > kGapSteps * layout_.step + res) {
      gap(dt, ln);
    } else if (dt < -(layout_.step / 2 + res)) {
      backwards(dt, ln);
    }
  }
  // (the rare cases out of line: check_step() stays small enough to inline)
#if defined(__GNUC__)
  __attribute__((noinline))
#endif
  void gap(double dt, const Line& ln) {
    ++report_.gaps;
    report_.gap_seconds += dt - layout_.step;
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

  const CsvLayout& layout_;
  Report& report_;
  bool adhoc_;
  int number_rule_;  // a csv_text::NumberRule
  csv_text::DateTimeParser dt_;
  // the sequence so far
  double last_time_ = std::numeric_limits<double>::quiet_NaN();
  double last_stamp_ = std::numeric_limits<double>::quiet_NaN();
  std::int64_t run_ = 0;  // lines since the stamp last changed
  // ad hoc csv (format "adhoc_csv"): how its time column is read, from options
  std::int64_t adhoc_skip_ = 0;  // lines before the data
  double time_div_ = 0, time_mul_ = 0, time_offset_ = 0;
  std::string time_fmt_;  // text time stamps' strptime() format ("": not read)
  bool time_iso_ = false;  // text time stamps read as fread reads ISO 8601 date-times
  csv_text::FreadDateTime iso_;
  double time_utc_offset_ = 0;
  ZoneTable zone_;  // a zone whose offset changes (options tz_*), else time_utc_offset_
  std::int64_t block_lines_ = 0;  // lines in one of GGIR's blocks (option block_lines)
  mutable double last_cal_ = 0;   // the last text time read, as its calendar read as UTC
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_CSV_TIME_HPP
