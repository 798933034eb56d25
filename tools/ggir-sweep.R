# Usage: Rscript tools/ggir-sweep.R [n] [seed]
#   (with gravcal installed: R_LIBS=<gravcal's library> Rscript tools/ggir-sweep.R 40 1)
#   SWEEP_TARGET=calibrate Rscript tools/ggir-sweep.R 40 1: g.calibrate() instead
#
# A randomized differential test ("parameter sweep") of gravcal::g.getmeta()
# against GGIR::g.getmeta() (GGIR 3.3-9): n random cases (default 5; seed
# default 1), each a file and a random draw of GGIR parameters, run through
# both, their M compared as tests/testthat/test-ggir-getmeta.R compares
# them (expect_same_meta()): identical() on every element of M but bsc_qc
# (GGIR's wall clock and memory), QClog's wall-clock `start` and `end`
# dropped from both first. GGIR runs here, live; nothing is cached.
#
# Files: synthetic recordings written once per run (simulate_recording()
# of 26-40 hours at 20-100 Hz with two flat stretches at rest, GGIR's
# non-wear, and 41 clipped samples, as helper-meta.R's
# write_meta_recording() makes them, written by write_recording() as .cwa,
# GENEActiv .bin, .gt3x, ActiGraph csv, Movisens, Parmay Matrix .bin, so
# that GGIR reads several blocks), one real ActiGraph recording (agcounts'
# 20.7 h at 30 Hz from ../shared/data, written as .gt3x), and the small
# real device files GGIRread, GGIR and read.gt3x ship.
#
# Parameters drawn per case (GGIR's four lists, completed from
# GGIR::load_params() with utils::modifyList(), as the tests do):
# windowsizes, chunksize, desiredtz and configtz, a random subset of the
# do.* metrics (never do.neishabouricounts or do.brondcounts; see
# draw_args() for the subsets on which GGIR 3.3-9 itself stops),
# nonwear_approach, sometimes dynrange, sometimes calibration coefficients
# (offset, scale, and sometimes tempoffset with meantempcal), sometimes the
# filter's lb, hb (below the file's Nyquist frequency) and n; gravcal is
# sometimes given GGIR's inspectfileobject too.
#
# Outcome of a case:
#   identical         every element of M but bsc_qc identical()
#   differs           some element not: which, and for the first one its
#                     first differing column, row and both values
#   refused           GGIR gives M, gravcal stops with an error naming one of
#                     GGIR's parameters (`name` in backticks)
#   both error        GGIR (g.inspectfile() or g.getmeta()) and gravcal stop
#   only GGIR errors  / only gravcal errors: one side stops, the other gives M
#
# Results: a markdown table, one row a case, appended as the cases run
# (<out>.md), and the raw records (<out>.rds: a list, one element a case,
# with the arguments, messages, differences, timings and the R code that
# reproduces the case), rewritten after every case, so a partial run
# still reports. Prints a line per case.
#
# Environment (all optional):
#   SWEEP_OUT       prefix of the result files (default /tmp/sweep-results)
#   SWEEP_FILES     folder for the synthetic recordings (default: a new
#                   folder under tempdir(), removed at the end; a folder
#                   given here is kept, so that cases can be rerun)
#   SWEEP_DEADLINE  a UTC time ("2026-12-02 02:00:00"): no case starts after it
#   SWEEP_THREADS   options(gravcal.threads) for gravcal (default: gravcal's own)
#
#   SWEEP_TARGET    getmeta (default) or calibrate (below)
#
# SWEEP_TARGET=calibrate: the same sweep of gravcal::g.calibrate() against
# GGIR::g.calibrate(), both called as GGIR's g.part1() calls it
# (GGIR::g.inspectfile(f, desiredtz =, params_rawdata =, configtz =), then
# g.calibrate(f, params_rawdata =, params_general =, params_cleaning =,
# inspectfileobject = I, verbose = FALSE); gravcal sometimes without I),
# every element of the result but bsc_qc (GGIR's wall clock and memory)
# compared with identical(), as expect_same_as_ggir() does. The files: the
# same pool, plus one ad hoc csv recording (written by write_adhoc_csv():
# random unit, header, time column, temperature unit, sometimes a gap),
# read with its rmc.* list. The parameters (draw_args_calibrate()): the
# ones GGIR's g.calibrate() and g.readaccfile() read (chunksize, spherecrit,
# minloadcrit, printsummary, interpolationType, frequency_tol, desiredtz,
# configtz; rmc.noise, rmc.check4timegaps, rmc.doresample for ad hoc csv)
# and, sometimes, ones GGIR takes and leaves alone there (windowsizes,
# dynrange, do.cal, backup.cal.coef, minimumFileSizeMB, imputeTimegaps,
# rmc.noise for a device file, dayborder, params_cleaning's), which gravcal
# must take and leave alone too.
#
# The file can also be source()d (nothing runs then) to rebuild a synthetic
# recording from its recipe: make_synthetic(recipe, file).

