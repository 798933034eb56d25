#' Auto-calibrate a triaxial accelerometer recording against gravity
#'
#' Finds the rest windows of a raw recording, selects calibration points and
#' fits correction coefficients, so that the calibrated vector of every rest
#' window has a norm of 1 g.
#'
#' With `method = "ggir"` it runs GGIR's procedure (van Hees et al. 2014),
#' see the section below. With `method = "lightweight"` (Farago et al. 2024)
#' it finds the rest windows with [rest_windows()] (5 s windows, max - min
#' below 0.12 g), keeps the reliable ones (see the guards below), chooses
#' calibration points among them and fits the paper's 9-parameter model
#' `a = K (v + o)` to them. How the points are chosen and fitted is set by
#' `selection`:
#'
#' * `"cells"` (default): every distinct posture the recording rested in,
#'   one point each: [select_points()] with `selection = "cells"` (the
#'   stillest rest window of each cube of side `cell` = 0.05 g). The
#'   objective of the paper is minimised by Levenberg-Marquardt
#'   ([fit_gradient()] with `algorithm = "lm"`) to convergence, and the
#'   model is chosen among those the points determine: all nine
#'   parameters, scales and offsets (cross-axis terms 0), or offsets alone,
#'   each with and without a temperature offset (below). A model is
#'   determined when every standard error is at most `max_se` (0.01) and
#'   there are at least twice as many points as parameters (and, for
#'   offsets alone, which assume scales of 1, when every axis rested beyond
#'   0.3 g on both sides, GGIR's sphere criterion); among the
#'   determined models the one with the lowest Bayesian information
#'   criterion (`n log(RSS / n) + k log(n)` over the points) is fitted, so
#'   that terms the data do not need (cross-axis terms of a device without
#'   them, a temperature offset of a device whose temperature does not
#'   move it) are left out. `fit$models` lists the candidates, whether each
#'   was determined, its BIC and which was chosen. When not even the
#'   offsets are determined the status is `"sphere_not_covered"`. The standard errors
#'   used for that choice are the larger of the robust (HC3) standard
#'   errors and those the points' geometry allows at a residual sd of
#'   0.004 (about 2 mg), so that a parameter only the absence of noise
#'   determines (the x offset of a device that always lay flat) is not
#'   fitted. Where the rest windows have a temperature that varies (and
#'   `use_temp`, default TRUE), each model is also tried with a
#'   temperature offset per axis, `a = K (v + o) + (T - meantemp) t`, as
#'   GGIR's model has (its standard error, times the sd of the points'
#'   temperature, against `max_se`). `model` forces one of `"full"`,
#'   `"scale_offset"`, `"offset"` (with the temperature offset when it is
#'   determined).
#'   The status message says which model was fitted and why. People at
#'   rest in daily life rarely turn every axis fully up and fully down, so
#'   the paper's bins often cannot all be filled; and 18 points leave nine
#'   parameters poorly determined, so that the same samples windowed
#'   differently give different coefficients. On real free-living
#'   recordings this selection calibrates where the paper's cannot, with a
#'   held-out error below the GGIR method's (`bench/results/freeliving.md`).
#' * `"paper"`: the paper's procedure: [select_points()] (3 x 3
#'   orientation bins, 2 points each, novelty threshold 0.3 g; bins that
#'   cannot be filled so are filled with 0.1 g, then 0.03 g) and
#'   [fit_gradient()] (forward-difference gradient descent); status
#'   `"bins_incomplete"` when the bins cannot be filled.
#'
#' Arguments of those functions can be given in `...`.
#'
#' With `selection = "paper"`: the paper stops after 50 iterations, a
#' budget for a microcontroller. On real point sets the slowest direction of the problem (a mix of one axis'
#' scale, offset and cross terms) contracts by only 2-10 % per iteration with
#' the paper's rates, so 50 iterations can leave a few mg of error. A
#' computer can afford to finish: `calibrate()` runs the same descent until
#' every parameter step is below `tol = 1e-10` (at most `max_iter = 5000`
#' iterations, typically 100-700). Give `max_iter = 50, tol = 0` for the
#' paper's budget, exactly as a device would run it.
#'
#' Three guards keep rest windows that are not a sensor at rest out of the
#' lightweight fit, and out of the GGIR method's in gravcal's own mode (the
#' paper and GGIR have none, and `ggir_compat = TRUE` keeps GGIR's rules;
#' [select_points()] and [fit_gradient()] called directly still take every
#' point they are given):
#' * a window whose mean vector has a norm farther than `max_norm_error`
#'   (default 0.3 g) from 1 g. Real sensors before calibration are 16-77 mg
#'   from 1 g on average (van Hees et al. 2014, Table 3), and the
#'   orientation bins already need every axis within 0.25 g of 0 or 1 g; a
#'   window 0.3 g off is not gravity (a glitch, a window of zeros, a
#'   clipped axis), and one such point among 18 can move the fit by
#'   hundreds of mg. A sensor with an offset above about 0.3 g loses the
#'   windows of that axis, and the fit reports `"bins_incomplete"` rather
#'   than wrong coefficients; give a larger `max_norm_error` (or `Inf`, no
#'   guard) for such a sensor.
#' * a window that reaches the sensor's range (clipping): on some axis
#'   `|mean| + (max - min)`, the largest |sample| the window can hold,
#'   is at least 98 % of the full scale `range_g` (g). For a device file
#'   the full scale is taken from the file when its reader knows it
#'   (Axivity, GENEActiv, ActiGraph); for samples in memory it is unknown
#'   unless `range_g` is given, and then this guard is off.
#' * a window made of identical samples: more than `max_identical`
#'   (default 0.8) of its samples after the first equal the sample before
#'   them in x, y and z (the window table's `n_repeat`, see
#'   [rest_windows()]). ActiGraph devices in idle sleep mode repeat their
#'   last sample, a stuck sensor gives a constant, a gap may be filled with
#'   zeros: such windows have no noise, pass any rest rule, and are not a
#'   measurement of gravity. A real still sensor is not left out: in the
#'   rest windows of the real recordings the tests reach (ActiGraph,
#'   Axivity AX3 and AX6), at most 0.36 of a still sensor's samples
#'   repeat the one before (AX3 at 100 Hz; ActiGraph at 30 Hz: at most 0.26),
#'   while idle sleep, a stuck sensor or zeros give nearly 1
#'   (bench/results/rest-quality.md).
#'   `max_identical = 1` turns this guard off.
#' A window left out for several reasons counts once: identical first, then
#' clipped, then norm.
#'
#' **Rest that is not rest.** A window can pass every rule above and still
#' not be a sensor at rest: in a car, a bus or a train the wrist keeps a
#' posture, the vibration's sd is low, and the vehicle's accelerations put
#' the norm of each window's mean 30-80 mg off 1 g, of either sign (within
#' the 0.3 g guard). Hours of such windows outnumber a day's distinct rest
#' postures and move the fit. So, in gravcal's own modes (the lightweight
#' method's default `selection = "cells"`, and the GGIR method with
#' `ggir_compat = FALSE`; never `ggir_compat = TRUE` nor [g.calibrate()],
#' whose rest windows stay GGIR's), after a fit that is applied (status
#' `"ok"` or `"high_error"`) each rest window's
#' residual `r = |a| - 1` is computed (`a` its calibrated mean, the
#' temperature term included), with the median `m` and the robust spread
#' `s = 1.4826 MAD` of the residuals of the windows kept; a window is left
#' out when `|r - m| > max(off_sphere * s, 5 mg)`, and the fit is done
#' again on the windows kept, until the windows left out no longer change
#' (at most 5 fits; a window can come back). `off_sphere` is 5 by default:
#' beyond any normal residual in a week of windows (a chance of 6e-7 per
#' window), so a clean recording loses none; 5 mg is the floor because it
#' is the smallest offset change that matters to a user's results
#' ([plausible_bounds()]'s `practical_min`), and very clean recordings
#' have spreads well under 1 mg. When more than a third of the rest
#' windows would be left out (the spread is the clean windows', so they
#' must be a clear majority), or when the fit without them fails, none is
#' left out and the message says so. `off_sphere = Inf` turns the rule off.
#' The fit, its errors and its standard errors are those of the windows
#' kept, which are its `windows` (and, for the GGIR method, its `points`
#' and `ggir$spheredata`). `fit$rejected` counts the windows left out
#' (`windows`, `of`, `share`, `threshold` and `spread` in g, `k`, `floor`,
#' `max_share`, `rounds`, `note`, `in_stretch`) and `fit$rejected_windows` lists them
#' with their `residual`. Runs of windows left out that last 30 minutes or
#' more (successive ones at most 5 minutes apart) are stretches: every
#' window within a stretch's time span is left out with them, those that
#' happen to lie near the sphere too (a vehicle's norm passes through 1 g;
#' the cut-off is wider when the model does not fit the device exactly),
#' counted in `fit$rejected$in_stretch`. Stretches are reported in
#' `fit$rejected_stretches` (`start`, `end`: date-times from the samples'
#' `time` column or the file's clock, else seconds from the first sample;
#' `hours`, `windows`, `median_mg`: the median `| |a| - 1 |` of its
#' windows, in mg) and in the message, `print()` and `summary()`: "3.0 h
#' from 2024-03-04 22:30 look like rest but are not on the sphere (median
#' 54 mg off)". On 28-hour recordings with three hours of such near-rest,
#' both methods give, within 2 combined standard errors, the coefficients
#' of the same recording without those hours, with status `"ok"` where it
#' was `"high_error"` (`bench/results/near-rest.md`). With
#' `selection = "paper"` the rule does not run (the paper's procedure, as
#' a device runs it). Pooled recordings ([calibrate_files()] with `pool`)
#' leave out windows by the same rule, without stretches.
#'
#' **Coefficients that change over time.** With `segments = "day"` (or a
#' number of hours) the lightweight method also fits each day (segment) of
#' the recording on its own rest windows, with the model and reference
#' temperature the whole recording chose, and merges neighbouring
#' segments wherever their coefficients do not differ: a Wald test of the
#' difference against the two fits' covariances, at `change_alpha` (0.01)
#' divided by the number of neighbouring pairs left. A segment that cannot
#' be fitted alone is merged with its neighbour. `fit$segments` has a row
#' per segment (`from`, `to` in the units of the windows' `start`: the
#' `time` column when the samples have one, else seconds from the start;
#' the coefficients named as in [coef()] and their standard errors with a
#' `.se` suffix); [apply_calibration()] applies each segment's
#' coefficients to its samples, and `plot(fit, type = "segments")` draws
#' them over time. A recording without drift comes out as one segment.
#' `K`, `offset` and `tempoffset` stay those of the whole recording. The
#' GGIR method takes `segments` too (see "The GGIR method").
#'
#' **An adaptive data budget.** With `budget = "adaptive"` the lightweight
#' method reads the recording block by block and, every `check_hours` (6)
#' hours of samples, fits what it has read; it stops reading once every
#' standard error of the fitted coefficients is at most `target_se`
#' (0.001: each coefficient known to about +-2 mg at 95 %) and the
#' coefficients moved by less than two standard errors of their
#' difference since the previous check. `fit$budget` says how much was
#' read (`hours_read`, and `hours_total` for samples in memory) and
#' whether it stopped early (`stopped`); `print()` shows it. The GGIR
#' method takes `budget` too (see "The GGIR method").
#'
#' The fit records the windows left out: `excluded` (counts, named `norm`,
#' `clipped` and `identical`), `excluded_windows` (those windows, with a
#' column `why`; lightweight method only) and `guards` (the limits used);
#' `print()` shows the counts. Windows left out are neither points nor
#' held-out windows. In the GGIR method's own mode the counts are of the
#' rest windows of the table before its duplicate filter (which also drops
#' all but the last of a run of equal windows).
#'
#' The rest windows that were not selected as calibration points are a
#' held-out set, as in the paper's Table 3: the fit reports the error on them
#' before and after calibration (`error_heldout_before`,
#' `error_heldout_after`).
#'
#' Calibration that cannot be done is a status, not an error: the fit then
#' carries identity coefficients (so [apply_calibration()] leaves the data
#' unchanged) and a `status` code with a `message` for people:
#'
#' | status | meaning | what to do |
#' |---|---|---|
#' | `"ok"` | calibrated | |
#' | `"high_error"` | calibrated, coefficients kept, but the calibration points are still 10 mg or more off 1 g on average after the fit (`error_after`; GGIR's threshold) | inspect the points with `plot()`: some may not be rest |
#' | `"too_short"` | fewer samples than one window | check `sf` and the file |
#' | `"all_zero"` | every sample is exactly 0 on all three axes (ActiGraph idle sleep, or a device that recorded nothing) | check the device and its download: there is nothing to calibrate |
#' | `"no_rest"` | no window met the rest criterion | check units (g) and `sf` |
#' | `"bins_incomplete"` | `selection = "paper"`: rest not seen in enough orientations | use a longer recording, the default selection, or lower `min_per_bin` / `min_distance` |
#' | `"sphere_not_covered"` | rest not seen in enough orientations to determine even the offsets | use a longer recording |
#' | `"diverged"` | the optimizer left the finite range | report it; try `objective = "mean"` |
#' | `"no_improvement"` | the fit did not lower the error | the data are likely already calibrated |
#' | `"implausible"` | coefficients outside plausible ranges | inspect the rest points with `plot()` |
#'
#' @param x Raw samples: a data frame or matrix with numeric columns `x`, `y`,
#'   `z` in g and optionally `temperature` and `time`; or the path of a file
#'   that [read_recording()] reads.
#' @param sf Sampling frequency in Hz (taken from the file when `x` is a path
#'   and `sf` is missing; a `.cwa`, `.bin` or `.gt3x` file's own rate is
#'   always used, and an `sf` that disagrees with it is an error).
#' @param method `"lightweight"` (Farago et al. 2024) or `"ggir"` (van Hees
#'   et al. 2014; see the section "The GGIR method").
#' @param ggir_compat For `method = "ggir"`: reproduce GGIR's
#'   `g.calibrate()` exactly, quirks included (`TRUE`), or use gravcal's
#'   corrected procedure (`FALSE`, default).
#' @param ... For the lightweight method, arguments passed on to
#'   [rest_windows()] (`window`, `max_range`, `axes`, `skip_zero`,
#'   `block_samples`, `progress`, `reader`, `rmc`), the guards (`max_norm_error`, in g,
#'   default 0.3; `range_g`, the sensor's full scale in g, default from the
#'   file or unknown; `max_identical`, default 0.8; `off_sphere`, the cut-off
#'   of the rule on rest that is not on the sphere in robust spreads, default
#'   5, `Inf` for none; see Details), the choice of points and model
#'   (`selection`, `"cells"` or `"paper"`; `cell`, in g, default 0.05;
#'   `max_se`, default 0.01; `model`, default `"auto"`; `use_temp`,
#'   default TRUE; `segments`, default none, and `change_alpha`, default
#'   0.01; `budget`, `"all"` or `"adaptive"`, `target_se`, default 0.001,
#'   and `check_hours`, default 6; see Details),
#'   [select_points()] for `selection = "paper"` (`per_bin`, `min_per_bin`,
#'   `min_distance`) and [fit_gradient()] (`arithmetic`, `max_iter`, `rates`,
#'   `h`, `objective`, `use_sqrt`, `tol`, `trace`, `difference`,
#'   `algorithm`, `se`). For the GGIR method:
#'   `use_temp` (fit the temperature term when there is one, default TRUE),
#'   `spherecrit` (0.3 g), `minloadcrit` (168 h), `chunksize` (1, about 12 h
#'   blocks), `max_sd` (0.013 g), `max_iter` (1000), `tol` (1e-10),
#'   `reader` (`"native"` or `"reference"`, see [rest_windows()]),
#'   `rmc` (GGIR's `rmc.*` parameters of an ad hoc csv file, see
#'   [rest_windows()]; the rest rule stays `max_sd`, where
#'   [g.calibrate()] takes GGIR's `1.2 * rmc.noise`), `verbose` and, in
#'   gravcal's own mode only (an error with `ggir_compat = TRUE`), the
#'   guards `max_norm_error`, `range_g`, `max_identical` and `off_sphere`
#'   (as for the lightweight method), `segments`, `change_alpha`, `budget`, `target_se`
#'   and `check_hours` (see "The GGIR method").
#' @section The GGIR method:
#' `method = "ggir"` runs the procedure of GGIR's `g.calibrate()` (see
#' [g.calibrate()] for the steps) and returns a `gravcal_fit` whose `K` is
#' `diag(scale)`; GGIR's own list is in `fit$ggir` and its QC message in
#' `fit$QCmessage`. Status codes: `"ok"` (GGIR: "recalibration done", or
#' "attempted with all available data" with an error after calibration
#' below 10 mg: GGIR's pipeline applies these coefficients), `"high_error"`
#' (attempted, error still 10 mg or more; coefficients kept, as GGIR keeps
#' them), `"implausible"` (not applied: coefficients outside the ranges
#' real devices show; not in compatible mode, which applies what GGIR
#' applies), `"no_improvement"`, `"sphere_not_covered"`, `"no_rest"`,
#' `"too_short"`, `"all_zero"` (gravcal's own mode: every sample is 0, the
#' idle-sleep zeros GGIR's rule removes; compatible mode keeps GGIR's
#' `"too_short"`) and `"diverged"`, the last six with identity
#' coefficients.
#'
#' With `ggir_compat = TRUE` the numbers are GGIR's: coefficients, errors
#' and window statistics identical, to the last bit, to those of
#' `GGIR::g.calibrate()` 3.3 on the same samples (the window statistics use
#' R's arithmetic, the fit R's own least-squares routine). gravcal's default differs
#' from GGIR in five places, each where GGIR's behaviour is an accident or
#' costs time for nothing:
#' 1. The fit runs to convergence (no parameter moves by more than `tol`).
#'    GGIR stops when its residual statistic, divided by the sum of the
#'    weights, changes by less than 1e-10, usually after 5-10 iterations;
#'    that leaves about 1 mg of offset error, 10 to 100 times what the
#'    converged fit leaves on simulated recordings with known truth.
#' 2. A window is dropped as a duplicate of the next one only when all six
#'    of its means and standard deviations are equal. GGIR drops it when
#'    exactly three are equal, and keeps fully identical windows.
#' 3. "Enough data" means at least one hour of distinct windows, in a
#'    recording of at least two hours. GGIR compares the number of 10 s
#'    windows with `minloadcrit - 21`, a number of hours, and asks two hours
#'    of its first block, whose size `chunksize` scales.
#' 4. Samples left over after the last whole hour of a block always carry
#'    over to the next block, and the sample before a trailing run of
#'    idle-sleep zeros keeps its value. (GGIR re-reads stale leftovers when a
#'    block ends exactly on an hour, drops a block shorter than an hour, and
#'    overwrites that sample with the one before it.)
#' 5. Time grows linearly with the recording. GGIR refits on all windows
#'    after every block once it has `minloadcrit` hours, so a recording that
#'    never reaches the error target costs time that grows with its square.
#'    gravcal decides whether to read on with a fit converged to 1e-6 on
#'    at most 10,000 evenly spaced windows of the table, started from the
#'    previous decision's coefficients, refits only once the window table
#'    has grown by a quarter, and fits to convergence on the whole table (accelerated, see [fit_icp()]) for
#'    the result it returns; it may therefore read up to a quarter more
#'    than GGIR before it stops. Twice the recording takes about twice the
#'    time (`bench/results/ggir-own-scaling.md`).
#'
#' **Beyond one fit** (gravcal's own mode; GGIR has no such parameters, so
#' `ggir_compat = TRUE` and [g.calibrate()] refuse them with an error naming
#' them). With `segments = "day"` (or a number of hours) the procedure
#' reads the whole recording (`minloadcrit` no longer stops it), then fits
#' GGIR's model (scale, offset and, when the whole fit used it, temperature
#' offset) to the rest windows of each segment of time (window i of the
#' procedure starts (i - 1) * 10 s after the first sample) and merges
#' neighbours as the lightweight method does (a Wald test at
#' `change_alpha`; a segment that does not cover the sphere or whose scale
#' or offset has a standard error above 0.01 joins a neighbour). Each
#' segment's offsets are referred to the whole recording's `meantemp`, so
#' that its temperature term applies as the whole fit's does. `fit$segments`
#' and [apply_calibration()] are as for the lightweight method, with times
#' in seconds from the first sample. With `budget = "adaptive"` the
#' procedure fits to convergence every `check_hours` hours of windows (at
#' the end of a block, and not before the table has grown by a quarter)
#' and, in place of `minloadcrit`, stops reading once GGIR's error target
#' is met (error below 10 mg and below the error before) and every
#' standard error is at most `target_se`, with the coefficients (at the
#' same reference temperature) stable since the previous check.
#' `fit$budget` is as for the lightweight method. The two cannot be
#' combined (segments need the whole recording).
#'
#' Window statistics in compatible mode are computed in GGIR's arithmetic
#' (R's `cumsum()` and `sd()`, bit for bit) so that its exact-equality rules
#' decide the same way; gravcal's own mode uses the streaming arithmetic.
#' @return A `gravcal_fit`: a list with
#'   * `K` (3 x 3) and `offset` (3), `tempoffset` (3) and `meantemp`, so that
#'     the calibrated vector is `a = K (v + offset) + (T - meantemp) *
#'     tempoffset`;
#'   * `points`: the rest windows the fit used; `windows`: all rest windows;
#'   * `error_before`, `error_after`: mean `| |a| - 1 |` over `points`, in g;
#'     `error_heldout_before`, `error_heldout_after`: the same over the rest
#'     windows not used for the fit (NA when there are none);
#'   * `iterations`, `converged`, `status`, `message`, `method`, `call`, and
#'     for the lightweight method `params` (the nine parameters) and
#'     `selection` (the choice of points and model: `selection`, `cell`,
#'     `max_se`, `model`, `use_temp`);
#'   * `se`: standard errors, named like [coef()]'s coefficients (NA for a
#'     coefficient the model does not fit, and for every coefficient when
#'     the fit was not applied); `vcov`: the covariance of the fitted
#'     coefficients (NULL when not fitted), `df` (residual degrees of
#'     freedom) and `sigma` (residual standard deviation), from the
#'     Jacobian of the residuals at the solution (see [vcov.gravcal_fit()]);
#'   * `model`: the names (as in [coef()]) of the coefficients the model
#'     fitted: those of the lightweight model (nine, six or three), GGIR's scale and offset
#'     with `t_x`, `t_y`, `t_z` when the temperature was used; empty when
#'     the coefficients are the identity;
#'   * for the lightweight method from [calibrate()]: `excluded`,
#'     `excluded_windows` and `guards`; for the GGIR method in gravcal's own
#'     mode: `excluded` and `guards` (see Details);
#'   * in gravcal's own modes (the lightweight method's default selection,
#'     the GGIR method with `ggir_compat = FALSE`): `rejected`,
#'     `rejected_windows` and `rejected_stretches`, the rest windows left
#'     out as not on the sphere and their stretches of time (see "Rest that
#'     is not rest" in Details);
#'   * in gravcal's own modes (both methods), `temperature_check`: the
#'     temperature sensor, a list with `available`, `flat` (the rest
#'     windows' temperature does not vary: sd below 0.01 degrees C), `sd`,
#'     `value`, `hours` and `stuck` (flat over 12 h or more: a stuck sensor,
#'     flagged `"temperature_stuck"` by `print()` and [calibrate_files()];
#'     see [plausible_bounds()]), `note`, and `implausible` with
#'     `range_note` (a temperature outside -20 to 70 degrees C: a faulty
#'     sensor or a misread temperature, flagged `"temperature_implausible"`).
#'     For the GGIR method the rest
#'     windows are read again only when the procedure left the temperature
#'     out because it does not vary.
#' @seealso [apply_calibration()], [plot.gravcal_fit()], [rest_windows()]
#' @export
#' @examples
#' rec <- simulate_recording(hours = 12, sf = 10, seed = 3)
#' fit <- calibrate(rec, sf = 10)
#' fit
#' summary(fit)
#' calibrated <- apply_calibration(rec, fit)
calibrate <- function(x, sf, method = c("lightweight", "ggir"),
                      ggir_compat = FALSE, ...) {
  call <- match.call()
  method <- match_choice(method, "method")
  check_flag(ggir_compat, "ggir_compat")
  if (method == "ggir") {
    # segments and the adaptive budget (gravcal's own mode only)
    dots <- list(...)
    over <- ggir_over_time(dots, ggir_compat)
    if (!is.null(over)) dots <- dots[!names(dots) %in% ggir_over_time_names]
    return(calibrate_ggir(x, if (missing(sf)) NULL else sf, ggir_compat,
                          dots, call, over))
  }
  if (is.character(x)) {
    # a file: read block by block by rest_windows()
    if (missing(sf)) sf <- NULL
  } else if (missing(sf)) {
    abort("`sf` (sampling frequency in Hz) is missing.")
  }
  la <- lightweight_args(list(...))
  args <- la$args
  choice <- la$choice
  max_norm_error <- la$max_norm_error
  range_g <- la$range_g
  max_identical <- la$max_identical
  rargs <- args$rest_windows
  if (choice$budget == "adaptive") {
    rargs$stop <- budget_rule(args$fit_gradient, choice, max_norm_error,
                              range_g, max_identical)
    rargs$stop_every <- choice$check_hours
    if (is.null(rargs$block_samples) && is.null(rargs$chunk_size) && !is.character(x)) {
      rargs$block_samples <- min(1e6, ceiling(choice$check_hours * 3600 * sf))
    }
  }
  w <- do.call(rest_windows, c(list(x = x, sf = sf, method = method), rargs))
  fit <- lightweight_from_windows(w, args, choice, max_norm_error, range_g, call,
                                  file = if (is.character(x)) basename(x),
                                  timed = !is.character(x) &&
                                    "time" %in% tolower(names(x)),
                                  max_identical = max_identical,
                                  off_sphere = la$off_sphere)
  # a stuck temperature sensor: the rest windows' temperature does not vary
  # (see ?plausible_bounds)
  fit$temperature_check <- temperature_check(
    fit_hours(fit), TRUE,
    temps = if (is.data.frame(fit$windows)) fit$windows$temperature else NA_real_)
  fit
}
