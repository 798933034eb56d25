# GGIR's "ad hoc" csv files: a csv of samples whose layout and units GGIR's
# rmc.* parameters describe (GGIR 3.3-9: read.myacc.csv(), g.readaccfile(),
# g.inspectfile()). Here the parameters become a layout for gravcal's csv
# decoder (decode_csv.hpp, format "adhoc_csv"): the lines to skip, the
# columns, the units and the sampling rate. The file is then read in GGIR's
# blocks like any csv (R/formats.R), by the native decoder or, with
# reader = "reference", by data.table::fread() block by block.
#
# What GGIR does that this reproduces:
# * the data start at line rmc.firstrow.acc; when that line's first field
#   is not a number (column names, or a text time stamp in the first
#   column), GGIR starts one line later (g.readaccfile's test of the column
#   names), so a text time stamp first loses the first sample, as in GGIR;
# * units: mg divided by 1000, then rmc.scalefactor.acc, then bits with
#   rmc.bitrate and rmc.dynamic_range (rmc.unsignedbit); temperature in K
#   gets 272.15 added (GGIR's constant), in F (t - 32) * 5 / 9;
# * the sampling rate from the header (rmc.firstrow.header,
#   rmc.header.length, rmc.headername.sf, rmc.header.structure; a row named
#   sample_rate; else rmc.sf); rmc.bitrate and rmc.dynamic_range may name
#   header rows too;
# * the rest threshold is rmc.noise * 1.2 (R/ggir-drop-in.R).
# Time stamps do not enter the calibration; they give read_recording() its
# time column (UNIXsec, UNIXmsec and ActivPAL read per sample, POSIX and
# character text from the first stamp on, start + i / sf), except with
# rmc.doresample and a UNIX time column: GGIR then resamples every block
# onto sf from its time stamps (see rmc_layout()), and rmc.check4timegaps:
# GGIR then fills each block's time gaps and drops its zero samples
# (g.imputeTimegaps; decode_ggir_timegaps.hpp), before any resampling.

