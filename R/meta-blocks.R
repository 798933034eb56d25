# g.getmeta()'s block loop (GGIR's g.getmeta() read block by block): the
# source with its time-gap filling (meta_source(), meta_clock_table()), the
# block held in the core (meta_store(), ggir_block_store.hpp), GGIR's
# decisions per block in R (meta_run()), the first block's start
# (meta_start(); the starts of the formats whose first time is in a
# header, and Parmay Matrix's log: R/meta-formats.R). The drop-in and its
# parameters are in R/ggir-part1.R.

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
                read_opts = ro, arg = arg, part = "getmeta", rmc = p$.rmc)
  }
  src <- open(read_opts)
  fe <- format_entry(src$format)
  if (is.null(src$native) || !isTRUE(p$imputeTimegaps) || !isTRUE(fe$ggir_timegaps)) {
    return(src)
  }
  # (the rate the first opening found from the file's data, where `sf` did
  # not give it, taken as found: formats that find it so skip that read)
  if (is.null(sf)) read_opts$found_sf <- src$sf
  ro <- c(read_opts, list(getmeta_timegaps = 1,
                          getmeta_gap_limit = max(c(((p$windowsizes[2] / 60) * 6), 90)),
                          getmeta_epoch_gaps = 1, short_epoch = p$windowsizes[1],
                          long_epoch = p$windowsizes[2]))
  zone <- if (length(p$configtz)) p$configtz else p$desiredtz
  start <- src$info$start_time
  if (is.numeric(start) && length(start) == 1 && is.finite(start)) {
    ro$local_zone <- meta_local_zone(start)
  }
  per_sample <- identical(format_local_clock(src$format, datafile, zone), "sample")
  tab <- if (per_sample && !isFALSE(fe$ggir_time) &&
             is.numeric(start) && length(start) == 1 && is.finite(start)) {
    meta_clock_table(zone, start)
  }
  if (!is.null(tab)) {
    ro$clock <- tab$text
    ro$clock_until <- tab$until
  }
  gc_decoder_close(src$native$ptr)
  source_with(open(ro), getmeta_timegaps = TRUE, epoch_gaps = TRUE,
              clock_shifted = !is.null(tab))
}

# The zone in which GGIR 3.3-9's g.imputeTimegaps() reads the time of day
# of a gap longer than its limit, as "second offset ..." from two days
# before `start` for 400 days (the offset from each UTC second on): on R 4.3
# or later data.table::hour() of a number, R's session zone (TZ); on R 4.1
# and 4.2.0 the number read in GMT (""); on R 4.2.1 to 4.2.3 GGIR stops
# there (as.POSIXlt() wants an origin), and gravcal gives what GGIR gives on
# the R versions users have now, the session zone's.
meta_local_zone <- function(start, days = 400,
                            version = c(R.version$major, R.version$minor)) {
  if (!(as.numeric(version[1]) >= 4 && as.numeric(version[2]) > 2)) return("")
  z <- zone_offsets("", start, days)
  z$offset[is.na(z$offset)] <- 0
  if (all(z$offset == 0)) return("")
  paste(sprintf("%.0f %.0f", z$at, z$offset), collapse = " ")
}

# A zone's offsets from UTC (`zone`: "" the session's) over `days` from two
# days before `start`: `at`, the table's first second then each change's
# UTC second (found at every 10 minutes, then halved to the second);
# `offset`, the offset from there on; `before`, the offset before each
# change; `until`, the table's last second.
zone_offsets <- function(zone, start, days) {
  off <- function(t) {
    as.POSIXlt(as.POSIXct(t, origin = "1970-01-01", tz = "UTC"), tz = zone)$gmtoff
  }
  from <- floor(start / 600) * 600 - 2 * 86400
  until <- from + (days + 2) * 86400
  g <- seq(from, until, by = 600)
  o <- off(g)
  ch <- which(o[-1] != o[-length(o)])
  at <- vapply(ch, function(i) {
    lo <- g[i]
    hi <- g[i + 1]
    while (hi - lo > 1) {
      mid <- floor((lo + hi) / 2)
      if (isTRUE(off(mid) == o[i + 1])) hi <- mid else lo <- mid
    }
    hi
  }, 0)
  list(at = c(from, at), offset = c(o[1], o[ch + 1]), before = o[ch], until = until)
}

