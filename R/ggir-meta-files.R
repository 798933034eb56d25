# GGIR part 1 as a drop-in: g.part1() writes, for every recording of a
# folder (or a vector of files), the meta/basic/meta_<file>.RData file GGIR's
# parts 2-5 read, with the objects GGIR 3.3-9's g.part1() saves. The
# calibration is gravcal's g.calibrate() (R/ggir-drop-in.R), the epoch
# signals gravcal's g.getmeta() (R/ggir-part1.R); `I` is GGIR's own
# g.inspectfile() (exported), or its result built by gravcal where GGIR's
# reads the whole file (R/ggir-inspect.R), so GGIR must be installed, as it
# must be for parts 2-5.

#' GGIR part 1 on gravcal's core: the meta files for GGIR's parts 2-5
#'
#' A drop-in replacement for `GGIR::g.part1()` (GGIR 3.3-9): same arguments,
#' same files. For each recording of `datadir` (a folder, searched
#' recursively, or a vector of file paths) from the `f0`-th to the `f1`-th,
#' it writes `<metadatadir>/meta/basic/meta_<file name>.RData` holding the
#' objects GGIR's part 1 saves, built as GGIR builds them (Details).
#'
#' The objects:
#'
#' * `I`: `GGIR::g.inspectfile()`'s result for the file (GGIR's own function,
#'   called with `desiredtz`, `params_rawdata` and `configtz` as GGIR's
#'   part 1 calls it). For a `.gt3x` file gravcal builds the same list itself:
#'   GGIR's function unzips and decodes the whole file for it (on a week at
#'   100 Hz, 15 s and 1.9 GB of memory), gravcal reads only its `info.txt`
#'   and hands it to `read.gt3x::parse_gt3x_info()`. Unlike GGIR's, it
#'   never renames a `.GT3X` file to `.gt3x`;
#' * `C`: the calibration, [g.calibrate()] (gravcal's, identical to GGIR's
#'   but for the wall-clock record `bsc_qc`) when `do.cal = TRUE`, no
#'   coefficients are retrieved and `I` has a sampling rate; else GGIR's
#'   "not done" list (unit scale, zero offsets, `QCmessage` "Autocalibration
#'   not done"). When the calibration ends with a larger error than it started
#'   with, or without errors, its scale, offset and temperature offset are set
#'   to 1, 0 and 0, as GGIR sets them. With `backup.cal.coef` (a csv file of
#'   GGIR's coefficient format, as [write_coefs()] writes it; or
#'   `"retrieve"`, GGIR's default: `<metadatadir>/results/QC/data_quality_report.csv`
#'   when part 2's report is there), a row for the file replaces the
#'   coefficients, errors, `meantempcal`, `QCmessage`, `npoints`,
#'   `nhoursused` and `use.temp`, read as GGIR reads them
#'   (`data.table::fread()`); a file without a row there is calibrated
#'   (`do.cal = TRUE`). `"redo"` ignores any such file. (As in GGIR, the
#'   coefficients come back through the csv's 15 significant digits, and
#'   part 2's report has no `meantempcal` column, so a part 1 run again
#'   after part 2 applies no temperature term: `M` is GGIR's either way);
#' * `M`: [g.getmeta()] (gravcal's, identical to GGIR's but for `bsc_qc`)
#'   with `C`'s `offset`, `scale`, `tempoffset` and `meantempcal`;
#' * `filename_dir`, `filefoldername`: the file's name as GGIR lists it;
#'   `tail_expansion_log`: `NULL`, or with `recordingEndSleepHour` the
#'   numbers of short and long epochs added to `M` past the recording's end
#'   (as GGIR adds them); `desiredtz_part1`: `desiredtz`;
#' * `GGIRversion`: `utils::packageVersion("GGIR")`, the installed GGIR's
#'   version, as GGIR writes it. Parts 2-5 do not read it (each records its
#'   own version), and the file is the one GGIR's part 1 would have written
#'   with that GGIR, so gravcal writes the same rather than its own.
#'
#' Files are chosen as GGIR chooses them: in a folder, the names containing
#' `.csv`, `.bin`, `.wav`, `.cwa` or `.gt3` (any case, in that order), those
#' of `minimumFileSizeMB` or less left out with a warning; a file whose meta
#' file exists is skipped unless `overwrite = TRUE`.
#'
#' Files of a format gravcal's [g.getmeta()] does not read (see its page;
#' and `.wav`, which gravcal does not read at all) are skipped with one warning naming them
#' and their formats, and get no meta file: `GGIR::GGIR(mode = 1:5,
#' overwrite = FALSE, ...)` (or `GGIR::g.part1()`) then makes theirs and
#' leaves the ones written here. Nothing is written for a file whose
#' processing fails: with `use_trycatch_serial = TRUE` (GGIR's default) its
#' error is printed at the end and its row says `"failed"`, as GGIR does;
#' otherwise the run ends in an error naming the file (after the other
#' files, which GGIR would not have begun).
#'
#' The files run as [calibrate_files()] runs a cohort's: one future per
#' file on the `future::plan()` the session has set
#' (`plan(multisession)` on a laptop, `future.batchtools` on Slurm), with
#' progress through progressr, when the future package is installed; in this
#' R process, one after the other, where no plan is set (the future package
#' not loaded, no `future.plan` option or `R_FUTURE_PLAN`); a file
#' whose R process dies is reported as failed, and the files that worker had
#' not begun are run again.
#'
#' @section GGIR's parameters:
#' The parameter lists are completed and checked by `GGIR::extract_params()`
#' (GGIR's own defaults and checks; legacy arguments in `...` win, as in
#' GGIR). Those read by g.calibrate() and g.getmeta() are honoured there or
#' refused with an error naming them (see their pages). Those only part 1
#' reads:
#'
#' | parameter | in GGIR's part 1 | here |
#' |---|---|---|
#' | `do.cal`, `backup.cal.coef` | whether and how `C` is made | honoured |
#' | `minimumFileSizeMB` | which files are read | honoured |
#' | `overwrite` | whether a file with a meta file is redone | honoured |
#' | `desiredtz`, `configtz` | `I`, `C`, `M`; `desiredtz_part1` | honoured |
#' | `print.filename` | prints | honoured |
#' | `use_trycatch_serial` | whether a file's error stops the run | honoured (see above) |
#' | `do.parallel`, `maxNcores` | GGIR runs files in parallel on 4 or more cores, and then lowers `chunksize` to 0.5 (3-5 metrics) or 0.4 (6 or more), which changes `M` | the files run on the session's future plan (see above); `chunksize` lowered as GGIR would lower it on this machine, so `M` is GGIR's |
#' | `recordingEndSleepHour` (`expand_tail_max_hours`), `dayborder` | `M` expanded past the recording's end to 8 hours past the next day border when the recording ends late enough; `tail_expansion_log` | honoured |
#' | `myfun` | an external function's values in `M` | honoured (see [g.getmeta()]) |
#' | `dataFormat`, `maxRecordingInterval`, `recording_split_*` | read by `GGIR::GGIR()` around part 1, not by g.part1() | no effect |
#'
#' Beyond GGIR's g.part1(): when `metadatadir` is not given, it is
#' `<outputdir>/output_<datadir's folder name>` (for a vector of files,
#' `output_<studyname>`), as `GGIR::GGIR()` names it, from `outputdir` and
#' `studyname` in `...`; and the folders it needs are made when missing.
#'
#' @param datadir A folder of recordings, or a vector of their paths.
#' @param metadatadir GGIR's output folder (`<outputdir>/output_<name>`);
#'   see Details for the default.
#' @param f0,f1 The first and last file (by their place in the list) to
#'   do; `f1 = c()` or 0: up to the last (GGIR's g.part1() warns on 0, as
#'   this does).
#' @param myfun GGIR's external function object: its values become columns
#'   of `M$metashort` (see [g.getmeta()]).
#' @param params_metrics,params_rawdata,params_cleaning,params_general
#'   GGIR's parameter lists (as from `GGIR::load_params()`); missing entries
#'   take GGIR's defaults.
#' @param verbose Print progress as GGIR does.
#' @param ... GGIR's legacy arguments (any parameter of the lists by name),
#'   and `outputdir`, `studyname` (see Details).
#' @return Invisibly, a data frame with a row per file considered: `file`,
#'   `status` (`"written"`, `"exists"`: skipped, its meta file was there;
#'   `"not read"`: a format gravcal's g.getmeta() does not read; `"failed"`,
#'   with `use_trycatch_serial = TRUE`), `message`, `meta_file` and
#'   `seconds`. (GGIR's returns nothing of use.)
#' @seealso [g.calibrate()], [g.getmeta()], [write_coefs()],
#'   [calibrate_cli()] (its `part1` verb).
#' @export
g.part1 <- function(datadir = c(), metadatadir = c(), f0 = 1, f1 = c(), myfun = c(),
                    params_metrics = c(), params_rawdata = c(), params_cleaning = c(),
                    params_general = c(), verbose = TRUE, ...) {
  input <- list(...)
  if (length(input) && (is.null(names(input)) || any(names(input) == ""))) {
    abort("All arguments in `...` must be named.")
  }
  check_flag(verbose, "verbose")
  for (pkg in c("GGIR", "data.table")) {
    if (!requireNamespace(pkg, quietly = TRUE)) {
      abort("g.part1() needs the ", pkg, " package (", if (pkg == "GGIR") {
        "its g.inspectfile() makes the meta file's `I`, and its parts 2-5 read the files"
      } else "GGIR reads coefficient files with it", "): install.packages(\"", pkg, "\").")
    }
  }
  outputdir <- input$outputdir
  studyname <- input$studyname
  input$outputdir <- NULL
  if (!is.character(datadir) || !length(datadir) || anyNA(datadir)) {
    abort("`datadir` must be a folder of recordings or a vector of their paths, not ",
          describe(datadir), ".")
  }
  filelist <- part1_is_filelist(datadir)
  if (!length(metadatadir)) {
    if (is.null(outputdir)) {
      abort("`metadatadir` (GGIR's <outputdir>/output_<name> folder) is missing; give it, ",
            "or `outputdir` (then it is named as GGIR::GGIR() names it).")
    }
    named_by_study <- part1_is_filelist(datadir, movisens = FALSE)
    if (named_by_study && !length(studyname)) {
      abort("`studyname` must be given with `outputdir` when `datadir` is a list of files ",
            "(GGIR names the output folder output_<studyname>).")
    }
    metadatadir <- file.path(outputdir, paste0("output_", if (named_by_study) studyname else {
      basename(sub("/+$", "", datadir))
    }))
  }
  if (!is.character(metadatadir) || length(metadatadir) != 1 || is.na(metadatadir)) {
    abort("`metadatadir` must be one folder path, not ", describe(metadatadir), ".")
  }
  p <- keep_warn_option(GGIR::extract_params(
    params_metrics = params_metrics, params_rawdata = params_rawdata,
    params_cleaning = params_cleaning, params_general = params_general, input = input,
    params2check = c("metrics", "rawdata", "cleaning", "general")))
  pm <- p$params_metrics
  pr <- p$params_rawdata
  pc <- p$params_cleaning
  pg <- p$params_general
  if (length(f1) && isTRUE(f1 == 0)) warning("\nWarning: f1 = 0 is not a meaningful value")
  # the parameters g.getmeta() reads, checked before any file is read
  mp <- meta_params(pm, pr, pg, pc, list())
  myfun <- if (length(myfun)) meta_myfun_check(myfun, mp$windowsizes[1])

  files <- part1_files(datadir, filelist)
  fnames <- files$fnames
  fnamesfull <- files$fnamesfull
  big <- file.size(fnamesfull) / 1e6 > pr[["minimumFileSizeMB"]]
  big[is.na(big)] <- FALSE
  if (verbose && any(!big)) {
    warning(paste0("\nSkipping files that are too small for analysis: ",
                   toString(fnames[!big]), " (configurable with parameter minimumFileSizeMB)."),
            call. = FALSE)
  }
  fnames <- fnames[big]
  fnamesfull <- fnamesfull[big]
  if (!length(fnamesfull)) {
    abort("No files to analyse: no accelerometer files over minimumFileSizeMB = ",
          pr[["minimumFileSizeMB"]], " MB in `datadir`.")
  }
  basic <- file.path(metadatadir, "meta", "basic")
  for (d in c(basic, file.path(metadatadir, "results", "QC"))) {
    if (!dir.exists(d) && !dir.create(d, recursive = TRUE, showWarnings = FALSE)) {
      abort("Could not make the folder \"", d, "\".")
    }
  }
  unreadable <- file.access(fnamesfull, mode = 4) == -1
  if (any(unreadable)) {
    if (verbose) cat("\nChecking that user has read access permission for all files in data directory: No")
    warning(paste0("\nThere are/is ", sum(unreadable), " file(s) in directory specified with ",
                   "argument datadir for which the user does not have read access permission\n"))
  } else if (verbose) {
    cat("\nChecking that user has read access permission for all files in data directory: Yes\n")
  }
  n <- length(fnames)
  if (!length(f0)) f0 <- 1
  if (!length(f1) || isTRUE(f1 == 0)) f1 <- n
  check_number(f0, "f0", min = 1, integer = TRUE)
  check_number(f1, "f1", min = 1, integer = TRUE)
  if (f0 > n) f0 <- 1
  if (f1 > n) f1 <- n
  # GGIR on 4 or more cores runs files in parallel and lowers chunksize
  # with the number of metrics: so that M is the one GGIR writes here
  pr[["chunksize"]] <- part1_parallel_chunksize(pm, pr, pg, f0, f1)
  done <- part1_done(basic, fnames)
  out <- list()
  todo <- integer(0)
  for (i in f0:f1) {
    meta <- file.path(basic, part1_meta_name(fnames[i], fnames[1]))
    if (!isTRUE(pg[["overwrite"]]) && done[i]) {
      out[[length(out) + 1]] <- part1_row(fnames[i], "exists",
                                          "meta file exists (overwrite = FALSE)", meta)
      next
    }
    fmt <- if (!is.null(mp$.rmc)) rmc_format() else {
      tryCatch(file_format(fnamesfull[i]), error = function(e) NA_character_)
    }
    if (is.na(fmt) || !fmt %in% meta_formats()) {
      what <- if (is.na(fmt)) "a format gravcal does not know" else format_entry(fmt)$label
      out[[length(out) + 1]] <- part1_row(fnames[i], "not read", what, meta)
      next
    }
    todo <- c(todo, i)
    out[[length(out) + 1]] <- part1_row(fnames[i], "to do", "", meta)
  }
  tab <- do.call(rbind, out)
  skipped <- tab$status == "not read"
  if (any(skipped)) {
    warning("gravcal's g.part1() reads ",
            paste(vapply(meta_formats(), function(f) format_entry(f)$label, ""), collapse = " and "),
            " files; no meta file written for ", sum(skipped), " file(s): ",
            paste0(tab$file[skipped], " (", tab$message[skipped], ")", collapse = ", "),
            ". GGIR::GGIR(mode = 1, overwrite = FALSE, ...) makes theirs and keeps these.",
            call. = FALSE)
  }
  # the files on the session's future plan (run_cohort(), R/cohort.R: one
  # future per file, progress through progressr, a worker that dies
  # reported), each file's message and time in a slot file beside the meta
  # files, gathered here
  slots <- file.path(metadatadir, "meta", ".gravcal-part1")
  if (length(todo)) dir.create(slots, showWarnings = FALSE, recursive = TRUE)
  on.exit(unlink(slots, recursive = TRUE), add = TRUE)
  slot <- function(i) file.path(slots, paste0(i, ".rds"))
  worker <- function(i, p) {
    if (verbose) cat(paste0(i, " "))
    t0 <- proc.time()[["elapsed"]]
    res <- part1_one(i, fnames, fnamesfull, metadatadir, pm, pr, pc, pg, verbose, myfun)
    saveRDS(list(message = res, seconds = proc.time()[["elapsed"]] - t0), slot(i))
    if (!is.null(p)) p(message = fnames[i])
    invisible(NULL)
  }
  failures <- run_cohort(todo, worker, stats::setNames(fnames, seq_along(fnames)))
  errors <- list()
  for (i in todo) {
    k <- match(fnames[i], tab$file)
    why <- failures[[as.character(i)]]
    if (is.null(why) && file.exists(slot(i))) {
      r <- readRDS(slot(i))
      tab$status[k] <- "written"
      tab$message[k] <- r$message
      tab$seconds[k] <- r$seconds
    } else {
      if (is.null(why)) why <- "no result (the worker gave none)"
      errors[[fnames[i]]] <- why
      tab$status[k] <- "failed"
      tab$message[k] <- why
    }
  }
  if (length(errors) && !isTRUE(pg[["use_trycatch_serial"]])) {
    abort("g.part1() failed for ", names(errors)[1], ": ", errors[[1]],
          if (length(errors) > 1) paste0(" (and ", length(errors) - 1, " other file(s))"))
  }
  if (length(errors) && verbose) {
    cat("\n\nErrors in part 1... for:")
    cat(paste0("\n-", names(errors), ": ", unlist(errors), collapse = ""))
  }
  invisible(tab)
}

