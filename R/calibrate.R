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
#' Two guards keep unreliable rest windows out of the lightweight fit (the
#' paper has none; [select_points()] and [fit_gradient()] called directly
#' still take every point they are given):
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
#' `K`, `offset` and `tempoffset` stay those of the whole recording.
#'
#' **An adaptive data budget.** With `budget = "adaptive"` the lightweight
#' method reads the recording block by block and, every `check_hours` (6)
#' hours of samples, fits what it has read; it stops reading once every
#' standard error of the fitted coefficients is at most `target_se`
#' (0.001: each coefficient known to about +-2 mg at 95 %) and the
#' coefficients moved by less than two standard errors of their
#' difference since the previous check. `fit$budget` says how much was
#' read (`hours_read`, and `hours_total` for samples in memory) and
#' whether it stopped early (`stopped`); `print()` shows it. GGIR's
#' procedure keeps its own rule (`minloadcrit`).
#'
#' The fit records the windows left out: `excluded` (counts, named `norm`
#' and `clipped`; a clipped window counts as clipped only),
#' `excluded_windows` (those windows, with a column `why`) and `guards` (the
#' limits used); `print()` shows the counts. Windows left out are neither
#' points nor held-out windows.
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
#' | `"too_short"` | fewer samples than one window | check `sf` and the file |
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
#'   and `sf` is missing).
#' @param method `"lightweight"` (Farago et al. 2024) or `"ggir"` (van Hees
#'   et al. 2014; see the section "The GGIR method").
#' @param ggir_compat For `method = "ggir"`: reproduce GGIR's
#'   `g.calibrate()` exactly, quirks included (`TRUE`), or use gravcal's
#'   corrected procedure (`FALSE`, default).
#' @param ... For the lightweight method, arguments passed on to
#'   [rest_windows()] (`window`, `max_range`, `axes`, `skip_zero`,
#'   `chunk_size`, `progress`, `reader`), the guards (`max_norm_error`, in g,
#'   default 0.3; `range_g`, the sensor's full scale in g, default from the
#'   file or unknown; see Details), the choice of points and model
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
#'   `reader` (`"native"` or `"reference"`, see [rest_windows()]) and
#'   `verbose`.
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
#' `"too_short"` and `"diverged"`, the last five with identity
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
#' 3. "Enough data" means at least one hour of distinct windows. GGIR
#'    compares the number of 10 s windows with `minloadcrit - 21`, a number
#'    of hours.
#' 4. Samples left over after the last whole hour of a block always carry
#'    over to the next block, and the sample before a trailing run of
#'    idle-sleep zeros keeps its value. (GGIR re-reads stale leftovers when a
#'    block ends exactly on an hour, drops a block shorter than an hour, and
#'    overwrites that sample with the one before it.)
#' 5. Time grows linearly with the recording. GGIR refits on all windows
#'    after every block once it has `minloadcrit` hours, so a recording that
#'    never reaches the error target costs time that grows with its square.
#'    gravcal decides whether to read on with a fit that stops as GGIR's
#'    does (a few iterations), refits only once the window table has grown
#'    by a quarter, and fits to convergence for the result it returns; it
#'    may therefore read up to a quarter more than GGIR before it stops.
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
#'     `excluded_windows` and `guards` (see Details).
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
    return(calibrate_ggir(x, if (missing(sf)) NULL else sf, ggir_compat,
                          list(...), call))
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
  rargs <- args$rest_windows
  if (choice$budget == "adaptive") {
    rargs$stop <- budget_rule(args$fit_gradient, choice, max_norm_error,
                              range_g)
    rargs$stop_every <- choice$check_hours
    if (is.null(rargs$chunk_size) && !is.character(x)) {
      rargs$chunk_size <- min(1e6, ceiling(choice$check_hours * 3600 * sf))
    }
  }
  w <- do.call(rest_windows, c(list(x = x, sf = sf, method = method), rargs))
  lightweight_from_windows(w, args, choice, max_norm_error, range_g, call,
                           file = if (is.character(x)) basename(x),
                           timed = !is.character(x) &&
                             "time" %in% tolower(names(x)))
}
# The lightweight method's arguments from calibrate()'s `...`, routed and
# checked: list(args (by destination), choice, max_norm_error, range_g).
lightweight_args <- function(dots) {
  args <- split_dots(dots, list(
    rest_windows = c("window", "max_range", "axes", "skip_zero",
                     "chunk_size", "progress", "reader"),
    guards = c("max_norm_error", "range_g"),
    choice = c("selection", "cell", "max_se", "model", "use_temp",
               "segments", "change_alpha", "budget", "target_se",
               "check_hours"),
    select_points = c("per_bin", "min_per_bin", "min_distance"),
    fit_gradient = c("arithmetic", "max_iter", "rates", "h", "objective",
                     "use_sqrt", "tol", "trace", "difference", "algorithm",
                     "se")))
  choice <- check_choice_args(args$choice, args$select_points)
  gargs <- args$guards
  max_norm_error <- if (is.null(gargs$max_norm_error)) 0.3 else
    gargs$max_norm_error
  if (!identical(max_norm_error, Inf)) {
    check_number(max_norm_error, "max_norm_error", min = 0,
                 min_inclusive = FALSE)
  }
  range_g <- gargs$range_g
  if (!is.null(range_g)) {
    check_number(range_g, "range_g", min = 0, min_inclusive = FALSE)
  }
  list(args = args, choice = choice, max_norm_error = max_norm_error,
       range_g = range_g)
}

