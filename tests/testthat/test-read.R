test_that("the bundled example reads with its sampling rate and truth", {
  rec <- read_recording(gravcal_example())
  expect_equal(rec$sf, 10)
  expect_true(all(c("time", "x", "y", "z", "temperature") %in%
                    names(rec$data)))
  expect_length(attr(rec$data, "truth")$params, 9)
})

test_that("csv files read, with sf from the time stamps", {
  rec <- simulate_recording(hours = 0.05, sf = 25, seed = 71)
  f <- tempfile(fileext = ".csv")
  d <- rec
  d$time <- as.numeric(d$time)
  utils::write.csv(d, f, row.names = FALSE)
  r <- read_recording(f)
  expect_equal(r$sf, 25)
  expect_equal(r$data$x, rec$x)
  fit1 <- calibrate(f)
  expect_s3_class(fit1, "gravcal_fit")
})

test_that("missing and unsupported files get clear errors", {
  expect_error(read_recording("no/such/file.csv"), "does not exist")
  f <- tempfile(fileext = ".xyz")
  writeLines("1", f)
  expect_error(read_recording(f), "unsupported extension \".xyz\"")
  expect_error(read_recording(c("a", "b")), "single file path")
  g <- tempfile(fileext = ".csv")
  utils::write.csv(data.frame(x = 1, y = 2, z = 3), g, row.names = FALSE)
  expect_error(read_recording(g), "give `sf`")
})

test_that("the devices' own files read: Axivity, GENEActiv, ActiGraph", {
  skip_if_not_installed("GGIRread")
  cwa <- system.file("testfiles", "ax3_testfile.cwa", package = "GGIRread")
  ref <- GGIRread::readAxivity(cwa, start = 0, end = 1e6, progressBar = FALSE)
  # the reference reader: GGIRread's samples, resampled onto its grid
  rec <- read_recording(cwa, reader = "reference")
  expect_identical(rec$sf, ref$header$frequency)
  expect_true(all(c("x", "y", "z", "temperature") %in% names(rec$data)))
  expect_identical(nrow(rec$data), nrow(ref$data))
  expect_identical(rec$data$x, ref$data$x)
  expect_identical(rec$data$temperature, ref$data$temp)
  # the native reader: the samples as stored (not resampled), over the same
  # time span, in the device's 1/256 g steps, nothing skipped
  nat <- read_recording(cwa)
  expect_identical(nat$sf, ref$header$frequency)
  expect_identical(as.numeric(nat$data$time[1]), ref$data$time[1])
  # 145 packed blocks of 120 samples (GGIRread's grid runs on to the end
  # time of the last block it looks ahead to)
  expect_identical(nat$input$report$units, 145)
  expect_identical(nrow(nat$data), 145L * 120L)
  expect_identical(nat$data$x * 256, round(nat$data$x * 256))
  expect_identical(nat$input$report$skipped, 0)
  # and light, each sample its block's raw value (283 to 435 in this file's
  # blocks: test-decode-cwa.R reads them from its bytes); the reference
  # reader gives no light column
  expect_identical(names(nat$data), c("x", "y", "z", "temperature", "time", "light"))
  expect_identical(range(nat$data$light), c(283, 435))
  expect_false("light" %in% names(rec$data))
  bin <- system.file("testfiles", "GENEActiv_testfile.bin", package = "GGIRread")
  ref <- GGIRread::readGENEActiv(bin, start = 1, end = 1e6)
  rec <- read_recording(bin, reader = "reference")
  expect_identical(rec$sf, round(ref$header$SampleRate))
  expect_identical(rec$data$z, ref$data.out$z)
  expect_identical(rec$data$temperature, ref$data.out$temperature)
  # the native reader: the device's own rate (85.7 Hz), values in double
  # where GGIRread rounds them to float (so equal to float precision)
  rec <- read_recording(bin)
  expect_identical(rec$sf, ref$header$SampleRate)
  expect_equal(rec$data$z, ref$data.out$z, tolerance = 1e-7)
  expect_equal(rec$data$temperature, ref$data.out$temperature, tolerance = 1e-7)
  # light in lux as readGENEActiv gives it, to the bit
  expect_identical(rec$data$light, ref$data.out$light)
  # windows from the file streamed block by block = from the data read whole
  w1 <- rest_windows(bin, progress = FALSE)
  w2 <- rest_windows(rec$data, sf = rec$sf)
  expect_identical(w1[c("mean_x", "sd_z", "temperature", "rest")],
                   w2[c("mean_x", "sd_z", "temperature", "rest")])
})

