# GGIR's parameters, once. Each row: its name in g.calibrate() (GGIR's own
# name, as in GGIR's parameter lists; NA where g.calibrate() does not take
# it), its name in calibrate(method = "ggir") (NA where that does not take
# it), its default and its check; then the audit of GGIR 3.3-9: the list it
# belongs to (`list`: "rawdata", "general"; NA for gravcal's own), GGIR's
# default there (`ggir_default`, GGIR::load_params() of GGIR 3.3-9, recorded
# here: GGIR is only suggested and never asked at run time), what it changes
# in what GGIR::g.calibrate() returns and for which formats (`effect`), and
# gravcal's `status`:
#   "honoured"  g.calibrate() gives GGIR's result for the value (read by
#               the front doors through ggir_param_values()); where it
#               cannot, `effect` says so and g.calibrate() stops with an
#               error naming the parameter (ggir_params(), ggir_check_tz());
#   "no effect" it does not change what GGIR::g.calibrate() returns: taken
#               and left alone;
# The audit read GGIR 3.3-9's g.calibrate(), g.readaccfile(),
# g.inspectfile(), g.imputeTimegaps() and GGIRread 1.2.0's readAxivity() and
# readGENEActiv(). g.calibrate() never reads params_cleaning: every entry of
# it is "no effect" (not listed). The two front doors read names, defaults
# and checks from here: g.calibrate() through ggir_params(),
# calibrate(method = "ggir") through calibrate_ggir(). The constants behind
# the defaults, with their sources, are in ggir_constants (ggir.R).
# A function, so that it is built after ggir_constants whatever the order
# the package's files are read in.
ggir_param_table <- function() {
  k <- ggir_constants
  row <- function(ggir, own, default, check = NULL, status = "honoured",
                  list = if (is.na(ggir)) NA_character_ else "rawdata",
                  ggir_default = default, effect = "") {
    list(ggir = ggir, own = own, default = default, check = check,
         status = status, list = list, ggir_default = ggir_default,
         effect = effect)
  }
  # rows GGIR reads nowhere on g.calibrate()'s path, or only for output
  no_effect <- function(list, defaults, effect) {
    lapply(names(defaults), function(nm) {
      row(nm, NA, defaults[[nm]], status = "no effect", list = list,
          effect = effect)
    })
  }
  # rows of the ad hoc csv parameters: name, default, check, effect
  rmc_rows <- function(specs) {
    lapply(specs, function(r) {
      row(r[[1]], NA, r[[2]], r[[3]], effect = paste("ad hoc csv:", r[[4]]))
    })
  }
  at_least_0 <- function(x, arg) check_number(x, arg, min = 0)
  above_0 <- function(x, arg) check_number(x, arg, min = 0, min_inclusive = FALSE)
  tz_check <- function(x, arg) {
    if (!is.null(x) && !(is.character(x) && length(x) == 1 && !is.na(x))) {
      abort("`", arg, "` must be a time zone name (a string), not ", describe(x), ".")
    }
  }
  c(
    # in calibrate()'s order (its message for an unknown argument lists them)
    list(
      row(NA, "use_temp", TRUE, check_flag),
      row("spherecrit", "spherecrit", k$spherecrit, at_least_0,
          effect = "all formats: the sphere coverage test"),
      row("minloadcrit", "minloadcrit", k$minloadcrit, at_least_0,
          effect = "all formats: hours read before a fit can stop the reading"),
      row("chunksize", "chunksize", 1, function(x, arg) {
        check_number(x, arg, min = 0, max = 1, min_inclusive = FALSE)
      }, effect = "all formats: GGIR's block size, so the block boundaries"),
      row(NA, "max_sd", k$max_sd, above_0),
      row(NA, "max_iter", k$max_iter, function(x, arg) {
        check_number(x, arg, min = 1, max = .Machine$integer.max, integer = TRUE)
      }),
      row(NA, "tol", k$tol, at_least_0),
      row(NA, "verbose", FALSE, check_flag),
      row("printsummary", NA, FALSE, check_flag,
          effect = "prints a summary (with verbose = TRUE); the result is the same"),
      # GGIR reads rmc.noise (ad hoc csv files) only when given
      row("rmc.noise", NA, NULL, function(x, arg) if (!is.null(x)) above_0(x, arg),
          ggir_default = 13,
          effect = "ad hoc csv: the rest threshold (1.2 * rmc.noise)"),
      row("rmc.sf", NA, NULL, function(x, arg) if (!is.null(x)) above_0(x, arg),
          effect = "ad hoc csv: the sampling rate"),
      row("interpolationType", NA, 1, function(x, arg) {
        if (!(is.numeric(x) && length(x) == 1 && x %in% c(1, 2))) {
          abort("`", arg, "` must be 1 (linear) or 2 (nearest neighbour), not ",
                describe(x), ".")
        }
      }, effect = paste0(".cwa (readAxivity's resampling), GENEActiv .bin at a ",
                         "rate that is not whole (g.readaccfile's resampling), ",
                         "Parmay Matrix .bin (readParmayMatrix's resampling); ",
                         "Movisens (g.readtemp_movisens' temperature); ",
                         "Axivity csv, ad hoc csv with rmc.doresample")),
      row("frequency_tol", NA, 0.1, at_least_0,
          effect = ".cwa: readAxivity's tolerance on a block's rate before it imputes"),
      row("desiredtz", NA, "", tz_check, list = "general",
          effect = paste0(".cwa: the zone of readAxivity's block times (configtz ",
                          "when that is not given); a change of UTC offset ",
                          "(daylight saving) during the recording moves them; ",
                          "honoured, across such changes too (refused only where ",
                          "a block of GGIR's reading starts at a time that exists ",
                          "twice or not at all there, and with reader = ",
                          "\"reference\"). Ad hoc csv: time stamps only (rmc.desiredtz)")),
      row("configtz", NA, NULL, tz_check, list = "general",
          effect = "as desiredtz, which it replaces when given"),
      # checked where the source is opened (open_source())
      row("reader", "reader", "native", list = NA_character_),
      # calibrate(method = "ggir")'s ad hoc csv files: GGIR's rmc.* list
      row(NA, "rmc", NULL, function(x, arg) rmc_values(x, arg))
    ),
    no_effect("rawdata", list(
      do.cal = TRUE, backup.cal.coef = "retrieve", dynrange = NULL,
      minimumFileSizeMB = 2, nonwear_range_threshold = 150),
      "read by GGIR's g.part1 and later steps, not by g.calibrate()"),
    list(row("imputeTimegaps", NA, TRUE, status = "no effect",
             effect = paste0("g.calibrate() calls g.imputeTimegaps() with ",
                             "impute = FALSE whatever it is"))),
    # GGIR's ad hoc csv files (R/adhoc-csv.R; GGIR's read.myacc.csv):
    # GGIR 3.3-9's load_params() defaults; rmc.firstrow.acc makes a file one.
    # Values gravcal does not implement are refused where a file is read
    # (rmc_layout()).
    rmc_rows(list(
      list("rmc.firstrow.acc", NULL, rmc_whole, "the first row of samples; makes a csv file ad hoc"),
      list("rmc.firstrow.header", NULL, rmc_whole, "the header's first row"),
      list("rmc.header.length", NULL, rmc_whole, "the header's length"),
      list("rmc.col.acc", 1:3, function(x, arg) {
        if (!is.numeric(x) || length(x) != 3 || anyNA(x) || any(x < 1) ||
            any(x != round(x)) || anyDuplicated(x)) {
          abort("`", arg, "` must be 3 different column numbers, not ", describe(x), ".")
        }
      }, "the acceleration columns"),
      list("rmc.col.temp", NULL, rmc_whole, "the temperature column"),
      list("rmc.col.time", NULL, rmc_whole, "the time column (time stamps only)"),
      list("rmc.unit.acc", "g", rmc_choice(c("g", "mg", "bit")), "the acceleration unit"),
      list("rmc.unit.temp", "C", rmc_choice(c("C", "K", "F")), "the temperature unit"),
      list("rmc.unit.time", "POSIX",
           rmc_choice(c("POSIX", "character", "UNIXsec", "UNIXmsec", "ActivPAL")),
           "the time column's unit (time stamps only)"),
      list("rmc.format.time", "%Y-%m-%d %H:%M:%OS", rmc_string, "text time's format"),
      list("rmc.bitrate", NULL, rmc_number_or_name, "unit bit: the bits per sample"),
      list("rmc.dynamic_range", NULL, rmc_number_or_name, "unit bit: the range in g"),
      list("rmc.unsignedbit", TRUE, check_flag, "unit bit: unsigned or signed"),
      list("rmc.origin", "1970-01-01", rmc_string, "UNIX time's origin (time stamps only)"),
      # time zones move time stamps only, which the calibration does not use
      list("rmc.desiredtz", NULL, rmc_string, "time stamps only"),
      list("rmc.configtz", NULL, rmc_string, "time stamps only"),
      list("rmc.headername.sf", NULL, rmc_string, "the header's name of the rate"),
      list("rmc.headername.sn", NULL, rmc_string, "the header's serial number (not used)"),
      list("rmc.headername.recordingid", NULL, rmc_string, "the header's recording id (not used)"),
      list("rmc.header.structure", NULL, rmc_string, "how header names and values are separated"),
      list("rmc.check4timegaps", FALSE, check_flag,
           paste0("TRUE with a time column: honoured (each block's time gaps filled and ",
                  "zero samples dropped, as g.imputeTimegaps; UNIX s/ms, ActivPAL, text ",
                  "time read by %Y %y %m %d %H %M %S %OS %T, in a zone with daylight saving too); ",
                  "ISO 8601 text as \"POSIX\", repeated whole-second stamps, ActivPAL days ",
                  "through an hour desiredtz's clocks skip, a block whose first stamp exists twice or ",
                  "not at all in the zone, and reader = \"reference\" refused")),
      list("rmc.doresample", FALSE, check_flag, "TRUE with a UNIX, ActivPAL or text time column: honoured (block by block resampling; time as for rmc.check4timegaps)"),
      # a wear column: g.calibrate() does not use its flags, but GGIR's
      # reader stops on flags that are not TRUE/FALSE (rmc_check_wear())
      list("rmc.col.wear", NULL, rmc_whole,
           paste0("a wear column: its flags read as GGIR reads them, not used by g.calibrate(); ",
                  "flags that are not TRUE/FALSE, or with rmc.doresample, an error as GGIR's reader stops")),
      list("rmc.dec", ".", rmc_choice(c(".", ",")), "the decimal mark"),
      list("rmc.scalefactor.acc", 1, function(x, arg) check_number(x, arg),
           "a factor on the acceleration")
    )),
    no_effect("general", list(
      overwrite = FALSE, acc.metric = "ENMO", maxNcores = NULL,
      print.filename = FALSE, do.parallel = TRUE, windowsizes = c(5, 900, 3600),
      idloc = 1, dayborder = 0, part5_agg2_60seconds = FALSE,
      sensor.location = "wrist", expand_tail_max_hours = NULL,
      recordingEndSleepHour = NULL, dataFormat = "raw",
      maxRecordingInterval = NULL, extEpochData_timeformat = "%d-%m-%Y %H:%M:%S",
      recording_split_times = NULL, recording_split_timeformat = "%d/%m/%Y %H:%M",
      recording_split_overlap = 0, recording_split_ignore_edges = FALSE,
      use_trycatch_serial = FALSE),
      "read by GGIR's later steps, not on g.calibrate()'s path")
  )
}

