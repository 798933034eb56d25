# Movisens recordings (a unisens folder: unisens.xml, acc.bin, temp.bin):
# gravcal's decoder (decode_movisens.hpp) against GGIR 3.3's reading
# through unisensR (readUnisensSignalEntry) and GGIR's g.readtemp_movisens,
# and gravcal::g.calibrate against GGIR::g.calibrate, on folders written by
# write_movisens() (R/write-movisens.R).

# A short recording with a temperature that changes, samples in g.
short_movisens <- function(n, seed = 1) {
  set.seed(seed)
  data.frame(x = stats::rnorm(n, 0, 0.5), y = stats::rnorm(n), z = stats::rnorm(n),
             temperature = 20 + 5 * sin(seq_len(n) / 3000))
}

test_that("write_movisens() writes what unisensR and GGIR read", {
  skip_if_not_installed("unisensR")
  skip_if_not_installed("GGIR")
  d <- file.path(tempfile("mv"), "rec")
  on.exit(unlink(dirname(d), recursive = TRUE))
  s <- short_movisens(64 * 300 + 17)
  gravcal:::write_movisens(s, d, lsb = 1 / 4096, baseline = 3, data_type = "int32")
  a <- unisensR::readUnisensSignalEntry(d, "acc.bin")
  expect_identical(dim(a), c(nrow(s), 3L))
  # stored in steps of 1/4096 g: within half a step
  expect_lte(max(abs(as.matrix(a) - as.matrix(s[, c("x", "y", "z")]))), 0.5 / 4096 + 1e-12)
  expect_identical(unisensR::getUnisensSignalSampleCount(d, "temp.bin"), 301)
  expect_identical(attr(a, "sampleRate"), 64)
  i <- GGIR::g.inspectfile(file.path(d, "acc.bin"))
  expect_identical(i$sf, 64)
  expect_identical(i$monc, 5L)  # GGIR's MONITOR$MOVISENS
})

test_that("the decoder gives unisensR's samples and g.readtemp_movisens' temperature", {
  skip_if_not_installed("unisensR")
  skip_if_not_installed("GGIR")
  root <- tempfile("mv")
  on.exit(unlink(root, recursive = TRUE))
  readtemp <- utils::getFromNamespace("g.readtemp_movisens", "GGIR")
  n <- 64 * 1000 + 29
  s <- short_movisens(n, seed = 2)
  cases <- list(list(type = "int16", lsb = 1 / 2048, base = 0, tsf = 1),
                list(type = "int32", lsb = 0.000244140625, base = -7, tsf = 2),
                list(type = "int16", lsb = 1, base = 0, tsf = 0.5))
  k <- 0
  for (cs in cases) {
    d <- file.path(root, paste0("r", k <- k + 1))
    gravcal:::write_movisens(s * if (cs$lsb == 1) 1000 else 1, d, data_type = cs$type,
                             lsb = cs$lsb, baseline = cs$base, temp_sf = cs$tsf)
    a <- unisensR::readUnisensSignalEntry(d, "acc.bin")
    # the reference reader's temperature (without GGIR's unexported
    # function): GGIR's, for the whole recording and for a block within it
    for (span in list(c(1, n), c(64 * 300 + 1, 64 * 600), c(64 * 900 + 1, n))) {
      m <- span[2] - span[1] + 1
      want <- tryCatch(readtemp(file.path(d, "acc.bin"), from = span[1], to = span[2],
                                acc_sf = 64, acc_length = m), error = function(e) "error")
      got <- tryCatch(gravcal:::movisens_temperature(d, span[1], span[2], 64, m),
                      error = function(e) "error")
      expect_identical(got, want)
      expect_identical(identical(got, "error"), cs$tsf == 0.5)
    }
    for (it in 1:2) {
      r <- read_recording(d)  # the folder
      expect_identical(r$data$x, as.double(a[[1]]))
      expect_identical(r$data$y, as.double(a[[2]]))
      expect_identical(r$data$z, as.double(a[[3]]))
      # gravcal's own reading interpolates the temperature as GGIR does
      # (interpolationType 1); g.calibrate passes interpolationType on
      src <- gravcal:::open_source(file.path(d, "acc.bin"), compat = TRUE,
                                   read_opts = list(interpolation = it))
      tt <- if (cs$tsf == 0.5) NULL else
        as.vector(readtemp(file.path(d, "acc.bin"), from = 1, to = n, acc_sf = 64,
                           acc_length = n, interpolationType = it))
      rs <- gravcal:::read_native(file.path(d, "acc.bin"), "movisens", 64, "file",
                                  extra = list(compat = 1, interpolation = it))
      if (is.null(tt)) {
        # 0.5 Hz: GGIR's first read (at 1 Hz) runs past temp.bin: no temperature
        expect_false(isTRUE(src$temperature))
      } else {
        expect_true(src$temperature)
        expect_identical(rs$temperature, tt)
      }
    }
  }
})

