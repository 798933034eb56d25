# Standard errors and covariance of a fit's coefficients, from the Jacobian
# J of its residuals at the solution: vcov = s^2 (J' W J)^-1 with
# s^2 = sum(w r^2) / (n - p), the linearised least-squares covariance
# (Seber & Wild 1989, Nonlinear Regression, Sec. 2.1; R's summary.nls).
#
# Lightweight model a = K (v + o): the residual is the one the fit
# minimised, |a|^2 - 1 (or |a| - 1 with use_sqrt), unweighted. GGIR model
# a_j = s_j (v_j + o_j) + (T - meantemp) t_j: the residual is |a| - 1, the
# distance to the closest point on the sphere, with GGIR's weights at the
# solution, min(1 / |r|, max_weight).

# Names of the coefficients each model fits, in coef()'s order.
fitted_names <- function(fit) {
  if (fit$method %in% c("lightweight", "ellipsoid")) {
    return(if (is.null(fit$fitted)) param_names() else fit$fitted)
  }
  nm <- c("k_xx", "k_yy", "k_zz", "o_x", "o_y", "o_z")
  if (isTRUE(fit$use_temp)) {
    nm <- c(nm, "t_x", "t_y", "t_z")
  }
  nm
}

# Jacobian (n x p) and residuals of a fit at its coefficients: the model's
# value from apply_model(), its derivatives here.
residual_jacobian <- function(fit, v, temperature = NULL, use_sqrt = FALSE) {
  lightweight <- identical(fit$method, "lightweight")
  temp <- !is.null(temperature) &&
    (lightweight || "t_x" %in% fitted_names(fit))
  dt <- if (temp) temperature - fit$meantemp
  K <- unname(fit$K)
  a <- apply_model(v, K, fit$offset, fit$tempoffset, dt)
  u <- sweep(v, 2, fit$offset, `+`)
  na <- sqrt(rowSums(a^2))
  if (lightweight) {
    if (use_sqrt) {
      r <- na - 1
      g <- a / na
    } else {
      r <- na^2 - 1
      g <- 2 * a
    }
    # d a / d k_ij = u_j e_i; d a / d o_j = K[, j]
    J <- cbind(g[, 1] * u[, 1], g[, 2] * u[, 2], g[, 3] * u[, 3],
               g[, 2] * u[, 1], g[, 3] * u[, 1], g[, 3] * u[, 2],
               g %*% K)
    colnames(J) <- param_names()
    if (temp) {
      J <- cbind(J, t_x = g[, 1] * dt, t_y = g[, 2] * dt, t_z = g[, 3] * dt)
    }
    return(list(J = J, r = r))
  }
  # GGIR's model (K diagonal): d a_j / d s_j = u_j, d a_j / d o_j = s_j
  g <- a / na
  J <- cbind(g * u, sweep(g, 2, diag(K), `*`))
  if (temp) J <- cbind(J, g * dt)
  colnames(J) <- fitted_names(fit)[seq_len(ncol(J))]
  list(J = J, r = na - 1)
}

# Attach se (named like coef(), NA for what the model does not fit), vcov
# (the fitted coefficients) and df to a fit whose coefficients were fitted.
add_uncertainty <- function(fit, v, temperature = NULL, weights = NULL,
                            use_sqrt = FALSE, max_weight = 100,
                            type = c("classic", "robust")) {
  type <- match.arg(type)
  fit <- clear_uncertainty(fit)
  fit$model <- fitted_names(fit)
  jr <- residual_jacobian(fit, v, temperature, use_sqrt)
  J <- jr$J[, fit$model, drop = FALSE]
  r <- jr$r
  w <- switch(weights %||% "none",
              none = rep(1, length(r)),
              ggir = pmin(1 / abs(r), max_weight))
  n <- nrow(J)
  p <- ncol(J)
  df <- n - p
  fit$df <- df
  if (df < 1 || !all(is.finite(J)) || !all(is.finite(r))) return(fit)
  s2 <- sum(w * r^2) / df
  A <- crossprod(J * sqrt(w))
  inv <- tryCatch(solve(A), error = function(e) NULL)
  if (is.null(inv) || rcond(A) < 1e-12) return(fit)
  V <- s2 * inv
  if (type == "robust") {
    # HC3 (MacKinnon & White 1985): each point's squared residual, inflated
    # by its leverage, in place of the common variance s^2
    Jw <- J * sqrt(w)
    h <- pmin(rowSums((Jw %*% inv) * Jw), 0.99)
    meat <- crossprod(Jw * (sqrt(w) * r / (1 - h)))
    V <- inv %*% meat %*% inv
  }
  V <- (V + t(V)) / 2
  dimnames(V) <- list(colnames(J), colnames(J))
  fit$vcov <- V
  fit$se[colnames(J)] <- sqrt(pmax(diag(V), 0))
  fit$sigma <- sqrt(s2)
  fit
}

