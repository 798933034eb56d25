# Plausibility of every fit (issue 31, item 1): the bounds table, and each
# device's history in calibrate_files().

# A cohort table as calibrate_files() makes it (the columns the judgement
# reads): `co` a matrix of scale.x..offset.z (one row per recording), `se`
# the standard errors (one number or a matrix).
cohort_tab <- function(co, se, serial, status = "ok", pooled = FALSE) {
  cols <- c("scale.x", "scale.y", "scale.z", "offset.x", "offset.y", "offset.z")
  co <- matrix(co, ncol = 6, dimnames = list(NULL, cols))
  se <- matrix(se, nrow(co), 6, dimnames = list(NULL, paste0(cols, ".se")))
  data.frame(file = sprintf("r%02d.cwa", seq_len(nrow(co))),
             status = rep_len(status, nrow(co)), co, se,
             serial = serial, pooled = rep_len(pooled, nrow(co)),
             stringsAsFactors = FALSE, check.names = FALSE)
}

# n recordings of a device with true coefficients p (6), each estimated
# with standard error se.
device_rows <- function(p, n, se) {
  t(replicate(n, p + stats::rnorm(6, sd = se)))
}

test_that("plausible_bounds() is the one table the guards read", {
  b <- plausible_bounds()
  expect_identical(b$coefficient, c("scale", "cross", "offset", "temperature_offset"))
  # omconvert's range check (omcalibrate.c): |scale - 1| <= 0.2,
  # offset <= 0.41 g, temperature offset <= 0.02 g per degree C
  expect_equal(b$flag_upper[c(1, 3, 4)], c(1.2, 0.41, 0.02))
  expect_true(all(b$flag_lower <= b$flag_upper & b$refuse_lower <= b$flag_lower &
                    b$flag_upper <= b$refuse_upper))
  # the refusal bounds guard_fit() and the GGIR method's own mode apply
  expect_equal(gravcal:::plausible$scale, unlist(b[1, c("refuse_lower", "refuse_upper")],
                                                  use.names = FALSE))
  expect_equal(gravcal:::plausible$offset, b$refuse_upper[3])
  expect_equal(gravcal:::plausible$temp, b$refuse_upper[4])
  expect_true(gravcal:::ggir_plausible(c(b$refuse_upper[1] - 0.01, 1, 1), c(0, 0, 0), NULL))
  expect_false(gravcal:::ggir_plausible(c(b$refuse_upper[1] + 0.01, 1, 1), c(0, 0, 0), NULL))
  # between the two levels: applied, but flagged
  co <- c(scale.x = 1.25, scale.y = 1, scale.z = 1, offset.x = 0, offset.y = -0.45,
          offset.z = 0.1)
  out <- gravcal:::beyond_flag_bounds(co)
  expect_length(out, 2)
  expect_match(out[1], "^scale.x = 1.25")
  expect_match(out[2], "^offset.y = -0.45")
  expect_length(gravcal:::beyond_flag_bounds(c(scale.x = 1.19, offset.z = 0.4)), 0)
  h <- attr(b, "history")
  expect_true(all(c("min_recordings", "z", "attenuation", "attenuation_absolute",
                    "agreement") %in% names(h)))
})

test_that("a recording that disagrees with its device's others is a device outlier", {
  set.seed(11)
  p <- c(1.01, 0.99, 1.005, 0.02, -0.01, 0.015)
  co <- device_rows(p, 5, 0.001)
  co[3, 4] <- co[3, 4] + 0.02  # offset.x moved by 20 SE
  j <- gravcal:::cohort_plausibility(cohort_tab(co, 0.001, "1234"))
  expect_identical(j$tab$plausibility, c("ok", "ok", "device_outlier", "ok", "ok"))
  expect_match(j$tab$plausibility_note[3], "offset.x")
  expect_match(j$tab$plausibility_note[3], "device 1234 reference")
  # the device's reference: the median of the recordings not flagged
  expect_identical(j$devices$serial, "1234")
  expect_equal(j$devices$recordings, 5)
  expect_equal(j$devices$ref.offset.x, stats::median(co[-3, 4]))
  expect_identical(j$devices$left_out_files, "r03.cwa")
  expect_lt(abs(j$devices$ref.offset.x - p[4]), 0.003)
  # within its uncertainty it is not: the same shift with standard errors
  # of 0.01
  co2 <- device_rows(p, 5, 0.001)
  co2[3, 4] <- co2[3, 4] + 0.02
  j2 <- gravcal:::cohort_plausibility(cohort_tab(co2, 0.01, "1234"))
  expect_identical(j2$tab$plausibility, rep("ok", 5))
})

