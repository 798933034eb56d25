# Axivity's csv export (OMGUI, cwa-convert): one line per sample: time
# stamp, x, y, z in g (AX6: and gyroscope columns), the time in UNIX
# seconds or as text ("2024-03-04 09:00:00.040"); an optional header line
# "Time,Accel-X (g), Accel-Y (g), Accel-Z (g)". GGIR 3.3-9 (g.inspectfile(),
# g.readaccfile()) takes a csv file whose first line is not ActiGraph's and
# whose lines have 4 or more fields for one of these; it finds the rate from
# the time stamps of lines 2 to 100001 (samples over seconds, rounded down
# to a multiple of 5 Hz) and resamples every block of lines linearly onto
# that rate, from the block's first time stamp to its last (the grid's last
# point dropped). gravcal's csv decoder reads the lines and its resampler
# (decode_ggir_resample.hpp) does the rest in GGIR-compatible mode; its own
# reads keep the samples as stored.
#
# How GGIR reads the time column of a block (data.table::fread(), header =
# FALSE): numbers are UNIX seconds (forced from UTC into its zone: configtz,
# else desiredtz, "" the session's); text fread reads as ISO 8601
# date-times ("2024-03-04 09:00:00.040", with "T", "Z" or an offset too) is
# seconds as fread computes them (forced into configtz/desiredtz when one is
# given); other text (slashes in the date, no seconds) goes through R's
# as.POSIXct() in that zone, its first format of "%Y-%m-%d %H:%M:%OS",
# "%Y/%m/%d %H:%M:%OS", "%Y-%m-%d %H:%M", "%Y/%m/%d %H:%M", ... that reads
# every stamp. A header line is data to that read (GGIR stops:
# "character string is not in a standard unambiguous format").

# The lines at the top of `file` (up to `n`, from its first `bytes` bytes),
# or NULL when they are not text (a binary file named .csv).
csv_head_lines <- function(file, n = 2, bytes = 1024) {
  con <- if (grepl("\\.gz$", file, ignore.case = TRUE)) gzfile(file, "rb") else file(file, "rb")
  on.exit(close(con))
  b <- readBin(con, "raw", bytes)
  nl <- which(b == as.raw(10))
  if (!length(nl)) return(NULL)
  b <- b[seq_len(nl[min(n, length(nl))] - 1)]
  b <- b[b != as.raw(13)]
  if (any((b < as.raw(32) & b != as.raw(10)) | b >= as.raw(127))) return(NULL)
  strsplit(rawToChar(b), "\n", fixed = TRUE)[[1]]
}

# A data line of an Axivity export: at least 4 comma-separated fields,
# numbers in fields 2 to 4 and a time stamp (anything) in field 1. (GGIR
# takes any csv of 4 or more columns that is not ActiGraph's for one.)
axivity_data_line <- function(line) {
  f <- trimws(strsplit(line, ",", fixed = TRUE)[[1]])
  length(f) >= 4 && nzchar(f[1]) && !anyNA(suppressWarnings(as.numeric(f[2:4])))
}

# OMGUI's header line: "Time,Accel-X (g), Accel-Y (g), Accel-Z (g)" (and
# gyroscope columns).
axivity_header_line <- function(line) {
  f <- trimws(strsplit(line, ",", fixed = TRUE)[[1]])
  length(f) >= 4 && tolower(f[1]) == "time" &&
    all(grepl("^accel-[xyz]", f[2:4], ignore.case = TRUE))
}

# Whether `file` looks like an Axivity csv export: not ActiGraph's, a first
# line that is a data line (not column names), or OMGUI's header line and
# a data line after it.
is_axivity_csv <- function(file) {
  if (is_actigraph_csv(file)) return(FALSE)
  lines <- csv_head_lines(file)
  if (!length(lines)) return(FALSE)
  if (axivity_data_line(lines[1])) return(TRUE)
  length(lines) >= 2 && axivity_header_line(lines[1]) && axivity_data_line(lines[2])
}

# Whether the export starts with OMGUI's header line.
axivity_csv_header <- function(file) {
  lines <- csv_head_lines(file, 1)
  length(lines) == 1 && axivity_header_line(lines[1])
}

