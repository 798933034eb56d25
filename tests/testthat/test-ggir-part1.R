# gravcal::g.part1() against GGIR 3.3-9's g.part1() on the same folder of
# recordings: the meta files' objects identical() (M and C but their
# wall-clock bsc_qc), and GGIR's part 2 on gravcal's meta files the same as
# on GGIR's. GGIR's side is cached (helper-ggir-cache.R) by the recordings'
# bytes and the arguments.

p1_quiet <- function(expr) {
  out <- NULL
  keep_warn(utils::capture.output(out <- suppressWarnings(expr)))
  out
}

# quiet, warnings kept (collected in p1_state$warnings)
p1_quiet0 <- function(expr) {
  out <- NULL
  keep_warn(utils::capture.output(out <- withCallingHandlers(expr, warning = function(w) {
    p1_state$warnings <- c(p1_state$warnings, conditionMessage(w))
    invokeRestart("muffleWarning")
  })))
  out
}


# A folder of two recordings of 26 hours written by the package's writers:
# an Axivity .cwa at 25 Hz and a GENEActiv .bin at 30 Hz, each with rest on
# a table (non-wear) and clipped samples (meta_recording() of
# test-ggir-getmeta.R's kind). Made once a session.
p1_state <- new.env()
p1_folder <- function() {
  if (is.null(p1_state$dir) || !dir.exists(p1_state$dir)) {
    d <- tempfile("part1-data-")
    dir.create(d)
    rec <- function(format, sf, seed, start, name) {
      write_meta_recording(file.path(d, name), format, sf, 26, seed, start)
    }
    rec("cwa", 25, 21, "2024-03-04 09:07:23", "p01.cwa")
    rec("bin", 30, 22, "2024-03-05 10:01:07", "p02.bin")
    p1_state$dir <- d
  }
  p1_state$dir
}

# A folder of one recording of 26 hours of the same kind, named `name`:
# `format` (write_meta_recording()'s) at `sf` Hz. Made once a session.
p1_folder_of <- function(name, format, sf, seed, start) {
  d <- p1_state[[name]]
  if (is.null(d) || !dir.exists(d)) {
    d <- tempfile(paste0("part1-", format, "-"))
    dir.create(d)
    write_meta_recording(file.path(d, name), format, sf, 26, seed, start)
    p1_state[[name]] <- d
  }
  d
}

# an ActiGraph .gt3x at 30 Hz; a Parmay Matrix .BIN at 25 Hz
p1_folder_gt3x <- function() p1_folder_of("g01.gt3x", "gt3x", 30, 23, "2024-03-06 11:00:00")
p1_folder_parmay <- function() p1_folder_of("m01.BIN", "parmay", 25, 24, "2024-03-06 11:00:00")

# Part 2 (GGIR::GGIR(mode = 2), with its report) on the meta files of
# outputdir/output_<data folder>: the ms2.out objects and the report's csv
# files as text.
p1_part2 <- function(datadir, outputdir) {
  p1_quiet(GGIR::GGIR(mode = 2, datadir = datadir, outputdir = outputdir, do.report = 2,
                      do.parallel = FALSE, verbose = FALSE, visualreport = FALSE))
  md <- file.path(outputdir, paste0("output_", basename(datadir)))
  csv <- c("part2_summary.csv", "part2_daysummary.csv", "QC/data_quality_report.csv")
  list(ms2 = p1_objects(file.path(md, "meta", "ms2.out")),
       csv = lapply(stats::setNames(csv, csv), function(f) {
         readLines(file.path(md, "results", f))
       }))
}

p1_run <- function(fun, datadir, outputdir, args) {
  md <- file.path(outputdir, paste0("output_", basename(datadir)))
  f1 <- if (is.null(args$f1)) 2 else args$f1
  tab <- p1_quiet(do.call(fun, c(list(datadir = datadir, metadatadir = md, f1 = f1,
                                      verbose = FALSE), args[setdiff(names(args), "f1")])))
  list(tab = tab, md = md)
}

