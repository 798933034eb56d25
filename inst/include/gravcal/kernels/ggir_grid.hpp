// gravcal kernels: GGIR's grid walk, written once.
//
// GGIR puts irregular samples onto a regular grid the way
// GGIRread::resample() does: grid point k, at time g, lies in the first
// interval (t0, t1] of raw times with t1 >= g, and takes the value
// u (v1 - v0) + v0 with the weight u = (g - t0) / (t1 - t0); with GGIR's
// interpolationType = 2 (nearest neighbour) u becomes
// ggir_nearest_weight(u) first. The decoders that do this (the GGIR
// resampler, Parmay, Movisens) differ only in rules, which are the
// parameters of GridWalk here:
// - where grid point k lies (the Grid): RegularGrid, origin + k by (the
//   resampler and Parmay); PositionGrid, R's seq(1, m, length.out = n)
//   with its ends exact (Movisens's temperature, whose raw "times" are the
//   sample positions 1, 2, ...); CappedGrid, min(start + k step, end) with
//   the product rounded on its own (the cwa kernel's);
// - how the weight is computed (the Weight): UnclampedWeight, the division
//   as it comes (the resampler, the cwa kernel); ClampedWeight, 0 outside
//   [0, 1] (Parmay, as GGIRread's readParmayMatrix() resamples); UnitWeight,
//   g - t0 (Movisens: its intervals are exactly one position long, and a
//   division by 1 is exact, so GGIRread's weight is g - t0 to the bit);
// - nearest neighbour or linear, and whether the multiply-add is fused
//   (the Interp): chosen at run time (Interp) or fixed at compile time
//   (InterpAs<nearest, fused>) where a decoder's loop is specialised.
// What each decoder keeps for itself is what is not the walk: where its
// raw intervals come from (a stream one sample at a time, a search over
// positions), and what it does with a point (hold it until the grid is
// known to reach beyond it, keep the grid's last or drop it).
//
// Who uses what: the resampler (decode_ggir_resample.hpp), Movisens's
// temperature (decode_movisens.hpp) and Parmay's point-by-point path
// (ParmayDecoder::next_points()) step the grid with GridWalk::through().
// Two hot loops take the walk's grid, weight and interpolation but step
// the grid themselves, each for a measured reason given where it is:
// Parmay's run() (through() and its lambdas cost it about 10% more
// instructions) and the cwa kernel's scalar reference (kernels/decode.hpp,
// cwa_interp_scalar: it searches the interval afresh for every point, the
// loop its AVX2 twin follows lane by lane and calls one point at a time).
//
// Header-only, standard headers only.
#ifndef GRAVCAL_KERNELS_GGIR_GRID_HPP
#define GRAVCAL_KERNELS_GGIR_GRID_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cmath>
#include <cstdint>

// Marks the functions a walk calls for each grid point (the callers'
// lambdas): inlined into the walk's loop, so that the caller's state stays
// in registers (GCC's heuristics leave a large lambda out of line).
#if defined(__GNUC__) || defined(__clang__)
#define GRAVCAL_GRID_POINT __attribute__((always_inline))
#else
#define GRAVCAL_GRID_POINT
#endif

