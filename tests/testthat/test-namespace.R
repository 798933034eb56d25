# gravcal's exports do not mask the functions of packages its users attach
# beside it (r-lib, the GGIR ecosystem, base R); g.calibrate() masks
# GGIR's on purpose: it is the drop-in (so do g.getmeta and g.part1).
test_that("exports clash with no common package's, g.calibrate aside", {
  ours <- getNamespaceExports("gravcal")
  pkgs <- c("base", "stats", "utils", "graphics", "grDevices", "methods",
            "cli", "rlang", "testthat", "withr", "fs", "glue", "purrr",
            "dplyr", "tibble", "data.table", "future", "future.apply",
            "progressr", "GGIR", "GGIRread", "read.gt3x", "signal")
  seen <- 0
  for (p in pkgs) {
    if (!requireNamespace(p, quietly = TRUE)) next
    seen <- seen + 1
    clash <- setdiff(intersect(ours, getNamespaceExports(p)),
                     if (p == "GGIR") c("g.calibrate", "g.getmeta", "g.part1"))
    expect_identical(clash, character(0), label = paste("clash with", p))
  }
  expect_gt(seen, 10)
  expect_false("cli" %in% ours)
})