# GGIR's part 1 (then part 2 and part 1 again, which retrieves the
# coefficients from part 2's report, when `then_part2`) and gravcal's on the
# folder with the same arguments.
p1_both <- function(args, then_part2 = FALSE, backup = NULL, folder = p1_folder) {
  skip_if_not_installed("GGIR")
  d <- folder()
  files <- file.path(d, dir(d))
  # a coefficient file given as its rows: the cache key holds them, not a
  # temporary path
  write_backup <- function() {
    if (is.null(backup)) return(args)
    f <- tempfile(fileext = ".csv")
    utils::write.csv(backup, f, row.names = FALSE)
    c(args, list(backup.cal.coef = f))
  }
  key <- c(args, list(backup = backup, then_part2 = then_part2))
  # a myfun's functions enter the key as their text (a closure's
  # serialization holds its environment)
  if (!is.null(key$myfun)) {
    key$myfun <- lapply(key$myfun, function(v) if (is.function(v)) deparse(v) else v)
  }
  ggir <- ggir_cached("g.part1", files, key, {
    out <- tempfile("part1-ggir-")
    dir.create(out)
    r <- p1_run(GGIR::g.part1, d, out, write_backup())
    res <- list(part1 = p1_objects(file.path(r$md, "meta", "basic")))
    if (then_part2) {
      res$part2 <- p1_part2(d, out)
      p1_run(GGIR::g.part1, d, out, c(args, list(overwrite = TRUE)))
      res$again <- p1_objects(file.path(r$md, "meta", "basic"))
    }
    unlink(out, recursive = TRUE)
    res
  })
  out <- tempfile("part1-gravcal-")
  dir.create(out)
  t0 <- proc.time()[["elapsed"]]
  r <- p1_run(gravcal::g.part1, d, out, write_backup())
  grav <- list(part1 = p1_objects(file.path(r$md, "meta", "basic")), tab = r$tab,
               seconds = proc.time()[["elapsed"]] - t0)
  if (then_part2) {
    grav$part2 <- p1_part2(d, out)
    p1_run(gravcal::g.part1, d, out, c(args, list(overwrite = TRUE)))
    grav$again <- p1_objects(file.path(r$md, "meta", "basic"))
  }
  list(ggir = ggir, gravcal = grav, md = r$md)
}

expect_same_objects <- function(G, R, what) {
  expect_identical(names(G), names(R), label = paste(what, ": gravcal's files"))
  for (f in names(R)) {
    expect_identical(names(G[[f]]), names(R[[f]]), label = paste(what, f, ": objects"))
    for (nm in names(R[[f]])) {
      expect_true(identical(G[[f]][[nm]], R[[f]][[nm]]),
                  label = paste0(what, " ", f, ": gravcal's ", nm, " identical() to GGIR's"))
    }
  }
}

test_that("g.part1() writes GGIR's meta files; GGIR's part 2 gives the same on them", {
  skip_if_quick()
  b <- p1_both(list(do.parallel = FALSE), then_part2 = TRUE)
  expect_identical(names(b$ggir$part1), c("meta_p01.cwa.RData", "meta_p02.bin.RData"))
  expect_same_objects(b$gravcal$part1, b$ggir$part1, "part 1")
  obj <- b$gravcal$part1[["meta_p01.cwa.RData"]]
  expect_identical(names(obj), sort(c("M", "I", "C", "filename_dir", "filefoldername",
                                      "tail_expansion_log", "GGIRversion",
                                      "desiredtz_part1")))
  # what the comparison saw: a calibration, temperature, non-wear, clipping
  expect_gt(obj$C$npoints, 1000)
  expect_false(identical(obj$C$scale, c(1, 1, 1)))
  expect_true(any(obj$M$metalong$nonwearscore > 0))
  expect_true(any(obj$M$metalong$clippingscore > 0))
  expect_identical(obj$GGIRversion, utils::packageVersion("GGIR"))
  expect_identical(b$gravcal$tab$status, c("written", "written"))
  # part 2 on gravcal's meta files: its ms2.out files and its report's csv
  # files (no run-time columns there) the same as on GGIR's
  expect_same_objects(b$gravcal$part2$ms2, b$ggir$part2$ms2, "part 2 ms2.out")
  expect_identical(b$gravcal$part2$csv, b$ggir$part2$csv)
  expect_gt(length(b$gravcal$part2$csv$part2_daysummary.csv), 2)
  # part 1 again after part 2 (overwrite = TRUE): the coefficients
  # retrieved from part 2's data_quality_report.csv (backup.cal.coef =
  # "retrieve"), as GGIR retrieves them, types and all
  expect_same_objects(b$gravcal$again, b$ggir$again, "part 1 again")
  # (through the csv's 15 significant digits)
  expect_equal(b$gravcal$again[["meta_p01.cwa.RData"]]$C$scale, obj$C$scale, tolerance = 1e-14)
})

# the first blocks read ahead and taken by g.getmeta() so far (R/meta-ahead.R)
p1_taken <- function() {
  v <- gravcal:::ahead_state$taken
  if (is.null(v)) 0 else v
}

