# GGIR's "ad hoc" csv files (rmc.* parameters; R/adhoc-csv.R, the csv
# decoder's format "adhoc_csv"): files written by write_adhoc_csv()
# (R/write-csv.R) from simulated recordings, read by GGIR 3.3-9 and by
# gravcal. The reference numbers are GGIR's own, computed in the test.

adhoc_rec <- function(hours = 30, sf = 10, seed = 11) {
  simulate_recording(hours = hours, sf = sf, seed = seed, params = known_params(),
                     tempoffset = c(0.002, -0.001, 0.0015))
}

# GGIR's g.calibrate() and gravcal's on `file` with the rmc.* list `pr`
# (GGIR gets load_params()'s list with pr in it, gravcal pr alone unless
# `full`), every element but bsc_qc compared.
expect_adhoc_same <- function(file, pr, full = TRUE, ...) {
  b <- run_both(file, pr)
  if (!full) {
    utils::capture.output(b$gravcal <- suppressWarnings(
      gravcal::g.calibrate(file, params_rawdata = pr, verbose = FALSE, ...)))
  }
  expect_same_as_ggir(b)
  for (nm in setdiff(names(b$ggir), "bsc_qc")) {
    expect_identical(b$gravcal[[nm]], b$ggir[[nm]], label = nm)
  }
  invisible(b)
}

test_that("g.calibrate() on ad hoc csv files is GGIR's, unit by unit and layout by layout", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  rec <- adhoc_rec()
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  noise <- list(rmc.noise = 0.013 / 1.2)  # GGIR's rest rule for other devices
  # mg, two header lines and a column-name line: samples from line 4
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10, unit = "mg", header = c("device,sim", "serial,S1"))
  expect_equal(pr$rmc.firstrow.acc, 4)
  b <- expect_adhoc_same(f, c(pr, noise))
  expect_gt(b$ggir$npoints, 100)
  expect_true(b$ggir$use.temp)
  # the same file through data.table::fread (reader = "reference"), and in
  # half-size blocks
  utils::capture.output(G <- gravcal::g.calibrate(
    f, params_rawdata = utils::modifyList(GGIR::load_params()$params_rawdata, c(pr, noise)),
    verbose = FALSE, reader = "reference"))
  for (nm in setdiff(names(b$ggir), "bsc_qc")) expect_identical(G[[nm]], b$ggir[[nm]], label = nm)
  expect_adhoc_same(f, c(pr, noise, list(chunksize = 0.5)))
  # g with a UNIX-seconds time column, no column names; gravcal given the
  # rmc.* list alone takes GGIR's default rmc.noise (13) as GGIR does
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10, unit = "g", time = "UNIXsec", colnames = FALSE)
  expect_adhoc_same(f, pr, full = FALSE)
  # 12-bit unsigned counts over +-8 g
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10, unit = "bit", bitrate = 12, dynamic_range = 8)
  expect_adhoc_same(f, c(pr, noise))
  # sf from a header row (rmc.headername.sf), time in ms, values in g read
  # as mg times rmc.scalefactor.acc = 1000, temperature in F
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10, unit = "g", time = "UNIXmsec", sf_header = TRUE,
                        header = c("device,sim"), temp_unit = "F")
  expect_null(pr$rmc.sf)
  pr$rmc.unit.acc <- "mg"
  pr$rmc.scalefactor.acc <- 1000
  expect_adhoc_same(f, c(pr, noise))
})

test_that("ad hoc csv in mg with one decimal after free-text header lines: GGIR's lines, GGIR's result", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  # GGIR skips rmc.firstrow.acc - 1 lines (and each block's start) with
  # data.table::fread(skip = ), which ends a line at "\n", "\r", "\r\n"
  # or "\n\r": a free-text line with a stray carriage return counts as
  # two. gravcal counts them alike (R/adhoc-csv.R fread_lines(), the csv
  # decoder's skip); counting "\n" only lost the first sample and moved
  # every window by one.
  rec <- adhoc_rec(seed = 18)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  noise <- list(rmc.noise = 0.013 / 1.2)
  layouts <- list(
    # "Recorded by ...\r" "exported ..." "Study notes" then the column
    # names: rmc.firstrow.acc = 4 by the writer's count is the names line
    # by fread's, and GGIR (its first field not a number) starts a line later
    stray_cr = c("Recorded by a simulated device\rexported 2024-03-04", "Study notes"),
    # free text with commas and quotes, Windows line ends ("\r\n"), the
    # names on line 3 and the samples from line 4
    crlf = c("\"Study, site 1\",left wrist\r", "free text, more text\r"),
    # a line ending "\r\r\n" (two line ends for fread and for R)
    double_cr = c("Recorded by a simulated device\r\r", "free text"))
  for (nm in names(layouts)) {
    pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10, unit = "mg", header = layouts[[nm]])
    expect_equal(pr$rmc.firstrow.acc, 4)
    b <- expect_adhoc_same(f, c(pr, noise))
    expect_gt(b$ggir$npoints, 1000)
    expect_true(b$ggir$use.temp)
  }
  # the values are mg with one decimal
  expect_true(any(grepl("^-?[0-9]+[.][0-9],", gravcal:::fread_lines(f, 20)[-(1:4)])))
})