# The lightweight method from its windows (rest_windows()'s table, with its
# attributes): the guards, the points, the fit and the held-out errors.
# `file`: the file's name for the fit (NULL for samples in memory); `timed`:
# whether the windows' start comes from a `time` column.
lightweight_from_windows <- function(w, args, choice, max_norm_error, range_g,
                                     call, file = NULL, timed = FALSE) {
  if (is.null(range_g)) range_g <- attr(w, "input")$range_g
  rest <- w[w$rest, , drop = FALSE]
  why <- guard_windows(rest, max_norm_error, range_g)
  excluded <- table(factor(why[!is.na(why)], levels = c("norm", "clipped")))
  excluded <- stats::setNames(as.integer(excluded), names(excluded))
  excluded_windows <- rest[!is.na(why), , drop = FALSE]
  excluded_windows$why <- why[!is.na(why)]
  rest <- rest[is.na(why), , drop = FALSE]
  rownames(rest) <- NULL
  attr(rest, "n_windows") <- nrow(w)
  guards <- list(max_norm_error = max_norm_error,
                 range_g = if (is.null(range_g)) NA_real_ else range_g)
  hours <- attr(w, "samples") / attr(w, "sf") / 3600
  budget <- list(budget = choice$budget, target_se = choice$target_se,
                 check_hours = choice$check_hours,
                 stopped = isTRUE(attr(w, "stopped")), hours_read = hours,
                 hours_total = attr(w, "samples_total") / attr(w, "sf") / 3600)
  fail <- function(status, message, points = rest[0, , drop = FALSE]) {
    f <- new_fit(points = points, method = "lightweight", status = status,
                 message = message, call = call)
    f$hours <- hours
    f$budget <- budget
    f$input <- attr(w, "input")
    f$file <- file
    f <- add_guards(f, excluded, excluded_windows, guards)
    finish_fit(f, rest)
  }
  if (nrow(w) == 0) {
    return(fail("too_short", sprintf(paste0(
      "recording too short: %d samples, fewer than one %g s window at %g Hz"),
      attr(w, "samples"), attr(w, "window"), attr(w, "sf"))))
  }
  if (nrow(rest) == 0 && sum(excluded) > 0) {
    return(fail("no_rest", sprintf(paste0(
      "no rest: %d windows met the rest criterion but all were left out ",
      "(%s); are the samples in g?"), sum(excluded), format_excluded(
        excluded, guards))))
  }
  if (nrow(rest) == 0) {
    return(fail("no_rest", sprintf(paste0(
      "no rest: none of the %d windows met the rest criterion; are the ",
      "samples in g and is sf right?"), nrow(w))))
  }
  if (choice$selection == "cells") {
    pts <- select_points(rest, selection = "cells", cell = choice$cell)
    fit <- fit_chosen_model(pts, args$fit_gradient, choice, fail)
    if (fit$status == "sphere_not_covered") return(fit)
    fit$call <- call
    fit$selection <- choice
    fit <- guard_fit(fit)
    if (!is.null(choice$segments) && fit$status == "ok") {
      fit <- fit_segments(fit, rest, origin = w$start[1], args$fit_gradient,
                          choice)
      fit$segment_settings$time <- if (timed) "time" else "seconds"
      fit$segment_settings$sf <- attr(w, "sf")
    }
    fit$hours <- hours
    fit$budget <- budget
    fit$input <- attr(w, "input")
    fit$file <- file
    fit <- add_guards(fit, excluded, excluded_windows, guards)
    return(finish_fit(fit, rest))
  }
  # the paper's procedure: the bins that a 0.3 g novelty threshold cannot
  # fill are filled with smaller thresholds, keeping the points already
  # chosen (unless the user set the thresholds)
  sargs <- args$select_points
  if (is.null(sargs$min_distance)) sargs$min_distance <- c(0.3, 0.1, 0.03)
  pts <- do.call(select_points, c(list(w = rest), sargs))
  if (!isTRUE(attr(pts, "complete"))) {
    return(fail("bins_incomplete", paste0(
      "not enough rest points on all sides of the sphere: ",
      nrow(rest), " rest windows, bins short of points: ",
      missing_bins(pts)), points = pts))
  }
  fargs <- utils::modifyList(list(max_iter = 5000, tol = 1e-10),
                             args$fit_gradient)
  if (choice$model != "auto") fargs$model <- choice$model
  fit <- do.call(fit_gradient, c(list(pts = pts), fargs))
  fit$call <- call
  fit$selection <- choice
  fit <- guard_fit(fit)
  fit$hours <- hours
  fit$input <- attr(w, "input")
  fit$file <- file
  fit <- add_guards(fit, excluded, excluded_windows, guards)
  finish_fit(fit, rest)
}