test_that("g.part1() reads g.getmeta()'s first block beside the calibration: the meta files of one thread", {
  # R/meta-ahead.R: on two threads the first block is read while
  # g.calibrate() makes its pass; on one (options(gravcal.threads = 1)) it
  # is not. The .cwa of 60 hours has two of GGIR's blocks (36 hours each)
  d <- tempfile("part1-ahead-")
  dir.create(d)
  on.exit(unlink(d, recursive = TRUE), add = TRUE)
  write_meta_recording(file.path(d, "a.cwa"), "cwa", 25, 60, 31, "2024-03-04 09:07:23")
  write_meta_recording(file.path(d, "b.bin"), "bin", 30, 26, 32, "2024-03-05 10:01:07")
  run <- function(threads) {
    old <- options(gravcal.threads = threads)
    on.exit(options(old))
    out <- tempfile("part1-ahead-out-")
    on.exit(unlink(out, recursive = TRUE), add = TRUE)
    before <- p1_taken()
    r <- p1_run(gravcal::g.part1, d, out, list())
    list(obj = p1_objects(file.path(r$md, "meta", "basic")), tab = r$tab,
         taken = p1_taken() - before)
  }
  two <- run(2)
  one <- run(1)
  expect_identical(two$taken, 2)  # both files read ahead
  expect_identical(one$taken, 0)
  expect_identical(two$tab$status, c("written", "written"))
  expect_identical(names(two$obj), c("meta_a.cwa.RData", "meta_b.bin.RData"))
  expect_same_objects(two$obj, one$obj, "read ahead")
  # what the comparison saw: the .cwa's two blocks, a calibration
  M <- two$obj[["meta_a.cwa.RData"]]$M
  expect_gt(nrow(M$metalong), 36 * 4)
  expect_false(identical(two$obj[["meta_a.cwa.RData"]]$C$scale, c(1, 1, 1)))
  # nothing left open or pending after the files
  expect_null(gravcal:::ahead_state$pending)
})

test_that("a block read ahead is taken only by the same read; what is not taken is closed", {
  d <- tempfile("part1-ahead-")
  dir.create(d)
  on.exit(unlink(d, recursive = TRUE), add = TRUE)
  f <- file.path(d, "a.cwa")
  write_meta_recording(f, "cwa", 25, 26, 33, "2024-03-04 09:07:23")
  on.exit(gravcal:::meta_ahead_close(), add = TRUE)
  # opened, then g.calibrate()'s pump reads the first block beside its pass
  expect_true(gravcal:::meta_ahead_open(f, c(), c(), c(), c(), NULL))
  a <- gravcal:::ahead_state$pending
  spec <- gravcal:::meta_ahead_spec()
  expect_identical(spec$units, a$src$units)
  expect_null(gravcal:::meta_ahead_spec())  # once
  st <- gravcal:::ahead_state
  st$pending$started <- FALSE
  C <- p1_quiet(gravcal::g.calibrate(f, verbose = FALSE))
  expect_true(gravcal:::ahead_state$pending$started)
  # another read than the one made is an error, never a silent block
  ms <- a$src$ahead_store
  expect_error(gravcal:::gc_meta_store_read(ms$store, a$src$native$ptr, a$src$units + 1, ms$chunk,
                                            ms$want_time),
               "not the one asked for")
  gravcal:::meta_ahead_close()
  expect_null(gravcal:::ahead_state$pending)
  expect_error(gravcal:::gc_decoder_epoch_gaps(a$src$native$ptr), "closed")
  # g.getmeta() with other parameters than those opened for: not taken
  # (closed), the file opened again; the same M as without any read ahead
  expect_true(gravcal:::meta_ahead_open(f, c(), c(), c(), c(), NULL))
  b <- gravcal:::ahead_state$pending
  before <- p1_taken()
  M1 <- gravcal::g.getmeta(f, verbose = FALSE, params_metrics = list(do.enmoa = TRUE))
  expect_identical(p1_taken(), before)
  expect_null(gravcal:::ahead_state$pending)
  expect_error(gravcal:::gc_decoder_epoch_gaps(b$src$native$ptr), "closed")
  M2 <- gravcal::g.getmeta(f, verbose = FALSE, params_metrics = list(do.enmoa = TRUE))
  M1$bsc_qc <- M2$bsc_qc <- NULL
  expect_identical(M1, M2)
  expect_true("ENMOa" %in% names(M1$metashort))
  # a reader that imputes time gaps (.gt3x): not opened ahead
  g <- file.path(d, "g.gt3x")
  write_meta_recording(g, "gt3x", 30, 3, 34, "2024-03-06 11:00:00")
  expect_false(gravcal:::meta_ahead_open(g, c(), c(), c(), c(), NULL))
  expect_null(gravcal:::ahead_state$pending)
  # the same parameters: taken, and the same M
  expect_true(gravcal:::meta_ahead_open(f, list(do.enmoa = TRUE), c(), c(), c(), NULL))
  M3 <- gravcal::g.getmeta(f, verbose = FALSE, params_metrics = list(do.enmoa = TRUE))
  expect_identical(p1_taken(), before + 1)
  M3$bsc_qc <- NULL
  expect_identical(M3, M1)
})

