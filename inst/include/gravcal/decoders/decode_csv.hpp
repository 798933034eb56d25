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
// col_z, col_temp, col_time, col_wear (1-based; 0: none; the wear flags
// TRUE/FALSE as fread() reads them: CsvDecoder::wear_of()), time_div (1: the time
// column holds seconds, 1000: milliseconds; 0: text, not read: time is
// start_time + i / sf, unless time_format is given: text read by that
// strptime() format (%Y %y %m %d %H %M %S %OS %T and literal characters;
// time_utc_offset seconds subtracted: a zone of fixed offset), for GGIR's
// gap imputation, or time_iso = 1: ISO 8601 text as data.table::fread reads
// it into date-times, less time_utc_offset (csv_text::FreadDateTime; an
// Axivity csv export's text time)), time_mul (numeric time multiplied by
// it instead: 86400 for ActivPAL days), time_offset (seconds added to
// numeric time; time_utc_offset then subtracted from it too), dec
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
// (read_plain_as, CsvTimeStamps::number_stamp); any other line, damaged or
// unusual, goes through take_line() and the general parser. Both give the
// same samples, counters and notes (option fast = 0 takes every line
// through take_line(); tests/cpp/test_csv and the fuzzer compare the two).
//
// The code is in three parts. CsvOpener (decode_csv_open.hpp) reads the
// header and learns the layout of the data lines (CsvLayout) and the
// sampling rate. CsvTimeStamps (decode_csv_time.hpp) reads a line's time
// stamp and checks the sequence of stamps (gaps, steps back). CsvDecoder,
// here, owns both and the line reader, and turns the data lines into
// samples: in place or through take_line(), with the damage counted and an
// ad hoc csv's values converted to g.
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
#include "gravcal/decoders/decode_csv_open.hpp"
#include "gravcal/decoders/decode_csv_text.hpp"
#include "gravcal/decoders/decode_csv_time.hpp"
#include "gravcal/decoders/line_reader.hpp"

namespace gravcal {

class CsvDecoder : public Decoder {
 public:
  static constexpr int kMaxFields = CsvLayout::kMaxFields;

  // `format`: "actigraph_csv" (the ActiLife header is required), "csv"
  // (either kind), "adhoc_csv" or "axivity_csv" (the layout from options, at
  // the top of this file). Options: compat (1: fread/GGIR, 0: the format),
  // fread_rule (with compat = 1: 1 or 2, data.table's rule for numbers), sf;
  // buffer (bytes of the read buffer, default 1 MiB) and fast (0: every
  // line through take_line(), none parsed in place; the same samples) for
  // tests and fuzzers.
  CsvDecoder(ByteSource& src, const Options& opts, const std::string& format = "csv")
      : lines_(src, buffer_bytes(opts)),
        rules_(ReadRules::of(opts)),
        number_rule_(number_rule_of(opts, rules_)),
        // an Axivity csv export (time stamp, x, y, z) is read by the same
        // layout options (R/formats.R gives them)
        adhoc_(format == "adhoc_csv" || format == "axivity_csv"),
        times_(opts, adhoc_, number_rule_, layout_, report_),
        opener_(lines_, times_, layout_, info_, error_, opts, format, rules_.compat) {
    fast_ = opts.num("fast", 1) != 0;
    if (adhoc_) {
      const double c[6] = {opts.num("col_x", 1), opts.num("col_y", 2), opts.num("col_z", 3),
                           opts.num("col_temp", 0), opts.num("col_time", 0), opts.num("col_wear", 0)};
      int* const to[6] = {&layout_.col_x, &layout_.col_y, &layout_.col_z, &layout_.col_temp, &layout_.col_time,
                          &layout_.col_wear};
      for (int i = 0; i < 6; ++i) *to[i] = c[i] >= 1 && c[i] <= kMaxFields ? static_cast<int>(c[i]) - 1 : -1;
      // text time: not read (start_time + i / sf) unless a format is given
      if (!times_.reads_adhoc_time()) layout_.col_time = -1;
      layout_.time_text = false;
      info_.start_time = opts.num("start_time", std::numeric_limits<double>::quiet_NaN());
      acc_div_ = opts.num("acc_div", 1);
      acc_scale_ = opts.num("acc_scale", 1);
      bit_ = static_cast<int>(opts.num("bit", 0));
      bit_pow_ = opts.num("bit_pow", 1);
      bit_range_ = opts.num("bit_range", 1);
      temp_unit_ = static_cast<int>(opts.num("temp_unit", 0));
    }
  }

