# Native .gt3x decoder (inst/include/gravcal/decoders/decode_gt3x.hpp) against
# read.gt3x 1.2.0, the reader GGIR and read_recording() use, on the real
# files and on files written from the format documents by write_gt3x().

gt3x_real <- function() {
  c(tas = system.file("extdata", "TAS1H30182785_2019-09-17.gt3x", package = "read.gt3x"),
    ggir = if (!is.null(shared_data("ggir", "actigraph_testfile.gt3x")))
      shared_data("ggir", "actigraph_testfile.gt3x"))
}

read_native <- function(f, ...) {
  gravcal:::native_read_all(f, "gt3x", options = list(...))
}

ref_whole <- function(f, impute) {
  suppressWarnings(read.gt3x::read.gt3x(f, asDataFrame = TRUE, imputeZeroes = impute))
}

expect_same_samples <- function(d, r) {
  expect_identical(nrow(d), nrow(r))
  expect_identical(d$x, r$X)
  expect_identical(d$y, r$Y)
  expect_identical(d$z, r$Z)
  expect_identical(d$time, as.numeric(r$time))
}

# Successive read(out, B) calls, as list of data frames (one per call).
native_batches <- function(f, B, ...) {
  h <- gravcal:::native_open(f, "gt3x", list(...))
  on.exit(gravcal:::gc_decoder_close(h$ptr))
  out <- list()
  repeat {
    b <- gravcal:::native_block(h, B, B * h$info$sf, TRUE, TRUE)
    n <- b$to
    if (n > 0) {
      out[[length(out) + 1]] <- data.frame(x = b$cols$x[seq_len(n)], y = b$cols$y[seq_len(n)],
                                           z = b$cols$z[seq_len(n)], time = b$cols$time[seq_len(n)])
    }
    if (b$done || (n == 0 && b$units == 0)) break
  }
  out
}

# Records of a stored log.bin inside a zip's bytes: offset (1-based, in the
# zip), type, time, size. Walks the records from the first separator.
log_records <- function(bytes) {
  name <- grepRaw(charToRaw("log.bin"), bytes)[1]  # in the local header, at byte 31
  extra <- as.integer(bytes[name - 2]) + 256L * as.integer(bytes[name - 1])
  at <- name + 7L + extra
  recs <- list()
  while (at + 8 <= length(bytes) && bytes[at] == as.raw(0x1E)) {
    size <- as.integer(bytes[at + 6]) + 256L * as.integer(bytes[at + 7])
    ts <- sum(as.numeric(bytes[at + 2:5]) * 256^(0:3))
    recs[[length(recs) + 1]] <- c(at, as.integer(bytes[at + 1]), ts, size)
    at <- at + 9L + size
  }
  r <- as.data.frame(do.call(rbind, recs))
  names(r) <- c("offset", "type", "time", "size")
  r
}

# Recomputes a record's checksum after an edit (README: ~XOR of its bytes).
fix_checksum <- function(bytes, rec) {
  idx <- rec$offset + seq_len(8 + rec$size) - 1L
  bytes[rec$offset + 8 + rec$size] <- as.raw(bitwXor(Reduce(bitwXor, as.integer(bytes[idx])), 255L))
  bytes
}

write_bytes <- function(bytes) {
  f <- tempfile(fileext = ".gt3x")
  writeBin(bytes, f)
  f
}

synthetic <- function(sf = 30, seconds = 600, extra = 7, ...) {
  set.seed(42)
  n <- sf * seconds + extra
  x <- matrix(rnorm(3 * n, sd = 1.5), n)
  f <- tempfile(fileext = ".gt3x")
  gravcal:::write_gt3x(x, f, sf, 1600000000, ...)
  list(file = f, x = x, sf = sf)
}

