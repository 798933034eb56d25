# The GGIR auto-calibration procedure (van Hees et al. 2014; GGIR's
# g.calibrate), block by block on gravcal's segmenter and ICP fit.
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
#      hours);
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
  refit_growth = 1.25     # gravcal's own mode: refit once the table grew by this
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
                     tol = ggir_constants$tol, lazy = TRUE) {
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
                       temperature = isTRUE(src$temperature), lazy = lazy)
  # memory in use after each block (GGIR records R's heap from a full gc(),
  # which costs about as much as decoding the block)
  bsc <- list()
  record <- function(i) {
    bsc[[length(bsc) + 1]] <<- data.frame(time = format(Sys.time()),
                                          size = memory_in_use_mb(),
                                          stringsAsFactors = FALSE)
    NULL
  }
  r <- gc_pump(src$pump(), "ggir", opts, record)
  check_source_read(src, r$samples)
  ggir_result(r, if (length(bsc)) do.call(rbind, bsc) else data.frame(),
              source_input(src, r$samples), verbose, printsummary)
}

# The procedure's settings for the core (GgirConfig in ggir_procedure.hpp):
# the user's, then GGIR's constants.
ggir_options <- function(compat, sf, spherecrit, minloadcrit, sdcriter, max_iter,
                         tol, verbose, block_units = 0, short_block_rows = 0,
                         temperature = TRUE, lazy = TRUE) {
  k <- ggir_constants
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
               verbose = verbose)
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
                               windows = r$windows)
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

