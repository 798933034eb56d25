# Coefficients that travel between tools (issue 31, item 3): read_coefs(),
# write_coefs(), apply_calibration() with a row of coefficients and
# compare_coefs(). The hand-written files below follow each tool's own
# source (named at each test); the expected calibrated samples are computed
# here with each tool's own formula, not with gravcal's conversion.

# A recording with a temperature column and a temperature effect, and
# gravcal's GGIR-method fit of it (which uses the temperature term).
coef_fixture <- local({
  cache <- NULL
  function() {
    if (is.null(cache)) {
      rec <- simulate_recording(hours = 30, sf = 10, seed = 31,
                                tempoffset = c(0.003, -0.002, 0.0015))
      fit <- calibrate(rec, sf = 10, method = "ggir")
      # and without the temperature term
      fit_nt <- calibrate(rec, sf = 10, method = "ggir", use_temp = FALSE)
      cache <<- list(rec = rec, fit = fit, fit_nt = fit_nt)
    }
    cache
  }
})

# A fit of GGIR's model with coefficients far from the identity, so that a
# slip in a conversion (offset before or after the scale, the temperature
# centred or not) moves the calibrated samples by far more than 1e-12 g.
far_fit <- function(fit) {
  diag(fit$K) <- c(1.05, 0.96, 1.02)
  fit$offset[] <- c(0.05, -0.03, 0.02)
  fit$tempoffset[] <- c(0.004, -0.0025, 0.0015)
  fit$meantemp <- 27.3
  fit
}

xyz_max_diff <- function(a, b) {
  max(abs(c(a$x - b$x, a$y - b$y, a$z - b$z)))
}

test_that("round trips through every format give the same calibrated samples to 1e-12 g", {
  fx <- coef_fixture()
  expect_identical(fx$fit$status, "ok")
  expect_true(any(fx$fit$tempoffset != 0))
  expect_true(is.finite(fx$fit$meantemp))
  d <- snap_dir("coefs-1")
  ext <- c(ggir = ".csv", actipy = ".json", ukb = "-summary.json",
           omconvert = ".txt", skdh = ".json")
  n <- 0
  expect_true(all(fx$fit_nt$tempoffset == 0))
  for (fit in list(fx$fit, far_fit(fx$fit), fx$fit_nt)) {
    direct <- apply_calibration(fx$rec, fit)
    # the fit does change the samples, by more than the tolerance
    expect_gt(xyz_max_diff(direct, fx$rec), 1e-3)
    for (fmt in names(ext)) {
      f <- file.path(d, paste0("p01", ext[[fmt]]))
      write_coefs(list(p01 = fit), f, format = fmt)
      for (how in c(fmt, "auto")) {
        cf <- read_coefs(f, format = how)
        expect_identical(nrow(cf), 1L)
        expect_identical(cf$tool, fmt)
        expect_identical(coef_key(cf$file), "p01")
        back <- apply_calibration(fx$rec, cf)
        expect_lt(xyz_max_diff(back, direct), 1e-12)
        n <- n + 1
      }
      # the centred tools keep the mean temperature; the others are 0
      cf <- read_coefs(f, format = fmt)
      if (all(fit$tempoffset == 0)) {
        expect_identical(cf$meantemp, NA_real_)
      } else if (fmt %in% c("ggir", "omconvert", "skdh")) {
        expect_equal(cf$meantemp, fit$meantemp, tolerance = 1e-14)
      } else {
        expect_identical(cf$meantemp, 0)
      }
      # and back out again, from the coefficients read (a data frame)
      f2 <- file.path(d, paste0("again", ext[[fmt]]))
      write_coefs(cf, f2, format = fmt)
      expect_lt(xyz_max_diff(apply_calibration(fx$rec, read_coefs(f2)),
                             direct), 1e-12)
    }
  }
  expect_identical(n, 30)
})

test_that("a conversion slip would be caught: centring matters by far more than 1e-12 g", {
  fx <- coef_fixture()
  fit <- far_fit(fx$fit)
  d <- snap_dir("coefs-2")
  f <- file.path(d, "p01.json")
  write_coefs(list(p01 = fit), f, format = "actipy")
  cf <- read_coefs(f)
  # reading actipy's uncentred intercept as if it were centred on the
  # fit's mean temperature moves every sample by t * meantemp
  wrong <- cf
  wrong$meantemp <- fit$meantemp
  expect_gt(xyz_max_diff(apply_calibration(fx$rec, wrong),
                         apply_calibration(fx$rec, fit)), 0.01)
})

