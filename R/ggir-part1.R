# GGIR part 1 after calibration: g.getmeta()'s calibrated epoch signals,
# read by gravcal's decoders and computed by its core
# (inst/include/gravcal/ggir/ggir_epochs.hpp), block by block as GGIR does.

#' Calibrated epoch signals as GGIR's g.getmeta, on gravcal's core
#'
#' A drop-in replacement for `GGIR::g.getmeta()` (GGIR 3.3-9): same
#' arguments, same returned list `M`. It reads the recording in GGIR's
#' blocks of about 24 hours (`chunksize` scales them), starts at the next
#' whole long epoch (15 minutes), keeps the whole long epochs of each block
#' (the rest carries into the next), applies the calibration as GGIR
#' applies it (`offset`, `scale`, `tempoffset` around `meantempcal`), and
#' computes per short epoch (5 s) the metrics asked for in `params_metrics`
#' and per long epoch the non-wear and clipping scores and the mean norm,
#' temperature and light. Every number is GGIR's to the bit: the epoch means
#' are R's block-wide cumulative sums, the angles GGIR's running median of
#' the block, the values rounded to 4 decimals and passed through R's text
#' as GGIR passes them.
#'
#' The file is read once, by gravcal's decoders, in the blocks GGIR's
#' readers give; the per-sample work is C++. Two threads by default: a
#' second one makes the running medians of GGIR's angles beside the other
#' signals. `options(gravcal.threads = 1)` keeps to one (M is the same
#' bits either way); a cohort run on a plan with several workers keeps each
#' worker to one.
#'
#' @section What this version covers:
#' Damaged files: where GGIR's reader skips or imputes as gravcal's decoder
#' does (`.cwa`, Parmay Matrix), M is GGIR's, `QClog` included; a damaged
#' GENEActiv page (garbled digits, a hex line cut short or too long, a
#' garbled temperature or rate, a line missing, a last page cut short) is
#' read as GGIRread reads it, so M is GGIR's there too (a warning says what
#' was read so); where GGIR stops on such a file, or its time stamps are
#' not defined where it reads them, gravcal's stops too, saying why. A
#' `.gt3x` file cut short (which GGIR's reader cannot open) or with damaged
#' records in `log.bin` (which it does not read as gravcal's decoder skips
#' them) is refused, the error saying why; so is an ActiGraph csv export with
#' damaged lines (fields missing or extra, a value or a time stamp that is
#' not one), which GGIR's reader does not read as gravcal's decoder does.
#'
#' Formats: Axivity `.cwa` (`QClog` GGIRread's log of the blocks it skips
#' or imputes: bad checksums, breaks in the sequence, a rate more than 5 %
#' off, an hour skipped or repeated at a change of `desiredtz`'s offset;
#' where GGIR's reader stops instead, on a zeroed block, more than 20 bad
#' blocks in a row or a gap of over 3 days, GGIR loses the whole block of its
#' reading that holds it, which gravcal does not reproduce: an error says
#' where), GENEActiv `.bin`, ActiGraph `.gt3x` and csv exports
#' (their time gaps and idle-sleep zeros filled as GGIR fills them; a
#' gap over GGIR's limit, 90 minutes or 6 long epochs, filled up to the next
#' long epoch and the rest imputed as whole epochs, non-wear, as GGIR 3.3-9
#' does on R 4.3 or later, which reads the gap's time of day in the session's
#' time zone; on R 4.2.1 to 4.2.3 GGIR stops there, gravcal gives what it
#' gives on R 4.3), Movisens, Axivity csv exports (each block resampled as
#' GGIR resamples it; across a change of `desiredtz`'s UTC offset UNIX and
#' ISO 8601 stamps forced into the zone as GGIR forces them: the hour they
#' jump in autumn filled as GGIR's resampling fills it, the hour the clocks
#' skip in spring NA stamps, after which GGIR's samples are NA to the
#' block's end, as gravcal's are; a block that starts or ends in that hour
#' an error, as GGIR stops there; text stamps in a zone whose offset
#' changes refused where a block of GGIR's starts at a time that exists
#' twice or not at all there, as by g.calibrate()), Parmay Matrix
#' `.bin`/`.BIN` (the whole file one block, as GGIRread's reader gives it,
#' a packet with a bad checksum kept as it keeps it; the dynamic range from
#' the file's header, whatever `dynrange` says; `configtz` changes nothing,
#' as in GGIR; `QClog` GGIRread's log of the packets; a file GGIRread's
#' reader fails on, with a packet cut inside its header, a negative sample
#' count or a header that declares no packet, refused naming why), ad hoc
#' csv files (`rmc.firstrow.acc` and the other `rmc.*` parameters, as for
#' [g.calibrate()]; the time column read stamp by stamp as GGIR reads it,
#' UNIX seconds or milliseconds, text by `rmc.format.time` in `configtz`,
#' else `desiredtz`, or ActivPAL days forced into `desiredtz` as
#' `lubridate::force_tz()` forces them, across changes of its UTC offset too
#' (the hour its clocks repeat at the later offset, the hour they skip NA:
#' where GGIR's start or a block's edge is NA, an error, as GGIR stops); GGIR's AD_HOC non-wear, sd below `1.2 * rmc.noise`, and
#' clipping beyond `rmc.dynamic_range`, none without it; with `rmc.col.wear`,
#' GGIR's non-wear from the wear flags (each long epoch's most frequent flag
#' in its non-wear window, times 3; flags GGIR's reader stops on, or a
#' window without one, an error as GGIR stops); time gaps filled by
#' `imputeTimegaps` and `rmc.check4timegaps`, each block from the block
#' before, GGIR's times slipping by two rows after a single sample between
#' two gaps as they do in GGIR; `rmc.doresample`). Refused with an error
#' naming it: no `rmc.col.time` (GGIR's g.getmeta() stops without time
#' stamps), `rmc.noise` empty (GGIR stops), `rmc.check4timegaps` with `rmc.doresample` and `imputeTimegaps`
#' (GGIR fills each block from the resampled block before), `rmc.dynamic_range`
#' naming a header row without `dynrange`, a deprecated `rmc.configtz` or
#' `rmc.desiredtz` other than the zone GGIR hands its reader (GGIR's reads
#' stop on it; text time is read in `configtz`, else `desiredtz`), and what
#' [g.calibrate()] refuses of text time (in a zone whose offset changes, a
#' block of GGIR's starting at a time that exists twice or not at all there).
#' Metrics:
#' every `do.*` of
#' `params_metrics` but `do.brondcounts` (GGIR stops on it too). Where a
#' recording has a block, GGIR stops, and so gravcal's g.getmeta() stops, on
#' none of them, and on part of a group GGIR computes whole: any of
#' `do.hfx`, `do.hfy`, `do.hfz` without `do.hfen`, one or two axes of
#' `do.roll_med_acc_*` or of `do.dev_roll_med_acc_*` ([epoch_signals()]
#' computes those);
#' `do.neishabouricounts` from the actilifecounts package, called in R on
#' each block's calibrated samples as GGIR calls it (with `actilife_LFE`);
#' the filtered ones (BFEN, HFEN, HFENplus, LFENMO,
#' LFEN, the per-axis filtered signals and zero crossings) need the signal
#' package, as GGIR does. Non-wear: `nonwear_approach` "2013" and "2023".
#' `myfun` (GGIR's external function object: `FUN`, `parameters`,
#' `expected_sample_rate`, `expected_unit`, `colnames`, `minlength`,
#' `outputres`, `outputtype`, `aggfunction`, `timestamp`): run in R on each
#' block's calibrated samples as GGIR runs it (in the unit and at the rate it
#' expects, resampled by GGIRread's resampler; time stamps from the
#' recording's start, as GGIR gives them to every block; its output
#' aggregated with `aggfunction` or repeated to the short epoch), its
#' columns added to `metashort` through R's text as GGIR adds them; blocks
#' cut to a whole `minlength`. `outputtype` must be "numeric" or
#' "character" (GGIR stops without it).
#' Anything else GGIR's g.getmeta() would compute (another format) is an
#' error naming it, never a result without it. Not reproduced: `bsc_qc` (GGIR's
#' wall-clock times and memory: gravcal's gives the time and the process's
#' resident memory in MB, without GGIR's full garbage collection); GGIR shrinks its blocks when its own R
#' session holds over 4000 MB, which gravcal's reading never makes it do.
#'
#' @param datafile Path of the recording.
#' @param params_metrics,params_rawdata,params_general,params_cleaning
#'   GGIR's parameter lists (as from `GGIR::load_params()`); missing entries
#'   take GGIR 3.3-9's defaults.
#' @param daylimit Stop after this many blocks (GGIR's; `FALSE`: none).
#' @param offset,scale,tempoffset,meantempcal The calibration, as
#'   [g.calibrate()] returns it (`meantempcal`: its `meantempcal`).
#' @param myfun GGIR's external function object (see "What this version
#'   covers"), or empty.
#' @param inspectfileobject Optional: GGIR's `g.inspectfile()` result; its
#'   `sf` must agree with the file (for an ad hoc csv file, with the rate the
#'   `rmc.*` parameters give).
#' @param verbose Print the blocks read, as GGIR does.
#' @param ... GGIR's legacy arguments: any parameter of the lists by name.
#'   Where GGIR's g.getmeta() runs its parameter check (an argument here,
#'   or a list not given), what that check changes is changed here too:
#'   `chunksize` below 0.1 is 0.1, `windowsizes` are made multiples of
#'   each other (with a warning), a `dataFormat` of epoch data is refused.
#' @return GGIR's list `M`: `filecorrupt`, `filetooshort`,
#'   `NFilePagesSkipped`, `metalong`, `metashort`, `wday`, `wdayname`,
#'   `windowsizes`, `bsc_qc`, `QClog`.
#' @seealso [g.calibrate()], [epoch_signals()].
#' @export
g.getmeta <- function(datafile, params_metrics = c(), params_rawdata = c(),
                      params_general = c(), params_cleaning = c(), daylimit = FALSE,
                      offset = c(0, 0, 0), scale = c(1, 1, 1), tempoffset = c(0, 0, 0),
                      meantempcal = c(), myfun = c(), inspectfileobject = c(),
                      verbose = TRUE, ...) {
  dots <- list(...)
  p <- meta_params(params_metrics, params_rawdata, params_general, params_cleaning, dots,
                   checked = ggir_extracts(dots, params_metrics, params_rawdata,
                                           params_general, params_cleaning))
  check_flag(verbose, "verbose")
  myfun <- if (length(myfun)) meta_myfun_check(myfun, p$windowsizes[1])
  cal <- meta_calibration(offset, scale, tempoffset, meantempcal)
  check_fp_build("`g.getmeta()`")
  # (g.part1() may have opened it already, its first block read beside
  # g.calibrate()'s pass: R/meta-ahead.R)
  src <- meta_ahead_take(datafile, p, inspectfileobject) %||%
    meta_open(datafile, p, inspectfileobject)
  on.exit(gc_decoder_close(src$native$ptr), add = TRUE)
  M <- meta_run(src, p, cal, daylimit, verbose, myfun = myfun, ggir = TRUE)
  # text time in a zone whose offset changes (ad hoc and Axivity csv), and
  # .cwa blocks there: a block of GGIR's that starts at a time that exists
  # twice or not at all there is refused, as by g.calibrate(); an Axivity
  # csv export's block that starts or ends in an hour the zone's clocks
  # skip stops, as GGIR does
  tz <- if (length(p$configtz)) p$configtz else p$desiredtz
  tz_arg <- if (length(p$configtz)) "configtz" else "desiredtz"
  if (!is.null(p$.rmc)) {
    ggir_check_zone_read(src, attr(p$.rmc, "tz"), attr(p$.rmc, "tz_arg"))
  } else {
    ggir_check_zone_read(src, tz, tz_arg)
  }
  ggir_check_nan_edge(src, tz, tz_arg)
  M
}