test_that("the meta files are save()'s bytes, gzipped on two threads (members in a row)", {
  gunzip <- function(z) {
    f <- tempfile()
    on.exit(unlink(f))
    writeBin(z, f)
    con <- gzfile(f, "rb")
    on.exit(close(con), add = TRUE)
    readBin(con, "raw", 4 * length(z) + 1e6)
  }
  set.seed(41)
  # 3 MB of text-like bytes (two members on two threads), 1000 bytes
  # (one), none
  big <- as.raw(sample(c(48:57, 32, 10), 3e6, replace = TRUE, prob = c(rep(1, 10), 4, 1)))
  for (b in list(big, big[1:1000], raw(0))) {
    z1 <- gravcal:::gc_gzip(b, 6L, 1L)
    z2 <- gravcal:::gc_gzip(b, 6L, 2L)
    expect_identical(gunzip(z1), b)
    expect_identical(gunzip(z2), b)
    expect_identical(z2[1:3], as.raw(c(0x1f, 0x8b, 0x08)))  # gzip, deflate
    if (length(b) >= 2^20) {
      # the second member's header, where the first member ends
      starts <- which(z2[-length(z2)] == as.raw(0x1f) & z2[-1] == as.raw(0x8b))
      expect_true(length(starts) >= 2)
      expect_false(identical(z1, z2))
    } else {
      expect_identical(z1, z2)
    }
  }
  expect_error(gravcal:::gc_gzip(big, 0L, 1L), "level must be 1 to 9")
  expect_error(gravcal:::gc_gzip(big, 6L, 0L), "threads must be at least 1")
  # part1_save(): load() gives the objects back; the file's bytes, once
  # gunzipped, are those of save() itself
  e <- new.env()
  e$M <- list(metashort = data.frame(timestamp = as.character(1:2e4), ENMO = stats::runif(2e4)))
  e$tag <- "x"
  f <- tempfile(fileext = ".RData")
  g <- tempfile(fileext = ".RData")
  on.exit(unlink(c(f, g)), add = TRUE)
  gravcal:::part1_save(c("M", "tag"), e, f)
  save(list = c("M", "tag"), envir = e, file = g)
  back <- new.env()
  load(f, envir = back)
  expect_identical(mget(c("M", "tag"), envir = back), mget(c("M", "tag"), envir = e))
  expect_identical(gunzip(readBin(f, "raw", file.size(f))),
                   gunzip(readBin(g, "raw", file.size(g))))
})

# g.part1() on the folder of one recording `name` at `sf` Hz against
# GGIR's, then part 2 and part 1 again: the meta files and what part 2
# makes of them the same. Returns gravcal's meta file's objects.
p1_expect_single <- function(folder, name, sf) {
  b <- p1_both(list(do.parallel = FALSE, desiredtz = "Europe/Amsterdam", f1 = 1),
               then_part2 = TRUE, folder = folder)
  expect_identical(names(b$ggir$part1), paste0("meta_", name, ".RData"))
  expect_same_objects(b$gravcal$part1, b$ggir$part1, "part 1")
  obj <- b$gravcal$part1[[1]]
  # what the comparison saw: a calibration, non-wear
  expect_identical(obj$I$sf, sf)
  expect_gt(obj$C$npoints, 1000)
  expect_true(any(obj$M$metalong$nonwearscore > 0))
  expect_same_objects(b$gravcal$part2$ms2, b$ggir$part2$ms2, "part 2 ms2.out")
  expect_identical(b$gravcal$part2$csv, b$ggir$part2$csv)
  expect_same_objects(b$gravcal$again, b$ggir$again, "part 1 again")
  obj
}

