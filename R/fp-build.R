# The floating-point build of the compiled code. GGIR's numbers are promised
# to the bit, which holds only if the compiler rounded every product and sum
# as R does: no fused multiply-add (gravcal/fp_contract.hpp pins that where
# the compiler lets it) and no -ffast-math. The package probes its own build
# when it loads and refuses the GGIR-compatible procedure from a build that
# breaks the rule, rather than return numbers that only look like GGIR's.

build_state <- new.env(parent = emptyenv())

# a * b is 1 - 2^-60, which rounds to 1: unfused, a * b + c is 0 (R computes
# it so, one operation at a time); fused, it is -2^-60.
fp_probe_operands <- c(a = 1 + 2^-30, b = 1 - 2^-30, c = -1)

# What the compiled code does with a * b + c, beside R.
fp_probe <- function() {
  o <- fp_probe_operands
  r <- gc_fp_probe(o[["a"]], o[["b"]], o[["c"]])
  list(fused = !identical(r$value, o[["a"]] * o[["b"]] + o[["c"]]),
       fast_math = isTRUE(r$fast_math))
}

.onLoad <- function(libname, pkgname) {
  # never fails: an error here leaves the probe to the first use
  build_state$fp <- tryCatch(fp_probe(), error = function(e) NULL)
}

# Stops when the build cannot give GGIR's bits; `what` names the caller.
check_fp_build <- function(what) {
  fp <- build_state$fp
  if (is.null(fp)) fp <- build_state$fp <- fp_probe()
  why <- c(if (isTRUE(fp$fused)) "fuses multiply-adds (-ffp-contract=fast)",
           if (isTRUE(fp$fast_math)) "uses -ffast-math")
  if (length(why)) {
    abort(what, " cannot give GGIR's numbers to the bit: gravcal was compiled ",
          "with flags that change floating-point rounding (its build ",
          paste(why, collapse = " and "), "). Remove -ffp-contract=fast, ",
          "-ffast-math and -Ofast from CXX17FLAGS and CXXFLAGS in ",
          "~/.R/Makevars (or R_MAKEVARS_USER) and reinstall gravcal; R's ",
          "default flags, and -O3 -march=native, are fine.")
  }
  invisible(TRUE)
}

# GGIR's Axivity (.cwa and csv exports) and GENEActiv-at-a-fractional-rate
# samples come through GGIRread::resample(), C++ compiled by the R it runs
# in with that R's flags: where its compiler contracts u * (v1 - v0) + v0
# into one fused multiply-add (GCC's default, -ffp-contract=fast, on
# aarch64), GGIR's samples are rounded once there, and gravcal's replay
# must round them once too. Which it is comes from this R, never from the
# processor's name: GGIRread::resample() itself on operands where the two
# differ, when GGIRread is installed (it is what GGIR calls); otherwise a
# probe compiled as GGIRread's code is, without gravcal's contraction pin
# (src/fp_probe_ggirread.cpp).
#
# u = 1 - 2^-30 and the values -1, 2^-30 (their difference 1 + 2^-30,
# exact): u times it is 1 - 2^-60, which rounds to 1, so the result is 0
# rounded twice and -2^-60 fused.
resample_probe_operands <- list(u = 1 - 2^-30, v = c(-1, 2^-30))

# list(fused, from = "GGIRread" or "compiler"), found once per session.
resample_probe <- function() {
  o <- resample_probe_operands
  got <- NULL
  if (requireNamespace("GGIRread", quietly = TRUE)) {
    got <- tryCatch(GGIRread::resample(matrix(o$v, 2, 1), c(0, 1), o$u, 2L, 1L),
                    error = function(e) NULL)
    got <- if (length(got) == 1 && is.finite(got)) as.vector(got) else NULL
  }
  from <- "GGIRread"
  if (is.null(got)) {
    got <- gc_fp_probe_unpinned(matrix(o$v, 2, 1), o$u)
    from <- "compiler"
  }
  list(fused = !identical(got, 0), from = from)
}

ggir_resample_fused <- function() {
  if (is.null(build_state$resample)) build_state$resample <- resample_probe()
  isTRUE(build_state$resample$fused)
}

# The decoder options with "resample_fused" added for the reads that replay
# GGIRread::resample (GGIR-compatible .cwa, GENEActiv and Axivity csv), unless
# the caller gave it.
with_resample_fused <- function(opts, format) {
  if (format %in% c("cwa", "geneactiv", "axivity_csv") && is.null(opts$resample_fused) &&
      !identical(as.numeric(opts$compat %||% 1), 0)) {
    opts$resample_fused <- as.numeric(ggir_resample_fused())
  }
  opts
}
