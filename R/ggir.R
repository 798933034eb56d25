# The GGIR auto-calibration procedure (van Hees et al. 2014; GGIR's
# g.calibrate): its constants and messages, and the one call into the core
# that runs it on a recording (ggir_run(); the procedure itself is
# GgirProcedure in ggir_procedure.hpp).
#
# GGIR-compatible mode reproduces GGIR 3.3's behaviour rule by rule, its
# quirks included. gravcal's own mode differs only where GGIR's behaviour is
# an accident (see ?calibrate, "The GGIR method"):
#   1. the fit runs to convergence instead of stopping on GGIR's statistic;
#   2. only windows identical to the next one in all six means and sds are
#      dropped as duplicates (GGIR drops a window when exactly 3 of the 6
#      values match, and keeps fully identical ones);
#   3. "enough data" means at least one hour of distinct windows (GGIR
#      compares the number of windows with minloadcrit - 21, a number of
#      hours), in a recording of at least two hours (GGIR asks that of its
#      first block, whose size chunksize scales);
#   4. samples left over at the end of a block always carry to the next
#      block, and the last sample before a run of idle-sleep zeros keeps its
#      own value (GGIR overwrites it with the sample before it).

# GGIR's constants, each with where it comes from (van Hees et al. 2014,
# doi:10.1152/jappphysiol.00421.2014; GGIR 3.3 g.calibrate, g.part1 and
# load_params). Every rule of the procedure takes its number from here.
ggir_constants <- list(
  window = 10,            # s, window length (paper; GGIR's calibEpochSize)
  max_sd = 0.013,         # g, rest: sd of every axis below (paper: 13 mg)
  max_abs_mean = 2,       # g, rest: |mean| of every axis below (clipping guard)
  min_rest = 10,          # rest windows needed to try a fit (g.calibrate)
  spherecrit = 0.3,       # g, each axis needs rest means beyond -+ this
  minloadcrit = 168,      # h, read at least this much before stopping (load_params)
  enough_offset = 21,     # GGIR's "enough data" test: windows > minloadcrit - 21
  min_hours = 1,          # h, gravcal's own "enough data" (distinct windows)
  max_error = 0.01,       # g, error after calibration accepted as done
  error_digits = 5,       # errors rounded to 5 digits before comparing
  temp_max_first = 120,   # temperature ignored when its first values exceed
  temp_min_sd = 0.01,     # temperature ignored when its sd is below
  temp_first_n = 10,      # how many first values are looked at
  temp_missing = 99999,   # GGIR's fill for an unused temperature column
  fill = 99999,           # GGIR's fill of its window table: such rows are dropped
  max_iter = 1000,        # ICP iterations (g.calibrate)
  tol = 1e-10,            # ICP stopping tolerance (g.calibrate)
  max_weight = 100,       # ICP weights capped at 1 / 0.01 (g.calibrate)
  block_hours = 12,       # GGIR reads about 12 h per block (chunksize = 1)
  refit_growth = 1.25,    # gravcal's own mode: refit once the table grew by this
  rmc_noise = 13          # g, GGIR's rmc.noise for ad hoc csv files when none is
                          # given (load_params(), GGIR 3.3-9): rest is then
                          # sd < 15.6 g, so |mean| < 2 g alone decides
)

# The memory in use, in MB, for GGIR's bsc_qc record: the process's
# resident memory where the system says it without cost (Linux's
# /proc/self/status, which counts the decoders' buffers too), else R's
# vector heap after a minor collection (GGIR's figure is that after a full
# one).
memory_in_use_mb <- function() {
  status <- "/proc/self/status"
  if (file.exists(status)) {
    l <- grep("^VmRSS:", readLines(status, warn = FALSE), value = TRUE)
    kb <- suppressWarnings(as.numeric(gsub("[^0-9]", "", l)))
    if (length(kb) == 1 && is.finite(kb)) return(kb / 1024)
  }
  gc(full = FALSE)[2, 2]
}

