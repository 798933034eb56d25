# Sources. A source (class gravcal_source, made and checked by new_source()
# only) is a list with `format`, `sf`, `filename`, `temperature`
# (does it carry a temperature column), `units` (the source's units in one
# of GGIR's blocks), `short_rows` (GENEActiv in compatible mode: a block
# with fewer rows is the last) and `pump()`, which makes the core's source
# for the one pump (gc_pump(), pipeline.hpp): an open decoder, the columns
# of a data frame, or the blocks that GGIR's own readers give (`read(i)`:
# block i, 1, 2, ... in order, as list(data = data frame with x, y, z and
# maybe temperature, last = logical), or NULL at the end; one block a unit).
# Block sizes are GGIR's (g.calibrate / g.readaccfile), so that gravcal cuts a
# file where GGIR does: `chunksize` scales them (1 = about 12 hours).
# `read_opts`: GGIR's reading parameters for the native decoders, as decoder
# options (`interpolation`, GGIR's interpolationType: .cwa and GENEActiv at
# a rate that is not whole; `frequency_tol`: .cwa); GGIR's own readers
# (reader = "reference") are called with GGIR's defaults, so another value
# there is an error naming the parameter.


# `rmc`: GGIR's rmc.* parameters (their checked values, rmc_values()); with
# rmc.firstrow.acc the file is read as an ad hoc csv file (R/adhoc-csv.R).
# `part`: whose blocks, g.calibrate()'s ("calibrate", about 12 hours at
# chunksize 1) or g.getmeta()'s ("getmeta", about 24 hours: every format's
# block at twice the chunksize, Movisens's a whole day).
open_source <- function(datafile, sf = NULL, chunksize = 1, arg = "datafile",
                        reader = "native", compat = TRUE, read_opts = list(),
                        rmc = NULL, sf_arg = "sf", part = "calibrate") {
  if (identical(part, "getmeta")) chunksize <- 2 * chunksize
  if (is.data.frame(datafile) || is.matrix(datafile)) {
    return(source_frame(datafile, sf, chunksize, arg))
  }
  datafile <- unisens_acc(datafile)
  if (!is.character(datafile) || length(datafile) != 1 || is.na(datafile)) {
    abort("`", arg, "` must be a file path or a data frame of raw samples, ",
          "not ", describe(datafile), ".")
  }
  check_file(datafile, arg)
  reader <- match_choice(reader, "reader", c("native", "reference"))
  layout <- NULL
  shown <- NULL  # the format fits and tables name, where it is read as another
  if (!is.null(rmc$rmc.firstrow.acc)) {
    format <- rmc_format()
    layout <- rmc_layout(rmc, datafile, ggir = compat, stamps = identical(part, "getmeta"))
    sf <- layout$sf
  } else {
    format <- file_format(datafile, arg)
    if (!is.null(as_adhoc <- format_entry(format)$adhoc_layout)) {
      layout <- as_adhoc(datafile, arg, compat)
      shown <- format
      format <- rmc_format()
      sf <- layout$sf
    }
  }
  # the source's fields: from the native decoder (source_native()), else
  # from the format's own reader (its `source`: the fields of a source, or a
  # reader's format, sf, temperature and read(i))
  got <- NULL
  if (reader == "native" && format_has_decoder(format)) {
    got <- source_native(datafile, format, sf, chunksize, compat, arg, read_opts,
                         extra = layout$opts, part = part)
  }
  if (is.null(got)) {
    check_reference_opts(read_opts, format)
    got <- if (is.null(layout)) format_entry(format)$source(datafile, sf, chunksize, arg, format) else
      format_entry(format)$source(datafile, sf, chunksize, arg, format, layout = layout)
  }
  fields <- unclass(got)
  if (!is.null(layout$serial)) fields$info$serial <- layout$serial
  check_sf_agrees(sf, fields$sf, format, datafile, sf_arg)
  fields$filename <- ggir_file_name(datafile)
  fields$path <- datafile
  if (is.null(fields$pump)) {
    fields$units <- 1
    fields$pump <- reference_pump(fields$read)
  }
  if (!is.null(shown)) fields$format <- shown
  do.call(new_source, fields)
}