`%||%` <- function(a, b) if (is.null(a)) b else a

# ---- files -------------------------------------------------------------------

# A synthetic recording from its recipe (a list: format, sf, hours, seed,
# start, rests = fractions of the two rest stretches), written to `file`
# (for Movisens a folder; the path to give g.getmeta() is returned).
make_synthetic <- function(recipe, file) {
  r <- recipe
  rec <- gravcal::simulate_recording(hours = r$hours, sf = r$sf, seed = r$seed,
                                     start = as.POSIXct(r$start, tz = "UTC"),
                                     tempoffset = c(0.001, -0.002, 0.0005))
  n <- nrow(rec)
  old <- if (exists(".Random.seed", envir = globalenv())) get(".Random.seed", envir = globalenv())
  on.exit(if (!is.null(old)) assign(".Random.seed", old, envir = globalenv()))
  set.seed(r$seed)
  # two stretches flat on a table (1 mg noise): GGIR's non-wear
  for (s in r$rests) {
    i <- round(s[1] * n):round(s[2] * n)
    rec$x[i] <- 0.02 + stats::rnorm(length(i), 0, 0.001)
    rec$y[i] <- -0.01 + stats::rnorm(length(i), 0, 0.001)
    rec$z[i] <- 0.99 + stats::rnorm(length(i), 0, 0.001)
  }
  # 41 samples at 7.9 g: clipping
  rec$x[round(0.8 * n) + 0:40] <- 7.9
  if (r$format == "adhoc_csv") {
    drop <- if (!is.null(r$gap)) round(r$gap * n) + seq_len(120 * r$sf) - 1L else integer()
    rmc <- gravcal:::write_adhoc_csv(rec, file, sf = r$sf, header = r$header, unit = r$unit,
                                     time = r$time, temp_unit = r$temp_unit,
                                     sf_header = r$sf_header, start = r$start, drop = drop)
    return(structure(file, rmc = rmc))
  }
  # formats without a temperature channel (write_recording() would warn)
  if (r$format %in% c("gt3x", "actigraph_csv")) rec$temperature <- NULL
  rec <- rec[, intersect(c("x", "y", "z", "temperature"), names(rec))]
  gravcal::write_recording(rec, file, sf = r$sf, format = r$format, start = r$start,
                           overwrite = TRUE)
  if (r$format == "movisens") file.path(file, "acc.bin") else file
}

# A random recipe for `format`: 26-40 hours (fewer at high rates, to keep
# GGIR's runs short), a rate the format can hold, a start that is sometimes
# a fraction past the second (.cwa) or just before a change of UTC offset
# in one of the zones drawn below.
draw_recipe <- function(format, seed) {
  sf <- switch(format,
               cwa = sample(c(25, 50, 100), 1, prob = c(0.5, 0.3, 0.2)),
               geneactiv = sample(c(20, 30, 40, 50, 75, 100), 1),
               gt3x = sample(c(20, 30, 40, 50, 60, 80, 100), 1),
               actigraph_csv = sample(c(20, 25, 30), 1),
               movisens = 64,
               parmay = sample(c(20, 25, 50, 100), 1),
               adhoc_csv = sample(c(10, 20, 25, 30), 1))
  hours <- if (sf >= 60) sample(26:32, 1) else sample(26:40, 1)
  starts <- c(plain = "2024-03-04 09:07:23",
              eu_spring = "2024-03-30 21:11:00",     # Europe: 31 March 01:00 UTC
              eu_autumn = "2024-10-26 20:13:07",     # Europe: 27 October 01:00 UTC
              ny_autumn = "2024-11-02 18:00:00",     # New York: 3 November 06:00 UTC
              lord_howe = "2024-04-06 05:30:00",     # Lord Howe: 6 April 15:00 UTC
              new_year = "2024-01-01 00:07:13")
  start <- sample(starts, 1)
  if (format == "cwa" && stats::runif(1) < 0.5) start <- paste0(start, ".37")
  a <- stats::runif(1, 0.1, 0.4)
  b <- stats::runif(1, 0.5, 0.7)
  r <- list(format = format, sf = sf, hours = hours, seed = seed, start = unname(start),
            rests = list(round(c(a, a + 0.07), 3), round(c(b, b + 0.03), 3)))
  if (format == "adhoc_csv") {
    r$unit <- sample(c("g", "mg", "bit"), 1)
    r$time <- sample(c("none", "UNIXsec", "UNIXmsec", "POSIX", "character"), 1)
    r$header <- if (stats::runif(1) < 0.5) c("device,sim", "serial,S1") else character()
    r$sf_header <- stats::runif(1) < 0.3
    r$temp_unit <- sample(c("C", "K", "F"), 1)
    # a 2-minute gap (samples left out) for rmc.check4timegaps
    if (r$time != "none" && stats::runif(1) < 0.5) r$gap <- round(stats::runif(1, 0.75, 0.95), 3)
  }
  r
}

