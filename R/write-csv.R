# Writers of synthetic csv files for the csv decoder's tests and benchmark
# (not exported). ActiLife's layout as the format description in
# inst/include/gravcal/decoders/decode_csv.hpp gives it: 10 header lines, an optional
# column-name line, then [time stamp,] x, y, z.

# ActiLife's 10 header lines for a recording of n samples at sf Hz from
# `start` (UTC), date format M/d/yyyy.
actigraph_csv_header <- function(sf, start, n, serial = "MOS2E00000000",
                                 date_format = "M/d/yyyy") {
  t0 <- as.POSIXct(start, tz = "UTC")
  t1 <- t0 + n / sf
  mdy <- function(t) {
    paste0(as.integer(format(t, "%m")), "/", as.integer(format(t, "%d")), "/",
           format(t, "%Y"))
  }
  c(paste0("------------ Data File Created By ActiGraph GT3X+ ActiLife v6.13.4 ",
           "Firmware v3.2.1 date format ", date_format, " at ", format(sf),
           " Hz  Filter Normal -----------"),
    paste("Serial Number:", serial),
    paste("Start Time", format(t0, "%H:%M:%S")),
    paste("Start Date", mdy(t0)),
    "Epoch Period (hh:mm:ss) 00:00:00",
    paste("Download Time", format(t1, "%H:%M:%S")),
    paste("Download Date", mdy(t1)),
    "Current Memory Address: 0",
    "Current Battery Voltage: 4.20     Mode = 12",
    "--------------------------------------------------")
}

# ActiLife's time stamps "M/d/yyyy HH:MM:SS.fff" of samples i0 + 0:(n-1).
actilife_stamps <- function(t0, sf, i0, n) {
  i <- i0 + seq_len(n) - 1
  ms <- round((i %% sf) * 1000 / sf)
  whole <- t0 + i %/% sf
  day <- as.integer(as.numeric(whole) %/% 86400)
  days <- unique(day)
  dstr <- format(as.POSIXct(days * 86400, origin = "1970-01-01", tz = "UTC"), "%m/%d/%Y")
  dstr <- sub("^0", "", sub("/0", "/", dstr))
  sod <- as.integer(as.numeric(whole) %% 86400)
  paste0(dstr[match(day, days)], " ", sprintf("%02d:%02d:%02d.%03d", sod %/% 3600L,
         (sod %/% 60L) %% 60L, sod %% 60L, as.integer(ms)))
}

# Writes samples x (a data frame or matrix with x, y, z) as an ActiGraph csv
# export. `digits`: decimals of the values (ActiLife writes 3); `stamps`:
# "none", "actilife" (M/d/yyyy HH:MM:SS.fff) or "iso" (fwrite's
# 2023-05-11T09:00:00.010Z, fast); `colnames`: the column-name line; `eol`:
# line end; `rows`: samples written per fwrite call.
write_actigraph_csv_file <- function(x, file, sf, start = "2023-05-11 09:00:00",
                                     stamps = "none", colnames = TRUE, digits = 3,
                                     eol = "\n", rows = 1e6) {
  s <- as_samples(x)
  t0 <- as.POSIXct(start, tz = "UTC")
  hdr <- actigraph_csv_header(sf, start, s$n)
  if (colnames) {
    hdr <- c(hdr, paste0(if (stamps != "none") "Timestamp,",
                         "Accelerometer X,Accelerometer Y,Accelerometer Z"))
  }
  con <- file(file, "wb")
  writeBin(charToRaw(paste0(paste(hdr, collapse = eol), eol)), con)
  close(con)
  for (from in seq(0, max(s$n - 1, 0), by = rows)) {
    k <- min(rows, s$n - from)
    if (k <= 0) break
    j <- from + seq_len(k)
    d <- list(round(s$x[j], digits), round(s$y[j], digits), round(s$z[j], digits))
    if (stamps == "actilife") d <- c(list(actilife_stamps(t0, sf, from, k)), d)
    if (stamps == "iso") d <- c(list(t0 + (from + seq_len(k) - 1) / sf), d)
    data.table::fwrite(d, file, append = TRUE, col.names = FALSE, eol = eol,
                       dateTimeAs = "ISO")
  }
  invisible(file)
}