#' Auto-calibration as GGIR's g.calibrate, on gravcal's core
#'
#' A drop-in replacement for `GGIR::g.calibrate()`: same arguments, same
#' procedure, same returned list, computed by gravcal's streaming C++ core.
#' It reads the recording in GGIR's blocks (about 12 hours; `chunksize`
#' scales them) and keeps whole hours only (the rest carries to the next
#' block; the last partial hour is dropped), removes idle-sleep samples (x =
#' y = z = 0), cuts 10-second windows, drops duplicate windows and the first
#' window, keeps the rest windows (sd below 13 mg and |mean| below 2 g on all
#' axes), checks that the sphere is covered (`spherecrit`), fits scale,
#' offset and temperature offset by weighted iterative closest point and,
#' after each block, decides whether to read on (`minloadcrit` hours). Every
#' rule is GGIR's, including the ones that look like accidents; see
#' [calibrate()] with `method = "ggir"` for gravcal's corrected variant.
#'
#' The returned numbers are GGIR's to the last bit (the window statistics
#' are computed in R's arithmetic, the fit with R's own least-squares
#' routine); the work is one pass over the samples in C++, without copying
#' them, so a week at 100 Hz held in memory takes about a second, some 55
#' times less than GGIR, and needs little memory beyond the input (the
#' window table and at most an hour of samples carried between blocks);
#' from a file, one block at a time. Figures: `bench/results/speed.md` in
#' the package sources.
#'
#' Where GGIR itself does not give a result, or gives one by accident, this
#' function departs from it, and says so: when a fit does not stay finite
#' (a temperature term the rest windows cannot determine), GGIR stops with
#' an error and `g.calibrate()` returns no correction with a QC message
#' that says why; GGIR's fits after intermediate blocks that cannot stop
#' the reading are skipped, so an error in one of those does not stop it
#' either. A missing (`NA`) or infinite sample in a data frame is left out
#' of its window (in GGIR's cumulative sums it would empty the rest of its
#' block). For a data frame, `rmc.noise` sets
#' the rest threshold as for an ad hoc csv file (`1.2 * rmc.noise`).
#'
#' Unlike GGIR's, this function does not need `inspectfileobject` (it finds
#' the format and sampling rate itself) but accepts GGIR's; and `datafile`
#' may also be a data frame of raw samples (columns `x`, `y`, `z` in g,
#' optional `temperature`), read in the blocks GGIR uses for csv files, with
#' the sampling rate given as `sf = ` in `...` (or from a `time` column).
#'
#' Formats: ActiGraph csv exports, csv files with `x`, `y`, `z` columns,
#' `.rds` data frames, ActiGraph `.gt3x`, Axivity `.cwa` and GENEActiv
#' `.bin`. They are read by gravcal's own decoders, which give what GGIR's
#' readers give (GGIRread's resampling of `.cwa` included), block by block
#' as GGIR reads them, in bounded memory; a damaged file keeps its good
#' samples where GGIR's readers stop. `reader = "reference"` in `...` reads
#' through GGIR's readers themselves (GGIRread, read.gt3x, data.table).
#'
#' @param datafile Path of the recording, or a data frame of raw samples.
#' @param params_rawdata,params_general,params_cleaning GGIR's parameter
#'   lists (as from `GGIR::load_params()`); gravcal uses `chunksize`,
#'   `spherecrit`, `minloadcrit`, `printsummary` and, for ad hoc csv files
#'   and data frames, `rmc.noise`, and ignores the rest. Missing entries take GGIR's defaults
#'   (`chunksize = 1`, `spherecrit = 0.3`, `minloadcrit = 168`,
#'   `printsummary = FALSE`).
#' @param inspectfileobject Optional: GGIR's `g.inspectfile()` result; its
#'   `sf` is used.
#' @param verbose Print progress (the blocks read) as GGIR does.
#' @param ... Legacy arguments that override the parameter lists, as in
#'   GGIR (`chunksize`, `spherecrit`, `minloadcrit`, `printsummary`), `sf`
#'   for a data frame, and `reader` (`"native"`, the default, or
#'   `"reference"`).
#' @return GGIR's list: `scale`, `offset`, `tempoffset` (empty when no fit
#'   ran), `cal.error.start`, `cal.error.end` (rounded to 5 digits),
#'   `spheredata` (the rest windows: `Euclidean Norm, meanx, meany, meanz,
#'   sdx, sdy, sdz` and `temperature` when used), `npoints`, `nhoursused`,
#'   `QCmessage`, `use.temp`, `meantempcal` and `bsc_qc` (time and memory
#'   in MB after each block: the process's resident memory where the system
#'   reports it, as on Linux, else R's heap; GGIR records R's heap). Invisibly,
#'   as GGIR.
#' @seealso [calibrate()] (`method = "ggir"`) for a `gravcal_fit`,
#'   [write_ggir_coefs()] to hand coefficients to GGIR.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 30, sf = 10, seed = 4)
#' C <- g.calibrate(rec, sf = 10, verbose = FALSE)
#' C$QCmessage
#' C$scale
#' C$offset
g.calibrate <- function(datafile, params_rawdata = c(), params_general = c(),
                        params_cleaning = c(), inspectfileobject = c(),
                        verbose = TRUE, ...) {
  dots <- list(...)
  if (length(dots) && (is.null(names(dots)) || any(names(dots) == ""))) {
    abort("All arguments in `...` must be named.")
  }
  pr <- ggir_params(params_rawdata, dots)
  check_flag(verbose, "verbose")
  check_fp_build("`g.calibrate()`")
  sf <- dots$sf
  if (is.null(sf) && length(inspectfileobject) && !is.null(inspectfileobject$sf)) {
    sf <- inspectfileobject$sf
  }
  if (is.null(sf) && length(pr$rmc.sf)) sf <- pr$rmc.sf
  open <- function() {
    open_source(datafile, sf = sf, chunksize = pr$chunksize,
                reader = pr$reader, compat = TRUE)
  }
  src <- open()
  # GGIR uses rmc.noise only for ad hoc csv files (its "AD_HOC" monitor);
  # samples in a data frame, which GGIR does not take, are treated alike
  sdcriter <- if (src$format %in% c("csv", "data.frame") && !is.null(pr$rmc.noise)) {
    pr$rmc.noise * 1.2
  } else {
    ggir_constants$max_sd
  }
  out <- ggir_run_exact(src, open, compat = TRUE, spherecrit = pr$spherecrit,
                        minloadcrit = pr$minloadcrit,
                        sdcriter = sdcriter, verbose = verbose,
                        printsummary = pr$printsummary)
  attr(out, "gravcal") <- NULL
  invisible(out)
}

# g.calibrate()'s parameters (ggir-params.R) from GGIR's params_rawdata and
# the legacy arguments in `dots`, which win; other arguments GGIR takes are
# accepted, anything else warned about.
ggir_params <- function(params_rawdata, dots) {
  if (length(params_rawdata) && !is.list(params_rawdata)) {
    abort("`params_rawdata` must be a list (as from GGIR::load_params()), ",
          "not ", describe(params_rawdata), ".")
  }
  known <- c(ggir_param_names("ggir"), "sf", "desiredtz", "configtz", "do.cal",
             "use.temp", "windowsizes", "outputdir", "studyname", "overwrite")
  extra <- setdiff(names(dots), known)
  if (length(extra)) {
    warning("g.calibrate(): ignored argument", if (length(extra) > 1) "s",
            " ", paste0("`", extra, "`", collapse = ", "), call. = FALSE)
  }
  ggir_param_values("ggir", list(params_rawdata, dots))
}

