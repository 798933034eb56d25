# The core's AVX2 paths (inst/include/gravcal/simd.hpp) against its baseline
# ones: where the processor has AVX2 they run by default, and they must give
# the same bits. gc_set_avx2(FALSE) turns them off for one side of each
# comparison. On a processor without AVX2 there is nothing to compare.

with_avx2 <- function(on, expr) {
  old <- gc_set_avx2(TRUE)  # whether the processor has them
  on.exit(gc_set_avx2(old))
  gc_set_avx2(on)
  expr
}

skip_if_no_avx2 <- function() {
  has <- gc_set_avx2(TRUE)
  if (!has) skip("the processor has no AVX2: only the baseline paths run here")
}

both_ways <- function(f) {
  list(avx2 = with_avx2(TRUE, f()), baseline = with_avx2(FALSE, f()))
}

decode_all <- function(file, format, compat, chunk) {
  d <- native_read_all(file, format, list(compat = compat), time = TRUE, chunk = chunk)
  list(data = d, report = attr(d, "report"))
}

test_that("the switch turns the AVX2 paths off and back on", {
  skip_if_no_avx2()
  expect_false(gc_set_avx2(FALSE))
  expect_true(gc_set_avx2(TRUE))
})

test_that("GRAVCAL_NO_AVX2 in the environment turns them off for the process", {
  skip_if_no_avx2()
  ask <- function(value) {
    env <- if (is.null(value)) character(0) else paste0("GRAVCAL_NO_AVX2=", value)
    out <- system2(file.path(R.home("bin"), "Rscript"),
                   c("-e", shQuote("cat(gravcal:::gc_use_avx2())")),
                   stdout = TRUE, stderr = FALSE, env = env)
    utils::tail(out, 1)
  }
  old <- Sys.getenv("GRAVCAL_NO_AVX2", unset = NA)
  Sys.unsetenv("GRAVCAL_NO_AVX2")
  on.exit(if (!is.na(old)) Sys.setenv(GRAVCAL_NO_AVX2 = old))
  expect_identical(ask(NULL), "TRUE")
  expect_identical(ask("0"), "TRUE")
  expect_identical(ask("1"), "FALSE")
})

test_that(".cwa: compatible and raw decoding are the same bits with and without AVX2", {
  skip_if_no_avx2()
  files <- c(system.file("testfiles", "ax3_testfile.cwa", package = "GGIRread"),
             system.file("testfiles", "ax6_testfile.cwa", package = "GGIRread"),
             system.file("testfiles", "ax3_testfile_corrupt_blocks_0_13_14_142_143_144.cwa",
                         package = "GGIRread"))
  files <- files[nzchar(files)]
  # synthetic: a rate a little off the header's (the grid meets the same or
  # a skipped interval now and then), a skipped block (imputed), a gap
  n <- 120 * 200
  tt <- seq_len(n) / 100
  x <- cbind(sin(tt), 0.9 * cos(tt), 0.3 + 0.1 * sin(3 * tt))
  tm <- 1.7e9 + 0.25 + (seq_len(n) - 1) / 99.3
  tm[seq(120 * 150 + 1, n)] <- tm[seq(120 * 150 + 1, n)] + 40  # a 40 s jump
  f1 <- tempfile(fileext = ".cwa")
  write_cwa(x, f1, sf = 100, time = tm, temperature = 20 + tt / 1000)
  b <- readBin(f1, raw(), file.size(f1))
  at <- 1024 + 512 * 77 + 30  # a flipped byte: block 77 fails its checksum
  b[at] <- as.raw(bitwXor(as.integer(b[at]), 0x10))
  f2 <- tempfile(fileext = ".cwa")
  writeBin(b, f2)
  files <- c(files, f1, f2)
  for (f in files) {
    for (compat in c(1, 0)) {
      for (chunk in c(1e6, 1001, 7)) {
        r <- both_ways(function() decode_all(f, "cwa", compat, chunk))
        expect_identical(r$avx2, r$baseline,
                         label = paste(basename(f), "compat", compat, "chunk", chunk))
      }
    }
  }
  # the imputed and the off-rate spans were met
  rep <- decode_all(f1, "cwa", 1, 1e6)$report
  expect_gt(rep$counters[["imputed_samples"]], 0)
})

test_that("GENEActiv .bin: decoding is the same bits with and without AVX2", {
  skip_if_no_avx2()
  files <- system.file("testfiles", "GENEActiv_testfile.bin", package = "GGIRread")
  files <- files[nzchar(files)]
  d <- simulate_recording(hours = 2, sf = 50, seed = 3)
  f1 <- tempfile(fileext = ".bin")
  write_geneactiv_bin(d, f1, sf = 50, start = as.POSIXct("2024-01-01", tz = "UTC"))
  # a page with a character that is not a hex digit, one in lower case
  l <- readLines(f1)
  hex <- which(nchar(l) == 3600)
  substr(l[hex[5]], 1000, 1000) <- "G"
  l[hex[9]] <- tolower(l[hex[9]])
  f2 <- tempfile(fileext = ".bin")
  writeLines(l, f2, sep = "\r\n")
  files <- c(files, f1, f2)
  for (f in files) {
    for (compat in c(1, 0)) {
      r <- both_ways(function() decode_all(f, "geneactiv", compat, 1001))
      expect_identical(r$avx2, r$baseline, label = paste(basename(f), "compat", compat))
    }
  }
  rep <- decode_all(f2, "geneactiv", 1, 1e6)$report
  expect_equal(rep$skipped, 1)
})

test_that("windows and fits are the same bits with and without AVX2", {
  skip_if_no_avx2()
  d <- simulate_recording(hours = 30, sf = 25, seed = 11,
                          params = c(1.02, 0.98, 1.01, 0, 0, 0, 0.03, -0.02, 0.01))
  d$x[5000:5400] <- 0
  d$y[5000:5400] <- 0
  d$z[5000:5400] <- 0  # idle-sleep zeros
  f <- tempfile(fileext = ".cwa")
  write_cwa(as.matrix(d[, c("x", "y", "z")]), f, sf = 25, start = 1.7e9,
            temperature = d$temperature)
  r <- both_ways(function() {
    utils::capture.output(g <- g.calibrate(f, verbose = FALSE))
    g$bsc_qc <- NULL  # time and memory of the run
    list(g = g,
         w = rest_windows(d, sf = 25),
         lw = calibrate(f, method = "lightweight"),
         gg = calibrate(f, method = "ggir"))
  })
  expect_identical(r$avx2$g, r$baseline$g)
  expect_identical(r$avx2$w, r$baseline$w)
  expect_identical(coef(r$avx2$lw), coef(r$baseline$lw))
  expect_identical(coef(r$avx2$gg), coef(r$baseline$gg))
  expect_gt(nrow(r$avx2$g$spheredata), 100)
})