# g.getmeta()'s source: `datafile` opened for GGIR's blocks (meta_source()),
# checked against `inspectfileobject`, and refused where gravcal's
# g.getmeta() does not read it or GGIR's gives no result to reproduce. The
# caller closes it.
meta_open <- function(datafile, p, inspectfileobject) {
  tz <- if (length(p$configtz)) p$configtz else p$desiredtz
  tz_arg <- if (length(p$configtz)) "configtz" else "desiredtz"
  read_opts <- list(interpolation = p$interpolationType, frequency_tol = p$frequency_tol,
                    zone = tz %||% "", zone_arg = tz_arg)
  sf <- NULL
  if (length(inspectfileobject)) {
    if (!is.list(inspectfileobject)) {
      abort("`inspectfileobject` must be a list (GGIR's g.inspectfile() result), not ",
            describe(inspectfileobject), ".")
    }
    ggir_check_inspect(inspectfileobject, datafile, adhoc = !is.null(p$.rmc))
    sf <- inspectfileobject$sf
  }
  src <- meta_source(datafile, p, sf, "datafile", read_opts)
  if (!is.null(p$.rmc) && !is.null(sf) && !isTRUE(all.equal(sf, src$sf, tolerance = 0))) {
    gc_decoder_close(src$native$ptr)
    abort("`inspectfileobject$sf` = ", format(sf), " but the rmc.* parameters give \"",
          basename(datafile), "\" ", format(src$sf), " Hz; give GGIR::g.inspectfile()'s ",
          "result for this file with the same parameters.")
  }
  if (!src$format %in% meta_formats() || is.null(src$native)) {
    if (!is.null(src$native)) gc_decoder_close(src$native$ptr)
    abort("gravcal's g.getmeta() does not read ", format_entry(src$format)$label %||% src$format,
          " yet (it reads ", paste(vapply(meta_formats(), function(f) format_entry(f)$label, ""),
                                    collapse = " and "),
          "); use GGIR::g.getmeta() for \"", basename(datafile), "\".")
  }
  stops <- format_entry(src$format)$ggir_stops
  why <- if (!is.null(stops)) stops(src)
  if (!is.null(why)) {
    gc_decoder_close(src$native$ptr)
    abort("\"", basename(datafile), "\" (`datafile`) has ", why, ": GGIR's g.getmeta() ",
          "gives no result to reproduce there, so gravcal's refuses the file (calibrate() ",
          "reads the rest of it).")
  }
  src
}

