#' Calibrate many recordings, in parallel, resumably
#'
#' Calibrates every file with [calibrate()], each read block by block, and
#' returns one row per recording. The work is spread over whatever
#' `future::plan()` the session has set (sequential by default;
#' `plan(multisession)` on a laptop, a cluster or `future.batchtools` on
#' SLURM or SGE), when the future.apply package is installed. Progress is
#' reported through progressr (wrap the call in
#' `progressr::with_progress()`, or set `progressr::handlers(global =
#' TRUE)`).
#'
#' A recording that cannot be read or calibrated becomes a row whose
#' `error` says why; the others go on. Each finished recording is saved at
#' once under `outdir/.gravcal/`, so an interrupted run started again with
#' the same `outdir` skips the recordings already done (`resume = TRUE`).
#' Every file is written under a temporary name and then renamed, so a run
#' killed half-way never leaves a half-written file (the temporary files it
#' may leave are removed by the next run). Run one `calibrate_files()` at a
#' time per `outdir`.
#'
#' Written to `outdir`: `calibration.csv` (the table below) and, for
#' `method = "ggir"`, `calibration_ggir_coefs.csv`, the coefficients in
#' GGIR's `backup.cal.coef` format ([write_ggir_coefs()]) for the
#' recordings that could be calibrated.
#'
#' @param files Paths of recordings (formats as [calibrate()] reads), or
#'   one directory, whose recordings are all taken.
#' @param method `"ggir"` (default) or `"lightweight"`; see [calibrate()].
#' @param outdir Directory for the results (created if needed).
#' @param ... Further arguments for [calibrate()] (for example `sf` for
#'   files that do not give it, `ggir_compat`, `minloadcrit`).
#' @param resume Skip recordings already done in `outdir`.
#' @param pattern For a directory: the file names to take (a regular
#'   expression).
#' @return A data frame, one row per recording, in the order of `files`:
#'   `file`, `format`, `hours` (of samples read), `windows`, `rest_windows`,
#'   `status` (see [calibrate()]), `k_xx` ... `o_z` (the model's nine
#'   parameters, as `coef()` of a fit gives them), `t_x`, `t_y`, `t_z`
#'   (temperature terms), `meantemp`, `error_before_mg`, `error_after_mg`
#'   (on the rest points used); what the file's reader did: `reader`
#'   (`"native"` or `"reference"`), `samples` read, `skipped` (units its
#'   decoder could not use: damaged blocks, pages, records or lines),
#'   `gaps` and `gap_seconds` (jumps in time), `truncated` and `read_notes`
#'   (the first problems, where they were); `seconds` (time taken) and
#'   `error` (why a recording failed, else empty). The fits are in
#'   `attr(, "fits")`.
#' @seealso [cli()] for batch scripts.
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
calibrate_files <- function(files, method = c("ggir", "lightweight"), outdir,
                            ..., resume = TRUE,
                            pattern = "\\.(csv|csv\\.gz|rds|gt3x|cwa|bin)$") {
  method <- match_choice(method, "method")
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
  store <- file.path(outdir, ".gravcal")
  dir.create(store, recursive = TRUE, showWarnings = FALSE)
  if (!dir.exists(store)) abort("Could not create `outdir`: \"", outdir, "\".")
  # temporary files of a run that was killed while writing
  unlink(list.files(c(outdir, store), pattern = "\\.tmp$", full.names = TRUE,
                    all.files = TRUE))
  keys <- file.path(store, paste0(file_key(files, method), ".rds"))
  todo <- if (resume) which(!file.exists(keys)) else seq_along(files)

  worker <- function(i, p) {
    res <- calibrate_one(files[i], method, args)
    save_atomic(res, keys[i])
    if (!is.null(p)) p(message = basename(files[i]))
    NULL
  }
  run_cohort(todo, worker)

  done <- lapply(keys, function(k) if (file.exists(k)) readRDS(k))
  missing <- vapply(done, is.null, TRUE)
  if (any(missing)) {
    abort("No result for ", sum(missing), " recording(s) (",
          paste(basename(files[missing]), collapse = ", "), ").")
  }
  tab <- do.call(rbind, lapply(done, `[[`, "row"))
  rownames(tab) <- NULL
  write_csv_atomic(tab, file.path(outdir, "calibration.csv"))
  fits <- stats::setNames(lapply(done, `[[`, "fit"), basename(files))
  if (method == "ggir") {
    ok <- vapply(fits, function(f) !is.null(f) && f$status %in% c("ok", "high_error"), TRUE)
    if (any(ok)) {
      tmp <- tempfile(tmpdir = outdir, fileext = ".csv.tmp")
      write_ggir_coefs(fits[ok], tmp)
      rename_or_abort(tmp, file.path(outdir, "calibration_ggir_coefs.csv"))
    }
  }
  attr(tab, "fits") <- fits
  tab
}

