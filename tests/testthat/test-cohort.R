# calibrate_files(): a folder of recordings in two formats, sequential and in
# parallel, a corrupt file, resumption after a killed run; calibrate_cli().
# The faults a cohort run must survive are in test-cohort-faults.R.

# A folder of the five recordings, each call a fresh copy (the tests change
# and add files in it) of one made once per run of this file: writing the
# csv files is most of a cohort test's time.
cohort_dir <- function() {
  template <- file.path(tempdir(), "gravcal-cohort-template")
  if (!file.exists(file.path(template, "p05_corrupt.csv"))) {
    unlink(template, recursive = TRUE)
    make_cohort_dir(template)
  }
  dir <- tempfile("cohort")
  dir.create(dir)
  ok <- file.copy(list.files(template, full.names = TRUE), dir)
  stopifnot(all(ok))
  dir
}

make_cohort_dir <- function(dir) {
  dir.create(dir)
  p <- c(k_xx = 1.02, k_yy = 0.98, k_zz = 1.01, k_xy = 0, k_xz = 0, k_yz = 0,
         o_x = 0.03, o_y = -0.02, o_z = 0.015)
  for (i in 1:2) {
    rec <- simulate_recording(hours = 26, sf = 10, seed = 100 + i, params = p)
    utils::write.csv(rec, file.path(dir, sprintf("p%02d.csv", i)), row.names = FALSE)
  }
  rec <- simulate_recording(hours = 26, sf = 10, seed = 103, params = p,
                            temperature = FALSE)
  gravcal:::write_actigraph_csv(rec, file.path(dir, "p03_actigraph.csv"), sf = 10)
  saveRDS(simulate_recording(hours = 26, sf = 10, seed = 104, params = p),
          file.path(dir, "p04.rds"))
  # (written last: its presence says the folder is whole)
  writeLines(c("x,y,z", "a,b,c", "1,2"), file.path(dir, "p05_corrupt.csv"))
  dir
}

# Kill a forked calibrate_files() run and wait until its process is gone
# or a zombie, as lock_stale() reads it (60 s at most): on a loaded machine
# the killed process can outlive the collection (a CI rehearsal saw its lock
# still held). TRUE when it is gone.
kill_run <- function(job) {
  tools::pskill(job$pid, tools::SIGKILL)
  suppressWarnings(parallel::mccollect(job, wait = TRUE, timeout = 5))
  gone <- function() {
    st <- file.path("/proc", job$pid, "stat")
    if (!dir.exists("/proc/self") || !file.exists(st)) return(TRUE)
    # (reaped between the two looks: file() warns, then errs)
    line <- tryCatch(readLines(st, n = 1L, warn = FALSE), error = function(e) NULL,
                     warning = function(w) NULL)
    is.null(line) || grepl("\\) [ZX]", paste(line, collapse = ""))
  }
  t0 <- Sys.time()
  while (!gone() && difftime(Sys.time(), t0, units = "secs") < 60) Sys.sleep(0.05)
  gone()
}

