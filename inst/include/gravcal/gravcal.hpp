// gravcal: auto-calibration of triaxial accelerometers against gravity.
// The header-only core for a host: the microcontroller tier (mcu.hpp: the
// model, the window cutter with streaming statistics, bins, the gradient
// fit, fixed point) and the host's Segmenter (segmenter.hpp: the streaming
// or R's exact arithmetic chosen at run time, with the vector kernels). The
// tiers above (ARCHITECTURE.md): the GGIR fit (icp.hpp, Eigen), the
// decoders, GGIR's procedure.
#ifndef GRAVCAL_GRAVCAL_HPP
#define GRAVCAL_GRAVCAL_HPP

#include "gravcal/mcu.hpp"
#include "gravcal/host/segmenter.hpp"

#endif  // GRAVCAL_GRAVCAL_HPP