test_that("a device's offsets are compared at one temperature", {
  # one device (true offsets p, temperature offsets t per degree C) whose
  # five recordings had mean temperatures 22 to 34 degrees C: each fit
  # states its offsets at its own mean temperature, o + (T - m) K^-1 t
  # apart, 12 mg apart at the extremes on x with t_x = 1 mg per degree C
  set.seed(12)
  p <- c(1.01, 0.99, 1.005, 0.02, -0.01, 0.015)
  t <- c(0.001, -0.0008, 0.0005)
  m <- c(22, 25, 28, 31, 34)
  co <- device_rows(p, 5, 0.0002)
  co[, 4:6] <- co[, 4:6] + outer(m - 28, t / p[1:3])
  tab <- cohort_tab(co, 0.0002, "555")
  tab[paste0("temperature.offset.", c("x", "y", "z"))] <- as.list(t)
  tab[paste0("temperature.offset.", c("x", "y", "z"), ".se")] <- 2e-5
  tab$meantempcal <- m
  j <- gravcal:::cohort_plausibility(tab)
  expect_identical(j$tab$plausibility, rep("ok", 5))
  expect_equal(j$devices$reference_temp, 28)
  expect_lt(abs(j$devices$ref.offset.x - p[4]), 0.001)
  # a recording whose offset moved by 8 mg (beyond the practical minimum
  # of 5 mg) is found at one temperature; as each fit states them, the
  # temperature's spread of the offsets (5 mg on y between 22 and 34
  # degrees C) hides it
  tab$offset.y[3] <- tab$offset.y[3] + 0.008
  j <- gravcal:::cohort_plausibility(tab)
  expect_identical(j$tab$plausibility, c("ok", "ok", "device_outlier", "ok", "ok"))
  expect_match(j$tab$plausibility_note[3], "offset.y", fixed = TRUE)
  expect_match(j$tab$plausibility_note[3], "at 28.0 degrees C", fixed = TRUE)
  tab0 <- tab
  tab0$meantempcal <- NA_real_
  j0 <- gravcal:::cohort_plausibility(tab0)
  expect_identical(j0$tab$plausibility, rep("ok", 5))
  # the restatement is the same calibration: equal calibrated samples at
  # any temperature, for a model with cross-axis terms too
  cf <- c(scale.x = 1.02, scale.y = 0.97, scale.z = 1.01, cross.xy = 0.01,
          cross.xz = -0.02, cross.yz = 0.015, offset.x = 0.03, offset.y = -0.02,
          offset.z = 0.01, temperature.offset.x = 0.002,
          temperature.offset.y = -0.001, temperature.offset.z = 0.0015)
  se <- stats::setNames(rep(1e-4, 12), names(cf))
  r <- gravcal:::offsets_at_temperature(cf, se, 26.3, 31)
  K <- gravcal:::params_to_K(cf[1:6])
  v <- matrix(stats::rnorm(30), 10)
  temp <- stats::runif(10, 15, 40)
  cal <- function(c, mt) {
    t(K %*% (t(v) + c[7:9])) + outer(temp - mt, c[10:12])
  }
  expect_equal(cal(r$co, 31), cal(cf, 26.3), tolerance = 1e-14)
  expect_true(all(r$se[7:9] > se[7:9]))
  expect_identical(r$se[c(1:6, 10:12)], se[c(1:6, 10:12)])
})

