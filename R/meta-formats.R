# What g.getmeta() takes from a format's own header or log, as GGIR's
# readers take it (the registry's ggir_start, ggir_qclog, ggir_stops,
# ggir_read_stops and ggir_damage_warning in R/formats.R point here): the
# start of an ActiGraph csv export and of a Movisens recording, a Parmay
# Matrix file's packet log and the files GGIR's Parmay reader fails on,
# and the damaged GENEActiv files GGIR's reader stops on or reads where
# gravcal's decoder does not follow.

# The start of an ActiGraph csv export, as GGIR's g.getstarttime() reads
# it: "Start Time" and "Start Date" from the header lines below the first,
# their date order from the first line's "date format" (as read.csv()
# makes it a column name), read in configtz and given in desiredtz.
actigraph_csv_start <- function(file, p) {
  lines <- utils::read.csv(file, nrows = 8, skip = 1)[[1]]
  field <- function(key) {
    for (v in vapply(lines[seq_len(min(7, length(lines)))], format, "")) {
      parts <- strsplit(v, key, fixed = TRUE)[[1]]
      if (length(parts) > 1) return(gsub(" ", "", parts[2], fixed = TRUE))
    }
    abort(key, " not found in the header of \"", basename(file), "\".")
  }
  when <- paste0(field("Start Date"), " ", field("Start Time"))
  top <- colnames(as.matrix(utils::read.csv(file, nrows = 1, skip = 0)))[1]
  order <- actigraph_date_order(top)
  if (is.na(order)) abort("The date format of \"", basename(file), "\" is not recognised.")
  sep <- if (grepl("/", when, fixed = TRUE)) "/" else if (grepl("-", when, fixed = TRUE)) "-" else "."
  sp <- strsplit(order, "")[[1]]
  fmt <- paste0("%", sp[1], sep, "%", sp[2], sep, "%", sp[3], " %H:%M:%S")
  ctz <- if (length(p$configtz)) p$configtz else p$desiredtz
  as.POSIXlt(as.POSIXct(when, format = fmt, tz = ctz), tz = p$desiredtz)
}

# The order of day, month and year that an ActiGraph header's "date format"
# (M/d/yyyy, dd.MM.yy, yyyy-MMM-d, ...; separators read as dots) gives, in
# strptime letters ("mdY", "dbY", ...), by GGIR's rules: each order tested
# by its patterns, the two-digit year given up where the four-digit one
# matches, the abbreviated month preferred to the numeric. NA when none.
actigraph_date_order <- function(top) {
  has <- function(...) as.numeric(length(grep(paste(c(...), collapse = "|"), top)) > 0)
  f <- c(
    mdY = has("MM[.]dd[.]yyyy", "M[.]d[.]yyyy", "M[.]dd[.]yyyy", "MM[.]d[.]yyyy"),
    mdy = has("MM[.]dd[.]yy", "M[.]d[.]yy", "M[.]dd[.]yy", "MM[.]d[.]yy"),
    bdY = has("MMM[.]dd[.]yyyy", "MMM[.]d[.]yyyy"), bdy = has("MMM[.]dd[.]yy", "MMM[.]d[.]yy"),
    dmY = has("d[.]M[.]yyyy", "d[.]MM[.]yyyy"), dmy = has("d[.]M[.]yy", "d[.]MM[.]yy"),
    dbY = has("d[.]MMM[.]yyyy"), dby = has("d[.]MMM[.]yy"),
    Ymd = has("yyyy[.]M[.]d", "yyyy[.]MM[.]d"), ymd = has("yy[.]M[.]d", "yy[.]MM[.]d"),
    Ybd = has("yyyy[.]MMM[.]d"), ybd = has("yy[.]MMM[.]d"),
    Ydm = has("yyyy[.]dd[.]MM", "yyyy[.]d[.]M", "yyyy[.]d[.]MM", "yyyy[.]dd[.]M"),
    ydm = has("yy[.]dd[.]MM", "yy[.]d[.]M", "yy[.]d[.]MM", "yy[.]dd[.]M"),
    Ydb = has("yyyy[.]dd[.]MMM", "yyyy[.]d[.]MMM"), ydb = has("yy[.]dd[.]MMM", "yy[.]d[.]MMM"))
  # for each group of four (numeric and month-name, four- and two-digit
  # year): drop the two-digit year where the four-digit matches, then the
  # numeric month where the name matches
  for (g in list(c("mdY", "mdy", "bdY", "bdy"), c("dmY", "dmy", "dbY", "dby"),
                 c("Ymd", "ymd", "Ybd", "ybd"), c("Ydm", "ydm", "Ydb", "ydb"))) {
    if (f[[g[1]]] == 1 && f[[g[2]]] == 1) f[[g[2]]] <- 0
    if (f[[g[3]]] == 1 && f[[g[4]]] == 1) f[[g[4]]] <- 0
    if (f[[g[1]]] == 1 && f[[g[3]]] == 1) f[[g[1]]] <- 0
    if (f[[g[2]]] == 1 && f[[g[4]]] == 1) f[[g[2]]] <- 0
  }
  names(f)[which(f == 1)[1]]
}