# The rate GGIR finds in an Axivity csv export (g.inspectfile()): the first
# column of lines 2 to 100001 (read.csv() takes line 1 for column names),
# text read by as.POSIXct() in the session's zone; n / (t[n] - t[1]),
# rounded down to a multiple of 5.
axivity_csv_sf <- function(file) {
  t <- utils::read.csv(file, nrows = 1e5)[[1]]
  n <- length(t)
  if (!is.numeric(t)) {
    t <- tryCatch(r_posixct_ends(t), error = function(e) NULL)
    if (is.null(t)) {
      abort("The time stamps of the Axivity csv export \"", file, "\" are in no format R's ",
            "as.POSIXct() reads (GGIR's g.inspectfile() stops on them too).")
    }
  } else if (n > 0) {
    t <- t[c(1, n)]
  }
  sf <- floor((n / (t[length(t)] - t[1])) / 5) * 5
  if (!isTRUE(sf > 0 && is.finite(sf))) {
    abort("The sampling frequency of the Axivity csv export \"", file, "\" is unknown: give `sf`.")
  }
  sf
}

# The first and last values of as.numeric(as.POSIXct(x)) for text `x` (in
# the session's zone), without converting the values between: R's
# as.POSIXlt() takes the first of its formats that reads every value that
# is not NA, and stops when none does. A format that does not read the
# first of them cannot read them all, so it is passed over after one value
# (R reads all of them with it); the one taken is checked on all, as R
# checks it; each value's time depends on its own text alone, so the two
# ends are converted alone. Other types (a factor, all NA) go through R's
# own conversion.
r_posixct_ends <- function(x) {
  n <- length(x)
  if (!is.character(x) || n == 0) {
    v <- as.numeric(as.POSIXct(x, origin = "1970-01-01"))
    return(if (n) v[c(1, n)] else v)
  }
  xx <- x[!is.na(x)]
  if (!length(xx)) return(as.numeric(as.POSIXct(x[c(1, n)])))
  for (f in r_time_formats) {
    if (is.na(strptime(xx[1], f, tz = ""))) next
    if (all(!is.na(strptime(xx, f, tz = "")))) {
      return(as.numeric(as.POSIXct(strptime(x[c(1, n)], f, tz = ""), tz = "")))
    }
  }
  stop("character string is not in a standard unambiguous format")
}

# The formats R's as.POSIXct() tries on text, in its order.
r_time_formats <- c("%Y-%m-%d %H:%M:%OS", "%Y/%m/%d %H:%M:%OS", "%Y-%m-%d %H:%M",
                    "%Y/%m/%d %H:%M", "%Y-%m-%d", "%Y/%m/%d")

# How GGIR's block read takes the export's time column, from its first data
# lines (after `skip`): list(kind = "unix" (numbers), "iso" (fread's
# date-times) or "text" (R's as.POSIXct(), `format` the one it chooses),
# first = the first stamp in seconds (UTC)). An error naming the file for
# other columns.
axivity_csv_time <- function(file, skip = 0) {
  lines <- fread_lines(file, skip + 1000)
  lines <- lines[seq_along(lines) > skip]
  lines <- lines[nzchar(trimws(lines))]
  stamps <- vapply(lines, function(l) trimws(strsplit(l, ",", fixed = TRUE)[[1]][1]), "",
                   USE.NAMES = FALSE)
  stamps <- gsub("^\"|\"$", "", stamps)
  if (!length(stamps)) abort("The Axivity csv export \"", file, "\" has no data lines.")
  col <- if (requireNamespace("data.table", quietly = TRUE)) {
    tryCatch(data.table::fread(text = lines, header = FALSE, showProgress = FALSE,
                               data.table = FALSE)[[1]], error = function(e) NULL)
  }
  num <- suppressWarnings(as.numeric(stamps))
  if (is.numeric(col) || (is.null(col) && !anyNA(num))) {
    return(list(kind = "unix", first = num[1]))
  }
  iso <- "^[0-9]{4}-[0-9]{1,2}-[0-9]{1,2}[ T][0-9]{1,2}:[0-9]{1,2}:[0-9]"
  if (inherits(col, "POSIXct") || (is.null(col) && all(grepl(iso, stamps)))) {
    first <- if (inherits(col, "POSIXct")) as.numeric(col[1]) else
      as.numeric(as.POSIXct(stamps[1], tz = "UTC"))
    return(list(kind = "iso", first = first))
  }
  if (is.character(col) || is.null(col)) {
    for (f in r_time_formats) {
      if (all(!is.na(strptime(stamps, f, tz = "UTC")))) {
        return(list(kind = "text", format = f,
                    first = as.numeric(as.POSIXct(stamps[1], format = f, tz = "UTC"))))
      }
    }
  }
  abort("The time stamps of the Axivity csv export \"", file, "\" (\"", stamps[1], "\") are ",
        "neither UNIX seconds nor a date-time GGIR reads: its reader stops on them.")
}

