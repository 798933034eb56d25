# gravcal's default for the lightweight method (issue 17): one point per
# distinct posture, Levenberg-Marquardt, the model the points determine.

test_that("selection = 'cells' keeps the stillest window of each 0.05 g cell", {
  w <- data.frame(
    mean_x = c(0.001, 0.004, 0.2, 0.201, 0.9, -1.0, 0.0),
    mean_y = c(0, 0, 0.1, 0.1, 0, 0, 1.0),
    mean_z = c(1, 1, 0.97, 0.97, 0.4, 0, 0),
    range_x = c(0.05, 0.02, 0.03, 0.03, 0.01, 0.01, 0.02),
    range_y = 0.01, range_z = 0.01,
    rest = c(TRUE, TRUE, TRUE, TRUE, TRUE, TRUE, FALSE))
  p <- select_points(w, selection = "cells")
  # rows 1 and 2 share a cell (the second is stiller); 3 and 4 share one
  # (equal stillness: the earlier); row 7 is not rest
  expect_identical(p$row, c(2L, 3L, 5L, 6L))
  expect_identical(attr(p, "selection"), "cells")
  expect_identical(attr(p, "offered"), 6L)
  expect_identical(as.character(p$bin), c("x0", "x0", "x+", "x-"))
  # cells are independent of the order of the windows (but for ties in
  # stillness, which go to the earlier)
  w2 <- w
  w2$range_x[4] <- 0.04
  o <- c(4, 3, 2, 1, 6, 5, 7)
  p2 <- select_points(w2[o, ], selection = "cells")
  expect_setequal(o[p2$row], p$row)
  # epochs without ranges: the smallest largest sd is the stillest
  e <- data.frame(mean_x = c(0, 0.002), mean_y = 0, mean_z = 1,
                  sd_x = c(0.004, 0.002), sd_y = 0.001, sd_z = 0.001)
  expect_identical(select_points(e, selection = "cells")$row, 2L)
  expect_error(select_points(w, selection = "cells", cell = 0),
               "`cell` must be")
  expect_error(select_points(w, selection = "grid"), "`selection` must be one of")
})

test_that("the number of points is bounded by the grid, not the recording", {
  set.seed(7)
  cand <- simulate_points(20000, noise = 0.001)
  p <- select_points(cand, selection = "cells")
  # a unit sphere crosses about 4 pi / 0.05^2 = 5027 cells of 0.05 g
  expect_lt(nrow(p), 4 * pi / 0.05^2 * 1.5)
  expect_gt(nrow(p), 2000)
  expect_identical(anyDuplicated(paste(round(p$mean_x / 0.05),
                                       round(p$mean_y / 0.05),
                                       round(p$mean_z / 0.05))), 0L)
})

test_that("Levenberg-Marquardt reaches the descent's optimum in few iterations", {
  set.seed(11)
  cand <- simulate_points(400, noise = 0.002)
  pts <- select_points(cand, selection = "cells")
  lm <- fit_gradient(pts, algorithm = "lm")
  gd <- fit_gradient(pts, max_iter = 1e5, tol = 1e-13)
  expect_true(lm$converged)
  expect_lt(lm$iterations, 15L)
  expect_gt(gd$iterations, 50L)
  # the same minimum of the same objective (the descent's forward
  # difference leaves a bias of about h = 1e-5)
  expect_equal(unname(lm$params), unname(gd$params), tolerance = 5e-5)
  expect_lte(lm$objective, gd$objective)
  # the gradient of the objective vanishes at the LM solution
  obj <- function(p) gravcal:::lm_objective(as.matrix(
    pts[c("mean_x", "mean_y", "mean_z")]), p, FALSE, FALSE)
  g <- sapply(1:9, function(j) {
    e <- replace(numeric(9), j, 1e-7)
    (obj(lm$params + e) - obj(lm$params - e)) / 2e-7
  })
  expect_lt(max(abs(g)), 1e-8)
  expect_error(fit_gradient(pts, algorithm = "lm", arithmetic = "fixed16"),
               "double arithmetic only")
})