# The start of a Movisens recording as GGIR's g.getstarttime() takes it:
# unisens.xml's timestampStart as unisensR reads it, its clock moved into
# configtz where given (as lubridate::force_tz() moves it: the same
# calendar time, read in that zone), given in desiredtz.
movisens_start <- function(file, p) {
  if (!requireNamespace("unisensR", quietly = TRUE)) {
    abort("The start of a Movisens recording as GGIR reads it needs the unisensR ",
          "package: install.packages(\"unisensR\").")
  }
  st <- unisensR::readUnisensStartTime(dirname(file))
  ctz <- if (length(p$configtz)) p$configtz else p$desiredtz
  if (!identical(ctz, "")) {
    whole <- floor(as.numeric(st))
    wall <- format(as.POSIXct(whole, origin = "1970-01-01", tz = attr(st, "tzone") %||% ""),
                   "%Y-%m-%d %H:%M:%S")
    st <- as.POSIXct(wall, tz = ctz) + (as.numeric(st) - whole)
  }
  as.POSIXlt(st, tz = p$desiredtz)
}

# GGIR's M$QClog for a Parmay Matrix file: GGIRread's readParmayMatrix() log
# of the packets, which GGIR's g.getmeta() keeps from its one block. A row
# per packet in the file's order: whether its checksum matched (imputed
# when not: GGIRread keeps such a packet as (0, 0, 1) g), its number, its
# first and last sample's time as the reader spreads its samples (a packet
# that starts a second or more after the previous one ended moved back to
# that end, by the gap; the last one period before the header's end), the
# span between, the rate set and the rate observed (the count over the
# header's span), the gap and the move, the packets the header declares
# and the file holds. From the decoder's packet table (unit_log()), the
# arithmetic R's.
parmay_qclog <- function(src) {
  log <- gc_decoder_unit_log(src$native$ptr)
  n <- length(log$t0)
  sf <- src$sf
  t0 <- log$t0
  t1 <- log$t1
  gap <- numeric(n)
  if (n > 1) gap[-1] <- t0[-1] - t1[-n]
  late <- which(gap >= 1)
  moved <- numeric(n)
  moved[late] <- gap[late]
  start <- t0
  start[late] <- t0[late] - gap[late]
  end <- t1 - 1 / sf
  pass <- log$checksum_pass == 1
  data.frame(checksum_pass = pass, blockID = seq_len(n), start = start, end = end,
             blockLengthSeconds = end - start, frequency_set = rep(sf, n),
             frequency_observed = log$n_acc / (t1 - t0), imputed = !pass,
             gap_with_previous_block_secs = moved, start_time_adjustment_secs = -moved,
             declared_packets = rep(parmay_declared(src$path), n),
             observed_packets = rep(n, n), acc_recorded = rep(TRUE, n))
}

# GGIR's M$QClog rows for a .cwa file's block (GGIRread's readAxivity()
# log, which g.getmeta() binds block after block): the rows the decoder
# logged after its first `from`, in readAxivity's types. Its data frame
# per block of reading has R's integer block numbers where readAxivity
# reads them from the blocks, and doubles where it counts them (a bad
# block's place, which readAxivity takes from its `start` argument at a
# block's start and as its loop's integer plus 1 within one); binding
# keeps a double once there is one, as rbind() does. NULL when there are
# no new rows.
cwa_qclog <- function(src, from) {
  log <- gc_decoder_unit_log(src$native$ptr)
  n <- length(log$kind)
  if (n <= from) return(NULL)
  k <- (from + 1):n
  kind <- log$kind[k]
  id <- function(v, double) if (double) v else as.integer(v)
  data.frame(checksum_pass = log$checksum_pass[k] == 1,
             blockID_current = id(log$blockID_current[k], any(kind == 0)),
             blockID_next = id(log$blockID_next[k], any(kind < 2)),
             start = log$start[k], end = log$end[k],
             blockLengthSeconds = log$blockLengthSeconds[k],
             frequency_blockheader = log$frequency_blockheader[k],
             frequency_observed = log$frequency_observed[k],
             imputed = log$imputed[k] == 1)
}

