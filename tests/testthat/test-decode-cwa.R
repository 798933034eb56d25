# The native Axivity .cwa decoder (inst/include/gravcal/decoders/decode_cwa.hpp).
# References: GGIRread 1.2.0's readAxivity() on the same bytes, called as
# GGIR's g.readaccfile calls it (windows of B blocks, start = previous end),
# and the samples given to write_cwa() (R/write-cwa.R, from openmovement's
# cwa.h).

ggirread_file <- function(name) {
  skip_if_not_installed("GGIRread")
  p <- system.file("testfiles", name, package = "GGIRread")
  if (!nzchar(p)) skip(paste("GGIRread has no test file", name))
  p
}

# readAxivity called window after window as GGIR does; NULL data ends.
# attr "QClog": its logs bound window after window, as GGIR's g.getmeta()
# binds them.
ref_windows <- function(f, B) {
  old <- Sys.getenv("TZ", unset = NA)
  Sys.setenv(TZ = "UTC")  # GGIR's configtz = "" is the machine's zone
  on.exit(if (is.na(old)) Sys.unsetenv("TZ") else Sys.setenv(TZ = old))
  out <- list()
  s <- 0
  header <- NULL
  qclog <- NULL
  repeat {
    P <- tryCatch(suppressWarnings(GGIRread::readAxivity(
      f, start = s, end = s + B, progressBar = FALSE, desiredtz = "",
      configtz = "", interpolationType = 1, frequency_tol = 0.1,
      header = header)), error = function(e) NULL)
    if (is.null(P) || is.null(P$data)) break
    header <- P$header
    qclog <- rbind(qclog, P$QClog)
    out[[length(out) + 1]] <- P$data[, c("x", "y", "z", "temp", "time", "light")]
    s <- s + B
  }
  d <- do.call(rbind, out)
  if (is.null(d)) return(NULL)
  names(d)[4] <- "temperature"
  rownames(d) <- NULL
  attr(d, "QClog") <- qclog
  d
}

# The native decoder, read(out, B) after read(out, B), `cap` samples at a
# time; light too (native_block()'s default), as readAxivity gives it.
# attr "QClog": the decoder's log as g.getmeta() takes it, window by window.
nat_windows <- function(f, B, cap = B * 120 + 1000, compat = 1) {
  h <- native_open(f, "cwa", list(compat = compat))
  on.exit(gc_decoder_close(h$ptr))
  src <- list(native = h)
  out <- list()
  units <- numeric(0)
  qclog <- NULL
  logged <- 0
  repeat {
    b <- native_block(h, B, cap, TRUE, TRUE)
    n <- b$to
    if (n > 0) out[[length(out) + 1]] <- as.data.frame(lapply(b$cols, `[`, seq_len(n)))
    units <- c(units, b$units)
    rows <- cwa_qclog(src, logged)
    logged <- logged + NROW(rows)
    qclog <- rbind(qclog, rows)
    if (b$done || (n == 0 && b$units == 0)) break
  }
  d <- do.call(rbind, out)
  attr(d, "units") <- units
  attr(d, "report") <- native_report(h)
  attr(d, "QClog") <- qclog
  d
}

strip <- function(d) {
  attributes(d) <- attributes(d)[c("names", "row.names", "class")]
  rownames(d) <- NULL
  d
}

# A synthetic recording and its file; samples stay within +-2 g so the
# packed 10-bit form holds them exactly at 1/256 g. Light changes from
# block to block over the whole 10-bit range (`light`: one a block).
synth_light <- function(blocks) (seq_len(blocks) * 97 + 5) %% 1024
synth <- function(blocks = 60, sf = 100, light = synth_light(blocks), ...) {
  n <- 120 * blocks
  tt <- seq_len(n) / sf
  x <- cbind(sin(tt), 0.9 * cos(tt), 0.3 + 0.1 * sin(3 * tt))
  f <- tempfile(fileext = ".cwa")
  write_cwa(x, f, sf = sf, start = 1.7e9 + 0.25, temperature = 20 + tt / 1000,
            light = light, ...)
  list(x = x, file = f, bytes = readBin(f, raw(), file.size(f)), light = light)
}