test_that("temperature offsets without meantemp are refused, never written as meantempcal 0", {
  # GGIR applies (T - meantempcal) * temperature.offset: a mean temperature
  # written as 0 would move every calibrated sample by temperature.offset *
  # meantemp (issue 44)
  fx <- coef_fixture()
  expect_true(any(fx$fit$tempoffset != 0))
  d <- snap_dir("coefs-meantemp")
  out <- file.path(d, "coefs.csv")
  msg <- paste0("`fits`: the fit for \"p01.bin\" has temperature offsets but ",
                "no `meantemp`: GGIR's coefficient file needs the mean ",
                "temperature they are centred on")
  no_mt <- fx$fit
  no_mt$meantemp <- NA_real_
  expect_error(write_coefs(list(p01.bin = no_mt), out), msg, fixed = TRUE)
  expect_error(write_coefs(list(p01.bin = no_mt), out, format = "ggir"), msg,
               fixed = TRUE)
  gone <- fx$fit
  gone["meantemp"] <- list(NULL)
  expect_null(gone$meantemp)
  expect_error(write_coefs(list(p01.bin = gone), out), msg, fixed = TRUE)
  expect_false(file.exists(out))
  # a g.calibrate() result names it meantempcal
  g <- fx$fit[["ggir"]]
  expect_true(any(g$tempoffset != 0))
  g["meantempcal"] <- list(NULL)
  for (w in list(function() write_coefs(list(p01.bin = g), out),
                 function() write_coefs(list(p01.bin = g), out, "ggir"))) {
    expect_error(w(), paste0("the fit for \"p01.bin\" has temperature ",
                             "offsets but no `meantempcal`: GGIR's"),
                 fixed = TRUE)
  }
  expect_false(file.exists(out))
  # the other tools' files need it as much
  expect_error(write_coefs(list(p01 = no_mt), file.path(d, "p01.json"), "actipy"),
               "has temperature offsets but no `meantemp`: the coefficients need",
               fixed = TRUE)
  # without temperature offsets: written as before, meantempcal 0
  nt <- fx$fit_nt
  expect_true(all(nt$tempoffset == 0))
  expect_identical(nt$meantemp, NA_real_)
  write_coefs(list(p01.bin = nt), out)
  expect_identical(utils::read.csv(out)$meantempcal, 0L)
  write_coefs(list(p01.bin = nt), out, "ggir")
  expect_identical(utils::read.csv(out)$meantempcal, 0L)
  nt["meantemp"] <- list(NULL)
  write_coefs(list(p01.bin = nt), out)
  expect_identical(utils::read.csv(out)$meantempcal, 0L)
  # with it: written, and GGIR's formula on the file is gravcal's calibration
  write_coefs(list(p01.bin = fx$fit), out)
  cf <- utils::read.csv(out)
  expect_equal(cf$meantempcal, fx$fit$meantemp, tolerance = 1e-14)
  rec <- fx$rec
  gx <- (rec$x + cf$offset.x) * cf$scale.x +
    (rec$temperature - cf$meantempcal) * cf$temperature.offset.x
  expect_lt(max(abs(gx - apply_calibration(rec, fx$fit)$x)), 1e-12)
})

test_that("GGIR's backup.cal.coef written by hand is read to its coefficients", {
  # columns as GGIR's g.calibrate() output / backup.cal.coef (the ones
  # write_coefs() documents); GGIR applies (v + offset) * scale +
  # (T - meantempcal) * temperature.offset
  d <- snap_dir("coefs-3")
  f <- file.path(d, "cal.csv")
  writeLines(c(
    "filename,scale.x,scale.y,scale.z,offset.x,offset.y,offset.z,temperature.offset.x,temperature.offset.y,temperature.offset.z,meantempcal",
    "a.bin,1.01,0.98,1.002,0.012,-0.02,0.007,0.001,-0.0005,0.0002,24.5",
    "b.bin,0.995,1.004,1,-0.004,0.003,0.001,0,0,0,0"), f)
  cf <- read_coefs(f)
  expect_identical(cf$file, c("a.bin", "b.bin"))
  expect_identical(cf$tool, c("ggir", "ggir"))
  expect_identical(unlist(cf[1, coef_names()], use.names = FALSE),
                   c(1.01, 0.98, 1.002, 0.012, -0.02, 0.007, 0.001, -0.0005,
                     0.0002))
  expect_identical(cf$meantemp, c(24.5, NA))
  v <- data.frame(x = 0.4, y = -0.7, z = 0.55, temperature = 31)
  got <- apply_calibration(v, cf[1, ])
  want <- (c(0.4, -0.7, 0.55) + c(0.012, -0.02, 0.007)) * c(1.01, 0.98, 1.002) +
    (31 - 24.5) * c(0.001, -0.0005, 0.0002)
  expect_equal(c(got$x, got$y, got$z), want, tolerance = 1e-14)
})

