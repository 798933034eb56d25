# Rest that is really rest (issue 44, item 1): rest windows far off the
# sphere after a first fit are left out and the fit done again, both
# methods in gravcal's own modes; sustained runs of them are reported as
# stretches; GGIR-compatible mode keeps GGIR's windows.

# The issue's case: 28 hours with three hours of vehicle-like near-rest
# (every 10 s window's norm 30-80 mg off 1 g, either sign, 5 mg of
# vibration), a device with cross-axis terms and temperature offsets (the
# cohort of bench/cohort-flags.R: scales 1 + N(0, 0.01), cross-axis
# N(0, 0.01), offsets N(0, 0.02) g). `clean` is the same recording without
# those hours (the rows cut out: simulate_recording() draws the vehicle's
# random numbers last, so the rest of the recording is the same).
# (simulated once per file and rate: the tests share it)
near_rest_cache <- new.env()
near_rest_case <- function(sf = 10, vehicle = 3, seed = 44) {
  key <- paste(sf, vehicle, seed)
  if (!is.null(near_rest_cache[[key]])) return(near_rest_cache[[key]])
  set.seed(7)
  p <- c(1 + stats::rnorm(3, sd = 0.01), stats::rnorm(3, sd = 0.01),
         stats::rnorm(3, sd = 0.02))
  rec <- simulate_recording(hours = 28, sf = sf, params = p, seed = seed,
                            vehicle = vehicle,
                            tempoffset = c(0.001, -0.0008, 0.0012),
                            start = as.POSIXct("2024-03-04 00:00:00", tz = "UTC"))
  cont <- attr(rec, "truth")$contaminated
  near_rest_cache[[key]] <- list(rec = rec, clean = rec[-(cont$from:cont$to), ],
                                 stretch = cont, sf = sf)
}

# fit f's coefficients against the clean fit's, in units of their combined
# standard error, with f's offsets restated at the clean fit's mean
# temperature (the left-out hours move the temperature the model is
# centred on): the largest |z| over the clean fit's model.
combined_z <- function(f, clean) {
  nm <- clean$model
  v <- gravcal:::fit_table_coefs(f)
  se <- stats::setNames(unname(f$se), names(v))
  co <- stats::setNames(gravcal:::offsets_at_temperature(
    v, se, f$meantemp, clean$meantemp)$co, names(coef(f)))
  max(abs(co[nm] - coef(clean)[nm]) / sqrt(f$se[nm]^2 + clean$se[nm]^2))
}

test_that("the rule leaves out what is more than k robust spreads off, never within the floor", {
  r <- c(rep(c(-0.001, 0, 0.001), 100), 0.03, -0.04)
  cut <- gravcal:::near_rest_cut(r)
  # median 0, MAD 0.001: spread 1.4826 mg, 5 spreads 7.4 mg
  expect_equal(cut$centre, 0)
  expect_equal(cut$spread, 1.4826 * 0.001)
  expect_equal(cut$threshold, 5 * 1.4826 * 0.001)
  expect_identical(which(cut$out), 301:302)
  # a very clean recording: the 5 mg floor, not 5 spreads
  cut <- gravcal:::near_rest_cut(c(r[1:300] / 10, 0.004, 0.006))
  expect_equal(cut$threshold, 0.005)
  expect_identical(which(cut$out), 302L)
  # the spread is that of the windows kept so far
  cut <- gravcal:::near_rest_cut(c(r[1:300], rep(0.2, 100)),
                                 out = c(rep(FALSE, 300), rep(TRUE, 100)))
  expect_equal(cut$spread, 1.4826 * 0.001)
  expect_true(all(cut$out[301:400]))
})

