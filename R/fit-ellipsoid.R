#' Fit the 9-parameter model by a non-iterative ellipsoid fit
#'
#' The closed-form alternative Farago et al. (2024) compare against in their
#' Table 3: the ellipsoid fit of Gietzelt et al. (2013). The rest points `v`
#' of a miscalibrated sensor lie on an ellipsoid, `(v + o)' A (v + o) = 1`
#' with `A = K'K`. Written out, that is a quadric `v' M v + n' v = 1` whose
#' nine coefficients (six in the symmetric `M`, three in `n`) follow from
#' one linear least-squares solve. The centre is then `o = M^-1 n / 2`, the
#' scale `A = M / (1 + o' M o)`, and `K` the lower-triangular factor with
#' `K'K = A` (a Cholesky factorization taken in reversed axis order), which
#' is the model of [fit_gradient()]: the same nine parameters, no
#' iterations.
#'
#' The solve minimizes the algebraic residual of the quadric, not the
#' distance from the unit sphere, so with noisy points it is not the
#' least-squares calibration: its error is somewhat larger than the
#' iterative fits' (as in the paper's Table 3).
#'
#' @inheritParams fit_gradient
#' @return A `gravcal_fit` with `method = "ellipsoid"` and `params`. Status
#'   `"ok"`, or `"diverged"` (identity coefficients) when the points do not
#'   determine an ellipsoid (fewer than 9 independent points, or a quadric
#'   that is not an ellipsoid).
#' @references Gietzelt M, Wolf K-H, Marschollek M, Haux R (2013).
#'   Performance comparison of accelerometer calibration algorithms based on
#'   3D-ellipsoid fitting methods. Computer Methods and Programs in
#'   Biomedicine 111(1), 62-71.
#' @seealso [fit_gradient()]
#' @export
#' @examples
#' set.seed(42)
#' cand <- simulate_points(500, noise = 0.001)
#' fit <- fit_ellipsoid(select_points(cand))
#' rbind(truth = attr(cand, "params"), fit = fit$params)
fit_ellipsoid <- function(pts) {
  call <- match.call()
  v <- point_matrix(pts, "pts")
  if (nrow(v) < 9) {
    abort("`pts` must hold at least 9 points to fit 9 parameters, not ",
          nrow(v), ".")
  }
  p <- ellipsoid_params(v)
  status <- "ok"
  message <- "closed-form ellipsoid fit"
  if (is.null(p)) {
    status <- "diverged"
    message <- paste0("the points do not determine an ellipsoid; ",
                      "coefficients left at the identity")
    p <- c(1, 1, 1, 0, 0, 0, 0, 0, 0)
  }
  p <- stats::setNames(p, param_names())
  if (!is.data.frame(pts) || !all(c("mean_x", "mean_y", "mean_z") %in% names(pts))) {
    pts <- data.frame(mean_x = v[, 1], mean_y = v[, 2], mean_z = v[, 3])
  }
  fit <- new_fit(K = params_to_K(p), offset = unname(p[7:9]), points = pts,
                 method = "ellipsoid", converged = status == "ok",
                 status = status, message = message, call = call)
  fit$params <- p
  fit
}

# The nine parameters of the ellipsoid through the points, or NULL.
ellipsoid_params <- function(v) {
  x <- v[, 1]
  y <- v[, 2]
  z <- v[, 3]
  D <- cbind(x * x, y * y, z * z, 2 * x * y, 2 * x * z, 2 * y * z, x, y, z)
  q <- tryCatch(qr.coef(qr(D), rep(1, nrow(v))), error = function(e) NULL)
  if (is.null(q) || !all(is.finite(q))) return(NULL)
  M <- matrix(c(q[1], q[4], q[5],
                q[4], q[2], q[6],
                q[5], q[6], q[3]), 3)
  Mi <- tryCatch(solve(M), error = function(e) NULL)
  if (is.null(Mi)) return(NULL)
  o <- drop(Mi %*% q[7:9]) / 2
  A <- M / (1 + drop(o %*% M %*% o))
  # K lower triangular with K'K = A: with J the reversal of the axes,
  # chol(J A J) = R upper triangular, and K = J R J is lower triangular
  J <- diag(3)[3:1, ]
  R <- tryCatch(chol(J %*% A %*% J), error = function(e) NULL)
  if (is.null(R)) return(NULL)
  K <- J %*% R %*% J
  c(K[1, 1], K[2, 2], K[3, 3], K[2, 1], K[3, 1], K[3, 2], o)
}