# The sum of a decoder report's counters named `nm` (list(counters =) from
# src$report(), or its counters), 0 for those it does not have.
report_count <- function(rep, nm) {
  k <- if (is.list(rep)) rep$counters else rep
  sum(vapply(nm, function(x) if (x %in% names(k)) unname(k[[x]]) else 0, 0))
}

# Why GGIR's reader of Parmay Matrix files (GGIRread's readParmayMatrix())
# gives no result to reproduce where gravcal's decoder reads on, or NULL:
# a packet too short for its header (at the file's end, a file cut inside
# one: the reader fails; within the file the reader takes the next packet's
# bytes for its own), a negative sample count, a header that declares no
# packet.
parmay_ggir_stops <- function(src) {
  rep <- src$report()
  short <- report_count(rep, "short_packet")
  if (short == 1 && isTRUE(rep$truncated)) {
    return("a packet cut inside its header at its end (GGIR's reader fails on it)")
  }
  if (short > 0) {
    return(paste0("a packet too short for its header within it (GGIR's reader takes the next ",
                  "packet's bytes for its own)"))
  }
  if (report_count(rep, "bad_packet_counts") > 0) {
    return("a packet with a negative sample count (GGIR's reader fails on it)")
  }
  declared <- parmay_declared(src$path)
  if (!isTRUE(declared >= 1)) {
    return(paste0("a header that declares ", declared, " packets (GGIR's reader gives ",
                  "nothing, and GGIR's g.getmeta() fails)"))
  }
  NULL
}

# Where GGIR's reader of .cwa files (GGIRread's readAxivity()) stops on a
# damaged file instead of skipping the damage, from the decoder's counts so
# far: a block that is not a data packet (not "AX", or not 508 bytes long:
# a zeroed block, at the file's end too), more than 20 bad blocks in a
# row, a time gap of over 3 days to impute. readAxivity() then fails for
# the whole of the call that meets it, so GGIR's g.calibrate() and
# g.getmeta() lose that block of their reading and every one after it
# (GGIR's g.getmeta() marks a first block's loss as a corrupt file), which
# gravcal does not reproduce: why, or NULL.
cwa_ggir_stops <- function(src) {
  rep <- src$report()
  n <- report_count(rep, "qclog_not_reproduced")
  if (n == 0) return(NULL)
  first <- grep("^bad_header|^bad_content|in a row|gap over 3 days", rep$notes, value = TRUE)
  paste0(n, " place", if (n != 1) "s", " where GGIR's reader (readAxivity()) stops instead of ",
         "skipping the damage (a block that is not a data packet, such as a zeroed one, more ",
         "than 20 bad blocks in a row, or a time gap of over 3 days",
         if (length(first)) paste0("; the first: ", first[1]),
         "), and GGIR's reading loses the whole of its block that holds it")
}

# Damaged lines in an ActiGraph csv export (fields missing or extra, a
# value or a time stamp that is not one) that the decoder skips or mends,
# where GGIR's reader (data.table's fread()) does not read them alike: on a
# damage sweep's files (stop 68) GGIR's g.calibrate() gave other
# coefficients, silently, and its g.getmeta() other values. A file cut
# short inside its last line is read alike (that line dropped), and so
# are unreadable time stamps where only the samples count (`part`
# "calibrate"; "getmeta" reads the time). Why, or NULL.
actigraph_csv_ggir_stops <- function(src, part) {
  rep <- src$report()
  damage <- c("long_lines", "short_lines", "non_numeric_lines",
              if (part == "getmeta") "bad_timestamps")
  n <- report_count(rep, damage)
  if (n == 0) return(NULL)
  first <- grep("too many fields|too few fields|not a number|unreadable time stamp", rep$notes,
                value = TRUE)
  paste0(n, " damaged line", if (n != 1) "s", if (length(first)) paste0(" (", first[1], ")"),
         ", which gravcal's decoder skips or mends and GGIR's reader (fread()) does not ",
         "read alike")
}