# The arguments that choose points and model: selection ("cells", the
# default, or "paper"), cell (g), max_se and model ("auto" or one of
# fit_gradient()'s models).
check_choice_args <- function(choice, sargs) {
  selection <- match_choice(choice$selection %||% "cells", "selection",
                            c("cells", "paper"))
  cell <- choice$cell %||% 0.05
  check_number(cell, "cell", min = 0.001, max = 1)
  max_se <- choice$max_se %||% default_max_se
  check_number(max_se, "max_se", min = 0, min_inclusive = FALSE)
  model <- match_choice(choice$model %||% "auto", "model",
                        c("auto", "full", "scale_offset", "offset"))
  if (selection == "cells" && length(sargs)) {
    abort("`", names(sargs)[1], "` sets the paper's orientation bins; give ",
          "it with `selection = \"paper\"` (the default, `\"cells\"`, ",
          "takes one point per distinct posture).")
  }
  if (selection == "paper" && model == "auto") model <- "full"
  use_temp <- choice$use_temp %||% TRUE
  check_flag(use_temp, "use_temp")
  segments <- choice$segments
  if (!is.null(segments)) {
    segment_seconds(segments)
    if (selection != "cells") {
      abort("`segments` needs the default `selection = \"cells\"`: the ",
            "paper's 18 points cannot be split over time.")
    }
  }
  change_alpha <- choice$change_alpha %||% 0.01
  check_number(change_alpha, "change_alpha", min = 0, max = 1,
               min_inclusive = FALSE, max_inclusive = FALSE)
  budget <- match_choice(choice$budget %||% "all", "budget",
                         c("all", "adaptive"))
  target_se <- choice$target_se %||% default_target_se
  check_number(target_se, "target_se", min = 0, min_inclusive = FALSE)
  check_hours <- choice$check_hours %||% 6
  check_number(check_hours, "check_hours", min = 0, min_inclusive = FALSE)
  if (budget == "adaptive" && selection != "cells") {
    abort("`budget = \"adaptive\"` needs the default `selection = ",
          "\"cells\"`.")
  }
  list(selection = selection, cell = cell, max_se = max_se, model = model,
       use_temp = use_temp, segments = segments, change_alpha = change_alpha,
       budget = budget, target_se = target_se, check_hours = check_hours)
}

# The adaptive data budget's target: every standard error of the fitted
# coefficients at most 1 mg (g, or g per degree C for a temperature
# offset), so that each is known to about +-2 mg at 95 %: below the
# 2-5 mg a calibrated device keeps on real rest windows
# (bench/results/freeliving.md).
default_target_se <- 0.001

# The stop rule of the adaptive budget: at each check, fit the rest
# windows read so far as calibrate() would; stop once every standard error
# is at most target_se and the coefficients moved by less than two
# standard errors of their difference since the previous check (the same
# model both times).
budget_rule <- function(fargs, choice, max_norm_error, range_g) {
  prev <- NULL
  function(w) {
    rest <- w[!is.na(w$rest) & w$rest, , drop = FALSE]
    rest <- rest[is.na(guard_windows(rest, max_norm_error, range_g)), ,
                 drop = FALSE]
    if (nrow(rest) == 0) return(FALSE)
    pts <- select_points(rest, selection = "cells", cell = choice$cell)
    f <- fit_chosen_model(pts, fargs, choice, function(status, message,
                                                       points) {
      list(status = status)
    })
    if (!identical(f$status, "ok")) {
      prev <<- NULL
      return(FALSE)
    }
    nm <- f$model
    se <- f$se[nm]
    done <- all(is.finite(se)) && all(se <= choice$target_se) &&
      !is.null(prev) && identical(prev$model, nm) &&
      all(abs(stats::coef(f)[nm] - stats::coef(prev)[nm]) <=
            2 * sqrt(se^2 + prev$se[nm]^2))
    prev <<- f
    done
  }
}