part1_row <- function(file, status, message, meta) {
  data.frame(file = file, status = status, message = message, meta_file = meta,
             seconds = NA_real_, stringsAsFactors = FALSE)
}

# GGIR's functions that set options(warn = -1) and restore it only when
# they get to their end: the session's `warn` kept whatever happens.
keep_warn_option <- function(expr) {
  op <- options(warn = getOption("warn"))
  on.exit(options(op), add = TRUE)
  expr
}

# Whether `datadir` names files rather than a folder (GGIR's rule: more
# than one path, or one whose name holds .bi, .cs, .wa, .cw, .gt or .BI);
# a Movisens folder of unisens folders counts as a list, as in GGIR.
part1_is_filelist <- function(datadir, movisens = TRUE) {
  if (length(datadir) != 1) return(TRUE)
  grepl("[.](bi|cs|wa|cw|gt|BI)", datadir) || (movisens && part1_is_movisens(datadir))
}

# GGIR's test for Movisens data: a unisens.xml beside the first file found.
part1_is_movisens <- function(datadir) {
  first <- dir(datadir, recursive = TRUE, full.names = TRUE)[1]
  path <- if (!is.na(first)) first else datadir
  file.exists(file.path(dirname(path), "unisens.xml"))
}

# The recordings and their names, as GGIR lists them: in a folder
# (recursively) the names containing .csv, .bin, .wav, .cwa, .gt3 (any
# case; in that order, a name matching two listed twice, as by GGIR), or
# the .RD* files when there are as many; a Movisens folder: the acc.bin of
# each unisens folder, named by its folder; a vector of files: as given.
part1_files <- function(datadir, filelist) {
  if (!filelist) {
    full <- unlist(lapply(c("[.]csv", "[.]bin", "[.]wav", "[.]cwa", "[.]gt3"), function(pat) {
      dir(datadir, recursive = TRUE, ignore.case = TRUE, pattern = pat, full.names = TRUE)
    }))
    rd <- dir(datadir, recursive = TRUE, pattern = "[.]RD", full.names = TRUE)
    if (length(full) == length(rd)) full <- rd
    return(list(fnames = basename(full), fnamesfull = full))
  }
  if (length(datadir) == 1 && part1_is_movisens(datadir) && dir.exists(datadir)) {
    full <- dir(datadir, recursive = TRUE, pattern = "acc.bin$", full.names = TRUE)
    return(list(fnames = basename(dirname(full)), fnamesfull = full))
  }
  list(fnames = basename(datadir), fnamesfull = datadir)
}