# The real files: GGIRread's, GGIR's and read.gt3x's test files that are raw
# acceleration (not epoch data, not .wav), each once.
real_files <- function() {
  rd <- system.file("testfiles", package = "GGIRread")
  gg <- system.file("testfiles", package = "GGIR")
  rg <- system.file("extdata", package = "read.gt3x")
  f <- c(file.path(rd, c("ax3_testfile.cwa", "ax3_testfile_corrupt_blocks_0_13_14_142_143_144.cwa",
                         "ax6_testfile.cwa", "GENEActiv_testfile.bin", "genea_testfile.bin",
                         "mtx_100Hz_acc_HR_temp.BIN", "mtx_12.5Hz_acc_gyro.BIN",
                         "mtx_12.5Hz_acc.BIN", "mtx_25Hz_acc_HR.BIN", "mtx_corrupted.bin",
                         "mtx_corrupted_full.bin")),
         file.path(gg, c("ActiGraph13.csv", "ActiGraph61.csv", "ActiGraph13_timestamps_headers.csv",
                         "actigraph_testfile.gt3x", "ax3_testfile_unix_timestamps.csv",
                         "ax6_testfile_formatted_timestamps.csv")),
         file.path(rg, "TAS1H30182785_2019-09-17.gt3x"))
  f[file.exists(f)]
}

# agcounts' real ActiGraph samples (../shared/data/agcounts: 20.7 h at 30
# Hz, no time stamps) written as a .gt3x file starting 2024-03-04 09:07:23
# UTC; NULL when the folder is not there.
agcounts_gt3x <- function(folder) {
  d <- c("/work/shared/data/agcounts", file.path("..", "shared", "data", "agcounts"))
  d <- d[dir.exists(d)][1]
  if (is.na(d)) return(NULL)
  v <- list()
  for (ax in c("X", "Y", "Z")) {
    e <- new.env()
    load(file.path(d, paste0("calibration", ax, "axis.RData")), envir = e)
    v[[tolower(ax)]] <- get(ax, envir = e)
  }
  f <- file.path(folder, "agcounts-real-30Hz.gt3x")
  gravcal::write_recording(as.data.frame(v), f, sf = 30, format = "gt3x",
                           start = "2024-03-04 09:07:23", overwrite = TRUE)
  f
}

# ---- parameters ----------------------------------------------------------------

zones <- c("", "UTC", "Europe/Amsterdam", "America/New_York", "Asia/Kolkata", "Australia/Lord_Howe")
metric_names <- function(defaults) {
  nm <- grep("^do[.]", names(defaults$params_metrics), value = TRUE)
  setdiff(nm, c("do.neishabouricounts", "do.brondcounts"))
}

# One case's arguments: only the entries that differ from GGIR's defaults
# (the lists are completed from GGIR::load_params() when the case runs).
# Numbers are whole numbers over powers of 10, so that their deparsed text
# reads back as the same double.
draw_args <- function(defaults, sf) {
  pm <- list()
  p_on <- sample(c(0.1, 0.25, 0.5), 1)
  on <- stats::setNames(stats::runif(length(metric_names(defaults))) < p_on, metric_names(defaults))
  # GGIR 3.3-9's g.getmeta() stops ("'names' attribute [k] must be the same
  # length as the vector [m]") unless roll_med_acc_x, _y, _z are asked all
  # or none, dev_roll_med_acc_x, _y, _z too, and HFX, HFY, HFZ only with
  # HFEN (checked one metric at a time on a 3 h .cwa recording). So that
  # most cases compare two Ms, 4 in 5 draws keep to those rules; the fifth
  # is drawn freely (GGIR stops there: gravcal's outcome is recorded).
  if (stats::runif(1) < 0.8) {
    for (g in list(paste0("do.roll_med_acc_", c("x", "y", "z")),
                   paste0("do.dev_roll_med_acc_", c("x", "y", "z")))) {
      on[g] <- on[g[1]]
    }
    if (any(on[paste0("do.hf", c("x", "y", "z"))])) on[["do.hfen"]] <- TRUE
  }
  for (m in names(on)) {
    if (!identical(on[[m]], defaults$params_metrics[[m]])) pm[[m]] <- on[[m]]
  }
  if (stats::runif(1) < 0.35) {
    hbs <- c(3, 4, 5, 6, 8, 10, 12, 15, 20)
    hbs <- hbs[hbs < (if (is.na(sf)) 6.25 else sf / 2) - 0.25]
    if (length(hbs)) {
      pm$lb <- sample(c(0.1, 0.2, 0.25, 0.3, 0.5, 1), 1)
      pm$hb <- if (length(hbs) == 1) hbs else sample(hbs, 1)
      pm$n <- sample(1:4, 1)
    }
  }
  rg <- draw_rawdata_general()
  pc <- draw_cleaning()
  args <- list(params_metrics = pm, params_rawdata = rg$pr, params_general = rg$pg,
               params_cleaning = pc)
  args <- args[lengths(args) > 0]
  if (stats::runif(1) < 0.4) {
    args$offset <- sample(-500:500, 3) / 10000
    args$scale <- sample(9500:10500, 3) / 10000
    if (stats::runif(1) < 0.5) {
      args$tempoffset <- sample(-500:500, 3) / 1e5
      args$meantempcal <- sample(1800:3000, 1) / 100
    }
  }
  args
}