# (also for a fit whose coefficients are set back to the identity: it then
# fits nothing, `model` is empty)
clear_uncertainty <- function(fit) {
  fit["model"] <- list(character(0))
  fit$se <- stats::setNames(rep(NA_real_, 12),
                            c(param_names(), "t_x", "t_y", "t_z"))
  fit["vcov"] <- list(NULL)
  fit["df"] <- list(NA_integer_)
  fit["sigma"] <- list(NA_real_)
  fit
}

#' Covariance and confidence intervals of calibration coefficients
#'
#' The covariance of the fitted coefficients, `s^2 (J' W J)^-1`, where `J`
#' is the Jacobian of the fit's residuals at the solution and `s^2` the
#' (weighted) residual variance on `n - p` degrees of freedom: for the
#' lightweight method the residuals `|a|^2 - 1` its objective sums (`|a| - 1`
#' with `use_sqrt = TRUE`), unweighted; for the GGIR method `|a| - 1` with
#' GGIR's weights at the solution, `min(1 / |r|, 100)`. Only the
#' coefficients the model fits have a covariance: the nine parameters of
#' the lightweight model; scale and offset (and temperature offset when it
#' was fitted) for GGIR's. The intervals are `estimate +- t(df) se`.
#'
#' These are linearised least-squares errors: they assume the rest windows'
#' errors are independent with one variance. The lightweight method of
#' [calibrate()] (its default `selection = "cells"`) uses the robust HC3
#' form instead, `(J'J)^-1 J' diag(r_i^2 / (1 - h_i)^2) J (J'J)^-1` with
#' `h_i` the leverage of point `i` (MacKinnon & White 1985), which does not
#' assume one variance: on real recordings rest windows in rare
#' orientations fit worse than common ones. The coverage they reach on
#' simulated recordings is in `bench/results/coverage.md`.
#' @param object A `gravcal_fit`.
#' @param parm Names or indices of coefficients (default: those fitted).
#' @param level Confidence level.
#' @param ... Unused.
#' @return `vcov()`: a square matrix named by the fitted coefficients (an
#'   error when the fit has none, for example with a status other than
#'   `"ok"`). `confint()`: a matrix with a row per coefficient and columns
#'   for the lower and upper limits.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 12, sf = 10, seed = 3)
#' fit <- calibrate(rec, sf = 10)
#' sqrt(diag(vcov(fit)))
#' confint(fit)
vcov.gravcal_fit <- function(object, ...) {
  check_fit(object, "object")
  if (is.null(object$vcov)) {
    abort("`object` has no covariance of its coefficients: its status is \"",
          object$status, "\"", if (identical(object$status, "ok"))
            " but too few points to estimate it" else
              " (no coefficients were fitted)", ".")
  }
  object$vcov
}

#' @rdname vcov.gravcal_fit
#' @export
confint.gravcal_fit <- function(object, parm, level = 0.95, ...) {
  V <- vcov.gravcal_fit(object)
  check_number(level, "level", min = 0, max = 1, min_inclusive = FALSE,
               max_inclusive = FALSE)
  nm <- colnames(V)
  if (missing(parm)) parm <- nm
  if (is.numeric(parm)) parm <- nm[parm]
  if (!is.character(parm) || anyNA(parm) || !all(parm %in% nm)) {
    abort("`parm` must name fitted coefficients (", paste(nm, collapse = ", "),
          "), not ", describe(parm), ".")
  }
  est <- stats::coef(object)[parm]
  q <- stats::qt(1 - (1 - level) / 2, object$df)
  se <- sqrt(diag(V))[parm]
  ci <- cbind(est - q * se, est + q * se)
  pct <- paste(format(100 * c((1 - level) / 2, 1 - (1 - level) / 2),
                      trim = TRUE, digits = 3), "%")
  dimnames(ci) <- list(parm, pct)
  ci
}
