#' Fit GGIR's calibration model by weighted iterative closest point
#'
#' The fit of van Hees et al. (2014), as GGIR's `g.calibrate()` runs it, in
#' C++: per axis `a = (v + offset) * scale + (T - meantemp) * tempoffset`,
#' where `meantemp` is the mean temperature of the windows. Each iteration
#' projects the calibrated window means onto the unit sphere, regresses the
#' projections on `[1, a, T - meantemp]` per axis by weighted least squares,
#' and updates the weights to `min(1 / |residual|, max_weight)`.
#'
#' Two stopping rules:
#' * `ggir_compat = TRUE`: GGIR's. It stops when its weighted residual
#'   statistic (divided by the sum of the weights) changes by less than `tol`
#'   (1e-10) -- usually after 5 to 10 iterations, before the parameters have
#'   settled. Use it to get GGIR's numbers.
#' * `ggir_compat = FALSE` (default): convergence. It stops when no
#'   parameter moves by more than `tol` in an iteration (the temperature
#'   offset is measured over the range of temperatures), which typically
#'   removes about 1 mg of offset error that GGIR's rule leaves. The
#'   fixed point is GGIR's, reached faster: each iteration takes its
#'   weights at the current coefficients (GGIR takes those of the iteration
#'   before; the fixed points are the same, the minima of a Huber loss of
#'   the distance to the sphere), and the iterations are accelerated by
#'   SQUAREM (Varadhan and Roland 2008) with that loss as the check of each
#'   step, so a fit needs tens of passes over the windows where GGIR's
#'   iteration needs hundreds. `iterations` counts those passes.
#'
#' When the windows' temperature does not vary (or is missing) the
#' temperature term is left out and `tempoffset` is 0, with a message in the
#' fit.
#'
#' @param w Epochs: a data frame with columns `mean_x`, `mean_y`, `mean_z`
#'   and, for the temperature term, `temperature`, one row per window, as
#'   from [rest_windows()] with `method = "ggir"`; when it has a logical
#'   `rest` column only the rest rows are used. GGIR's `spheredata` (columns
#'   `meanx`, `meany`, `meanz`, `temperature`) is accepted as it is.
#' @param use_temp Fit the temperature term (needs a `temperature` column).
#' @param ggir_compat Use GGIR's stopping rule (see above).
#' @param max_iter Most iterations (GGIR: 1000).
#' @param tol Stopping tolerance (GGIR: 1e-10).
#' @param max_weight Cap on the weights (GGIR: 100, i.e. 1 / 0.01 g).
#' @param trace Keep the parameters and GGIR's statistic after each
#'   iteration, in `fit$trace` (one row per iteration).
#' @return A `gravcal_fit` with method `"ggir"`: `K` is `diag(scale)`, and
#'   `offset`, `tempoffset`, `meantemp` are GGIR's coefficients; `points` are
#'   the windows used; `error_before` and `error_after` are GGIR's
#'   `cal.error.start` and `cal.error.end` before rounding.
#' @references van Hees VT, Fang Z, Langford J, et al. (2014).
#'   Autocalibration of accelerometer data for free-living physical activity
#'   assessment using local gravity and temperature: an evaluation on four
#'   continents. Journal of Applied Physiology 117(7), 738-744.
#'   \doi{10.1152/jappphysiol.00421.2014}
#' @seealso [g.calibrate()] for the whole GGIR procedure on a file,
#'   [calibrate()] for gravcal's.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 24, sf = 10, seed = 2, tempoffset =
#'                           c(0.002, -0.001, 0.0015))
#' w <- rest_windows(rec, sf = 10, method = "ggir")
#' fit <- fit_icp(w)
#' fit
#' attr(rec, "truth")$tempoffset
fit_icp <- function(w, use_temp = TRUE, ggir_compat = FALSE, max_iter = 1000,
                    tol = 1e-10, max_weight = 100, trace = FALSE) {
  call <- match.call()
  check_flag(use_temp, "use_temp")
  check_flag(ggir_compat, "ggir_compat")
  check_number(max_iter, "max_iter", min = 1, max = .Machine$integer.max,
               integer = TRUE)
  check_number(tol, "tol", min = 0)
  check_number(max_weight, "max_weight", min = 0, min_inclusive = FALSE)
  check_flag(trace, "trace")
  w <- icp_epochs(w)
  if (use_temp && !is.null(w$temperature) && !is.numeric(w$temperature) &&
      !all(is.na(w$temperature))) {
    abort("Column `temperature` of `w` must be numeric (degrees C), not ",
          class(w$temperature)[1], "; or use `use_temp = FALSE`.")
  }
  if ("rest" %in% names(w)) w <- w[w$rest %in% TRUE, , drop = FALSE]
  ok <- is.finite(w$mean_x) & is.finite(w$mean_y) & is.finite(w$mean_z)
  w <- w[ok, , drop = FALSE]
  temp <- NULL
  msg <- ""
  if (use_temp) {
    if (is.null(w$temperature) || !any(is.finite(w$temperature))) {
      use_temp <- FALSE
      msg <- "no temperature in `w`, so the temperature term was not fitted"
    } else if (!all(is.finite(w$temperature))) {
      abort("Column `temperature` of `w` has missing or non-finite values ",
            "in ", sum(!is.finite(w$temperature)), " windows; drop them or ",
            "use `use_temp = FALSE`.")
    } else {
      temp <- as.double(w$temperature)
    }
  }
  if (nrow(w) < 10) {
    fit <- new_fit(points = w, method = "ggir", status = "no_rest",
                   message = paste0("only ", nrow(w), " windows to fit; ",
                                    "at least 10 are needed"), call = call)
    return(fit)
  }
  r <- icp_means(as.double(w$mean_x), as.double(w$mean_y), as.double(w$mean_z),
                 temp, use_temp, if (ggir_compat) "ggir_r" else "converge",
                 max_iter, tol, max_weight, trace)
  if (use_temp && !r$temp_used) {
    msg <- "temperature does not vary over the windows, so the temperature term was not fitted"
  }
  status <- "ok"
  if (!r$finite) {
    status <- "diverged"
    msg <- "the fit did not stay finite"
  }
  fit <- new_fit(K = diag(r$scale, 3), offset = r$offset,
                 tempoffset = r$tempoffset,
                 meantemp = if (use_temp) r$meantemp else NA_real_,
                 points = w, method = "ggir", iterations = r$iterations,
                 converged = r$converged, status = status, message = msg,
                 call = call)
  fit$use_temp <- isTRUE(r$temp_used)
  fit$ggir_compat <- ggir_compat
  if (status == "ok") {
    fit <- add_uncertainty(fit, cbind(as.double(w$mean_x),
                                      as.double(w$mean_y),
                                      as.double(w$mean_z)),
                           temp, weights = "ggir", max_weight = max_weight)
  }
  if (trace) {
    tr <- as.data.frame(t(r$trace))
    names(tr) <- c("scale_x", "scale_y", "scale_z", "offset_x", "offset_y",
                   "offset_z", "tempoffset_x", "tempoffset_y", "tempoffset_z",
                   "statistic")
    fit$trace <- tr
  }
  fit
}

