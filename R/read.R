#' Read a raw accelerometer recording from a file
#'
#' Reads the whole file into memory and returns its samples in g with the
#' sampling frequency. Formats, by file extension:
#' * `.rds`: a data frame as written by `saveRDS()` (for example the bundled
#'   example, see [gravcal_example()]); `sf` from its `sf` attribute or its
#'   `time` column;
#' * `.csv`, `.csv.gz`: an ActiGraph csv export (ActiLife's 10-line header,
#'   with or without time stamps; `sf` from the header), or a header line with
#'   columns `x`, `y`, `z` and optionally `time` and `temperature`; `sf` from
#'   `time` or the argument;
#' * `.gt3x`: ActiGraph, through the read.gt3x package (a Suggests package);
#'   idle-sleep gaps come back as zeros, which [rest_windows()] skips;
#' * `.cwa` (Axivity) and `.bin` (GENEActiv), through the GGIRread package
#'   (a Suggests package), with their temperature.
#'
#' To calibrate a long recording, give its path to [calibrate()] or
#' [rest_windows()] instead: they read it block by block, in bounded memory.
#'
#' @param file Path of the file.
#' @param sf Sampling frequency in Hz, when the file does not give it.
#' @return A list with `data` (a data frame with `x`, `y`, `z` and, where the
#'   file has them, `time` and `temperature`) and `sf`.
#' @export
#' @examples
#' rec <- read_recording(gravcal_example())
#' rec$sf
#' head(rec$data)
read_recording <- function(file, sf = NULL) {
  if (!is.character(file) || length(file) != 1 || is.na(file)) {
    abort("`file` must be a single file path, not ", describe(file), ".")
  }
  if (!file.exists(file)) abort("`file` does not exist: \"", file, "\".")
  ext <- tolower(sub(".*?\\.((csv\\.gz)|[^.]+)$", "\\1", basename(file)))
  data <- switch(ext,
    rds = readRDS(file),
    csv = , "csv.gz" = if (is_actigraph_csv(file)) read_blocks(file, sf) else
      utils::read.csv(file, stringsAsFactors = FALSE),
    gt3x = read_gt3x_file(file),
    cwa = , bin = read_blocks(file),
    abort("`file` has an unsupported extension \".", ext, "\"; gravcal ",
          "reads .rds, .csv, .csv.gz, .gt3x, .cwa and .bin."))
  if (!is.data.frame(data)) {
    abort("`file` does not hold a data frame of samples: \"", file, "\".")
  }
  names(data) <- tolower(names(data))
  if (is.null(sf)) sf <- attr(data, "sf")
  if (is.null(sf) && !is.null(attr(data, "sample_rate"))) {
    sf <- attr(data, "sample_rate")
  }
  if (is.null(sf) && "time" %in% names(data)) sf <- sf_from_time(data$time)
  if (is.null(sf)) {
    abort("The sampling frequency of \"", file, "\" is unknown: give `sf`.")
  }
  check_sf(sf)
  list(data = data, sf = sf)
}

is_actigraph_csv <- function(file) {
  grepl("ActiGraph", readLines(file, n = 1, warn = FALSE)[1], ignore.case = TRUE)
}

# A whole .cwa, .bin or ActiGraph csv file, from its blocks.
read_blocks <- function(file, sf = NULL) {
  src <- open_source(file, sf = sf, arg = "file")
  parts <- list()
  i <- 1
  repeat {
    b <- src$read(i)
    if (is.null(b)) break
    parts[[i]] <- b$data
    if (isTRUE(b$last)) break
    i <- i + 1
  }
  if (!length(parts)) abort("`file` holds no samples: \"", file, "\".")
  out <- do.call(rbind, parts)
  rownames(out) <- NULL
  attr(out, "sf") <- src$sf
  out
}