test_that("ActiGraph .gt3x files read (read.gt3x's and GGIR's test files)", {
  skip_if_not_installed("read.gt3x")
  f <- system.file("extdata", "TAS1H30182785_2019-09-17.gt3x", package = "read.gt3x")
  rec <- read_recording(f)
  ref <- read.gt3x::read.gt3x(f, asDataFrame = TRUE, imputeZeroes = TRUE)
  expect_identical(rec$sf, as.numeric(attr(ref, "sample_rate")))
  expect_identical(rec$data$y, as.numeric(ref$Y))
  g <- skip_if_no_shared("ggir", "actigraph_testfile.gt3x")
  rec <- read_recording(g)
  expect_gt(nrow(rec$data), 1000)
  expect_true(all(abs(rec$data$x) <= 8))
})

test_that("a .gt3x file streamed in blocks gives the samples of a whole read", {
  skip_if_quick()
  skip_if_not_installed("read.gt3x")
  # read.gt3x's batches count stored seconds and leave out idle-sleep gaps;
  # the block reader must put the gaps back as zeros where a whole read
  # (imputeZeroes = TRUE) has them. Both files have idle-sleep gaps.
  files <- c(system.file("extdata", "TAS1H30182785_2019-09-17.gt3x", package = "read.gt3x"),
             shared_data("ggir", "actigraph_testfile.gt3x"))
  files <- files[nzchar(files)]
  for (f in files) {
    rr <- read_recording(f)
    whole <- rr$data
    expect_gt(sum(whole$x == 0 & whole$y == 0 & whole$z == 0), 1000)
    src <- gravcal:::open_source(f, chunksize = 60 / 43200, # 60 s blocks
                                 reader = "reference")
    parts <- list()
    repeat {
      b <- src$read(length(parts) + 1)
      if (is.null(b)) break
      parts[[length(parts) + 1]] <- b$data
    }
    expect_gt(length(parts), 3)
    s <- do.call(rbind, parts)
    n <- nrow(s)
    # the same samples at the same positions; a whole read also pads the
    # idle time after the last stored sample with zeros
    expect_identical(s$x, whole$x[seq_len(n)], label = basename(f))
    expect_identical(s$z, whole$z[seq_len(n)], label = basename(f))
    rest <- whole[-seq_len(n), ]
    expect_true(all(rest$x == 0 & rest$y == 0 & rest$z == 0))
    # the native decoder streamed into the segmenter: the windows of the
    # recording read whole, with the idle-sleep zeros in place
    w1 <- rest_windows(f, skip_zero = FALSE, progress = FALSE)
    w2 <- rest_windows(whole, sf = rr$sf, skip_zero = FALSE)
    expect_identical(w1$mean_x, w2$mean_x[seq_along(w1$mean_x)], label = basename(f))
  }
})

test_that("a GENEActiv .bin written by gravcal reads back through GGIRread", {
  skip_if_not_installed("GGIRread")
  rec <- simulate_recording(hours = 26, sf = 10, seed = 7, resolution = 0)
  f <- tempfile(fileext = ".bin")
  on.exit(unlink(f))
  gravcal:::write_geneactiv_bin(rec, f, sf = 10, gain = c(25875, 25734, 25538),
                                offset = c(439, -662, -3056))
  back <- read_recording(f)
  expect_identical(back$sf, 10)
  n <- nrow(back$data)
  expect_identical(n, nrow(rec) %/% 300L * 300L)
  # 12-bit counts: within half a count (100 / gain g) of the samples, plus
  # single precision (GGIRread converts in float)
  expect_lt(max(abs(back$data$x - rec$x[1:n])), 0.5 * 100 / 25875 + 1e-6)
  expect_lt(max(abs(back$data$z - rec$z[1:n])), 0.5 * 100 / 25538 + 1e-6)
  # temperature: one value per page of 300 samples, the page mean
  page_mean <- rep(colMeans(matrix(rec$temperature[1:n], 300)), each = 300)
  expect_lt(max(abs(back$data$temperature - page_mean)), 0.05 + 1e-6)
  # 26 hours at 10 Hz are 3 of GGIR's GENEActiv blocks: streamed windows are
  # the windows of the whole recording
  w1 <- rest_windows(f, progress = FALSE)
  w2 <- rest_windows(back$data, sf = 10)
  expect_identical(w1[c("mean_x", "sd_y", "temperature", "rest")],
                   w2[c("mean_x", "sd_y", "temperature", "rest")])
})

