# The command line: calibrate_cli().

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
#' REGEX` (the recordings taken from a directory), `--recursive` (a
#' directory's subfolders too; recordings are then named by their path
#' relative to it), `--rmc LIST` (ad hoc
#' csv files: GGIR's `rmc.*` parameters as R arguments, `'rmc.firstrow.acc
#' = 2, rmc.sf = 50'`, or an `.rds` file of their list; see
#' [rest_windows()]), `--coefs FILE[,FILE...]` (apply the coefficients in
#' these files, another tool's or an earlier run's, instead of fitting each
#' recording's own; read by [read_coefs()], whose format is recognised; see
#' `coefs` in [calibrate_files()]), `--no-resume` (redo
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
#' @section The part1 verb:
#' `Rscript -e 'gravcal::calibrate_cli()' -- part1 --out results/ data/`
#' runs [g.part1()] (GGIR part 1 on gravcal) on one folder or on
#' recordings: it writes the meta files GGIR's parts 2-5 read in
#' `<out>/output_<folder name>/meta/basic` (for recordings, with
#' `--studyname NAME`: `output_NAME`), as `GGIR::GGIR(outputdir = <out>)`
#' names the folder, so that `GGIR::GGIR(mode = 2:5, datadir = , outputdir
#' = <out>)` goes on from them. Options: `--out DIR` (GGIR's outputdir,
#' required), `--studyname NAME`, `--overwrite` (redo recordings whose meta
#' file exists; by default they are skipped), `--no-cal` (GGIR's `do.cal =
#' FALSE`), `--coefs FILE` (coefficients instead of calibrating: GGIR's
#' `backup.cal.coef`; another format [read_coefs()] reads is converted to
#' GGIR's), `--params LIST` (GGIR's parameters as R arguments,
#' `'desiredtz = "Europe/London", chunksize = 0.5'`, or an `.rds` file of
#' their list), `--f0 N`, `--f1 N`, `--verbose` (GGIR's progress messages),
#' `--help`. A recording's error does not stop the others (GGIR's
#' `use_trycatch_serial = TRUE`). It prints `gravcal part1: N
#' recording(s): a written, b already there, c not read (...), d failed;
#' meta files in DIR`; the exit status is 0 when no recording failed, 1
#' when any did, 2 when the run could not start.
#'
#' @param args The command-line arguments (by default those after `--`).
#' @param quit End the R process with the exit status above (`TRUE`), or
#'   return (`FALSE`, for use from R). `--help` always returns.
#' @return The table of [calibrate_files()] (for `part1`, of [g.part1()]),
#'   invisibly (when `quit = FALSE`); `NULL` after `--help`.
#' @export
#' @examples
#' calibrate_cli("--help")
calibrate_cli <- function(args = commandArgs(trailingOnly = TRUE),
                          quit = !interactive()) {
  check_flag(quit, "quit")
  args <- as.character(args)
  if (anyNA(args)) {
    abort("`args` must be character strings without NA; element ",
          which(is.na(args))[1], " is NA.")
  }
  if (length(args) && args[1] == "--") args <- args[-1]
  part1 <- length(args) && args[1] == "part1"
  if (part1) args <- args[-1]
  if (!length(args) || any(args %in% c("--help", "-h"))) {
    writeLines(if (part1) cli_part1_help() else cli_help())
    return(invisible(NULL))
  }
  run <- if (part1) cli_part1 else cli_run
  if (!quit) return(invisible(run(args)))
  tab <- tryCatch(run(args), error = function(e) {
    message("gravcal: error: ", conditionMessage(e))
    base::quit(save = "no", status = 2)
  })
  base::quit(save = "no", status = if (any(tab$status == "failed")) 1 else 0)
}