test_that("actipy's calibration info written by hand is read to its coefficients", {
  # keys of actipy.processing.calibrate_gravity()'s info dict; it applies
  # intercept + slope * v + slopeT * T (temperature not centred)
  d <- snap_dir("coefs-4")
  f <- file.path(d, "p02.json")
  writeLines(c("{", '  "CalibOK": 1,', '  "CalibErrorBefore(mg)": 12.5,',
               '  "CalibErrorAfter(mg)": 2.1,',
               '  "CalibxIntercept": 0.021, "CalibyIntercept": -0.013,',
               '  "CalibzIntercept": 0.0045,',
               '  "CalibxSlope": 1.012, "CalibySlope": 0.991, "CalibzSlope": 1.003,',
               '  "CalibxSlopeT": 0.0011, "CalibySlopeT": -0.0007, "CalibzSlopeT": 0.0002',
               "}"), f)
  cf <- read_coefs(f)
  expect_identical(cf$file, "p02")
  expect_identical(cf$tool, "actipy")
  expect_identical(cf$status, "ok")
  expect_identical(unlist(cf[c("scale.x", "scale.y", "scale.z")],
                          use.names = FALSE), c(1.012, 0.991, 1.003))
  expect_equal(unlist(cf[c("offset.x", "offset.y", "offset.z")],
                      use.names = FALSE),
               c(0.021, -0.013, 0.0045) / c(1.012, 0.991, 1.003),
               tolerance = 1e-15)
  expect_identical(cf$meantemp, 0)
  v <- data.frame(x = c(0.4, -0.9), y = c(-0.7, 0.1), z = c(0.55, 0.3),
                  temperature = c(31, 18))
  got <- apply_calibration(v, cf)
  for (i in 1:2) {
    want <- c(0.021, -0.013, 0.0045) +
      c(1.012, 0.991, 1.003) * c(v$x[i], v$y[i], v$z[i]) +
      c(0.0011, -0.0007, 0.0002) * v$temperature[i]
    expect_equal(c(got$x[i], got$y[i], got$z[i]), want, tolerance = 1e-14)
  }
  # without temperature slopes (actipy on data without temperature)
  writeLines('{"CalibxIntercept": 0.01, "CalibyIntercept": 0, "CalibzIntercept": 0, "CalibxSlope": 1.1, "CalibySlope": 1, "CalibzSlope": 1}', f)
  cf <- read_coefs(f, "actipy")
  expect_identical(unlist(cf[coef_names()[7:9]], use.names = FALSE), c(0, 0, 0))
  expect_identical(cf$meantemp, NA_real_)
  expect_identical(cf$status, NA_character_)
})

