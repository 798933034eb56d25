# The core's AVX2 paths (inst/include/gravcal/kernels/simd.hpp) against its baseline
# ones: where the processor has AVX2 they run by default, and they must give
# the same bits. gc_set_avx2(FALSE) turns them off for one side of each
# comparison. On a processor without AVX2 there is nothing to compare.

with_avx2 <- function(on, expr) {
  old <- gc_set_avx2(TRUE)  # whether the processor has them
  on.exit(gc_set_avx2(old))
  gc_set_avx2(on)
  expr
}

skip_if_no_avx2 <- function() {
  has <- gc_set_avx2(TRUE)
  if (!has) skip("the processor has no AVX2: only the baseline paths run here")
}

both_ways <- function(f) {
  list(avx2 = with_avx2(TRUE, f()), baseline = with_avx2(FALSE, f()))
}

decode_all <- function(file, format, compat, chunk) {
  d <- native_read_all(file, format, list(compat = compat), time = TRUE, chunk = chunk)
  list(data = d, report = attr(d, "report"))
}

test_that("the switch turns the AVX2 paths off and back on", {
  skip_if_no_avx2()
  expect_false(gc_set_avx2(FALSE))
  expect_true(gc_set_avx2(TRUE))
})

test_that("GRAVCAL_NO_AVX2 in the environment turns them off for the process", {
  skip_if_no_avx2()
  ask <- function(value) {
    env <- if (is.null(value)) character(0) else paste0("GRAVCAL_NO_AVX2=", value)
    out <- system2(file.path(R.home("bin"), "Rscript"),
                   c("-e", shQuote("cat(gravcal:::gc_use_avx2())")),
                   stdout = TRUE, stderr = FALSE, env = env)
    utils::tail(out, 1)
  }
  old <- Sys.getenv("GRAVCAL_NO_AVX2", unset = NA)
  Sys.unsetenv("GRAVCAL_NO_AVX2")
  on.exit(if (!is.na(old)) Sys.setenv(GRAVCAL_NO_AVX2 = old))
  expect_identical(ask(NULL), "TRUE")
  expect_identical(ask("0"), "TRUE")
  expect_identical(ask("1"), "FALSE")
})

test_that(".cwa: compatible and raw decoding are the same bits with and without AVX2", {
  skip_if_no_avx2()
  files <- c(system.file("testfiles", "ax3_testfile.cwa", package = "GGIRread"),
             system.file("testfiles", "ax6_testfile.cwa", package = "GGIRread"),
             system.file("testfiles", "ax3_testfile_corrupt_blocks_0_13_14_142_143_144.cwa",
                         package = "GGIRread"))
  files <- files[nzchar(files)]
  # synthetic: a rate a little off the header's (the grid meets the same or
  # a skipped interval now and then), a skipped block (imputed), a gap
  n <- 120 * 200
  tt <- seq_len(n) / 100
  x <- cbind(sin(tt), 0.9 * cos(tt), 0.3 + 0.1 * sin(3 * tt))
  tm <- 1.7e9 + 0.25 + (seq_len(n) - 1) / 99.3
  tm[seq(120 * 150 + 1, n)] <- tm[seq(120 * 150 + 1, n)] + 40  # a 40 s jump
  f1 <- tempfile(fileext = ".cwa")
  write_cwa(x, f1, sf = 100, time = tm, temperature = 20 + tt / 1000)
  b <- readBin(f1, raw(), file.size(f1))
  at <- 1024 + 512 * 77 + 30  # a flipped byte: block 77 fails its checksum
  b[at] <- as.raw(bitwXor(as.integer(b[at]), 0x10))
  f2 <- tempfile(fileext = ".cwa")
  writeBin(b, f2)
  files <- c(files, f1, f2)
  for (f in files) {
    for (compat in c(1, 0)) {
      for (chunk in c(1e6, 1001, 7)) {
        r <- both_ways(function() decode_all(f, "cwa", compat, chunk))
        expect_identical(r$avx2, r$baseline,
                         label = paste(basename(f), "compat", compat, "chunk", chunk))
      }
    }
  }
  # the imputed and the off-rate spans were met
  rep <- decode_all(f1, "cwa", 1, 1e6)$report
  expect_gt(rep$counters[["imputed_samples"]], 0)
})

