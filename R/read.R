#' Read a raw accelerometer recording from a file
#'
#' Reads the whole file into memory and returns its samples in g with the
#' sampling frequency. Formats, by file extension:
#' * `.rds`: a data frame as written by `saveRDS()` (for example the bundled
#'   example, see [gravcal_example()]); `sf` from its `sf` attribute or its
#'   `time` column;
#' * `.csv`, `.csv.gz`: an ActiGraph csv export (ActiLife's 10-line header,
#'   with or without time stamps; `sf` from the header), an Axivity csv
#'   export (time stamp, x, y, z, the time in UNIX seconds or text, read as
#'   UTC; OMGUI's optional header line; `sf` as GGIR finds it from the time
#'   stamps, the samples as stored), a GENEActiv csv export (its
#'   header's rate; x, y, z and temperature, the time stamps not read), or a
#'   header line with
#'   columns `x`, `y`, `z` and optionally `time` and `temperature`; `sf` from
#'   `time` or the argument;
#' * `.gt3x` (ActiGraph; current `log.bin` and older `activity.bin`
#'   devices): idle-sleep gaps come back as zeros, which [rest_windows()]
#'   skips;
#' * `.cwa` (Axivity AX3 and AX6) and `.bin` (GENEActiv), with their
#'   temperature.
#'
#' gravcal reads these device formats with its own decoders (C++, one pass
#' through a fixed buffer). They keep every good sample of a damaged file
#' and say what they skipped (corrupt blocks, bad checksums, malformed
#' lines, a truncated end, jumps in time): see `input$report`. The samples
#' are those the device stored, at their own times; GGIR's readers
#' (`reader = "reference"`: GGIRread, read.gt3x, data.table, Suggests
#' packages) resample Axivity files onto a regular grid and round GENEActiv
#' values to single precision. [g.calibrate()] and
#' `calibrate(ggir_compat = TRUE)` read exactly what GGIR reads.
#'
#' To calibrate a long recording, give its path to [calibrate()] or
#' [rest_windows()] instead: they read it block by block, in bounded memory.
#'
#' @param file Path of the file.
#' @param sf Sampling frequency in Hz, when the file does not give it (a
#'   `.cwa`, `.bin` or `.gt3x` file's own rate is always used, and an `sf`
#'   that disagrees with it is an error).
#' @param reader `"native"` (default): gravcal's own decoders for `.cwa`,
#'   `.bin`, `.gt3x` and csv, which give the samples as the device stored
#'   them and count what they had to skip; `"reference"`: the readers GGIR
#'   uses (GGIRread, read.gt3x, data.table).
#' @param rmc For an "ad hoc" csv file (any layout of columns and units):
#'   GGIR's `rmc.*` parameters as a named list, as in GGIR's
#'   `params_rawdata` (`rmc.firstrow.acc`, required, `rmc.col.acc`,
#'   `rmc.unit.acc`, `rmc.col.temp`, `rmc.col.time`, `rmc.sf`, ...; see
#'   [g.calibrate()]). The samples are those GGIR's `read.myacc.csv()` gives
#'   (converted to g and C as it converts them; a text time stamp in the
#'   first column makes GGIR, and so gravcal, skip the first line). `time`
#'   is the file's for UNIX or ActivPAL time stamps, else the first stamp
#'   plus the sample index over `sf`.
#' @return A list with `data` (a data frame with `x`, `y`, `z` and, where the
#'   file has them, `time` and `temperature`; with the native reader, `light`
#'   for `.cwa` and GENEActiv `.bin` files, the device's light value as
#'   GGIRread gives it: an Axivity block's raw 10-bit sensor value,
#'   GENEActiv's lux), `sf` and `input` (for the native reader: the samples
#'   read and what was skipped, and why).
#' @export
#' @examples
#' rec <- read_recording(gravcal_example())
#' rec$sf
#' head(rec$data)
read_recording <- function(file, sf = NULL, reader = c("native", "reference"),
                           rmc = NULL) {
  file <- unisens_acc(file)
  check_file(file, "file")
  reader <- match_choice(reader, "reader")
  if (!is.null(rmc)) return(read_adhoc(file, reader, rmc_values(rmc)))
  read_file(file, sf, reader, "file")
}

# read_recording() of an ad hoc csv file: its decoder (numbers as fread reads
# them, so that the samples are GGIR's) or data.table::fread().
read_adhoc <- function(file, reader, p) {
  if (is.null(p$rmc.firstrow.acc)) {
    abort("`rmc` must give `rmc.firstrow.acc` (the line where the samples start).")
  }
  if (reader == "native") {
    layout <- rmc_layout(p, file, ggir = FALSE)
    d <- read_native(file, rmc_format(), layout$sf, "file",
                     extra = c(layout$opts, compat = 1))
    if (is.null(d)) reader <- "reference"
  }
  if (reader == "reference") {
    src <- open_source(file, arg = "file", reader = "reference", compat = FALSE,
                       rmc = p)
    d <- as.data.frame(gc_pump(src$pump(), "samples", list(time = 0)))
    attr(d, "sf") <- src$sf
    attr(d, "input") <- list(source = basename(file), format = rmc_format(),
                             reader = "reference", samples = nrow(d))
  }
  if (!nrow(d)) abort("`file` holds no samples: \"", file, "\".")
  list(data = d, sf = attr(d, "sf"), input = attr(d, "input"))
}