# The largest standard error (HC3) a fitted parameter may have for its
# group to be fitted: 0.01 is 10 mg of error on a 1 g axis, about the
# error calibration is to remove; a parameter known no better than that
# is noise.
default_max_se <- 0.01

# The offsets-only model needs, on every axis, rest points beyond
# +-offset_coverage g on both sides (GGIR's sphere criterion, 0.3 g): with
# an axis seen on one side only, an offset cannot be told from a scale
# error. The axes that fail, as text ("" when none).
offset_coverage <- 0.3
one_sided_axes <- function(pts) {
  m <- cbind(pts$mean_x, pts$mean_y, pts$mean_z)
  lo <- apply(m, 2, min) < -offset_coverage
  hi <- apply(m, 2, max) > offset_coverage
  bad <- !(lo & hi)
  if (!any(bad)) return("")
  paste(sprintf("%s: %s", c("x", "y", "z")[bad],
                ifelse(!lo[bad] & !hi[bad], "neither side",
                       ifelse(lo[bad], "none above", "none below"))),
        collapse = ", ")
}

# Bayesian information criterion of a lightweight fit on its points: n
# log(RSS / n) + k log(n), RSS the sum of the squared residuals of the
# objective (|a|^2 - 1, or |a| - 1 with use_sqrt) and k the parameters
# fitted (Schwarz 1978).
model_bic <- function(fit, pts) {
  v <- point_matrix(pts, "pts")
  temp <- if (any(c("t_x", "t_y", "t_z") %in% fit$model)) pts$temperature
  r <- residual_jacobian(fit, v, temp, isTRUE(fit$settings$use_sqrt))$r
  n <- length(r)
  n * log(sum(r^2) / n) + length(fit$model) * log(n)
}

# The standard errors the points' geometry alone allows: those of a fit
# whose residuals had the sd `floor_sigma` (in the objective's units,
# |a|^2 - 1, about twice |a| - 1). Real rest windows fit to 2-5 mg at
# best; a simulated or unusually clean recording can fit far better, and
# a parameter that only its lack of noise determines (the x offset of a
# device that rested flat on its back) is not determined.
design_se <- function(fit, pts, floor_sigma = 0.004) {
  v <- point_matrix(pts, "pts")
  temp <- if (any(c("t_x", "t_y", "t_z") %in% fit$model)) pts$temperature
  J <- residual_jacobian(fit, v, temp)$J[, fit$model, drop = FALSE]
  A <- crossprod(J)
  inv <- tryCatch(solve(A), error = function(e) NULL)
  if (is.null(inv) || rcond(A) < 1e-12) return(rep(Inf, ncol(J)))
  floor_sigma * sqrt(pmax(diag(inv), 0))
}