# The light word's low 10 bits of every data block of a file (cwa.h: bytes
# 18-19 of a block), read from its bytes.
block_light <- function(f) {
  b <- readBin(f, raw(), file.size(f))
  nb <- (length(b) - 1024) %/% 512
  vapply(seq_len(nb) - 1, function(k) {
    bitwAnd(readBin(b[block_at(k) + 19:20], integer(), size = 2, signed = FALSE,
                    endian = "little"), 1023L)
  }, 0L)
}

block_at <- function(k) 1024 + 512 * k  # byte offset of data block k (0-based)

with_bytes <- function(b) {
  g <- tempfile(fileext = ".cwa")
  writeBin(b, g)
  g
}

flip <- function(b, at, mask = 0x10) {
  b[at] <- as.raw(bitwXor(as.integer(b[at]), mask))
  b
}

# Raw-mode samples of a file with the block each came from (read one block
# at a time: max_units = 1 consumes one block).
raw_blocks <- function(f) {
  h <- native_open(f, "cwa", list(compat = 0))
  on.exit(gc_decoder_close(h$ptr))
  out <- list()
  k <- 0
  repeat {
    b <- native_block(h, 1, 120, TRUE, TRUE)
    if (b$to > 0) {
      d <- as.data.frame(lapply(b$cols, `[`, seq_len(b$to)))
      d$block <- k
      out[[length(out) + 1]] <- d
    }
    k <- k + b$units
    if (b$done || b$units == 0) break
  }
  do.call(rbind, out)
}

test_that("compat = 1 gives GGIR's readAxivity windows to the bit (GGIRread's files)", {
  files <- c("ax3_testfile.cwa", "ax6_testfile.cwa",
             "ax3_testfile_corrupt_blocks_0_13_14_142_143_144.cwa")
  for (name in files) {
    f <- ggirread_file(name)
    # B = round(12 * 3600 * sf / 80) = 54000 at 100 Hz (g.calibrate); 37, 9:
    # windows inside the file (light compared too: ref_windows())
    for (B in c(54000, 37, 9)) {
      ref <- ref_windows(f, B)
      nat <- nat_windows(f, B)
      expect_gt(nrow(ref), 11000)
      expect_identical(strip(nat), strip(ref), label = paste(name, "B =", B))
      # readAxivity's log (the corrupt file: blocks 0, 13 and 14 skipped, the
      # span before them imputed; 142-144 end the file, never read)
      expect_identical(attr(nat, "QClog"), attr(ref, "QClog"), label = paste(name, "B =", B))
    }
  }
})

test_that("the header gives device, serial, rate, range and start", {
  f <- ggirread_file("ax6_testfile.cwa")
  h <- native_open(f, "cwa")
  on.exit(gc_decoder_close(h$ptr))
  ref <- GGIRread::readAxivity(f, start = 0, end = 1, progressBar = FALSE)$header
  expect_identical(h$info$device, ref$hardwareType)
  expect_identical(h$info$serial, as.character(ref$uniqueSerialCode))
  expect_identical(h$info$sf, ref$frequency)
  expect_identical(h$info$range_g, as.numeric(ref$accrange))
  expect_identical(h$info$start_time, as.numeric(ref$start))
})

