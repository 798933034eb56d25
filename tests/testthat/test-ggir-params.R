# GGIR's parameters (R/ggir-params.R): one table of names, defaults and
# checks behind g.calibrate() and calibrate(method = "ggir").

test_that("both front doors take their defaults and checks from one table", {
  own <- gravcal:::ggir_param_values("own")
  ggir <- gravcal:::ggir_param_values("ggir")
  k <- gravcal:::ggir_constants
  # the defaults GGIR uses (GGIR 3.3 load_params, g.calibrate)
  for (p in list(own, ggir)) {
    expect_identical(p$spherecrit, 0.3)
    expect_identical(p$minloadcrit, 168)
    expect_identical(p$chunksize, 1)
    expect_identical(p$reader, "native")
  }
  expect_identical(own[c("max_sd", "max_iter", "tol")],
                   list(max_sd = k$max_sd, max_iter = k$max_iter, tol = k$tol))
  expect_true(own$use_temp)
  expect_false(own$verbose)
  expect_false(ggir$printsummary)
  expect_null(ggir$rmc.noise)
  # each door under its own names only
  expect_identical(names(own), c("use_temp", "spherecrit", "minloadcrit",
                                 "chunksize", "max_sd", "max_iter", "tol",
                                 "verbose", "reader", "rmc"))
  # GGIR's rmc.* parameters of ad hoc csv files (GGIR 3.3-9 load_params()),
  # with GGIR's defaults
  rmc <- c("rmc.firstrow.acc", "rmc.firstrow.header", "rmc.header.length",
           "rmc.col.acc", "rmc.col.temp", "rmc.col.time", "rmc.unit.acc",
           "rmc.unit.temp", "rmc.unit.time", "rmc.format.time", "rmc.bitrate",
           "rmc.dynamic_range", "rmc.unsignedbit", "rmc.origin", "rmc.desiredtz",
           "rmc.configtz", "rmc.headername.sf", "rmc.headername.sn",
           "rmc.headername.recordingid", "rmc.header.structure",
           "rmc.check4timegaps", "rmc.doresample", "rmc.col.wear", "rmc.dec",
           "rmc.scalefactor.acc")
  expect_identical(names(ggir), c("spherecrit", "minloadcrit", "chunksize",
                                  "printsummary", "rmc.noise", "rmc.sf",
                                  "interpolationType", "frequency_tol",
                                  "desiredtz", "configtz", "reader", rmc))
  expect_identical(ggir[c("interpolationType", "frequency_tol", "desiredtz")],
                   list(interpolationType = 1, frequency_tol = 0.1, desiredtz = ""))
  expect_null(ggir$configtz)
  if (requireNamespace("GGIR", quietly = TRUE)) {
    d <- GGIR::load_params()$params_rawdata
    expect_true(all(rmc %in% names(d)))
    for (nm in rmc) expect_identical(ggir[[nm]], d[[nm]], label = nm)
  }
})

test_that("a later source wins, and a value is checked wherever it comes from", {
  v <- gravcal:::ggir_param_values("ggir", list(list(chunksize = 0.5, other = 1),
                                                list(chunksize = 0.2)))
  expect_identical(v$chunksize, 0.2)
  expect_null(v$other)
  # the same check at both doors, with the argument's name
  rec <- simulate_recording(hours = 1, sf = 10, seed = 2)
  msg <- "`chunksize` must be a number in (0, 1], not 2."
  expect_error(g.calibrate(rec, sf = 10, verbose = FALSE, chunksize = 2),
               msg, fixed = TRUE)
  expect_error(g.calibrate(rec, sf = 10, verbose = FALSE,
                           params_rawdata = list(chunksize = 2)), msg, fixed = TRUE)
  expect_error(calibrate(rec, sf = 10, method = "ggir", chunksize = 2), msg,
               fixed = TRUE)
  expect_error(calibrate(rec, sf = 10, method = "ggir", minloadcrit = -1),
               "`minloadcrit` must be a number >= 0, not -1.", fixed = TRUE)
  expect_error(g.calibrate(rec, sf = 10, verbose = FALSE, rmc.noise = 0),
               "`rmc.noise` must be a number > 0, not 0.", fixed = TRUE)
  expect_error(calibrate(rec, sf = 10, method = "ggir", use_temp = NA),
               "`use_temp` must be TRUE or FALSE, not NA.", fixed = TRUE)
  # GGIR's names are not calibrate()'s, nor the other way round
  expect_error(calibrate(rec, sf = 10, method = "ggir", printsummary = TRUE),
               "Unknown argument in `...`: `printsummary`. Known: use_temp, ",
               fixed = TRUE)
  expect_warning(g.calibrate(rec, sf = 10, verbose = FALSE, max_iter = 5),
                 "ignored argument `max_iter`", fixed = TRUE)
})

