# Fault injection for calibrate_files(): each mishap of a cohort run must end
# with no lost, stale or half-written result and, once the fault is gone, a
# table equal to a clean run's. Faults are real where the machine allows
# (processes killed with SIGKILL, a full tmpfs when we may mount one) and
# injected through gravcal's test hook GRAVCAL_FAULT otherwise (see
# cohort_fault() in R/cohort.R): "write:REGEX" writes only half of a file,
# "calibrate:REGEX" kills the process that starts a recording, "pause:REGEX"
# makes a recording take 3 s.

# A new folder of n (at most 4) recordings, p01.rds to p04.rds. They are the
# same in every test (seeds 201 to 204): simulated and saved once per run,
# then copied (the same bytes, a new file) into each test's folder.
fault_cohort <- local({
  template <- NULL
  function(n = 4) {
    stopifnot(n <= 4)
    if (is.null(template)) {
      t <- tempfile("faults-template")
      dir.create(t)
      for (i in 1:4) {
        saveRDS(simulate_recording(hours = 8, sf = 5, seed = 200 + i),
                file.path(t, sprintf("p%02d.rds", i)))
      }
      template <<- t
    }
    dir <- tempfile("faults")
    dir.create(dir)
    stopifnot(all(file.copy(file.path(template, sprintf("p%02d.rds", seq_len(n))), dir)))
    dir
  }
})

# the table without what may differ between equal runs
strip <- function(tab) {
  attr(tab, "fits") <- NULL
  tab$seconds <- NULL
  tab
}

run <- function(dir, out, ...) {
  calibrate_files(dir, method = "lightweight", outdir = out, ...)
}

clean_run <- function(dir, ...) {
  strip(run(dir, tempfile("clean", tmpdir = dir), ...))
}

# nothing half-written, no lock left, nothing stale among the saved results
expect_tidy <- function(out) {
  left <- list.files(out, pattern = "[.](part|tmp)$", recursive = TRUE,
                     all.files = TRUE)
  expect_identical(left, character(0))
  expect_false(dir.exists(file.path(out, ".gravcal", "lock")))
}

with_fault <- function(fault, code) {
  old <- Sys.getenv("GRAVCAL_FAULT", unset = NA)
  Sys.setenv(GRAVCAL_FAULT = fault)
  on.exit(if (is.na(old)) Sys.unsetenv("GRAVCAL_FAULT") else
    Sys.setenv(GRAVCAL_FAULT = old))
  force(code)
}

slots_of <- function(out) {
  list.files(file.path(out, ".gravcal"), pattern = "[.]rds$", full.names = TRUE)
}

test_that("a worker killed mid-file fails only its recording; a rerun completes", {
  skip_if_quick()
  # slow tier: two multisession workers started twice (seconds of wall time);
  # make quick keeps the run killed mid-run (below)
  skip_if_not_installed("future")
  skip_on_os("windows")
  dir <- fault_cohort()
  on.exit(unlink(dir, recursive = TRUE))
  clean <- clean_run(dir)
  # the workers start in one folder, the run is given a relative outdir
  # from another one: outdir must be made absolute for the workers
  start <- tempfile("wd", tmpdir = dir)
  dir.create(start)
  here <- setwd(start)
  on.exit(setwd(here), add = TRUE, after = FALSE)
  old <- future::plan("list")
  on.exit(future::plan(old), add = TRUE, after = FALSE)
  # the workers inherit the fault: the one that starts p02 kills itself
  with_fault("calibrate:p02", future::plan(future::multisession, workers = 2))
  setwd(dir)
  tab <- run(dir, "out")
  future::plan(future::sequential)
  out <- file.path(dir, "out")
  expect_identical(tab$status, c("ok", "failed", "ok", "ok"))
  expect_match(tab$message[2], "no result: the R process calibrating it stopped.*run again")
  expect_identical(strip(tab)[-2, ], clean[-2, ])
  expect_true(file.exists(file.path(out, "calibration.csv")))
  expect_length(slots_of(out), 3)
  expect_tidy(out)
  # fault gone, fresh workers: the rerun calibrates only the lost recording
  stamp <- file.mtime(slots_of(out))
  tab2 <- run(dir, out)
  expect_identical(strip(tab2), clean)
  expect_identical(file.mtime(slots_of(out)[-2]), stamp)
  expect_tidy(out)
})

