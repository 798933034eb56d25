test_that("the Jacobian of the residuals matches finite differences", {
  rec <- simulate_recording(hours = 24, sf = 10, seed = 2,
                            tempoffset = c(0.001, -0.001, 0.0005))
  fl <- calibrate(rec, sf = 10)
  v <- as.matrix(fl$points[c("mean_x", "mean_y", "mean_z")])
  res <- function(p, sqrt_) {
    a <- sweep(v, 2, p[7:9], `+`) %*% t(gravcal:::params_to_K(p))
    if (sqrt_) sqrt(rowSums(a^2)) - 1 else rowSums(a^2) - 1
  }
  for (s in c(FALSE, TRUE)) {
    jr <- gravcal:::residual_jacobian(fl, v, use_sqrt = s)
    num <- sapply(1:9, function(k) {
      e <- replace(numeric(9), k, 1e-6)
      (res(fl$params + e, s) - res(fl$params - e, s)) / 2e-6
    })
    expect_equal(unname(jr$J), num, tolerance = 1e-7)
    expect_equal(jr$r, res(fl$params, s))
  }
  fi <- fit_icp(rest_windows(rec, sf = 10, method = "ggir"))
  v <- as.matrix(fi$points[c("mean_x", "mean_y", "mean_z")])
  tt <- fi$points$temperature
  resg <- function(p) {
    a <- sweep(sweep(v, 2, p[4:6], `+`), 2, p[1:3], `*`) +
      outer(tt - fi$meantemp, p[7:9])
    sqrt(rowSums(a^2)) - 1
  }
  p0 <- c(diag(fi$K), fi$offset, fi$tempoffset)
  jr <- gravcal:::residual_jacobian(fi, v, tt)
  num <- sapply(1:9, function(k) {
    e <- replace(numeric(9), k, 1e-6)
    (resg(p0 + e) - resg(p0 - e)) / 2e-6
  })
  expect_equal(unname(jr$J), unname(num), tolerance = 1e-6)
  expect_equal(colnames(jr$J), c("k_xx", "k_yy", "k_zz", "o_x", "o_y", "o_z",
                                 "t_x", "t_y", "t_z"))
})

