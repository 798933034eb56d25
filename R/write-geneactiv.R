# Write raw samples as a GENEActiv .bin file (the device's text format: a
# header, then pages of 300 samples, each page with its own header lines and
# one line of 12 hex digits per sample: x, y, z as 12-bit two's complement
# counts, then 10 bits of light and 2 status bits). Counts are
# round((g * gain + offset) / 100), GENEActiv's calibration in reverse, and
# clip at the 12-bit range (about +-8 g). A last part-page is left out.
# Temperature, where given, is written per page (its mean, 0.1 degree).
# Used by the tests and benchmarks to give gravcal and GGIR a device file.
# `eol` "\r\n" writes the line ends of real files; `page_sf` (one rate per
# page) writes pages at other rates, timed one after the other; `time_zone`
# is the header's "Time Zone:" text. `append = TRUE` adds pages to the end
# of a file written by this function (no header), numbered from `page0`;
# `pages_total` is the header's page count for a file written in pieces.
# `light`: the 10-bit light value of each sample (0 to 1023; NULL: 0),
# written with status bits `status` (0 to 3); `model`: the header's "Device
# Model:" value; `volts_line`, `lux_line`: its "Volts:" and "Lux:" lines
# (whole lines: a test may misspell them, the header keeps its 59 lines).
# Test-only; not exported.
write_geneactiv_bin <- function(x, file, sf, start = "2024-01-01 00:00:00",
                                gain = c(25600, 25600, 25600),
                                offset = c(0, 0, 0), pages_per_write = 2000,
                                eol = "\n", page_sf = NULL,
                                time_zone = "GMT +00:00", serial = "000000",
                                append = FALSE, page0 = 0, pages_total = NULL,
                                light = NULL, status = 0, model = "1.1",
                                volts_line = "Volts:300", lux_line = "Lux:800") {
  s <- as_samples(x)
  pages <- s$n %/% 300
  if (pages < 1) abort("`x` has fewer than 300 samples, one GENEActiv page.")
  if (is.null(page_sf)) page_sf <- rep(sf, pages)
  if (length(page_sf) != pages) abort("`page_sf` must have one rate per page (", pages, ").")
  t0 <- as.numeric(as.POSIXct(start, tz = "UTC"))
  page_t <- t0 + cumsum(c(0, 300 / page_sf[-pages]))
  hdr <- ga_header(t0, sf, if (is.null(pages_total)) pages else pages_total,
                   gain, offset, time_zone, serial, model, volts_line, lux_line)
  lt <- if (is.null(light)) integer(s$n) else as.integer(rep_len(light, s$n))
  if (anyNA(lt) || any(lt < 0 | lt > 1023)) abort("`light` must be in 0..1023.")
  lt <- lt * 4L + as.integer(rep_len(status, s$n))
  con <- file(file, if (append) "ab" else "wb")
  on.exit(close(con))
  if (!append) writeLines(hdr, con, sep = eol)
  lut <- ga_hex_lut()
  for (p0 in seq(0, pages - 1, by = pages_per_write)) {
    p1 <- min(p0 + pages_per_write, pages)
    from <- p0 * 300 + 1
    to <- p1 * 300
    lines <- ga_hex_lines(lut, ga_counts(s$x[from:to], gain[1], offset[1]),
                          ga_counts(s$y[from:to], gain[2], offset[2]),
                          ga_counts(s$z[from:to], gain[3], offset[3]), lt[from:to])
    np <- p1 - p0
    temp <- if (is.null(s$temperature)) rep(20, np) else
      colMeans(matrix(s$temperature[from:to], 300))
    idx <- p0 + seq_len(np)
    page <- rbind("Recorded Data", paste0("Device Unique Serial Code:", serial),
                  paste0("Sequence Number:", page0 + idx - 1),
                  paste0("Page Time:", ga_stamp(page_t[idx])), "Unassigned:",
                  paste0("Temperature:", sprintf("%.1f", temp)),
                  "Battery voltage:4.1", "Device Status:Recording",
                  paste0("Measurement Frequency:", format(page_sf[idx])), lines)
    writeLines(c(page), con, sep = eol)
  }
  invisible(file)
}

# "YYYY-MM-DD HH:MM:SS:mmm" of seconds since 1970 (UTC fields).
ga_stamp <- function(t) {
  ms <- round(t * 1000)
  sec <- (ms - ms %% 1000) / 1000
  paste0(format(as.POSIXct(sec, origin = "1970-01-01", tz = "UTC"), "%Y-%m-%d %H:%M:%S"),
         ":", sprintf("%03d", as.integer(ms %% 1000)))
}

ga_header <- function(t0, sf, pages, gain, offset, time_zone, serial,
                      model = "1.1", volts_line = "Volts:300", lux_line = "Lux:800") {
  st <- ga_stamp(t0)
  c("Device Identity", paste0("Device Unique Serial Code:", serial),
    "Device Type:GENEActiv", paste0("Device Model:", model),
    "Device Firmware Version:Ver1.30 date 05Aug11",
    paste0("Calibration Date:", st), "",
    "Device Capabilities", "Accelerometer Range:-8 to 8",
    "Accelerometer Resolution:0.0039", "Accelerometer Units:g",
    "Light Meter Range:0 to 5000", "Light Meter Resolution:5",
    "Light Meter Units:lux", "Temperature Sensor Range:0 to 70",
    "Temperature Sensor Resolution:0.1", "Temperature Sensor Units:deg. C", "",
    "Configuration Info", paste0("Measurement Frequency:", format(sf), " Hz"),
    paste0("Measurement Period:", ceiling(pages * 300 / sf / 3600), " Hours"),
    paste0("Start Time:", st), paste0("Time Zone:", time_zone), "",
    "Trial Info", "Study Centre:", "Study Code:", "Investigator ID:",
    "Exercise Type:", "Config Operator ID:", paste0("Config Time:", st),
    "Config Notes:", "Extract Operator ID:", paste0("Extract Time:", st),
    "Extract Notes:", "", "Subject Info", "Device Location Code:",
    "Subject Code:", "Date of Birth:", "Sex:", "Height:", "Weight:",
    "Handedness Code:", "Subject Notes:", "", "Calibration Data",
    paste0(c("x gain:", "x offset:", "y gain:", "y offset:", "z gain:",
             "z offset:"), c(rbind(round(gain), round(offset)))),
    volts_line, lux_line, "", "Memory Status",
    paste0("Number of Pages:", pages), "")
}

# 12-bit two's complement counts (0..4095) of values in g.
ga_counts <- function(v, gain, offset) {
  r <- round((v * gain + offset) / 100)
  r <- pmin(pmax(r, -2048), 2047)
  as.integer(r %% 4096)
}

# The three upper-case hex digits (as raw) of every count 0..4095, by column.
ga_hex_lut <- function() {
  d <- charToRaw("0123456789ABCDEF")
  v <- 0:4095
  rbind(d[v %/% 256 + 1], d[(v %/% 16) %% 16 + 1], d[v %% 16 + 1])
}

# One 3600-digit line per page: x, y, z digits of each sample, then those of
# its light and status bits `ls` (light * 4 + status; 0: "000").
ga_hex_lines <- function(lut, cx, cy, cz, ls = integer(length(cx))) {
  n <- length(cx)
  m <- matrix(as.raw(48L), 12L, n)
  m[1:12, ] <- lut[, rbind(cx, cy, cz, ls) + 1L]
  dim(m) <- c(3600L, n %/% 300L)
  vapply(seq_len(ncol(m)), function(j) rawToChar(m[, j]), "")
}