# The rmc.* parameters (their values from the parameter table,
# ggir-params.R) as the decoder's layout for `file`: list(opts = decoder
# options, sf, skip, cols, temperature, ...). Errors name the parameter.
# `ggir`: the lines as GGIR's blocks have them (g.readaccfile skips line
# rmc.firstrow.acc when its first field is not a number, be it a column
# name or a text time stamp); FALSE (read_recording()): only a line whose
# x field is not a number is skipped (a column-name line).
rmc_layout <- function(p, file, tz = "", ggir = TRUE, stamps = FALSE) {
  if (is.null(p$rmc.firstrow.acc)) {
    abort("`rmc.firstrow.acc` must be given to read \"", file, "\" as an ad hoc csv file.")
  }
  refuse <- function(nm, why) {
    abort("`", nm, "` = ", deparse(p[[nm]]), " is not supported by gravcal (", why,
          "); GGIR::g.calibrate() reads such files.")
  }
  gaps <- isTRUE(p$rmc.check4timegaps) && length(p$rmc.col.time) > 0
  resample <- isTRUE(p$rmc.doresample) && length(p$rmc.col.time) > 0
  header <- rmc_header(p, file)
  sf <- rmc_sf(p, header, file)
  from_header <- function(nm) {
    v <- p[[nm]]
    if (is.character(v)) {
      got <- suppressWarnings(as.numeric(header$value[header$name == v[1]]))
      if (length(got) != 1 || is.na(got)) {
        abort("`", nm, "` = \"", v[1], "\" names no numeric row of the header of \"", file, "\".")
      }
      v <- got
    }
    v
  }
  opts <- list(sf = as.numeric(sf))
  if (p$rmc.unit.acc == "bit") {
    bitrate <- from_header("rmc.bitrate")
    range <- from_header("rmc.dynamic_range")
    if (!length(bitrate) || !length(range)) {
      abort("`rmc.unit.acc` = \"bit\" needs `rmc.bitrate` and `rmc.dynamic_range`.")
    }
    opts$bit <- if (isTRUE(p$rmc.unsignedbit)) 1 else 2
    opts$bit_pow <- 2^bitrate
    opts$bit_range <- as.numeric(range)
  }
  if (p$rmc.unit.acc == "mg") opts$acc_div <- 1000
  if (p$rmc.scalefactor.acc != 1) opts$acc_scale <- as.numeric(p$rmc.scalefactor.acc)
  opts$temp_unit <- match(p$rmc.unit.temp, c("C", "K", "F")) - 1
  cols <- as.numeric(p$rmc.col.acc)
  opts$col_x <- cols[1]
  opts$col_y <- cols[2]
  opts$col_z <- cols[3]
  if (length(p$rmc.col.temp)) opts$col_temp <- as.numeric(p$rmc.col.temp)
  # a wear column, read as GGIR's reader reads it (TRUE/FALSE: the decoder's
  # wear_of()): g.getmeta()'s non-wear from it; GGIR's reader stops on
  # values that are not TRUE/FALSE (rmc_check_wear()) and on a resampled
  # block's (the resampled column is numbers)
  if (ggir && length(p$rmc.col.wear)) {
    if (resample) {
      abort("`rmc.col.wear` with `rmc.doresample` = TRUE: GGIR's reader stops on such a file ",
            "(\"Corrupt file\": the resampled wear column is no longer TRUE/FALSE), and so ",
            "does gravcal's. Leave out one of the two.")
    }
    opts$col_wear <- as.numeric(p$rmc.col.wear)
  }
  if (p$rmc.dec == ",") opts$dec <- ","
  # the first data line: after the column-name line, if any (GGIR's test:
  # the first field of line rmc.firstrow.acc read as a number)
  first <- fread_lines(file, p$rmc.firstrow.acc + 1)
  if (length(first) < p$rmc.firstrow.acc) {
    abort("`rmc.firstrow.acc` = ", p$rmc.firstrow.acc, ", but \"", file, "\" has ",
          length(first), " lines.")
  }
  skip <- p$rmc.firstrow.acc - 1
  f1 <- rmc_fields(first[skip + 1])
  lead <- if (ggir) f1[1] else f1[cols[1]]
  if (p$rmc.dec == ",") lead <- if (ggir) lead else sub(",", ".", lead, fixed = TRUE)
  if (is.na(suppressWarnings(as.numeric(lead)))) skip <- skip + 1
  opts$skip <- skip
  if (length(p$rmc.col.time)) {
    opts$col_time <- as.numeric(p$rmc.col.time)
    unit <- p$rmc.unit.time
    origin <- rmc_origin(p$rmc.origin, tz)
    if (unit %in% c("UNIXsec", "UNIXmsec")) {
      opts$time_div <- if (unit == "UNIXmsec") 1000 else 1
      opts$time_offset <- origin
    } else if (unit == "ActivPAL") {
      # days since 1899-12-30, as read.myacc.csv() reads them: v * 86400
      # from the origin, then forced into desiredtz (time_utc_offset, set
      # by rmc_time_opts() below: a zone of one offset over the recording)
      opts$time_div <- 1
      opts$time_mul <- 86400
      opts$time_offset <- as.numeric(as.POSIXct("1899-12-30", tz = "UTC"))
    } else {
      line <- if (length(first) > skip) first[skip + 1] else NA_character_
      stamp <- rmc_fields(line)[p$rmc.col.time]
      t0 <- as.POSIXct(stamp, format = p$rmc.format.time, tz = tz)
      if (is.na(t0)) {
        abort("`rmc.format.time` = \"", p$rmc.format.time, "\" does not read the ",
              "time column (", p$rmc.col.time, ") of \"", file, "\": its first value is \"",
              stamp, "\".")
      }
      opts$start_time <- as.numeric(t0)
    }
  }
  # rmc.doresample: GGIR resamples each block linearly (interpolationType
  # 2: nearest neighbour) from its first time stamp to its last, at sf
  # (decode_ggir_resample.hpp; GGIR-compatible reads only)
  if (resample) opts$grid_sf <- as.numeric(sf)
  # rmc.check4timegaps: each block's gaps filled at sf and its zero samples
  # dropped, as g.imputeTimegaps does (decode_ggir_timegaps.hpp), before
  # any resampling. Both read the time stamps (text time as R's
  # as.POSIXct() reads it: rmc_time_opts())
  # `stamps` (g.getmeta()): every time stamp read as GGIR reads it (its
  # start, its gaps, its QClog), each block's gap filling from the block
  # before (GGIR passes its PreviousLastValue and PreviousLastTime)
  if (gaps || resample || (stamps && length(p$rmc.col.time))) {
    what <- if (gaps) "rmc.check4timegaps" else if (resample) "rmc.doresample" else {
      "g.getmeta()'s time column (`rmc.col.time`)"
    }
    g <- rmc_time_opts(p, file, skip, tz, what)
    opts[names(g)] <- g
  }
  # a numeric time column's first stamp, for what needs the start before
  # the samples are read (g.getmeta()'s zone table of long gaps:
  # meta_source()), converted as the decoder converts every stamp
  if (!is.null(opts$time_offset)) {
    line <- if (length(first) > skip) first[skip + 1] else NA_character_
    v <- suppressWarnings(as.numeric(rmc_fields(line)[p$rmc.col.time]))
    if (length(v) == 1 && is.finite(v)) opts$start_time <- rmc_number_time(v, opts)
  }
  if (gaps) opts$timegaps <- as.numeric(sf)
  if (gaps && stamps) opts$timegaps_carry <- 1
  list(opts = opts, sf = sf, skip = skip, header = header,
       serial = if (length(p$rmc.headername.sn)) {
         header$value[match(p$rmc.headername.sn[1], header$name)]
       })
}