test_that("calibrate_files() calibrates a folder, one row per recording", {
  skip_if_quick()
  dir <- cohort_dir()
  on.exit(unlink(dir, recursive = TRUE))
  out <- file.path(dir, "out")
  tab <- calibrate_files(dir, outdir = out, sf = 10)
  ggir_names <- c("scale.x", "scale.y", "scale.z", "offset.x", "offset.y",
                  "offset.z", "temperature.offset.x", "temperature.offset.y",
                  "temperature.offset.z")
  expect_identical(names(tab)[1:12], c("file", "status", "message", ggir_names))
  expect_identical(tab$file, c("p01.csv", "p02.csv", "p03_actigraph.csv",
                               "p04.rds", "p05_corrupt.csv"))
  # each row is calibrate() on that file
  for (i in 1:4) {
    f <- calibrate(file.path(dir, tab$file[i]), sf = 10, method = "ggir")
    expect_equal(unname(unlist(tab[i, ggir_names])),
                 unname(coef(f)[c(1:3, 7:12)]), tolerance = 0, label = tab$file[i])
    expect_identical(tab$status[i], f$status)
  }
  # their standard errors, named with a .se suffix, are the fits'
  se_names <- paste0(ggir_names, ".se")
  expect_identical(names(tab)[13:21], se_names)
  fits <- attr(tab, "fits")
  for (i in which(tab$status %in% c("ok", "high_error"))) {
    expect_equal(unname(unlist(tab[i, se_names])),
                 unname(fits[[i]]$se[c(1:3, 7:12)]), label = tab$file[i])
    expect_true(all(is.finite(unlist(tab[i, se_names[1:6]]))))
  }
  expect_true(all(is.na(unlist(tab[5, se_names]))))
  expect_identical(tab$status[5], "failed")
  expect_match(tab$message[5], "p05_corrupt.csv.*no lines of it hold samples")
  expect_identical(tab$message[1:4], vapply(1:4, function(i) {
    calibrate(file.path(dir, tab$file[i]), sf = 10, method = "ggir")$message
  }, ""))
  expect_true(all(tab$error_after_mg[1:4] < tab$error_before_mg[1:4]))
  expect_equal(tab$hours[1], 26, tolerance = 0.01)
  # files written: the table and GGIR's coefficient file, nothing half-done
  written <- utils::read.csv(file.path(out, "calibration.csv"), stringsAsFactors = FALSE)
  expect_identical(written$file, tab$file)
  expect_equal(written$offset.x, tab$offset.x)
  coefs <- utils::read.csv(file.path(out, "calibration_ggir_coefs.csv"))
  expect_identical(sort(coefs$filename), sort(tab$file[tab$status %in% c("ok", "high_error")]))
  expect_length(list.files(out, pattern = "tmp$|part$", recursive = TRUE, all.files = TRUE), 0)
  # the lightweight method too
  tl <- calibrate_files(file.path(dir, c("p01.csv", "p04.rds")),
                        method = "lightweight", outdir = out, sf = 10)
  expect_identical(unname(unlist(tl[1, c(ggir_names[1:6], "cross.xy", "cross.xz",
                                         "cross.yz")])),
                   unname(coef(calibrate(file.path(dir, "p01.csv"), sf = 10))[c(1:3, 7:9, 4:6)]))
  expect_identical(unname(unlist(tl[1, c("cross.xy.se", "cross.xz.se",
                                         "cross.yz.se", "scale.x.se")])),
                   unname(attr(tl, "fits")[[1]]$se[c(4:6, 1)]))
  # the model fitted: standard errors for its coefficients, NA for the
  # others (the simulated device has no cross-axis error: 6 parameters)
  f1 <- attr(tl, "fits")[[1]]
  expect_identical(tl$parameters[1], length(f1$model))
  expect_identical(tl$points[1], nrow(f1$points))
  expect_true(all(is.finite(unlist(tl[1, c("scale.x.se", "offset.z.se")]))))
  expect_identical(is.finite(unlist(tl[1, c("cross.xy.se", "cross.xz.se", "cross.yz.se")])),
                   stats::setNames(c("k_xy", "k_xz", "k_yz") %in% f1$model,
                                   c("cross.xy.se", "cross.xz.se", "cross.yz.se")))
  expect_false(file.exists(file.path(out, "calibration_lightweight.csv")))
  # the GGIR coefficients of the earlier run no longer match the table
  expect_false(file.exists(file.path(out, "calibration_ggir_coefs.csv")))
})

test_that("in parallel (multisession, 2 workers) the table is the same", {
  skip_if_quick()
  skip_if_not_installed("future")
  skip_if_not_installed("future.apply")
  skip_on_os("windows")
  dir <- cohort_dir()
  on.exit(unlink(dir, recursive = TRUE))
  seq_tab <- calibrate_files(dir, outdir = file.path(dir, "seq"), sf = 10)
  old <- future::plan(future::multisession, workers = 2)
  on.exit(future::plan(old), add = TRUE)
  par_tab <- calibrate_files(dir, outdir = file.path(dir, "par"), sf = 10)
  drop <- c("seconds")
  expect_identical(par_tab[setdiff(names(par_tab), drop)],
                   seq_tab[setdiff(names(seq_tab), drop)])
})

