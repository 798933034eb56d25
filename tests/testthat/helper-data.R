# Real recordings live in ../shared/data beside the repository (never in the
# package). The Makefile passes their absolute path as GRAVCAL_SHARED_DATA;
# from a source checkout they are found relative to tests/testthat.
shared_data <- function(...) {
  roots <- c(Sys.getenv("GRAVCAL_SHARED_DATA"),
             file.path("..", "..", "..", "shared", "data"),
             file.path("..", "..", "..", "..", "shared", "data"))
  for (r in roots[nzchar(roots)]) {
    p <- file.path(r, ...)
    if (file.exists(p)) return(normalizePath(p))
  }
  NULL
}

skip_if_no_shared <- function(...) {
  p <- shared_data(...)
  if (is.null(p)) {
    skip(paste0("shared data file ", file.path(...), " not found ",
                "(set GRAVCAL_SHARED_DATA to ../shared/data)"))
  }
  p
}

# Mean | |v| - 1 | of an n x 3 matrix: an independent restatement of the
# calibration error for checks.
err_mg <- function(v) 1000 * mean(abs(sqrt(rowSums(v^2)) - 1))

# A folder for files made by a test, under a fixed name, and a snapshot
# transform that replaces it with "<dir>", so that snapshots of messages
# naming those files do not depend on the session's temporary folder.
snap_dir <- function(name) {
  d <- file.path(tempdir(), name)
  unlink(d, recursive = TRUE)
  dir.create(d)
  d
}

scrub_dir <- function(d) {
  force(d)
  function(x) {
    x <- gsub(d, "<dir>", x, fixed = TRUE)
    gsub(normalizePath(d, winslash = "/", mustWork = FALSE), "<dir>", x,
         fixed = TRUE)
  }
}

# The slow tier: tests that take tens of seconds each, and tests of a few
# seconds (large files, GGIR run beside gravcal, processes started and
# killed) whose path a quicker test still checks in make quick. make quick
# sets GRAVCAL_TEST_TIER=quick and leaves them out (about 3 1/4 minutes on an
# idle 2-core machine; bench/results/test-profile-quick.md); make test and
# R CMD check run them all.
skip_if_quick <- function() {
  if (identical(Sys.getenv("GRAVCAL_TEST_TIER"), "quick")) {
    testthat::skip("slow tier, left out by make quick (GRAVCAL_TEST_TIER=quick)")
  }
}