test_that("g.part1() on a .gt3x file: GGIR's meta file (its I without GGIR's whole-file reads)", {
  skip_if_quick()
  skip_if_not_installed("read.gt3x")
  p1_expect_single(p1_folder_gt3x, "g01.gt3x", 30)
})

test_that("g.part1() on a Parmay Matrix file: GGIR's meta file (I from GGIR's g.inspectfile())", {
  skip_if_quick()
  skip_if_not_installed("GGIRread")
  obj <- p1_expect_single(p1_folder_parmay, "m01.BIN", 25)
  expect_identical(obj$I$monn, "parmay_mtx")
  # GGIRread's log of the file's packets, of 2 minutes each
  expect_identical(nrow(obj$M$QClog), 780L)
})

test_that("g.part1() is GGIR's with backup.cal.coef (a file with one recording), desiredtz", {
  skip_if_quick()
  skip_if_not_installed("data.table")
  d <- p1_folder()
  C <- p1_quiet(gravcal::g.calibrate(file.path(d, "p01.cwa"), verbose = FALSE))
  f <- tempfile(fileext = ".csv")
  write_coefs(list(p01.cwa = C), f)
  backup <- utils::read.csv(f, stringsAsFactors = FALSE)
  b <- p1_both(list(do.parallel = FALSE, desiredtz = "Europe/Amsterdam"), backup = backup)
  expect_same_objects(b$gravcal$part1, b$ggir$part1, "part 1")
  got <- b$gravcal$part1
  # p01.cwa: retrieved (no g.calibrate() list: no spheredata); p02.bin: not
  # in the file, so calibrated
  expect_null(got[["meta_p01.cwa.RData"]]$C$spheredata)
  expect_equal(got[["meta_p01.cwa.RData"]]$C$scale, C$scale, tolerance = 1e-14)
  expect_false(is.null(got[["meta_p02.bin.RData"]]$C$spheredata))
  expect_identical(got[["meta_p01.cwa.RData"]]$desiredtz_part1, "Europe/Amsterdam")
})

test_that("g.part1() is GGIR's without calibration, for f0 and f1", {
  skip_if_quick()
  # GGIR's order: .bin before .cwa; f0 = f1 = 2 is p01.cwa alone
  b <- p1_both(list(do.parallel = FALSE, do.cal = FALSE, f0 = 2, f1 = 2))
  expect_identical(names(b$ggir$part1), "meta_p01.cwa.RData")
  expect_same_objects(b$gravcal$part1, b$ggir$part1, "part 1")
  C <- b$gravcal$part1[[1]]$C
  expect_identical(C$QCmessage, "Autocalibration not done")
  expect_identical(C$scale, c(1, 1, 1))
})

test_that("g.part1() passes myfun to g.getmeta() as GGIR's does", {
  skip_if_quick()
  skip_if_not_installed("GGIRread")
  mf <- list(FUN = function(data, parameters) {
    i <- seq(1, floor(nrow(data) / 125) * 125, by = 125)
    round(data[i, 1] * parameters, 3)
  }, parameters = 10, expected_sample_rate = 25, expected_unit = "g", colnames = "x10",
  minlength = 5, outputres = 5, outputtype = "numeric")
  b <- p1_both(list(do.parallel = FALSE, do.cal = FALSE, f0 = 2, f1 = 2, myfun = mf))
  expect_same_objects(b$gravcal$part1, b$ggir$part1, "part 1")
  ms <- b$gravcal$part1[[1]]$M$metashort
  expect_identical(names(ms)[ncol(ms)], "x10")
  expect_gt(sum(!is.na(ms$x10)), 1000)
})

test_that("g.part1() is GGIR's with recordingEndSleepHour (M's tail expanded)", {
  skip_if_quick()
  # days from noon to noon: both recordings end late enough before the
  # border for GGIR to add epochs to 8 hours past it
  b <- p1_both(list(do.parallel = FALSE, do.cal = FALSE, recordingEndSleepHour = 19,
                    dayborder = 12, desiredtz = "Europe/London"))
  expect_same_objects(b$gravcal$part1, b$ggir$part1, "part 1")
  obj <- b$gravcal$part1[["meta_p01.cwa.RData"]]
  expect_gt(obj$tail_expansion_log$long, 100)
  expect_identical(nrow(obj$M$metalong) - obj$tail_expansion_log$long,
                   sum(obj$M$metalong$nonwearscore != -1))
  expect_true("nonwear" %in% names(obj$M))
})

