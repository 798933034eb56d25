# The header tiers (ARCHITECTURE.md): what mcu.hpp includes, and all
# that those include in turn, is the microcontroller core; it may include
# only C++ standard headers and other headers of that tier (no R, no Eigen,
# no decoders, no GGIR emulation). tests/cpp builds it for a Cortex-M4.
std_headers <- c(
  "algorithm", "array", "cassert", "cfloat", "climits", "cmath", "cstddef",
  "cstdint", "cstdio", "cstdlib", "cstring", "limits", "type_traits",
  "utility", "emmintrin.h", "immintrin.h")

includes_of <- function(path) {
  l <- readLines(path, warn = FALSE)
  l <- grep("^\\s*#\\s*include", l, value = TRUE)
  list(system = sub('^\\s*#\\s*include\\s*<([^>]+)>.*', "\\1",
                    grep("<", l, value = TRUE, fixed = TRUE)),
       local = sub('^\\s*#\\s*include\\s*"([^"]+)".*', "\\1",
                   grep('"', l, value = TRUE, fixed = TRUE)))
}

# a header's local includes, as paths relative to `dir`: the core's headers
# name each other from the include root ("gravcal/kernels/x.hpp" is
# "kernels/x.hpp"); any other spelling is kept as written (and fails below)
local_includes <- function(dir, h) {
  inc <- includes_of(file.path(dir, h))$local
  sub("^gravcal/", "", inc)
}

core_tier <- function(dir) {
  seen <- character(0)
  todo <- "mcu.hpp"
  while (length(todo)) {
    h <- todo[1]
    todo <- todo[-1]
    if (h %in% seen) next
    seen <- c(seen, h)
    todo <- c(todo, local_includes(dir, h))
  }
  seen
}

test_that("the microcontroller core includes only standard headers", {
  dir <- system.file("include", "gravcal", package = "gravcal")
  skip_if(!nzchar(dir), "the package's headers are not installed")
  tier <- core_tier(dir)
  # the core itself, and none of the tiers above it
  expect_true(all(c("model.hpp", "window_cutter.hpp", "stats_streaming.hpp",
                    "bins.hpp", "gradient.hpp", "fixed_point.hpp") %in% tier))
  # not the host's segmenter (R's arithmetic), the vector kernels, the GGIR
  # fit, the decoders or GGIR's procedure
  expect_false(any(c("segmenter.hpp", "stats_r.hpp", "kernels.hpp", "simd.hpp",
                     "icp.hpp", "pipeline.hpp", "ggir_procedure.hpp",
                     "ggir_blocks.hpp", "decode.hpp") %in% tier))
  expect_false(any(startsWith(tier, "kernels/")))
  # gravcal.hpp, the host's umbrella, is the tier and the host's Segmenter
  expect_setequal(local_includes(dir, "gravcal.hpp"), c("mcu.hpp", "segmenter.hpp"))
  for (h in tier) {
    inc <- includes_of(file.path(dir, h))
    expect_identical(setdiff(inc$system, std_headers), character(0),
                     label = paste(h, "includes"))
    expect_identical(setdiff(local_includes(dir, h), tier), character(0),
                     label = paste(h, "includes"))
  }
  # a path from a subfolder resolves to the header it names
  expect_true("simd.hpp" %in% local_includes(dir, "kernels/window.hpp"))
  # the check can fail: a header that includes R's is caught
  f <- tempfile(fileext = ".hpp")
  writeLines(c('#include <Rcpp.h>', '#include "icp.hpp"'), f)
  inc <- includes_of(f)
  expect_identical(setdiff(inc$system, std_headers), "Rcpp.h")
})

test_that("the core's headers include each other one way: \"gravcal/x.hpp\"", {
  dir <- system.file("include", "gravcal", package = "gravcal")
  skip_if(!nzchar(dir), "the package's headers are not installed")
  hs <- list.files(dir, pattern = "[.]hpp$", recursive = TRUE)
  expect_true(length(hs) > 30)
  inc <- unlist(lapply(hs, function(h) includes_of(file.path(dir, h))$local))
  # from the include root (-I.../inst/include), never relative to the file
  expect_identical(inc[!startsWith(inc, "gravcal/")], character(0))
  # and each names a header that is there
  expect_true(all(file.exists(file.path(dirname(dir), inc))))
})
