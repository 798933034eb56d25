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

test_that("the rate's two time stamps are R's as.POSIXct() of the whole column, every format and zone", {
  # axivity_csv_sf() converts only the first and last of GGIR's 100,000
  # stamps (r_posixct_ends()); the reference is R's own conversion of all
  # of them (as g.inspectfile() converts them), in the session's zone
  whole <- function(x) {
    v <- tryCatch(as.numeric(as.POSIXct(x, origin = "1970-01-01")), error = function(e) "error")
    if (is.character(v)) v else v[c(1, length(v))]
  }
  ends <- function(x) tryCatch(gravcal:::r_posixct_ends(x), error = function(e) "error")
  t0 <- as.POSIXct("2024-03-31 00:30:00", tz = "UTC") + (0:35999) / 10.03  # Amsterdam's spring change
  txt <- function(f, t = t0) format(t, f, tz = "UTC")
  cases <- list(
    iso = txt("%Y-%m-%d %H:%M:%OS3"),
    slash = txt("%Y/%m/%d %H:%M:%OS2"),
    minutes = txt("%Y-%m-%d %H:%M"),
    slash_minutes = txt("%Y/%m/%d %H:%M"),
    days = txt("%Y-%m-%d"),
    # one stamp without seconds: R takes "%Y-%m-%d %H:%M" for all (the
    # seconds of the others dropped)
    one_short = replace(txt("%Y-%m-%d %H:%M:%S"), 20000, "2024-03-31 06:00"),
    # the first stamps in one format, the last in another: none reads all
    mixed = c(txt("%Y/%m/%d %H:%M:%S")[1:100], txt("%Y-%m-%d %H:%M:%S")[-(1:100)]),
    na_inside = replace(txt("%Y-%m-%d %H:%M:%S"), c(5, 900), NA),
    na_first = replace(txt("%Y-%m-%d %H:%M:%S"), 1, NA),
    all_na = rep(NA_character_, 10),
    garbage = c("not a time", txt("%Y-%m-%d %H:%M:%S")[-1]),
    one = txt("%Y-%m-%d %H:%M:%S")[1],
    factor = factor(txt("%Y-%m-%d %H:%M:%S")[1:50]))
  old <- Sys.getenv("TZ", unset = NA)
  on.exit(if (is.na(old)) Sys.unsetenv("TZ") else Sys.setenv(TZ = old), add = TRUE)
  for (tz in c("UTC", "Europe/Amsterdam", "America/New_York")) {
    Sys.setenv(TZ = tz)
    for (nm in names(cases)) {
      expect_identical(ends(cases[[nm]]), whole(cases[[nm]]), label = paste(tz, nm))
    }
  }
  expect_identical(ends(cases$mixed), "error")
  expect_true(is.numeric(ends(cases$one_short)))
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
  # text time stamps (OMGUI's), with and without its header line: the same
  # samples, the stamps read (UTC)
  gravcal:::write_axivity_csv(rec, f, true_sf = 10.5, digits = 4, stamps = "text")
  expect_identical(gravcal:::file_format(f), "axivity_csv")
  r2 <- read_recording(f)
  expect_identical(r2$sf, 10)
  expect_identical(r2$data$x, r$data$x)
  expect_identical(round(as.numeric(r2$data$time), 3), round(t, 3))
  gravcal:::write_axivity_csv(rec, f, true_sf = 10.5, digits = 4, stamps = "text", header = TRUE)
  expect_identical(gravcal:::file_format(f), "axivity_csv")
  r3 <- read_recording(f)
  expect_identical(r3$data$x, r$data$x)
  expect_identical(r3$data$time, r2$data$time)
  # stamps in no format R or fread reads: an error naming the file
  writeLines(paste0("04.01.2024 00:00:0", 0:9, ",0,0,1"), f)
  expect_error(read_recording(f), "neither UNIX seconds nor a date-time GGIR reads")
  # a header of column names, or three fields, is not an Axivity export
  writeLines(c("time,x,y,z", "1,0,0,1"), f)
  expect_identical(gravcal:::file_format(f), "csv")
  writeLines(c("0,0,1", "0,0,1"), f)
  expect_identical(gravcal:::file_format(f), "csv")
})