test_that("stretches are runs of left-out windows, small gaps allowed, 30 min or longer", {
  start <- seq(0, by = 10, length.out = 2000)
  out <- rep(FALSE, 2000)
  out[101:400] <- TRUE                 # 50 min from 1000 s
  out[c(150, 151, 200:220)] <- FALSE   # kept windows inside: still one run
  out[1001:1100] <- TRUE               # 16.7 min: too short
  out[1500:1700] <- TRUE               # 33.5 min, but a 6 min hole:
  out[1600:1635] <- FALSE              #   two runs, both too short
  r <- ifelse(out, 0.05, 0)
  s <- gravcal:::near_rest_stretches(start, out, r, 10)
  expect_equal(nrow(s), 1)
  expect_equal(s$start, 1000)
  expect_equal(s$end, 4000)
  expect_equal(s$hours, 3000 / 3600)
  expect_equal(s$windows, 300 - 23)
  expect_equal(s$median_mg, 50)
  clock <- as.POSIXct("2024-03-04 08:00:00", tz = "UTC")
  s <- gravcal:::near_rest_stretches(start, out, r, 10, clock)
  expect_equal(s$start, clock + 1000)
  expect_match(gravcal:::format_stretches(s),
               "^0.8 h from 2024-03-04 08:16 look like rest but are not on the sphere \\(median 50 mg off\\)$")
})

test_that("a stretch takes every window within its span, those near the sphere too", {
  set.seed(5)
  n <- 1200
  u <- gravcal:::random_unit_vectors(n)
  start <- seq(0, by = 10, length.out = n)
  # 1 h from 3000 s off the sphere by 50 mg, a fifth of it within the
  # cut-off (a vehicle's norm passing near 1 g); an isolated window
  # within the floor elsewhere
  d <- rep(0, n)
  span <- 301:661
  d[span] <- rep(c(0.05, -0.05, 0.05, 0.05, 0.002), length.out = length(span))
  v <- u * (1 + d + stats::rnorm(n, sd = 0.0005))
  fit <- gravcal:::new_fit(points = data.frame(mean_x = v[, 1], mean_y = v[, 2],
                                               mean_z = v[, 3]),
                           method = "ggir")
  kept <- NULL
  refit <- function(keep) {
    kept <<- keep
    fit
  }
  # without the windows' times: only those beyond the cut-off
  nr <- gravcal:::near_rest_trim(fit, v, NULL, refit)
  expect_identical(which(nr$out), span[d[span] != 0.002])
  expect_identical(nr$rejected$in_stretch, 0L)
  # with them: the whole span, counted apart, and the fit of what is left
  nr <- gravcal:::near_rest_trim(fit, v, NULL, refit, start = start, window = 10)
  expect_identical(which(nr$out), span)
  expect_identical(kept, !nr$out)
  expect_identical(nr$rejected$windows, length(span))
  expect_identical(nr$rejected$in_stretch, sum(d[span] == 0.002))
  r <- gravcal:::near_rest_residuals(fit, v, NULL)
  s <- gravcal:::near_rest_stretches(start, nr$out, r, 10)
  expect_equal(s$start, 3000)
  expect_equal(s$windows, length(span))
  expect_match(gravcal:::near_rest_message(nr$rejected, s),
               "^361 rest windows \\(30.1 %\\) left out, more than 5.0 mg off the others after the fit or within the stretches they form \\(72\\): 1.0 h from")
  # a run too short to be a stretch takes nothing more
  d2 <- rep(0, n)
  d2[301:420] <- rep(c(0.05, 0.002), 60)          # 20 min
  v2 <- u * (1 + d2 + stats::rnorm(n, sd = 0.0005))
  nr <- gravcal:::near_rest_trim(fit, v2, NULL, refit, start = start, window = 10)
  expect_identical(which(nr$out), seq.int(301L, 419L, by = 2L))
})

