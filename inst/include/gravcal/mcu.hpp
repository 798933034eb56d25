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

#include "gravcal/mcu/fp_contract.hpp"

#include "gravcal/mcu/model.hpp"
#include "gravcal/mcu/stats_streaming.hpp"
#include "gravcal/mcu/window_cutter.hpp"
#include "gravcal/mcu/bins.hpp"
#include "gravcal/mcu/gradient.hpp"
#include "gravcal/mcu/fixed_point.hpp"

#endif  // GRAVCAL_MCU_HPP