# `file` must name one existing file (not a folder): an error naming the
# caller's argument `arg` otherwise.
check_file <- function(file, arg) {
  if (!is.character(file) || length(file) != 1 || is.na(file)) {
    abort("`", arg, "` must be a single file path, not ", describe(file), ".")
  }
  if (dir.exists(file)) {
    abort("`", arg, "` must be a file, not a folder: \"", file, "\".")
  }
  if (!file.exists(file)) {
    abort("`", arg, "` does not exist: \"", file, "\".")
  }
  check_regular_file(file, arg)
  invisible(file)
}

# read_recording() for a checked path; errors name the caller's argument.
read_file <- function(file, sf, reader, arg) {
  format <- file_format(file, arg)
  data <- NULL
  if (reader == "native" && format_has_decoder(format)) {
    data <- read_native(file, format, sf, arg)
  }
  if (is.null(data)) {
    data <- format_entry(format)$read(file, sf, reader, arg)
  }
  if (!is.data.frame(data)) {
    abort("`", arg, "` does not hold a data frame of samples: \"", file,
          "\" holds ", describe(data), ".")
  }
  check_column_case(names(data), arg)
  names(data) <- tolower(names(data))
  check_sample_columns(data, file, arg)
  if (nrow(data) == 0) no_samples_error(data, file, format, arg)
  check_sf_agrees(sf, attr(data, "sf") %||% attr(data, "sample_rate"), format, file)
  if (is.null(sf)) sf <- attr(data, "sf")
  if (is.null(sf) && !is.null(attr(data, "sample_rate"))) {
    sf <- attr(data, "sample_rate")
  }
  if (is.null(sf) && "time" %in% names(data)) sf <- sf_from_time(data$time)
  if (is.null(sf)) {
    abort("The sampling frequency of \"", file, "\" is unknown: give `sf`.")
  }
  check_sf(sf)
  list(data = data, sf = sf, input = attr(data, "input"))
}

# An .rds file: what saveRDS() wrote, or an error naming the file.
read_rds <- function(file, arg) {
  if (file.size(file) == 0) {
    abort("Cannot read `", arg, "` \"", file, "\" as an .rds file: the file ",
          "is empty.")
  }
  tryCatch(readRDS(file), error = function(e) {
    abort("Cannot read `", arg, "` \"", file, "\" as an .rds file (from ",
          "saveRDS()): it is truncated or not an .rds file (",
          conditionMessage(e), ").")
  })
}

# A plain csv through utils::read.csv() (the reference reader).
read_plain_csv <- function(file, arg) {
  tryCatch(utils::read.csv(file, stringsAsFactors = FALSE),
           error = function(e) {
             abort("Cannot read `", arg, "` \"", file, "\" as a csv file of ",
                   "samples: ", conditionMessage(e), ".")
           })
}

# Samples read from a file need numeric columns x, y, z; a csv separated by
# semicolons or with comma decimals is said to be one.
check_sample_columns <- function(data, file, arg) {
  missing <- setdiff(c("x", "y", "z"), names(data))
  if (length(missing)) {
    first <- tryCatch(suppressWarnings(readLines(file, n = 1, warn = FALSE)), error = function(e) "")
    hint <- if (any(grepl(";", first, fixed = TRUE))) {
      " It looks separated by semicolons: gravcal's own reader (`reader = \"native\"`) reads those."
    } else ""
    abort("`", arg, "` \"", file, "\" must have columns x, y, z; it has ",
          paste(names(data), collapse = ", "), ".", hint)
  }
  for (v in c("x", "y", "z")) {
    if (!is.numeric(data[[v]]) && nrow(data) > 0) {
      abort("Column `", v, "` of `", arg, "` \"", file, "\" must be numeric ",
            "(acceleration in g), not ", class(data[[v]])[1],
            if (is.character(data[[v]]) && any(grepl(",", data[[v]], fixed = TRUE)))
              " (comma decimals?)", ".")
    }
  }
}