test_that("lsbValue and baseline are read as R reads them (unisensR's as.numeric)", {
  skip_if_not_installed("unisensR")
  root <- tempfile("mvl")
  on.exit(unlink(root, recursive = TRUE))
  s <- short_movisens(2000, seed = 4)
  # the writer gives 17 significant digits: long decimals, not only binary fractions
  for (lsb in c(0.000598550415, 0.1, 0.0001, 1 / 3000, 9.80665 / 4096, 0.3)) {
    d <- file.path(root, format(lsb))
    gravcal:::write_movisens(s, d, lsb = lsb, baseline = 0.5)
    a <- unisensR::readUnisensSignalEntry(d, "acc.bin")
    r <- read_recording(d)
    expect_identical(r$data$x, a[[1]], label = format(lsb))
    expect_identical(r$data$z, a[[3]], label = format(lsb))
  }
  # lsbValue and baseline texts of 22 significant digits that this R's
  # as.numeric() reads otherwise than a correctly rounded parse (R sums the
  # digits in its long double, or in double where it has none; about one in
  # four thousand such texts differs by an ulp), looked for among random
  # ones: the decoder takes R's values, so its samples are unisensR's
  correct <- function(x) gravcal:::gc_csv_numbers(x, 0L)
  set.seed(11)
  pick <- function(lead) {
    for (i in 1:200000) {
      s <- paste0(lead, paste(sample(0:9, 22, TRUE), collapse = ""))
      if (!identical(as.numeric(s), correct(s))) return(s)
    }
    NULL
  }
  lsb_txt <- pick("0.000")
  base_txt <- pick("0.")
  # an R whose long double is wide enough (quad precision on aarch64) reads
  # them all correctly rounded: then two fixed long texts, whose samples
  # must still be unisensR's
  differs <- !is.null(lsb_txt) && !is.null(base_txt)
  if (!differs) {
    lsb_txt <- "0.0004882812500000000000123"
    base_txt <- "0.3333333333333333333333"
  }
  d <- file.path(root, "long")
  gravcal:::write_movisens(s, d, lsb = 1 / 2048, baseline = 0.5)
  xml <- readLines(file.path(d, "unisens.xml"))
  xml <- sub('lsbValue="[^"]*"', paste0('lsbValue="', lsb_txt, '"'), xml)
  xml <- sub('baseline="[^"]*"', paste0('baseline=" ', base_txt, ' "'), xml)
  writeLines(xml, file.path(d, "unisens.xml"))
  a <- unisensR::readUnisensSignalEntry(d, "acc.bin")
  r <- read_recording(d)
  expect_identical(r$data$x, a[[1]])
  expect_identical(r$data$y, a[[2]])
  # and where R's reading differs, those samples are not the correctly
  # rounded numbers' (the test can fail)
  if (differs) {
    raw <- round(as.numeric(a[[1]]) / as.numeric(lsb_txt) + as.numeric(base_txt))
    expect_false(identical(r$data$x, (raw - correct(base_txt)) * correct(lsb_txt)))
  }
})

# 30 hours at 64 Hz (GGIR's blocks: 12 h, so three), written once: one
# simulated 6 hours five times over, each copy 0.7 degrees warmer
# (simulating 30 hours at 64 Hz takes longer than the rest of this file)
movisens_30h <- local({
  d <- NULL
  function() {
    if (is.null(d)) {
      d <<- file.path(tempfile("mv30"), "rec")
      rec <- simulate_recording(hours = 6, sf = 64, seed = 43,
                                tempoffset = c(0.002, -0.001, 0.0015))
      n <- nrow(rec)
      k <- rep(0:4, each = n)
      gravcal:::write_movisens(data.frame(x = rep(rec$x, 5), y = rep(rec$y, 5),
                                          z = rep(rec$z, 5),
                                          temperature = rep(rec$temperature, 5) + 0.7 * k), d)
    }
    d
  }
})

test_that("g.calibrate matches GGIR on 30 hours of a Movisens recording", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("unisensR")
  d <- movisens_30h()
  f <- file.path(d, "acc.bin")
  bs <- list()
  for (it in 1:2) {
    b <- run_both(f, list(interpolationType = it))
    expect_gt(b$ggir$npoints, 1000)
    expect_true(any(b$ggir$tempoffset != 0))  # the temperature was used
    expect_same_as_ggir(b)
    bs[[it]] <- b
  }
  expect_identical(length(bs), 2L)
  # nearest-neighbour temperature changes GGIR's fit (so it is honoured)
  expect_false(identical(bs[[1]]$ggir$scale, bs[[2]]$ggir$scale))
  # the folder itself names the same recording
  G <- gravcal::g.calibrate(d, params_rawdata = list(interpolationType = 2),
                            verbose = FALSE)
  expect_identical(G$scale, b$gravcal$scale)
  expect_identical(G$offset, b$gravcal$offset)
})

