# GGIR part 1 after calibration: g.getmeta()'s calibrated epoch signals,
# read by gravcal's decoders and computed by its core
# (inst/include/gravcal/ggir_epochs.hpp), block by block as GGIR does.

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
#' readers give; the per-sample work is C++.
#'
#' @section What this version covers:
#' Formats: Axivity `.cwa`, GENEActiv `.bin`, ActiGraph `.gt3x` and csv
#' exports (their time gaps and idle-sleep zeros filled as GGIR fills them, up
#' to GGIR's 90-minute limit: a longer gap is an error), Movisens. Metrics:
#' every `do.*` of
#' `params_metrics` but `do.brondcounts` (GGIR stops on it too) and
#' `do.neishabouricounts`; the filtered ones (BFEN, HFEN, HFENplus, LFENMO,
#' LFEN, the per-axis filtered signals and zero crossings) need the signal
#' package, as GGIR does. Non-wear: `nonwear_approach` "2013" and "2023".
#' Anything else GGIR's g.getmeta() would compute (`myfun`, another
#' format) is an error naming it, never a result without it. Not reproduced: `bsc_qc` (GGIR's
#' wall-clock times and memory); GGIR shrinks its blocks when its own R
#' session holds over 4000 MB, which gravcal's reading never makes it do.
#'
#' @param datafile Path of the recording.
#' @param params_metrics,params_rawdata,params_general,params_cleaning
#'   GGIR's parameter lists (as from `GGIR::load_params()`); missing entries
#'   take GGIR 3.3-9's defaults.
#' @param daylimit Stop after this many blocks (GGIR's; `FALSE`: none).
#' @param offset,scale,tempoffset,meantempcal The calibration, as
#'   [g.calibrate()] returns it (`meantempcal`: its `meantempcal`).
#' @param myfun Not supported yet: an error when given.
#' @param inspectfileobject Optional: GGIR's `g.inspectfile()` result; its
#'   `sf` must agree with the file.
#' @param verbose Print the blocks read, as GGIR does.
#' @param ... GGIR's legacy arguments: any parameter of the lists by name.
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
  p <- meta_params(params_metrics, params_rawdata, params_general, params_cleaning,
                   list(...))
  check_flag(verbose, "verbose")
  if (length(myfun)) {
    abort("`myfun`: an external function per block is not supported by gravcal's ",
          "g.getmeta() yet; use GGIR::g.getmeta() for it.")
  }
  cal <- meta_calibration(offset, scale, tempoffset, meantempcal)
  check_fp_build("`g.getmeta()`")
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
    ggir_check_inspect(inspectfileobject, datafile, adhoc = FALSE)
    sf <- inspectfileobject$sf
  }
  src <- meta_source(datafile, p, sf, "datafile", read_opts)
  if (!src$format %in% meta_formats() || is.null(src$native)) {
    abort("gravcal's g.getmeta() does not read ", format_entry(src$format)$label %||% src$format,
          " yet (it reads ", paste(vapply(meta_formats(), function(f) format_entry(f)$label, ""),
                                    collapse = " and "),
          "); use GGIR::g.getmeta() for \"", basename(datafile), "\".")
  }
  on.exit(gc_decoder_close(src$native$ptr), add = TRUE)
  meta_run(src, p, cal, daylimit, verbose)
}

# g.getmeta()'s source: the file's native decoder, and for a format whose
# time gaps GGIR's g.getmeta() fills (with imputeTimegaps) the filling in
# the decoder (decode_ggir_timegaps.hpp, g.getmeta's mode): with the limit
# beyond which GGIR imputes whole epochs instead and, for a clock read per
# sample in a time zone, the zone's shifts of the file's clock
# (meta_clock_table()), which GGIR's reader applies before the gaps are
# seen. The file is opened once to learn its start, then again with these.
meta_source <- function(datafile, p, sf, arg, read_opts) {
  open <- function(ro) {
    open_source(datafile, sf = sf, chunksize = p$chunksize, reader = "native", compat = TRUE,
                read_opts = ro, arg = arg, part = "getmeta")
  }
  src <- open(read_opts)
  fe <- format_entry(src$format)
  if (is.null(src$native) || !isTRUE(p$imputeTimegaps) || !isTRUE(fe$ggir_timegaps)) {
    return(src)
  }
  ro <- c(read_opts, list(getmeta_timegaps = 1,
                          getmeta_gap_limit = max(c(((p$windowsizes[2] / 60) * 6), 90))))
  zone <- if (length(p$configtz)) p$configtz else p$desiredtz
  start <- src$info$start_time
  tab <- if (identical(fe$local_clock, "sample") && !isFALSE(fe$ggir_time) &&
             is.numeric(start) && length(start) == 1 && is.finite(start)) {
    meta_clock_table(zone, start)
  }
  if (!is.null(tab)) {
    ro$clock <- tab$text
    ro$clock_until <- tab$until
  }
  gc_decoder_close(src$native$ptr)
  src <- open(ro)
  src$getmeta_timegaps <- TRUE
  src$clock_shifted <- !is.null(tab)
  src
}