ggir_messages <- c(
  done = "recalibration done, no problems detected",
  done_no_temp = "recalibration done, but temperature values not used",
  attempted = paste0("recalibration attempted with all available data, but ",
                     "possibly not good enough: Check calibration error ",
                     "variable to varify this"),
  no_decrease = "recalibration not done because recalibration does not decrease error",
  no_sphere = "recalibration not done because not enough points on all sides of the sphere",
  no_rest = "recalibration not done because no non-movement data available",
  no_data = paste0("recalibration not done because not enough data in the ",
                   "file or because file is corrupt"),
  # gravcal's own: where GGIR's fit fails with an error
  not_finite = paste0("recalibration not done because the fit did not stay ",
                      "finite (the rest windows do not determine every ",
                      "coefficient)")
)

ggir_feature_names <- function(temp) {
  c("Euclidean Norm", "meanx", "meany", "meanz", "sdx", "sdy", "sdz",
    if (temp) "temperature")
}

# Run the procedure on a source (see open_source()): one call into the core
# (ggir_procedure.hpp), which reads the source block by block through the
# pump. Returns GGIR's list plus, in attribute "gravcal", what calibrate()
# needs.
ggir_run <- function(src, compat = TRUE,
                     spherecrit = ggir_constants$spherecrit,
                     minloadcrit = ggir_constants$minloadcrit,
                     sdcriter = ggir_constants$max_sd, verbose = FALSE,
                     printsummary = FALSE, max_iter = ggir_constants$max_iter,
                     tol = ggir_constants$tol, lazy = TRUE,
                     guards = NULL, reading = "ggir", check_hours = 6,
                     on_fit = NULL) {
  sf <- src$sf
  if (!(10 * sf >= 1 && 10 * sf < 1e7)) {
    abort("`sf` must give 1 to 1e7 samples in a 10 s window, not ",
          format(10 * sf), " (sf = ", format(sf), " Hz",
          if (isTRUE(!is.na(src$filename))) paste0(", from \"", src$filename, "\""),
          ").")
  }
  opts <- ggir_options(compat, sf, spherecrit, minloadcrit, sdcriter, max_iter,
                       tol, verbose, block_units = src$units,
                       short_block_rows = src$short_rows %||% 0,
                       temperature = isTRUE(src$temperature), lazy = lazy,
                       guards = guards, reading = reading,
                       check_hours = check_hours)
  # a non-finite sample read from a file enters R's cumulative sums as in
  # GGIR (GGIRread's resampling of repeated time stamps gives NaN); one in
  # a data frame (which GGIR does not take) is left out of its window
  opts$nonfinite_in_sums <- as.numeric(!identical(src$format, "data.frame"))
  # the windows' sums on a second thread beside the decode (the same
  # windows; options(gravcal.threads = 1): one thread)
  opts$threads <- gravcal_threads()
  # the adaptive budget's rule, called by the core after a converged fit
  # that meets GGIR's error target (GgirHost::enough())
  if (!is.null(on_fit)) opts$on_fit <- on_fit
  # memory in use after each block (GGIR records R's heap from a full gc(),
  # which costs about as much as decoding the block)
  bsc <- list()
  record <- function(i) {
    bsc[[length(bsc) + 1]] <<- data.frame(time = format(Sys.time()),
                                          size = memory_in_use_mb(),
                                          stringsAsFactors = FALSE)
    NULL
  }
  # (in g.part1(), g.getmeta()'s first block is read beside this pass:
  # R/meta-ahead.R)
  r <- gc_pump(src$pump(), "ggir", opts, record, meta_ahead_spec())
  check_source_read(src, r$samples)
  ggir_result(r, if (length(bsc)) do.call(rbind, bsc) else data.frame(),
              source_input(src, r$samples), verbose, printsummary)
}

