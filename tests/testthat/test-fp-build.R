# The floating-point build: the load-time probe of contraction
# (src/fp_probe.cpp, R/fp-build.R), and the refusal of the GGIR-compatible
# procedure from a build that would not give GGIR's bits. `make flags-check`
# builds the package with aggressive flags for real; here the probe's
# verdict is replaced to test the refusal.

# Replaces the probe's verdict until the calling test (or local()) ends.
local_fp_verdict <- function(fused, fast_math = FALSE, env = parent.frame()) {
  st <- gravcal:::build_state
  old <- st$fp
  st$fp <- list(fused = fused, fast_math = fast_math)
  restore <- function() st$fp <- old
  do.call(on.exit, list(as.call(list(restore)), add = TRUE), envir = env)
}

test_that("the probe's operands tell a fused multiply-add from two roundings", {
  o <- gravcal:::fp_probe_operands
  # a * b = (1 + 2^-30)(1 - 2^-30) = 1 - 2^-60 exactly, closer to 1 than
  # half a unit below it (2^-54): rounded, 1, so a * b + c is 0; fused, -2^-60
  expect_identical(o[["a"]] * o[["b"]], 1)
  expect_identical(o[["a"]] * o[["b"]] + o[["c"]], 0)
})

test_that("this build does not fuse, and the verdict is the one taken at load", {
  p <- gravcal:::fp_probe()
  expect_false(p$fused)
  expect_false(p$fast_math)
  expect_identical(gravcal:::build_state$fp, p)
  # the compiled expression itself: 0, not -2^-60
  o <- gravcal:::fp_probe_operands
  expect_identical(gravcal:::gc_fp_probe(o[["a"]], o[["b"]], o[["c"]])$value, 0)
})

test_that("a fused build refuses GGIR's procedure, and says how to reinstall", {
  rec <- simulate_recording(hours = 2, sf = 10, seed = 5)
  local_fp_verdict(fused = TRUE)
  expect_snapshot(error = TRUE, g.calibrate(rec, sf = 10, verbose = FALSE))
  expect_snapshot(error = TRUE,
                  calibrate(rec, sf = 10, method = "ggir", ggir_compat = TRUE))
  # gravcal's own mode and the lightweight method promise no GGIR bits
  expect_s3_class(calibrate(rec, sf = 10, method = "ggir"), "gravcal_fit")
  expect_s3_class(calibrate(rec, sf = 10), "gravcal_fit")
})

test_that("a -ffast-math build refuses too; the verdict comes back after", {
  rec <- simulate_recording(hours = 2, sf = 10, seed = 5)
  local({
    local_fp_verdict(fused = FALSE, fast_math = TRUE)
    expect_error(g.calibrate(rec, sf = 10, verbose = FALSE), "uses -ffast-math")
  })
  expect_false(gravcal:::build_state$fp$fused)
  expect_type(g.calibrate(rec, sf = 10, verbose = FALSE)$QCmessage, "character")
})

test_that("the resampling probe's operands tell GGIRread's fused step from two roundings", {
  o <- gravcal:::resample_probe_operands
  # (1 - 2^-30)(1 + 2^-30) = 1 - 2^-60 exactly, rounded 1: R's u * (v1 - v0)
  # + v0 is 0; one fused multiply-add gives -2^-60
  expect_identical(o$v[2] - o$v[1], 1 + 2^-30)
  expect_identical(o$u * (o$v[2] - o$v[1]) + o$v[1], 0)
  v <- gravcal:::gc_fp_probe_unpinned(matrix(o$v, 2, 1), o$u)
  expect_true(identical(v, 0) || identical(v, -2^-60))
})

test_that("gravcal's replay of GGIRread::resample rounds as GGIRread's compiled code does here", {
  skip_if_not_installed("GGIRread")
  fused <- gravcal:::ggir_resample_fused()
  o <- gravcal:::resample_probe_operands
  g <- GGIRread::resample(matrix(o$v, 2, 1), c(0, 1), o$u, 2L, 1L)[1, 1]
  expect_identical(fused, !identical(g, 0))
  expect_identical(gravcal:::build_state$resample$from, "GGIRread")
  # irregular samples onto a 100 Hz grid, as readAxivity resamples a block:
  # GGIRread's own function against gravcal's kernel (the scalar reference,
  # which the decoders use when `fused`), and the other rounding differs
  set.seed(30)
  n <- 400
  tm <- 1.7e9 + cumsum(c(0, stats::runif(n, 0.006, 0.014)))
  v <- matrix(stats::rnorm(3 * (n + 1)), n + 1, 3)
  grid <- seq(tm[1], tm[n + 1], by = 0.01)
  ref <- GGIRread::resample(v, tm, grid, as.integer(n + 1), 1L)
  ours <- function(f) {
    gravcal:::gc_kernel_check("cwa_interp", list(
      time = tm, x = v[, 1], y = v[, 2], z = v[, 3], start = tm[1], step = 0.01,
      end = Inf, temp = 0, pos = 0, stop = length(grid), source = 1L, fused = f))$scalar
  }
  same <- ours(fused)
  expect_identical(same$written, as.numeric(nrow(ref)))
  expect_identical(cbind(same$x, same$y, same$z), unname(ref))
  other <- ours(!fused)
  expect_false(identical(cbind(other$x, other$y, other$z), unname(ref)))
})
