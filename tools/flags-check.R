# `make flags-check`: gravcal installed with a user's aggressive compiler
# flags (the Makefile's R_MAKEVARS_USER), against GGIR. Run from the
# repository's root with R_LIBS pointing at that installation.
#   Rscript tools/flags-check.R bits    the build does not fuse multiply-adds
#     (the pin in gravcal/mcu/fp_contract.hpp won over the flags), and
#     g.calibrate() gives GGIR's result, to the bit, on real files
#   Rscript tools/flags-check.R refuse  the flags beat the pin (clang's
#     -ffp-contract=fast): the load-time probe says so, and both
#     GGIR-compatible entries refuse with the message that says how to
#     reinstall, while gravcal's own mode still runs
# Any difference or failed expectation stops with an error (exit status 1).
suppressPackageStartupMessages({
  library(testthat)
  library(gravcal)
})
mode <- commandArgs(trailingOnly = TRUE)[1]
if (!mode %in% c("bits", "refuse")) stop("usage: flags-check.R bits|refuse")
# the test suite's helpers: run_both() (GGIR and gravcal on one file, with
# GGIR's parameters), expect_same_as_ggir() (every number identical()),
# shared_data()
for (h in c("helper-ggir-cache.R", "helper-ggir.R", "helper-data.R")) {
  source(file.path("tests", "testthat", h))
}
fp <- gravcal:::build_state$fp
cat("probe of the build: a * b + c", if (isTRUE(fp$fused)) "fused" else "not fused",
    if (isTRUE(fp$fast_math)) "(-ffast-math)", "\n")
ggirread <- function(name) system.file("testfiles", name, package = "GGIRread")

if (mode == "refuse") {
  expect_true(isTRUE(fp$fused) || isTRUE(fp$fast_math))
  f <- ggirread("ax3_testfile.cwa")
  expect_error(gravcal::g.calibrate(f, verbose = FALSE),
               "cannot give GGIR's numbers to the bit.*reinstall gravcal")
  expect_error(calibrate(f, method = "ggir", ggir_compat = TRUE),
               "ggir_compat = TRUE.*reinstall gravcal")
  expect_s3_class(calibrate(f, method = "ggir"), "gravcal_fit")
  cat("refused: g.calibrate() and calibrate(ggir_compat = TRUE); gravcal's",
      "own mode runs\n")
  quit(save = "no")
}

expect_false(fp$fused)
expect_false(fp$fast_math)
check <- function(label, f, params = list()) {
  b <- run_both(f, params)
  expect_same_as_ggir(b)
  n <- if (length(b$ggir$npoints)) b$ggir$npoints else 0
  cat(sprintf("identical to GGIR: %s (%d rest windows; %s)\n", label,
              as.integer(n), b$ggir$QCmessage))
}
# GGIRread's own device files (short: GGIR's outcome is "not enough data")
check("GGIRread ax3_testfile.cwa", ggirread("ax3_testfile.cwa"))
check("GGIRread GENEActiv_testfile.bin", ggirread("GENEActiv_testfile.bin"))
# a real 20.7 h ActiGraph recording (agcounts, see ../shared/data/README.md)
# as an ActiGraph csv: a fit on real rest windows
d <- shared_data("agcounts", "calibrationXaxis.RData")
if (is.null(d)) stop("../shared/data not found: set GRAVCAL_SHARED_DATA")
env <- new.env()
for (v in c("X", "Y", "Z")) {
  load(file.path(dirname(d), paste0("calibration", v, "axis.RData")), envir = env)
}
f <- tempfile(fileext = ".csv")
gravcal:::write_actigraph_csv(data.frame(x = env$X, y = env$Y, z = env$Z), f,
                              sf = 30)
check("agcounts recording, ActiGraph csv", f)
unlink(f)
# a 30 h GENEActiv .bin with a temperature term, three of GGIR's blocks
rec <- simulate_recording(hours = 30, sf = 20, seed = 21,
                          tempoffset = c(0.002, -0.001, 0.0015))
f <- tempfile(fileext = ".bin")
gravcal:::write_geneactiv_bin(rec, f, sf = 20)
check("simulated 30 h GENEActiv .bin with temperature", f)
unlink(f)
