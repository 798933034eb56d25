#' Names of the nine parameters of the lightweight model
#'
#' In the order of Farago et al. (2024), Eq. 6: scales `k_xx, k_yy, k_zz`,
#' misalignments `k_xy, k_xz, k_yz`, offsets `o_x, o_y, o_z` (g).
#' @return A character vector of length 9.
#' @export
#' @examples
#' param_names()
param_names <- function() {
  c("k_xx", "k_yy", "k_zz", "k_xy", "k_xz", "k_yz", "o_x", "o_y", "o_z")
}

#' Fit the 9-parameter model by forward-difference gradient descent
#'
#' The optimizer of Farago et al. (2024), Sec. II-C: starting from the ideal
#' sensor `p0 = (1, 1, 1, 0, 0, 0, 0, 0, 0)`, each iteration estimates the
#' gradient of the objective by forward differences with step `h` (Eq. 13)
#' and moves against it with one learning rate per parameter group (Eq. 14,
#' 16). The calibrated vector is `a = K (v + o)` with lower-triangular `K`
#' (Eq. 7-9).
#'
#' The objective is `f(p) = w * sum((|a|^2 - 1)^2)` over the points (the
#' square root left out, as the paper does for its rates), or
#' `w * sum((|a| - 1)^2)` with `use_sqrt = TRUE`. The paper prints a plain
#' sum (`w = 1`), but with its learning rates a plain sum over 18 points
#' diverges: the curvature along an offset is about `8 N / 3` (about 48 for
#' N = 18), so a step of 0.2 times the gradient overshoots. gravcal's default
#' `objective = "mean"` (`w = 1 / N`) divides the curvature by N; the paper's
#' rates then settle in 20 to 30 iterations to within about 1e-3 of the
#' optimum, as its Fig. 9 shows (reproduced in `bench/table2.R`). The slowest
#' direction contracts by only 2-10 % per iteration, so reaching the optimum
#' itself takes a few hundred iterations (see `tol`; [calibrate()] does so).
#'
#' A forward difference biases the gradient by about `h / 2` times the
#' curvature, so even on noise-free points the fitted parameters sit about
#' `h` (1e-5) from the truth; a smaller `h` removes the bias in double
#' arithmetic.
#'
#' @param pts Calibration points: the result of [select_points()], or any
#'   data frame or matrix with numeric columns `mean_x`, `mean_y`, `mean_z`
#'   (or `x`, `y`, `z`) in g. At least 9 points.
#' @param arithmetic Number type the core computes in: `"double"`,
#'   `"float"` (single precision, as on a microcontroller with an FPU), or
#'   fixed point as on one without: `"fixed32"` (Q3.29 in 32-bit integers,
#'   64-bit intermediates) or `"fixed16"` (Q1.14 in 16-bit integers, 32-bit
#'   intermediates), saturating on overflow. The points are rounded to the
#'   arithmetic first. The result is bit for bit what the same header-only
#'   core computes on a device (`inst/include/gravcal/fixed_point.hpp`; see
#'   `vignette("firmware")`).
#' @param max_iter Number of iterations M (paper: 50).
#' @param rates Learning rates for the scale, misalignment and offset groups
#'   (paper: 0.3, 0.8, 0.2), a named or unnamed vector of 3.
#' @param h Finite-difference step (paper: 1e-5 for double, float and 32-bit
#'   fixed point, 0.01 for 16-bit fixed point; the default follows
#'   `arithmetic`). It must be at least the arithmetic's resolution near 1:
#'   2^-14 (about 6.1e-5) for `"fixed16"`, 2^-29 for `"fixed32"`, 2^-23 for
#'   `"float"` and 2^-52 for `"double"`; a smaller step is an error.
#' @param objective `"mean"` (default) or `"sum"` over points; see Details.
#' @param use_sqrt Keep the square root in the objective.
#' @param tol Stop early once every parameter step is below `tol`; 0 (the
#'   paper's rule) always runs `max_iter` iterations.
#' @param trace Keep the parameters after every iteration (for the paper's
#'   Fig. 9); stored as `fit$trace`.
#' @param difference `"forward"` (the paper's Eq. 13) or `"central"`
#'   differences for the gradient. Central differences cost twice the
#'   evaluations but remove the forward difference's bias of about `h / 2`
#'   per parameter: negligible with `h = 1e-5`, about 5 mg with the 16-bit
#'   step `h = 0.01` (`bench/results/fixed.md`).
#' @return A `gravcal_fit` (see [calibrate()]) with `K` lower-triangular,
#'   `offset`, zero `tempoffset`, `params` (the nine named parameters),
#'   `objective`, and `trace` when asked for. Status `"ok"`; `"diverged"`
#'   (identity coefficients) when the parameters left the finite range; or
#'   `"no_improvement"` (identity coefficients) when the objective at the
#'   end is not below its value at the start (the identity), for example
#'   with a step `h` so small that the differences are rounding error.
#' @references Farago D, Maczak B, Gingl Z (2024). Enhancing accuracy in
#'   actigraphic measurements: a lightweight calibration method for triaxial
#'   accelerometers. IEEE Access.
#' @seealso [select_points()], [calibrate()], [simulate_points()]
#' @export
#' @examples
#' set.seed(42)
#' cand <- simulate_points(500, noise = 0.001)
#' fit <- fit_gradient(select_points(cand))
#' rbind(truth = attr(cand, "params"), fit = fit$params)
fit_gradient <- function(pts, arithmetic = c("double", "float", "fixed32",
                                              "fixed16"),
                         max_iter = 50, rates = c(scale = 0.3,
                         misalignment = 0.8, offset = 0.2),
                         h = if (arithmetic[1] == "fixed16") 0.01 else 1e-5,
                         objective = c("mean", "sum"), use_sqrt = FALSE,
                         tol = 0, trace = FALSE,
                         difference = c("forward", "central")) {
  call <- match.call()
  arithmetic <- match_choice(arithmetic, "arithmetic")
  objective <- match_choice(objective, "objective")
  difference <- match_choice(difference, "difference")
  v <- point_matrix(pts, "pts")
  if (nrow(v) < 9) {
    abort("`pts` must hold at least 9 points to fit 9 parameters, not ",
          nrow(v), ".")
  }
  check_number(max_iter, "max_iter", min = 1, max = 1e6, integer = TRUE)
  if (!is.numeric(rates) || length(rates) != 3 || !all(is.finite(rates)) ||
      any(rates <= 0)) {
    abort("`rates` must be 3 positive numbers (scale, misalignment, offset), ",
          "not ", describe(rates), ".")
  }
  check_number(h, "h", min = 0, min_inclusive = FALSE)
  check_step(h, arithmetic)
  limit <- c(double = Inf, float = Inf, fixed32 = 4, fixed16 = 2)[[arithmetic]]
  if (any(abs(v) >= limit)) {
    abort("`pts` has coordinates beyond the range of ", arithmetic, " (+-",
          limit, " g): ", sum(rowSums(abs(v) >= limit) > 0), " of ", nrow(v),
          " points. Rest points lie within about 1.3 g; are they in g?")
  }
  check_flag(use_sqrt, "use_sqrt")
  check_number(tol, "tol", min = 0)
  check_flag(trace, "trace")

  r <- gc_fit_gradient(v[, 1], v[, 2], v[, 3],
                       c(1, 1, 1, 0, 0, 0, 0, 0, 0), as.integer(max_iter), h,
                       rep(unname(rates), each = 3), use_sqrt,
                       objective == "sum", tol, trace, arithmetic,
                       difference == "central")
  p <- stats::setNames(r$p, param_names())
  status <- "ok"
  message <- sprintf("fitted in %d iterations (%s arithmetic)", r$iterations,
                     arithmetic)
  f0 <- gc_fit_gradient(v[, 1], v[, 2], v[, 3], c(1, 1, 1, 0, 0, 0, 0, 0, 0),
                        0L, h, rep(1, 9), use_sqrt, objective == "sum", 0,
                        FALSE, arithmetic, FALSE)$objective
  if (!r$finite || !all(is.finite(p)) || !is.finite(r$objective) ||
      r$objective > 10 * f0 + 1e-6) {
    status <- "diverged"
    message <- paste0("the gradient descent diverged (objective = \"",
                      objective, "\", rates ", paste(rates, collapse = ", "),
                      "); coefficients left at the identity")
    p <- stats::setNames(c(1, 1, 1, 0, 0, 0, 0, 0, 0), param_names())
  } else if (!(r$objective < f0)) {
    status <- "no_improvement"
    message <- sprintf(paste0(
      "the objective did not decrease in %d iterations (%s arithmetic, ",
      "h = %s): %s at the start, %s at the end; coefficients left at the ",
      "identity"), r$iterations, arithmetic, format(h), format(f0),
      format(r$objective))
    p <- stats::setNames(c(1, 1, 1, 0, 0, 0, 0, 0, 0), param_names())
  }
  if (!is.data.frame(pts) || !all(c("mean_x", "mean_y", "mean_z") %in%
                                  names(pts))) {
    pts <- data.frame(mean_x = v[, 1], mean_y = v[, 2], mean_z = v[, 3])
  }
  fit <- new_fit(K = params_to_K(p), offset = unname(p[7:9]),
                 points = pts, method = "lightweight",
                 iterations = r$iterations,
                 converged = r$converged || (status == "ok" && tol == 0),
                 status = status, message = message, call = call)
  fit$params <- p
  fit$objective <- r$objective
  fit$settings <- list(arithmetic = arithmetic, max_iter = max_iter,
                       rates = rates, h = h, objective = objective,
                       use_sqrt = use_sqrt, tol = tol, difference = difference)
  if (status == "ok") fit <- add_uncertainty(fit, v, use_sqrt = use_sqrt)
  if (trace) {
    tr <- t(r$trace)
    colnames(tr) <- c(param_names(), "f")
    fit$trace <- cbind(iteration = seq_len(nrow(tr)), tr)
  }
  fit
}

