test_that("print, summary and plot describe the fit", {
  rec <- simulate_recording(hours = 12, sf = 10, seed = 61)
  fit <- calibrate(rec, sf = 10)
  expect_output(print(fit), "lightweight method, status: ok")
  expect_output(print(fit), "error on held-out rest: +[0-9.]+ mg -> [0-9.]+ mg")
  s <- summary(fit)
  expect_s3_class(s, "summary.gravcal_fit")
  expect_equal(s$errors$n, c(nrow(fit$points),
                             nrow(fit$windows) - nrow(fit$points)))
  expect_equal(s$errors$before_mg[2], 1000 * fit$error_heldout_before)
  expect_output(print(s), "Points per orientation bin")
  f <- tempfile(fileext = ".png")
  grDevices::png(f, width = 800, height = 800)
  expect_invisible(plot(fit))
  plot(fit, which = 1, set = "points")
  grDevices::dev.off()
  expect_gt(file.size(f), 5000)
  expect_error(plot(fit, which = 7), "`which` must be a subset of 1:4")
})

test_that("a fit without points cannot be plotted, and says why", {
  f <- calibrate(data.frame(x = 0, y = 0, z = rep(1, 10)), sf = 10)
  expect_output(print(f), "too_short")
  expect_error(plot(f), "no rest points to plot \\(status: too_short\\)")
})

test_that("plot(): text where a number belongs, zero or missing rest vectors", {
  rec <- simulate_recording(hours = 3, sf = 10, seed = 1)
  fit <- calibrate(rec, sf = 10)
  grDevices::pdf(NULL)
  on.exit(grDevices::dev.off())
  expect_snapshot(error = TRUE, plot(fit, which = "1"))
  expect_snapshot(error = TRUE, plot(fit, theta = "a"))
  expect_snapshot(error = TRUE, plot(fit, phi = NA))
  expect_snapshot(error = TRUE, plot(fit, set = 1))
  zero <- fit
  zero$windows[c(1, 4), c("mean_x", "mean_y", "mean_z")] <- 0
  expect_snapshot(error = TRUE, plot(zero))
  # the fitting points alone have no zero vector: they plot
  expect_invisible(plot(zero, set = "points"))
  missing <- fit
  missing$windows$mean_x[2] <- NA
  expect_snapshot(error = TRUE, plot(missing))
  expect_snapshot(error = TRUE, plot.gravcal_fit(list(K = diag(3))))
})

test_that("the sphere map places each rest window and marks the fit's points", {
  rec <- simulate_recording(hours = 12, sf = 10, seed = 61)
  fit <- calibrate(rec, sf = 10)
  v <- as.matrix(fit$windows[, c("mean_x", "mean_y", "mean_z")])
  a <- gravcal:::calibrate_points(fit, v, fit$windows$temperature)
  m <- gravcal:::sphere_map_data(fit, fit$windows, v, a)
  # directions and errors, restated independently
  r <- sqrt(v[, 1]^2 + v[, 2]^2 + v[, 3]^2)
  expect_equal(m$azimuth, atan2(v[, 2], v[, 1]) / pi * 180)
  expect_equal(m$elevation, 90 - acos(v[, 3] / r) / pi * 180)
  expect_equal(m$error_before_mg, 1000 * abs(r - 1))
  np <- nrow(fit$points)
  expect_equal(mean(m$error_after_mg), 1000 * fit$error_heldout_after *
                 (nrow(v) - np) / nrow(v) + 1000 * fit$error_after * np / nrow(v))
  expect_identical(sum(m$used), nrow(fit$points))
  expect_true(all(abs(m$elevation) <= 90) && all(abs(m$azimuth) <= 180))
  f <- tempfile(fileext = ".png")
  grDevices::png(f, width = 1100, height = 500)
  expect_invisible(plot(fit))
  expect_invisible(plot(fit, type = "map", set = "points"))
  grDevices::dev.off()
  expect_gt(file.size(f), 5000)
  expect_error(plot(fit, type = "globe"), "`type`")
})
