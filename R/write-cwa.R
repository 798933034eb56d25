# Test-only writer of Axivity .cwa files (openmovement Docs/ax3/cwa.h): a
# 1024-byte "MD" header, then 512-byte "AX" data blocks of little-endian
# 16-bit words whose sum is 0 mod 2^16. Used by the decoder tests and the
# benchmark; not exported.

cwa_header_bytes <- 1024
cwa_block_words <- 256
cwa_chunk_blocks <- 8192  # blocks built at once (bounds the writer's memory)

# Write samples `x` (n x 3, in g) as a .cwa file at `sf` Hz from `start`
# (POSIXct or seconds since 1970 UTC). `packed`: AX3 3 x 10-bit + exponent
# (120 samples a block), else 16-bit (80; 40 with `ax6`, gyroscope 0).
# `temperature` in degrees C: one value, or one a sample (each block takes
# its first sample's). `light`: the light sensor's raw value (0 to 1023),
# one value, one a block, or one a sample (each block takes its first
# sample's). `time`: optional time of each sample, to place blocks
# (gaps, jumps); a block starts at its first sample's time. `fractional`:
# blocks carry a fraction of a second (deviceFractional's top bit).
# `append = TRUE` adds the blocks to the end of an existing file written by
# this function (no header), numbering them from `block0`: long recordings
# are written in pieces, each with its own `start`.
write_cwa <- function(x, file, sf = 100, start = 1.7e9, packed = TRUE,
                      temperature = 25, light = 0, range = 8, ax6 = FALSE,
                      time = NULL, fractional = TRUE, device_id = 43981,
                      session = 7, scale_code = if (ax6) 4 else 0,
                      append = FALSE, block0 = 0) {
  x <- as.matrix(x)
  n <- nrow(x)
  if (ax6) packed <- FALSE
  spb <- if (packed) 120 else if (ax6) 40 else 80
  rate <- 15 - log2(3200 / sf)
  stopifnot(rate == round(rate), rate >= 0, rate <= 15, n >= 1)
  rate_byte <- rate + 64 * log2(16 / range)
  nb <- ceiling(n / spb)
  first <- (seq_len(nb) - 1) * spb + 1
  t0 <- if (is.null(time)) as.numeric(start) + (first - 1) / sf else as.numeric(time)[first]
  temp <- if (length(temperature) == n) temperature[first] else rep_len(temperature, nb)
  lux <- if (length(light) == n) light[first] else rep_len(light, nb)
  con <- file(file, if (append) "ab" else "wb")
  on.exit(close(con))
  if (!append) writeBin(cwa_header(device_id, session, rate_byte, ax6), con)
  for (b0 in seq(1, nb, by = cwa_chunk_blocks)) {
    bl <- b0:min(nb, b0 + cwa_chunk_blocks - 1)
    rows <- ((bl[1] - 1) * spb + 1):min(n, bl[length(bl)] * spb)
    w <- cwa_words(x[rows, , drop = FALSE], bl + block0, spb, t0[bl], temp[bl], sf,
                   packed, ax6, lux[bl], rate_byte, scale_code, fractional,
                   device_id, session)
    writeBin(as.integer(w), con, size = 2, endian = "little")  # 16-bit words
  }
  invisible(file)
}

cwa_header <- function(device_id, session, rate_byte, ax6) {
  h <- raw(cwa_header_bytes)
  h[1:2] <- charToRaw("MD")
  h[3:4] <- cwa_le(1020, 2)             # header length after the first 4 bytes
  h[5] <- as.raw(if (ax6) 0x64 else 0x17)  # hardware type
  h[6:7] <- cwa_le(device_id %% 65536, 2)
  h[8:11] <- cwa_le(session, 4)
  h[12:13] <- cwa_le(device_id %/% 65536, 2)
  h[37] <- as.raw(rate_byte)
  h[42] <- as.raw(44)                    # firmware version
  h
}

# Little-endian bytes of non-negative whole numbers.
cwa_le <- function(v, nbytes) {
  as.raw(vapply(seq_len(nbytes) - 1, function(k) (v %/% 256^k) %% 256, numeric(1)))
}