# The recordings: the paths given, or those in one directory.
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
    return(sort(found))
  }
  absent <- !file.exists(files)
  if (any(absent)) {
    abort("`files`: ", sum(absent), " file(s) do not exist: ",
          paste0("\"", utils::head(files[absent], 3), "\"", collapse = ", "),
          if (sum(absent) > 3) ", ...", ".")
  }
  if (anyDuplicated(normalizePath(files))) abort("`files` lists a file twice.")
  files
}

# A key per file and method: the file name and the md5 of its full path.
file_key <- function(files, method) {
  tmp <- tempfile()
  on.exit(unlink(tmp))
  vapply(files, function(f) {
    writeLines(paste(normalizePath(f, mustWork = FALSE), method), tmp)
    paste0(gsub("[^A-Za-z0-9._-]", "_", basename(f)), "-",
           substr(unname(tools::md5sum(tmp)), 1, 12))
  }, "", USE.NAMES = FALSE)
}

# One recording: the fit and its row, or a row saying what went wrong.
calibrate_one <- function(file, method, args) {
  t0 <- proc.time()[["elapsed"]]
  fit <- NULL
  err <- ""
  fit <- tryCatch(
    withCallingHandlers(
      do.call(calibrate, c(list(x = file, method = method), args)),
      warning = function(w) invokeRestart("muffleWarning")),
    error = function(e) {
      err <<- conditionMessage(e)
      NULL
    })
  list(row = cohort_row(file, fit, err, proc.time()[["elapsed"]] - t0),
       fit = fit)
}

cohort_row <- function(file, fit, err, seconds) {
  cf <- if (is.null(fit)) rep(NA_real_, 12) else unname(stats::coef(fit))
  names(cf) <- c(param_names(), "t_x", "t_y", "t_z")
  format <- tryCatch(file_format(file), error = function(e) NA_character_)
  num <- function(v) if (is.null(v)) NA_real_ else as.numeric(v)
  inp <- if (is.null(fit)) NULL else fit$input
  rep <- inp$report
  data.frame(
    file = basename(file), format = format,
    hours = if (is.null(fit)) NA_real_ else fit_hours(fit),
    windows = if (is.null(fit) || is.null(fit$n_windows)) NA_real_ else as.numeric(fit$n_windows),
    rest_windows = if (is.null(fit) || is.null(fit$windows)) NA_real_ else as.numeric(NROW(fit$windows)),
    status = if (is.null(fit)) "failed" else fit$status,
    as.list(cf),
    meantemp = if (is.null(fit)) NA_real_ else as.numeric(fit$meantemp),
    error_before_mg = if (is.null(fit)) NA_real_ else 1000 * fit$error_before,
    error_after_mg = if (is.null(fit)) NA_real_ else 1000 * fit$error_after,
    # what the reader read and skipped (native decoders)
    reader = if (is.null(inp$reader)) NA_character_ else inp$reader,
    samples = num(inp$samples),
    skipped = num(rep$skipped), gaps = num(rep$gaps),
    gap_seconds = num(rep$gap_seconds),
    truncated = if (is.null(rep)) NA else isTRUE(rep$truncated),
    read_notes = if (length(rep$notes)) paste(rep$notes, collapse = "; ") else "",
    seconds = seconds, error = err, stringsAsFactors = FALSE)
}

fit_hours <- function(fit) {
  if (is.null(fit$hours)) NA_real_ else as.numeric(fit$hours)
}

# Run worker(i, progressor) for every i in todo: future.apply when
# installed (on the plan the user set), else a plain loop.
run_cohort <- function(todo, worker) {
  if (!length(todo)) return(invisible())
  has_progressr <- requireNamespace("progressr", quietly = TRUE)
  p <- if (has_progressr) progressr::progressor(steps = length(todo)) else NULL
  if (requireNamespace("future.apply", quietly = TRUE)) {
    future.apply::future_lapply(todo, worker, p = p, future.seed = TRUE,
                                future.packages = "gravcal")
  } else {
    lapply(todo, worker, p = p)
  }
  invisible()
}

