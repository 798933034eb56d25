# Cases a new user ran into (issue 31, "Tried as a new user would"): each
# ends in an error that names the argument and what was expected, or in the
# result the clean input gives; nothing the user had is lost.

rec <- simulate_recording(hours = 30, sf = 10, seed = 4)

test_that("write_coefs() refuses a target that is not a regular file", {
  skip_on_os("windows")  # no named pipes
  fit <- calibrate(rec, sf = 10, method = "ggir")
  dir <- tempfile("coefs")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  pipe <- file.path(dir, "coefs.csv")
  skip_if_not(system2("mkfifo", pipe) == 0, "mkfifo is not available")
  # writing would replace the pipe by a regular file, or (a device such as
  # /dev/full) end in the device's error
  expect_error(write_coefs(list(a.bin = fit), pipe),
               "`file` must be a regular file, not a named pipe: .*coefs.csv")
  expect_identical(gravcal:::file_kind(pipe), "fifo")
  expect_length(list.files(dir, all.files = TRUE, no.. = TRUE), 1)
})

test_that("write_coefs() on a really full disk: an error naming the file, no file left", {
  skip_on_os(c("windows", "mac"))
  mnt <- tempfile("tmpfs")
  dir.create(mnt)
  can_mount <- identical(unname(Sys.info()["user"]), "root") &&
    nzchar(Sys.which("mount")) &&
    suppressWarnings(system2("mount", c("-t", "tmpfs", "-o", "size=16k", "tmpfs", mnt),
                             stdout = FALSE, stderr = FALSE)) == 0
  skip_if_not(can_mount, "mounting a tmpfs needs root (test-cohort-faults.R injects the fault)")
  on.exit({
    system2("umount", mnt)
    unlink(mnt, recursive = TRUE)
  })
  fit <- calibrate(rec, sf = 10, method = "ggir")
  # 400 rows of about 300 bytes: more than the 16 kB the disk holds
  fits <- stats::setNames(rep(list(fit), 400), sprintf("p%04d.bin", 1:400))
  coefs <- file.path(mnt, "coefs.csv")
  expect_error(write_coefs(fits, coefs), paste0("Could not write \"", coefs, "\""),
               fixed = TRUE)
  expect_length(list.files(mnt, all.files = TRUE, no.. = TRUE), 0)
  # a small file still fits: it is written whole
  write_coefs(fits[1], coefs)
  expect_identical(read.csv(coefs)$filename, "p0001.bin")
})

test_that("calibrate_cli() with NA arguments: an error naming `args`", {
  expect_error(calibrate_cli(NA, quit = FALSE),
               "`args` must be character strings without NA; element 1 is NA.", fixed = TRUE)
  expect_error(calibrate_cli(c("--out", NA, "a.cwa"), quit = FALSE),
               "`args` must be character strings without NA; element 2 is NA.", fixed = TRUE)
  expect_error(calibrate_cli(c("--out", tempdir(), "x.cwa"), quit = NA),
               "`quit` must be TRUE or FALSE")
})

test_that("g.calibrate() with a malformed inspectfileobject: an error naming it", {
  d <- rec[c("x", "y", "z")]
  expect_error(g.calibrate(d, inspectfileobject = 5, verbose = FALSE),
               "`inspectfileobject` must be a list (GGIR's g.inspectfile() result), not 5.",
               fixed = TRUE)
  expect_error(g.calibrate(d, inspectfileobject = "a", verbose = FALSE),
               "`inspectfileobject` must be a list", fixed = TRUE)
  expect_error(g.calibrate(d, inspectfileobject = list(sf = "a"), verbose = FALSE),
               "`inspectfileobject$sf` must be a number > 0", fixed = TRUE)
  expect_error(g.calibrate(d, inspectfileobject = list(sf = c(10, 20)), verbose = FALSE),
               "`inspectfileobject$sf` must be a number > 0", fixed = TRUE)
  # a well-formed one is used as GGIR uses it
  expect_identical(g.calibrate(d, inspectfileobject = list(sf = 10), verbose = FALSE)[1:4],
                   g.calibrate(d, sf = 10, verbose = FALSE)[1:4])
})

