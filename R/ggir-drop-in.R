# GGIR's front doors: g.calibrate() (the drop-in, GGIR's arguments and
# list) and calibrate(method = "ggir") (a gravcal_fit), both on the one
# procedure (ggir_run(), R/ggir.R).

#' Auto-calibration as GGIR's g.calibrate, on gravcal's core
#'
#' A drop-in replacement for `GGIR::g.calibrate()`: same arguments, same
#' procedure, same returned list, computed by gravcal's streaming C++ core.
#' It reads the recording in GGIR's blocks (about 12 hours; `chunksize`
#' scales them) and keeps whole hours only (the rest carries to the next
#' block; the last partial hour is dropped), removes idle-sleep samples (x =
#' y = z = 0), cuts 10-second windows, drops duplicate windows and the first
#' window, keeps the rest windows (sd below 13 mg and |mean| below 2 g on all
#' axes), checks that the sphere is covered (`spherecrit`), fits scale,
#' offset and temperature offset by weighted iterative closest point and,
#' after each block, decides whether to read on (`minloadcrit` hours). Every
#' rule is GGIR's, including the ones that look like accidents; see
#' [calibrate()] with `method = "ggir"` for gravcal's corrected variant.
#'
#' The returned numbers are GGIR's to the last bit (the window statistics
#' are computed in R's arithmetic, the fit with R's own least-squares
#' routine); the work is one pass over the samples in C++, without copying
#' them, so a week at 100 Hz held in memory takes about a second, some 55
#' times less than GGIR, and needs little memory beyond the input (the
#' window table and at most an hour of samples carried between blocks);
#' from a file, one block at a time. Figures: `bench/results/speed.md` in
#' the package sources.
#'
#' Where GGIR itself does not give a result, or gives one by accident, this
#' function departs from it, and says so: when a fit does not stay finite
#' (a temperature term the rest windows cannot determine), GGIR stops with
#' an error and `g.calibrate()` returns no correction with a QC message
#' that says why; GGIR's fits after intermediate blocks that cannot stop
#' the reading are skipped, so an error in one of those does not stop it
#' either. A missing (`NA`) or infinite sample in a data frame is left out
#' of its window (in GGIR's cumulative sums it would empty the rest of its
#' block); one read from a file (GGIRread's resampling gives `NaN` where
#' time stamps repeat, as whole-second ones do) enters the sums as in GGIR.
#' For a data frame, `rmc.noise` sets
#' the rest threshold as for an ad hoc csv file (`1.2 * rmc.noise`).
#'
#' Unlike GGIR's, this function does not need `inspectfileobject` (it finds
#' the format and sampling rate itself) but accepts GGIR's; and `datafile`
#' may also be a data frame of raw samples (columns `x`, `y`, `z` in g,
#' optional `temperature`), read in the blocks GGIR uses for csv files, with
#' the sampling rate given as `sf = ` in `...` (or from a `time` column).
#'
#' Formats: ActiGraph csv exports, Axivity csv exports (OMGUI: UNIX time
#' stamps, or text ones read as GGIR reads them, ISO 8601 date-times as
#' `data.table::fread()` computes them and other text as `as.POSIXct()`
#' does; resampled block by block as GGIR does, linearly; OMGUI's optional
#' header line, on which GGIR's reader stops, is refused), csv files with
#' `x`, `y`, `z` columns, ad hoc csv files (below), `.rds` data frames, ActiGraph `.gt3x`, Axivity `.cwa`, GENEActiv
#' `.bin`, Parmay Matrix `.bin` and Movisens recordings (the unisens folder or,
#' as GGIR takes it, its `acc.bin`; at 64 Hz, the rate GGIR assumes for them:
#' another rate is an error). A GENEActiv csv export, which GGIR no longer reads
#' (its `g.inspectfile()` stops), is refused as GGIR refuses it, the error naming
#' the `rmc.*` parameters that read it as an ad hoc csv file (GGIR's advice). The other formats are read by gravcal's own decoders, which give what GGIR's
#' readers give (GGIRread's resampling of `.cwa` included), block by block
#' as GGIR reads them, in bounded memory. Where GGIR's reader stops on a
#' damaged `.cwa` or GENEActiv file (and loses the block of its reading that
#' holds the damage), or cannot open a `.gt3x` file cut short (or reads its
#' damaged records otherwise) or an ActiGraph csv export's damaged lines, this
#' function stops too, saying where; `calibrate()`
#' keeps the good samples of such a file. `reader = "reference"` in `...` reads
#' through GGIR's readers themselves (GGIRread, read.gt3x, data.table).
#'
#' @section GGIR's parameters:
#' Every parameter of GGIR 3.3-9's `params_rawdata` and `params_general`
#' that can change what `GGIR::g.calibrate()` returns, and what this
#' function does with it (the package's one table of them is
#' `R/ggir-params.R`). The others (`do.cal`, `backup.cal.coef`, `dynrange`,
#' `minimumFileSizeMB`, `nonwear_range_threshold`, `imputeTimegaps`, the
#' rest of `params_general` and all of `params_cleaning`) do not change
#' it, and are taken and left alone.
#'
#' | parameter | changes GGIR's result for | here |
#' |---|---|---|
#' | `chunksize`, `spherecrit`, `minloadcrit` | every format | honoured |
#' | `printsummary` | (prints only) | honoured |
#' | `interpolationType` (1 linear, 2 nearest neighbour) | `.cwa`; GENEActiv `.bin` at a rate that is not whole; Parmay Matrix `.bin`; Movisens (its temperature); Axivity csv; ad hoc csv with `rmc.doresample` | honoured (an error with `reader = "reference"` unless 1) |
#' | `frequency_tol` | `.cwa` | honoured (an error with `reader = "reference"` unless 0.1) |
#' | `desiredtz`, `configtz` | `.cwa` (the zone of its block times) | honoured, across changes of UTC offset (daylight saving) too, by the zone rules of the R it runs in; an error naming it only where a block of GGIR's reading starts or ends at a calendar time that exists twice or not at all in that zone, and with `reader = "reference"` where the offset changes |
#' | `desiredtz`, `configtz` | Axivity csv (the zone GGIR reads or forces its time stamps in) | honoured: text that is not ISO 8601 as `as.POSIXct()` reads it in the zone, across changes of offset too; UNIX and ISO 8601 stamps forced into the zone as GGIR forces them (`lubridate::force_tz()`), across changes of offset too (in spring GGIR's samples are NA from the skipped hour to its block's end, and so are gravcal's); an error naming it where one of GGIR's blocks starts or ends in that hour, as GGIR stops there |
#' | `rmc.noise`, `rmc.sf` | ad hoc csv | honoured (also for data frames) |
#' | other `rmc.*` | ad hoc csv | see "Ad hoc csv files" |
#'
#' @section Ad hoc csv files (GGIR's `rmc.*` parameters):
#' With `rmc.firstrow.acc` in `params_rawdata`, the file is read as GGIR
#' reads an "ad hoc" csv file, by gravcal's csv decoder in GGIR's blocks:
#'
#' | parameter | |
#' |---|---|
#' | `rmc.firstrow.acc` | honoured: line of the first sample (GGIR starts one line later when that line's first field is not a number) |
#' | `rmc.col.acc`, `rmc.col.temp` | honoured |
#' | `rmc.unit.acc` | honoured: `"g"`, `"mg"`, `"bit"` (with `rmc.bitrate`, `rmc.dynamic_range`, `rmc.unsignedbit`; the first two may name header rows) |
#' | `rmc.scalefactor.acc` | honoured |
#' | `rmc.unit.temp` | honoured: `"C"`, `"K"` (GGIR adds 272.15), `"F"` |
#' | `rmc.sf`, `rmc.firstrow.header`, `rmc.header.length`, `rmc.headername.sf`, `rmc.header.structure` | honoured: the sampling rate from the header, else `rmc.sf` |
#' | `rmc.dec` | honoured (`","` with `;` or tab separated fields) |
#' | `rmc.noise` | honoured: rest is sd below `1.2 * rmc.noise` (GGIR's default 13 when not given) |
#' | `rmc.col.time`, `rmc.unit.time`, `rmc.format.time`, `rmc.origin` | accepted (the calibration does not use time, except with `rmc.doresample` and `rmc.check4timegaps`); a text time that `rmc.format.time` does not read is an error (GGIR then reads no data) |
#' | `rmc.desiredtz`, `rmc.configtz`, `rmc.headername.sn`, `rmc.headername.recordingid` | accepted: no effect on the calibration (text time is read in `configtz`, else `desiredtz`, as GGIR's g.readaccfile() hands them to read.myacc.csv, whatever `rmc.configtz` and `rmc.desiredtz` say) |
#' | `rmc.col.wear` | its flags read as GGIR's reader reads them (TRUE/FALSE, true/false or True/False, one spelling per block; empty or NA for none): no effect on the calibration; flags it does not read as TRUE/FALSE (1/0, say), or with `rmc.doresample`, an error, as GGIR's reader stops ("Corrupt file") |
#' | `rmc.doresample = TRUE` with a time column | honoured for UNIX seconds or milliseconds, ActivPAL days (as for `rmc.check4timegaps`) and text time (`"character"`, `"POSIX"`, read by `rmc.format.time` as for `rmc.check4timegaps`): every block resampled from its first time stamp to its last at the rate, as `interpolationType` says; the time `rmc.check4timegaps` refuses, refused with an error |
#' | `rmc.check4timegaps = TRUE` with a time column | honoured: in each block of lines, samples with x = y = z = 0 dropped (the block's first becomes 0, 0, 1, its last takes the values before it) and every step of at least 0.25 s (or 2 / sf) filled by repeating the sample before it (normalised when its norm exceeds 1.005), as GGIR's `g.imputeTimegaps()` does, before `rmc.doresample`; a gap between two blocks stays, as in GGIR. For UNIX seconds or milliseconds, ActivPAL days, and text time read by `rmc.format.time` with `%Y %y %m %d %H %M %S %OS %T` in the zone `configtz`, else `desiredtz` (across changes of its UTC offset too, as for `.cwa`). Refused with an error: other directives, ActivPAL days through an hour the clocks of `desiredtz` skip (into which GGIR forces them with `lubridate::force_tz()`, which gives NA there; across the other changes honoured), a block of GGIR's reading whose first stamp exists twice or not at all in the zone, ISO 8601 text time as `"POSIX"` with fractions of a second (GGIR reads it through `fread()`, which drops them; `"character"` keeps them), whole-second text stamps that repeat, `reader = "reference"` |
#'
#' @param datafile Path of the recording, or a data frame of raw samples.
#' @param params_rawdata,params_general,params_cleaning GGIR's parameter
#'   lists (as from `GGIR::load_params()`); see "GGIR's parameters" for the
#'   ones that change the result. Missing entries take GGIR's defaults
#'   (`chunksize = 1`, `spherecrit = 0.3`, `minloadcrit = 168`,
#'   `printsummary = FALSE`, `interpolationType = 1`, `frequency_tol = 0.1`,
#'   `desiredtz = ""`).
#' @param inspectfileobject Optional: GGIR's `g.inspectfile()` result; its
#'   `sf` is used. One that names another format than the file's (its
#'   `monc`, `dformc`), decimal commas for a csv export, or no `sf` is an
#'   error saying so.
#' @param verbose Print progress (the blocks read) as GGIR does.
#' @param ... Legacy arguments that override the parameter lists, as in
#'   GGIR (any parameter of the lists by name, e.g. `chunksize`,
#'   `interpolationType`), `sf` for a data frame, and `reader` (`"native"`,
#'   the default, or `"reference"`).
#' @return GGIR's list: `scale`, `offset`, `tempoffset` (empty when no fit
#'   ran), `cal.error.start`, `cal.error.end` (rounded to 5 digits),
#'   `spheredata` (the rest windows: `Euclidean Norm, meanx, meany, meanz,
#'   sdx, sdy, sdz` and `temperature` when used), `npoints`, `nhoursused`,
#'   `QCmessage`, `use.temp`, `meantempcal` and `bsc_qc` (time and memory
#'   in MB after each block: the process's resident memory where the system
#'   reports it, as on Linux, else R's heap; GGIR records R's heap). Invisibly,
#'   as GGIR.
#' @seealso [calibrate()] (`method = "ggir"`) for a `gravcal_fit`,
#'   [write_coefs()] to hand coefficients to GGIR.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 30, sf = 10, seed = 4)
#' C <- g.calibrate(rec, sf = 10, verbose = FALSE)
#' C$QCmessage
#' C$scale
#' C$offset
g.calibrate <- function(datafile, params_rawdata = c(), params_general = c(),
                        params_cleaning = c(), inspectfileobject = c(),
                        verbose = TRUE, ...) {
  dots <- list(...)
  if (length(dots) && (is.null(names(dots)) || any(names(dots) == ""))) {
    abort("All arguments in `...` must be named.")
  }
  pr <- ggir_params(params_rawdata, params_general, dots,
                    checked = ggir_extracts(dots, params_rawdata, params_general,
                                            params_cleaning))
  check_flag(verbose, "verbose")
  check_fp_build("`g.calibrate()`")
  sf <- dots$sf
  if (length(inspectfileobject) && !is.list(inspectfileobject)) {
    abort("`inspectfileobject` must be a list (GGIR's g.inspectfile() result), ",
          "not ", describe(inspectfileobject), ".")
  }
  sf_arg <- "sf"
  if (is.null(sf) && length(inspectfileobject) && !is.null(inspectfileobject$sf)) {
    sf <- inspectfileobject$sf
    sf_arg <- "inspectfileobject$sf"
    check_number(sf, "inspectfileobject$sf", min = 0, min_inclusive = FALSE)
  }
  if (is.null(sf) && length(pr$rmc.sf)) sf <- pr$rmc.sf
  # rmc.firstrow.acc: an ad hoc csv file, read by the rmc.* parameters
  rmc <- if (!is.null(pr$rmc.firstrow.acc) && is.character(datafile)) {
    pr[grepl("^rmc[.]", names(pr))]
  }
  # the zone GGIR reads text time in (rmc.check4timegaps): configtz, else
  # desiredtz, as g.readaccfile() hands them to read.myacc.csv
  if (!is.null(rmc)) rmc <- rmc_with_zone(rmc, pr)
  if (length(inspectfileobject) && is.character(datafile)) {
    ggir_check_inspect(inspectfileobject, datafile, adhoc = !is.null(rmc))
  }
  # the zone of a .cwa file's calendar times (readAxivity's configtz, else
  # desiredtz): offsets that change (daylight saving) move block times
  tz <- if (length(pr$configtz)) pr$configtz else pr$desiredtz
  tz_arg <- if (length(pr$configtz)) "configtz" else "desiredtz"
  read_opts <- list(interpolation = pr$interpolationType,
                    frequency_tol = pr$frequency_tol, zone = tz %||% "", zone_arg = tz_arg)
  open <- function() {
    open_source(datafile, sf = sf, chunksize = pr$chunksize,
                reader = pr$reader, compat = TRUE, read_opts = read_opts, rmc = rmc,
                sf_arg = sf_arg)
  }
  src <- open()
  if (is.null(src$native)) ggir_check_tz(src, datafile, pr$desiredtz, pr$configtz)
  # GGIR uses rmc.noise only for ad hoc csv files (its "AD_HOC" monitor),
  # with GGIR's default (load_params(): 13) where the list has none;
  # samples in a data frame, which GGIR does not take, are treated alike
  noise <- if (identical(src$format, "data.frame")) "given" else format_entry(src$format)$ggir_noise
  sdcriter <- if (identical(noise, "default")) {
    (pr$rmc.noise %||% ggir_constants$rmc_noise) * 1.2
  } else if (identical(noise, "given") && !is.null(pr$rmc.noise)) {
    pr$rmc.noise * 1.2
  } else {
    ggir_constants$max_sd
  }
  out <- ggir_run_exact(src, open, compat = TRUE, spherecrit = pr$spherecrit,
                        minloadcrit = pr$minloadcrit,
                        sdcriter = sdcriter, verbose = verbose,
                        printsummary = pr$printsummary)
  # where GGIR's reader stops, or reads what the decoder does not follow
  # (GENEActiv: damaged pages)
  stops <- format_entry(src$format)$ggir_read_stops
  why <- if (!is.null(stops) && !is.null(src$native)) stops(src, "calibrate")
  if (!is.null(why)) {
    abort("\"", basename(datafile), "\" (`datafile`) has ", why, ": GGIR's g.calibrate() ",
          "gives no result there that gravcal reproduces, so gravcal's refuses the file ",
          "(calibrate() reads it).")
  }
  if (identical(src$format, rmc_format()) && !is.null(rmc)) {
    ggir_check_zone_read(src, attr(rmc, "tz") %||% "", attr(rmc, "tz_arg"))
    rmc_check_wear(src)
  } else {
    ggir_check_zone_read(src, tz %||% "", tz_arg)
    ggir_check_nan_edge(src, tz %||% "", tz_arg)
  }
  attr(out, "gravcal") <- NULL
  invisible(out)
}

