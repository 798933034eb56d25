# A long fit stops on Ctrl-C (SIGINT) within moments, instead of when the C++
# call returns: the glue checks for interrupts through the core's observer.
# Starts `code` (which defines run()) in a separate R process, sends it
# SIGINT `wait` seconds after run() started, and returns how long after the
# signal R had the interrupt in hand (the child writes the clock's time from
# its interrupt handler: the process's exit, which includes its teardown, is
# slow under AddressSanitizer and is not what is measured), and whether run()
# finished or was interrupted.
interrupt_after <- function(code, wait = 2) {
  skip_on_os("windows")
  out <- tempfile()
  script <- tempfile(fileext = ".R")
  writeLines(c(
    "suppressPackageStartupMessages(library(gravcal))",
    "set.seed(1)",
    code,
    sprintf("out <- '%s'", out),
    "writeLines('ready', out)",
    "tryCatch({ run(); writeLines(c('ready', 'finished'), out) },",
    "  interrupt = function(e) writeLines(c('ready', 'interrupted',",
    "    format(as.numeric(Sys.time()), digits = 17)), out))"),
    script)
  rscript <- file.path(R.home("bin"), "Rscript")
  pidfile <- tempfile()
  system2("bash", c("-c", shQuote(sprintf("exec '%s' '%s' > /dev/null 2>&1 & echo $! > '%s'",
                                          rscript, script, pidfile))), wait = TRUE)
  pid <- as.integer(readLines(pidfile))
  alive <- function() isTRUE(tools::pskill(pid, 0L))
  t0 <- Sys.time()
  while (!file.exists(out) && Sys.time() - t0 < 60) Sys.sleep(0.05)
  Sys.sleep(wait)
  expect_true(alive())
  t1 <- as.numeric(Sys.time())
  tools::pskill(pid, tools::SIGINT)
  while (alive() && as.numeric(Sys.time()) - t1 < 120) Sys.sleep(0.05)
  if (alive()) tools::pskill(pid, tools::SIGKILL)
  lines <- readLines(out)
  list(outcome = if (length(lines) > 1) lines[2] else "killed",
       seconds = if (length(lines) > 2) as.numeric(lines[3]) - t1 else NA_real_)
}

test_that("Ctrl-C stops a long gradient fit", {
  # a million iterations on 500 points: about 2 minutes without the interrupt
  res <- interrupt_after(c(
    "pts <- simulate_points(500, noise = 0.001)",
    "run <- function() fit_gradient(pts, max_iter = 1e6, tol = 0)"))
  expect_identical(res$outcome, "interrupted")
  expect_lt(res$seconds, 3)
})

test_that("Ctrl-C stops a long ICP fit", {
  # 20,000 windows, up to a million iterations with tol = 0
  res <- interrupt_after(c(
    "v <- simulate_points(20000, noise = 0.002)",
    "run <- function() fit_icp(v, use_temp = FALSE, max_iter = 1e6, tol = 0)"))
  expect_identical(res$outcome, "interrupted")
  expect_lt(res$seconds, 3)
})
