// libFuzzer harness: the bin selector offered arbitrary points (NaN and
// infinities included) with arbitrary settings. Checks its invariants: no
// bin over its cap, every kept point in the bin it counts for and at least
// min_distance from every other kept point, counts summing to the points.
#include <cmath>
#include <type_traits>

#include "fuzz_input.hpp"
#include "gravcal/mcu/bins.hpp"
#include "gravcal/mcu/fixed_point.hpp"

// The resolution of T: the selector squares and sums differences in T, so
// each of the three squares and the squared threshold can be off by about
// one unit in the last place (Q1.14: 6.1e-5, which at a min_distance of
// 0.01 is more than half of min_distance squared).
template <typename T>
static double resolution() {
  if constexpr (std::is_floating_point_v<T>) {
    return 1e-12;
  } else {
    return std::ldexp(1.0, -T::frac_bits);
  }
}

template <typename T>
static void run(FuzzInput in, const gravcal::BinConfig& cfg) {
  gravcal::BinSelector<T, 90> sel(cfg);
  if (!sel.valid()) return;
  while (!in.empty()) {
    const double x = in.sample(), y = in.sample(), z = in.sample();
    const int r = sel.offer(gravcal::Vec3<T>{T(x), T(y), T(z)});
    if (r < gravcal::BIN_TOO_CLOSE || r > 8) __builtin_trap();
  }
  int total = 0;
  for (int b = 0; b < 9; ++b) {
    if (sel.count(b) < 0 || sel.count(b) > cfg.max_per_bin) __builtin_trap();
    total += sel.count(b);
  }
  if (total != sel.size()) __builtin_trap();
  const double md = cfg.min_distance;
  for (int i = 0; i < sel.size(); ++i) {
    const gravcal::Vec3<T> p = sel.point(i);
    const double c[3] = {static_cast<double>(p.x), static_cast<double>(p.y),
                         static_cast<double>(p.z)};
    const int b = sel.bin(i);
    const int axis = b / 3, j = b % 3;
    if (sel.subset_of(p.x) != j && axis == 0) __builtin_trap();
    if (sel.subset_of(p.y) != j && axis == 1) __builtin_trap();
    if (sel.subset_of(p.z) != j && axis == 2) __builtin_trap();
    for (int k = 0; k < i; ++k) {
      const gravcal::Vec3<T> q = sel.point(k);
      const double d[3] = {c[0] - static_cast<double>(q.x), c[1] - static_cast<double>(q.y),
                           c[2] - static_cast<double>(q.z)};
      // the selector compares squared distances in T; allow T's rounding of
      // the three squares, the threshold and the points themselves
      const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      const double tol = 8 * resolution<T>() + 1e-9;
      if (d2 < md * md - tol) __builtin_trap();
    }
  }
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in{data, size};
  gravcal::BinConfig cfg;
  cfg.max_per_bin = 1 + in.byte() % 10;
  cfg.min_per_bin = 1 + in.byte() % cfg.max_per_bin;
  cfg.min_distance = (in.byte() % 64) / 100.0;
  const int type = in.byte() % 3;
  if (type == 0) run<double>(in, cfg);
  else if (type == 1) run<gravcal::fixed32>(in, cfg);
  else run<gravcal::fixed16>(in, cfg);
  return 0;
}
