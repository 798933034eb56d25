# The lightweight method (Farago, Maczak & Gingl 2024) from rest windows to
# a fit: its arguments, the guards on its windows, the fit.

# The lightweight method's arguments from calibrate()'s `...`, routed and
# checked: list(args (by destination), choice, max_norm_error, range_g,
# max_identical, off_sphere).
lightweight_args <- function(dots) {
  args <- split_dots(dots, list(
    rest_windows = c("window", "max_range", "axes", "skip_zero",
                     "block_samples", "chunk_size", "progress", "reader", "rmc"),
    guards = c("max_norm_error", "range_g", "max_identical", "off_sphere"),
    choice = c("selection", "cell", "max_se", "model", "use_temp",
               "segments", "change_alpha", "budget", "target_se",
               "check_hours"),
    select_points = c("per_bin", "min_per_bin", "min_distance"),
    fit_gradient = c("arithmetic", "max_iter", "rates", "h", "objective",
                     "use_sqrt", "tol", "trace", "difference", "algorithm",
                     "se")))
  choice <- check_choice_args(args$choice, args$select_points)
  g <- guard_args(args$guards)
  list(args = args, choice = choice, max_norm_error = g$max_norm_error,
       range_g = g$range_g, max_identical = g$max_identical,
       off_sphere = g$off_sphere)
}

# The guards' arguments (max_norm_error, range_g, max_identical, and the
# cut-off of the rule on rest that is not on the sphere, off_sphere, in
# robust spreads: near-rest.R), checked, with their defaults; range_g NULL
# when not given (the file's, or unknown).
guard_args <- function(gargs) {
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
  max_identical <- if (is.null(gargs$max_identical)) default_max_identical else
    gargs$max_identical
  check_number(max_identical, "max_identical", min = 0, max = 1)
  off_sphere <- gargs$off_sphere %||% near_rest_rule$k
  if (!identical(off_sphere, Inf)) {
    check_number(off_sphere, "off_sphere", min = 1)
  }
  list(max_norm_error = max_norm_error, range_g = range_g,
       max_identical = max_identical, off_sphere = off_sphere)
}

# The lightweight method from its windows (rest_windows()'s table, with its
# attributes): the guards, the points, the fit and the held-out errors.
# `file`: the file's name for the fit (NULL for samples in memory); `timed`:
# whether the windows' start comes from a `time` column.
lightweight_from_windows <- function(w, args, choice, max_norm_error, range_g,
                                     call, file = NULL, timed = FALSE,
                                     max_identical = default_max_identical,
                                     off_sphere = near_rest_rule$k) {
  if (is.null(range_g)) range_g <- attr(w, "input")$range_g
  rest <- w[w$rest, , drop = FALSE]
  why <- guard_windows(rest, max_norm_error, range_g, max_identical)
  excluded <- count_excluded(why)
  excluded_windows <- rest[!is.na(why), , drop = FALSE]
  excluded_windows$why <- why[!is.na(why)]
  rest <- rest[is.na(why), , drop = FALSE]
  rownames(rest) <- NULL
  attr(rest, "n_windows") <- nrow(w)
  guards <- list(max_norm_error = max_norm_error,
                 range_g = if (is.null(range_g)) NA_real_ else range_g,
                 max_identical = max_identical)
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
    # the samples exactly 0 on all three axes are skipped (skip_zero): when
    # they are all there is, the recording is not short but empty
    n <- attr(w, "samples")
    zeros <- attr(w, "skipped_zero")
    if (is.null(zeros)) zeros <- 0
    if (n > 0 && zeros >= n) {
      return(fail("all_zero", sprintf(paste0(
        "no data: all %.0f samples are exactly 0 on all three axes (ActiGraph ",
        "idle sleep, or a device that recorded nothing); there is nothing to ",
        "calibrate"), n)))
    }
    if (zeros > 0) {
      return(fail("too_short", sprintf(paste0(
        "recording too short: of %.0f samples, %.0f are exactly 0 on all ",
        "three axes (skipped as idle sleep) and the other %.0f are fewer ",
        "than one %g s window at %g Hz"), n, zeros, n - zeros,
        attr(w, "window"), attr(w, "sf"))))
    }
    return(fail("too_short", sprintf(paste0(
      "recording too short: %.0f samples, fewer than one %g s window at %g Hz"),
      n, attr(w, "window"), attr(w, "sf"))))
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
    fit_rest <- function(keep) {
      pts <- select_points(rest[keep, , drop = FALSE], selection = "cells",
                           cell = choice$cell)
      fit <- fit_chosen_model(pts, args$fit_gradient, choice, fail)
      if (fit$status == "sphere_not_covered") return(fit)
      fit$call <- call
      fit$selection <- choice
      guard_fit(fit)
    }
    fit <- fit_rest(rep(TRUE, nrow(rest)))
    if (fit$status == "sphere_not_covered") return(fit)
    # rest that is not rest (near_rest_trim(), near-rest.R): the windows
    # far off the sphere after the fit are left out and the fit done again
    # (off_sphere = Inf: not applied)
    if (is.finite(off_sphere)) {
      v <- point_matrix(rest, "rest")
      secs <- if (inherits(rest$start, "POSIXct")) {
        as.numeric(rest$start) - as.numeric(w$start[1])
      } else rest$start - w$start[1]
      # a device's recordings pooled (pool.R) have no one time line: their
      # windows are left out, without stretches
      pooled <- identical(attr(w, "input")$source, "pooled")
      nr <- near_rest_trim(fit, v, rest$temperature, function(keep) {
        f <- fit_rest(keep)
        # the points' rows are those of the windows kept
        if (!is.null(f$points$row)) f$points$row <- which(keep)[f$points$row]
        f
      }, k = off_sphere, start = if (!pooled) secs, window = attr(w, "window"))
      fit <- nr$fit
      rejected_windows <- rest[nr$out, , drop = FALSE]
      rejected_windows$residual <- near_rest_residuals(
        fit, v[nr$out, , drop = FALSE], rejected_windows$temperature)
      stretches <- near_rest_stretches(
        secs, nr$out & !pooled, near_rest_residuals(fit, v, rest$temperature),
        attr(w, "window"), clock = if (inherits(w$start, "POSIXct")) {
          w$start[1]
        } else near_rest_clock(NULL, attr(w, "input")))
      if (any(nr$out)) {
        keep <- !nr$out
        fit$points$row <- match(fit$points$row, which(keep))
        rest <- rest[keep, , drop = FALSE]
        rownames(rest) <- NULL
        attr(rest, "n_windows") <- nrow(w)
      }
      fit <- add_near_rest(fit, nr$rejected, stretches)
      fit$rejected_windows <- rejected_windows
    }
    if (!is.null(choice$segments) && fit$status == "ok") {
      fit <- fit_segments(fit, rest$start, origin = w$start[1],
                          segment_fitter_lw(fit, rest, args$fit_gradient,
                                            choice), choice)
      fit$segment_settings$time <- if (timed) "time" else "seconds"
      fit$segment_settings$sf <- attr(w, "sf")
    }
    fit$hours <- hours
    fit$budget <- budget
    fit$input <- attr(w, "input")
    fit$file <- file
    fit <- add_guards(fit, excluded, excluded_windows, guards)
    return(judge_error(finish_fit(fit, rest)))
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
  judge_error(finish_fit(fit, rest))
}