# A source (see the top of this file), its fields checked: `format`,
# `sf`, `temperature`, `units` and `pump()` are required; a decoder's
# source has `info`, `native` and `report()`, a reference reader's
# `read(i)`, samples in memory `n` and `time`; meta_source() adds what the
# decoder was opened with for g.getmeta() (`getmeta_timegaps`,
# `epoch_gaps`, `clock_shifted`). A field of the wrong type is an error
# (the package's, not the caller's).
new_source <- function(format, sf, temperature, units, pump, filename = NA_character_,
                       path = NULL, short_rows = 0, info = NULL, native = NULL,
                       report = NULL, read = NULL, n = NULL, time = NULL,
                       getmeta_timegaps = NULL, epoch_gaps = NULL, clock_shifted = NULL) {
  bad <- function(what) abort("Internal error: a source's `", what, "`.")
  one <- function(x, test) length(x) == 1 && test(x)
  if (!one(format, is.character) || is.na(format)) bad("format")
  if (!one(sf, is.numeric)) bad("sf")
  if (!one(temperature, is.logical) || is.na(temperature)) bad("temperature")
  if (!one(units, is.numeric)) bad("units")
  if (!is.function(pump)) bad("pump")
  if (!one(filename, is.character)) bad("filename")
  if (!is.null(path) && !one(path, is.character)) bad("path")
  if (!one(short_rows, is.numeric)) bad("short_rows")
  if (!is.null(info) && !is.list(info)) bad("info")
  if (!is.null(native) && !is.list(native)) bad("native")
  for (f in c("report", "read")) {
    if (!is.null(get(f)) && !is.function(get(f))) bad(f)
  }
  if (!is.null(n) && !one(n, is.numeric)) bad("n")
  if (!is.null(time) && !is.atomic(time)) bad("time")
  for (f in c("getmeta_timegaps", "epoch_gaps", "clock_shifted")) {
    if (!is.null(get(f)) && !one(get(f), is.logical)) bad(f)
  }
  src <- list(format = format, sf = sf, filename = filename, path = path,
              temperature = temperature, units = units, short_rows = short_rows,
              info = info, native = native, report = report, read = read, n = n,
              time = time, getmeta_timegaps = getmeta_timegaps, epoch_gaps = epoch_gaps,
              clock_shifted = clock_shifted, pump = pump)
  structure(src[!vapply(src, is.null, TRUE)], class = "gravcal_source")
}

# `src` with some fields given anew, checked again.
source_with <- function(src, ...) {
  do.call(new_source, utils::modifyList(unclass(src), list(...)))
}

# The pump of a source whose blocks GGIR's own readers give (`read(i)`):
# one block a unit. The previous block is garbage once the next is asked
# for: it is collected before the next is read, so that memory stays at
# about one block.
reference_pump <- function(read) {
  columns <- function(blk) {
    if (is.null(blk)) return(NULL)
    d <- blk$data
    col <- function(v) {
      if (!is.numeric(v)) abort("The recording has a non-numeric acceleration or temperature column.")
      as.double(v)
    }
    list(x = col(d$x), y = col(d$y), z = col(d$z),
         temperature = if ("temperature" %in% names(d)) col(d$temperature),
         last = isTRUE(blk$last))
  }
  function() {
    i <- 1
    first <- columns(read(1))
    if (is.null(first)) {
      first <- list(x = numeric(0), y = numeric(0), z = numeric(0),
                    temperature = NULL, last = TRUE)
    }
    gc_source_blocks(first, function() {
      first <<- NULL
      i <<- i + 1
      columns(read(i))
    })
  }
}

# What a fit was computed from: the source, the samples read and, from a
# native decoder, its report of what it skipped (see decode.hpp's Report).
source_input <- function(src, samples) {
  if (is.null(src) || identical(src$format, "data.frame")) {
    return(list(source = "memory", samples = samples))
  }
  rep <- if (is.null(src$report)) NULL else src$report()
  list(source = src$filename, format = src$format,
       reader = if (is.null(src$native)) "reference" else "native",
       serial = if (is.null(src$info$serial)) NA_character_ else src$info$serial,
       range_g = if (is.numeric(src$info$range_g) &&
                     length(src$info$range_g) == 1) src$info$range_g else
                       NA_real_,
       samples = samples, report = rep,
       # the first sample's time (UNIX seconds, the file's clock) where the
       # decoder knows it: near_rest_clock() dates the stretches with it
       start_time = if (is.numeric(src$info$start_time) &&
                        length(src$info$start_time) == 1) src$info$start_time else
                          NA_real_)
}

