# epoch_signals(): the calibrated epoch signals of a recording (GGIR part
# 1's metrics), from a device file or samples in memory, with a gravcal fit
# or GGIR's coefficients.

#' Calibrated epoch signals: ENMO, angles, non-wear, clipping
#'
#' Applies a calibration to a recording and computes the epoch signals that
#' GGIR's part 1 computes (`g.getmeta()`): per short epoch (5 s) ENMO and
#' anglez by default, or any of GGIR's metrics; per long epoch (15 min) the
#' non-wear and clipping scores and the mean norm, temperature and light. The
#' arithmetic is GGIR's, block by block (about 24 hours), so that the
#' numbers are those [g.getmeta()] returns for the same coefficients; the
#' time stamps are date-times rather than GGIR's text.
#'
#' @param x A device file (the formats [g.getmeta()] reads), or a data
#'   frame of raw samples in g (`x`, `y`, `z`, optional `temperature`,
#'   `light`) with a `time` column (POSIXct or seconds since 1970) or
#'   `start`.
#' @param fit The calibration: a `gravcal_fit` (any method; cross-axis terms
#'   are applied as the fit's model), a [g.calibrate()] result, or `NULL`
#'   (none).
#' @param sf Sampling rate in Hz, for a data frame without one (attribute
#'   `sf` or its time stamps tell it otherwise).
#' @param metrics GGIR's metric names for the short epochs (`"ENMO"`,
#'   `"anglez"`, `"anglex"`, `"angley"`, `"EN"`, `"ENMOa"`, `"MAD"`,
#'   `"BFEN"`, `"HFEN"`, `"HFENplus"`, `"LFENMO"`, `"LFEN"`, `"ZCX"`, ...);
#'   filtered ones need the signal package.
#' @param windowsizes Short, long and non-wear window in seconds (GGIR's).
#' @param start For a data frame without a `time` column: the time of its
#'   first sample (POSIXct).
#' @param tz The time zone of the time stamps (GGIR's `desiredtz`).
#' @param se With a `fit` that has a covariance of its coefficients
#'   ([vcov.gravcal_fit()]) and ENMO among the metrics: compute the
#'   gradient of each short epoch's ENMO with respect to the coefficients,
#'   in the same pass, so that [summary.gravcal_epochs()] gives the
#'   standard errors the calibration's uncertainty puts on the daily mean
#'   ENMO and time above 100 mg (`TRUE`, default), or not (`FALSE`: a
#'   little faster, no standard errors).
#' @param ... More of GGIR's parameters, by name (for example
#'   `nonwear_approach`, `nonwear_range_threshold`, `dynrange`, `hb`,
#'   `chunksize`).
#' @return A `gravcal_epochs` object: a list with `short` (a data frame:
#'   `time` and one column per metric) and `long` (`time`, `nonwearscore`,
#'   `clippingscore`, `lightmean`, `lightpeak`, `temperaturemean` where the
#'   recording has them, `EN`), and `windowsizes`, `sf`, `file`; with ENMO,
#'   `summary`, the daily outcomes and their standard errors
#'   ([summary.gravcal_epochs()] at 100 mg); with standard errors,
#'   `enmo_gradient` (a matrix: a row per short epoch, a column per
#'   coefficient as [coef()] names them) and `vcov`, the fit's covariance.
#' @seealso [g.getmeta()] for GGIR's list; [summary.gravcal_epochs()].
#' @export
#' @examples
#' rec <- simulate_recording(hours = 4, sf = 10, seed = 1)
#' ep <- epoch_signals(rec, fit = calibrate(rec, sf = 10))
#' head(ep$short)
#' ep$summary
#' plot(ep)
epoch_signals <- function(x, fit = NULL, sf = NULL, metrics = c("ENMO", "anglez"),
                          windowsizes = c(5, 900, 3600), start = NULL, tz = "UTC",
                          se = TRUE, ...) {
  if (!is.character(metrics) || !length(metrics) || anyNA(metrics)) {
    abort("`metrics` must be GGIR metric names, not ", describe(metrics), ".")
  }
  tab <- meta_metric_table()
  known <- sub("angle_", "angle", tab$name, fixed = TRUE)
  bad <- setdiff(metrics, known)
  if (length(bad)) {
    abort("`metrics`: unknown ", paste0("\"", bad, "\"", collapse = ", "), "; GGIR's are ",
          paste(known, collapse = ", "), ".")
  }
  if (!(is.character(tz) && length(tz) == 1 && !is.na(tz))) {
    abort("`tz` must be a time zone name, not ", describe(tz), ".")
  }
  check_flag(se, "se")
  dots <- list(...)
  do <- stats::setNames(as.list(known %in% metrics), meta_do_name(tab$name))
  p <- meta_params(do, list(), list(windowsizes = windowsizes, desiredtz = tz), list(), dots)
  cal <- meta_calibration(c(0, 0, 0), c(1, 1, 1), c(0, 0, 0), c())
  model <- NULL
  gradient <- NULL
  if (!is.null(fit)) {
    # a fit GGIR's coefficients cannot hold is applied as apply_calibration()
    # applies it: cross-axis terms, or a temperature term of a fit that is
    # not GGIR's (GGIR's coefficients keep it only with `use_temp`)
    if (inherits(fit, "gravcal_fit") && (any(abs(fit$K[row(fit$K) != col(fit$K)]) > 0) ||
                                         (any(fit$tempoffset != 0) && !isTRUE(fit$use_temp)))) {
      gradient <- outcome_gradient_spec(fit, any(fit$tempoffset != 0))
      model <- epochs_model(fit)
    } else {
      row <- ggir_coef_row(fit, "fit")
      cal <- meta_calibration(unlist(row[c("offset.x", "offset.y", "offset.z")]),
                              unlist(row[c("scale.x", "scale.y", "scale.z")]),
                              unlist(row[c("temperature.offset.x", "temperature.offset.y",
                                           "temperature.offset.z")]),
                              if (isTRUE(row$use.temperature)) row$meantempcal)
      gradient <- outcome_gradient_spec(fit, isTRUE(row$use.temperature))
    }
  }
  if (!se || !"ENMO" %in% metrics) gradient <- NULL
  if (is.character(x)) {
    src <- meta_source(x, p, sf, "x", list(interpolation = p$interpolationType,
                                           frequency_tol = p$frequency_tol, zone = tz,
                                           zone_arg = "tz"))
    if (!src$format %in% meta_formats() || is.null(src$native)) {
      abort("epoch_signals() does not read ", format_entry(src$format)$label %||% src$format,
            " yet; read it with read_recording() and give the samples.")
    }
    on.exit(gc_decoder_close(src$native$ptr), add = TRUE)
  } else {
    src <- epochs_frame_source(x, sf, start, p$chunksize)
  }
  if (!is.null(model) && any(fit$tempoffset != 0) &&
      !isTRUE(if (!is.null(src$native)) src$native$info$temperature else
        !is.null(src$samples$temperature))) {
    abort("`fit` has a temperature offset, so `x` must have a temperature (a `temperature` ",
          "column, or a device file that records it).")
  }
  M <- meta_run(src, p, cal, FALSE, FALSE, model = model, gradient = gradient)
  ep <- epochs_result(M, src, p, tz)
  if (!is.null(gradient)) {
    ep$enmo_gradient <- M$enmo_gradient
    ep$vcov <- fit$vcov
  }
  if ("ENMO" %in% names(ep$short)) ep$summary <- summary.gravcal_epochs(ep)
  ep
}