test_that("read_recording() reads ActiGraph csv exports, with or without time stamps", {
  rec <- simulate_recording(hours = 1, sf = 30, seed = 3, temperature = FALSE)
  for (ts in c(FALSE, TRUE)) {
    f <- tempfile(fileext = ".csv")
    gravcal:::write_actigraph_csv(rec, f, sf = 30, timestamps = ts)
    r <- read_recording(f)
    unlink(f)
    expect_identical(r$sf, 30)
    # the native reader adds each sample's time: the header's start + i / sf,
    # or the time stamp column
    expect_identical(names(r$data), c("x", "y", "z", "time"))
    expect_equal(as.numeric(r$data$time[c(1, 31)]),
                 as.numeric(as.POSIXct("2023-05-11 09:00:00", tz = "UTC")) + c(0, 1))
    expect_identical(nrow(r$data), nrow(rec))
    # fwrite writes the shortest decimal that reads back to the same double
    expect_identical(r$data$y, rec$y)
  }
})

test_that("sf comes from time stamps written as text, whole seconds included", {
  rec <- simulate_recording(hours = 0.5, sf = 10, seed = 4)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  # write.csv() writes POSIXct times in whole seconds: 10 rows per stamp
  utils::write.csv(rec, f, row.names = FALSE)
  expect_match(readLines(f, n = 3)[3], "2024-01-01 00:00:00")
  expect_identical(read_recording(f)$sf, 10)
  # stamps with fractions of a second
  rec$time <- format(rec$time, "%Y-%m-%d %H:%M:%OS3")
  utils::write.csv(rec, f, row.names = FALSE)
  expect_identical(read_recording(f)$sf, 10)
  # unreadable time stamps: no guess, an error asking for sf
  rec$time <- "soon"
  utils::write.csv(rec, f, row.names = FALSE)
  expect_error(read_recording(f), "unknown: give `sf`")
  expect_identical(gravcal:::sf_from_time(c(5, 5, 5)), NULL)
  expect_identical(gravcal:::sf_from_time(as.POSIXct("2024-01-01", tz = "UTC") + (0:99) / 25), 25)
})

test_that("files that hold no samples: errors that name the file and why", {
  d <- snap_dir("gravcal-read-errors")
  on.exit(unlink(d, recursive = TRUE))
  tr <- scrub_dir(d)
  rec <- simulate_recording(hours = 0.1, sf = 10, seed = 1)
  # .rds: empty, truncated, not a data frame; folders named like files
  empty <- file.path(d, "empty.rds")
  file.create(empty)
  cut <- file.path(d, "cut.rds")
  saveRDS(rec, cut)
  writeBin(readBin(cut, raw(), 200), cut)
  notdf <- file.path(d, "vector.rds")
  saveRDS(1:10, notdf)
  dir.create(folder_rds <- file.path(d, "folder.rds"))
  dir.create(folder_cwa <- file.path(d, "folder.cwa"))
  expect_snapshot(error = TRUE, read_recording(empty), transform = tr)
  expect_snapshot(error = TRUE, calibrate(empty), transform = tr)
  expect_snapshot(error = TRUE, read_recording(cut), transform = tr)
  expect_snapshot(error = TRUE, calibrate(cut, method = "ggir"), transform = tr)
  expect_snapshot(error = TRUE, read_recording(notdf), transform = tr)
  expect_snapshot(error = TRUE, read_recording(folder_rds), transform = tr)
  expect_snapshot(error = TRUE, calibrate(folder_cwa), transform = tr)
  expect_snapshot(error = TRUE, rest_windows(folder_cwa), transform = tr)
  expect_snapshot(error = TRUE, g.calibrate(folder_rds, verbose = FALSE),
                  transform = tr)
  # csv: comma decimals in comma-separated fields, a header and no rows, a
  # binary file, semicolons through the reference reader
  commas <- file.path(d, "comma-decimals.csv")
  writeLines(c("x,y,z", "0,5,1,2,0,3", "0,5,1,2,0,3"), commas)
  header <- file.path(d, "header-only.csv")
  writeLines("x,y,z", header)
  binary <- file.path(d, "binary.csv")
  writeBin(as.raw((seq_len(2000) * 37) %% 256), binary)
  semi <- file.path(d, "semicolons.csv")
  utils::write.table(rec[1:50, c("x", "y", "z")], semi, sep = ";",
                     row.names = FALSE)
  expect_snapshot(error = TRUE, read_recording(commas, sf = 10), transform = tr)
  expect_snapshot(error = TRUE, read_recording(header, sf = 10), transform = tr)
  expect_snapshot(error = TRUE, read_recording(binary, sf = 10), transform = tr)
  expect_snapshot(error = TRUE, calibrate(binary, sf = 10), transform = tr)
  expect_snapshot(error = TRUE, read_recording(semi, sf = 10, reader = "reference"),
                  transform = tr)
  # gravcal's own reader reads semicolons (and comma decimals with them)
  expect_equal(read_recording(semi, sf = 10)$data$x, rec$x[1:50])
  # a header and no rows is a recording too short to calibrate
  expect_identical(calibrate(header, sf = 10)$status, "too_short")
})

