// gravcal: auto-calibration of triaxial accelerometers against gravity.
// The header-only core (no Eigen, no heap). Its microcontroller tier, in
// double, float or fixed point (fixed_point.hpp), standard headers only:
// model.hpp, window_cutter.hpp with stats_streaming.hpp (StreamSegmenter),
// bins.hpp, gradient.hpp. segmenter.hpp adds R's arithmetic (stats_r.hpp)
// and the vector kernels (kernels.hpp). The GGIR fit, which uses Eigen, is
// icp.hpp.
#ifndef GRAVCAL_GRAVCAL_HPP
#define GRAVCAL_GRAVCAL_HPP

#include "model.hpp"
#include "segmenter.hpp"
#include "bins.hpp"
#include "gradient.hpp"
#include "fixed_point.hpp"

#endif  // GRAVCAL_GRAVCAL_HPP