# Checks of the rmc.* rows (NULL is each one's "not given").
rmc_whole <- function(x, arg) {
  if (!is.null(x)) check_number(x, arg, min = 1, integer = TRUE)
}
rmc_string <- function(x, arg) {
  if (!is.null(x) && !(is.character(x) && length(x) == 1 && !is.na(x))) {
    abort("`", arg, "` must be a string, not ", describe(x), ".")
  }
}
rmc_choice <- function(choices) {
  function(x, arg) {
    if (!(is.character(x) && length(x) == 1 && x %in% choices)) {
      abort("`", arg, "` must be one of ", paste0("\"", choices, "\"", collapse = ", "),
            ", not ", describe(x), ".")
    }
  }
}
rmc_number_or_name <- function(x, arg) {
  if (is.character(x)) rmc_string(x, arg) else if (!is.null(x)) check_number(x, arg, min = 0)
}

# The rmc.* parameters, checked, with GGIR's defaults: from `rmc` (a list;
# calibrate(), read_recording()) or from the values of g.calibrate()'s
# table. An unknown name is an error.
rmc_values <- function(rmc, arg = "rmc") {
  if (is.null(rmc)) return(NULL)
  if (!is.list(rmc) || (length(rmc) && is.null(names(rmc)))) {
    abort("`", arg, "` must be a named list of GGIR's rmc.* parameters, not ",
          describe(rmc), ".")
  }
  rows <- Filter(function(p) grepl("^rmc[.]", p$ggir), ggir_param_table())
  nms <- vapply(rows, `[[`, "", "ggir")
  bad <- setdiff(names(rmc), nms)
  if (length(bad)) {
    abort("Unknown parameter", if (length(bad) > 1) "s", " in `", arg, "`: ",
          paste0("`", bad, "`", collapse = ", "), ". Known: ", paste(nms, collapse = ", "), ".")
  }
  out <- stats::setNames(lapply(rows, `[[`, "default"), nms)
  for (nm in names(rmc)) out[nm] <- list(rmc[[nm]])
  for (p in rows) if (!is.null(p$check)) p$check(out[[p$ggir]], p$ggir)
  out
}