test_that("reduced models fix what they do not fit, in both algorithms", {
  set.seed(12)
  cand <- simulate_points(400, noise = 0.001)
  pts <- select_points(cand, selection = "cells")
  for (alg in c("lm", "descent")) {
    f6 <- fit_gradient(pts, algorithm = alg, model = "scale_offset",
                       max_iter = if (alg == "lm") 100 else 5000, tol = 1e-12)
    expect_equal(unname(f6$params[4:6]), c(0, 0, 0))
    expect_identical(f6$model, c("k_xx", "k_yy", "k_zz", "o_x", "o_y", "o_z"))
    expect_true(all(is.na(f6$se[c("k_xy", "k_xz", "k_yz")])))
    expect_identical(f6$df, nrow(pts) - 6L)
    f3 <- fit_gradient(pts, algorithm = alg, model = "offset",
                       max_iter = if (alg == "lm") 100 else 5000, tol = 1e-12)
    expect_equal(unname(f3$params[1:6]), c(1, 1, 1, 0, 0, 0))
    expect_identical(f3$model, c("o_x", "o_y", "o_z"))
    expect_equal(colnames(vcov(f3)), c("o_x", "o_y", "o_z"))
  }
  # the two algorithms agree on the reduced model too
  a <- fit_gradient(pts, algorithm = "lm", model = "scale_offset")
  b <- fit_gradient(pts, model = "scale_offset", max_iter = 1e5, tol = 1e-13)
  expect_equal(unname(a$params), unname(b$params), tolerance = 5e-5)
  expect_error(fit_gradient(pts[1:5, ], model = "scale_offset"),
               "at least 6 points to fit 6 parameters")
})

# Rests in a band of tilts only: with |z| near 1 never seen, and x, y
# never far from +-1 or 0, how much each model is determined varies.
band_recording <- function(tilts, params, hours = 12, seed = 1) {
  set.seed(seed)
  n_post <- 300
  az <- stats::runif(n_post, 0, 2 * pi)
  el <- sample(tilts, n_post, replace = TRUE) + stats::rnorm(n_post, sd = 0.02)
  u <- cbind(cos(el) * cos(az), cos(el) * sin(az), sin(el))
  v <- distort(u, params)
  each <- 60
  n <- n_post * each
  data.frame(x = rep(v[, 1], each = each) + stats::rnorm(n, sd = 0.003),
             y = rep(v[, 2], each = each) + stats::rnorm(n, sd = 0.003),
             z = rep(v[, 3], each = each) + stats::rnorm(n, sd = 0.003))
}

test_that("the model is the one the rest points determine, and says so", {
  p <- c(1.02, 0.98, 1.01, 0.01, -0.01, 0.02, 0.03, -0.02, 0.01)
  # every orientation: all nine parameters
  all <- band_recording(seq(-1.5, 1.5, by = 0.1), p)
  f9 <- calibrate(all, sf = 10)
  expect_identical(f9$status, "ok")
  expect_identical(f9$model, param_names())
  expect_match(f9$message, "all 9 parameters")
  expect_equal(unname(f9$params), p, tolerance = 2e-3)
  # the device horizontal-ish only (elevation within +-0.3 rad): z never
  # near +-1, so the cross terms with z and z's scale cannot be told apart
  # from its offset: scale and offset, or offset only
  flat <- band_recording(c(-0.35, 0.35), p, seed = 2)
  ff <- calibrate(flat, sf = 10)
  # offsets alone leave the undetermined 1-2 % of scale and cross-axis
  # terms: the points stay 12 mg off the sphere, which the status says
  expect_identical(ff$status, "high_error")
  expect_match(ff$message, "still 1[0-9].[0-9] mg off 1 g")
  expect_lt(length(ff$model), 9L)
  expect_match(ff$message, "not determined by the rest points")
  expect_true(all(ff$se[ff$model] <= 0.01))
  # tilts within +-0.2 rad: z never beyond 0.3 g, and offsets alone
  # (scales assumed 1) need every axis seen on both sides
  narrow <- calibrate(band_recording(c(-0.2, 0.2), p, seed = 2), sf = 10)
  expect_identical(narrow$status, "sphere_not_covered")
  expect_match(narrow$message, "both sides of every axis \\(z: neither side\\)")
  # forcing the model
  fo <- calibrate(all, sf = 10, model = "offset")
  expect_identical(fo$model, c("o_x", "o_y", "o_z"))
  expect_equal(unname(fo$params[1:6]), c(1, 1, 1, 0, 0, 0))
  # max_se is an argument, checked
  strict <- calibrate(flat, sf = 10, max_se = 1e-6)
  expect_identical(strict$status, "sphere_not_covered")
  expect_match(strict$message, "3 parameters \\(offset\\) not determined")
  expect_identical(unname(coef(strict)), c(1, 1, 1, rep(0, 9)))
  expect_error(calibrate(all, sf = 10, max_se = -1), "`max_se` must be")
  expect_error(calibrate(all, sf = 10, model = "nine"), "`model` must be one of")
  expect_error(calibrate(all, sf = 10, selection = "bins"),
               "`selection` must be one of")
})

