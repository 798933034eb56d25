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
