# Times the testthat suite of the installed gravcal, file by file and test by
# test (make profile-tests): writes a table of the slowest files and tests.
# Usage (from tests/testthat): Rscript ../../tools/profile-tests.R OUT.md
suppressPackageStartupMessages({
  library(testthat)
  library(gravcal)
})
out <- commandArgs(TRUE)[1]
filter <- Sys.getenv("GRAVCAL_TEST_FILTER")
t0 <- proc.time()[["elapsed"]]
res <- as.data.frame(test_dir(".", reporter = "silent", stop_on_failure = FALSE,
                              package = "gravcal", load_package = "installed",
                              filter = if (nzchar(filter)) filter))
total <- proc.time()[["elapsed"]] - t0
by_file <- aggregate(cbind(real = res$real, tests = 1) ~ file, res, sum)
by_file <- by_file[order(-by_file$real), ]
by_test <- res[order(-res$real), c("file", "test", "real")][1:min(40, nrow(res)), ]
lines <- c(
  sprintf("# Test suite profile (%s, tier %s)", format(Sys.time(), "%Y-%m-%d"),
          Sys.getenv("GRAVCAL_TEST_TIER", "full")),
  "",
  sprintf("R %s, %s; total %.0f s wall (testthat's sum of tests: %.0f s), %d tests, %d failed.",
          getRversion(), R.version$platform, total, sum(res$real), nrow(res),
          sum(res$failed) + sum(res$error)),
  "", "## By file", "", "| file | tests | seconds | share |", "|---|---|---|---|",
  sprintf("| %s | %d | %.1f | %.1f %% |", by_file$file, as.integer(by_file$tests),
          by_file$real, 100 * by_file$real / sum(res$real)),
  "", "## The 40 slowest tests", "", "| file | test | seconds |", "|---|---|---|",
  sprintf("| %s | %s | %.1f |", by_test$file, gsub("|", "\\|", by_test$test, fixed = TRUE),
          by_test$real))
bad <- res[res$failed > 0 | res$error, c("file", "test")]
if (nrow(bad)) {
  lines <- c(lines, "", "## Failed", "", sprintf("- %s: %s", bad$file, bad$test))
}
writeLines(lines, out)
cat(lines[1:3], sep = "\n")
