test_that("apply_calibration() applies a = K (v + o) and keeps the rest", {
  rec <- simulate_recording(hours = 0.2, sf = 10, seed = 51, noise = 0,
                            resolution = 0)
  tr <- attr(rec, "truth")
  fit <- gravcal:::new_fit(K = tr$K, offset = tr$offset,
                           method = "lightweight")
  copy <- rec
  cal <- apply_calibration(rec, fit)
  expect_identical(rec, copy)
  expect_identical(names(cal), names(rec))
  expect_identical(cal$time, rec$time)
  expect_identical(cal$temperature, rec$temperature)
  u <- cbind(rec$x, rec$y, rec$z) + rep(tr$offset, each = nrow(rec))
  expect_equal(cbind(cal$x, cal$y, cal$z), u %*% t(tr$K),
               ignore_attr = TRUE)
  # rest samples come back on the unit sphere
  w <- rest_windows(cal, sf = 10)
  expect_lt(max(abs(w$mean_norm[w$rest] - 1)), 1e-9)
})

test_that("matrices, tibbles and upper-case columns keep their shape", {
  fit <- gravcal:::new_fit(K = diag(c(1.1, 0.9, 1)), offset = c(0.1, 0, 0),
                           method = "lightweight")
  m <- matrix(c(1, 0, 0, 0, 1, 0), ncol = 3, byrow = TRUE)
  cm <- apply_calibration(m, fit)
  expect_true(is.matrix(cm))
  expect_equal(cm[1, ], c(1.21, 0, 0))
  d <- data.frame(X = 1, Y = 0, Z = 0, id = "a")
  cd <- apply_calibration(d, fit)
  expect_named(cd, c("X", "Y", "Z", "id"))
  expect_equal(cd$X, 1.21)
  skip_if_not_installed("tibble")
  tb <- tibble::tibble(x = 1, y = 0, z = 0)
  ct <- apply_calibration(tb, fit)
  expect_s3_class(ct, "tbl_df")
  expect_equal(ct$x, 1.21)
})

test_that("temperature offsets need a temperature column", {
  fit <- gravcal:::new_fit(tempoffset = c(0.001, 0, 0), meantemp = 25,
                           method = "ggir")
  d <- data.frame(x = 1, y = 0, z = 0, temperature = 35)
  expect_equal(apply_calibration(d, fit)$x, 1.01)
  expect_error(apply_calibration(d[1:3], fit), "`temperature` column")
})

test_that("invalid fits are refused", {
  d <- data.frame(x = 1, y = 0, z = 0)
  expect_error(apply_calibration(d, list(K = diag(3))), "must be a gravcal_fit")
  fit <- gravcal:::new_fit(method = "lightweight")
  fit$K[1, 1] <- NA
  expect_error(apply_calibration(d, fit), "not a valid gravcal_fit")
  fit <- gravcal:::new_fit(method = "lightweight")
  fit$offset <- 1:2
  expect_error(apply_calibration(d, fit), "not a valid gravcal_fit")
})