# gravcal's lightweight fit: Levenberg-Marquardt on the paper's objective
# over the points, with the model the points determine. "auto" tries all
# nine parameters, then scale and offset, then offset alone, and keeps the
# first whose every standard error is at most max_se; a model needs at
# least twice as many points as parameters.
fit_chosen_model <- function(pts, fargs, choice, fail) {
  if (!is.null(fargs$arithmetic) && fargs$arithmetic != "double" &&
      is.null(fargs$algorithm)) {
    fargs$algorithm <- "descent"
  }
  fargs <- utils::modifyList(list(algorithm = "lm", se = "robust"), fargs)
  if (identical(fargs$algorithm, "descent")) {
    fargs <- utils::modifyList(list(max_iter = 5000, tol = 1e-10), fargs)
  }
  # the temperature term, where the points have a temperature that varies
  # and the fit is Levenberg-Marquardt
  temp_sd <- if (is.numeric(pts$temperature) &&
                 all(is.finite(pts$temperature)) && nrow(pts) > 1) {
    stats::sd(pts$temperature)
  } else 0
  with_temp <- isTRUE(choice$use_temp) && temp_sd > 0 &&
    identical(fargs$algorithm, "lm")
  models <- if (choice$model == "auto") c("full", "scale_offset", "offset")
    else choice$model
  tries <- expand.grid(temp = if (with_temp) c(TRUE, FALSE) else FALSE,
                       model = models, stringsAsFactors = FALSE)
  why <- character(0)
  cand <- list()
  table <- data.frame(model = tries$model, temperature = tries$temp,
                      parameters = NA_integer_, determined = FALSE,
                      bic = NA_real_, chosen = FALSE)
  for (i in seq_len(nrow(tries))) {
    m <- tries$model[i]
    tt <- tries$temp[i]
    k <- as.integer(sum(model_free(m)) + 3 * tt)
    table$parameters[i] <- k
    what <- sprintf("%d parameters (%s%s)", k,
                    switch(m, full = "scale, cross-axis, offset",
                           scale_offset = "scale, offset", offset = "offset"),
                    if (tt) ", temperature offset" else "")
    if (nrow(pts) < 2 * k) {
      why <- c(why, sprintf("%d points are too few for %s", nrow(pts), what))
      next
    }
    if (m == "offset" && nzchar(one_sided <- one_sided_axes(pts))) {
      # offsets alone assume scales of 1: where an axis rested on one side
      # only, its offset would absorb its scale error
      why <- c(why, sprintf(paste0(
        "%s not determined: offsets alone need rest beyond %s g on both ",
        "sides of every axis (%s)"), what, format(offset_coverage),
        one_sided))
      next
    }
    fit <- do.call(fit_gradient, c(list(pts = pts, model = m, use_temp = tt),
                                   fargs))
    if (fit$status != "ok") return(fit)
    if (choice$model != "auto" && (!tt || i == nrow(tries))) return(fit)
    # standard errors against max_se; a temperature offset's (g per degree
    # C) at one standard deviation of the points' temperature
    se <- pmax(fit$se[fit$model], design_se(fit, pts))
    tcols <- fit$model %in% c("t_x", "t_y", "t_z")
    se[tcols] <- se[tcols] * temp_sd
    bad <- !is.finite(se) | se > choice$max_se
    if (!any(bad)) {
      table$determined[i] <- TRUE
      table$bic[i] <- model_bic(fit, pts)
      cand[[i]] <- fit
      # a forced model: the first determined form (with temperature first)
      if (choice$model != "auto") break
      next
    }
    worst <- which.max(ifelse(is.finite(se), se, Inf))
    why <- c(why, sprintf(paste0(
      "%s not determined by the rest points (standard error of %s%s %s > ",
      "max_se = %s)"), what, names(se)[worst],
      if (tcols[worst]) " times the temperature's sd" else "",
      format(signif(se[worst], 2)), format(choice$max_se)))
  }
  if (any(table$determined)) {
    best <- which(table$determined)[which.min(table$bic[table$determined])]
    table$chosen[best] <- TRUE
    fit <- cand[[best]]
    fit$message <- paste0(fit$message, sprintf(" on %d points", nrow(pts)))
    if (sum(table$determined) > 1) {
      fit$message <- paste0(fit$message, sprintf(
        ": of the %d models these points determine, the one with the lowest BIC",
        sum(table$determined)))
    }
    if (length(why)) {
      fit$message <- paste0(fit$message, "; ", paste(why, collapse = "; "))
    }
    fit$models <- table
    return(fit)
  }
  need <- 2 * min(vapply(models, function(m) sum(model_free(m)), 0))
  fail("sphere_not_covered", paste0(
    "not calibrated: the rest windows do not cover enough of the sphere (",
    nrow(pts), " distinct posture", if (nrow(pts) != 1) "s", " in cells of ",
    format(choice$cell), " g); ", if (nrow(pts) < need) {
      sprintf("at least %d are needed to fit %d parameters", need, need / 2)
    } else paste(why, collapse = "; ")), points = pts)
}

# The rest windows that are never calibration points, and why: "clipped"
# when on some axis the largest |sample| the window can hold, |mean| +
# (max - min), reaches 98 % of the sensor's full scale `range_g` (skipped
# when the range is unknown); else "norm" when the mean vector's norm is
# farther than `max_norm_error` g from 1 g. NA for the windows kept.
guard_windows <- function(rest, max_norm_error, range_g) {
  why <- rep(NA_character_, nrow(rest))
  if (nrow(rest) == 0) return(why)
  m <- cbind(rest$mean_x, rest$mean_y, rest$mean_z)
  norm <- sqrt(rowSums(m^2))
  why[abs(norm - 1) > max_norm_error] <- "norm"
  if (length(range_g) == 1 && is.finite(range_g) && range_g > 0) {
    r <- cbind(rest$range_x, rest$range_y, rest$range_z)
    if (is.null(r) || ncol(r) < 3) r <- matrix(0, nrow(m), 3)
    r[!is.finite(r)] <- 0
    reach <- rowSums(abs(m) + r >= clip_fraction * range_g) > 0
    why[reach] <- "clipped"
  }
  why
}

