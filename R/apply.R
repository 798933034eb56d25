#' Apply calibration coefficients to raw samples
#'
#' Replaces the `x`, `y`, `z` columns by their calibrated values
#' `a = K (v + offset) + (T - meantemp) * tempoffset`, the temperature term
#' being used only when the fit has a non-zero `tempoffset` (and then `x` must
#' have a `temperature` column). All other columns, the row order and the
#' class of `x` (data frame, tibble, data.table or matrix) are kept; the
#' caller's object is not modified.
#'
#' A fit of GGIR's model (`method = "ggir"`) is applied exactly as GGIR's
#' `g.getmeta()` applies its coefficients, `(v + offset) / (1 / scale) + (T -
#' meantemp) / (1 / tempoffset)` per axis, so the calibrated samples are
#' GGIR's to the last bit.
#'
#' A fit whose status says it could not calibrate carries identity
#' coefficients, so the samples come back unchanged.
#'
#' @param x Raw samples: a data frame or matrix with columns `x`, `y`, `z`
#'   (case-insensitive), as given to [calibrate()].
#' @param fit A `gravcal_fit` from [calibrate()], [fit_gradient()] or
#'   `fit_icp()`, or one row of coefficients: a one-row data frame from
#'   [read_coefs()] (another tool's coefficients, converted to gravcal's
#'   model) or of a [calibrate_files()] table of GGIR's model. A row is
#'   applied as a fit of GGIR's model (GGIR's operation order).
#' @return `x` with calibrated `x`, `y`, `z`.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 12, sf = 10, seed = 3)
#' fit <- calibrate(rec, sf = 10)
#' cal <- apply_calibration(rec, fit)
#' head(cal)
apply_calibration <- function(x, fit) {
  if (is.data.frame(fit)) fit <- coefs_fit(fit, "fit")
  check_fit(fit)
  s <- as_samples(x)
  uses_temp <- any(fit$tempoffset != 0)
  if (uses_temp) {
    if (is.null(s$temperature)) {
      abort("`fit` has a temperature offset, so `x` must have a ",
            "`temperature` column.")
    }
    if (!is.finite(fit$meantemp)) {
      abort("`fit` has a temperature offset but no finite `meantemp`.")
    }
  }
  if (segmented(fit)) return(apply_segments(x, s, fit))
  K <- fit$K
  # GGIR's model in GGIR's operation order (g.getmeta): GGIR's bits
  ggir <- identical(fit$method, "ggir") && all(K[row(K) != col(K)] == 0)
  a <- apply_model(s[c("x", "y", "z")], K, fit$offset, fit$tempoffset,
                   dt = if (uses_temp) s$temperature - fit$meantemp,
                   arithmetic = if (ggir) "ggir" else "matrix")
  replace_xyz(x, a[[1]], a[[2]], a[[3]])
}

# The model, applied here once for every caller: measured v to calibrated
# a = K (v + offset) + dt tempoffset, dt = T - meantemp (NULL: no
# temperature term). `v` is an n x 3 matrix (the result is one too) or a
# list of its three columns (the result is a list too, so that a recording's
# samples are not bound into a matrix). Two arithmetics, chosen by name:
#   "matrix": each row of K times (v + offset), summed left to right, then
#     + dt tempoffset: the bits of `(v + offset) %*% t(K)` with R's
#     reference BLAS, whatever BLAS R is linked to;
#   "ggir": GGIR's model (K diagonal, scale = diag(K)) in the operation
#     order of GGIR's g.getmeta(), (v + offset) / (1 / scale) + dt /
#     (1 / tempoffset), which differs from "matrix" in the last bit and
#     gives GGIR's calibrated samples to the bit.
apply_model <- function(v, K, offset, tempoffset = c(0, 0, 0), dt = NULL,
                        arithmetic = c("matrix", "ggir")) {
  arithmetic <- match.arg(arithmetic)
  col <- if (is.matrix(v)) function(j) v[, j] else function(j) v[[j]]
  u <- lapply(1:3, function(j) col(j) + offset[[j]])
  a <- lapply(1:3, function(i) {
    if (arithmetic == "ggir") {
      ai <- u[[i]] / (1 / K[i, i])
      if (!is.null(dt)) ai <- ai + dt / (1 / tempoffset[[i]])
    } else {
      ai <- K[i, 1] * u[[1]] + K[i, 2] * u[[2]] + K[i, 3] * u[[3]]
      if (!is.null(dt)) ai <- ai + dt * tempoffset[[i]]
    }
    ai
  })
  if (is.matrix(v)) do.call(cbind, a) else a
}

# x with its x, y, z columns replaced, same class and other columns.
replace_xyz <- function(x, ax, ay, az) {
  cols <- match(c("x", "y", "z"), tolower(colnames(x)))
  if (is.matrix(x) && anyNA(cols)) cols <- 1:3
  if (is.matrix(x)) {
    x[, cols[1]] <- ax
    x[, cols[2]] <- ay
    x[, cols[3]] <- az
    return(x)
  }
  nm <- names(x)
  x[[nm[cols[1]]]] <- ax
  x[[nm[cols[2]]]] <- ay
  x[[nm[cols[3]]]] <- az
  x
}

# A fit with coefficients per segment of time: each sample gets its
# segment's. Times: the `time` column (when the fit's windows were timed by
# it), else seconds from the first sample (the `time` column less its first
# value, or the row number over the sampling rate).
apply_segments <- function(x, s, fit) {
  st <- fit$segment_settings
  n <- length(s$x)
  if (identical(st$time, "time")) {
    if (is.null(s$time)) {
      abort("`fit` has coefficients per segment of time, timed by the ",
            "`time` column it was fitted on, so `x` must have a `time` ",
            "column.")
    }
    t <- as.numeric(s$time)
  } else if (!is.null(s$time)) {
    t <- as.numeric(s$time) - as.numeric(s$time[1]) + st$origin
  } else {
    t <- (seq_len(n) - 1) / st$sf + st$origin
  }
  if (any(fit$segments[c("t_x", "t_y", "t_z")] != 0)) {
    if (is.null(s$temperature)) {
      abort("`fit` has a temperature offset, so `x` must have a ",
            "`temperature` column.")
    }
  }
  a <- calibrate_points_by_time(fit, cbind(s$x, s$y, s$z), t, s$temperature)
  replace_xyz(x, a[, 1], a[, 2], a[, 3])
}
