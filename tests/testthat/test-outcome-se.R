# The outcome's uncertainty from the calibration's (issue 43, item 4):
# summary.gravcal_epochs() and its delta-method standard errors. References:
# the ENMO gradient against finite differences of ENMO computed here in R;
# the summaries against their definitions; the standard errors against
# simulated recordings with known truth (bench/outcome-se.R does 200 a
# method; results in bench/results/outcome-se.md).

# Epoch means of unrounded ENMO of samples calibrated by `K`, `offset` and
# the temperature term, over epochs of `n` samples from the first; with
# `kink`, whether each epoch holds a sample within `kink` of |a| = 1, where
# ENMO has no derivative.
enmo_epochs <- function(rec, K, offset, tempoffset = c(0, 0, 0), meantemp = 0, n = 50,
                        kink = NULL) {
  u <- cbind(rec$x, rec$y, rec$z) + matrix(offset, nrow(rec), 3, byrow = TRUE)
  a <- u %*% t(K)
  if (any(tempoffset != 0)) a <- a + outer(rec$temperature - meantemp, tempoffset)
  r <- sqrt(rowSums(a^2)) - 1
  keep <- seq_len(n * (length(r) %/% n))
  if (!is.null(kink)) return(colSums(matrix(abs(r[keep]) < kink, nrow = n)) > 0)
  colMeans(matrix(pmax(r, 0)[keep], nrow = n))
}

# The core's gradient against central differences, on the first 3 hours
# (the recordings start at a whole 15 minutes: the epochs are the
# samples' 50s), away from the epochs where ENMO has no derivative (a
# sample at |a| = 1 to 1e-9: the samples' 1/256 g steps put a few there);
# those must be rare.
expect_gradient <- function(G, rec, fit) {
  rec <- rec[seq_len(3 * 3600 * 10), ]
  G <- G[seq_len(3 * 720), , drop = FALSE]
  fd <- enmo_fd(rec, fit)
  mt <- if (is.finite(fit$meantemp)) fit$meantemp else 0
  kink <- enmo_epochs(rec, fit$K, fit$offset, fit$tempoffset, mt, kink = 1e-9)
  expect_lt(mean(kink), 0.001)
  expect_lt(max(abs(G[!kink, fit$model] - fd[!kink, ])), 1e-6)
  fd
}

# Central differences of enmo_epochs() for each coefficient of `fit`'s model.
enmo_fd <- function(rec, fit, h = 1e-10) {
  at <- function(nm, d) {
    K <- fit$K
    o <- fit$offset
    to <- fit$tempoffset
    pos <- c(k_xx = 1, k_yy = 5, k_zz = 9, k_xy = 2, k_xz = 3, k_yz = 6)
    if (nm %in% names(pos)) K[pos[[nm]]] <- K[pos[[nm]]] + d
    if (nm %in% c("o_x", "o_y", "o_z")) o[match(nm, c("o_x", "o_y", "o_z"))] <- o[match(nm, c("o_x", "o_y", "o_z"))] + d
    if (nm %in% c("t_x", "t_y", "t_z")) to[match(nm, c("t_x", "t_y", "t_z"))] <- to[match(nm, c("t_x", "t_y", "t_z"))] + d
    enmo_epochs(rec, K, o, to, if (is.finite(fit$meantemp)) fit$meantemp else 0)
  }
  sapply(fit$model, function(nm) (at(nm, h) - at(nm, -h)) / (2 * h))
}

test_that("the core's ENMO gradient is the derivative of each epoch's ENMO", {
  rec <- simulate_recording(hours = 3, sf = 10, seed = 31,
                            start = as.POSIXct("2024-01-01 00:00:00", tz = "UTC"))
  fit <- calibrate(rec, sf = 10)
  expect_identical(fit$model, c("k_xx", "k_yy", "k_zz", "k_xy", "k_xz", "k_yz", "o_x", "o_y", "o_z"))
  ep <- epoch_signals(rec, fit = fit, metrics = "ENMO")
  G <- ep$enmo_gradient
  expect_identical(dim(G), c(nrow(ep$short), 12L))
  expect_identical(colnames(G), names(coef(fit)))
  fd <- expect_gradient(G, rec, fit)
  expect_gt(max(abs(fd)), 0.1)
  # the epoch's ENMO is the one the gradient belongs to
  e <- enmo_epochs(rec, fit$K, fit$offset)
  expect_identical(length(e), nrow(ep$short))
  expect_lte(max(abs(round(e, 4) - ep$short$ENMO)), 1e-4 + 1e-12)
  expect_identical(ep$vcov, vcov(fit))
  # GGIR's model with its temperature term (applied as g.getmeta applies it)
  rec <- simulate_recording(hours = 30, sf = 10, seed = 32,
                            params = c(1.02, 0.98, 1.01, 0, 0, 0, 0.03, -0.02, 0.01),
                            tempoffset = c(0.002, -0.001, 0.0015),
                            start = as.POSIXct("2024-01-01 00:00:00", tz = "UTC"))
  gf <- calibrate(rec, sf = 10, method = "ggir")
  expect_true(all(c("t_x", "t_y", "t_z") %in% gf$model))
  ep <- epoch_signals(rec, fit = gf, metrics = "ENMO")
  G <- ep$enmo_gradient
  fd <- expect_gradient(G, rec, gf)
  expect_gt(max(abs(fd[, "t_x"])), 0.1)
})

