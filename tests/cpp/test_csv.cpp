// Standalone tests of the csv decoder's numbers and of its lines parsed in
// place (decode_csv_text.hpp, decode_csv.hpp), built without R:
//   make -C tests/cpp
// * parse_number (rules 1 and 2) against fread's rules written out here on
//   their own: the digits as an integer (at most 18 kept), times 10^e in
//   long double (rule 1, data.table before 1.15.0) or divided by 10^-e for
//   e < 0 (rule 2, from 1.15.0; 10^-300 at most in one step), the powers the
//   literals' values as strtold gives them, rounded to double, the sign
//   applied to the long double value;
// * parse_number (rule 0) against std::from_chars (correctly rounded),
//   and the strtod path (decimal_to_double_strtod, used where the C++
//   library lacks floating-point from_chars) against it on every number;
//   `make` builds this file twice, the second time with
//   GRAVCAL_NO_FROM_CHARS (the decoder on the strtod path throughout);
// * the plain shape (scan_plain_number + plain_value) against parse_number,
//   every number of up to 6 digits and random longer ones;
// * the date-time parser that keeps the last date and second against a
//   fresh one for each stamp; fread's ISO 8601 date-times (FreadDateTime),
//   kept text against fresh, and the lines skipped as fread's skip counts
//   them, across refills of small buffers;
// * a decoder reading lines in place against one reading every line through
//   the general parser (option fast = 0), bit for bit, on files of several
//   layouts, with damage, CRLF and small buffers.
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "gravcal/decoders/decode_csv.hpp"

namespace csv = gravcal::csv_text;

static int failures = 0;
static long checked = 0;
#define CHECK(cond, what)                                                      \
  do {                                                                         \
    ++checked;                                                                 \
    if (!(cond)) {                                                             \
      if (failures < 20) std::printf("FAIL %s:%d: %s (%s)\n", __FILE__, __LINE__, #cond, \
                                     std::string(what).c_str());               \
      ++failures;                                                              \
    }                                                                          \
  } while (0)

static bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// fread's value of s ([+-]digits[.digits][(e|E)[+-]digits], the whole
// text) by rule 1 or 2, written from its description: leading zeros skipped, at
// most 18 digits kept (a longer integer needs a point or an exponent), at
// most 3 exponent digits, the product of the kept digits and 10^e (rule 1)
// or their quotient by 10^-e when e < 0 (rule 2) in long double, rounded to
// double, the sign applied to the long double value. NaN when it is not a
// number (|e| <= 300 here, where rule 2 divides once).
static double fread_rule(const std::string& s, int rule = 1) {
  std::size_t i = 0;
  const bool neg = i < s.size() && s[i] == '-';
  if (i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
  std::string digits;
  int e = 0;
  bool any = false, point = false, lead = true;
  for (; i < s.size() && s[i] != 'e' && s[i] != 'E'; ++i) {
    const char c = s[i];
    if (c == '.' && !point) { point = true; continue; }
    if (c < '0' || c > '9') return NAN;
    any = true;
    if (lead && c == '0') {
      if (point) --e;
      continue;
    }
    lead = false;
    if (digits.size() < 18) {
      digits += c;
      if (point) --e;
    } else if (!point) {
      ++e;
    }
  }
  if (!any || (e > 0 && !point && i == s.size())) return NAN;
  if (i < s.size()) {  // the exponent
    ++i;
    const bool eneg = i < s.size() && s[i] == '-';
    if (i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
    const std::size_t from = i;
    int x = 0;
    for (; i < s.size() && s[i] >= '0' && s[i] <= '9'; ++i) x = x * 10 + (s[i] - '0');
    if (i == from || i - from > 3 || i != s.size()) return NAN;
    e += eneg ? -x : x;
  }
  const long double acc = digits.empty() ? 0.0L : std::strtold(digits.c_str(), nullptr);
  long double r;
  if (rule == 2 && e < 0) {
    r = acc / std::strtold(("1e" + std::to_string(-e)).c_str(), nullptr);
  } else {
    r = acc * std::strtold(("1e" + std::to_string(e)).c_str(), nullptr);
  }
  return static_cast<double>(neg ? -r : r);
}

// The reference: std::from_chars where this C++ library has it for double
// (whatever the decoder was built to use); else (libc++ before 20) the C
// library's strtod, which is then the decoder's path as well.
#if defined(__cpp_lib_to_chars) && __cpp_lib_to_chars >= 201611L
#define TEST_HAVE_FROM_CHARS 1
#endif
static double correctly_rounded(const std::string& s) {
  std::size_t i = 0;
  const bool neg = !s.empty() && s[0] == '-';
  if (!s.empty() && (s[0] == '-' || s[0] == '+')) i = 1;
  double v = NAN;
#if defined(TEST_HAVE_FROM_CHARS)
  const auto r = std::from_chars(s.data() + i, s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return NAN;
#else
  char* end = nullptr;
  v = std::strtod(s.c_str() + i, &end);
  if (end != s.c_str() + s.size() || std::isinf(v)) return NAN;
  if (v == 0 && s.find_first_of("123456789") < s.find_first_of("eE")) return NAN;
#endif
  return neg ? -v : v;
}

// decimal_to_double_strtod() against the reference on the unsigned text
// (it is not given a sign): the same success and bits.
static long strtod_checked = 0;
static void check_strtod_path(const std::string& s) {
  const std::string u = !s.empty() && (s[0] == '-' || s[0] == '+') ? s.substr(1) : s;
  if (u.empty() || u.find_first_not_of("0123456789.eE+-") != std::string::npos) return;
  const double want = correctly_rounded(u);
  const bool nonzero = u.find_first_of("123456789") < u.find_first_of("eE");
  double v = NAN;
  const bool ok = csv::decimal_to_double_strtod(u.c_str(), u.size(), nonzero, v);
  ++strtod_checked;
  CHECK(ok == !std::isnan(want), u + " (strtod path: taken)");
  if (ok && !std::isnan(want)) CHECK(same_bits(v, want), u + " (strtod path: bits)");
}

static bool parse(const std::string& s, int rule, double& v) {
  return csv::parse_number(s.data(), s.data() + s.size(), '.', rule, v);
}

// The plain shape on s (followed by a line end); false when not taken.
static bool plain(const std::string& s, int rule, double& v) {
  const std::string t = s + "\n";
  csv::PlainNumber n;
  const char* e = csv::scan_plain_number(t.data(), '.', n);
  if (e == nullptr || e != t.data() + s.size()) return false;
  const bool ok = csv::plain_value(n, t.data(), e, '.', rule, v);
  // the look-up table of 1-4 decimals, where it applies: the same bits
  const csv::Decimals& d = csv::decimals(rule);
  if (ok && n.frac >= 1 && n.frac <= csv::kTableDecimals && n.acc < d.limit[n.frac]) {
    const double w = d.value[n.frac][n.acc] * (n.neg ? -1.0 : 1.0);
    CHECK(same_bits(v, w), s + " (decimals table)");
  }
  return ok;
}

// What is a number is fread's under every rule; its value fread's (rules 1
// and 2) or the correctly rounded one (rule 0).
static long rules_differ = 0;
static void check_number(const std::string& s, bool strtod_too = true) {
  if (strtod_too) check_strtod_path(s);
  const double fr[3] = {0, fread_rule(s, 1), fread_rule(s, 2)};
  if (!std::isnan(fr[1]) && !same_bits(fr[1], fr[2])) ++rules_differ;
  for (int rule = 0; rule <= 2; ++rule) {
    double v = 0;
    const bool ok = parse(s, rule, v);
    CHECK(ok == !std::isnan(fr[1]), s);
    if (ok) {
      CHECK(same_bits(v, rule ? fr[rule] : correctly_rounded(s)),
            s + " (rule " + std::to_string(rule) + ")");
    }
    double w = 0;
    if (plain(s, rule, w)) CHECK(ok && same_bits(v, w), s + " (plain shape)");
  }
}

// Every number of the plain shape with up to `nd` digits around the point,
// with and without a sign.
static void test_short_numbers(int nd) {
  char buf[32];
  for (int digits = 1; digits <= nd; ++digits) {
    long top = 1;
    for (int k = 0; k < digits; ++k) top *= 10;
    for (int point = 0; point <= digits; ++point) {
      for (long m = 0; m < top; ++m) {
        std::snprintf(buf, sizeof buf, "%0*ld", digits, m);
        std::string s(buf);
        if (point < digits) s.insert(static_cast<std::size_t>(point), ".");
        // (the strtod path on one in 13: short decimals are its easy case)
        check_number(s, m % 13 == 0);
        check_number("-" + s, false);
        if (m % 7 == 0) check_number("+" + s, false);
      }
    }
  }
}

// Random numbers of 7 to 21 digits (15 to 19 significant are fread's and
// the fast path's edges), and values next to rounding boundaries: the
// shortest decimal of a double and of its neighbours, with a digit added.
static void test_long_numbers(std::mt19937_64& rng, int scale) {
  std::uniform_int_distribution<int> nd(7, 21), pos(0, 21), dig(0, 9), coin(0, 3);
  for (int i = 0; i < 200000 / scale; ++i) {
    const int n = nd(rng);
    std::string s;
    for (int k = 0; k < n; ++k) s += static_cast<char>('0' + dig(rng));
    if (coin(rng) > 0) s.insert(static_cast<std::size_t>(pos(rng) % (n + 1)), ".");
    if (coin(rng) == 0) s = "-" + s;
    check_number(s);
  }
  std::uniform_real_distribution<double> u(-16, 16);
  char buf[64];
  for (int i = 0; i < 100000 / scale; ++i) {
    const double x = u(rng);
    for (double y : {x, std::nextafter(x, 100.0), std::nextafter(x, -100.0)}) {
      for (int prec = 15; prec <= 19; ++prec) {
        std::snprintf(buf, sizeof buf, "%.*f", prec, y);
        check_number(buf);
      }
      std::snprintf(buf, sizeof buf, "%.3f5", y);  // halfway between 4-decimal values
      check_number(buf);
    }
  }
}

// ---- time stamps: the parser's caches change no value ----------------------

// A run of stamps such as files hold (and some they should not): each
// parsed by one parser, which keeps the last date and second, and by a
// fresh one; the same success and bits.
static void test_stamps(std::mt19937_64& rng, int scale) {
  std::uniform_int_distribution<int> k(0, 99), sec(0, 61), ms(0, 999);
  const std::vector<std::string> dates = {"5/11/2023", "5/12/2023", "12/31/2023", "1/1/2024",
                                          "2023-05-11", "11/5/2023", "5/11/23", "2/30/2023"};
  const std::vector<std::string> tails = {"", "Z", "1", " ", ".", ":5", ".0000000001", "x"};
  for (csv::DateOrder order : {csv::DateOrder::mdy, csv::DateOrder::dmy}) {
    csv::DateTimeParser kept(order);
    std::string date = dates[0];
    int hh = 9, mm = 0, ss = 0;
    for (int i = 0; i < 200000 / scale; ++i) {
      const int c = k(rng);
      if (c == 0) date = dates[static_cast<std::size_t>(k(rng)) % dates.size()];
      if (c == 1) ss = sec(rng);
      if (c < 10) ss = (ss + 1) % 62;
      if (c == 2) mm = (mm + 1) % 61;
      if (c == 3) hh = (hh + 1) % 26;
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s%s%02d:%02d:%02d", date.c_str(),
                    c == 4 ? "T" : (c == 5 ? "  " : " "), hh, mm, ss);
      std::string stamp = buf;
      if (c < 90) {
        std::snprintf(buf, sizeof buf, ".%0*d", 1 + c % 3, ms(rng) % (c % 3 == 0 ? 10 : 1000));
        stamp += buf;
      }
      if (c >= 85) stamp += tails[static_cast<std::size_t>(c) % tails.size()];
      if (c == 6) stamp = stamp.substr(0, stamp.size() - 2);
      // now and then another date with an impossible time, then this stamp
      // again (the parser has taken in the other date meanwhile)
      std::vector<std::string> run = {stamp};
      if (c == 7) run = {stamp, dates[(i / 7) % dates.size()] + " 25:00:00.000", stamp};
      for (const std::string& st : run) {
        double a = 0, b = 0;
        int fa = -1, fb = -1;
        csv::DateTimeParser fresh(order);
        const bool oa = kept.parse(st.data(), st.data() + st.size(), a, fa);
        const bool ob = fresh.parse(st.data(), st.data() + st.size(), b, fb);
        CHECK(oa == ob, st);
        if (oa && ob) CHECK(same_bits(a, b) && fa == fb, st);
      }
    }
  }
}

// ---- whole files: in place against line by line ---------------------------

struct Decoded {
  bool opened = false;
  std::string error;
  std::vector<double> values;
  std::vector<std::int64_t> blocks;
  gravcal::Report report;
};

static Decoded decode(const std::string& text, const std::string& format, double compat,
                      double fast, double buffer, std::size_t cap, std::int64_t units) {
  Decoded d;
  gravcal::MemorySource src(reinterpret_cast<const unsigned char*>(text.data()), text.size());
  gravcal::Options o;
  // compat 2: fread's numbers by rule 2 (option fread_rule)
  o.set("compat", compat > 0 ? 1.0 : 0.0);
  if (compat == 2) o.set("fread_rule", 2.0);
  o.set("fast", fast);
  o.set("buffer", buffer);
  if (text.compare(0, 6, "x,y,z\n") == 0) o.set("sf", 30.0);  // no time column
  gravcal::CsvDecoder dec(src, o, format);
  d.opened = dec.open();
  d.error = dec.error();
  if (!d.opened) return d;
  std::vector<double> x(cap), y(cap), z(cap), t(cap), tm(cap);
  for (int calls = 0; calls < 1000000 && !dec.done(); ++calls) {
    gravcal::SampleBuffer b;
    b.x = x.data(); b.y = y.data(); b.z = z.data(); b.t = t.data(); b.time = tm.data();
    b.capacity = cap;
    const std::int64_t u = dec.read(b, units);
    d.blocks.push_back(u);
    d.blocks.push_back(static_cast<std::int64_t>(b.n));
    for (std::size_t i = 0; i < b.n; ++i) {
      for (double v : {x[i], y[i], z[i], t[i], tm[i]}) d.values.push_back(v);
    }
    if (u == 0 && b.n == 0) break;
  }
  d.report = dec.report();
  return d;
}

static bool same(const Decoded& a, const Decoded& b) {
  if (a.opened != b.opened || a.error != b.error || a.blocks != b.blocks) return false;
  if (a.values.size() != b.values.size()) return false;
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    if (!same_bits(a.values[i], b.values[i])) return false;
  }
  const gravcal::Report& r = a.report;
  const gravcal::Report& s = b.report;
  return r.units == s.units && r.samples == s.samples && r.skipped == s.skipped &&
         r.gaps == s.gaps && same_bits(r.gap_seconds, s.gap_seconds) &&
         r.truncated == s.truncated && r.counters == s.counters && r.notes == s.notes;
}

static std::string actigraph_header() {
  return "------------ Data File Created By ActiGraph GT3X+ ActiLife v6.13.4 Firmware v3.2.1 "
         "date format M/d/yyyy at 30 Hz  Filter Normal -----------\n"
         "Serial Number: MOS2E00000000\nStart Time 10:00:00\nStart Date 5/11/2023\n"
         "Epoch Period (hh:mm:ss) 00:00:00\nDownload Time 10:00:00\nDownload Date 5/12/2023\n"
         "Current Memory Address: 0\nCurrent Battery Voltage: 4.20     Mode = 12\n"
         "--------------------------------------------------\n";
}

// A number as a csv writer might give it: mostly 3 decimals, sometimes
// more digits, a sign, an exponent or text.
static std::string some_number(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> k(0, 99);
  std::uniform_real_distribution<double> u(-8, 8);
  char buf[64];
  const int c = k(rng);
  if (c < 70) std::snprintf(buf, sizeof buf, "%.3f", u(rng));
  else if (c < 80) std::snprintf(buf, sizeof buf, "%.*f", 1 + c % 17, u(rng));
  else if (c < 85) std::snprintf(buf, sizeof buf, "%+.4f", u(rng));
  else if (c < 88) std::snprintf(buf, sizeof buf, "%.6e", u(rng));
  else if (c < 90) std::snprintf(buf, sizeof buf, "%.17g", u(rng));
  else if (c < 92) std::snprintf(buf, sizeof buf, "%d", c % 5);
  else if (c < 93) std::snprintf(buf, sizeof buf, "-0.000");
  else if (c < 94) std::snprintf(buf, sizeof buf, " %.3f", u(rng));
  else if (c < 95) std::snprintf(buf, sizeof buf, "\"%.3f\"", u(rng));
  else if (c < 96) std::snprintf(buf, sizeof buf, "NA");
  else if (c < 97) std::snprintf(buf, sizeof buf, "%s", "");
  else if (c < 98) std::snprintf(buf, sizeof buf, "1.5.2");
  else std::snprintf(buf, sizeof buf, "%.3f\r", u(rng));
  return buf;
}

static std::string some_line(std::mt19937_64& rng, const std::vector<std::string>& cols,
                             char sep, int i) {
  std::uniform_int_distribution<int> k(0, 199);
  const int damage = k(rng);
  std::string s;
  for (std::size_t c = 0; c < cols.size(); ++c) {
    if (c) s += sep;
    if (cols[c] == "stamp") {
      char buf[64];
      std::snprintf(buf, sizeof buf, "5/11/2023 10:%02d:%02d.%03d", (i / 1800) % 60, (i / 30) % 60,
                    (i % 30) * 33);
      s += buf;
    } else if (cols[c] == "time") {
      char buf[64];
      // a jump of 2.5 s forward every 700 lines (a gap), one 1 s back
      // every 1100 (time going back)
      std::snprintf(buf, sizeof buf, "%.3f",
                    1683799200.0 + i / 30.0 + (i / 700) * 2.5 - (i % 1100 == 1099 ? 1.0 : 0.0));
      s += buf;
    } else if (cols[c] == "iso") {
      char buf[64];
      std::snprintf(buf, sizeof buf, "2023-05-11T10:%02d:%02d.%03dZ", (i / 1800) % 60,
                    (i / 30) % 60, (i % 30) * 33);
      s += buf;
    } else if (cols[c] == "steps") {
      s += std::to_string(i % 3);
    } else {
      std::string v = some_number(rng);
      if (sep == ';') {
        for (char& ch : v) if (ch == '.') ch = ',';
      }
      s += v;
    }
  }
  if (damage == 0) s = "";
  if (damage == 1) s += sep;
  if (damage == 2) s = s.substr(0, s.size() / 2);
  if (damage == 3) s = "  ";
  return s;
}

static void test_files(std::mt19937_64& rng) {
  struct Layout {
    std::string format, head;
    std::vector<std::string> cols;
    char sep;
  };
  const std::vector<Layout> layouts = {
      {"actigraph_csv", "Accelerometer X,Accelerometer Y,Accelerometer Z\n", {"x", "y", "z"}, ','},
      {"actigraph_csv", "", {"x", "y", "z"}, ','},
      {"actigraph_csv", "Timestamp,Accelerometer X,Accelerometer Y,Accelerometer Z\n",
       {"stamp", "x", "y", "z"}, ','},
      {"actigraph_csv", "", {"iso", "x", "y", "z"}, ','},
      {"actigraph_csv", "Axis1,Axis2,Axis3,Steps\n", {"x", "y", "z", "steps"}, ','},
      {"csv", "x,y,z\n", {"x", "y", "z"}, ','},
      {"csv", "time,x,y,z,temperature\n", {"time", "x", "y", "z", "temp"}, ','},
      {"csv", "z;temp;y;x;time\n", {"z", "temp", "y", "x", "iso"}, ';'},
      {"csv", "acc_x\tacc_y\tacc_z\ttimestamp\n", {"x", "y", "z", "iso"}, '\t'},
  };
  int files = 0;
  for (const Layout& l : layouts) {
    for (int eol = 0; eol < 2; ++eol) {
      for (int rep = 0; rep < 3; ++rep) {
        std::string text = l.format == "actigraph_csv" ? actigraph_header() : "";
        text += l.head;
        const int n = 3000;
        for (int i = 0; i < n; ++i) {
          text += some_line(rng, l.cols, l.sep, i);
          text += eol ? "\r\n" : "\n";
        }
        if (rep == 2) text.resize(text.size() - 5);  // cut inside the last line
        for (double compat : {0.0, 1.0, 2.0}) {
          // small buffers: lines cross refills (an ActiLife header line needs 300)
          const double small = l.format == "csv" ? 64 : 300;
          for (double buffer : {small, 333.0, 1048576.0}) {
            const std::size_t cap = rep == 1 ? 7 : 1000;
            const std::int64_t units = rep == 0 ? -1 : 11;
            const Decoded a = decode(text, l.format, compat, 1, buffer, cap, units);
            const Decoded b = decode(text, l.format, compat, 0, buffer, cap, units);
            CHECK(a.opened, l.format + " " + l.head + " " + a.error);
            CHECK(same(a, b), l.format + " " + l.head);
            ++files;
          }
        }
      }
    }
  }
  std::printf("csv files: %d decodings in place and line by line compared\n", files);
}

// LineReader::skip_fread_lines() counts line ends as fread's skip does
// ("\n", "\r", "\r\n" and "\n\r" one each), whatever the buffer's size
// (a pair split by a refill): where each count of lines ends.
static void test_fread_skip() {
  const std::string text = "a\rb\r\nc\n\rd\r\re\n\nf\ng,1\n";
  // the byte after k lines by that count: a b c d "" e "" f g,1
  const std::int64_t ends[] = {2, 5, 8, 10, 11, 13, 14, 16, 20};
  for (std::size_t buffer : {64, 65, 66, 67, 68, 1024}) {
    // padded so that a small buffer's refills fall inside the text
    const std::size_t pad = buffer - 4;
    const std::string padded = std::string(pad, 'x') + text;
    for (int k = 1; k <= 9; ++k) {
      gravcal::MemorySource src(reinterpret_cast<const unsigned char*>(padded.data()), padded.size());
      gravcal::LineReader lr(src, buffer);
      CHECK(lr.skip_fread_lines(k) == k, "skip " + std::to_string(k));
      CHECK(lr.offset() == static_cast<std::int64_t>(pad) + ends[k - 1],
            "after " + std::to_string(k) + " lines, buffer " + std::to_string(buffer));
    }
  }
  gravcal::MemorySource src(reinterpret_cast<const unsigned char*>(text.data()), text.size());
  gravcal::LineReader lr(src);
  CHECK(lr.skip_fread_lines(20) == 9, "lines at the end of the input");
}

// FreadDateTime: fread's value of ISO 8601 date-times, with the minute's
// text kept from stamp to stamp (as a fresh parser gives).
static void test_fread_datetime() {
  struct Case {
    const char* s;
    double want;  // seconds since 1970; NaN: not taken
  } cases[] = {
      {"2024-03-04 09:17:00.04", 1709543820.04},
      {"2024-03-04T09:17:00.040Z", 1709543820.04},
      {"2024-03-04 09:17:00.040+01:00", 1709540220.04},
      {"2024-03-04 09:17:00 +0130", 1709538420.0},
      {"2024-03-04 09:17:00-05:30", 1709561820.0 - 1800.0},  // fread: -5 h, +30 min
      {"2024-3-4 9:7:5", 1709543225.0},
      {"2024-02-30 09:17:00", NAN},
      {"2024-03-04 24:00:00", NAN},
      {"2024-03-04 09:17:60", NAN},
      {"2024-03-04 09:17", NAN},
      {"2024-03-04", NAN},
      {"2024/03/04 09:17:00", NAN},
      {"2024-03-04 09:17:00.5 Z", NAN},
  };
  csv::FreadDateTime kept;
  for (const Case& c : cases) {
    const char* b = c.s;
    const char* e = c.s + std::strlen(c.s);
    double t = 0, u = 0;
    csv::FreadDateTime fresh;
    const bool ok = kept.parse(b, e, csv::kFreadMultiply, t);
    const bool ok2 = fresh.parse(b, e, csv::kFreadMultiply, u);
    CHECK(ok == !std::isnan(c.want), std::string(c.s) + " (taken)");
    CHECK(ok == ok2, std::string(c.s) + " (kept text)");
    if (ok && ok2) {
      CHECK(same_bits(t, u), std::string(c.s) + " (kept text: bits)");
      CHECK(std::fabs(t - c.want) < 1e-6, std::string(c.s) + " (value)");
    }
  }
}


// `--quick` (make valgrind: memcheck, not the numbers, is the point there;
// `make test` runs the whole set natively): numbers of up to 4 digits
// exhaustively instead of 6, a tenth of the random ones.
int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  const int scale = quick ? 10 : 1;
  std::mt19937_64 rng(20240601);
  for (const char* s : {"0.121", "-0.891", "+1.5", "-0.000", "0", "-0", ".5", "5.", "-.5", "1e-3",
                        "1.358931", "-1.10116583029324", "123456789012345678",
                        "1234567890123456789", "0.000000000000000000000001",
                        "9007199254740993", "0.1234567890123456789", "00000000000000000001.5"}) {
    check_number(s);
  }
  // the edges of the double range, where only the general conversion
  // decides: subnormals are numbers, what rounds to 0 or overflows is not
  for (const char* s : {"1e-310", "4.9e-324", "2.5e-324", "2.4e-324", "2.4703282292062328e-324",
                        "2.4703282292062327e-324", "1e-330", "0e-340", "0.0e300", "1e309",
                        "1.7976931348623157e308", "1.7976931348623158e308",
                        "1.7976931348623159e308", "2.2250738585072011e-308", "1e+5",
                        "123456789012345678e-340", "-1e-310", "-1e309"}) {
    check_strtod_path(s);
    double v = 0;
    const bool ok = parse(s, 0, v);
    const double want = correctly_rounded(s);
    CHECK(ok == !std::isnan(want), std::string(s) + " (range edge: taken)");
    if (ok && !std::isnan(want)) CHECK(same_bits(v, want), std::string(s) + " (range edge: bits)");
  }
  test_short_numbers(quick ? 4 : 6);
  test_long_numbers(rng, scale);
  test_stamps(rng, scale);
  test_files(rng);
  test_fread_skip();
  test_fread_datetime();
  // the two fread rules are told apart by the inputs above (with x87's or
  // quad's long double; where long double is double they may agree)
  std::printf("csv: fread's rules 1 and 2 differ on %ld numbers\n", rules_differ);
  if (sizeof(long double) > sizeof(double)) CHECK(rules_differ > 0, "rules 1 and 2 differ somewhere");
  std::printf("csv (%s): %ld checks (%ld of the strtod path against %s), %s\n",
#if defined(GRAVCAL_HAVE_FROM_CHARS)
              "decoder on from_chars",
#else
              "decoder on strtod",
#endif
              checked, strtod_checked,
#if defined(TEST_HAVE_FROM_CHARS)
              "from_chars",
#else
              "the C library's strtod",
#endif
              failures ? "FAILED" : "all passed");
  return failures ? 1 : 0;
}
