# The floating-point build of the compiled code. GGIR's numbers are promised
# to the bit, which holds only if the compiler rounded every product and sum
# as R does: no fused multiply-add (gravcal/mcu/fp_contract.hpp pins that where
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
  build_state$r_long_double <- tryCatch(r_accumulator_probe(), error = function(e) TRUE)
  try(gc_set_r_long_double(build_state$r_long_double), silent = TRUE)
}

# R's accumulator. R sums (mean(), sum(), cumsum(), var(), rowSums()) in its
# LDOUBLE type: long double, or double when R was configured with
# --disable-long-double (CRAN's "noLD" check). GGIR computes in R, so the
# compiled replays of R's arithmetic must accumulate as this R does. Read
# from the R it runs in: capabilities("long.double"), checked against R's
# own mean() and sd() of an input whose sums differ between the two
# accumulators (probe_values()); where the two replays agree on it (where
# long double is double anyway: macOS arm64) capabilities() decides.
# TRUE: long double.
r_accumulator_probe <- function() {
  cap <- isTRUE(capabilities("long.double"))
  x <- probe_values()
  r <- c(mean(x), stats::sd(x))
  ld <- gc_r_mean_sd(x, TRUE)
  d <- gc_r_mean_sd(x, FALSE)
  if (identical(ld, d)) return(cap)
  if (identical(r, ld)) return(TRUE)
  if (identical(r, d)) return(FALSE)
  cap
}

# An input whose mean and sd differ between sums in long double and in
# double: 1 followed by values of about 2^-40 (lost in part when added to 1
# in double, kept in the 64 bits of x87's long double), then the same
# values after -1.
probe_values <- function() {
  small <- (1 + (1:64) / 128) * 2^-40
  c(1, small, -1, rev(small) * 3)
}

# Runs `code` with R's accumulator taken as long double (TRUE) or double
# (FALSE), whatever this R has: for the tests of the replay of an R without
# long double on an R with it.
with_r_accumulator <- function(long_double, code) {
  old <- gc_set_r_long_double(long_double)
  on.exit(gc_set_r_long_double(old), add = TRUE)
  force(code)
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
# GGIRread::resample (GGIR-compatible reads of the formats whose registry
# entry says resample_fused: .cwa, GENEActiv, Parmay Matrix, Axivity csv,
# ad hoc csv with rmc.doresample, ...), and "fread_rule" for the csv reads
# that replay data.table::fread's numbers (fread_rule), unless the caller
# gave them.
with_resample_fused <- function(opts, format) {
  compat <- !identical(as.numeric(opts$compat %||% 1), 0)
  entry <- format_entry(format)
  if (isTRUE(entry$resample_fused) && is.null(opts$resample_fused) && compat) {
    opts$resample_fused <- as.numeric(ggir_resample_fused())
  }
  if (isTRUE(entry$fread_rule) && is.null(opts$fread_rule) && compat) {
    opts$fread_rule <- as.numeric(fread_number_rule())
  }
  opts
}

# GGIR reads csv files with data.table::fread, whose value for a number with
# many digits changed in data.table 1.15.0 (its issue 4461): before, the
# digits times a negative power of ten; from it, divided by a positive one,
# in long double both (rule 1 and rule 2 of decode_csv_text.hpp). The two
# differ in the last bit of about one number in ten thousand of 15 digits.
# Which one GGIR gets comes from the installed fread itself, on numbers
# where the two rules differ in this build; where they give the same values
# (a long double with no more bits than double: macOS arm64) the version
# decides, and so it does without data.table (which GGIR needs anyway).
fread_probe_numbers <- c(
  "-6.94352849999999", "6.94352849999999", "1.358931", "-1.10116583029324",
  "0.729435", "1.897258", "3.14159265358979", "-0.999999999999999")

# list(rule = 1 or 2, from = "fread", "version" or "default"), found once
# per session; a warning when the installed fread follows neither rule.
fread_rule_probe <- function() {
  s <- fread_probe_numbers
  r1 <- gc_csv_numbers(s, 1L)
  r2 <- gc_csv_numbers(s, 2L)
  if (!requireNamespace("data.table", quietly = TRUE)) return(list(rule = 2L, from = "default"))
  by_version <- if (utils::packageVersion("data.table") >= "1.15.0") 2L else 1L
  if (identical(r1, r2)) return(list(rule = by_version, from = "version"))
  got <- tryCatch(data.table::fread(text = c("v", s), colClasses = "numeric",
                                    header = TRUE, showProgress = FALSE)[[1]],
                  error = function(e) NULL)
  if (identical(got, r1)) return(list(rule = 1L, from = "fread"))
  if (identical(got, r2)) return(list(rule = 2L, from = "fread"))
  warning("data.table ", format(utils::packageVersion("data.table")),
          " reads numbers by a rule gravcal does not know: numbers in csv files may ",
          "differ from GGIR's in the last bit, and so may GGIR-compatible results.",
          call. = FALSE)
  list(rule = by_version, from = "version")
}

fread_number_rule <- function() {
  if (is.null(build_state$fread_rule)) build_state$fread_rule <- fread_rule_probe()
  build_state$fread_rule$rule
}
