# Rest that is really rest (issue 31, item 2): windows made of identical
# samples (idle sleep, a stuck sensor, zeros) are left out in gravcal's own
# modes, counted under "identical"; GGIR-compatible mode keeps GGIR's rules.

# The largest |coefficient - clean coefficient| in units of the clean fit's
# standard error, over the clean fit's model.
dev_se <- function(f, clean) {
  nm <- clean$model
  max(abs(coef(f)[nm] - coef(clean)[nm]) / clean$se[nm])
}

test_that("the window table counts samples equal to the one before", {
  x <- c(0.1, 0.1, 0.1, 0.2, 0.2, 0.3, 0.3, 0.3, 0.3, 0.3)
  rec <- data.frame(x = x, y = 0, z = 1)
  rec$y[3] <- 0.5  # breaks one repeat (y differs from the sample before)
  w <- rest_windows(rec, sf = 1, window = 5, max_range = 10)
  # window 1: samples 2 (= 1) repeat; 3 differs in y; 5 (= 4) repeats
  # window 2: samples 7, 8, 9, 10 repeat the one before (sample 6 is first)
  expect_equal(w$n_repeat, c(2L, 4L))
  # the same from the sample-by-sample path (a non-finite value sends the
  # window there) and in R's arithmetic (the GGIR rule)
  rec2 <- rec
  rec2$x[1] <- NA
  expect_warning(w2 <- rest_windows(rec2, sf = 1, window = 5, max_range = 10),
                 "non-finite")
  expect_equal(w2$n_repeat, c(1L, 4L))
  w3 <- rest_windows(rec, sf = 1, window = 5, method = "ggir")
  expect_equal(w3$n_repeat, c(2L, 4L))
  # chunking does not change the counts
  w4 <- rest_windows(rec, sf = 1, window = 5, max_range = 10, block_samples = 3)
  expect_equal(w4$n_repeat, w$n_repeat)
})

test_that("simulate_recording() makes idle-sleep and stuck stretches", {
  a <- simulate_recording(hours = 3, sf = 5, seed = 4)
  b <- simulate_recording(hours = 3, sf = 5, seed = 4, idle_sleep = 0.5,
                          stuck = 0.25)
  st <- attr(b, "truth")$contaminated
  expect_equal(st$kind, c("idle_sleep", "stuck"))
  expect_equal(st$to - st$from + 1, c(0.5, 0.25) * 3600 * 5)
  inside <- unlist(Map(seq, st$from, st$to))
  # outside the stretches the samples are the clean recording's
  expect_identical(a$x[-inside], b$x[-inside])
  expect_null(attr(a, "truth")$contaminated)
  # idle sleep repeats the sample before the stretch
  i <- st$from[1]
  expect_true(all(b$x[i:st$to[1]] == a$x[i - 1]))
  # a stuck sensor's constant is not that sample
  j <- st$from[2]
  off <- abs(c(b$x[j], b$y[j], b$z[j]) - c(a$x[j - 1], a$y[j - 1], a$z[j - 1]))
  expect_true(all(off >= 0.05 & off <= 0.2))
  expect_length(unique(b$z[j:st$to[2]]), 1)
  expect_error(simulate_recording(hours = 1, idle_sleep = 2), "`idle_sleep`")
  expect_error(simulate_recording(hours = 1, stuck = -1), "`stuck`")
})

# A clean simulated day (a sensor without cross-axis terms, so that GGIR's
# model fits it), its contaminated twins (the same samples but for 4 of the
# 24 hours: 8 stretches of 30 min), and the clean day with those stretches
# missing (NA): what a guard that leaves out exactly the contaminated
# windows fits.
sim_params <- c(1.02, 0.97, 1.01, 0, 0, 0, 0.03, -0.02, 0.05)
clean_day <- function() {
  simulate_recording(hours = 24, sf = 10, seed = 11, params = sim_params)
}
contaminated <- function(kind) {
  a <- list(hours = 24, sf = 10, seed = 11, params = sim_params)
  a[[kind]] <- 4
  do.call(simulate_recording, a)
}
missing_twin <- function(clean, rec) {
  st <- attr(rec, "truth")$contaminated
  for (i in seq_len(nrow(st))) clean[st$from[i]:st$to[i], c("x", "y", "z")] <- NA
  clean
}

test_that("idle-sleep and stuck windows are counted and left out (lightweight)", {
  clean <- clean_day()
  fc <- calibrate(clean, sf = 10)
  expect_equal(fc$status, "ok")
  expect_equal(fc$excluded[["identical"]], 0L)
  for (kind in c("idle_sleep", "stuck")) {
    rec <- contaminated(kind)
    f <- calibrate(rec, sf = 10)
    expect_equal(f$status, "ok")
    # 4 h of 5 s windows: 2880, less the windows a stretch shares with
    # clean samples (its first), all at rest (no variation at all)
    expect_gte(f$excluded[["identical"]], 2880 - 8)
    expect_lte(f$excluded[["identical"]], 2880)
    expect_true(all(f$excluded_windows$why[
      f$excluded_windows$why != "norm"] == "identical"))
    # the coefficients within their standard errors of the clean ones, and
    # those of the clean day without the stretches' samples
    expect_lte(dev_se(f, fc), 1)
    fn <- suppressWarnings(calibrate(missing_twin(clean, rec), sf = 10))
    expect_lte(dev_se(f, fn), 0.01)
    # without the guard, the stretches move the fit (bench/results/rest-quality.md;
    # with the rule on rest off the sphere off too, which catches some of
    # them: test-near-rest.R)
    off <- calibrate(rec, sf = 10, max_identical = 1, off_sphere = Inf)
    expect_equal(off$excluded[["identical"]], 0L)
    expect_gt(dev_se(off, fc), 2)
    expect_match(paste(capture.output(print(f)), collapse = "\n"),
                 paste0(f$excluded[["identical"]], " with more than 80 % of ",
                        "samples identical"), fixed = TRUE)
  }
  expect_error(calibrate(clean, sf = 10, max_identical = 2),
               "`max_identical` must be a number in [0, 1], not 2.",
               fixed = TRUE)
})