test_that("ad hoc csv: text time stamps first, Kelvin, decimal commas", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  # a text time stamp in the first column: GGIR starts one line later
  rec <- adhoc_rec(sf = 5, seed = 12)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 5, time = "POSIX", temp_unit = "K", colnames = FALSE)
  expect_adhoc_same(f, c(pr, list(rmc.noise = 0.013 / 1.2)))
  # semicolons and decimal commas
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 5, sep = ";", dec = ",", time = "UNIXsec")
  expect_adhoc_same(f, c(pr, list(rmc.noise = 0.013 / 1.2)))
})

test_that("ad hoc csv with idle-sleep zeros and a time column is GGIR's", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  # GGIR drops x = y = z = 0 rows (g.imputeTimegaps, impute = FALSE), here
  # with the time column beside them: a long run and a short one
  rec <- adhoc_rec(seed = 16)
  for (i in list(50000:80000, 500000:500003)) rec[i, c("x", "y", "z")] <- 0
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10, time = "UNIXsec")
  expect_adhoc_same(f, c(pr, list(rmc.noise = 0.013 / 1.2)))
})

test_that("a wear column (rmc.col.wear): g.calibrate() is GGIR's, and stops where GGIR's reader stops", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  # the flags do not enter the calibration; GGIR's reader (g.readaccfile())
  # stops on a block whose flags fread() does not read as TRUE/FALSE
  rec <- adhoc_rec(seed = 23)
  n <- nrow(rec)
  flags <- rep("TRUE", n)
  flags[1:5000] <- "FALSE"
  flags[7000:7100] <- NA
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10, time = "UNIXsec", wear = flags)
  expect_identical(pr$rmc.col.wear, 6L)
  expect_adhoc_same(f, c(pr, list(rmc.noise = 0.013 / 1.2)))
  stop_both <- function(wear, p, msg) {
    gravcal:::write_adhoc_csv(rec, f, sf = 10, time = "UNIXsec", wear = wear)
    pg <- utils::modifyList(GGIR::load_params()$params_rawdata, p)
    I <- keep_warn(suppressWarnings(GGIR::g.inspectfile(f, params_rawdata = pg)))
    # (keep_warn(): GGIR's g.calibrate() turns warnings off while it reads,
    # and leaves them off when its reader stops)
    expect_match(ggir_error("g.calibrate", f, list(pg),
                            keep_warn(utils::capture.output(GGIR::g.calibrate(f, params_rawdata = pg,
                                                                              inspectfileobject = I,
                                                                              verbose = FALSE)))),
                 "Corrupt file. The wear column")
    expect_error(gravcal::g.calibrate(f, params_rawdata = p, verbose = FALSE), msg)
  }
  warn <- getOption("warn")
  # 1 and 0 (fread() reads numbers); "false" among "TRUE" (text)
  stop_both(ifelse(flags %in% "TRUE", "1", "0"), pr,
            "wear column \\(`rmc.col.wear`\\) holds [0-9]+ values .*first: line 2 ")
  stop_both(replace(flags, 3000, "false"), pr, "holds 1 value .*line 3001 .*not spelt as")
  # a resampled block's flags are numbers: GGIR's reader stops
  stop_both(flags, c(pr, list(rmc.doresample = TRUE)), "`rmc.col.wear` with `rmc.doresample` = TRUE")
  # the session's warnings as they were
  expect_identical(getOption("warn"), warn)
})

test_that("rmc.doresample: every block resampled from its time stamps, as GGIR does", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  # a device whose clock ran at 10.3 Hz for a nominal 10 Hz: time stamps
  # (written to the millisecond) 1 / 10.3 s apart, rmc.sf = 10; GGIR's
  # read.myacc.csv resamples each block of lines onto 10 Hz from its first
  # time stamp to its last (its last included)
  rec <- adhoc_rec(hours = 30, sf = 10, seed = 17)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  noise <- list(rmc.noise = 0.013 / 1.2)
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10.3, unit = "g", time = "UNIXsec")
  pr$rmc.sf <- 10
  pr$rmc.doresample <- TRUE
  b <- expect_adhoc_same(f, c(pr, noise))
  expect_gt(b$ggir$npoints, 100)
  # the resampling moved GGIR's windows: without it, other numbers
  b0 <- run_both(f, c(utils::modifyList(pr, list(rmc.doresample = FALSE)), noise))
  expect_false(identical(b0$ggir$spheredata, b$ggir$spheredata))
  # nearest neighbour (interpolationType = 2)
  b2 <- expect_adhoc_same(f, c(pr, noise, list(interpolationType = 2)))
  expect_false(identical(b2$ggir$spheredata, b$ggir$spheredata))
  # UNIX milliseconds, in blocks of half the size
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10.3, unit = "mg", time = "UNIXmsec")
  pr$rmc.sf <- 10
  pr$rmc.doresample <- TRUE
  expect_adhoc_same(f, c(pr, noise, list(chunksize = 0.5)))
  # ActivPAL days (v * 86400 from 1899-12-30, in the session's zone)
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10.3, unit = "g", time = "ActivPAL")
  pr$rmc.sf <- 10
  pr$rmc.doresample <- TRUE
  b <- expect_adhoc_same(f, c(pr, noise))
  expect_gt(b$ggir$npoints, 100)
  # GGIR's own reader through data.table (reader = "reference") does not
  # resample: an error naming the parameter
  expect_error(suppressWarnings(gravcal::g.calibrate(
    f, params_rawdata = pr, verbose = FALSE, reader = "reference")),
    "`rmc.doresample` = TRUE is taken by gravcal's own csv decoder only")
})

