// gravcal: fixed-point number types for the templated core, so that the
// lightweight method runs on microcontrollers without a floating-point unit
// (Farago, Maczak & Gingl 2024 ran it in 32-bit and 16-bit fixed point on an
// ATmega328 and a Cortex-M3).
//
// Fixed<Int, Wide, Frac> stores x as the integer round(x * 2^Frac) in Int;
// products and quotients are formed in the wider integer Wide, then rounded
// and saturated back to Int's range, so an overflow clips at the largest
// representable value instead of wrapping around. Sums saturate too.
//
// The two types the core is built and tested with:
//   fixed32 = Q3.29 in int32_t (int64_t intermediates): range [-4, 4),
//             resolution 1.9e-9; finite-difference step h = 1e-5.
//   fixed16 = Q1.14 in int16_t (int32_t intermediates): range [-2, 2),
//             resolution 6.1e-5; h = 0.01, as the paper's 16-bit version.
//             Rest vectors (within 1.3 g) and squared norms (within 1.7)
//             fit; Q3.12 (range 8) loses two bits of resolution for nothing,
//             and its errors on the paper's simulation were about 15 %
//             larger. Raw sensor data beyond +-2 g saturate, which only
//             movement, never rest, produces.
// Why not Q16.16 for 32 bits: its resolution (1.5e-5) is coarser than the
// paper's step h = 1e-5, and the objective changes by about |gradient| * h
// (a few 1e-6) over one step, below one unit of Q16.16: the forward
// differences would be noise. Calibration needs fraction bits, not integer
// range: rest vectors are within 1.3 g, squared norms within 2, the
// objective (a mean of squared residuals) well below 1.
//
// Header-only, standard headers only, no heap, no floating point at run time
// except in from_double()/to_double(), which the host side (R, tests) uses to
// exchange values; firmware gives its constants through from_raw() or
// constant expressions.
#ifndef GRAVCAL_FIXED_POINT_HPP
#define GRAVCAL_FIXED_POINT_HPP

#include <cstdint>
#include <limits>
#include <type_traits>

namespace gravcal {

template <typename Int, typename Wide, int Frac>
struct Fixed {
  static_assert(sizeof(Wide) >= 2 * sizeof(Int), "Wide must hold a product");
  static_assert(Frac > 0 && Frac < 8 * static_cast<int>(sizeof(Int)) - 1,
                "Frac out of range");
  using raw_type = Int;
  using wide_type = Wide;
  static constexpr int frac_bits = Frac;
  static constexpr Wide one = Wide(1) << Frac;
  static constexpr Wide max_raw = std::numeric_limits<Int>::max();
  static constexpr Wide min_raw = std::numeric_limits<Int>::min();

  Int raw;

  constexpr Fixed() : raw(0) {}
  // From a double: rounded to nearest (ties away from zero), saturated.
  // Implicit, so that the core's T(0.3), T(1e-5) read naturally.
  constexpr Fixed(double d) : raw(from_double_raw(d)) {}  // NOLINT
  constexpr Fixed(int i) : raw(saturate(Wide(i) * one)) {}  // NOLINT

  static constexpr Fixed from_raw(Wide r) {
    Fixed f;
    f.raw = saturate(r);
    return f;
  }
  constexpr double to_double() const {
    return static_cast<double>(raw) / static_cast<double>(one);
  }

  explicit constexpr operator double() const { return to_double(); }

  static constexpr Int saturate(Wide r) {
    return static_cast<Int>(r > max_raw ? max_raw : (r < min_raw ? min_raw : r));
  }
  static constexpr Int from_double_raw(double d) {
    // NaN maps to 0; the range check comes before the conversion to Wide
    return !(d == d) ? Int(0)
           : d * static_cast<double>(one) >= static_cast<double>(max_raw)
               ? static_cast<Int>(max_raw)
           : d * static_cast<double>(one) <= static_cast<double>(min_raw)
               ? static_cast<Int>(min_raw)
               : static_cast<Int>(static_cast<Wide>(
                     d * static_cast<double>(one) + (d < 0 ? -0.5 : 0.5)));
  }