test_that("scales changed by one common factor are an attenuation", {
  set.seed(12)
  p <- c(0.985, 1.01, 0.995, 0.02, -0.01, 0.015)
  co <- device_rows(p, 4, 0.001)
  # the raw signal attenuated by 5 % on one recording: scales / 0.95
  co[2, 1:3] <- co[2, 1:3] / 0.95
  j <- gravcal:::cohort_plausibility(cohort_tab(co, 0.001, "77"))
  expect_identical(j$tab$plausibility, c("ok", "attenuated", "ok", "ok"))
  expect_match(j$tab$plausibility_note[2], "relative to the device's reference")
  expect_match(j$tab$plausibility_note[2], "attenuated by (4[.]9|5[.]0|5[.]1) %")
  # one axis alone moved by as much is not an attenuation, but an outlier
  co3 <- device_rows(p, 4, 0.001)
  co3[2, 1] <- co3[2, 1] / 0.95
  j3 <- gravcal:::cohort_plausibility(cohort_tab(co3, 0.001, "77"))
  expect_identical(j3$tab$plausibility, c("ok", "device_outlier", "ok", "ok"))
  # a whole device attenuated, without a history (two recordings) or with
  # one (three): relative to 1
  for (n in 2:3) {
    co4 <- device_rows(c(1, 1, 1, 0.01, 0, -0.01), n, 0.001)
    co4[, 1:3] <- co4[, 1:3] / 0.93
    j4 <- gravcal:::cohort_plausibility(cohort_tab(co4, 0.001, "88"))
    expect_identical(j4$tab$plausibility, rep("attenuated", n))
    expect_match(j4$tab$plausibility_note, "relative to 1")
  }
  # a device without a serial number: judged alone, relative to 1
  co5 <- rbind(c(1.08, 1.07, 1.075, 0, 0, 0), c(1.01, 0.99, 1, 0, 0, 0))
  j5 <- gravcal:::cohort_plausibility(cohort_tab(co5, 0.001, NA_character_))
  expect_identical(j5$tab$plausibility, c("attenuated", "ok"))
  expect_null(j5$devices)
})

test_that("a clean cohort is not flagged", {
  set.seed(13)
  # 30 devices, 3 to 5 recordings each, gains and offsets as van Hees et al.
  # (2014, Table 2) report across devices (SD 0.01 and 0.02 g)
  rows <- lapply(1:30, function(d) {
    p <- c(1 + stats::rnorm(3, sd = 0.01), stats::rnorm(3, sd = 0.02))
    n <- 3 + d %% 3
    list(co = device_rows(p, n, 0.002), serial = rep(sprintf("S%02d", d), n))
  })
  tab <- cohort_tab(do.call(rbind, lapply(rows, `[[`, "co")), 0.002,
                    unlist(lapply(rows, `[[`, "serial")))
  j <- gravcal:::cohort_plausibility(tab)
  expect_identical(unique(j$tab$plausibility), "ok")
  expect_equal(nrow(j$devices), 30)
  # recordings not calibrated are not judged; pooled ones are not part of
  # the history
  tab$status[1] <- "no_rest"
  tab$status[2] <- "implausible"
  tab$pooled[4] <- TRUE
  j <- gravcal:::cohort_plausibility(tab)
  expect_identical(j$tab$plausibility[1:4], c(NA, "out_of_bounds", "ok", "ok"))
  expect_match(j$tab$plausibility_note[4], "pooled")
  expect_match(j$tab$plausibility_note[3], "no device history")
})

test_that("a device's spread is at least the cohort's", {
  # fits that vary between recordings ten times more than their standard
  # errors say (as fits of short free-living recordings do): a device whose
  # first two recordings happen to agree holds its third, as far from them
  # as the cohort's recordings typically are, to the cohort's spread
  set.seed(14)
  rows <- lapply(1:12, function(d) {
    device_rows(c(1 + stats::rnorm(3, sd = 0.01), stats::rnorm(3, sd = 0.02)), 3, 0.005)
  })
  p <- c(1.01, 0.99, 1, 0.01, 0.02, -0.01)
  rows[[1]] <- rbind(p, p + 1e-5, p + c(0, 0, 0, 0.008, 0, 0))
  tab <- cohort_tab(do.call(rbind, rows), 0.0005, rep(sprintf("S%02d", 1:12), each = 3))
  j <- gravcal:::cohort_plausibility(tab)
  expect_identical(j$tab$plausibility[1:3], rep("ok", 3))
  expect_gt(j$devices$spread.offset.x[1], 0.002)
  # alone, its own spread (1e-5) would flag it
  j1 <- gravcal:::cohort_plausibility(tab[1:3, ])
  expect_identical(j1$tab$plausibility[1:3], c("ok", "ok", "device_outlier"))
})