# The format GGIR's g.inspectfile() result `I` names by its monitor and
# data format codes (monc, dformc; GGIR's MONITOR and FORMAT), as the
# registry's name (R/formats.R); NA for a pair gravcal has none for, NULL
# when `I` has no such codes.
ggir_inspect_format <- function(I) {
  mon <- I$monc
  dform <- I$dformc
  if (!is.numeric(mon) || !is.numeric(dform) || length(mon) != 1 || length(dform) != 1) {
    return(NULL)
  }
  if (isTRUE(mon == 6)) mon <- 3  # Verisense: read as ActiGraph
  code <- paste(mon, dform)
  hit <- names(Filter(function(f) code %in% f$ggir_codes, recording_formats))
  if (length(hit)) hit[1] else NA_character_
}

# g.calibrate() follows an `inspectfileobject` (GGIR's g.inspectfile()
# result) where GGIR's g.calibrate() would: its sf (used as the rate), and
# its format, which decides GGIR's reader. One that gravcal cannot honour
# is an error naming what, never a quiet "not enough data": a format other
# than the one gravcal reads the file as (the object of another file, or
# rmc.firstrow.acc given on one side only), decimal commas in a csv export
# read with decimal points, no sf (GGIR's g.calibrate() then returns
# nothing).
ggir_check_inspect <- function(I, datafile, adhoc) {
  claimed <- ggir_inspect_format(I)
  if (!is.null(claimed)) {
    file <- unisens_acc(datafile)
    check_file(file, "datafile")
    actual <- if (adhoc) rmc_format() else tryCatch(file_format(file, "datafile"),
                                                   error = function(e) NA_character_)
    if (!identical(claimed, actual)) {
      what <- if (is.na(claimed)) "a format gravcal does not read" else format_entry(claimed)$label
      abort("`inspectfileobject` (monc = ", I$monc, ", dformc = ", I$dformc, ": ", what,
            ") does not describe \"", basename(datafile), "\", which gravcal reads as ",
            if (is.na(actual)) "no format it knows" else format_entry(actual)$label,
            if (adhoc) " (rmc.firstrow.acc is given)",
            "; GGIR would read it with the reader the object names. Give ",
            "GGIR::g.inspectfile()'s result for this file with the same parameters, or ",
            "leave `inspectfileobject` out.")
    }
    if (isTRUE(format_entry(claimed)$ggir_decimal) && identical(I$decn, ",")) {
      abort("`inspectfileobject$decn` = \",\": GGIR would read the values of \"",
            basename(datafile), "\" with decimal commas; gravcal reads this csv export ",
            "with decimal points.")
    }
  }
  if (is.null(I$sf)) {
    abort("`inspectfileobject` has no `sf`: GGIR's g.calibrate() returns nothing for it. ",
          "Give GGIR::g.inspectfile()'s result for this file, or leave `inspectfileobject` out.")
  }
  invisible()
}

