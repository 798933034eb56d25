// gravcal: auto-calibration of triaxial accelerometers against gravity.
// The header-only core's microcontroller tier (no Eigen, no heap, no vector
// kernels, standard headers only), in double, float or fixed point
// (fixed_point.hpp): model.hpp, window_cutter.hpp with stats_streaming.hpp
// (StreamSegmenter), bins.hpp, gradient.hpp. The tiers above it include it:
// segmenter.hpp (the host's Segmenter: R's arithmetic, stats_r.hpp, and
// the vector kernels, kernels.hpp), the GGIR fit (icp.hpp, Eigen), the
// decoders and GGIR's procedure (ARCHITECTURE.md).
#ifndef GRAVCAL_GRAVCAL_HPP
#define GRAVCAL_GRAVCAL_HPP

#include "model.hpp"
#include "stats_streaming.hpp"
#include "window_cutter.hpp"
#include "bins.hpp"
#include "gradient.hpp"
#include "fixed_point.hpp"

#endif  // GRAVCAL_GRAVCAL_HPP