test_that("more than a third off the others: nothing left out, and the fit says so", {
  set.seed(3)
  u <- gravcal:::random_unit_vectors(300)
  k <- c(rep(1, 180), rep(c(0.95, 1.05), 60))   # 40 % off by 50 mg
  v <- u * k
  fit <- gravcal:::new_fit(points = data.frame(mean_x = v[, 1], mean_y = v[, 2],
                                               mean_z = v[, 3]),
                           method = "ggir")
  calls <- 0
  nr <- gravcal:::near_rest_trim(fit, v, NULL, function(keep) {
    calls <<- calls + 1
    fit
  })
  expect_identical(calls, 0)
  expect_false(any(nr$out))
  expect_identical(nr$rejected$windows, 0L)
  expect_match(nr$rejected$note, "^40 % of the rest windows are more than 5.0 mg off")
  # a third or less: left out
  v2 <- u * c(rep(1, 210), rep(c(0.95, 1.05), 45))
  nr <- gravcal:::near_rest_trim(fit, v2, NULL, function(keep) fit)
  expect_identical(which(nr$out), 211:300)
  expect_identical(nr$rejected$note, "")
})

test_that("simulate_recording(vehicle =) gives near-rest off the sphere, the rest unchanged", {
  rec <- simulate_recording(hours = 4, sf = 10, seed = 5, vehicle = 1,
                            params = c(1, 1, 1, 0, 0, 0, 0, 0, 0), noise = 0,
                            resolution = 0)
  rec0 <- simulate_recording(hours = 4, sf = 10, seed = 5,
                             params = c(1, 1, 1, 0, 0, 0, 0, 0, 0), noise = 0,
                             resolution = 0)
  cont <- attr(rec, "truth")$contaminated
  expect_identical(cont$kind, "vehicle")
  expect_identical(cont$to - cont$from + 1L, 36000L)
  expect_identical((cont$from - 1L) %% 18000L, 0L)  # from a whole half hour
  rows <- cont$from:cont$to
  for (col in names(rec0)) expect_identical(rec[[col]][-rows], rec0[[col]][-rows])
  for (m in c("lightweight", "ggir")) {
    w <- rest_windows(rec[rows, ], sf = 10, method = m)
    # every window at rest, its norm 30-80 mg off 1 g (within the 5 mg
    # vibration's mean over the window), of either sign
    expect_gt(mean(w$rest), 0.9)
    off <- sqrt(w$mean_x^2 + w$mean_y^2 + w$mean_z^2) - 1
    off <- off[w$rest]
    expect_true(all(abs(off) > 0.025 & abs(off) < 0.085), label = m)
    expect_true(any(off > 0) && any(off < 0))
  }
  expect_error(simulate_recording(hours = 2, vehicle = 3), "at most `hours`")
})

test_that("three hours of vehicle-like near-rest: both methods as without them, the stretch reported", {
  cs <- near_rest_case()
  truth_from <- cs$rec$time[cs$stretch$from]
  for (m in c("lightweight", "ggir")) {
    fc <- calibrate(cs$rec, sf = cs$sf, method = m)
    f0 <- calibrate(cs$clean, sf = cs$sf, method = m)
    expect_identical(fc$status, "ok", label = m)
    expect_identical(f0$status, "ok", label = m)
    # within 2 combined standard errors of the recording without those
    # hours (before the rule: the lightweight fit lost its temperature
    # term and was high_error, bench/results/near-rest.md)
    expect_lt(combined_z(fc, f0), 2, label = m)
    # the standard errors are those of the fit on what is left
    expect_equal(fc$se[f0$model], f0$se[f0$model], tolerance = 0.2, label = m)
    # one stretch, where the vehicle was, three hours long
    s <- fc$rejected_stretches
    expect_equal(nrow(s), 1, label = m)
    win <- if (m == "ggir") 10 else 5
    expect_lte(abs(as.numeric(s$start) - as.numeric(truth_from)), 2 * win,
               label = m)
    expect_equal(s$hours, 3, tolerance = 2 * win / 3600 / 3, label = m)
    expect_gt(s$median_mg, 30)
    expect_lt(s$median_mg, 80)
    # every window of the stretch at rest is left out, and no other
    expect_equal(fc$rejected$windows, s$windows)
    expect_gte(s$windows, 0.95 * 3 * 3600 / win)
    expect_match(fc$message, "3.0 h from 2024-03-04 22:30 look like rest but are not on the sphere (median",
                 fixed = TRUE)
    out <- capture.output(print(fc))
    expect_true(any(grepl("off the sphere, left out: ", out, fixed = TRUE)))
    expect_true(any(grepl("^    3.0 h from 2024-03-04 22:30 look like rest", out)))
    out <- capture.output(print(summary(fc)))
    expect_true(any(grepl("Rest windows off the sphere, left out:", out, fixed = TRUE)))
    # the clean recording: nothing left out, status unchanged
    expect_identical(f0$rejected$windows, 0L, label = m)
    expect_identical(nrow(f0$rejected_stretches), 0L)
    expect_identical(f0$rejected$note, "")
    # the cohort table's columns
    row <- gravcal:::cohort_row("a.rds", "a.rds", fc, NULL, character(0), 0, m)
    expect_equal(row$rejected_windows, s$windows)
    expect_equal(row$rejected_hours, s$hours)
    row0 <- gravcal:::cohort_row("a.rds", "a.rds", f0, NULL, character(0), 0, m)
    expect_identical(row0$rejected_windows, 0L)
    expect_identical(row0$rejected_hours, 0)
  }
})