# Whether GGIR's part 1 (overwrite = FALSE) takes the recordings `fnames`
# as done by the files in `basic`, by its reading of the names, which split
# at patterns ("." any character): each file's name before the first match
# of ".RData", its part between the first "meta_" and the next (NA without
# one, "" for "meta_meta_..."), cut at every match of ".csv"; a recording
# is done where its name before the first ".csv" match, then before the
# first ".RD", is one of those pieces. So "s_csv.cwa" is done when
# "meta_s_csv.bin.RData" is there, and "meta_a.cwa" never is.
part1_done <- function(basic, fnames) {
  first <- function(x, split) vapply(strsplit(x, split), function(p) p[1], "")
  f <- dir(basic)
  if (!length(f)) return(rep(FALSE, length(fnames)))
  pieces <- unlist(strsplit(vapply(strsplit(first(f, ".RData"), "meta_"),
                                   function(p) p[2], ""), ".csv"))
  own <- first(first(fnames, ".csv"), "[.]RD")
  vapply(own, function(x) any(pieces == x, na.rm = TRUE), TRUE, USE.NAMES = FALSE)
}

# The meta file's name for the recording named `fname` (GGIR: .RData added
# unless the first recording's name holds ".RD").
part1_meta_name <- function(fname, first) {
  name <- basename(fname)
  paste0("meta_", name, if (!grepl("[.]RD", first)) ".RData")
}