# The formats g.getmeta() reads so far (the registry's `ggir_getmeta`).
meta_formats <- function() {
  names(Filter(function(f) isTRUE(f$ggir_getmeta), recording_formats))
}

# The metrics of g.applymetrics() in the order GGIR computes them (its
# result's names); `filtered`: a Butterworth filter's (ggir_filters.hpp,
# coefficients from the signal package).
meta_metric_table <- function() {
  data.frame(
    name = c("BFX", "BFY", "BFZ", "BFEN", "ZCX", "ZCY", "ZCZ", "LFX", "LFY", "LFZ", "LFEN",
             "LFENMO", "HFX", "HFY", "HFZ", "HFEN", "HFENplus",
             "roll_med_acc_x", "roll_med_acc_y", "roll_med_acc_z",
             "dev_roll_med_acc_x", "dev_roll_med_acc_y", "dev_roll_med_acc_z",
             "angle_x", "angle_y", "angle_z", "ENMO", "MAD", "EN", "ENMOa"),
    filtered = c(rep(TRUE, 17), rep(FALSE, 13)),
    stringsAsFactors = FALSE)
}

# GGIR 3.3-9's defaults (load_params()) of the parameters g.getmeta() reads.
meta_defaults <- function() {
  do <- c("do.anglex", "do.angley", "do.anglez", "do.zcx", "do.zcy", "do.zcz", "do.enmo",
          "do.lfenmo", "do.en", "do.mad", "do.enmoa", "do.roll_med_acc_x",
          "do.roll_med_acc_y", "do.roll_med_acc_z", "do.dev_roll_med_acc_x",
          "do.dev_roll_med_acc_y", "do.dev_roll_med_acc_z", "do.bfen", "do.hfen",
          "do.hfenplus", "do.lfen", "do.lfx", "do.lfy", "do.lfz", "do.hfx", "do.hfy",
          "do.hfz", "do.bfx", "do.bfy", "do.bfz", "do.brondcounts", "do.neishabouricounts")
  metrics <- stats::setNames(as.list(do %in% c("do.anglez", "do.enmo")), do)
  list(metrics = c(metrics, list(hb = 15, lb = 0.2, n = 4, zc.lb = 0.25, zc.hb = 3,
                                 zc.sb = 0.01, zc.order = 2, zc.scale = 1,
                                 actilife_LFE = FALSE)),
       rawdata = list(chunksize = 1, dynrange = NULL, nonwear_range_threshold = 150,
                      imputeTimegaps = TRUE, interpolationType = 1, frequency_tol = 0.1),
       general = list(windowsizes = c(5, 900, 3600), desiredtz = "", configtz = NULL),
       cleaning = list(nonwear_approach = "2023"))
}

