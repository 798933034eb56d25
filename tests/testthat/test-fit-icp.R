# fit_icp() and the R-compatible window arithmetic behind GGIR mode.

test_that("fit_icp reproduces GGIR's stored fit on data.calibrate (1e-8)", {
  f <- skip_if_no_shared("ggir", "data.calibrate.RData")
  env <- new.env()
  load(f, envir = env)
  C <- env$data.calibrate
  # Reference: GGIR's own g.calibrate output stored with the windows
  # (wadpac/GGIR data/data.calibrate.RData, v3.3-7).
  fit <- fit_icp(C$spheredata, ggir_compat = TRUE)
  expect_s3_class(fit, "gravcal_fit")
  expect_equal(fit$status, "ok")
  expect_lt(max(abs(diag(fit$K) - C$scale)), 1e-8)
  expect_lt(max(abs(fit$offset - C$offset)), 1e-8)
  expect_lt(max(abs(fit$tempoffset - C$tempoffset)), 1e-8)
  expect_equal(fit$iterations, 5L)
  # this stored result keeps the errors unrounded
  expect_lt(abs(fit$error_before - C$cal.error.start), 1e-8)
  expect_lt(abs(fit$error_after - C$cal.error.end), 1e-8)
  expect_equal(fit$meantemp, mean(C$spheredata$temperature))
  expect_true(all(fit$K[row(fit$K) != col(fit$K)] == 0))
})

test_that("gravcal's own stopping rule converges past GGIR's", {
  rec <- simulate_recording(hours = 30, sf = 10, seed = 5,
                            tempoffset = c(0.002, -0.001, 0.0015))
  w <- rest_windows(rec, sf = 10, method = "ggir")
  ggir <- fit_icp(w, ggir_compat = TRUE, trace = TRUE)
  own <- fit_icp(w, trace = TRUE)
  expect_true(own$converged)
  expect_gt(own$iterations, ggir$iterations)
  # converged: another run started from the result would not move; check
  # that the last step of the trace is below the tolerance
  tr <- as.matrix(own$trace[, 1:9])
  expect_lt(max(abs(tr[nrow(tr), ] - tr[nrow(tr) - 1, ])), 1e-9)
  expect_lte(own$error_after, ggir$error_after + 1e-6)
  expect_equal(nrow(own$trace), own$iterations)
})

test_that("the accelerated converged fit reaches the fixed point of GGIR's own iteration", {
  # GGIR's iteration written out here in R (weights of the iteration before,
  # as GGIR's g.calibrate() takes them), run until it no longer moves, on
  # windows with cross-axis errors that its model cannot remove, so that it
  # converges slowly; gravcal's accelerated fit must land on its fixed point
  set.seed(11)
  p <- random_params(scale = 0.05, misalignment = 0.25, offset = 0.05)
  rec <- simulate_recording(hours = 40, sf = 2, params = p, seed = 11,
                            noise = 0.01, tempoffset = c(0.002, -0.001, 0.001))
  w <- rest_windows(rec, sf = 2, method = "ggir")
  w <- w[w$rest, ]
  v <- as.matrix(w[c("mean_x", "mean_y", "mean_z")])
  tt <- w$temperature - mean(w$temperature)
  o <- c(0, 0, 0); s <- c(1, 1, 1); to <- c(0, 0, 0); wt <- rep(1, nrow(v))
  for (it in 1:20000) {
    cur <- sweep(sweep(v, 2, o, "+"), 2, s, "*") + outer(tt, to)
    cp <- cur / sqrt(rowSums(cur^2))
    fitted <- cur
    o_new <- o; s_new <- s; to_new <- to
    for (k in 1:3) {
      b <- stats::lm.wfit(cbind(1, cur[, k], tt), cp[, k], wt)$coefficients
      fitted[, k] <- b[1] + b[2] * cur[, k] + b[3] * tt
      o_new[k] <- o[k] + b[1] / (s[k] * b[2])
      s_new[k] <- s[k] * b[2]
      to_new[k] <- to[k] * b[2] + b[3]
    }
    moved <- max(abs(c(o_new - o, s_new - s, (to_new - to) * diff(range(tt)))))
    o <- o_new; s <- s_new; to <- to_new
    wt <- pmin(1 / sqrt(rowSums((fitted - cp)^2)), 100)
    if (moved < 1e-13) break
  }
  expect_lt(moved, 1e-13)
  expect_gt(it, 200)  # slow for GGIR's iteration ...
  own <- fit_icp(w)
  expect_true(own$converged)
  expect_lt(own$iterations, it / 4)  # ... fast for the accelerated one
  expect_lt(max(abs(diag(own$K) - s)), 1e-8)
  expect_lt(max(abs(own$offset - o)), 1e-8)
  expect_lt(max(abs(own$tempoffset - to)), 1e-9)
  expect_equal(own$meantemp, mean(w$temperature))
})

