# GGIR's own unit tests, run with gravcal's drop-ins in GGIR's place.
#
# GGIR's test files that reach part 1 (g.part1(), or GGIR() with mode 1)
# are run twice, each file in a fresh R process and an empty folder of its
# own: once as they are (GGIR's part 1), once with g.part1(), g.calibrate()
# and g.getmeta() in GGIR's namespace replaced by gravcal's (so that GGIR()
# and every GGIR function that calls them reaches gravcal's, and the test
# file's own calls too). Each replacement counts its calls, so a test that
# passes without reaching gravcal is seen. The two runs' results are put
# side by side, test by test: a test that passes with GGIR's part 1 and not
# with gravcal's is a difference to mend or to explain.
#
# GGIR's tests are not shipped with the installed package and are GGIR's
# text (not copied into gravcal): they are read from a GGIR source tree,
# a git directory (its HEAD's tests/testthat) or a checkout, given as
# GGIR_SOURCE (default: the mirror fetch gives, /work/.mirror/wadpac+GGIR/repo).
#
#   Rscript tools/ggir-own-tests.R [out.md]
# (make test-ggir-own; not part of make test: it needs GGIR's source tree,
# and GGIR's parts 1 to 5 run twice per file.) Exits with status 1 when a
# test passes with GGIR's part 1 and fails with gravcal's, or a file that
# calls part 1 did not reach gravcal's.

args <- commandArgs(trailingOnly = TRUE)
out_md <- if (length(args) >= 1) args[[1]] else "bench/results/ggir-own-tests.md"
src <- Sys.getenv("GGIR_SOURCE", "/work/.mirror/wadpac+GGIR/repo")

# the test files that reach part 1
files <- c("test_part1_with_allmetrics.R", "test_integration.R", "test_StudyDatesFile.R",
           "test_detect_nonwear.R", "test_lightPart5.R", "test_part2_short_recordings.R",
           "test_part3_1_night.R", "test_part3_no4am.R", "test_qwindowPart2.R",
           "test_recording.starts.at.midnight.R", "test_recordingEndSleepHour.R",
           "test_sibSadeh_sptHorAngle.R", "test_skipAndLogFileErrors.R", "test_splitRecords.R")

# GGIR_OWN_FILES="test_a.R test_b.R": only those
only <- strsplit(Sys.getenv("GGIR_OWN_FILES"), "[ ,]+")[[1]]
if (length(only)) files <- intersect(files, only)
tests_dir <- tempfile("ggir-tests-")
dir.create(tests_dir)
on.exit(unlink(tests_dir, recursive = TRUE), add = TRUE)
if (dir.exists(file.path(src, "tests", "testthat"))) {
  file.copy(file.path(src, "tests", "testthat", files), tests_dir)
  version <- read.dcf(file.path(src, "DESCRIPTION"), "Version")[1, 1]
} else if (dir.exists(file.path(src, "objects"))) {
  # a bare git directory: its HEAD's files
  for (f in files) {
    txt <- system2("git", c(paste0("--git-dir=", src), "show", paste0("HEAD:tests/testthat/", f)),
                   stdout = TRUE)
    writeLines(txt, file.path(tests_dir, f))
  }
  desc <- system2("git", c(paste0("--git-dir=", src), "show", "HEAD:DESCRIPTION"), stdout = TRUE)
  version <- sub("^Version: *", "", grep("^Version:", desc, value = TRUE))
} else {
  stop("GGIR_SOURCE (", src, ") holds neither tests/testthat nor a git directory.", call. = FALSE)
}
missing <- files[!file.exists(file.path(tests_dir, files))]
if (length(missing)) stop("not in GGIR's tests: ", paste(missing, collapse = ", "), call. = FALSE)

# One file in a fresh process: its results (testthat's, one row a test) and
# the calls gravcal's drop-ins had, as an rds.
runner <- file.path(tests_dir, "run-one.R")
writeLines(c(
  "a <- commandArgs(TRUE); file <- a[1]; side <- a[2]; out <- a[3]",
  "setwd(dirname(out)); Sys.setenv(NOT_CRAN = 'true')",
  "suppressPackageStartupMessages({library(testthat); library(GGIR)})",
  "calls <- c(g.part1 = 0, g.calibrate = 0, g.getmeta = 0)",
  "if (side == 'gravcal') {",
  "  for (nm in names(calls)) local({",
  "    f <- getExportedValue('gravcal', nm)",
  "    fa <- lapply(names(formals(f)), function(k) if (k == '...') quote(...) else as.name(k))",
  "    names(fa) <- ifelse(names(formals(f)) == '...', '', names(formals(f)))",
  "    w <- function() NULL",
  "    formals(w) <- formals(f)",
  "    body(w) <- bquote({",
  "      calls[[.(nm)]] <<- calls[[.(nm)]] + 1",
  "      .(as.call(c(quote(f), fa)))",
  "    })",
  "    utils::assignInNamespace(nm, w, 'GGIR')",
  "    assign(nm, w, envir = globalenv())",
  "  })",
  "}",
  "raw <- tryCatch(testthat::test_file(file, reporter = 'silent', package = 'GGIR',",
  "                                    stop_on_failure = FALSE),",
  "                error = function(e) e)",
  "if (inherits(raw, 'error')) {",
  "  res <- data.frame(test = '(the file)', failed = 1L, error = TRUE, skipped = FALSE,",
  "                    message = conditionMessage(raw))",
  "} else {",
  "  res <- as.data.frame(raw)[, c('test', 'failed', 'error', 'skipped')]",
  "  res$message <- vapply(raw, function(t) {",
  "    bad <- Filter(function(x) inherits(x, c('expectation_failure', 'expectation_error')),",
  "                  t$results)",
  "    paste(vapply(bad, function(x) substr(conditionMessage(x), 1, 300), ''), collapse = ' / ')",
  "  }, '')",
  "}",
  "saveRDS(list(res = res, calls = calls), out)"
), runner)