# GGIR's chunksize in part 1: with do.parallel on a machine of 4 or more
# cores and more than one file to a worker pool, 0.5 for 3-5 metrics and
# 0.4 for 6 or more (from chunksize above 0.6).
part1_parallel_chunksize <- function(pm, pr, pg, f0, f1, cores = parallel::detectCores()[1]) {
  cs <- pr[["chunksize"]]
  if (!isTRUE(pg[["do.parallel"]])) return(cs)
  if (is.na(cores) || cores <= 3) return(cs)
  maxn <- if (length(pg[["maxNcores"]])) pg[["maxNcores"]] else cores
  if (min(c(cores - 1, maxn, (f1 - f0) + 1)) <= 1) return(cs)
  counted <- c("do.anglex", "do.angley", "do.anglez", "do.zcx", "do.zcy", "do.zcz",
               "do.enmo", "do.lfenmo", "do.en", "do.mad", "do.enmoa", "do.roll_med_acc_x",
               "do.roll_med_acc_y", "do.roll_med_acc_z", "do.dev_roll_med_acc_x",
               "do.dev_roll_med_acc_y", "do.dev_roll_med_acc_z", "do.bfen", "do.hfen",
               "do.hfenplus", "do.lfen", "do.lfx", "do.lfy", "do.lfz", "do.hfx", "do.hfy",
               "do.hfz", "do.bfx", "do.bfy", "do.bfz", "do.brondcounts",
               "do.neishabouricounts")
  nm <- sum(unlist(pm[counted]))
  if (cs > 0.6 && nm >= 3 && nm < 6) return(0.5)
  if (cs > 0.6 && nm >= 6) return(0.4)
  cs
}