# g.calibrate()'s parameters (ggir-params.R) from GGIR's params_rawdata and
# params_general (each parameter from its own list, as GGIR reads it) and
# the legacy arguments in `dots`, which win; other parameters GGIR takes
# (the table's rows, params_cleaning's) are accepted, anything else in
# `dots` warned about.
ggir_params <- function(params_rawdata, params_general, dots, checked = FALSE) {
  for (a in c("params_rawdata", "params_general")) {
    v <- get(a)
    if (length(v) && !is.list(v)) {
      abort("`", a, "` must be a list (as from GGIR::load_params()), ",
            "not ", describe(v), ".")
    }
  }
  rows <- ggir_param_rows("ggir")
  from <- function(lst, which) {
    nms <- vapply(Filter(function(p) identical(p$list, which), rows), `[[`, "", "ggir")
    lst[intersect(names(lst), nms)]
  }
  known <- c(ggir_param_known(), "sf", "use.temp", "outputdir", "studyname")
  extra <- setdiff(names(dots), known)
  over <- intersect(extra, ggir_over_time_names)
  if (length(over)) {
    abort("g.calibrate(): ", paste0("`", over, "`", collapse = ", "),
          ": GGIR's g.calibrate() has no such parameter (coefficients per ",
          "segment of time and the adaptive budget are gravcal's own mode's: ",
          "calibrate(method = \"ggir\"), ggir_compat = FALSE).")
  }
  if (length(extra)) {
    warning("g.calibrate(): ignored argument", if (length(extra) > 1) "s",
            " ", paste0("`", extra, "`", collapse = ", "), call. = FALSE)
  }
  out <- ggir_param_values("ggir", list(from(params_rawdata, "rawdata"),
                                        from(params_general, "general"), dots))
  if (checked) out <- ggir_check_values(out, "rawdata")
  out
}

