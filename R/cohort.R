#' Calibrate many recordings, in parallel, resumably
#'
#' Calibrates every file with [calibrate()], each read block by block, and
#' returns one row per recording. The work is spread over whatever
#' `future::plan()` the session has set
#' (`plan(multisession)` on a laptop, `future.batchtools` on Slurm or SGE),
#' one future per recording, when the future package is installed; in this R
#' process, one recording after the other, where no plan is set (the future
#' package not loaded, no `future.plan` option or `R_FUTURE_PLAN`).
#' Progress is reported through progressr (wrap the call in
#' `progressr::with_progress()`, or set `progressr::handlers(global =
#' TRUE)`).
#'
#' A recording that cannot be read or calibrated, or whose worker died,
#' becomes a row with status `"failed"` whose `message` says why; the others
#' go on.
#'
#' **Resuming.** Each finished recording is saved at once under
#' `outdir/.gravcal/`, with the key it was computed under: the recording's
#' full path, size, modification time and an MD5 fingerprint of its first
#' and last megabyte, and every setting that changes the result
#' (`method`, the arguments in `...`, gravcal's version). A run started
#' again with the same `outdir` takes a saved result only when its key is
#' unchanged (`resume = TRUE`); a recording replaced or changed, or new
#' settings, are calibrated again. A saved result that cannot be read (an
#' empty or truncated file) is recomputed, and its row's `message` says so.
#'
#' **Writing safely.** Every file is written under a name only gravcal uses
#' in the same folder (`.gravcal-<pid>-<random>.part`), flushed, checked for
#' its full size and then renamed over the old one, so a killed run or a
#' full disk never leaves a half-written file; a failed write is an error
#' naming the file, and the files written before stay as they were.
#' gravcal never deletes or overwrites a file it did not write: a
#' `calibration.csv` of someone else's in `outdir` stops the run. `outdir`
#' is made absolute before any worker starts. A run holds a lock on
#' `outdir` (the folder `outdir/.gravcal/lock`, holding the process id and
#' host of its owner); a second run on the same `outdir` refuses to start.
#' A lock left by a run that was killed on the same host is taken over
#' (the process is checked to be gone, without signalling it: on Windows
#' through `tasklist`, and a lock whose process cannot be checked there
#' is kept); one from another host must be
#' removed by hand, as the error message says.
#'
#' Written to `outdir`: `calibration.csv` (the table below) and, for
#' `method = "ggir"`, `calibration_ggir_coefs.csv`, the coefficients in
#' GGIR's `backup.cal.coef` format ([write_coefs()]) of exactly the
#' recordings of this table that were calibrated (status `"ok"`,
#' `"high_error"` or `"given"`; only the header when there are none). A run with the
#' lightweight method removes a `calibration_ggir_coefs.csv` an earlier run
#' wrote, since it no longer matches the table.
#'
#' **Identity.** A recording is known by its path relative to the cohort's
#' root: the directory given as `files`, or the longest common directory of
#' the paths given (for recordings all in one folder, their file names;
#' for `a/p01.bin` and `b/p01.bin`, those). This identity is the table's
#' `file` column, the names of `attr(, "fits")`, and names the recording in
#' progress and in messages. GGIR's coefficient file matches rows by file
#' name alone, so `method = "ggir"` refuses, before any work, two
#' recordings with the same file name in different folders.
#'
#' **Plausibility.** Every calibrated recording is judged against the
#' bounds of [plausible_bounds()] and against its device's other recordings
#' (by the `serial` column; pooled rows are not part of a device's
#' history). A device with at least 3 calibrated recordings has a
#' reference: the median of each coefficient over its recordings (first
#' those without a firmware-style attenuation when at least 3 remain; then,
#' for the judgement that counts, those the first judgement did not flag,
#' when at least 2 remain), with a
#' robust spread (the median absolute deviation, scaled to a standard
#' deviation; the median of all devices' spreads in the cohort when that
#' is larger, so that a device whose few recordings happen to agree is not
#' held to a tighter rule than the cohort's fits show). Offsets depend on
#' the temperature a fit's temperature term is centred on (its recording's
#' mean temperature), so a device's offsets are first restated at one
#' temperature, the median of its recordings' (`o + (T_ref - m) K^-1 t`).
#' A recording's coefficient disagrees with the reference when
#' it differs by more than 4 times the combined uncertainty (its standard
#' error, the reference's and the spread) and by at least the coefficient's
#' practical minimum (`practical_min` of [plausible_bounds()]: 5 mg for
#' offsets, 0.5 % for scales, 1 mg per degree C for temperature offsets,
#' changes that move a day's ENMO by about 1 mg). Column `plausibility` says
#' `"attenuated"` (all three scales changed by one common factor, at least
#' 0.02 from the device's reference or 0.03 from 1, beyond their uncertainty:
#' what a firmware fault that attenuates the raw signal does, as in
#' ActiGraph's notice 16CPAN03), `"out_of_bounds"` (beyond omconvert's
#' bounds, or not applied because beyond gravcal's),
#' `"temperature_implausible"` (a mean temperature outside -20 to 70 degrees
#' C, `plausible_bounds()`'s `temperature_range`: a faulty sensor or a
#' misread temperature), `"temperature_stuck"`
#' (the recording's temperature does not vary, column `temperature_flat`,
#' over 12 h or more, or while another recording of the device has a
#' temperature that varies: a stuck sensor, whose recording is calibrated
#' without a temperature term; gravcal's own modes), `"device_outlier"`
#' (disagrees with its device's reference) or `"ok"`, in that order of
#' precedence; `NA` for a recording not calibrated. `plausibility_note`
#' says why, with the device's reference values. The devices' references
#' are in `attr(, "devices")` (one row per device with a history: `serial`,
#' `recordings`, `reference_recordings`, `reference_files` and
#' `left_out_files` (the recordings its reference used and those it left
#' out, separated by `"; "`), `reference_temp`, `ref.<coefficient>`,
#' `spread.<coefficient>`), and each fit in `attr(, "fits")` carries its
#' flag (`fit$plausibility`), which `print()` shows. GGIR's coefficient file
#' is unchanged.
#'
#' @param files Paths of recordings (formats as [calibrate()] reads), or
#'   one directory, whose recordings are all taken.
#' @param method `"ggir"` (default) or `"lightweight"`; see [calibrate()].
#' @param outdir Directory for the results (created if needed).
#' @param ... Further arguments for [calibrate()] (for example `sf` for
#'   files that do not give it, `ggir_compat`, `minloadcrit`). They are
#'   part of the key of every saved result.
#' @param resume Take the results saved in `outdir` whose key matches
#'   (`TRUE`), or calibrate every recording again (`FALSE`).
#' @param pattern For a directory: the file names to take (a regular
#'   expression; the default takes every extension [read_recording()]
#'   reads).
#' @param recursive For a directory: take the recordings in its subfolders
#'   too (`TRUE`), leaving out gravcal's output folders (`outdir`, and any
#'   folder holding a `.gravcal` store), or only those in the directory
#'   itself (`FALSE`, default).
#' @param pool `"none"` (default) or `"device"`: calibrate the recordings
#'   that cannot be calibrated alone (status `"sphere_not_covered"`,
#'   `"bins_incomplete"`, `"too_short"` or `"no_rest"`) with the rest
#'   windows of all recordings of the same device (the serial number in the
#'   file's header, column `serial`). The device's recordings that do
#'   calibrate alone must first agree: no pair of them may differ by a Wald
#'   test of their coefficients at `0.01` over the number of pairs;
#'   otherwise, or when the pooled windows do not calibrate either, the
#'   rows stay as they were and their `message` says why. Pooled rows have
#'   `pooled = TRUE`, the pooled fit's coefficients and status, and a
#'   message naming the recordings pooled. For the GGIR method, each
#'   recording's rest windows are those GGIR's procedure kept when it
#'   calibrated that recording alone (with the settings in `...`: `sf`,
#'   `chunksize`, `max_sd`, `use_temp`, ...; a recording too short for the
#'   procedure gives none), and their union goes through the procedure's
#'   last step: at least 10 windows, every axis beyond `-+spherecrit`, the
#'   fit, GGIR's errors and QC message (`minloadcrit` against the hours
#'   pooled), the temperature term when every recording pooled used it.
#' @param coefs `NULL` (default), or coefficients to apply instead of each
#'   recording's own: a data frame from [read_coefs()] (another tool's,
#'   converted to gravcal's model), a [calibrate_files()] table or a named
#'   list of fits of GGIR's model, with a row for every recording (matched
#'   by file name without folder and extension; rows for other recordings
#'   are not used). Each recording is still read and calibrated as without
#'   `coefs` (its saved result is the same, so `resume` reuses it), then its
#'   row and fit take the given coefficients: status `"given"`, a message
#'   naming the tool and the recording's own status, `error_before_mg` and
#'   `error_after_mg` on its own rest points with the given coefficients, no
#'   standard errors, `parameters` 0; `calibration_ggir_coefs.csv` holds
#'   them. Not with `pool = "device"`.
#' @param outcomes Add each recording's outcomes with its calibration and
#'   their standard errors from the fit's covariance (`TRUE`), or not
#'   (`FALSE`, default: no epoch signals are computed). The worker that
#'   calibrates a recording then computes its epoch signals
#'   ([epoch_signals()], ENMO, from the file, or from the samples
#'   [read_recording()] gives for a format it does not read) and their
#'   [summary.gravcal_epochs()]; a recording whose fit is replaced after
#'   (`pool`, `coefs`) has them computed again with the new fit. Results
#'   saved without outcomes are computed again; those saved with them serve
#'   runs without.
#' @return A data frame, one row per recording, in the order of `files`:
#'   `file` (the recording's identity, see above), `status` (see [calibrate()], `"given"` (see
#'   `coefs`), or `"failed"`),
#'   `message` (why, for a recording that failed or was not calibrated;
#'   also notes such as a damaged saved result that was recomputed); the
#'   coefficients named as in GGIR's coefficient file: `scale.x`,
#'   `scale.y`, `scale.z`, `offset.x`, `offset.y`, `offset.z`,
#'   `temperature.offset.x`, `temperature.offset.y`,
#'   `temperature.offset.z`, then for the lightweight method the cross-axis
#'   terms `cross.xy`, `cross.xz`, `cross.yz` (`k_xy`, `k_xz`, `k_yz` of
#'   `coef()`); their standard errors, in the same order, named with a
#'   `.se` suffix (`scale.x.se`, ...; `fit$se`, NA for what was not
#'   fitted or not applied); `parameters` (how many coefficients the model
#'   fitted: 9, 6 or 3 for the lightweight method, which fits what the
#'   recording determines; 6 or 9 for the GGIR method; 0 when not
#'   calibrated) and `points` (calibration points used); `meantempcal`;
#'   `temperature_flat` (TRUE when the recording has a temperature that does
#'   not vary, see [plausible_bounds()]; FALSE when it varies; NA without a
#'   temperature or in GGIR-compatible mode);
#'   `error_before_mg`, `error_after_mg` (on the rest points used); `format`,
#'   `serial` (the device's serial number from the file's header, NA
#'   where there is none), `pooled` (see `pool`), `plausibility` and
#'   `plausibility_note` (see Plausibility above), `hours` (of samples read), `windows`,
#'   `rest_windows`, `excluded_norm`, `excluded_clipped` and
#'   `excluded_identical` (rest windows the guards left out, by reason; NA
#'   where they do not run: GGIR-compatible mode), `rejected_windows` and
#'   `rejected_hours` (rest windows left out as not on the sphere, and the
#'   hours of their stretches, see "Rest that is not rest" in
#'   [calibrate()]; NA where the rule does not run: GGIR-compatible mode,
#'   `selection = "paper"`, given coefficients); what the file's reader did: `reader` (`"native"` or
#'   `"reference"`), `samples` read, `skipped` (units its decoder could
#'   not use: damaged blocks, pages, records or lines), `gaps` and
#'   `gap_seconds` (jumps in time), `truncated` and `read_notes` (the first
#'   problems, where they were); `warnings` (the warnings raised while
#'   calibrating that recording, separated by `"; "`) and `seconds` (time
#'   taken); with `outcomes = TRUE`, last, `enmo_mg` (the mean ENMO of the
#'   recording's 5 s epochs, mg), `min_above_100mg_day` (minutes of epochs
#'   above 100 mg per 24 hours) and their standard errors from the
#'   calibration's uncertainty, `enmo_mg_se` and `min_above_100mg_day_se`
#'   (NA where the fit has no covariance), as
#'   `summary(epoch_signals(file, fit))$recording` gives them; why they are
#'   missing, if they are, is in `message`. The fits are in
#'   `attr(, "fits")`.
#' @seealso [calibrate_cli()] for batch scripts.
#' @export
#' @examples
#' dir <- tempfile("cohort")
#' dir.create(dir)
#' for (i in 1:2) {
#'   rec <- simulate_recording(hours = 6, sf = 10, seed = i)
#'   saveRDS(rec, file.path(dir, sprintf("p%02d.rds", i)))
#' }
#' res <- calibrate_files(dir, method = "lightweight",
#'                        outdir = file.path(dir, "out"))
#' res[, c("file", "status", "error_before_mg", "error_after_mg")]
#' list.files(file.path(dir, "out"))
#' unlink(dir, recursive = TRUE)
calibrate_files <- function(files, method = c("ggir", "lightweight"), outdir,
                            ..., resume = TRUE,
                            pattern = format_file_pattern(),
                            pool = c("none", "device"), recursive = FALSE,
                            coefs = NULL, outcomes = FALSE) {
  method <- match_choice(method, "method")
  pool <- match_choice(pool, "pool")
  if (!is.null(coefs) && pool == "device") {
    abort("`pool = \"device\"` cannot be used with `coefs`: the given ",
          "coefficients replace every recording's own.")
  }
  if (missing(outdir) || !is.character(outdir) || length(outdir) != 1 ||
      is.na(outdir) || !nzchar(outdir)) {
    abort("`outdir` must be a directory path for the results.")
  }
  check_flag(recursive, "recursive")
  check_flag(outcomes, "outcomes")
  cohort <- cohort_files(files, pattern, recursive, outdir)
  paths <- cohort$path
  ids <- cohort$id
  # GGIR's coefficient file keys its rows by file name
  if (method == "ggir") check_ggir_names(paths, ids)
  given <- if (!is.null(coefs)) given_coefs(coefs, ids)
  check_flag(resume, "resume")
  args <- list(...)
  if (length(args) && (is.null(names(args)) || any(!nzchar(names(args))))) {
    abort("All arguments in `...` must be named (they go to calibrate()).")
  }
  if (length(args)) args <- args[order(names(args))]
  outdir <- cohort_outdir(outdir)
  store <- file.path(outdir, ".gravcal")
  lock <- lock_outdir(store)
  on.exit(unlock_outdir(lock), add = TRUE)
  # what a killed run of gravcal's left half-written: gravcal's names only
  remove_parts(c(outdir, store))
  outputs <- file.path(outdir, c("calibration.csv", "calibration_ggir_coefs.csv"))
  check_owned(outputs, store)

  settings <- list(method = method, args = args,
                   gravcal = as.character(utils::packageVersion("gravcal")))
  slots <- file.path(store, paste0(slot_names(paths, method), ".rds"))
  saved <- lapply(seq_along(paths), function(i) {
    if (resume) read_saved(slots[i], file_identity(paths[i]), settings) else list()
  })
  # (with `outcomes`, also the results saved without them: the key is the
  # same, so that a run without outcomes reuses results saved with them)
  todo <- which(vapply(saved, function(s) {
    is.null(s$result) || (outcomes && is.null(s$result$outcomes))
  }, TRUE))
  # what is redone is not taken from an earlier run if this one fails
  unlink(slots[todo])
  failures <- run_cohort(todo, cohort_worker(paths, ids, slots, method, args,
                                             settings, outcomes), ids)

  results <- lapply(seq_along(paths), function(i) {
    s <- saved[[i]]
    if (i %in% todo) {
      s2 <- read_saved(slots[i], NULL, settings)
      s$result <- s2$result
      if (is.null(s$result)) {
        why <- failures[[as.character(i)]]
        if (is.null(why)) why <- if (is.null(s2$note)) "no saved result" else s2$note
        s$result <- list(row = cohort_row(paths[i], ids[i], NULL, paste0(
          "no result: ", sub("[.]$", "", why), "; run again to retry"), "",
          NA_real_, method),
          fit = NULL)
      }
    }
    # the identity in this run's cohort (a result saved when the cohort's
    # root was another keeps its key, the full path)
    s$result$row$file <- ids[i]
    if (!is.null(s$note)) s$result$row$message <- join_notes(s$result$row$message, s$note)
    s$result
  })
  tab <- do.call(rbind, lapply(results, `[[`, "row"))
  rownames(tab) <- NULL
  fits <- stats::setNames(lapply(results, `[[`, "fit"), ids)
  own_fits <- fits
  if (pool == "device") {
    pooled <- pool_devices(paths, ids, tab, fits, method, args)
    tab <- pooled$tab
    fits <- pooled$fits
  }
  if (!is.null(given)) {
    for (i in seq_along(ids)) {
      if (is.null(fits[[i]])) next  # failed: nothing to apply them to
      g <- with_given(fits[[i]], given[i, , drop = FALSE])
      row <- cohort_row(paths[i], ids[i], g, NULL, character(0),
                        tab$seconds[i], method)
      row$warnings <- tab$warnings[i]
      tab[i, ] <- row
      fits[[i]] <- g
    }
  }
  if (outcomes) tab <- add_outcomes(tab, results, fits, own_fits, paths, args$sf)
  # whether each recording's temperature varies (the fit's own check)
  tab <- add_temperature_flat(tab, fits)
  # each fit judged against the bounds and its device's other recordings
  judged <- cohort_plausibility(tab)
  tab <- place_plausibility(judged$tab)
  for (i in seq_along(fits)) {
    if (!is.null(fits[[i]])) {
      fits[[i]]$plausibility <- list(flag = tab$plausibility[i],
                                     note = tab$plausibility_note[i])
    }
  }
  write_owned(csv_bytes(tab), outputs[1], store)
  if (method == "ggir") {
    ok <- tab$status %in% c("ok", "high_error", "given") &
      !vapply(fits, is.null, TRUE)
    ggir_rows <- if (any(ok)) {
      ggir_coef_table(stats::setNames(fits[ok], ggir_file_name(paths[ok])))
    } else empty_ggir_coefs()
    write_owned(csv_bytes(ggir_rows), outputs[2], store)
  } else {
    remove_owned(outputs[2], store)
  }
  attr(tab, "fits") <- fits
  attr(tab, "devices") <- judged$devices
  tab
}

