# The header tiers (ARCHITECTURE.md), one folder each under
# inst/include/gravcal/: mcu/ (the microcontroller core), host/ (the host's
# segmenter), kernels/ (vector kernels), decoders/, ggir/ (the pipeline and
# GGIR's emulation); at the top only the umbrellas a user includes,
# gravcal.hpp and mcu.hpp. What mcu.hpp includes, and all that those include
# in turn, is the microcontroller core: the headers of mcu/, which may
# include only C++ standard headers and each other (no R, no Eigen, no
# decoders, no GGIR emulation). tests/cpp builds it for a Cortex-M4.
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
# name each other from the include root ("gravcal/mcu/<name>.hpp" is
# "mcu/<name>.hpp"); any other spelling is kept as written (and fails below)
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
  mcu <- file.path("mcu", list.files(file.path(dir, "mcu"), pattern = "[.]hpp$"))
  # the core itself, and none of the tiers above it
  expect_true(all(file.path("mcu", c("model.hpp", "window_cutter.hpp",
                                     "stats_streaming.hpp", "bins.hpp",
                                     "gradient.hpp", "fixed_point.hpp")) %in% tier))
  # mcu.hpp reaches the whole of mcu/ and nothing outside it: not the host's
  # segmenter (R's arithmetic), the vector kernels, the GGIR fit, the
  # decoders or GGIR's procedure
  expect_setequal(tier, c("mcu.hpp", mcu))
  expect_false(any(c("host/segmenter.hpp", "host/stats_r.hpp",
                     "kernels/kernels.hpp", "kernels/simd.hpp", "ggir/icp.hpp",
                     "ggir/pipeline.hpp", "ggir/ggir_procedure.hpp",
                     "ggir/ggir_blocks.hpp", "ggir/ggir_window_table.hpp",
                     "ggir/ggir_config.hpp", "decoders/decode.hpp") %in% tier))
  # at the top, only the umbrellas; gravcal.hpp, the host's, is the tier
  # and the host's Segmenter
  expect_setequal(list.files(dir, pattern = "[.]hpp$"), c("gravcal.hpp", "mcu.hpp"))
  expect_setequal(local_includes(dir, "gravcal.hpp"), c("mcu.hpp", "host/segmenter.hpp"))
  # every header of mcu/ (reached or not) includes only standard headers
  # and mcu/'s own
  for (h in union(tier, mcu)) {
    inc <- includes_of(file.path(dir, h))
    expect_identical(setdiff(inc$system, std_headers), character(0),
                     label = paste(h, "includes"))
    expect_identical(setdiff(local_includes(dir, h), mcu), character(0),
                     label = paste(h, "includes"))
  }
  # a path into a folder resolves to the header it names
  expect_true("kernels/simd.hpp" %in% local_includes(dir, "kernels/window.hpp"))
  # the check can fail: a header that includes R's is caught, and so is a
  # header of mcu/ that includes another tier's
  f <- tempfile(fileext = ".hpp")
  writeLines(c('#include <Rcpp.h>', '#include "gravcal/host/r_arith.hpp"'), f)
  inc <- includes_of(f)
  expect_identical(setdiff(inc$system, std_headers), "Rcpp.h")
  expect_identical(setdiff(sub("^gravcal/", "", inc$local), mcu), "host/r_arith.hpp")
})

test_that("the core's headers include each other one way: \"gravcal/<tier>/<name>.hpp\"", {
  dir <- system.file("include", "gravcal", package = "gravcal")
  skip_if(!nzchar(dir), "the package's headers are not installed")
  hs <- list.files(dir, pattern = "[.]hpp$", recursive = TRUE)
  expect_true(length(hs) > 30)
  # each in its tier's folder, or an umbrella at the top
  expect_identical(setdiff(dirname(hs), c(".", "mcu", "host", "kernels", "decoders", "ggir")),
                   character(0))
  inc <- unlist(lapply(hs, function(h) includes_of(file.path(dir, h))$local))
  # from the include root (-I.../inst/include), never relative to the file
  expect_identical(inc[!startsWith(inc, "gravcal/")], character(0))
  # and each names a header that is there
  expect_true(all(file.exists(file.path(dirname(dir), inc))))
})

test_that("the tiers' folders include one another one way", {
  dir <- system.file("include", "gravcal", package = "gravcal")
  skip_if(!nzchar(dir), "the package's headers are not installed")
  # each folder may include its own headers and those of the folders before it
  order <- c("mcu", "kernels", "host", "decoders", "ggir")
  hs <- list.files(dir, pattern = "[.]hpp$", recursive = TRUE)
  hs <- hs[dirname(hs) != "."]
  rank_of <- function(h) match(dirname(h), order)
  for (h in hs) {
    inc <- local_includes(dir, h)
    expect_true(all(rank_of(inc) <= rank_of(h)), label = paste(h, "includes", toString(inc)))
  }
  # the microcontroller's umbrella: mcu/ only
  expect_true(all(dirname(local_includes(dir, "mcu.hpp")) == "mcu"))
  # the check can fail: a kernel that included the host's arithmetic
  expect_false(rank_of("host/r_arith.hpp") <= rank_of("kernels/window.hpp"))
})
