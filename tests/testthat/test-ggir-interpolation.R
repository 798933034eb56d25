# GGIR's reading parameters on .cwa files: interpolationType (1 linear, 2
# nearest neighbour) and frequency_tol, honoured by the native decoder
# (decode_cwa.hpp); desiredtz / configtz honoured, across changes of the
# zone's UTC offset too (R/zone.R), refused only where a block of GGIR's
# reading starts at a calendar time that exists twice or not at all.
# References: GGIRread 1.2.0's readAxivity() on the same bytes, called as
# GGIR 3.3-9's g.readaccfile calls it, and GGIR::g.calibrate() itself.

cwa_testfile <- function(name) {
  skip_if_not_installed("GGIRread")
  p <- system.file("testfiles", name, package = "GGIRread")
  if (!nzchar(p)) skip(paste("GGIRread has no test file", name))
  p
}

with_tz <- function(tz, code) {
  old <- Sys.getenv("TZ", unset = NA)
  Sys.setenv(TZ = tz)
  on.exit(if (is.na(old)) Sys.unsetenv("TZ") else Sys.setenv(TZ = old))
  code
}

# readAxivity window after window (B blocks), as g.readaccfile calls it, in
# the session's zone `tz` (configtz = desiredtz = "")
ref_cwa <- function(f, B, interpolationType = 1, frequency_tol = 0.1, tz = "UTC") {
  with_tz(tz, {
    out <- list()
    s <- 0
    header <- NULL
    repeat {
      P <- tryCatch(suppressWarnings(GGIRread::readAxivity(
        f, start = s, end = s + B, progressBar = FALSE, desiredtz = "",
        configtz = "", interpolationType = interpolationType,
        frequency_tol = frequency_tol, header = header)),
        error = function(e) NULL)
      if (is.null(P) || is.null(P$data)) break
      header <- P$header
      # light too: the native decoder gives it (native_block()'s default)
      out[[length(out) + 1]] <- P$data[, c("x", "y", "z", "temp", "time", "light")]
      s <- s + B
    }
    d <- do.call(rbind, out)
    names(d)[4] <- "temperature"
    rownames(d) <- NULL
    d
  })
}

# the native decoder, one read of B blocks at a time
nat_cwa <- function(f, B, opts) {
  h <- gravcal:::native_open(f, "cwa", c(list(compat = 1), opts))
  on.exit(gravcal:::gc_decoder_close(h$ptr))
  out <- list()
  repeat {
    b <- gravcal:::native_block(h, B, B * 120 + 1000, TRUE, TRUE)
    n <- b$to
    if (n > 0) out[[length(out) + 1]] <- as.data.frame(lapply(b$cols, `[`, seq_len(n)))
    if (b$done || (n == 0 && b$units == 0)) break
  }
  d <- do.call(rbind, out)
  rownames(d) <- NULL
  d
}

# A 30-hour .cwa at 25 Hz from the simulator: rest on several faces, with
# movement and temperature; `drift`: from hour 3 to hour 20 the block times
# advance 5 % slower than the samples (readAxivity observes a rate 5 % off
# the nominal one: imputed when frequency_tol is below 0.05).
synth_cwa <- function(hours = 30, sf = 25, seed = 61, start = 1.7e9, drift = FALSE) {
  rec <- simulate_recording(hours = hours, sf = sf, seed = seed,
                            tempoffset = c(0.002, -0.001, 0.0015))
  dt <- rep(1 / sf, nrow(rec))
  if (drift) dt[(3 * 3600 * sf):(20 * 3600 * sf)] <- 1 / (sf * 1.05)
  f <- tempfile(fileext = ".cwa")
  gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), f, sf = sf,
                      start = start, temperature = rec$temperature, range = 8,
                      time = start + cumsum(dt) - dt[1])
  f
}