test_that("calibrate_files() flags a firmware-style attenuation; print() shows it", {
  dir <- tempfile("plaus")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  p <- c(1.01, 0.99, 1.005, 0, 0, 0, 0.02, -0.015, 0.01)
  for (k in 1:3) {
    rec <- simulate_recording(hours = 12, sf = 12.5, params = p, seed = k)
    v <- as.matrix(rec[, c("x", "y", "z")])
    if (k == 2) v <- round(v * 0.93 * 256) / 256  # the raw signal attenuated by 7 %
    gravcal:::write_cwa(v, file.path(dir, sprintf("r%d.cwa", k)), sf = 12.5,
                        packed = FALSE, temperature = rec$temperature,
                        device_id = 4321)
  }
  res <- calibrate_files(dir, method = "lightweight", outdir = file.path(dir, "out"))
  expect_identical(res$serial, rep("4321", 3))
  expect_identical(res$status, rep("ok", 3))
  expect_identical(res$plausibility, c("ok", "attenuated", "ok"))
  expect_identical(names(res)[match("pooled", names(res)) + 1:2],
                   c("plausibility", "plausibility_note"))
  expect_equal(attr(res, "devices")$serial, "4321")
  # the attenuated recording's scales: 1 / 0.93 times the others'
  expect_equal(res$scale.x[2] / res$scale.x[1], 1 / 0.93, tolerance = 0.01)
  fit <- attr(res, "fits")[[2]]
  expect_identical(fit$plausibility$flag, "attenuated")
  expect_output(print(fit), "plausibility: attenuated")
  expect_false(any(grepl("plausibility", capture.output(print(attr(res, "fits")[[1]])))))
  # the table written holds the flags
  csv <- utils::read.csv(file.path(dir, "out", "calibration.csv"), stringsAsFactors = FALSE)
  expect_identical(csv$plausibility, res$plausibility)
})

test_that("print() of a fit beyond omconvert's bounds says so", {
  set.seed(5)
  p <- c(1.24, 1.0, 0.98, 0, 0, 0, 0.02, 0.01, -0.01)
  rec <- simulate_recording(hours = 12, sf = 10, params = p, seed = 3)
  fit <- calibrate(rec, sf = 10, method = "lightweight")
  expect_identical(fit$status, "ok")
  expect_output(print(fit), "plausibility: out_of_bounds - beyond omconvert's bounds")
})

# A cohort table with temperature offsets: `co` 9 columns (scale, offset,
# temperature offset), one standard error per group.
cohort_tab_t <- function(co, se, serial, meantemp = 28) {
  cols <- c("scale.x", "scale.y", "scale.z", "offset.x", "offset.y", "offset.z",
            "temperature.offset.x", "temperature.offset.y", "temperature.offset.z")
  co <- matrix(co, ncol = 9, dimnames = list(NULL, cols))
  se <- matrix(rep(se, each = nrow(co)), nrow(co), 9,
               dimnames = list(NULL, paste0(cols, ".se")))
  data.frame(file = sprintf("r%02d.cwa", seq_len(nrow(co))), status = "ok", co, se,
             meantempcal = meantemp, serial = serial, pooled = FALSE,
             stringsAsFactors = FALSE, check.names = FALSE)
}

