// gravcal: the text primitives of the csv decoder (decode_csv.hpp): numbers,
// date-times, field splitting (the line reader: line_reader.hpp).
//
// Numbers. data.table::fread reads a decimal as an integer of at most 18
// significant digits and scales it by a power of ten in long double, then
// rounds that to double. That is not correctly rounded, and how it scales
// changed in data.table 1.15.0 (its issue 4461):
//  * rule 1 (data.table before 1.15.0; Debian 12's 1.14.8): the digits
//    times 10^e, with a table of negative powers for e < 0. "1.358931",
//    "-1.10116583029324" differ from strtod's value in the last bit (about
//    1 in 4000 numbers of 6 or more digits; none of 3 or 4 decimals, which
//    ActiLife writes, and none of 17 digits);
//  * rule 2 (data.table 1.15.0 and later): the digits divided by 10^-e for
//    e < 0 (times 10^e for e >= 0), the power beyond 10^300 applied first.
//    "-6.94352849999999" is one where the two rules differ.
// Rule 0 is the correctly rounded value (std::from_chars where the C++
// library has it for double, else strtod in the "C" locale: see
// decimal_to_double()). Which fread rule GGIR's reads follow is found in R
// from the installed data.table's own fread (R/fp-build.R), and given to
// the decoder as an option; the long double is the compiler's, as
// data.table's is (x87's 64-bit mantissa, IEEE quad on aarch64, double on
// macOS arm64), so each rule is data.table's on the same platform.
#ifndef GRAVCAL_DECODE_CSV_TEXT_HPP
#define GRAVCAL_DECODE_CSV_TEXT_HPP

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

// Floating-point std::from_chars: libstdc++ from GCC 11 (12 on mingw-w64),
// MSVC; not libc++ before 20 (macOS) nor older Rtools' GCC. The library
// says so with __cpp_lib_to_chars (set by <charconv>, which every C++17
// library has for integers). GRAVCAL_NO_FROM_CHARS forces the strtod path
// (tests/cpp builds the csv tests both ways).
#include <charconv>
#if defined(__cpp_lib_to_chars) && __cpp_lib_to_chars >= 201611L && !defined(GRAVCAL_NO_FROM_CHARS)
#define GRAVCAL_HAVE_FROM_CHARS 1
#endif
// strtod with an explicit "C" locale (the decimal point is '.', whatever
// LC_NUMERIC the session has): _strtod_l on Windows (UCRT, msvcrt),
// strtod_l from <xlocale.h> on macOS and the BSDs, POSIX 2008's elsewhere.
#include <locale.h>
#if defined(__APPLE__) || defined(__FreeBSD__) || defined(__NetBSD__) || defined(__OpenBSD__)
#include <xlocale.h>
#endif

#include "gravcal/decoders/decode.hpp"

// Inlined into the loop over a line's fields (GCC's heuristics would not).
#if defined(__GNUC__) || defined(__clang__)
#define GRAVCAL_CSV_INLINE inline __attribute__((always_inline))
#else
#define GRAVCAL_CSV_INLINE inline
#endif