test_that("interpolationType 2: the decoder gives readAxivity's samples to the bit", {
  for (name in c("ax3_testfile.cwa", "ax6_testfile.cwa",
                 "ax3_testfile_corrupt_blocks_0_13_14_142_143_144.cwa")) {
    f <- cwa_testfile(name)
    for (B in c(54000, 37)) {
      ref <- ref_cwa(f, B, interpolationType = 2)
      nat <- nat_cwa(f, B, list(interpolation = 2))
      expect_gt(nrow(ref), 11000)
      expect_identical(nat, ref, label = paste(name, "B =", B))
      # and it is not the linear result (the parameter is not ignored)
      lin <- nat_cwa(f, B, list(interpolation = 1))
      expect_false(identical(lin$x, nat$x), label = paste(name, "B =", B))
    }
  }
})

test_that("frequency_tol: the decoder imputes where readAxivity does", {
  f <- cwa_testfile("ax3_testfile.cwa")
  for (tol in c(0.1, 0.001)) {
    ref <- ref_cwa(f, 37, frequency_tol = tol)
    nat <- nat_cwa(f, 37, list(frequency_tol = tol))
    expect_identical(nat, ref, label = paste("frequency_tol =", tol))
  }
})

test_that("g.calibrate() is GGIR's with interpolationType 1 and 2 (.cwa)", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  files <- c(cwa_testfile("ax3_testfile.cwa"), cwa_testfile("ax6_testfile.cwa"),
             cwa_testfile("ax3_testfile_corrupt_blocks_0_13_14_142_143_144.cwa"))
  long <- synth_cwa()
  on.exit(unlink(long))
  n <- 0
  for (f in c(files, long)) {
    res <- list()
    for (it in 1:2) {
      b <- with_tz("UTC", run_both(f, list(interpolationType = it)))
      expect_same_as_ggir(b)
      n <- n + 1
      res[[it]] <- b$ggir
    }
    if (identical(f, long)) {
      # 30 hours: a fit, and the two interpolations give other numbers
      expect_gt(res[[2]]$npoints, 50)
      expect_false(identical(res[[1]]$spheredata, res[[2]]$spheredata))
    }
  }
  expect_identical(n, 8)
})

test_that("g.calibrate() is GGIR's with frequency_tol 0.1 and 0.02 (.cwa, a clock off by 5 %)", {
  skip_if_quick()
  # slow tier: a 30-hour .cwa through both, twice; make quick keeps the
  # decoder's imputation against readAxivity's (above)
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  f <- synth_cwa(seed = 62, drift = TRUE)
  on.exit(unlink(f))
  res <- list()
  for (tol in c(0.1, 0.02)) {
    b <- with_tz("UTC", run_both(f, list(frequency_tol = tol)))
    expect_same_as_ggir(b)
    res[[length(res) + 1]] <- b$ggir
  }
  # the tolerance changes GGIR's result here (imputed hours are not rest
  # windows of the device's own samples)
  expect_gt(res[[1]]$npoints, 50)
  expect_false(identical(res[[1]]$spheredata, res[[2]]$spheredata))
})

test_that("desiredtz: a zone with a fixed offset over the recording gives GGIR's result", {
  skip_if_quick()
  # slow tier: a 30-hour .cwa through both; make quick keeps the zone's
  # offsets (R/zone.R) and the refused block start below
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  # GGIR's desiredtz = "" is the session's zone: Europe/Amsterdam (UTC + 1
  # in November, no change within these 30 hours) moves every block time by
  # an hour, which leaves the result to the bit
  f <- synth_cwa(seed = 63)
  on.exit(unlink(f))
  for (it in 1:2) {
    b <- with_tz("Europe/Amsterdam", run_both(f, list(interpolationType = it)))
    expect_same_as_ggir(b)
  }
})

