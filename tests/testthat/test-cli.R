# calibrate_cli()'s part1 verb: g.part1() from the command line.

cli_quiet <- function(expr) {
  out <- NULL
  keep_warn(utils::capture.output(type = "message", invisible(utils::capture.output(
    out <- suppressWarnings(expr)))))
  out
}

cli_small_cwa <- function(dir, name, seed) {
  rec <- simulate_recording(hours = 3, sf = 25, seed = seed,
                            start = as.POSIXct("2024-03-04 09:07:23", tz = "UTC"))
  gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), file.path(dir, name), sf = 25,
                      start = as.numeric(rec$time[1]), temperature = rec$temperature)
  file.path(dir, name)
}

load_meta <- function(f) {
  e <- new.env()
  load(f, envir = e)
  v <- mget(sort(ls(e)), envir = e)
  v$M$bsc_qc <- NULL
  v$C$bsc_qc <- NULL
  v
}

test_that("calibrate_cli part1 writes g.part1()'s meta files for a folder", {
  skip_if_not_installed("GGIR")
  d <- file.path(tempfile("cli-"), "study")
  dir.create(d, recursive = TRUE)
  cli_small_cwa(d, "a.cwa", 3)
  cli_small_cwa(d, "b.cwa", 4)
  out <- tempfile("cli-out-")
  dir.create(out)
  msg <- utils::capture.output(type = "message", invisible(utils::capture.output(
    tab <- keep_warn(calibrate_cli(c("part1", "--out", out, "--params",
                                     "minimumFileSizeMB = 0, do.parallel = FALSE", d),
                                   quit = FALSE)))))
  expect_identical(tab$status, c("written", "written"))
  expect_true(any(grepl("2 recording(s): 2 written, 0 already there", msg, fixed = TRUE)))
  basic <- file.path(out, "output_study", "meta", "basic")
  expect_identical(sort(dir(basic)), c("meta_a.cwa.RData", "meta_b.cwa.RData"))
  # the same objects as g.part1() called from R
  out2 <- tempfile("cli-r-")
  cli_quiet(gravcal::g.part1(d, file.path(out2, "output_study"), minimumFileSizeMB = 0,
                             do.parallel = FALSE, verbose = FALSE))
  for (f in dir(basic)) {
    expect_true(identical(load_meta(file.path(basic, f)),
                          load_meta(file.path(out2, "output_study", "meta", "basic", f))),
                label = paste("the CLI's", f, "and g.part1()'s"))
  }
  # again: already there; --overwrite, --no-cal, --f0/--f1
  tab <- cli_quiet(calibrate_cli(c("part1", "--out", out, "--params",
                                   "minimumFileSizeMB = 0, do.parallel = FALSE", d),
                                 quit = FALSE))
  expect_identical(tab$status, c("exists", "exists"))
  tab <- cli_quiet(calibrate_cli(c("part1", "--out", out, "--overwrite", "--no-cal",
                                   "--f0", "2", "--f1", "2", "--params",
                                   "minimumFileSizeMB = 0, do.parallel = FALSE", d),
                                 quit = FALSE))
  expect_identical(tab$file, "b.cwa")
  expect_identical(tab$status, "written")
  expect_identical(load_meta(file.path(basic, "meta_b.cwa.RData"))$C$QCmessage,
                   "Autocalibration not done")
})

test_that("calibrate_cli part1: files with a study name, coefficients from a file", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("data.table")
  d <- tempfile("cli-files-")
  dir.create(d)
  f <- cli_small_cwa(d, "a.cwa", 3)
  coefs <- tempfile(fileext = ".csv")
  write_coefs(list(a.cwa = list(scale = c(1.01, 0.99, 1), offset = c(0.01, 0, -0.02),
                                     tempoffset = c(0, 0, 0), QCmessage = "given",
                                     meantempcal = 0)), coefs)
  out <- tempfile("cli-out-")
  dir.create(out)
  tab <- cli_quiet(calibrate_cli(c("part1", "--out", out, "--studyname", "s1", "--coefs", coefs,
                                   "--params", "minimumFileSizeMB = 0", f), quit = FALSE))
  expect_identical(tab$status, "written")
  C <- load_meta(file.path(out, "output_s1", "meta", "basic", "meta_a.cwa.RData"))$C
  expect_identical(C$scale, c(1.01, 0.99, 1))
  expect_identical(C$QCmessage, "given")
})

test_that("calibrate_cli part1 refuses bad arguments, saying why", {
  expect_error(calibrate_cli(c("part1", "x.cwa"), quit = FALSE), "--out DIR")
  expect_error(calibrate_cli(c("part1", "--out", tempdir(), "--bogus", "x.cwa"), quit = FALSE),
               "Unknown option `--bogus`")
  expect_error(calibrate_cli(c("part1", "--out", tempdir(), "no-such.cwa"), quit = FALSE),
               "No such file")
  f <- tempfile(fileext = ".cwa")
  writeBin(as.raw(1), f)
  expect_error(calibrate_cli(c("part1", "--out", tempdir(), f), quit = FALSE), "--studyname")
  expect_error(calibrate_cli(c("part1", "--out", tempdir(), "--studyname", "s", "--f0", "x", f),
                             quit = FALSE), "--f0")
  expect_error(calibrate_cli(c("part1", "--out", tempdir(), "--studyname", "s",
                               "--params", "a = ", f), quit = FALSE), "--params")
  help <- utils::capture.output(calibrate_cli(c("part1", "--help"), quit = FALSE))
  expect_true(any(grepl("meta_<file>.RData", help, fixed = TRUE)))
  expect_true(any(grepl("part1", utils::capture.output(calibrate_cli("--help", quit = FALSE)))))
})
