# Test-only writers of ActiGraph .gt3x files (zip of info.txt and log.bin or
# activity.bin), from ActiGraph's GT3X-File-Format and NHANES-GT3X-File-Format
# documents. Vectorised: a week at 100 Hz is written in seconds. Not exported.

gt3x_epoch0001 <- 62135596800  # seconds from 0001-01-01 to 1970-01-01
gt3x_sep <- 0x1E               # record separator
gt3x_types <- c(activity = 0x00, battery = 0x02, metadata = 0x06,
                parameters = 0x15, activity2 = 0x1A)

# x: samples in g (matrix or data frame, columns x, y, z), sf in Hz, start in
# seconds since 1970 (local time, as the device keeps it) or POSIXct.
# format "log": log.bin with one ACTIVITY2 (record = "activity2", 16-bit) or
# ACTIVITY (record = "activity", 12-bit YXZ) record a second; `idle` seconds
# (0-based from the start) get no record (idle sleep), `marker` seconds get a
# one-byte idle record instead of their samples. format "activity": an old
# NEO file with a packed activity.bin (firmware 2.5.0). `deflate`: zip method
# 8, else stored; `zip64`: sizes and offsets in zip64's structures (see
# gt3x_write_zip()). `last` overrides info.txt's Last Sample Time (seconds).
write_gt3x <- function(x, file, sf, start, format = c("log", "activity"),
                       record = c("activity2", "activity"), idle = integer(0),
                       marker = integer(0), scale = NULL, deflate = TRUE,
                       last = NULL, serial = NULL, zip64 = FALSE) {
  format <- match.arg(format)
  record <- match.arg(record)
  x <- as.matrix(x)[, 1:3, drop = FALSE]
  start <- round(as.numeric(start))
  old <- format == "activity"
  twelve <- old || record == "activity"
  if (is.null(scale)) scale <- if (old) 341 else 256
  lim <- if (twelve) c(-2048, 2047) else c(-32768, 32767)
  counts_of <- function(rows) {
    v <- round(x[rows, , drop = FALSE] * scale)
    v[] <- pmin(pmax(v, lim[1]), lim[2])
    storage.mode(v) <- "integer"
    v
  }
  nsec <- ceiling(nrow(x) / sf)
  if (is.null(serial)) serial <- if (old) "NEO1A23456789" else "MOS2E12345678"
  info <- gt3x_info_txt(serial, sf, start, if (is.null(last)) start + nsec else last,
                        scale, old)
  data <- if (old) {
    function(put) {  # whole 6-hour chunks of an even sample count stay byte-aligned
      for (r in gt3x_chunks(nrow(x), sf * 21600)) put(gt3x_pack12(counts_of(r)[, c(2, 1, 3), drop = FALSE]))
    }
  } else {
    function(put) gt3x_log_bin(counts_of, nrow(x), sf, start, twelve, idle, marker, scale, put)
  }
  entries <- list(info.txt = charToRaw(info))
  entries[[if (old) "activity.bin" else "log.bin"]] <- data
  gt3x_write_zip(entries, file, deflate, zip64)
  invisible(file)
}

# Row ranges of at most `size` rows.
gt3x_chunks <- function(n, size) {
  if (n == 0) return(list())
  from <- seq(1, n, by = size)
  lapply(from, function(a) a:min(n, a + size - 1))
}

gt3x_ticks <- function(seconds) {
  paste0(format(seconds + gt3x_epoch0001, scientific = FALSE, trim = TRUE), "0000000")
}

gt3x_info_txt <- function(serial, sf, start, last, scale, old) {
  lines <- c(
    paste0("Serial Number: ", serial),
    paste0("Device Type: ", if (old) "GT3XPlus" else "wGT3XBT"),
    paste0("Firmware: ", if (old) "2.5.0" else "1.9.2"),
    "Battery Voltage: 4.10",
    paste0("Sample Rate: ", sf),
    paste0("Start Date: ", gt3x_ticks(start)),
    "Stop Date: 0",
    paste0("Last Sample Time: ", gt3x_ticks(last)),
    "TimeZone: 00:00:00",
    paste0("Download Date: ", gt3x_ticks(last)),
    "Board Revision: 5",
    "Unexpected Resets: 0",
    paste0("Acceleration Scale: ", format(scale, nsmall = 1)),
    paste0("Acceleration Min: ", if (old) "-6.0" else "-8.0"),
    paste0("Acceleration Max: ", if (old) "6.0" else "8.0"),
    "Subject Name: synthetic")
  paste0(paste(lines, collapse = "\r\n"), "\r\n")
}

# Little-endian bytes of 32- and 16-bit unsigned values (as doubles).
gt3x_u32 <- function(v) {
  v <- as.numeric(v)
  as.raw(rbind(v %% 256, (v %/% 256) %% 256, (v %/% 65536) %% 256, (v %/% 16777216) %% 256))
}
gt3x_u16 <- function(v) as.raw(rbind(v %% 256, (v %/% 256) %% 256))