  bool open() override {
    if (!opener_.open()) return false;
    info_.has_time = layout_.col_time >= 0 || (std::isfinite(info_.start_time) && info_.sf > 0);
    info_.has_temperature = layout_.col_temp >= 0;
    info_.has_wear = layout_.col_wear >= 0;
    learn_roles();
    opened_ = true;
    done_ = lines_.exhausted();
    return true;
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

  // ---- data lines -----------------------------------------------------------

  // What each field of a data line is for: kTime a time stamp read by
  // CsvTimeStamps::time_of(), kTimeNumber one that is a number (read as the
  // values are).
  enum Role : unsigned char { kSkip, kX, kY, kZ, kTemp, kTime, kTimeNumber };

  // The role of each field; lines are parsed in place when every field has
  // one column at most (plain_ = 2 when the fields are x, y, z and no
  // more, the commonest layout, which has a loop of its own).
  void learn_roles() {
    plain_ = 0;
    // (a wear column's lines go through take_line(): its text is not a number)
    if (!fast_ || layout_.nfields < 3 || layout_.nfields > kMaxFields || layout_.col_wear >= 0) return;
    std::fill(role_, role_ + kMaxFields, kSkip);
    const int cols[5] = {layout_.col_x, layout_.col_y, layout_.col_z, layout_.col_temp, layout_.col_time};
    const Role roles[5] = {kX, kY, kZ, kTemp, kTime};
    for (int i = 0; i < 5; ++i) {
      if (cols[i] < 0) continue;
      if (cols[i] >= layout_.nfields || role_[cols[i]] != kSkip) return;
      role_[cols[i]] = roles[i];
    }
    if (layout_.col_x < 0 || layout_.col_y < 0 || layout_.col_z < 0) return;
    // numeric time (CsvTimeStamps::time_of()'s plain number) is parsed in
    // place too
    number_time_ = layout_.col_time >= 0 && !layout_.time_text && times_.plain_numbers();
    if (number_time_) role_[layout_.col_time] = kTimeNumber;
    plain_ = layout_.nfields == 3 && role_[0] == kX && role_[1] == kY && role_[2] == kZ ? 2 : 1;
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
        t = times_.number_stamp(v[kTimeNumber], line0 + static_cast<std::int64_t>(i - first) + 1,
                                offset0 + (q - p0));
      } else if (!kXyz && layout_.col_time >= 0) {
        Line ln;
        ln.number = line0 + static_cast<std::int64_t>(i - first) + 1;
        ln.offset = offset0 + (q - p0);
        t = times_.stamp_time(tf, ln);
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

  // The value of the plain number (csv_text::scan_plain_number) at p when
  // the byte after it is `a` or `b` (the field ends there); returns that
  // byte's address, or nullptr.
  GRAVCAL_CSV_INLINE const char* plain_number(const char* p, char a, char b, double& v) const {
    csv_text::PlainNumber pn;
    const char* e = csv_text::scan_plain_number(p, layout_.dec, pn);
    if (e == nullptr || (*e != a && *e != b)) return nullptr;
    if (pn.frac >= 1 && pn.frac <= csv_text::kTableDecimals && pn.acc < decimals_->limit[pn.frac]) {
      // a look-up instead of a long double product or a division; the sign
      // by a product with -1: exact, and -(+0) is -0, as above
      static constexpr double kSign[2] = {1.0, -1.0};
      v = decimals_->value[pn.frac][pn.acc] * kSign[pn.neg];
      return e;
    }
    return csv_text::plain_value(pn, p, e, layout_.dec, number_rule_, v) ? e : nullptr;
  }

  // The fields of the data line at q (whole, ending in '\n') when they are
  // all of the common shape: every value a plain number that fills its
  // field, layout_.nfields fields. Puts the values in v (by role) and the time
  // field in tf, and returns the line's '\n'; nullptr for any other line
  // (take_line() decides).
  const char* plain_fields(const char* q, double* v, csv_text::Field& tf) const {
    v[kTemp] = std::numeric_limits<double>::quiet_NaN();
    const char* p = q;
    for (int i = 0; i < layout_.nfields; ++i) {
      const Role r = static_cast<Role>(role_[i]);
      const bool last = i + 1 == layout_.nfields;
      if (r == kSkip || r == kTime) {
        const char* fe = csv_text::field_end(p, layout_.sep);
        if (r == kTime) tf = csv_text::Field{p, fe};
        p = fe;
      } else {
        p = last ? plain_number(p, '\n', '\r', v[r]) : plain_number(p, layout_.sep, layout_.sep, v[r]);
        if (p == nullptr) return nullptr;
      }
      if (!last) {
        if (*p != layout_.sep) return nullptr;
        ++p;
      }
    }
    if (*p == '\r') {
      ++p;
    } else if (role_[layout_.nfields - 1] == kTime && p[-1] == '\r') {
      tf.e = p - 1;  // CRLF: the line ends before the '\r'
    }
    if (*p != '\n') return nullptr;
    if (layout_.col_time >= 0 && !number_time_) tf = csv_text::field_of(tf.b, tf.e);
    return p;
  }

  // The same for the fields x, y, z.
  GRAVCAL_CSV_INLINE const char* xyz_fields(const char* q, double* v) const {
    const char* p = plain_number(q, layout_.sep, layout_.sep, v[kX]);
    if (p == nullptr) return nullptr;
    p = plain_number(p + 1, layout_.sep, layout_.sep, v[kY]);
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
    const int nf = csv_text::split(ln.p, ln.n, layout_.sep, f, kMaxFields);
    if (nf < layout_.nfields) return skip_line(ln, "short_lines", "too few fields");
    if (nf > layout_.nfields) return skip_line(ln, "long_lines", "too many fields");
    double x, y, z, temp = std::numeric_limits<double>::quiet_NaN();
    if (!csv_text::parse_number(f[layout_.col_x].b, f[layout_.col_x].e, layout_.dec, number_rule_, x) ||
        !csv_text::parse_number(f[layout_.col_y].b, f[layout_.col_y].e, layout_.dec, number_rule_, y) ||
        !csv_text::parse_number(f[layout_.col_z].b, f[layout_.col_z].e, layout_.dec, number_rule_, z) ||
        (layout_.col_temp >= 0 && !csv_text::parse_number(f[layout_.col_temp].b, f[layout_.col_temp].e, layout_.dec, number_rule_, temp))) {
      return skip_line(ln, "non_numeric_lines", "a value is not a number");
    }
    if (!ln.has_end) {
      report_.count("no_final_line_end");
      report_.note("line " + std::to_string(ln.number) + " (byte " + std::to_string(ln.offset) +
                   "): the last line has no line end; kept");
    }
    const double t = layout_.col_time >= 0 ? times_.stamp_time(f[layout_.col_time], ln)
                                           : info_.start_time + static_cast<double>(index_) / info_.sf;
    if (adhoc_) {
      x = adhoc_acc(x);
      y = adhoc_acc(y);
      z = adhoc_acc(z);
      temp = adhoc_temp(temp);
    }
    if (layout_.col_wear >= 0) {
      const double w = wear_of(f[layout_.col_wear], ln);
      if (out.wear != nullptr) out.wear[out.n] = w;
    }
    out.put(x, y, z, temp, t);
    ++report_.samples;
  }

  // A wear flag as data.table's fread() (1.14) reads a column of them in
  // one of GGIR's blocks: TRUE/FALSE, true/false or True/False, one of the
  // three spellings in the block (a mix is text to fread), "" and NA
  // missing (NaN); 1 or 0. Anything else (1/0 as well: fread reads those
  // as numbers) is counted and noted ("wear_not_logical"; GGIR's reader
  // stops on such a block) and given as NaN.
  double wear_of(const csv_text::Field& f, const Line& ln) {
    const std::size_t n = static_cast<std::size_t>(f.e - f.b);
    auto is = [&](const char* w) { return n == std::strlen(w) && std::memcmp(f.b, w, n) == 0; };
    if (n == 0 || is("NA")) return std::numeric_limits<double>::quiet_NaN();
    static const char* const kSpell[3][2] = {{"TRUE", "FALSE"}, {"true", "false"}, {"True", "False"}};
    int style = 0;
    double v = 0;
    for (int k = 0; k < 3 && style == 0; ++k) {
      for (int b = 0; b < 2; ++b) {
        if (is(kSpell[k][b])) {
          style = k + 1;
          v = b == 0 ? 1 : 0;
        }
      }
    }
    const std::int64_t block = times_.block_of(ln.number);
    if (block != wear_block_) {
      wear_block_ = block;
      wear_style_ = 0;
    }
    if (style != 0 && (wear_style_ == 0 || wear_style_ == style)) {
      wear_style_ = style;
      return v;
    }
    report_.count("wear_not_logical");
    report_.note("line " + std::to_string(ln.number) + " (byte " + std::to_string(ln.offset) + "): the wear value \"" +
                 csv_text::excerpt(f.b, n) + "\" is not " +
                 (style != 0 ? "spelt as the block's other TRUE/FALSE values" : "TRUE, FALSE or empty"));
    return std::numeric_limits<double>::quiet_NaN();
  }


  static int number_rule_of(const Options& opts, const ReadRules& rules) {
    const double fr = opts.num("fread_rule", 1);
    return !rules.compat ? csv_text::kCorrectlyRounded
           : fr == 2 ? csv_text::kFreadDivide : csv_text::kFreadMultiply;
  }

  LineReader lines_;
  // the reading rules (compat, interpolation, resample_fused), read once
  const ReadRules rules_;
  const int number_rule_;  // a csv_text::NumberRule
  // an ad hoc csv (format "adhoc_csv" or "axivity_csv"): its layout and
  // units from options
  const bool adhoc_;
  CsvLayout layout_;     // filled in by opener_
  CsvTimeStamps times_;  // the time of each line (reads layout_)
  CsvOpener opener_;     // the header read and the layout learnt
  bool fast_ = true;
  bool opened_ = false, done_ = false;
  // lines parsed in place
  const csv_text::Decimals* decimals_ = nullptr;  // csv_text::decimals(number_rule_)
  unsigned char role_[kMaxFields] = {};  // a Role for each field
  int plain_ = 0;  // lines parsed in place: 0 no, 1 yes, 2 yes and they are x, y, z
  bool number_time_ = false;  // with a time column of numbers (role kTimeNumber)
  // position
  std::int64_t index_ = 0;  // data lines consumed
  // an ad hoc csv's units, from options
  double acc_div_ = 1, acc_scale_ = 1, bit_pow_ = 1, bit_range_ = 1;
  int bit_ = 0, temp_unit_ = 0;
  // the wear column's spelling in the current block (wear_of())
  std::int64_t wear_block_ = -1;
  int wear_style_ = 0;
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_CSV_HPP