test_that("standard errors agree with R's nls() on the same residuals", {
  # reference: stats::nls() fits the same model to the same points and
  # reports s^2 (J'J)^-1 (summary.nls), computed by R's own code
  set.seed(7)
  cand <- simulate_points(500, noise = 0.003)
  fit <- fit_gradient(select_points(cand), max_iter = 5000, tol = 1e-12)
  expect_equal(fit$status, "ok")
  d <- data.frame(x = fit$points$mean_x, y = fit$points$mean_y,
                  z = fit$points$mean_z, one = 1)
  p <- fit$params
  ref <- stats::nls(one ~ (kxx * (x + ox))^2 +
                      (kxy * (x + ox) + kyy * (y + oy))^2 +
                      (kxz * (x + ox) + kyz * (y + oy) + kzz * (z + oz))^2,
                    data = d, start = list(kxx = p[[1]], kyy = p[[2]],
                                           kzz = p[[3]], kxy = p[[4]],
                                           kxz = p[[5]], kyz = p[[6]],
                                           ox = p[[7]], oy = p[[8]],
                                           oz = p[[9]]))
  se_ref <- summary(ref)$coefficients[, "Std. Error"]
  expect_equal(unname(fit$se[param_names()]), unname(se_ref), tolerance = 1e-3)
  # the descent's forward differences leave it about h = 1e-5 from the
  # optimum nls() finds (see ?fit_gradient), far below the standard errors
  expect_equal(unname(coef(ref)), unname(fit$params), tolerance = 1e-4)
  expect_equal(fit$df, 9L)
  expect_equal(dim(vcov(fit)), c(9L, 9L))
  expect_equal(sqrt(diag(vcov(fit))), fit$se[param_names()])
  expect_true(all(is.na(fit$se[c("t_x", "t_y", "t_z")])))

  # GGIR's weighted fit: nls() with the weights at the solution
  rec <- simulate_recording(hours = 24, sf = 10, seed = 2,
                            tempoffset = c(0.001, -0.001, 0.0005))
  fi <- fit_icp(rest_windows(rec, sf = 10, method = "ggir"))
  pt <- fi$points
  g <- data.frame(x = pt$mean_x, y = pt$mean_y, z = pt$mean_z,
                  dt = pt$temperature - fi$meantemp, one = 1)
  a <- gravcal:::calibrate_points(fi, as.matrix(g[1:3]), pt$temperature)
  w <- pmin(1 / abs(sqrt(rowSums(a^2)) - 1), 100)
  s0 <- diag(fi$K)
  o0 <- fi$offset
  t0 <- fi$tempoffset
  # evaluated at gravcal's solution (maxiter = 0, whose warning that it
  # stopped is expected), where the weights were computed
  refg <- suppressWarnings(stats::nls(one ~ sqrt((sx * (x + ox) + dt * tx)^2 +
                                  (sy * (y + oy) + dt * ty)^2 +
                                  (sz * (z + oz) + dt * tz)^2),
                     data = g, weights = w,
                     start = list(sx = s0[[1]], sy = s0[[2]], sz = s0[[3]],
                                  ox = o0[[1]], oy = o0[[2]], oz = o0[[3]],
                                  tx = t0[[1]], ty = t0[[2]], tz = t0[[3]]),
                     control = stats::nls.control(maxiter = 0,
                                                  warnOnly = TRUE,
                                                  nDcentral = TRUE)))
  # (central differences: nls()'s forward differences step a temperature
  # offset of 0.001 by 1.5e-11 and give its standard error to only about
  # 1e-5; central ones agree with the analytic Jacobian to about 1e-8)
  se_g <- summary(refg)$coefficients[, "Std. Error"]
  nm <- c("k_xx", "k_yy", "k_zz", "o_x", "o_y", "o_z", "t_x", "t_y", "t_z")
  expect_equal(unname(fi$se[nm]), unname(se_g), tolerance = 1e-6)
  expect_true(all(is.na(fi$se[c("k_xy", "k_xz", "k_yz")])))
  # the GGIR procedure's fit carries them too
  fg <- calibrate(rec, sf = 10, method = "ggir")
  expect_true(all(is.finite(fg$se[nm])))
  expect_equal(colnames(vcov(fg)), nm)
})

test_that("fits not applied have no standard errors", {
  # (constant samples: the guard against identical samples, which would
  # leave every window out, is turned off to reach these statuses)
  flat <- data.frame(x = 0.01 + 0 * seq_len(3600), y = -0.02, z = 1.03)
  f <- calibrate(flat, sf = 10, selection = "paper", max_identical = 1)
  expect_equal(f$status, "bins_incomplete")
  expect_true(all(is.na(f$se)))
  expect_error(vcov(f), "no covariance.*bins_incomplete")
  f <- calibrate(flat, sf = 10, max_identical = 1)
  expect_equal(f$status, "sphere_not_covered")
  expect_true(all(is.na(f$se)))
  expect_error(vcov(f), "no covariance.*sphere_not_covered")
  expect_error(confint(f), "no covariance")
  # a fit refused by guard_fit() loses its errors with its coefficients
  rec <- simulate_recording(hours = 24, sf = 10, seed = 3)
  clip <- rec
  clip$x[1:50] <- 2
  clip$y[1:50] <- 0.2
  clip$z[1:50] <- 0.1
  bad <- calibrate(clip, sf = 10, max_norm_error = Inf, selection = "paper",
                   max_identical = 1)
  expect_equal(bad$status, "implausible")
  expect_true(all(is.na(bad$se)))
  expect_null(bad$vcov)
})