test_that("interpolationType 2: GENEActiv at a rate that is not whole, GGIR's to the bit", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  rec <- simulate_recording(hours = 30, sf = 12.5, seed = 64,
                            tempoffset = c(0.002, -0.001, 0.0015))
  f <- tempfile(fileext = ".bin")
  on.exit(unlink(f))
  gravcal:::write_geneactiv_bin(rec, f, sf = 12.5)
  res <- list()
  for (it in 1:2) {
    b <- run_both(f, list(interpolationType = it))
    expect_same_as_ggir(b)
    res[[it]] <- b$ggir
  }
  expect_false(identical(res[[1]]$spheredata, res[[2]]$spheredata))
})

# GGIR's and gravcal's g.calibrate() with GGIR's params_general changed by
# `general` (desiredtz, configtz)
run_both_general <- function(f, general, rawdata = list()) {
  pr <- utils::modifyList(GGIR::load_params()$params_rawdata, rawdata)
  pg <- utils::modifyList(GGIR::load_params()$params_general, general)
  quiet <- function(expr) {
    out <- NULL
    keep_warn(utils::capture.output(out <- suppressWarnings(expr)))
    out
  }
  R <- ggir_cached("g.calibrate", f, list(params_rawdata = pr, params_general = pg), {
    I <- quiet(GGIR::g.inspectfile(f, params_rawdata = pr, params_general = pg))
    quiet(GGIR::g.calibrate(f, params_rawdata = pr, params_general = pg,
                            inspectfileobject = I, verbose = FALSE))
  })
  list(ggir = R,
       gravcal = quiet(g.calibrate(f, params_rawdata = pr, params_general = pg,
                                   verbose = FALSE)))
}

test_that("a zone's offsets by calendar minute, as this R converts (R/zone.R)", {
  # Europe/Amsterdam from 2000 to 2063: two changes a year; the calendar hour
  # that exists twice each autumn marked as one span, 02:00 to 03:00
  z <- gravcal:::zone_table("Europe/Amsterdam")
  expect_identical(length(z$at), 129L)
  expect_identical(sort(unique(z$off)), c(3600, 7200))
  autumn <- as.numeric(as.POSIXct("2023-10-29 02:00:00", tz = "UTC"))
  expect_true(autumn %in% z$amb_lo)
  expect_true(all(z$amb_hi - z$amb_lo == 3600))
  fmt <- "%Y-%m-%d %H:%M:%S"
  for (txt in c("2023-03-26 01:59:00", "2023-03-26 03:00:00", "2023-10-29 03:00:00", "2023-07-01 12:00:00")) {
    cal <- as.numeric(as.POSIXct(txt, tz = "UTC"))
    off <- z$off[findInterval(cal, z$at)]
    expect_identical(cal - off, as.numeric(as.POSIXct(txt, format = fmt, tz = "Europe/Amsterdam")),
                     label = txt)
  }
  # a fixed offset: no table (the calendar read as UTC shifts every time alike)
  expect_null(gravcal:::zone_table("UTC"))
  expect_null(gravcal:::zone_table("Etc/GMT-1"))
  # the quick test of a zone without changes (the instants' offsets) gives
  # what converting every day's calendar time gives, with and without
  # changes, the session's zone included
  for (tz in c("", "UTC", "Etc/GMT-1", "Asia/Kolkata", "Europe/Amsterdam", "America/Sao_Paulo")) {
    expect_identical(gravcal:::zone_table_make(tz), gravcal:::zone_table_make(tz, fast = FALSE),
                     label = paste0("zone_table_make(\"", tz, "\")"))
  }
  o <- gravcal:::zone_options("Europe/Amsterdam")
  expect_identical(o$tz_n, 129L)
  expect_identical(o$tz_amb_n, 64L)
})

