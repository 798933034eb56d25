# GGIR's front doors: g.calibrate() (the drop-in, GGIR's arguments and
# list) and calibrate(method = "ggir") (a gravcal_fit), both on the one
# procedure (ggir_run(), R/ggir.R).

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
#' Formats: ActiGraph csv exports, Axivity csv exports (OMGUI, UNIX time
#' stamps; resampled block by block as GGIR does, linearly), csv files with
#' `x`, `y`, `z` columns, ad hoc csv files (below), `.rds` data frames, ActiGraph `.gt3x`, Axivity `.cwa` and GENEActiv
#' `.bin`. They are read by gravcal's own decoders, which give what GGIR's
#' readers give (GGIRread's resampling of `.cwa` included), block by block
#' as GGIR reads them, in bounded memory; a damaged file keeps its good
#' samples where GGIR's readers stop. `reader = "reference"` in `...` reads
#' through GGIR's readers themselves (GGIRread, read.gt3x, data.table).
#'
#' @section Ad hoc csv files (GGIR's `rmc.*` parameters):
#' With `rmc.firstrow.acc` in `params_rawdata`, the file is read as GGIR
#' reads an "ad hoc" csv file, by gravcal's csv decoder in GGIR's blocks:
#'
#' | parameter | |
#' |---|---|
#' | `rmc.firstrow.acc` | honoured: line of the first sample (GGIR starts one line later when that line's first field is not a number) |
#' | `rmc.col.acc`, `rmc.col.temp` | honoured |
#' | `rmc.unit.acc` | honoured: `"g"`, `"mg"`, `"bit"` (with `rmc.bitrate`, `rmc.dynamic_range`, `rmc.unsignedbit`; the first two may name header rows) |
#' | `rmc.scalefactor.acc` | honoured |
#' | `rmc.unit.temp` | honoured: `"C"`, `"K"` (GGIR adds 272.15), `"F"` |
#' | `rmc.sf`, `rmc.firstrow.header`, `rmc.header.length`, `rmc.headername.sf`, `rmc.header.structure` | honoured: the sampling rate from the header, else `rmc.sf` |
#' | `rmc.dec` | honoured (`","` with `;` or tab separated fields) |
#' | `rmc.noise` | honoured: rest is sd below `1.2 * rmc.noise` (GGIR's default 13 when not given) |
#' | `rmc.col.time`, `rmc.unit.time`, `rmc.format.time`, `rmc.origin` | accepted (the calibration does not use time); a text time that `rmc.format.time` does not read is an error (GGIR then reads no data) |
#' | `rmc.desiredtz`, `rmc.configtz`, `rmc.headername.sn`, `rmc.headername.recordingid`, `rmc.col.wear` | accepted: no effect on the calibration |
#' | `rmc.check4timegaps = TRUE`; `rmc.doresample = TRUE` with a time column | refused with an error |
#'
#' @param datafile Path of the recording, or a data frame of raw samples.
#' @param params_rawdata,params_general,params_cleaning GGIR's parameter
#'   lists (as from `GGIR::load_params()`); gravcal uses `chunksize`,
#'   `spherecrit`, `minloadcrit`, `printsummary`, the `rmc.*` parameters of
#'   ad hoc csv files (see below) and, for data frames, `rmc.noise`, and
#'   ignores the rest. Missing entries take GGIR's defaults
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
  # rmc.firstrow.acc: an ad hoc csv file, read by the rmc.* parameters
  rmc <- if (!is.null(pr$rmc.firstrow.acc) && is.character(datafile)) {
    pr[grepl("^rmc[.]", names(pr))]
  }
  open <- function() {
    open_source(datafile, sf = sf, chunksize = pr$chunksize,
                reader = pr$reader, compat = TRUE, rmc = rmc)
  }
  src <- open()
  # GGIR resamples Axivity csv exports as interpolationType says; gravcal
  # linearly only (GGIR's default, 1)
  it <- dots$interpolationType %||% params_rawdata[["interpolationType"]]
  if (identical(src$format, "axivity_csv") && !is.null(it) && !identical(as.numeric(it), 1)) {
    abort("`interpolationType` = ", deparse(it), " is not supported for Axivity csv ",
          "exports (gravcal resamples them linearly, interpolationType = 1).")
  }
  # GGIR uses rmc.noise only for ad hoc csv files (its "AD_HOC" monitor),
  # with GGIR's default (load_params(): 13) where the list has none;
  # samples in a data frame, which GGIR does not take, are treated alike
  sdcriter <- if (src$format == "adhoc_csv") {
    (pr$rmc.noise %||% ggir_constants$rmc_noise) * 1.2
  } else if (src$format %in% c("csv", "data.frame") && !is.null(pr$rmc.noise)) {
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
                       reader = a$reader, compat = compat,
                       rmc = if (is.character(x)) rmc_values(a$rmc))
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
