#' Calibrate many recordings, in parallel, resumably
#'
#' Calibrates every file with [calibrate()], each read block by block, and
#' returns one row per recording. The work is spread over whatever
#' `future::plan()` the session has set (sequential by default;
#' `plan(multisession)` on a laptop, `future.batchtools` on Slurm or SGE),
#' one future per recording, when the future package is installed.
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
#' identity (full path, size, modification time and an MD5 fingerprint of
#' its first and last megabyte) and every setting that changes the result
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
#' (the process is checked to be gone); one from another host must be
#' removed by hand, as the error message says.
#'
#' Written to `outdir`: `calibration.csv` (the table below) and, for
#' `method = "ggir"`, `calibration_ggir_coefs.csv`, the coefficients in
#' GGIR's `backup.cal.coef` format ([write_ggir_coefs()]) of exactly the
#' recordings of this table that were calibrated (status `"ok"` or
#' `"high_error"`; only the header when there are none). A run with the
#' lightweight method removes a `calibration_ggir_coefs.csv` an earlier run
#' wrote, since it no longer matches the table.
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
#'   message naming the recordings pooled.
#' @return A data frame, one row per recording, in the order of `files`:
#'   `file` (the file name), `status` (see [calibrate()], or `"failed"`),
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
#'   `error_before_mg`, `error_after_mg` (on the rest points used); `format`,
#'   `serial` (the device's serial number from the file's header, NA
#'   where there is none), `pooled` (see `pool`), `hours` (of samples read), `windows`,
#'   `rest_windows`; what the file's reader did: `reader` (`"native"` or
#'   `"reference"`), `samples` read, `skipped` (units its decoder could
#'   not use: damaged blocks, pages, records or lines), `gaps` and
#'   `gap_seconds` (jumps in time), `truncated` and `read_notes` (the first
#'   problems, where they were); `warnings` (the warnings raised while
#'   calibrating that recording, separated by `"; "`) and `seconds` (time
#'   taken). The fits are in `attr(, "fits")`.
#' @seealso [calibrate_cli()] for batch scripts.
#' @export
#' @examples
#' dir <- tempfile("cohort")
#' dir.create(dir)
#' for (i in 1:2) {
#'   rec <- simulate_recording(hours = 12, sf = 10, seed = i)
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
                            pool = c("none", "device")) {
  method <- match_choice(method, "method")
  pool <- match_choice(pool, "pool")
  files <- cohort_files(files, pattern)
  if (missing(outdir) || !is.character(outdir) || length(outdir) != 1 ||
      is.na(outdir) || !nzchar(outdir)) {
    abort("`outdir` must be a directory path for the results.")
  }
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
  slots <- file.path(store, paste0(slot_names(files, method), ".rds"))
  saved <- lapply(seq_along(files), function(i) {
    if (resume) read_saved(slots[i], file_identity(files[i]), settings) else list()
  })
  todo <- which(vapply(saved, function(s) is.null(s$result), TRUE))
  # what is redone is not taken from an earlier run if this one fails
  unlink(slots[todo])
  failures <- run_cohort(todo, cohort_worker(files, slots, method, args, settings),
                         basename(files))

  results <- lapply(seq_along(files), function(i) {
    s <- saved[[i]]
    if (i %in% todo) {
      s2 <- read_saved(slots[i], NULL, settings)
      s$result <- s2$result
      if (is.null(s$result)) {
        why <- failures[[as.character(i)]]
        if (is.null(why)) why <- if (is.null(s2$note)) "no saved result" else s2$note
        s$result <- list(row = cohort_row(files[i], NULL, paste0(
          "no result: ", sub("[.]$", "", why), "; run again to retry"), "",
          NA_real_, method),
          fit = NULL)
      }
    }
    if (!is.null(s$note)) s$result$row$message <- join_notes(s$result$row$message, s$note)
    s$result
  })
  tab <- do.call(rbind, lapply(results, `[[`, "row"))
  rownames(tab) <- NULL
  fits <- stats::setNames(lapply(results, `[[`, "fit"), basename(files))
  if (pool == "device") {
    pooled <- pool_devices(files, tab, fits, method, args)
    tab <- pooled$tab
    fits <- pooled$fits
  }
  write_owned(csv_bytes(tab), outputs[1], store)
  if (method == "ggir") {
    ok <- tab$status %in% c("ok", "high_error") &
      !vapply(fits, is.null, TRUE)
    coefs <- if (any(ok)) ggir_coef_table(fits[ok]) else empty_ggir_coefs()
    write_owned(csv_bytes(coefs), outputs[2], store)
  } else {
    remove_owned(outputs[2], store)
  }
  attr(tab, "fits") <- fits
  tab
}

