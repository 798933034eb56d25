# Runs the testthat suite of the installed gravcal from tests/testthat and
# exits with status 1 on any failure (used by `make sanitize` and
# `make test-noLD`).
suppressPackageStartupMessages({
  library(testthat)
  library(gravcal)
})
# the tests see the package namespace (internal helpers such as the file
# writers), as under R CMD check
# GRAVCAL_TEST_FILTER: only the files whose name (without test- and .R)
# matches this regular expression (make test-noLD)
filter <- Sys.getenv("GRAVCAL_TEST_FILTER")
# every failure printed, not the first ten
options(testthat.summary.max_reports = 10000L)
res <- as.data.frame(test_dir(".", reporter = "summary", stop_on_failure = FALSE,
                              package = "gravcal", load_package = "installed",
                              filter = if (nzchar(filter)) filter))
bad <- sum(res$failed) + sum(res$error)
cat(sprintf("\n%d tests in %d files, %d expectations; %d failed\n", nrow(res),
            length(unique(res$file)), sum(res$nb), bad))
if (bad > 0) quit(status = 1)