test_that("a run killed mid-run leaves its lock and whole results; the rerun resumes", {
  skip_on_os("windows")  # fork
  dir <- fault_cohort()
  on.exit(unlink(dir, recursive = TRUE))
  clean <- clean_run(dir)
  out <- file.path(dir, "out")
  # a forked R process, killed with SIGKILL while it calibrates p03
  job <- with_fault("pause:p03", parallel::mcparallel(run(dir, out), silent = TRUE))
  t0 <- Sys.time()
  while (length(slots_of(out)) < 2 && difftime(Sys.time(), t0, units = "secs") < 60) {
    Sys.sleep(0.05)
  }
  tools::pskill(job$pid, tools::SIGKILL)
  suppressWarnings(parallel::mccollect(job, wait = TRUE, timeout = 5))
  saved <- slots_of(out)
  expect_length(saved, 2)
  owner <- readLines(file.path(out, ".gravcal", "lock", "owner"))
  expect_true(paste0("pid=", job$pid) %in% owner)
  expect_false(file.exists(file.path(out, "calibration.csv")))
  stamp <- file.mtime(saved)
  # the lock of a process that is gone is taken over
  expect_message(tab <- run(dir, out), "took over the lock.*process")
  expect_identical(strip(tab), clean)
  expect_identical(file.mtime(saved), stamp)
  expect_tidy(out)
})

test_that("a full disk is an error naming the file; nothing written is lost", {
  dir <- fault_cohort()
  on.exit(unlink(dir, recursive = TRUE))
  clean <- clean_run(dir)
  out <- file.path(dir, "out")
  run(dir, out)
  table <- file.path(out, "calibration.csv")
  good <- readBin(table, "raw", 1e6)
  # the table: half of it reaches the disk
  expect_error(with_fault("write:calibration[.]csv$", run(dir, out, resume = FALSE)),
               paste0("Could not write \"", table, "\".*is it full"), fixed = FALSE)
  expect_identical(readBin(table, "raw", 1e6), good)
  expect_tidy(out)
  # one saved result: its row says so, the others go on
  tab <- with_fault("write:p02[.]rds-", run(dir, out, resume = FALSE))
  expect_identical(tab$status, c("ok", "failed", "ok", "ok"))
  expect_match(tab$message[2], "Could not write .*p02[.]rds-.*is it full")
  expect_tidy(out)
  expect_identical(strip(run(dir, out)), clean)
  # write_coefs()
  fit <- calibrate(simulate_recording(hours = 30, sf = 10, seed = 4), sf = 10,
                   method = "ggir")
  coefs <- file.path(dir, "coefs.csv")
  expect_error(with_fault("write:coefs", write_coefs(list(a.bin = fit), coefs)),
               "Could not write \".*coefs.csv\"")
  expect_false(file.exists(coefs))
  expect_length(list.files(dir, pattern = "part$", all.files = TRUE), 0)
})

test_that("a really full disk (a small tmpfs) loses nothing", {
  skip_if_quick()
  # slow tier; make quick keeps the injected full disk (above)
  skip_on_os(c("windows", "mac"))
  mnt <- tempfile("tmpfs")
  dir.create(mnt)
  can_mount <- identical(unname(Sys.info()["user"]), "root") &&
    nzchar(Sys.which("mount")) &&
    suppressWarnings(system2("mount", c("-t", "tmpfs", "-o", "size=3m", "tmpfs", mnt),
                             stdout = FALSE, stderr = FALSE)) == 0
  skip_if_not(can_mount, "mounting a tmpfs needs root; the injected full disk above still runs")
  dir <- fault_cohort()
  on.exit({
    system2("umount", mnt)
    unlink(c(dir, mnt), recursive = TRUE)
  })
  clean <- clean_run(dir)
  out <- file.path(mnt, "out")
  expect_identical(strip(run(dir, out)), clean)
  table <- file.path(out, "calibration.csv")
  good <- readBin(table, "raw", 1e6)
  system2("dd", c("if=/dev/zero", paste0("of=", file.path(mnt, "filler")), "bs=64k"),
          stdout = FALSE, stderr = FALSE)
  expect_error(run(dir, out, resume = FALSE), paste0("Could not (write|create) .*", mnt))
  expect_identical(readBin(table, "raw", 1e6), good)
  unlink(file.path(mnt, "filler"))
  expect_tidy(out)
  expect_identical(strip(run(dir, out)), clean)
})