test_that("recordingEndSleepHour on a recording without epochs: GGIR's outcome at the time it runs", {
  # GGIR 3.3-9's g.part1() takes the last epochs' times into times of now
  # (Sys.time()); a recording without epochs (too short, unreadable) leaves
  # them so: it expands (and stops on the rows it does not have) only when
  # run between recordingEndSleepHour and the day border in desiredtz's
  # clock, and writes M as it is otherwise. Before, gravcal stopped at any
  # time. Found by tools/ggir-sweep-part1.R (stop 68), where GGIR wrote the
  # file at 04:xx UTC with recordingEndSleepHour 20
  M <- list(metashort = NULL, metalong = NULL, windowsizes = NULL)
  at <- function(h) as.POSIXct(sprintf("2026-12-02 %02d:30:00", h), tz = "UTC")
  for (h in c(0, 4, 12, 19)) {
    r <- gravcal:::part1_expand_tail(M, 20, 0, "UTC", "a.cwa", now = at(h))
    expect_identical(r, list(M = M, log = NULL), label = paste("at", h))
  }
  for (h in c(20, 23)) {
    expect_error(gravcal:::part1_expand_tail(M, 20, 0, "UTC", "a.cwa", now = at(h)),
                 "no epochs to expand.*run now \\(after 20:00", label = paste("at", h))
  }
  # the clock is desiredtz's: 19:30 UTC is 20:30 in Amsterdam (winter)
  expect_error(gravcal:::part1_expand_tail(M, 20, 0, "Europe/Amsterdam", "a.cwa", now = at(19)),
               "no epochs to expand")
})

test_that("overwrite = FALSE and backup.cal.coef find a recording's name as GGIR's part 1 does", {
  # GGIR 3.3-9 splits the names at patterns ("." any character): a meta
  # file's name before ".RData", its piece after "meta_", cut at ".csv";
  # a recording's own name before ".csv", then ".RD". So "s_csv.cwa" is
  # done by "meta_s_csv.bin.RData" (both "s"), and a recording named
  # "meta_a.cwa" never is (its meta file "meta_meta_a.cwa.RData" reads as
  # ""). Found by tools/ggir-sweep-part1.R (stop 68), against GGIR's
  # g.part1(): before, gravcal wrote s_csv.cwa's meta file and skipped
  # meta_a.cwa's, where GGIR does the opposite
  basic <- tempfile("basic-")
  dir.create(basic)
  file.create(file.path(basic, c("meta_s_csv.bin.RData", "meta_meta_a.cwa.RData",
                                 "meta_b.cwa.RData", "notes.txt")))
  done <- gravcal:::part1_done(basic, c("s_csv.cwa", "meta_a.cwa", "b.cwa", "c.cwa", "s_csv.bin"))
  expect_identical(done, c(TRUE, FALSE, TRUE, FALSE, TRUE))
  expect_identical(gravcal:::part1_done(tempfile(), "a.cwa"), FALSE)
  # backup.cal.coef: a row named "meta_meta_a.cwa.RData" is no recording's
  csv <- tempfile(fileext = ".csv")
  utils::write.csv(data.frame(filename = c("meta_meta_a.cwa.RData", "meta_b.cwa.RData", "c.cwa"),
                              scale.x = c(0.99, 0.98, 0.97), scale.y = 1, scale.z = 1,
                              offset.x = 0, offset.y = 0, offset.z = 0),
                   csv, row.names = FALSE)
  C <- list()
  expect_null(gravcal:::part1_retrieve(C, csv, "meta_a.cwa"))
  expect_identical(gravcal:::part1_retrieve(C, csv, "b.cwa")$scale, c(0.98, 1, 1))
  expect_identical(gravcal:::part1_retrieve(C, csv, "c.cwa")$scale, c(0.97, 1, 1))
  unlink(c(basic, csv), recursive = TRUE)
})

# A folder of one ad hoc csv file (GGIR's rmc.* files) of 8 hours at 10 Hz,
# in mg with UNIX seconds and temperature, after two free header lines
# (write_adhoc_csv()); its rmc.* list in p1_state$adhoc_rmc. Made once a
# session.
p1_folder_adhoc <- function() {
  if (is.null(p1_state$adhoc) || !dir.exists(p1_state$adhoc)) {
    d <- tempfile("part1-adhoc-")
    dir.create(d)
    rec <- simulate_recording(hours = 8, sf = 10, seed = 24,
                              tempoffset = c(0.001, -0.002, 0.0005))
    p1_state$adhoc_rmc <- gravcal:::write_adhoc_csv(rec, file.path(d, "h01.csv"), sf = 10,
                                                    unit = "mg", time = "UNIXsec",
                                                    header = c("device,sim", "serial,S1"))
    p1_state$adhoc <- d
  }
  p1_state$adhoc
}