# The lightweight method's judgement of its error after calibration, GGIR's
# rule (ggir_constants$max_error): a fit whose calibration points stay 10 mg
# or more off the sphere on average (mean | |v| - 1 |, `error_after`) is
# "high_error", its coefficients kept, as the GGIR method keeps them. At
# rest, points are 10 s means whose noise is well under 1 mg, so 10 mg left
# after the fit means the points are not all rest or the model does not fit.
judge_error <- function(fit) {
  e <- fit$error_after
  if (identical(fit$status, "ok") && length(e) == 1 && is.finite(e) &&
      e >= ggir_constants$max_error) {
    fit$status <- "high_error"
    fit$message <- paste0(if (nzchar(fit$message)) paste0(fit$message, "; "),
      sprintf(paste0(
      "the calibration points are still %.1f mg off 1 g on average after ",
      "the fit (%.0f mg or more): some may not be rest, or the model may ",
      "not fit the device; inspect them with plot()"), 1000 * e,
      1000 * ggir_constants$max_error))
  }
  fit
}

# The rest windows that are never calibration points, and why: "identical"
# when more than `max_identical` of the window's samples after its first
# equal the one before them in x, y and z (`n_repeat`: a stuck sensor,
# ActiGraph's idle sleep repeating its last sample, a run of zeros; see
# default_max_identical); else "clipped" when on some axis the largest
# |sample| the window can hold, |mean| + (max - min), reaches 98 % of the
# sensor's full scale `range_g` (skipped when the range is unknown); else
# "norm" when the mean vector's norm is farther than `max_norm_error` g
# from 1 g. NA for the windows kept. GGIR's procedure in gravcal's own mode
# applies the same rules in the core (GgirProcedure::guard()).
guard_windows <- function(rest, max_norm_error, range_g,
                          max_identical = default_max_identical) {
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
  if (!is.null(rest$n_repeat) && !is.null(rest$n)) {
    valid <- rest$n - if (is.null(rest$n_invalid)) 0L else rest$n_invalid
    same <- valid > 1 & rest$n_repeat > max_identical * (valid - 1)
    why[!is.na(same) & same] <- "identical"
  }
  why
}

# The reasons guard_windows() gives, counted (named integers).
excluded_reasons <- c("norm", "clipped", "identical")
count_excluded <- function(why) {
  ex <- table(factor(why[!is.na(why)], levels = excluded_reasons))
  stats::setNames(as.integer(ex), names(ex))
}

# A rest window is left out as "identical" when more than this fraction of
# its samples (after the first) equal the sample before them in x, y and z.
# Measured (bench/rest-quality.R, bench/results/rest-quality.md) on the
# rest windows of the real recordings the tests reach: at most 0.36 of a
# still sensor's samples repeat the one before (Axivity AX3 at 100 Hz,
# GGIRread's ax3_testfile.cwa: median 0.35; ActiGraph at 30 Hz, agcounts'
# 20.7 h: median 0.04, largest 0.24 of 8171 windows; ActiGraph .gt3x
# 0.26; AX6 0). Idle sleep, a stuck sensor or zeros give (n - 2) / (n - 1)
# or more (only a window's first samples can differ). 0.8 keeps twice the
# largest measured fraction clear of the limit; a window that is 80 %
# constant is no longer a measurement of the posture's gravity.
default_max_identical <- 0.8

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
  ident <- if ("identical" %in% names(excluded)) excluded[["identical"]] else 0L
  mi <- if (is.null(guards$max_identical)) default_max_identical else
    guards$max_identical
  paste0(excluded[["norm"]], " with | |v| - 1 | > ",
         format(guards$max_norm_error), " g, ", excluded[["clipped"]],
         " clipped", if (isTRUE(is.finite(guards$range_g)))
           paste0(" (range +-", format(guards$range_g), " g)") else
             " (sensor range unknown, not checked)",
         ", ", ident, " with more than ", format(100 * mi),
         " % of samples identical")
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
