# GGIR's reading parameters on .cwa files: interpolationType (1 linear, 2
# nearest neighbour) and frequency_tol, honoured by the native decoder
# (decode_cwa.hpp); desiredtz / configtz honoured where the zone's UTC offset
# stays the same over the recording, refused where it changes.
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

# readAxivity window after window (B blocks), as g.readaccfile calls it
ref_cwa <- function(f, B, interpolationType = 1, frequency_tol = 0.1) {
  with_tz("UTC", {
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
      out[[length(out) + 1]] <- P$data[, c("x", "y", "z", "temp", "time")]
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
# movement, temperature and a clock that runs 3 % fast for a stretch (so
# frequency_tol decides whether readAxivity imputes there).
synth_cwa <- function(hours = 30, sf = 25, seed = 61, start = 1.7e9) {
  rec <- simulate_recording(hours = hours, sf = sf, seed = seed,
                            tempoffset = c(0.002, -0.001, 0.0015))
  f <- tempfile(fileext = ".cwa")
  gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), f, sf = sf,
                      start = start, temperature = rec$temperature, range = 8)
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
  skip_if_not_installed("GGIR")
  files <- c(cwa_testfile("ax3_testfile.cwa"), cwa_testfile("ax6_testfile.cwa"))
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
  expect_identical(n, 6)
})