# chunksize, dynrange, windowsizes, desiredtz and configtz: list(pr, pg)
draw_rawdata_general <- function() {
  pr <- list()
  ch <- sample(c(0.2, 0.5, 1), 1)
  if (ch != 1) pr$chunksize <- ch
  if (stats::runif(1) < 0.3) pr$dynrange <- sample(c(2, 4, 6, 8, 16), 1)
  pg <- list()
  ws <- list(c(5, 900, 3600), c(1, 300, 1800), c(15, 900, 3600), c(5, 600, 1200),
             c(10, 900, 2700))[[sample(5, 1)]]
  if (!identical(ws, c(5, 900, 3600))) pg$windowsizes <- ws
  tz <- sample(zones, 1)
  if (tz != "") pg$desiredtz <- tz
  u <- stats::runif(1)
  if (u < 0.3 && tz != "") {
    pg$configtz <- tz
  } else if (u < 0.6) {
    pg$configtz <- sample(setdiff(zones, c("", tz)), 1)
  }
  list(pr = pr, pg = pg)
}

draw_cleaning <- function() {
  pc <- list()
  # ("2023" is GGIR 3.3-9's default)
  if (stats::runif(1) < 0.5) pc$nonwear_approach <- "2013"
  pc
}

# One g.calibrate() case's arguments (SWEEP_TARGET=calibrate): the common
# draws above, then the parameters GGIR's g.calibrate() and g.readaccfile()
# read, sometimes ones it leaves alone; `rmc`: the ad hoc csv file's rmc.*
# list (NULL for other files).
draw_args_calibrate <- function(defaults, sf, rmc = NULL) {
  rg <- draw_rawdata_general()
  pr <- rg$pr
  pg <- rg$pg
  pc <- draw_cleaning()
  if (stats::runif(1) < 0.2) pr$chunksize <- sample(c(0.1, 0.3, 0.8), 1)
  if (stats::runif(1) < 0.5) pr$spherecrit <- sample(c(0.1, 0.2, 0.4, 0.5, 0.7, 0.9), 1)
  if (stats::runif(1) < 0.6) pr$minloadcrit <- sample(c(1, 6, 12, 20, 24, 30, 48, 72), 1)
  if (stats::runif(1) < 0.2) pr$printsummary <- TRUE
  if (stats::runif(1) < 0.3) pr$interpolationType <- 2
  if (stats::runif(1) < 0.25) pr$frequency_tol <- sample(c(0, 0.05, 0.2, 0.5, 1), 1)
  # taken by GGIR, no effect on its g.calibrate()
  if (stats::runif(1) < 0.15) pr$do.cal <- FALSE
  if (stats::runif(1) < 0.15) pr$backup.cal.coef <- "/nonexistent/calibration.csv"
  if (stats::runif(1) < 0.15) pr$minimumFileSizeMB <- 0
  if (stats::runif(1) < 0.15) pr$imputeTimegaps <- FALSE
  if (stats::runif(1) < 0.15) pr$nonwear_range_threshold <- 100
  if (stats::runif(1) < 0.15) pg$dayborder <- 4
  if (stats::runif(1) < 0.15) pc$includedaycrit <- 10
  if (stats::runif(1) < 0.15) pc$hrs.del.start <- 1
  if (!is.null(rmc)) {
    pr <- c(pr, rmc)
    pr$rmc.noise <- sample(c(0.01, 0.011, 0.013, 13), 1)
    if (!is.null(rmc$rmc.col.time)) {
      if (stats::runif(1) < 0.4) pr$rmc.check4timegaps <- TRUE
      if (stats::runif(1) < 0.3) pr$rmc.doresample <- TRUE
    }
  } else if (stats::runif(1) < 0.15) {
    pr$rmc.noise <- 0.01
  }
  args <- list(params_rawdata = pr, params_general = pg, params_cleaning = pc)
  args[lengths(args) > 0]
}

