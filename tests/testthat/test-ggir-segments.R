# The GGIR method beyond one fit (issue 31, item 4): coefficients per
# segment of time and the adaptive budget, in gravcal's own mode, with the
# temperature term.

# A device GGIR's model describes (no cross-axis terms) with a temperature
# offset, its x offset drifting linearly by `drift` g over the recording.
ggir_drifting <- function(days, drift, seed, sf = 5,
                          tempoffset = c(0.0008, -0.0006, 0.0004)) {
  set.seed(seed)
  p <- random_params(misalignment = 0)
  rec <- simulate_recording(hours = 24 * days, sf = sf, params = p,
                            tempoffset = tempoffset, seed = seed)
  t <- as.numeric(rec$time - rec$time[1])
  rec$x <- rec$x + drift * t / max(t)
  rec
}

test_that("GGIR's method follows a drifting offset day by day, with temperature", {
  rec <- ggir_drifting(4, 0.012, seed = 11)
  one <- calibrate(rec, sf = 5, method = "ggir")
  fs <- calibrate(rec, sf = 5, method = "ggir", segments = "day")
  expect_identical(fs$status, one$status)
  expect_true(fs$use_temp)
  expect_identical(fs$model, one$model)
  seg <- fs$segments
  expect_identical(nrow(seg), 4L)
  expect_identical(seg$from[1], -Inf)
  expect_identical(seg$to[4], Inf)
  expect_equal(seg$from[2:4], c(1, 2, 3) * 86400)
  expect_identical(fs$segment_settings$time, "seconds")
  # the x offset falls by the drift (3 mg a day); the others stay within
  # their errors; the scales are GGIR's (no cross-axis terms)
  d <- diff(seg$o_x)
  expect_true(all(d < -0.002 & d > -0.004))
  expect_lt(max(abs(diff(seg$o_y))), 5 * max(seg$o_y.se))
  expect_true(all(seg[c("k_xy", "k_xz", "k_yz")] == 0))
  # each segment's temperature offset, referred to the whole recording's
  # mean temperature, near the simulated one
  expect_true(all(abs(seg$t_x - 0.0008) < 5 * seg$t_x.se + 1e-4))
  expect_match(fs$message, "4 segments")
  expect_output(print(fs), "4 segments over time")
  # applied by time: each sample with its day's coefficients and the
  # temperature term at the whole fit's reference temperature
  cal <- apply_calibration(rec, fs)
  t <- as.numeric(rec$time - rec$time[1])
  i <- which(t >= 2 * 86400 & t < 3 * 86400)[1:5]
  dt <- rec$temperature[i] - fs$meantemp
  expect_equal(cal$x[i], seg$k_xx[3] * (rec$x[i] + seg$o_x[3]) + dt * seg$t_x[3])
  expect_equal(cal$z[i], seg$k_zz[3] * (rec$z[i] + seg$o_z[3]) + dt * seg$t_z[3])
  err <- function(d) {
    w <- rest_windows(d, sf = 5)
    err_mg(as.matrix(w[w$rest, c("mean_x", "mean_y", "mean_z")]))
  }
  expect_lt(err(cal), 0.5 * err(apply_calibration(rec, one)))
  # the same without a time column (times from the row numbers)
  nt <- rec[names(rec) != "time"]
  fn <- calibrate(nt, sf = 5, method = "ggir", segments = "day")
  expect_equal(fn$segments$o_x, seg$o_x)
  expect_equal(apply_calibration(nt, fn)$x, cal$x)
})

test_that("GGIR's method without drift is one segment, the whole fit", {
  rec <- ggir_drifting(3, 0, seed = 12)
  one <- calibrate(rec, sf = 5, method = "ggir")
  fs <- calibrate(rec, sf = 5, method = "ggir", segments = 12)
  expect_identical(nrow(fs$segments), 1L)
  expect_identical(unname(unlist(fs$segments[names(coef(one))])),
                   unname(coef(one)))
  expect_identical(apply_calibration(rec, fs), apply_calibration(rec, one))
  expect_false(grepl("segments", fs$message))
})

