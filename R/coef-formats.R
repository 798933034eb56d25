# Coefficients that travel between tools: the coefficient files and
# conventions of GGIR, actipy, the UK Biobank pipeline
# (biobankAccelerometerAnalysis), omconvert and scikit-digital-health,
# converted exactly to gravcal's model, and two tools' coefficients compared
# (each tool's reader and writer: R/coef-tools.R; compare_coefs():
# R/coef-compare.R).
#
# gravcal's model, per axis i (diagonal K, the only one the other tools
# have): a_i = s_i (v_i + o_i) + t_i (T - m). The tools' conventions, from
# their sources:
#   GGIR (g.calibrate, backup.cal.coef): the same, m = meantempcal, the mean
#     temperature of the recording's rest windows.
#   omconvert (omcalibrate.c, OmCalibrateFindAutoCalibration and its info
#     file's "Calibration:" line): (v + offset) * scale + (T -
#     referenceTemperature) * tempOffset, referenceTemperature the mean
#     temperature of its stationary points: the same as GGIR's.
#   scikit-digital-health (skdh.preprocessing.CalibrateAccelerometer.predict,
#     its documented formula): (y + d) s + (T - mean T) m: the same as GGIR's;
#     its results hold "offset", "scale" and "temperature scale" but not the
#     mean temperature.
#   actipy (processing.calibrate_gravity, its info dict) and the UK Biobank
#     pipeline since biobankAccelerometerAnalysis pull request #184 (summary
#     json): intercept + slope v + slopeT T, temperature not centred and the
#     intercept after the slope. Hence s = slope, t = slopeT, and with m = 0,
#     o = intercept / slope.
#   The UK Biobank pipeline before #184 (summary json with
#     "calibration-meanDeviceTemp(C)"; files.csv with a meanTemp column):
#     intercept + slope v + temp (T - meanTemp): s = slope, t = temp, m =
#     meanTemp, o = intercept / slope.

coef_tools <- c("ggir", "actipy", "ukb", "omconvert", "skdh")

coef_names <- function() {
  c("scale.x", "scale.y", "scale.z", "offset.x", "offset.y", "offset.z",
    "temperature.offset.x", "temperature.offset.y", "temperature.offset.z")
}