# A synthetic recording of `hours` (whole hours) at sf Hz written as an
# ActiGraph csv, fast enough for a week at 100 Hz: one hour of motion (the
# device turning through orientations, with noise) is formatted once as
# text and written again for every hour, with the hour (and, each new day,
# the date) of its time stamps rewritten in place. `stamps`: "actilife"
# (M/d/yyyy HH:MM:SS.fff), "iso" (2023-05-11T09:00:00.010Z) or "none".
write_actigraph_csv_synthetic <- function(file, hours, sf = 100, stamps = "actilife",
                                          start = "2023-05-11 09:00:00") {
  per_hour <- round(3600 * sf)
  t0 <- as.POSIXct(start, tz = "UTC")
  h0 <- as.numeric(t0) %/% 3600
  writeLines(c(actigraph_csv_header(sf, start, hours * per_hour),
               paste0(if (stamps != "none") "Timestamp,",
                      "Accelerometer X,Accelerometer Y,Accelerometer Z")), file)
  i <- seq_len(per_hour) - 1
  a <- 2 * pi * i / per_hour
  noise <- ((i * 7919) %% 101 - 50) / 5000
  values <- paste(round(sin(a) * 0.9 + noise, 3), round(cos(a) * 0.6 - noise, 3),
                  round(sin(2 * a) * 0.4 + noise / 2, 3), sep = ",")
  sec <- i %/% sf
  clock <- sprintf("%02d:%02d.%03d", sec %/% 60, sec %% 60, round((i %% sf) * 1000 / sf))
  con <- file(file, "ab")
  on.exit(close(con))
  block <- NULL
  day <- -1
  for (h in h0 + seq_len(hours) - 1) {
    if (stamps == "none") {
      if (is.null(block)) block <- charToRaw(paste0(values, "\n", collapse = ""))
      writeBin(block, con)
      next
    }
    if (h %/% 24 != day) {
      day <- h %/% 24
      d <- as.POSIXct(day * 86400, origin = "1970-01-01", tz = "UTC")
      date <- if (stamps == "iso") format(d, "%Y-%m-%dT") else
        paste0(as.integer(format(d, "%m")), "/", as.integer(format(d, "%d")), "/",
               format(d, "%Y"), " ")
      lines <- paste0(date, "00:", clock, if (stamps == "iso") "Z", ",", values, "\n")
      block <- charToRaw(paste(lines, collapse = ""))
      # the hour's two digits, at a fixed place in every line
      at <- c(0, cumsum(nchar(lines, "bytes"))[-length(lines)]) + nchar(date, "bytes")
    }
    hh <- charToRaw(sprintf("%02d", h %% 24))
    block[at + 1] <- hh[1]
    block[at + 2] <- hh[2]
    writeBin(block, con)
  }
  invisible(file)
}

# Writes a data frame as a plain csv with a header line of its column names
# (POSIXct as ISO text), for the "csv" format.
write_plain_csv <- function(d, file, sep = ",", dec = ".") {
  data.table::fwrite(d, file, sep = sep, dec = dec, dateTimeAs = "ISO")
  invisible(file)
}

# Writes samples x, y, z (in g) as Axivity's csv export (OMGUI,
# cwa-convert): lines "time,x,y,z", the time of sample i at `start` + i /
# `true_sf` (a device's clock runs a little off its nominal rate), `digits`
# decimals of g. `stamps`: "unix" (seconds since 1970 with 3 decimals) or
# text: `time_format` (a format() of the whole second, UTC), then
# `decimals` digits of its fraction after a point (0: none), then `suffix`
# ("Z", "+01:00"); `header`: OMGUI's header line first.
write_axivity_csv <- function(x, file, true_sf, start = "2024-01-01 00:00:00",
                              digits = 4, stamps = c("unix", "text"),
                              time_format = "%Y-%m-%d %H:%M:%S", decimals = 3,
                              suffix = "", header = FALSE) {
  stamps <- match.arg(stamps)
  s <- as_samples(x)
  t <- as.numeric(as.POSIXct(start, tz = "UTC")) + (seq_len(s$n) - 1) / true_sf
  tcol <- if (stamps == "unix") sprintf("%.3f", t) else {
    # the fraction from the time rounded to the last decimal written
    k <- round(t * 10^decimals)
    whole <- k %/% 10^decimals
    paste0(format(.POSIXct(whole, tz = "UTC"), time_format),
           if (decimals > 0) sprintf(".%0*.0f", decimals, k %% 10^decimals), suffix)
  }
  if (header) writeLines("Time,Accel-X (g), Accel-Y (g), Accel-Z (g)", file)
  data.table::fwrite(list(tcol, round(s$x, digits), round(s$y, digits), round(s$z, digits)),
                     file, col.names = FALSE, quote = FALSE, append = header)
  invisible(file)
}