# The outcome columns (outcome_row()) at the end of the table: the workers'
# with each recording's own fit, computed again here for a recording whose
# fit was replaced after them (pooled, given coefficients); their notes
# joined to `message`.
add_outcomes <- function(tab, results, fits, own_fits, paths, sf) {
  rows <- lapply(seq_along(fits), function(i) {
    o <- results[[i]]$outcomes
    if (is.null(o) || !identical(fits[[i]], own_fits[[i]])) {
      o <- outcome_row(paths[i], fits[[i]], sf_for_file(paths[i], sf))
    }
    if (!is.null(o$note)) tab$message[i] <<- join_notes(tab$message[i], o$note)
    o$row
  })
  cbind(tab, do.call(rbind, rows))
}

# Column `temperature_flat` after `meantempcal`: TRUE when the recording
# has a temperature that does not vary (the fit's temperature_check(),
# gravcal's own modes), FALSE when it varies, NA when not known (no
# temperature, not calibrated, GGIR-compatible mode).
add_temperature_flat <- function(tab, fits) {
  flat <- vapply(fits, function(f) {
    v <- if (is.null(f)) NULL else f$temperature_check$flat
    if (length(v) == 1 && !is.na(v)) as.logical(v) else NA
  }, NA)
  tab$temperature_flat <- unname(flat)
  at <- match("meantempcal", names(tab))
  rest <- setdiff(names(tab), "temperature_flat")
  tab[c(rest[seq_len(at)], "temperature_flat", rest[-seq_len(at)])]
}