#' Read and write the calibration coefficients of other tools
#'
#' `read_coefs()` reads the coefficient files of GGIR, actipy, the UK
#' Biobank pipeline (biobankAccelerometerAnalysis), omconvert and
#' scikit-digital-health, and converts them exactly to gravcal's model
#' `a = scale * (v + offset) + (T - meantemp) * tempoffset` per axis;
#' `write_coefs()` writes gravcal's fits (or coefficients read from another
#' tool) in each tool's form. The data frame `read_coefs()` returns can be
#' given to [apply_calibration()] (one row) and to [compare_coefs()].
#'
#' The tools and the forms read and written:
#' * `"ggir"`: GGIR's `backup.cal.coef` csv file, one row per recording,
#'   which `GGIR::GGIR(..., backup.cal.coef = file)` uses instead of
#'   calibrating those recordings itself (rows matched by file name:
#'   `filename`, `scale.x` ... `temperature.offset.z`, `cal.error.start`,
#'   `cal.error.end`, `meantempcal`, `QCmessage`, `n.10sec.windows`,
#'   `n.hours.considered`, `use.temperature`); temperature centred on
#'   `meantempcal`, the mean temperature of the recording's rest windows.
#'   Written only for fits without cross-axis terms (GGIR applies none); a
#'   fit without a temperature term gets `meantempcal` 0 (GGIR subtracts it
#'   from the temperature of files that have one), and one with temperature
#'   offsets but no mean temperature is an error (GGIR would move every
#'   sample by `temperature.offset * meantemp`).
#' * `"actipy"`: actipy's calibration info (the dict
#'   `actipy.processing.calibrate_gravity()` returns, saved as json),
#'   keys `CalibxIntercept`, `CalibxSlope`, `CalibxSlopeT` (and `y`, `z`),
#'   `CalibOK`: `intercept + slope * v + slopeT * T`, temperature not
#'   centred. One recording per file.
#' * `"ukb"`: the UK Biobank pipeline's `-summary.json`, keys
#'   `calibration-xOffset(g)`, `calibration-xSlope`, `calibration-xSlopeTemp`
#'   (and `y`, `z`), `file-name`, `quality-goodCalibration`: the same
#'   uncentred model as actipy's (since its pull request #184, which explains
#'   why: centring moves the offsets with the recording's mean temperature).
#'   Read also: the older summaries (`calibration-xSlope(g)`,
#'   `calibration-xTemp(C)`, `calibration-meanDeviceTemp(C)`, temperature
#'   centred on the mean device temperature) and the pipeline's `files.csv`
#'   (`fileName,calOffset,calSlope,calTemp[,meanTemp]`, each triple separated
#'   by spaces: the values it gives to `accProcess --calOffset --calSlope
#'   --calTemp [--meanTemp]`). Written: the current summary keys, one
#'   recording per file.
#' * `"omconvert"`: the `Calibration:` line of omconvert's `-info` file,
#'   `scale x,y,z, offset x,y,z, tempOffset x,y,z, referenceTemperature`
#'   (the same ten values, comma-separated, are what its `-calibration`
#'   option takes), with `Calibration-Result:` (0: calibrated); its model is
#'   GGIR's, centred on the mean temperature of its stationary points. One
#'   recording per file.
#' * `"skdh"`: scikit-digital-health's `CalibrateAccelerometer` results,
#'   `offset`, `scale` and `temperature scale` (saved as json); its model is
#'   GGIR's, but its results do not hold the mean temperature it centred on:
#'   gravcal writes it under the key `temperature mean`, and a file without
#'   it needs `meantemp` when its temperature scale is not zero.
#'
#' omconvert prints its coefficients with 10 decimals, actipy and the UK
#' Biobank pipeline with Python's shortest exact representation; gravcal
#' writes 17 significant digits (GGIR's csv: 15, as R's `write.csv()`), so
#' that coefficients written and read back calibrate to within 1e-12 g.
#'
#' @param file For `read_coefs()`, the paths of coefficient files (a
#'   multi-recording file or one file per recording). For `write_coefs()`,
#'   the path of the file to write: one path for `"ggir"`, one per recording
#'   for the other formats (they hold one recording each; actipy's,
#'   omconvert's and skdh's hold no recording name, so name each file after
#'   its recording: `read_coefs()` takes the name from it).
#' @param format The tool whose form the file has; `"auto"` (for reading)
#'   tells it from the file's content.
#' @param meantemp For `"skdh"` files without a `temperature mean`: the mean
#'   temperature (degree C) the temperature scale is centred on. An error for
#'   other formats, which hold their own.
#' @return `read_coefs()`: a data frame, one row per recording: `file` (the
#'   recording: GGIR's `filename`, the UK Biobank's `file-name`, else the
#'   coefficient file's name without extension), `tool`, `status` (`"ok"`,
#'   `"failed"` where the tool says it did not calibrate, or `NA`),
#'   `scale.x`, `scale.y`, `scale.z`, `offset.x`, `offset.y`, `offset.z`
#'   (g, added before the scale, as GGIR's), `temperature.offset.x`,
#'   `temperature.offset.y`, `temperature.offset.z` (g per degree C),
#'   `meantemp` (degree C; 0 for the uncentred tools, `NA` when there is no
#'   temperature term) and `source` (the file read). `write_coefs()`: that
#'   data frame for what was written, invisibly.
#' @seealso [compare_coefs()], [calibrate_files()].
#' @export
#' @examples
#' rec <- simulate_recording(hours = 30, sf = 10, seed = 4,
#'                           tempoffset = c(0.002, -0.001, 0.001))
#' fit <- calibrate(rec, sf = 10, method = "ggir")
#' out <- file.path(tempdir(), "p01.json")  # named after the recording
#' write_coefs(list(p01 = fit), out, format = "actipy")
#' cf <- read_coefs(out)
#' cf
#' cal <- apply_calibration(rec, cf)
#' max(abs(cal$x - apply_calibration(rec, fit)$x))
read_coefs <- function(file, format = c("auto", "ggir", "actipy", "ukb",
                                        "omconvert", "skdh"),
                       meantemp = NULL) {
  format <- match_choice(format, "format")
  if (!is.character(file) || !length(file) || anyNA(file) ||
      any(!nzchar(file))) {
    abort("`file` must be paths of coefficient files, not ", describe(file),
          ".")
  }
  if (!is.null(meantemp)) check_number(meantemp, "meantemp")
  absent <- !file.exists(file) | dir.exists(file)
  if (any(absent)) {
    abort("`file`: \"", file[absent][1], "\" is not a file.")
  }
  for (f in file) check_regular_file(f, "file")
  rows <- lapply(file, function(f) {
    text <- read_text(f)
    fmt <- if (format == "auto") detect_coef_format(text, f) else format
    if (!is.null(meantemp) && fmt != "skdh") {
      abort("`meantemp` is only for \"skdh\" files (whose results do not ",
            "hold it); \"", f, "\" is a ", fmt, " file, which holds its own.")
    }
    out <- switch(fmt,
                  ggir = read_ggir_file(f),
                  actipy = read_actipy(text, f),
                  ukb = read_ukb(text, f),
                  omconvert = read_omconvert(text, f),
                  skdh = read_skdh(text, f, meantemp))
    out$source <- f
    out
  })
  out <- do.call(rbind, rows)
  rownames(out) <- NULL
  out
}