# The shift GGIR's reader adds to each time of a per-sample clock (the
# file's clock, read as UTC, read again as the clock time in `zone`), as a
# table of its changes over `days` from two days before `start`: the zone's
# offset changes found to the second (UTC instants, at every 10 minutes,
# then halved), each taking effect at the clock time where the zone's
# clock first shows it: a clock time that occurs twice (the hour a clock
# goes back) is read as the later one, a clock time that does not occur
# (the hour a clock goes forward) with the new offset, as GGIR's .gt3x
# times show. NULL in UTC. list(text = "second shift ...", until = the
# table's last second).
meta_clock_table <- function(zone, start, days = 400) {
  if (!length(zone) || !nzchar(zone) || zone %in% c("UTC", "GMT")) return(NULL)
  off <- function(t) {
    as.POSIXlt(as.POSIXct(t, origin = "1970-01-01", tz = "UTC"), tz = zone)$gmtoff
  }
  from <- floor(start / 600) * 600 - 2 * 86400
  until <- from + (days + 2) * 86400
  g <- seq(from, until, by = 600)
  o <- off(g)
  if (anyNA(o)) abort("The time zone \"", zone, "\" gives no offsets from UTC.")
  ch <- which(o[-1] != o[-length(o)])
  at <- vapply(ch, function(i) {
    lo <- g[i]
    hi <- g[i + 1]
    while (hi - lo > 1) {
      mid <- floor((lo + hi) / 2)
      if (off(mid) == o[i + 1]) hi <- mid else lo <- mid
    }
    hi + min(o[i], o[i + 1])
  }, 0)
  list(text = paste(sprintf("%.0f %.0f", c(from, at), -c(o[1], o[ch + 1])), collapse = " "),
       until = until)
}