test_that("without a plan of the user's the recordings run in this process, without futures", {
  # a fresh process: the future package not loaded, no plan in the options
  # or the environment; a worker's error is that recording's failure
  skip_if_not_installed("future")
  code <- paste(
    "w <- function(i, p) if (i == 2) stop('bad file ', i) else invisible(NULL)",
    "f <- gravcal:::run_cohort(1:3, w, c('a', 'b', 'c'))",
    "cat(isNamespaceLoaded('future'), names(f), f[[1]], sep = '|')",
    "options(future.plan = 'sequential')",
    "f <- gravcal:::run_cohort(1:3, w, c('a', 'b', 'c'))",
    "cat('|', isNamespaceLoaded('future'), names(f), f[[1]], sep = '|')", sep = "; ")
  out <- system2(file.path(R.home("bin"), "Rscript"), c("-e", shQuote(code)), stdout = TRUE,
                 stderr = FALSE, env = "R_FUTURE_PLAN=")
  expect_identical(out, "FALSE|2|bad file 2||TRUE|2|bad file 2")
})

test_that("an interrupted run resumes without redoing finished recordings", {
  skip_if_quick()
  skip_on_os("windows")  # fork
  dir <- cohort_dir()
  on.exit(unlink(dir, recursive = TRUE))
  out <- file.path(dir, "out")
  full <- calibrate_files(dir, outdir = file.path(dir, "full"), sf = 10)
  # a run killed after its first recordings: a forked R process, killed
  # as soon as two results are saved
  job <- parallel::mcparallel(calibrate_files(dir, outdir = out, sf = 10),
                              silent = TRUE)
  store <- file.path(out, ".gravcal")
  t0 <- Sys.time()
  while (length(list.files(store, pattern = "rds$")) < 2 &&
         difftime(Sys.time(), t0, units = "secs") < 120) Sys.sleep(0.05)
  expect_true(kill_run(job))
  saved <- list.files(store, pattern = "rds$", full.names = TRUE)
  expect_gte(length(saved), 2)
  expect_lt(length(saved), 5)  # stopped before the end
  stamp <- file.mtime(saved)
  # the killed run's lock names a process that is gone: taken over
  expect_message(tab <- calibrate_files(dir, outdir = out, sf = 10),
                 "took over the lock")
  # finished recordings were not redone, and the table is the same
  expect_identical(file.mtime(saved), stamp)
  expect_identical(tab[setdiff(names(tab), "seconds")],
                   full[setdiff(names(full), "seconds")])
  expect_length(list.files(out, pattern = "tmp$|part$", recursive = TRUE, all.files = TRUE), 0)
})

test_that("a lock is stale once its process has ended, also before it is reaped", {
  skip_on_os("windows")  # fork
  skip_if_not(dir.exists("/proc/self"), "no /proc: liveness by signal 0")
  host <- "here"
  owner <- function(pid) c(pid = as.character(pid), host = host)
  # a child killed and not yet collected: a zombie, /proc/<pid> stays
  job <- parallel::mcparallel(Sys.sleep(60), silent = TRUE)
  tools::pskill(job$pid, tools::SIGKILL)
  t0 <- Sys.time()
  zombie <- function() {
    st <- tryCatch(readLines(file.path("/proc", job$pid, "stat"), warn = FALSE),
                   error = function(e) "")
    grepl("\\) Z ", st)
  }
  while (!zombie() && difftime(Sys.time(), t0, units = "secs") < 30) Sys.sleep(0.02)
  expect_true(dir.exists(file.path("/proc", job$pid)))
  expect_true(lock_stale(owner(job$pid), host))
  suppressWarnings(parallel::mccollect(job, wait = TRUE, timeout = 10))
  expect_true(lock_stale(owner(job$pid), host))  # reaped: gone
  # a live process is not stale; nor is a lock of another host
  live <- parallel::mcparallel(Sys.sleep(30), silent = TRUE)
  on.exit(tools::pskill(live$pid, tools::SIGKILL), add = TRUE)
  expect_false(lock_stale(owner(live$pid), host))
  expect_false(lock_stale(c(pid = as.character(job$pid), host = "elsewhere"), host))
})