# A gravcal fit that GGIR's coefficients cannot hold, as meta_run() applies
# it to each block, with the bits of apply_calibration(): its linear model
# in the core (apply_model()'s "matrix" arithmetic), GGIR's model (a GGIR
# fit without cross-axis terms, its temperature term outside GGIR's
# coefficients) as g.getmeta's calibration (apply_model()'s "ggir"
# arithmetic is g.getmeta's operation order), coefficients that change over
# time (segments) by apply_calibration() in R.
epochs_model <- function(fit) {
  uses_temp <- any(fit$tempoffset != 0)
  if (uses_temp && !is.finite(fit$meantemp)) {
    abort("`fit` has a temperature offset but no finite `meantemp`.")
  }
  if (segmented(fit)) {
    return(list(fun = function(d) {
      df <- data.frame(x = d$x, y = d$y, z = d$z)
      if (!is.null(d$temperature)) df$temperature <- d$temperature
      y <- apply_calibration(df, fit)
      list(x = y$x, y = y$y, z = y$z)
    }))
  }
  K <- unname(fit$K)
  if (identical(fit$method, "ggir") && all(K[row(K) != col(K)] == 0)) {
    return(list(ggir = meta_calibration(as.double(fit$offset), diag(K),
                                        as.double(fit$tempoffset),
                                        if (uses_temp) fit$meantemp)))
  }
  c(list(K = K, offset = unname(as.double(fit$offset))),
    if (uses_temp) list(tempoffset = unname(as.double(fit$tempoffset)),
                        meantemp = fit$meantemp))
}