# Text time stamps, as GGIR 3.3-9 reads them: its block reader
# (data.table::fread(), header = FALSE) takes ISO 8601 date-times
# ("2024-03-04 09:00:00.040", "Z" or an offset after it) as fread computes
# them, other text (slashes) through as.POSIXct(); g.inspectfile() finds the
# rate from the stamps in the session's zone. Stamps of whole seconds repeat
# for every sample of a second: GGIRread's resampling then gives NaN at
# each block's start, which empties the rest of the block in GGIR's
# cumulative sums, and GGIR calibrates on almost nothing; gravcal the same.
test_that("g.calibrate() on Axivity csv exports with text time stamps is GGIR's, format by format", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  skip_if_not_installed("data.table")
  # OMGUI's stamps on 30 hours (three of GGIR's blocks), the others on 13
  # (two blocks: GGIR's run costs time)
  recs <- list(long = simulate_recording(hours = 30, sf = 10, seed = 23, params = known_params(),
                                         temperature = FALSE),
               short = simulate_recording(hours = 13, sf = 10, seed = 26,
                                          params = known_params(), temperature = FALSE))
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  styles <- list(
    omgui = list(),                                        # 2024-03-04 09:00:00.040
    zulu = list(suffix = "Z", decimals = 2),               # ...09:00:00.04Z
    offset = list(suffix = "+01:00"),                      # ...09:00:00.040+01:00
    slashes = list(time_format = "%Y/%m/%d %H:%M:%S"),     # as.POSIXct()'s path
    seconds = list(decimals = 0))                          # 2024-03-04 09:00:00
  pr <- GGIR::load_params()$params_rawdata
  quiet <- function(expr) {
    out <- NULL
    keep_warn(utils::capture.output(out <- suppressWarnings(expr)))
    out
  }
  for (nm in names(styles)) {
    rec <- recs[[if (nm == "omgui") "long" else "short"]]
    do.call(gravcal:::write_axivity_csv,
            c(list(rec, f, true_sf = 10.03, start = "2024-03-04 09:00:00", stamps = "text"),
              styles[[nm]]))
    expect_identical(gravcal:::file_format(f), "axivity_csv")
    b <- run_both(f)
    expect_same_as_ggir(b)
    for (k in setdiff(names(b$ggir), "bsc_qc")) {
      expect_identical(b$gravcal[[k]], b$ggir[[k]], label = paste(nm, k))
    }
    if (nm == "seconds") {
      expect_identical(b$ggir$QCmessage, gravcal:::ggir_messages[["no_data"]])
    } else {
      expect_gt(b$ggir$npoints, 1000)
    }
    if (nm == "omgui") {
      # given GGIR's inspectfileobject (the issue: "not enough data" before),
      # and through fread and GGIRread::resample (reader = "reference")
      I <- quiet(GGIR::g.inspectfile(f, params_rawdata = pr))
      G <- quiet(gravcal::g.calibrate(f, params_rawdata = pr, inspectfileobject = I,
                                      verbose = FALSE))
      G2 <- quiet(gravcal::g.calibrate(f, params_rawdata = pr, verbose = FALSE,
                                       reader = "reference"))
      for (k in setdiff(names(b$ggir), "bsc_qc")) {
        expect_identical(G[[k]], b$ggir[[k]], label = paste("inspectfileobject", k))
        expect_identical(G2[[k]], b$ggir[[k]], label = paste("reference", k))
      }
    }
  }
})

test_that("fread's date-times: the csv decoder's value of every millisecond is fread's", {
  skip_if_not_installed("data.table")
  # each millisecond of a minute, with and without an offset, against
  # fread's own POSIXct values
  s <- expand.grid(ms = 0:999, sec = c(0, 7, 31, 59))
  stamp <- sprintf("2024-03-04 09:17:%02d.%03d", s$sec, s$ms)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  for (suffix in c("", "Z", "+0130", "-05:30", " +02")) {
    txt <- paste0(stamp, suffix)
    writeLines(paste0(txt, ",0.5,0.25,1"), f)
    ref <- as.numeric(data.table::fread(f, header = FALSE, data.table = FALSE)[[1]])
    expect_false(anyNA(ref))
    lay <- gravcal:::axivity_csv_layout(f, sf = 10, compat = TRUE)
    expect_identical(lay$time$kind, "iso")
    # the decoder as GGIR's reads take it (fread's rule for the seconds),
    # without the resampling
    opts <- lay$opts[setdiff(names(lay$opts), "grid_sf")]
    d <- gravcal:::native_read_all(f, "adhoc_csv", c(list(compat = 1), opts))
    expect_identical(d$time, ref, label = paste0("suffix \"", suffix, "\""))
  }
})