test_that("g.part1() on an ad hoc csv file (rmc.*): GGIR's meta file", {
  skip_if_quick()
  skip_if_not_installed("data.table")
  p1_folder_adhoc()
  args <- c(p1_state$adhoc_rmc, list(do.parallel = FALSE, f1 = 1, chunksize = 0.2,
                                     desiredtz = "Europe/Amsterdam"))
  b <- p1_both(args, folder = p1_folder_adhoc)
  expect_identical(names(b$ggir$part1), "meta_h01.csv.RData")
  expect_same_objects(b$gravcal$part1, b$ggir$part1, "part 1")
  obj <- b$gravcal$part1[[1]]
  expect_identical(obj$I$dformc, 5L)
  expect_gt(nrow(obj$M$metashort), 8 * 700)
  expect_identical(b$gravcal$tab$status, "written")
})

test_that("g.part1() skips done files, leaves others' formats to GGIR, refuses what it does not do", {
  skip_if_not_installed("GGIR")
  d <- tempfile("part1-small-")
  dir.create(d)
  rec <- simulate_recording(hours = 3, sf = 25, seed = 5,
                            start = as.POSIXct("2024-03-04 09:07:23", tz = "UTC"))
  gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), file.path(d, "a.cwa"), sf = 25,
                      start = as.numeric(rec$time[1]), temperature = rec$temperature)
  # listed by GGIR (.wav), read by no reader of gravcal's
  writeBin(as.raw(1:100), file.path(d, "b.wav"))
  out <- tempfile("part1-out-")
  md <- file.path(out, "output_x")
  p1_state$warnings <- NULL
  tab <- p1_quiet0(gravcal::g.part1(d, md, minimumFileSizeMB = 0, do.parallel = FALSE,
                                    verbose = FALSE))
  expect_true(any(grepl("b.wav (a format gravcal does not know)", p1_state$warnings, fixed = TRUE) &
                    grepl("overwrite = FALSE", p1_state$warnings, fixed = TRUE)))
  expect_identical(tab$file, c("b.wav", "a.cwa"))
  expect_identical(tab$status, c("not read", "written"))
  meta <- file.path(md, "meta", "basic", "meta_a.cwa.RData")
  expect_true(file.exists(meta))
  expect_identical(dir(file.path(md, "meta", "basic"), all.files = TRUE, no.. = TRUE),
                   "meta_a.cwa.RData")
  expect_true(dir.exists(file.path(md, "results", "QC")))
  # done: skipped unless overwrite = TRUE
  before <- file.mtime(meta)
  tab <- (p1_quiet0(gravcal::g.part1(d, md, minimumFileSizeMB = 0,
                                                     do.parallel = FALSE, verbose = FALSE)))
  expect_identical(tab$status[tab$file == "a.cwa"], "exists")
  expect_identical(file.mtime(meta), before)
  # too small (GGIR's default minimumFileSizeMB = 2): none left
  expect_error(suppressWarnings(gravcal::g.part1(d, md, verbose = FALSE)), "No files to analyse")
  # GGIR's outputdir naming
  tab <- (p1_quiet0(gravcal::g.part1(d, outputdir = out, minimumFileSizeMB = 0,
                                                     verbose = FALSE)))
  expect_true(file.exists(file.path(out, paste0("output_", basename(d)), "meta", "basic",
                                    "meta_a.cwa.RData")))
  expect_error(gravcal::g.part1(d, md, myfun = list(FUN = mean), verbose = FALSE), "myfun")
  # GGIR's own parameter check stops on Brond's counts here
  expect_error(gravcal::g.part1(d, md, do.brondcounts = TRUE, verbose = FALSE),
               "brondcounts")
  expect_error(gravcal::g.part1(d, verbose = FALSE), "metadatadir")
  expect_error(gravcal::g.part1(file.path(d, "a.cwa"), outputdir = out, verbose = FALSE),
               "studyname")
  # use_trycatch_serial: a file's error is reported, the run goes on
  bad <- file.path(d, "c.cwa")
  writeBin(as.raw(rep(0, 3000)), bad)
  tab <- (p1_quiet0(gravcal::g.part1(d, md, minimumFileSizeMB = 0,
                                                     use_trycatch_serial = TRUE,
                                                     overwrite = TRUE, verbose = FALSE)))
  expect_identical(tab$status[tab$file == "c.cwa"], "failed")
  expect_identical(tab$status[tab$file == "a.cwa"], "written")
})

