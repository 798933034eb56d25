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
#'   `fit_icp()`.
#' @return `x` with calibrated `x`, `y`, `z`.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 12, sf = 10, seed = 3)
#' fit <- calibrate(rec, sf = 10)
#' cal <- apply_calibration(rec, fit)
#' head(cal)
apply_calibration <- function(x, fit) {
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
  o <- fit$offset
  to <- fit$tempoffset
  if (identical(fit$method, "ggir") && all(K[row(K) != col(K)] == 0)) {
    # GGIR's model, in GGIR's operation order (g.getmeta): the same bits
    s3 <- diag(K)
    ax <- (s$x + o[[1]]) / (1 / s3[1])
    ay <- (s$y + o[[2]]) / (1 / s3[2])
    az <- (s$z + o[[3]]) / (1 / s3[3])
    if (uses_temp) {
      dt <- s$temperature - fit$meantemp
      ax <- ax + dt / (1 / to[[1]])
      ay <- ay + dt / (1 / to[[2]])
      az <- az + dt / (1 / to[[3]])
    }
  } else {
    ux <- s$x + o[[1]]
    uy <- s$y + o[[2]]
    uz <- s$z + o[[3]]
    ax <- K[1, 1] * ux + K[1, 2] * uy + K[1, 3] * uz
    ay <- K[2, 1] * ux + K[2, 2] * uy + K[2, 3] * uz
    az <- K[3, 1] * ux + K[3, 2] * uy + K[3, 3] * uz
    if (uses_temp) {
      dt <- s$temperature - fit$meantemp
      ax <- ax + dt * to[[1]]
      ay <- ay + dt * to[[2]]
      az <- az + dt * to[[3]]
    }
  }
  replace_xyz(x, ax, ay, az)
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