test_that("real .gt3x files decode as read.gt3x reads them whole", {
  skip_if_not_installed("read.gt3x")
  for (f in gt3x_real()) {
    for (imp in c(FALSE, TRUE)) {
      d <- read_native(f, impute_zeroes = as.numeric(imp))
      expect_same_samples(d, ref_whole(f, imp))
    }
    rep <- attr(d, "report")
    expect_identical(rep$skipped, 0)
    expect_false(rep$truncated)
    expect_false(rep$read_error)
  }
  # read.gt3x's TAS file: 330 ACTIVITY2 seconds at 100 Hz (33000 samples),
  # 240500 with imputed zeros = (Last Sample Time - Start Date) * 100, seven
  # jumps in time (python walk of its log.bin, 2 idle records)
  d <- read_native(gt3x_real()[["tas"]], impute_zeroes = 1)
  expect_identical(nrow(d), 240500L)
  rep <- attr(d, "report")
  expect_identical(rep$units, 330)
  expect_identical(rep$gaps, 7)
  expect_identical(rep$counters[["idle_seconds"]], 2)
  expect_identical(attr(d, "info")$sf, 100)
  expect_identical(attr(d, "info")$serial, "TAS1H30182785")
})

test_that("blocks of B seconds are GGIR's read.gt3x batches", {
  skip_if_not_installed("read.gt3x")
  # GGIR: batch_begin = 1, then previous end + 1; batch_end = begin + B - 1
  for (f in gt3x_real()) {
    B <- 100
    ours <- native_batches(f, B)
    for (i in seq_along(ours)) {
      r <- suppressWarnings(read.gt3x::read.gt3x(f, batch_begin = (i - 1) * B + 1,
                                                 batch_end = i * B, asDataFrame = TRUE))
      expect_identical(ours[[i]]$x, r$X)
      expect_identical(ours[[i]]$y, r$Y)
      expect_identical(ours[[i]]$z, r$Z)
      expect_identical(ours[[i]]$time, as.numeric(r$time))
    }
    after <- try(read.gt3x::read.gt3x(f, batch_begin = length(ours) * B + 1,
                                      batch_end = (length(ours) + 1) * B, asDataFrame = TRUE),
                 silent = TRUE)
    expect_true(inherits(after, "try-error") || nrow(after) == 0)
  }
})

test_that("synthetic files: read.gt3x reads them back, the decoder gives the same", {
  skip_if_not_installed("read.gt3x")
  for (rec in c("activity2", "activity")) {
    for (deflate in c(TRUE, FALSE)) {
      s <- synthetic(record = rec, deflate = deflate, idle = c(5:9, 100:130), marker = c(50, 200))
      for (imp in c(FALSE, TRUE)) {
        d <- read_native(s$file, impute_zeroes = as.numeric(imp))
        expect_same_samples(d, ref_whole(s$file, imp))
      }
      # the written values: counts of 1/256 g (12 bits: clipped at +-2048)
      keep <- setdiff(seq_len(nrow(s$x)), as.vector(outer(1:30, 30 * c(5:9, 100:130, 50, 200), "+")))
      lim <- if (rec == "activity") 2048 else 32768
      # C's round(): halves away from zero (R's round() takes them to even)
      g <- pmin(pmax(round(s$x[keep, 1] * 256), -lim), lim - 1) / 256
      want <- sign(g) * floor(abs(g) * 1000 + 0.5) / 1000
      expect_equal(read_native(s$file)$x, want, tolerance = 0)
    }
  }
  s <- synthetic(format = "activity")
  d <- read_native(s$file)
  expect_same_samples(d, ref_whole(s$file, FALSE))
  expect_identical(nrow(d), nrow(s$x))
  expect_identical(attr(d, "report")$units, 601)
})

test_that("info.txt's Last Sample Time caps a whole imputed read, not batches", {
  skip_if_not_installed("read.gt3x")
  # 600 s of records, info.txt says 300 s: read.gt3x stops a whole read at
  # 300 * sf samples, its batches read on
  s <- synthetic(extra = 0, last = 1600000000 + 300, idle = 20:40)
  d <- read_native(s$file, impute_zeroes = 1)
  expect_same_samples(d, ref_whole(s$file, TRUE))
  expect_identical(nrow(d), 300L * 30L)
  expect_identical(attr(d, "report")$counters[["after_last_sample_time"]], 1)
  ours <- native_batches(s$file, 200)
  expect_length(ours, 3)
  for (i in seq_along(ours)) {
    r <- read.gt3x::read.gt3x(s$file, batch_begin = (i - 1) * 200 + 1, batch_end = i * 200,
                              asDataFrame = TRUE)
    expect_identical(ours[[i]]$x, r$X)
    expect_identical(ours[[i]]$time, as.numeric(r$time))
  }
})