test_that("rmc.doresample: samples equal read.myacc.csv's, block by block, grid ends included", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  # time stamps 0.1 s apart as text, from UNIX time 0: a block's (t_n -
  # t_1) / 0.1 lands within 1e-10 of a whole number, so GGIR's grid (R's
  # seq()) sometimes ends past the last time stamp and is clamped to it;
  # blocks of 37 lines
  set.seed(5)
  n <- 3700
  d <- data.frame(time = sprintf("%.1f", (seq_len(n) - 1) * 0.1),
                  x = round(stats::rnorm(n), 4), y = round(stats::rnorm(n), 4),
                  z = round(stats::rnorm(n), 4), temperature = round(stats::runif(n, 20, 30), 2))
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  utils::write.table(d, f, sep = ",", quote = FALSE, row.names = FALSE)
  pr <- list(rmc.firstrow.acc = 2, rmc.col.acc = 2:4, rmc.col.temp = 5, rmc.col.time = 1,
             rmc.unit.time = "UNIXsec", rmc.sf = 10, rmc.doresample = TRUE)
  B <- 37
  for (type in 1:2) {
    lay <- gravcal:::rmc_layout(gravcal:::rmc_values(pr), f)
    h <- gravcal:::native_open(f, "adhoc_csv", c(list(compat = 1, interpolation = type), lay$opts))
    clamped <- 0
    for (i in seq_len(n / B)) {
      G <- GGIR:::read.myacc.csv(rmc.file = f, rmc.nrow = B, rmc.skip = (i - 1) * B,
                                 rmc.firstrow.acc = 2, rmc.col.acc = 2:4, rmc.col.temp = 5,
                                 rmc.col.time = 1, rmc.unit.time = "UNIXsec", rmc.sf = 10,
                                 rmc.doresample = TRUE, interpolationType = type,
                                 desiredtz = "UTC")$data
      g <- gravcal:::native_block(h, max_units = B, time = TRUE)
      got <- g$cols
      for (v in c("x", "y", "z", "temperature", "time")) {
        expect_identical(got[[v]][seq_len(g$to)], G[[v]], label = paste(type, i, v))
      }
      tt <- as.numeric(d$time[(i - 1) * B + c(1, B)])
      if (G$time[nrow(G)] == tt[2] && tt[1] + (nrow(G) - 1) * 0.1 > tt[2]) {
        clamped <- clamped + 1
      }
    }
    gravcal:::gc_decoder_close(h$ptr)
    # some blocks' grids were clamped to their last time stamp
    expect_gt(clamped, 0)
  }
})

test_that("rmc.doresample: a gap in the time stamps is filled as GGIR fills it, a huge one not", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  # 300 lines at 10 Hz with a 1,000 s gap after line 150: GGIR interpolates
  # 10,000 grid points across it (more than the resampler makes at once)
  t <- c((0:149) * 0.1, 1000 + (150:299) * 0.1)
  set.seed(6)
  d <- data.frame(time = sprintf("%.1f", t), x = round(stats::rnorm(300), 4),
                  y = round(stats::rnorm(300), 4), z = round(stats::rnorm(300), 4))
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  utils::write.table(d, f, sep = ",", quote = FALSE, row.names = FALSE)
  pr <- list(rmc.firstrow.acc = 2, rmc.col.acc = 2:4, rmc.col.time = 1,
             rmc.unit.time = "UNIXsec", rmc.sf = 10, rmc.doresample = TRUE)
  G <- GGIR:::read.myacc.csv(rmc.file = f, rmc.nrow = 300, rmc.firstrow.acc = 2,
                             rmc.col.acc = 2:4, rmc.col.time = 1, rmc.unit.time = "UNIXsec",
                             rmc.sf = 10, rmc.doresample = TRUE, desiredtz = "UTC")$data
  lay <- gravcal:::rmc_layout(gravcal:::rmc_values(pr), f)
  h <- gravcal:::native_open(f, "adhoc_csv", c(list(compat = 1), lay$opts))
  g <- gravcal:::native_block(h, max_units = 300, time = TRUE, capacity = 20000)
  gravcal:::gc_decoder_close(h$ptr)
  expect_gt(nrow(G), 10000)
  expect_equal(g$to, nrow(G))
  for (v in c("x", "y", "z", "time")) {
    expect_identical(g$cols[[v]][seq_len(g$to)], G[[v]], label = v)
  }
  # a gap of 2e7 s (2e8 grid points at 10 Hz: GGIR would need gigabytes)
  # is not filled, and the report says so
  d$time <- sprintf("%.1f", c((0:149) * 0.1, 2e7 + (150:299) * 0.1))
  utils::write.table(d, f, sep = ",", quote = FALSE, row.names = FALSE)
  r <- gravcal:::native_read_all(f, "adhoc_csv", c(list(compat = 1), lay$opts))
  rep <- attr(r, "report")
  expect_lt(nrow(r), 400)
  expect_identical(rep$counters[["resample_gaps_not_filled"]], 1)
  expect_true(any(grepl("time stamps jump by 20000000", rep$notes, fixed = TRUE)))
  # time stamps so far out that a grid step is below their resolution
  # (1e300 s: before, the grid's loops never ended on them) are left out
  # with their samples, as non-finite ones are
  d$time <- sprintf("%.1f", (0:299) * 0.1)
  d$time[151:152] <- "1e300"
  utils::write.table(d, f, sep = ",", quote = FALSE, row.names = FALSE)
  r <- gravcal:::native_read_all(f, "adhoc_csv", c(list(compat = 1), lay$opts))
  rep <- attr(r, "report")
  expect_identical(rep$counters[["resample_bad_time"]], 2)
  expect_lt(nrow(r), 400)
})