# The last line of `file` that holds text (NA when there is none).
file_last_line <- function(file) {
  if (grepl("\\.gz$", file, ignore.case = TRUE)) {
    con <- gzfile(file, "rb")
    on.exit(close(con))
    tail <- raw(0)
    repeat {
      b <- readBin(con, "raw", 2^20)
      if (!length(b)) break
      tail <- c(tail, b)
      if (length(tail) > 8192) tail <- tail[(length(tail) - 8191):length(tail)]
    }
  } else {
    size <- file.size(file)
    con <- file(file, "rb")
    on.exit(close(con))
    if (size > 8192) seek(con, size - 8192)
    tail <- readBin(con, "raw", 8192)
  }
  tail <- tail[tail != as.raw(0)]
  lines <- strsplit(rawToChar(tail), "\r?\n")[[1]]
  lines <- lines[nzchar(trimws(lines))]
  if (length(lines)) lines[length(lines)] else NA_character_
}

# GGIR's time zone for the export's time (configtz, else desiredtz; ""
# the session's), in GGIR-compatible reads: decoder options, or an error
# naming the parameter (`zone_arg`) where gravcal does not reproduce it.
# Numbers (UNIX seconds) and fread's date-times are forced into the zone
# (lubridate::force_tz(); fread's date-times only when a zone is given): a
# fixed offset moves every stamp of the recording by the same whole
# seconds, which leaves the resampling, and so GGIR's result, to the bit as
# it is (times of 2004 to 2038 share one floating-point exponent). Across
# a change of offset during the recording the decoder forces each stamp as
# force_tz() does (the offset at its clock time; a clock time that exists
# twice takes the later offset), so that GGIR's resampling interpolates
# across the hour the stamps jump in autumn as GGIR's does; in spring the
# stamps of the hour the clocks skip are NA, and the resampler reads them
# as GGIRread::resample() does (every later sample of the block NA; a
# block that starts or ends with one stops, as GGIR's seq() does:
# ggir_check_nan_edge()). Other text is read by as.POSIXct() in the zone,
# as the csv decoder reads it (its offset, or R/zone.R's table of them where it
# changes; a block of GGIR's reading that starts at a time that exists
# twice or not at all there is refused after the read,
# ggir_check_zone_read()).
axivity_csv_zone <- function(file, time, zone, zone_arg) {
  if (time$kind == "iso" && !nzchar(zone)) return(list())
  zone_name <- if (nzchar(zone)) paste0("`", zone_arg, "` = \"", zone, "\"") else
    "the session's time zone (GGIR's when desiredtz and configtz are \"\")"
  if (time$kind == "text") {
    if (!is.null(zone_table(zone))) return(c(list(time_utc_offset = 0), zone_options(zone)))
    off <- civil_offset(floor(time$first), zone)
    if (is.na(off)) abort(zone_name, ": R cannot convert the recording's times in this zone.")
    return(list(time_utc_offset = off))
  }
  if (is.null(zone_table(zone))) {
    # a zone of one offset from 2000 to 2063: the stamps forced into it by
    # it (fread's date-times; for UNIX seconds a constant that changes
    # nothing, not applied)
    if (time$kind == "unix") return(list())
    # (at the first stamp's whole second: civil_offset() reads whole
    # seconds, a fraction would be taken for part of the offset)
    off <- civil_offset(floor(time$first), zone)
    return(if (is.na(off)) list() else list(time_utc_offset = off))
  }
  # a zone whose offset changes: across a change in the recording's span
  # the stamps follow force_tz()'s table of the zone (zone_force_options()),
  # moved by the offset at each stamp's clock time, NaN where it does not
  # exist
  o <- axivity_csv_force_table(file, time, zone)
  if (isTRUE(o$no_offset)) {
    abort(zone_name, ": R gives no UTC offset in that zone for some of the times of the ",
          "Axivity csv export \"", basename(file), "\".")
  }
  if (is.null(o)) {
    # (one offset over the span: as for a zone of one offset above)
    if (time$kind == "unix") return(list())
    return(list(time_utc_offset = civil_offset(floor(time$first), zone)))
  }
  c(list(time_utc_offset = 0), o)
}

# Whether GGIR's reader forces the export's stamps across a change of UTC
# offset in `zone` (UNIX seconds or fread's date-times, a change within
# the recording's span, from its first and last stamps a day either side):
# force_tz()'s table of the zone then (zone_force_options(); `no_offset`
# TRUE where R gives no offset), else NULL.
axivity_csv_force_table <- function(file, time, zone) {
  if (time$kind == "text" || is.null(zone_table(zone))) return(NULL)
  last <- file_last_line(file)
  t1 <- axivity_stamp_seconds(trimws(strsplit(last, ",", fixed = TRUE)[[1]][1]), time)
  span <- range(c(time$first, t1), na.rm = TRUE)
  at <- floor(seq(span[1] - 86400, span[2] + 86400, by = 1800))
  off <- civil_offset(at, zone)
  if (anyNA(off)) return(list(no_offset = TRUE))
  if (all(off == off[1])) return(NULL)
  zone_force_options(zone, span[1], span[2])
}