test_that("GENEActiv .bin: decoding is the same bits with and without AVX2", {
  skip_if_no_avx2()
  files <- system.file("testfiles", "GENEActiv_testfile.bin", package = "GGIRread")
  files <- files[nzchar(files)]
  d <- simulate_recording(hours = 2, sf = 50, seed = 3)
  f1 <- tempfile(fileext = ".bin")
  write_geneactiv_bin(d, f1, sf = 50, start = as.POSIXct("2024-01-01", tz = "UTC"))
  # a page with a character that is not a hex digit, one in lower case
  l <- readLines(f1)
  hex <- which(nchar(l) == 3600)
  substr(l[hex[5]], 1000, 1000) <- "G"
  l[hex[9]] <- tolower(l[hex[9]])
  f2 <- tempfile(fileext = ".bin")
  writeLines(l, f2, sep = "\r\n")
  files <- c(files, f1, f2)
  for (f in files) {
    for (compat in c(1, 0)) {
      r <- both_ways(function() decode_all(f, "geneactiv", compat, 1001))
      expect_identical(r$avx2, r$baseline, label = paste(basename(f), "compat", compat))
    }
  }
  # the damaged page was met: read as GGIRread reads it in GGIR's mode,
  # skipped whole in gravcal's own
  rep <- decode_all(f2, "geneactiv", 1, 1e6)$report
  expect_equal(rep$skipped, 0)
  expect_equal(rep$counters[["damaged_hex"]], 1)
  rep <- decode_all(f2, "geneactiv", 0, 1e6)$report
  expect_equal(rep$skipped, 1)
  expect_equal(rep$counters[["bad_hex"]], 1)
})

test_that("windows and fits are the same bits with and without AVX2", {
  skip_if_no_avx2()
  d <- simulate_recording(hours = 30, sf = 25, seed = 11,
                          params = c(1.02, 0.98, 1.01, 0, 0, 0, 0.03, -0.02, 0.01))
  d$x[5000:5400] <- 0
  d$y[5000:5400] <- 0
  d$z[5000:5400] <- 0  # idle-sleep zeros
  f <- tempfile(fileext = ".cwa")
  write_cwa(as.matrix(d[, c("x", "y", "z")]), f, sf = 25, start = 1.7e9,
            temperature = d$temperature)
  r <- both_ways(function() {
    utils::capture.output(g <- g.calibrate(f, verbose = FALSE))
    g$bsc_qc <- NULL  # time and memory of the run
    list(g = g,
         w = rest_windows(d, sf = 25),
         lw = calibrate(f, method = "lightweight"),
         gg = calibrate(f, method = "ggir"))
  })
  expect_identical(r$avx2$g, r$baseline$g)
  expect_identical(r$avx2$w, r$baseline$w)
  expect_identical(coef(r$avx2$lw), coef(r$baseline$lw))
  expect_identical(coef(r$avx2$gg), coef(r$baseline$gg))
  expect_gt(nrow(r$avx2$g$spheredata), 100)
})

# ---------------------------------------------------------------------------
# Each vector kernel (inst/include/gravcal/kernels/) against its scalar
# reference: gc_kernel_check() runs every variant compiled in (and, for AVX2,
# runnable here) on the same input, and each must give the reference's bits
# (identical() with num.eq = FALSE: -0 is not 0; every NaN that is not NA is
# one value), on random input and on adversarial input: NaN, +-0, +-Inf,
# denormals, huge and tiny values, exact midpoints between doubles, and every
# length from 0 (or 1) to 33, so that every loop's tail is met.

kernel_variants <- function(name, args) {
  out <- gc_kernel_check(name, args)
  if (length(out) < 2) skip(paste0("no vector variant of ", name, " runs here"))
  out
}

# The cases where a variant's outputs (after `view`) differ from the scalar
# reference's, as labels; character(0) when none does.
kernel_diffs <- function(name, cases, view = function(o, a) o) {
  bad <- character(0)
  for (i in seq_along(cases)) {
    out <- kernel_variants(name, cases[[i]])
    ref <- view(out$scalar, cases[[i]])
    for (v in setdiff(names(out), "scalar")) {
      if (!identical(view(out[[v]], cases[[i]]), ref, num.eq = FALSE)) {
        bad <- c(bad, paste0(v, " case ", i, " (", names(cases)[i], ")"))
      }
    }
  }
  bad
}