namespace gravcal {
namespace csv_text {

// fread reads at most this many significant digits of a number
constexpr int kMaxSigDigits = 18;
// and gives up on exponents beyond this (the value is not a number for it)
constexpr int kMaxExponent = 350;

// 10^e for |e| <= kMaxExponent in long double, each correctly rounded (the
// value a compiler gives the literal 1e<e>L, as fread's table holds them).
inline const long double* pow10_table() {
  static const std::vector<long double> t = [] {
    std::vector<long double> v(2 * kMaxExponent + 1);
    for (int e = -kMaxExponent; e <= kMaxExponent; ++e) {
      const std::string lit = "1e" + std::to_string(e);
      v[static_cast<std::size_t>(e + kMaxExponent)] = std::strtold(lit.c_str(), nullptr);
    }
    return v;
  }();
  return t.data();
}

// The common exponents as long double literals (no look-up call per number).
constexpr int kNearExponent = 22;
constexpr long double kPow10Near[2 * kNearExponent + 1] = {
    1e-22L, 1e-21L, 1e-20L, 1e-19L, 1e-18L, 1e-17L,
    1e-16L, 1e-15L, 1e-14L, 1e-13L, 1e-12L, 1e-11L,
    1e-10L, 1e-9L, 1e-8L, 1e-7L, 1e-6L, 1e-5L,
    1e-4L, 1e-3L, 1e-2L, 1e-1L, 1e0L, 1e1L,
    1e2L, 1e3L, 1e4L, 1e5L, 1e6L, 1e7L,
    1e8L, 1e9L, 1e10L, 1e11L, 1e12L, 1e13L,
    1e14L, 1e15L, 1e16L, 1e17L, 1e18L, 1e19L,
    1e20L, 1e21L, 1e22L};

inline bool is_digit(char c) { return c >= '0' && c <= '9'; }

// The value of the byte as a digit; above 9 when it is not one.
inline unsigned digit_of(char c) { return static_cast<unsigned>(static_cast<unsigned char>(c)) - '0'; }

// kPow10Near by sign, [1] the negative powers: a negative number's value
// is its digits times a negative power, with no branch on the sign (which
// varies from number to number). Rounding to nearest is symmetric, so
// round(acc * -p) is -round(acc * p), and 0 * -p is -0.
struct Pow10BySign {
  long double v[2][2 * kNearExponent + 1];
};
constexpr Pow10BySign pow10_by_sign() {
  Pow10BySign t{};
  for (int i = 0; i < 2 * kNearExponent + 1; ++i) {
    t.v[0][i] = kPow10Near[i];
    t.v[1][i] = -kPow10Near[i];
  }
  return t;
}
constexpr Pow10BySign kPow10Signed = pow10_by_sign();

// 10^e in long double for kNearExponent < |e| <= kMaxExponent (out of line:
// rare, and it keeps fread_value small enough to inline).
#if defined(__GNUC__)
__attribute__((noinline))
#endif
inline long double pow10_far(int e) {
  return pow10_table()[e + kMaxExponent];
}

// The rules for a number's value (see the top of this file).
enum NumberRule : int { kCorrectlyRounded = 0, kFreadMultiply = 1, kFreadDivide = 2 };

// fread's value of (-)acc * 10^exp10, for acc < 10^18 and |exp10| <=
// kMaxExponent, by rule 1 (rule = kFreadMultiply) or rule 2: in long
// double, rounded to double once (fread applies the sign to the long double
// value; rounding to nearest is symmetric, so the same value).
GRAVCAL_CSV_INLINE double fread_value(std::uint64_t acc, int exp10, bool neg, int rule = kFreadMultiply) {
  // acc < 10^18 < 2^63: a signed conversion, exact in long double
  const long double a = static_cast<long double>(static_cast<std::int64_t>(acc));
  if (rule != kFreadDivide) {
    const long double p10 = (exp10 >= -kNearExponent && exp10 <= kNearExponent)
                                ? kPow10Signed.v[neg][exp10 + kNearExponent]
                                : (neg ? -pow10_far(exp10) : pow10_far(exp10));
    return static_cast<double>(a * p10);
  }
  // rule 2: powers 10^0..10^300 only; beyond, the excess first
  long double r = a;
  int e = exp10;
  if (e < -300 || e > 300) {
    const int extra = e < 0 ? e + 300 : e - 300;
    r = extra < 0 ? r / pow10_far(-extra) : r * pow10_far(extra);
    e -= extra;
  }
  const int k = e < 0 ? -e : e;
  const long double p = k <= kNearExponent ? kPow10Near[k + kNearExponent] : pow10_far(k);
  r = e < 0 ? r / p : r * p;
  return static_cast<double>(neg ? -r : r);
}

// The correctly rounded value of (-)acc * 10^exp10 when one IEEE operation
// on exact operands gives it (Clinger's fast path: acc < 2^53, |exp10| <=
// 22); false otherwise. The sign rides on the power, as above.
constexpr double kExactSigned[2][23] = {
    {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
     1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22},
    {-1e0, -1e1, -1e2, -1e3, -1e4, -1e5, -1e6, -1e7, -1e8, -1e9, -1e10, -1e11,
     -1e12, -1e13, -1e14, -1e15, -1e16, -1e17, -1e18, -1e19, -1e20, -1e21, -1e22}};
GRAVCAL_CSV_INLINE bool exact_value(std::uint64_t acc, int exp10, bool neg, double& out) {
  if (acc >= (std::uint64_t(1) << 53) || exp10 < -22 || exp10 > 22) return false;
  const double a = static_cast<double>(acc);
  out = exp10 < 0 ? a / kExactSigned[neg][-exp10] : a * kExactSigned[neg][exp10];
  return true;
}

// The correctly rounded double of the unsigned decimal s[0, n) (digits,
// '.', an exponent; s[n] is '\0'), through strtod in the "C" locale. The C
// libraries R runs on round correctly (glibc, musl, macOS's, the BSDs',
// Windows' UCRT since 2015). As std::from_chars, a value beyond the
// double range fails (infinite; or 0 when `nonzero`, the decimal having a
// digit other than 0), and a subnormal one does not (strtod's ERANGE for it
// is ignored). False also when strtod does not take all of s.
inline bool decimal_to_double_strtod(const char* s, std::size_t n, bool nonzero, double& out) {
  char* end = nullptr;
  double v = 0;
#if defined(_WIN32)
  static const _locale_t c_locale = _create_locale(LC_ALL, "C");
  v = c_locale ? _strtod_l(s, &end, c_locale) : std::strtod(s, &end);
#else
  static const locale_t c_locale = newlocale(LC_ALL_MASK, "C", static_cast<locale_t>(0));
  // (newlocale() of "C" does not fail in practice; R keeps LC_NUMERIC "C")
  v = c_locale ? strtod_l(s, &end, c_locale) : std::strtod(s, &end);
#endif
  if (end != s + n) return false;
  if (std::isinf(v) || (v == 0 && nonzero)) return false;
  out = v;
  return true;
}

#if defined(GRAVCAL_HAVE_FROM_CHARS)
// The same through std::from_chars (no locale, no terminator needed).
inline bool decimal_to_double_from_chars(const char* s, std::size_t n, double& out) {
  double v = 0;
  const auto r = std::from_chars(s, s + n, v);
  if (r.ec != std::errc() || r.ptr != s + n) return false;
  out = v;
  return true;
}
#endif

// The correctly rounded double of s[0, n) as above: std::from_chars where
// the library has it, else strtod; the same bits and the same failures
// (tests/cpp/test_csv.cpp compares the two on every number it checks).
inline bool decimal_to_double(const char* s, std::size_t n, bool nonzero, double& out) {
#if defined(GRAVCAL_HAVE_FROM_CHARS)
  (void)nonzero;
  return decimal_to_double_from_chars(s, n, out);
#else
  return decimal_to_double_strtod(s, n, nonzero, out);
#endif
}

// A number in [b, e): [+-]digits[<dec>digits][(e|E)[+-]digits], the whole
// field. rule: a NumberRule (0: the correctly rounded value; 1, 2: fread's).
inline bool parse_number(const char* b, const char* e, char dec, int rule, double& out) {
  const char* p = b;
  if (p == e) return false;
  const bool neg = *p == '-';
  if (neg || *p == '+') ++p;
  const char* start = p;
  std::uint64_t acc = 0;
  int exp10 = 0, left = kMaxSigDigits;
  bool any = false;
  while (p < e && *p == '0') { ++p; any = true; }
  for (; p < e; ++p) {
    const unsigned d = digit_of(*p);
    if (d > 9) break;
    any = true;
    if (left > 0) { acc = acc * 10 + d; --left; }
    else ++exp10;
  }
  // fread: a longer integer without a decimal part is not a double
  if (exp10 > 0 && (p == e || (*p != dec && *p != 'e' && *p != 'E'))) return false;
  if (p < e && *p == dec) {
    ++p;
    if (acc == 0) {
      while (p < e && *p == '0') { ++p; --exp10; any = true; }
    }
    for (; p < e; ++p) {
      const unsigned d = digit_of(*p);
      if (d > 9) break;
      any = true;
      if (left > 0) { acc = acc * 10 + d; --left; --exp10; }
    }
  }
  if (!any) return false;
  const char* mant_end = p;
  if (p < e && (*p == 'e' || *p == 'E')) {
    ++p;
    const bool eneg = p < e && *p == '-';
    if (p < e && (*p == '-' || *p == '+')) ++p;
    int x = 0, nd = 0;
    for (; p < e && is_digit(*p) && nd < 3; ++p, ++nd) x = x * 10 + (*p - '0');
    if (nd == 0) return false;
    exp10 += eneg ? -x : x;
  }
  if (p != e) return false;
  if (exp10 < -kMaxExponent || exp10 > kMaxExponent) return false;
  if (rule != kCorrectlyRounded) {
    out = fread_value(acc, exp10, neg, rule);
    return true;
  }
  // correctly rounded: one IEEE operation when it is exact (the first
  // digit kept is not 0, so acc < 2^53 means fewer than 18 digits kept)...
  if (exact_value(acc, exp10, neg, out)) return true;
  // ...else the general conversion, which wants '.' and no sign
  char tmp[128];
  const std::size_t n = static_cast<std::size_t>(e - start);
  if (n >= sizeof tmp) return false;
  std::memcpy(tmp, start, n);
  tmp[n] = '\0';
  if (dec != '.') {
    const std::size_t d = static_cast<std::size_t>(mant_end - start);
    for (std::size_t i = 0; i < d; ++i) if (tmp[i] == dec) tmp[i] = '.';
  }
  double v = 0;
  if (!decimal_to_double(tmp, n, acc != 0, v)) return false;
  out = neg ? -v : v;
  return true;
}

// The shape nearly every number in a csv of samples has: [+-]digits
// [<dec>digits], 1 to kMaxSigDigits digits in all (leading zeros counted),
// so that parse_number keeps every digit: its acc is the digits read as one
// integer and its exp10 minus the count of digits after `dec`.
struct PlainNumber {
  std::uint64_t acc = 0;
  int frac = 0;  // digits after `dec`: exp10 is -frac
  bool neg = false;
};

// Reads a number of that shape at p and returns the byte after it, or
// nullptr when the text at p has another shape (then parse_number decides).
// The text must go on to a byte that is neither a digit nor `dec` (a line
// end): the scan stops there at the latest. Whether the number ends its
// field (the byte after it) is the caller's to check. Byte by byte, with
// branches: a number's length is predicted, so the next field's start does
// not wait for this one's bytes. Measured against the alternatives on a
// day of ad hoc csv (UNIX time, mg, temperature), an Axivity csv export
// and an ActiLife export: a scan of fixed offsets for D.DDD first was no
// faster (slower on 4 decimals, where it falls back to this loop); digits
// valued 8 at a time, each field's length known from separators found 64
// bytes at a time beforehand, took 1.1 to 1.2 times as long (more
// instructions than this loop on numbers of 4 or 5 digits).
GRAVCAL_CSV_INLINE const char* scan_plain_number(const char* p, char dec, PlainNumber& n) {
  n.neg = false;
  if (*p == '-') {
    n.neg = true;
    ++p;
  } else if (*p == '+') {
    ++p;
  }
  const char* const first = p;
  std::uint64_t acc = 0;
  for (unsigned d; (d = digit_of(*p)) <= 9; ++p) acc = acc * 10 + d;
  std::ptrdiff_t count = p - first, frac = 0;
  if (*p == dec) {
    const char* const f = ++p;
    for (unsigned d; (d = digit_of(*p)) <= 9; ++p) acc = acc * 10 + d;
    frac = p - f;
    count += frac;
  }
  // (acc wraps past 19 digits, but such a number is not taken)
  if (count < 1 || count > kMaxSigDigits) return nullptr;
  n.acc = acc;
  n.frac = static_cast<int>(frac);
  return p;
}

// The value parse_number gives for [b, e), the text scan_plain_number read
// as `n` (every digit kept, exp10 = -frac): fread_value() or exact_value(),
// as parse_number computes it, else parse_number itself.
GRAVCAL_CSV_INLINE bool plain_value(const PlainNumber& n, const char* b, const char* e, char dec,
                                    int rule, double& out) {
  if (rule != kCorrectlyRounded) {
    out = fread_value(n.acc, -n.frac, n.neg, rule);
    return true;
  }
  if (exact_value(n.acc, -n.frac, n.neg, out)) return true;
  return parse_number(b, e, dec, kCorrectlyRounded, out);
}

// 8 bytes at p as a word, byte 0 lowest (one load on a little-endian
// machine).
inline std::uint64_t load_le64(const char* p) {
  const unsigned char* b = reinterpret_cast<const unsigned char*>(p);
  return static_cast<std::uint64_t>(b[0]) | static_cast<std::uint64_t>(b[1]) << 8 |
         static_cast<std::uint64_t>(b[2]) << 16 | static_cast<std::uint64_t>(b[3]) << 24 |
         static_cast<std::uint64_t>(b[4]) << 32 | static_cast<std::uint64_t>(b[5]) << 40 |
         static_cast<std::uint64_t>(b[6]) << 48 | static_cast<std::uint64_t>(b[7]) << 56;
}

// The top bit of every byte of x that is 0, no other bit.
inline std::uint64_t zero_bytes(std::uint64_t x) {
  const std::uint64_t low7 = 0x7F7F7F7F7F7F7F7FULL;
  return ~(((x & low7) + low7) | x | low7);
}

// The index of the lowest byte flagged in m (top bits only, at least one).
inline int first_flagged(std::uint64_t m) {
#if defined(__GNUC__) || defined(__clang__)
  return __builtin_ctzll(m) >> 3;
#else
  int k = 0;
  for (; (m & 0x80) == 0; m >>= 8) ++k;
  return k;
#endif
}

// The first byte at or after p that is `sep` or '\n', one of which lies
// ahead; 8 bytes at a time, so it may read up to 7 bytes past it (the
// LineReader's kPad).
GRAVCAL_CSV_INLINE const char* field_end(const char* p, char sep) {
  const std::uint64_t ones = 0x0101010101010101ULL;
  const std::uint64_t s = ones * static_cast<unsigned char>(sep), nl = ones * '\n';
  for (;; p += 8) {
    const std::uint64_t w = load_le64(p);
    const std::uint64_t m = zero_bytes(w ^ s) | zero_bytes(w ^ nl);
    if (m != 0) return p + first_flagged(m);
  }
}

// The values of the numbers with 1 to 4 decimals whose digits are below
// 16384 (ActiLife writes up to 3 decimals of g, dropping trailing zeros;
// OMGUI's Axivity export 4; ad hoc files often 1 decimal of mg,
// temperatures 2), by their digits as one integer k:
// decimals(rule).value[f][k] is the value of k / 10^f by the NumberRule,
// for k < decimals().limit[f]. Computed once per process, on first use, by
// fread_value / exact_value, the functions parse_number uses (the four
// tables: 512 KiB a rule).
constexpr int kTableDecimals = 4;
// the integers k of each table: k / 10^f below 1.6384 for four decimals
// (g), 16.384 for three, 1638.4 and 163.84 for one and two (mg, degrees)
constexpr std::uint64_t kDecimalsLimit[kTableDecimals + 1] = {0, 16384, 16384, 16384, 16384};
struct Decimals {
  std::vector<double> table[kTableDecimals + 1];
  const double* value[kTableDecimals + 1] = {nullptr, nullptr, nullptr, nullptr, nullptr};
  std::uint64_t limit[kTableDecimals + 1] = {0, 0, 0, 0, 0};
};
inline Decimals decimals_values(int rule) {
  Decimals d;
  for (int f = kTableDecimals; f >= 1; --f) {
    const std::uint64_t lim = kDecimalsLimit[f];
    std::vector<double>& t = d.table[f];
    t.resize(lim);
    for (std::uint64_t k = 0; k < lim; ++k) {
      if (rule != kCorrectlyRounded) t[k] = fread_value(k, -f, false, rule);
      else exact_value(k, -f, false, t[k]);  // (exact for every k here)
    }
    d.value[f] = t.data();
    d.limit[f] = lim;
  }
  return d;
}
inline const Decimals& decimals(int rule) {
  if (rule == kFreadMultiply) {
    static const Decimals t = decimals_values(kFreadMultiply);
    return t;
  }
  if (rule == kFreadDivide) {
    static const Decimals t = decimals_values(kFreadDivide);
    return t;
  }
  static const Decimals t = decimals_values(kCorrectlyRounded);
  return t;
}

inline unsigned days_in_month(std::int64_t y, unsigned m) {
  static const unsigned k[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
  return m == 2 && leap ? 29 : k[m - 1];
}

// The order of a date's parts: month-day-year (ActiLife's M/d/yyyy, R's
// "%m/%d/%Y"), day-month-year (dd/MM/yyyy). Year-first dates (ISO) are
// recognised by their four-digit first part whatever the order says.
enum class DateOrder { mdy, dmy, ymd };

// The order an ActiLife "date format" names (letters M, d, y in some order).
inline DateOrder date_order_of(const std::string& fmt) {
  const std::size_t m = fmt.find('M'), d = fmt.find('d'), y = fmt.find('y');
  if (y != std::string::npos && (m == std::string::npos || y < m) &&
      (d == std::string::npos || y < d)) return DateOrder::ymd;
  if (d != std::string::npos && m != std::string::npos && d < m) return DateOrder::dmy;
  return DateOrder::mdy;
}

// Reads 1 to max_digits digits at p; false when there are none.
inline bool read_uint(const char*& p, const char* e, int max_digits, std::int64_t& v, int& nd) {
  v = 0;
  nd = 0;
  while (p < e && is_digit(*p) && nd < max_digits) { v = v * 10 + (*p - '0'); ++p; ++nd; }
  return nd > 0;
}

// A date (three numbers split by '/', '-' or '.') as days since 1970.
inline bool parse_date(const char*& p, const char* e, DateOrder order, std::int64_t& days) {
  std::int64_t v[3];
  int nd[3];
  for (int i = 0; i < 3; ++i) {
    if (i > 0) {
      if (p >= e || (*p != '/' && *p != '-' && *p != '.')) return false;
      ++p;
    }
    if (!read_uint(p, e, 4, v[i], nd[i])) return false;
  }
  std::int64_t y, m, d;
  if (nd[0] == 4) { y = v[0]; m = v[1]; d = v[2]; }
  else if (order == DateOrder::dmy) { d = v[0]; m = v[1]; y = v[2]; }
  else { m = v[0]; d = v[1]; y = v[2]; }
  if (nd[0] != 4 && nd[2] != 4) return false;
  if (m < 1 || m > 12 || d < 1 || d > days_in_month(y, static_cast<unsigned>(m))) return false;
  days = days_from_civil(y, static_cast<unsigned>(m), static_cast<unsigned>(d));
  return true;
}

// HH:MM:SS as whole seconds.
inline bool parse_hms(const char*& p, const char* e, std::int64_t& whole) {
  std::int64_t h, m, s;
  int nd;
  if (!read_uint(p, e, 2, h, nd) || p >= e || *p != ':') return false;
  ++p;
  if (!read_uint(p, e, 2, m, nd) || nd != 2 || p >= e || *p != ':') return false;
  ++p;
  if (!read_uint(p, e, 2, s, nd) || nd != 2) return false;
  if (h > 24 || m > 59 || s > 60) return false;
  whole = h * 3600 + m * 60 + s;
  return true;
}

// What may follow the seconds: [.fff...] (or GENEActiv-like ":fff"), its
// first 9 digits as an integer; frac_digits = 0 when there is none.
inline bool parse_fraction(const char*& p, const char* e, std::int64_t& frac, int& frac_digits) {
  frac = 0;
  frac_digits = 0;
  if (p < e && (*p == '.' || *p == ':')) {
    ++p;
    if (!read_uint(p, e, 9, frac, frac_digits)) return false;
    while (p < e && is_digit(*p)) ++p;
  }
  return true;
}

inline double clock_seconds(std::int64_t whole, std::int64_t frac, int frac_digits) {
  static const double scale[10] = {1, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9};
  return static_cast<double>(whole) + static_cast<double>(frac) / scale[frac_digits];
}

// HH:MM:SS[.fff...] as seconds; `frac_digits` tells the resolution.
inline bool parse_clock(const char*& p, const char* e, double& secs, int& frac_digits) {
  std::int64_t whole, frac;
  if (!parse_hms(p, e, whole) || !parse_fraction(p, e, frac, frac_digits)) return false;
  secs = clock_seconds(whole, frac, frac_digits);
  return true;
}

// Parses "<date>[ T]<clock>[Z]" into seconds since 1970 UTC (local times are
// taken as UTC, as gravcal's R readers do). Keeps the text of the last
// date and of the last date and time to the whole second, so that a file
// of one stamp per sample parses a date once a day and a time once a
// second: a stamp that starts with the same text has the same value to
// the second, whatever follows.
class DateTimeParser {
 public:
  explicit DateTimeParser(DateOrder order = DateOrder::mdy) : order_(order) {}
  void set_order(DateOrder o) {
    order_ = o;
    cached_len_ = 0;
    second_len_ = 0;
  }
  bool parse(const char* b, const char* e, double& t, int& frac_digits) {
    const std::size_t n = static_cast<std::size_t>(e - b);
    const char* p;
    std::int64_t days, whole;
    if (second_len_ > 0 && n >= second_len_ && std::memcmp(b, second_, second_len_) == 0) {
      p = b + second_len_;
      days = second_days_;
      whole = second_whole_;
    } else {
      const char* sp = b;
      while (sp < e && *sp != ' ' && *sp != 'T') ++sp;
      if (sp == e || sp - b > kMaxDate) return false;
      const std::size_t dl = static_cast<std::size_t>(sp - b);
      if (dl != cached_len_ || std::memcmp(b, cached_, dl) != 0) {
        p = b;
        if (!parse_date(p, sp, order_, days) || p != sp) return false;
        std::memcpy(cached_, b, dl);
        cached_len_ = dl;
        cached_days_ = days;
      }
      days = cached_days_;
      p = sp + 1;
      while (p < e && *p == ' ') ++p;
      if (!parse_hms(p, e, whole)) return false;
      if (p - b <= kMaxSecond) {
        second_len_ = static_cast<std::size_t>(p - b);
        std::memcpy(second_, b, second_len_);
        second_days_ = days;
        second_whole_ = whole;
      }
    }
    std::int64_t frac;
    if (!parse_fraction(p, e, frac, frac_digits)) return false;
    if (p < e && *p == 'Z') ++p;
    if (p != e) return false;
    t = static_cast<double>(days * 86400) + clock_seconds(whole, frac, frac_digits);
    return true;
  }

 private:
  static constexpr int kMaxDate = 24;
  static constexpr int kMaxSecond = 48;
  DateOrder order_;
  char cached_[kMaxDate];
  std::size_t cached_len_ = 0;
  std::int64_t cached_days_ = 0;
  char second_[kMaxSecond];  // the text of a date and time to the second
  std::size_t second_len_ = 0;
  std::int64_t second_days_ = 0, second_whole_ = 0;
};

// An integer as data.table::fread reads the parts of a date-time: an
// optional sign, any leading zeros, then at most 10 digits of a value at
// most 2^31 - 1; at least one character after the sign. Moves p past it.
inline bool fread_int32(const char*& p, const char* e, std::int64_t& v) {
  const char* q = p;
  const bool neg = q < e && *q == '-';
  if (q < e && (*q == '-' || *q == '+')) ++q;
  const char* const start = q;
  while (q < e && *q == '0') ++q;
  std::int64_t acc = 0;
  int nd = 0;
  for (; q < e && is_digit(*q); ++q, ++nd) {
    if (nd == 10) return false;
    acc = acc * 10 + (*q - '0');
  }
  if (q == start || acc > 2147483647) return false;
  v = neg ? -acc : acc;
  p = q;
  return true;
}

// A date-time as data.table::fread reads it into a POSIXct column
// (data.table 1.13.0 on, its default tz = "UTC"): the date as
// [+-]year-month-day (each part an fread integer, the day valid for the
// month), ' ' or 'T', hour (0-23) ':' minute (0-59) ':' seconds (an fread
// number, 0 to below 60, by `rule`), then nothing (taken as UTC), 'Z', or
// an optional blank and an offset: +hh:mm or +hh (fread takes minutes after
// the colon as they are, so -05:30 moves the time by -5 h and +30 min),
// +hhmm, and +h, +hhh (hours). The value is the whole seconds of the
// calendar less the offset, exact, plus the seconds: one rounding, as
// fread's 86400 * days + 3600 * (hour - offset hours) + 60 * (minute -
// offset minutes) + seconds. A file's stamps share their date and minute
// for many lines: the text up to the seconds is kept with its value, so
// the next stamp with the same start parses its seconds only.
class FreadDateTime {
 public:
  bool parse(const char* b, const char* e, int rule, double& t) {
    const std::size_t n = static_cast<std::size_t>(e - b);
    const char* p;
    std::int64_t minute_secs;
    if (prefix_len_ > 0 && n > prefix_len_ && std::memcmp(b, prefix_, prefix_len_) == 0) {
      p = b + prefix_len_;
      minute_secs = prefix_secs_;
    } else {
      p = b;
      if (!calendar_minute(p, e, minute_secs)) return false;
      const std::size_t len = static_cast<std::size_t>(p - b);
      if (len <= kMaxPrefix) {
        std::memcpy(prefix_, b, len);
        prefix_len_ = len;
        prefix_secs_ = minute_secs;
      }
    }
    // the seconds: [+-]digits[.digits][(e|E)[+-]digits], as fread scans them
    const char* s = p;
    if (p < e && (*p == '-' || *p == '+')) ++p;
    while (p < e && is_digit(*p)) ++p;
    if (p < e && *p == '.') {
      ++p;
      while (p < e && is_digit(*p)) ++p;
    }
    if (p < e && (*p == 'e' || *p == 'E')) {
      const char* x = p + 1;
      if (x < e && (*x == '-' || *x == '+')) ++x;
      int nd = 0;
      while (x < e && is_digit(*x) && nd < 3) { ++x; ++nd; }
      if (nd == 0) return false;
      p = x;
    }
    double sec;
    if (p == s || !parse_number(s, p, '.', rule, sec) || sec < 0 || sec >= 60) return false;
    std::int64_t zone_secs = 0;
    if (p < e && *p == 'Z') {
      ++p;
    } else if (p < e) {
      if (*p == ' ') ++p;
      if (p >= e || (*p != '+' && *p != '-')) return false;
      const char* const start = p;
      std::int64_t hh, mm = 0;
      if (!fread_int32(p, e, hh)) return false;
      const std::ptrdiff_t len = p - start;
      if (len == 5 && hh != 0) {
        if (hh > 2400 || hh < -2400) return false;
        mm = hh % 100;
        hh /= 100;
      } else if (len == 3) {
        if (hh > 24 || hh < -24) return false;
        if (p < e && *p == ':') {
          ++p;
          if (!fread_int32(p, e, mm)) return false;
        }
      }
      zone_secs = 3600 * hh + 60 * mm;
    }
    if (p != e) return false;
    t = static_cast<double>(minute_secs - zone_secs) + sec;
    return true;
  }

 private:
  // "<date>[ T]hh:mm:" as seconds since 1970 (the calendar read as UTC).
  static bool calendar_minute(const char*& p, const char* e, std::int64_t& secs) {
    std::int64_t y, m, d, hh, mi;
    if (!fread_int32(p, e, y) || y < 1 || p >= e || *p++ != '-') return false;
    if (!fread_int32(p, e, m) || m < 1 || m > 12 || p >= e || *p++ != '-') return false;
    if (!fread_int32(p, e, d) || d < 1 ||
        d > days_in_month(y, static_cast<unsigned>(m))) return false;
    if (p >= e || (*p != ' ' && *p != 'T')) return false;
    ++p;
    if (!fread_int32(p, e, hh) || hh < 0 || hh > 23 || p >= e || *p++ != ':') return false;
    if (!fread_int32(p, e, mi) || mi < 0 || mi > 59 || p >= e || *p++ != ':') return false;
    secs = days_from_civil(y, static_cast<unsigned>(m), static_cast<unsigned>(d)) * 86400 +
           hh * 3600 + mi * 60;
    return true;
  }

  static constexpr std::size_t kMaxPrefix = 40;
  char prefix_[kMaxPrefix];
  std::size_t prefix_len_ = 0;
  std::int64_t prefix_secs_ = 0;
};

// A field of a line: trimmed of blanks and of one pair of double quotes.
struct Field {
  const char* b;
  const char* e;
};

inline void trim(const char*& b, const char*& e) {
  while (b < e && (*b == ' ' || *b == '\t')) ++b;
  while (e > b && (e[-1] == ' ' || e[-1] == '\t')) --e;
  if (e - b >= 2 && *b == '"' && e[-1] == '"') {
    ++b;
    --e;
    while (b < e && (*b == ' ' || *b == '\t')) ++b;
    while (e > b && (e[-1] == ' ' || e[-1] == '\t')) --e;
  }
}

// The field [b, e) of a line, trimmed.
inline Field field_of(const char* b, const char* e) {
  if (b < e && (*b == ' ' || *b == '\t' || *b == '"' || e[-1] == ' ' || e[-1] == '\t' ||
                e[-1] == '"')) {
    trim(b, e);
  }
  return Field{b, e};
}

// Splits [p, p + n) at `sep` into at most max_fields fields; returns the
// number of fields the line has (which may be more than max_fields).
inline int split(const char* p, std::size_t n, char sep, Field* f, int max_fields) {
  const char* e = p + n;
  int k = 0;
  const char* b = p;
  for (;;) {
    const char* fe = b;
    while (fe < e && *fe != sep) ++fe;  // fields are short: no memchr call
    if (k < max_fields) f[k] = field_of(b, fe);
    ++k;
    if (fe == e) break;
    b = fe + 1;
  }
  return k;
}

// A short printable excerpt of a line, for notes.
inline std::string excerpt(const char* p, std::size_t n) {
  constexpr std::size_t kShown = 40;
  std::string s;
  for (std::size_t i = 0; i < n && i < kShown; ++i) {
    const unsigned char c = static_cast<unsigned char>(p[i]);
    s += (c >= 32 && c < 127) ? static_cast<char>(c) : '?';
  }
  if (n > kShown) s += "...";
  return s;
}

// R's signif(x, digits) for x > 0 (as its fprec does), for sf from time.
inline double signif(double x, int digits) {
  if (!(x > 0) || !std::isfinite(x)) return x;
  const int e10 = digits - 1 - static_cast<int>(std::floor(std::log10(x)));
  if (e10 > 0) {
    const double p10 = std::pow(10.0, e10);
    return std::nearbyint(x * p10) / p10;
  }
  const double p10 = std::pow(10.0, -e10);
  return std::nearbyint(x / p10) * p10;
}

}  // namespace csv_text
}  // namespace gravcal

#endif  // GRAVCAL_DECODE_CSV_TEXT_HPP