complete_args <- function(args, defaults, lists = c("metrics", "rawdata", "general", "cleaning")) {
  for (k in lists) {
    nm <- paste0("params_", k)
    args[[nm]] <- utils::modifyList(defaults[[nm]], args[[nm]] %||% list())
  }
  args
}

compact <- function(x) paste(deparse(x, width.cutoff = 500L), collapse = " ")

# ---- running and comparing -----------------------------------------------------------

# expr's value, its printed output dropped, its warnings collected, its
# error caught: list(value, error = message or NULL, warnings, seconds)
run_quiet <- function(expr) {
  # (GGIR's readers set options(warn = -1) and may stop before resetting it)
  op <- options(warn = getOption("warn"))
  on.exit(options(op), add = TRUE)
  warns <- character()
  t0 <- proc.time()[["elapsed"]]
  value <- NULL
  err <- NULL
  utils::capture.output(
    value <- tryCatch(withCallingHandlers(suppressMessages(expr), warning = function(w) {
      warns <<- c(warns, conditionMessage(w))
      invokeRestart("muffleWarning")
    }), error = function(e) {
      err <<- conditionMessage(e)
      NULL
    }))
  list(value = value, error = err, warnings = unique(warns),
       seconds = round(proc.time()[["elapsed"]] - t0, 2))
}

fmt_value <- function(v) {
  if (is.numeric(v)) format(v, digits = 17) else paste(format(v), collapse = " ")
}

# The first difference between two vectors (GGIR's a, gravcal's b): index,
# both values, how many differ, the largest absolute difference.
first_diff <- function(a, b) {
  if (!identical(class(a), class(b)) || !identical(typeof(a), typeof(b))) {
    return(list(row = NA, ggir = paste(class(a), typeof(a)), gravcal = paste(class(b), typeof(b)),
                note = "class or type"))
  }
  if (length(a) != length(b)) {
    return(list(row = NA, ggir = length(a), gravcal = length(b), note = "length"))
  }
  if (!is.atomic(a)) {
    return(list(row = NA, ggir = NA, gravcal = NA,
                note = paste(utils::head(all.equal(a, b), 2), collapse = "; ")))
  }
  va <- unclass(a)
  vb <- unclass(b)
  eq <- va == vb
  eq[is.na(eq)] <- FALSE
  if (is.double(va)) {
    eq <- eq | (is.na(va) & is.na(vb) & is.nan(va) == is.nan(vb))
  } else {
    eq <- eq | (is.na(va) & is.na(vb))
  }
  i <- which(!eq)
  if (!length(i)) {
    return(list(row = NA, ggir = NA, gravcal = NA, note = paste(
      "attributes:", paste(utils::head(all.equal(a, b), 2), collapse = "; "))))
  }
  d <- if (is.numeric(va)) suppressWarnings(max(abs(va[i] - vb[i]), na.rm = TRUE)) else NA
  list(row = i[1], ggir = fmt_value(a[i[1]]), gravcal = fmt_value(b[i[1]]),
       note = sprintf("%d of %d differ%s", length(i), length(a),
                      if (is.finite(d)) sprintf(", max |diff| %.3g", d) else ""))
}

# One element of M that is not identical: where it first differs.
diff_element <- function(nm, R, G) {
  out <- list(element = nm, column = NA, row = NA, ggir = NA, gravcal = NA, note = "")
  if (is.data.frame(R) && is.data.frame(G)) {
    if (!identical(names(R), names(G))) {
      out$note <- paste0("columns: GGIR ", paste(names(R), collapse = ","), "; gravcal ",
                         paste(names(G), collapse = ","))
      return(out)
    }
    if (nrow(R) != nrow(G)) out$note <- sprintf("rows: GGIR %d, gravcal %d; ", nrow(R), nrow(G))
    for (col in names(R)) {
      a <- R[[col]]
      b <- G[[col]]
      k <- min(length(a), length(b))
      if (!identical(a[seq_len(k)], b[seq_len(k)])) {
        fd <- first_diff(a[seq_len(k)], b[seq_len(k)])
        out[c("column", "row", "ggir", "gravcal")] <- list(col, fd$row, fd$ggir, fd$gravcal)
        out$note <- paste0(out$note, fd$note)
        return(out)
      }
    }
    if (!nzchar(out$note)) {
      out$note <- paste("data frame attributes:", paste(utils::head(all.equal(R, G), 2), collapse = "; "))
    }
    return(out)
  }
  fd <- first_diff(R, G)
  out[c("row", "ggir", "gravcal", "note")] <- fd[c("row", "ggir", "gravcal", "note")]
  out
}

