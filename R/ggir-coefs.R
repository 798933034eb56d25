# GGIR's coefficient file (backup.cal.coef): what GGIR reads to use
# coefficients instead of calibrating a file itself.

#' Write calibration coefficients in GGIR's format (deprecated)
#'
#' Deprecated: use [write_coefs()] with `format = "ggir"` (its default),
#' which writes the same file and also takes a data frame of coefficients.
#' `write_ggir_coefs()` still writes the file, with a deprecation warning.
#'
#' @param fits,file As for [write_coefs()].
#' @return The rows written (GGIR's columns), invisibly.
#' @keywords internal
#' @export
write_ggir_coefs <- function(fits, file) {
  .Deprecated("write_coefs", package = "gravcal",
              msg = paste0("write_ggir_coefs() is deprecated: use write_coefs(fits, file) ",
                           "(format = \"ggir\", the default), which writes the same file."))
  write_ggir_file(fits, file)
}

# GGIR's coefficient file (backup.cal.coef) for a fit or a named list of
# fits, written atomically; the rows written returned (write_coefs()).
write_ggir_file <- function(fits, file) {
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
  # the file is replaced by a rename: never a pipe's or a device's node
  check_regular_file(file, "file", missing_ok = TRUE)
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
    check_meantemp(to, mt, name, "meantemp")
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
    check_meantemp(to, mt, name, "meantempcal")
  } else {
    abort("Element \"", name, "\" of `fits` is not a gravcal_fit or a ",
          "g.calibrate() result but ", describe(f), ".")
  }
  if (!all(is.finite(c(scale, offset, to))) || length(scale) != 3 ||
      length(offset) != 3 || length(to) != 3) {
    abort("The coefficients for \"", name, "\" are not 3 finite values each.")
  }
  # no temperature term: GGIR subtracts meantempcal from the temperature of
  # files that have one, so 0, never NA
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

# Temperature offsets are centred on the mean temperature `mt` (the model's
# `(T - meantemp) * tempoffset`): a fit that has offsets but no finite `mt`
# cannot be written or converted, since a missing mean temperature taken as
# 0 (GGIR reads it so) moves every calibrated sample by tempoffset *
# meantemp. `field`: the fit's name for it; `ggir`: the message is about
# GGIR's coefficient file (write_coefs()), else about coefficients in
# general (as_coefs()).
check_meantemp <- function(to, mt, name, field, arg = "fits", ggir = TRUE) {
  if (length(to) && all(is.finite(to)) && any(to != 0) &&
      !(length(mt) >= 1 && isTRUE(is.finite(as.numeric(mt[1]))))) {
    abort("`", arg, "`: the fit for \"", name, "\" has temperature offsets ",
          "but no `", field, "`: ", if (ggir) {
            paste0("GGIR's coefficient file needs the mean temperature ",
                   "they are centred on (its `meantempcal`); written as 0, ",
                   "GGIR would move every calibrated sample by ",
                   "temperature.offset * meantemp")
          } else {
            paste0("the coefficients need the mean temperature the offsets ",
                   "are centred on (GGIR's `meantempcal`); taken as 0, every ",
                   "calibrated sample would move by tempoffset * meantemp")
          }, ". Give the fit its `", field, "`, or refit it.")
  }
}