# 12-bit two's-complement values packed big-endian, two values in 3 bytes;
# an odd last value fills 2 bytes (Activity.md). `counts`: rows of samples,
# columns in packing order; returns the bytes of all values in row order.
gt3x_pack12 <- function(counts) {
  v <- as.integer(t(counts)) %% 4096L
  odd <- length(v) %% 2L == 1L
  if (odd) v <- c(v, 0L)
  # a pair as one 24-bit number, written big-endian in 4 bytes, first dropped
  pair <- v[c(TRUE, FALSE)] * 4096L + v[c(FALSE, TRUE)]
  out <- matrix(writeBin(pair, raw(), size = 4, endian = "big"), 4)[-1, , drop = FALSE]
  out <- as.vector(out)
  if (odd) out <- out[-length(out)]
  out
}

# One record: separator, type, time, size, payload, checksum (README).
gt3x_record <- function(type, time, payload) {
  h <- c(as.raw(gt3x_sep), as.raw(type), gt3x_u32(time), gt3x_u16(length(payload)))
  c(h, payload, gt3x_checksum(c(h, payload)))
}
gt3x_checksum <- function(bytes) {
  as.raw(bitwXor(Reduce(bitwXor, as.integer(bytes), 0L), 255L))
}

# PARAMETERS payload: start time (address 1, key 12) and ACCEL_SCALE (0, 55)
# as the three-byte fraction and one-byte exponent float.
gt3x_parameters <- function(start, scale) {
  e <- floor(log2(scale)) + 1
  f <- round(scale / 2^e * 2^23)
  c(gt3x_u16(1), gt3x_u16(12), gt3x_u32(start),
    gt3x_u16(0), gt3x_u16(55), gt3x_u32(f + (e %% 256) * 2^24))
}

# log.bin through put(bytes), six hours at a time: METADATA, PARAMETERS, a
# record a second, a BATTERY record at the end.
gt3x_log_bin <- function(counts_of, n, sf, start, twelve, idle, marker, scale, put) {
  type <- if (twelve) gt3x_types[["activity"]] else gt3x_types[["activity2"]]
  put(c(gt3x_record(gt3x_types[["metadata"]], start, charToRaw("{\"Subject\":\"synthetic\"}")),
        gt3x_record(gt3x_types[["parameters"]], start, gt3x_parameters(start, scale))))
  full <- n %/% sf
  for (r in gt3x_chunks(full, 21600)) {
    put(gt3x_log_seconds(counts_of(((r[1] - 1) * sf + 1):(r[length(r)] * sf)), sf,
                         start, r - 1L, type, twelve, idle, marker))
  }
  nsec <- ceiling(n / sf)
  if (full < nsec && !((nsec - 1) %in% c(idle, marker))) {
    rest <- counts_of((full * sf + 1):n)
    put(gt3x_record(type, start + full, as.vector(gt3x_payloads(rest, nrow(rest), twelve))))
  }
  put(gt3x_record(gt3x_types[["battery"]], start + nsec, gt3x_u16(4100)))
}

# Records of whole seconds `secs` (0-based), one matrix column each.
gt3x_log_seconds <- function(counts, sf, start, secs, type, twelve, idle, marker) {
  m <- gt3x_payloads(counts, sf, twelve)
  hdr <- rbind(as.raw(gt3x_sep), as.raw(type), matrix(gt3x_u32(start + secs), 4),
               matrix(gt3x_u16(rep(nrow(m), length(secs))), 2))
  chk <- !xor(gt3x_xor_rows(hdr), gt3x_xor_rows(m))
  keep <- !(secs %in% c(idle, marker))
  out <- list()
  from <- secs[1]
  for (k in sort(unique(c(marker[marker %in% secs], secs[length(secs)] + 1L)))) {
    cols <- which(keep & secs >= from & secs < k)
    out[[length(out) + 1]] <- as.vector(rbind(hdr[, cols, drop = FALSE], m[, cols, drop = FALSE],
                                              chk[cols]))
    if (k %in% marker) out[[length(out) + 1]] <- gt3x_record(type, start + k, as.raw(0))
    from <- k + 1L
  }
  unlist(out, use.names = FALSE)
}

# Payload bytes of seconds of `k` samples each, one column a second.
gt3x_payloads <- function(counts, k, twelve) {
  if (!nrow(counts)) return(matrix(raw(0), if (twelve) ceiling(4.5 * k) else 6 * k, 0))
  nsec <- nrow(counts) %/% k
  if (twelve) {
    yxz <- counts[, c(2, 1, 3), drop = FALSE]
    if ((3 * k) %% 2 == 0) return(matrix(gt3x_pack12(yxz), ncol = nsec))
    per <- lapply(seq_len(nsec), function(s) gt3x_pack12(yxz[(s - 1) * k + seq_len(k), , drop = FALSE]))
    return(matrix(unlist(per), ncol = nsec))
  }
  # little-endian int16, XYZ (Activity2.md)
  matrix(writeBin(as.integer(t(counts)), raw(), size = 2, endian = "little"), ncol = nsec)
}