# A numeric time stamp `v` in seconds since 1970 as the decoder's
# adhoc_number() (decode_csv_time.hpp) converts it from the options `o`, in
# GGIR's operations and order: v / time_div (v / 1 not taken) or
# v * time_mul, + time_offset, - time_utc_offset (when not 0), or less the
# offset of force_tz()'s table (zone_force_options(); NA where none).
rmc_number_time <- function(v, o) {
  v <- if (!is.null(o$time_mul)) v * o$time_mul else if (o$time_div != 1) v / o$time_div else v
  v <- v + o$time_offset
  if (!is.null(o$tz_na_n)) return(v - zone_force_offset(v, o))
  if (!is.null(o$time_utc_offset) && o$time_utc_offset != 0) v <- v - o$time_utc_offset
  v
}

# `rmc` (the rmc.* parameters) with the zone GGIR reads text time in
# (attributes tz and tz_arg, the parameter that gave it): configtz, else
# desiredtz (`p` holds them). GGIR's g.readaccfile() hands read.myacc.csv
# configtz (desiredtz where it is not given), never NULL, so the deprecated
# rmc.configtz and rmc.desiredtz never choose the zone there; one that
# differs from what it is handed stops each of GGIR's reads
# (rmc_zone_conflict()).
rmc_with_zone <- function(rmc, p) {
  attr(rmc, "tz") <- if (length(p$configtz)) p$configtz else p$desiredtz %||% ""
  attr(rmc, "tz_arg") <- if (length(p$configtz)) "configtz" else "desiredtz"
  # ActivPAL days are forced into desiredtz (read.myacc.csv(): a deprecated
  # rmc.desiredtz takes the place of a desiredtz of "")
  desired <- p$desiredtz %||% ""
  if (!nzchar(desired) && !is.null(rmc$rmc.desiredtz)) desired <- rmc$rmc.desiredtz
  attr(rmc, "desiredtz") <- desired
  rmc
}

# The rmc.* zone parameter on which GGIR 3.3-9's read.myacc.csv() stops
# when g.readaccfile() calls it, with the reason, or NULL: rmc.desiredtz
# other than a desiredtz that is not "", rmc.configtz other than configtz
# (desiredtz where it is not given).
rmc_zone_conflict <- function(rmc, p) {
  desired <- p$desiredtz %||% ""
  config <- if (length(p$configtz)) p$configtz else desired
  if (!is.null(rmc$rmc.desiredtz) && nzchar(desired) && !identical(rmc$rmc.desiredtz, desired)) {
    return(list(nm = "rmc.desiredtz", other = "desiredtz", value = desired))
  }
  if (!is.null(rmc$rmc.configtz) && !identical(rmc$rmc.configtz, config)) {
    return(list(nm = "rmc.configtz", other = if (length(p$configtz)) "configtz" else "desiredtz",
                value = config))
  }
  NULL
}

