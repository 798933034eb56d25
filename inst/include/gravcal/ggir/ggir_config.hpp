// gravcal: the settings of GGIR's auto-calibration procedure
// (ggir_procedure.hpp) and of its window table (ggir_window_table.hpp), in
// one typed struct. The R glue builds it once from R's option list
// (src/glue_pipeline.cpp's parse_ggir_options(): each key read there and only
// there); the stages take the struct and read no option by name.
#ifndef GRAVCAL_GGIR_CONFIG_HPP
#define GRAVCAL_GGIR_CONFIG_HPP

#include <cmath>
#include <cstddef>

namespace gravcal {

// GGIR's constants used by the procedure (the R side lists them all, with
// their sources, in ggir_constants).
struct GgirConfig {
  bool compat = true;          // GGIR's rules, accidents included
  double sf = 0.0;             // samples per second
  double block_units = 0.0;    // source units per GGIR block
  double short_block_rows = 0.0;  // a block with fewer rows is the last (0: none)
  bool temperature = true;     // use the source's temperature if it has one
  bool lazy = true;            // compatible mode: R's sds only where seen
  bool nonfinite_in_sums = false;  // compatible mode: a non-finite sample
                                   // enters R's cumulative sums (GGIR's
                                   // readers' samples: its NaN empties the
                                   // rest of its block); else left out of
                                   // its window (samples in memory)
  int threads = 1;             // 2: the segmenter's windows on a second
                               // thread beside the decode (GgirBlocks::async())
  bool r_long_double = true;   // R's accumulator (its LDOUBLE) is long
                               // double; false: double (an R without long
                               // double, capabilities("long.double") FALSE)
  double spherecrit = 0.3;     // g
  double minloadcrit = 168.0;  // h
  double max_sd = 0.013;       // g, rest: sd of every axis below
  double max_abs_mean = 2.0;   // g, rest: |mean| of every axis below
  int min_rest = 10;           // rest windows needed to try a fit
  double enough_offset = 21.0; // GGIR: windows > minloadcrit - 21
  double min_hours = 1.0;      // own mode: hours of distinct windows needed
  double max_error = 0.01;     // g
  int error_digits = 5;
  double temp_max_first = 120.0;
  double temp_min_sd = 0.01;
  double temp_missing = 99999.0;
  double fill = 99999.0;
  int max_iter = 1000;
  double tol = 1e-10;
  double max_weight = 100.0;
  double refit_growth = 1.25;  // own mode: refit once the table grew by this
  std::size_t decide_windows = 10000;  // own mode: most windows (evenly
                                       // spaced) a decision to read on fits,
  double decide_tol = 1e-6;            // and to what tolerance
  // own mode's guards on rest windows (compatible mode has none; R's
  // calibrate() documents them): a window whose mean vector's norm is
  // farther than guard_norm g from 1 g; one that reaches guard_clip g on
  // some axis (|mean| + max - min; not positive or NaN: not checked); one
  // with more than guard_repeat of its samples after the first equal to the
  // one before (WindowStats::n_repeat). Inf: the guard is off.
  double guard_norm = INFINITY;
  double guard_clip = 0.0;
  double guard_repeat = INFINITY;
  // own mode only: when to stop reading. 0: GGIR's rule (the error target
  // met after minloadcrit hours); 1: read the whole recording (coefficients
  // per segment of time need every part of it); 2: the adaptive budget: a
  // converged fit every check_hours of windows (or once the table grew by
  // refit_growth, whichever is later), and stop once GGIR's error target
  // is met and the host's enough() says the coefficients are determined
  int reading = 0;
  double check_hours = 6.0;
};

}  // namespace gravcal

#endif  // GRAVCAL_GGIR_CONFIG_HPP