read_gt3x_file <- function(file) {
  if (!requireNamespace("read.gt3x", quietly = TRUE)) {
    abort("Reading .gt3x files needs the read.gt3x package: ",
          "install.packages(\"read.gt3x\").")
  }
  d <- read.gt3x::read.gt3x(file, asDataFrame = TRUE, imputeZeroes = TRUE,
                            verbose = FALSE)
  sf <- attr(d, "sample_rate")
  out <- data.frame(time = d$time, x = d$X, y = d$Y, z = d$Z)
  if ("temperature" %in% tolower(names(d))) {
    out$temperature <- d[[which(tolower(names(d)) == "temperature")[1]]]
  }
  attr(out, "sf") <- sf
  out
}

# Sampling frequency from time stamps, in Hz: one over the median step; for
# time stamps in whole seconds (as a csv of POSIXct times holds them), the
# samples counted between the first and the last change of second. NULL when
# the time stamps do not tell.
sf_from_time <- function(time) {
  t <- time_seconds(time[seq_len(min(length(time), 100000))])
  if (is.null(t) || length(t) < 2) return(NULL)
  d <- diff(t)
  step <- stats::median(d)
  if (is.finite(step) && step > 0) return(signif(1 / step, 6))
  ch <- which(d > 0)
  if (length(ch) < 2) return(NULL)
  first <- ch[1]
  last <- ch[length(ch)]
  sf <- (last - first) / (t[last + 1] - t[first + 1])
  if (!is.finite(sf) || sf <= 0) return(NULL)
  signif(sf, 6)
}

# Time stamps as seconds: numbers and date-times as they are, text parsed as
# a date-time in one of the usual layouts; NULL when that fails.
time_seconds <- function(time) {
  if (is.numeric(time) || inherits(time, "POSIXt")) {
    t <- as.numeric(time)
  } else if (is.character(time) || is.factor(time)) {
    t <- tryCatch(as.numeric(as.POSIXct(as.character(time), tz = "UTC",
      tryFormats = c("%Y-%m-%d %H:%M:%OS", "%Y/%m/%d %H:%M:%OS",
                     "%Y-%m-%dT%H:%M:%OS", "%m/%d/%Y %H:%M:%OS"))),
      error = function(e) NULL)
  } else {
    return(NULL)
  }
  if (is.null(t) || anyNA(t)) return(NULL)
  t
}

#' Path of the bundled example recording
#'
#' A 12-hour recording at 10 Hz with temperature, made by
#' [simulate_recording()] with known calibration errors (script
#' `data-raw/example.R`); its truth is in `attr(readRDS(path), "truth")`.
#' @return The path of the `.rds` file.
#' @export
#' @examples
#' rec <- readRDS(gravcal_example())
#' attr(rec, "truth")$params
gravcal_example <- function() {
  system.file("extdata", "example.rds", package = "gravcal", mustWork = TRUE)
}

# ---------------------------------------------------------------------------
# Block readers. A source is a list with `format`, `sf`, `filename`,
# `temperature` (does it carry a temperature column) and `read(i)`, which
# returns block i (1, 2, ... in order), or NULL when there is nothing more,
# in one of two forms: list(data = data frame with x, y, z and maybe
# temperature, last = logical) for blocks read from a file, or list(cols =
# list of double vectors x, y, z and maybe temperature, from, to, last) for
# rows [from, to) (0-based) of data held in memory.
# Block sizes are GGIR's (g.calibrate / g.readaccfile), so that gravcal cuts a
# file where GGIR does: `chunksize` scales them (1 = about 12 hours).

# Samples per block for formats GGIR reads by rows (csv, and data frames).
ggir_rows_per_block <- function(sf, chunksize) {
  round((14512 * (sf / 50)) * (chunksize * 0.5)) * 300
}

