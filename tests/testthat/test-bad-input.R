# The bad-input matrix: every public function that takes data, given each
# kind of bad input. Each case asserts the exact outcome: an error that
# names the argument and what was expected, or a fit whose status says why
# it could not calibrate and whose coefficients are the identity. Every call
# also leaves the caller's object unchanged.

rec <- simulate_recording(hours = 3, sf = 10, seed = 1)
base <- rec[c("x", "y", "z", "temperature")]

# Run f(x) and check that x is unchanged afterwards.
unchanged <- function(x, f) {
  copy <- x
  out <- f(x)
  expect_identical(x, copy)
  invisible(out)
}

expect_identity_fit <- function(fit, status) {
  expect_s3_class(fit, "gravcal_fit")
  expect_identical(fit$status, status)
  expect_equal(unname(fit$K), diag(3))
  expect_equal(unname(fit$offset), c(0, 0, 0))
  expect_equal(unname(fit$tempoffset), c(0, 0, 0))
}

bad_columns <- list(
  missing = list(data = base[c("x", "y")], error = "`x` must have a column `z`"),
  misnamed = list(data = stats::setNames(base, c("a", "b", "c", "temperature")),
                  error = "`x` must have a column `x`"),
  character = list(data = transform(base, x = as.character(x)),
                   error = "Column `x` of `x` must be numeric, not character"),
  factor = list(data = transform(base, y = factor(round(y, 1))),
                error = "Column `y` of `x` must be numeric, not factor"),
  logical = list(data = transform(base, z = z > 0),
                 error = "Column `z` of `x` must be numeric, not logical"))

test_that("columns missing, misnamed or not numeric: errors naming them", {
  for (nm in names(bad_columns)) {
    k <- bad_columns[[nm]]
    for (m in c("lightweight", "ggir")) {
      unchanged(k$data, function(d) {
        expect_error(calibrate(d, sf = 10, method = m), k$error, fixed = TRUE, label = nm)
      })
    }
    unchanged(k$data, function(d) expect_error(rest_windows(d, sf = 10), k$error, fixed = TRUE))
    # g.calibrate() names its argument `datafile`, as GGIR does
    unchanged(k$data, function(d) {
      expect_error(g.calibrate(d, sf = 10, verbose = FALSE),
                   "of `datafile` must be numeric|`datafile` must have a column")
    })
  }
  fit <- calibrate(base, sf = 10)
  expect_error(apply_calibration(bad_columns$character$data, fit),
               "Column `x` of `x` must be numeric", fixed = TRUE)
  # window tables for the fits
  w <- data.frame(mean_x = "a", mean_y = 1, mean_z = 1)
  expect_error(select_points(w), "Column `mean_x` of `w` must be numeric")
  expect_error(fit_gradient(w), "must be numeric")
  expect_error(fit_icp(w), "must be numeric")
  expect_error(fit_ellipsoid(w), "must be numeric")
})

test_that("integer columns are accepted as numbers", {
  di <- data.frame(x = as.integer(round(base$x)), y = as.integer(round(base$y)),
                   z = as.integer(round(base$z)))
  dd <- data.frame(x = as.double(di$x), y = as.double(di$y), z = as.double(di$z))
  expect_identical(unchanged(di, function(d) rest_windows(d, sf = 10)),
                   rest_windows(dd, sf = 10))
  expect_identical(coef(calibrate(di, sf = 10, method = "ggir")),
                   coef(calibrate(dd, sf = 10, method = "ggir")))
})

test_that("NA, NaN and Inf samples: their windows are not rest, with a warning", {
  for (v in list(NA_real_, NaN, Inf, -Inf)) {
    d <- base
    d$x[100:200] <- v
    unchanged(d, function(d) {
      expect_warning(rest_windows(d, sf = 10), "101 non-finite samples .* in 3 windows")
    })
    w <- suppressWarnings(rest_windows(d, sf = 10))
    expect_false(any(w$rest[w$n_invalid > 0]))
    expect_identical(sum(w$n_invalid), 101L)
    f <- suppressWarnings(calibrate(d, sf = 10))
    expect_identical(f$status, "ok")
    expect_true(all(is.finite(coef(f))))
    fg <- suppressWarnings(calibrate(d, sf = 10, method = "ggir"))
    expect_true(all(is.finite(coef(fg))))
  }
})

