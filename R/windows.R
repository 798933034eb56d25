#' Find rest windows in raw accelerometer samples
#'
#' Cuts the recording into consecutive, non-overlapping windows of fixed
#' duration and computes, per window, the mean, standard deviation and range
#' of each axis, the mean vector norm and the mean temperature, in one
#' streaming pass in C++. Each window is then classed as rest or not by the
#' chosen method's criterion.
#'
#' * `method = "lightweight"` (Farago et al. 2024): 5 s windows; rest when
#'   max - min is below `max_range` (0.12 g) on every axis in `axes`. The
#'   paper watches a single axis of a worn device; gravcal watches all three
#'   by default, which costs nothing on a computer and rejects motion that
#'   happens to spare one axis.
#' * `method = "ggir"` (van Hees et al. 2014): 10 s windows; rest when the
#'   standard deviation is below `max_sd` (13 mg) and the absolute mean below
#'   `max_abs_mean` (2 g) on all three axes.
#'
#' Samples are fed to the core in blocks of `block_samples`; the result does not
#' depend on the chunk size (the segmenter carries the open window across
#' chunks). A trailing incomplete window is dropped. Samples with x, y and z
#' all exactly 0 (ActiGraph idle sleep) are skipped when `skip_zero` is TRUE.
#' Samples with a non-finite value (NA, NaN, Inf) are left out of the window
#' statistics and make their window ineligible as rest, with a warning.
#'
#' @param x Raw samples: a data frame or matrix with numeric columns `x`, `y`,
#'   `z` in g (case-insensitive), and optionally `temperature` (degrees C) and
#'   `time` (used for the `start` column); or the path of a recording in a
#'   format [calibrate()] reads, which is read block by block (about 12 hours
#'   at a time), so that memory holds one block and the window table.
#' @param sf Sampling frequency in Hz, a positive number (for a file: only
#'   when the file does not give it).
#' @param method `"lightweight"` or `"ggir"`: which rest criterion and which
#'   defaults to use.
#' @param window Window duration in seconds; default 5 (lightweight) or 10
#'   (ggir). Must hold at least 2 samples.
#' @param max_range Lightweight rest threshold on max - min, in g (paper: 0.12).
#' @param axes Lightweight: the axes whose range is checked, any of `"x"`,
#'   `"y"`, `"z"` (default all three).
#' @param max_sd GGIR rest threshold on each axis' standard deviation, in g
#'   (13 mg).
#' @param max_abs_mean GGIR clipping guard on each axis' absolute mean, in g
#'   (2 g).
#' @param skip_zero Skip samples that are exactly zero on all three axes.
#' @param block_samples Number of samples passed to the core at a time (a
#'   memory bound for samples held in R; not GGIR's `chunksize`, the
#'   fraction of 12 hours GGIR reads per block).
#' @param progress Show a progress bar (default: in interactive sessions, for
#'   recordings of more than 20 chunks).
#' @param reader For a file: `"native"` (default), gravcal's own decoders
#'   (Axivity `.cwa`, GENEActiv `.bin`, ActiGraph `.gt3x`, csv), which
#'   stream the file in bounded memory and count what they skip; or
#'   `"reference"`, the readers GGIR uses (GGIRread, read.gt3x,
#'   data.table), block by block.
#' @param rmc For an "ad hoc" csv file (any layout of columns and units):
#'   GGIR's `rmc.*` parameters as a named list, as GGIR's `params_rawdata`
#'   gives them (`rmc.firstrow.acc`, which is required, `rmc.col.acc`,
#'   `rmc.unit.acc`, `rmc.sf`, ...; see [g.calibrate()]); `NULL` (default):
#'   the format is found from the file.
#' @param stop `NULL` (read everything), or a function called with the
#'   windows read so far (a data frame as returned) after every block or
#'   chunk that ends at least `stop_every` hours of samples after the last
#'   call; reading stops, and the windows so far are returned, when it
#'   returns `TRUE` (attribute `stopped` then TRUE). [calibrate()] uses it
#'   for its adaptive data budget.
#' @param stop_every Hours of samples between calls of `stop`.
#' @param chunk_size Deprecated: the old name of `block_samples` (a warning).
#' @return A data frame, one row per complete window: `start` (time of the
#'   first sample, from `time` when given, else seconds from the start), `n`
#'   (samples), `mean_x`, `mean_y`, `mean_z`, `sd_x`, `sd_y`, `sd_z`,
#'   `range_x`, `range_y`, `range_z`, `mean_norm`, `temperature` (NA without
#'   a temperature column), `n_invalid` (non-finite samples), `n_repeat`
#'   (samples equal in x, y and z to the sample before them in the window:
#'   a stuck sensor, ActiGraph's idle sleep, zeros) and `rest` (logical). Attributes record `sf`, `method`, `window`, the criterion and
#'   `input`: what was read and, for a file, what its reader skipped and why.
#' @references
#' Farago D, Maczak B, Gingl Z (2024). Enhancing accuracy in actigraphic
#' measurements: a lightweight calibration method for triaxial
#' accelerometers. IEEE Access.
#'
#' van Hees VT, Fang Z, Langford J, et al. (2014). Autocalibration of
#' accelerometer data for free-living physical activity assessment using
#' local gravity and temperature: an evaluation on four continents. Journal
#' of Applied Physiology 117(7), 738-744. \doi{10.1152/jappphysiol.00421.2014}
#' @seealso [select_points()], [calibrate()]
#' @export
#' @examples
#' rec <- simulate_recording(hours = 2, sf = 10, seed = 1)
#' w <- rest_windows(rec, sf = 10)
#' head(w)
#' mean(w$rest)
rest_windows <- function(x, sf, method = c("lightweight", "ggir"),
                         window = NULL, max_range = 0.12,
                         axes = c("x", "y", "z"), max_sd = 0.013,
                         max_abs_mean = 2, skip_zero = TRUE,
                         block_samples = 1e6, progress = NULL,
                         reader = c("native", "reference"), rmc = NULL,
                         stop = NULL, stop_every = 6, chunk_size = NULL) {
  if (!is.null(chunk_size)) {
    if (!missing(block_samples)) {
      abort("Give `block_samples`, or the deprecated `chunk_size`, not both.")
    }
    warning("rest_windows(): `chunk_size` is deprecated: use `block_samples` (the ",
            "samples passed to the core at a time).", call. = FALSE)
    block_samples <- chunk_size
  }
  method <- match_choice(method, "method")
  if (!is.null(stop) && !is.function(stop)) {
    abort("`stop` must be NULL or a function, not ", describe(stop), ".")
  }
  check_number(stop_every, "stop_every", min = 0, min_inclusive = FALSE)
  src <- NULL
  if (is.character(x)) {
    reader <- match_choice(reader, "reader")
    # blocks of about 12 hours (GGIR's), shorter when `stop` is to be asked
    # more often
    src <- open_source(x, sf = if (missing(sf)) NULL else sf, arg = "x",
                       reader = reader, compat = FALSE,
                       rmc = rmc_values(rmc),
                       chunksize = if (is.null(stop)) 1 else
                         min(1, stop_every / 12))
    sf <- src$sf
    s <- list(n = 0, time = NULL)
  } else {
    if (missing(sf)) abort("`sf` (sampling frequency in Hz) is missing.")
    s <- as_samples(x, temperature = if (method == "lightweight") "ignore" else "use")
  }
  check_sf(sf)
  if (is.null(window)) window <- if (method == "lightweight") 5 else 10
  check_number(window, "window", min = 0, min_inclusive = FALSE)
  if (window * sf < 2 || window * sf >= 1e7) {
    abort("`window` * `sf` must give ", if (window * sf < 2)
            "at least 2" else "fewer than 1e7", " samples per window, not ",
          format(window * sf), " (window = ", format(window), " s, sf = ",
          format(sf), " Hz", if (!is.null(src)) paste0(", from \"",
          src$filename, "\""), ").")
  }
  check_flag(skip_zero, "skip_zero")
  check_number(block_samples, "block_samples", min = 1)
  if (!is.null(progress)) check_flag(progress, "progress")
  if (method == "lightweight") {
    check_number(max_range, "max_range", min = 0, min_inclusive = FALSE)
    if (!is.character(axes) || !length(axes) ||
        !all(axes %in% c("x", "y", "z"))) {
      abort("`axes` must name one or more of \"x\", \"y\", \"z\", not ",
            describe(axes), ".")
    }
    rule <- 0L
    par <- c(max_range, sum(c(x = 1, y = 2, z = 4)[unique(axes)]))
  } else {
    check_number(max_sd, "max_sd", min = 0, min_inclusive = FALSE)
    check_number(max_abs_mean, "max_abs_mean", min = 0, min_inclusive = FALSE)
    rule <- 1L
    par <- c(max_sd, max_abs_mean)
  }
  if (!is.null(s$time) && length(s$time) != s$n) {
    abort("Column `time` of `x` must have one value per sample.")
  }
  if (is.null(src)) {
    pump_src <- gc_source_columns(s$x, s$y, s$z, s$temperature)
    units <- block_samples
    blocks <- ceiling(s$n / block_samples)
  } else {
    pump_src <- src$pump()
    units <- src$units
    blocks <- NA
  }
  out <- gc_pump(pump_src, "windows",
                 list(window_samples = window * sf, skip_zero = as.numeric(skip_zero),
                      r_arithmetic = 0, temperature = 1, rule = rule, par = par,
                      block_units = units, want_table = as.numeric(!is.null(stop))),
                 window_progress(src, s, sf, stop, stop_every, progress, blocks))
  if (!is.null(src)) {
    check_source_read(src, out$samples)
    s$n <- out$samples
  }
  w <- windows_frame(out$windows, s, sf)
  attr(w, "stopped") <- isTRUE(out$stopped)
  attr(w, "samples_total") <- if (is.null(src)) s$n else NA_real_
  if (is.null(src) && isTRUE(out$stopped)) s$n <- out$samples
  attr(w, "sf") <- sf
  attr(w, "method") <- method
  attr(w, "window") <- window
  attr(w, "criterion") <- if (method == "lightweight") {
    list(max_range = max_range, axes = unique(axes))
  } else {
    list(max_sd = max_sd, max_abs_mean = max_abs_mean)
  }
  attr(w, "samples") <- s$n
  attr(w, "skipped_zero") <- out$skipped_zero
  attr(w, "dropped_tail") <- out$pending
  attr(w, "input") <- source_input(src, s$n)
  n_bad <- sum(w$n_invalid)
  if (n_bad > 0) {
    warning(sprintf(paste0("`x` has %d non-finite samples (NA, NaN or Inf) ",
                           "in %d windows; those windows are not used as ",
                           "rest."), n_bad, sum(w$n_invalid > 0)),
            call. = FALSE)
  }
  w
}

