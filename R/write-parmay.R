# Test-only writer of Parmay Matrix .bin files, from the format as GGIRread
# 1.2.0 documents and reads it (see inst/include/gravcal/decoders/decode_parmay.hpp):
# 512 bytes of remarks, "MDTC", the packet count (int32), the accelerometer
# range (int16, g) and the gyroscope range (int16); then packets of
# "MDTCPACK", a CRC-32 of the packet from its byte 12, the packet's start
# and end time (int32 s since 1970 UTC), the counts of accelerometer,
# gyroscope, temperature and heart-rate samples (int32), accelerometer x,
# y, z (int16: v * range / 32767, or / 32768 below 0) and temperature (two
# int16 in tenths of a degree: body surface, ambient). Used by the tests;
# not exported.

# Write samples `x` (x, y, z in g; a `temperature` column, or the
# `temperature` argument: one value or one a sample, the ambient
# temperature) as a Parmay Matrix file at `sf` Hz from `start` (seconds
# since 1970 UTC, whole), in packets of `packet_seconds` (sf *
# packet_seconds samples each; the last may be shorter), with `temp_per_packet`
# temperature samples a packet (0: none in the file).
write_parmay_bin <- function(x, file, sf = 25, start = 1.7e9, range = 8,
                             packet_seconds = 60, temperature = NULL,
                             temp_per_packet = 2, remarks = "gravcal test file") {
  x <- as.data.frame(x)
  n <- nrow(x)
  per <- sf * packet_seconds
  stopifnot(n >= 1, per == round(per), start == round(start), packet_seconds >= 1)
  temp <- if (!is.null(temperature)) rep_len(temperature, n) else
    if (!is.null(x$temperature)) x$temperature else rep_len(25, n)
  np <- ceiling(n / per)
  con <- file(file, "wb")
  on.exit(close(con))
  h <- raw(524)
  rm <- charToRaw(remarks)[seq_len(min(512, nchar(remarks, "bytes")))]
  h[seq_along(rm)] <- rm
  h[513:516] <- charToRaw("MDTC")
  h[517:520] <- parmay_le(np, 4)
  h[521:522] <- parmay_le(range, 2)
  h[523:524] <- parmay_le(2000, 2)
  writeBin(h, con)
  q <- function(v) {
    v <- ifelse(v >= 0, round(v / range * 32767), round(v / range * 32768))
    as.integer(pmin(pmax(v, -32768), 32767))
  }
  for (p in seq_len(np)) {
    rows <- ((p - 1) * per + 1):min(n, p * per)
    k <- length(rows)
    t0 <- start + (p - 1) * packet_seconds
    t1 <- t0 + round(k / sf)
    nt <- if (temp_per_packet > 0) temp_per_packet else 0
    at <- rows[pmin(k, 1 + floor((seq_len(nt) - 1) * k / max(nt, 1)))]
    body <- c(parmay_le(c(t0, t1, k, 0, nt, 0), 4),
              parmay_le(as.vector(rbind(q(x$x[rows]), q(x$y[rows]), q(x$z[rows]))), 2),
              if (nt) parmay_le(as.vector(rbind(round(temp[at] * 10) + 50L,
                                                round(temp[at] * 10))), 2))
    writeBin(c(charToRaw("MDTCPACK"), parmay_le(gc_crc32(body), 4), body), con)
  }
  invisible(file)
}

# Little-endian bytes of integers (`size` 2 or 4), two's complement.
parmay_le <- function(v, size) {
  v <- as.numeric(v)
  v <- ifelse(v < 0, v + 2^(8 * size), v)
  b <- vapply(seq_len(size) - 1, function(i) (v %/% 2^(8 * i)) %% 256, numeric(length(v)))
  as.raw(as.vector(t(matrix(b, ncol = size))))
}