# The rows a front door takes: door "ggir" (g.calibrate()) or "own"
# (calibrate(method = "ggir")): the honoured ones under that door's name.
ggir_param_rows <- function(door) {
  Filter(function(p) !is.na(p[[door]]) && p$status == "honoured",
         ggir_param_table())
}

ggir_param_names <- function(door) {
  vapply(ggir_param_rows(door), `[[`, "", door)
}

# A front door's parameters under its own names: each the value in the last
# list of `given` that names it, else its default; then each checked, in
# the table's order (an error names the argument).
ggir_param_values <- function(door, given = list()) {
  rows <- ggir_param_rows(door)
  nms <- ggir_param_names(door)
  out <- stats::setNames(lapply(rows, `[[`, "default"), nms)
  for (g in given) {
    for (nm in intersect(nms, names(g))) out[nm] <- list(g[[nm]])
  }
  for (p in rows) {
    if (!is.null(p$check)) p$check(out[[p[[door]]]], p[[door]])
  }
  out
}

# The parameters g.calibrate() takes in `...`, by name: every row with a
# GGIR name.
ggir_param_known <- function() {
  rows <- Filter(function(p) !is.na(p$ggir), ggir_param_table())
  vapply(rows, `[[`, "", "ggir")
}

# Whether GGIR 3.3-9's g.calibrate() and g.getmeta() pass their parameters
# through extract_params() and so check_params(): when an argument comes
# in `...` or one of the parameter lists they take is not given (empty).
# g.part1() always does (it calls GGIR's own).
ggir_extracts <- function(dots, ...) {
  length(dots) > 0 || any(vapply(list(...), length, 0L) == 0)
}