test_that("GGIR-compatible mode leaves no window out", {
  cs <- near_rest_case()
  fc <- calibrate(cs$rec, sf = cs$sf, method = "ggir", ggir_compat = TRUE)
  expect_null(fc$rejected)
  expect_null(fc$rejected_stretches)
  own <- calibrate(cs$rec, sf = cs$sf, method = "ggir")
  # GGIR's spheredata holds every rest window of the procedure, the
  # vehicle's included; own mode's holds those kept
  expect_identical(NROW(fc$ggir$spheredata),
                   NROW(own$ggir$spheredata) + own$rejected$windows)
  row <- gravcal:::cohort_row("a.rds", "a.rds", fc, NULL, character(0), 0, "ggir")
  expect_identical(row$rejected_windows, NA_integer_)
  expect_identical(row$rejected_hours, NA_real_)
})

test_that("a device file dates its stretch by the file's clock", {
  skip_if_quick()
  cs <- near_rest_case(sf = 12.5)
  f <- tempfile(fileext = ".cwa")
  on.exit(unlink(f))
  gravcal:::write_cwa(as.matrix(cs$rec[, c("x", "y", "z")]), f, sf = 12.5,
                      packed = FALSE, temperature = cs$rec$temperature,
                      start = as.numeric(cs$rec$time[1]))
  truth_from <- cs$rec$time[cs$stretch$from]
  for (m in c("lightweight", "ggir")) {
    fit <- calibrate(f, method = m)
    expect_identical(fit$status, "ok")
    s <- fit$rejected_stretches
    expect_equal(nrow(s), 1, label = m)
    expect_s3_class(s$start, "POSIXct")
    expect_lte(abs(as.numeric(s$start) - as.numeric(truth_from)), 20, label = m)
    expect_equal(s$hours, 3, tolerance = 0.01)
  }
})

test_that("off_sphere sets the cut-off; Inf turns the rule off; compatible mode refuses it", {
  cs <- near_rest_case()
  for (m in c("lightweight", "ggir")) {
    off <- calibrate(cs$rec, sf = cs$sf, method = m, off_sphere = Inf)
    expect_null(off$rejected)
    expect_null(off$rejected_stretches)
    # before the rule (as without it): the vehicle's hours move the fit
    # beyond 2 combined standard errors, or leave it high_error
    f0 <- calibrate(cs$clean, sf = cs$sf, method = m)
    expect_true(combined_z(off, f0) > 2 || off$status == "high_error", label = m)
    wide <- calibrate(cs$rec, sf = cs$sf, method = m, off_sphere = 50)
    expect_equal(wide$rejected$k, 50)
    expect_lt(wide$rejected$windows, calibrate(cs$rec, sf = cs$sf, method = m)$rejected$windows)
  }
  expect_error(calibrate(cs$rec, sf = cs$sf, off_sphere = 0.5),
               "`off_sphere` must be")
  expect_error(calibrate(cs$rec, sf = cs$sf, method = "ggir", ggir_compat = TRUE,
                         off_sphere = 5),
               "`off_sphere` is for gravcal's own mode")
})