open_source <- function(datafile, sf = NULL, chunksize = 1, arg = "datafile") {
  if (is.data.frame(datafile) || is.matrix(datafile)) {
    return(source_frame(datafile, sf, chunksize, arg))
  }
  if (!is.character(datafile) || length(datafile) != 1 || is.na(datafile)) {
    abort("`", arg, "` must be a file path or a data frame of raw samples, ",
          "not ", describe(datafile), ".")
  }
  if (!file.exists(datafile) || dir.exists(datafile)) {
    abort("`", arg, "` does not exist: \"", datafile, "\".")
  }
  ext <- tolower(sub(".*?\\.((csv\\.gz)|[^.]+)$", "\\1", basename(datafile)))
  src <- switch(ext,
    csv = , "csv.gz" = source_csv(datafile, sf, chunksize),
    rds = {
      rec <- read_recording(datafile, sf)
      source_frame(rec$data, rec$sf, chunksize, arg)
    },
    gt3x = source_gt3x(datafile, chunksize),
    cwa = source_cwa(datafile, chunksize),
    bin = source_geneactiv(datafile, chunksize),
    abort("`", arg, "` has an unsupported extension \".", ext, "\"; gravcal ",
          "reads .csv (ActiGraph or x,y,z columns), .csv.gz, .rds, .gt3x, ",
          ".cwa and GENEActiv .bin."))
  src$filename <- basename(datafile)
  # blocks read from the file (not views of data already in memory): the
  # block loops collect each one's garbage before reading the next, so that
  # memory stays at about one block
  src$from_file <- !identical(src$format, "data.frame") &&
    !identical(src$format, "csv")
  src
}

`%||%` <- function(a, b) if (is.null(a)) b else a

source_frame <- function(x, sf, chunksize, arg) {
  s <- as_samples(x, arg)
  if (is.null(sf)) sf <- attr(x, "sf")
  if (is.null(sf) && !is.null(s$time)) sf <- sf_from_time(s$time)
  if (is.null(sf)) abort("The sampling frequency of `", arg, "` is unknown: give `sf`.")
  check_sf(sf)
  B <- ggir_rows_per_block(sf, chunksize)
  n <- s$n
  list(format = "data.frame", sf = sf, filename = NA_character_,
       temperature = !is.null(s$temperature), n = n,
       read = function(i) {
         from <- (i - 1) * B
         if (from >= n) return(NULL)
         to <- min(i * B, n)
         # the block as a range of the caller's columns: nothing is copied
         list(cols = s, from = from, to = to, last = to >= n)
       })
}

# ActiGraph csv export (10 header lines, optional column-name line, then
# [timestamp,] x, y, z) or a plain csv with a header line naming x, y, z.
source_csv <- function(file, sf, chunksize) {
  head <- readLines(file, n = 12, warn = FALSE)
  if (!length(head)) abort("`datafile` is empty: \"", file, "\".")
  actigraph <- is_actigraph_csv(file)
  if (!actigraph) {
    rec <- read_recording(file, sf)
    src <- source_frame(rec$data, rec$sf, chunksize, "datafile")
    src$format <- "csv"
    return(src)
  }
  hz <- regmatches(head[1], regexpr("[0-9.]+ *Hz", head[1]))
  if (is.null(sf)) {
    if (!length(hz)) abort("No sampling frequency (\"at N Hz\") in the header of \"", file, "\": give `sf`.")
    sf <- as.numeric(sub(" *Hz", "", hz))
  }
  check_sf(sf)
  skip0 <- 10L
  if (length(head) >= 11) {
    first <- strsplit(head[11], ",")[[1]][1]
    if (is.na(suppressWarnings(as.numeric(first)))) skip0 <- 11L
  }
  B <- ggir_rows_per_block(sf, chunksize)
  # with a time stamp column first, x, y, z are columns 2 to 4; the time
  # stamps are not read at all (as strings they would take more memory than
  # the samples)
  data_line <- head[skip0 + 1]
  fields <- if (is.na(data_line)) 3L else length(strsplit(data_line, ",")[[1]])
  cols <- if (fields > 3) 2:4 else 1:3
  read_rows <- function(skip, nrows) {
    d <- tryCatch({
      if (requireNamespace("data.table", quietly = TRUE)) {
        data.table::fread(file, skip = skip, nrows = nrows, header = FALSE,
                          select = cols, showProgress = FALSE,
                          data.table = FALSE)
      } else {
        cc <- rep("NULL", fields)
        cc[cols] <- NA
        utils::read.csv(file, skip = skip, nrows = nrows, header = FALSE,
                        colClasses = cc)
      }
    }, error = function(e) NULL)
    if (is.null(d) || !nrow(d) || ncol(d) < 3) return(NULL)
    names(d) <- c("x", "y", "z")
    for (v in c("x", "y", "z")) {
      if (!is.numeric(d[[v]])) abort("Corrupt file \"", file, "\": column ", v, " is not numeric.")
    }
    d
  }
  list(format = "actigraph_csv", sf = sf, temperature = FALSE,
       read = function(i) {
         d <- read_rows(skip0 + (i - 1) * B, B)
         if (is.null(d)) return(NULL)
         list(data = d, last = nrow(d) < B)
       })
}