#' @rdname read_coefs
#' @param fits What to write: a `gravcal_fit` of GGIR's model (from
#'   `calibrate(..., method = "ggir")` or [fit_icp()]; a fit with cross-axis
#'   terms cannot be written, as no other tool applies them), a named list of
#'   them (names: the recordings), a `g.calibrate()` result, or a data frame
#'   of coefficients (from `read_coefs()` or [calibrate_files()]).
#' @export
write_coefs <- function(fits, file, format = c("ggir", "actipy", "ukb",
                                               "omconvert", "skdh")) {
  format <- match_choice(format, "format")
  if (!is.character(file) || !length(file) || anyNA(file) ||
      any(!nzchar(file))) {
    abort("`file` must be file paths, not ", describe(file), ".")
  }
  # GGIR's file names each row by its recording and has its own rules on
  # what it can hold: those said first, in its words (ggir_coef_table())
  by_fit <- inherits(fits, "gravcal_fit") || is_ggir_result(fits) ||
    (is.list(fits) && !is.data.frame(fits))
  cf <- if (format == "ggir" && by_fit) {
    ggir_frame_coefs(ggir_coef_table(fits), "fits")
  } else {
    as_coefs(fits, "fits", ggir = format == "ggir")
  }
  if (format == "ggir") {
    if (length(file) != 1) {
      abort("`file` must be one path for format \"ggir\" (one csv file for ",
            "all recordings), not ", length(file), ".")
    }
    if (by_fit) {
      write_ggir_file(fits, file)
    } else {
      write_ggir_file(stats::setNames(lapply(seq_len(nrow(cf)), function(i) {
        r <- cf[i, ]
        to <- unlist(r[coef_names()[7:9]])
        list(scale = unlist(r[coef_names()[1:3]]),
             offset = unlist(r[coef_names()[4:6]]), tempoffset = to,
             QCmessage = "", meantempcal = r$meantemp,
             use.temp = any(to != 0), cal.error.start = NA_real_,
             cal.error.end = NA_real_, npoints = NA_real_,
             nhoursused = NA_real_)
      }), cf$file), file)
    }
    return(invisible(cf))
  }
  if (length(file) != nrow(cf)) {
    abort("`file` must give one path per recording for format \"", format,
          "\" (one recording per file): ", nrow(cf), " recordings, ",
          length(file), " paths.")
  }
  for (i in seq_along(file)) {
    f <- file[i]
    if (dir.exists(f)) {
      abort("`file`: \"", f, "\" is a directory, not a file path.")
    }
    if (!dir.exists(dirname(f))) {
      abort("`file`: the folder \"", dirname(f), "\" does not exist.")
    }
    check_regular_file(f, "file", missing_ok = TRUE)
    r <- cf[i, ]
    text <- switch(format,
                   actipy = actipy_text(r),
                   ukb = ukb_text(r),
                   omconvert = omconvert_text(r),
                   skdh = skdh_text(r))
    write_bytes_atomic(charToRaw(text), f)
  }
  invisible(cf)
}