# Where GGIR's reader of .gt3x files (read.gt3x) gives what gravcal does
# not reproduce: a damaged archive it cannot open (it finds the entries by
# the zip's central directory; the native decoder reads them from their
# local headers when that is cut short or damaged), where GGIR's
# g.getmeta() marks the file corrupt and its g.calibrate() gives NULL; or
# damaged records in log.bin, which the decoder skips. Why, or NULL.
gt3x_ggir_stops <- function(src) {
  rep <- src$report()
  if (report_count(rep, "zip_directory_damaged") > 0) {
    return(paste0("a zip archive whose central directory is missing or damaged (the file ",
                  "cut short, for example), which GGIR's reader (read.gt3x) cannot open"))
  }
  if (isTRUE(rep$skipped > 0)) {
    # GGIR's reader does not skip them alike: its g.calibrate() gave other
    # coefficients, its g.getmeta() other values or (R 4.2) an error
    # ("'origin' must be supplied"), on a damage sweep's files (stop 68)
    first <- grep("^bad_|^long_", rep$notes, value = TRUE)
    return(paste0(rep$skipped, " damaged record", if (rep$skipped != 1) "s",
                  " in log.bin (", if (length(first)) first[1] else "bad checksums or separators",
                  ") that gravcal's decoder skips and GGIR's reader (read.gt3x) does not ",
                  "read alike"))
  }
  NULL
}

# Where GGIR's reading of a damaged GENEActiv .bin file (GGIRread's
# readGENEActiv(), whose reading of damaged pages the native decoder follows
# in GGIR's mode: decode_geneactiv.hpp) stops, or goes where the decoder
# does not follow, from the decoder's counts so far: why, or NULL.
# `part`: "getmeta" (its start is read; a block's first and last time
# stamps are checked in meta_run()) or "calibrate" (time stamps matter only
# where GGIR resamples the blocks by them: a rate that is not whole).
geneactiv_ggir_stops <- function(src, part) {
  rep <- src$report()
  n <- function(nm) report_count(rep, nm)
  if (n("ggir_not_reproduced") > 0) {
    return(paste0("a page line longer than 8192 characters that GGIR's reader reads on ",
                  "(gravcal's decoder keeps lines to that length)"))
  }
  if (n("ggir_rate_mismatch") > 0) {
    return(paste0("a page whose \"Measurement Frequency:\" reads as another rate than ",
                  "the file's where GGIR takes the file's rate from it, or decides by it ",
                  "whether to resample a block (or stops: \"sampling rate inconsistency\")"))
  }
  if (n("ggir_start_unread") > 0 && (part == "getmeta" || n("ggir_resampled_time_undefined") > 0)) {
    return(paste0("a first page whose \"Page Time:\" GGIR's reader does not read as a time ",
                  "(its time stamps are then NA, and GGIR stops on them)"))
  }
  if (n("ggir_resampled_time_undefined") > 0) {
    return(paste0("a page read at 0 Hz, whose time stamps GGIR's reader does not define ",
                  "(what they hold depends on the platform), in a recording GGIR resamples ",
                  "by its time stamps"))
  }
  NULL
}

# g.getmeta()'s warning of a GENEActiv file's damage, which the native
# decoder read as GGIR's reader reads it (so M is GGIR's): damaged pages
# (a hex line that is not 3600 hex digits: what decodes of it kept, garbled
# digits read as far as they go; a page header line not as the format has
# it), lines missing or extra (GGIR reads ten lines a page regardless), a
# last page cut short.
geneactiv_damage_warning <- function(src) {
  rep <- src$report()
  n <- function(nm) report_count(rep, nm)
  damaged <- n("damaged_hex") + n("damaged_page_header")
  what <- c(
    if (damaged > 0) {
      paste0(damaged, " damaged page", if (damaged != 1) "s", " (what GGIR's reader decodes ",
             "of each kept, garbled digits read as far as they go)")
    },
    if (n("misaligned_page") > 0) {
      paste0(n("misaligned_page"), " page", if (n("misaligned_page") != 1) "s",
             " after lines missing or extra, read ten lines a page as GGIR's reader reads them")
    },
    if (n("truncated_page") > 0) "a last page cut short")
  if (!length(what)) return(invisible())
  warning("\"", basename(src$filename), "\": ", paste(what, collapse = ", "),
          "; read as GGIR's reader (GGIRread) reads them, so M is GGIR's ",
          "(M$QClog is NULL, as GGIR's).", call. = FALSE)
  invisible()
}