# GGIR's parameters for g.getmeta(): the lists (missing entries from
# GGIR's defaults), then the legacy arguments in `dots` by name. The ones
# that change M and are not honoured are an error naming them.
meta_params <- function(params_metrics, params_rawdata, params_general, params_cleaning,
                        dots, checked = FALSE) {
  if (length(dots) && (is.null(names(dots)) || any(names(dots) == ""))) {
    abort("All arguments in `...` must be named.")
  }
  d <- meta_defaults()
  lists <- list(metrics = params_metrics, rawdata = params_rawdata,
                general = params_general, cleaning = params_cleaning)
  p <- list()
  for (k in names(lists)) {
    v <- lists[[k]]
    if (length(v) && !is.list(v)) {
      abort("`params_", k, "` must be a list (as from GGIR::load_params()), not ",
            describe(v), ".")
    }
    p[names(d[[k]])] <- d[[k]]
    for (nm in names(v)) p[nm] <- list(v[[nm]])
  }
  for (nm in names(dots)) p[nm] <- list(dots[[nm]])
  # (GGIR's g.getmeta() checks them when a list is not given or an argument
  # comes in `...`: what that check changes, changed here)
  if (checked) p <- ggir_check_values(p, c("metrics", "rawdata", "general"))
  # nonwear_approach as a number (GGIR's config.csv read back gives 2023):
  # GGIR's %in% and == read it as its text
  na <- p$nonwear_approach
  if (is.numeric(na) && length(na) == 1 && as.character(na) %in% c("2013", "2023")) {
    p$nonwear_approach <- as.character(na)
  }
  # GGIR's ad hoc csv files (rmc.*): the parameters checked, those not
  # honoured refused (meta_rmc())
  p$.rmc <- meta_rmc(p)
  # legacy arguments that are no parameter GGIR knows: said, as GGIR's
  # extract_params() would leave them
  known <- c(unlist(lapply(d, names)), ggir_param_known(), "sf")
  extra <- setdiff(names(dots), known)
  if (length(extra)) {
    warning("g.getmeta(): ignored argument", if (length(extra) > 1) "s", " ",
            paste0("`", extra, "`", collapse = ", "), " (no GGIR parameter g.getmeta() reads)",
            call. = FALSE)
  }
  do <- grep("^do[.]", names(d$metrics), value = TRUE)
  for (nm in do) check_flag(p[[nm]], nm)
  tab <- meta_metric_table()
  dov <- meta_do_name(tab$name)
  asked <- vapply(dov, function(nm) isTRUE(p[[nm]]), TRUE)
  if (any(tab$filtered & asked) && !requireNamespace("signal", quietly = TRUE)) {
    abort("`", dov[tab$filtered & asked][1], "` = TRUE needs the signal package ",
          "(GGIR's Butterworth filters): install.packages(\"signal\").")
  }
  for (nm in c("n", "lb", "hb", "zc.lb", "zc.hb", "zc.sb", "zc.order")) {
    check_number(p[[nm]], nm, min = 0, min_inclusive = FALSE)
  }
  if (isTRUE(p$do.brondcounts)) {
    abort("`do.brondcounts` = TRUE: GGIR has withdrawn Brond's counts (its g.getmeta() stops ",
          "on them); use `do.neishabouricounts`.")
  }
  check_flag(p$actilife_LFE, "actilife_LFE")
  if (isTRUE(p$do.neishabouricounts) && !requireNamespace("actilifecounts", quietly = TRUE)) {
    abort("`do.neishabouricounts` = TRUE needs the actilifecounts package (the counts GGIR ",
          "takes from it): install.packages(\"actilifecounts\").")
  }
  ws <- p$windowsizes
  if (!is.numeric(ws) || length(ws) != 3 || anyNA(ws) || any(ws <= 0)) {
    abort("`windowsizes` must be 3 positive numbers of seconds, not ", describe(ws), ".")
  }
  if (ws[3] < ws[2] || ws[2] < ws[1]) {
    abort("`windowsizes` must be increasing (short, long, non-wear window), not ",
          paste(ws, collapse = ", "), ".")
  }
  check_number(p$chunksize, "chunksize", min = 0, min_inclusive = FALSE)
  check_number(p$nonwear_range_threshold, "nonwear_range_threshold", min = 0)
  if (length(p$dynrange)) check_number(p$dynrange, "dynrange", min = 0, min_inclusive = FALSE)
  if (!identical(p$nonwear_approach, "2013") && !identical(p$nonwear_approach, "2023")) {
    abort("`nonwear_approach` must be \"2013\" or \"2023\", not ", describe(p$nonwear_approach), ".")
  }
  if (!isTRUE(p$interpolationType %in% c(1, 2))) {
    abort("`interpolationType` must be 1 (linear) or 2 (nearest neighbour), not ",
          describe(p$interpolationType), ".")
  }
  check_flag(p$imputeTimegaps, "imputeTimegaps")
  p
}