test_that("the UK Biobank pipeline's summaries and files.csv written by hand are read", {
  d <- snap_dir("coefs-5")
  v <- data.frame(x = 0.4, y = -0.7, z = 0.55, temperature = 29)
  # since biobankAccelerometerAnalysis #184 (device.py,
  # store_calibration_params): uncentred, intercept + slope v + slopeT T
  f <- file.path(d, "p03-summary.json")
  writeLines(c("{", '    "file-name": "/data/raw/p03.cwa",',
               '    "file-deviceID": 41234,',
               '    "calibration-xOffset(g)": -0.0123,',
               '    "calibration-yOffset(g)": 0.0204,',
               '    "calibration-zOffset(g)": 0.0066,',
               '    "calibration-xSlope": 1.0078,',
               '    "calibration-ySlope": 0.9952,',
               '    "calibration-zSlope": 1.0011,',
               '    "calibration-xSlopeTemp": 0.00081,',
               '    "calibration-ySlopeTemp": -0.00042,',
               '    "calibration-zSlopeTemp": 0.00013,',
               '    "calibration-errsBefore(mg)": 9.8,',
               '    "quality-goodCalibration": 1', "}"), f)
  cf <- read_coefs(f)
  expect_identical(cf$file, "p03.cwa")
  expect_identical(cf$tool, "ukb")
  expect_identical(cf$status, "ok")
  got <- apply_calibration(v, cf)
  want <- c(-0.0123, 0.0204, 0.0066) + c(1.0078, 0.9952, 1.0011) *
    c(0.4, -0.7, 0.55) + c(0.00081, -0.00042, 0.00013) * 29
  expect_equal(c(got$x, got$y, got$z), want, tolerance = 1e-14)
  # before #184 (accelerometer/device.py, storeCalibrationParams): the
  # temperature centred on calibration-meanDeviceTemp(C)
  f <- file.path(d, "p04-summary.json")
  writeLines(c("{", '"file-name": "p04.cwa",',
               '"calibration-xOffset(g)": -0.0123, "calibration-yOffset(g)": 0.0204,',
               '"calibration-zOffset(g)": 0.0066,',
               '"calibration-xSlope(g)": 1.0078, "calibration-ySlope(g)": 0.9952,',
               '"calibration-zSlope(g)": 1.0011,',
               '"calibration-xTemp(C)": 0.00081, "calibration-yTemp(C)": -0.00042,',
               '"calibration-zTemp(C)": 0.00013,',
               '"calibration-meanDeviceTemp(C)": 26.4,',
               '"quality-goodCalibration": 0', "}"), f)
  cf <- read_coefs(f, "ukb")
  expect_identical(cf$status, "failed")
  expect_identical(cf$meantemp, 26.4)
  got <- apply_calibration(v, cf)
  want <- c(-0.0123, 0.0204, 0.0066) + c(1.0078, 0.9952, 1.0011) *
    c(0.4, -0.7, 0.55) + c(0.00081, -0.00042, 0.00013) * (29 - 26.4)
  expect_equal(c(got$x, got$y, got$z), want, tolerance = 1e-14)
  # files.csv (utils.py, writeFilesWithCalibrationCoefs): the values it
  # passes to accProcess --calOffset --calSlope --calTemp --meanTemp
  f <- file.path(d, "files.csv")
  writeLines(c("fileName,calOffset,calSlope,calTemp,meanTemp",
               "p05.cwa,-0.0123 0.0204 0.0066,1.0078 0.9952 1.0011,0.00081 -0.00042 0.00013,26.4",
               "p06.cwa,0.01 0 0,1 1 1,0 0 0,20"), f)
  cf <- read_coefs(f)
  expect_identical(cf$file, c("p05.cwa", "p06.cwa"))
  got <- apply_calibration(v, cf[1, ])
  expect_equal(c(got$x, got$y, got$z), want, tolerance = 1e-14)
  expect_identical(cf$meantemp[2], NA_real_)
})

test_that("omconvert's -info file written by hand is read to its coefficients", {
  # omconvert.c writes "Calibration: %.10f,..." (scale x3, offset x3,
  # tempOffset x3, referenceTemperature) and "Calibration-Result: %d";
  # omcalibrate.c applies (v + offset) * scale + (T - referenceTemperature)
  # * tempOffset
  d <- snap_dir("coefs-6")
  f <- file.path(d, "p07.txt")
  writeLines(c("Calibration-Result: 0",
               "Calibration: 1.0123456789,0.9876543210,1.0011111111,0.0150000000,-0.0220000000,0.0030000000,0.0012000000,-0.0006000000,0.0001000000,25.7500000000",
               "Calibration-Stationary-Count: 812",
               "Calibration-Stationary-Error-Pre: 0.0134000000",
               "Calibration-Stationary-Error-Post: 0.0031000000"), f)
  cf <- read_coefs(f)
  expect_identical(cf$tool, "omconvert")
  expect_identical(cf$status, "ok")
  expect_identical(cf$meantemp, 25.75)
  v <- data.frame(x = 0.4, y = -0.7, z = 0.55, temperature = 22)
  got <- apply_calibration(v, cf)
  want <- (c(0.4, -0.7, 0.55) + c(0.015, -0.022, 0.003)) *
    c(1.0123456789, 0.9876543210, 1.0011111111) +
    (22 - 25.75) * c(0.0012, -0.0006, 0.0001)
  expect_equal(c(got$x, got$y, got$z), want, tolerance = 1e-14)
})