# M of both compared as expect_same_meta() compares them: a list of the
# differing elements (empty: identical). (g.calibrate()'s lists too: they
# have no QClog; bsc_qc is left out as expect_same_as_ggir() leaves it.)
compare_meta <- function(R, G) {
  if (!identical(names(G), names(R))) {
    return(list(list(element = "(names of M)", column = NA, row = NA,
                     ggir = paste(names(R), collapse = ","), gravcal = paste(names(G), collapse = ","),
                     note = "")))
  }
  for (k in c("start", "end")) {
    if (is.list(R$QClog)) R$QClog[[k]] <- NULL
    if (is.list(G$QClog)) G$QClog[[k]] <- NULL
  }
  diffs <- list()
  for (nm in setdiff(names(R), "bsc_qc")) {
    if (!identical(G[[nm]], R[[nm]])) diffs[[length(diffs) + 1]] <- diff_element(nm, R[[nm]], G[[nm]])
  }
  diffs
}

# The names an error may give in backticks when gravcal refuses a parameter.
param_names <- function(defaults) {
  c(unlist(lapply(defaults, names), use.names = FALSE),
    "offset", "scale", "tempoffset", "meantempcal", "inspectfileobject", "daylimit", "myfun")
}
named_param <- function(msg, pnames) {
  hit <- pnames[vapply(pnames, function(p) grepl(paste0("`", p, "`"), msg, fixed = TRUE), TRUE)]
  if (length(hit)) paste(unique(hit), collapse = ",") else NA_character_
}

# What the sweep compares (SWEEP_TARGET): the function, GGIR's parameter
# lists it takes, the g.inspectfile() call that gives GGIR's
# inspectfileobject (code run with the file `f` and the completed
# arguments `a`), a one-line summary of an identical result.
sweep_targets <- list(
  getmeta = list(
    fun = "g.getmeta", lists = c("metrics", "rawdata", "general", "cleaning"),
    inspect = "GGIR::g.inspectfile(f, params_rawdata = a$params_rawdata, params_general = a$params_general)",
    summary = function(v) sprintf("metashort %d x %d, metalong %d x %d",
                                  NROW(v$metashort), NCOL(v$metashort),
                                  NROW(v$metalong), NCOL(v$metalong))),
  calibrate = list(
    # (as GGIR's g.part1() calls g.inspectfile())
    fun = "g.calibrate", lists = c("rawdata", "general", "cleaning"),
    inspect = paste("GGIR::g.inspectfile(f, desiredtz = a$params_general[[\"desiredtz\"]],",
                    "params_rawdata = a$params_rawdata, configtz = a$params_general[[\"configtz\"]])"),
    summary = function(v) sprintf("npoints %s, nhoursused %s, use.temp %s: %s",
                                  paste(v$npoints, collapse = ","), paste(format(v$nhoursused), collapse = ","),
                                  paste(v$use.temp, collapse = ","), paste(v$QCmessage, collapse = " "))))

sweep_target <- function() {
  name <- Sys.getenv("SWEEP_TARGET", "getmeta")
  if (!name %in% names(sweep_targets)) {
    stop("ggir-sweep: SWEEP_TARGET must be one of ", paste(names(sweep_targets), collapse = ", "))
  }
  sweep_targets[[name]]
}

# The code of the three calls of a case (I, R, G), run by run_case() and
# written into repro_code().
call_code <- function(target, give_inspect) {
  list(I = target$inspect,
       R = paste0("do.call(GGIR::", target$fun, ", c(list(datafile = f, inspectfileobject = I, ",
                  "verbose = FALSE), a))"),
       G = paste0("do.call(gravcal::", target$fun, ", c(list(datafile = f, ",
                  if (give_inspect) "inspectfileobject = I, ", "verbose = FALSE), a))"))
}

# R code that reruns a case: `build` is the code that rebuilds the file
# (a synthetic recording, from its recipe; NULL for a real file).
repro_code <- function(path, args, give_inspect, build, target = sweep_targets$getmeta) {
  code <- call_code(target, give_inspect)
  c(if (!is.null(build)) c(
      "source(\"tools/ggir-sweep.R\")  # its functions; nothing runs",
      paste0("f <- ", deparse(path), "  # kept with SWEEP_FILES, else rebuild it:"),
      paste0("# f <- ", build)),
    if (is.null(build)) paste0("f <- ", deparse(path)),
    paste0("a <- ", compact(args)),
    "d <- GGIR::load_params()",
    paste0("for (k in paste0(\"params_\", ", compact(target$lists), ")) a[[k]] <- ",
           "utils::modifyList(d[[k]], if (is.null(a[[k]])) list() else a[[k]])"),
    paste0("I <- ", code$I), paste0("R <- ", code$R), paste0("G <- ", code$G))
}