test_that("old activity.bin files stream in seconds of sf samples", {
  s <- synthetic(format = "activity", extra = 0, seconds = 10)
  b <- native_batches(s$file, 3)
  expect_identical(vapply(b, nrow, 1L), c(90L, 90L, 90L, 30L))
  expect_identical(do.call(rbind, b)$x, read_native(s$file)$x)
})

test_that("a cut activity.bin keeps its whole samples and says so", {
  s <- synthetic(format = "activity", deflate = FALSE)
  clean <- read_native(s$file)
  bytes <- readBin(s$file, raw(), file.size(s$file))
  at <- grepRaw(charToRaw("activity.bin"), bytes) + 12L  # data after the name
  for (cut in c(4500, 4502, 4505)) {  # 1000 samples = 4500 bytes; mid-sample
    d <- read_native(write_bytes(bytes[seq_len(at + cut - 1)]))
    expect_identical(d$x, clean$x[seq_len(floor(cut / 4.5))])
    expect_identical(d$time, clean$time[seq_len(floor(cut / 4.5))])
    expect_true(attr(d, "report")$truncated)
  }
})

test_that("compat = 0 takes the PARAMETERS scale and record times", {
  s <- synthetic(seconds = 20, extra = 0, scale = 256)
  d1 <- read_native(s$file)
  d0 <- read_native(s$file, compat = 0)
  expect_identical(d0$x, d1$x)  # the PARAMETERS record says 256 too
  expect_identical(d0$time, 1600000000 + rep(0:19, each = 30) + rep(0:29, 20) / 30)
})

test_that("a bad checksum loses that second only", {
  s <- synthetic(deflate = FALSE)
  clean <- read_native(s$file)
  bytes <- readBin(s$file, raw(), file.size(s$file))
  recs <- log_records(bytes)
  act <- recs[recs$type == 0x1A, ]
  k <- act[200, ]
  bad <- bytes
  bad[k$offset + 8 + k$size] <- xor(bad[k$offset + 8 + k$size], as.raw(0xFF))
  d <- read_native(write_bytes(bad))
  lost <- clean$time >= k$time & clean$time < k$time + 1
  expect_identical(sum(lost), 30L)
  expect_identical(d$x, clean$x[!lost])
  expect_identical(d$time, clean$time[!lost])
  rep <- attr(d, "report")
  expect_identical(rep$counters[["bad_checksum"]], 1)
  expect_identical(rep$skipped, 1)
  expect_identical(rep$gaps, 1)
  expect_match(rep$notes[1], "bad_checksum: log.bin bytes")
  # a flipped payload byte in the middle of a record: the same
  bad <- bytes
  bad[k$offset + 100] <- xor(bad[k$offset + 100], as.raw(0x5A))
  d <- read_native(write_bytes(bad))
  expect_identical(d$x, clean$x[!lost])
  expect_identical(attr(d, "report")$counters[["bad_checksum"]], 1)
})

test_that("a flipped byte in a real file loses that second only", {
  f <- gt3x_real()[["tas"]]
  clean <- read_native(f)
  bytes <- readBin(f, raw(), file.size(f))
  recs <- log_records(bytes)
  k <- recs[recs$type == 0x1A, ][50, ]
  bad <- bytes
  bad[k$offset + 8 + 123] <- xor(bad[k$offset + 8 + 123], as.raw(0x10))
  d <- read_native(write_bytes(bad))
  lost <- clean$time >= k$time & clean$time < k$time + 1
  expect_identical(sum(lost), 100L)
  expect_identical(d$x, clean$x[!lost])
  expect_identical(d$time, clean$time[!lost])
  expect_identical(attr(d, "report")$counters[["bad_checksum"]], 1)
})

test_that("damage inside a deflated entry: what is given is right, the loss is reported", {
  s <- synthetic(deflate = TRUE)
  clean <- read_native(s$file)
  bytes <- readBin(s$file, raw(), file.size(s$file))
  for (at in round(length(bytes) * c(0.3, 0.6))) {
    bad <- bytes
    bad[at] <- xor(bad[at], as.raw(0x24))
    d <- read_native(write_bytes(bad))
    rep <- attr(d, "report")
    expect_true(rep$read_error || rep$skipped > 0)
    i <- match(d$time, clean$time)
    expect_false(anyNA(i))
    expect_identical(d$x, clean$x[i])
  }
})