test_that("scikit-digital-health's results written by hand are read, with the mean temperature given", {
  # CalibrateAccelerometer.predict() returns "offset", "scale" and
  # "temperature scale" (shape (1, 3)) and applies (y + d) s + (T - mean T) m,
  # the mean temperature not returned
  d <- snap_dir("coefs-7")
  f <- file.path(d, "p08.json")
  writeLines('{"offset": [0.011, -0.004, 0.02], "scale": [1.004, 0.997, 1.01], "temperature scale": [[0.0009, -0.0003, 0.0002]]}', f)
  expect_error(read_coefs(f), "`meantemp` is needed")
  cf <- read_coefs(f, meantemp = 23.1)
  expect_identical(cf$tool, "skdh")
  expect_identical(cf$meantemp, 23.1)
  v <- data.frame(x = 0.4, y = -0.7, z = 0.55, temperature = 30)
  got <- apply_calibration(v, cf)
  want <- (c(0.4, -0.7, 0.55) + c(0.011, -0.004, 0.02)) * c(1.004, 0.997, 1.01) +
    (30 - 23.1) * c(0.0009, -0.0003, 0.0002)
  expect_equal(c(got$x, got$y, got$z), want, tolerance = 1e-14)
})

test_that("files saved with a byte order mark are read", {
  d <- snap_dir("coefs-bom")
  bom <- as.raw(c(0xef, 0xbb, 0xbf))
  f <- file.path(d, "p.json")
  writeBin(c(bom, charToRaw('{"CalibxIntercept": 0.01, "CalibyIntercept": 0, "CalibzIntercept": 0, "CalibxSlope": 1.1, "CalibySlope": 1, "CalibzSlope": 1}')), f)
  expect_identical(read_coefs(f)$scale.x, 1.1)
  g <- file.path(d, "g.csv")
  writeBin(c(bom, charToRaw(paste0(
    "filename,scale.x,scale.y,scale.z,offset.x,offset.y,offset.z,",
    "temperature.offset.x,temperature.offset.y,temperature.offset.z,",
    "meantempcal\na.bin,1.1,1,1,0,0,0,0,0,0,0\n"))), g)
  expect_identical(read_coefs(g)$scale.x, 1.1)
})

test_that("bad input is an error naming the argument", {
  fx <- coef_fixture()
  d <- snap_dir("coefs-8")
  f <- file.path(d, "p.json")
  expect_error(read_coefs(f), "`file`")
  expect_error(read_coefs(1), "`file` must be paths")
  writeLines('{"CalibxIntercept": 0.01}', f)
  expect_error(read_coefs(f, format = "nope"), "`format`")
  expect_error(read_coefs(f, "actipy"), "lacks the key \"CalibyIntercept\"")
  writeLines('{"CalibxIntercept": NaN, "CalibyIntercept": 0, "CalibzIntercept": 0, "CalibxSlope": 1, "CalibySlope": 1, "CalibzSlope": 1}', f)
  expect_error(read_coefs(f), "`file`.*not 3 finite")
  writeLines('{"something": 1}', f)
  expect_error(read_coefs(f), "`format`")
  g <- file.path(d, "g.csv")
  writeLines(c("filename,scale.x,scale.y,scale.z,offset.x,offset.y,offset.z,temperature.offset.x,temperature.offset.y,temperature.offset.z,meantempcal",
               "a.bin,1,1,Inf,0,0,0,0,0,0,0"), g)
  expect_error(read_coefs(g), "`file`.*not all finite")
  writeLines(c("filename,scale.x,scale.y,offset.x", "a.bin,1,1,0"), g)
  expect_error(read_coefs(g, "ggir"), "lacks the column\\(s\\) `scale.z`")
  o <- file.path(d, "o.txt")
  writeLines("Calibration: 1,1,1,0,0,0", o)
  expect_error(read_coefs(o), "10 finite numbers")
  writeLines('{"offset": [0, 0, 0], "scale": [1, 1, 1]}', f)
  expect_error(read_coefs(f, "skdh", meantemp = NA), "`meantemp`")
  expect_error(read_coefs(g, "ggir", meantemp = 20), "`meantemp` is only")
  # writing
  expect_error(write_coefs(list(p = fx$fit), file.path(d, "a.json"),
                           format = "csv"), "`format`")
  expect_error(write_coefs(list(p = fx$fit, q = fx$fit),
                           file.path(d, "a.json"), format = "actipy"),
               "one path per recording")
  expect_error(write_coefs(list(fx$fit), file.path(d, "a.json"), "actipy"),
               "`fits` must be named")
  lw <- calibrate(fx$rec, sf = 10)
  if (any(lw$K[row(lw$K) != col(lw$K)] != 0)) {
    expect_error(write_coefs(list(p = lw), file.path(d, "a.json"), "actipy"),
                 "`fits`.*cross-axis")
  }
  expect_error(write_coefs(data.frame(file = "a", scale.x = 1), f, "actipy"),
               "`fits` lacks the column\\(s\\) `scale.y`")
  bad <- read_coefs(g <- {
    writeLines(c("filename,scale.x,scale.y,scale.z,offset.x,offset.y,offset.z,temperature.offset.x,temperature.offset.y,temperature.offset.z,meantempcal",
                 "a.bin,1,1,1,0,0,0,0,0,0,0", "b.bin,1,1,1,0,0,0,0,0,0,0"), g)
    g
  })
  expect_error(apply_calibration(fx$rec, bad), "`fit` must be one row")
  bad$offset.x[1] <- NA
  expect_error(apply_calibration(fx$rec, bad[1, ]), "`fit`.*not all finite")
  expect_error(write_coefs(list(p = fx$fit), file.path(d, "no", "a.json"),
                           "actipy"), "`file`: the folder")
})