# The rmc.* parameters of `p` (with rmc.firstrow.acc: an ad hoc csv file)
# for the reader (rmc_values(), the zone of text time: rmc_with_zone()), or
# NULL. What g.getmeta() does not reproduce is an error naming it; so is
# what GGIR's g.getmeta() stops on.
meta_rmc <- function(p) {
  if (is.null(p$rmc.firstrow.acc)) return(NULL)
  given <- p[grep("^rmc[.]", names(p))]
  # GGIR's default rmc.noise (load_params()) where no list names it
  if (!"rmc.noise" %in% names(given)) given$rmc.noise <- ggir_constants$rmc_noise
  rmc <- rmc_with_zone(rmc_values(given, "params_rawdata"), p)
  refuse <- function(nm, why) {
    abort("`", nm, "` = ", paste(deparse(rmc[[nm]]), collapse = ""), ": ", why, ".")
  }
  bad <- rmc_zone_conflict(rmc, p)
  if (!is.null(bad)) {
    refuse(bad$nm, paste0("GGIR's reads of the file stop on it with `", bad$other, "` = \"",
                          bad$value, "\" (read.myacc.csv(): give only `", bad$other,
                          "`), so GGIR's g.getmeta() finds the file empty"))
  }
  if (!length(rmc$rmc.col.time)) {
    abort("`rmc.col.time` is not given: GGIR's g.getmeta() stops on an ad hoc csv file ",
          "without a time column (\"Timestamps not found\"), and so does gravcal's; name ",
          "the file's time column with `rmc.col.time`.")
  }
  if (!length(rmc$rmc.noise)) {
    abort("`rmc.noise` is not given: GGIR's g.getmeta() stops on an ad hoc csv file ",
          "without it (its non-wear sd criterion is 1.2 * rmc.noise), and so does gravcal's.")
  }
  # (with imputeTimegaps = FALSE GGIR carries read.myacc.csv's own last
  # sample, before the resampling, as the decoder does)
  if (isTRUE(rmc$rmc.check4timegaps) && isTRUE(rmc$rmc.doresample) && isTRUE(p$imputeTimegaps)) {
    refuse("rmc.doresample", paste0("with `rmc.check4timegaps` = TRUE and `imputeTimegaps` = ",
                                    "TRUE, GGIR fills each block's gaps from the resampled ",
                                    "block before it, which gravcal's g.getmeta() does not ",
                                    "reproduce; use one of the two, or imputeTimegaps = FALSE"))
  }
  # GGIR's clipping threshold without dynrange is rmc.dynamic_range as it
  # is: a header row's name would be compared as text
  if (!length(p$dynrange) && is.character(rmc$rmc.dynamic_range)) {
    refuse("rmc.dynamic_range", paste0("without `dynrange`, GGIR's g.getmeta() takes it for ",
                                       "its clipping threshold and compares the samples with ",
                                       "the text; give `dynrange`, or the range as a number"))
  }
  rmc
}