# rmc.check4timegaps and rmc.doresample (`what`): what the decoder needs to
# read the time stamps as GGIR's gap imputation and resampling see them
# (options time_format and time_utc_offset for text time), or an error
# naming `what` and what gravcal does not reproduce. GGIR reads text time
# in the zone configtz, else desiredtz: a fixed offset is subtracted from
# the stamps, as as.POSIXct() does (the resampling's grid starts at the
# first stamp: its value counts); a zone whose offset changes is followed
# minute by minute (R/zone.R). ActivPAL days: rmc_activpal_zone().
rmc_time_opts <- function(p, file, skip, tz, what) {
  unit <- p$rmc.unit.time
  if (unit %in% c("UNIXsec", "UNIXmsec")) return(list())
  if (unit == "ActivPAL") return(rmc_activpal_zone(p, file, skip, tz, what))
  zone <- attr(p, "tz") %||% p$rmc.configtz %||% p$rmc.desiredtz %||% tz
  lines <- fread_lines(file, skip + 1000)
  lines <- lines[seq_along(lines) > skip]
  stamps <- vapply(lines, function(l) rmc_fields(l)[p$rmc.col.time], "", USE.NAMES = FALSE)
  refuse <- function(why) {
    lead <- if (grepl("^rmc[.]", what)) paste0("`", what, "` = TRUE") else what
    abort(lead, " with `rmc.unit.time` = \"", unit, "\" is not supported by ",
          "gravcal (", why, "); GGIR reads such files.")
  }
  fmt <- p$rmc.format.time
  d <- regmatches(fmt, gregexpr("%O?.", fmt))[[1]]
  bad <- setdiff(d, c("%Y", "%y", "%m", "%d", "%H", "%M", "%S", "%OS", "%T", "%%"))
  if (length(bad)) {
    refuse(paste0("its text time is read with `rmc.format.time` directives ",
                  "%Y %y %m %d %H %M %S %OS %T only, not ", paste(bad, collapse = " ")))
  }
  t <- as.numeric(as.POSIXct(stamps, format = fmt, tz = "UTC"))
  # GGIR spreads whole-second stamps that repeat over the second
  # ("POSIX"): not reproduced. What GGIR 3.3-9's read.myacc.csv() does,
  # per block of lines, when the block's first 1000 stamps repeat one and
  # sf is given: with b the ends of the runs of equal stamps (1 first,
  # duplicates dropped, the block's last line last; so a first run of one
  # line merges with the next) and L = diff(b) (the first "run" counted one
  # short), in this order, each an addition to the stamps, with d =
  # (0:(sf - 1)) * (1 / sf) (seq()'s products, not quotients): runs with
  # L == sf get d (the first run from its second line on); a first run
  # with L != sf gets seq(1 - b[2] / sf, 1 - 1 / sf, by = 1 / sf); a last
  # run with L != sf gets d[1:L] (NA beyond sf); with more than four b,
  # every run after the first with L != sf (the last one again) gets
  # d[1:L], d[sf] repeated beyond sf. A streaming wrapper under
  # GgirTimegapsOf could replay it holding the first 1000 lines and four
  # runs.
  w <- t[!is.na(t)]
  if (unit == "POSIX" && all(w == floor(w)) && anyDuplicated(w)) {
    refuse("whole-second time stamps that repeat are spread over the second by GGIR")
  }
  # "POSIX": GGIR formats what fread gives; fread reads ISO 8601 stamps as
  # date-times, whose format() drops the fraction of a second (and GGIR
  # then spreads the repeated whole seconds)
  if (unit == "POSIX" && any(grepl("[0-9]:[0-9]{2}[.,][0-9]", stamps)) &&
      rmc_fread_datetime(lines[seq_len(min(5, length(lines)))], p$rmc.col.time)) {
    refuse(paste0("GGIR reads ISO 8601 text time like \"", stamps[1], "\" through ",
                  "data.table::fread(), losing its fractions of a second; with ",
                  "rmc.unit.time = \"character\" GGIR keeps them and gravcal follows"))
  }
  t0 <- t[!is.na(t)][1]
  if (is.na(t0)) refuse("the time column's first values cannot be read")
  # (whole seconds: the text below has none of the first stamp's fraction)
  at <- floor(t0) + (0:25) * 30.44 * 86400
  off <- civil_offset(at, zone)
  if (!anyNA(off) && all(off == off[1])) {
    return(list(time_format = p$rmc.format.time, time_utc_offset = off[1]))
  }
  zone_name <- paste0("the time zone \"", zone, "\"", if (!nzchar(zone)) " (the session's)")
  # a zone whose offset changes: text time read in it as as.POSIXct() reads
  # it, minute by minute (R/zone.R); GGIR converts a block's stamps in
  # order, so a stamp that exists twice or not at all in the zone takes the
  # offset of the conversion before it, which gravcal knows except for the
  # first stamp of a block (the decoder counts those, and g.calibrate()
  # refuses: ggir_check_zone_read())
  lo <- as.numeric(as.POSIXct("2000-01-01", tz = "UTC"))
  hi <- as.numeric(as.POSIXct("2064-01-01", tz = "UTC"))
  if (t0 < lo || t0 >= hi) {
    refuse(paste0(zone_name, " changes its UTC offset, and gravcal follows its changes from 2000 ",
                  "to 2063 only"))
  }
  c(list(time_format = p$rmc.format.time, time_utc_offset = 0), zone_options(zone))
}