namespace gravcal {

// GGIR's nearest-neighbour resampling (interpolationType = 2, as
// GGIRread::resample computes it): the weight u of a grid point between two
// samples becomes 0 up to u = 0.5 and 1 beyond (0 outside [0, 1]); the value
// is then computed as the linear one, w * (right - left) + left.
inline double ggir_nearest_weight(double u) {
  if (u < 0 || u > 1) u = 0;
  return std::ceil(u - 0.5);
}

namespace kernels {

// The replay's one deliberate fused multiply-add, a * b + c rounded once
// (std::fma), kept out of line: wherever it is called, the instruction the
// target has for it sits in this function alone, which tools/fma-count.sh
// counts apart from contractions (a build with -march=native would
// otherwise inline it into every caller).
#if defined(__GNUC__)
__attribute__((noinline))
#endif
inline double replay_fma(double a, double b, double c) {
  return std::fma(a, b, c);
}

// GGIRread's w (v1 - v0) + v0, rounded twice (R's compiler did not contract
// it) or once (it did).
inline double ggir_lerp(double w, double v0, double v1, bool fused) {
  const double d = v1 - v0;
  return fused ? replay_fma(w, d, v0) : w * d + v0;  // not contracted: fp_contract.hpp
}

// ---- where grid point k lies

// origin + k by: the grid of R's seq(origin, by = by). k is the caller's
// counter (an integer, or a double that counts whole numbers), made a
// double as the decoders always did.
struct RegularGrid {
  double origin = 0, by = 0;
  template <class K>
  double at(K k) const {
    return origin + static_cast<double>(k) * by;
  }
};

// R's seq(1, m, length.out = n) as positions: 1 + q by (by = (m - 1) /
// (n - 1)) with its ends exact, 1 at q = 0 and m at q = last = n - 1.
struct PositionGrid {
  double m = 1, by = 0;
  std::int64_t last = 0;
  double at(std::int64_t q) const {
    return q == 0 ? 1.0 : q == last ? m : 1 + static_cast<double>(q) * by;
  }
};

// min(start + p step, end), the product rounded before the sum (volatile:
// never one fused multiply-add, whatever the flags): the cwa kernel's grid,
// which GGIRread caps at the block's end.
struct CappedGrid {
  double start = 0, step = 0, end = 0;
  double at(std::int64_t p) const {
    volatile double e = static_cast<double>(p) * step;  // no fused multiply-add
    const double t = start + e;
    return t < end ? t : end;
  }
};

// ---- the weight of grid time g in the interval (t0, t1]

// (g - t0) / (t1 - t0) as it comes.
struct UnclampedWeight {
  static double of(double g, double t0, double t1) { return (g - t0) / (t1 - t0); }
};

// (g - t0) / (t1 - t0), 0 outside [0, 1].
struct ClampedWeight {
  static double of(double g, double t0, double t1) {
    double u = (g - t0) / (t1 - t0);
    if (u < 0 || u > 1) u = 0;
    return u;
  }
};

// g - t0: intervals one long (t1 - t0 exactly 1).
struct UnitWeight {
  static double of(double g, double t0, double) { return g - t0; }
};

// ---- nearest neighbour or linear, fused or not

// chosen at run time
struct Interp {
  bool nearest = false;  // GGIR's interpolationType = 2
  bool fused = false;    // GGIRread's multiply-add rounded once
};

// fixed at compile time (a loop specialised for each)
template <bool Nearest, bool Fused>
struct InterpAs {
  static constexpr bool nearest = Nearest;
  static constexpr bool fused = Fused;
};

// The walk: a grid, a weight rule and an interpolation rule.
template <class Grid, class Weight, class In = Interp>
struct GridWalk {
  Grid grid;
  In interp;

  // The weight of grid time g in (t0, t1], nearest neighbour's where asked.
  double weight(double g, double t0, double t1) const {
    double u = Weight::of(g, t0, t1);
    if (interp.nearest) u = ggir_nearest_weight(u);
    return u;
  }

  // The value at weight u between v0 and v1.
  double value(double u, double v0, double v1) const {
    return ggir_lerp(u, v0, v1, interp.fused);
  }

  // Steps the counter k over the grid points of the interval that ends at
  // t1 (those with grid.at(k) <= t1), while more(k) holds: point(k, g) for
  // each, which returns false to leave that point untaken (k stays at it)
  // and stop. True when the walk reached a point beyond t1 (the interval
  // has no more; k is that point); false when more() or point() stopped it.
  template <class K, class More, class Point>
  bool through(K& k, double t1, More&& more, Point&& point) const {
    while (more(k)) {
      const double g = grid.at(k);
      if (!(g <= t1)) return true;
      if (!point(k, g)) return false;
      k += 1;
    }
    return false;
  }
};

}  // namespace kernels
}  // namespace gravcal

#endif  // GRAVCAL_KERNELS_GGIR_GRID_HPP