test_that("compare_coefs() gives the differences, z values and mapping difference", {
  fx <- coef_fixture()
  fit <- fx$fit
  d <- snap_dir("coefs-9")
  f <- file.path(d, "p01.json")
  write_coefs(list(p01 = fit), f, format = "actipy")
  cmp <- compare_coefs(list(p01.bin = fit), read_coefs(f))
  expect_s3_class(cmp, "gravcal_coef_comparison")
  expect_identical(nrow(cmp), 1L)
  expect_identical(c(cmp$tool_a, cmp$tool_b), c("gravcal", "actipy"))
  # the same calibration in two conventions: no difference once both are
  # at the same reference temperature
  expect_lt(cmp$mapping_mg, 1e-9)
  expect_lt(max(abs(unlist(cmp[paste0("d_", coef_names())]))), 1e-12)
  expect_identical(cmp$reference_temp, fit$meantemp)
  # a known change: offset.x by 0.01 g moves the mapping by scale.x * 10 mg
  # in every orientation; its z is the change over the fit's standard error
  moved <- read_coefs(f)
  moved$offset.x <- moved$offset.x + 0.01
  cmp <- compare_coefs(list(p01 = fit), moved)
  expect_equal(cmp$mapping_mg, 10 * fit$K[1, 1], tolerance = 1e-9)
  expect_equal(cmp$d_offset.x, 0.01, tolerance = 1e-9)
  expect_true(is.finite(fit$se[["o_x"]]))
  expect_equal(cmp$z_offset.x, 0.01 / fit$se[["o_x"]], tolerance = 1e-9)
  expect_equal(cmp$max_abs_z, max(abs(unlist(cmp[paste0("z_", coef_names())])),
                                  na.rm = TRUE))
  expect_output(print(cmp), "largest mapping difference: 1[0-9][.][0-9]+ mg")
  # unmatched recordings are reported, not dropped silently
  two <- rbind(moved, transform(moved, file = "p09"))
  cmp <- compare_coefs(list(p01 = fit), two)
  expect_identical(attr(cmp, "only_b"), "p09")
  expect_output(print(cmp), "1 only in `b`")
  expect_error(compare_coefs(list(p02 = fit), moved), "no recording in common")
})