# ActivPAL days (rmc_time_opts()): read.myacc.csv() forces them into
# desiredtz with lubridate::force_tz(), which subtracts the zone's UTC
# offset at each stamp's clock time. Over a recording that sees one offset
# (its first and last stamps, a day either side, every half hour) that is
# the option time_utc_offset. Across a change of offset (daylight saving)
# the decoder follows force_tz()'s table (zone_force_options()): the stamps
# after the change move by it, those in an hour the clocks skip are NA.
# GGIR's gap filling (rmc.check4timegaps) and resampling (rmc.doresample)
# of NA stamps are not reproduced: with either (`what`), a recording
# through such an hour is refused, naming it.
rmc_activpal_zone <- function(p, file, skip, tz, what) {
  zone <- attr(p, "desiredtz") %||% p$rmc.desiredtz %||% tz
  lines <- fread_lines(file, skip + 1)
  first <- if (length(lines) > skip) lines[skip + 1] else NA_character_
  day <- function(line) suppressWarnings(as.numeric(rmc_fields(line)[p$rmc.col.time]))
  origin <- as.numeric(as.POSIXct("1899-12-30", tz = "UTC"))
  t <- c(day(first), day(file_last_line(file))) * 86400 + origin
  lead <- if (grepl("^rmc[.]", what)) paste0("`", what, "` = TRUE") else what
  if (!is.finite(t[1])) {
    abort(lead, " with `rmc.unit.time` = \"ActivPAL\": the time column (", p$rmc.col.time,
          ") of \"", file, "\" does not start with a number of days (\"",
          rmc_fields(first)[p$rmc.col.time], "\").")
  }
  # (a last line that is not a stamp: 25 months from the first, as for text)
  if (!is.finite(t[2])) t[2] <- t[1] + 25 * 30.44 * 86400
  span <- range(t)
  at <- floor(seq(span[1] - 86400, span[2] + 86400, by = 1800))
  off <- civil_offset(at, zone)
  if (!anyNA(off) && all(off == off[1])) return(list(time_utc_offset = off[1]))
  o <- zone_force_options(zone, span[1], span[2])
  if (is.null(o)) return(list(time_utc_offset = off[1]))
  skipped <- vapply(seq_len(o$tz_na_n), function(j) {
    o[[paste0("tz_na_lo_", j - 1L)]] <= span[2] && o[[paste0("tz_na_hi_", j - 1L)]] > span[1]
  }, TRUE)
  if (any(skipped) && grepl("^rmc[.]", what)) {
    zone_name <- paste0("the time zone \"", zone, "\"", if (!nzchar(zone)) " (the session's)")
    abort(lead, " with `rmc.unit.time` = \"ActivPAL\" is not supported by gravcal for \"",
          basename(file), "\": the recording's clock passes through an hour that ", zone_name,
          " (desiredtz, into which GGIR forces ActivPAL days) skips (daylight saving), where ",
          "lubridate::force_tz() gives no time (NA), and gravcal does not reproduce GGIR's ",
          "`", what, "` of NA time stamps. Without it, or in a zone without that change ",
          "(\"UTC\", or a fixed offset such as \"Etc/GMT-1\"), gravcal reads the file.")
  }
  c(list(time_utc_offset = 0), o)
}

# Whether data.table::fread() reads column `col` of `lines` as date-times
# (ISO 8601); without data.table, whether its first value looks like one.
rmc_fread_datetime <- function(lines, col) {
  if (requireNamespace("data.table", quietly = TRUE)) {
    d <- tryCatch(data.table::fread(text = lines, header = FALSE, showProgress = FALSE,
                                    data.table = FALSE), error = function(e) NULL)
    if (!is.null(d) && ncol(d) >= col) return(inherits(d[[col]], "POSIXct"))
  }
  grepl("^[0-9]{4}-[0-9]{2}-[0-9]{2}[T ][0-9]{2}:[0-9]{2}:[0-9]{2}", rmc_fields(lines[1])[col])
}