test_that("a corrupt first block: every other block is read, as in the clean file", {
  clean <- raw_blocks(ggirread_file("ax3_testfile.cwa"))
  bad_file <- ggirread_file("ax3_testfile_corrupt_blocks_0_13_14_142_143_144.cwa")
  bad <- raw_blocks(bad_file)
  lost <- c(0, 13, 14, 142, 143, 144)
  expect_identical(strip(bad), strip(clean[!clean$block %in% lost, ]))
  d <- native_read_all(bad_file, "cwa", list(compat = 0))
  r <- attr(d, "report")
  expect_identical(r$skipped, 6)
  expect_identical(r$counters[["bad_checksum"]], 6)
  expect_identical(r$units, 139)
  expect_identical(r$gaps, 0)
  expect_match(r$notes[2], "bad_checksum in block 0 at byte 1024")
})

test_that("raw samples are the written ones at their times; the reference reads the file", {
  for (packed in c(TRUE, FALSE)) {
    s <- synth(blocks = 20, packed = packed)
    d <- native_read_all(s$file, "cwa", list(compat = 0))
    expect_identical(unname(as.matrix(d[, 1:3])), round(s$x * 256) / 256)
    n <- nrow(s$x)
    # block starts are stored to 1/32768 s
    expect_lt(max(abs(d$time - (1.7e9 + 0.25 + (seq_len(n) - 1) / 100))), 2^-15)
    temp_raw <- round((20 + seq(1, n, by = 120) / 100 / 1000 + 50) * 256 / 75)
    expect_identical(d$temperature, rep(temp_raw * 75 / 256 - 50, each = 120))
    expect_identical(strip(nat_windows(s$file, 54000)), strip(ref_windows(s$file, 54000)))
    expect_identical(strip(nat_windows(s$file, 7)), strip(ref_windows(s$file, 7)))
  }
  s <- synth(blocks = 10, ax6 = TRUE)
  d <- native_read_all(s$file, "cwa", list(compat = 0))
  expect_identical(unname(as.matrix(d[, 1:3])), round(s$x * 4096) / 4096)
  expect_identical(strip(nat_windows(s$file, 13)), strip(ref_windows(s$file, 13)))
})

test_that("max_units: raw mode one block a unit; compat resumes a window when out fills", {
  s <- synth(blocks = 30)
  b <- raw_blocks(s$file)
  expect_identical(as.vector(table(b$block)), rep(120L, 30))
  whole <- nat_windows(s$file, 11)
  expect_identical(attr(whole, "units"), c(11, 11, 8))
  small <- nat_windows(s$file, 11, cap = 500)
  expect_identical(strip(small), strip(whole))
  # units come with the call that ends a window; the others give 0
  expect_identical(sum(attr(small, "units")), 30)
  expect_true(all(attr(small, "units") %in% c(0, 11, 8)))
})

damage_cases <- function(s) {
  b <- s$bytes
  seqgap <- b
  for (k in 30:59) {
    seqgap[block_at(k) + 11] <- as.raw(k + 5)  # sequence id low byte
    seqgap <- cwa_fix_checksum(seqgap, k)
  }
  month13 <- b  # month field 13 (bits 22..25 of the RTC word at byte 14)
  month13[block_at(15) + 18] <- as.raw(bitwOr(bitwAnd(as.integer(b[block_at(15) + 18]), 0xfc), 0x03))
  month13[block_at(15) + 17] <- as.raw(bitwOr(as.integer(b[block_at(15) + 17]), 0x40))
  badtag <- b
  badtag[block_at(40) + 1] <- charToRaw("Q")
  list(corrupt = flip(b, block_at(20) + 100),
       checksum = flip(b, block_at(25) + 511, 0x01),
       first = flip(b, block_at(0) + 40),
       last3 = flip(flip(flip(b, block_at(57) + 50), block_at(58) + 50), block_at(59) + 50),
       seqgap = seqgap,
       month13 = cwa_fix_checksum(month13, 15),
       badtag = cwa_fix_checksum(badtag, 40))
}