# The plausibility columns right after `pooled`.
place_plausibility <- function(tab) {
  pl <- c("plausibility", "plausibility_note")
  rest <- setdiff(names(tab), pl)
  at <- match("pooled", rest)
  tab[c(rest[seq_len(at)], pl, rest[-seq_len(at)])]
}

# The recordings of a cohort: list(path, id). `path`: absolute, so that
# workers with another working directory find them. `id`: the recording's
# identity, its path relative to the cohort's root (the directory given, or
# the longest common directory of the paths given), with "/" between
# folders: the file name when all recordings are in one folder. A directory
# is listed with its subfolders when `recursive`, leaving out gravcal's
# output folders (`outdir`, and any folder holding a .gravcal store).
cohort_files <- function(files, pattern, recursive, outdir) {
  if (!is.character(files) || !length(files) || anyNA(files)) {
    abort("`files` must be file paths or one directory, not ",
          describe(files), ".")
  }
  if (length(files) == 1 && dir.exists(files)) {
    root <- normalizePath(files, winslash = "/", mustWork = TRUE)
    rel <- list.files(root, pattern = pattern, recursive = recursive,
                      ignore.case = TRUE)
    path <- file.path(root, rel)
    # regular files only: a folder is not a recording, and opening a named
    # pipe would wait for a writer
    keep <- vapply(path, file_kind, "") == "file" & !in_unisens_folder(path)
    if (recursive) keep <- keep & !under_output(path, root, outdir)
    rel <- rel[keep]
    if (!length(rel)) {
      abort("`files`: no recordings in \"", files, "\" (pattern \"", pattern, "\"",
            if (recursive) ", subfolders included", ").")
    }
    o <- order(rel)
    return(list(path = path[keep][o], id = rel[o]))
  }
  # unisens folders (Movisens recordings) stand for their acc.bin
  files <- unname(vapply(files, unisens_acc, ""))
  absent <- !file.exists(files)
  if (any(absent)) {
    abort("`files`: ", sum(absent), " file(s) do not exist: ",
          paste0("\"", utils::head(files[absent], 3), "\"", collapse = ", "),
          if (sum(absent) > 3) ", ...", ".")
  }
  folders <- dir.exists(files)
  if (any(folders)) {
    abort("`files` must be recordings or one directory; these are ",
          "directories: ", paste0("\"", utils::head(files[folders], 3), "\"",
                                   collapse = ", "), ".")
  }
  for (f in files) check_regular_file(f, "files")
  files <- normalizePath(files, winslash = "/", mustWork = TRUE)
  if (anyDuplicated(files)) {
    abort("`files` lists a file twice: \"", files[anyDuplicated(files)], "\".")
  }
  list(path = files, id = relative_to_common(files))
}