# ---- one row of coefficients ----------------------------------------------

# The start of a message about one recording's coefficients.
coef_what <- function(arg, file, tool) {
  paste0("`", arg, "`: the coefficients of \"", file, "\" (", tool, ")")
}

coefs_row <- function(file, tool, scale, offset, tempoffset, meantemp,
                      status = NA_character_, se = NULL, arg = "file") {
  v <- c(scale, offset, tempoffset)
  if (length(scale) != 3 || length(offset) != 3 || length(tempoffset) != 3 ||
      !is.numeric(v) || !all(is.finite(v))) {
    abort(coef_what(arg, file, tool), " are not 3 finite ",
          "values each for scale, offset and temperature offset.")
  }
  if (any(scale == 0)) {
    abort(coef_what(arg, file, tool), " have a zero scale.")
  }
  if (any(tempoffset != 0) && !isTRUE(is.finite(meantemp))) {
    abort(coef_what(arg, file, tool), " have a ",
          "temperature term but no finite mean temperature.")
  }
  out <- data.frame(file = file, tool = tool, status = status,
                    stringsAsFactors = FALSE)
  out[coef_names()] <- as.list(as.double(v))
  out$meantemp <- as.double(meantemp)
  if (!is.null(se)) out[paste0(coef_names(), ".se")] <- as.list(as.double(se))
  out
}

# intercept + slope v + slopeT (T - m) in gravcal's form.
from_intercept <- function(file, tool, intercept, slope, slope_t, m = 0,
                           status = NA_character_, arg = "file") {
  if (!all(is.finite(c(intercept, slope, slope_t, m))) ||
      length(intercept) != 3 || length(slope) != 3 || length(slope_t) != 3) {
    abort(coef_what(arg, file, tool), " are not 3 finite ",
          "values each for intercept, slope and temperature slope.")
  }
  if (any(slope == 0)) {
    abort(coef_what(arg, file, tool), " have a zero slope.")
  }
  coefs_row(file, tool, slope, intercept / slope, slope_t,
            if (any(slope_t != 0)) m else NA_real_, status, arg = arg)
}

# gravcal's form to intercept + slope v + slopeT T (uncentred).
to_intercept <- function(r) {
  s <- unlist(r[coef_names()[1:3]])
  o <- unlist(r[coef_names()[4:6]])
  t <- unlist(r[coef_names()[7:9]])
  m <- if (any(t != 0)) r$meantemp else 0
  list(intercept = unname(s * o - t * m), slope = unname(s),
       slope_t = unname(t))
}