# calibrate(method = "ggir"): the procedure, then a gravcal_fit.
calibrate_ggir <- function(x, sf, compat, dots, call) {
  args <- split_dots(dots, list(ggir = ggir_param_names("own")))$ggir
  a <- ggir_param_values("own", list(args))
  if (compat) check_fp_build("`calibrate(method = \"ggir\", ggir_compat = TRUE)`")
  if (is.null(sf) && !is.character(x) && is.null(attr(x, "sf")) &&
      !("time" %in% tolower(colnames(x)))) {
    abort("`sf` (sampling frequency in Hz) is missing.")
  }
  open <- function() {
    src <- open_source(x, sf = sf, chunksize = a$chunksize, arg = "x",
                       reader = a$reader, compat = compat)
    if (!a$use_temp) src$temperature <- FALSE
    src
  }
  src <- open()
  res <- ggir_run_exact(src, open, compat = compat, spherecrit = a$spherecrit,
                        minloadcrit = a$minloadcrit, sdcriter = a$max_sd,
                        verbose = a$verbose, max_iter = a$max_iter, tol = a$tol)
  fit <- ggir_fit(res, compat, call, a$minloadcrit)
  if (!is.null(fit$input) && is.numeric(src$sf)) fit$input$sf <- src$sf
  if (is.character(x)) fit$file <- basename(x)
  fit
}

# GGIR's result as a gravcal_fit, with a status code beside GGIR's message.
ggir_plausible <- function(scale, offset, tempoffset) {
  to <- if (length(tempoffset)) tempoffset else 0
  all(is.finite(c(scale, offset, to))) &&
    all(scale >= plausible$scale[1] & scale <= plausible$scale[2]) &&
    all(abs(offset) <= plausible$offset) && all(abs(to) <= plausible$temp)
}

ggir_fit <- function(res, compat, call, minloadcrit) {
  info <- attr(res, "gravcal")
  attr(res, "gravcal") <- NULL
  sd <- res$spheredata
  pts <- NULL
  if (length(sd) > 0 && nrow(sd) > 0) {
    pts <- data.frame(mean_x = sd[[2]], mean_y = sd[[3]], mean_z = sd[[4]],
                      sd_x = sd[[5]], sd_y = sd[[6]], sd_z = sd[[7]],
                      mean_norm = sd[[1]],
                      temperature = if (isTRUE(res$use.temp)) sd[[8]] else NA_real_)
  }
  qc <- res$QCmessage
  key <- names(ggir_messages)[match(qc, ggir_messages)]
  icp <- info$icp
  status <- switch(key,
    done = , done_no_temp = "ok",
    attempted = if (!is.null(res$cal.error.end) && res$cal.error.end < ggir_constants$max_error) "ok" else "high_error",
    no_decrease = "no_improvement",
    no_sphere = "sphere_not_covered",
    no_rest = "no_rest",
    no_data = "too_short",
    not_finite = "diverged")
  if (!is.null(icp) && !isTRUE(icp$finite)) status <- "diverged"
  detail <- switch(status,
    ok = if (identical(key, "attempted")) sprintf(
      "calibrated on all %g hours of the recording (fewer than minloadcrit = %g hours)",
      res$nhoursused, minloadcrit) else "",
    high_error = sprintf(paste0(
      "coefficients kept, as GGIR applies them, but the error after ",
      "calibration is %.2f mg (GGIR accepts < 10 mg)"), 1000 * res$cal.error.end),
    too_short = "fewer distinct 10 s windows than the procedure needs",
    diverged = "the fit did not stay finite", "")
  # gravcal's own mode does not apply coefficients outside the ranges real
  # devices show (GGIR, and so compatible mode, applies them)
  if (!compat && status %in% c("ok", "high_error") &&
      !ggir_plausible(res$scale, res$offset, res$tempoffset)) {
    status <- "implausible"
    detail <- paste0("calibration not applied: coefficients outside plausible ",
                     "ranges (scale ", plausible$scale[1], "-", plausible$scale[2],
                     ", |offset| <= ", plausible$offset, " g, |temperature offset| <= ",
                     plausible$temp, " g per degree C)")
  }
  applied <- status %in% c("ok", "high_error")
  fit <- new_fit(
    K = if (applied) diag(res$scale, 3) else diag(3),
    offset = if (applied) res$offset else c(0, 0, 0),
    tempoffset = if (applied && length(res$tempoffset)) res$tempoffset else c(0, 0, 0),
    meantemp = if (length(res$meantempcal)) res$meantempcal else NA_real_,
    points = pts, method = "ggir",
    iterations = if (is.null(icp)) 0L else icp$iterations,
    converged = !is.null(icp) && isTRUE(icp$converged), status = status,
    message = if (nzchar(detail)) paste0(detail, " [GGIR: ", qc, "]") else qc,
    call = call)
  fit$ggir <- res
  fit$QCmessage <- qc
  fit$ggir_compat <- compat
  fit$use_temp <- isTRUE(res$use.temp)
  if (applied && !is.null(pts) && nrow(pts) > 0) {
    fit <- add_uncertainty(fit, cbind(pts$mean_x, pts$mean_y, pts$mean_z),
                           if (fit$use_temp) pts$temperature,
                           weights = "ggir",
                           max_weight = ggir_constants$max_weight)
  }
  fit$n_windows <- info$windows
  fit$input <- info$input
  fit$hours <- info$windows * 10 / 3600
  fit
}