# A file whose reader found no sample at all, having skipped what it read,
# cannot be read: an error naming it and the first problem.
check_source_read <- function(src, samples) {
  if (samples > 0 || is.null(src$report)) return(invisible())
  r <- src$report()
  if (r$skipped > 0 || isTRUE(r$read_error)) {
    abort("Cannot read \"", src$filename, "\": no ", unit_name(src$format, 2),
          " of it hold samples (", format(r$skipped), " skipped",
          if (length(r$notes)) paste0("; first: ", r$notes[1]), ").")
  }
  # lines read whose time stamps could not be, so that GGIR's resampling
  # (which needs them) had nothing to give
  bad <- unname(r$counters["bad_timestamps"])
  if (isTRUE(bad > 0)) {
    abort("Cannot read \"", src$filename, "\": none of its time stamps could be read (",
          format(bad), " unreadable", if (length(r$notes)) paste0("; first: ", r$notes[1]),
          "), and GGIR's resampling of it needs them.")
  }
}

# The decoder's reason a file could not be opened, in the package's words
# where it is the missing sampling rate.
native_open_error <- function(file, format, why, arg) {
  if (grepl("sampling rate is unknown", why, fixed = TRUE)) {
    abort("The sampling frequency of \"", file, "\" is unknown: give `sf`.")
  }
  abort("Cannot read `", arg, "` \"", file, "\" as ", native_format_name(format),
        ": ", why, ".")
}

# A file read by gravcal's own decoder (decode_*.hpp). NULL when this build
# has no decoder for the format. Blocks are GGIR's (in the format's units);
# each block comes as one or more parts (list(cols, from, to)), which hold
# the samples of GGIR's block together, however many samples that is.
# `segment()` streams units straight into a segmenter, without R vectors.
# `extra`: more options for the decoder (an ad hoc csv file's layout).
source_native <- function(file, format, sf, chunksize, compat, arg,
                          read_opts = list(), extra = NULL, part = "calibrate") {
  opts <- c(list(compat = as.numeric(isTRUE(compat))), read_opts)
  opts$zone_arg <- NULL
  opts$found_sf <- NULL
  if (!is.null(sf)) opts$sf <- as.numeric(sf)
  opts[names(extra)] <- extra
  set <- format_decoder_options(format, file, opts, sf,
                                list(whole = FALSE, compat = compat, chunksize = chunksize,
                                     part = part, zone = read_opts$zone,
                                     zone_arg = read_opts$zone_arg,
                                     found_sf = read_opts$found_sf))
  opts <- set$opts
  sf <- set$sf
  h <- decoder_open(file, format, opts)
  if (is.null(h$ptr)) {
    if (isTRUE(h$unsupported)) return(NULL)
    native_open_error(file, format, h$error, arg)
  }
  entry <- format_entry(format)
  if (is.null(sf) || isTRUE(entry$own_rate)) sf <- h$info$sf
  if (isTRUE(compat) && !is.null(entry$ggir_check_sf)) entry$ggir_check_sf(file, sf)
  if (!isTRUE(is.finite(sf) && sf > 0)) {
    abort("The sampling frequency of \"", file, "\" is unknown: give `sf`.")
  }
  check_sf(sf)
  B <- format_block_units(format, sf, chunksize, part)
  # GGIR's last block (GENEActiv: fewer rows than its pages hold)
  short <- if (isTRUE(compat) && !is.null(entry$ggir_short_rows)) entry$ggir_short_rows(B) else 0
  # a source's fields (open_source() makes the source)
  list(format = format, sf = sf, temperature = isTRUE(h$info$temperature),
       info = h$info, native = h, units = B, short_rows = short,
       report = function() native_report(h),
       pump = function() gc_source_decoder(h$ptr))
}

`%||%` <- function(a, b) if (is.null(a)) b else a

# GGIR's readers, as gravcal calls them, take GGIR's default reading
# parameters only: another value, for a format whose reading it changes, is
# an error naming GGIR's parameter.
check_reference_opts <- function(read_opts, format) {
  defaults <- list(interpolation = c(interpolationType = 1),
                   frequency_tol = c(frequency_tol = 0.1))
  used <- format_entry(format)$ggir_read_opts
  for (nm in intersect(intersect(names(read_opts), names(defaults)), used)) {
    d <- defaults[[nm]]
    if (!identical(as.numeric(read_opts[[nm]]), unname(d))) {
      abort("`", names(d), "` = ", describe(read_opts[[nm]]), " is taken by ",
            "gravcal's own decoders only (reader = \"native\"); GGIR's readers ",
            "are called with its default ", format(d), ".")
    }
  }
  invisible()
}

