// gravcal: the header-only core's microcontroller tier (no Eigen, no heap,
// no vector kernels, standard headers only), in double, float or fixed
// point (fixed_point.hpp): the model (model.hpp), the window cutter with
// the streaming statistics (window_cutter.hpp, stats_streaming.hpp:
// StreamSegmenter), the bins (bins.hpp) and the gradient fit
// (gradient.hpp). tests/testthat/test-headers.R checks what it includes;
// tests/cpp builds it for a Cortex-M4. gravcal.hpp adds the host's
// Segmenter (segmenter.hpp: R's arithmetic and the vector kernels).
#ifndef GRAVCAL_MCU_HPP
#define GRAVCAL_MCU_HPP

#include "fp_contract.hpp"

#include "model.hpp"
#include "stats_streaming.hpp"
#include "window_cutter.hpp"
#include "bins.hpp"
#include "gradient.hpp"
#include "fixed_point.hpp"

#endif  // GRAVCAL_MCU_HPP