# After a GGIR-compatible .cwa or ad hoc csv read in a zone whose offset
# changes: a block of GGIR's reading that starts (or, .cwa, ends) at a
# calendar time that exists twice or not at all there (R/zone.R) has a time
# that depends on R's conversions before it, which gravcal does not know:
# an error naming the parameter.
ggir_check_zone_read <- function(src, tz, arg) {
  if (!isTRUE(format_entry(src$format)$ggir_zone_ambiguous)) return(invisible())
  zone_block_stop(src, "zone_ambiguous", tz, arg,
                  "at a time that exists twice or not at all in that zone (a change of UTC offset), ",
                  "where GGIR's time depends on R's conversions before it; gravcal does not ",
                  "reproduce that")
}

# After a read of an Axivity csv export through an hour its zone's clocks
# skip (GGIR forces the stamps into the zone: NA there): where one of
# GGIR's blocks starts or ends with such a stamp, GGIR's seq() of the
# block's grid stops ("'from' (or 'to') must be a finite number"); so
# does gravcal, naming the parameter.
ggir_check_nan_edge <- function(src, tz, arg) {
  zone_block_stop(src, "resample_nan_edge", tz, arg,
                  "in the hour that zone's clocks skip (daylight saving), where GGIR's time ",
                  "stamps are NA (lubridate::force_tz()) and its resampling of the block stops; ",
                  "gravcal's stops too")
}