test_that("damaged blocks are skipped, every good sample kept, the loss counted", {
  s <- synth(blocks = 60)
  clean <- raw_blocks(s$file)
  cases <- damage_cases(s)
  lost <- list(corrupt = 20, checksum = 25, first = 0, last3 = 57:59, seqgap = integer(0),
               month13 = 15, badtag = 40)
  why <- c(corrupt = "bad_checksum", checksum = "bad_checksum", first = "bad_checksum",
           last3 = "bad_checksum", month13 = "bad_timestamp", badtag = "bad_header")
  for (case in names(cases)) {
    g <- with_bytes(cases[[case]])
    got <- raw_blocks(g)
    expect_identical(strip(got), strip(clean[!clean$block %in% lost[[case]], ]), label = case)
    r <- attr(native_read_all(g, "cwa", list(compat = 0)), "report")
    expect_identical(r$skipped, as.numeric(length(lost[[case]])), label = case)
    expect_identical(r$units, 60 - length(lost[[case]]), label = case)
    expect_identical(r$gaps, 0, label = case)
    if (case %in% names(why)) {
      expect_identical(r$counters[[why[[case]]]], as.numeric(length(lost[[case]])), label = case)
      expect_match(r$notes[2], paste0(why[[case]], " in block ", lost[[case]][1], " at byte ",
                                      block_at(lost[[case]][1])), fixed = TRUE)
    }
    if (case == "seqgap") expect_identical(r$counters[["sequence_gaps"]], 1)
  }
})

test_that("compat = 1 on damaged files is readAxivity's output where it reads them", {
  s <- synth(blocks = 60)
  cases <- damage_cases(s)
  for (case in c("corrupt", "checksum", "first", "last3", "seqgap")) {
    g <- with_bytes(cases[[case]])
    for (B in c(54000, 9)) {
      ref <- strip(ref_windows(g, B))
      expect_identical(strip(nat_windows(g, B)), ref, label = paste(case, B))
    }
  }
  # readAxivity stops on an impossible date or a bad tag (GGIR gets no
  # samples); the decoder skips the block and goes on
  for (case in c("month13", "badtag")) {
    g <- with_bytes(cases[[case]])
    expect_null(ref_windows(g, 54000))
    d <- nat_windows(g, 54000)
    expect_gt(nrow(d), 7000)
    expect_identical(attr(d, "report")$skipped, 1)
  }
})

test_that("a jump in time is a reported gap; compat imputes it as readAxivity does", {
  n <- 120 * 60
  tt <- seq_len(n) / 100
  x <- cbind(sin(tt), 0.9 * cos(tt), 0.3 + 0.1 * sin(3 * tt))
  tm <- 1.7e9 + (seq_len(n) - 1) / 100
  after <- (25 * 120 + 1):n
  tm[after] <- tm[after] + 100
  f <- tempfile(fileext = ".cwa")
  # light changes from block to block: the imputed span takes block 24's
  write_cwa(x, f, sf = 100, time = tm, light = synth_light(60))
  d <- native_read_all(f, "cwa", list(compat = 0))
  r <- attr(d, "report")
  expect_identical(nrow(d), as.integer(n))
  expect_identical(r$gaps, 1)
  expect_equal(r$gap_seconds, 100, tolerance = 1e-4)
  expect_match(r$notes, "time gap of 100.0000.. s before block 25", all = FALSE)
  for (B in c(54000, 10)) {
    nat <- nat_windows(f, B)
    ref <- ref_windows(f, B)
    expect_identical(strip(nat), strip(ref), label = paste("B =", B))
    expect_identical(attr(nat, "QClog"), attr(ref, "QClog"), label = paste("B =", B))
  }
  expect_true(all(attr(nat, "QClog")$imputed))
  # 100 s at 100 Hz filled in (block 24's span and the gap, less a grid point)
  expect_gt(attr(nat, "report")$counters[["imputed_samples"]], 10000)
})

