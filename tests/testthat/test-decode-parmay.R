# The native Parmay Matrix decoder (decode_parmay.hpp) against the reference
# reader GGIRread::readParmayMatrix 1.2.0 (as GGIR's g.readaccfile calls it),
# on GGIRread's own test files and on files written by write_parmay_bin()
# (R/write-parmay.R) from the format description; and g.calibrate() against
# GGIR::g.calibrate() on them.

mtx_files <- function() {
  skip_if_not_installed("GGIRread")
  td <- system.file("testfiles", package = "GGIRread")
  f <- list.files(td, pattern = "^mtx_.*\\.(BIN|bin)$", full.names = TRUE)
  # mtx_corrupted_full.bin has no "MDTC" header: GGIRread refuses it too
  f <- f[!grepl("_full", f)]
  if (!length(f)) skip("GGIRread has no Matrix test files")
  f
}

# GGIRread's columns, renamed as GGIR renames them.
mtx_ref <- function(file, interpolation = 1) {
  P <- GGIRread::readParmayMatrix(file, interpolationType = interpolation)
  d <- P$data
  data.frame(x = d$acc_x, y = d$acc_y, z = d$acc_z,
             temperature = if (is.null(d$ambient_temp)) NA_real_ else d$ambient_temp,
             time = d$time)
}

mtx_read <- function(file, ...) {
  gravcal:::native_read_all(file, "parmay", options = list(...))
}

mtx_sim <- function(seconds, sf, seed = 1) {
  set.seed(seed)
  t <- seq_len(seconds * sf) / sf
  x <- 0.9 * sin(t / 7)
  y <- 0.4 * cos(t / 5)
  data.frame(x = x, y = y, z = sqrt(1 - x^2 - y^2) + stats::rnorm(length(t), 0, 0.02),
             temperature = 25 + 3 * sin(t / 100))
}

expect_same_samples <- function(d, r, temperature = TRUE) {
  expect_identical(nrow(d), nrow(r))
  for (col in c("x", "y", "z", "time")) expect_identical(d[[col]], r[[col]], label = col)
  if (temperature) expect_identical(d$temperature, r$temperature)
}

test_that("the decoder gives GGIRread's samples on its test files (interpolationType 1, 2)", {
  n_files <- 0
  for (f in mtx_files()) {
    for (it in 1:2) {
      r <- mtx_ref(f, it)
      d <- mtx_read(f, interpolation = it)
      has_temp <- !all(is.na(r$temperature))
      expect_identical(attr(d, "info")$temperature, has_temp)
      expect_same_samples(d, r, temperature = has_temp)
    }
    n_files <- n_files + 1
  }
  expect_identical(n_files, 5)
  # the damaged file: GGIRread keeps its bad packet, acceleration (0, 0, 1),
  # and so does the compatible mode; the report counts it
  f <- system.file("testfiles", "mtx_corrupted.bin", package = "GGIRread")
  rep <- attr(mtx_read(f), "report")
  expect_identical(rep$skipped, 1)
  expect_identical(rep$units, 4)
  # gravcal's own reading leaves it out (the first packet) and gives the
  # others' samples as stored (their counts in their headers, at byte 20)
  d0 <- mtx_read(f, compat = 0)
  expect_identical(attr(d0, "report")$skipped, 1)
  b <- readBin(f, raw(), file.size(f))
  starts <- grepRaw("MDTCPACK", b, fixed = TRUE, all = TRUE)
  counts <- vapply(starts, function(p) readBin(b[p + 20:23], "integer", size = 4,
                                               endian = "little"), 1L)
  expect_identical(nrow(d0), sum(counts[-1]))
  expect_false(any(d0$x == 0 & d0$y == 0 & d0$z == 1))
  expect_false(any(d0$x == 0 & d0$y == 0 & d0$z == 1))
})

test_that("file_format() tells a Parmay Matrix .BIN from a GENEActiv .bin", {
  f <- mtx_files()
  for (x in f) expect_identical(gravcal:::file_format(x), "parmay")
  g <- system.file("testfiles", "GENEActiv_testfile.bin", package = "GGIRread")
  expect_identical(gravcal:::file_format(g), "geneactiv")
  d <- read_recording(f[1])
  expect_identical(d$input$format, "parmay")
  expect_gt(nrow(d$data), 1000)
})

test_that("reader = 'reference' reads through GGIRread, with the same result", {
  f <- mtx_files()[1]
  a <- read_recording(f, reader = "reference")
  r <- mtx_ref(f)
  expect_identical(a$data$x, r$x)
  expect_identical(a$data$temperature, r$temperature)
  skip_if_not_installed("GGIR")
  G1 <- gravcal::g.calibrate(f, verbose = FALSE, reader = "reference")
  G2 <- gravcal::g.calibrate(f, verbose = FALSE)
  expect_identical(G1[names(G1) != "bsc_qc"], G2[names(G2) != "bsc_qc"])
  expect_error(gravcal::g.calibrate(f, verbose = FALSE, reader = "reference",
                                    interpolationType = 2),
               "`interpolationType` = 2 is taken by gravcal's own decoders only")
})