# Samples in memory as a source for meta_run(): blocks of GGIR's csv size.
epochs_frame_source <- function(x, sf, start, chunksize) {
  s <- as_samples(x, "x")
  if (is.null(sf)) sf <- attr(x, "sf")
  if (is.null(sf) && !is.null(s$time)) sf <- sf_from_time(s$time)
  if (is.null(sf)) abort("The sampling frequency of `x` is unknown: give `sf`.")
  check_sf(sf)
  time <- if (!is.null(s$time)) time_seconds(s$time) else NULL
  if (is.null(time)) {
    if (!(inherits(start, "POSIXct") && length(start) == 1 && !is.na(start))) {
      abort("`x` has no `time` column: give `start`, the time of its first sample (POSIXct).")
    }
    time <- as.numeric(start) + (seq_len(s$n) - 1) / sf
  }
  light <- if (is.data.frame(x) && "light" %in% names(x)) as.double(x$light)
  list(format = "data.frame", sf = sf, filename = NA_character_,
       units = frame_block_units(sf, 2 * chunksize),
       samples = list(time = time, x = s$x, y = s$y, z = s$z,
                      temperature = s$temperature, light = light))
}

# gravcal_epochs from g.getmeta()'s M.
epochs_result <- function(M, src, p, tz) {
  if (isTRUE(M$filetooshort) || !is.data.frame(M$metashort)) {
    abort("The recording is too short for epoch signals: GGIR's part 1 needs at least ",
          format(2 * p$windowsizes[3] / 3600), " hours.")
  }
  st <- function(txt) as.POSIXct(txt, format = "%Y-%m-%dT%H:%M:%S%z", tz = tz)
  short <- M$metashort
  long <- M$metalong
  names(short)[1] <- names(long)[1] <- "time"
  short$time <- st(short$time)
  long$time <- st(long$time)
  structure(list(short = short, long = long, windowsizes = p$windowsizes, sf = src$sf,
                 file = src$filename),
            class = "gravcal_epochs")
}

#' @export
print.gravcal_epochs <- function(x, ...) {
  days <- nrow(x$long) * x$windowsizes[2] / 86400
  cat("<gravcal_epochs> ", format(nrow(x$short)), " epochs of ", format(x$windowsizes[1]),
      " s (", format(round(days, 2)), " days from ", format(x$short$time[1]), ")\n", sep = "")
  cat("  short: ", paste(names(x$short)[-1], collapse = ", "), "\n", sep = "")
  cat("  long:  ", paste(names(x$long)[-1], collapse = ", "), "\n", sep = "")
  if ("ENMO" %in% names(x$short)) {
    cat("  mean ENMO ", format(round(1000 * mean(x$short$ENMO, na.rm = TRUE), 1)),
        " mg; non-wear ", format(round(100 * mean(x$long$nonwearscore >= 2), 1)),
        " % of long epochs\n", sep = "")
  }
  invisible(x)
}

#' Plot a day of epoch signals
#'
#' ENMO (mg) and, where computed, anglez over one day, with the long epochs
#' scored as non-wear shaded.
#' @param x A `gravcal_epochs` object ([epoch_signals()]).
#' @param day Which day (1 = the first 24 hours).
#' @param ... Passed to [graphics::plot()].
#' @return `x`, invisibly.
#' @export
plot.gravcal_epochs <- function(x, day = 1, ...) {
  check_number(day, "day", min = 1, integer = TRUE)
  t0 <- x$short$time[1] + (day - 1) * 86400
  s <- x$short[x$short$time >= t0 & x$short$time < t0 + 86400, , drop = FALSE]
  if (!nrow(s)) abort("`day` = ", day, ": the recording has no epochs on that day.")
  l <- x$long[x$long$time >= t0 & x$long$time < t0 + 86400, , drop = FALSE]
  panels <- intersect(c("ENMO", "anglez"), names(s))
  if (!length(panels)) panels <- names(s)[2]
  op <- graphics::par(mfrow = c(length(panels), 1), mar = c(3, 4, 1.5, 1))
  on.exit(graphics::par(op))
  for (m in panels) {
    v <- if (m == "ENMO") 1000 * s[[m]] else s[[m]]
    graphics::plot(s$time, v, type = "l", xlab = "", ylab = if (m == "ENMO") "ENMO (mg)" else m,
                   main = if (m == panels[1]) paste("Day", day) else "", ...)
    nw <- l$time[l$nonwearscore >= 2]
    if (length(nw)) {
      usr <- graphics::par("usr")
      graphics::rect(nw, usr[3], nw + x$windowsizes[2], usr[4], col = grDevices::adjustcolor("grey", 0.4),
                     border = NA)
    }
  }
  invisible(x)
}