# XOR of each column of a raw matrix, folding the rows in halves.
gt3x_xor_rows <- function(m) {
  while (nrow(m) > 1) {
    if (nrow(m) %% 2 == 1) m <- rbind(m, as.raw(0))
    h <- nrow(m) %/% 2
    m <- xor(m[seq_len(h), , drop = FALSE], m[h + seq_len(h), , drop = FALSE])
  }
  m[1, ]
}

# Little-endian bytes of 64-bit unsigned values (as doubles, below 2^53).
gt3x_u64 <- function(v) {
  v <- as.numeric(v)
  as.vector(rbind(matrix(gt3x_u32(v %% 2^32), 4), matrix(gt3x_u32(v %/% 2^32), 4)))
}

# A zip of entries (raw vectors, or functions that write their bytes through
# put()), stored or deflated (PKWARE APPNOTE). The deflate stream and CRC-32
# come from a gzip file written by R's own zlib (RFC 1952: 10-byte header,
# deflate data, CRC-32 and size trailer); data is copied in chunks.
# `zip64`: every size, offset and count that zip64 can carry is written
# there (APPNOTE 4.3.14, 4.3.15, 4.5.3): the 32-bit fields hold 0xFFFFFFFF
# (0xFFFF for counts), the values stand in each header's zip64 extra field
# (0x0001; the sizes in a local header, the sizes and the local header's
# offset in the central directory), and a zip64 end of central directory
# record and its locator come before the end record.
gt3x_write_zip <- function(entries, file, deflate = TRUE, zip64 = FALSE) {
  out <- file(file, "wb")
  on.exit(close(out))
  central <- list()
  off <- 0
  mark <- 2^32 - 1
  version <- if (zip64) 45 else 20
  for (name in names(entries)) {
    e <- gt3x_entry(entries[[name]], deflate)
    nm <- charToRaw(name)
    local_extra <- if (zip64) c(gt3x_u16(c(1, 16)), gt3x_u64(c(e$size, e$body_len)))
    central_extra <- if (zip64) c(gt3x_u16(c(1, 24)), gt3x_u64(c(e$size, e$body_len, off)))
    common <- function(extra) {
      c(gt3x_u16(c(version, 0, if (deflate) 8 else 0, 0, 33)), e$crc,
        gt3x_u32(if (zip64) c(mark, mark) else c(e$body_len, e$size)),
        gt3x_u16(c(length(nm), length(extra))))
    }
    writeBin(c(gt3x_u32(0x04034b50), common(local_extra), nm, local_extra), out)
    gt3x_copy(e$path, e$body_from, e$body_len, out)
    unlink(e$files)
    central[[name]] <- c(gt3x_u32(0x02014b50), gt3x_u16(version), common(central_extra),
                         gt3x_u16(c(0, 0, 0)), gt3x_u32(c(0, if (zip64) mark else off)), nm,
                         central_extra)
    off <- off + 30 + length(nm) + length(local_extra) + e$body_len
  }
  cd <- unlist(central, use.names = FALSE)
  writeBin(cd, out)
  n <- length(entries)
  if (zip64) {
    writeBin(c(gt3x_u32(0x06064b50), gt3x_u64(44), gt3x_u16(c(45, 45)), gt3x_u32(c(0, 0)),
               gt3x_u64(c(n, n, length(cd), off))), out)
    writeBin(c(gt3x_u32(0x07064b50), gt3x_u32(0), gt3x_u64(off + length(cd)), gt3x_u32(1)), out)
    writeBin(c(gt3x_u32(0x06054b50), gt3x_u16(c(0, 0, 65535, 65535)),
               gt3x_u32(c(mark, mark)), gt3x_u16(0)), out)
  } else {
    writeBin(c(gt3x_u32(0x06054b50), gt3x_u16(c(0, 0, n, n)),
               gt3x_u32(c(length(cd), off)), gt3x_u16(0)), out)
  }
  invisible(file)
}

# Writes an entry's bytes to a gzip file (and a plain one when stored).
gt3x_entry <- function(content, deflate) {
  gz <- tempfile(fileext = ".gz")
  plain <- tempfile()
  gzc <- gzfile(gz, "wb", compression = if (deflate) 1 else 0)
  pc <- if (!deflate) file(plain, "wb")
  size <- 0
  put <- function(bytes) {
    writeBin(bytes, gzc)
    if (!deflate) writeBin(bytes, pc)
    size <<- size + length(bytes)
  }
  if (is.function(content)) content(put) else put(content)
  close(gzc)
  if (!deflate) close(pc)
  g <- file(gz, "rb")
  seek(g, file.size(gz) - 8)
  crc <- readBin(g, raw(), 4)
  close(g)
  if (deflate) {
    list(path = gz, body_from = 10, body_len = file.size(gz) - 18, size = size, crc = crc,
         files = gz)
  } else {
    list(path = plain, body_from = 0, body_len = size, size = size, crc = crc,
         files = c(gz, plain))
  }
}

gt3x_copy <- function(path, from, len, out) {
  con <- file(path, "rb")
  on.exit(close(con))
  if (from > 0) readBin(con, raw(), from)
  while (len > 0) {
    b <- readBin(con, raw(), min(len, 2^26))
    if (!length(b)) break
    writeBin(b, out)
    len <- len - length(b)
  }
}