test_that("summary() of epoch signals: calendar days, mean ENMO and minutes above, by definition", {
  rec <- simulate_recording(hours = 30, sf = 10, seed = 33,
                            start = as.POSIXct("2024-03-01 20:00:00", tz = "UTC"))
  fit <- calibrate(rec, sf = 10)
  ep <- epoch_signals(rec, fit = fit, tz = "Europe/Amsterdam")
  s <- ep$summary
  expect_s3_class(s, "summary.gravcal_epochs")
  expect_identical(s, summary(ep))
  d <- s$days
  # 21:00 local to 03:00 local two days later: three calendar days there
  expect_identical(format(d$day), c("2024-03-01", "2024-03-02", "2024-03-03"))
  expect_equal(d$hours, c(3, 24, 3))
  day <- format(ep$short$time, "%Y-%m-%d", tz = "Europe/Amsterdam")
  expect_equal(d$enmo_mg, 1000 * as.vector(tapply(ep$short$ENMO, day, mean)))
  expect_equal(d$min_above, as.vector(tapply(ep$short$ENMO > 0.1, day, sum)) * 5 / 60)
  expect_equal(s$recording$enmo_mg, 1000 * mean(ep$short$ENMO))
  expect_equal(s$recording$hours, nrow(ep$short) * 5 / 3600)
  expect_equal(s$recording$min_above_day, sum(ep$short$ENMO > 0.1) * 5 / 60 * 24 / s$recording$hours)
  # the delta method: the day's mean gradient through the covariance
  V <- vcov(fit)
  g <- 1000 * colMeans(ep$enmo_gradient[day == "2024-03-02", colnames(V)])
  expect_equal(d$enmo_mg_se[2], sqrt(drop(g %*% V %*% g)))
  expect_true(all(d$enmo_mg_se > 0 & d$min_above_se > 0))
  expect_identical(s$fitted, colnames(V))
  # another threshold: more minutes above a lower one
  s50 <- summary(ep, threshold = 50)
  expect_true(all(s50$days$min_above >= d$min_above))
  expect_identical(s50$days$enmo_mg, d$enmo_mg)
  expect_output(print(s), "Whole recording: mean ENMO")
  expect_output(print(s), "standard errors from the calibration's covariance")
})

test_that("no covariance, no standard errors; se = FALSE skips the gradient", {
  rec <- simulate_recording(hours = 4, sf = 10, seed = 34,
                            start = as.POSIXct("2024-01-01 00:00:00", tz = "UTC"))
  fit <- calibrate(rec, sf = 10)
  a <- epoch_signals(rec, fit = fit)
  b <- epoch_signals(rec, fit = fit, se = FALSE)
  expect_identical(a$short, b$short)
  expect_null(b$enmo_gradient)
  expect_true(all(is.na(b$summary$days$enmo_mg_se)))
  expect_identical(b$summary$days$enmo_mg, a$summary$days$enmo_mg)
  expect_output(print(b$summary), "no standard errors")
  none <- epoch_signals(rec)
  expect_null(none$enmo_gradient)
  expect_true(all(is.na(none$summary$recording[c("enmo_mg_se", "min_above_day_se")])))
  # without ENMO: no summary, and summary() says why
  ang <- epoch_signals(rec, fit = fit, metrics = "anglez")
  expect_null(ang$summary)
  expect_null(ang$enmo_gradient)
  expect_error(summary(ang), "ENMO")
  expect_error(summary(a, threshold = -1), "`threshold`")
  expect_error(epoch_signals(rec, fit = fit, se = NA), "`se`")
})