test_that("ad hoc csv samples equal GGIR's read.myacc.csv, sample for sample", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  rec <- adhoc_rec(hours = 0.25, sf = 10, seed = 13)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  layouts <- list(
    list(unit = "mg", header = c("a,1", "b,2"), time = "POSIX", temp_unit = "K"),
    list(unit = "bit", time = "UNIXmsec", temp_unit = "F", bitrate = 16, dynamic_range = 4),
    list(unit = "g", sep = ";", dec = ",", time = "UNIXsec", colnames = FALSE))
  for (l in layouts) {
    pr <- do.call(gravcal:::write_adhoc_csv, c(list(rec, f, sf = 10), l))
    args <- c(list(rmc.file = f, desiredtz = "UTC"),
              pr[intersect(names(pr), names(formals(GGIR:::read.myacc.csv)))])
    G <- do.call(GGIR:::read.myacc.csv, args)$data
    expect_identical(nrow(G), nrow(rec))
    for (rd in c("native", "reference")) {
      r <- read_recording(f, rmc = pr, reader = rd)
      expect_identical(r$sf, 10)
      for (v in c("x", "y", "z", "temperature")) {
        expect_identical(r$data[[v]], G[[v]], label = paste(l$unit, rd, v))
      }
    }
    # UNIX time stamps are the file's; text ones start at the first stamp
    r <- read_recording(f, rmc = pr)
    expect_equal(as.numeric(r$data$time[c(1, 100)]),
                 as.numeric(G$time[c(1, 100)]), tolerance = 1e-3 / 1.7e9)
  }
})

test_that("calibrate() and rest_windows() read ad hoc csv files by the same rmc list", {
  rec <- adhoc_rec(hours = 14, sf = 10, seed = 14)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10, unit = "mg", time = "UNIXsec",
                        header = c("device,sim"), digits = 6)
  d <- read_recording(f, rmc = pr)$data
  expect_identical(nrow(d), nrow(rec))
  # the file and its samples in memory give the same fits
  a <- calibrate(f, rmc = pr, method = "ggir", ggir_compat = TRUE)
  m <- calibrate(d[c("x", "y", "z", "temperature")], sf = 10, method = "ggir",
                 ggir_compat = TRUE)
  expect_identical(a$ggir[c("scale", "offset", "tempoffset", "npoints")],
                   m$ggir[c("scale", "offset", "tempoffset", "npoints")])
  w1 <- rest_windows(f, rmc = pr)
  w2 <- rest_windows(d[c("x", "y", "z")], sf = 10)
  expect_identical(w1$mean_x, w2$mean_x)
  expect_identical(w1$rest, w2$rest)
  l1 <- calibrate(f, rmc = pr)
  expect_identical(l1$status, "ok")
  expect_lt(l1$error_after, l1$error_before)
  # a cohort of such files, by the same list
  d <- tempfile("adhoc")
  dir.create(d)
  on.exit(unlink(d, recursive = TRUE), add = TRUE)
  file.copy(f, file.path(d, "rec1.csv"))
  res <- calibrate_files(d, outdir = file.path(d, "out"), method = "ggir", rmc = pr)
  own <- calibrate(f, rmc = pr, method = "ggir")
  expect_identical(res$format, "adhoc_csv")
  expect_identical(res$scale.x, unname(coef(own)[1]))
  expect_identical(res$status, own$status)
  # and from the command line, the list as R arguments or an .rds file
  arg <- paste0("rmc.firstrow.acc = ", pr$rmc.firstrow.acc, ", rmc.col.acc = 2:4, ",
                "rmc.col.temp = 5, rmc.col.time = 1, rmc.unit.time = \"UNIXsec\", ",
                "rmc.unit.acc = \"mg\", rmc.sf = 10")
  utils::capture.output(type = "message", tab <- calibrate_cli(
    c("--out", file.path(d, "cli"), "--rmc", arg, d), quit = FALSE))
  expect_identical(tab$scale.x, res$scale.x)
  rds <- tempfile(fileext = ".rds")  # not in the folder of recordings
  on.exit(unlink(rds), add = TRUE)
  saveRDS(pr, rds)
  utils::capture.output(type = "message", tab <- calibrate_cli(
    c("--out", file.path(d, "cli2"), "--rmc", rds, d), quit = FALSE))
  expect_identical(tab$scale.x, res$scale.x)
  expect_error(calibrate_cli(c("--out", file.path(d, "cli3"), "--rmc", "rmc.unit.acc = \"kg\"", d),
                             quit = FALSE), "`rmc.unit.acc` must be one of")
})

