// gravcal: auto-calibration of triaxial accelerometers against gravity.
// The header-only core; includes only standard headers (and Eigen in icp.hpp).
#ifndef GRAVCAL_GRAVCAL_HPP
#define GRAVCAL_GRAVCAL_HPP

#include "model.hpp"
#include "segmenter.hpp"
#include "bins.hpp"
#include "gradient.hpp"

#endif  // GRAVCAL_GRAVCAL_HPP