# do.<name> of a metric of g.applymetrics()'s result (GGIR's rule: lower
# case, "angle_" as "angle").
meta_do_name <- function(name) sub("angle_", "angle", paste0("do.", tolower(name)), fixed = TRUE)

# The calibration as g.getmeta() applies it, for the core.
meta_calibration <- function(offset, scale, tempoffset, meantempcal) {
  chk <- function(v, arg) {
    if (!is.numeric(v) || length(v) != 3 || anyNA(v)) {
      abort("`", arg, "` must be 3 numbers (x, y, z), not ", describe(v), ".")
    }
    as.double(v)
  }
  offset <- chk(offset, "offset")
  scale <- chk(scale, "scale")
  tempoffset <- chk(tempoffset, "tempoffset")
  out <- list(offset = offset, inv_scale = 1 / scale)
  if (length(meantempcal)) {
    if (!is.numeric(meantempcal) || length(meantempcal) != 1 || is.na(meantempcal)) {
      abort("`meantempcal` must be one number (degrees C) or empty, not ",
            describe(meantempcal), ".")
    }
    out$meantemp <- as.double(meantempcal)
    out$inv_tempoffset <- 1 / tempoffset
  }
  out
}

# GGIR's clipping threshold, non-wear criteria and block size
# (get_nw_clip_block_params()) for the source.
meta_nonwear <- function(src, p) {
  dynrange <- p$dynrange
  # an ActiGraph's range from its serial number, whatever dynrange says
  serial <- src$info$serial
  if (identical(format_entry(src$format)$ggir_monitor, "actigraph") && is.character(serial)) {
    for (r in list(c("CLE", 6), c("MOS", 8), c("NEO", 6))) {
      if (length(grep(r[1], serial)) == 1) {
        dynrange <- as.numeric(r[2])
        break
      }
    }
  }
  mon <- format_entry(src$format)$ggir_monitor
  # a Parmay Matrix's range from its header, whatever dynrange says
  if (identical(mon, "parmay_mtx")) dynrange <- src$info$range_g
  clipthres <- if (length(dynrange)) dynrange - 0.5 else format_entry(src$format)$ggir_clip %||% 7.5
  sdcriter <- 0.013
  if (identical(mon, "ad_hoc")) {
    # GGIR's AD_HOC monitor: clipping beyond rmc.dynamic_range itself (none
    # without it: GGIR compares with NULL), sd below 1.2 * rmc.noise
    rmc <- p$.rmc
    if (!length(dynrange)) clipthres <- if (length(rmc$rmc.dynamic_range)) rmc$rmc.dynamic_range else Inf
    sdcriter <- rmc$rmc.noise * 1.2
  }
  list(clipthres = as.numeric(clipthres), sdcriter = sdcriter,
       racriter = p$nonwear_range_threshold / 1000,
       approach = p$nonwear_approach)
}