test_that("plausible_bounds() states a practical minimum change per coefficient", {
  b <- plausible_bounds()
  # bench/results/enmo-sensitivity.md: the changes that move a day's ENMO
  # by about 1 mg (5 mg offsets, 0.5 % scales; 1 mg per degree C = 5 mg
  # over the wrist's usual 4 degrees C from its mean)
  expect_equal(b$practical_min, c(0.005, 0.005, 0.005, 0.001))
  expect_true(all(nzchar(b$practical_source)))
  h <- attr(b, "history")
  expect_equal(h[c("min_reference", "temperature_flat_sd", "temperature_stuck_hours")],
               list(min_reference = 2L, temperature_flat_sd = 0.01,
                    temperature_stuck_hours = 12))
})

# Coefficients of 8 devices of 3-4 recordings (`n`): each device's scales
# (around 1, sd 1 %), offsets (sd 20 mg) and temperature offsets (sd 0.5 mg
# per degree C), its recordings that plus differences of sd `within`
# (scale, offset, temperature offset; the scale's relative to it when
# `relative`). One row a recording.
device_cohort <- function(n, within, relative = FALSE) {
  do.call(rbind, lapply(n, function(k) {
    p <- c(1 + stats::rnorm(3, sd = 0.01), stats::rnorm(3, sd = 0.02),
           stats::rnorm(3, sd = 0.0005))
    t(replicate(k, p + c((if (relative) p[1:3] else 1) * stats::rnorm(3, sd = within[1]),
                         stats::rnorm(3, sd = within[2]), stats::rnorm(3, sd = within[3]))))
  }))
}

test_that("a device outlier needs a change of practical size, not only a large z", {
  set.seed(41)
  # 8 devices of 3-4 recordings that agree within a device to 0.5 mg and
  # 0.03 % (fits of 26 h), standard errors 0.2 mg and 0.02 %
  n <- rep(c(3, 4), 4)
  co <- device_cohort(n, c(0.0003, 0.0005, 0.00002))
  serial <- rep(sprintf("S%d", 1:8), n)
  se <- c(0.0002, 0.0002, 0.0002, 0.0002, 0.0002, 0.0002, 0.00001, 0.00001, 0.00001)
  tab <- cohort_tab_t(co, se, serial)
  expect_identical(unique(gravcal:::cohort_plausibility(tab)$tab$plausibility), "ok")
  # recording 2 of S1: offset.y 3.5 mg and temperature.offset.z 0.24 mg per
  # degree C from its device's others (the issue's clean recording);
  # recording 6 of S2: offset.x 50 mg (a jump)
  tab$offset.y[2] <- stats::median(tab$offset.y[c(1, 3)]) + 0.0035
  tab$temperature.offset.z[2] <- stats::median(tab$temperature.offset.z[c(1, 3)]) + 0.00024
  tab$offset.x[6] <- tab$offset.x[6] + 0.05
  j <- gravcal:::cohort_plausibility(tab)
  expect_identical(j$tab$plausibility[2], "ok")
  expect_identical(j$tab$plausibility[6], "device_outlier")
  expect_match(j$tab$plausibility_note[6], "offset.x .*\\(\\+(49|50)[.][0-9] mg, z = ")
  expect_identical(sum(j$tab$plausibility != "ok"), 1L)
  # statistically, recording 2 does differ (z above 4 for both): only the
  # practical minimum keeps it unflagged
  d <- j$devices[j$devices$serial == "S1", ]
  zof <- function(col) {
    u <- sqrt(tab[[paste0(col, ".se")]][2]^2 +
                (1.2533 * tab[[paste0(col, ".se")]][2] / sqrt(d$reference_recordings))^2 +
                d[[paste0("spread.", col)]]^2)
    (tab[[col]][2] - d[[paste0("ref.", col)]]) / u
  }
  expect_gt(zof("offset.y"), 4)
  expect_gt(zof("temperature.offset.z"), 4)
  # twice as large, beyond the practical minimum (7 mg, 0.48 mg per degree
  # C stays below 1): flagged for the offset only
  tab$offset.y[2] <- tab$offset.y[2] + 0.0035
  tab$temperature.offset.z[2] <- tab$temperature.offset.z[2] + 0.00024
  j2 <- gravcal:::cohort_plausibility(tab)
  expect_identical(j2$tab$plausibility[2], "device_outlier")
  expect_match(j2$tab$plausibility_note[2], "offset.y")
  expect_no_match(j2$tab$plausibility_note[2], "temperature.offset.z")
  # a temperature offset 1.5 mg per degree C off, and a scale 0.7 % off
  tab$temperature.offset.x[9] <- tab$temperature.offset.x[9] + 0.0015
  tab$scale.z[12] <- tab$scale.z[12] * 1.007
  tab$scale.y[13] <- tab$scale.y[13] * 1.003  # 0.3 %: below the minimum
  j3 <- gravcal:::cohort_plausibility(tab)
  expect_identical(j3$tab$plausibility[c(9, 12, 13)], c("device_outlier", "device_outlier", "ok"))
  expect_match(j3$tab$plausibility_note[9], "temperature.offset.x .*\\+1[.][45][0-9] mg per degree C")
  expect_match(j3$tab$plausibility_note[12], "scale.z .*\\+0[.]7[0-9] %")
})