test_that("rmc.* parameters gravcal does not implement, or cannot use, are errors naming them", {
  rec <- adhoc_rec(hours = 0.1, sf = 10, seed = 15)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10, time = "POSIX")
  gc <- function(...) g.calibrate(f, params_rawdata = utils::modifyList(pr, list(...)),
                                  verbose = FALSE)
  # rmc.check4timegaps with ISO 8601 text time as "POSIX": GGIR reads it
  # through fread, which drops the fractions of a second (see the gap tests)
  expect_error(gc(rmc.check4timegaps = TRUE),
               "`rmc.check4timegaps` = TRUE with `rmc.unit.time` = \"POSIX\" is not supported")
  # rmc.doresample: the same ISO 8601 text
  expect_error(gc(rmc.doresample = TRUE),
               "`rmc.doresample` = TRUE with `rmc.unit.time` = \"POSIX\" is not supported", fixed = TRUE)
  expect_error(gc(rmc.unit.acc = "kg"), "`rmc.unit.acc` must be one of \"g\", \"mg\", \"bit\"")
  expect_error(gc(rmc.unit.acc = "bit"), "`rmc.unit.acc` = \"bit\" needs `rmc.bitrate`")
  expect_error(gc(rmc.col.acc = c(2, 2, 3)), "`rmc.col.acc` must be 3 different column numbers")
  expect_error(gc(rmc.format.time = "%d/%m/%Y"), "`rmc.format.time` = \"%d/%m/%Y\" does not read")
  expect_error(gc(rmc.col.temp = 9), "column 9 asked for, but data lines have 5 fields")
  expect_error(gc(rmc.sf = NULL), "`rmc.sf`", fixed = TRUE)
  expect_error(gc(rmc.bitrate = "bits", rmc.dynamic_range = 8, rmc.unit.acc = "bit"),
               "`rmc.bitrate` = \"bits\" names no numeric row of the header")
  expect_error(read_recording(f, rmc = list(rmc.firstrow.acc = 2, rmc.sf = 10, rmc.nosuch = 1)),
               "Unknown parameter in `rmc`: `rmc.nosuch`")
  expect_error(read_recording(f, rmc = list(rmc.sf = 10)), "`rmc` must give `rmc.firstrow.acc`")
  expect_error(calibrate(f, rmc = "x"), "`rmc` must be a named list")
})

# Time gaps (rmc.check4timegaps = TRUE): GGIR's read.myacc.csv hands each
# block to g.imputeTimegaps (k = 0.25 s, or 2 / sf): zero samples dropped
# (a block's first becomes 0, 0, 1, its last takes the values before it),
# each gap filled by repeating the sample before it (normalised when its
# norm exceeds 1.005), and g.calibrate passes no previous block: a gap
# between two blocks stays.
gap_lines <- function(n = 3700, sf = 10, text = FALSE, single = FALSE) {
  set.seed(7)
  t <- (seq_len(n) - 1) / sf
  t[1001:n] <- t[1001:n] + 0.35  # three samples missing
  # `single`: three more after the next, which is then alone between two
  # gaps (GGIR's times slip by two rows there: decode_ggir_timegaps.hpp)
  if (single) t[1002:n] <- t[1002:n] + 0.35
  t[2001:n] <- t[2001:n] + 250   # a long gap
  t[3001:n] <- t[3001:n] + 0.5
  xyz <- function(m) round(stats::rnorm(n, m, 0.6), 4)
  d <- data.frame(time = 1.6e9 + t, x = xyz(0), y = xyz(0), z = xyz(0.5),
                  temperature = round(stats::runif(n, 20, 30), 2))
  # zero samples: a run, a block's (of 185 lines) last and the next one's
  # first, one before a gap, the file's first ones
  zero <- c(5:9, 370, 371, 740, 1500:1530, 2999, 3000, 3330)
  d[zero, c("x", "y", "z")] <- 0
  d$time <- if (text) {
    format(as.POSIXct(d$time, origin = "1970-01-01", tz = "UTC") + 5e-5, "%d/%m/%Y %H:%M:%OS3")
  } else {
    sprintf("%.2f", d$time)
  }
  d
}

