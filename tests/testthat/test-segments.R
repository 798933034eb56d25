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
