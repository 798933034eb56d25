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
                                  "printsummary", "rmc.noise", "rmc.sf", rmc,
                                  "reader"))
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