test_that("a bad separator and a corrupted record are skipped, the rest kept", {
  s <- synthetic(deflate = FALSE)
  clean <- read_native(s$file)
  bytes <- readBin(s$file, raw(), file.size(s$file))
  act <- log_records(bytes)
  act <- act[act$type == 0x1A, ]
  k <- act[10, ]
  bad <- bytes
  bad[k$offset] <- as.raw(0x55)
  d <- read_native(write_bytes(bad))
  lost <- clean$time >= k$time & clean$time < k$time + 1
  expect_identical(d$x, clean$x[!lost])
  expect_identical(attr(d, "report")$counters[["bad_separator"]], 1)
  # three records overwritten with noise: those three seconds lost
  bad <- bytes
  from <- act$offset[300]
  to <- act$offset[303] - 1
  set.seed(3)
  bad[from:to] <- as.raw(sample(0:255, to - from + 1, TRUE))
  d <- read_native(write_bytes(bad))
  lost <- clean$time >= act$time[300] & clean$time < act$time[303]
  expect_identical(d$x, clean$x[!lost])
  expect_identical(attr(d, "report")$skipped, 1)
})

test_that("truncated files keep every whole second and say so", {
  s <- synthetic(deflate = FALSE)
  clean <- read_native(s$file)
  bytes <- readBin(s$file, raw(), file.size(s$file))
  act <- log_records(bytes)
  act <- act[act$type == 0x1A, ]
  for (k in c(1, 250, 600)) {
    for (cut in c(3, 50)) {  # inside the header, inside the payload
      d <- read_native(write_bytes(bytes[seq_len(act$offset[k] + cut)]))
      kept <- clean$time < act$time[k]
      expect_identical(d$x, clean$x[kept])
      rep <- attr(d, "report")
      expect_true(rep$truncated)
      expect_identical(rep$counters[["zip_directory_damaged"]], 1)
    }
  }
  # deflated: the inflater stops where the file stops
  s <- synthetic(deflate = TRUE)
  clean <- read_native(s$file)
  bytes <- readBin(s$file, raw(), file.size(s$file))
  d <- read_native(write_bytes(bytes[seq_len(length(bytes) %/% 2)]))
  rep <- attr(d, "report")
  expect_true(rep$truncated)
  expect_false(rep$read_error)
  expect_gt(nrow(d), 0)
  expect_identical(d$x, clean$x[seq_len(nrow(d))])
  expect_identical(nrow(d) %% 30L, 0L)
  # cut inside info.txt (it comes first): nothing to read, a clear error
  expect_error(read_native(write_bytes(bytes[1:100])), "info.txt")
})

test_that("damaged time stamps never make weeks of zeros", {
  s <- synthetic(deflate = FALSE)
  clean <- read_native(s$file, impute_zeroes = 1)
  bytes <- readBin(s$file, raw(), file.size(s$file))
  recs <- log_records(bytes)
  act <- recs[recs$type == 0x1A, ]
  k <- act[100, ]
  bad <- bytes
  bad[k$offset + 2:5] <- gravcal:::gt3x_u32(k$time + 30 * 86400)  # a month ahead, checksum fixed
  bad <- fix_checksum(bad, k)
  d <- read_native(write_bytes(bad), impute_zeroes = 1)
  lost <- clean$time >= k$time & clean$time < k$time + 1
  expect_identical(nrow(d), nrow(clean))
  expect_identical(d$x[!lost], clean$x[!lost])
  expect_true(all(d$x[lost] == 0))
  rep <- attr(d, "report")
  expect_identical(rep$counters[["bad_timestamp"]], 1)
  expect_lt(rep$gap_seconds, 86400)
  # five minutes ahead, inside the recording, the next record back in line:
  # a damaged stamp, the record kept at its place, no gap
  bad <- bytes
  bad[k$offset + 2:5] <- gravcal:::gt3x_u32(k$time + 300)
  bad <- fix_checksum(bad, k)
  for (imp in 0:1) {
    d <- read_native(write_bytes(bad), impute_zeroes = imp)
    ok <- read_native(s$file, impute_zeroes = imp)
    expect_identical(d$x, ok$x)
    expect_identical(d$time, ok$time)
    expect_identical(attr(d, "report")$gaps, attr(ok, "report")$gaps)
    expect_identical(attr(d, "report")$counters[["bad_timestamp"]], 1)
  }
  # stamped back in time: kept (as read.gt3x keeps it) and counted
  bad <- bytes
  bad[k$offset + 2:5] <- gravcal:::gt3x_u32(k$time - 50)
  bad <- fix_checksum(bad, k)
  d <- read_native(write_bytes(bad))
  expect_identical(nrow(d), nrow(read_native(s$file)))
  expect_identical(attr(d, "report")$counters[["time_backwards"]], 1)
})