#' Write calibration coefficients in GGIR's backup.cal.coef format
#'
#' Writes a csv file that `GGIR::GGIR(..., backup.cal.coef = file)` reads:
#' for every recording listed, GGIR then uses these coefficients instead of
#' calibrating the file itself. One row per recording, with the columns GGIR
#' looks for: `filename` (the recording's file name, as GGIR lists it),
#' `scale.x`, `scale.y`, `scale.z`, `offset.x`, `offset.y`, `offset.z`,
#' `temperature.offset.x`, `temperature.offset.y`, `temperature.offset.z`,
#' `cal.error.start`, `cal.error.end`, `meantempcal`, `QCmessage`,
#' `n.10sec.windows`, `n.hours.considered`, `use.temperature`.
#'
#' GGIR applies them per sample as `(xyz + offset) * scale + (T -
#' meantempcal) * temperature.offset`, the model of `method = "ggir"`. Only
#' fits of that model (diagonal `K`) can be written; a 9-parameter fit from
#' the lightweight method has cross-axis terms GGIR cannot apply. When a
#' fit has no temperature term, `meantempcal` is written as 0, because GGIR
#' subtracts it from the temperature of files that have one (a missing value
#' there would turn every sample into NA).
#'
#' @param fits A `gravcal_fit` from `calibrate(..., method = "ggir")` or
#'   [fit_icp()], a `g.calibrate()` result, or a named list of either: the
#'   names are the recordings' file names. A fit made by `calibrate()` on a
#'   file path already knows its file name.
#' @param file Path of the csv file to write.
#' @return The data frame written, invisibly.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 30, sf = 10, seed = 4)
#' fit <- calibrate(rec, sf = 10, method = "ggir")
#' out <- tempfile(fileext = ".csv")
#' write_ggir_coefs(list(participant01.bin = fit), out)
#' read.csv(out)[, 1:7]
write_ggir_coefs <- function(fits, file) {
  if (!is.character(file) || length(file) != 1 || is.na(file) || !nzchar(file)) {
    abort("`file` must be a single file path, not ", describe(file), ".")
  }
  if (dir.exists(file)) {
    abort("`file` must be the path of a csv file, but \"", file,
          "\" is a directory.")
  }
  if (!dir.exists(dirname(file))) {
    abort("`file`: the folder \"", dirname(file), "\" does not exist.")
  }
  out <- ggir_coef_table(fits)
  write_bytes_atomic(csv_bytes(out), file)
  invisible(out)
}