test_that("the issue's cohort: recordings 1.5 mg and 0.1 % apart are not flagged, faults are", {
  set.seed(44)
  n <- rep(c(3, 4), 4)
  co <- device_cohort(n, c(0.001, 0.0015, 0.00005), relative = TRUE)
  serial <- rep(sprintf("S%d", 1:8), n)
  tab <- cohort_tab_t(co, c(rep(0.0003, 6), rep(0.00003, 3)), serial)
  j <- gravcal:::cohort_plausibility(tab)
  expect_identical(unique(j$tab$plausibility), "ok")
  # faults: a 50 mg offset jump (4), an attenuated recording (11: the raw
  # signal x 0.95, scales / 0.95), an implausible gain (20: refused)
  tab$offset.x[4] <- tab$offset.x[4] + 0.05
  tab[11, c("scale.x", "scale.y", "scale.z")] <- tab[11, c("scale.x", "scale.y", "scale.z")] / 0.95
  tab$status[20] <- "implausible"
  j <- gravcal:::cohort_plausibility(tab)
  expect_identical(j$tab$plausibility[c(4, 11, 20)],
                   c("device_outlier", "attenuated", "out_of_bounds"))
  expect_identical(sum(j$tab$plausibility != "ok"), 3L)
})

test_that("a device's reference leaves out the recordings the run flags", {
  set.seed(45)
  p <- c(1.01, 0.99, 1.005, 0.02, -0.01, 0.015)
  co <- device_rows(p, 4, 0.0005)
  co[2, 1:3] <- co[2, 1:3] / 0.95      # attenuated
  co[4, 4] <- co[4, 4] + 0.03          # an offset jump of 30 mg
  # a second device, clean
  co <- rbind(co, device_rows(c(1, 1.01, 0.995, -0.01, 0.01, 0), 3, 0.0005))
  tab <- cohort_tab(co, 0.0005, rep(c("A", "B"), c(4, 3)))
  j <- gravcal:::cohort_plausibility(tab)
  expect_identical(j$tab$plausibility,
                   c("ok", "attenuated", "ok", "device_outlier", "ok", "ok", "ok"))
  a <- j$devices[j$devices$serial == "A", ]
  expect_identical(a$reference_files, "r01.cwa; r03.cwa")
  expect_identical(a$left_out_files, "r02.cwa; r04.cwa")
  expect_equal(a$reference_recordings, 2)
  expect_equal(a$ref.offset.x, mean(co[c(1, 3), 4]))
  expect_equal(a$ref.scale.y, mean(co[c(1, 3), 2]))
  # the note names the reference of 2 recordings
  expect_match(j$tab$plausibility_note[4], "median of 2 recordings")
  b <- j$devices[j$devices$serial == "B", ]
  expect_identical(b$reference_files, "r05.cwa; r06.cwa; r07.cwa")
  expect_identical(b$left_out_files, "")
  # a device of 3 with 2 flagged keeps all 3 in its reference (fewer than
  # min_reference would remain)
  co3 <- device_rows(p, 3, 0.0005)
  co3[1, 4] <- co3[1, 4] + 0.03
  co3[2, 5] <- co3[2, 5] - 0.03
  j3 <- gravcal:::cohort_plausibility(cohort_tab(co3, 0.0005, "C"))
  expect_identical(j3$tab$plausibility, c("device_outlier", "device_outlier", "ok"))
  expect_identical(j3$devices$reference_files, "r01.cwa; r02.cwa; r03.cwa")
})