# A file that gave no sample at all: why, in the reader's words where it
# skipped what it read.
no_samples_error <- function(data, file, format, arg) {
  r <- attr(data, "report")
  why <- if (!is.null(r) && (r$skipped > 0 || isTRUE(r$read_error))) {
    paste0("every ", unit_name(format, 1), " read was skipped (",
           format(r$skipped), " skipped",
           if (length(r$notes)) paste0("; first: ", r$notes[1]), ")")
  } else {
    format_entry(format)$empty_why %||% "it holds no samples"
  }
  hint <- format_entry(format)$long_lines_hint
  if (!is.null(r) && !is.null(hint) && isTRUE(unname(r$counters["long_lines"]) > 0)) {
    why <- paste0(why, ". ", hint)
  }
  abort("`", arg, "` \"", file, "\" holds no samples: ", why, ".")
}

# A whole file through its native decoder (raw samples, not resampled), time
# as POSIXct; NULL when this build has no decoder for the format.
read_native <- function(file, format, sf, arg = "file", extra = NULL) {
  opts <- list(compat = 0)
  if (!is.null(sf)) opts$sf <- as.numeric(sf)
  opts[names(extra)] <- extra
  # the format's own options for a whole read (R/formats.R: a .gt3x's
  # idle sleep as zeros, an Axivity csv export's layout)
  set <- format_decoder_options(format, file, opts, sf, list(whole = TRUE))
  opts <- set$opts
  sf <- set$sf
  h <- decoder_open(file, format, opts)
  if (is.null(h$ptr)) {
    if (isTRUE(h$unsupported)) return(NULL)
    native_open_error(file, format, h$error, arg)
  }
  on.exit(gc_decoder_close(h$ptr))
  d <- native_samples(h, time = TRUE)
  if (!is.null(d$time)) d$time <- as.POSIXct(d$time, origin = "1970-01-01", tz = "UTC")
  if (isTRUE(is.finite(attr(d, "sf")) && attr(d, "sf") > 0)) sf <- attr(d, "sf")
  attr(d, "sf") <- sf
  attr(d, "input") <- list(source = basename(file), format = format,
                           reader = "native",
                           serial = attr(d, "info")$serial,
                           samples = nrow(d), report = attr(d, "report"))
  d
}

is_actigraph_csv <- function(file) {
  # the first line's bytes, not text: a binary file named .csv must not make
  # a text connection warn about its encoding
  con <- if (grepl("\\.gz$", file, ignore.case = TRUE)) gzfile(file, "rb") else file(file, "rb")
  on.exit(close(con))
  b <- readBin(con, "raw", 512)
  nl <- match(as.raw(10), b)
  if (!is.na(nl)) b <- b[seq_len(nl - 1)]
  b <- b[b >= as.raw(32) & b < as.raw(127)]
  grepl("ActiGraph", rawToChar(b), ignore.case = TRUE)
}

# A whole .cwa, .bin or ActiGraph csv file through GGIR's readers, block by
# block through the pump.
read_blocks <- function(file, sf = NULL, reader = "reference") {
  src <- open_source(file, sf = sf, arg = "file", reader = reader)
  out <- as.data.frame(gc_pump(src$pump(), "samples", list(time = 0)))
  if (!nrow(out)) abort("`file` holds no samples: \"", file, "\".")
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

# One line for print(): what was read and what was skipped.
format_input <- function(input) {
  if (is.null(input) || identical(input$source, "memory")) return(NULL)
  s <- sprintf("%s samples from %s (%s reader)",
               format(input$samples, big.mark = ","), input$source,
               input$reader)
  r <- input$report
  if (!is.null(r)) {
    lost <- c(if (r$skipped > 0) sprintf("%s unreadable %s skipped",
                                          format(r$skipped, big.mark = ","),
                                          unit_name(input$format, r$skipped)),
              if (r$gaps > 0) sprintf("%d gap%s in time (%.1f s)", r$gaps,
                                      if (r$gaps > 1) "s" else "", r$gap_seconds),
              if (isTRUE(r$truncated)) "file truncated",
              if (isTRUE(r$read_error)) "READ ERROR before the end of the file")
    s <- paste0(s, if (length(lost)) paste0("; ", paste(lost, collapse = ", ")) else
      "; nothing skipped")
  }
  s
}

unit_name <- function(format, n) {
  u <- format_entry(format)$unit %||% "unit"
  if (n == 1) u else paste0(u, "s")
}

# The format of a recording from its name (and, for csv, its first line):
# the first format in the registry (formats.R) with the file's extension
# whose detector, if it has one, says yes.
file_format <- function(file, arg = "file") {
  exts <- format_extensions()
  two <- gsub(".", "\\.", exts[grepl(".", exts, fixed = TRUE)], fixed = TRUE)
  ext <- tolower(sub(paste0(".*?\\.(", paste0("(", two, ")|", collapse = ""),
                            "[^.]+)$"), "\\1", basename(file)))
  for (nm in names(recording_formats)) {
    f <- recording_formats[[nm]]
    if (ext %in% names(f$ext) && (is.null(f$detect) || f$detect(file))) return(nm)
  }
  abort("`", arg, "` has an unsupported extension \".", ext, "\"; ",
        format_readable())
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