run_case <- function(id, file, args, give_inspect, defaults, pnames, recipe = NULL,
                     build = NULL, target = sweep_targets$getmeta) {
  full <- complete_args(args, defaults, target$lists)
  code <- call_code(target, give_inspect)
  env <- new.env()
  env$f <- file
  env$a <- full
  ins <- run_quiet(eval(str2lang(code$I), env))
  env$I <- ins$value
  gg <- if (is.null(ins$error)) {
    run_quiet(eval(str2lang(code$R), env))
  } else {
    list(value = NULL, error = paste("g.inspectfile():", ins$error), warnings = ins$warnings,
         seconds = 0)
  }
  if (give_inspect && !is.null(ins$error)) code$G <- call_code(target, FALSE)$G
  gc <- run_quiet(eval(str2lang(code$G), env))
  diffs <- list()
  refused <- if (!is.null(gc$error)) named_param(gc$error, pnames) else NA_character_
  if (is.null(gg$error) && is.null(gc$error)) {
    diffs <- compare_meta(gg$value, gc$value)
    outcome <- if (length(diffs)) "differs" else "identical"
  } else if (!is.null(gg$error) && !is.null(gc$error)) {
    outcome <- "both error"
  } else if (!is.null(gc$error)) {
    outcome <- if (!is.na(refused)) "refused" else "only gravcal errors"
  } else {
    outcome <- "only GGIR errors"
  }
  detail <- switch(outcome,
    identical = target$summary(gg$value),
    differs = paste(vapply(diffs, function(d) {
      sprintf("%s[%s, %s]: GGIR %s, gravcal %s (%s)", d$element, d$row, d$column,
              d$ggir, d$gravcal, d$note)
    }, ""), collapse = " / "),
    `both error` = paste0("GGIR: ", gg$error, " | gravcal: ", gc$error),
    refused = paste0("gravcal (", refused, "): ", gc$error),
    `only gravcal errors` = paste0("gravcal: ", gc$error),
    `only GGIR errors` = paste0("GGIR: ", gg$error))
  # (a Movisens recording is its folder's acc.bin: the folder names it)
  label <- if (basename(file) == "acc.bin") file.path(basename(dirname(file)), "acc.bin") else basename(file)
  list(id = id, file = file, label = label, recipe = recipe, args = args,
       give_inspect = give_inspect, outcome = outcome, refused = refused, detail = detail,
       diffs = diffs, ggir_error = gg$error, gravcal_error = gc$error,
       ggir_warnings = gg$warnings, gravcal_warnings = gc$warnings,
       seconds_inspect = ins$seconds, seconds_ggir = gg$seconds, seconds_gravcal = gc$seconds,
       repro = repro_code(file, args, give_inspect && is.null(ins$error), build, target), time = format(Sys.time(), tz = "UTC"))
}

md_cell <- function(x, max = 600) {
  x <- gsub("[\r\n]+", " ", x)
  x <- gsub("|", "\\|", x, fixed = TRUE)
  if (nchar(x) > max) paste0(substr(x, 1, max), "...") else x
}

# ---- main --------------------------------------------------------------------

# A sweep's settings: n and seed from the command line, SWEEP_OUT (default
# `out`), SWEEP_DEADLINE, SWEEP_THREADS (set as options(gravcal.threads)).
sweep_settings <- function(n, out) {
  a <- commandArgs(TRUE)
  deadline <- Sys.getenv("SWEEP_DEADLINE", "")
  if (nzchar(Sys.getenv("SWEEP_THREADS"))) options(gravcal.threads = as.integer(Sys.getenv("SWEEP_THREADS")))
  list(n = if (length(a) >= 1) as.integer(a[1]) else n,
       seed = if (length(a) >= 2) as.integer(a[2]) else 1L,
       out = Sys.getenv("SWEEP_OUT", out),
       deadline = if (nzchar(deadline)) as.POSIXct(deadline, tz = "UTC"))
}

# The count of each outcome, printed and appended to <out>.md; the results.
sweep_summary <- function(results, out) {
  tab <- table(vapply(results, function(r) r$outcome, ""))
  summary <- paste(sprintf("%s: %d", names(tab), as.integer(tab)), collapse = ", ")
  cat(sprintf("\n%d cases: %s\n", length(results), summary))
  cat("\n", sprintf("%d cases: %s.", length(results), summary), "\n", sep = "",
      file = paste0(out, ".md"), append = TRUE)
  invisible(results)
}