test_that("calibrate_files(coefs = ) applies another tool's coefficients to each recording", {
  skip_if_quick()
  d <- snap_dir("coefs-cohort")
  raw <- file.path(d, "raw")
  dir.create(raw)
  for (i in 1:2) {
    rec <- simulate_recording(hours = 30, sf = 10, seed = 40 + i,
                              tempoffset = c(0.002, -0.001, 0.001))
    saveRDS(rec, file.path(raw, sprintf("p%02d.rds", i)))
  }
  own <- calibrate_files(raw, method = "ggir", outdir = file.path(d, "own"),
                         sf = 10)
  expect_true(all(own$status %in% c("ok", "high_error")))
  # another tool's coefficients for both: p01's own fit through actipy's
  # form, and for p02 a hand-made set (files named after the recordings)
  fits <- attr(own, "fits")
  write_coefs(list(p01 = fits[[1]]), file.path(d, "p01.json"), "actipy")
  writeLines('{"CalibxIntercept": 0.02, "CalibyIntercept": -0.01, "CalibzIntercept": 0.005, "CalibxSlope": 1.01, "CalibySlope": 0.99, "CalibzSlope": 1.002}',
             file.path(d, "p02.json"))
  cf <- read_coefs(file.path(d, c("p01.json", "p02.json")))
  res <- calibrate_files(raw, method = "ggir", outdir = file.path(d, "given"),
                         sf = 10, coefs = cf)
  expect_identical(res$status, c("given", "given"))
  expect_identical(res$message, paste0(
    "coefficients of actipy given (p0", 1:2, "), not fitted; the ",
    "recording's own fit: ", own$status))
  g <- attr(res, "fits")
  for (i in 1:2) {
    rec <- readRDS(file.path(raw, sprintf("p%02d.rds", i)))
    expect_lt(xyz_max_diff(apply_calibration(rec, g[[i]]),
                           apply_calibration(rec, cf[i, ])), 1e-12)
  }
  # p01: the same calibration as its own, so the same error on its points
  expect_equal(res$error_after_mg[1], own$error_after_mg[1], tolerance = 1e-9)
  expect_equal(res$error_before_mg, own$error_before_mg, tolerance = 1e-12)
  # p02: the error of the hand-made coefficients on p02's own rest points,
  # restated here from the points and actipy's formula
  pts <- g[[2]]$points
  expect_gt(NROW(pts), 10)
  a <- cbind(0.02 + 1.01 * pts$mean_x, -0.01 + 0.99 * pts$mean_y,
             0.005 + 1.002 * pts$mean_z)
  expect_equal(res$error_after_mg[2], err_mg(a), tolerance = 1e-9)
  expect_identical(res$parameters, c(0L, 0L))
  expect_true(all(is.na(res$scale.x.se)))
  expect_equal(res$scale.x, cf$scale.x, tolerance = 1e-15)
  # the cohort's own table against the given coefficients: p01 the same
  # calibration, p02 another
  cmp <- compare_coefs(own, cf)
  expect_identical(cmp$file, c("p01.rds", "p02.rds"))
  expect_lt(cmp$mapping_mg[1], 1e-9)
  expect_gt(cmp$mapping_mg[2], 1)
  expect_lt(cmp$max_abs_z[1], 1e-6)
  expect_true(is.finite(cmp$max_abs_z[2]))
  # GGIR's file holds the given coefficients
  gg <- read_coefs(file.path(d, "given", "calibration_ggir_coefs.csv"))
  expect_equal(gg$offset.x, cf$offset.x, tolerance = 1e-14)
  # the command line takes the same files: the same table
  cli <- suppressMessages(calibrate_cli(c(
    "--method", "ggir", "--out", file.path(d, "cli"), "--sf", "10", "--coefs",
    paste(file.path(d, c("p01.json", "p02.json")), collapse = ","), raw),
    quit = FALSE))
  expect_identical(cli$status, res$status)
  expect_identical(cli[c("scale.x", "offset.y", "error_after_mg")],
                   res[c("scale.x", "offset.y", "error_after_mg")])
  expect_error(calibrate_cli(c("--out", file.path(d, "cli2"), "--coefs",
                               file.path(d, "none.json"), raw), quit = FALSE),
               "`--coefs`: `file`: .*none.json.* is not a file")
  # bad input
  expect_error(calibrate_files(raw, method = "ggir",
                               outdir = file.path(d, "x"), sf = 10,
                               coefs = cf[1, ]),
               "`coefs` has no coefficients for 1 recording\\(s\\): \"p02.rds\"")
  expect_error(calibrate_files(raw, method = "ggir",
                               outdir = file.path(d, "x"), sf = 10,
                               coefs = cf, pool = "device"), "`pool")
  expect_error(calibrate_files(raw, method = "ggir",
                               outdir = file.path(d, "x"), sf = 10,
                               coefs = data.frame(file = "p01")),
               "`coefs` lacks the column")
})