run_file <- function(f, side) {
  wd <- tempfile(paste0(side, "-"))
  dir.create(wd)
  on.exit(unlink(wd, recursive = TRUE), add = TRUE)
  file.copy(file.path(tests_dir, f), wd)
  out <- file.path(normalizePath(wd), "result.rds")
  t0 <- Sys.time()
  log <- suppressWarnings(system2(file.path(R.home("bin"), "Rscript"),
                                  c(shQuote(runner), shQuote(f), side, shQuote(out)),
                                  stdout = TRUE, stderr = TRUE, env = character()))
  secs <- as.numeric(difftime(Sys.time(), t0, units = "secs"))
  r <- if (file.exists(out)) readRDS(out) else NULL
  if (is.null(r)) {
    r <- list(res = data.frame(test = "(the file)", failed = 1L, error = TRUE, skipped = FALSE,
                               message = paste(tail(log, 5), collapse = " / ")),
              calls = c(g.part1 = NA, g.calibrate = NA, g.getmeta = NA),
              log = tail(log, 20))
  }
  r$secs <- secs
  r
}

`%||%` <- function(a, b) if (is.null(a)) b else a
rows <- list()
bad <- character(0)
for (f in files) {
  cat(f, "...\n")
  g <- run_file(f, "ggir")
  v <- run_file(f, "gravcal")
  status <- function(r) {
    d <- r$res
    ifelse(d$skipped, "skipped", ifelse(d$error | d$failed > 0, "fails", "passes"))
  }
  tests <- union(g$res$test, v$res$test)
  sg <- stats::setNames(status(g), g$res$test)[tests]
  sv <- stats::setNames(status(v), v$res$test)[tests]
  reached <- sum(v$calls, na.rm = TRUE)
  for (k in seq_along(tests)) {
    why <- function(r) {
      m <- r$res$message[match(tests[k], r$res$test)]
      if (is.na(m)) "" else gsub("[\r\n|]+", " ", substr(m, 1, 160))
    }
    rows[[length(rows) + 1]] <- data.frame(
      file = f, test = tests[k], ggir = sg[[k]] %||% NA, gravcal = sv[[k]] %||% NA,
      part1_calls = paste(v$calls, collapse = "/"), ggir_s = round(g$secs),
      gravcal_s = round(v$secs),
      why_ggir = why(g), why_gravcal = why(v))
    if (identical(unname(sg[[k]]), "passes") && !identical(unname(sv[[k]]), "passes")) {
      m <- v$res$message[match(tests[k], v$res$test)]
      bad <- c(bad, paste0(f, ": ", tests[k], if (!is.na(m) && nzchar(m)) paste0(": ", m)))
    }
  }
  # (a file that fails with GGIR's part 1 too may stop before part 1)
  if (!isTRUE(reached > 0) && any(status(g) == "passes")) {
    bad <- c(bad, paste0(f, ": gravcal's drop-ins not reached"))
  }
  if (!is.null(v$log)) cat(v$log, sep = "\n")
}
tab <- do.call(rbind, rows)
print(tab[, 1:7], row.names = FALSE)

md <- c(
  "# GGIR's own tests with gravcal's part 1 (tools/ggir-own-tests.R)",
  "",
  paste0("GGIR's test files that reach part 1, from GGIR ", version, "'s source, run with ",
         "GGIR ", as.character(utils::packageVersion("GGIR")), " installed, each file in a ",
         "fresh R process: as they are (`ggir`), and with `g.part1()`, `g.calibrate()` and ",
         "`g.getmeta()` in GGIR's namespace replaced by gravcal's (`gravcal`). `part1_calls`: ",
         "the calls gravcal's g.part1 / g.calibrate / g.getmeta had in that run. ",
         R.version.string, ", ", format(Sys.Date()), "."),
  "",
  "`Rscript tools/ggir-own-tests.R` (`make test-ggir-own`).",
  "",
  "| file | test | GGIR's part 1 | gravcal's part 1 | part1_calls | GGIR (s) | gravcal (s) |",
  "|---|---|---|---|---|---:|---:|",
  sprintf("| %s | %s | %s | %s | %s | %s | %s |", tab$file,
          gsub("|", "\\|", tab$test, fixed = TRUE), tab$ggir, tab$gravcal, tab$part1_calls,
          tab$ggir_s, tab$gravcal_s),
  "",
  "Why the tests that fail fail (the first failure's message, cut):",
  "",
  unlist(lapply(which(tab$ggir == "fails" | tab$gravcal == "fails"), function(i) {
    c(paste0("- ", tab$file[i], ", \"", tab$test[i], "\":"),
      if (nzchar(tab$why_ggir[i])) paste0("  GGIR's part 1: ", tab$why_ggir[i]),
      if (nzchar(tab$why_gravcal[i])) paste0("  gravcal's part 1: ", tab$why_gravcal[i]))
  })),
  "",
  if (length(bad)) c("Differences:", "", paste0("- ", bad)) else
    paste0("Every test that passes with GGIR's part 1 passes with gravcal's, and every file ",
           "with a test that passes reached gravcal's drop-ins.")
)
dir.create(dirname(out_md), showWarnings = FALSE, recursive = TRUE)
writeLines(md, out_md)
cat("written:", out_md, "\n")
if (length(bad)) {
  cat("differences:\n", paste0("  ", bad, "\n"), sep = "")
  quit(status = 1)
}