# The first `n` lines of `file` (fewer when it has fewer) as
# data.table::fread's `skip` counts lines, and so as GGIR's reads of an ad
# hoc csv file count them (skip = rmc.firstrow.acc - 1 + its block's start;
# the csv decoder skips its `skip` lines the same way): a line ends at
# "\n", at "\r" and at the pairs "\r\n" and "\n\r". R's readLines() takes
# "\n\r" for two line ends, the decoder's data lines end at "\n" only: a
# stray carriage return in a free-text header line would otherwise move
# every sample by a line.
fread_lines <- function(file, n) {
  if (n <= 0) return(character(0))
  con <- gzfile(file, "rb")  # (reads an uncompressed file as it is)
  on.exit(close(con))
  b <- raw(0)
  repeat {
    more <- readBin(con, "raw", 65536)
    b <- c(b, more)
    if (!length(more) || sum(b == as.raw(10) | b == as.raw(13)) > n + 1) break
  }
  at <- which(b == as.raw(10) | b == as.raw(13))
  lines <- character(0)
  start <- 1L
  k <- 1L
  while (length(lines) < n && k <= length(at)) {
    e <- at[k]
    seg <- b[seq.int(start, length.out = e - start)]
    lines <- c(lines, rawToChar(seg[seg != as.raw(0)]))
    nxt <- e + 1L
    # a pair of different line-end bytes is one line end
    if (k < length(at) && at[k + 1L] == nxt && b[nxt] != b[e]) {
      k <- k + 1L
      nxt <- nxt + 1L
    }
    start <- nxt
    k <- k + 1L
  }
  if (length(lines) < n && start <= length(b)) {
    rest <- b[start:length(b)]
    rest <- rest[rest != as.raw(0)]
    if (length(rest)) lines <- c(lines, rawToChar(rest))
  }
  lines
}

# The fields of a line, split at the first of ';', tab or ',' it holds
# (a line with ';' or tabs may hold decimal commas), blanks and double
# quotes around them removed.
rmc_fields <- function(line) {
  if (is.na(line)) return(NA_character_)
  sep <- c(";", "\t", ",")
  sep <- sep[vapply(sep, grepl, NA, x = line, fixed = TRUE)]
  f <- if (length(sep)) strsplit(line, sep[1], fixed = TRUE)[[1]] else line
  gsub("^[[:space:]\"]+|[[:space:]\"]+$", "", f)
}

# rmc.origin in seconds since 1970 (added to UNIX time stamps; 0 for GGIR's
# default).
rmc_origin <- function(origin, tz) {
  if (identical(origin, "1970-01-01")) return(0)
  o <- tryCatch(as.numeric(as.POSIXct(origin, tz = if (nzchar(tz)) tz else "UTC")),
                error = function(e) NA)
  if (is.na(o)) abort("`rmc.origin` must be a date (\"1970-01-01\"), not \"", origin, "\".")
  o
}

# The header's rows as name and value: lines rmc.firstrow.header to
# rmc.firstrow.header + rmc.header.length - 1 (GGIR's default length:
# the lines up to the data), fields 1 and 2, or field 1 split by
# rmc.header.structure. NULL without rmc.firstrow.header.
rmc_header <- function(p, file) {
  if (!length(p$rmc.firstrow.header)) return(NULL)
  n <- if (length(p$rmc.header.length)) p$rmc.header.length else p$rmc.firstrow.acc - 1
  lines <- fread_lines(file, p$rmc.firstrow.header - 1 + n)
  lines <- lines[seq_along(lines) >= p$rmc.firstrow.header]
  lines <- lines[nzchar(trimws(lines))]
  rows <- lapply(lines, function(l) {
    f <- rmc_fields(l)
    if (length(p$rmc.header.structure)) {
      f <- trimws(strsplit(f[1], p$rmc.header.structure[1])[[1]])
    }
    c(f[1], if (length(f) > 1) f[2] else NA_character_)
  })
  data.frame(name = vapply(rows, `[`, "", 1), value = vapply(rows, `[`, "", 2),
             stringsAsFactors = FALSE)
}