test_that("compat = 1 logs what readAxivity logs (its QClog), window by window", {
  # bad checksums at a window's start, within one and at its end, a
  # sequence break, a block whose rate is 6 % off (logged, not imputed) and
  # one 20 % off (imputed); the time jump of the test above. readAxivity's
  # own logs, bound window after window as GGIR binds them, are the
  # reference: identical(), types (integer or double block numbers) too.
  s <- synth(blocks = 60)
  cases <- damage_cases(s)[c("corrupt", "checksum", "first", "last3", "seqgap")]
  rate_off <- function(b, k, samples) {
    # block k starts `samples` samples earlier (cwa.h's timestampOffset,
    # bytes 26-27): the block before spans that much less, k that much more
    at <- block_at(k) + 27:28
    v <- readBin(b[at], integer(), size = 2, signed = TRUE, endian = "little")
    b[at] <- writeBin(as.integer(v + samples), raw(), size = 2, endian = "little")[1:2]
    cwa_fix_checksum(b, k)
  }
  cases$rate6 <- rate_off(s$bytes, 33, 7)     # 106 Hz: logged (the next, 95 Hz, not)
  cases$rate20 <- rate_off(s$bytes, 41, -25)  # 83 and 126 Hz: imputed
  cases$mixed <- flip(flip(rate_off(cases$seqgap, 12, 7), block_at(27) + 90), block_at(0) + 90)
  logged <- 0
  for (case in names(cases)) {
    g <- with_bytes(cases[[case]])
    for (B in c(54000, 9, 5)) {
      nat <- nat_windows(g, B)
      ref <- ref_windows(g, B)
      expect_identical(strip(nat), strip(ref), label = paste(case, B))
      expect_identical(attr(nat, "QClog"), attr(ref, "QClog"), label = paste(case, B))
      expect_false("qclog_not_reproduced" %in% names(attr(nat, "report")$counters))
      logged <- logged + NROW(attr(ref, "QClog"))
    }
  }
  # every kind of row is there: a bad block (at a start and inside), a
  # break, a rate logged but not imputed
  ref <- attr(ref_windows(with_bytes(cases$mixed), 9), "QClog")
  expect_true(all(c(FALSE, TRUE) %in% ref$checksum_pass))
  expect_true(is.double(ref$blockID_current) && is.double(ref$blockID_next))
  expect_true(any(ref$checksum_pass & !ref$imputed))
  ref <- attr(ref_windows(with_bytes(cases$rate6), 54000), "QClog")
  expect_identical(nrow(ref), 1L)
  expect_false(ref$imputed)
  expect_true(is.integer(ref$blockID_current))
  expect_gt(logged, 40)
})

test_that("a truncated file keeps its whole blocks and says so", {
  s <- synth(blocks = 60)
  for (cut in c(block_at(59) + 300, block_at(30) + 1, block_at(1) + 511)) {
    g <- with_bytes(s$bytes[seq_len(cut)])
    d <- native_read_all(g, "cwa", list(compat = 0))
    whole <- (cut - 1024) %/% 512
    expect_identical(nrow(d), as.integer(120 * whole))
    r <- attr(d, "report")
    expect_true(r$truncated)
    expect_match(r$notes[2], paste("after block", whole), fixed = TRUE)
    expect_identical(strip(nat_windows(g, 54000)), strip(ref_windows(g, 54000)))
  }
})

test_that("files that are not .cwa are refused with the reason", {
  s <- synth(blocks = 2)
  expect_error(native_open(with_bytes(s$bytes[1:700]), "cwa"), "header truncated at byte 700")
  b <- s$bytes
  b[1:2] <- charToRaw("PK")
  expect_error(native_open(with_bytes(b), "cwa"),
               "not an Axivity .cwa file: first two bytes are 0x50 0x4b")
  d <- native_read_all(with_bytes(s$bytes[1:1024]), "cwa")
  expect_identical(nrow(d), 0L)
})