test_that("`sf` that disagrees with a device file's own rate: an error naming both", {
  v <- as.matrix(simulate_recording(hours = 1, sf = 25, seed = 3)[c("x", "y", "z")])
  dir <- tempfile("rates")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  files <- c(bin = file.path(dir, "a.bin"), cwa = file.path(dir, "a.cwa"),
             gt3x = file.path(dir, "a.gt3x"))
  gravcal:::write_geneactiv_bin(v, files[["bin"]], sf = 25)
  gravcal:::write_cwa(v, files[["cwa"]], sf = 25)
  gravcal:::write_gt3x(v, files[["gt3x"]], sf = 25, start = 1.6e9)
  for (f in files) {
    msg <- "`sf` = 20 Hz, but \"a[.](bin|cwa|gt3x)\" records its own rate, 25 Hz"
    expect_error(calibrate(f, sf = 20), msg, label = f)
    expect_error(calibrate(f, sf = 20, method = "ggir"), msg, label = f)
    expect_error(g.calibrate(f, sf = 20, verbose = FALSE), msg, label = f)
    expect_error(rest_windows(f, sf = 20), msg, label = f)
    expect_error(read_recording(f, sf = 20), msg, label = f)
    # the file's own rate, given or not, is the rate used
    expect_identical(read_recording(f, sf = 25)$sf, 25)
    expect_identical(read_recording(f)$sf, 25)
  }
  # GGIR's own readers too
  for (f in files[c("bin", "cwa")]) {
    expect_error(read_recording(f, sf = 20, reader = "reference"),
                 "`sf` = 20 Hz, but .* 25 Hz", label = f)
  }
  skip_if_not_installed("read.gt3x")
  expect_error(read_recording(files[["gt3x"]], sf = 20, reader = "reference"),
               "`sf` = 20 Hz, but .* 25 Hz")
})

test_that("a cohort's `sf` is for its files that do not record their rate", {
  dir <- tempfile("mixed")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  # a 25 Hz .cwa beside a csv of samples at 10 Hz without time stamps
  gravcal:::write_cwa(as.matrix(rec[1:90000, c("x", "y", "z")]), file.path(dir, "a.cwa"),
                      sf = 25)
  utils::write.csv(rec[1:36000, c("x", "y", "z")], file.path(dir, "b.csv"), row.names = FALSE)
  tab <- calibrate_files(dir, method = "lightweight", outdir = file.path(dir, "out"),
                         sf = 10)
  expect_false(any(tab$status == "failed"))
  fits <- attr(tab, "fits")
  expect_identical(vapply(fits, function(f) as.numeric(attr(f$windows, "sf")), 0),
                   c(a.cwa = 25, b.csv = 10)[names(fits)])
})

test_that("x (g) and X (mg) in one data frame: an error naming both columns", {
  d <- rec[c("x", "y", "z")]
  d$X <- d$x * 1000
  msg <- "`x` has columns `x` and `X`; names are matched ignoring case, so it is not clear which is the acceleration in g."
  expect_error(calibrate(d, sf = 10), msg, fixed = TRUE)
  expect_error(calibrate(d, sf = 10, method = "ggir"), msg, fixed = TRUE)
  expect_error(g.calibrate(d, sf = 10, verbose = FALSE), "`datafile` has columns `x` and `X`")
  expect_error(rest_windows(d, sf = 10), msg, fixed = TRUE)
  expect_error(apply_calibration(d, calibrate(rec[c("x", "y", "z")], sf = 10)), msg, fixed = TRUE)
  d2 <- rec[c("x", "y", "z", "temperature")]
  d2$Temperature <- 0
  expect_error(calibrate(d2, sf = 10), "`x` has columns `temperature` and `Temperature`")
  f <- tempfile(fileext = ".rds")
  on.exit(unlink(f))
  saveRDS(d, f)
  expect_error(read_recording(f), "`file` has columns `x` and `X`")
})