# as.numeric(as.character(v)), R's text of each number read back, taken
# once per distinct value: R writes each element on its own (15 significant
# digits), so equal values give equal text (NA and NaN are told apart by
# unique() and match() as by the text). An epoch signal repeats its values
# (ENMO's zeros at rest; 4 decimals): 2-17x faster than element by element.
text_round_trip <- function(v) {
  u <- unique(v)
  as.numeric(as.character(u))[match(v, u)]
}

# Times `tt` (seconds since 1970) as GGIR writes M's time stamps,
# strftime(as.POSIXlt(tt, tz = tz), "%Y-%m-%dT%H:%M:%S%z"): R's conversion
# to local time, then the text made in C++ (gc_iso_stamps()) wherever it is
# certainly R's, else by R's own formatter.
iso_stamps <- function(tt, tz) {
  lt <- as.POSIXlt(tt, origin = "1970-01-01", tz = tz)
  u <- unclass(lt)
  off <- u$gmtoff
  if (is.null(off) && !(attr(lt, "tzone")[1] %in% c("UTC", "GMT"))) off <- NA
  s <- if (is.null(off) || is.integer(off)) {
    gc_iso_stamps(u$year, u$mon, u$mday, u$hour, u$min, u$sec, u$isdst, off)
  }
  if (is.null(s)) s <- strftime(lt, format = "%Y-%m-%dT%H:%M:%S%z")
  s
}