# Writes samples (x, y, z in g, optional temperature in C) as an "ad hoc"
# csv file, the kind GGIR reads with its rmc.* parameters, and returns those
# parameters (a list for params_rawdata). Layout, from top: the `header`
# lines ("name,value"), a column-name line (`colnames`), then one line per
# sample: [time,] x, y, z[, temperature]. `unit`: "g" (`digits` decimals),
# "mg" (`digits` - 3 decimals) or "bit" (unsigned counts of `bitrate` bits
# over +-`dynamic_range` g); `time`: "none", "UNIXsec", "UNIXmsec",
# "ActivPAL" (days since 1899-12-30, the clock's time of `start` on) or
# "POSIX" ("%Y-%m-%d %H:%M:%OS" text, millisecond decimals) or "character"
# ("%d/%m/%Y %H:%M:%OS" text, millisecond decimals); `drop`: the indices of
# samples left out (a time gap where their time stamps would be); `temp_unit`:
# "C", "K" (written as GGIR reads it back: t - 272.15) or "F"; `sep` and
# `dec`: separator and decimal mark. The sampling rate goes to rmc.sf, or
# with `sf_header = TRUE` to a header line "sample_rate_hz,<sf>" read by
# rmc.headername.sf. `wear`: a wear flag's text per sample ("TRUE",
# "FALSE", NA for none, ...), written as the last column (rmc.col.wear).
write_adhoc_csv <- function(x, file, sf, header = character(), colnames = TRUE,
                            unit = "g", time = "none", temperature = TRUE,
                            temp_unit = "C", bitrate = 12, dynamic_range = 8,
                            digits = 4, sep = ",", dec = ".", sf_header = FALSE,
                            start = "2024-01-01 00:00:00", drop = integer(), wear = NULL) {
  s <- as_samples(x)
  if (!is.null(wear) && (!is.character(wear) || length(wear) != s$n)) {
    abort("`wear` must be a character vector with a value per sample (\"TRUE\", \"FALSE\", NA ...), not ",
          describe(wear), ".")
  }
  if (sf_header) header <- c(header, paste0("sample_rate_hz", sep, format(sf)))
  acc <- switch(unit,
    g = function(a) round(a, digits),
    mg = function(a) round(a * 1000, max(digits - 3, 0)),
    bit = function(a) round((a / (2 * dynamic_range) + 0.5) * 2^bitrate))
  d <- list(x = acc(s$x), y = acc(s$y), z = acc(s$z))
  if (temperature) {
    if (is.null(s$temperature)) abort("`x` has no temperature column.")
    tc <- round(s$temperature, 2)
    d$temperature <- switch(temp_unit, C = tc, K = tc - 272.15, F = tc * 9 / 5 + 32)
  }
  t <- as.numeric(as.POSIXct(start, tz = "UTC")) + (seq_len(s$n) - 1) / sf
  tcol <- switch(time, none = NULL,
    UNIXsec = round(t, 3),
    UNIXmsec = round(t * 1000),
    ActivPAL = (t - as.numeric(as.POSIXct("1899-12-30", tz = "UTC"))) / 86400,
    POSIX = format(as.POSIXct(t, origin = "1970-01-01", tz = "UTC") + 5e-5,
                   "%Y-%m-%d %H:%M:%OS3"),
    character = format(as.POSIXct(t, origin = "1970-01-01", tz = "UTC") + 5e-5,
                       "%d/%m/%Y %H:%M:%OS3"))
  if (!is.null(tcol)) d <- c(list(time = tcol), d)
  if (!is.null(wear)) d$wear <- wear
  if (length(drop)) d <- lapply(d, function(v) v[-drop])
  writeLines(c(header, if (colnames) paste(names(d), collapse = sep)), file)
  data.table::fwrite(d, file, append = TRUE, col.names = FALSE, sep = sep, dec = dec)
  first <- length(header) + as.integer(colnames) + 1
  k <- if (is.null(tcol)) 0 else 1
  p <- list(rmc.firstrow.acc = first, rmc.col.acc = k + 1:3, rmc.unit.acc = unit,
            rmc.dec = dec)
  if (temperature) {
    p$rmc.col.temp <- k + 4
    p$rmc.unit.temp <- temp_unit
  }
  if (!is.null(wear)) p$rmc.col.wear <- length(d)
  if (!is.null(tcol)) {
    p$rmc.col.time <- 1
    p$rmc.unit.time <- time
    if (time == "character") p$rmc.format.time <- "%d/%m/%Y %H:%M:%OS"
  }
  if (unit == "bit") {
    p$rmc.bitrate <- bitrate
    p$rmc.dynamic_range <- dynamic_range
  }
  if (sf_header) {
    p$rmc.firstrow.header <- 1
    p$rmc.header.length <- length(header)
    p$rmc.headername.sf <- "sample_rate_hz"
  } else {
    p$rmc.sf <- sf
  }
  p
}