test_that("rmc.check4timegaps: samples equal read.myacc.csv's, block by block", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  n <- 3700
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr0 <- list(rmc.firstrow.acc = 2, rmc.col.acc = 2:4, rmc.col.temp = 5, rmc.col.time = 1,
              rmc.sf = 10, rmc.check4timegaps = TRUE)
  # blocks of 185 lines: line 370 ends the second, 371 starts the third
  combos <- list(list(text = FALSE, B = 185, rs = FALSE, type = 1),
                 list(text = FALSE, B = 185, rs = TRUE, type = 1),
                 list(text = FALSE, B = 370, rs = TRUE, type = 2),
                 list(text = TRUE, B = 185, rs = FALSE, type = 1),
                 list(text = TRUE, B = 3700, rs = FALSE, type = 1),
                 list(text = FALSE, B = 185, rs = FALSE, type = 1, single = TRUE),
                 list(text = FALSE, B = 370, rs = TRUE, type = 1, single = TRUE))
  for (cb in combos) {
    utils::write.table(gap_lines(n, text = cb$text, single = isTRUE(cb$single)), f, sep = ",",
                       quote = FALSE, row.names = FALSE)
    pr <- c(pr0, list(rmc.doresample = cb$rs),
            if (cb$text) list(rmc.unit.time = "character", rmc.format.time = "%d/%m/%Y %H:%M:%OS")
            else list(rmc.unit.time = "UNIXsec"))
    lay <- gravcal:::rmc_layout(gravcal:::rmc_values(pr), f, tz = "UTC", ggir = FALSE)
    h <- gravcal:::native_open(f, "adhoc_csv", c(list(compat = 1, interpolation = cb$type), lay$opts))
    rows <- 0
    for (i in seq_len(n / cb$B)) {
      G <- do.call(GGIR:::read.myacc.csv, c(list(rmc.file = f, rmc.nrow = cb$B, rmc.skip = (i - 1) * cb$B,
                                                 interpolationType = cb$type, desiredtz = "UTC"),
                                            pr[names(pr) != "rmc.sf"], list(rmc.sf = 10)))$data
      g <- gravcal:::native_block(h, max_units = cb$B, time = TRUE, capacity = 10000)
      lab <- paste(cb$text, cb$B, cb$rs, cb$type, isTRUE(cb$single), "block", i)
      expect_equal(g$to, nrow(G), label = lab)
      for (v in c("x", "y", "z", "temperature")) {
        expect_identical(g$cols[[v]][seq_len(g$to)], G[[v]], label = paste(lab, v))
      }
      # UNIX time stamps to the bit; text ones as R's strptime reads them
      if (cb$text) {
        expect_equal(g$cols$time[seq_len(g$to)], G$time, tolerance = 1e-12, label = paste(lab, "time"))
      } else {
        expect_identical(g$cols$time[seq_len(g$to)], G$time, label = paste(lab, "time"))
      }
      rows <- rows + nrow(G)
    }
    rep <- gravcal:::native_report(h)
    gravcal:::gc_decoder_close(h$ptr)
    # the long gap was filled (about 2,500 samples)
    expect_gt(rows, n + 2400)
    expect_gt(rep$counters[["timegaps_imputed"]], 0)
  }
})

test_that("ActivPAL days: time stamps equal read.myacc.csv's to the bit, forced into desiredtz, resampled", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  n <- 3700
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  # gap_lines()'s times as ActivPAL exports write them: days since
  # 1899-12-30 with 10 decimals, the device's clock
  d <- gap_lines(n)
  d$time <- sprintf("%.10f", (as.numeric(d$time) + 2209161600) / 86400)
  utils::write.table(d, f, sep = ",", quote = FALSE, row.names = FALSE)
  pr <- list(rmc.firstrow.acc = 2, rmc.col.acc = 2:4, rmc.col.temp = 5, rmc.col.time = 1,
             rmc.sf = 10, rmc.unit.time = "ActivPAL", rmc.check4timegaps = TRUE)
  B <- 185
  # GGIR: v * 86400 from 1899-12-30, then lubridate::force_tz() into
  # desiredtz (+05:30, +05:45, and a zone with daylight saving in winter);
  # and each block resampled from its first stamp (rmc.doresample; gaps
  # filled first)
  for (tz in c("Asia/Kolkata", "Asia/Kathmandu", "Europe/Berlin")) {
    for (rs in c(FALSE, TRUE)) {
      p <- c(pr, list(rmc.doresample = rs))
      lay <- gravcal:::rmc_layout(gravcal:::rmc_values(p), f, tz = tz, ggir = FALSE)
      expect_identical(lay$opts$time_mul, 86400)
      h <- gravcal:::native_open(f, "adhoc_csv", c(list(compat = 1, interpolation = 1), lay$opts))
      for (i in seq_len(n / B)) {
        G <- do.call(GGIR:::read.myacc.csv, c(list(rmc.file = f, rmc.nrow = B, rmc.skip = (i - 1) * B,
                                                   desiredtz = tz), p))$data
        g <- gravcal:::native_block(h, max_units = B, time = TRUE, capacity = 10000)
        lab <- paste(tz, rs, "block", i)
        expect_equal(g$to, nrow(G), label = lab)
        for (v in c("time", "x", "temperature")) {
          expect_identical(g$cols[[v]][seq_len(g$to)], G[[v]], label = paste(lab, v))
        }
      }
      gravcal:::gc_decoder_close(h$ptr)
    }
  }
  # a recording across a change of desiredtz's UTC offset: refused, naming it
  d$time <- sprintf("%.10f", (as.numeric(as.POSIXct("2024-03-31 00:59:00", tz = "UTC")) +
                                (seq_len(n) - 1) / 10 + 2209161600) / 86400)
  utils::write.table(d, f, sep = ",", quote = FALSE, row.names = FALSE)
  expect_error(gravcal:::rmc_layout(gravcal:::rmc_values(pr), f, tz = "Europe/London", ggir = FALSE),
               "`rmc.check4timegaps` = TRUE with `rmc.unit.time` = \"ActivPAL\".*Europe/London")
  expect_identical(gravcal:::rmc_layout(gravcal:::rmc_values(pr), f, tz = "Asia/Tokyo",
                                        ggir = FALSE)$opts$time_utc_offset, 32400)
  # without gap filling, across both changes of Europe/London's offset in
  # 2024: stamps a second apart from 00:30, in blocks of an hour; the
  # clock's hour skipped (March 31, 01:00 to 02:00) NA in GGIR's and
  # gravcal's, the hour repeated (October 27) read at the later offset
  pr$rmc.check4timegaps <- NULL
  for (start in c("2024-03-31 00:30:00", "2024-10-27 00:30:00")) {
    n <- 7200
    d <- gap_lines(n)
    d$time <- sprintf("%.10f", (as.numeric(as.POSIXct(start, tz = "UTC")) + seq_len(n) - 1 +
                                  2209161600) / 86400)
    utils::write.table(d, f, sep = ",", quote = FALSE, row.names = FALSE)
    lay <- gravcal:::rmc_layout(gravcal:::rmc_values(pr), f, tz = "Europe/London", ggir = FALSE,
                                stamps = TRUE)
    expect_identical(lay$opts$tz_na_n, if (start < "2024-06") 1L else 0L)
    h <- gravcal:::native_open(f, "adhoc_csv", c(list(compat = 1, interpolation = 1), lay$opts))
    nas <- 0L
    for (i in 1:2) {
      G <- do.call(GGIR:::read.myacc.csv, c(list(rmc.file = f, rmc.nrow = 3600,
                                                 rmc.skip = (i - 1) * 3600,
                                                 desiredtz = "Europe/London"), pr))$data
      g <- gravcal:::native_block(h, max_units = 3600, time = TRUE, capacity = 10000)
      tg <- g$cols$time[seq_len(g$to)]
      expect_identical(is.na(tg), is.na(G$time), label = paste(start, "block", i, "NA"))
      expect_identical(tg[!is.na(tg)], G$time[!is.na(G$time)], label = paste(start, "block", i))
      nas <- nas + sum(is.na(G$time))
    }
    # (the stamps whose clock time, day * 86400 from 1899-12-30, is in the
    # skipped hour: 02:00:00 written to 10 decimals of a day can fall in it)
    clock <- as.numeric(d$time) * 86400 + as.numeric(as.POSIXct("1899-12-30", tz = "UTC"))
    skipped <- clock >= as.numeric(as.POSIXct("2024-03-31 01:00:00", tz = "UTC")) &
      clock < as.numeric(as.POSIXct("2024-03-31 02:00:00", tz = "UTC"))
    expect_identical(nas, sum(skipped))
    expect_gte(nas, if (start < "2024-06") 3600 else 0)
    k <- gravcal:::gc_decoder_report(h$ptr)$counters
    expect_identical(if ("time_not_existing" %in% names(k)) k[["time_not_existing"]] else 0,
                     as.numeric(nas))
    gravcal:::gc_decoder_close(h$ptr)
  }
})