# The procedure's settings for the core (GgirConfig in ggir_config.hpp):
# the user's, then GGIR's constants.
# `reading` (own mode only): when to stop reading: "ggir" (GGIR's rule,
# minloadcrit), "all" (the whole recording, for coefficients per segment of
# time) or "adaptive" (the adaptive budget: a check every `check_hours`
# hours of windows, or once the table grew by a quarter, whichever is later).
ggir_options <- function(compat, sf, spherecrit, minloadcrit, sdcriter, max_iter,
                         tol, verbose, block_units = 0, short_block_rows = 0,
                         temperature = TRUE, lazy = TRUE, guards = NULL,
                         reading = "ggir", check_hours = 6) {
  k <- ggir_constants
  # own mode's guards on rest windows (see guard_windows(), lightweight.R);
  # none in compatible mode, nor when not given
  g <- if (compat) NULL else guards
  clip <- if (length(g$range_g) == 1 && is.finite(g$range_g)) clip_fraction * g$range_g else 0
  opts <- list(compat = compat, sf = sf, block_units = block_units,
               short_block_rows = short_block_rows, temperature = temperature,
               lazy = lazy, spherecrit = spherecrit, minloadcrit = minloadcrit,
               max_sd = sdcriter, max_abs_mean = k$max_abs_mean,
               min_rest = k$min_rest, enough_offset = k$enough_offset,
               min_hours = k$min_hours, max_error = k$max_error,
               error_digits = k$error_digits, temp_max_first = k$temp_max_first,
               temp_min_sd = k$temp_min_sd, temp_missing = k$temp_missing,
               fill = k$fill, max_iter = max_iter, tol = tol,
               max_weight = k$max_weight, refit_growth = k$refit_growth,
               verbose = verbose,
               guard_norm = if (is.null(g$max_norm_error)) Inf else g$max_norm_error,
               guard_clip = clip,
               guard_repeat = if (is.null(g$max_identical)) Inf else g$max_identical,
               reading = match(reading, c("ggir", "all", "adaptive")) - 1,
               check_hours = check_hours)
  lapply(opts, as.numeric)
}

# GGIR's list from the core's outcome `r` (gc_pump(stage = "ggir") or
# gc_ggir_fit_table()), with what calibrate() needs in attribute "gravcal".
ggir_result <- function(r, bsc_qc, input, verbose = FALSE, printsummary = FALSE) {
  for (w in r$warnings) warning(w, call. = FALSE)
  QC <- if (nzchar(r$qc)) ggir_messages[[r$qc]]
  spheredata <- NULL
  ft <- r$table
  if (!is.null(ft) && nrow(ft) > 0 && ncol(ft) > 0) {
    spheredata <- as.data.frame(unname(ft))
    attr(spheredata, "row.names") <- r$rows
    nm <- ggir_feature_names(r$use.temp)
    names(spheredata) <- c(nm, rep(NA_character_, ncol(ft) - length(nm)))
  }
  use.temp <- r$use.temp
  meantempcal <- if (use.temp && length(spheredata) > 0) mean(spheredata[, 8], na.rm = TRUE) else NULL
  out <- list(scale = r$scale, offset = r$offset, tempoffset = r$tempoffset,
              cal.error.start = r$cal.error.start, cal.error.end = r$cal.error.end,
              spheredata = spheredata, npoints = r$npoints,
              nhoursused = r$nhoursused, QCmessage = QC, use.temp = use.temp,
              meantempcal = meantempcal, bsc_qc = bsc_qc)
  if (printsummary && verbose) ggir_print_summary(out)
  if (verbose) cat("\n")
  icp <- r$icp
  if (!is.null(icp)) icp$meantemp <- r$meantemp
  attr(out, "gravcal") <- list(icp = icp, meantemp = r$meantemp,
                               blocks = r$blocks, input = input,
                               temp.available = r$temp.available,
                               windows = r$windows, samples = r$samples,
                               zeros = r$zeros, excluded = r$excluded,
                               early = isTRUE(r$early),
                               temperature_warnings = as.character(r$warnings))
  out
}

# GGIR's summary of the procedure (printsummary = TRUE).
ggir_print_summary <- function(out) {
  cat("\nSummary of autocalibration procedure:\n")
  cat(paste0("\nStatus: ", out$QCmessage))
  cat(paste0("\nCalibration error (g) before: ", out$cal.error.start))
  cat(paste0("\nCalibration error (g) after: ", out$cal.error.end))
  cat(paste0("\nOffset correction ", c("x", "y", "z"), ": ", out$offset))
  cat(paste0("\nScale correction ", c("x", "y", "z"), ": ", out$scale))
  cat(paste0("\nNumber of hours used: ", out$nhoursused))
  cat(paste0("\nNumber of 10 second windows around the sphere: ", out$npoints))
  cat(paste0("\nTemperature used (if available): ", out$use.temp))
  cat(paste0("\nTemperature offset (if temperature is available) ",
             c("x", "y", "z"), ": ", out$tempoffset))
  cat("\n")
}