# The 256 x nb matrix of 16-bit words of data blocks `bl`.
cwa_words <- function(x, bl, spb, t0, temp, sf, packed, ax6, light, rate_byte,
                      scale_code, fractional, device_id, session) {
  nb <- length(bl)
  count <- pmin(spb, nrow(x) - (seq_len(nb) - 1) * spb)
  w <- matrix(0, cwa_block_words, nb)
  w[1, ] <- 0x5841                       # "AX"
  w[2, ] <- 508
  q <- round(t0 * 32768)                 # time in 1/32768 s
  secs <- q %/% 32768
  f15 <- q %% 32768
  if (fractional) {
    w[3, ] <- 32768 + f15
    offset <- -floor(2 * f15 * floor(sf) / 65536)  # undone by the reader's shim
  } else {
    w[3, ] <- device_id %% 32768
    offset <- round((secs - t0) * sf)
  }
  w[4, ] <- session %% 65536
  w[5, ] <- session %/% 65536
  w[6, ] <- (bl - 1) %% 65536            # sequence id
  w[7, ] <- (bl - 1) %/% 65536
  coded <- cwa_rtc(secs)
  w[8, ] <- coded %% 65536
  w[9, ] <- coded %/% 65536
  w[10, ] <- light + 8192 * scale_code + if (ax6) 1024 * 2 else 0
  w[11, ] <- round((temp + 50) * 256 / 75) %% 1024
  w[12, ] <- 256 * 200                   # battery byte
  w[13, ] <- rate_byte + 256 * (if (ax6) 0x62 else if (packed) 0x30 else 0x32)
  w[14, ] <- offset %% 65536
  w[15, ] <- count
  w[16:255, ] <- cwa_data_words(x, nb * spb, packed, ax6, scale_code)
  w[256, ] <- (65536 - colSums(w[1:255, , drop = FALSE]) %% 65536) %% 65536
  w
}

# The packed RTC time of whole seconds since 1970 (UTC).
cwa_rtc <- function(secs) {
  lt <- as.POSIXlt(secs, origin = "1970-01-01", tz = "UTC")
  (lt$year - 100) * 2^26 + (lt$mon + 1) * 2^22 + lt$mday * 2^17 + lt$hour * 2^12 +
    lt$min * 2^6 + floor(lt$sec)
}

# 240 words a block of samples (padded with zeros to `slots` samples).
cwa_data_words <- function(x, slots, packed, ax6, scale_code) {
  pad <- slots - nrow(x)
  counts <- function(a, scale) c(round(x[, a] * scale), numeric(pad))
  if (packed) {
    v <- lapply(1:3, counts, scale = 256)
    m <- pmax(abs(v[[1]]), abs(v[[2]]), abs(v[[3]]))
    e <- (m >= 512) + (m >= 1024) + (m >= 2048)  # exponent: 10 bits hold the rest
    u <- lapply(v, function(c) (c %/% 2^e) %% 1024)
    word <- u[[1]] + u[[2]] * 2^10 + u[[3]] * 2^20 + e * 2^30
    return(c(rbind(word %% 65536, word %/% 65536)))
  }
  v <- lapply(1:3, function(a) counts(a, 2^(8 + scale_code)) %% 65536)
  if (ax6) {
    z <- numeric(slots)
    return(c(rbind(z, z, z, v[[1]], v[[2]], v[[3]])))
  }
  c(rbind(v[[1]], v[[2]], v[[3]]))
}

# Sets the checksum word of data block `block` (0-based) of file bytes `b`
# so the block's words sum to 0 again (after a test edits the block).
cwa_fix_checksum <- function(b, block) {
  at <- cwa_header_bytes + 512 * block
  bytes <- as.integer(b[at + 1:510])
  s <- sum(bytes[c(TRUE, FALSE)] + 256 * bytes[c(FALSE, TRUE)]) %% 65536
  b[at + 511:512] <- cwa_le((65536 - s) %% 65536, 2)
  b
}