# The error of the two checks above, where the source's report counts
# `counter`: the zone parameter `arg` = `tz`, "a block of GGIR's reading
# of this file starts or ends " and `...`, and what to do.
zone_block_stop <- function(src, counter, tz, arg, ...) {
  if (is.null(src$report)) return(invisible())
  n <- src$report()$counters[counter]
  if (isTRUE(n > 0)) {
    abort("`", arg, "` = \"", tz, "\"", if (!nzchar(tz)) " (the session's time zone)",
          ": a block of GGIR's reading of this file starts or ends ", ..., ". Give a zone ",
          "without a change there (\"UTC\", or a fixed offset such as \"Etc/GMT-1\"), or ",
          "another `chunksize`.")
  }
  invisible()
}

# desiredtz / configtz (GGIR's params_general) for a .cwa file read by
# GGIR's own reader (reader = "reference"): readAxivity
# converts each block's calendar time to seconds in that zone (configtz,
# else desiredtz; "" is the session's zone); gravcal's decoder converts in
# UTC. A constant offset moves every time by the same whole seconds, which
# leaves GGIR's resampling and so its result to the bit unchanged (times of
# 2004 to 2038 share one floating-point exponent); a change of offset
# (daylight saving) during the recording moves the blocks after it, which
# gravcal does not reproduce: an error naming the parameter. The span looked
# at is the first block's time to the last block's (calendar times read as
# UTC), 15 hours either side (more than any zone's offset).
ggir_check_tz <- function(src, datafile, desiredtz, configtz) {
  if (!isTRUE(format_entry(src$format)$ggir_calendar) || !is.character(datafile)) return(invisible())
  tz <- if (length(configtz)) configtz else desiredtz
  arg <- if (length(configtz)) "configtz" else "desiredtz"
  span <- cwa_time_span(datafile)
  if (is.null(span)) return(invisible())
  # calendar times every half hour, converted as readAxivity converts them
  # (as.POSIXct() of the text in the zone): by how much each moves
  at <- seq(span[1] - 15 * 3600, span[2] + 15 * 3600, by = 1800)
  txt <- format(as.POSIXct(at, origin = "1970-01-01", tz = "UTC"), "%Y-%m-%d %H:%M:%S")
  off <- at - as.numeric(as.POSIXct(txt, tz = tz))
  if (anyNA(off) || length(unique(off)) > 1) {
    abort("`", arg, "` = \"", tz, "\"", if (!nzchar(tz)) " (the session's time zone)",
          ": the recording spans a change of UTC offset in that zone (daylight ",
          "saving), which moves GGIR's .cwa block times; gravcal's decoder reads ",
          "them in UTC and does not reproduce that. Give a zone without a ",
          "change there (\"UTC\", or a fixed offset such as \"Etc/GMT-1\").")
  }
  invisible()
}