# The recordings: the paths given, or those in one directory; absolute, so
# that workers with another working directory find them.
cohort_files <- function(files, pattern) {
  if (!is.character(files) || !length(files) || anyNA(files)) {
    abort("`files` must be file paths or one directory, not ",
          describe(files), ".")
  }
  if (length(files) == 1 && dir.exists(files)) {
    found <- list.files(files, pattern = pattern, full.names = TRUE,
                        ignore.case = TRUE)
    found <- found[!dir.exists(found)]
    if (!length(found)) {
      abort("`files`: no recordings in \"", files, "\" (pattern \"", pattern, "\").")
    }
    return(normalizePath(sort(found), mustWork = TRUE))
  }
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
  files <- normalizePath(files, mustWork = TRUE)
  if (anyDuplicated(files)) {
    abort("`files` lists a file twice: \"", files[anyDuplicated(files)], "\".")
  }
  files
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

# One saved result per recording and method, named after the file and the
# MD5 of its path and the method.
slot_names <- function(files, method) {
  vapply(files, function(f) {
    paste0(gsub("[^A-Za-z0-9._-]", "_", basename(f)), "-",
           substr(md5_raw(charToRaw(paste(f, method))), 1, 12))
  }, "", USE.NAMES = FALSE)
}

md5_raw <- function(bytes) {
  tmp <- tempfile("gravcal-md5-")
  on.exit(unlink(tmp))
  writeBin(bytes, tmp)
  unname(tools::md5sum(tmp))
}

# What a recording is: its path, size, modification time and the MD5 of its
# first and last MiB. Hashing whole files (a week at 100 Hz is 0.3-1 GB)
# would read the cohort once more on every resume; a replaced recording has
# another header (device, start time) and another end, and an edited one
# another size or time, so these 2 MiB and the size tell them apart.
file_identity <- function(file, mib = 1) {
  info <- file.info(file, extra_cols = FALSE)
  n <- mib * 2^20
  con <- file(file, "rb", raw = TRUE)
  on.exit(close(con))
  head <- readBin(con, "raw", n)
  tail <- raw(0)
  if (info$size > n) {
    seek(con, max(n, info$size - n))
    tail <- readBin(con, "raw", n)
  }
  list(path = file, size = info$size, mtime = as.numeric(info$mtime),
       fingerprint = md5_raw(c(head, tail)))
}

# A saved result whose key matches: list(result = ); a stale one is removed
# (list()); a damaged one is removed and noted (list(note = )).
read_saved <- function(slot, identity, settings) {
  if (!file.exists(slot)) return(list())
  res <- tryCatch(readRDS(slot), error = function(e) e, warning = function(w) w)
  bad <- if (inherits(res, "condition")) {
    conditionMessage(res)
  } else if (!is.list(res) || !is.data.frame(res$row) || !is.list(res$key)) {
    "not a gravcal result"
  }
  if (!is.null(bad)) {
    unlink(slot)
    return(list(note = paste0("the saved result \"", slot, "\" could not be ",
                              "read (", bad, ") and was recomputed")))
  }
  # a result saved before the rows carried standard errors and the model's
  # size is stale too
  if (!identical(res$key$settings, settings) ||
      !all(c("scale.x.se", "parameters", "serial") %in% names(res$row)) ||
      (!is.null(identity) && !identical(res$key$identity, identity))) {
    unlink(slot)
    return(list())
  }
  list(result = res)
}

# The function each worker runs for recording i: calibrate, save at once.
cohort_worker <- function(files, slots, method, args, settings) {
  force(files)
  force(slots)
  force(method)
  force(args)
  force(settings)
  function(i, p) {
    identity <- file_identity(files[i])
    res <- calibrate_one(files[i], method, args)
    res$key <- list(identity = identity, settings = settings)
    write_bytes_atomic(serialize(res, NULL), slots[i])
    if (!is.null(p)) p(message = basename(files[i]))
    invisible(NULL)
  }
}

# Run worker(i, progressor) for every i in todo, one future per recording
# on the plan the user set (a plain loop without the future package).
# Returns why the recordings without a result have none, by index. When a
# worker dies, the recordings it was calibrating are reported; those that
# could not even start on the dead worker are run again once on fresh
# workers (the plan is set again, which restarts its workers).
run_cohort <- function(todo, worker, labels) {
  failures <- list()
  if (!length(todo)) return(failures)
  dead <- FALSE
  failed <- function(i) {
    force(i)
    function(e) {
      why <- conditionMessage(e)
      if (inherits(e, "FutureError")) {
        dead <<- TRUE
        why <- paste0("the R process calibrating it stopped (",
                      sub("[.] Post-mortem.*$", "", why), ")")
      }
      failures[[as.character(i)]] <<- why
      NULL
    }
  }
  p <- if (requireNamespace("progressr", quietly = TRUE)) {
    progressr::progressor(steps = length(todo))
  }
  if (!requireNamespace("future", quietly = TRUE)) {
    for (i in todo) tryCatch(worker(i, p), error = failed(i))
    return(failures)
  }
  run <- function(queue) {
    fs <- list()
    unstarted <- integer(0)
    for (i in queue) {
      f <- tryCatch(
        future::future(worker(i, p), globals = list(worker = worker, i = i, p = p),
                       packages = "gravcal", seed = TRUE, label = labels[i]),
        error = function(e) e)
      if (inherits(f, "FutureError")) {
        # the worker it went to had died with an earlier recording
        dead <<- TRUE
        unstarted <- c(unstarted, i)
      } else if (inherits(f, "error")) {
        failed(i)(f)
      } else {
        fs[[as.character(i)]] <- f
      }
    }
    for (k in names(fs)) tryCatch(future::value(fs[[k]]), error = failed(k))
    unstarted
  }
  again <- run(todo)
  if (dead) {
    restart_workers()
    dead <- FALSE
  }
  if (length(again)) {
    again <- run(again)
    if (dead) restart_workers()
    for (i in again) {
      failures[[as.character(i)]] <- "no worker could start it (they had stopped)"
    }
  }
  failures
}

# Set the plan again: a cluster plan starts fresh workers.
restart_workers <- function() {
  strategies <- future::plan("list")
  future::plan(future::sequential)
  future::plan(strategies)
}

# One recording: the fit and its row, or a row saying what went wrong. The
# warnings raised while calibrating it go into its row.
calibrate_one <- function(file, method, args) {
  t0 <- proc.time()[["elapsed"]]
  cohort_fault("calibrate", file)
  cohort_fault("pause", file)
  warns <- character(0)
  err <- NULL
  fit <- tryCatch(
    withCallingHandlers(
      do.call(calibrate, c(list(x = file, method = method), args)),
      warning = function(w) {
        warns <<- c(warns, conditionMessage(w))
        invokeRestart("muffleWarning")
      }),
    error = function(e) {
      err <<- conditionMessage(e)
      NULL
    })
  list(row = cohort_row(file, fit, err, unique(warns),
                        proc.time()[["elapsed"]] - t0, method),
       fit = fit)
}

cohort_row <- function(file, fit, error, warnings, seconds, method) {
  na <- is.null(fit)
  cf <- if (na) rep(NA_real_, 12) else unname(stats::coef(fit))
  coefs <- stats::setNames(as.list(cf[c(1:3, 7:12)]), c(
    "scale.x", "scale.y", "scale.z", "offset.x", "offset.y", "offset.z",
    "temperature.offset.x", "temperature.offset.y", "temperature.offset.z"))
  if (method == "lightweight") {
    coefs[c("cross.xy", "cross.xz", "cross.yz")] <- as.list(cf[4:6])
  }
  # their standard errors, same order, named with a .se suffix
  se <- if (na || is.null(fit$se)) rep(NA_real_, 12) else unname(fit$se)
  se <- se[c(1:3, 7:12, 4:6)[seq_along(coefs)]]
  coefs[paste0(names(coefs), ".se")] <- as.list(se)
  num <- function(v) if (is.null(v)) NA_real_ else as.numeric(v)[1]
  inp <- if (na) NULL else fit$input
  rep <- inp$report
  format <- tryCatch(file_format(file), error = function(e) NA_character_)
  rest <- if (na) NA_real_ else if (method == "ggir") {
    as.numeric(NROW(fit$points))
  } else as.numeric(NROW(fit$windows))
  data.frame(
    file = basename(file),
    status = if (na) "failed" else fit$status,
    message = if (na) paste(error, collapse = "; ") else fit$message,
    coefs,
    parameters = if (na) NA_integer_ else length(fit$model),
    points = if (na) NA_integer_ else NROW(fit$points),
    meantempcal = if (na) NA_real_ else num(fit$meantemp),
    error_before_mg = if (na) NA_real_ else 1000 * fit$error_before,
    error_after_mg = if (na) NA_real_ else 1000 * fit$error_after,
    format = format,
    serial = if (na || is.null(fit$input$serial)) NA_character_ else
      as.character(fit$input$serial),
    pooled = FALSE,
    hours = if (na) NA_real_ else fit_hours(fit),
    windows = if (na) NA_real_ else num(fit$n_windows),
    rest_windows = rest,
    # what the reader read and skipped (native decoders)
    reader = if (is.null(inp$reader)) NA_character_ else inp$reader,
    samples = num(inp$samples),
    skipped = num(rep$skipped), gaps = num(rep$gaps),
    gap_seconds = num(rep$gap_seconds),
    truncated = if (is.null(rep)) NA else isTRUE(rep$truncated),
    read_notes = if (length(rep$notes)) paste(rep$notes, collapse = "; ") else "",
    warnings = paste(warnings, collapse = "; "),
    seconds = seconds, stringsAsFactors = FALSE, check.names = FALSE)
}

# Hours of samples read (the GGIR method's own count holds only the whole
# hours it used).
fit_hours <- function(fit) {
  inp <- fit$input
  if (isTRUE(is.finite(inp$samples) && is.finite(inp$sf) && inp$sf > 0)) {
    return(as.numeric(inp$samples) / inp$sf / 3600)
  }
  if (is.null(fit$hours)) NA_real_ else as.numeric(fit$hours)
}

join_notes <- function(a, b) {
  if (is.na(a) || !nzchar(a)) b else paste0(a, "; ", b)
}

# ---- writing: atomic files, owned outputs, the lock -----------------------

# Test hook: fault injection for the fault-injection tests,
# set through the environment so that workers inherit it.
# GRAVCAL_FAULT="write:REGEX" writes half the bytes of files whose path
# matches (a full disk); "calibrate:REGEX" kills the R process that starts
# to calibrate a matching recording (a worker dying mid-file); "pause:REGEX"
# waits 3 s before calibrating a matching recording (a long one).
cohort_fault <- function(stage, path) {
  f <- Sys.getenv("GRAVCAL_FAULT")
  if (!nzchar(f) || !startsWith(f, paste0(stage, ":"))) return(FALSE)
  if (!grepl(substring(f, nchar(stage) + 2), path)) return(FALSE)
  if (stage == "calibrate") tools::pskill(Sys.getpid(), tools::SIGKILL)
  if (stage == "pause") Sys.sleep(3)
  TRUE
}

# Write bytes to `path`: under a name only gravcal uses, in the same
# folder, flushed and checked for its size, then renamed over `path`.
write_bytes_atomic <- function(bytes, path) {
  tmp <- tempfile(sprintf(".gravcal-%d-", Sys.getpid()), tmpdir = dirname(path),
                  fileext = ".part")
  n <- if (cohort_fault("write", path)) length(bytes) %/% 2 else length(bytes)
  err <- tryCatch({
    con <- file(tmp, "wb")
    tryCatch({
      writeBin(bytes[seq_len(n)], con)
      flush(con)
    }, finally = close(con))
    NULL
  }, error = conditionMessage, warning = conditionMessage)
  size <- file.size(tmp)
  if (is.null(err) && !identical(size, as.double(length(bytes)))) {
    err <- sprintf("%s of %d bytes reached the disk; is it full?",
                   format(size), length(bytes))
  }
  if (is.null(err) && !file.rename(tmp, path)) {
    err <- paste0("could not rename \"", tmp, "\" to it")
  }
  if (!is.null(err)) {
    unlink(tmp)
    abort("Could not write \"", path, "\" (", err, "); that file was left ",
          "as it was.")
  }
  invisible(path)
}

csv_bytes <- function(df) {
  con <- rawConnection(raw(0), "wb")
  on.exit(close(con))
  utils::write.csv(df, con, row.names = FALSE)
  rawConnectionValue(con)
}

# Half-written files of gravcal's that a killed run left: gravcal's names
# only, removed while the lock is held.
remove_parts <- function(dirs) {
  unlink(list.files(dirs, pattern = "^[.]gravcal-[0-9]+-.*[.]part$",
                    full.names = TRUE, all.files = TRUE))
}

# The files of outdir that gravcal wrote, with their MD5, in
# .gravcal/written.csv: gravcal overwrites or removes only those.
owned_table <- function(store) {
  f <- file.path(store, "written.csv")
  tab <- if (file.exists(f)) {
    tryCatch(utils::read.csv(f, stringsAsFactors = FALSE, colClasses = "character"),
             error = function(e) NULL)
  }
  if (is.null(tab) || !all(c("file", "md5") %in% names(tab))) {
    tab <- data.frame(file = character(0), md5 = character(0))
  }
  tab
}

is_owned <- function(path, store) {
  tab <- owned_table(store)
  i <- match(basename(path), tab$file)
  !is.na(i) && identical(unname(tools::md5sum(path)), tab$md5[i])
}

check_owned <- function(paths, store) {
  for (p in paths[file.exists(paths)]) {
    if (!is_owned(p, store)) {
      abort("`outdir` holds \"", p, "\", which gravcal did not write (or ",
            "which was changed since); gravcal does not overwrite it. Move ",
            "it away or choose another `outdir`.")
    }
  }
}

record_owned <- function(path, store, md5) {
  tab <- owned_table(store)
  tab <- tab[tab$file != basename(path), , drop = FALSE]
  if (!is.na(md5)) tab <- rbind(tab, data.frame(file = basename(path), md5 = md5))
  write_bytes_atomic(csv_bytes(tab), file.path(store, "written.csv"))
}

write_owned <- function(bytes, path, store) {
  check_owned(path, store)
  write_bytes_atomic(bytes, path)
  record_owned(path, store, unname(tools::md5sum(path)))
}

remove_owned <- function(path, store) {
  if (file.exists(path) && is_owned(path, store)) {
    unlink(path)
    record_owned(path, store, NA_character_)
  }
}

# The lock on outdir: a folder created atomically, holding its owner's
# process id and host. A lock whose owner was on this host and is gone is
# taken over.
lock_outdir <- function(store) {
  lock <- file.path(store, "lock")
  host <- Sys.info()[["nodename"]]
  for (attempt in 1:2) {
    if (dir.create(lock, showWarnings = FALSE)) {
      owner <- c(paste0("pid=", Sys.getpid()), paste0("host=", host),
                 paste0("started=", format(Sys.time(), "%Y-%m-%d %H:%M:%S")))
      tryCatch(
        write_bytes_atomic(charToRaw(paste0(owner, "\n", collapse = "")),
                           file.path(lock, "owner")),
        error = function(e) {
          unlink(lock, recursive = TRUE)
          stop(e)
        })
      return(lock)
    }
    if (!dir.exists(lock)) {
      abort("Could not create the lock \"", lock, "\" on `outdir` (is the ",
            "disk full or the folder read-only?).")
    }
    owner <- lock_owner(lock)
    if (attempt == 2 || !lock_stale(owner, host)) break
    # move the stale lock aside (atomic), check it is the one we judged
    aside <- tempfile(sprintf(".gravcal-%d-", Sys.getpid()), tmpdir = store,
                      fileext = ".part")
    if (!file.rename(lock, aside)) next
    if (!identical(lock_owner(aside), owner)) {
      file.rename(aside, lock)
      break
    }
    unlink(aside, recursive = TRUE)
    message("gravcal: took over the lock of a run that is no longer ",
            "running (", lock_describe(owner), ").")
  }
  owner <- lock_owner(lock)
  abort("`outdir` \"", dirname(store), "\" is in use by another ",
        "calibrate_files() run (", lock_describe(owner), "; lock \"", lock,
        "\"). Wait for it to end. If no such run is going on (it was killed ",
        "on another machine), remove the lock: unlink(\"", lock,
        "\", recursive = TRUE).")
}

lock_owner <- function(lock) {
  lines <- tryCatch(suppressWarnings(readLines(file.path(lock, "owner"))),
                    error = function(e) character(0))
  kv <- strsplit(lines[grepl("=", lines)], "=", fixed = TRUE)
  stats::setNames(vapply(kv, function(x) paste(x[-1], collapse = "="), ""),
                  vapply(kv, `[`, "", 1))
}

lock_describe <- function(owner) {
  if (!length(owner) || is.na(owner["pid"])) return("owner unknown")
  paste0("process ", owner["pid"], " on ", owner["host"], ", started ",
         owner["started"])
}

# Stale: taken on this host by a process that no longer exists.
lock_stale <- function(owner, host) {
  pid <- suppressWarnings(as.integer(owner["pid"]))
  if (is.na(pid) || !identical(unname(owner["host"]), host) ||
      pid == Sys.getpid()) {
    return(FALSE)
  }
  if (dir.exists("/proc/self")) {
    if (!dir.exists(file.path("/proc", pid))) return(TRUE)
    # a process that has ended but is not yet reaped by its parent (a
    # zombie) holds nothing: its state, after the name in parentheses
    stat <- tryCatch(readLines(file.path("/proc", pid, "stat"), n = 1L, warn = FALSE),
                     error = function(e) character(0))
    state <- sub("^.*\\) ([A-Za-z]).*$", "\\1", stat)
    return(length(state) == 1L && state %in% c("Z", "X"))
  }
  !isTRUE(suppressWarnings(tools::pskill(pid, 0)))
}

unlock_outdir <- function(lock) {
  owner <- lock_owner(lock)
  if (identical(unname(owner["pid"]), as.character(Sys.getpid()))) {
    unlink(lock, recursive = TRUE)
  }
}

#' Command-line entry for batch scripts
#'
#' Runs [calibrate_files()] from the command line, for batch jobs on a
#' workstation or a cluster:
#'
#' `Rscript -e 'gravcal::calibrate_cli()' -- --method ggir --out results/ data/*.cwa`
#'
#' Options: `--method ggir|lightweight` (default ggir), `--out DIR`
#' (required), `--workers N` (parallel R sessions through
#' `future::plan(multisession)`; default: the plan already set, else one),
#' `--sf HZ` (for files that do not give their sampling rate), `--pattern
#' REGEX` (the recordings taken from a directory), `--no-resume` (redo
#' recordings already done), `--help`. The other arguments are the
#' recordings (or one directory).
#'
#' It prints a summary line, `gravcal: N recording(s): a calibrated, b not
#' calibrated, c failed; results in DIR/calibration.csv`. With `quit =
#' TRUE` (the default outside an interactive session) the R process then
#' ends with exit status 0 when no recording failed, 1 when any recording
#' failed (status `"failed"`: unreadable, or its worker died), and 2 when
#' the run could not start (bad arguments, `outdir` locked by another run,
#' a file that could not be written); the message says why. A recording
#' that was read but could not be calibrated (for example `"no_rest"`) is
#' not a failure. A batch job can therefore be resubmitted until it exits
#' with 0: it resumes.
#'
#' @param args The command-line arguments (by default those after `--`).
#' @param quit End the R process with the exit status above (`TRUE`), or
#'   return (`FALSE`, for use from R). `--help` always returns.
#' @return The table of [calibrate_files()], invisibly (when `quit =
#'   FALSE`); `NULL` after `--help`.
#' @export
#' @examples
#' calibrate_cli("--help")
calibrate_cli <- function(args = commandArgs(trailingOnly = TRUE),
                          quit = !interactive()) {
  check_flag(quit, "quit")
  args <- as.character(args)
  if (length(args) && args[1] == "--") args <- args[-1]
  if (!length(args) || any(args %in% c("--help", "-h"))) {
    writeLines(cli_help())
    return(invisible(NULL))
  }
  if (!quit) return(invisible(cli_run(args)))
  tab <- tryCatch(cli_run(args), error = function(e) {
    message("gravcal: error: ", conditionMessage(e))
    base::quit(save = "no", status = 2)
  })
  base::quit(save = "no", status = if (any(tab$status == "failed")) 1 else 0)
}

cli_help <- function() {
  c(
    "Usage: Rscript -e 'gravcal::calibrate_cli()' -- [options] FILE... | DIR",
    "Calibrate accelerometer recordings against gravity (gravcal).",
    "",
    "  --method M       ggir (default) or lightweight",
    "  --out DIR        directory for calibration.csv and the per-recording results",
    "  --workers N      parallel R sessions (future's multisession plan)",
    "  --sf HZ          sampling rate, for files that do not give it",
    "  --pattern REGEX  for a directory: the file names to take",
    "  --no-resume      redo recordings already done in DIR",
    "  --help           this text",
    "",
    "Exit status: 0 no recording failed, 1 some recording failed,",
    "2 the run could not start (bad arguments, DIR locked by another run).")
}

cli_run <- function(args) {
  opt <- cli_parse(args)
  extra <- list()
  if (!is.null(opt$sf)) {
    sf <- suppressWarnings(as.numeric(opt$sf))
    if (!isTRUE(is.finite(sf) && sf > 0)) {
      abort("`--sf` must be a positive number (Hz), not \"", opt$sf, "\".")
    }
    extra$sf <- sf
  }
  if (!is.null(opt$pattern)) extra$pattern <- opt$pattern
  if (!is.null(opt$workers)) {
    w <- suppressWarnings(as.numeric(opt$workers))
    if (!isTRUE(is.finite(w) && w >= 1 && w == round(w))) {
      abort("`--workers` must be a positive whole number, not \"",
            opt$workers, "\".")
    }
    if (!requireNamespace("future", quietly = TRUE)) {
      abort("`--workers` needs the future package: install.packages(\"future\").")
    }
    old <- future::plan(future::multisession, workers = w)
    on.exit(future::plan(old), add = TRUE)
  }
  tab <- do.call(calibrate_files, c(list(files = opt$files, method = opt$method,
                                         outdir = opt$out, resume = opt$resume),
                                    extra))
  done <- tab$status %in% c("ok", "high_error")
  failed <- tab$status == "failed"
  message(sprintf(paste0("gravcal: %d recording(s): %d calibrated, %d not ",
                         "calibrated, %d failed; results in %s"),
                  nrow(tab), sum(done), sum(!done & !failed), sum(failed),
                  file.path(normalizePath(opt$out), "calibration.csv")))
  tab
}

cli_parse <- function(args) {
  opt <- list(method = "ggir", resume = TRUE)
  files <- character(0)
  given <- character(0)
  takes <- c("--method", "--out", "--workers", "--sf", "--pattern")
  i <- 1
  while (i <= length(args)) {
    a <- args[i]
    if (a %in% takes) {
      if (i == length(args) || startsWith(args[i + 1], "--")) {
        abort("`", a, "` needs a value; see --help.")
      }
      name <- sub("^--", "", a)
      if (name %in% given) abort("`", a, "` is given twice.")
      given <- c(given, name)
      opt[[name]] <- args[i + 1]
      i <- i + 2
    } else if (a == "--no-resume") {
      opt$resume <- FALSE
      i <- i + 1
    } else if (startsWith(a, "-") && a != "-") {
      abort("Unknown option `", a, "`; see --help.")
    } else {
      files <- c(files, a)
      i <- i + 1
    }
  }
  if (is.null(opt$out)) abort("`--out DIR` is required; see --help.")
  if (!length(files)) abort("No recordings given; see --help.")
  if (!opt$method %in% c("ggir", "lightweight")) {
    abort("`--method` must be ggir or lightweight, not \"", opt$method, "\".")
  }
  opt$files <- files
  opt
}

# Statuses of a recording that cannot be calibrated alone, for pooling.
poolable_status <- c("sphere_not_covered", "bins_incomplete", "too_short",
                     "no_rest")

# calibrate_files(pool = "device"): see its documentation.
pool_devices <- function(files, tab, fits, method, args, alpha = 0.01) {
  need <- tab$status %in% poolable_status & !is.na(tab$serial)
  for (s in unique(tab$serial[need])) {
    idx <- which(tab$serial == s & !is.na(tab$serial))
    todo <- idx[need[idx]]
    note <- function(why) {
      tab$message[todo] <<- join_notes(tab$message[todo], paste0(
        "not pooled: ", why))
    }
    if (length(idx) < 2) {
      note(sprintf("no other recording of device %s", s))
      next
    }
    alone <- idx[tab$status[idx] == "ok" & !vapply(fits[idx], is.null, NA)]
    p <- pairwise_wald(fits[alone])
    if (length(p) && any(p <= alpha / length(p))) {
      note(sprintf(paste0("the recordings of device %s that calibrate alone ",
                          "disagree (Wald test, smallest p = %.2g)"), s,
                   min(p)))
      next
    }
    pf <- tryCatch(pooled_fit(files[idx], method, args),
                   error = function(e) e)
    if (inherits(pf, "error")) {
      note(sprintf("the pooled fit failed: %s", conditionMessage(pf)))
      next
    }
    if (!identical(pf$status, "ok")) {
      note(sprintf(paste0("pooled, the %d recordings of device %s still do ",
                          "not calibrate (%s)"), length(idx), s, pf$status))
      next
    }
    pf$pooled <- list(serial = s, files = basename(files[idx]))
    if (is.null(pf$input)) pf$input <- list(source = "pooled")
    pf$input$serial <- s
    for (i in todo) {
      row <- cohort_row(files[i], pf, NULL, "", tab$seconds[i], method)
      row$pooled <- TRUE
      row$message <- sprintf(paste0(
        "calibrated with the rest windows of %d recordings of device %s ",
        "(%s), pooled; alone: %s"), length(idx), s,
        paste(basename(files[idx]), collapse = ", "), tab$status[i])
      row$hours <- tab$hours[i]
      row$samples <- tab$samples[i]
      tab[i, ] <- row
      fits[[i]] <- pf
    }
  }
  list(tab = tab, fits = fits)
}

# p-values of the Wald tests of every pair of fits' common coefficients.
pairwise_wald <- function(fits) {
  p <- numeric(0)
  if (length(fits) < 2) return(p)
  for (i in seq_len(length(fits) - 1)) for (j in (i + 1):length(fits)) {
    a <- fits[[i]]
    b <- fits[[j]]
    nm <- intersect(a$model, b$model)
    if (!length(nm) || is.null(a$vcov) || is.null(b$vcov)) next
    d <- stats::coef(a)[nm] - stats::coef(b)[nm]
    V <- a$vcov[nm, nm, drop = FALSE] + b$vcov[nm, nm, drop = FALSE]
    W <- tryCatch(drop(t(d) %*% solve(V, d)), error = function(e) Inf)
    p <- c(p, stats::pchisq(W, df = length(nm), lower.tail = FALSE))
  }
  p
}

# One fit on the rest windows of several recordings of a device.
pooled_fit <- function(files, method, args) {
  if (method == "ggir") {
    ggir_args <- args[intersect(names(args), c("use_temp", "max_iter", "tol"))]
    ws <- lapply(files, function(f) rest_windows(f, method = "ggir"))
    w <- do.call(rbind, ws)
    return(do.call(fit_icp, c(list(w = w[w$rest, , drop = FALSE]), ggir_args)))
  }
  la <- lightweight_args(args)
  rargs <- la$args$rest_windows[intersect(names(la$args$rest_windows),
                                          c("window", "max_range", "axes",
                                            "skip_zero", "reader"))]
  ws <- lapply(files, function(f) do.call(rest_windows, c(list(x = f), rargs)))
  w <- do.call(rbind, ws)
  attr(w, "sf") <- attr(ws[[1]], "sf")
  attr(w, "window") <- attr(ws[[1]], "window")
  attr(w, "samples") <- sum(vapply(ws, function(x) attr(x, "samples"), 0))
  attr(w, "samples_total") <- NA_real_
  inp <- attr(ws[[1]], "input")
  inp$source <- "pooled"
  inp$samples <- attr(w, "samples")
  inp$report <- NULL
  attr(w, "input") <- inp
  # segments and the adaptive budget are for one recording
  la$choice$segments <- NULL
  la$choice$budget <- "all"
  lightweight_from_windows(w, la$args, la$choice, la$max_norm_error,
                           la$range_g, call = NULL, file = NULL)
}