test_that("two runs on one outdir: the second refuses, the first completes", {
  skip_if_quick()
  skip_on_os("windows")  # fork
  dir <- fault_cohort()
  on.exit(unlink(dir, recursive = TRUE))
  clean <- clean_run(dir)
  out <- file.path(dir, "out")
  job <- with_fault("pause:p01", parallel::mcparallel(strip(run(dir, out)), silent = TRUE))
  lock <- file.path(out, ".gravcal", "lock", "owner")
  t0 <- Sys.time()
  while (!file.exists(lock) && difftime(Sys.time(), t0, units = "secs") < 60) Sys.sleep(0.02)
  expect_error(run(dir, out), paste0("in use by another calibrate_files\\(\\) run \\(process ",
                                     job$pid, ".*unlink"))
  first <- parallel::mccollect(job, wait = TRUE)[[1]]
  expect_identical(first, clean)
  expect_identical(strip(run(dir, out)), clean)
  expect_tidy(out)
  # a lock held on another machine is never taken over
  dir.create(file.path(out, ".gravcal", "lock"))
  writeLines(c("pid=1", "host=elsewhere.example.org", "started=2026-01-01 00:00:00"),
             file.path(out, ".gravcal", "lock", "owner"))
  expect_error(run(dir, out), "process 1 on elsewhere.example.org.*unlink\\(")
  expect_true(dir.exists(file.path(out, ".gravcal", "lock")))
})

test_that("a damaged saved result is recomputed and noted in its row", {
  dir <- fault_cohort()
  on.exit(unlink(dir, recursive = TRUE))
  clean <- clean_run(dir)
  out <- file.path(dir, "out")
  run(dir, out)
  slots <- slots_of(out)
  bytes <- readBin(slots[2], "raw", file.size(slots[2]))
  writeBin(bytes[seq_len(length(bytes) %/% 2)], slots[2])  # truncated
  file.create(slots[3])                                     # empty
  stamp <- file.mtime(slots[c(1, 4)])
  tab <- run(dir, out)
  expect_match(tab$message[2], paste0("saved result \".*", basename(slots[2]),
                                      "\" could not be read .* recomputed"))
  expect_match(tab$message[3], "could not be read .* recomputed")
  notes <- strip(tab)
  notes$message <- sub("; the saved result .*$", "", notes$message)
  expect_identical(notes, clean)
  expect_identical(file.mtime(slots[c(1, 4)]), stamp)
  expect_true(all(vapply(slots, function(s) is.list(readRDS(s)), TRUE)))
  expect_tidy(out)
  expect_identical(strip(run(dir, out)), clean)
})

test_that("a recording replaced between runs is calibrated again", {
  dir <- fault_cohort()
  on.exit(unlink(dir, recursive = TRUE))
  out <- file.path(dir, "out")
  run(dir, out)
  p02 <- file.path(dir, "p02.rds")
  when <- file.mtime(p02)
  saveRDS(simulate_recording(hours = 8, sf = 5, seed = 999), p02)
  Sys.setFileTime(p02, when)  # same name, same time: the content tells
  clean <- clean_run(dir)
  expect_identical(strip(run(dir, out)), clean)
  expect_length(slots_of(out), 4)
  expect_tidy(out)
})

test_that("settings changed between runs recompute every recording", {
  dir <- fault_cohort(2)
  on.exit(unlink(dir, recursive = TRUE))
  out <- file.path(dir, "out")
  first <- strip(run(dir, out))
  clean <- clean_run(dir, max_iter = 3)
  second <- strip(run(dir, out, max_iter = 3))
  expect_identical(second, clean)
  expect_false(identical(second$scale.x, first$scale.x))
  expect_identical(strip(run(dir, out)), first)
  expect_length(slots_of(out), 2)
  expect_tidy(out)
})