main <- function() {
  st <- sweep_settings(5L, "/tmp/sweep-results")
  n <- st$n
  seed <- st$seed
  out <- st$out
  deadline <- st$deadline
  folder <- Sys.getenv("SWEEP_FILES", "")
  keep <- nzchar(folder)
  if (!keep) folder <- file.path(tempdir(), "ggir-sweep")
  dir.create(folder, showWarnings = FALSE, recursive = TRUE)
  if (!keep) on.exit(unlink(folder, recursive = TRUE), add = TRUE)
  target <- sweep_target()
  suppressMessages(library(gravcal))
  if (!requireNamespace("GGIR", quietly = TRUE)) stop("ggir-sweep: needs GGIR")
  defaults <- GGIR::load_params()
  pnames <- param_names(defaults)
  set.seed(seed)

  # the files: synthetic ones (one per format, written once) and real ones,
  # each with its sampling rate (for the filters' hb)
  pool <- list()
  formats <- c("cwa", "geneactiv", "gt3x", "actigraph_csv", "movisens", "parmay",
               if (target$fun == "g.calibrate") "adhoc_csv")
  for (fm in formats) {
    if (fm == "movisens" && !requireNamespace("unisensR", quietly = TRUE)) next
    r <- draw_recipe(fm, seed = sample(1e4, 1))
    ext <- c(cwa = ".cwa", geneactiv = ".bin", gt3x = ".gt3x", actigraph_csv = ".csv",
             movisens = "", parmay = ".bin", adhoc_csv = ".csv")[[fm]]
    name <- sprintf("syn-s%d-%s-%gHz-%dh%s", seed, fm, r$sf, r$hours, ext)
    t0 <- proc.time()[["elapsed"]]
    path <- make_synthetic(r, file.path(folder, name))
    cat(sprintf("wrote %s (start %s) in %.1f s\n", name, r$start, proc.time()[["elapsed"]] - t0))
    rmc <- attr(path, "rmc")
    path <- as.vector(path)
    pool[[length(pool) + 1]] <- list(path = path, sf = r$sf, recipe = r, synthetic = TRUE, rmc = rmc,
                                     build = paste0("make_synthetic(", compact(r), ", ",
                                                    deparse(file.path(folder, name)), ")"))
  }
  ag <- tryCatch(agcounts_gt3x(folder), error = function(e) NULL)
  if (!is.null(ag)) {
    cat("wrote", basename(ag), "(agcounts' real samples)\n")
    pool[[length(pool) + 1]] <- list(path = ag, sf = 30, recipe = NULL, synthetic = TRUE,
                                     build = paste0("agcounts_gt3x(", deparse(folder), ")"))
  }
  for (f in real_files()) {
    sf <- tryCatch(run_quiet(GGIR::g.inspectfile(f))$value$sf, error = function(e) NULL)
    pool[[length(pool) + 1]] <- list(path = f, sf = if (length(sf)) sf else NA, recipe = NULL,
                                     synthetic = FALSE, build = NULL)
  }
  synth <- vapply(pool, function(p) p$synthetic, TRUE)

  writeLines(c(sprintf("# %s(): gravcal against GGIR %s, random parameters (%stools/ggir-sweep.R %d %d)",
                       target$fun, utils::packageVersion("GGIR"),
                       if (target$fun == "g.calibrate") "SWEEP_TARGET=calibrate " else "", n, seed), "",
               sprintf("R %s, gravcal %s, started %s UTC.", getRversion(),
                       utils::packageVersion("gravcal"), format(Sys.time(), tz = "UTC")), "",
               "| case | file | parameters (non-default) | outcome | detail | GGIR s | gravcal s |",
               "|---|---|---|---|---|---|---|"), paste0(out, ".md"))
  results <- list()
  for (i in seq_len(n)) {
    if (!is.null(deadline) && Sys.time() > deadline) {
      cat("deadline passed: stopping before case", i, "\n")
      break
    }
    # half the cases on a synthetic recording (several GGIR blocks), half on a real file
    k <- if (stats::runif(1) < 0.5) which(synth) else which(!synth)
    p <- pool[[if (length(k) == 1) k else sample(k, 1)]]
    args <- if (target$fun == "g.calibrate") {
      draw_args_calibrate(defaults, p$sf, p$rmc)
    } else {
      draw_args(defaults, p$sf)
    }
    give_inspect <- stats::runif(1) < 0.3
    id <- sprintf("s%d-%03d", seed, i)
    r <- run_case(id, p$path, args, give_inspect, defaults, pnames, p$recipe, p$build, target)
    results[[length(results) + 1]] <- r
    saveRDS(results, paste0(out, ".rds"))
    shown <- compact(c(args, if (give_inspect) list(gravcal_gets_inspectfileobject = TRUE)))
    cat(sprintf("| %s | %s | %s | %s | %s | %.1f | %.1f |\n", id, md_cell(r$label), md_cell(shown, 2000),
                r$outcome, md_cell(r$detail), r$seconds_ggir + r$seconds_inspect, r$seconds_gravcal),
        file = paste0(out, ".md"), append = TRUE)
    cat(sprintf("%s %-40s %-20s GGIR %6.1f s gravcal %5.1f s  %s\n", id, substr(r$label, 1, 40),
                r$outcome, r$seconds_ggir + r$seconds_inspect, r$seconds_gravcal,
                substr(r$detail, 1, 150)))
  }
  sweep_summary(results, out)
}

if (sys.nframe() == 0L) main()