# A window reaches the sensor's range when a sample may lie within 2 % of
# full scale: the last counts of an ADC and a decoder's rounding.
clip_fraction <- 0.98

add_guards <- function(fit, excluded, excluded_windows, guards) {
  fit$excluded <- excluded
  fit$excluded_windows <- excluded_windows
  fit$guards <- guards
  fit
}

format_excluded <- function(excluded, guards) {
  paste0(excluded[["norm"]], " with | |v| - 1 | > ",
         format(guards$max_norm_error), " g, ", excluded[["clipped"]],
         " clipped", if (is.finite(guards$range_g))
           paste0(" (range +-", format(guards$range_g), " g)") else
             " (sensor range unknown, not checked)")
}

# Route `...` to the functions that take each argument; unknown names fail.
split_dots <- function(dots, table) {
  nms <- names(dots)
  if (length(dots) && (is.null(nms) || any(nms == ""))) {
    abort("All arguments in `...` must be named.")
  }
  known <- unlist(table, use.names = FALSE)
  bad <- setdiff(nms, known)
  if (length(bad)) {
    abort("Unknown argument", if (length(bad) > 1) "s", " in `...`: ",
          paste0("`", bad, "`", collapse = ", "), ". Known: ",
          paste(known, collapse = ", "), ".")
  }
  lapply(table, function(keep) dots[intersect(nms, keep)])
}

# Plausible coefficient ranges, far wider than the correction factors van
# Hees et al. (2014, Table 2; vignette("vanhees2014")) report for the
# devices of four cohorts (mean gain 0.990-1.005 with SD up to 0.014, mean
# offset -0.012 to 0.105 g with SD up to 0.037 g, mean temperature offset
# up to 0.004 g per degree C), so that only coefficients no real sensor
# needs are refused.
plausible <- list(scale = c(0.7, 1.3), cross = 0.2, offset = 0.6, temp = 0.05)

# A fit that does not lower the error or whose coefficients are implausible
# is not applied: identity coefficients and a status that says why.
guard_fit <- function(fit) {
  if (fit$status != "ok") return(fit)
  identity <- function(status, message) {
    fit$K[] <- diag(3)
    fit$offset[] <- 0
    fit$tempoffset[] <- 0
    if (!is.null(fit$params)) fit$params[] <- c(1, 1, 1, 0, 0, 0, 0, 0, 0)
    fit$status <- status
    fit$message <- message
    fit <- refresh_errors(clear_uncertainty(fit))
    fit
  }
  before <- fit$error_before
  after <- fit$error_after
  if (!(after < before)) {
    return(identity("no_improvement", sprintf(paste0(
      "calibration not applied: it does not lower the error on the rest ",
      "points (%.2f mg before, %.2f mg after)"), 1000 * before,
      1000 * after)))
  }
  K <- fit$K
  off <- abs(K[lower.tri(K)])
  if (any(diag(K) < plausible$scale[1] | diag(K) > plausible$scale[2]) ||
      any(off > plausible$cross) || any(abs(fit$offset) > plausible$offset)) {
    return(identity("implausible", paste0(
      "calibration not applied: coefficients outside plausible ranges ",
      "(scale ", plausible$scale[1], "-", plausible$scale[2],
      ", |cross-axis| <= ", plausible$cross, ", |offset| <= ",
      plausible$offset, " g)")))
  }
  fit
}

# Attach the rest windows and held-out errors.
finish_fit <- function(fit, rest) {
  fit$windows <- rest
  fit$n_windows <- attr(rest, "n_windows")
  used <- if (is.null(fit$points$row)) integer(0) else fit$points$row
  held <- rest[setdiff(seq_len(nrow(rest)), used), , drop = FALSE]
  fit$error_heldout_before <- NA_real_
  fit$error_heldout_after <- NA_real_
  if (nrow(held) > 0) {
    v <- point_matrix(held, "held")
    fit$error_heldout_before <- sphere_error(v)
    fit$error_heldout_after <- sphere_error(if (segmented(fit)) {
      calibrate_points_by_time(fit, v, held$start, held$temperature)
    } else calibrate_points(fit, v, held$temperature))
  }
  if (segmented(fit) && NROW(fit$points)) {
    v <- point_matrix(fit$points, "points")
    fit$error_after <- sphere_error(calibrate_points_by_time(
      fit, v, fit$points$start, fit$points$temperature))
  }
  fit
}