test_that("on Windows a lock's process is looked up in tasklist, never signalled", {
  # the Windows branch, on any system: `os` and tasklist's answer given
  host <- "here"
  owner <- function(pid) c(pid = as.character(pid), host = host)
  calls <- list()
  answer <- function(out, status = NULL) {
    function(command, args, stdout, stderr) {
      calls[[length(calls) + 1L]] <<- list(command = command, args = args, stdout = stdout)
      if (!is.null(status)) attr(out, "status") <- status
      out
    }
  }
  # tools::pskill() terminates a process on Windows whatever the signal:
  # the Windows branch must never call it
  signalled <- 0L
  signal <- function(pid, sig) {
    signalled <<- signalled + 1L
    TRUE
  }
  stale <- function(pid, run) {
    lock_stale(owner(pid), host, os = "windows", run = run, signal = signal)
  }
  row <- function(pid) sprintf('"Rterm.exe","%d","Console","1","102,400 K"', pid)
  # a process id other than this test's own (which is never looked up: a
  # fresh machine's test process can be 4242)
  pid <- if (Sys.getpid() == 4242L) 4243L else 4242L
  # running: the lock is kept
  expect_false(stale(pid, answer(row(pid))))
  expect_identical(calls[[1]]$command, "tasklist")
  expect_true(paste0("\"PID eq ", pid, "\"") %in% calls[[1]]$args)
  expect_true(isTRUE(calls[[1]]$stdout))
  # gone: tasklist's message (in any language), or only other processes'
  # rows (4242 is not 42420)
  expect_true(stale(pid, answer("INFO: No tasks are running which match the specified criteria.")))
  expect_true(stale(pid, answer("INFORMATION: Es werden keine Aufgaben mit den angegebenen Kriterien ausgef\u00fchrt.")))
  expect_true(stale(pid, answer(row(pid * 10L))))
  # tasklist cannot tell: the lock is kept
  expect_false(stale(pid, function(...) stop("'tasklist' not found")))
  expect_false(stale(pid, answer("ERROR: Invalid argument/option", status = 1L)))
  expect_false(stale(pid, answer(character(0))))
  # another host's lock, or this process's: tasklist is not asked
  n <- length(calls)
  expect_false(lock_stale(c(pid = "4242", host = "elsewhere"), host, os = "windows",
                          run = answer(character(0))))
  expect_false(lock_stale(owner(Sys.getpid()), host, os = "windows", run = answer(character(0)),
                          signal = signal))
  expect_identical(length(calls), n)
  expect_identical(signalled, 0L)
})

test_that("calibrate_files() and calibrate_cli() reject bad input clearly", {
  expect_error(calibrate_files(character(0), outdir = tempdir()), "`files`")
  expect_error(calibrate_files(tempfile(), outdir = tempdir()), "do not exist")
  d <- tempfile("empty")
  dir.create(d)
  expect_error(calibrate_files(d, outdir = tempdir()), "no recordings")
  expect_error(calibrate_files(gravcal_example()), "`outdir`")
  expect_error(calibrate_files(gravcal_example(), "ggir", tempdir(), 3), "named")
  expect_error(calibrate_files(c(gravcal_example(), d), outdir = tempdir()),
               "are directories")
  expect_error(calibrate_files(gravcal_example(), outdir = gravcal_example()),
               "is a file")
  expect_error(calibrate_files(gravcal_example(), outdir = tempdir(), resume = NA),
               "`resume` must be TRUE or FALSE")
  help <- utils::capture.output(calibrate_cli("--help", quit = FALSE))
  expect_match(help[1], "Usage")
  # --help lists every option the parser takes
  for (o in c("--method", "--out", "--workers", "--sf", "--pattern",
              "--no-resume", "--help")) {
    expect_true(any(grepl(o, help, fixed = TRUE)), label = o)
  }
  cli <- function(a) calibrate_cli(a, quit = FALSE)
  expect_error(cli(c("--out")), "`--out` needs a value")
  expect_error(cli(c("--out", "--method", "ggir")), "`--out` needs a value")
  expect_error(cli(c("--bogus", "x")), "Unknown option `--bogus`")
  expect_error(cli(c("--out", tempdir())), "No recordings")
  expect_error(cli(gravcal_example()), "`--out DIR` is required")
  expect_error(cli(c("--out", tempdir(), "--method", "x", gravcal_example())), "ggir or lightweight")
  expect_error(cli(c("--out", tempdir(), "--workers", "0", gravcal_example())),
               "`--workers` must be a positive whole number, not \"0\"")
  expect_error(cli(c("--out", tempdir(), "--sf", "fast", gravcal_example())),
               "`--sf` must be a positive number")
  expect_error(cli(c("--out", tempdir(), "--out", tempdir(), gravcal_example())),
               "given twice")
  expect_error(calibrate_cli("--help", quit = NA), "`quit`")
  # no function of gravcal's masks cli::cli()
  expect_false("cli" %in% getNamespaceExports("gravcal"))
})

