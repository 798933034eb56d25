// gravcal: auto-calibration of triaxial accelerometers against gravity.
// The header-only core, standard headers only (no Eigen, no heap): what a
// microcontroller needs, in double, float or fixed point (fixed_point.hpp).
// The GGIR fit, which uses Eigen, is icp.hpp.
#ifndef GRAVCAL_GRAVCAL_HPP
#define GRAVCAL_GRAVCAL_HPP

#include "model.hpp"
#include "segmenter.hpp"
#include "bins.hpp"
#include "gradient.hpp"
#include "fixed_point.hpp"

#endif  // GRAVCAL_GRAVCAL_HPP
