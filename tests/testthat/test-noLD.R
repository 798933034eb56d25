# R without long double (configure --disable-long-double, CRAN's "noLD"
# check): R's mean(), sd(), cumsum() then accumulate in double, and gravcal's
# replays of R's arithmetic must too (r_arith.hpp; the accumulator is read
# from the R gravcal runs in when it loads, R/fp-build.R). These tests run
# the double accumulator on any R (gravcal:::with_r_accumulator(FALSE, ...))
# and compare it with R's algorithms written out here in R, whose scalar
# arithmetic is double: what an R without long double computes. On such an R
# (make test-noLD) the GGIR-identity test files check the rest against GGIR.

# R's mean() (summary.c): the sum over n, corrected by the mean of the
# deviations from it, each sum in R's accumulator, here double.
noLD_mean <- function(x) {
  n <- length(x)
  s <- 0
  for (v in x) s <- s + v
  m <- s / n
  if (is.finite(m)) {
    t <- 0
    for (v in x) t <- t + (v - m)
    m <- m + t / n
  }
  m
}

# R's var() of one column (cov.c): the same two-pass mean, then the sum of
# squared deviations from it over n - 1; sd() its square root.
noLD_sd <- function(x) {
  m <- noLD_mean(x)
  ss <- 0
  for (v in x) ss <- ss + (v - m) * (v - m)
  sqrt(ss / (length(x) - 1))
}

# The accumulator this R has, as gravcal found it when it loaded.
build_state_ld <- function() gravcal:::build_state$r_long_double

# R's cumsum() (cum.c) with a double accumulator.
noLD_cumsum <- function(x) Reduce(`+`, x, accumulate = TRUE)

# Inputs on which the two accumulators often differ: full 53-bit values
# about a large mean, of many lengths.
noLD_inputs <- function(k, seed) {
  set.seed(seed)
  lapply(seq_len(k), function(i) {
    n <- sample(c(2:20, 100, 500, 1000, 3000), 1)
    stats::rnorm(n, mean = stats::runif(1, -2, 2), sd = 10^stats::runif(1, -6, 0))
  })
}

test_that("the load-time probe reads R's accumulator", {
  ld <- gravcal:::build_state$r_long_double
  expect_type(ld, "logical")
  # the probe input tells the accumulators apart (else the probe could not)
  x <- gravcal:::probe_values()
  expect_false(identical(gravcal:::gc_r_mean_sd(x, TRUE), gravcal:::gc_r_mean_sd(x, FALSE)))
  # and this R's mean() and sd() are the replay of the accumulator found
  expect_identical(gravcal:::gc_r_mean_sd(x, ld), c(mean(x), stats::sd(x)))
  expect_identical(c(noLD_mean(x), noLD_sd(x)), gravcal:::gc_r_mean_sd(x, FALSE))
  if (!isTRUE(capabilities("long.double"))) expect_false(ld)
})

test_that("mean() and sd() with a double accumulator are an R without long double's", {
  xs <- noLD_inputs(400, seed = 30)
  differ <- 0
  for (x in xs) {
    d <- gravcal:::gc_r_mean_sd(x, FALSE)
    expect_identical(d, c(noLD_mean(x), noLD_sd(x)))
    expect_identical(gravcal:::gc_r_mean_sd(x, build_state_ld()), c(mean(x), stats::sd(x)))
    differ <- differ + !identical(d, gravcal:::gc_r_mean_sd(x, TRUE))
  }
  # the double path is a path of its own where long double is wider
  if (.Machine$sizeof.longdouble > 8) expect_gt(differ, 40)
})

test_that("R-compatible windows with a double accumulator are noLD R's numbers", {
  set.seed(31)
  L <- 500
  n <- 40 * L
  x <- stats::rnorm(n, 0.3, 0.01)
  y <- stats::rnorm(n, -0.2, 0.004)
  z <- stats::rnorm(n, 0.9, 0.02)
  tt <- 25 + cumsum(stats::rnorm(n, 0, 0.001))
  win <- function(ld) {
    gravcal:::with_r_accumulator(ld, {
      pump_windows(gravcal:::gc_source_columns(x, y, z, tt), L, TRUE)$windows
    })
  }
  w <- win(FALSE)
  ends <- seq(1, n + 1, by = L)
  rmean <- function(v) diff(c(0, noLD_cumsum(v))[ends]) / L
  rsd <- function(v) apply(matrix(v, L), 2, noLD_sd)
  expect_identical(w$mean_x, rmean(x))
  expect_identical(w$mean_y, rmean(y))
  expect_identical(w$mean_z, rmean(z))
  expect_identical(w$mean_norm, rmean(sqrt(x^2 + y^2 + z^2)))
  expect_identical(w$temperature, rmean(tt))
  expect_identical(w$sd_x, rsd(x))
  expect_identical(w$sd_y, rsd(y))
  expect_identical(w$sd_z, rsd(z))
  # and the two accumulators differ on some of these windows
  w_ld <- win(TRUE)
  if (.Machine$sizeof.longdouble > 8) {
    expect_gt(sum(w_ld$sd_x != w$sd_x) + sum(w_ld$sd_z != w$sd_z), 0)
  }
  # the setting is restored afterwards
  expect_identical(gravcal:::gc_set_r_long_double(build_state_ld()), build_state_ld())
})

test_that("GGIR's temperature rules with a double accumulator follow noLD R", {
  sf <- 10
  H <- 3600 * sf
  set.seed(32)
  t <- 25 + stats::rnorm(H, 0, 0.02)
  r <- gravcal:::with_r_accumulator(FALSE, {
    pump_blocks(list(list(x = rep(0.1, H), y = rep(0.2, H), z = rep(0.97, H), t = t)),
                sf, TRUE, temp_min_sd = 0.01, per_hour = H)[[1]]
  })
  # the sd is decided on the right side of the threshold (exact only when
  # close to it), and the window temperatures are noLD R's cumsum means
  expect_identical(r$temp_sd < 0.01, noLD_sd(t) < 0.01)
  ends <- seq(1, H + 1, by = 10 * sf)
  expect_identical(r$windows$temperature, diff(c(0, noLD_cumsum(t))[ends]) / (10 * sf))
})

test_that("GGIR's procedure with a double accumulator: lazy sds give the exact ones' result", {
  skip_on_cran()
  sf <- 10
  rec <- simulate_recording(hours = 30, sf = sf, seed = 33, params = known_params(),
                            tempoffset = c(0.002, -0.001, 0.0015))
  run <- function(lazy) {
    gravcal:::with_r_accumulator(FALSE, {
      src <- gravcal:::open_source(rec, sf = sf)
      suppressWarnings(gravcal:::ggir_run(src, compat = TRUE, lazy = lazy))
    })
  }
  a <- run(TRUE)
  b <- run(FALSE)
  for (nm in c("scale", "offset", "tempoffset", "meantempcal", "npoints",
               "cal.error.start", "cal.error.end", "QCmessage")) {
    expect_identical(a[[nm]], b[[nm]], label = nm)
  }
  expect_gt(a$npoints, 10)
  # the rest windows' sds are noLD R's sd() of the window's samples
  rows <- as.integer(rownames(a$spheredata))
  n <- 10 * sf
  for (ax in c("x", "y", "z")) {
    want <- vapply(rows, function(k) noLD_sd(rec[[ax]][(k - 1) * n + seq_len(n)]), 0)
    expect_identical(a$spheredata[[paste0("sd", ax)]], want)
  }
})
