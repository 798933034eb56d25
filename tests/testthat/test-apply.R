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

test_that("a GGIR fit is applied in GGIR's operation order, to the bit", {
  rec <- simulate_recording(hours = 0.5, sf = 10, seed = 52)
  s <- c(1.013, 0.987, 1.004)
  o <- c(-0.021, 0.013, 0.007)
  to <- c(0.0021, -0.0013, 0.0008)
  fit <- gravcal:::new_fit(K = diag(s), offset = o, tempoffset = to,
                           meantemp = 27.3, method = "ggir")
  cal <- apply_calibration(rec, fit)
  # GGIR's g.getmeta() calibrates with base R's scale(): (v + o) / (1 / s),
  # plus (T - meantemp) / (1 / tempoffset)
  v <- cbind(rec$x, rec$y, rec$z)
  ggir <- scale(v, center = -o, scale = 1 / s) +
    scale(cbind(rec$temperature, rec$temperature, rec$temperature),
          center = rep(27.3, 3), scale = 1 / to)
  expect_identical(cbind(cal$x, cal$y, cal$z), unname(unclass(ggir)[, 1:3]))
  # the model's own arithmetic differs in the last bit on some samples,
  # so the test above tells the two apart
  lw <- fit
  lw$method <- "lightweight"
  own <- apply_calibration(rec, lw)
  expect_true(any(own$x != cal$x | own$y != cal$y | own$z != cal$z))
  expect_equal(own$x, cal$x, tolerance = 1e-14)
})

test_that("the one model function keeps the shape it is given", {
  K <- matrix(c(1.02, 0.01, -0.02, 0, 0.98, 0.015, 0, 0, 1.01), 3)
  o <- c(0.01, -0.02, 0.03)
  v <- matrix(c(1, 0, 0, 0, -1, 0, 0.6, 0, 0.8), ncol = 3, byrow = TRUE)
  a <- gravcal:::apply_model(v, K, o)
  expect_true(is.matrix(a))
  expect_equal(a, (v + rep(o, each = 3)) %*% t(K), tolerance = 1e-15)
  l <- gravcal:::apply_model(list(v[, 1], v[, 2], v[, 3]), K, o)
  expect_identical(l, list(a[, 1], a[, 2], a[, 3]))
  dt <- c(-2, 0, 3)
  to <- c(0.001, 0, -0.002)
  expect_identical(gravcal:::apply_model(v, K, o, to, dt),
                   a + outer(dt, to))
  expect_error(gravcal:::apply_model(v, K, o, arithmetic = "fma"))
})
