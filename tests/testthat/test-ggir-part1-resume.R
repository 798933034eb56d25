# gravcal::g.part1() killed in the middle of a folder (a cluster job at its
# time limit: SIGKILL, no chance to clean up) and run again: the meta files
# written before the kill are complete and kept, none is half written, the
# second run writes only the rest, and every meta file ends as an
# uninterrupted run writes it.

test_that("g.part1() killed mid-folder resumes: finished files kept, the rest written, same result", {
  skip_on_os("windows")
  skip_if_quick()
  skip_if_not_installed("GGIR")
  d <- tempfile("resume-data-")
  dir.create(d)
  # four recordings of 8 hours (about a second each in g.part1())
  for (k in 1:4) {
    write_meta_recording(file.path(d, sprintf("r%d.cwa", k)), "cwa", 25, 8, 30 + k,
                         "2024-03-04 09:07:23")
  }
  args <- sprintf("datadir = '%s', minimumFileSizeMB = 0, do.parallel = FALSE, verbose = FALSE", d)
  # the reference: one uninterrupted run
  ref <- tempfile("resume-ref-")
  run <- function(metadatadir) {
    gravcal::g.part1(datadir = d, metadatadir = metadatadir, minimumFileSizeMB = 0,
                     do.parallel = FALSE, verbose = FALSE)
  }
  suppressWarnings(utils::capture.output(run(ref)))
  want <- p1_objects(file.path(ref, "meta", "basic"))
  expect_identical(names(want), sprintf("meta_r%d.cwa.RData", 1:4))

  # the run that is killed once its first meta file is there
  md <- tempfile("resume-md-")
  basic <- file.path(md, "meta", "basic")
  script <- tempfile(fileext = ".R")
  writeLines(c(sprintf(".libPaths(c(%s))", paste(deparse(.libPaths()), collapse = "")),
               "suppressWarnings(gravcal::g.part1(",
               sprintf("  %s, metadatadir = '%s'))", args, md)),
             script)
  pidfile <- tempfile()
  rscript <- file.path(R.home("bin"), "Rscript")
  system2("bash", c("-c", shQuote(sprintf("exec '%s' '%s' > /dev/null 2>&1 & echo $! > '%s'",
                                          rscript, script, pidfile))), wait = TRUE)
  pid <- as.integer(readLines(pidfile))
  t0 <- Sys.time()
  while (length(dir(basic, pattern = "^meta_")) == 0 && Sys.time() - t0 < 120) Sys.sleep(0.01)
  tools::pskill(pid, tools::SIGKILL)
  t1 <- Sys.time()
  while (isTRUE(tools::pskill(pid, 0L)) && Sys.time() - t1 < 30) Sys.sleep(0.05)
  done <- dir(basic, pattern = "^meta_")
  # killed in the middle: at least one file written, not all
  expect_gte(length(done), 1)
  expect_lt(length(done), 4)
  # what GGIR's part 2 lists in meta/basic is only whole meta files (a temp
  # file the kill left behind is hidden)
  expect_identical(dir(basic), done)
  kept <- file.mtime(file.path(basic, done))

  # the second run: the finished files skipped, the others written
  tab <- NULL
  suppressWarnings(utils::capture.output(tab <- run(md)))
  st <- stats::setNames(tab$status, tab$file)
  expect_identical(unname(st[sub("^meta_(.*)[.]RData$", "\\1", done)]), rep("exists", length(done)))
  expect_identical(sum(st == "written"), 4L - length(done))
  expect_identical(file.mtime(file.path(basic, done)), kept)
  expect_identical(p1_objects(basic), want)
})
