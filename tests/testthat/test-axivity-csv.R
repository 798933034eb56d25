# Axivity's csv export (OMGUI: UNIX time stamp, x, y, z, no header; the
# registry's format "axivity_csv", R/axivity-csv.R): files written by
# write_axivity_csv() (R/write-csv.R) from simulated recordings, whose clock
# runs off the nominal rate so that GGIR's resampling of every block
# matters. The reference numbers are GGIR 3.3-9's own, computed here.

test_that("g.calibrate() on an Axivity csv export is GGIR's, both readers", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  skip_if_not_installed("data.table")
  rec <- simulate_recording(hours = 30, sf = 10, seed = 21, params = known_params(),
                            temperature = FALSE)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  # 10.03 Hz and 13.1 Hz clocks: GGIR finds 10 Hz for both (rounded down to
  # a multiple of 5) and resamples each block onto it
  for (true_sf in c(10.03, 13.1)) {
    gravcal:::write_axivity_csv(rec, f, true_sf = true_sf)
    expect_identical(gravcal:::file_format(f), "axivity_csv")
    expect_identical(gravcal:::axivity_csv_sf(f), 10)
    b <- run_both(f)
    expect_same_as_ggir(b)
    for (nm in setdiff(names(b$ggir), "bsc_qc")) {
      expect_identical(b$gravcal[[nm]], b$ggir[[nm]], label = paste(true_sf, nm))
    }
    expect_gt(b$ggir$npoints, 100)
  }
  # through data.table::fread() and GGIRread::resample() (reader = "reference")
  pr <- GGIR::load_params()$params_rawdata
  utils::capture.output(G <- gravcal::g.calibrate(f, params_rawdata = pr, verbose = FALSE,
                                                  reader = "reference"))
  for (nm in setdiff(names(b$ggir), "bsc_qc")) expect_identical(G[[nm]], b$ggir[[nm]], label = nm)
  # GGIR's nearest-neighbour resampling (interpolationType = 2): gravcal's
  # decoder; GGIR's reader as gravcal calls it takes only 1
  b2 <- run_both(f, list(interpolationType = 2))
  expect_same_as_ggir(b2)
  for (nm in setdiff(names(b2$ggir), "bsc_qc")) {
    expect_identical(b2$gravcal[[nm]], b2$ggir[[nm]], label = paste("nearest", nm))
  }
  expect_false(identical(b2$ggir$spheredata, b$ggir$spheredata))
  expect_error(gravcal::g.calibrate(f, params_rawdata = c(pr[names(pr) != "interpolationType"],
                                                          list(interpolationType = 2)),
                                    verbose = FALSE, reader = "reference"),
               "`interpolationType` = 2 is taken by gravcal's own decoders only")
})

test_that("an Axivity csv export read whole keeps its samples and times; other csv files are not one", {
  rec <- simulate_recording(hours = 0.1, sf = 10, seed = 22, temperature = FALSE)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  gravcal:::write_axivity_csv(rec, f, true_sf = 10.5, digits = 4)
  r <- read_recording(f)
  expect_identical(r$sf, 10)
  expect_identical(nrow(r$data), nrow(rec))
  expect_identical(r$data$x, round(rec$x, 4))
  t <- as.numeric(r$data$time)
  # the file's time stamps (written to the millisecond), not a grid
  expect_lt(abs((t[100] - t[1]) - 99 / 10.5), 1e-3)
  # text time stamps are refused with a reason
  writeLines(c("2024-01-01 00:00:00.000,0,0,1", "2024-01-01 00:00:00.100,0,0,1"), f)
  expect_identical(gravcal:::file_format(f), "axivity_csv")
  expect_error(read_recording(f), "text time stamps")
  # a header of column names, or three fields, is not an Axivity export
  writeLines(c("time,x,y,z", "1,0,0,1"), f)
  expect_identical(gravcal:::file_format(f), "csv")
  writeLines(c("0,0,1", "0,0,1"), f)
  expect_identical(gravcal:::file_format(f), "csv")
})
