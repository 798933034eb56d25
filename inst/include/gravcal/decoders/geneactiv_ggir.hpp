// gravcal: how GGIRread's GENEActiv reader reads the text of a damaged
// page, rule by rule (decode_geneactiv.hpp's GGIR-compatible mode uses
// them; gravcal's own mode does not).
//
// GGIRread's GENEActivReader (C++, built with the R it runs in) reads a page
// as ten lines, whatever they hold, with std::getline. Of the eight page
// header lines it reads two values, each as a std::stringstream of the
// line on which everything up to the first ':' is ignored and a double is
// then extracted: "Temperature:" (the fifth) and "Measurement Frequency:"
// (the eighth). It cuts the hex line into samples of 12 characters and
// each sample into four groups of 3, each read by std::stoll(group,
// nullptr, 16). The rules below are those of GCC's standard library
// (libstdc++: the R of Linux and of Rtools on Windows) and of the C
// library's strtoll/strtod.
//
// A value line (read_field()):
// * no ':', or nothing but blanks after it: the extraction fails before it
//   starts and the value keeps what it had (keep);
// * otherwise the characters a number is made of are taken as num_get
//   takes them (a sign, digits, one '.', an exponent after a digit, with
//   its sign) and converted by strtod: the number they make, 0 when they
//   do not make one ("2x.5" gives 2, "abc" 0, "1e" 0), the largest double
//   for one too large.
//
// The hex line (read_hex_line()): samples start every 12 characters while
// the start is before the line's length less one (the line with its '\r',
// for a CRLF file); a group starts 3 characters after the one before, is
// at most 3 characters long (fewer at the line's end) and reads as strtoll
// in base 16 reads it: blanks skipped, a sign, a "0x" before a hex digit,
// then the hex digits as far as they go ("1G2" is 1, " -F" is -15). A
// group that starts past the line's end, or holds no digit, ends the page:
// its sample and every one after it are lost. A sample's x, y and z are
// their groups' values, 2048 and above less 4096; its light the fourth
// group's value over 4 (an integer, towards zero).
#ifndef GRAVCAL_GENEACTIV_GGIR_HPP
#define GRAVCAL_GENEACTIV_GGIR_HPP

#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