# Paths (absolute, "/"-separated) relative to their longest common
# directory; whole paths where they have none (two drives).
relative_to_common <- function(paths) {
  dirs <- strsplit(dirname(paths), "/", fixed = TRUE)
  k <- 0L
  while (k < min(lengths(dirs)) &&
         all(vapply(dirs, `[`, "", k + 1L) == dirs[[1]][k + 1L])) {
    k <- k + 1L
  }
  if (k == 0L) return(paths)
  substring(paths, nchar(paste(dirs[[1]][seq_len(k)], collapse = "/")) + 2L)
}

# Which paths lie in gravcal's output folders below `root`: `outdir` and
# any folder holding a .gravcal store.
under_output <- function(paths, root, outdir) {
  dirs <- list.dirs(root, full.names = TRUE, recursive = TRUE)
  out <- dirs[dir.exists(file.path(dirs, ".gravcal"))]
  if (dir.exists(outdir)) out <- c(out, normalizePath(outdir, winslash = "/"))
  out <- setdiff(out, root)
  inside <- logical(length(paths))
  for (d in out) inside <- inside | startsWith(paths, paste0(d, "/"))
  inside
}

# GGIR's coefficient file (calibration_ggir_coefs.csv; GGIR's
# backup.cal.coef) matches its rows to recordings by file name: two
# recordings of one name in different folders are refused before any work.
check_ggir_names <- function(paths, ids) {
  name <- ggir_file_name(paths)
  d <- anyDuplicated(name)
  if (d) {
    both <- ids[name == name[d]]
    abort("`files`: \"", both[1], "\" and \"", both[2], "\" have the same ",
          "file name, \"", name[d], "\", and GGIR's coefficient file (",
          "calibration_ggir_coefs.csv, for GGIR's backup.cal.coef) takes one ",
          "row per file name. Rename one, calibrate them in separate runs ",
          "(another `outdir`), or use method = \"lightweight\".")
  }
}

# `outdir`, created if needed, as an absolute path.
cohort_outdir <- function(outdir) {
  if (file.exists(outdir) && !dir.exists(outdir)) {
    abort("`outdir` must be a directory, but \"", outdir, "\" is a file.")
  }
  dir.create(file.path(outdir, ".gravcal"), recursive = TRUE,
             showWarnings = FALSE)
  if (!dir.exists(file.path(outdir, ".gravcal"))) {
    abort("Could not create `outdir`: \"", outdir, "\".")
  }
  normalizePath(outdir, mustWork = TRUE)
}

# ---- resume: saved results and their keys ---------------------------------

md5_raw <- function(bytes) {
  tmp <- tempfile("gravcal-md5-")
  on.exit(unlink(tmp))
  writeBin(bytes, tmp)
  unname(tools::md5sum(tmp))
}