test_that("the cohort table has the outcomes when asked, not by default", {
  skip_if_quick()
  dir <- snap_dir("outcome-cohort")
  recs <- list()
  for (i in 1:2) {
    recs[[i]] <- simulate_recording(hours = 4, sf = c(10, 25)[i], seed = 40 + i,
                                    start = as.POSIXct("2024-01-01 00:00:00", tz = "UTC"))
  }
  saveRDS(recs[[1]], file.path(dir, "p01.rds"))
  gravcal:::write_cwa(as.matrix(recs[[2]][, c("x", "y", "z")]), file.path(dir, "p02.cwa"),
                      sf = 25, start = as.numeric(recs[[2]]$time[1]),
                      temperature = recs[[2]]$temperature)
  out <- file.path(dir, "out")
  plain <- calibrate_files(dir, method = "lightweight", outdir = out)
  expect_false(any(c("enmo_mg", "enmo_mg_se") %in% names(plain)))
  tab <- calibrate_files(dir, method = "lightweight", outdir = out, outcomes = TRUE)
  cols <- c("enmo_mg", "enmo_mg_se", "min_above_100mg_day", "min_above_100mg_day_se")
  expect_identical(utils::tail(names(tab), 4), cols)
  fits <- attr(tab, "fits")
  ref <- summary(epoch_signals(recs[[1]], fit = fits[["p01.rds"]], sf = 10))$recording
  expect_equal(unlist(tab[1, cols]), unlist(ref[c("enmo_mg", "enmo_mg_se", "min_above_day",
                                                  "min_above_day_se")]), ignore_attr = TRUE)
  ref <- summary(epoch_signals(file.path(dir, "p02.cwa"), fit = fits[["p02.cwa"]]))$recording
  expect_equal(tab$enmo_mg[2], ref$enmo_mg)
  expect_equal(tab$enmo_mg_se[2], ref$enmo_mg_se)
  expect_true(all(tab$enmo_mg_se > 0))
  # saved with outcomes, reused without; and the other way round
  again <- calibrate_files(dir, method = "lightweight", outdir = out)
  expect_identical(names(again), names(plain))
  expect_error(calibrate_files(dir, outdir = out, outcomes = "yes"), "`outcomes`")
  unlink(dir, recursive = TRUE)
})

# The coverage of the stated 95 % intervals on simulated recordings with
# known truth, as bench/outcome-se.R (fewer recordings): per method in its
# own mode, 24 hours from midnight at 10 Hz, one day each; the truth is the
# same samples calibrated with the true parameters.
coverage_run <- function(method, n) {
  rows <- lapply(seq_len(n), function(i) {
    seed <- (if (method == "lightweight") 1000 else 5000) + i
    set.seed(seed)
    if (method == "lightweight") {
      p <- random_params()
      tof <- c(0, 0, 0)
    } else {
      p <- random_params(misalignment = 0)
      tof <- 2 * (stats::runif(3) - 0.5) * 0.002
    }
    rec <- simulate_recording(hours = 24, sf = 10, params = p, tempoffset = tof, seed = seed)
    fit <- calibrate(rec, sf = 10, method = method)
    expect_identical(fit$status, "ok")
    est <- epoch_signals(rec, fit = fit, metrics = "ENMO")$summary$days
    tr <- attr(rec, "truth")
    u <- cbind(rec$x, rec$y, rec$z) + matrix(tr$offset, nrow(rec), 3, byrow = TRUE)
    a <- u %*% t(tr$K) + outer(rec$temperature - tr$meantemp, tr$tempoffset)
    rec[c("x", "y", "z")] <- as.data.frame(a)
    tru <- summary(epoch_signals(rec, sf = 10, metrics = "ENMO"))$days
    expect_identical(est$day, tru$day)
    data.frame(enmo_z = (est$enmo_mg - tru$enmo_mg) / est$enmo_mg_se,
               above_z = (est$min_above - tru$min_above) / est$min_above_se)
  })
  do.call(rbind, rows)
}

# Accept a coverage when the number of intervals that hold the truth is
# within the central 99 % of Binomial(n, 0.95), and the spread of the
# standardised errors when their sd is within 3 of its standard errors
# (1 / sqrt(2 n)) of 1.
expect_covers <- function(z, what) {
  n <- length(z)
  hit <- sum(abs(z) <= stats::qnorm(0.975))
  lo <- stats::qbinom(0.005, n, 0.95)
  expect(hit >= lo, sprintf("%s: %d of %d intervals hold the truth, fewer than %d", what,
                            hit, n, lo))
  s <- stats::sd(z)
  expect(abs(s - 1) <= 3 / sqrt(2 * n), sprintf("%s: sd of (estimate - truth) / se is %.2f",
                                                what, s))
}

test_that("the stated standard errors cover the outcome of the true calibration (lightweight)", {
  skip_if_quick()
  z <- coverage_run("lightweight", 30)
  expect_covers(z$enmo_z, "lightweight, mean ENMO")
  expect_covers(z$above_z, "lightweight, minutes above 100 mg")
})

test_that("the stated standard errors cover the outcome of the true calibration (GGIR)", {
  skip_if_quick()
  z <- coverage_run("ggir", 30)
  expect_covers(z$enmo_z, "GGIR, mean ENMO")
  expect_covers(z$above_z, "GGIR, minutes above 100 mg")
})
