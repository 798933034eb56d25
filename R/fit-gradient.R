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
#' arithmetic. `difference = "analytic"` uses the gradient's closed form
#' instead, with `c = 4 r` (or `2 r / |a|` with `use_sqrt`) and `u = v + o`:
#' `df/dk_jk = w * sum(c * a_j * u_k)` for each entry of `K`, and
#' `df/do = K^T b` with `b = w * sum(c * a)`. It needs no step, costs one pass
#' over the points per iteration (the forward difference takes ten), and in
#' 16-bit fixed point fits as well as double (`bench/results/fixed.md`),
#' where the paper's step `h = 0.01` leaves about 11 times double's error.
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
#'   core computes on a device (`inst/include/gravcal/mcu/fixed_point.hpp`; see
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
#' @param difference How the gradient is obtained: `"forward"` differences
#'   (the paper's Eq. 13), `"central"` differences, or `"analytic"`, the
#'   closed form (see Details; `h` is then not used). Central differences
#'   cost twice the evaluations but remove the forward difference's bias of
#'   about `h / 2` per parameter: negligible with `h = 1e-5`, about 5 mg
#'   with the 16-bit step `h = 0.01`. The analytic gradient removes it
#'   altogether at a tenth of the forward difference's cost. In fixed point
#'   it is computed in block floating point (16 x 16 -> 32-bit products for
#'   `"fixed16"`, with the scale of every sum a power of two chosen from the
#'   data) and the parameters are kept in the wide type between steps, so
#'   that gradients and steps far below one unit of Q1.14 still count:
#'   `"fixed16"` then comes within 1 % of double's mean absolute error on
#'   the paper's simulation, against 11 times (forward) and 3.8 times
#'   (central) at 1 mg of noise (`bench/results/fixed.md`;
#'   `inst/include/gravcal/mcu/gradient_analytic.hpp`).
#' @param model Which parameters to fit: `"full"` (all nine, the paper's
#'   model), `"scale_offset"` (scales and offsets; the cross-axis terms stay
#'   0) or `"offset"` (offsets only; scales 1, cross-axis terms 0). A
#'   parameter the points cannot determine (for example the cross-axis
#'   terms of a recording that rested in few orientations) is better left
#'   out than fitted to noise; [calibrate()] chooses the model this way.
#' @param algorithm `"descent"` (the paper's forward-difference gradient
#'   descent, in any `arithmetic`) or `"lm"` (Levenberg-Marquardt on the
#'   same objective with its exact Jacobian, double arithmetic only). Both
#'   minimise the same objective; Levenberg-Marquardt reaches its minimum
#'   in a handful of iterations where the descent needs hundreds (its
#'   slowest direction contracts by 2-10 % per iteration). With `"lm"`,
#'   `rates`, `h` and `difference` are not used, `max_iter` defaults to
#'   100 and the fit stops once no parameter moves by more than `tol`
#'   (default `1e-10` when `tol = 0`).
#' @param se How the standard errors are computed (see
#'   [vcov.gravcal_fit()]): `"classic"`, `s^2 (J'J)^-1`, which assumes every
#'   point has the same error variance; or `"robust"`, the HC3 sandwich
#'   estimator (MacKinnon & White 1985), which stays honest when the
#'   points' errors differ (real rest windows in rare orientations fit
#'   worse than common ones). `"robust"` needs more points than parameters
#'   by a margin (it is [calibrate()]'s choice for its many-point fits).
#' @param use_temp Also fit a temperature offset per axis, the model
#'   `a = K (v + o) + (T - meantemp) t` with `meantemp` the points' mean
#'   temperature (as GGIR's model has, here with the cross-axis terms).
#'   Needs `algorithm = "lm"` and a `temperature` column in `pts`.
#' @param meantemp With `use_temp`: the reference temperature of the model
#'   (degrees C); default the points' mean. Fits that are to be compared
#'   (the segments of one recording) share one reference, so that their
#'   offsets are offsets at the same temperature.
#' @return A `gravcal_fit` (see [calibrate()]) with `K` lower-triangular,
#'   `offset`, `tempoffset` and `meantemp` (zero and NA unless
#'   `use_temp`), `params` (the nine named parameters),
#'   `objective`, `model` (the names of the fitted parameters), and `trace`
#'   when asked for (descent only). Status `"ok"`; `"diverged"`
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
                         difference = c("forward", "central", "analytic"),
                         model = c("full", "scale_offset", "offset"),
                         algorithm = c("descent", "lm"),
                         se = c("classic", "robust"), use_temp = FALSE,
                         meantemp = NULL) {
  call <- match.call()
  arithmetic <- match_choice(arithmetic, "arithmetic")
  objective <- match_choice(objective, "objective")
  difference <- match_choice(difference, "difference")
  model <- match_choice(model, "model")
  algorithm <- match_choice(algorithm, "algorithm")
  se <- match_choice(se, "se")
  free <- model_free(model)
  v <- point_matrix(pts, "pts")
  if (nrow(v) < sum(free)) {
    abort("`pts` must hold at least ", sum(free), " points to fit ",
          sum(free), " parameters, not ", nrow(v), ".")
  }
  if (algorithm == "lm" && arithmetic != "double") {
    abort("`algorithm = \"lm\"` computes in double arithmetic only, not ",
          "`arithmetic = \"", arithmetic, "\"`; use `algorithm = \"descent\"` ",
          "for the device's arithmetic.")
  }
  check_flag(use_temp, "use_temp")
  dT <- NULL
  if (!use_temp) meantemp <- NA_real_
  if (use_temp) {
    if (algorithm != "lm") {
      abort("`use_temp = TRUE` needs `algorithm = \"lm\"`: the paper's ",
            "gradient descent fits the nine parameters only.")
    }
    temp <- if (is.data.frame(pts)) pts$temperature else NULL
    if (!is.numeric(temp) || !all(is.finite(temp))) {
      abort("`use_temp = TRUE` needs a finite numeric `temperature` column ",
            "in `pts`.")
    }
    if (is.null(meantemp)) meantemp <- mean(temp)
    check_number(meantemp, "meantemp")
    dT <- temp - meantemp
  }
  if (algorithm == "lm" && missing(max_iter)) max_iter <- 100
  check_number(max_iter, "max_iter", min = 1, max = 1e6, integer = TRUE)
  if (!is.numeric(rates) || length(rates) != 3 || !all(is.finite(rates)) ||
      any(rates <= 0)) {
    abort("`rates` must be 3 positive numbers (scale, misalignment, offset), ",
          "not ", describe(rates), ".")
  }
  check_number(h, "h", min = 0, min_inclusive = FALSE)
  # the analytic gradient takes no step
  if (difference != "analytic") check_step(h, arithmetic)
  limit <- c(double = Inf, float = Inf, fixed32 = 4, fixed16 = 2)[[arithmetic]]
  if (any(abs(v) >= limit)) {
    abort("`pts` has coordinates beyond the range of ", arithmetic, " (+-",
          limit, " g): ", sum(rowSums(abs(v) >= limit) > 0), " of ", nrow(v),
          " points. Rest points lie within about 1.3 g; are they in g?")
  }
  check_flag(use_sqrt, "use_sqrt")
  check_number(tol, "tol", min = 0)
  check_flag(trace, "trace")

  if (algorithm == "lm") {
    r <- fit_lm(v, c(free, rep(use_temp, 3)), as.integer(max_iter),
                if (tol > 0) tol else 1e-10, use_sqrt, objective == "sum", dT)
    trace <- FALSE
  } else {
    r <- gc_fit_gradient(v[, 1], v[, 2], v[, 3],
                         c(1, 1, 1, 0, 0, 0, 0, 0, 0), as.integer(max_iter), h,
                         rep(unname(rates), each = 3) * free, use_sqrt,
                         objective == "sum", tol, trace, arithmetic,
                         difference)
  }
  tempoffset <- if (use_temp) r$p[10:12] else c(0, 0, 0)
  p <- stats::setNames(r$p[1:9], param_names())
  status <- "ok"
  message <- if (algorithm == "lm") {
    sprintf("fitted %s%s in %d iterations (Levenberg-Marquardt)",
            model_label(model), if (use_temp) " and a temperature offset"
            else "", r$iterations)
  } else {
    sprintf("fitted %sin %d iterations (%s arithmetic)",
            if (model == "full") "" else paste0(model_label(model), " "),
            r$iterations, arithmetic)
  }
  f0 <- if (algorithm == "lm") {
    lm_objective(v, c(1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0), use_sqrt,
                 objective == "sum")
  } else {
    gc_fit_gradient(v[, 1], v[, 2], v[, 3], c(1, 1, 1, 0, 0, 0, 0, 0, 0),
                    0L, h, rep(1, 9), use_sqrt, objective == "sum", 0,
                    FALSE, arithmetic, "forward")$objective
  }
  if (!r$finite || !all(is.finite(p)) || !is.finite(r$objective) ||
      r$objective > 10 * f0 + 1e-6) {
    status <- "diverged"
    message <- paste0("the gradient descent diverged (objective = \"",
                      objective, "\", rates ", paste(rates, collapse = ", "),
                      "); coefficients left at the identity")
    p <- stats::setNames(c(1, 1, 1, 0, 0, 0, 0, 0, 0), param_names())
    tempoffset <- c(0, 0, 0)
  } else if (!(r$objective < f0)) {
    status <- "no_improvement"
    message <- sprintf(paste0(
      "the objective did not decrease in %d iterations (%s arithmetic, ",
      "h = %s): %s at the start, %s at the end; coefficients left at the ",
      "identity"), r$iterations, arithmetic, format(h), format(f0),
      format(r$objective))
    p <- stats::setNames(c(1, 1, 1, 0, 0, 0, 0, 0, 0), param_names())
    tempoffset <- c(0, 0, 0)
  }
  if (!is.data.frame(pts) || !all(c("mean_x", "mean_y", "mean_z") %in%
                                  names(pts))) {
    pts <- data.frame(mean_x = v[, 1], mean_y = v[, 2], mean_z = v[, 3])
  }
  fit <- new_fit(K = params_to_K(p), offset = unname(p[7:9]),
                 tempoffset = tempoffset, meantemp = meantemp,
                 points = pts, method = "lightweight",
                 iterations = r$iterations,
                 converged = r$converged ||
                   (algorithm == "descent" && status == "ok" && tol == 0),
                 status = status, message = message, call = call)
  fit$params <- p
  fit$objective <- r$objective
  fit$settings <- list(arithmetic = arithmetic, max_iter = max_iter,
                       rates = rates, h = h, objective = objective,
                       use_sqrt = use_sqrt, tol = tol, difference = difference,
                       model = model, algorithm = algorithm, se = se,
                       use_temp = use_temp)
  fit$fitted <- c(param_names(), "t_x", "t_y", "t_z")[c(free,
                                                        rep(use_temp, 3))]
  if (status == "ok") {
    fit <- add_uncertainty(fit, v, temperature = if (use_temp) pts$temperature,
                           use_sqrt = use_sqrt, type = se)
  }
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

# Which of the nine parameters each model fits.
model_free <- function(model) {
  switch(model,
         full = rep(TRUE, 9),
         scale_offset = c(TRUE, TRUE, TRUE, FALSE, FALSE, FALSE,
                          TRUE, TRUE, TRUE),
         offset = c(rep(FALSE, 6), TRUE, TRUE, TRUE))
}

model_label <- function(model) {
  switch(model,
         full = "all 9 parameters (scale, cross-axis, offset)",
         scale_offset = "6 parameters (scale, offset)",
         offset = "3 parameters (offset)")
}

# Residuals of the lightweight objective at parameters p: |a|^2 - 1, or
# |a| - 1 with use_sqrt, a = K (v + o).
lm_residuals <- function(v, p, use_sqrt, dT = NULL) {
  a <- apply_model(v, params_to_K(p), p[7:9], p[10:12], dT)
  na2 <- rowSums(a^2)
  if (use_sqrt) sqrt(na2) - 1 else na2 - 1
}

lm_objective <- function(v, p, use_sqrt, sum_scale) {
  r <- lm_residuals(v, p, use_sqrt)
  sum(r^2) / if (sum_scale) 1 else length(r)
}

# Levenberg-Marquardt (Marquardt 1963, with the scaled damping of More
# 1978) on the lightweight objective, over the parameters marked in
# `free` (12: the nine, then the temperature offsets, fitted when `dT`, the
# points' temperatures less their mean, is given), from the ideal sensor. Stops once no parameter moves by more
# than `tol`, when the damping can no longer find a step that lowers the
# objective (the minimum, to rounding), or after `max_iter` iterations.
fit_lm <- function(v, free, max_iter, tol, use_sqrt, sum_scale, dT = NULL) {
  p <- c(1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0)
  jac <- function(p) {
    f <- list(K = params_to_K(p), offset = p[7:9], tempoffset = p[10:12],
              meantemp = 0, method = "lightweight")
    J <- residual_jacobian(f, v, temperature = dT, use_sqrt = use_sqrt)$J
    J[, free[seq_len(ncol(J))], drop = FALSE]
  }
  r <- lm_residuals(v, p, use_sqrt, dT)
  S <- sum(r^2)
  mu <- 1e-3
  converged <- FALSE
  finite <- TRUE
  it <- 0L
  while (it < max_iter) {
    it <- it + 1L
    J <- jac(p)
    A <- crossprod(J)
    g <- crossprod(J, r)
    d <- pmax(diag(A), 1e-12)
    moved <- FALSE
    while (mu < 1e12) {
      step <- tryCatch(-solve(A + mu * diag(d, length(d)), g),
                       error = function(e) NULL)
      if (!is.null(step) && all(is.finite(step))) {
        pn <- p
        pn[free] <- p[free] + step
        rn <- lm_residuals(v, pn, use_sqrt, dT)
        Sn <- sum(rn^2)
        if (is.finite(Sn) && Sn <= S) {
          moved <- TRUE
          break
        }
      }
      mu <- mu * 10
    }
    if (!moved) {
      # no step lowers the objective: the minimum, to rounding
      converged <- TRUE
      break
    }
    mu <- max(mu / 10, 1e-15)
    small <- max(abs(pn - p)) <= tol
    p <- pn
    r <- rn
    S <- Sn
    if (small) {
      converged <- TRUE
      break
    }
  }
  if (!all(is.finite(p))) finite <- FALSE
  list(p = p, iterations = it, converged = converged, finite = finite,
       objective = S / if (sum_scale) 1 else length(r))
}