# GGIR's M from the blocks' values: the columns as GGIR's character
# matrices hold them (R's text of each number, read back), time stamps in
# desiredtz.
meta_result <- function(short, long, asked, metnames, metricnames_long, starttime, wday,
                        wdayname, filetooshort, filecorrupt, p, ws3, ws2, QClog,
                        myfun = NULL) {
  via_text <- text_round_trip
  bsc_qc <- data.frame(time = format(Sys.time()), size = memory_in_use_mb(),
                       stringsAsFactors = FALSE)
  if (filecorrupt || filetooshort) {
    # (no block made: GGIR's bsc_qc as it starts, no row)
    return(invisible(list(filecorrupt = filecorrupt, filetooshort = TRUE,
                          NFilePagesSkipped = 0, metalong = c(), metashort = c(),
                          wday = c(), wdayname = c(), windowsizes = c(),
                          bsc_qc = data.frame(time = c(), size = c(), stringsAsFactors = FALSE),
                          QClog = QClog)))
  }
  n_short <- short$count - 1
  stamp <- function(n, by, min_rows) {
    if (n <= min_rows) return(rep(" ", n))
    t0 <- round(as.numeric(starttime))
    iso_stamps(seq(t0, t0 + (n - 1) * by, by = by), p$desiredtz)
  }
  ms <- data.frame(timestamp = stamp(n_short, ws3, 1), stringsAsFactors = FALSE)
  for (k in seq_along(metnames)) {
    ms[[metnames[k]]] <- via_text(sheet_column(short, asked[k]))
  }
  if (!is.null(myfun)) {
    for (nm in myfun$colnames) {
      v <- sheet_column(short, nm)
      ms[[nm]] <- if (identical(myfun$outputtype, "numeric")) suppressWarnings(as.numeric(v)) else v
    }
  }
  cols_long <- metricnames_long[-1]
  n_long <- if (is.null(long)) 0 else long$count - 1
  ml <- data.frame(timestamp = stamp(n_long, ws2, 2), stringsAsFactors = FALSE)
  for (nm in cols_long) {
    ml[[nm]] <- via_text(if (is.null(long)) numeric(0) else sheet_column(long, nm))
  }
  invisible(list(filecorrupt = filecorrupt, filetooshort = filetooshort,
                 NFilePagesSkipped = 0, metalong = ml, metashort = ms, wday = wday,
                 wdayname = wdayname, windowsizes = p$windowsizes, bsc_qc = bsc_qc,
                 QClog = QClog))
}