# (a, b): the largest |difference| / sqrt(se_a^2 + se_b^2) over the
# coefficients, and all of them
windowing_z <- function(fits) {
  z <- NULL
  for (i in seq_along(fits)[-length(fits)]) for (j in (i + 1):length(fits)) {
    a <- fits[[i]]
    b <- fits[[j]]
    z <- c(z, (a$params - b$params) / sqrt(a$se[param_names()]^2 +
                                             b$se[param_names()]^2))
  }
  z
}

test_that("the same recording windowed differently agrees within its standard errors", {
  # simulated: the windowings select mostly different windows (one per
  # cell), so their estimates are close to independent and the z values
  # of their differences should look like N(0, 1) draws, not wider
  rec <- simulate_recording(hours = 24, sf = 10, seed = 5)
  fits <- list(calibrate(rec, sf = 10),
               calibrate(rec, sf = 10, window = 10),
               calibrate(rec[-(1:25), ], sf = 10),
               calibrate(rec[-(1:50), ], sf = 10, window = 10))
  z <- windowing_z(fits)
  expect_length(z, 54)
  expect_lt(sqrt(mean(z^2)), 1.5)
  expect_lt(max(abs(z)), 4)
  # chunks change nothing at all
  expect_identical(calibrate(rec, sf = 10, block_samples = 5000)$params,
                   fits[[1]]$params)
  # the real recording: within 2 standard errors (issue 17; measured in
  # bench/results/freeliving.md: at most 1.0)
  dir <- skip_if_no_shared("agcounts")
  e <- new.env()
  for (a in c("X", "Y", "Z")) {
    load(file.path(dir, paste0("calibration", a, "axis.RData")), envir = e)
  }
  ag <- data.frame(x = e$X, y = e$Y, z = e$Z)
  fits <- list(calibrate(ag, sf = 30), calibrate(ag, sf = 30, window = 10),
               calibrate(ag[-(1:75), ], sf = 30),
               calibrate(ag[-(1:150), ], sf = 30, window = 10))
  expect_true(all(vapply(fits, `[[`, "", "status") == "ok"))
  expect_lt(max(abs(windowing_z(fits))), 2)
})

test_that("on a real free-living recording: ok where the paper gives up, and better held out than GGIR", {
  dir <- skip_if_no_shared("agcounts")
  e <- new.env()
  for (a in c("X", "Y", "Z")) {
    load(file.path(dir, paste0("calibration", a, "axis.RData")), envir = e)
  }
  sf <- 30
  rec <- data.frame(x = e$X, y = e$Y, z = e$Z)
  # the paper's Table 3 protocol: fit on the odd hours, check on the even
  odd <- floor((seq_len(nrow(rec)) - 1) / (sf * 3600)) %% 2 == 1
  fl <- calibrate(rec[odd, ], sf = sf)
  fp <- calibrate(rec[odd, ], sf = sf, selection = "paper")
  fg <- calibrate(rec[odd, ], sf = sf, method = "ggir")
  expect_identical(fl$status, "ok")
  expect_identical(fp$status, "bins_incomplete")
  expect_identical(fg$status, "ok")
  chk <- rest_windows(rec[!odd, ], sf = sf)
  chk <- chk[chk$rest, ]
  v <- as.matrix(chk[c("mean_x", "mean_y", "mean_z")])
  v <- v[abs(sqrt(rowSums(v^2)) - 1) <= 0.3, ]
  err <- function(f) {
    a <- t(f$K %*% (t(v) + f$offset))
    mean(abs(sqrt(rowSums(a^2)) - 1))
  }
  # bench/results/freeliving.md: 3.50 mg against the GGIR method's 4.92
  expect_lt(err(fl), 1.1 * err(fg))
  expect_lt(err(fl), 0.2 * mean(abs(sqrt(rowSums(v^2)) - 1)))
})

