# write_recording(): samples written as each device format and read back
# (read_recording(), whose decoders are tested against the formats'
# reference readers in test-decode-*.R), within each format's resolution;
# what a format cannot hold is an error naming the argument; a user's file
# is never replaced unless asked.

wr_rec <- function(hours = 1, sf = 25, seed = 3) {
  simulate_recording(hours = hours, sf = sf, seed = seed)
}

test_that("each format round-trips the samples, the rate and the start", {
  rec <- wr_rec()
  d <- tempfile("wr")
  dir.create(d)
  # the format's step in g (x, y, z as stored), and whether it keeps the
  # temperature
  cases <- list(cwa = list(ext = ".cwa", step = 1 / 256 * 4, temp = TRUE),
                geneactiv = list(ext = ".bin", step = 100 / 25600, temp = TRUE),
                gt3x = list(ext = ".gt3x", step = 1 / 256, temp = FALSE),
                actigraph_csv = list(ext = ".csv", step = 0.001, temp = FALSE),
                movisens = list(ext = "", step = 1 / 2048, temp = TRUE),
                parmay = list(ext = ".bin", step = 16 / 65535, temp = TRUE))
  start <- as.POSIXct("2024-03-04 09:07:23", tz = "UTC")
  for (fmt in names(cases)) {
    cs <- cases[[fmt]]
    f <- file.path(d, paste0("r-", fmt, cs$ext))
    if (fmt == "gt3x") {
      expect_warning(out <- write_recording(rec, f, format = fmt, start = start),
                     "holds no temperature")
    } else {
      out <- write_recording(rec, f, format = fmt, start = start)
    }
    expect_identical(out, f)
    b <- read_recording(f)
    expect_identical(b$sf, 25, label = fmt)
    n <- nrow(b$data)
    expect_identical(n, nrow(rec), label = fmt)
    for (a in c("x", "y", "z")) {
      expect_lte(max(abs(b$data[[a]] - rec[[a]])), cs$step, label = paste(fmt, a))
    }
    if (!is.null(b$data$time)) {
      expect_equal(as.numeric(b$data$time[1]), as.numeric(start), tolerance = 1e-9,
                   label = paste(fmt, "start"))
    }
    expect_identical(!is.null(b$data$temperature), cs$temp, label = paste(fmt, "temperature"))
    if (cs$temp) expect_lt(abs(mean(b$data$temperature) - mean(rec$temperature)), 0.2)
  }
  # the extension names the format: .bin is GENEActiv's
  f <- file.path(d, "auto.bin")
  write_recording(rec, f)
  expect_identical(gravcal:::file_format(f), "geneactiv")
})

test_that("a file is never replaced unless asked, and a failed write leaves nothing", {
  rec <- wr_rec(hours = 0.25)
  d <- tempfile("wr")
  dir.create(d)
  f <- file.path(d, "mine.cwa")
  writeLines("a user's file", f)
  expect_error(write_recording(rec, f), "exists; give `overwrite = TRUE`")
  expect_identical(readLines(f), "a user's file")
  write_recording(rec, f, overwrite = TRUE)
  expect_identical(read_recording(f)$sf, 25)
  # the check before any writing: nothing left beside the file
  expect_error(write_recording(rec, file.path(d, "x.cwa"), sf = 30), "3200 / 2\\^k Hz")
  expect_identical(sort(dir(d, all.files = TRUE, no.. = TRUE)), "mine.cwa")
  # a Movisens folder: an empty one is taken, one with files is not
  m <- file.path(d, "mv")
  dir.create(m)
  write_recording(rec, m, format = "movisens")
  expect_true(file.exists(file.path(m, "unisens.xml")))
  expect_error(write_recording(rec, m, format = "movisens"), "exists")
})

test_that("what a format cannot hold is an error naming the argument", {
  rec <- wr_rec(hours = 0.25)
  f <- function(ext) tempfile(fileext = ext)
  expect_error(write_recording(rec, f(".gt3x"), sf = 30.5), "`sf`: this format holds a whole")
  expect_error(write_recording(rec, f(".bin"), format = "parmay",
                               start = as.POSIXct("2024-01-01 00:00:00.5", tz = "UTC")),
               "`start`: a Parmay")
  expect_error(write_recording(rec, f(".dat")), "`format`: .* has no extension")
  expect_error(write_recording(rec, f(".cwa"), format = "avi"), "`format` must be one of")
  expect_error(write_recording(rec[0, ], f(".cwa")), "no samples")
  expect_error(write_recording(rec[1:100, ], f(".bin")), "fewer than one GENEActiv page")
  expect_error(write_recording(data.frame(a = 1), f(".cwa")), "`x` must be a data frame")
  bad <- rec
  bad$y[5] <- NA
  expect_error(write_recording(bad, f(".cwa")), "`x\\$y` must be finite")
  expect_error(write_recording(rec[c("x", "y", "z")], f(".cwa")), "`sf` is needed")
  expect_error(write_recording(rec, f(".cwa"), start = "soon"), "`start` must be a time")
  expect_error(write_recording(rec, file.path(tempfile(), "a.cwa")), "does not exist")
  expect_error(write_recording(rec, f(".cwa"), overwrite = NA), "overwrite")
})

test_that("a written recording with known errors is calibrated from the file", {
  skip_if_quick()
  # a day and a half of GENEActiv at 25 Hz with simulate_recording()'s
  # errors (tens of mg): g.calibrate() on the file brings the rest windows'
  # error under 10 mg
  rec <- simulate_recording(hours = 36, sf = 25, seed = 8, temperature = FALSE)
  f <- write_recording(rec, tempfile(fileext = ".bin"))
  C <- suppressWarnings(gravcal::g.calibrate(f, verbose = FALSE))
  expect_gt(C$cal.error.start, 0.02)
  expect_lt(C$cal.error.end, 0.01)
})