# GGIR's C when no calibration is done.
part1_default_cal <- function() {
  list(cal.error.end = 0, cal.error.start = 0, scale = c(1, 1, 1), offset = c(0, 0, 0),
       tempoffset = c(0, 0, 0), QCmessage = "Autocalibration not done", npoints = 0,
       nhoursused = 0, use.temp = TRUE)
}

# The coefficient file's row for the recording `fname` as GGIR reads it
# into C (data.table::fread(); a name with "meta_" in it, split there, stands
# for its second piece before the first match of the pattern ".RData": so
# "meta_meta_a.cwa.RData" for "", never a recording); NULL when it has none.
part1_retrieve <- function(C, file, fname) {
  d <- data.table::fread(file, data.table = FALSE)
  nm <- vapply(as.character(d$filename), function(x) {
    p <- strsplit(x, "meta_")[[1]]
    if (length(p) > 1) strsplit(p[2], ".RData")[[1]][1] else x
  }, "", USE.NAMES = FALSE)
  r <- which(nm == fname)[1]
  if (is.na(r)) return(NULL)
  col <- function(names) which(colnames(d) %in% names)
  C$scale <- as.numeric(d[r, col(c("scale.x", "scale.y", "scale.z"))])
  C$offset <- as.numeric(d[r, col(c("offset.x", "offset.y", "offset.z"))])
  C$tempoffset <- as.numeric(d[r, col(c("temperature.offset.x", "temperature.offset.y",
                                       "temperature.offset.z"))])
  C$meantempcal <- d[r, col("meantempcal")]
  C$cal.error.start <- as.numeric(d[r, col("cal.error.start")])
  C$cal.error.end <- as.numeric(d[r, col("cal.error.end")])
  C$QCmessage <- d[r, col("QCmessage")]
  C$npoints <- d[r, col("n.10sec.windows")]
  C$nhoursused <- d[r, col("n.hours.considered")]
  C$use.temp <- d[r, col("use.temperature")]
  C
}

