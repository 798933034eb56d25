# Test-only writer of Movisens recordings, from the unisens 2.0 format as
# unisensR reads it (see inst/include/gravcal/decoders/decode_movisens.hpp): a folder
# with unisens.xml, whose root element <unisens> (namespace
# http://www.unisens.org/unisens2.0) gives timestampStart and whose
# <signalEntry> elements each describe one binary file (id: its name;
# dataType int16 or int32; sampleRate; lsbValue and baseline: a value is
# (stored - baseline) * lsbValue; <binFileFormat endianess="LITTLE"/>; one
# <channel name=..> per interleaved channel): acc.bin (three channels) and
# temp.bin (one channel named "temp", degrees C). Used by the tests; not
# exported.

# Write samples `x` (x, y, z in g; a `temperature` column, or the
# `temperature` argument: one value or one a sample) as a Movisens folder
# `dir` at `sf` Hz from `start` (POSIXct or text, UTC), acceleration stored
# as `data_type` with `lsb` g a step, temperature at `temp_sf` Hz (the value
# of the sample at each temperature time, `temp_lsb` degrees a step;
# `temp = FALSE`: no temp.bin and no entry for it). The temperature file
# holds ceiling(n / sf * temp_sf) samples, which covers every sample
# (Movisens devices write it so).
write_movisens <- function(x, dir, sf = 64, start = "2023-05-11 09:00:00",
                           lsb = 1 / 2048, baseline = 0, data_type = "int16",
                           temperature = NULL, temp_sf = 1, temp_lsb = 0.1,
                           temp = TRUE, serial = "12345",
                           measurement = "gravcal-test") {
  x <- as.data.frame(x)
  n <- nrow(x)
  stopifnot(n >= 1, data_type %in% c("int16", "int32"), sf > 0, temp_sf > 0)
  size <- if (data_type == "int16") 2L else 4L
  lim <- if (size == 2L) 32767 else 2147483647
  q <- function(v, step, base) {
    as.integer(pmin(pmax(round(v / step + base), -lim - 1), lim))
  }
  dir.create(dir, showWarnings = FALSE, recursive = TRUE)
  acc <- as.vector(rbind(q(x$x, lsb, baseline), q(x$y, lsb, baseline),
                         q(x$z, lsb, baseline)))
  writeBin(acc, file.path(dir, "acc.bin"), size = size, endian = "little")
  num <- function(v) format(v, digits = 17, scientific = FALSE, trim = TRUE)
  t0 <- as.POSIXct(start, tz = "UTC")
  entry <- function(id, type, rate, step, base, unit, cls, channels) {
    c(paste0('  <signalEntry id="', id, '" dataType="', type, '" sampleRate="',
             num(rate), '" lsbValue="', num(step), '" baseline="', num(base),
             '" unit="', unit, '" contentClass="', cls, '">'),
      '    <binFileFormat endianess="LITTLE"/>',
      paste0('    <channel name="', channels, '"/>'),
      '  </signalEntry>')
  }
  xml <- c('<?xml version="1.0" encoding="UTF-8" standalone="yes"?>',
           paste0('<unisens xmlns="http://www.unisens.org/unisens2.0" version="2.0" ',
                  'measurementId="', measurement, '" timestampStart="',
                  format(t0, "%Y-%m-%dT%H:%M:%S.000", tz = "UTC"), '" duration="',
                  num(n / sf), '">'),
           '  <customAttributes>',
           paste0('    <customAttribute key="sensorSerialNumber" value="', serial, '"/>'),
           '  </customAttributes>',
           entry("acc.bin", data_type, sf, lsb, baseline, "g", "ACC",
                 c("accX", "accY", "accZ")))
  if (temp) {
    tv <- if (!is.null(temperature)) rep_len(temperature, n) else
      if (!is.null(x$temperature)) x$temperature else rep_len(25, n)
    nt <- ceiling(n / sf * temp_sf)
    at <- pmin(n, 1 + floor((seq_len(nt) - 1) / temp_sf * sf))
    writeBin(q(tv[at], temp_lsb, 0), file.path(dir, "temp.bin"), size = 2L,
             endian = "little")
    xml <- c(xml, entry("temp.bin", "int16", temp_sf, temp_lsb, 0,
                        "degree Celsius", "TEMP", "temp"))
  }
  writeLines(c(xml, "</unisens>"), file.path(dir, "unisens.xml"))
  invisible(dir)
}