# The first and last block times of a .cwa file (seconds since 1970, read
# as UTC) from the first and the last whole block's packed time; one for
# both when the other is not a date; NULL when neither is.
cwa_time_span <- function(file) {
  size <- file.size(file)
  if (is.na(size) || size < 1024 + 512) return(NULL)
  con <- file(file, "rb")
  on.exit(close(con))
  at <- function(block) {
    seek(con, 1024 + 512 * block + 14)
    b <- as.numeric(readBin(con, "raw", 4))
    coded <- sum(b * 256^(0:3))
    field <- function(shift, bits) (coded %/% 2^shift) %% 2^bits
    as.numeric(ISOdatetime(2000 + field(26, 6), field(22, 4), field(17, 5),
                           field(12, 5), field(6, 6), field(0, 6), tz = "UTC"))
  }
  t <- c(at(0), at((size - 1024) %/% 512 - 1))
  t <- t[is.finite(t)]
  if (!length(t)) return(NULL)
  range(t)
}

# calibrate(method = "ggir"): the procedure, then a gravcal_fit. `over`:
# the choices beyond one fit (ggir_over_time(); NULL: none).
calibrate_ggir <- function(x, sf, compat, dots, call, over = NULL) {
  d <- split_dots(dots, list(ggir = ggir_param_names("own"),
                             guards = c("max_norm_error", "range_g",
                                        "max_identical", "off_sphere")))
  args <- d$ggir
  a <- ggir_param_values("own", list(args))
  # own mode's guards on rest windows; GGIR-compatible mode keeps GGIR's
  # rules, so a guard given there is an error, not ignored
  if (compat && length(d$guards)) {
    abort("`", names(d$guards)[1], "` is for gravcal's own mode: with ",
          "`ggir_compat = TRUE` the rest windows are GGIR's.")
  }
  guards <- if (!compat) guard_args(d$guards)
  if (compat) check_fp_build("`calibrate(method = \"ggir\", ggir_compat = TRUE)`")
  if (is.null(sf) && !is.character(x) && is.null(attr(x, "sf")) &&
      !("time" %in% tolower(colnames(x)))) {
    abort("`sf` (sampling frequency in Hz) is missing.")
  }
  open <- function() {
    src <- open_source(x, sf = sf, chunksize = a$chunksize, arg = "x",
                       reader = a$reader, compat = compat,
                       rmc = if (is.character(x)) rmc_values(a$rmc))
    if (!a$use_temp) src <- source_with(src, temperature = FALSE)
    src
  }
  src <- open()
  if (!compat && is.null(guards$range_g) && is.numeric(src$info$range_g) &&
      length(src$info$range_g) == 1) {
    guards$range_g <- src$info$range_g
  }
  res <- ggir_run_exact(src, open, compat = compat, spherecrit = a$spherecrit,
                        minloadcrit = a$minloadcrit, sdcriter = a$max_sd,
                        verbose = a$verbose, max_iter = a$max_iter, tol = a$tol,
                        guards = guards,
                        reading = ggir_reading(over),
                        check_hours = over$check_hours %||% 6,
                        on_fit = if (identical(over$budget, "adaptive")) {
                          ggir_budget_rule(over$target_se, a$minloadcrit)
                        })
  ex <- attr(res, "gravcal")$excluded
  early <- isTRUE(attr(res, "gravcal")$early)
  temp_warn <- attr(res, "gravcal")$temperature_warnings
  fit <- ggir_fit(res, compat, call, a$minloadcrit)
  if (!compat) {
    # rest that is not rest (near-rest.R): windows far off the sphere after
    # the fit are left out and the fit done again on the others
    if (fit$status %in% c("ok", "high_error") && NROW(res$spheredata) > 0 &&
        is.finite(guards$off_sphere)) {
      fit <- ggir_near_rest(res, fit, a, src$sf, call,
                            clock = near_rest_clock(x, fit$input),
                            k = guards$off_sphere)
    }
    fit$excluded <- stats::setNames(as.integer(ex[excluded_reasons]),
                                    excluded_reasons)
    fit$guards <- list(max_norm_error = guards$max_norm_error,
                       range_g = if (is.null(guards$range_g)) NA_real_ else
                         guards$range_g,
                       max_identical = guards$max_identical)
    if (fit$status == "no_rest" && sum(fit$excluded) > 0) {
      fit$message <- paste0("all rest windows were left out (",
                            format_excluded(fit$excluded, fit$guards), ") [GGIR: ",
                            fit$QCmessage, "]")
    }
    # GGIR's rule removes idle-sleep zeros (x = y = z = 0) before the
    # windows: when they are all there is, the recording is empty, not short
    # (compatible mode keeps GGIR's words)
    n <- attr(res, "gravcal")$samples
    zeros <- attr(res, "gravcal")$zeros
    if (fit$status == "too_short" && length(zeros) == 1 && zeros > 0) {
      if (zeros >= n) {
        fit$status <- "all_zero"
        fit$message <- sprintf(paste0(
          "no data: all %.0f samples are exactly 0 on all three axes ",
          "(ActiGraph idle sleep, or a device that recorded nothing); there ",
          "is nothing to calibrate [GGIR: %s]"), n, fit$QCmessage)
      } else {
        fit$message <- sprintf(paste0(
          "fewer distinct 10 s windows than the procedure needs: of %.0f ",
          "samples, %.0f are exactly 0 on all three axes (removed as idle ",
          "sleep) [GGIR: %s]"), n, zeros, fit$QCmessage)
      }
    }
  }
  if (!is.null(fit$input) && is.numeric(src$sf)) fit$input$sf <- src$sf
  if (is.character(x)) fit$file <- basename(x)
  fit <- ggir_over_time_fit(fit, over, a, src$sf, early,
                            hours_total = if (!is.character(x)) {
                              NROW(x) / src$sf / 3600
                            })
  # a stuck or implausible temperature sensor (gravcal's own mode, see
  # ?plausible_bounds): where the procedure left the temperature out because
  # a block's does not vary, or its first values exceed GGIR's 120, the rest
  # windows of the whole recording say whether it ever varies and what it
  # reads (a second pass of the segmenter, only then)
  if (!compat) {
    temps <- NULL
    if (isTRUE(src$temperature) && any(grepl("does not vary|exceed", temp_warn))) {
      temps <- tryCatch({
        w <- rest_windows(x, sf = src$sf, method = "ggir", reader = a$reader,
                          rmc = if (is.character(x)) a$rmc)
        w$temperature[w$rest]
      }, error = function(e) NA_real_)
    }
    fit$temperature_check <- temperature_check(
      fit_hours(fit), isTRUE(src$temperature), temps = temps,
      flat = if (is.null(temps)) FALSE, mean_temp = fit$meantemp)
  }
  fit
}

