# Window statistics recomputed in plain R, independently of the C++ core.
r_windows <- function(x, y, z, L) {
  k <- (seq_along(x) - 1) %/% L
  keep <- k < length(x) %/% L
  f <- function(v, fun) unname(tapply(v[keep], k[keep], fun))
  data.frame(mean_x = f(x, mean), mean_y = f(y, mean), mean_z = f(z, mean),
             sd_x = f(x, sd), sd_y = f(y, sd), sd_z = f(z, sd),
             range_x = f(x, function(v) diff(range(v))),
             range_y = f(y, function(v) diff(range(v))),
             range_z = f(z, function(v) diff(range(v))))
}

test_that("window statistics match an independent R computation", {
  rec <- simulate_recording(hours = 0.5, sf = 10, seed = 21)
  w <- rest_windows(rec, sf = 10)
  ref <- r_windows(rec$x, rec$y, rec$z, 50)
  expect_equal(nrow(w), nrow(ref))
  expect_equal(w[names(ref)], ref, tolerance = 1e-12)
  expect_equal(w$n, rep(50L, nrow(w)))
  expect_equal(w$start, rec$time[seq(1, by = 50, length.out = nrow(w))])
  expect_equal(w$temperature,
               as.vector(tapply(rec$temperature[1:(50 * nrow(w))],
                             rep(seq_len(nrow(w)), each = 50), mean)))
  # the rest rule (paper: max - min < 0.12 g on the watched axes)
  expect_identical(w$rest, with(ref, range_x < 0.12 & range_y < 0.12 &
                                  range_z < 0.12))
  w1 <- rest_windows(rec, sf = 10, axes = "x")
  expect_identical(w1$rest, ref$range_x < 0.12)
})

test_that("chunk_size, the old name of block_samples, still works, with a warning", {
  rec <- simulate_recording(hours = 0.2, sf = 30, seed = 23)
  new <- rest_windows(rec, sf = 30, block_samples = 1000)
  expect_warning(old <- rest_windows(rec, sf = 30, chunk_size = 1000), "`chunk_size` is deprecated")
  expect_identical(old, new)
  expect_error(rest_windows(rec, sf = 30, block_samples = 1000, chunk_size = 1000),
               "not both")
  # through calibrate()'s `...` too
  expect_warning(f <- calibrate(rec, sf = 30, chunk_size = 1000), "`chunk_size` is deprecated")
  expect_identical(f$params, calibrate(rec, sf = 30, block_samples = 1000)$params)
})

test_that("the segmenter gives identical windows however the signal is split", {
  rec <- simulate_recording(hours = 0.5, sf = 30, seed = 22)
  rec$x[c(100, 20000)] <- 0
  rec$y[c(100, 20000)] <- 0
  rec$z[c(100, 20000)] <- 0
  whole <- rest_windows(rec, sf = 30, block_samples = nrow(rec))
  set.seed(7)
  for (cs in c(1, 7, 149, 150, 151, sample(2:5000, 5))) {
    expect_identical(rest_windows(rec, sf = 30, block_samples = cs), whole)
  }
  # also through the core directly with random, uneven chunk boundaries
  s <- gravcal:::as_samples(rec)
  cuts <- sort(unique(c(0, sample(nrow(rec), 40), nrow(rec))))
  src <- blocks_source(cut_blocks(s$x, s$y, s$z, s$temperature, cuts))
  parts <- pump_windows(src, 150, rule = 0L, par = c(0.12, 7), skip_zero = TRUE)
  got <- gravcal:::windows_frame(parts$windows, s, 30)
  expect_identical(got, whole[names(got)], ignore_attr = TRUE)
})

test_that("ggir windows use 10 s and the sd rule (13 mg, |mean| < 2 g)", {
  rec <- simulate_recording(hours = 0.5, sf = 10, seed = 23)
  w <- rest_windows(rec, sf = 10, method = "ggir")
  ref <- r_windows(rec$x, rec$y, rec$z, 100)
  expect_equal(nrow(w), nrow(ref))
  expect_identical(w$rest, with(ref, sd_x < 0.013 & sd_y < 0.013 &
                                  sd_z < 0.013 & abs(mean_x) < 2 &
                                  abs(mean_y) < 2 & abs(mean_z) < 2))
  expect_equal(attr(w, "window"), 10)
})

test_that("a rate that is not a whole number of samples per window keeps time", {
  n <- 10000
  x <- data.frame(x = rep(0, n), y = rep(0, n), z = rep(1, n))
  w <- rest_windows(x, sf = 85.7)
  # window k holds samples [round(k L), round((k + 1) L)), L = 428.5,
  # halves rounded away from zero
  L <- 5 * 85.7
  b <- floor(seq(0, by = L, length.out = nrow(w) + 1) + 0.5)
  expect_equal(w$n, as.integer(diff(b)))
  expect_equal(nrow(w), floor(n / L))
})

test_that("idle-sleep zeros are skipped, non-finite samples spoil a window", {
  base <- data.frame(x = rep(0.01, 100), y = rep(0.02, 100), z = rep(1, 100))
  z <- base
  z[11:30, c("x", "y", "z")] <- 0
  w <- rest_windows(z, sf = 10)
  expect_equal(nrow(w), 1)
  expect_equal(attr(w, "skipped_zero"), 20)
  expect_equal(w$mean_z, 1)
  expect_equal(nrow(rest_windows(z, sf = 10, skip_zero = FALSE)), 2)
  bad <- base
  bad$x[3] <- NA
  bad$y[60] <- Inf
  expect_warning(w2 <- rest_windows(bad, sf = 10), "2 non-finite samples")
  expect_equal(w2$rest, c(FALSE, FALSE))
  expect_equal(w2$n_invalid, c(1L, 1L))
  expect_equal(w2$mean_x[1], 0.01)
})

