# Damaged device files through the whole pipeline: every good sample is
# calibrated, and what the reader skipped reaches the fit, its print() and
# the cohort table.

# A 26-hour recording at 25 Hz as an Axivity .cwa (packed, 120 samples a
# 512-byte block after a 1024-byte header; R/write-cwa.R).
damaged_cwa <- function(dir) {
  rec <- simulate_recording(hours = 26, sf = 25, seed = 61,
                            tempoffset = c(0.001, -0.001, 0.002))
  clean <- file.path(dir, "clean.cwa")
  gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), clean, sf = 25,
                      temperature = rec$temperature)
  b <- readBin(clean, raw(), file.size(clean))
  # three data blocks with a flipped bit: their checksums no longer add up
  for (k in c(100, 2000, 5000)) {
    at <- 1024 + 512 * k + 200
    b[at] <- as.raw(bitwXor(as.integer(b[at]), 0x10))
  }
  bad <- file.path(dir, "damaged.cwa")
  writeBin(b, bad)
  # and a copy cut short in the middle of a block
  cut <- file.path(dir, "cut.cwa")
  writeBin(b[seq_len(1024 + 512 * 6000 + 300)], cut)
  list(clean = clean, bad = bad, cut = cut)
}

test_that("a damaged .cwa is calibrated from its good blocks, the loss reported", {
  dir <- tempfile("damaged")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  f <- damaged_cwa(dir)
  for (method in c("lightweight", "ggir")) {
    good <- calibrate(f$clean, method = method)
    bad <- calibrate(f$bad, method = method)
    expect_identical(good$input$report$skipped, 0)
    expect_identical(bad$input$report$skipped, 3)
    expect_identical(unname(bad$input$report$counters["bad_checksum"]), 3)
    # three blocks of 120 samples lost, nothing else
    expect_identical(good$input$samples - bad$input$samples, 3 * 120)
    expect_identical(bad$status, good$status)
    # the coefficients hardly move for three lost blocks of 7,800
    expect_lt(max(abs(coef(bad) - coef(good))), 2e-3)
    out <- utils::capture.output(print(bad))
    expect_true(any(grepl("3 unreadable blocks skipped", out)), label = method)
    expect_true(any(grepl("nothing skipped", utils::capture.output(print(good)))))
  }
  cut <- calibrate(f$cut, method = "lightweight")
  expect_true(cut$input$report$truncated)
  # 6000 whole blocks before the cut, the three damaged ones among them
  expect_identical(cut$input$samples, (6000 - 3) * 120)
  expect_true(any(grepl("file truncated", utils::capture.output(print(cut)))))
  # the cohort table carries the same counts
  tab <- calibrate_files(c(f$clean, f$bad, f$cut), method = "lightweight",
                         outdir = file.path(dir, "out"))
  expect_identical(tab$reader, rep("native", 3))
  expect_identical(tab$skipped, c(0, 3, 3))
  expect_identical(tab$truncated, c(FALSE, FALSE, TRUE))
  expect_match(tab$read_notes[2], "bad_checksum in block 100")
  expect_identical(tab$samples[2], bad$input$samples)
})

test_that("a damaged GENEActiv .bin keeps its other pages and reports the bad one", {
  dir <- tempfile("damaged")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  rec <- simulate_recording(hours = 26, sf = 10, seed = 62)
  clean <- file.path(dir, "clean.bin")
  gravcal:::write_geneactiv_bin(rec, clean, sf = 10)
  txt <- readLines(clean)
  hex <- which(nchar(txt) == 3600)
  txt[hex[50]] <- paste0(substr(txt[hex[50]], 1, 100), "ZZ",
                         substr(txt[hex[50]], 103, 3600))
  bad <- file.path(dir, "bad.bin")
  writeLines(txt, bad)
  a <- calibrate(clean, method = "ggir")
  b <- calibrate(bad, method = "ggir")
  expect_identical(a$input$samples - b$input$samples, 300)
  expect_identical(unname(b$input$report$counters["bad_hex"]), 1)
  expect_identical(b$status, a$status)
  expect_true(any(grepl("1 unreadable page skipped", utils::capture.output(print(b)))))
})