# The shift GGIR's reader adds to each time of a per-sample clock (the
# file's clock, read as UTC, read again as the clock time in `zone`), as a
# table of its changes over `days` from two days before `start`: the zone's
# offset changes found to the second (zone_offsets()), each taking effect
# at the clock time where the zone's clock first shows it: a clock time
# that occurs twice (the hour a clock goes back) is read as the later one,
# a clock time that does not occur (the hour a clock goes forward) with the
# new offset, as GGIR's .gt3x times show. NULL in UTC. list(text = "second
# shift ...", until = the table's last second).
meta_clock_table <- function(zone, start, days = 400) {
  if (!length(zone) || !nzchar(zone) || zone %in% c("UTC", "GMT")) return(NULL)
  z <- zone_offsets(zone, start, days)
  if (anyNA(z$offset)) abort("The time zone \"", zone, "\" gives no offsets from UTC.")
  n <- length(z$at)
  clock <- z$at
  if (n > 1) clock[-1] <- z$at[-1] + pmin(z$before, z$offset[-1])
  list(text = paste(sprintf("%.0f %.0f", clock, -z$offset), collapse = " "),
       until = z$until)
}

# The block store of meta_run() (gc_meta_store(), ggir_block_store.hpp)
# and its reader: one of GGIR's blocks appended to it, from a native
# decoder or from samples in memory (`units` rows a block). `time`: keep a
# time column (GGIR's time-gap imputation reads it).
meta_store <- function(src, time) {
  cols <- if (!is.null(src$native)) {
    c(temperature = isTRUE(src$native$info$temperature),
      light = isTRUE(src$native$info$light), wear = isTRUE(src$native$info$wear))
  } else {
    c(temperature = !is.null(src$samples$temperature), light = !is.null(src$samples$light),
      wear = FALSE)
  }
  store <- gc_meta_store(cols[["temperature"]], time, cols[["light"]], cols[["wear"]])
  want_time <- !isFALSE(format_entry(src$format)$ggir_time)
  # rows a read of the decoder's at most (the block is the same whatever
  # it is): its temperature, light and time wait in buffers of this many
  # rows before they join their columns, 512 KB each (at 2^20 rows, the two
  # 8 MB buffers of a read beside the calibration stayed in that thread's
  # heap: 16 MB more at the peak of every metric)
  chunk <- 2^16
  if (!is.null(src$native)) {
    read <- function() gc_meta_store_read(store, src$native$ptr, src$units, chunk, want_time)
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
       light = cols[["light"]], wear = cols[["wear"]], keep_time = time, want_time = want_time,
       chunk = chunk)
}

# Rows `i` of a block (a list of equal-length columns).
meta_rows <- function(d, i) lapply(d, function(v) v[i])