test_that("a corrupt zip directory is read through the local headers", {
  s <- synthetic(deflate = TRUE)
  clean <- read_native(s$file)
  bytes <- readBin(s$file, raw(), file.size(s$file))
  eocd <- grepRaw(as.raw(c(0x50, 0x4b, 0x05, 0x06)), bytes, all = TRUE)
  bytes[eocd + 16:19] <- as.raw(0xEE)  # directory offset points nowhere
  d <- read_native(write_bytes(bytes))
  expect_identical(d$x, clean$x)
  expect_identical(attr(d, "report")$counters[["zip_directory_damaged"]], 1)
})

test_that("files that are not .gt3x fail to open with the reason", {
  f <- tempfile(fileext = ".gt3x")
  writeBin(as.raw(1:200), f)
  expect_error(read_native(f), "not a zip file")
  s <- synthetic(seconds = 5)
  g <- tempfile(fileext = ".gt3x")
  gravcal:::gt3x_write_zip(list(log.bin = as.raw(1:10)), g)
  expect_error(read_native(g), "no info.txt")
  gravcal:::gt3x_write_zip(list(info.txt = charToRaw("Sample Rate: 30\r\n")), g)
  expect_error(read_native(g), "Start Date")
})

# ---- zip64 (issue 44) --------------------------------------------------------

# The entries of a .gt3x (a zip), by name, as raw vectors (R's own unzip).
zip_entries <- function(f) {
  d <- tempfile("gt3x-entries")
  on.exit(unlink(d, recursive = TRUE))
  utils::unzip(f, exdir = d)
  nm <- c("info.txt", "log.bin")
  stats::setNames(lapply(file.path(d, nm), function(p) readBin(p, raw(), file.size(p))), nm)
}

# Where log.bin's zip64 extra field (id 0x0001) stands in a zip64 file from
# gt3x_write_zip(zip64 = TRUE): 1-based byte of its id in the local header
# and in the central directory; the values follow the id and the length (4
# bytes): size, compressed size (and in the central directory the local
# header's offset), 8 bytes each.
zip64_fields <- function(bytes) {
  at <- grepRaw(charToRaw("log.bin"), bytes, all = TRUE)
  c(local = at[1] + 7L, central = at[2] + 7L)
}

u64_at <- function(bytes, at) sum(as.numeric(bytes[at + 0:7]) * 256^(0:7))
put_u64 <- function(bytes, at, v) {
  bytes[at + 0:7] <- gravcal:::gt3x_u64(v)
  bytes
}

test_that("zip64 .gt3x files read as the zip files they were made from", {
  # a real file's entries in zip64's structures (every size, offset and
  # count 0xFFFFFFFF / 0xFFFF, the values in the zip64 extra fields and the
  # zip64 end record), deflated and stored
  f <- gt3x_real()[["tas"]]
  orig <- read_recording(f)
  e <- zip_entries(f)
  for (deflate in c(TRUE, FALSE)) {
    z <- tempfile(fileext = ".gt3x")
    gravcal:::gt3x_write_zip(e, z, deflate = deflate, zip64 = TRUE)
    bytes <- readBin(z, raw(), file.size(z))
    expect_identical(bytes[grepRaw(charToRaw("log.bin"), bytes)[1] - 12:9],
                     as.raw(c(0xFF, 0xFF, 0xFF, 0xFF)))  # the marker, not the size
    r <- read_recording(z)
    expect_identical(r$data$x, orig$data$x)
    expect_identical(r$data$y, orig$data$y)
    expect_identical(r$data$z, orig$data$z)
    expect_identical(r$data$time, orig$data$time)
    expect_identical(r$input$report, orig$input$report)
    expect_false(r$input$report$truncated)
    expect_identical(r$input$report$notes, character(0))
    if (requireNamespace("read.gt3x", quietly = TRUE)) {  # zip64 as others read it
      expect_same_samples(read_native(z, impute_zeroes = 1), ref_whole(z, TRUE))
    }
  }
  # files written from the format documents, with and without zip64
  for (deflate in c(TRUE, FALSE)) {
    a <- synthetic(deflate = deflate)
    b <- synthetic(deflate = deflate, zip64 = TRUE)
    da <- read_native(a$file)
    db <- read_native(b$file)
    expect_identical(db$x, da$x)
    expect_identical(db$time, da$time)
    expect_identical(attr(db, "report"), attr(da, "report"))
  }
})