# Whether GGIR's reader takes the export's clock per sample after reading
# (UNIX seconds forced into the zone by one offset, which the decoder leaves
# to g.getmeta(): "sample"), or not (NULL: text and fread's date-times the
# decoder reads in the zone, and stamps across a change of offset, which the
# decoder forces itself).
axivity_csv_clock <- function(file, zone) {
  time <- axivity_csv_time(file, as.numeric(axivity_csv_header(file)))
  if (!identical(time$kind, "unix")) return(NULL)
  o <- tryCatch(axivity_csv_force_table(file, time, zone %||% ""), error = function(e) NULL)
  if (is.null(o) || isTRUE(o$no_offset)) "sample"
}

# A stamp of the kind `time` in seconds (UTC), for the recording's span.
axivity_stamp_seconds <- function(stamp, time) {
  stamp <- gsub("^\"|\"$", "", stamp)
  if (time$kind == "unix") return(suppressWarnings(as.numeric(stamp)))
  if (requireNamespace("data.table", quietly = TRUE)) {
    v <- tryCatch(data.table::fread(text = paste0(stamp, ",0,0,0"), header = FALSE,
                                    showProgress = FALSE, data.table = FALSE)[[1]],
                  error = function(e) NULL)
    if (inherits(v, "POSIXct")) return(as.numeric(v))
  }
  as.numeric(as.POSIXct(stamp, tz = "UTC", tryFormats = r_time_formats, optional = TRUE))
}

# The csv decoder's layout for an Axivity csv export (time stamp, x, y, z),
# and its rate: `sf` when given, else GGIR's. `compat`: GGIR's reading
# (its zone `zone`, named `zone_arg` in errors; a header line refused, as
# GGIR's reader stops on it); else gravcal's own (text time read as UTC).
axivity_csv_layout <- function(file, sf = NULL, compat = FALSE, zone = "",
                               zone_arg = "desiredtz") {
  header <- axivity_csv_header(file)
  if (header && compat) {
    abort("\"", file, "\" is an Axivity csv export with a header line (\"Time,Accel-X (g), ...\"): ",
          "GGIR 3.3-9 reads that line as data and stops (\"character string is not in a ",
          "standard unambiguous format\"). Remove the line for GGIR's result; calibrate() and ",
          "read_recording() read the file as it is.")
  }
  skip <- as.numeric(header)
  time <- axivity_csv_time(file, skip)
  if (is.null(sf)) sf <- axivity_csv_sf(file)
  check_sf(sf)
  opts <- list(sf = as.numeric(sf), grid_sf = as.numeric(sf), skip = skip,
               col_time = 1, col_x = 2, col_y = 3, col_z = 4)
  opts <- c(opts, switch(time$kind,
    unix = list(time_div = 1),
    iso = list(time_iso = 1),
    text = list(time_format = time$format)))
  if (compat) {
    z <- axivity_csv_zone(file, time, zone %||% "", zone_arg)
    opts[names(z)] <- z
  }
  list(sf = sf, opts = opts, time = time)
}

# The file block by block through data.table::fread() and GGIRread's
# resampling (reader = "reference"), the time column as GGIR's reader takes
# it in the session's zone (desiredtz and configtz "").
source_axivity_csv <- function(file, sf, chunksize, format) {
  if (!requireNamespace("data.table", quietly = TRUE)) {
    abort("Reading Axivity csv files with reader = \"reference\" needs the data.table package.")
  }
  need_ggirread("Axivity csv")
  sf <- axivity_csv_layout(file, sf, compat = TRUE)$sf
  B <- format_block_units(format, sf, chunksize)
  list(format = format, sf = sf, temperature = FALSE,
       read = function(i) {
         d <- tryCatch(data.table::fread(file, skip = (i - 1) * B, nrows = B, header = FALSE,
                                         showProgress = FALSE, data.table = FALSE),
                       error = function(e) NULL)
         if (is.null(d) || nrow(d) < 2 || ncol(d) < 4) return(NULL)
         t <- d[[1]]
         if (is.character(t)) t <- as.POSIXct(t, tz = "", origin = "1970-01-01")
         t <- as.numeric(t)
         grid <- seq(t[1], t[length(t)], by = 1 / sf)
         grid <- grid[-length(grid)]
         a <- GGIRread::resample(as.matrix(d[, 2:4]), t, grid, nrow(d), 1L)
         list(data = data.frame(x = a[, 1], y = a[, 2], z = a[, 3]), last = nrow(d) < B)
       })
}