test_that("empty data and recordings shorter than a window: too_short", {
  for (d in list(base[0, ], base[1:20, ])) {
    unchanged(d, function(d) {
      expect_identity_fit(calibrate(d, sf = 10), "too_short")
      expect_identity_fit(calibrate(d, sf = 10, method = "ggir"), "too_short")
      expect_identical(nrow(rest_windows(d, sf = 10)), 0L)
    })
  }
  expect_identity_fit(fit_icp(data.frame(mean_x = numeric(0), mean_y = numeric(0),
                                         mean_z = numeric(0))), "no_rest")
  expect_error(fit_gradient(data.frame(mean_x = 1, mean_y = 0, mean_z = 0)),
               "at least 9 points")
  G <- g.calibrate(base[0, ], sf = 10, verbose = FALSE)
  expect_match(G$QCmessage, "recalibration not done")
  expect_identical(G$scale, c(1, 1, 1))
})

test_that("sf: zero, negative, NA, a vector, text are errors; 85.7 Hz works", {
  for (sf in list(0, -1, NA, NA_real_, c(10, 20), "10", Inf)) {
    expect_error(calibrate(base, sf = sf), "`sf` must be a number > 0")
    expect_error(rest_windows(base, sf = sf), "`sf` must be a number > 0")
  }
  expect_error(calibrate(base), "`sf`")
  # 85.7 Hz: 428.5 samples per 5 s window; windows alternate 428 and 429
  r <- simulate_recording(hours = 2, sf = 85.7, seed = 2)
  w <- rest_windows(r, sf = 85.7)
  expect_setequal(unique(w$n), c(428L, 429L))
  expect_equal(sum(w$n) / nrow(w), 428.5, tolerance = 1e-3)
})

test_that("a recording of zeros is all_zero, not too short, and says so", {
  # idle-sleep zeros: 100 hours at 10 Hz, every sample 0 on all three axes
  # (issue 44: reported as "3600000 samples, fewer than one 5 s window")
  zeros <- data.frame(x = numeric(3.6e6), y = 0, z = 0)
  unchanged(zeros, function(d) {
    f <- calibrate(d, sf = 10)
    expect_identity_fit(f, "all_zero")
    expect_identical(f$message, paste0(
      "no data: all 3600000 samples are exactly 0 on all three axes (ActiGraph ",
      "idle sleep, or a device that recorded nothing); there is nothing to ",
      "calibrate"))
    g <- calibrate(d, sf = 10, method = "ggir")
    expect_identity_fit(g, "all_zero")
    expect_match(g$message, paste0(
      "^no data: all 3600000 samples are exactly 0 on all three axes .*",
      "\\[GGIR: recalibration not done because not enough data"))
    # GGIR-compatible mode: GGIR's outcome and words, unchanged
    gc <- calibrate(d, sf = 10, method = "ggir", ggir_compat = TRUE)
    expect_identity_fit(gc, "too_short")
    expect_identical(gc$QCmessage, gravcal:::ggir_messages[["no_data"]])
    expect_match(gc$message, "^fewer distinct 10 s windows than the procedure needs \\[GGIR")
  })
  # a few samples that are not zero, fewer than a window: too short, and
  # the message counts the zeros
  few <- zeros
  few$z[1:30] <- 1
  f <- calibrate(few, sf = 10)
  expect_identity_fit(f, "too_short")
  expect_match(f$message, paste0(
    "of 3600000 samples, 3599970 are exactly 0 on all three axes (skipped as ",
    "idle sleep) and the other 30 are fewer than one 5 s window at 10 Hz"),
    fixed = TRUE)
  g <- calibrate(few, sf = 10, method = "ggir")
  expect_identity_fit(g, "too_short")
  expect_match(g$message, "of 3600000 samples, 3599970 are exactly 0 on all three axes",
               fixed = TRUE)
  # zeros kept as samples (skip_zero = FALSE) are windows of identical
  # samples: no rest, as before
  expect_identity_fit(calibrate(zeros[1:36000, ], sf = 10, skip_zero = FALSE), "no_rest")
  # shorter than a window is still too short, zeros or not
  expect_identity_fit(calibrate(zeros[1:20, ], sf = 10), "all_zero")
  expect_identity_fit(calibrate(base[1:20, ], sf = 10), "too_short")
  expect_snapshot({
    calibrate(zeros[1:36000, ], sf = 10)$message
    calibrate(zeros[1:36000, ], sf = 10, method = "ggir")$message
    calibrate(few[1:36000, ], sf = 10)$message
  })
})

test_that("unsorted or repeated time stamps do not change the windows", {
  # the samples' order is the stream's order; time stamps only label windows
  d <- rec
  d$time <- rev(d$time)
  expect_identical(rest_windows(d, sf = 10)[c("mean_x", "rest")],
                   rest_windows(rec, sf = 10)[c("mean_x", "rest")])
  d$time <- d$time[1]
  expect_identical(rest_windows(d, sf = 10)$mean_z, rest_windows(rec, sf = 10)$mean_z)
  # without sf: an error that says so
  expect_error(rest_windows(d), "`sf` (sampling frequency in Hz) is missing", fixed = TRUE)
})