test_that("rmc.check4timegaps: g.calibrate() is GGIR's on a 30-hour file with gaps", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  f <- tempfile(fileext = ".csv")
  # GGIR reads text time in desiredtz = "", the machine's zone: one of fixed
  # offset here (a zone with daylight saving is refused, see below)
  old <- Sys.getenv("TZ", unset = NA)
  Sys.setenv(TZ = "UTC")
  on.exit({
    unlink(f)
    if (is.na(old)) Sys.unsetenv("TZ") else Sys.setenv(TZ = old)
  })
  noise <- list(rmc.noise = 0.013 / 1.2)
  # UNIX seconds at 10 Hz, text time at 5 Hz (GGIR's text parsing is slow)
  for (tm in c("UNIXsec", "character")) {
    sf <- if (tm == "UNIXsec") 10 else 5
    rec <- adhoc_rec(sf = sf, seed = 18)
    B <- gravcal:::format_block_units("adhoc_csv", sf, 1)  # GGIR's block of lines
    # three short gaps (0.4 or 0.6 s), a 30-minute gap, a 5 s gap between
    # the last line of GGIR's first block and the first of its second (not
    # filled: g.calibrate gives no previous block), a run of 60 s of zeros
    short <- c(20000, 150000, 400000) + rep(0:2, each = 3)
    across <- B + length(short) + seq_len(5 * sf)
    drop <- sort(c(short, 450000 + seq_len(1800 * sf), across))
    rec[480000 + seq_len(60 * sf), c("x", "y", "z")] <- 0
    pr <- gravcal:::write_adhoc_csv(rec, f, sf = sf, time = tm, drop = drop)
    pr$rmc.check4timegaps <- TRUE
    b <- expect_adhoc_same(f, c(pr, noise))
    expect_gt(b$ggir$npoints, 100)
    if (tm == "UNIXsec") {
      # the gaps change the numbers: without filling them, others
      utils::capture.output(G0 <- suppressWarnings(gravcal::g.calibrate(
        f, params_rawdata = c(utils::modifyList(pr, list(rmc.check4timegaps = FALSE)), noise),
        verbose = FALSE)))
      expect_false(identical(G0$spheredata, b$ggir$spheredata))
    }
    # filled, then resampled from the time stamps (text time as
    # as.POSIXct() reads it)
    expect_adhoc_same(f, c(pr, noise, list(rmc.doresample = TRUE)))
  }
})