test_that("g.calibrate() is GGIR's on a GENEActiv .bin with damaged pages, or cut short", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  dir <- tempfile("damaged")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  # 26 hours at 10 Hz, CRLF line ends: GGIR's blocks of 1451 pages (12 h)
  rec <- simulate_recording(hours = 26, sf = 10, seed = 62)
  clean <- file.path(dir, "clean.bin")
  gravcal:::write_geneactiv_bin(rec, clean, sf = 10, eol = "\r\n")
  bytes <- readBin(clean, raw(), file.size(clean))
  txt <- strsplit(rawToChar(bytes), "\r\n", fixed = TRUE)[[1]]
  rd <- which(txt == "Recorded Data")
  put <- function(l, name) {
    f <- file.path(dir, name)
    writeBin(charToRaw(paste0(paste(l, collapse = "\r\n"), "\r\n")), f)
    f
  }
  cut <- function(n, name) {
    f <- file.path(dir, name)
    writeBin(bytes[seq_len(n)], f)
    f
  }
  # a non-hex character at a sample's start in page 100: GGIRread keeps the
  # page's first 100 samples, and GGIR takes its first block, 200 samples
  # short, for the last
  l <- txt
  substr(l[rd[100] + 9], 1201, 1201) <- "G"
  b <- run_both(put(l, "nonhex.bin"))
  expect_same_as_ggir(b)
  expect_lt(b$gravcal$nhoursused, 12.1)
  # one inside a group (read as far as it goes), in the second block
  l <- txt
  substr(l[rd[2000] + 9], 602, 602) <- "Q"
  expect_same_as_ggir(run_both(put(l, "garbled.bin")))
  # a line missing in page 2000: every page after it misaligned (none of
  # them decoded)
  expect_same_as_ggir(run_both(put(txt[-(rd[2000] + 4)], "missing.bin")))
  # page 1's time garbled: GGIR's times are NA, which g.calibrate() does
  # not read at a whole rate
  l <- txt
  l[rd[1] + 3] <- "Page Tine:2024-01-01 00:00:00:000"
  expect_same_as_ggir(run_both(put(l, "time.bin")))
  # cut in the last page's header lines (GGIRread gives the page before
  # again) and inside its hex line
  last <- tail(gregexpr("Recorded Data", rawToChar(bytes), fixed = TRUE)[[1]], 1)
  expect_same_as_ggir(run_both(cut(last + 120, "cut-header.bin")))
  expect_same_as_ggir(run_both(cut(length(bytes) - 1000, "cut-hex.bin")))
  # where GGIR's result is not reproduced, g.calibrate() stops, saying why:
  # a hex line longer than the decoder keeps, all of it decodable (GGIRread
  # reads 900 samples from it)
  l <- txt
  l[rd[10] + 9] <- strrep(l[rd[10] + 9], 3)
  expect_error(gravcal::g.calibrate(put(l, "long.bin"), verbose = FALSE),
               "\"long.bin\" \\(`datafile`\\) has a page line longer than 8192 characters")
  # the real test file (85.7 Hz, which GGIR resamples) with its last page's
  # rate garbled to 0: GGIR takes that block at 0 Hz, whole, and does not
  # resample it
  r <- system.file("testfiles", "GENEActiv_testfile.bin", package = "GGIRread")
  rb <- readBin(r, raw(), file.size(r))
  at <- tail(grepRaw("Measurement Frequency:85.7", rb, fixed = TRUE, all = TRUE), 1)
  rb[at + 22:25] <- charToRaw("abc.")
  g <- file.path(dir, "rate.bin")
  writeBin(rb, g)
  expect_error(suppressWarnings(gravcal::g.calibrate(g, verbose = FALSE)),
               "reads as another rate than the file's")
})