  friend constexpr Fixed operator+(Fixed a, Fixed b) {
    return from_raw(Wide(a.raw) + Wide(b.raw));
  }
  friend constexpr Fixed operator-(Fixed a, Fixed b) {
    return from_raw(Wide(a.raw) - Wide(b.raw));
  }
  friend constexpr Fixed operator-(Fixed a) { return from_raw(-Wide(a.raw)); }
  // Product rounded to nearest: (a b + 2^(Frac-1)) / 2^Frac, with an
  // arithmetic shift (floor), so ties round up.
  friend constexpr Fixed operator*(Fixed a, Fixed b) {
    return from_raw((Wide(a.raw) * Wide(b.raw) + (Wide(1) << (Frac - 1))) >> Frac);
  }
  // Quotient truncated toward zero; division by zero saturates by sign.
  friend constexpr Fixed operator/(Fixed a, Fixed b) {
    return b.raw == 0 ? from_raw(a.raw >= 0 ? max_raw : min_raw)
                      : from_raw((Wide(a.raw) * one) / Wide(b.raw));
  }
  friend constexpr bool operator<(Fixed a, Fixed b) { return a.raw < b.raw; }
  friend constexpr bool operator>(Fixed a, Fixed b) { return a.raw > b.raw; }
  friend constexpr bool operator<=(Fixed a, Fixed b) { return a.raw <= b.raw; }
  friend constexpr bool operator>=(Fixed a, Fixed b) { return a.raw >= b.raw; }
  friend constexpr bool operator==(Fixed a, Fixed b) { return a.raw == b.raw; }
  friend constexpr bool operator!=(Fixed a, Fixed b) { return a.raw != b.raw; }
};

// Integer helpers on the wide type, for code that keeps its own scaling in
// raw integers (the analytic gradient, gradient_analytic.hpp). Saturation is
// symmetric, to [-max, max], so that |x| of a saturated value never
// overflows. Right shifts of negative values are arithmetic (floor), as the
// products above already assume.
namespace fx {

template <typename W>
constexpr W top() {
  return std::numeric_limits<W>::max();
}

// a + b, saturated to [-max, max] (a and b within that range).
template <typename W>
inline W sat_add(W a, W b) {
  if (b > 0 && a > top<W>() - b) return top<W>();
  if (b < 0 && a < -top<W>() - b) return -top<W>();
  return a + b;
}

template <typename W>
inline W clamp(W v, W lo, W hi) {
  return v < lo ? lo : (v > hi ? hi : v);
}

template <typename W>
inline W abs(W v) {
  return v < 0 ? -v : v;
}

// v / 2^s rounded to nearest, ties up (s >= 0), without forming v + 2^(s-1).
template <typename W>
inline W round_shift(W v, int s) {
  return s <= 0 ? v : (v >> s) + ((v >> (s - 1)) & W(1));
}

// v * 2^s (s >= 0), saturated.
template <typename W>
inline W sat_shl(W v, int s) {
  if (v == 0 || s <= 0) return v;
  if (s >= 8 * static_cast<int>(sizeof(W)) - 1) return v > 0 ? top<W>() : -top<W>();
  const W lim = top<W>() >> s;
  if (v > lim) return top<W>();
  if (v < -lim) return -top<W>();
  return v * (W(1) << s);
}

// v * 2^s for any sign of s: rounded when s < 0, saturated when s > 0.
template <typename W>
inline W scale2(W v, int s) {
  return s >= 0 ? sat_shl(v, s) : round_shift(v, -s);
}

// v / d rounded to nearest (ties away from zero), d > 0.
template <typename W>
inline W round_div(W v, W d) {
  const W a = abs(v);
  const W q = a / d + ((a % d) >= d - (a % d) ? W(1) : W(0));
  return v < 0 ? -q : q;
}

// v * 2^k / d truncated toward zero and saturated, d > 0 and
// d < 2^(bits - 1 - k), by long division: the remainder times 2^k fits.
template <typename W>
inline W div_shift(W v, W d, int k) {
  const W a = abs(v);
  const W q = sat_add(sat_shl(a / d, k), ((a % d) * (W(1) << k)) / d);
  return v < 0 ? -q : q;
}

// Number of bits of v >= 0 (0 for 0).
template <typename W>
inline int bit_length(W v) {
  int b = 0;
  while (v > 0) {
    v >>= 1;
    ++b;
  }
  return b;
}

// floor(sqrt(n)), by bits.
template <typename U>
inline U isqrt(U n) {
  static_assert(!std::numeric_limits<U>::is_signed, "isqrt takes an unsigned type");
  U r = 0;
  U bit = U(1) << (8 * sizeof(U) - 2);
  while (bit > n) bit >>= 2;
  while (bit != 0) {
    if (n >= r + bit) {
      n -= r + bit;
      r = (r >> 1) + bit;
    } else {
      r >>= 1;
    }
    bit >>= 2;
  }
  return r;
}

}  // namespace fx

// Square root, for the objective's optional use_sqrt form (the paper leaves
// it out): the integer square root of raw * 2^Frac, by bits, rounded down.
template <typename Int, typename Wide, int Frac>
inline Fixed<Int, Wide, Frac> sqrt(Fixed<Int, Wide, Frac> a) {
  using F = Fixed<Int, Wide, Frac>;
  if (a.raw <= 0) return F();
  using U = typename std::make_unsigned<Wide>::type;
  return F::from_raw(static_cast<Wide>(fx::isqrt(static_cast<U>(Wide(a.raw)) << Frac)));
}

// A value divided by a count (the mean over points), without representing
// the count itself, which may be out of range (18 > 8 for fixed16).
template <typename Int, typename Wide, int Frac>
inline Fixed<Int, Wide, Frac> divide_by_count(Fixed<Int, Wide, Frac> a, int n) {
  return Fixed<Int, Wide, Frac>::from_raw(Wide(a.raw) / Wide(n));
}

using fixed32 = Fixed<std::int32_t, std::int64_t, 29>;
using fixed16 = Fixed<std::int16_t, std::int32_t, 14>;

// The paper's finite-difference steps per arithmetic.
template <typename T>
struct default_step {
  static constexpr double value = 1e-5;
};
template <>
struct default_step<fixed16> {
  static constexpr double value = 0.01;
};

}  // namespace gravcal

#endif  // GRAVCAL_FIXED_POINT_HPP