# What GGIR 3.3-9's check_params() changes, of the values g.calibrate() and
# g.getmeta() read, in the lists it checks (`lists`: "rawdata", "general",
# "metrics"), on the parameters `p` (one list by name):
# * `chunksize` below 0.1 is taken as 0.1;
# * `windowsizes`: a long epoch that is not whole minutes is rounded up to
#   them; then a short epoch that does not divide the long one is taken as
#   the nearest of 1, 5, 10, 15, 20, 30 and 60 seconds; then a non-wear
#   window that is not a whole number of long epochs is rounded up to one
#   (each with a warning, as GGIR warns);
# * a `dataFormat` of epoch data (Actiwatch, PHB, UK Biobank) turns off the
#   metrics of raw data, on which GGIR's g.getmeta() computes nothing: an
#   error naming it.
ggir_check_values <- function(p, lists) {
  if ("rawdata" %in% lists) {
    cs <- p$chunksize
    if (is.numeric(cs) && length(cs) == 1 && !is.na(cs) && cs < 0.1) p$chunksize <- 0.1
  }
  ws <- p$windowsizes
  if ("general" %in% lists && is.numeric(ws) && length(ws) == 3 && !anyNA(ws) && all(ws > 0)) {
    said <- function(what, to) {
      warning("`windowsizes`: ", what, ", so GGIR's parameter check makes it ", to,
              " seconds (and so does gravcal's g.getmeta()).", call. = FALSE)
    }
    if (ws[2] / 60 != round(ws[2] / 60)) {
      ws[2] <- 60 * ceiling(ws[2] / 60)
      said("the long epoch is not a whole number of minutes", ws[2])
    }
    if (ws[2] / ws[1] != round(ws[2] / ws[1])) {
      steps <- c(1, 5, 10, 15, 20, 30, 60)
      d <- abs(steps - ws[1])
      near <- steps[d == min(d)]
      if (length(near) != 1) {
        abort("`windowsizes`: the short epoch of ", ws[1], " seconds does not divide the long ",
              "epoch, and GGIR's parameter check would replace it by two values at once (",
              paste(near, collapse = " and "), ": its windowsizes then has four); give a short ",
              "epoch that divides the long one.")
      }
      ws[1] <- near
      said("the short epoch does not divide the long one", ws[1])
    }
    if (ws[3] / ws[2] != round(ws[3] / ws[2])) {
      ws[3] <- ws[2] * ceiling(ws[3] / ws[2])
      said("the non-wear window is not a whole number of long epochs", ws[3])
    }
    p$windowsizes <- ws
  }
  epoch_data <- c("actiwatch_awd", "actiwatch_csv", "phb_xlsx", "ukbiobank")
  if (all(c("metrics", "general") %in% lists) && isTRUE(p$dataFormat %in% epoch_data)) {
    abort("`dataFormat` = \"", p$dataFormat, "\": epoch data, not raw samples; GGIR's parameter ",
          "check then turns off the metrics of raw data, and g.getmeta() has nothing to compute ",
          "(GGIR's GGIR() reads such files without part 1's g.getmeta()).")
  }
  p
}