# Values that stress a kernel's arithmetic and comparisons.
tricky <- c(NaN, 0, -0, Inf, -Inf, 4.9e-324, -4.9e-324, 2.2250738585072014e-308,
            1e-310, -1e-310, .Machine$double.xmax, -.Machine$double.xmax, 1e300, -1e300,
            1e-300, 1, 1 + 2^-52, 1 - 2^-53, 2^-53, 2^53, 2^53 + 2, 0.5, 1.5, -1.5, 3)

# n values: ordinary samples (about a gravity component), or drawn from
# `tricky` and ordinary ones; finite = TRUE leaves out NaN and +-Inf.
kernel_values <- function(n, kind, finite = FALSE) {
  pool <- if (finite) tricky[is.finite(tricky)] else tricky
  v <- switch(kind,
    ordinary = 0.6 + 0.01 * stats::rnorm(n),
    tricky = ifelse(stats::runif(n) < 0.5, sample(pool, n, replace = TRUE),
                    0.6 + 0.01 * stats::rnorm(n)),
    # the mean of d and the next double is a midpoint; zeros of both signs
    midpoint = sample(c(1, 1 + 2^-52, 0, -0), n, replace = TRUE),
    wide = stats::rnorm(n) * 10^sample(-300:300, n, replace = TRUE))
  as.double(v)
}

# Three columns of every length 0 (or `from`) to 33, of every kind.
column_cases <- function(from = 0, finite = FALSE, kinds = c("ordinary", "tricky", "midpoint", "wide")) {
  cases <- list()
  for (kind in kinds) {
    for (n in from:33) {
      cases[[paste(kind, n)]] <- list(x = kernel_values(n, kind, finite),
                                      y = kernel_values(n, kind, finite),
                                      z = kernel_values(n, kind, finite))
    }
  }
  cases
}

test_that("run_end: every variant finds the run's end of the reference", {
  set.seed(1)
  cases <- list()
  for (n in 1:33) {
    for (rep in 1:4) {
      v <- sample(c(0, -0, NaN, 1, 1 + 2^-52), 1)
      x <- rep(v, n)
      if (rep > 1) x[sample(n, rep - 1, replace = TRUE)] <- sample(tricky, rep - 1)
      cases[[paste(n, rep)]] <- list(v = x, i = sample(n, 1) - 1)
    }
  }
  expect_identical(kernel_diffs("run_end", cases), character(0))
})

test_that("stream_window: the streaming sums, min, max and zero test of the reference", {
  set.seed(2)
  finite <- column_cases(from = 1, finite = TRUE)
  with_t <- lapply(finite, function(a) c(a, list(t = 20 + stats::rnorm(length(a$x)))))
  without_t <- lapply(finite, function(a) c(a, list(t = NULL)))
  expect_identical(kernel_diffs("stream_window", c(with_t, without_t)), character(0))
  # with a non-finite sample only the sums' finiteness is promised (the
  # segmenter then takes the window sample by sample)
  any_nonfinite <- lapply(column_cases(from = 1, kinds = "tricky"),
                          function(a) c(a, list(t = NULL)))
  sums_finite <- function(o, a) all(is.finite(c(o$s, o$q, o$nrm)))
  expect_identical(kernel_diffs("stream_window", any_nonfinite, sums_finite), character(0))
})

test_that("r_scan: R's running sums, min, max, zero test and lanes of the reference", {
  set.seed(3)
  cases <- list()
  for (want_w in c(TRUE, FALSE)) {
    cs <- column_cases(from = 1, finite = TRUE)
    names(cs) <- paste(names(cs), want_w)
    cases <- c(cases, lapply(cs, function(a) {
      c(a, list(c = c(stats::rnorm(3) * 1e4, 1e5 * stats::runif(1)), want_w = want_w))
    }))
  }
  expect_identical(kernel_diffs("r_scan", cases), character(0))
  # the long double sums themselves, on a week-like window of 500 samples
  big <- list(x = 0.6 + 0.01 * stats::rnorm(500), y = -0.2 + 0.01 * stats::rnorm(500),
              z = 0.7 + 0.01 * stats::rnorm(500), c = c(1234.5, -321.25, 777, 9999),
              want_w = FALSE)
  expect_identical(kernel_diffs("r_scan", list(big = big)), character(0))
  nonfinite <- lapply(column_cases(from = 1, kinds = "tricky"),
                      function(a) c(a, list(c = c(0, 0, 0, 0), want_w = FALSE)))
  sums_finite <- function(o, a) all(is.finite(o$c_double))
  expect_identical(kernel_diffs("r_scan", nonfinite, sums_finite), character(0))
})