test_that("GGIR's listing of a folder and of a list of files", {
  d <- tempfile("part1-list-")
  dir.create(file.path(d, "sub"), recursive = TRUE)
  for (f in c("a.cwa", "B.CWA", "sub/c.bin", "d.csv", "e.gt3x", "notes.txt", "f.wav")) {
    writeBin(as.raw(1), file.path(d, f))
  }
  expect_false(gravcal:::part1_is_filelist(d))
  got <- gravcal:::part1_files(d, FALSE)
  if (requireNamespace("GGIR", quietly = TRUE)) {
    expect_identical(got, GGIR::datadir2fnames(d, FALSE)[c("fnames", "fnamesfull")])
  }
  expect_identical(got$fnames[c(1:3, 6)], c("d.csv", "c.bin", "f.wav", "e.gt3x"))
  expect_identical(sort(got$fnames[4:5]), sort(c("a.cwa", "B.CWA")))
  expect_true(gravcal:::part1_is_filelist(file.path(d, "a.cwa")))
  expect_identical(gravcal:::part1_files(file.path(d, c("a.cwa", "sub/c.bin")), TRUE)$fnames,
                   c("a.cwa", "c.bin"))
})

test_that("GGIR's chunksize when it would run files in parallel", {
  skip_if_not_installed("GGIR")
  p <- GGIR::load_params()
  pm <- p$params_metrics
  pr <- p$params_rawdata
  pg <- p$params_general
  cs <- function(..., f1 = 2, cores = 8) {
    gravcal:::part1_parallel_chunksize(utils::modifyList(pm, list(...)), pr, pg, 1, f1, cores)
  }
  expect_identical(cs(), 1)                       # 2 metrics
  expect_identical(cs(do.mad = TRUE), 0.5)        # 3
  expect_identical(cs(do.mad = TRUE, do.en = TRUE, do.bfen = TRUE, do.hfen = TRUE), 0.4)
  expect_identical(cs(do.mad = TRUE, cores = 3), 1)  # GGIR runs serially below 4 cores
  expect_identical(cs(do.mad = TRUE, f1 = 1), 1)     # one file: serially
  pg$do.parallel <- FALSE
  expect_identical(gravcal:::part1_parallel_chunksize(utils::modifyList(pm, list(do.mad = TRUE)),
                                                      pr, pg, 1, 2, 8), 1)
})

test_that("g.part1() runs its files on the session's future plan, as calibrate_files() does", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("future")
  d <- tempfile("part1-plan-")
  dir.create(d)
  for (k in 1:2) {
    rec <- simulate_recording(hours = 3, sf = 25, seed = 40 + k,
                              start = as.POSIXct("2024-03-04 09:07:23", tz = "UTC"))
    gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), file.path(d, sprintf("p%d.cwa", k)),
                        sf = 25, start = as.numeric(rec$time[1]), temperature = rec$temperature)
  }
  run <- function(md) {
    p1_quiet0(gravcal::g.part1(d, md, minimumFileSizeMB = 0, verbose = FALSE))
  }
  seq_md <- file.path(tempfile("part1-seq-"), "output_x")
  tab_seq <- run(seq_md)
  old <- future::plan(future::multisession, workers = 2)
  on.exit(future::plan(old), add = TRUE)
  par_md <- file.path(tempfile("part1-par-"), "output_x")
  tab_par <- run(par_md)
  future::plan(old)
  expect_identical(tab_par$status, c("written", "written"))
  expect_identical(tab_par$message, tab_seq$message)
  expect_true(all(tab_par$seconds > 0))
  # the same meta files, made in other R processes
  expect_identical(p1_objects(file.path(par_md, "meta", "basic")),
                   p1_objects(file.path(seq_md, "meta", "basic")))
  # nothing of the run left beside the meta files
  expect_identical(dir(file.path(par_md, "meta"), all.files = TRUE, no.. = TRUE), "basic")
  # without use_trycatch_serial, a file's error ends the run naming it
  writeBin(as.raw(rep(0, 3000)), file.path(d, "p3.cwa"))
  expect_error(p1_quiet0(gravcal::g.part1(d, seq_md, minimumFileSizeMB = 0, overwrite = TRUE,
                                          use_trycatch_serial = FALSE, verbose = FALSE)),
               "g.part1\\(\\) failed for p3.cwa")
})