# The pump's callback after each block but the last (see gc_pump()): shows
# progress (a bar over the blocks of samples in memory, the hours read from
# a file) and, every `stop_every` hours, asks `stop` with the windows so far
# whether to stop. NULL when there is nothing to do.
window_progress <- function(src, s, sf, stop, stop_every, progress, blocks) {
  if (is.null(progress)) {
    progress <- interactive() && (!is.null(src) || blocks > 20)
  }
  if (!isTRUE(progress) && is.null(stop)) return(NULL)
  bar <- NULL
  if (isTRUE(progress) && is.null(src) && blocks > 1) {
    bar <- utils::txtProgressBar(min = 0, max = blocks, style = 3)
  }
  i <- 0
  next_check <- stop_every * 3600 * sf
  function(n, table) {
    i <<- i + 1
    if (!is.null(bar)) utils::setTxtProgressBar(bar, i)
    if (isTRUE(progress) && !is.null(src)) {
      cat(sprintf("\rblock %d: %.1f hours read", i, n / sf / 3600))
    }
    if (is.null(stop) || n < next_check) return(FALSE)
    next_check <<- n + stop_every * 3600 * sf
    isTRUE(stop(windows_frame(table, s, sf)))
  }
}

# The segmenter's window table (gc_pump()'s `windows`) as rest_windows()'s
# data frame.
windows_frame <- function(table, s, sf) {
  col <- function(name) {
    v <- table[[name]]
    if (is.null(v)) numeric(0) else v
  }
  first <- col("first")
  start <- if (is.null(s$time)) first / sf else s$time[first + 1]
  w <- data.frame(
    start = start,
    n = as.integer(col("n")),
    mean_x = col("mean_x"), mean_y = col("mean_y"), mean_z = col("mean_z"),
    sd_x = col("sd_x"), sd_y = col("sd_y"), sd_z = col("sd_z"),
    range_x = col("max_x") - col("min_x"),
    range_y = col("max_y") - col("min_y"),
    range_z = col("max_z") - col("min_z"),
    mean_norm = col("mean_norm"),
    temperature = col("temperature"),
    n_invalid = as.integer(col("n_invalid")),
    n_repeat = as.integer(col("n_repeat")),
    rest = as.logical(col("rest"))
  )
  if (!length(first)) w$rest <- logical(0)
  w
}