test_that("GGIR segments that cannot be fitted alone join a neighbour", {
  rec <- ggir_drifting(2, 0, seed = 13)
  # 1-hour segments: too few postures to cover the sphere
  fs <- calibrate(rec, sf = 5, method = "ggir", segments = 1)
  expect_identical(fs$status, "ok")
  expect_lt(nrow(fs$segments), 48L)
  expect_true(all(fs$segments$points >= 18))
})

test_that("segments read the whole recording, past minloadcrit", {
  rec <- ggir_drifting(3, 0.006, seed = 14)
  # GGIR's rule stops after minloadcrit hours once the error is small
  one <- calibrate(rec, sf = 5, method = "ggir", minloadcrit = 24)
  expect_lt(one$hours, 72)
  fs <- calibrate(rec, sf = 5, method = "ggir", minloadcrit = 24,
                  segments = "day")
  expect_equal(fs$hours, 72)
  expect_identical(nrow(fs$segments), 3L)
})

test_that("an adaptive budget stops GGIR's procedure once its errors are small", {
  rec <- ggir_drifting(4, 0, seed = 15)
  fa <- calibrate(rec, sf = 5, method = "ggir", budget = "adaptive")
  ff <- calibrate(rec, sf = 5, method = "ggir")
  expect_identical(fa$status, "ok")
  b <- fa$budget
  expect_true(b$stopped)
  expect_equal(b$hours_total, 96)
  expect_lt(b$hours_read, 48)
  expect_equal(fa$hours, b$hours_read)
  expect_true(all(fa$se[fa$model] <= 0.001))
  # the coefficients agree with the whole recording's within their errors,
  # at the same reference temperature
  nm <- ff$model
  expect_identical(fa$model, nm)
  ar <- gravcal:::ggir_rereference(fa, ff$meantemp)
  expect_true(all(abs(coef(ar)[nm] - coef(ff)[nm]) <= 3 * ar$se[nm]))
  expect_output(print(fa), "adaptive budget: read [0-9.]+ of 96.0 hours, stopped")
  # an unreachable target reads everything, and gives the whole fit
  fu <- calibrate(rec, sf = 5, method = "ggir", budget = "adaptive",
                  target_se = 1e-9)
  expect_false(fu$budget$stopped)
  expect_equal(fu$budget$hours_read, 96)
  expect_identical(coef(fu), coef(ff))
  expect_output(print(fu), "the target was not reached")
  expect_null(ff$budget)
})

test_that("segments and the budget are refused where GGIR has no such parameter", {
  rec <- ggir_drifting(1, 0, seed = 16)
  expect_error(calibrate(rec, sf = 5, method = "ggir", ggir_compat = TRUE,
                         segments = "day"),
               "`segments` cannot be used with `ggir_compat = TRUE`: GGIR's g.calibrate\\(\\) has no such parameter")
  expect_error(calibrate(rec, sf = 5, method = "ggir", ggir_compat = TRUE,
                         budget = "adaptive", target_se = 0.01),
               "`budget`, `target_se` cannot be used")
  expect_error(g.calibrate(rec, sf = 5, verbose = FALSE, segments = "day"),
               "g.calibrate\\(\\): `segments`: GGIR's g.calibrate\\(\\) has no such parameter")
  expect_error(g.calibrate(rec, sf = 5, verbose = FALSE, budget = "adaptive"),
               "`budget`: GGIR's")
  expect_error(calibrate(rec, sf = 5, method = "ggir", segments = "day",
                         budget = "adaptive"), "cannot be combined")
  expect_error(calibrate(rec, sf = 5, method = "ggir", segments = "week"),
               "`segments` must be")
  expect_error(calibrate(rec, sf = 5, method = "ggir", budget = "half"),
               "`budget` must be one of")
  expect_error(calibrate(rec, sf = 5, method = "ggir", budget = "adaptive",
                         check_hours = -1), "`check_hours` must be")
})