test_that("r_scan counts the samples equal to the one before in x, y and z", {
  set.seed(4)
  # runs of repeated samples (a stuck sensor, an idle-sleep stretch), some
  # equal on two axes only, zeros of both signs (equal), every length
  cases <- list()
  for (n in c(1:33, 200, 501)) {
    for (want_w in c(TRUE, FALSE)) {
      i <- cumsum(c(TRUE, stats::runif(n - 1) < 0.4))
      v <- list(x = c(0.6, -0, 0, 1 + 2^-52, 0.5)[(i %% 5) + 1],
                y = sample(c(-0.2, 0.1), max(i), replace = TRUE)[i],
                z = 0.7 + 0.01 * stats::rnorm(max(i))[i])
      # a change on one axis alone breaks a repeat
      if (n > 5) v$z[seq(3, n, by = 7)] <- v$z[seq(3, n, by = 7)] + 2^-40
      cases[[paste(n, want_w)]] <- c(v, list(c = c(1, 2, 3, 4), want_w = want_w))
    }
  }
  expect_identical(kernel_diffs("r_scan", cases), character(0))
  # the reference's count is R's
  counted <- vapply(cases, function(a) {
    gc_kernel_check("r_scan", a)$scalar$repeats
  }, numeric(1))
  expected <- vapply(cases, function(a) {
    n <- length(a$x)
    if (n < 2) return(0)
    as.double(sum(a$x[-1] == a$x[-n] & a$y[-1] == a$y[-n] & a$z[-1] == a$z[-n]))
  }, numeric(1))
  expect_identical(counted, expected)
  expect_gt(sum(expected), 1000)
})

test_that("r_var_means3: the means it decides are R's (mean())", {
  set.seed(5)
  cases <- column_cases()
  # windows of a sensor at rest, where it must decide most
  for (i in 1:50) {
    n <- sample(50:600, 1)
    cases[[paste("rest", i)]] <- list(x = 0.6 + 0.003 * stats::rnorm(n),
                                      y = -0.1 + 0.003 * stats::rnorm(n),
                                      z = 0.8 + 0.003 * stats::rnorm(n))
  }
  # where R's own rounding matters (as tests/cpp/test_core.cpp's
  # test_r_var_mean()): the exact mean half-way between two doubles or next
  # to one, values crossing zero, a wide spread about a small mean
  after <- function(d) d + 2^(floor(log2(abs(d))) - 52)
  for (i in 1:300) {
    n <- sample(2:1500, 1)
    centre <- (0.5 + stats::runif(1)) * 2^sample(-8:3, 1)
    col <- function() {
      switch(i %% 4 + 1,
        rep(c(centre, after(centre)), length.out = n),
        { v <- rep(c(centre, after(centre)), length.out = n); k <- sample(n, 1); v[k] <- after(v[k]); v },
        2^-sample(3:30, 1) * stats::rnorm(n),
        centre + 300 * centre * stats::rnorm(n))
    }
    cases[[paste("rounding", i)]] <- list(x = col(), y = col(), z = col())
  }
  # the kernel decides the means of an R with long double (gravcal uses it
  # only there); on an R without long double (make test-noLD) the
  # reference is the core's long double replay of mean(), which
  # test-noLD.R checks against mean() on an R with long double
  r_mean <- if (isTRUE(gravcal:::build_state$r_long_double)) {
    mean
  } else {
    function(v) gravcal:::gc_r_mean_sd(v, TRUE)[1]
  }
  decided <- 0
  wrong <- character(0)
  for (i in seq_along(cases)) {
    a <- cases[[i]]
    out <- kernel_variants("r_var_means3", a)
    expect_false(out$scalar$decided)  # the reference leaves every mean to R's passes
    for (v in setdiff(names(out), "scalar")) {
      if (!out[[v]]$decided) next
      decided <- decided + 1
      r <- c(r_mean(a$x), r_mean(a$y), r_mean(a$z))
      if (!identical(out[[v]]$mean, r, num.eq = FALSE)) wrong <- c(wrong, names(cases)[i])
    }
  }
  expect_identical(wrong, character(0))
  expect_gt(decided, 40)
})