test_that("damaged Movisens recordings: a cut acc.bin, no temp.bin, a bad unisens.xml", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("unisensR")
  src <- movisens_30h()
  d <- file.path(tempfile("mvd"), "rec")
  on.exit(unlink(dirname(d), recursive = TRUE))
  dir.create(d, recursive = TRUE)
  file.copy(file.path(src, c("unisens.xml", "acc.bin", "temp.bin")), d)
  f <- file.path(d, "acc.bin")
  # a partial last sample (3 of its 6 bytes)
  b <- readBin(f, raw(), file.size(f))
  writeBin(b[seq_len(length(b) - 3)], f)
  bb <- run_both(f)
  expect_same_as_ggir(bb)
  fit <- calibrate(f)
  expect_true(fit$input$report$truncated)
  expect_identical(fit$input$report$samples, length(b) / 6 - 1)
  # no temp.bin: GGIR calibrates without temperature
  unlink(file.path(d, "temp.bin"))
  bb <- run_both(f)
  expect_same_as_ggir(bb)
  expect_true(all(bb$gravcal$tempoffset == 0))
  s0 <- gravcal:::open_source(d)
  expect_true(any(grepl("temp.bin is missing", s0$report()$notes, fixed = TRUE)))
  expect_false(s0$temperature)
  # temp.bin cut to 26 h: GGIR fails in its third block ("subscript out of
  # bounds"), gravcal's drop-in says why; gravcal's own reading goes on
  file.copy(file.path(src, "temp.bin"), d)
  tb <- file.path(d, "temp.bin")
  writeBin(readBin(tb, raw(), 26 * 3600 * 2), tb)
  expect_match(ggir_error("g.calibrate", d, list(),
                          keep_warn(suppressWarnings(GGIR::g.calibrate(f, inspectfileobject = GGIR::g.inspectfile(f),
                                                                       verbose = FALSE)))),
               "subscript out of bounds", fixed = TRUE)
  expect_error(gravcal::g.calibrate(f, verbose = FALSE),
               "temp.bin does not cover samples 5529601 to 6911999")
  r <- read_recording(d)
  expect_identical(r$input$report$counters[["temperature_blocks_unreadable"]], 1)
  expect_true(all(is.nan(r$data$temperature[5529601:6911999])))
  expect_false(anyNA(r$data$temperature[1:5529600]))
  # unisens.xml: malformed, or without acc.bin's entry (a short recording)
  d <- file.path(dirname(d), "short")
  gravcal:::write_movisens(short_movisens(64 * 60), d)
  xml <- readLines(file.path(d, "unisens.xml"))
  writeLines(sub("sampleRate=\"64\"", "sampleRate=\"64", xml), file.path(d, "unisens.xml"))
  expect_error(read_recording(d), "unisens.xml is malformed")
  writeLines(sub("acc.bin", "acc2.bin", xml, fixed = TRUE), file.path(d, "unisens.xml"))
  expect_error(read_recording(d), "no signalEntry for acc.bin")
  # another rate: gravcal reads it, GGIR's drop-in refuses (GGIR takes 64 Hz)
  writeLines(sub("sampleRate=\"64\"", "sampleRate=\"32\"", xml), file.path(d, "unisens.xml"))
  expect_identical(read_recording(d)$sf, 32)
  expect_error(gravcal::g.calibrate(d, verbose = FALSE), "reads every Movisens recording as 64 Hz")
})

test_that("calibrate_files() takes unisens folders, named as GGIR names them", {
  root <- tempfile("mvc")
  on.exit(unlink(root, recursive = TRUE))
  for (p in c("p01", "p02")) {
    gravcal:::write_movisens(short_movisens(64 * 600), file.path(root, "site", p))
  }
  out <- file.path(root, "out")
  # a directory of unisens folders: their acc.bin, not temp.bin
  res <- suppressWarnings(calibrate_files(file.path(root, "site"), outdir = out,
                                          recursive = TRUE))
  expect_identical(res$file, c("p01/acc.bin", "p02/acc.bin"))
  # the folders themselves, in method "ggir" (GGIR's coefficient file names
  # a Movisens recording by its folder, so two acc.bin do not clash)
  res <- suppressWarnings(calibrate_files(file.path(root, "site", c("p01", "p02")),
                                          outdir = file.path(root, "out2")))
  expect_identical(nrow(res), 2L)
  expect_identical(gravcal:::ggir_file_name(file.path(root, "site", "p01", "acc.bin")), "p01")
})