namespace gravcal {
namespace geneactiv {

// isspace() in the C locale
inline bool c_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
}

inline int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

// What reading a value line gives: a value, the value kept from before, or
// (a line known only in part: cut by the line reader) not known.
struct FieldRead {
  enum Kind { value, keep, unknown };
  Kind kind = keep;
  double v = 0;
  static FieldRead of(double x) {
    FieldRead r;
    r.kind = value;
    r.v = x;
    return r;
  }
  static FieldRead kept() { return FieldRead(); }
  static FieldRead not_known() {
    FieldRead r;
    r.kind = unknown;
    return r;
  }
};

// The line p[0, n) as GGIRread reads a value from it (see the top). whole:
// the line is all there; false for the first n bytes of a longer one.
inline FieldRead read_field(const char* p, std::size_t n, bool whole) {
  const char* end = p + n;
  const char* colon = static_cast<const char*>(std::memchr(p, ':', n));
  if (colon == nullptr) return whole ? FieldRead::kept() : FieldRead::not_known();
  const char* q = colon + 1;
  while (q < end && c_space(*q)) ++q;
  if (q == end) return whole ? FieldRead::kept() : FieldRead::not_known();
  std::string taken;  // what num_get takes, for strtod
  if (*q == '+' || *q == '-') taken += *q++;
  bool mantissa = false;
  while (q < end && *q == '0') {  // leading zeros: one is kept
    if (!mantissa) taken += '0';
    mantissa = true;
    ++q;
  }
  bool dot = false, exponent = false;
  while (q < end) {
    const char c = *q;
    if (c >= '0' && c <= '9') {
      taken += c;
      mantissa = true;
    } else if (c == '.' && !dot && !exponent) {
      taken += '.';
      dot = true;
    } else if ((c == 'e' || c == 'E') && !exponent && mantissa) {
      taken += 'e';
      exponent = true;
      if (q + 1 < end && (q[1] == '+' || q[1] == '-')) taken += *++q;
    } else {
      break;
    }
    ++q;
  }
  if (q == end && !whole) return FieldRead::not_known();  // the number may go on
  char* stop = nullptr;
  const double v = std::strtod(taken.c_str(), &stop);
  if (taken.empty() || stop != taken.c_str() + taken.size()) return FieldRead::of(0.0);
  if (std::isinf(v)) return FieldRead::of(v > 0 ? DBL_MAX : -DBL_MAX);
  return FieldRead::of(v);
}

// A group of len (at most 3) characters as strtoll in base 16 reads it;
// false when it holds no digit.
inline bool read_group(const char* s, std::size_t len, int& v) {
  std::size_t i = 0;
  while (i < len && c_space(s[i])) ++i;
  bool negative = false;
  if (i < len && (s[i] == '+' || s[i] == '-')) negative = s[i++] == '-';
  if (i + 1 < len && s[i] == '0' && (s[i + 1] == 'x' || s[i + 1] == 'X')) {
    if (i + 2 < len && hex_digit(s[i + 2]) >= 0) {
      i += 2;
    } else {
      // "0x" with no hex digit after it: C libraries differ. glibc's
      // strtoll reads the 0 and stops at the x; Microsoft's C runtime (as
      // Wine's, where the Windows build's tests run) reads nothing, so that
      // GGIRread's std::stoll throws there. GGIRread's reader is built with
      // the toolchain R's packages are built with, as gravcal is: ask the
      // same strtoll (only here: it is rare, and a call per group would
      // cost seconds a week).
      char buf[4] = {0, 0, 0, 0};
      std::memcpy(buf, s, len);
      char* stop = nullptr;
      static_cast<void>(std::strtoll(buf, &stop, 16));
      if (stop == buf) return false;
      v = 0;  // the 0 before the x, signed or not
      return true;
    }
  }
  int value = 0;
  std::size_t digits = 0;
  for (; i < len; ++i) {
    const int d = hex_digit(s[i]);
    if (d < 0) break;
    value = value * 16 + d;
    ++digits;
  }
  if (digits == 0) return false;
  v = negative ? -value : value;
  return true;
}

// What read_hex_line() found.
struct HexRead {
  std::size_t count = 0;  // samples read
  bool unknown = false;   // a sample needs bytes past those known
  bool full = false;      // more samples than `cap`
  bool all_read = true;   // no group ended the page before the line's end
};

// A hex line as GGIRread reads it (see the top): `size` characters at p
// (with the '\r' of a CRLF line), of which `known` are there (known <
// size: a line the line reader cut; its size is then not known either).
// At most `cap` samples: their counts (12-bit, as stored) into raw, and
// their light values into light.
inline HexRead read_hex_line(const char* p, std::size_t size, std::size_t known,
                             bool size_known, std::size_t cap, std::uint16_t (*raw)[3],
                             std::int16_t* light) {
  HexRead r;
  if (size_known && size == 0) {  // the first group is empty
    r.all_read = false;
    return r;
  }
  for (std::size_t at = 0;; at += 12) {
    if (size_known ? at + 1 >= size : at + 1 >= known) {
      r.unknown = !size_known;
      break;
    }
    int v[4];
    bool ok = true;
    for (std::size_t a = 0; a < 4 && ok; ++a) {
      const std::size_t pos = at + 3 * a;
      std::size_t len = 3;
      if (size_known) {
        if (pos > size) {  // std::string::substr() throws
          ok = false;
          break;
        }
        if (size - pos < len) len = size - pos;
      } else if (pos + len > known) {
        r.unknown = true;
        return r;
      }
      ok = read_group(p + pos, len, v[a]);
    }
    if (!ok) {
      r.all_read = false;
      break;
    }
    if (r.count == cap) {
      r.full = true;
      break;
    }
    for (int a = 0; a < 3; ++a) {
      raw[r.count][a] = static_cast<std::uint16_t>((v[a] + 4096) & 0xFFF);
    }
    light[r.count] = static_cast<std::int16_t>(v[3] / 4);
    ++r.count;
  }
  return r;
}

}  // namespace geneactiv
}  // namespace gravcal

#endif  // GRAVCAL_GENEACTIV_GGIR_HPP