test_that("a temperature offset is fitted with the nine parameters where it is determined", {
  rec <- simulate_recording(hours = 24, sf = 10, seed = 8,
                            tempoffset = c(0.002, -0.001, 0.0015))
  tr <- attr(rec, "truth")
  fit <- calibrate(rec, sf = 10)
  expect_identical(fit$model, c(param_names(), "t_x", "t_y", "t_z"))
  expect_match(fit$message, "and a temperature offset")
  # within 0.1 mg per degree C (the standard errors are about 0.03)
  expect_lt(max(abs(fit$tempoffset - c(0.002, -0.001, 0.0015))), 1e-4)
  expect_equal(unname(fit$params[1:6]), unname(tr$params[1:6]), tolerance = 1e-3)
  expect_equal(fit$meantemp, mean(fit$points$temperature))
  # without the term the same points leave more error
  f9 <- calibrate(rec, sf = 10, use_temp = FALSE)
  expect_identical(f9$model, param_names())
  expect_gt(f9$error_heldout_after, 2 * fit$error_heldout_after)
  # applied by time: apply_calibration() uses the temperature column
  cal <- apply_calibration(rec, fit)
  w <- rest_windows(cal, sf = 10)
  w <- w[w$rest, ]
  expect_lt(err_mg(as.matrix(w[c("mean_x", "mean_y", "mean_z")])), 1)
  pts <- fit$points
  expect_error(fit_gradient(pts, use_temp = TRUE), "needs `algorithm = \"lm\"`")
  pts$temperature <- NULL
  expect_error(fit_gradient(pts, algorithm = "lm", use_temp = TRUE),
               "finite numeric `temperature` column")
  expect_error(calibrate(rec, sf = 10, use_temp = NA), "`use_temp` must be")
})

test_that("cross-axis terms and temperature together: the criterion keeps both where the device has both", {
  # one recording of bench/models.R's scenario A (its results: 9 + T maps
  # with a small fraction of 6 + T's error)
  set.seed(31001)
  p <- random_params()
  tof <- 2 * (stats::runif(3) - 0.5) * 0.002
  rec <- simulate_recording(hours = 24, sf = 10, params = p, tempoffset = tof,
                            seed = 31001)
  truth <- attr(rec, "truth")
  f <- calibrate(rec, sf = 10)
  expect_identical(f$model, c(param_names(), "t_x", "t_y", "t_z"))
  expect_identical(f$models$chosen, f$models$model == "full" & f$models$temperature)
  # its BIC, restated: n log(RSS / n) + k log(n) on |a|^2 - 1
  v <- as.matrix(f$points[c("mean_x", "mean_y", "mean_z")])
  a <- t(f$K %*% (t(v) + f$offset)) +
    outer(f$points$temperature - f$meantemp, f$tempoffset)
  r <- rowSums(a^2) - 1
  n <- length(r)
  expect_equal(f$models$bic[f$models$chosen], n * log(sum(r^2) / n) + 12 * log(n))
  # mapping error over the sphere at the recording's extreme temperatures
  set.seed(1)
  u <- gravcal:::random_unit_vectors(500)
  map_err <- function(fit) {
    mean(vapply(range(rec$temperature), function(temp) {
      v <- distort(u - outer(rep(temp - truth$meantemp, 500), tof), p)
      a <- gravcal:::calibrate_points(fit, v, rep(temp, 500))
      mean(sqrt(rowSums((a - u)^2)))
    }, 0))
  }
  f6 <- calibrate(rec, sf = 10, model = "scale_offset")
  expect_identical(f6$model, c("k_xx", "k_yy", "k_zz", "o_x", "o_y", "o_z",
                               "t_x", "t_y", "t_z"))
  expect_lt(map_err(f), 0.5 * map_err(f6))
  expect_lt(1000 * map_err(f), 1)
})