test_that("the audit covers every parameter of GGIR's params_rawdata and params_general", {
  skip_if_not_installed("GGIR")
  tab <- gravcal:::ggir_param_table()
  audited <- Filter(function(p) !is.na(p$ggir), tab)
  nm <- vapply(audited, `[[`, "", "ggir")
  expect_false(anyDuplicated(nm) > 0)
  expect_true(all(vapply(tab, function(p) p$status %in% c("honoured", "no effect"), TRUE)))
  p <- GGIR::load_params()
  num <- function(v) if (is.numeric(v)) as.numeric(v) else v
  for (lst in c("rawdata", "general")) {
    ggir <- p[[paste0("params_", lst)]]
    # every parameter of GGIR's list has a row, in that list
    expect_setequal(intersect(nm, names(ggir)), names(ggir))
    for (row in audited) {
      if (!identical(row$list, lst)) next
      expect_true(row$ggir %in% names(ggir), label = row$ggir)
      # the default recorded in the table is GGIR's (rmc.noise: gravcal's
      # door default is NULL, GGIR's list default is recorded beside it)
      expect_identical(num(row$ggir_default), num(ggir[[row$ggir]]),
                       label = row$ggir)
    }
  }
})

test_that("a reading parameter gravcal cannot honour is an error naming it", {
  skip_if_not_installed("GGIRread")
  f <- system.file("testfiles", "ax3_testfile.cwa", package = "GGIRread")
  skip_if(!nzchar(f), "GGIRread has no ax3_testfile.cwa")
  expect_error(g.calibrate(f, verbose = FALSE, interpolationType = 3),
               "`interpolationType` must be 1 (linear) or 2 (nearest neighbour), not 3.",
               fixed = TRUE)
  expect_error(g.calibrate(f, verbose = FALSE,
                           params_rawdata = list(frequency_tol = -1)),
               "`frequency_tol` must be a number >= 0, not -1.", fixed = TRUE)
  expect_error(g.calibrate(f, verbose = FALSE, params_general = "UTC"),
               "`params_general` must be a list", fixed = TRUE)
  expect_error(g.calibrate(f, verbose = FALSE, params_general = list(desiredtz = 1)),
               "`desiredtz` must be a time zone name (a string), not 1.", fixed = TRUE)
  # GGIR's own readers are called with GGIR's defaults only
  expect_error(g.calibrate(f, verbose = FALSE, reader = "reference",
                           params_rawdata = list(interpolationType = 2)),
               "`interpolationType` = 2 is taken by gravcal's own decoders only",
               fixed = TRUE)
  expect_error(g.calibrate(f, verbose = FALSE, reader = "reference",
                           frequency_tol = 0.2),
               "`frequency_tol` = 0.2 is taken by gravcal's own decoders only",
               fixed = TRUE)
  # a parameter of params_rawdata is not read from params_general
  rec <- simulate_recording(hours = 1, sf = 10, seed = 2)
  expect_silent(g.calibrate(rec, sf = 10, verbose = FALSE,
                            params_general = list(interpolationType = 3,
                                                  windowsizes = c(5, 900, 3600)),
                            params_cleaning = list(includedaycrit = 10)))
  # calibrate(method = "ggir") takes no GGIR reading parameter: named
  expect_error(calibrate(f, method = "ggir", interpolationType = 2),
               "Unknown argument in `...`: `interpolationType`", fixed = TRUE)
  # GGIR's parameters with no effect on the result are taken silently
  expect_silent(g.calibrate(rec, sf = 10, verbose = FALSE, do.cal = FALSE,
                            imputeTimegaps = FALSE, dataFormat = "raw",
                            nonwear_range_threshold = 100))
})

test_that("desiredtz / configtz: GGIR's own reader refuses a .cwa that spans a change of UTC offset", {
  # 30 hours across the end of daylight saving in Europe/Amsterdam
  # (2023-10-29 01:00 UTC): GGIR's readAxivity sees its block times jump an
  # hour there. gravcal's decoder follows (test-ggir-interpolation.R);
  # reader = "reference" does not, and refuses; a fixed-offset zone, or
  # UTC, is taken
  rec <- simulate_recording(hours = 2, sf = 25, seed = 3)
  f <- tempfile(fileext = ".cwa")
  on.exit(unlink(f))
  start <- as.numeric(as.POSIXct("2023-10-28 12:00:00", tz = "UTC"))
  gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), f, sf = 25, start = start)
  # (only the first and last block times are read: one at each end is enough)
  gravcal:::write_cwa(as.matrix(rec[1:120, c("x", "y", "z")]), f, sf = 25,
                      start = start + 30 * 3600, append = TRUE, block0 = 10^4)
  skip_if_not_installed("GGIRread")
  expect_error(g.calibrate(f, verbose = FALSE, reader = "reference",
                           params_general = list(desiredtz = "Europe/Amsterdam")),
               "`desiredtz` = \"Europe/Amsterdam\": the recording spans a change of UTC offset")
  expect_error(g.calibrate(f, verbose = FALSE, desiredtz = "UTC", reader = "reference",
                           configtz = "Europe/London"),
               "`configtz` = \"Europe/London\"", fixed = TRUE)
  # the same two hours a day and a half before the change are taken
  g <- tempfile(fileext = ".cwa")
  on.exit(unlink(g), add = TRUE)
  gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), g, sf = 25,
                      start = start - 36 * 3600)
  C <- suppressWarnings(g.calibrate(g, verbose = FALSE, desiredtz = "Europe/Amsterdam"))
  expect_type(C$QCmessage, "character")
  for (tz in c("UTC", "Etc/GMT-1", "Asia/Tokyo")) {
    C <- suppressWarnings(g.calibrate(f, verbose = FALSE, desiredtz = tz))
    expect_type(C$QCmessage, "character")
  }
})