# GGIR's result as a gravcal_fit, with a status code beside GGIR's message.
ggir_plausible <- function(scale, offset, tempoffset) {
  to <- if (length(tempoffset)) tempoffset else 0
  all(is.finite(c(scale, offset, to))) &&
    all(scale >= plausible$scale[1] & scale <= plausible$scale[2]) &&
    all(abs(offset) <= plausible$offset) && all(abs(to) <= plausible$temp)
}

ggir_fit <- function(res, compat, call, minloadcrit) {
  info <- attr(res, "gravcal")
  attr(res, "gravcal") <- NULL
  sd <- res$spheredata
  pts <- NULL
  if (length(sd) > 0 && nrow(sd) > 0) {
    pts <- data.frame(mean_x = sd[[2]], mean_y = sd[[3]], mean_z = sd[[4]],
                      sd_x = sd[[5]], sd_y = sd[[6]], sd_z = sd[[7]],
                      mean_norm = sd[[1]],
                      temperature = if (isTRUE(res$use.temp)) sd[[8]] else NA_real_)
  }
  qc <- res$QCmessage
  key <- names(ggir_messages)[match(qc, ggir_messages)]
  icp <- info$icp
  status <- switch(key,
    done = , done_no_temp = "ok",
    attempted = if (!is.null(res$cal.error.end) && res$cal.error.end < ggir_constants$max_error) "ok" else "high_error",
    no_decrease = "no_improvement",
    no_sphere = "sphere_not_covered",
    no_rest = "no_rest",
    no_data = "too_short",
    not_finite = "diverged")
  if (!is.null(icp) && !isTRUE(icp$finite)) status <- "diverged"
  detail <- switch(status,
    ok = if (identical(key, "attempted")) sprintf(
      "calibrated on all %g hours of the recording (fewer than minloadcrit = %g hours)",
      res$nhoursused, minloadcrit) else "",
    high_error = sprintf(paste0(
      "coefficients kept, as GGIR applies them, but the error after ",
      "calibration is %.2f mg (GGIR accepts < 10 mg)"), 1000 * res$cal.error.end),
    too_short = "fewer distinct 10 s windows than the procedure needs",
    diverged = "the fit did not stay finite", "")
  # gravcal's own mode does not apply coefficients outside the ranges real
  # devices show (GGIR, and so compatible mode, applies them)
  if (!compat && status %in% c("ok", "high_error") &&
      !ggir_plausible(res$scale, res$offset, res$tempoffset)) {
    status <- "implausible"
    detail <- paste0("calibration not applied: coefficients outside plausible ",
                     "ranges (scale ", plausible$scale[1], "-", plausible$scale[2],
                     ", |offset| <= ", plausible$offset, " g, |temperature offset| <= ",
                     plausible$temp, " g per degree C)")
  }
  applied <- status %in% c("ok", "high_error")
  fit <- new_fit(
    K = if (applied) diag(res$scale, 3) else diag(3),
    offset = if (applied) res$offset else c(0, 0, 0),
    tempoffset = if (applied && length(res$tempoffset)) res$tempoffset else c(0, 0, 0),
    meantemp = if (length(res$meantempcal)) res$meantempcal else NA_real_,
    points = pts, method = "ggir",
    iterations = if (is.null(icp)) 0L else icp$iterations,
    converged = !is.null(icp) && isTRUE(icp$converged), status = status,
    message = if (nzchar(detail)) paste0(detail, " [GGIR: ", qc, "]") else qc,
    call = call)
  fit$ggir <- res
  fit$QCmessage <- qc
  fit$ggir_compat <- compat
  fit$use_temp <- isTRUE(res$use.temp)
  if (applied && !is.null(pts) && nrow(pts) > 0) {
    fit <- add_uncertainty(fit, cbind(pts$mean_x, pts$mean_y, pts$mean_z),
                           if (fit$use_temp) pts$temperature,
                           weights = "ggir",
                           max_weight = ggir_constants$max_weight)
  }
  fit$n_windows <- info$windows
  fit$input <- info$input
  fit$hours <- info$windows * 10 / 3600
  fit
}