test_that("files gravcal did not write are never deleted or overwritten", {
  dir <- fault_cohort(1)
  on.exit(unlink(dir, recursive = TRUE))
  out <- file.path(dir, "out")
  dir.create(out)
  writeLines("mine", file.path(out, "notes.tmp"))
  writeLines("mine", file.path(out, "calibration.csv"))
  expect_error(run(dir, out), "holds \".*calibration.csv\", which gravcal did not write")
  expect_identical(readLines(file.path(out, "calibration.csv")), "mine")
  file.rename(file.path(out, "calibration.csv"), file.path(out, "mine.csv"))
  run(dir, out)
  expect_identical(readLines(file.path(out, "notes.tmp")), "mine")
  # a table of gravcal's that someone edited is not overwritten either
  cat("edited\n", file = file.path(out, "calibration.csv"), append = TRUE)
  expect_error(run(dir, out), "which gravcal did not write \\(or which was changed")
})

test_that("rows carry warnings, hours and rest windows; the GGIR file holds this run only", {
  dir <- tempfile("rows")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  rec <- simulate_recording(hours = 8, sf = 5, seed = 301)
  rec$x[1:5] <- NA
  saveRDS(rec, file.path(dir, "gaps.rds"))
  short <- simulate_recording(hours = 1.9, sf = 10, seed = 302)
  utils::write.csv(short, file.path(dir, "short.csv"), row.names = FALSE)
  long <- simulate_recording(hours = 26, sf = 5, seed = 303)
  utils::write.csv(long, file.path(dir, "long.csv"), row.names = FALSE)
  out <- file.path(dir, "out")
  tl <- run(file.path(dir, "gaps.rds"), out)
  expect_match(tl$warnings, "non-finite")
  tg <- calibrate_files(file.path(dir, c("short.csv", "long.csv")), "ggir",
                        outdir = out, sf = 10)
  fits <- attr(tg, "fits")
  expect_equal(tg$hours, c(1.9, 26 * 5 / 10), tolerance = 1e-6)
  expect_identical(tg$rest_windows, c(as.numeric(NROW(fits[[1]]$points)),
                                      as.numeric(NROW(fits[[2]]$points))))
  expect_gt(tg$rest_windows[2], 0)
  coefs <- utils::read.csv(file.path(out, "calibration_ggir_coefs.csv"))
  expect_identical(coefs$filename, tg$file[tg$status %in% c("ok", "high_error")])
  # a rerun in which nothing is calibrated leaves no coefficients of the last
  writeLines(c("x,y,z", "a,b,c"), file.path(dir, "bad.csv"))
  tb <- calibrate_files(file.path(dir, "bad.csv"), "ggir", outdir = out)
  expect_identical(tb$status, "failed")
  coefs <- utils::read.csv(file.path(out, "calibration_ggir_coefs.csv"))
  expect_identical(nrow(coefs), 0L)
  expect_true("scale.x" %in% names(coefs))
})

test_that("the command line exits 1 when a recording failed, 2 on bad arguments", {
  skip_on_os("windows")
  dir <- fault_cohort(1)
  on.exit(unlink(dir, recursive = TRUE))
  writeLines(c("x,y,z", "a,b,c"), file.path(dir, "bad.csv"))
  rscript <- file.path(R.home("bin"), "Rscript")
  env <- paste0("R_LIBS=", shQuote(paste(.libPaths(), collapse = .Platform$path.sep)))
  cli <- function(...) {
    out <- suppressWarnings(system2(rscript, c("-e", shQuote("gravcal::calibrate_cli()"),
                                               "--", ...), stdout = TRUE, stderr = TRUE,
                                    env = env))
    list(status = if (is.null(attr(out, "status"))) 0L else attr(out, "status"),
         text = paste(out, collapse = "\n"))
  }
  ok <- cli("--method", "lightweight", "--out", file.path(dir, "a"), file.path(dir, "p01.rds"))
  expect_identical(ok$status, 0L)
  expect_match(ok$text, "1 recording\\(s\\): 1 calibrated, 0 not calibrated, 0 failed")
  bad <- cli("--method", "lightweight", "--out", file.path(dir, "b"),
             file.path(dir, "p01.rds"), file.path(dir, "bad.csv"))
  expect_identical(bad$status, 1L)
  expect_match(bad$text, "1 calibrated, 0 not calibrated, 1 failed")
  usage <- cli("--out", file.path(dir, "c"), "--workers", "many", file.path(dir, "p01.rds"))
  expect_identical(usage$status, 2L)
  expect_match(usage$text, "gravcal: error: `--workers` must be a positive whole number")
})
