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