test_that("bad input gets errors that name the argument", {
  x <- data.frame(x = 1:10 / 10, y = 0, z = 1)
  expect_error(rest_windows(x, sf = -1), "`sf` must be a number > 0, not -1")
  expect_error(rest_windows(x, sf = NA), "`sf` must be a number")
  expect_error(rest_windows(x, sf = c(10, 20)), "`sf` must be a number")
  expect_error(rest_windows(x, sf = "10"), "`sf` must be a number")
  expect_error(rest_windows(data.frame(x = 1, y = 2), sf = 10),
               "must have a column `z`")
  expect_error(rest_windows(data.frame(x = "a", y = 1, z = 1), sf = 10),
               "Column `x` of `x` must be numeric, not character")
  expect_error(rest_windows(data.frame(x = factor(1), y = 1, z = 1), sf = 10),
               "must be numeric, not factor")
  expect_error(rest_windows(list(1, 2), sf = 10), "data frame or matrix")
  expect_error(rest_windows(matrix(0, 3, 4), sf = 10), "exactly 3 unnamed")
  expect_error(rest_windows(x, sf = 0.2), "at least 2 samples per window")
  expect_error(rest_windows(x, sf = 10, axes = "w"), "`axes` must name")
  expect_error(rest_windows(x, sf = 10, method = "other"), "`method` must be one of")
  # integer columns are accepted; a short recording gives no windows
  xi <- data.frame(x = 0L, y = 0L, z = rep(1L, 20))
  w <- rest_windows(xi, sf = 10)
  expect_equal(nrow(w), 0)
  expect_named(w, c("start", "n", "mean_x", "mean_y", "mean_z", "sd_x",
                    "sd_y", "sd_z", "range_x", "range_y", "range_z",
                    "mean_norm", "temperature", "n_invalid", "n_repeat",
                    "rest"))
})

test_that("rest_windows() does not change the caller's data", {
  rec <- simulate_recording(hours = 0.1, sf = 10, seed = 24)
  copy <- rec
  rest_windows(rec, sf = 10)
  expect_identical(rec, copy)
  m <- as.matrix(rec[c("x", "y", "z")])
  m2 <- m
  rest_windows(m, sf = 10)
  expect_identical(m, m2)
})

test_that("a file is windowed block by block as the same data in memory", {
  rec <- simulate_recording(hours = 26, sf = 10, seed = 8, temperature = FALSE)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  gravcal:::write_actigraph_csv(rec, f, sf = 10)
  wf <- rest_windows(f, progress = FALSE)
  wm <- rest_windows(rec[, c("x", "y", "z")], sf = 10)
  expect_identical(attr(wf, "samples"), as.numeric(nrow(rec)))
  cols <- c("mean_x", "mean_y", "mean_z", "sd_x", "sd_y", "sd_z", "rest")
  expect_identical(wf[cols], wm[cols])
  expect_identical(wf$start, wm$start)
  fit_f <- calibrate(f, progress = FALSE)
  fit_m <- calibrate(rec[, c("x", "y", "z")], sf = 10)
  expect_identical(coef(fit_f), coef(fit_m))
})

test_that("R-compatible windows do not depend on the chunking", {
  set.seed(12)
  n <- 25000
  x <- stats::rnorm(n, 0.1, 0.01)
  y <- stats::rnorm(n, 0, 0.01)
  z <- stats::rnorm(n, 1, 0.01)
  t <- 25 + stats::rnorm(n, 0, 0.1)
  x[3333] <- NaN  # this window takes the sample-by-sample path
  one <- function(r, cuts) {
    src <- blocks_source(cut_blocks(x, y, z, t, cuts))
    as.data.frame(pump_windows(src, 1000, r)$windows)
  }
  for (r in c(TRUE, FALSE)) {
    a <- one(r, c(0, n))
    b <- one(r, c(0, 17, 999, 1000, 4321, 4322, 12000, n))
    expect_identical(a, b)
  }
  # and they are R's own numbers (GGIR computes them with cumsum and sd)
  a <- one(TRUE, c(0, n))
  k <- 3
  idx <- (k - 1) * 1000 + 1:1000
  expect_identical(a$sd_y[k], stats::sd(y[idx]))
  expect_identical(a$mean_y[k], diff(cumsum(c(0, y))[c(1, 1001) + (k - 1) * 1000]) / 1000)
})

test_that("a window of 1e7 samples or more is an error naming window and sf", {
  rec <- simulate_recording(hours = 0.5, sf = 10, seed = 1)
  expect_snapshot(error = TRUE, rest_windows(rec, sf = 10, window = 1e7))
  expect_snapshot(error = TRUE, rest_windows(rec, sf = 1e7))
  expect_snapshot(error = TRUE, rest_windows(rec, sf = 0.2))
  expect_snapshot(error = TRUE, calibrate(rec, sf = 0.05, method = "ggir"))
  expect_snapshot(error = TRUE, g.calibrate(rec, sf = 2e6, verbose = FALSE))
})