save_atomic <- function(object, path) {
  tmp <- tempfile(tmpdir = dirname(path), fileext = ".rds.tmp")
  saveRDS(object, tmp)
  rename_or_abort(tmp, path)
}

write_csv_atomic <- function(df, path) {
  tmp <- tempfile(tmpdir = dirname(path), fileext = ".csv.tmp")
  utils::write.csv(df, tmp, row.names = FALSE)
  rename_or_abort(tmp, path)
}

rename_or_abort <- function(from, to) {
  if (!file.rename(from, to)) {
    unlink(from)
    abort("Could not write \"", to, "\".")
  }
}

#' Command-line entry for batch scripts
#'
#' Runs [calibrate_files()] from the command line, for HPC batch jobs:
#'
#' `Rscript -e 'gravcal::cli()' -- --method ggir --out results/ data/*.cwa`
#'
#' Options: `--method ggir|lightweight` (default ggir), `--out DIR`
#' (required), `--workers N` (parallel R sessions through
#' `future::plan(multisession)`; default: the plan already set, else one),
#' `--sf HZ` (for files that do not give their sampling rate),
#' `--no-resume` (redo recordings already done), `--help`. The other
#' arguments are the recordings (or one directory).
#'
#' @param args The command-line arguments (by default those after `--`).
#' @return The table of [calibrate_files()], invisibly; `NULL` after
#'   `--help`.
#' @export
#' @examples
#' cli("--help")
cli <- function(args = commandArgs(trailingOnly = TRUE)) {
  args <- as.character(args)
  args <- args[args != "--"]
  help <- c(
    "Usage: Rscript -e 'gravcal::cli()' -- [options] FILE... | DIR",
    "Calibrate accelerometer recordings against gravity (gravcal).",
    "",
    "  --method M     ggir (default) or lightweight",
    "  --out DIR      directory for calibration.csv and the per-recording results",
    "  --workers N    parallel R sessions (future's multisession plan)",
    "  --sf HZ        sampling rate, for files that do not give it",
    "  --no-resume    redo recordings already done in DIR",
    "  --help         this text")
  if (!length(args) || "--help" %in% args || "-h" %in% args) {
    writeLines(help)
    return(invisible(NULL))
  }
  opt <- list(method = "ggir", out = NULL, workers = NULL, sf = NULL, resume = TRUE)
  files <- character(0)
  i <- 1
  value <- function(name) {
    if (i >= length(args)) abort("cli(): `", name, "` needs a value.")
    args[i + 1]
  }
  while (i <= length(args)) {
    a <- args[i]
    if (a %in% c("--method", "--out", "--workers", "--sf")) {
      opt[[sub("^--", "", a)]] <- value(a)
      i <- i + 2
    } else if (a == "--no-resume") {
      opt$resume <- FALSE
      i <- i + 1
    } else if (startsWith(a, "--")) {
      abort("cli(): unknown option `", a, "`; see --help.")
    } else {
      files <- c(files, a)
      i <- i + 1
    }
  }
  if (is.null(opt$out)) abort("cli(): `--out DIR` is required; see --help.")
  if (!length(files)) abort("cli(): no recordings given; see --help.")
  if (!opt$method %in% c("ggir", "lightweight")) {
    abort("cli(): `--method` must be ggir or lightweight, not \"", opt$method, "\".")
  }
  extra <- list()
  if (!is.null(opt$sf)) {
    sf <- suppressWarnings(as.numeric(opt$sf))
    check_sf(sf)
    extra$sf <- sf
  }
  if (!is.null(opt$workers)) {
    w <- suppressWarnings(as.integer(opt$workers))
    if (is.na(w) || w < 1) abort("cli(): `--workers` must be a positive whole number.")
    if (!requireNamespace("future", quietly = TRUE)) {
      abort("cli(): `--workers` needs the future package: install.packages(\"future\").")
    }
    old <- future::plan(future::multisession, workers = w)
    on.exit(future::plan(old), add = TRUE)
  }
  tab <- do.call(calibrate_files, c(list(files = files, method = opt$method,
                                         outdir = opt$out, resume = opt$resume),
                                    extra))
  failed <- sum(tab$status == "failed")
  message(sprintf("gravcal: %d recording(s): %d calibrated, %d not calibrated, %d failed; results in %s",
                  nrow(tab), sum(tab$status %in% c("ok", "high_error")),
                  sum(!tab$status %in% c("ok", "high_error", "failed")), failed,
                  file.path(opt$out, "calibration.csv")))
  invisible(tab)
}