test_that("a temperature that does not vary is a stuck sensor: alone over 12 h, or against the device", {
  set.seed(46)
  co <- device_rows(c(1.01, 0.99, 1.005, 0.02, -0.01, 0.015), 4, 0.0005)
  tab <- cohort_tab(co, 0.0005, "T1")
  tab$hours <- c(26, 26, 26, 6)
  tab$temperature_flat <- c(FALSE, TRUE, FALSE, TRUE)
  j <- gravcal:::cohort_plausibility(tab)
  expect_identical(j$tab$plausibility, c("ok", "temperature_stuck", "ok", "temperature_stuck"))
  expect_match(j$tab$plausibility_note[2], "temperature stuck: the temperature does not vary (sd < 0.01 degrees C) over 26.0 h",
               fixed = TRUE)
  expect_match(j$tab$plausibility_note[4], "over 6.0 h while 2 other recording(s) of device T1 vary",
               fixed = TRUE)
  # left out of the device's reference
  expect_identical(j$devices$reference_files, "r01.cwa; r03.cwa")
  # 6 h without a device whose temperature is seen to vary: not flagged;
  # 26 h alone (no serial): flagged
  tab2 <- tab
  tab2$temperature_flat <- c(NA, NA, NA, TRUE)
  expect_identical(gravcal:::cohort_plausibility(tab2)$tab$plausibility, rep("ok", 4))
  tab3 <- tab[2, ]
  tab3$serial <- NA_character_
  expect_identical(gravcal:::cohort_plausibility(tab3)$tab$plausibility, "temperature_stuck")
  # a table without the column (GGIR-compatible mode, older tables)
  expect_identical(gravcal:::cohort_plausibility(tab[setdiff(names(tab), "temperature_flat")])$tab$plausibility,
                   rep("ok", 4))
})

test_that("calibrate() in gravcal's own modes flags a stuck temperature sensor; GGIR-compatible mode does not look", {
  rec <- simulate_recording(hours = 13, sf = 10, seed = 47, tempoffset = c(0.001, -0.0005, 0.0008))
  stuck <- rec
  stuck$temperature <- stuck$temperature[1]
  for (m in c("lightweight", "ggir")) {
    f <- suppressWarnings(calibrate(stuck, sf = 10, method = m))
    expect_identical(f$status, "ok")
    expect_true(f$temperature_check$stuck, label = m)
    expect_identical(unname(f$tempoffset), c(0, 0, 0))
    expect_output(print(f), "plausibility: temperature_stuck - temperature stuck: the temperature ")
    if (m == "lightweight") {
      expect_match(f$temperature_check$note, sprintf("reads %.2f degrees C", rec$temperature[1]),
                   fixed = TRUE)
    }
    # the same recording with its temperature: not stuck, temperature term fitted
    g <- calibrate(rec, sf = 10, method = m)
    expect_false(g$temperature_check$stuck)
    expect_false(g$temperature_check$flat)
    expect_true(any(g$tempoffset != 0))
    expect_no_match(paste(capture.output(print(g)), collapse = "\n"), "temperature_stuck")
    # 6 h: flat, but too short to say alone
    s6 <- stuck[seq_len(6 * 3600 * 10), ]
    f6 <- suppressWarnings(calibrate(s6, sf = 10, method = m))
    expect_true(f6$temperature_check$flat)
    expect_false(f6$temperature_check$stuck)
  }
  # no temperature: nothing to judge
  nt <- calibrate(rec[c("time", "x", "y", "z")], sf = 10)
  expect_false(nt$temperature_check$available)
  expect_false(nt$temperature_check$stuck)
  # GGIR-compatible mode keeps GGIR's outcome and adds no check
  fc <- suppressWarnings(calibrate(stuck, sf = 10, method = "ggir", ggir_compat = TRUE))
  expect_null(fc$temperature_check)
})