test_that("calibrate_cli() calibrates files given on the command line", {
  skip_if_quick()
  dir <- cohort_dir()
  on.exit(unlink(dir, recursive = TRUE))
  out <- file.path(dir, "cli")
  expect_message(tab <- calibrate_cli(c("--", "--method", "lightweight", "--sf", "10", "--out", out,
                              file.path(dir, "p01.csv"), file.path(dir, "p05_corrupt.csv")),
                              quit = FALSE),
                 "1 calibrated, 0 not calibrated, 1 failed")
  expect_identical(tab$file, c("p01.csv", "p05_corrupt.csv"))
  expect_true(file.exists(file.path(out, "calibration.csv")))
})

# ---- the recording's identity: its path relative to the cohort's root ----

# Recordings in subfolders of a new folder: `files` names them relative to
# it; each a different 8-hour recording at 5 Hz (the i-th of seed 500 + i,
# simulated and saved once per run, then copied: the same bytes in every
# test).
nested_cohort <- local({
  saved <- character()
  function(files) {
    dir <- tempfile("nested")
    for (i in seq_along(files)) {
      if (length(saved) < i) {
        s <- tempfile(sprintf("nested-%d-", i), fileext = ".rds")
        saveRDS(simulate_recording(hours = 8, sf = 5, seed = 500 + i), s)
        saved[i] <<- s
      }
      f <- file.path(dir, files[i])
      dir.create(dirname(f), recursive = TRUE, showWarnings = FALSE)
      stopifnot(file.copy(saved[i], f))
    }
    dir
  }
})

strip_run <- function(tab) {
  attr(tab, "fits") <- NULL
  tab$seconds <- NULL
  tab
}

test_that("two recordings of one file name in different folders are told apart", {
  dir <- nested_cohort(c("a/p01.rds", "b/p01.rds"))
  on.exit(unlink(dir, recursive = TRUE))
  both <- file.path(dir, c("a/p01.rds", "b/p01.rds"))
  tab <- calibrate_files(both, method = "lightweight", outdir = file.path(dir, "out"))
  expect_identical(tab$file, c("a/p01.rds", "b/p01.rds"))
  expect_identical(names(attr(tab, "fits")), tab$file)
  # each row is its own recording's calibration
  for (i in 1:2) {
    expect_identical(tab$offset.x[i], unname(calibrate(both[i])$offset[1]),
                     label = tab$file[i])
  }
  expect_false(identical(tab$offset.x[1], tab$offset.x[2]))
  written <- utils::read.csv(file.path(dir, "out", "calibration.csv"))
  expect_identical(written$file, tab$file)
  expect_length(list.files(file.path(dir, "out", ".gravcal"), pattern = "rds$"), 2)
  # GGIR's coefficient file keys by file name: refused before any work,
  # naming both (paths given, or the folder listed with its subfolders)
  out <- file.path(dir, "ggir")
  msg <- "\"a/p01.rds\" and \"b/p01.rds\" have the same file name, \"p01.rds\".*GGIR's coefficient file"
  expect_error(calibrate_files(both, method = "ggir", outdir = out), msg)
  expect_error(calibrate_files(dir, method = "ggir", outdir = out, recursive = TRUE), msg)
  expect_false(dir.exists(out))
})

test_that("a folder with subfolders: identities relative to it, output folders left out", {
  dir <- nested_cohort(c("p00.rds", "a/p01.rds", "a/deep/p02.rds", "b/p03.rds"))
  on.exit(unlink(dir, recursive = TRUE))
  # an earlier run's output folder inside the cohort
  calibrate_files(file.path(dir, "p00.rds"), method = "lightweight",
                  outdir = file.path(dir, "b", "old"))
  out <- file.path(dir, "out")
  dir.create(out)
  writeLines("x,y,z", file.path(out, "stray.csv"))
  expect_identical(calibrate_files(dir, method = "lightweight", outdir = out)$file,
                   "p00.rds")
  tab <- calibrate_files(dir, method = "ggir", outdir = out, recursive = TRUE)
  ids <- c("a/deep/p02.rds", "a/p01.rds", "b/p03.rds", "p00.rds")
  expect_identical(tab$file, ids)
  expect_identical(names(attr(tab, "fits")), ids)
  expect_true(all(tab$status %in% c("ok", "high_error")))
  for (i in 1:4) {
    expect_identical(tab$scale.x[i], unname(diag(calibrate(file.path(dir, ids[i]),
                                                           method = "ggir")$K)[1]),
                     label = ids[i])
  }
  # GGIR's file names its rows by file name, which GGIR matches
  coefs <- utils::read.csv(file.path(out, "calibration_ggir_coefs.csv"))
  expect_identical(coefs$filename, basename(ids))
  expect_equal(coefs$scale.x, tab$scale.x, tolerance = 1e-13)  # csv: 15 digits
  # paths given: relative to their longest common directory
  tp <- calibrate_files(file.path(dir, ids[1:2]), method = "lightweight",
                        outdir = file.path(dir, "out2"))
  expect_identical(tp$file, c("deep/p02.rds", "p01.rds"))
  expect_error(calibrate_files(dir, outdir = out, recursive = NA),
               "`recursive` must be TRUE or FALSE")
})