test_that("an Axivity csv export with OMGUI's header line: GGIR stops, so g.calibrate() refuses it", {
  skip_if_quick()
  # slow tier: GGIR's error is recomputed on every run (errors are never
  # cached); make quick keeps the other Axivity csv cases
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  rec <- simulate_recording(hours = 2, sf = 10, seed = 24, temperature = FALSE)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  gravcal:::write_axivity_csv(rec, f, true_sf = 10.03, stamps = "text", header = TRUE)
  pr <- GGIR::load_params()$params_rawdata
  I <- suppressWarnings(GGIR::g.inspectfile(f, params_rawdata = pr))
  # GGIR stops with the session's warnings switched off (options(warn =
  # -1)); keep_warn() restores them, so later snapshots record warnings
  warn <- getOption("warn")
  expect_match(ggir_error("g.calibrate", f, list(pr),
                          keep_warn(suppressWarnings(GGIR::g.calibrate(f, params_rawdata = pr,
                                                                       inspectfileobject = I,
                                                                       verbose = FALSE)))),
               "standard unambiguous format")
  expect_identical(getOption("warn"), warn)
  expect_error(gravcal::g.calibrate(f, verbose = FALSE),
               "Axivity csv export with a header line", fixed = TRUE)
  expect_error(gravcal::g.calibrate(f, inspectfileobject = I, verbose = FALSE),
               "GGIR 3.3-9 reads that line as data and stops", fixed = TRUE)
  # gravcal's own methods read it
  expect_s3_class(calibrate(f), "gravcal_fit")
})

test_that("g.calibrate() refuses an inspectfileobject it cannot honour, naming why", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  rec <- simulate_recording(hours = 1, sf = 10, seed = 25, temperature = FALSE)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  gravcal:::write_axivity_csv(rec, f, true_sf = 10.03, stamps = "text")
  I <- suppressWarnings(GGIR::g.inspectfile(f))
  expect_identical(gravcal:::ggir_inspect_format(I), "axivity_csv")
  # another format's object (an ActiGraph csv export's codes)
  I2 <- utils::modifyList(I, list(monc = 3L, monn = "actigraph"))
  expect_error(gravcal::g.calibrate(f, inspectfileobject = I2, verbose = FALSE),
               paste0("`inspectfileobject` (monc = 3, dformc = 2: an ActiGraph csv export) ",
                      "does not describe \"", basename(f), "\", which gravcal reads as an ",
                      "Axivity csv export"), fixed = TRUE)
  # the ad hoc csv reader named on one side only
  expect_error(gravcal::g.calibrate(f, inspectfileobject = I, verbose = FALSE,
                                    rmc.firstrow.acc = 1, rmc.sf = 10),
               "(rmc.firstrow.acc is given)", fixed = TRUE)
  # decimal commas, and no sf
  expect_error(gravcal::g.calibrate(f, inspectfileobject = utils::modifyList(I, list(decn = ",")),
                                    verbose = FALSE),
               "`inspectfileobject$decn` = \",\"", fixed = TRUE)
  I3 <- I
  I3$sf <- NULL
  expect_error(gravcal::g.calibrate(f, inspectfileobject = I3, verbose = FALSE),
               "`inspectfileobject` has no `sf`", fixed = TRUE)
  # a rate that is not the file's own (.cwa): the error names the object's sf
  cwa <- system.file("testfiles", "ax3_testfile.cwa", package = "GGIRread")
  skip_if(!nzchar(cwa), "GGIRread's test .cwa file is missing")
  Icwa <- suppressWarnings(GGIR::g.inspectfile(cwa))
  expect_error(gravcal::g.calibrate(cwa, inspectfileobject = utils::modifyList(Icwa, list(sf = 37)),
                                    verbose = FALSE),
               "`inspectfileobject$sf` = 37 Hz", fixed = TRUE)
  # stamps no reader takes: an error, not GGIR's quiet "not enough data"
  writeLines(sprintf("04.03.2024 09:%02d:%02d,0,0,1", (0:999) %/% 60, (0:999) %% 60), f)
  expect_error(gravcal::g.calibrate(f, inspectfileobject = I, verbose = FALSE),
               "neither UNIX seconds nor a date-time GGIR reads", fixed = TRUE)
})