test_that("desiredtz: across a change of UTC offset the decoder gives readAxivity's block times", {
  skip_if_quick()
  skip_if_not_installed("GGIRread")
  # 30 hours across the end of daylight saving in Europe/Amsterdam (its
  # calendar 03:00 on 2023-10-29 is 02:00 UTC, not 01:00: readAxivity's
  # times jump an hour there, and its grid fills the hour) and across its
  # start in Europe/London (2024-03-31, 01:00 to 02:00 does not exist: the
  # times go back an hour and the grid skips it); the device's calendar
  # runs on without a jump
  B <- gravcal:::format_block_units("cwa", 25, 1)
  cases <- list(list(tz = "Europe/Amsterdam", start = "2023-10-28 12:00:00", rows = 31),
                list(tz = "Europe/London", start = "2024-03-30 12:00:00", rows = 29))
  for (cs in cases) {
    f <- synth_cwa(seed = 65, start = as.numeric(as.POSIXct(cs$start, tz = "UTC")))
    ref <- ref_cwa(f, B, tz = cs$tz)
    nat <- nat_cwa(f, B, list(zone = cs$tz))
    expect_identical(nat, ref, label = cs$tz)
    # the hour filled or skipped: 31 or 29 hours of grid from 30 of samples
    expect_equal(nrow(ref) / (25 * 3600), cs$rows, tolerance = 0.01, label = cs$tz)
    # in UTC (no zone) the times are the calendar's, an hour apart in places
    utc <- nat_cwa(f, B, list())
    expect_false(identical(utc$time, nat$time))
    unlink(f)
  }
})

test_that("desiredtz, configtz: across a change of UTC offset g.calibrate() gives GGIR's result", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  # the end of daylight saving in the session's zone (desiredtz = ""), with
  # interpolationType 1 and 2
  f <- synth_cwa(seed = 65, start = as.numeric(as.POSIXct("2023-10-28 12:00:00", tz = "UTC")))
  on.exit(unlink(f))
  res <- list()
  for (it in 1:2) {
    b <- with_tz("Europe/Amsterdam", run_both(f, list(interpolationType = it)))
    expect_same_as_ggir(b)
    res[[it]] <- b$ggir
  }
  # the zone changes GGIR's result (the test can fail): UTC's differs
  utc <- with_tz("UTC", run_both(f))
  expect_same_as_ggir(utc)
  expect_false(identical(utc$ggir$spheredata, res[[1]]$spheredata))
  # the start of daylight saving, named by desiredtz, and by configtz over
  # a desiredtz without it, in a session in UTC
  f2 <- synth_cwa(seed = 66, start = as.numeric(as.POSIXct("2024-03-30 12:00:00", tz = "UTC")))
  on.exit(unlink(f2), add = TRUE)
  for (g in list(list(desiredtz = "Europe/London"),
                 list(desiredtz = "UTC", configtz = "Europe/London"))) {
    b <- with_tz("UTC", run_both_general(f2, g))
    expect_same_as_ggir(b)
    expect_gt(b$ggir$npoints, 50)
  }
})

test_that("desiredtz: a block of GGIR's reading that starts at a time that exists twice is refused", {
  # Europe/Amsterdam's calendar 02:00 to 03:00 on 2023-10-29 exists twice;
  # GGIR's first block starts there, where readAxivity's time depends on R's
  # conversions before it
  f <- synth_cwa(hours = 2, seed = 67,
                 start = as.numeric(as.POSIXct("2023-10-29 02:20:00", tz = "UTC")))
  on.exit(unlink(f))
  expect_error(with_tz("Europe/Amsterdam", g.calibrate(f, verbose = FALSE)),
               "`desiredtz` = \"\" (the session's time zone): a block of GGIR's reading",
               fixed = TRUE)
  expect_error(with_tz("UTC", g.calibrate(f, verbose = FALSE, configtz = "Europe/Amsterdam")),
               "`configtz` = \"Europe/Amsterdam\": a block", fixed = TRUE)
  # an hour later the calendar is unambiguous again
  f2 <- synth_cwa(hours = 2, seed = 67,
                  start = as.numeric(as.POSIXct("2023-10-29 03:20:00", tz = "UTC")))
  on.exit(unlink(f2), add = TRUE)
  expect_silent(with_tz("Europe/Amsterdam", suppressWarnings(g.calibrate(f2, verbose = FALSE))))
})