test_that("empty, truncated and unusual .bin files: errors that say why", {
  d <- snap_dir("gravcal-bin-errors")
  on.exit(unlink(d, recursive = TRUE))
  tr <- scrub_dir(d)
  rec <- simulate_recording(hours = 1, sf = 10, seed = 1)
  ok <- file.path(d, "ok.bin")
  gravcal:::write_geneactiv_bin(rec, ok, sf = 10)
  b <- readBin(ok, raw(), file.size(ok))
  empty <- file.path(d, "empty.bin")
  file.create(empty)
  cut <- file.path(d, "cut.bin")
  writeBin(b[1:100], cut)
  # a Matrix/Parmay .BIN without packets, an older Genea file: said so
  matrix_bin <- file.path(d, "matrix.BIN")
  writeBin(c(as.raw(rep(0, 512)), charToRaw("MDTC"), as.raw(rep(1, 600))),
           matrix_bin)
  genea <- file.path(d, "genea.bin")
  writeLines(c("GENEA Serial Number:1234", "junk"), genea)
  # a header rate of 0.1 Hz that no page holds
  slow <- file.path(d, "slow.bin")
  L <- readLines(ok)
  i <- grep("^Measurement Frequency", L)
  L[i] <- "Measurement Frequency:0.1 Hz"
  writeLines(L, slow)
  for (f in c(empty, cut, matrix_bin, genea)) {
    expect_snapshot(error = TRUE, read_recording(f), transform = tr)
  }
  expect_snapshot(error = TRUE, calibrate(cut), transform = tr)
  expect_snapshot(error = TRUE, read_recording(slow), transform = tr)
  expect_snapshot(error = TRUE, calibrate(slow), transform = tr)
  expect_snapshot(error = TRUE, calibrate(slow, method = "ggir"), transform = tr)
})

test_that("the pump's options: an unknown key and a missing one are errors naming them", {
  # each stage reads its option list once (OptionReader, src/glue_pipeline.cpp):
  # a key no stage reads is a misspelling, never ignored
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  rec <- readRDS(gravcal_example())
  write_recording(rec[1:3000, ], f, format = "actigraph_csv")
  pump <- function() {
    gravcal:::open_source(f, arg = "file", reader = "native", compat = FALSE)$pump()
  }
  expect_equal(nrow(as.data.frame(gravcal:::gc_pump(pump(), "samples", list(time = 0)))), 3000)
  expect_error(gravcal:::gc_pump(pump(), "samples", list(time = 0, tiem = 1)),
               "unknown option 'tiem'", fixed = TRUE)
  expect_error(gravcal:::gc_pump(pump(), "windows", list(window_samples = 100)),
               "option 'skip_zero' is missing", fixed = TRUE)
})