# Any of the inputs the functions take, as rows of coefficients (with their
# standard errors where there are some). `ggir`: they are to be written to
# GGIR's coefficient file (for the errors' words).
as_coefs <- function(x, arg, ggir = FALSE) {
  if (inherits(x, "gravcal_fit") || is_ggir_result(x)) {
    nm <- if (is.null(x$file)) "recording" else basename(x$file)
    x <- stats::setNames(list(x), nm)
  }
  if (is.data.frame(x)) return(coefs_from_frame(x, arg))
  if (!is.list(x) || !length(x)) {
    abort("`", arg, "` must be a gravcal_fit, a g.calibrate() result, a ",
          "named list of them or a data frame of coefficients, not ",
          describe(x), ".")
  }
  nms <- names(x)
  if (is.null(nms)) nms <- rep("", length(x))
  for (i in seq_along(x)) {
    if ((is.na(nms[i]) || !nzchar(nms[i])) && is.list(x[[i]]) &&
        is.character(x[[i]]$file)) {
      nms[i] <- basename(x[[i]]$file)
    }
  }
  if (any(is.na(nms) | !nzchar(nms))) {
    abort("`", arg, "` must be named by the recordings, e.g. ",
          "list(p01 = fit).")
  }
  rows <- lapply(seq_along(x), function(i) {
    f <- x[[i]]
    if (inherits(f, "gravcal_fit")) {
      check_fit(f, arg)
      K <- f$K
      if (any(K[row(K) != col(K)] != 0)) {
        abort("`", arg, "`: the fit for \"", nms[i], "\" has cross-axis ",
              "terms (method \"", f$method, "\"), which no other tool ",
              "applies; use calibrate(..., method = \"ggir\").")
      }
      se <- if (!is.null(f$se)) {
        unname(f$se[c("k_xx", "k_yy", "k_zz", "o_x", "o_y", "o_z", "t_x",
                      "t_y", "t_z")])
      }
      uses <- any(f$tempoffset != 0)
      check_meantemp(f$tempoffset, f$meantemp, nms[i], "meantemp", arg,
                     ggir = ggir)
      coefs_row(nms[i], "gravcal", diag(K), f$offset, f$tempoffset,
                if (uses) f$meantemp else NA_real_,
                if (identical(f$status, "ok")) "ok" else f$status, se,
                arg = arg)
    } else if (is_ggir_result(f)) {
      to <- if (length(f$tempoffset)) f$tempoffset else c(0, 0, 0)
      mt <- if (length(f$meantempcal)) f$meantempcal[1] else NA_real_
      check_meantemp(to, mt, nms[i], "meantempcal", arg, ggir = ggir)
      coefs_row(nms[i], "ggir", f$scale, f$offset, to,
                if (any(to != 0)) mt else NA_real_, arg = arg)
    } else {
      abort("`", arg, "`: element \"", nms[i], "\" is not a gravcal_fit ",
            "or a g.calibrate() result but ", describe(f), ".")
    }
  })
  out <- rbind_fill(rows)
  if (anyDuplicated(out$file)) {
    abort("`", arg, "` holds two sets of coefficients for \"",
          out$file[anyDuplicated(out$file)], "\".")
  }
  out
}

# A data frame of coefficients: read_coefs()'s, calibrate_files()'s, or
# GGIR's columns.
coefs_from_frame <- function(x, arg) {
  nm <- names(x)
  if (!"file" %in% nm && "filename" %in% nm) x$file <- x$filename
  if (!"meantemp" %in% nm && "meantempcal" %in% nm) x$meantemp <- x$meantempcal
  if (!all(coef_names()[7:9] %in% nm)) x[coef_names()[7:9]] <- 0
  need <- c("file", coef_names()[1:6])
  miss <- setdiff(need, names(x))
  if (length(miss)) {
    abort("`", arg, "` lacks the column(s) ", paste0("`", miss, "`",
                                                     collapse = ", "),
          " (a data frame of coefficients needs `file`, `scale.x` ... ",
          "`offset.z`, and `temperature.offset.x` ... with `meantemp` ",
          "where there is a temperature term).")
  }
  if (!nrow(x)) abort("`", arg, "` has no rows.")
  cross <- intersect(c("cross.xy", "cross.xz", "cross.yz"), names(x))
  if (length(cross) && any(as.matrix(x[cross]) != 0, na.rm = TRUE)) {
    abort("`", arg, "` has cross-axis terms (`cross.*` columns of the ",
          "lightweight method), which no other tool applies.")
  }
  if (!"meantemp" %in% names(x)) x$meantemp <- NA_real_
  has_se <- all(paste0(coef_names(), ".se") %in% names(x))
  rows <- lapply(seq_len(nrow(x)), function(i) {
    v <- vapply(coef_names(), function(n) as.double(x[[n]][i]), 0)
    if (!all(is.finite(v))) {
      abort("`", arg, "`: the coefficients of \"", x$file[i], "\" (row ", i,
            if ("status" %in% names(x)) paste0(", status \"", x$status[i],
                                               "\""),
            ") are not all finite numbers.")
    }
    to <- v[7:9]
    coefs_row(as.character(x$file[i]),
              if ("tool" %in% names(x)) as.character(x$tool[i]) else "gravcal",
              v[1:3], v[4:6], to,
              if (any(to != 0)) as.double(x$meantemp[i]) else NA_real_,
              if ("status" %in% names(x)) as.character(x$status[i]) else
                NA_character_,
              if (has_se) vapply(paste0(coef_names(), ".se"),
                                 function(n) as.double(x[[n]][i]), 0),
              arg = arg)
  })
  out <- rbind_fill(rows)
  if ("source" %in% names(x)) out$source <- x$source
  out
}