# Constructor of the one fit class both methods return.
new_fit <- function(K = diag(3), offset = c(0, 0, 0), tempoffset = c(0, 0, 0),
                    meantemp = NA_real_, points = NULL, method, iterations = 0L,
                    converged = FALSE, status = "ok", message = "", call = NULL) {
  dimnames(K) <- list(c("x", "y", "z"), c("x", "y", "z"))
  fit <- list(K = K, offset = stats::setNames(as.double(offset), c("x", "y", "z")),
              tempoffset = stats::setNames(as.double(tempoffset),
                                           c("x", "y", "z")),
              meantemp = meantemp, points = points,
              iterations = as.integer(iterations), converged = converged,
              status = status, message = message, method = method, call = call)
  class(fit) <- "gravcal_fit"
  fit <- refresh_errors(clear_uncertainty(fit))
  # the coefficients the model fitted, named as in coef() (none when the
  # fit is the identity)
  if (identical(status, "ok")) fit$model <- fitted_names(fit)
  fit
}

refresh_errors <- function(fit) {
  fit$error_before <- NA_real_
  fit$error_after <- NA_real_
  if (!is.null(fit$points) && nrow(fit$points) > 0) {
    v <- point_matrix(fit$points, "points")
    fit$error_before <- sphere_error(v)
    fit$error_after <- sphere_error(calibrate_points(fit, v,
                                                     fit$points$temperature))
  }
  fit
}

# Mean | |v| - 1 | over the rows of an n x 3 matrix.
sphere_error <- function(v) {
  mean(abs(sqrt(rowSums(v^2)) - 1))
}

# Calibrated n x 3 matrix of a fit's model (apply_model()), with the
# temperature term where the fit has one and `temperature` is given.
calibrate_points <- function(fit, v, temperature = NULL) {
  dt <- if (any(fit$tempoffset != 0) && !is.null(temperature)) {
    temperature - fit$meantemp
  }
  unname(apply_model(v, fit$K, fit$offset, fit$tempoffset, dt))
}

#' @export
coef.gravcal_fit <- function(object, ...) {
  check_fit(object, "object")
  K <- object$K
  stats::setNames(c(diag(K), K[2, 1], K[3, 1], K[3, 2], object$offset,
                    object$tempoffset),
                  c(param_names(), "t_x", "t_y", "t_z"))
}

#' @export
print.gravcal_fit <- function(x, digits = 5, ...) {
  check_fit(x, "x")
  check_number(digits, "digits", min = 0, max = 15, integer = TRUE)
  cat("<gravcal_fit> ", x$method, " method, status: ", x$status, "\n",
      sep = "")
  if (nzchar(x$message)) cat("  ", x$message, "\n", sep = "")
  inp <- format_input(x$input)
  if (!is.null(inp)) cat("  input: ", inp, "\n", sep = "")
  np <- if (is.null(x$points)) 0L else nrow(x$points)
  nw <- if (is.null(x$windows)) NA else nrow(x$windows)
  cat(sprintf("  points: %d", np))
  if (!is.na(nw)) {
    cat(sprintf(" of %d rest windows (%s windows in all)", nw,
                format(x$n_windows)))
  }
  cat("\n")
  if (!is.null(x$excluded)) {
    cat("  rest windows left out: ", format_excluded(x$excluded, x$guards),
        "\n", sep = "")
  }
  if (identical(x$budget$budget, "adaptive")) {
    b <- x$budget
    cat(sprintf("  adaptive budget: read %.1f%s hours, %s\n", b$hours_read,
                if (is.finite(b$hours_total)) sprintf(" of %.1f", b$hours_total)
                else "", if (b$stopped) sprintf(paste0(
                  "stopped once every standard error was at most %s and ",
                  "the coefficients stable"), format(b$target_se)) else
                  "the target was not reached before the end"))
  }
  if (is.finite(x$error_before)) {
    cat(sprintf("  error on fitting points: %.2f mg -> %.2f mg\n",
                1000 * x$error_before, 1000 * x$error_after))
  }
  if (isTRUE(is.finite(x$error_heldout_before))) {
    cat(sprintf("  error on held-out rest:  %.2f mg -> %.2f mg\n",
                1000 * x$error_heldout_before, 1000 * x$error_heldout_after))
  }
  cat("  K (a = K (v + offset)):\n")
  K <- format(round(x$K, digits), nsmall = digits)
  cat(paste0("    ", apply(K, 1, paste, collapse = "  "), collapse = "\n"),
      "\n")
  cat("  offset (g):", format(round(x$offset, digits), nsmall = digits), "\n")
  if (any(x$tempoffset != 0)) {
    cat("  tempoffset (g/degree C):",
        format(signif(x$tempoffset, digits)), "\n")
    cat("  meantemp (degree C):", format(x$meantemp), "\n")
  }
  print_se(x$se, x$df)
  if (segmented(x)) {
    seg <- x$segments
    cat(sprintf("  %d segments over time (coefficients in fit$segments):\n",
                nrow(seg)))
    for (i in seq_len(nrow(seg))) {
      cat(sprintf("    %d: %s to %s, %d points, offset %s\n", i,
                  format_segment_time(x, seg$from[i]),
                  format_segment_time(x, seg$to[i]), seg$points[i],
                  paste(format(round(c(seg$o_x[i], seg$o_y[i], seg$o_z[i]),
                                     digits), nsmall = digits),
                        collapse = " ")))
    }
  }
  invisible(x)
}