test_that("calibrate_cli() --recursive takes a folder's subfolders", {
  dir <- nested_cohort(c("p00.rds", "a/p01.rds", "a/deep/p02.rds"))
  on.exit(unlink(dir, recursive = TRUE))
  cli <- function(...) {
    suppressMessages(calibrate_cli(c("--method", "lightweight", ...), quit = FALSE))
  }
  expect_identical(cli("--out", file.path(dir, "o1"), dir)$file, "p00.rds")
  tab <- cli("--recursive", "--out", file.path(dir, "o2"), dir)
  expect_identical(tab$file, c("a/deep/p02.rds", "a/p01.rds", "p00.rds"))
  direct <- calibrate_files(dir, method = "lightweight", outdir = file.path(dir, "o3"),
                            recursive = TRUE)
  expect_identical(strip_run(tab), strip_run(direct))
  help <- utils::capture.output(calibrate_cli("--help", quit = FALSE))
  expect_true(any(grepl("--recursive", help, fixed = TRUE)))
})

test_that("an interrupted run of recordings in subfolders resumes", {
  skip_on_os("windows")  # fork
  dir <- nested_cohort(c("a/p01.rds", "b/p01.rds", "c/p02.rds"))
  on.exit(unlink(dir, recursive = TRUE))
  run <- function(out, files = dir) {
    calibrate_files(files, method = "lightweight", outdir = out, recursive = TRUE)
  }
  clean <- strip_run(run(file.path(dir, "clean")))
  out <- file.path(dir, "out")
  store <- file.path(out, ".gravcal")
  # killed while the last recording (held 3 s) is being calibrated
  old <- Sys.getenv("GRAVCAL_FAULT", unset = NA)
  Sys.setenv(GRAVCAL_FAULT = "pause:c/p02")
  job <- parallel::mcparallel(run(out), silent = TRUE)
  if (is.na(old)) Sys.unsetenv("GRAVCAL_FAULT") else Sys.setenv(GRAVCAL_FAULT = old)
  t0 <- Sys.time()
  while (length(list.files(store, pattern = "rds$")) < 2 &&
         difftime(Sys.time(), t0, units = "secs") < 60) Sys.sleep(0.05)
  expect_true(kill_run(job))
  saved <- list.files(store, pattern = "rds$", full.names = TRUE)
  expect_length(saved, 2)
  # both recordings named p01.rds have their own saved result
  expect_identical(sort(sub("-.*$", "", basename(saved))), c("p01.rds", "p01.rds"))
  stamp <- file.mtime(saved)
  expect_message(tab <- run(out), "took over the lock")
  expect_identical(strip_run(tab), clean)
  expect_identical(file.mtime(saved), stamp)
  # another root (a recording from elsewhere joins): the saved results are
  # taken, under their new identities
  extra <- tempfile("extra")
  dir.create(extra)
  on.exit(unlink(extra, recursive = TRUE), add = TRUE)
  saveRDS(simulate_recording(hours = 8, sf = 5, seed = 599), file.path(extra, "q.rds"))
  wider <- run(out, c(file.path(dir, c("a/p01.rds", "b/p01.rds")),
                      file.path(extra, "q.rds")))
  expect_identical(wider$file, c(file.path(basename(dir), c("a/p01.rds", "b/p01.rds")),
                                 file.path(basename(extra), "q.rds")))
  expect_identical(file.mtime(saved), stamp)
  expect_identical(strip_run(wider)[1:2, -1], clean[1:2, -1])
})