source_gt3x <- function(file, chunksize) {
  if (!requireNamespace("read.gt3x", quietly = TRUE)) {
    abort("Reading .gt3x files needs the read.gt3x package: install.packages(\"read.gt3x\").")
  }
  hdr <- tryCatch(read.gt3x::parse_gt3x_info(file),
                  error = function(e) abort("Corrupt .gt3x file \"", file, "\": ", conditionMessage(e)))
  sf <- as.numeric(hdr[["Sample Rate"]])
  # read.gt3x counts batches in seconds of stored data: idle-sleep periods,
  # which the device does not store, are skipped, and batches come without
  # the zeros that a whole read (imputeZeroes = TRUE) puts there. Put them
  # back from the time stamps, so that a streamed file has the same samples
  # at the same positions as the file read whole.
  B <- (12 * 3600) * chunksize
  t0 <- NULL
  next_i <- 0
  list(format = "gt3x", sf = sf, temperature = FALSE,
       read = function(i) {
         from <- B * (i - 1) + 1
         d <- tryCatch(read.gt3x::read.gt3x(file, batch_begin = from,
                                            batch_end = from + B - 1,
                                            asDataFrame = TRUE, verbose = FALSE),
                       error = function(e) NULL)
         if (is.null(d) || !nrow(d)) return(NULL)
         t <- as.numeric(d$time)
         if (is.null(t0)) t0 <<- t[1]
         pos <- round((t - t0) * sf) - next_i
         keep <- pos >= 0 & !duplicated(pos)
         n <- max(pos[keep]) + 1
         out <- data.frame(x = numeric(n), y = numeric(n), z = numeric(n))
         out$x[pos[keep] + 1] <- as.numeric(d$X[keep])
         out$y[pos[keep] + 1] <- as.numeric(d$Y[keep])
         out$z[pos[keep] + 1] <- as.numeric(d$Z[keep])
         next_i <<- next_i + n
         list(data = out, last = FALSE)
       })
}

need_ggirread <- function(what) {
  if (!requireNamespace("GGIRread", quietly = TRUE)) {
    abort("Reading ", what, " files needs the GGIRread package: install.packages(\"GGIRread\").")
  }
}

source_cwa <- function(file, chunksize) {
  need_ggirread("Axivity .cwa")
  first <- tryCatch(GGIRread::readAxivity(file, start = 0, end = 1, progressBar = FALSE),
                    error = function(e) NULL)
  if (is.null(first) || is.null(first$header$frequency)) {
    abort("Corrupt or unreadable .cwa file \"", file, "\".")
  }
  sf <- first$header$frequency
  B <- round(12 * 3600 * sf / 80 * chunksize)
  list(format = "cwa", sf = sf, temperature = TRUE,
       read = function(i) {
         start <- B * (i - 1)
         P <- tryCatch(GGIRread::readAxivity(file, start = start, end = start + B,
                                             progressBar = FALSE, frequency_tol = 0.1),
                       error = function(e) NULL)
         if (is.null(P) || is.null(P$data) || !nrow(P$data)) return(NULL)
         # GGIRread calls the temperature "temp" (GGIR renames it too)
         names(P$data)[names(P$data) == "temp"] <- "temperature"
         d <- P$data[, intersect(c("x", "y", "z", "temperature"), names(P$data))]
         list(data = d, last = FALSE)
       })
}