test_that("confint() gives estimate +- t(df) se and checks its arguments", {
  rec <- simulate_recording(hours = 24, sf = 10, seed = 3)
  fit <- calibrate(rec, sf = 10, selection = "paper")
  ci <- confint(fit)
  expect_equal(rownames(ci), param_names())
  expect_equal(colnames(ci), c("2.5 %", "97.5 %"))
  q <- stats::qt(0.975, 9)
  expect_equal(ci[, 2] - ci[, 1], 2 * q * fit$se[param_names()])
  expect_equal(rownames(confint(fit, "o_x", level = 0.9)), "o_x")
  expect_equal(rownames(confint(fit, 7:9)), c("o_x", "o_y", "o_z"))
  expect_error(confint(fit, "t_x"), "`parm` must name fitted coefficients")
  expect_error(confint(fit, level = 2), "`level` must be")
  expect_output(print(fit), "standard errors \\(9 residual df\\)")
  expect_output(print(summary(fit)), "estimate +se")
})

test_that("fits name the coefficients their model fitted", {
  rec <- simulate_recording(hours = 26, sf = 10, seed = 61,
                            params = c(1.01, 0.99, 1.02, 0, 0, 0, 0.02, -0.01, 0.015),
                            tempoffset = c(0.001, 0, -0.001))
  lw <- calibrate(rec, sf = 10, method = "lightweight")
  expect_equal(lw$status, "ok")
  # no cross-axis terms in the truth: scale, offset and temperature
  six <- c("k_xx", "k_yy", "k_zz", "o_x", "o_y", "o_z")
  expect_identical(lw$model, c(six, "t_x", "t_y", "t_z"))
  expect_lt(max(abs(lw$tempoffset - c(0.001, 0, -0.001))), 1e-4)
  lw9 <- calibrate(rec, sf = 10, use_temp = FALSE)
  expect_identical(lw9$model, six)
  expect_identical(calibrate(rec, sf = 10, model = "full")$model,
                   c(param_names(), "t_x", "t_y", "t_z"))
  gg <- calibrate(rec, sf = 10, method = "ggir")
  expect_equal(gg$status, "ok")
  expect_identical(gg$model, c("k_xx", "k_yy", "k_zz", "o_x", "o_y", "o_z",
                               "t_x", "t_y", "t_z"))
  # the model's coefficients are the ones with a standard error
  expect_identical(names(gg$se)[!is.na(gg$se)], gg$model)
  gg0 <- calibrate(rec[, c("x", "y", "z")], sf = 10, method = "ggir")
  expect_identical(gg0$model, c("k_xx", "k_yy", "k_zz", "o_x", "o_y", "o_z"))
  # not calibrated: identity, no model
  short <- calibrate(simulate_recording(hours = 1, sf = 10, seed = 62), sf = 10,
                     method = "ggir")
  expect_false(short$status == "ok")
  expect_identical(short$model, character(0))
})

test_that("robust (HC3) standard errors: the sandwich, restated", {
  rec <- simulate_recording(hours = 24, sf = 10, seed = 3, temperature = FALSE)
  fit <- calibrate(rec, sf = 10)
  expect_identical(fit$settings$se, "robust")
  v <- as.matrix(fit$points[c("mean_x", "mean_y", "mean_z")])
  # an independent restatement: the Jacobian by central differences of
  # |K(v + o)|^2 - 1 in the nine parameters, then HC3
  res <- function(p) {
    K <- matrix(0, 3, 3)
    diag(K) <- p[1:3]
    K[2, 1] <- p[4]; K[3, 1] <- p[5]; K[3, 2] <- p[6]
    u <- t(t(v) + p[7:9])
    rowSums((u %*% t(K))^2) - 1
  }
  p <- unname(fit$params)
  J <- sapply(1:9, function(j) {
    e <- replace(numeric(9), j, 1e-6)
    (res(p + e) - res(p - e)) / 2e-6
  })
  r <- res(p)
  B <- solve(crossprod(J))
  h <- rowSums((J %*% B) * J)
  V <- B %*% crossprod(J * (r / (1 - h))) %*% B
  expect_equal(unname(fit$se[param_names()]), sqrt(diag(V)), tolerance = 1e-5)
  expect_equal(fit$df, nrow(v) - 9L)
  # classic on request: s^2 (J'J)^-1
  fc <- fit_gradient(fit$points, algorithm = "lm", se = "classic")
  expect_equal(unname(fc$se[param_names()]),
               sqrt(diag(sum(r^2) / (nrow(v) - 9) * B)), tolerance = 1e-5)
})