test_that("a gap over 3 days is not imputed in compat mode (readAxivity stops there)", {
  n <- 120 * 20
  tt <- seq_len(n) / 25
  x <- cbind(sin(tt), 0.9 * cos(tt), 0.3 + 0.1 * sin(3 * tt))
  tm <- 1.7e9 + (seq_len(n) - 1) / 25
  after <- (10 * 120 + 1):n
  tm[after] <- tm[after] + 4 * 86400
  f <- tempfile(fileext = ".cwa")
  write_cwa(x, f, sf = 25, time = tm)
  expect_null(ref_windows(f, 5400))  # "encountered a time gap in the file of 4 days"
  d <- nat_windows(f, 5400)
  r <- attr(d, "report")
  expect_identical(r$counters[["gaps_not_imputed"]], 1)
  expect_identical(r$gaps, 1)
  expect_equal(r$gap_seconds, 4 * 86400, tolerance = 1e-6)
  # block 9's span is not filled; the grid restarts at block 10
  expect_lt(nrow(d), n)
  expect_gt(nrow(d), n - 130)
  expect_identical(d$time[d$time > 1.7e9 + 86400][1], tm[10 * 120 + 1])
})

test_that("light: each block's 10-bit value, in both modes; none when not asked", {
  # GGIRread's files: compat = 0 gives every sample its block's value, read
  # from the file's bytes (bytes 18-19 of a block, low 10 bits: 283 to 435
  # on ax3_testfile.cwa; 16 on ax6_testfile.cwa, whose upper bits hold the
  # gyroscope range)
  for (name in c("ax3_testfile.cwa", "ax6_testfile.cwa",
                 "ax3_testfile_corrupt_blocks_0_13_14_142_143_144.cwa")) {
    f <- ggirread_file(name)
    raw <- raw_blocks(f)
    expect_identical(raw$light, as.numeric(block_light(f)[raw$block + 1]), label = name)
  }
  expect_identical(range(raw_blocks(ggirread_file("ax3_testfile.cwa"))$light), c(283, 435))
  # the whole-file compat read (GGIR's g.getmeta block: round(24 * 3600 *
  # sf / 80) = 108000 blocks at 100 Hz) is readAxivity's light
  f <- ggirread_file("ax3_testfile.cwa")
  expect_identical(nat_windows(f, 108000)$light, ref_windows(f, 108000)$light)
  # synthetic: the values written, one a block
  s <- synth(blocks = 20)
  d <- native_read_all(s$file, "cwa", list(compat = 0))
  expect_identical(d$light, rep(as.numeric(s$light), each = 120))
  expect_true(attr(d, "info")$light)
  # not asked: no column, nothing else changes
  for (compat in 0:1) {
    a <- native_read_all(s$file, "cwa", list(compat = compat))
    b <- native_read_all(s$file, "cwa", list(compat = compat), light = FALSE)
    expect_identical(names(b), c("x", "y", "z", "temperature", "time"))
    expect_identical(strip(b), strip(a)[names(b)])
    h <- native_open(s$file, "cwa", list(compat = compat))
    blk <- native_block(h, 7, 7 * 120, TRUE, TRUE, light = FALSE)
    gc_decoder_close(h$ptr)
    expect_null(blk$cols$light)
  }
})

test_that("light on damaged copies: readAxivity's, several block sizes", {
  # every damaged copy GGIRread reads (compat = 1: ref_windows() has light);
  # compat = 0: the clean file's light less the blocks lost
  s <- synth(blocks = 60)
  cases <- damage_cases(s)
  clean <- raw_blocks(s$file)
  for (case in c("corrupt", "checksum", "first", "last3", "seqgap")) {
    g <- with_bytes(cases[[case]])
    for (B in c(108000, 17, 5)) {
      nat <- nat_windows(g, B)
      ref <- ref_windows(g, B)
      expect_identical(nat$light, ref$light, label = paste(case, B))
    }
    got <- raw_blocks(g)
    expect_identical(got$light, clean$light[paste(clean$block, clean$time) %in%
                                              paste(got$block, got$time)], label = case)
  }
})