test_that("a device on a table for a week: not calibrated, and says why", {
  set.seed(3)
  n <- 7 * 24 * 3600  # a week at 1 Hz
  flat <- data.frame(x = 0.01 + stats::rnorm(n, sd = 0.003), y = -0.02,
                     z = 1.03, temperature = 25)
  unchanged(flat, function(d) {
    expect_identity_fit(calibrate(d, sf = 1), "sphere_not_covered")
    expect_identity_fit(calibrate(d, sf = 1, selection = "paper"),
                        "bins_incomplete")
    f <- suppressWarnings(calibrate(d, sf = 1, method = "ggir"))
    expect_identity_fit(f, "sphere_not_covered")
  })
  # exactly constant: every window is a duplicate of the next, which GGIR's
  # procedure drops, leaving too few
  const <- data.frame(x = rep(0.01, n), y = -0.02, z = 1.03)
  f <- calibrate(const, sf = 1, method = "ggir")
  expect_identity_fit(f, "too_short")
  expect_match(f$message, "distinct")
  # rests in one orientation only, with movement between them
  one <- rec
  one$x <- abs(one$x) * 0.1
  one$y <- abs(one$y) * 0.1
  one$z <- sqrt(pmax(1 - one$x^2 - one$y^2, 0)) + 0.02
  expect_identity_fit(calibrate(one, sf = 10), "sphere_not_covered")
  expect_identity_fit(calibrate(one, sf = 10, selection = "paper"),
                      "bins_incomplete")
  expect_identity_fit(calibrate(one, sf = 10, method = "ggir"), "sphere_not_covered")
})

test_that("idle-sleep zeros are skipped; clipping at +-8 g is never rest", {
  z0 <- base
  z0[1:5000, c("x", "y", "z")] <- 0
  w <- rest_windows(z0, sf = 10)
  # the first window starts after the 5000 zeros (500 s)
  expect_equal(w$start[1], 500)
  expect_identical(sum(w$n), nrow(z0) - 5000L)
  expect_identical(calibrate(z0, sf = 10)$status, "ok")
  clip <- base
  clip$x <- pmin(pmax(clip$x * 10, -8), 8)
  f <- calibrate(clip, sf = 10, method = "ggir")
  expect_identity_fit(f, "no_rest")
  # a sensor stuck at its limit is flat but not 1 g: rest windows far from
  # the sphere never pass the guards as a calibration
  stuck <- data.frame(x = rep(8, 36000), y = 0, z = 0)
  expect_false(calibrate(stuck, sf = 10)$status == "ok")
})

test_that("temperature missing, constant, NA or absurd", {
  # the lightweight method fits a temperature term only where the
  # temperature varies: a constant one, absurd or not, is as none
  none <- base
  none$temperature <- NULL
  f0 <- calibrate(none, sf = 10)
  expect_false("t_x" %in% f0$model)
  for (t in list(25, -300, 1e6)) {
    d <- base
    d$temperature <- t
    expect_identical(coef(calibrate(d, sf = 10)), coef(f0))
  }
  # a temperature that varies without moving the readings: considered,
  # and left out by the information criterion
  fb <- calibrate(base, sf = 10)
  expect_true(any(fb$models$temperature & fb$models$determined))
  expect_false("t_x" %in% fb$model)
  # GGIR method: constant or absurd temperature is not used, with a warning
  d <- base
  d$temperature <- 25
  expect_warning(f <- calibrate(d, sf = 10, method = "ggir"), "does not vary")
  expect_equal(unname(f$tempoffset), c(0, 0, 0))
  d$temperature <- 1e6 + base$temperature
  expect_warning(f <- calibrate(d, sf = 10, method = "ggir"), "exceed 120")
  expect_equal(unname(f$tempoffset), c(0, 0, 0))
  # missing values in the temperature: those windows carry NA temperature
  d <- base
  d$temperature[1:100] <- NA
  expect_true(all(is.finite(coef(calibrate(d, sf = 10, method = "ggir")))))
})

test_that("tibble and data.table input give the same fit, and stay unchanged", {
  ref <- calibrate(base, sf = 10)
  skip_if_not_installed("tibble")
  tb <- tibble::as_tibble(base)
  expect_identical(coef(unchanged(tb, function(d) calibrate(d, sf = 10))), coef(ref))
  cal <- apply_calibration(tb, ref)
  expect_s3_class(cal, "tbl_df")
  skip_if_not_installed("data.table")
  dt <- data.table::as.data.table(base)
  expect_identical(coef(unchanged(dt, function(d) calibrate(d, sf = 10))), coef(ref))
  cal <- unchanged(dt, function(d) apply_calibration(d, ref))
  expect_s3_class(cal, "data.table")
  expect_identical(cal$x, apply_calibration(base, ref)$x)
})