# One recording: I, C, M, then the meta file (written to a hidden name in
# the folder and renamed, so that an interrupted run leaves no half file).
# Returns the calibration's QC message.
part1_one <- function(i, fnames, fnamesfull, metadatadir, pm, pr, pc, pg, verbose,
                      myfun = NULL) {
  if (isTRUE(pg[["print.filename"]]) && verbose) cat(paste0("\nFile name: ", fnames[i]))
  datafile <- as.character(fnamesfull[i])
  I <- part1_inspect(datafile, pg[["desiredtz"]], pr, pg[["configtz"]])
  if (verbose) cat(paste0("\nP1 file ", i))
  # backup.cal.coef: "retrieve" is part 2's report when there is one,
  # "redo" none; a path is the file
  bcc <- pr[["backup.cal.coef"]]
  report <- file.path(metadatadir, "results", "QC", "data_quality_report.csv")
  if (length(bcc) && identical(bcc, "retrieve")) {
    bcc <- if (file.exists(report)) report else NULL
  } else if (length(bcc) && identical(bcc, "redo")) {
    bcc <- NULL
  }
  if (!length(bcc)) bcc <- NULL
  pr[["backup.cal.coef"]] <- bcc
  do_cal <- isTRUE(pr[["do.cal"]])
  calibrate <- function() {
    if (verbose) cat("\n\nInvestigate calibration of the sensors with function g.calibrate:\n")
    g.calibrate(datafile, params_rawdata = pr, params_general = pg, params_cleaning = pc,
                inspectfileobject = I, verbose = verbose)
  }
  Cdefault <- part1_default_cal()
  C <- Cdefault
  if (do_cal && is.null(bcc) && !is.null(I$sf)) {
    # g.getmeta()'s first block read beside the calibration's pass
    # (R/meta-ahead.R); what g.getmeta() does not take is closed
    on.exit(meta_ahead_close(), add = TRUE)
    meta_ahead_open(datafile, pm, pr, pg, pc, I)
    C <- calibrate()
  }
  start <- C$cal.error.start
  if (!length(start)) start <- NA
  if (is.na(start) || !length(C$cal.error.end) || isTRUE(start < C$cal.error.end)) {
    C$scale <- c(1, 1, 1)
    C$offset <- c(0, 0, 0)
    C$tempoffset <- c(0, 0, 0)
  }
  if (!is.null(bcc)) {
    if (do_cal && verbose) cat("\nRetrieving previously derived calibration coefficients")
    got <- part1_retrieve(C, bcc, fnames[i])
    if (!is.null(got)) {
      C <- got
      if (verbose) {
        cat(paste0("\nRetrieved Calibration error (g) before: ", C$cal.error.start))
        cat(paste0("\nRetrieved Callibration error (g) after: ", C$cal.error.end))
        cat(paste0("\nRetrieved offset correction ", c("x", "y", "z"), ": ", C$offset))
        cat(paste0("\nRetrieved scale correction ", c("x", "y", "z"), ": ", C$scale))
        cat(paste0("\nRetrieved tempoffset correction ", c("x", "y", "z"), ": ", C$tempoffset))
        cat("\n")
      }
    } else if (do_cal) {
      C <- calibrate()
      if (is.null(C)) C <- Cdefault
    }
  }
  if (verbose) cat("\nExtract signal features (metrics) with the g.getmeta function:\n")
  # g.getmeta() uses tempoffset only with meantempcal; GGIR's g.calibrate()
  # leaves it empty when no fit ran
  tempoffset <- if (length(C$tempoffset)) C$tempoffset else c(0, 0, 0)
  M <- g.getmeta(datafile, params_metrics = pm, params_rawdata = pr, params_general = pg,
                 params_cleaning = pc, daylimit = FALSE, tempoffset = tempoffset,
                 scale = C$scale, offset = C$offset, meantempcal = C$meantempcal,
                 myfun = myfun, inspectfileobject = I, verbose = verbose)
  tail_expansion_log <- NULL
  if (!is.null(pg[["recordingEndSleepHour"]])) {
    ex <- part1_expand_tail(M, pg[["recordingEndSleepHour"]], pg[["dayborder"]],
                            pg[["desiredtz"]], fnames[i])
    M <- ex$M
    tail_expansion_log <- ex$log
  }
  if (verbose) {
    cat("\nSave .RData-file with: calibration report, file inspection report and all signal features...\n")
  }
  basic <- file.path(metadatadir, "meta", "basic")
  target <- file.path(basic, part1_meta_name(fnames[i], fnames[1]))
  env <- new.env(parent = emptyenv())
  env$M <- M
  env$I <- I
  env$C <- C
  env$filename_dir <- env$filefoldername <- fnames[i]
  env$tail_expansion_log <- tail_expansion_log
  env$GGIRversion <- utils::packageVersion("GGIR")
  env$desiredtz_part1 <- pg[["desiredtz"]]
  tmp <- tempfile(pattern = ".part1-", tmpdir = basic, fileext = ".RData")
  on.exit(unlink(tmp), add = TRUE)
  part1_save(c("M", "I", "C", "filename_dir", "filefoldername", "tail_expansion_log",
               "GGIRversion", "desiredtz_part1"), env, tmp)
  if (!file.rename(tmp, target)) abort("Could not write \"", target, "\".")
  if (length(C$QCmessage)) as.character(C$QCmessage)[1] else ""
}