# The ICP fit of n window means x, y, z (icp.hpp): the one way to it, for
# fit_icp() and for the GGIR procedure (ggir_run(), which fits the rest
# windows of its table after a block). temp: the windows' temperatures, or
# NULL; use_temp: fit the temperature term. rule, the stopping rule:
#   "converge": until no parameter moves by more than `tol` (gravcal's);
#   "ggir_r": GGIR's statistic in GGIR's R arithmetic, least squares by R's
#     own routine: GGIR's coefficients to the bit (compatible mode);
#   "ggir": GGIR's statistic in gravcal's arithmetic, a cheap early stop
#     (the GGIR procedure uses it to decide whether to read on).
# Returns the core's list: scale, offset, tempoffset, meantemp, temp_used,
# iterations, converged, finite, statistic and (trace = TRUE) the trace.
icp_means <- function(x, y, z, temp, use_temp, rule = c("converge", "ggir_r", "ggir"),
                      max_iter = ggir_constants$max_iter, tol = ggir_constants$tol,
                      max_weight = ggir_constants$max_weight, trace = FALSE) {
  rule <- match.arg(rule)
  gc_fit_icp(x, y, z, if (use_temp) temp, use_temp, rule, as.integer(max_iter),
             tol, max_weight, trace)
}

# Accept gravcal epochs or GGIR's spheredata.
icp_epochs <- function(w, arg = "w") {
  if (is.data.frame(w) && all(c("meanx", "meany", "meanz") %in% names(w)) &&
      !all(c("mean_x", "mean_y", "mean_z") %in% names(w))) {
    w <- data.frame(mean_x = as.numeric(w$meanx), mean_y = as.numeric(w$meany),
                    mean_z = as.numeric(w$meanz),
                    temperature = if (!is.null(w$temperature))
                      as.numeric(w$temperature) else NA_real_)
  }
  as_epochs(w, arg)
}
