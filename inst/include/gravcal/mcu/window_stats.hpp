// gravcal: what a window is, and the rules that call it at rest.
//
// A window's statistics (WindowStats), whichever arithmetic computed them
// (stats_streaming.hpp, stats_r.hpp); the window cutter (window_cutter.hpp)
// gives them out in order. The rest rules of the two methods read them.
//
// Header-only, standard headers only, no heap (the microcontroller tier).
#ifndef GRAVCAL_WINDOW_STATS_HPP
#define GRAVCAL_WINDOW_STATS_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace gravcal {

// Per-window results.
struct WindowStats {
  std::int64_t index;  // window number, from 0
  std::int64_t first;  // stream index (all samples pushed, skipped ones
                       // included) of the window's first retained sample
  std::int32_t n;      // retained samples in the window
  std::int32_t n_invalid;  // of which non-finite in x, y or z (not in stats)
  double mean[3];
  double sd[3];        // n - 1 denominator; NaN with fewer than 2 samples
  double min[3];
  double max[3];
  double mean_norm;    // mean of sqrt(x^2 + y^2 + z^2)
  double temperature;  // mean of finite temperatures, NaN if none
  std::int64_t n_repeat;  // valid samples equal in x, y and z to the valid
                          // sample before them in the window: a stuck
                          // sensor, ActiGraph's idle sleep (the last sample
                          // repeated), a run of zeros. Last, so that the
                          // fields before it keep their bytes.
};

// Of m samples, how many equal the one before them in x, y and z (the
// whole-window twin of WindowCounts::add_valid()'s count, window_cutter.hpp);
// only those from sample `from` on (the vector kernels count the rest).
inline std::int64_t count_repeats(const double* x, const double* y, const double* z,
                                  std::size_t m, std::size_t from = 1) {
  std::int64_t r = 0;
  for (std::size_t k = from > 1 ? from : 1; k < m; ++k) {
    r += (x[k] == x[k - 1]) & (y[k] == y[k - 1]) & (z[k] == z[k - 1]);
  }
  return r;
}

// A sum kept in four lanes by the sample's position in the window (k & 3),
// joined as (0 + 1) + (2 + 3): the rule every streaming sum follows, so that
// whole windows can be summed several samples per instruction with the same
// bits as sample by sample.
inline double lane_total(const double* v) { return (v[0] + v[1]) + (v[2] + v[3]); }

// Rest rule of the lightweight method (Farago et al. 2024, Sec. II-B-1):
// max - min below `max_range` (paper: 0.12 g) on every axis in `axes`
// (bit 0 = x, 1 = y, 2 = z; the paper watches one axis, gravcal all three).
struct RangeRestRule {
  double max_range = 0.12;
  unsigned axes = 7u;
};

inline bool is_rest(const WindowStats& s, const RangeRestRule& r) {
  if (s.n_invalid > 0 || s.n < 2) return false;
  for (int a = 0; a < 3; ++a) {
    if (!(r.axes & (1u << a))) continue;
    if (!(s.max[a] - s.min[a] < r.max_range)) return false;
  }
  return true;
}

// Rest rule of GGIR (van Hees et al. 2014): sd below `max_sd` (13 mg) and
// |mean| below `max_abs_mean` (2 g, a clipping guard) on all three axes.
struct SdRestRule {
  double max_sd = 0.013;
  double max_abs_mean = 2.0;
};

inline bool is_rest(const WindowStats& s, const SdRestRule& r) {
  if (s.n_invalid > 0 || s.n < 2) return false;
  for (int a = 0; a < 3; ++a) {
    if (!(s.sd[a] < r.max_sd)) return false;
    if (!(std::fabs(s.mean[a]) < r.max_abs_mean)) return false;
  }
  return true;
}

}  // namespace gravcal

#endif  // GRAVCAL_WINDOW_STATS_HPP