# Samples in memory; `format` is "data.frame" but for a csv file of
# samples read whole (source_csv()).
source_frame <- function(x, sf, chunksize, arg, format = "data.frame") {
  s <- as_samples(x, arg)
  if (is.null(sf)) sf <- attr(x, "sf")
  if (is.null(sf) && !is.null(s$time)) sf <- sf_from_time(s$time)
  if (is.null(sf)) abort("The sampling frequency of `", arg, "` is unknown: give `sf`.")
  check_sf(sf)
  new_source(format = format, sf = sf, filename = NA_character_,
             temperature = !is.null(s$temperature), n = s$n, time = s$time,
             units = frame_block_units(sf, chunksize), short_rows = 0,
             pump = function() gc_source_columns(s$x, s$y, s$z, s$temperature))
}

# ActiGraph csv export (10 header lines, optional column-name line, then
# [timestamp,] x, y, z) or a plain csv with a header line naming x, y, z.
source_csv <- function(file, sf, chunksize, format) {
  head <- suppressWarnings(readLines(file, n = 12, warn = FALSE))
  if (!length(head)) abort("`datafile` is empty: \"", file, "\".")
  actigraph <- is_actigraph_csv(file)
  if (!actigraph) {
    rec <- read_file(file, sf, "native", "datafile")
    return(source_frame(rec$data, rec$sf, chunksize, "datafile", format))
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
  B <- format_block_units(format, sf, chunksize)
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
  list(format = format, sf = sf, temperature = FALSE,
       read = function(i) {
         d <- read_rows(skip0 + (i - 1) * B, B)
         if (is.null(d)) return(NULL)
         list(data = d, last = nrow(d) < B)
       })
}

need_ggirread <- function(what) {
  if (!requireNamespace("GGIRread", quietly = TRUE)) {
    abort("Reading ", what, " files needs the GGIRread package: install.packages(\"GGIRread\").")
  }
}

source_cwa <- function(file, chunksize, format) {
  need_ggirread("Axivity .cwa")
  first <- tryCatch(GGIRread::readAxivity(file, start = 0, end = 1, progressBar = FALSE),
                    error = function(e) NULL)
  if (is.null(first) || is.null(first$header$frequency)) {
    abort("Corrupt or unreadable .cwa file \"", file, "\".")
  }
  sf <- first$header$frequency
  B <- format_block_units(format, sf, chunksize)
  list(format = format, sf = sf, temperature = TRUE,
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

source_geneactiv <- function(file, chunksize, format) {
  need_ggirread("GENEActiv .bin")
  first <- tryCatch(GGIRread::readGENEActiv(file, start = 1, end = 2),
                    error = function(e) NULL)
  if (is.null(first) || is.null(first$header$SampleRate)) {
    abort("Corrupt or unreadable GENEActiv .bin file \"", file, "\".")
  }
  sf <- round(first$header$SampleRate)
  B <- format_block_units(format, sf, chunksize)
  list(format = format, sf = sf, temperature = TRUE,
       read = function(i) {
         start <- B * (i - 1) + 1
         P <- tryCatch(GGIRread::readGENEActiv(file, start = start, end = start + B - 1),
                       error = function(e) NULL)
         if (is.null(P) || is.null(P$data.out) || !nrow(P$data.out)) return(NULL)
         d <- P$data.out[, intersect(c("x", "y", "z", "temperature"), names(P$data.out))]
         list(data = d, last = nrow(d) < B * 300)
       })
}

# GGIRread's reader gives the whole file in one call (see R/formats.R).
source_parmay <- function(file, format) {
  need_ggirread("Parmay Matrix .bin")
  sf <- tryCatch(GGIRread::readParmayMatrix(file, output = "sf"), error = function(e) NULL)
  if (!isTRUE(is.numeric(sf) && length(sf) == 1 && is.finite(sf))) {
    abort("Corrupt or unreadable Parmay Matrix .bin file \"", file, "\".")
  }
  list(format = format, sf = sf, temperature = TRUE,
       read = function(i) {
         if (i > 1) return(NULL)
         P <- tryCatch(GGIRread::readParmayMatrix(file, start = 1, end = 2^31 - 1),
                       error = function(e) NULL)
         if (is.null(P) || is.null(P$data) || !NROW(P$data)) return(NULL)
         names(P$data) <- sub("^acc_", "", names(P$data))
         names(P$data)[names(P$data) == "ambient_temp"] <- "temperature"
         d <- P$data[, intersect(c("x", "y", "z", "temperature"), names(P$data))]
         list(data = d, last = TRUE)
       })
}

# GGIR's block of a Movisens recording, in samples: sf * 60 * 1440 / 2 with
# its sf, which g.inspectfile sets to 64 whatever unisens.xml says.
movisens_block <- function(file = NULL, part = "calibrate") {
  if (identical(part, "getmeta")) 64 * 60 * 1440 else 64 * 60 * 1440 / 2
}

# The number attributes of a Movisens recording's unisens.xml (sampleRate,
# lsbValue, baseline) as R's as.numeric() reads them, which is how unisensR
# reads them: R's digits accumulate in its long double (in double in an R
# built without one), so a long number such as 1/3000 written to 17 digits
# can end in other bits than strtod's. Named "r_number:<text>" for the
# decoder, which takes these values for those texts. Nothing when the file
# cannot be read (the decoder says why).
unisens_r_numbers <- function(file) {
  xml <- file.path(dirname(file), "unisens.xml")
  size <- file.size(xml)
  if (!isTRUE(size > 0 && size <= 16 * 2^20)) return(list())
  txt <- tryCatch(paste(readLines(xml, warn = FALSE, encoding = "UTF-8"), collapse = "\n"),
                  error = function(e) "")
  m <- tryCatch(regmatches(txt, gregexpr("(sampleRate|lsbValue|baseline)[[:space:]]*=[[:space:]]*(\"[^\"]*\"|'[^']*')",
                                         txt, useBytes = TRUE))[[1]],
                error = function(e) character(0))
  if (!length(m)) return(list())
  quoted <- sub("^[^=]*=[[:space:]]*", "", m)
  val <- trimws(substr(quoted, 2L, nchar(quoted) - 1L), whitespace = "[ \t\r\n]")
  val <- unique(val[nzchar(val)])
  out <- as.list(suppressWarnings(as.numeric(val)))
  names(out) <- paste0("r_number:", val)
  out
}

# GGIR's own reading of a Movisens recording, block by block: unisensR for
# the acceleration, movisens_temperature() for the temperature.
source_movisens <- function(file, format) {
  if (!requireNamespace("unisensR", quietly = TRUE) ||
      !requireNamespace("GGIRread", quietly = TRUE)) {
    abort("Reading Movisens recordings by GGIR's reader needs the unisensR and GGIRread packages.")
  }
  dir <- dirname(file)
  n <- tryCatch(unisensR::getUnisensSignalSampleCount(dir, "acc.bin"),
                error = function(e) NULL)
  if (!isTRUE(is.numeric(n) && length(n) == 1 && n >= 1)) {
    abort("Corrupt or unreadable Movisens recording \"", file, "\".")
  }
  B <- movisens_block(file)
  list(format = format, sf = 64, temperature = TRUE,
       read = function(i) {
         from <- (i - 1) * B + 1
         if (from > n) return(NULL)
         to <- min(n, from + B - 1)
         d <- unisensR::readUnisensSignalEntry(dir, "acc.bin", startIndex = from,
                                              endIndex = to)
         d <- as.data.frame(d)
         names(d) <- c("x", "y", "z")
         tt <- tryCatch(movisens_temperature(dir, from, to, 64, nrow(d)),
                        error = function(e) NULL)
         if (!is.null(tt)) d$temperature <- as.vector(tt)
         list(data = d, last = to >= n)
       })
}

# The temperature of a Movisens block (acceleration samples `from` to `to`
# at `acc_sf`), as GGIR's part 1 takes it from temp.bin: the temperature
# samples over the same span (their indices rounded up, first as if
# temp.bin held 1 sample a second, then again at its own rate when that
# differs), stretched over the block's `n` samples by GGIRread's linear
# resampling. An error where temp.bin cannot be read.
movisens_temperature <- function(dir, from, to, acc_sf, n) {
  span <- function(rate) ceiling(c(from, to) / acc_sf * rate)
  read <- function(i) unisensR::readUnisensSignalEntry(dir, "temp.bin", startIndex = i[1],
                                                       endIndex = i[2])
  tt <- read(span(1))
  rate <- attr(tt, "sampleRate")
  if (rate != 1) tt <- read(span(rate))
  v <- as.matrix(tt$temp)
  k <- nrow(v)
  at <- seq_len(k)
  GGIRread::resample(v, at, seq(from = 1, to = at[k], length.out = n), k, type = 1)
}

source_gt3x <- function(file, chunksize, format) {
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
  B <- format_block_units(format, sf, chunksize)
  t0 <- NULL
  next_i <- 0
  list(format = format, sf = sf, temperature = FALSE,
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