test_that("desiredtz across daylight saving: GGIR's, forced stamps and GGIR's NA samples too", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  skip_if(is.null(gravcal:::zone_table("Europe/Amsterdam")),
          "this R has no daylight saving rules for Europe/Amsterdam")
  # 13 hours across Europe/Amsterdam's change of 2024-03-31 (01:00 UTC)
  rec <- simulate_recording(hours = 13, sf = 10, seed = 27, params = known_params(),
                            temperature = FALSE)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pl <- GGIR::load_params()
  pg <- utils::modifyList(pl$params_general, list(desiredtz = "Europe/Amsterdam"))
  quiet <- function(expr) {
    out <- NULL
    keep_warn(utils::capture.output(out <- suppressWarnings(expr)))
    out
  }
  both <- function(pr = pl$params_rawdata) {
    list(ggir = ggir_cached("g.calibrate", f, list(params_rawdata = pr, params_general = pg), {
           I <- quiet(GGIR::g.inspectfile(f, params_rawdata = pr, params_general = pg))
           tryCatch(quiet(GGIR::g.calibrate(f, params_rawdata = pr, params_general = pg,
                                            inspectfileobject = I, verbose = FALSE)),
                    error = function(e) e)
         }),
         gravcal = tryCatch(quiet(gravcal::g.calibrate(f, params_rawdata = pr, params_general = pg,
                                                       verbose = FALSE)),
                            error = function(e) e))
  }
  # text GGIR reads with as.POSIXct() in the zone: its result, which the
  # zone changes
  gravcal:::write_axivity_csv(rec, f, true_sf = 10.03, start = "2024-03-30 20:00:00",
                              stamps = "text", time_format = "%Y/%m/%d %H:%M:%S")
  b <- both()
  R <- b$ggir
  G <- b$gravcal
  k <- setdiff(names(R), "bsc_qc")
  expect_true(identical(G[k], R[k]), label = "identical(gravcal[-bsc_qc], GGIR[-bsc_qc])")
  expect_gt(R$npoints, 1000)
  G0 <- quiet(gravcal::g.calibrate(f, params_rawdata = pl$params_rawdata, verbose = FALSE))
  expect_false(identical(G0$spheredata, G$spheredata))
  # ISO 8601 and UNIX stamps, which GGIR forces into the zone
  # (lubridate::force_tz()): NA through the hour the clocks skip, where
  # GGIRread::resample()'s search stops, so that the block's samples are NA
  # from there to its end (left out of the fit): GGIR's result (gravcal
  # refused these)
  for (st in c("text", "unix")) {
    gravcal:::write_axivity_csv(rec, f, true_sf = 10.03, start = "2024-03-30 20:00:00", stamps = st)
    b <- both()
    expect_true(identical(b$gravcal[k], b$ggir[k]), label = paste(st, "spring: identical"))
    expect_lt(b$ggir$npoints, R$npoints)
    # a block of GGIR's (chunksize 0.5: 217,800 lines) that ends in the
    # hour: GGIR's seq() of its grid stops, and so does gravcal, naming why
    b <- both(utils::modifyList(pl$params_rawdata, list(chunksize = 0.5)))
    expect_s3_class(b$ggir, "error")
    expect_match(conditionMessage(b$ggir), "must be a finite number")
    expect_s3_class(b$gravcal, "error")
    expect_match(conditionMessage(b$gravcal),
                 "`desiredtz` = \"Europe/Amsterdam\": a block of GGIR's reading .* starts or ends in the hour")
    # a recording that starts in the hour: its first block's first stamp is
    # NA, where GGIR's seq() of the grid stops (g.calibrate() and
    # g.getmeta()), and so does gravcal
    gravcal:::write_axivity_csv(rec, f, true_sf = 10.03, start = "2024-03-31 02:30:00", stamps = st)
    b <- both()
    expect_s3_class(b$ggir, "error")
    expect_match(conditionMessage(b$ggir), "must be a finite number")
    expect_s3_class(b$gravcal, "error")
    expect_match(conditionMessage(b$gravcal), "starts or ends in the hour that zone's clocks skip")
    args <- list(params_rawdata = pl$params_rawdata, params_general = pg,
                 params_metrics = pl$params_metrics, params_cleaning = pl$params_cleaning)
    gm <- tryCatch({
      I <- quiet(GGIR::g.inspectfile(f, params_rawdata = pl$params_rawdata, params_general = pg))
      quiet(do.call(GGIR::g.getmeta, c(list(f), args, list(inspectfileobject = I, verbose = FALSE))))
    }, error = function(e) e)
    expect_s3_class(gm, "error")
    expect_match(conditionMessage(gm), "must be a finite number")
    expect_error(quiet(do.call(gravcal::g.getmeta, c(list(f), args, list(verbose = FALSE)))),
                 "starts or ends in the hour that zone's clocks skip")
  }
  # across the autumn change (2024-10-27, 01:00 UTC) forced stamps jump an
  # hour ahead (clock times that exist twice take the later offset), and
  # GGIR's resampling fills the hour: GGIR's result, and not the one of a
  # zone without the change
  for (st in c("text", "unix")) {
    gravcal:::write_axivity_csv(rec, f, true_sf = 10.03, start = "2024-10-26 20:00:00", stamps = st)
    b <- both()
    G <- b$gravcal
    expect_true(identical(G[k], b$ggir[k]), label = paste(st, "autumn: identical"))
    G0 <- quiet(gravcal::g.calibrate(f, params_rawdata = pl$params_rawdata, verbose = FALSE))
    expect_false(identical(G0$spheredata, G$spheredata), label = st)
  }
})