test_that("fit_icp handles missing or constant temperature", {
  rec <- simulate_recording(hours = 24, sf = 10, seed = 6)
  w <- rest_windows(rec, sf = 10, method = "ggir")
  w0 <- w
  w0$temperature <- 25
  f0 <- fit_icp(w0)
  expect_equal(f0$status, "ok")
  expect_equal(unname(f0$tempoffset), c(0, 0, 0))
  expect_match(f0$message, "does not vary")
  f1 <- fit_icp(w, use_temp = FALSE)
  expect_equal(unname(f1$tempoffset), c(0, 0, 0))
  expect_equal(unname(f1$offset), unname(f0$offset), tolerance = 1e-12)
  w2 <- w
  w2$temperature[3] <- NA
  expect_error(fit_icp(w2), "temperature")
  expect_equal(fit_icp(w[w$rest, ][1:5, ])$status, "no_rest")
  expect_error(fit_icp(w, max_iter = 0), "max_iter")
  expect_error(fit_icp(list(1)), "data frame")
})

test_that("R-compatible windows are R's own numbers, bit for bit", {
  set.seed(3)
  n <- 3 * 600
  x <- round(rnorm(n, 0.3, 0.01), 3)
  y <- round(rnorm(n, -0.2, 0.01), 3)
  z <- round(rnorm(n, 0.9, 0.01), 3)
  tt <- 25 + cumsum(rnorm(n, 0, 0.001))
  L <- 600
  w <- pump_windows(gravcal:::gc_source_columns(x, y, z, tt), L, TRUE)$windows
  # GGIR's rollMean (cumsum then diff) and rollSD (sd per column)
  rmean <- function(v) diff(cumsum(c(0, v))[seq(1, n + 1, by = L)]) / L
  rsd <- function(v) apply(matrix(v, L), 2, stats::sd)
  expect_identical(w$mean_x, rmean(x))
  expect_identical(w$mean_z, rmean(z))
  expect_identical(w$sd_x, rsd(x))
  expect_identical(w$sd_y, rsd(y))
  expect_identical(w$mean_norm, rmean(sqrt(x^2 + y^2 + z^2)))
  expect_identical(w$temperature, rmean(tt))
  # a new block of GGIR's (here each third of the samples) restarts the
  # cumulative sums: each block's means are its own cumsum's differences
  per <- n / 3
  b <- pump_blocks(cut_blocks(x, y, z, tt, c(0, per, 2 * per, n)), sf = L / 10,
                   compat = TRUE, per_hour = per)
  for (k in 1:3) {
    r <- (k - 1) * per + seq_len(per)
    expect_identical(b[[k]]$windows$mean_x,
                     diff(cumsum(c(0, x[r]))[seq(1, per + 1, by = L)]) / L)
  }
})

test_that("fit_icp(): iterations beyond an integer, text temperature", {
  rec <- simulate_recording(hours = 3, sf = 10, seed = 1)
  w <- rest_windows(rec, sf = 10, method = "ggir")
  expect_snapshot(error = TRUE, fit_icp(w, max_iter = 1e10))
  expect_snapshot(error = TRUE, fit_icp(w, max_iter = 2.5))
  expect_snapshot(error = TRUE, fit_icp(w, max_iter = "10"))
  wt <- w
  wt$temperature <- as.character(wt$temperature)
  expect_snapshot(error = TRUE, fit_icp(wt))
  # without the temperature term the column is not used
  expect_identical(coef(fit_icp(wt, use_temp = FALSE)),
                   coef(fit_icp(w, use_temp = FALSE)))
  # the GGIR method refuses it too; the lightweight method, which can
  # calibrate without a temperature term, says that it leaves it out
  rt <- transform(rec, temperature = as.character(temperature))
  expect_snapshot(error = TRUE, calibrate(rt, sf = 10, method = "ggir"))
  expect_snapshot(fl <- calibrate(rt, sf = 10))
  expect_identical(coef(fl), coef(calibrate(rec[names(rec) != "temperature"],
                                            sf = 10)))
})

test_that("the GGIR procedure's fit is fit_icp()'s on its rest windows", {
  # g.calibrate() and calibrate(method = "ggir") fit through the same
  # internal as fit_icp() (icp_means()): refitting their spheredata with
  # fit_icp() gives their coefficients to the bit
  rec <- simulate_recording(hours = 30, sf = 10, seed = 4,
                            tempoffset = c(0.002, -0.001, 0.0015))
  C <- g.calibrate(rec, sf = 10, verbose = FALSE, minloadcrit = 12)
  expect_true(C$use.temp)
  f <- fit_icp(C$spheredata, ggir_compat = TRUE)
  expect_identical(unname(diag(f$K)), C$scale)
  expect_identical(unname(f$offset), C$offset)
  expect_identical(unname(f$tempoffset), C$tempoffset)
  own <- calibrate(rec, sf = 10, method = "ggir", minloadcrit = 12)
  fo <- fit_icp(own$points)
  expect_identical(coef(fo), coef(own))
  expect_identical(fo$iterations, own$iterations)
})