# Why GGIR 3.3-9's g.getmeta() stops on a recording with a block, for the
# metrics `asked` (meta_metric_table()'s names) and Neishabouri's count
# columns `neish`, or NULL. Its block reads the first column of
# g.applymetrics()'s result, which has none without a metric ("subscript
# out of bounds"); and g.applymetrics() gives HFEN with any of HFX, HFY,
# HFZ, and all three axes of roll_med_acc and of dev_roll_med_acc with any
# one, asked or not, while g.getmeta() keeps the asked columns but names
# them all ("'names' attribute [..] must be the same length as the vector
# [..]").
meta_ggir_stops <- function(asked, neish) {
  if (!length(asked) && !length(neish)) {
    return(paste0("No metric asked: every `do.*` of `params_metrics` GGIR computes is FALSE, ",
                  "and GGIR's g.getmeta() stops on the first block of such a recording ",
                  "(\"subscript out of bounds\"); gravcal's does too. Ask at least one ",
                  "(GGIR's default: `do.enmo` and `do.anglez`)."))
  }
  do <- meta_do_name
  axes <- function(base) paste0(base, c("x", "y", "z"))
  groups <- list(list(any = c("HFX", "HFY", "HFZ"), gives = "HFEN"),
                 list(any = axes("roll_med_acc_"), gives = axes("roll_med_acc_")),
                 list(any = axes("dev_roll_med_acc_"), gives = axes("dev_roll_med_acc_")))
  for (g in groups) {
    missing <- setdiff(g$gives, asked)
    if (any(g$any %in% asked) && length(missing)) {
      return(paste0("`", paste(do(intersect(g$any, asked)), collapse = "`, `"), "` without `",
                    paste(do(missing), collapse = "`, `"), "`: GGIR's g.applymetrics() computes ",
                    paste(missing, collapse = ", "), " with ", if (length(g$any) > 1) "any of ",
                    paste(g$any, collapse = ", "), ", and its g.getmeta() then stops on the ",
                    "names of its metrics (\"'names' attribute must be the same length as the ",
                    "vector\"); gravcal's does too. Ask for ",
                    paste0("`", do(missing), "`", collapse = ", "), " as well (set to TRUE)."))
    }
  }
  NULL
}

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
# only: g.getmeta()'s M never has it). `ggir`: g.getmeta()'s run, which
# stops where GGIR's does on the metrics asked (meta_ggir_stops());
# epoch_signals() computes what it is asked.
meta_run <- function(src, p, cal, daylimit, verbose, model = NULL, gradient = NULL,
                     myfun = NULL, ggir = FALSE) {
  sf <- src$sf
  ws3 <- p$windowsizes[1]
  ws2 <- p$windowsizes[2]
  ws <- p$windowsizes[3]
  nwc <- meta_nonwear(src, p)
  tab <- meta_metric_table()
  asked <- tab$name[vapply(meta_do_name(tab$name), function(nm) isTRUE(p[[nm]]), TRUE)]
  # Neishabouri's counts (actilifecounts, in R on each block) after the
  # metrics, as GGIR names them; `cols`: the sheet's metric columns
  neish <- if (isTRUE(p$do.neishabouricounts)) paste0("NeishabouriCount_", c("x", "y", "z", "vm"))
  cols <- c(asked, neish)
  metnames <- c(sub("angle_", "angle", asked, fixed = TRUE), neish)
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
    k <- src$report()
    g <- function(nm) report_count(k, nm)
    c(read = g("timegap_rows_read"), gaps = g("timegaps_imputed"), rows = g("timegap_rows"),
      over = g("timegaps_over_limit"), longest = g("timegap_longest_rows"),
      missing = g("clock_time_missing"), exceeded = g("clock_table_exceeded"),
      not_filled = g("timegaps_not_filled"))
  }
  before <- if (impute) counters()
  na_times <- function() {
    if (!isTRUE(fe$rmc) || is.null(src$report)) return(FALSE)
    report_count(src$report(), "time_not_existing") > 0
  }
  last_read <- NA_real_  # the last time stamp of the block before
  # (the store g.part1() made, its first block read beside g.calibrate()'s
  # pass: R/meta-ahead.R)
  ms <- src$ahead_store %||% meta_store(src, time = FALSE)
  store <- ms$store
  on.exit(gc_meta_store_release(store), add = TRUE)
  # GGIR's metashort and metalong (R/meta-sheet.R): the metrics (by
  # `asked`), a myfun's columns as text and the ENMO gradient's columns
  # (epoch_signals()); metalong's columns once the first block says which
  grad_cols <- NULL
  short <- sheet_new(cols, myfun$colnames)
  long <- NULL
  # GGIR's long gaps imputed as whole epochs (epoch_gaps): the rows of the
  # store that carry GGIR's remaining_epochs (0-based) and their values,
  # whether GGIR's block has that column, and its last value (GGIR's
  # remaining_epochs, which outlives the block it was read in)
  marks <- data.frame(pos = numeric(0), remaining = numeric(0))
  marked_prev <- FALSE
  last_marks <- NULL
  given <- 0        # rows the decoder has given
  filetooshort <- filecorrupt <- FALSE
  carry <- 0        # rows carried from the block before
  carry_time <- NA_real_  # the carry's last time stamp (desiredtz's clock)
  starttime <- NULL
  wday <- wdayname <- NULL
  light.available <- use.temp <- FALSE
  metricnames_long <- NULL
  short_rows <- src$short_rows %||% 0
  zone <- if (length(p$configtz)) p$configtz else p$desiredtz
  clock <- format_local_clock(src$format, src$path, zone)
  threads <- gravcal_threads()
  i <- 1
  LD <- 2
  QClog <- NULL
  logged <- 0  # rows of the reader's log taken
  while (LD > 1) {
    if (verbose) cat(if (i == 1) "\nLoading chunk: 1" else paste0(" ", i))
    size_before <- gc_meta_store_size(store)
    info <- ms$read()
    if (ms$wear) rmc_check_wear(src)
    nr <- info$n
    marked <- FALSE
    if (isTRUE(src$epoch_gaps)) {
      eg <- gc_decoder_epoch_gaps(src$native$ptr)
      new <- data.frame(pos = size_before + (eg$row - given), remaining = eg$remaining)
      marked <- nrow(new) > 0 || (carry > 0 && marked_prev)
      marks <- rbind(marks[marks$pos < size_before, , drop = FALSE], new)
    }
    given <- given + info$n
    if (impute) {
      # GGIR's decisions below take the rows read, before the gaps are filled
      now <- counters()
      step <- now - before
      before <- now
      nr <- step[["read"]]
      if (step[["not_filled"]] > 0) {
        abort("\"", basename(src$filename), "\" has a time gap of more than 400 days (idle ",
              "sleep or a damaged time stamp); gravcal's g.getmeta() does not impute it.")
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
    # ActivPAL days through an hour desiredtz's clocks skip: NA time stamps
    # (lubridate::force_tz()), on which GGIR stops where its start, or a
    # block's first or the last before it, is one
    if (info$n > 0 && ms$want_time && na_times()) {
      if (i == 1 && is.na(times[1])) {
        abort("\"", basename(src$filename), "\" starts in an hour the clocks of `desiredtz` = \"",
              zone, "\" skip (daylight saving), where GGIR's time stamps are NA ",
              "(lubridate::force_tz()): GGIR's g.getmeta() stops on it too.")
      }
      if (i > 1 && (is.na(times[1]) || is.na(last_read)) && (impute || carry > 0)) {
        abort("\"", basename(src$filename), "\": a block of GGIR's reading starts or ends in ",
              "an hour the clocks of `desiredtz` = \"", zone, "\" skip (daylight saving), ",
              "where GGIR's time stamps are NA (lubridate::force_tz()): GGIR's g.getmeta() stops ",
              "there too (its time gap between blocks is NA).")
      }
    }
    last_read <- times[3]
    # where GGIR's reader stops, or reads what the decoder does not follow
    # (GENEActiv: damaged pages), from what has been read so far
    if (!is.null(fe$ggir_read_stops) && !is.null(src$native)) {
      why <- fe$ggir_read_stops(src, "getmeta")
      if (!is.null(why)) {
        abort("\"", basename(src$filename), "\" (`datafile`) has ", why, ": GGIR's ",
              "g.getmeta() gives no result there that gravcal reproduces, so gravcal's refuses ",
              "the file (calibrate() reads it).")
      }
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
    if (!is.null(fe$ggir_block_qclog)) {
      # the reader's log of this block (.cwa: readAxivity's), kept as GGIR
      # keeps it: when the block's samples are
      rows <- fe$ggir_block_qclog(src, logged)
      logged <- logged + NROW(rows)
      if (have) QClog <- rbind(QClog, rows)
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
        # the log GGIR's reader gives with its first block (Parmay Matrix)
        if (!is.null(fe$ggir_qclog)) QClog <- rbind(QClog, fe$ggir_qclog(src))
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
      # a time stamp the decoder leaves NaN where GGIR's reader does not
      # define it (GENEActiv: a page read at 0 Hz), read by GGIR here
      if (meta_undefined_time(src, if (i == 1) times[1] else if (carry > 0) c(times[1], carry_time))) {
        abort("\"", basename(src$filename), "\" (`datafile`) has a page read at 0 Hz (its ",
              "\"Measurement Frequency:\" damaged or cut), after which GGIR's reader's time ",
              "stamps are not defined (they depend on the platform), and GGIR's g.getmeta() ",
              "reads them at a block's edge; gravcal's refuses the file (calibrate() reads it).")
      }
      if (carry > 0 && !is.na(times[1]) && !is.na(carry_time)) {
        gap <- as.numeric(times[1] - carry_time)
        if (gap > 3600 * sf) {
          abort("Time gap observed of more than 1 hour between data chunks for ",
                basename(src$filename), " (GGIR's g.getmeta() stops here too).")
        } else if (gap > 3 / sf && gap <= 60 * sf) {
          k <- round(gap * sf)
          gc_meta_store_fill_gap(store, carry, k)
          # the rows put in copy the carry's last, its mark too
          at <- marks$pos >= carry
          marks$pos[at] <- marks$pos[at] + k
          last <- marks[marks$pos == carry - 1, , drop = FALSE]
          if (nrow(last)) {
            marks <- rbind(marks, data.frame(pos = carry - 1 + seq_len(k),
                                             remaining = last$remaining[1]))
            marks <- marks[order(marks$pos), , drop = FALSE]
          }
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
          marks$pos <- marks$pos - k
          marks <- marks[marks$pos >= 0, , drop = FALSE]
        }
      }
      LD <- gc_meta_store_size(store)
      if (LD < ws * sf && i == 1) {
        warning("\nWarning data too short for doing non-wear detection 3\n", call. = FALSE)
        isLastBlock <- TRUE
        LD <- 0
      }
      if (LD >= ws * sf) {
        # where GGIR's g.getmeta() stops once it has a block (a file too
        # short for one gets its M)
        if (ggir && !is.null(why <- meta_ggir_stops(asked, neish))) abort(why)
        use <- meta_myfun_use((floor(LD / (ws2 * sf))) * (ws2 * sf), myfun)
        # GGIR's data[1:use, ]: the first n_use rows (R's `:` on a use that
        # may not be whole)
        n_use <- floor(abs(use - 1) + 1 + 1.1920928955078125e-07)
        # GGIR's remaining_epochs of this block: its marks in the rows used
        # (1-based), or the last block's where this block has no such column
        if (marked) last_marks <- marks[marks$pos < n_use, , drop = FALSE]
        fill <- last_marks
        grad <- NULL
        if (!is.null(gradient)) {
          grad <- gc_meta_store_gradient(store, n_use, sf, ws3, gradient,
                                         gradient$temp && (use.temp || !is.null(model)))
          grad_names <- colnames(grad)
          grad_cols <- paste0(".gradient", seq_len(ncol(grad)))
          colnames(grad) <- grad_cols
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
        out_fun <- counts <- NULL
        if (!is.null(myfun) || length(neish)) {
          # what runs in R takes the block's samples calibrated in R, as GGIR
          # calibrates them
          xyz <- meta_myfun_xyz(gc_meta_store_rows(store, 0, n_use), cal, use.temp)
          if (length(neish)) counts <- meta_counts_block(xyz, sf, ws3, p$actilife_LFE, neish)
          if (!is.null(myfun)) {
            out_fun <- meta_myfun_block(xyz, myfun, sf, ws3, starttime, p$interpolationType)
          }
          rm(xyz)
        }
        r <- gc_meta_store_epochs(store, cal_b, lin, use.temp, sf, p$windowsizes, asked, nwc,
                                  filters, fused$conv, fused$rec, n_use, threads)
        n_block <- if (length(asked)) length(r$short[[1]]) else NROW(counts)
        if (!is.null(counts) && length(asked) && nrow(counts) != n_block) {
          abort("actilifecounts::get_counts() gave ", nrow(counts), " epochs for a block of ",
                n_block, " (GGIR's g.getmeta() stops on such a block too).")
        }
        short <- sheet_put(short, lapply(r$short[asked], round, 4))
        if (!is.null(counts)) short <- sheet_put(short, counts)
        if (!is.null(grad)) short <- sheet_put(short, grad)
        if (!is.null(out_fun)) {
          # GGIR's columns after the counts start one too early (its column
          # index moves on by 3 for their 4): the function's first column
          # lands on NeishabouriCount_vm, its last stays blank
          colnames(out_fun) <- if (length(neish)) {
            c(neish[4], myfun$colnames)[seq_len(ncol(out_fun))]
          } else {
            myfun$colnames
          }
          short <- sheet_put(short, out_fun)
        }
        blk <- list(nonwearscore = r$nonwear, clippingscore = r$clipping)
        if (light.available) {
          blk$lightmean <- round(r$lightmean, 4)
          blk$lightpeak <- round(r$lightpeak, 4)
        }
        if (use.temp) blk$temperaturemean <- round(r$temperature, 4)
        blk$EN <- round(r$en, 4)
        if (is.null(long)) long <- sheet_new(names(blk))
        long <- sheet_put(long, blk)
        if (!is.null(fill) && nrow(fill)) {
          # GGIR's epoch-level imputation: the long epoch of each mark
          # non-wear (3), the short epoch's metrics 0 (EN 1), each repeated
          pos1 <- fill$pos + 1
          long <- sheet_impute(long, floor(pos1 / (ws2 * sf)) + long$count,
                               floor(fill$remaining * (ws3 / ws2)) + 1, list(nonwearscore = 3))
          zero <- c(grep("time|angle", cols, invert = TRUE, value = TRUE), grad_cols)
          set <- stats::setNames(rep(list(0), length(zero)), zero)
          if ("EN" %in% asked) set$EN <- 1
          short <- sheet_impute(short, floor(pos1 / (ws3 * sf)) + short$count,
                                fill$remaining, set)
        }
        long <- sheet_advance(long, length(blk$nonwearscore))
        short <- sheet_advance(short, n_block)
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
        marks <- marks[marks$pos >= from & marks$pos < from + count, , drop = FALSE]
        marks$pos <- marks$pos - from
        marked_prev <- marked
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
  # the block's memory given back before M is made (on.exit() above gives
  # it back on an error)
  gc_meta_store_release(store)
  rep <- if (!is.null(src$report)) src$report() else list()
  # (a format whose reader's log is M$QClog keeps its damaged units as
  # GGIR's reader keeps them, and logs them there)
  counter <- function(nm) report_count(rep, nm)
  imputed <- counter("imputed_spans")
  if (is.null(fe$ggir_qclog) && is.null(fe$ggir_block_qclog) &&
      (imputed > 0 || isTRUE(rep$skipped > 0))) {
    # (csv lines the decoder skips; .gt3x records skipped are refused,
    # gt3x_ggir_stops(); GENEActiv pages are read as GGIR's reader reads
    # them, none skipped: ggir_damage_warning)
    warning("\"", basename(src$filename), "\": ", rep$skipped, " damaged ",
            unit_name(src$format, rep$skipped), " skipped, ", imputed, " span",
            if (imputed != 1) "s", " imputed (damage, or time stamps that jump); GGIR's reader ",
            "may keep part of a damaged ", unit_name(src$format, 1),
            ", so M can differ from GGIR's from there on, ",
            "and GGIR's QClog of them is not reproduced (M$QClog is NULL).", call. = FALSE)
  }
  if (!is.null(fe$ggir_block_qclog) && isTRUE(rep$skipped > 0)) {
    # (GGIR's reader warns of each)
    warning("\"", basename(src$filename), "\": ", rep$skipped, " damaged ",
            unit_name(src$format, rep$skipped), " skipped, as GGIR's reader skips them ",
            "(M$QClog logs them).", call. = FALSE)
  }
  if (!is.null(fe$ggir_damage_warning)) fe$ggir_damage_warning(src)
  M <- meta_result(short, long, cols, metnames, metricnames_long, starttime, wday, wdayname,
                   filetooshort, filecorrupt, p, ws3, ws2, QClog, myfun)
  if (!is.null(gradient)) {
    M$enmo_gradient <- do.call(cbind, lapply(grad_cols, function(nm) sheet_column(short, nm)))
    if (!is.null(M$enmo_gradient)) colnames(M$enmo_gradient) <- grad_names
  }
  invisible(M)
}

# Whether `times` (what GGIR's g.getmeta() reads of a block) hold one that
# the native decoder left NaN because GGIR's reader does not define it (its
# count "ggir_time_undefined": GENEActiv).
meta_undefined_time <- function(src, times) {
  # (NaN, or NA once the zone's shift has been applied)
  if (!anyNA(times) || is.null(src$native) || is.null(src$report)) return(FALSE)
  report_count(src$report(), "ggir_time_undefined") > 0
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
  # (a time that is not finite, GENEActiv's after a page read at 0 Hz,
  # stays as it is)
  ok <- is.finite(time)
  if (!any(ok)) return(time)
  d <- shift(time[ok][1])
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