# The block store of meta_run() (gc_meta_store(), ggir_block_store.hpp)
# and its reader: one of GGIR's blocks appended to it, from a native
# decoder or from samples in memory (`units` rows a block). `time`: keep a
# time column (GGIR's time-gap imputation reads it).
meta_store <- function(src, time) {
  cols <- if (!is.null(src$native)) {
    c(temperature = isTRUE(src$native$info$temperature),
      light = isTRUE(src$native$info$light))
  } else {
    c(temperature = !is.null(src$samples$temperature), light = !is.null(src$samples$light))
  }
  store <- gc_meta_store(cols[["temperature"]], time, cols[["light"]])
  want_time <- !isFALSE(format_entry(src$format)$ggir_time)
  if (!is.null(src$native)) {
    read <- function() gc_meta_store_read(store, src$native$ptr, src$units, 2^20, want_time)
  } else {
    s <- src$samples[!vapply(src$samples, is.null, TRUE)]
    if (!want_time) s$time <- NULL
    from <- 0
    read <- function() {
      n <- length(s$x)
      i <- if (from < n) (from + 1):min(n, from + src$units) else integer(0)
      from <<- from + length(i)
      gc_meta_store_put(store, meta_rows(s, i), -1)
    }
  }
  list(store = store, read = read, temperature = cols[["temperature"]],
       light = cols[["light"]], keep_time = time, want_time = want_time)
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
                        dots) {
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
  # GGIR's ad hoc csv reading (rmc.*): not read by g.getmeta() yet
  rmc <- grep("^rmc[.]", names(p), value = TRUE)
  if (length(rmc) && !is.null(p$rmc.firstrow.acc)) {
    abort("`rmc.firstrow.acc`: gravcal's g.getmeta() does not read ad hoc csv files yet; ",
          "use GGIR::g.getmeta() for them.")
  }
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
  for (nm in c("do.brondcounts", "do.neishabouricounts")) {
    if (isTRUE(p[[nm]])) {
      abort("`", nm, "` = TRUE: not supported by gravcal's g.getmeta(); use GGIR::g.getmeta().")
    }
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
  clipthres <- if (length(dynrange)) dynrange - 0.5 else if (identical(mon, "movisens")) 15.5 else 7.5
  list(clipthres = clipthres, sdcriter = 0.013,
       racriter = p$nonwear_range_threshold / 1000,
       approach = p$nonwear_approach)
}

# Rows `i` of a block (a list of equal-length columns).
meta_rows <- function(d, i) lapply(d, function(v) v[i])

# g.getmeta()'s loop over the blocks of an open native source (or samples
# in memory), each block held in the core (meta_store()): R decides what
# GGIR decides per block (the last block, the start, the gap to the carry,
# the carry), the core reads, fills, calibrates and computes. `model`: a
# calibration GGIR's coefficients cannot hold, applied before the epoch
# signals instead of `cal`: list(K, offset and, for a temperature term,
# tempoffset and meantemp), the linear model as apply_model() applies it,
# list(fun) a function of a block's columns giving them calibrated, or
# list(ggir) a calibration as meta_calibration() gives it, in place of
# `cal`. With `gradient` (outcome_gradient_spec(): the fit's linear
# model), also each short epoch's ENMO gradient with respect to the fit's
# coefficients, from
# the raw samples of each block (M$enmo_gradient, a matrix; epoch_signals()
# only: g.getmeta()'s M never has it).
meta_run <- function(src, p, cal, daylimit, verbose, model = NULL, gradient = NULL) {
  sf <- src$sf
  ws3 <- p$windowsizes[1]
  ws2 <- p$windowsizes[2]
  ws <- p$windowsizes[3]
  nwc <- meta_nonwear(src, p)
  tab <- meta_metric_table()
  asked <- tab$name[vapply(meta_do_name(tab$name), function(nm) isTRUE(p[[nm]]), TRUE)]
  metnames <- sub("angle_", "angle", asked, fixed = TRUE)
  filters <- NULL
  fused <- list(conv = FALSE, rec = FALSE)
  if (any(asked %in% tab$name[tab$filtered])) {
    filters <- ggir_filter_coefs(sf, n = p$n, lb = p$lb, hb = p$hb, zc.lb = p$zc.lb,
                                 zc.hb = p$zc.hb, zc.sb = p$zc.sb, zc.order = p$zc.order)
    fused <- stats_filter_fused()
  }
  fe <- format_entry(src$format)
  # the time gaps filled by the decoder (meta_source()); its counters, per
  # block, give GGIR's QClog
  impute <- isTRUE(src$getmeta_timegaps)
  counters <- function() {
    k <- src$report()$counters
    g <- function(nm) if (nm %in% names(k)) k[[nm]] else 0
    c(read = g("timegap_rows_read"), gaps = g("timegaps_imputed"), rows = g("timegap_rows"),
      over = g("timegaps_over_limit"), longest = g("timegap_longest_rows"),
      missing = g("clock_time_missing"), exceeded = g("clock_table_exceeded"))
  }
  before <- if (impute) counters()
  ms <- meta_store(src, time = FALSE)
  store <- ms$store
  short <- list()   # per metric, the blocks' rounded epoch values
  grads <- list()
  long <- list()
  filetooshort <- filecorrupt <- FALSE
  carry <- 0        # rows carried from the block before
  carry_time <- NA_real_  # the carry's last time stamp (desiredtz's clock)
  starttime <- NULL
  wday <- wdayname <- NULL
  light.available <- use.temp <- FALSE
  metricnames_long <- NULL
  short_rows <- src$short_rows %||% 0
  zone <- if (length(p$configtz)) p$configtz else p$desiredtz
  clock <- fe$local_clock
  i <- 1
  LD <- 2
  QClog <- NULL
  while (LD > 1) {
    if (verbose) cat(if (i == 1) "\nLoading chunk: 1" else paste0(" ", i))
    info <- ms$read()
    nr <- info$n
    if (impute) {
      # GGIR's decisions below take the rows read, before the gaps are filled
      now <- counters()
      step <- now - before
      before <- now
      nr <- step[["read"]]
      if (step[["over"]] > 0) {
        limit <- max(c(((ws2 / 60) * 6), 90))
        abort("\"", basename(src$filename), "\" has a time gap of ",
              format(round(now[["longest"]] / sf / 60, 1)),
              " minutes (idle sleep or no data), longer than GGIR's limit of ", format(limit),
              " minutes, beyond which GGIR's g.getmeta() imputes whole epochs; gravcal's ",
              "g.getmeta() does not reproduce that yet (GGIR 3.3-9 stops on it in R before ",
              "4.3). Use GGIR::g.getmeta() on R 4.3 or later.")
      }
      if (step[["missing"]] > 0) {
        abort("The recording's clock passes through times that do not exist in the time zone \"",
              zone, "\" (`configtz`/`desiredtz`).")
      }
      if (step[["exceeded"]] > 0) {
        abort("\"", basename(src$filename), "\" runs more than 400 days from its start: ",
              "gravcal's g.getmeta() reads a per-sample clock in a time zone for 400 days.")
      }
    }
    # the times GGIR's logic reads: the first read, the last two of the
    # block, in the zone's clock as GGIR's reader gives them
    times <- c(info$first_time, info$tail_time[2], info$tail_time[1])
    if (!ms$want_time || info$n == 0) times[] <- NA_real_
    if (!is.null(clock) && !is.na(times[1]) && !isTRUE(src$clock_shifted)) {
      times <- meta_zone_shift(times, zone, per_sample = identical(clock, "sample"))
    }
    isLastBlock <- FALSE
    have <- TRUE
    if (nr == 0) {
      isLastBlock <- TRUE
      if (i == 1) {
        warning("\nFile empty, possibly corrupt.\n", call. = FALSE)
        filetooshort <- filecorrupt <- TRUE
      }
      have <- FALSE
    } else if (nr < sf * ws * 2 + 1) {
      isLastBlock <- TRUE
      if (i == 1) {
        have <- FALSE
        filetooshort <- TRUE
      }
    } else if (nr < short_rows) {
      isLastBlock <- TRUE
    }
    if (have && impute) {
      # GGIR's QClog of the block: its start (the clock's when the file has
      # no time stamps, as GGIR's), its start plus its rows as its end
      start <- if (!is.na(times[1])) times[1] else as.numeric(Sys.time())
      end <- start + info$n
      QClog <- rbind(QClog, data.frame(imputed = step[["gaps"]] > 0, start = start, end = end,
                                       blockLengthSeconds = (end - start) / sf,
                                       timegaps_n = as.integer(step[["gaps"]]),
                                       timegaps_min = step[["rows"]] / sf / 60))
    }
    if (have) {
      if (i == 1) {
        light.available <- ms$light
        use.temp <- ms$temperature
        if (use.temp && mean(info$head_temp[1:10], na.rm = TRUE) > 50) {
          warning("temperature value is unreaslistically high (> 50 Celcius) and will not be used.",
                  call. = FALSE)
          use.temp <- FALSE
        }
        metricnames_long <- c("timestamp", "nonwearscore", "clippingscore",
                              if (light.available) c("lightmean", "lightpeak"),
                              if (use.temp) "temperaturemean", "EN")
      }
      if (carry > 0 && !is.na(times[1]) && !is.na(carry_time)) {
        gap <- as.numeric(times[1] - carry_time)
        if (gap > 3600 * sf) {
          abort("Time gap observed of more than 1 hour between data chunks for ",
                basename(src$filename), " (GGIR's g.getmeta() stops here too).")
        } else if (gap > 3 / sf && gap <= 60 * sf) {
          gc_meta_store_fill_gap(store, carry, round(gap * sf))
        }
      }
      if (i == 1) {
        sw <- meta_start(list(time = if (!is.na(times[1])) times[1]), src, p, sf, ws2)
        starttime <- sw$starttime
        wday <- sw$wday
        wdayname <- sw$wdayname
        if (sw$shift > 1) {
          k <- min(sw$shift, info$size)
          gc_meta_store_keep(store, k, info$size - k)
        }
      }
      LD <- gc_meta_store_size(store)
      if (LD < ws * sf && i == 1) {
        warning("\nWarning data too short for doing non-wear detection 3\n", call. = FALSE)
        isLastBlock <- TRUE
        LD <- 0
      }
      if (LD >= ws * sf) {
        use <- (floor(LD / (ws2 * sf))) * (ws2 * sf)
        # GGIR's data[1:use, ]: the first n_use rows (R's `:` on a use that
        # may not be whole)
        n_use <- floor(abs(use - 1) + 1 + 1.1920928955078125e-07)
        if (!is.null(gradient)) {
          grads[[length(grads) + 1]] <- gc_meta_store_gradient(
            store, n_use, sf, ws3, gradient,
            gradient$temp && (use.temp || !is.null(model)))
        }
        lin <- NULL
        cal_b <- cal
        if (!is.null(model$fun)) {
          d <- model$fun(gc_meta_store_rows(store, 0, n_use))
          gc_meta_store_set_xyz(store, d$x, d$y, d$z)
        } else if (!is.null(model$ggir)) {
          cal_b <- model$ggir
        } else if (!is.null(model)) {
          lin <- model
        }
        r <- gc_meta_store_epochs(store, cal_b, lin, use.temp, sf, p$windowsizes, asked, nwc,
                                  filters, fused$conv, fused$rec, n_use)
        for (nm in asked) short[[nm]] <- c(short[[nm]], list(round(r$short[[nm]], 4)))
        blk <- list(nonwearscore = r$nonwear, clippingscore = r$clipping)
        if (light.available) {
          blk$lightmean <- round(r$lightmean, 4)
          blk$lightpeak <- round(r$lightpeak, 4)
        }
        if (use.temp) blk$temperaturemean <- round(r$temperature, 4)
        blk$EN <- round(r$en, 4)
        long[[length(long) + 1]] <- blk
        # the carry: GGIR's data[(use + 1):LD, ] when more than one row is
        # left (R's `:` and its index truncation on a use that may not be
        # whole); its last time stamp for the next block's gap
        if ((LD - use) > 1) {
          from <- floor(use + 1) - 1
          count <- floor(abs(LD - (use + 1)) + 1 + 1.1920928955078125e-07)
        } else {
          from <- LD
          count <- 0
        }
        back <- LD - (from + count)
        carry_time <- if (count > 0 && back < 2) times[3 - back] else NA_real_
        carry <- gc_meta_store_keep(store, from, count)
        if (ms$keep_time && carry > 0) {
          carry_time <- gc_meta_store_rows(store, carry - 1, 1)$time
        }
      }
    } else {
      LD <- 0
    }
    if (isLastBlock) LD <- 0
    if (ceiling(daylimit) != FALSE && i == ceiling(daylimit)) {
      LD <- 0
      if (verbose) cat(paste0("\nstopped reading data because this analysis is limited to ",
                              ceiling(daylimit), " days\n"))
    }
    i <- i + 1
  }
  rep <- if (!is.null(src$report)) src$report() else list()
  if (isTRUE(rep$counters["imputed_spans"] > 0) || isTRUE(rep$skipped > 0)) {
    warning("\"", basename(src$filename), "\": ", rep$skipped, " damaged ",
            unit_name(src$format, 2), " skipped or imputed; GGIR's QClog of them is not ",
            "reproduced (M$QClog is NULL).", call. = FALSE)
  }
  M <- meta_result(short, long, metnames, metricnames_long, starttime, wday, wdayname,
                   filetooshort, filecorrupt, p, ws3, ws2, QClog)
  if (!is.null(gradient)) M$enmo_gradient <- do.call(rbind, grads)
  invisible(M)
}

# A block's time stamps, from a decoder that reads the file's clock as UTC,
# as GGIR's reader gives them when it reads that clock in `zone`: moved by
# the zone's offset at the block's first time (GGIRread converts each
# block's first time in the zone and counts the samples from there). A
# whole number of seconds added to times in one binade: the same bits as
# GGIR's sums.
# With `per_sample` (lubridate::force_tz() on each time), the offset at
# each sample: computed for the block's first and last, and for every
# sample only when those differ (a change of offset within the block).
meta_zone_shift <- function(time, zone, per_sample = FALSE) {
  if (!length(time) || identical(zone, "UTC") || identical(zone, "GMT")) return(time)
  shift <- function(t) {
    t1 <- floor(t)
    wall <- format(as.POSIXct(t1, origin = "1970-01-01", tz = "UTC"), "%Y-%m-%d %H:%M:%S")
    local <- as.numeric(as.POSIXct(wall, tz = zone))
    if (anyNA(local)) {
      abort("The recording's clock time ", wall[is.na(local)][1], " does not exist in the ",
            "time zone \"", zone, "\" (`configtz`/`desiredtz`).")
    }
    local - t1
  }
  d <- shift(time[1])
  if (per_sample && shift(time[length(time)]) != d) d <- shift(time)
  time + d
}

# The first block's start: GGIR's get_starttime_weekday_truncdata(), which
# starts the analysis at the next whole long epoch (the start's seconds
# rounded up to the next minute).
meta_start <- function(data, src, p, sf, ws2) {
  start_meas <- ws2 / 60
  st <- if (!is.null(data$time)) {
    as.POSIXlt(data$time[1], tz = p$desiredtz, origin = "1970-01-01")
  } else if (!is.null(start <- format_entry(src$format)$ggir_start)) {
    start(src$path, p)
  } else {
    abort("\"", basename(src$filename), "\" has no time stamps to start from.")
  }
  wday <- st$wday + 1
  wdayname <- c("Sunday", "Monday", "Tuesday", "Wednesday", "Thursday", "Friday",
                "Saturday")[wday]
  secshift <- 60 - st$sec
  if (secshift == 60) {
    secshift <- 0
  } else {
    st$min <- st$min + 1
  }
  minshift <- start_meas - (st$min %% start_meas)
  if (minshift == start_meas) minshift <- 0
  shift <- floor((minshift * 60 * sf) + (secshift * sf))
  st$min <- st$min + minshift
  st$sec <- 0
  list(starttime = st, wday = wday, wdayname = wdayname, shift = shift)
}

# GGIR's M from the blocks' values: the columns as GGIR's character
# matrices hold them (R's text of each number, read back), time stamps in
# desiredtz.
meta_result <- function(short, long, metnames, metricnames_long, starttime, wday, wdayname,
                        filetooshort, filecorrupt, p, ws3, ws2, QClog) {
  via_text <- function(v) as.numeric(as.character(v))
  bsc_qc <- data.frame(time = format(Sys.time()), size = gc()[2, 2], stringsAsFactors = FALSE)
  if (filecorrupt || filetooshort) {
    return(invisible(list(filecorrupt = filecorrupt, filetooshort = TRUE,
                          NFilePagesSkipped = 0, metalong = c(), metashort = c(),
                          wday = c(), wdayname = c(), windowsizes = c(),
                          bsc_qc = bsc_qc, QClog = QClog)))
  }
  n_short <- if (length(short)) length(unlist(short[[1]], use.names = FALSE)) else 0
  if (!length(short)) n_short <- 0
  stamp <- function(n, by, min_rows) {
    if (n <= min_rows) return(rep(" ", n))
    t0 <- round(as.numeric(starttime))
    tt <- seq(t0, t0 + (n - 1) * by, by = by)
    strftime(as.POSIXlt(tt, origin = "1970-01-01", tz = p$desiredtz),
             format = "%Y-%m-%dT%H:%M:%S%z")
  }
  ms <- data.frame(timestamp = stamp(n_short, ws3, 1), stringsAsFactors = FALSE)
  for (k in seq_along(metnames)) {
    ms[[metnames[k]]] <- via_text(unlist(short[[k]], use.names = FALSE))
  }
  cols_long <- metricnames_long[-1]
  n_long <- sum(vapply(long, function(b) length(b$nonwearscore), 0))
  ml <- data.frame(timestamp = stamp(n_long, ws2, 2), stringsAsFactors = FALSE)
  for (nm in cols_long) {
    ml[[nm]] <- via_text(unlist(lapply(long, `[[`, nm), use.names = FALSE))
  }
  invisible(list(filecorrupt = filecorrupt, filetooshort = filetooshort,
                 NFilePagesSkipped = 0, metalong = ml, metashort = ms, wday = wday,
                 wdayname = wdayname, windowsizes = p$windowsizes, bsc_qc = bsc_qc,
                 QClog = QClog))
}

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
