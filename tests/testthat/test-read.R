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
  rec <- read_recording(cwa)
  ref <- GGIRread::readAxivity(cwa, start = 0, end = 1e6, progressBar = FALSE)
  expect_identical(rec$sf, ref$header$frequency)
  expect_true(all(c("x", "y", "z", "temperature") %in% names(rec$data)))
  expect_identical(nrow(rec$data), nrow(ref$data))
  expect_identical(rec$data$x, ref$data$x)
  expect_identical(rec$data$temperature, ref$data$temp)
  bin <- system.file("testfiles", "GENEActiv_testfile.bin", package = "GGIRread")
  rec <- read_recording(bin)
  ref <- GGIRread::readGENEActiv(bin, start = 1, end = 1e6)
  expect_identical(rec$sf, round(ref$header$SampleRate))
  expect_identical(rec$data$z, ref$data.out$z)
  expect_identical(rec$data$temperature, ref$data.out$temperature)
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
  expect_identical(rec$sf, attr(ref, "sample_rate"))
  expect_identical(rec$data$y, as.numeric(ref$Y))
  g <- skip_if_no_shared("ggir", "actigraph_testfile.gt3x")
  rec <- read_recording(g)
  expect_gt(nrow(rec$data), 1000)
  expect_true(all(abs(rec$data$x) <= 8))
})
