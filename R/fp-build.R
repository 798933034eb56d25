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
