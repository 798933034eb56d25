# Coefficients per segment of time (issue 20, item 1).

# A recording whose x offset drifts linearly by `drift` g over its length.
drifting <- function(days, drift, seed, sf = 5) {
  set.seed(seed)
  p <- random_params()
  rec <- simulate_recording(hours = 24 * days, sf = sf, params = p,
                            seed = seed)
  t <- as.numeric(rec$time - rec$time[1])
  rec$x <- rec$x + drift * t / max(t)
  rec
}

test_that("a drifting offset is followed day by day, and applied by time", {
  rec <- drifting(4, 0.012, seed = 3)
  one <- calibrate(rec, sf = 5)
  fs <- calibrate(rec, sf = 5, segments = "day")
  expect_identical(fs$status, "ok")
  seg <- fs$segments
  expect_identical(nrow(seg), 4L)
  expect_identical(seg$segment, 1:4)
  # the x offset falls by the drift (3 mg a day); the others do not move
  d <- diff(seg$o_x)
  expect_true(all(d < -0.002 & d > -0.004))
  expect_lt(max(abs(diff(seg$o_y))), 5 * max(seg$o_y.se))
  expect_true(all(seg$o_x.se > 0 & seg$o_x.se < 0.001))
  expect_identical(seg$from[1], -Inf)
  expect_identical(seg$to[4], Inf)
  expect_equal(seg$from[2:4] - seg$from[2], c(0, 86400, 2 * 86400))
  expect_match(fs$message, "4 segments")
  expect_output(print(fs), "4 segments over time")
  # applied by time: each sample with its day's coefficients
  cal <- apply_calibration(rec, fs)
  day <- findInterval(as.numeric(rec$time), seg$from)
  i <- which(day == 3)[1:5]
  u <- cbind(rec$x[i] + seg$o_x[3], rec$y[i] + seg$o_y[3], rec$z[i] + seg$o_z[3])
  expect_equal(cal$x[i], seg$k_xx[3] * u[, 1])
  expect_equal(cal$z[i], seg$k_xz[3] * u[, 1] + seg$k_yz[3] * u[, 2] +
                 seg$k_zz[3] * u[, 3])
  err <- function(d) {
    w <- rest_windows(d, sf = 5)
    err_mg(as.matrix(w[w$rest, c("mean_x", "mean_y", "mean_z")]))
  }
  expect_lt(err(cal), 0.5 * err(apply_calibration(rec, one)))
  # without a time column: times from the row numbers
  nt <- rec[names(rec) != "time"]
  fn <- calibrate(nt, sf = 5, segments = "day")
  expect_identical(fn$segment_settings$time, "seconds")
  expect_equal(fn$segments$o_x, seg$o_x)
  expect_equal(apply_calibration(nt, fn)$x, cal$x)
  expect_error(apply_calibration(nt, fs), "must have a `time` column")
  # the plot over time
  f <- tempfile(fileext = ".png")
  grDevices::png(f, width = 700, height = 700)
  expect_invisible(plot(fs, type = "segments"))
  grDevices::dev.off()
  expect_gt(file.size(f), 1000)
  unlink(f)
  expect_error(plot(one, type = "segments"), "has no segments")
})

test_that("a recording without drift is one segment, the whole fit", {
  rec <- drifting(3, 0, seed = 4)
  one <- calibrate(rec, sf = 5)
  fs <- calibrate(rec, sf = 5, segments = 12)
  expect_identical(nrow(fs$segments), 1L)
  expect_equal(unname(unlist(fs$segments[param_names()])),
               unname(coef(one)[param_names()]))
  expect_identical(apply_calibration(rec, fs), apply_calibration(rec, one))
  expect_identical(fs$error_heldout_after, one$error_heldout_after)
})

test_that("segments that cannot be fitted alone join a neighbour; bad arguments", {
  rec <- drifting(2, 0, seed = 5)
  # 1-hour segments hold too few postures for nine parameters
  fs <- calibrate(rec, sf = 5, segments = 1)
  expect_identical(fs$status, "ok")
  expect_lt(nrow(fs$segments), 48L)
  expect_true(all(fs$segments$points >= 18))
  expect_error(calibrate(rec, sf = 5, segments = "week"), "`segments` must be")
  expect_error(calibrate(rec, sf = 5, segments = 0), "`segments` must be")
  expect_error(calibrate(rec, sf = 5, segments = "day", selection = "paper"),
               "`segments` needs the default")
  expect_error(calibrate(rec, sf = 5, segments = "day", change_alpha = 2),
               "`change_alpha` must be")
})

test_that("wald_test() is d' (Va + Vb)^-1 d against chi-squared", {
  # two fits of x and y offset, 10 and 20 mg apart; standard errors 10 mg
  # in x and 20 mg in y each, b's two correlated (covariance 5e-5)
  fit <- function(o, V) {
    f <- gravcal:::new_fit(offset = o, method = "ggir")
    f$model <- c("o_x", "o_y")
    f$vcov <- matrix(V, 2, 2, dimnames = list(f$model, f$model))
    f
  }
  a <- fit(c(0.01, 0.02, 0), c(1e-4, 0, 0, 4e-4))
  b <- fit(c(0, 0, 0), c(1e-4, 5e-5, 5e-5, 4e-4))
  # by hand: d = (0.01, 0.02), V = [2e-4 5e-5; 5e-5 8e-4], det V = 1.575e-7,
  # V^-1 = [8e-4 -5e-5; -5e-5 2e-4] / det V, so
  # W = (8e-4 * 1e-4 - 2 * 5e-5 * 2e-4 + 2e-4 * 4e-4) / 1.575e-7 = 8 / 9,
  # and with 2 degrees of freedom P(chi2 > W) = exp(-W / 2)
  expect_equal(gravcal:::wald_test(a, b), exp(-4 / 9), tolerance = 1e-12)
  # uncorrelated, equal errors in x alone: W = 0.01^2 / 2e-4 = 0.5, one
  # degree of freedom
  expect_equal(gravcal:::wald_test(a, b, nm = "o_x"),
               pchisq(0.5, df = 1, lower.tail = FALSE), tolerance = 1e-12)
  expect_identical(gravcal:::wald_test(a, a), 1)
  # nothing to compare: NA; a covariance that cannot be inverted: 0
  b0 <- b
  b0$vcov <- NULL
  expect_identical(gravcal:::wald_test(a, b0), NA_real_)
  sing <- fit(c(0, 0, 0), c(-1e-4, 0, 0, -4e-4))
  expect_identical(gravcal:::wald_test(a, sing), 0)
  # pairwise over a device's fits: every pair, in order
  expect_equal(gravcal:::pairwise_wald(list(a, b, a)),
               c(gravcal:::wald_test(a, b), 1, gravcal:::wald_test(b, a)))
})
