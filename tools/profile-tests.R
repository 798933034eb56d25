# Times the testthat suite of the installed gravcal, file by file and test by
# test (make profile-tests, make profile-quick): writes a table of the files
# and of the slowest tests.
# Usage (from tests/testthat): Rscript ../../tools/profile-tests.R OUT.md
# GRAVCAL_TEST_TIER and GRAVCAL_TEST_FILTER as for tools/run-tests.R.
#
# Each file's wall time and its CPU time (user + system, of this R process
# and of the child processes it waited for: Rscript, a compiler, callr; not
# of the workers of a PSOCK cluster, which outlive the test): on a machine
# shared with other jobs the wall time grows with the load, the CPU time much
# less, so the CPU time is the better estimate of an idle machine's wall time
# for the files that run one process at a time. And the wall time less the
# time this R process waited, runnable, for a core (its run-queue wait, from
# /proc/self/schedstat on Linux): what the file would take were this process
# never kept waiting by other jobs, an upper estimate of an idle machine's
# wall time (it still counts the waits of child processes). The load average
# (1 min) at the start and end of each file is kept beside it.
suppressPackageStartupMessages({
  library(testthat)
  library(gravcal)
})
out <- commandArgs(TRUE)[1]
filter <- Sys.getenv("GRAVCAL_TEST_FILTER")
tier <- Sys.getenv("GRAVCAL_TEST_TIER", "full")
if (!nzchar(tier)) tier <- "full"

loadavg <- function() {
  l <- tryCatch(readLines("/proc/loadavg", warn = FALSE), error = function(e) NA)
  as.numeric(strsplit(l, " ")[[1]][1])
}
# seconds this process has waited, runnable, for a core (NA off Linux)
runq <- function() {
  l <- tryCatch(readLines("/proc/self/schedstat", warn = FALSE), error = function(e) NA)
  as.numeric(strsplit(l, " ")[[1]][2]) / 1e9
}
cpu_of <- function(p) sum(p[c("user.self", "sys.self", "user.child", "sys.child")], na.rm = TRUE)

# a reporter that times each file (start_file to end_file) and prints a line
# per file as it ends
FileTimer <- R6::R6Class("FileTimer", inherit = testthat::Reporter,
  public = list(
    file = NULL, t0 = NULL, q0 = NA, l0 = NA, rows = list(),
    start_file = function(filename) {
      self$file <- filename
      self$l0 <- loadavg()
      self$q0 <- runq()
      self$t0 <- proc.time()
    },
    end_file = function() {
      d <- proc.time() - self$t0
      row <- data.frame(file = self$file, wall = d[["elapsed"]], cpu = cpu_of(d),
                        ready = d[["elapsed"]] - (runq() - self$q0),
                        load0 = self$l0, load1 = loadavg())
      self$rows[[length(self$rows) + 1L]] <- row
      cat(sprintf("%-32s %7.1f s wall %7.1f s cpu %7.1f s unqueued  load %.1f-%.1f\n",
                  row$file, row$wall, row$cpu, row$ready, row$load0, row$load1),
          file = stderr())
    }
  ))
timer <- FileTimer$new()

l_start <- loadavg()
q_start <- runq()
t0 <- proc.time()
res <- as.data.frame(test_dir(".", reporter = timer, stop_on_failure = FALSE,
                              package = "gravcal", load_package = "installed",
                              filter = if (nzchar(filter)) filter))
d <- proc.time() - t0
total <- d[["elapsed"]]
total_cpu <- cpu_of(d)
total_ready <- total - (runq() - q_start)
l_end <- loadavg()

files <- do.call(rbind, timer$rows)
res$ran <- !res$skipped
counts <- aggregate(cbind(tests = 1, ran = res$ran) ~ file, res, sum)
by_file <- merge(files, counts, by = "file", all.x = TRUE)
by_file[is.na(by_file)] <- 0
by_file <- by_file[order(-by_file$cpu), ]
res$cpu <- res$user + res$system
ran <- res[res$ran, ]
by_test <- ran[order(-ran$cpu), c("file", "test", "real", "cpu")][seq_len(min(40, nrow(ran))), ]

lines <- c(
  sprintf("# Test suite profile (%s, tier %s)", format(Sys.time(), "%Y-%m-%d"), tier),
  "",
  sprintf("R %s, %s, %d cores; total %.0f s wall, %.0f s CPU (user + system, with waited-for children), %.0f s wall less run-queue wait; %d tests (%d run, %d skipped) in %d files, %d failed; load average %.1f at the start, %.1f at the end.",
          getRversion(), R.version$platform, parallel::detectCores(), total, total_cpu, total_ready,
          nrow(res), sum(res$ran), sum(!res$ran), nrow(by_file),
          sum(res$failed) + sum(res$error), l_start, l_end),
  "", "## By file (by CPU time)", "",
  "| file | tests | run | wall s | CPU s | wall less run-queue wait s | share of CPU | load at start-end |",
  "|---|---|---|---|---|---|---|---|",
  sprintf("| %s | %d | %d | %.1f | %.1f | %.1f | %.1f %% | %.1f-%.1f |", by_file$file,
          as.integer(by_file$tests), as.integer(by_file$ran), by_file$wall, by_file$cpu,
          by_file$ready, 100 * by_file$cpu / sum(by_file$cpu), by_file$load0, by_file$load1),
  "", sprintf("## The %d slowest tests (by CPU time of this process)", nrow(by_test)), "",
  "| file | test | wall s | CPU s |", "|---|---|---|---|",
  sprintf("| %s | %s | %.1f | %.1f |", by_test$file, gsub("|", "\\|", by_test$test, fixed = TRUE),
          by_test$real, by_test$cpu))
bad <- res[res$failed > 0 | res$error, c("file", "test")]
if (nrow(bad)) {
  lines <- c(lines, "", "## Failed", "", sprintf("- %s: %s", bad$file, bad$test))
}
writeLines(lines, out)
# GRAVCAL_PROFILE_RDS: the tables themselves too (for comparing runs)
rds <- Sys.getenv("GRAVCAL_PROFILE_RDS")
if (nzchar(rds)) saveRDS(list(tests = res, files = by_file, wall = total, cpu = total_cpu,
                           ready = total_ready), rds)
cat(lines[1:3], sep = "\n")