test_that("the GGIR method's own mode counts and leaves out identical windows", {
  clean <- clean_day()
  fc <- calibrate(clean, sf = 10, method = "ggir")
  expect_equal(fc$status, "ok")
  expect_equal(fc$excluded, c(norm = 0L, clipped = 0L, identical = 0L))
  for (kind in c("idle_sleep", "stuck")) {
    rec <- contaminated(kind)
    f <- calibrate(rec, sf = 10, method = "ggir")
    expect_equal(f$status, "ok")
    # 4 h of 10 s windows (1440), before the duplicate filter
    expect_gte(f$excluded[["identical"]], 1440 - 8)
    expect_lte(f$excluded[["identical"]], 1440)
    expect_lte(dev_se(f, fc), 1)
    fn <- suppressWarnings(calibrate(missing_twin(clean, rec), sf = 10,
                                     method = "ggir"))
    expect_lte(dev_se(f, fn), 0.01)
    off <- calibrate(rec, sf = 10, method = "ggir", max_identical = 1,
                     off_sphere = Inf)
    expect_gt(dev_se(off, fc), 1.5)
    expect_match(paste(capture.output(print(f)), collapse = "\n"),
                 "% of samples identical", fixed = TRUE)
    # GGIR-compatible mode keeps GGIR's rules: no guard, no count, and
    # g.calibrate()'s result
    g <- calibrate(rec, sf = 10, method = "ggir", ggir_compat = TRUE)
    expect_null(g$excluded)
    keep <- setdiff(names(g$ggir), "bsc_qc")
    expect_identical(g$ggir[keep],
                     g.calibrate(rec, sf = 10, verbose = FALSE)[keep])
  }
  expect_error(calibrate(clean, sf = 10, method = "ggir", ggir_compat = TRUE,
                         max_identical = 0.5),
               "`max_identical` is for gravcal's own mode", fixed = TRUE)
})

test_that("constant and all-zero recordings count as identical: no rest", {
  rec <- simulate_recording(hours = 3, sf = 10, seed = 5)
  rec$x <- rec$x[1]
  rec$y <- rec$y[1]
  rec$z <- rec$z[1]
  f <- calibrate(rec, sf = 10)
  expect_equal(f$status, "no_rest")
  expect_equal(f$excluded[["identical"]], nrow(rest_windows(rec, sf = 10)))
  expect_match(f$message, "left out", fixed = TRUE)
  # the GGIR method: its own duplicate filter leaves one distinct window,
  # under its hour of data; the guard's count is of the table before it
  g <- calibrate(rec, sf = 10, method = "ggir")
  expect_equal(g$status, "too_short")
  expect_gt(g$excluded[["identical"]], 1000)
  # zeros kept as samples (skip_zero = FALSE): identical before norm
  rec[, c("x", "y", "z")] <- 0
  f0 <- calibrate(rec, sf = 10, skip_zero = FALSE)
  expect_equal(f0$status, "no_rest")
  expect_equal(f0$excluded[["identical"]],
               nrow(rest_windows(rec, sf = 10, skip_zero = FALSE)))
  expect_equal(f0$excluded[["norm"]], 0L)
})

test_that("calibrate_files() reports the windows each guard left out", {
  # (a .cwa file's rate is 3200 / 2^k Hz)
  rec <- simulate_recording(hours = 24, sf = 12.5, seed = 11, params = sim_params,
                            idle_sleep = 4)
  dir <- tempfile("rest-quality")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE), add = TRUE)
  v <- as.matrix(rec[, c("x", "y", "z")])
  gravcal:::write_cwa(round(v * 256) / 256, file.path(dir, "sleepy.cwa"),
                      sf = 12.5, packed = FALSE, temperature = rec$temperature)
  for (method in c("lightweight", "ggir")) {
    tab <- calibrate_files(dir, method = method,
                           outdir = file.path(dir, paste0("out-", method)))
    fit <- attr(tab, "fits")[[1]]
    expect_identical(tab$excluded_identical, fit$excluded[["identical"]])
    expect_identical(tab$excluded_norm, fit$excluded[["norm"]])
    expect_identical(tab$excluded_clipped, fit$excluded[["clipped"]])
    expect_gte(tab$excluded_identical, if (method == "ggir") 1440 - 8 else 2880 - 8)
  }
  # GGIR-compatible mode runs no guard: NA, not 0
  tab <- calibrate_files(dir, method = "ggir", ggir_compat = TRUE,
                         outdir = file.path(dir, "out-compat"))
  expect_identical(tab$excluded_identical, NA_integer_)
})