test_that("damaged zip64 structures: a clear error, or the local headers read and a note", {
  s <- synthetic(deflate = FALSE, zip64 = TRUE)
  clean <- read_native(s$file)
  bytes <- readBin(s$file, raw(), file.size(s$file))
  at <- zip64_fields(bytes)
  comp <- u64_at(bytes, at[["central"]] + 12)
  expect_identical(comp, u64_at(bytes, at[["local"]] + 12))
  read_bad <- function(b) read_native(write_bytes(b))
  via_local <- function(b, note) {
    d <- read_bad(b)
    expect_identical(d$x, clean$x)
    expect_identical(d$time, clean$time)
    rep <- attr(d, "report")
    expect_identical(rep$counters[["zip_directory_damaged"]], 1)
    expect_false(rep$truncated)
    expect_match(rep$notes[1], note)
  }
  # the zip64 extra field cut from the central directory (its id changed):
  # read through the local headers; cut from both: an error naming it
  bad <- bytes
  bad[at[["central"]]] <- as.raw(0x99)
  via_local(bad, "central directory's log.bin: .*no zip64 extra field")
  bad[at[["local"]]] <- as.raw(0x99)
  expect_error(read_bad(bad), "local header of log.bin at byte [0-9]+: .*no zip64 extra field")
  # too short for the values marked 0xFFFFFFFF (16 and 24 bytes said 8)
  bad <- bytes
  bad[at + 2] <- as.raw(8)
  expect_error(read_bad(bad), "log.bin.*zip64 extra field holds 8 bytes, too few")
  # sizes that disagree between the central directory and the local header
  bad <- put_u64(bytes, at[["central"]] + 12, comp + 1)
  expect_error(read_bad(bad), paste0("inconsistent zip64 sizes of log.bin: ", comp,
                                     " stored bytes .* ", comp + 1, " \\("))
  # a size past the central directory: the directory is not used
  bad <- put_u64(bytes, at[["central"]] + 12, 2^40)
  via_local(bad, "run past the directory")
  # a size out of any file's range, in both headers
  bad <- put_u64(bytes, at[["central"]] + 12, 2^60)
  via_local(bad, "out of range")
  bad <- put_u64(bad, at[["local"]] + 12, 2^60)
  expect_error(read_bad(bad), "local header of log.bin.*compressed size 1152921504606846976 is out of range")
  # the zip64 end record's locator pointing nowhere: the local headers
  loc <- grepRaw(as.raw(c(0x50, 0x4b, 0x06, 0x07)), bytes)
  bad <- put_u64(bytes, loc + 8, 5)
  via_local(bad, "zip64 end of central directory record not found at byte 5")
  # the end record marks zip64 values but the locator is gone
  bad <- bytes
  bad[loc + 0:3] <- as.raw(0)
  via_local(bad, "no zip64 locator precedes it")
  # cut short: every whole second kept, as without zip64
  act <- log_records(bytes)
  act <- act[act$type == 0x1A, ]
  d <- read_bad(bytes[seq_len(act$offset[250] + 50)])
  expect_identical(d$x, clean$x[clean$time < act$time[250]])
  expect_true(attr(d, "report")$truncated)
  # every byte of the zip structures flipped: an error or samples, never a
  # crash
  cd <- grepRaw(as.raw(c(0x50, 0x4b, 0x01, 0x02)), bytes)
  for (k in c(seq_len(act$offset[1] - 1), cd:length(bytes))) {
    bad <- bytes
    bad[k] <- xor(bad[k], as.raw(0xA5))
    d <- tryCatch(read_bad(bad), error = function(e) conditionMessage(e))
    expect_true(is.character(d) || is.data.frame(d))
  }
})