# GENEActiv's csv export as its PC software writes it (R/geneactiv-csv.R):
# 100 header lines of "name,value" (device, rate as "Measurement Frequency,
# <sf> Hz", start time; the rest filled with the calibration and subject
# rows), then time stamp ("YYYY-MM-DD hh:mm:ss:mmm"), x, y, z in g with 4
# decimals, light, button, temperature with 1 decimal. `rec`: x, y, z and
# optionally temperature; `start` in seconds since 1970 (UTC).
write_geneactiv_csv <- function(rec, file, sf, start = 1.6e9, chunk = 500000L) {
  n <- nrow(rec)
  t0 <- as.POSIXct(start, origin = "1970-01-01", tz = "UTC")
  stamp <- function(t) paste0(format(t, "%Y-%m-%d %H:%M:%S"), ":000")
  hdr <- c("Device Type,GENEActiv", "Device Model,1.1", "Device Unique Serial Code,012345",
           "Device Firmware Version,Ver06.17.15", "Calibration Date,2019-02-20 08:53:49:000",
           "Application name & version,GENEActiv PC Software 3.2",
           paste0("Measurement Frequency,", format(sf), " Hz"),
           paste0("Measurement Period,", ceiling(n / sf / 3600), " Hours"),
           paste0("Start Time,", stamp(t0)), "Study Centre,", "Study Code,",
           "Investigator ID,", "Exercise Type,", "Device Location Code,left wrist",
           "Subject Code,", "Date of Birth,", "Sex,", "Height,", "Weight,", "Handedness Code,",
           "x gain,25548", "x offset,-5", "y gain,25428", "y offset,-12",
           "z gain,25636", "z offset,8", "Volts,300", "Lux,800")
  hdr <- c(hdr, paste0("Extension line ", seq_len(100 - length(hdr)), ","))
  con <- file(file, "w")
  on.exit(close(con))
  writeLines(hdr, con)
  temp <- if (is.null(rec$temperature)) rep(25, n) else rec$temperature
  for (a in seq(1L, n, by = chunk)) {
    i <- a:min(n, a + chunk - 1L)
    k <- i - 1L
    sec <- t0 + k %/% sf
    ms <- round((k %% sf) * 1000 / sf)
    ts <- paste0(format(sec, "%Y-%m-%d %H:%M:%S"), ":", sprintf("%03d", as.integer(ms)))
    writeLines(paste(ts, sprintf("%.4f", rec$x[i]), sprintf("%.4f", rec$y[i]),
                     sprintf("%.4f", rec$z[i]), "0", "0", sprintf("%.1f", temp[i]), sep = ","),
               con)
  }
  invisible(file)
}