# A segment boundary for people: hours from the start of the recording.
format_segment_time <- function(fit, t) {
  if (!is.finite(t)) return(if (t < 0) "start" else "end")
  sprintf("%.1f h", (t - fit$segment_settings$origin) / 3600)
}

# The standard errors that exist, by group.
print_se <- function(se, df) {
  if (is.null(se) || !any(is.finite(se))) return(invisible())
  cat(sprintf("  standard errors (%d residual df):\n", as.integer(df)))
  groups <- list("scale" = c("k_xx", "k_yy", "k_zz"),
                 "cross-axis" = c("k_xy", "k_xz", "k_yz"),
                 "offset (g)" = c("o_x", "o_y", "o_z"),
                 "tempoffset (g/degree C)" = c("t_x", "t_y", "t_z"))
  for (g in names(groups)) {
    v <- se[groups[[g]]]
    if (any(is.finite(v))) {
      cat("    ", g, ": ", paste(format(signif(v, 2)), collapse = " "),
          "\n", sep = "")
    }
  }
  invisible()
}

#' @export
summary.gravcal_fit <- function(object, ...) {
  check_fit(object, "object")
  co <- stats::coef(object)
  num <- function(v) if (length(v) == 1 && is.numeric(v)) v else NA_real_
  err <- data.frame(set = "fitting points", n = NROW(object$points),
                    before_mg = 1000 * num(object$error_before),
                    after_mg = 1000 * num(object$error_after))
  # the held-out set: rest windows not used as points, where the fit keeps
  # its rest windows apart from its points (the lightweight method)
  if (!is.null(object$windows) && !is.null(object$points$row)) {
    err <- rbind(err, data.frame(
      set = "held-out rest windows",
      n = NROW(object$windows) - length(unique(object$points$row)),
      before_mg = 1000 * num(object$error_heldout_before),
      after_mg = 1000 * num(object$error_heldout_after)))
  }
  err$improvement <- err$before_mg / err$after_mg
  bins <- NULL
  if (!is.null(object$points$bin)) bins <- table(object$points$bin)
  se <- object$se
  if (is.null(se)) se <- stats::setNames(rep(NA_real_, length(co)), names(co))
  co <- cbind(estimate = co, se = unname(se[names(co)]))
  structure(list(method = object$method, status = object$status,
                 message = object$message, coefficients = co, errors = err,
                 df = if (is.null(object$df)) NA_integer_ else object$df,
                 bins = bins, iterations = object$iterations,
                 converged = object$converged),
            class = "summary.gravcal_fit")
}

#' @export
print.summary.gravcal_fit <- function(x, ...) {
  cat("gravcal calibration (", x$method, " method)\n", sep = "")
  cat("status: ", x$status, if (nzchar(x$message)) paste0(" - ", x$message),
      "\n\n", sep = "")
  cat("Coefficients:\n")
  co <- x$coefficients
  if (any(is.finite(co[, "se"]))) {
    cat("(standard errors on ", x$df, " residual df; NA: not fitted)\n",
        sep = "")
    print(cbind(estimate = round(co[, "estimate"], 6),
                se = signif(co[, "se"], 3)))
  } else {
    print(round(co[, "estimate"], 6))
  }
  cat("\nError | |a| - 1 | (mg):\n")
  e <- x$errors
  e$before_mg <- round(e$before_mg, 2)
  e$after_mg <- round(e$after_mg, 2)
  e$improvement <- round(e$improvement, 2)
  print(e, row.names = FALSE)
  if (!is.null(x$bins)) {
    cat("\nPoints per orientation bin:\n")
    print(x$bins)
  }
  cat("\niterations:", x$iterations, "\n")
  invisible(x)
}