test_that("first_zero: the first idle-sleep sample of the reference", {
  set.seed(6)
  cases <- column_cases()
  for (n in 0:40) {  # zeros of both signs on some axes, all zeros somewhere
    zeros <- function() as.double(sample(c(0, -0, 1), n, replace = TRUE))
    cases[[paste("zeros", n)]] <- list(x = zeros(), y = zeros(),
                                       z = as.double(ifelse(stats::runif(n) < 0.9, 1, -0)))
  }
  expect_identical(kernel_diffs("first_zero", cases), character(0))
})

test_that("order_next: the running median's next value, as the reference finds it", {
  # windows of 0 to 60 values (the median's is 51 at 10 Hz), in time order
  # (not sorted), with ties, signed zeros, infinities, subnormals; the
  # median's value drawn from the window (ties with it), from tricky values
  # (never NaN: the median keeps NaN out of its window) and between; down
  # and up
  set.seed(8)
  pool <- tricky[!is.na(tricky)]
  cases <- list()
  for (n in 0:60) {
    for (kind in c("ordinary", "ties", "tricky")) {
      w <- switch(kind,
        ordinary = 0.6 + 0.01 * stats::rnorm(n),
        ties = sample(c(-0, 0, 0.25, 0.5, 1), n, replace = TRUE),
        tricky = sample(pool, n, replace = TRUE))
      from <- c(w, pool, 0.6 + 0.01 * stats::rnorm(3))
      for (r in 1:3) {
        for (down in c(TRUE, FALSE)) {
          cases[[paste(kind, n, r, down)]] <- list(w = as.double(w), v = sample(from, 1), down = down)
        }
      }
    }
  }
  # the reference is the rule itself (on every platform, vector code or not)
  rule <- function(cs) {
    beyond <- if (cs$down) cs$w[cs$w < cs$v] else cs$w[cs$w > cs$v]
    val <- if (length(beyond) == 0) (if (cs$down) -Inf else Inf) else
      if (cs$down) max(beyond) else min(beyond)
    list(val = if (val == 0) 0 else val, count = as.double(sum(cs$w == val)))
  }
  for (nm in c("ties 60 1 TRUE", "ties 60 1 FALSE", "tricky 33 2 TRUE", "tricky 33 2 FALSE",
               "ordinary 51 3 TRUE", "ordinary 51 3 FALSE", "ties 0 1 TRUE")) {
    out <- gc_kernel_check("order_next", cases[[nm]])$scalar
    expect_identical(out, rule(cases[[nm]]), info = nm)
  }
  # a zero is +0, whichever zero the window holds
  out <- gc_kernel_check("order_next", list(w = c(-0, 1, -0), v = 1, down = TRUE))$scalar
  expect_identical(1 / out$val, Inf)
  expect_identical(out$count, 2)
  expect_identical(kernel_diffs("order_next", cases), character(0))
})

test_that("offset_divide: GGIR's calibration of an axis span, as the reference and R compute it", {
  # spans of 0 to 33 values (every loop's tail), ordinary and tricky
  # values, offsets, scales and temperature terms; with and without the
  # term (without it, -0 stays -0)
  set.seed(9)
  cases <- list()
  for (n in 0:33) {
    for (kind in c("ordinary", "tricky", "wide", "midpoint")) {
      for (add in c(TRUE, FALSE)) {
        cases[[paste(kind, n, add)]] <- list(
          p = kernel_values(n, kind), o = sample(c(0.01, -0.02, 0, -0, sample(tricky, 1)), 1),
          s = sample(c(1 / 1.01, 1 / 0.98, 1, sample(tricky, 1)), 1),
          term = sample(c(0.0013, -0.002, 0, -0, sample(tricky, 1)), 1), add = add)
      }
    }
  }
  # the reference is R's arithmetic: (p + o) / s, then + term
  for (cs in cases[c("ordinary 33 TRUE", "ordinary 17 FALSE", "wide 9 TRUE", "midpoint 12 FALSE")]) {
    out <- gc_kernel_check("offset_divide", cs)$scalar$p
    want <- (cs$p + cs$o) / cs$s
    if (cs$add) want <- want + cs$term
    expect_identical(out, want)
  }
  expect_identical(gc_kernel_check("offset_divide", list(p = c(-0, 0.5), o = 0, s = 1, term = 0,
                                                         add = FALSE))$scalar$p, c(-0, 0.5))
  expect_identical(kernel_diffs("offset_divide", cases), character(0))
})