# The rows of GGIR's coefficient file for a fit or a named list of fits.
ggir_coef_table <- function(fits) {
  if (inherits(fits, "gravcal_fit") || is_ggir_result(fits)) {
    nm <- fits$file
    fits <- list(fits)
    if (!is.null(nm)) names(fits) <- nm
  }
  if (!is.list(fits) || !length(fits)) {
    abort("`fits` must be a gravcal_fit, a g.calibrate() result or a named ",
          "list of them, not ", describe(fits), ".")
  }
  nms <- names(fits)
  for (i in seq_along(fits)) {
    if ((is.null(nms) || is.na(nms[i]) || !nzchar(nms[i])) && !is.null(fits[[i]]$file)) {
      if (is.null(nms)) nms <- rep("", length(fits))
      nms[i] <- fits[[i]]$file
    }
  }
  if (is.null(nms) || any(is.na(nms) | !nzchar(nms))) {
    abort("`fits` must be named by the recordings' file names (GGIR matches ",
          "rows by file name), e.g. list(\"p01.bin\" = fit).")
  }
  if (anyDuplicated(nms)) {
    abort("`fits` holds two fits for the recording \"",
          nms[anyDuplicated(nms)], "\"; GGIR takes one row per file name.")
  }
  rows <- lapply(seq_along(fits), function(i) ggir_coef_row(fits[[i]], nms[i]))
  do.call(rbind, rows)
}

# The header of GGIR's coefficient file, no rows.
empty_ggir_coefs <- function() {
  ggir_coef_row(list(scale = c(1, 1, 1), offset = c(0, 0, 0),
                     tempoffset = c(0, 0, 0), QCmessage = ""), "none")[0, ]
}

is_ggir_result <- function(x) {
  is.list(x) && !inherits(x, "gravcal_fit") &&
    all(c("scale", "offset", "QCmessage") %in% names(x))
}

ggir_coef_row <- function(f, name) {
  num1 <- function(v) if (length(v)) as.numeric(v[1]) else NA_real_
  if (inherits(f, "gravcal_fit")) {
    K <- f$K
    if (!is.matrix(K) || !all(dim(K) == 3) || !all(is.finite(K))) {
      abort("The fit for \"", name, "\" has no 3 x 3 finite `K`; it cannot ",
            "be written as GGIR coefficients.")
    }
    if (any(abs(K[row(K) != col(K)]) > 0)) {
      abort("The fit for \"", name, "\" has cross-axis terms (method \"",
            f$method, "\"); GGIR applies only scale, offset and temperature ",
            "offset. Use calibrate(..., method = \"ggir\") for GGIR.")
    }
    scale <- diag(K)
    offset <- f$offset
    to <- f$tempoffset
    g <- f[["ggir"]]  # exact: `$` would take `ggir_compat` for fit_icp() fits
    start <- if (!is.null(g)) num1(g$cal.error.start) else f$error_before
    end <- if (!is.null(g)) num1(g$cal.error.end) else f$error_after
    qc <- if (!is.null(f$QCmessage)) f$QCmessage else f$message
    npts <- if (!is.null(g)) num1(g$npoints) else NROW(f$points)
    hours <- if (!is.null(g)) num1(g$nhoursused) else NA_real_
    use_temp <- isTRUE(f$use_temp) && any(to != 0)
    mt <- f$meantemp
  } else if (is_ggir_result(f)) {
    scale <- f$scale
    offset <- f$offset
    to <- if (length(f$tempoffset)) f$tempoffset else c(0, 0, 0)
    start <- num1(f$cal.error.start)
    end <- num1(f$cal.error.end)
    qc <- f$QCmessage
    npts <- num1(f$npoints)
    hours <- num1(f$nhoursused)
    use_temp <- isTRUE(f$use.temp)
    mt <- num1(f$meantempcal)
  } else {
    abort("Element \"", name, "\" of `fits` is not a gravcal_fit or a ",
          "g.calibrate() result but ", describe(f), ".")
  }
  if (!all(is.finite(c(scale, offset, to))) || length(scale) != 3 ||
      length(offset) != 3 || length(to) != 3) {
    abort("The coefficients for \"", name, "\" are not 3 finite values each.")
  }
  if (!length(mt) || !is.finite(mt[1])) mt <- 0
  mt <- as.numeric(mt[1])
  data.frame(filename = name,
             scale.x = scale[1], scale.y = scale[2], scale.z = scale[3],
             offset.x = offset[1], offset.y = offset[2], offset.z = offset[3],
             temperature.offset.x = to[1], temperature.offset.y = to[2],
             temperature.offset.z = to[3],
             cal.error.start = start, cal.error.end = end, meantempcal = mt,
             QCmessage = if (length(qc)) qc else "", n.10sec.windows = npts,
             n.hours.considered = hours, use.temperature = use_temp,
             row.names = NULL, stringsAsFactors = FALSE)
}