test_that("own GGIR mode: the verdict on a 30-hour recording does not depend on chunksize", {
  ref <- calibrate(rec, sf = 10, method = "ggir", ggir_compat = FALSE)
  expect_identical(ref$status, "ok")
  for (cs in c(0.1, 0.2, 0.5)) {
    fit <- calibrate(rec, sf = 10, method = "ggir", ggir_compat = FALSE, chunksize = cs)
    expect_identical(fit$status, ref$status, label = paste("chunksize", cs))
    # the same windows, fitted to convergence: the same coefficients
    expect_equal(fit$offset, ref$offset, tolerance = 1e-6)
    expect_equal(diag(fit$K), diag(ref$K), tolerance = 1e-6)
  }
  # GGIR-compatible mode keeps GGIR's rule: a first block under 2 hours
  # means the file is too short (GGIR 3.3.9 g.calibrate gives "not enough data")
  expect_identical(calibrate(rec, sf = 10, method = "ggir", ggir_compat = TRUE,
                             chunksize = 0.1)$status, "too_short")
  # a recording shorter than 2 hours stays too short in own mode
  short <- simulate_recording(hours = 1.5, sf = 10, seed = 4)
  expect_identical(calibrate(short, sf = 10, method = "ggir", ggir_compat = FALSE)$status,
                   "too_short")
})

test_that("a named pipe, a folder or a device as the recording: an error before opening", {
  skip_on_os("windows")
  dir <- tempfile("pipe")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  pipe <- file.path(dir, "rec.cwa")
  skip_if_not(system2("mkfifo", pipe) == 0, "mkfifo is not available")
  # nothing writes to the pipe: opening it would block forever
  msg <- "must be a regular file, not a named pipe"
  expect_error(calibrate(pipe), paste0("`x` ", msg))
  expect_error(calibrate(pipe, method = "ggir"), paste0("`x` ", msg))
  expect_error(g.calibrate(pipe, verbose = FALSE), paste0("`datafile` ", msg))
  expect_error(read_recording(pipe), paste0("`file` ", msg))
  expect_error(rest_windows(pipe), paste0("`x` ", msg))
  expect_error(calibrate("/dev/null"), "`x` must be a regular file, not a device")
  # a cohort: a pipe named explicitly is refused, one in a folder not taken
  expect_error(calibrate_files(pipe, outdir = file.path(dir, "out")),
               "`files` must be a regular file, not a named pipe")
  utils::write.csv(rec[1:36000, c("x", "y", "z")], file.path(dir, "b.csv"), row.names = FALSE)
  tab <- calibrate_files(dir, method = "lightweight", outdir = file.path(dir, "out"),
                         sf = 10)
  expect_identical(tab$file, "b.csv")
  expect_identical(gravcal:::file_kind(dir), "directory")
  expect_identical(gravcal:::file_kind(file.path(dir, "none")), "missing")
})

test_that("one Inf temperature sample is left out, not the temperature model", {
  # a temperature effect to find (simulate_recording()'s `tempoffset`, g / degree C)
  trec <- simulate_recording(hours = 30, sf = 10, seed = 4,
                             tempoffset = c(0.002, -0.002, 0.001))
  fits <- function(r) {
    list(light = calibrate(r, sf = 10),
         ggir = calibrate(r, sf = 10, method = "ggir", ggir_compat = FALSE))
  }
  clean <- fits(trec)
  bad <- trec
  bad$temperature[c(5, 123457)] <- c(-Inf, Inf)  # one among the first 10
  dirty <- fits(bad)
  for (m in names(clean)) {
    expect_true(all(clean[[m]]$tempoffset != 0), label = m)
    expect_identical(dirty[[m]]$status, clean[[m]]$status, label = m)
    # two samples of 1.08 million moved: the coefficients within a tenth of a
    # per cent of the clean fit's
    expect_equal(dirty[[m]]$tempoffset, clean[[m]]$tempoffset, tolerance = 1e-3, label = m)
    expect_equal(dirty[[m]]$offset, clean[[m]]$offset, tolerance = 1e-3, label = m)
  }
  # GGIR-compatible mode is unchanged: an Inf makes the block's sd NaN, on
  # which GGIR 3.3.9's g.calibrate stops (`sd(...) < 0.01` is NA in its
  # `if`); gravcal's compatible mode calibrates without the temperature and
  # says so
  expect_warning(g <- g.calibrate(bad, sf = 10, verbose = FALSE), "temperature not used")
  expect_false(g$use.temp)
})