test_that("write_parmay_bin() writes what GGIRread reads", {
  skip_if_not_installed("GGIRread")
  for (sf in c(12.5, 25, 100)) {
    s <- mtx_sim(600, sf)
    f <- tempfile(fileext = ".BIN")
    gravcal:::write_parmay_bin(s, f, sf = sf, packet_seconds = 60, temp_per_packet = 3)
    P <- GGIRread::readParmayMatrix(f)
    expect_identical(P$header$sf, sf)
    expect_identical(P$header$acc_dynrange, 8L)
    expect_true(all(P$QClog$checksum_pass))
    expect_identical(nrow(P$QClog), 10L)
    # whole packets: GGIRread's grid is the samples' own times, so its values
    # are the samples within the int16 resolution (8 / 32767 g)
    n <- nrow(P$data)
    expect_identical(n, nrow(s))
    expect_lte(max(abs(P$data$acc_x - s$x), abs(P$data$acc_y - s$y),
                   abs(P$data$acc_z - s$z)), 8 / 32767)
    # and gravcal's decoder gives GGIRread's samples to the bit
    expect_same_samples(mtx_read(f), mtx_ref(f))
    expect_same_samples(mtx_read(f, interpolation = 2), mtx_ref(f, 2))
    unlink(f)
  }
})

test_that("damaged copies: gravcal reads what is valid and says what it skipped", {
  skip_if_not_installed("GGIRread")
  s <- mtx_sim(600, 25)
  f <- tempfile(fileext = ".BIN")
  gravcal:::write_parmay_bin(s, f, sf = 25, packet_seconds = 60)
  b <- readBin(f, raw(), file.size(f))
  starts <- grepRaw("MDTCPACK", b, fixed = TRUE, all = TRUE)
  expect_length(starts, 10)
  # a corrupted sample in packet 4
  bad <- tempfile(fileext = ".BIN")
  b2 <- b
  i <- starts[4] + 100
  b2[i] <- xor(b2[i], as.raw(0x55))
  writeBin(b2, bad)
  d <- mtx_read(bad)
  rep <- attr(d, "report")
  expect_identical(rep$skipped, 1)
  expect_match(rep$notes[[1]], "bad checksum")
  expect_same_samples(d, mtx_ref(bad))
  expect_identical(sum(d$x == 0 & d$y == 0 & d$z == 1), 1500L)
  # gravcal's own reading: the packet's 60 s are a gap
  r0 <- read_recording(bad)
  expect_identical(r0$input$report$skipped, 1)
  expect_identical(r0$input$report$gaps, 1)
  expect_identical(nrow(r0$data), 9L * 1500L)
  expect_false(any(r0$data$x == 0 & r0$data$y == 0 & r0$data$z == 1))
  # cut in the middle of packet 7: the rest of the file is read, the cut
  # packet is damaged (GGIRread keeps what the file holds of it)
  cut <- tempfile(fileext = ".BIN")
  writeBin(b[seq_len(starts[7] + 2000)], cut)
  d <- mtx_read(cut)
  expect_identical(attr(d, "report")$skipped, 1)
  expect_same_samples(d, mtx_ref(cut))
  expect_gt(nrow(d), 6 * 1500)
  d0 <- mtx_read(cut, compat = 0)
  expect_identical(nrow(d0), 6L * 1500L)
  # cut inside a packet's header: skipped, said so
  cut2 <- tempfile(fileext = ".BIN")
  writeBin(b[seq_len(starts[7] + 20)], cut2)
  d <- mtx_read(cut2, compat = 0)
  expect_identical(attr(d, "report")$counters[["short_packet"]], 1)
  expect_identical(nrow(d), 6L * 1500L)
  # garbage: a header that names a Matrix file and no packet
  junk <- tempfile(fileext = ".BIN")
  writeBin(c(as.raw(rep(0, 512)), charToRaw("MDTC"), as.raw(rep(1, 600))), junk)
  expect_error(read_recording(junk), "no packet of 10 s or more")
  unlink(c(f, bad, cut, cut2, junk))
})

test_that("g.calibrate matches GGIR on GGIRread's Matrix files (interpolationType 1, 2)", {
  skip_if_not_installed("GGIR")
  n <- 0
  for (f in mtx_files()) {
    for (it in 1:2) {
      b <- run_both(f, list(interpolationType = it))
      expect_same_as_ggir(b)
      n <- n + 1
    }
  }
  expect_identical(n, 10)
})

test_that("g.calibrate matches GGIR on 30 hours written as a Matrix file (a real fit)", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  f <- tempfile(fileext = ".BIN")
  on.exit(unlink(f))
  for (sf in c(12.5, 25)) {
    rec <- simulate_recording(hours = 30, sf = sf, seed = 41,
                              tempoffset = c(0.002, -0.001, 0.0015))
    gravcal:::write_parmay_bin(rec, f, sf = sf, packet_seconds = 120)
    for (it in if (sf == 25) 1 else 1:2) {
      b <- run_both(f, list(interpolationType = it))
      expect_gt(b$ggir$npoints, 1000)
      expect_same_as_ggir(b)
    }
  }
  # damaged copy: a corrupted packet, kept by GGIR as (0, 0, 1) g
  b <- readBin(f, raw(), file.size(f))
  i <- 524 + 200 * (8 + 4 + 24 + 6 * 3000 + 8) + 300
  b[i] <- xor(b[i], as.raw(0xff))
  writeBin(b, f)
  bb <- run_both(f)
  expect_same_as_ggir(bb)
  fit <- calibrate(f)
  expect_identical(fit$input$report$skipped, 1)
})

test_that("no light: GGIRread's readParmayMatrix() gives none, nor does the decoder", {
  f <- mtx_files()[1]
  expect_false("light" %in% names(GGIRread::readParmayMatrix(f)$data))
  d <- mtx_read(f)
  expect_false(attr(d, "info")$light)
  expect_false("light" %in% names(d))
  h <- gravcal:::native_open(f, "parmay")
  on.exit(gravcal:::gc_decoder_close(h$ptr))
  expect_null(gravcal:::native_block(h, 10, 1e5, TRUE, TRUE, light = TRUE)$cols$light)
})