source_geneactiv <- function(file, chunksize) {
  need_ggirread("GENEActiv .bin")
  first <- tryCatch(GGIRread::readGENEActiv(file, start = 1, end = 2),
                    error = function(e) NULL)
  if (is.null(first) || is.null(first$header$SampleRate)) {
    abort("Corrupt or unreadable GENEActiv .bin file \"", file, "\".")
  }
  sf <- round(first$header$SampleRate)
  B <- round((14512 * (sf / 50)) * (chunksize * 0.5))
  list(format = "geneactiv", sf = sf, temperature = TRUE,
       read = function(i) {
         start <- B * (i - 1) + 1
         P <- tryCatch(GGIRread::readGENEActiv(file, start = start, end = start + B - 1),
                       error = function(e) NULL)
         if (is.null(P) || is.null(P$data.out) || !nrow(P$data.out)) return(NULL)
         d <- P$data.out[, intersect(c("x", "y", "z", "temperature"), names(P$data.out))]
         list(data = d, last = nrow(d) < B * 300)
       })
}

# Write raw samples as an ActiGraph csv export (ActiLife layout: 10 header
# lines, a column-name line, then x, y, z in g). Used by the tests to hand
# the same samples to GGIR and to gravcal. `timestamps = TRUE` adds ActiLife's
# time stamp column (M/d/yyyy HH:MM:SS.fff) before x, y, z.
write_actigraph_csv <- function(x, file, sf, start = "2023-05-11 09:00:00",
                                timestamps = FALSE) {
  s <- as_samples(x)
  t0 <- as.POSIXct(start, tz = "UTC")
  t1 <- t0 + s$n / sf
  hdr <- c(
    paste0("------------ Data File Created By ActiGraph GT3X+ ActiLife v6.13.4 ",
           "Firmware v3.2.1 date format M/d/yyyy at ", format(sf), " Hz  ",
           "Filter Normal -----------"),
    "Serial Number: MOS2E00000000",
    paste("Start Time", format(t0, "%H:%M:%S")),
    paste("Start Date", format(t0, "%m/%d/%Y")),
    "Epoch Period (hh:mm:ss) 00:00:00",
    paste("Download Time", format(t1, "%H:%M:%S")),
    paste("Download Date", format(t1, "%m/%d/%Y")),
    "Current Memory Address: 0",
    "Current Battery Voltage: 4.20     Mode = 12",
    "--------------------------------------------------",
    paste0(if (timestamps) "Timestamp,", "Accelerometer X,Accelerometer Y,Accelerometer Z"))
  writeLines(hdr, file)
  d <- data.frame(x = s$x, y = s$y, z = s$z)
  if (timestamps) {
    t <- t0 + (seq_len(s$n) - 1) / sf
    ms <- round((as.numeric(t) %% 1) * 1000)
    stamp <- paste0(as.integer(format(t, "%m")), "/", as.integer(format(t, "%d")),
                    format(t - ms / 1000, "/%Y %H:%M:%S"), sprintf(".%03d", ms))
    d <- cbind(timestamp = stamp, d)
  }
  if (requireNamespace("data.table", quietly = TRUE)) {
    data.table::fwrite(d, file, append = TRUE, col.names = FALSE)
  } else {
    utils::write.table(d, file, append = TRUE, sep = ",", row.names = FALSE,
                       col.names = FALSE)
  }
  invisible(file)
}