# Smallest step each arithmetic can take from parameters near 1: one unit
# of the last place of its numbers in [1, 2) (float, double), or the
# resolution of its fixed-point format (Q3.29, Q1.14). A smaller `h` rounds
# to zero, or leaves the difference quotient all rounding error.
step_resolution <- c(double = 2^-52, float = 2^-23, fixed32 = 2^-29,
                     fixed16 = 2^-14)

check_step <- function(h, arithmetic) {
  res <- step_resolution[[arithmetic]]
  if (h < res) {
    what <- switch(arithmetic,
      fixed16 = "16-bit fixed point (Q1.14)", fixed32 = "32-bit fixed point (Q3.29)",
      float = "single precision near 1", double = "double precision near 1")
    abort("`h` must be at least ", format(signif(res, 3)), ", the resolution ",
          "of ", what, ", not ", format(h), ": a smaller step ",
          if (arithmetic %in% c("fixed16", "fixed32")) "rounds to zero" else
            "does not move the parameters", ".")
  }
  invisible(h)
}

# 9 parameters -> lower-triangular K.
params_to_K <- function(p) {
  K <- diag(unname(p[1:3]))
  K[2, 1] <- p[[4]]
  K[3, 1] <- p[[5]]
  K[3, 2] <- p[[6]]
  dimnames(K) <- list(c("x", "y", "z"), c("x", "y", "z"))
  K
}

# A numeric n x 3 matrix of point coordinates from mean_x/... or x/y/z.
point_matrix <- function(pts, arg) {
  if (is.matrix(pts) && is.numeric(pts) && is.null(colnames(pts)) &&
      ncol(pts) == 3) {
    return(pts)
  }
  if (is.matrix(pts)) pts <- as.data.frame(pts)
  if (is.data.frame(pts) && !all(c("mean_x", "mean_y", "mean_z") %in%
                                 names(pts)) &&
      all(c("x", "y", "z") %in% names(pts))) {
    pts <- data.frame(mean_x = pts$x, mean_y = pts$y, mean_z = pts$z)
  }
  pts <- as_epochs(pts, arg)
  v <- cbind(as.double(pts$mean_x), as.double(pts$mean_y),
             as.double(pts$mean_z))
  if (!all(is.finite(v))) {
    abort("`", arg, "` must not contain NA, NaN or Inf coordinates.")
  }
  v
}