# ggir_run() on `src`, then, in compatible mode, once more without the lazy
# sds (on a source from open()) when the result's spheredata holds windows
# that are not at rest: GGIR returns every window when the recording is too
# short to use, and only rest windows are sure to carry R's sds otherwise.
ggir_run_exact <- function(src, open, compat, ...) {
  out <- ggir_run(src, compat = compat, ...)
  if (compat && identical(out$QCmessage, ggir_messages[["no_data"]]) &&
      length(out$spheredata) > 0) {
    if (isTRUE(list(...)$verbose)) cat("\nReading again for R's sds of every window\n")
    out <- ggir_run(open(), compat = compat, ..., lazy = FALSE)
  }
  out
}

# gravcal's own mode beyond one fit: coefficients per segment of time
# (`segments`, `change_alpha`) and the adaptive budget (`budget`,
# `target_se`, `check_hours`), as for the lightweight method. GGIR's
# g.calibrate() has no such parameters, so compatible mode refuses them.
ggir_over_time_names <- c("segments", "change_alpha", "budget", "target_se",
                          "check_hours")

# These arguments from calibrate()'s `...`, checked (check_choice_args());
# NULL when none is given.
ggir_over_time <- function(dots, compat) {
  given <- intersect(names(dots), ggir_over_time_names)
  if (!length(given)) return(NULL)
  if (compat) {
    abort(paste0("`", given, "`", collapse = ", "), " cannot be used with ",
          "`ggir_compat = TRUE`: GGIR's g.calibrate() has no such ",
          "parameter (coefficients per segment of time and the adaptive ",
          "budget are gravcal's own mode's; give `ggir_compat = FALSE`).")
  }
  ch <- check_choice_args(dots[given], list())
  if (!is.null(ch$segments) && ch$budget == "adaptive") {
    abort("`segments` and `budget = \"adaptive\"` cannot be combined for ",
          "`method = \"ggir\"`: coefficients per segment of time need the ",
          "whole recording read.")
  }
  ch
}

# How the procedure reads for these choices (ggir_options()'s `reading`).
ggir_reading <- function(over) {
  if (is.null(over)) return("ggir")
  if (!is.null(over$segments)) return("all")
  if (identical(over$budget, "adaptive")) return("adaptive")
  "ggir"
}

# The adaptive budget's stop rule for GGIR's procedure: the core calls it
# (GgirHost::enough()) with its outcome after a converged fit that meets
# GGIR's error target; TRUE stops the reading once the fit's standard
# errors (those of ggir_fit(): the Jacobian at the solution with GGIR's
# weights) are at most target_se and the coefficients are stable since the
# previous check (budget_met(), as for the lightweight method).
ggir_budget_rule <- function(target_se, minloadcrit) {
  prev <- NULL
  function(r) {
    r$warnings <- character(0)  # the run reports them once, at its end
    r$qc <- "done"              # the core called: GGIR's error target met
    f <- ggir_fit(ggir_result(r, data.frame(), list()), FALSE, call = NULL,
                  minloadcrit)
    if (!identical(f$status, "ok")) {
      prev <<- NULL
      return(FALSE)
    }
    # the previous check's offsets at this fit's reference temperature
    if (!is.null(prev)) prev <- ggir_rereference(prev, f$meantemp)
    done <- budget_met(f, prev, target_se)
    prev <<- f
    done
  }
}

# A fit of GGIR's model with its temperature term referred to `meantemp`
# instead of the mean temperature of its points, where GGIR's ICP centres
# it: the same model, (v + o) s + (T - m') t = (v + o + (m - m') t / s) s +
# (T - m) t, so only the offsets move; the covariance is taken again there
# (add_uncertainty(), GGIR's weights), so that fits of different stretches
# of a recording compare (segments, the adaptive budget's checks).
ggir_rereference <- function(f, meantemp) {
  if (!isTRUE(f$use_temp) || !any(f$tempoffset != 0) ||
      !isTRUE(is.finite(meantemp)) || identical(f$meantemp, meantemp)) {
    return(f)
  }
  f$offset <- f$offset + (meantemp - f$meantemp) * f$tempoffset / diag(f$K)
  f$meantemp <- meantemp
  pts <- f$points
  add_uncertainty(f, cbind(pts$mean_x, pts$mean_y, pts$mean_z),
                  pts$temperature, weights = "ggir",
                  max_weight = ggir_constants$max_weight)
}