test_that("apply_calibration() refuses fits that are not fits", {
  fit <- calibrate(base, sf = 10)
  fg <- calibrate(base, sf = 10, method = "ggir")
  bad <- fit
  bad$K <- "a"
  expect_error(apply_calibration(base, bad), "`fit` is not a valid gravcal_fit")
  bad <- fit
  bad$K[1, 1] <- NA
  expect_error(apply_calibration(base, bad), "`fit` is not a valid gravcal_fit")
  bad <- fit
  bad$offset <- 1:2
  expect_error(apply_calibration(base, bad), "`fit` is not a valid gravcal_fit")
  expect_error(apply_calibration(base, list(K = diag(3))), "`fit` must be a gravcal_fit")
  expect_error(apply_calibration(base, NULL), "`fit` must be a gravcal_fit")
  # a fit of the other method works on the same samples
  expect_identical(nrow(unchanged(base, function(d) apply_calibration(d, fg))), nrow(base))
  # a fit with a temperature term needs the temperature
  if (any(fg$tempoffset != 0)) {
    expect_error(apply_calibration(base[c("x", "y", "z")], fg),
                 "`x` must have a `temperature` column")
  }
})

test_that("write_coefs() refuses what GGIR cannot use", {
  fit <- calibrate(base, sf = 10)
  f <- tempfile(fileext = ".csv")
  expect_error(write_coefs(fit, f), "`fits` must be named")
  expect_error(write_coefs(list(rec.csv = fit), f), "cross-axis|GGIR")
  expect_error(write_coefs(list(rec.csv = "x"), f), "gravcal_fit|g.calibrate")
  expect_false(file.exists(f))
})

test_that("GGIR method: implausible coefficients are not applied (gravcal's mode)", {
  # a sensor whose x axis reads 1 / 1.4 of the truth: the fit needs a scale
  # of 1.4, beyond the plausible 0.7-1.3 (real devices: van Hees et al.
  # 2014, Table 2, mean gains 0.990-1.005 with SD up to 0.014)
  r <- simulate_recording(hours = 30, sf = 10, seed = 61,
                          params = c(1.4, 1, 1, 0, 0, 0, 0, 0, 0))
  f <- calibrate(r, sf = 10, method = "ggir")
  expect_identity_fit(f, "implausible")
  expect_match(f$message, "plausible ranges")
  expect_identical(apply_calibration(r, f)$x, r$x)
  # compatible mode applies what GGIR applies
  fc <- calibrate(r, sf = 10, method = "ggir", ggir_compat = TRUE)
  expect_true(fc$status %in% c("ok", "high_error"))
  expect_gt(fc$K[1, 1], 1.3)
  # the plausible ranges themselves
  expect_true(gravcal:::ggir_plausible(c(1.1, 0.9, 1), c(0.4, -0.1, 0), c(0.01, 0, 0)))
  expect_false(gravcal:::ggir_plausible(c(1, 1, 1), c(0.7, 0, 0), NULL))
  expect_false(gravcal:::ggir_plausible(c(1, 1, 1), c(0, 0, 0), c(0, 0.06, 0)))
  expect_false(gravcal:::ggir_plausible(c(1, NA, 1), c(0, 0, 0), NULL))
})

test_that("exported functions: numbers out of range or given as text are named", {
  w <- rest_windows(base, sf = 10, method = "ggir")
  expect_snapshot(error = TRUE, calibrate(base, sf = 10, method = "ggir", max_iter = 1e10))
  expect_snapshot(error = TRUE, calibrate(base, sf = 10, method = "ggir", max_iter = 2.5))
  expect_snapshot(error = TRUE, rest_windows(base, sf = 10, progress = "a"))
  expect_snapshot(error = TRUE, rest_windows(base, sf = 10, block_samples = "a"))
  expect_snapshot(error = TRUE, g.calibrate(base, sf = 10, verbose = FALSE,
                                            params_rawdata = list(chunksize = "a")))
  expect_snapshot(error = TRUE, select_points(w, min_distance = "a"))
  expect_snapshot(error = TRUE, fit_icp(w, max_weight = 0))
  expect_snapshot(error = TRUE, fit_gradient(simulate_points(100), rates = "a"))
  # the methods of the fit class refuse what is not a fit
  bad <- structure(list(), class = "gravcal_fit")
  expect_snapshot(error = TRUE, coef(bad))
  expect_snapshot(error = TRUE, print(bad))
  expect_snapshot(error = TRUE, summary(bad))
  fit <- calibrate(base, sf = 10)
  expect_snapshot(error = TRUE, print(fit, digits = "a"))
})