# Write raw samples as a GENEActiv .bin file (the device's text format: a
# header, then pages of 300 samples, each page with its own header lines and
# one line of 12 hex digits per sample: x, y, z as 12-bit two's complement
# counts, then 10 bits of light and 2 status bits). Counts are
# round((g * gain + offset) / 100), GENEActiv's calibration in reverse, and
# clip at the 12-bit range (about +-8 g). A last part-page is left out.
# Temperature, where given, is written per page (its mean, 0.1 degree).
# Used by the tests and benchmarks to give gravcal and GGIR a device file.
write_geneactiv_bin <- function(x, file, sf, start = "2024-01-01 00:00:00",
                                gain = c(25600, 25600, 25600),
                                offset = c(0, 0, 0), pages_per_write = 2000) {
  s <- as_samples(x)
  pages <- s$n %/% 300
  if (pages < 1) abort("`x` has fewer than 300 samples, one GENEActiv page.")
  t0 <- as.POSIXct(start, tz = "UTC")
  stamp <- function(t) {
    ms <- round((as.numeric(t) %% 1) * 1000)
    paste0(format(t - (ms / 1000), "%Y-%m-%d %H:%M:%S"), ":", sprintf("%03d", ms))
  }
  hz <- format(sf)
  hdr <- c("Device Identity", "Device Unique Serial Code:000000",
    "Device Type:GENEActiv", "Device Model:1.1",
    "Device Firmware Version:Ver1.30 date 05Aug11",
    paste0("Calibration Date:", stamp(t0)), "",
    "Device Capabilities", "Accelerometer Range:-8 to 8",
    "Accelerometer Resolution:0.0039", "Accelerometer Units:g",
    "Light Meter Range:0 to 5000", "Light Meter Resolution:5",
    "Light Meter Units:lux", "Temperature Sensor Range:0 to 70",
    "Temperature Sensor Resolution:0.1", "Temperature Sensor Units:deg. C", "",
    "Configuration Info", paste0("Measurement Frequency:", hz, " Hz"),
    paste0("Measurement Period:", ceiling(pages * 300 / sf / 3600), " Hours"),
    paste0("Start Time:", stamp(t0)), "Time Zone:GMT +00:00", "",
    "Trial Info", "Study Centre:", "Study Code:", "Investigator ID:",
    "Exercise Type:", "Config Operator ID:", paste0("Config Time:", stamp(t0)),
    "Config Notes:", "Extract Operator ID:", paste0("Extract Time:", stamp(t0)),
    "Extract Notes:", "", "Subject Info", "Device Location Code:",
    "Subject Code:", "Date of Birth:", "Sex:", "Height:", "Weight:",
    "Handedness Code:", "Subject Notes:", "", "Calibration Data",
    paste0(c("x gain:", "x offset:", "y gain:", "y offset:", "z gain:",
             "z offset:"), c(rbind(round(gain), round(offset)))),
    "Volts:300", "Lux:800", "", "Memory Status",
    paste0("Number of Pages:", pages), "")
  con <- file(file, "wb")
  on.exit(close(con))
  writeLines(hdr, con)
  counts <- function(v, a, from, to) {
    r <- round((v[from:to] * gain[a] + offset[a]) / 100)
    r <- pmin(pmax(r, -2048), 2047)
    as.integer(r %% 4096)
  }
  for (p0 in seq(0, pages - 1, by = pages_per_write)) {
    p1 <- min(p0 + pages_per_write, pages)
    from <- p0 * 300 + 1
    to <- p1 * 300
    hi <- counts(s$x, 1, from, to) * 4096L + counts(s$y, 2, from, to)
    lo <- counts(s$z, 3, from, to) * 4096L
    hex <- paste(sprintf("%06X%06X", hi, lo), collapse = "")
    np <- p1 - p0
    lines <- substring(hex, (seq_len(np) - 1) * 3600 + 1, seq_len(np) * 3600)
    temp <- if (is.null(s$temperature)) rep(20, np) else
      colMeans(matrix(s$temperature[from:to], 300))
    ptime <- stamp(t0 + (p0 + seq_len(np) - 1) * 300 / sf)
    page <- rbind("Recorded Data", "Device Unique Serial Code:000000",
                  paste0("Sequence Number:", p0 + seq_len(np) - 1),
                  paste0("Page Time:", ptime), "Unassigned:",
                  paste0("Temperature:", sprintf("%.1f", temp)),
                  "Battery voltage:4.1", "Device Status:Recording",
                  paste0("Measurement Frequency:", hz), lines)
    writeLines(c(page), con)
  }
  invisible(file)
}