test_that("write_ggir_coefs() is deprecated and writes what write_coefs() writes", {
  rec <- simulate_recording(hours = 30, sf = 10, seed = 4,
                            tempoffset = c(0.002, -0.001, 0.001))
  fit <- calibrate(rec, sf = 10, method = "ggir")
  a <- tempfile(fileext = ".csv")
  b <- tempfile(fileext = ".csv")
  write_coefs(list(p01.bin = fit), a)
  expect_warning(out <- write_ggir_coefs(list(p01.bin = fit), b), "write_coefs")
  expect_identical(readBin(b, "raw", 1e5), readBin(a, "raw", 1e5))
  expect_identical(out$filename, "p01.bin")
  expect_identical(out$scale.x, unname(diag(fit$K))[1])
})

test_that("the JSON of other tools is parsed, not searched as text", {
  d <- snap_dir("coefs-json")
  f <- file.path(d, "p09-summary.json")
  # Python's json module writes NaN and Infinity for missing values (the UK
  # Biobank pipeline's summary of a file it could not calibrate holds
  # them); a key's name inside another value's text is no key; escaped
  # quotes and \u escapes in the file name
  writeLines(c("{",
               '  "file-name": "/data/p\\"09\\u00e9.cwa",',
               '  "note": "\\"calibration-xOffset(g)\\": 5",',
               '  "calibration-errsBefore(mg)": NaN, "calibration-errsAfter(mg)": Infinity,',
               '  "calibration-xOffset(g)": -0.0123, "calibration-yOffset(g)": 0.0204,',
               '  "calibration-zOffset(g)": 0.0066,',
               '  "calibration-xSlope": 1.0078, "calibration-ySlope": 0.9952,',
               '  "calibration-zSlope": 1.0011,',
               '  "quality-goodCalibration": 1, "nested": {"calibration-xSlope": 7}',
               "}"), f)
  cf <- read_coefs(f)
  expect_identical(cf$file, "p\"09\u00e9.cwa")
  expect_identical(cf$offset.x, -0.0123 / 1.0078)
  expect_identical(cf$scale.x, 1.0078)
  # results nested in an object of their own (skdh saved by a script)
  g <- file.path(d, "p10.json")
  writeLines('{"CalibrateAccelerometer": {"offset": [0.011, -0.004, 0.02], "scale": [1.004, 0.997, 1.01], "temperature scale": [[0, 0, 0]]}}', g)
  expect_identical(read_coefs(g)$scale.y, 0.997)
  # a value Python wrote as NaN is not a finite coefficient: said so
  writeLines('{"CalibxIntercept": 0, "CalibyIntercept": 0, "CalibzIntercept": 0, "CalibxSlope": NaN, "CalibySlope": 1, "CalibzSlope": 1}', g)
  expect_error(read_coefs(g), "not 3 finite")
  # text that is not JSON: an error naming the file and what is wrong
  for (bad in c('{"CalibxSlope": 1,, "CalibySlope": 1}', '{"CalibxSlope": 1',
                '{"CalibxSlope": 1} extra', '{"CalibxSlope": tru}',
                '{"CalibxSlope": "a\\q"}')) {
    writeLines(bad, g)
    expect_error(read_coefs(g, "actipy"), "p10.json\" is not valid JSON")
  }
  writeLines('{"CalibxIntercept": {"a": 1}, "CalibyIntercept": 0, "CalibzIntercept": 0, "CalibxSlope": 1, "CalibySlope": 1, "CalibzSlope": 1}', g)
  expect_error(read_coefs(g), "\"CalibxIntercept\" is not a number")
  # what gravcal writes, it reads back (file names with quotes included)
  fx <- coef_fixture()
  out <- file.path(d, "p\"11-summary.json")
  write_coefs(list("p\"11.cwa" = fx$fit), out, "ukb")
  back <- read_coefs(out)
  expect_identical(back$file, "p\"11.cwa")
  v <- data.frame(x = 0.4, y = -0.7, z = 0.55, temperature = 29)
  expect_equal(unlist(apply_calibration(v, back)), unlist(apply_calibration(v, fx$fit)),
               tolerance = 1e-12)
})