test_that(".cwa kernels: checksum, packed samples, sample times and resampling", {
  set.seed(7)
  sums <- lapply(0:16, function(k) list(bytes = as.raw(sample(0:255, 32 * k, replace = TRUE))))
  sums$ones <- list(bytes = as.raw(rep(255, 512)))
  expect_identical(kernel_diffs("word_sum", sums), character(0))
  packed <- list()
  for (n in 0:33) {
    for (scale in c(2^-8, 2^-15, 1, 2^-1074, 2^1019)) {
      b <- as.raw(sample(0:255, 4 * n, replace = TRUE))
      if (n > 0) b[4 * seq_len(n) - sample(0:3, n, replace = TRUE)] <- as.raw(sample(c(0, 255, 0x80, 0x7f, 0xc0), n, replace = TRUE))
      packed[[paste(n, scale)]] <- list(bytes = b, scale = scale)
    }
  }
  expect_identical(kernel_diffs("scale_packed", packed), character(0))
  times <- list()
  for (len in 1:33) {
    times[[paste(len)]] <- list(len = len, start = 1.7e9 + stats::runif(1),
                                spacing = 0.01 * stats::runif(1))
    times[[paste(len, "tricky")]] <- list(len = len, start = sample(tricky, 1),
                                          spacing = sample(tricky, 1))
  }
  expect_identical(kernel_diffs("span_times", times), character(0))
  interp <- list()
  for (len in 1:33) {
    for (kind in c("regular", "jitter", "tricky")) {
      tm <- 1.7e9 + cumsum(c(0, rep(0.01, len)))
      if (kind == "jitter") tm <- tm + c(0, stats::runif(len, -0.004, 0.004))
      if (kind == "tricky" && len > 1) tm[sample(len + 1, 2)] <- sample(c(NaN, tm[1], -Inf, 2e9), 2)
      vals <- function() if (kind == "tricky") kernel_values(len + 1, "tricky") else kernel_values(len + 1, "ordinary")
      step <- 0.01 * (1 + sample(c(0, 0, 1e-9, -0.05, 0.3), 1))
      pos <- sample(0:3, 1)
      interp[[paste(len, kind)]] <- list(
        time = tm, x = vals(), y = vals(), z = vals(), start = tm[1] - 0.001 - pos * step,
        step = step, end = tm[1] + sample(c(1e9, 0.01 * len / 2), 1), temp = 25.5, pos = pos,
        stop = pos + sample(0:40, 1), source = sample(len, 1))
    }
  }
  expect_identical(kernel_diffs("cwa_interp", interp), character(0))
})

test_that("GENEActiv kernel: the hex digits' counts and checks of the reference", {
  set.seed(8)
  digits <- charToRaw("0123456789ABCDEFabcdef")
  others <- as.raw(c(0:47, 58:64, 71:96, 103:255))
  cases <- list()
  for (k in 0:33) {
    for (kind in c("valid", "one bad", "many bad")) {
      b <- sample(digits, 12 * k, replace = TRUE)
      nbad <- switch(kind, valid = 0, "one bad" = 1, "many bad" = k)
      if (k > 0 && nbad > 0) b[sample(12 * k, nbad)] <- sample(others, nbad, replace = TRUE)
      cases[[paste(k, kind)]] <- list(bytes = b)
    }
  }
  expect_identical(kernel_diffs("hex_counts", cases), character(0))
  # the checks are met: a bad digit anywhere in a sample's 12 is found
  expect_true(gc_kernel_check("hex_counts", cases[["5 one bad"]])$scalar$bad)
})

test_that("the kernel table holds one variant per kernel, chosen once", {
  k <- gc_kernels()
  expect_true(all(k %in% c("scalar", "sse2", "avx2")))
  expect_setequal(names(k), c("run_end", "stream_window", "r_scan", "r_var_means3",
                              "first_zero", "order_next", "offset_divide", "word_sum",
                              "scale_packed", "span_times", "cwa_interp", "hex_counts"))
  # GRAVCAL_KERNELS forces a kernel to its scalar reference in a new process
  skip_if_no_avx2()
  out <- system2(file.path(R.home("bin"), "Rscript"),
                 c("-e", shQuote("k <- gravcal:::gc_kernels(); cat(k[['r_scan']], k[['run_end']])")),
                 stdout = TRUE, stderr = FALSE,
                 env = c("GRAVCAL_KERNELS=r_scan=scalar", "GRAVCAL_NO_AVX2="))  # (not inherited)
  expect_identical(utils::tail(out, 1), "scalar avx2")
})