# save()'s file of the objects `names` of `env`: the same bytes as save()
# writes (R's serialization, then gzip at save()'s level 6), compressed on
# two threads (gc_gzip(): two gzip members in a row, which load() reads as
# one file). The serialization goes through a plain file in the session's
# temporary folder (a raw connection grows in small steps).
part1_save <- function(names, env, file) {
  plain <- tempfile("part1-save-")
  on.exit(unlink(plain))
  save(list = names, envir = env, file = plain, compress = FALSE)
  bytes <- readBin(plain, "raw", file.size(plain))
  writeBin(gc_gzip(bytes, 6L, gravcal_threads()), file)
}

# recordingEndSleepHour: when the recording ends less than 24 h + dayborder
# - recordingEndSleepHour (hours) before the next day border, GGIR's part 1
# adds epochs from its last ones to 8 hours past that border (so that
# parts 3-5 see a last night): metashort's metrics 0 (EN 1), its angles a
# slow square wave of +-15 degrees, metalong's scores 0 with nonwearscore
# -1, time stamps going on (GGIR's exported POSIXtime2iso8601() and
# iso8601chartime2POSIX(), in desiredtz); M gains `nonwear` (NA for the
# recorded short epochs, 0 for the added ones), as in GGIR. Returns
# list(M, log = list(short =, long =) or NULL).
#
# A recording without epochs (too short, or unreadable): GGIR starts from
# times of now (Sys.time()), which the last epochs' zero-length times leave
# as they are, so it writes the file without expansion unless it runs
# between recordingEndSleepHour and the day border (desiredtz's clock),
# where it stops on the rows it does not have. So does this (`now`: the
# time it runs).
part1_expand_tail <- function(M, end_hour, dayborder, tz, fname, now = Sys.time()) {
  empty <- !NROW(M$metashort) || !NROW(M$metalong)
  ws3 <- M$windowsizes[1]
  ws2 <- M$windowsizes[2]
  # as POSIXct times without a zone of their own (GGIR fills such a vector)
  last_ts <- .POSIXct(c(0, 0))
  if (empty) {
    last_ts[1:2] <- now
  } else {
    last <- c(long = as.character(M$metalong$timestamp[nrow(M$metalong)]),
              short = as.character(M$metashort$timestamp[nrow(M$metashort)]))
    for (k in 1:2) last_ts[k] <- GGIR::iso8601chartime2POSIX(x = last[[k]], tz = tz)
  }
  last_ts <- list(long = last_ts[1], short = last_ts[2])
  refhour <- 24 + dayborder
  to_border <- vapply(last_ts, function(t) {
    clock <- as.numeric(format(t, format = "%H", tz = tz)) * 3600 +
      as.numeric(format(t, format = "%M", tz = tz)) * 60 +
      as.numeric(format(t, format = "%S", tz = tz))
    refhour * 3600 - clock
  }, 0)
  if (to_border[["long"]] > (refhour - (end_hour - dayborder)) * 3600) {
    return(list(M = M, log = NULL))
  }
  if (empty) {
    abort("`recordingEndSleepHour`: \"", fname, "\" has no epochs to expand (too short or ",
          "unreadable), and GGIR's part 1 run now (after ", end_hour, ":00 in `desiredtz`, ",
          "before the day border) stops on such a file, taking the time of now for its ",
          "last epoch; at other times of day it writes the file without expansion, as ",
          "gravcal's does.")
  }
  to_border <- to_border + 8 * 3600
  n_long <- ceiling(to_border[["long"]] / ws2) + 1
  n_short <- ceiling(to_border[["short"]] / ws3) + 1
  per <- ws2 / ws3
  if (n_short / per < n_long) n_short <- n_long * per
  # short epochs
  nr <- nrow(M$metashort)
  add <- M$metashort[nr, ]
  add[, grep("timestamp|angle", names(add), invert = TRUE)] <- 0
  if ("EN" %in% names(add)) add$EN <- 1
  rows <- (nr + 1):(nr + n_short)
  M$metashort[rows, ] <- add
  M$nonwear[rows] <- 0
  M$metashort$timestamp[rows] <- GGIR::POSIXtime2iso8601(
    seq(last_ts$short + ws3, last_ts$short + n_short * ws3, by = ws3), tz = tz)
  angles <- grep("angle", names(add))
  if (length(angles)) M$metashort[rows, angles] <- round(sin(seq_along(rows) / per)) * 15
  log <- list(short = length(rows))
  # long epochs
  nr <- nrow(M$metalong)
  add <- M$metalong[nr, ]
  add[, grep("timestamp", names(add), invert = TRUE)] <- 0
  add[, "nonwearscore"] <- -1
  rows <- (nr + 1):(nr + n_long)
  M$metalong[rows, ] <- add
  M$metalong$timestamp[rows] <- GGIR::POSIXtime2iso8601(
    seq(last_ts$long + ws2, last_ts$long + n_long * ws2, by = ws2), tz = tz)
  log$long <- length(rows)
  list(M = M, log = log)
}