rbind_fill <- function(rows) {
  cols <- unique(unlist(lapply(rows, names)))
  rows <- lapply(rows, function(r) {
    for (n in setdiff(cols, names(r))) r[[n]] <- NA_real_
    r[cols]
  })
  out <- do.call(rbind, rows)
  rownames(out) <- NULL
  out
}

# The fit apply_calibration() applies for one row of coefficients.
coefs_fit <- function(x, arg = "fit") {
  if (nrow(x) != 1) {
    abort("`", arg, "` must be one row of coefficients (one recording), ",
          "not ", nrow(x), " rows; take the recording's row, e.g. ",
          "coefs[coefs$file == \"p01\", ].")
  }
  r <- as_coefs(x, arg)
  v <- unlist(r[coef_names()])
  to <- v[7:9]
  fit <- new_fit(K = diag(v[1:3]), offset = v[4:6], tempoffset = to,
                 meantemp = if (any(to != 0)) r$meantemp else NA_real_,
                 method = "ggir", status = "given",
                 message = paste0("coefficients of ", r$tool, " for ", r$file,
                                  ", given, not fitted"))
  fit$use_temp <- any(to != 0)
  fit
}

# calibrate_files(coefs = ): the given coefficients, one row per recording
# (matched by file name without folder and extension), checked before any
# work.
given_coefs <- function(coefs, ids) {
  cf <- as_coefs(coefs, "coefs")
  key <- coef_key(cf$file)
  if (anyDuplicated(key)) {
    abort("`coefs` holds two rows for the recording \"",
          key[anyDuplicated(key)], "\" (file names are matched without ",
          "folder and extension).")
  }
  idk <- coef_key(ids)
  miss <- !idk %in% key
  if (any(miss)) {
    abort("`coefs` has no coefficients for ", sum(miss), " recording(s): ",
          paste0("\"", utils::head(ids[miss], 3), "\"", collapse = ", "),
          if (sum(miss) > 3) ", ...", " (matched by file name without ",
          "folder and extension).")
  }
  cf[match(idk, key), , drop = FALSE]
}

# A recording's fit with the given coefficients in place of its own: the
# same rest points, the errors on them with the given coefficients, no
# standard errors (nothing was fitted), status "given".
with_given <- function(fit, r) {
  g <- coefs_fit(r, "coefs")
  fit$K <- g$K
  fit$offset <- g$offset
  fit$tempoffset <- g$tempoffset
  fit$meantemp <- g$meantemp
  fit$use_temp <- g$use_temp
  if (!is.null(fit$params)) {
    fit$params[] <- c(diag(g$K), 0, 0, 0, g$offset)
  }
  own <- fit$status
  fit <- clear_uncertainty(fit)
  fit[c("segments", "segment_settings", "ggir")] <- list(NULL)
  fit$error_heldout_before <- NA_real_
  fit$error_heldout_after <- NA_real_
  fit$status <- "given"
  fit$message <- paste0("coefficients of ", r$tool, " given (", r$file,
                        "), not fitted; the recording's own fit: ", own)
  if (any(fit$tempoffset != 0) && NROW(fit$points) &&
      is.null(fit$points$temperature)) {
    fit$message <- paste0(fit$message, "; the recording has no temperature, ",
                          "so the errors leave the temperature term out")
  }
  refresh_errors(fit)
}

# ---- reading ----------------------------------------------------------------

num17 <- function(v) {
  ifelse(is.na(v), "NaN", sprintf("%.17g", v))
}