test_that("text time in a zone with daylight saving: g.calibrate() is GGIR's across its changes", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  f <- tempfile(fileext = ".csv")
  old <- Sys.getenv("TZ", unset = NA)
  on.exit({
    unlink(f)
    if (is.na(old)) Sys.unsetenv("TZ") else Sys.setenv(TZ = old)
  })
  noise <- list(rmc.noise = 0.013 / 1.2)
  # desiredtz = "": the session's zone. The device's calendar runs on; read
  # in the zone, its times jump an hour forward at the end of daylight
  # saving in Europe/Amsterdam (2023-10-29 03:00, a gap GGIR fills) and
  # back an hour at its start in Europe/London (2024-03-31 01:00)
  cases <- list(list(tz = "Europe/Amsterdam", start = "2023-10-28 12:00:00", seed = 22),
                list(tz = "Europe/London", start = "2024-03-30 12:00:00", seed = 23))
  for (cs in cases) {
    Sys.setenv(TZ = cs$tz)
    rec <- adhoc_rec(sf = 5, seed = cs$seed)
    pr <- gravcal:::write_adhoc_csv(rec, f, sf = 5, time = "character", start = cs$start)
    for (extra in list(list(rmc.check4timegaps = TRUE), list(rmc.doresample = TRUE))) {
      b <- expect_adhoc_same(f, c(pr, noise, extra))
      expect_gt(b$ggir$npoints, 100)
    }
  }
})

test_that("rmc.doresample with text time: g.calibrate() is GGIR's, in a zone of fixed offset", {
  skip_if_quick()
  # slow tier; make quick keeps rmc.doresample's filled gaps against GGIR's
  # (above)
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  f <- tempfile(fileext = ".csv")
  # desiredtz = "": the session's zone, UTC + 1 all year; the grid starts at
  # the first stamp as as.POSIXct() reads it there
  old <- Sys.getenv("TZ", unset = NA)
  Sys.setenv(TZ = "Etc/GMT-1")
  on.exit({
    unlink(f)
    if (is.na(old)) Sys.unsetenv("TZ") else Sys.setenv(TZ = old)
  })
  noise <- list(rmc.noise = 0.013 / 1.2)
  rec <- adhoc_rec(sf = 5, seed = 21)
  # a sample rate 1 % off the nominal one: resampling moves every sample
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 5 * 1.01, time = "character")
  pr$rmc.sf <- 5
  b <- expect_adhoc_same(f, c(pr, noise, list(rmc.doresample = TRUE)))
  expect_gt(b$ggir$npoints, 100)
  # resampled: other numbers than the lines as they are
  b0 <- run_both(f, c(pr, noise))
  expect_false(identical(b0$ggir$spheredata, b$ggir$spheredata))
})

test_that("rmc.check4timegaps: what gravcal does not reproduce is an error naming it", {
  rec <- adhoc_rec(hours = 0.1, sf = 10, seed = 19)
  f <- tempfile(fileext = ".csv")
  old <- Sys.getenv("TZ", unset = NA)
  Sys.setenv(TZ = "UTC")  # desiredtz = "": the machine's zone
  on.exit({
    unlink(f)
    if (is.na(old)) Sys.unsetenv("TZ") else Sys.setenv(TZ = old)
  })
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = 10, time = "character")
  pr$rmc.check4timegaps <- TRUE
  gc <- function(...) g.calibrate(f, params_rawdata = utils::modifyList(pr, list(...)),
                                  verbose = FALSE)
  # a zone with daylight saving is followed (see below); the first stamp
  # of a block of GGIR's reading at a time that exists twice there is not
  d2 <- data.frame(time = format(as.POSIXct("2023-10-29 02:20:00", tz = "UTC") + (0:599) / 10,
                                 "%d/%m/%Y %H:%M:%OS3"), x = 0, y = 0, z = 1)
  f2 <- tempfile(fileext = ".csv")
  on.exit(unlink(f2), add = TRUE)
  utils::write.csv(d2, f2, row.names = FALSE, quote = FALSE)
  expect_error(g.calibrate(f2, params_rawdata = utils::modifyList(pr, list(rmc.col.temp = NULL)),
                           params_general = list(desiredtz = "Europe/Amsterdam"), verbose = FALSE),
               "`desiredtz` = \"Europe/Amsterdam\": a block of GGIR's reading of this file starts",
               fixed = TRUE)
  expect_error(gc(rmc.format.time = "%d/%m/%Y %R:%OS"), "directives .* not %R")
  expect_error(g.calibrate(f, params_rawdata = pr, verbose = FALSE, reader = "reference"),
               "`rmc.check4timegaps` = TRUE is taken by gravcal's own csv decoder only")
  # whole-second text stamps that repeat: GGIR spreads them over the second
  d <- data.frame(time = format(as.POSIXct(1.6e9 + (0:99) %/% 10, origin = "1970-01-01", tz = "UTC"),
                                "%d/%m/%Y %H:%M:%S"), x = 0.1, y = 0.2, z = 0.9)
  utils::write.table(d, f, sep = ",", quote = FALSE, row.names = FALSE, col.names = FALSE)
  expect_error(read_recording(f, rmc = list(rmc.firstrow.acc = 1, rmc.col.acc = 2:4, rmc.col.time = 1,
                                            rmc.unit.time = "POSIX", rmc.format.time = "%d/%m/%Y %H:%M:%OS",
                                            rmc.sf = 10, rmc.check4timegaps = TRUE)),
               "whole-second time stamps that repeat")
})