# The sampling rate: the header's row rmc.headername.sf, else its row
# "sample_rate", else rmc.sf (GGIR's g.inspectfile and read.myacc.csv).
rmc_sf <- function(p, header, file) {
  sf <- NA_real_
  if (!is.null(header)) {
    for (nm in c(if (length(p$rmc.headername.sf)) p$rmc.headername.sf[1], "sample_rate")) {
      v <- suppressWarnings(as.numeric(header$value[match(nm, header$name)]))
      if (!is.na(v)) {
        sf <- v
        break
      }
    }
  }
  if (is.na(sf) && length(p$rmc.sf)) sf <- p$rmc.sf
  if (is.na(sf) || !(sf > 0)) {
    abort("The sampling frequency of the ad hoc csv file \"", file, "\" is unknown: ",
          "give `rmc.sf`", if (length(p$rmc.firstrow.header)) " or `rmc.headername.sf`", ".")
  }
  check_sf(sf)
  sf
}

# An ad hoc csv file block by block through data.table::fread() (reader =
# "reference"): the same blocks, columns and units as the native decoder,
# in R.
source_adhoc <- function(file, sf, chunksize, arg, layout, format) {
  if (!requireNamespace("data.table", quietly = TRUE)) {
    abort("Reading ad hoc csv files with reader = \"reference\" needs the data.table package.")
  }
  o <- layout$opts
  sf <- layout$sf
  if (!is.null(o$grid_sf)) {
    abort("`rmc.doresample` = TRUE is taken by gravcal's own csv decoder only ",
          "(reader = \"native\"), not with reader = \"reference\".")
  }
  if (!is.null(o$timegaps)) {
    abort("`rmc.check4timegaps` = TRUE is taken by gravcal's own csv decoder only ",
          "(reader = \"native\"), not with reader = \"reference\".")
  }
  B <- format_block_units(format, sf, chunksize)
  acc <- function(a) {
    if (!is.null(o$acc_div)) a <- a / o$acc_div
    if (!is.null(o$acc_scale)) a <- a * o$acc_scale
    if (identical(o$bit, 1)) a <- ((a / o$bit_pow) - 0.5) * 2 * o$bit_range
    if (identical(o$bit, 2)) a <- (a / (o$bit_pow / 2)) * o$bit_range
    a
  }
  temp <- function(t) {
    switch(o$temp_unit + 1, t, t + 272.15, (t - 32) * (5 / 9))
  }
  cols <- c(o$col_x, o$col_y, o$col_z, o$col_temp)
  list(format = format, sf = sf, temperature = !is.null(o$col_temp),
       read = function(i) {
         d <- tryCatch(data.table::fread(file, skip = layout$skip + (i - 1) * B, nrows = B,
                                         header = FALSE, dec = if (is.null(o$dec)) "." else o$dec,
                                         showProgress = FALSE, data.table = FALSE),
                       error = function(e) NULL)
         if (is.null(d) || !nrow(d) || ncol(d) < max(cols)) return(NULL)
         d <- d[, cols]
         names(d) <- c("x", "y", "z", if (!is.null(o$col_temp)) "temperature")
         for (v in names(d)) {
           if (!is.numeric(d[[v]])) abort("Corrupt file \"", file, "\": column ", v, " is not numeric.")
           d[[v]] <- if (v == "temperature") temp(as.numeric(d[[v]])) else acc(as.numeric(d[[v]]))
         }
         list(data = d, last = nrow(d) < B)
       })
}

# GGIR's reader stops on a block whose wear column (rmc.col.wear) fread()
# does not read as TRUE/FALSE ("Corrupt file"); the decoder counts such
# values ("wear_not_logical"): an error, as GGIR's stop.
rmc_check_wear <- function(src) {
  if (is.null(src$report)) return(invisible())
  r <- src$report()
  n <- unname(r$counters["wear_not_logical"])
  if (isTRUE(n > 0)) {
    first <- grep("wear value", r$notes, value = TRUE, fixed = TRUE)
    abort("\"", basename(src$filename), "\": its wear column (`rmc.col.wear`) holds ", format(n),
          " value", if (n > 1) "s", " that GGIR's reader does not read as TRUE/FALSE (it takes ",
          "TRUE/FALSE, true/false or True/False, one spelling in each of its blocks, and ",
          "empty or NA for none)", if (length(first)) paste0("; first: ", first[1]),
          ". GGIR stops on such a file (\"Corrupt file\"), and so does gravcal.")
  }
  invisible()
}