test_that("calibrate_files() flags a stuck temperature sensor, both methods", {
  skip_if_quick()
  dir <- tempfile("stuck")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  p <- c(1.01, 0.99, 1.005, 0, 0, 0, 0.02, -0.015, 0.01)
  for (k in 1:3) {
    rec <- simulate_recording(hours = 13, sf = 12.5, params = p, seed = 60 + k,
                              tempoffset = c(0.001, -0.0005, 0.0008))
    temp <- rec$temperature
    if (k == 3) temp[] <- temp[1]
    gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), file.path(dir, sprintf("r%d.cwa", k)),
                        sf = 12.5, packed = FALSE, temperature = temp, device_id = 77)
  }
  for (m in c("ggir", "lightweight")) {
    res <- suppressWarnings(calibrate_files(dir, method = m, outdir = file.path(dir, paste0("out-", m))))
    expect_identical(res$status, rep("ok", 3))
    expect_identical(res$temperature_flat, c(FALSE, FALSE, TRUE))
    expect_identical(res$plausibility, c("ok", "ok", "temperature_stuck"), label = m)
    expect_match(res$plausibility_note[3], "temperature stuck")
    expect_identical(attr(res, "fits")[[3]]$plausibility$flag, "temperature_stuck")
  }
})

test_that("a temperature no worn or resting device has is flagged: the fit, print() and the cohort", {
  lim <- attr(plausible_bounds(), "history")$temperature_range
  expect_identical(lim, c(-20, 70))
  tc <- gravcal:::temperature_check(26, TRUE, temps = c(301.2, 302.5, 300.9))
  expect_true(tc$implausible)
  expect_match(tc$range_note, "the sensor reads 300.9 to 302.5 degrees C, outside the -20 to 70", fixed = TRUE)
  # at the edges: inside; just beyond: flagged; a mean where no windows are kept
  expect_false(gravcal:::temperature_check(26, TRUE, temps = c(-20, 70))$implausible)
  expect_true(gravcal:::temperature_check(26, TRUE, temps = c(25, 70.1))$implausible)
  expect_true(gravcal:::temperature_check(26, TRUE, flat = FALSE, mean_temp = -40)$implausible)
  expect_false(gravcal:::temperature_check(26, TRUE, flat = FALSE, mean_temp = 31)$implausible)
  # no temperature: nothing judged
  expect_false(gravcal:::temperature_check(26, FALSE, temps = numeric(0))$implausible)
  # a recording whose temperature was read in Kelvin: both own modes flag it
  rec <- simulate_recording(hours = 13, sf = 10, seed = 48, tempoffset = c(0.001, -0.0005, 0.0008))
  kelvin <- rec
  kelvin$temperature <- kelvin$temperature + 273.15
  for (m in c("lightweight", "ggir")) {
    f <- suppressWarnings(calibrate(kelvin, sf = 10, method = m))
    expect_true(f$temperature_check$implausible, label = m)
    expect_identical(gravcal:::fit_plausibility(f)$flag, "temperature_implausible", label = m)
    expect_output(print(f), "plausibility: temperature_implausible - temperature implausible: the sensor reads 29")
    g <- calibrate(rec, sf = 10, method = m)
    expect_false(g$temperature_check$implausible, label = m)
  }
  # in a cohort table: by its mean temperature, and left out of the device's reference
  set.seed(49)
  co <- device_rows(c(1.01, 0.99, 1.005, 0.02, -0.01, 0.015), 4, 0.0005)
  tab <- cohort_tab(co, 0.0005, "T2")
  tab$meantempcal <- c(30.1, 303.4, 29.5, 31.0)
  j <- gravcal:::cohort_plausibility(tab)
  expect_identical(j$tab$plausibility, c("ok", "temperature_implausible", "ok", "ok"))
  expect_match(j$tab$plausibility_note[2], "temperature implausible: the sensor reads 303.4 degrees C", fixed = TRUE)
  expect_false(grepl("r02.cwa", j$devices$reference_files, fixed = TRUE))
})