cli_help <- function() {
  c(
    "Usage: Rscript -e 'gravcal::calibrate_cli()' -- [options] FILE... | DIR",
    "       Rscript -e 'gravcal::calibrate_cli()' -- part1 [options] FILE... | DIR",
    "Calibrate accelerometer recordings against gravity (gravcal); with part1,",
    "write GGIR part 1's meta files (g.part1(); see part1 --help).",
    "",
    "  --method M       ggir (default) or lightweight",
    "  --out DIR        directory for calibration.csv and the per-recording results",
    "  --workers N      parallel R sessions (future's multisession plan)",
    "  --sf HZ          sampling rate, for files that do not give it",
    "  --pattern REGEX  for a directory: the file names to take",
    "  --recursive      for a directory: its subfolders too",
    "  --rmc LIST       ad hoc csv files: GGIR's rmc.* parameters, as R arguments",
    "                   ('rmc.firstrow.acc = 2, rmc.unit.acc = \"mg\", rmc.sf = 50')",
    "                   or an .rds file holding their list",
    "  --coefs FILES    apply the coefficients in these files (comma-separated;",
    "                   GGIR, actipy, UK Biobank, omconvert or skdh: see read_coefs())",
    "                   instead of fitting each recording's own",
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
  if (!is.null(opt$rmc)) extra$rmc <- cli_rmc(opt$rmc)
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
  if (opt$recursive) extra$recursive <- TRUE
  if (!is.null(opt$coefs)) {
    paths <- trimws(strsplit(opt$coefs, ",", fixed = TRUE)[[1]])
    extra$coefs <- tryCatch(read_coefs(paths[nzchar(paths)]), error = function(e) {
      abort("`--coefs`: ", conditionMessage(e))
    })
  }
  tab <- do.call(calibrate_files, c(list(files = opt$files, method = opt$method,
                                         outdir = opt$out, resume = opt$resume),
                                    extra))
  done <- tab$status %in% c("ok", "high_error", "given")
  failed <- tab$status == "failed"
  message(sprintf(paste0("gravcal: %d recording(s): %d calibrated, %d not ",
                         "calibrated, %d failed; results in %s"),
                  nrow(tab), sum(done), sum(!done & !failed), sum(failed),
                  file.path(normalizePath(opt$out), "calibration.csv")))
  tab
}

# --rmc: an .rds file of the list, or its entries as R arguments; checked
# as calibrate()'s `rmc`.
cli_rmc <- function(value) {
  rmc <- if (grepl("\\.rds$", value, ignore.case = TRUE) && file.exists(value)) {
    readRDS(value)
  } else {
    tryCatch(eval(parse(text = paste0("list(", value, ")")), envir = new.env(parent = baseenv())),
             error = function(e) {
               abort("`--rmc` must be rmc.* arguments (\"rmc.firstrow.acc = 2, rmc.sf = 50\") ",
                     "or an .rds file of their list, not \"", value, "\": ", conditionMessage(e))
             })
  }
  rmc_values(rmc, "--rmc")
  rmc
}

cli_parse <- function(args) {
  opt <- list(method = "ggir", resume = TRUE, recursive = FALSE)
  files <- character(0)
  given <- character(0)
  takes <- c("--method", "--out", "--workers", "--sf", "--pattern", "--rmc",
             "--coefs")
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
    } else if (a == "--recursive") {
      opt$recursive <- TRUE
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

# The part1 verb: g.part1() on files or a folder.
cli_part1_help <- function() {
  c(
    "Usage: Rscript -e 'gravcal::calibrate_cli()' -- part1 [options] FILE... | DIR",
    "GGIR part 1 on gravcal (g.part1()): for each recording, the meta file",
    "<out>/output_<DIR's name or --studyname>/meta/basic/meta_<file>.RData that",
    "GGIR's parts 2-5 read (GGIR::GGIR(mode = 2:5, datadir = , outputdir = <out>)).",
    "",
    "  --out DIR        GGIR's outputdir (required)",
    "  --studyname NAME the output folder's name for a list of files (output_NAME)",
    "  --overwrite      redo recordings whose meta file exists (default: skip them)",
    "  --no-cal         no calibration (GGIR's do.cal = FALSE)",
    "  --coefs FILE     coefficients to use instead of calibrating (GGIR's",
    "                   backup.cal.coef; any format read_coefs() reads)",
    "  --params LIST    GGIR's parameters, as R arguments",
    "                   ('desiredtz = \"Europe/London\", do.mad = TRUE, chunksize = 0.5')",
    "                   or an .rds file holding their list",
    "  --f0 N, --f1 N   the first and last file to do (by their place in the list)",
    "  --verbose        GGIR's progress messages",
    "  --help           this text",
    "",
    "Exit status: 0 no recording failed, 1 some recording failed (the others",
    "are written), 2 the run could not start (bad arguments).")
}

cli_part1 <- function(args) {
  takes <- c("--out", "--studyname", "--coefs", "--params", "--f0", "--f1")
  flags <- c("--overwrite", "--no-cal", "--verbose")
  opt <- list()
  files <- character(0)
  i <- 1
  while (i <= length(args)) {
    a <- args[i]
    if (a %in% takes) {
      if (i == length(args) || startsWith(args[i + 1], "--")) {
        abort("`", a, "` needs a value; see part1 --help.")
      }
      name <- sub("^--", "", a)
      if (!is.null(opt[[name]])) abort("`", a, "` is given twice.")
      opt[[name]] <- args[i + 1]
      i <- i + 2
    } else if (a %in% flags) {
      opt[[sub("^--", "", a)]] <- TRUE
      i <- i + 1
    } else if (startsWith(a, "-") && a != "-") {
      abort("Unknown option `", a, "` for part1; see part1 --help.")
    } else {
      files <- c(files, a)
      i <- i + 1
    }
  }
  if (is.null(opt$out)) abort("`--out DIR` is required; see part1 --help.")
  if (!length(files)) abort("No recordings given; see part1 --help.")
  if (!dir.exists(opt$out)) abort("`--out`: the folder \"", opt$out, "\" does not exist.")
  missing <- files[!file.exists(files)]
  if (length(missing)) abort("No such file or folder: ", paste0("\"", missing, "\"", collapse = ", "), ".")
  one_dir <- length(files) == 1 && dir.exists(files)
  if (!one_dir && any(dir.exists(files))) {
    abort("Give one folder, or recordings (files): not both, nor several folders.")
  }
  if (!one_dir && is.null(opt$studyname)) {
    abort("`--studyname NAME` is required for a list of files (the output folder is ",
          "output_NAME, as GGIR names it); see part1 --help.")
  }
  params <- if (!is.null(opt$params)) cli_params(opt$params) else list()
  num <- function(v, arg) {
    n <- suppressWarnings(as.numeric(v))
    if (!isTRUE(is.finite(n) && n >= 1 && n == round(n))) {
      abort("`", arg, "` must be a positive whole number, not \"", v, "\".")
    }
    n
  }
  f0 <- if (!is.null(opt$f0)) num(opt$f0, "--f0") else 1
  f1 <- if (!is.null(opt$f1)) num(opt$f1, "--f1") else c()
  if (isTRUE(opt$overwrite)) params$overwrite <- TRUE
  if (isTRUE(opt$`no-cal`)) params$do.cal <- FALSE
  if (!is.null(opt$coefs)) {
    params$backup.cal.coef <- cli_ggir_coefs(opt$coefs)
  }
  # one file's error is reported in the table, the others still done
  params$use_trycatch_serial <- TRUE
  datadir <- if (one_dir) sub("/+$", "", files) else files
  metadatadir <- file.path(opt$out, paste0("output_", if (one_dir) basename(datadir) else opt$studyname))
  verbose <- isTRUE(opt$verbose)
  tab <- do.call(g.part1, c(list(datadir = datadir, metadatadir = metadatadir, f0 = f0,
                                 f1 = f1, verbose = verbose), params))
  n <- function(s) sum(tab$status == s)
  message(sprintf(paste0("gravcal part1: %d recording(s): %d written, %d already there, ",
                         "%d not read (formats gravcal's g.part1() does not read), ",
                         "%d failed; meta files in %s"),
                  nrow(tab), n("written"), n("exists"), n("not read"), n("failed"),
                  file.path(normalizePath(metadatadir), "meta", "basic")))
  if (n("failed")) {
    message(paste0("  ", tab$file[tab$status == "failed"], ": ",
                   tab$message[tab$status == "failed"], collapse = "\n"))
  }
  tab
}

# --params: an .rds file of the list, or GGIR's parameters as R arguments.
cli_params <- function(value) {
  p <- if (grepl("\\.rds$", value, ignore.case = TRUE) && file.exists(value)) {
    readRDS(value)
  } else {
    tryCatch(eval(parse(text = paste0("list(", value, ")")), envir = new.env(parent = baseenv())),
             error = function(e) {
               abort("`--params` must be GGIR's parameters as R arguments (\"desiredtz = ",
                     "'Europe/London', chunksize = 0.5\") or an .rds file of their list, not \"",
                     value, "\": ", conditionMessage(e))
             })
  }
  if (!is.list(p) || (length(p) && (is.null(names(p)) || any(names(p) == "")))) {
    abort("`--params` must give named parameters, not ", describe(p), ".")
  }
  p
}

# --coefs for part1: GGIR's coefficient file as it is, any other format
# read_coefs() reads converted to one (a temporary file).
cli_ggir_coefs <- function(path) {
  if (!file.exists(path)) abort("`--coefs`: no such file \"", path, "\".")
  fmt <- tryCatch(detect_coef_format(read_text(path), path),
                  error = function(e) abort("`--coefs`: ", conditionMessage(e)))
  if (identical(fmt, "ggir")) return(path)
  cf <- tryCatch(read_coefs(path), error = function(e) abort("`--coefs`: ", conditionMessage(e)))
  out <- tempfile(fileext = ".csv")
  tryCatch(write_coefs(cf, out, format = "ggir"),
           error = function(e) abort("`--coefs`: ", conditionMessage(e)))
  out
}
