# Adversarial differential tests of the compatible mode: gravcal::g.calibrate
# against GGIR::g.calibrate on inputs built to sit on the edges of the speed
# shortcuts the compatible mode takes while claiming GGIR's numbers to the
# bit (segmenter.hpp: lazy R sds; r_arith.hpp / ggir_blocks.hpp: the
# temperature check from run-length code; ggir_blocks.hpp: GGIR's block
# rules; the native decoders writing into the block buffer). Every input is
# run through GGIR and gravcal and compared with expect_same_as_ggir()
# (helper-ggir.R); where it can, a test also asserts that the edge it aims
# at is actually hit in the samples GGIR reads (fread's values of the csv,
# the .bin's counts).
#
# Sizes: GGIR's "enough data" test counts windows against minloadcrit - 21
# (hours), and its first block needs two hours, so a few hours suffice;
# chunksize 0.2 makes GGIR's blocks about 2.4 hours (14512 * sf / 50 * 0.1
# GENEActiv pages, or 300 times as many csv rows).

# --- helpers ---------------------------------------------------------------

st_ulp <- function(x) 2^(floor(log2(abs(x))) - 52)

# The value R reads back from the decimals write.csv writes (15 significant
# digits); dims kept.
st_csv15 <- function(v) {
  v[] <- as.numeric(sprintf("%.15g", v))
  v
}

# fread's values (GGIR's reader) of the decimals write.csv writes for v.
st_fread15 <- function(v) {
  s <- sprintf("%.15g", v)
  u <- unique(s)
  p <- as.numeric(data.table::fread(text = c("t", u), header = TRUE)$t)
  p[match(s, u)]
}

# Move one value of v along its representable neighbours (step(x, k): the
# k-th one) until R's sd(v) is `target`, or as near as those allow: a binary
# search for the first step at or past the target, for each of the values
# furthest from the mean, keeping the best.
st_hit_sd <- function(v, target, step, tries = 4) {
  best <- v
  bestd <- abs(stats::sd(v) - target)
  for (j in utils::head(order(-abs(v - mean(v))), tries)) {
    dir <- sign(v[j] - mean(v))
    at <- function(k) {
      w <- best
      w[j] <- step(best[j], dir * k)
      w
    }
    sdk <- function(k) stats::sd(at(k))
    lo <- -2^24
    hi <- 2^24
    if (sdk(lo) > target || sdk(hi) < target) next
    while (hi - lo > 1) {
      m <- (lo + hi) %/% 2
      if (sdk(m) >= target) hi <- m else lo <- m
    }
    for (k in (lo - 3):(hi + 3)) {
      d <- abs(sdk(k) - target)
      if (d < bestd) {
        best <- at(k)
        bestd <- d
      }
    }
    if (bestd == 0) break
  }
  best
}

# Neighbours among 15-digit decimals (csv by write.csv) and among doubles.
st_step15 <- function(x, k) st_csv15(x + k * 10^(floor(log10(abs(x))) - 14))
st_step_ulp <- function(x, k) x + k * st_ulp(x)

# An ad hoc csv with every value written with 17 significant digits (so
# that the file holds the doubles themselves), and GGIR's parameters for it.
st_write_csv17 <- function(rec, file, sf, noise = 0.013 / 1.2) {
  cols <- lapply(rec[, c("x", "y", "z", "temperature")], sprintf, fmt = "%.17g")
  writeLines(c("x,y,z,temperature", do.call(paste, c(cols, sep = ","))), file)
  list(rmc.firstrow.acc = 2, rmc.col.acc = 1:3, rmc.col.temp = 4,
       rmc.sf = sf, rmc.noise = noise, rmc.unit.acc = "g",
       rmc.unit.temp = "C")
}

# R's statistics of the windows GGIR forms from n whole windows of L samples
# starting at row `from` of matrix d (one block: cumsum restarts there).
st_features <- function(d, from, n, L) {
  X <- d[from - 1 + seq_len(n * L), 1:3, drop = FALSE]
  means <- vapply(1:3, function(j) {
    diff(c(0, cumsum(X[, j])[seq(L, n * L, L)])) / L
  }, numeric(n))
  sds <- vapply(1:3, function(j) apply(matrix(X[, j], L), 2, stats::sd), numeric(n))
  cbind(matrix(means, n), matrix(sds, n))
}

# GGIR's block rule on counts of rows (g.calibrate: idle-sleep rows
# removed, whole hours used, the rest carried; a block of whole hours keeps
# the old carry, one with less than an hour is dropped and keeps it too).
st_block_plan <- function(rows, zeros, H) {
  carry <- 0
  out <- NULL
  for (i in seq_along(rows)) {
    LD <- carry + rows[i] - zeros[i]
    use <- floor(LD / H) * H
    new_carry <- if (use > 0 && use != LD) LD - use else carry
    out <- rbind(out, data.frame(block = i, rows = rows[i], LD = LD, use = use,
                                 carry = new_carry))
    carry <- new_carry
  }
  out
}

# gravcal on the samples held in memory, as GGIR's answer on the csv of
# the same samples: the two results side by side for expect_same_as_ggir().
st_frame_vs <- function(b, file, sf, chunksize, ...) {
  d <- data.table::fread(file, data.table = FALSE)
  G <- suppressWarnings(gravcal::g.calibrate(d, sf = sf, chunksize = chunksize,
                                             verbose = FALSE, ...))
  list(ggir = b$ggir, gravcal = G)
}

# GGIR's and gravcal's results as run_both() gives them, or the error
# (condition) each one stops with.
st_run_both <- function(file, params) {
  pr <- utils::modifyList(GGIR::load_params()$params_rawdata, params)
  quiet <- function(expr) {
    out <- NULL
    keep_warn(utils::capture.output(out <- suppressWarnings(expr)))
    out
  }
  R <- ggir_cached("g.calibrate", file, list(params_rawdata = pr),
    tryCatch(quiet({
      I <- GGIR::g.inspectfile(file, params_rawdata = pr)
      GGIR::g.calibrate(file, params_rawdata = pr, inspectfileobject = I,
                        verbose = FALSE)
    }), error = function(e) e))
  G <- tryCatch(quiet(gravcal::g.calibrate(file, params_rawdata = pr,
                                           verbose = FALSE)),
                error = function(e) e)
  list(ggir = R, gravcal = G)
}

# Both give the same result, or both stop with an error.
st_expect_same_outcome <- function(r, what = "") {
  if (inherits(r$ggir, "error")) {
    expect_true(inherits(r$gravcal, "error"),
                label = paste0("gravcal stopping where GGIR stops (\"",
                               conditionMessage(r$ggir), "\")", what))
  } else if (inherits(r$gravcal, "error")) {
    fail(paste0("gravcal stops (\"", conditionMessage(r$gravcal),
                "\") where GGIR gives a result", what))
  } else {
    expect_same_as_ggir(r)
  }
}

# --- 1. the rest rule at its threshold (lazy R sds) ------------------------

test_that("rest rule: windows whose R sd is 0.013 to the ulp (csv, 15 digits)", {
  # Aims at Segmenter::lazy_r_sd() / fast_sd(): a window's sds in double
  # may stand only when some axis is surely above the rest threshold. Rest
  # windows of a simulated recording get one axis (two for some) replaced
  # by a zero-mean pattern scaled to sd 0.013 and then tuned, one value's
  # last written digit at a time, to R's sd 0.013 - 2, -1, 0, +1, +2 ulps,
  # on the values fread gives GGIR: patterns normal, two-level, one spike,
  # a ramp, quarter steps; about the window's own mean, or about 0 (finest
  # decimals), or about 1.95 g (widest error bounds). The windows around
  # are clearly moving or clearly resting, so that the fit runs.
  skip_if_not_installed("GGIR")
  sf <- 10
  L <- 10 * sf
  rec <- simulate_recording(hours = 5, sf = sf, seed = 101,
                            params = known_params(),
                            tempoffset = c(0.002, -0.001, 0.0015))
  nwin <- nrow(rec) %/% L
  X <- as.matrix(rec[, c("x", "y", "z")])
  wsd <- vapply(1:3, function(a) apply(matrix(X[1:(nwin * L), a], L), 2, stats::sd),
                numeric(nwin))
  rest <- which(apply(wsd, 1, max) < 0.008)
  thr <- 0.013 / 1.2 * 1.2  # GGIR's sdcriter for ad hoc csv (rmc.noise * 1.2)
  expect_identical(thr, 0.013)
  set.seed(7)
  tw <- sort(sample(rest[rest > 2], 360))
  offs <- c(-2, -1, 0, 0, 0, 1, 2)
  info <- data.frame(w = tw, axis = 0L, axis2 = 0L, target = 0)
  for (i in seq_along(tw)) {
    rows <- (tw[i] - 1) * L + seq_len(L)
    axes <- (i %% 3) + 1
    if (i %% 11 == 0) axes <- c(axes, (axes %% 3) + 1)  # two axes at the edge
    tg <- thr + offs[(i %% length(offs)) + 1] * st_ulp(thr)
    for (a in axes) {
      p <- switch((i %% 5) + 1,
                  stats::rnorm(L),
                  rep(c(-1, 1), length.out = L),
                  c(10, rep(0, L - 1)),
                  seq_len(L),
                  round(stats::rnorm(L) * 4) / 4)
      p <- p - mean(p)
      mu <- mean(X[rows, a])
      if (i %% 7 == 0) mu <- 0
      if (i %% 13 == 0) mu <- 1.95
      X[rows, a] <- st_hit_sd(st_csv15(mu + p * thr / stats::sd(p)), tg, st_step15)
    }
    info$axis[i] <- axes[1]
    info$axis2[i] <- if (length(axes) > 1) axes[2] else 0L
    info$target[i] <- tg
  }
  # means at the other rule's edge, |mean| < 2: constant +-2 g on one axis
  # (whether R's mean from cumsum() differences comes out 2 or just below
  # is up to rounding), with a resting rest of the window
  edge2 <- setdiff(rest[rest > 2], c(tw, tw - 1, tw + 1))[1:30]
  for (k in seq_along(edge2)) {
    rows <- (edge2[k] - 1) * L + seq_len(L)
    X[rows, (k %% 3) + 1] <- c(2, -2, 1.99999999999999, -1.99999999999999)[(k %% 4) + 1]
  }
  rec[, c("x", "y", "z")] <- X
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- write_adhoc(rec, f, sf)
  # the edge is hit in the values GGIR reads
  d <- as.matrix(data.table::fread(f, data.table = FALSE))
  got <- vapply(seq_along(tw), function(i) {
    stats::sd(d[(tw[i] - 1) * L + seq_len(L), info$axis[i]])
  }, 0)
  off <- (got - thr) / st_ulp(thr)
  expect_gt(sum(got == thr), 20)
  expect_gt(sum(off < 0 & off >= -2), 40)
  expect_gt(sum(off > 0 & off <= 2), 40)
  expect_true(all(abs(got - thr) < 1e-15))
  for (cs in c(0.2, 0.5)) {
    b <- run_both(f, c(pr, list(chunksize = cs)))
    expect_same_as_ggir(b)
    # GGIR's rest windows among the tuned ones are those below the
    # threshold on every axis (those sds R's, to the bit)
    rn <- as.integer(rownames(b$ggir$spheredata))
    two <- info$axis2 > 0
    below <- got < thr
    below[two] <- below[two] & vapply(which(two), function(i) {
      stats::sd(d[(tw[i] - 1) * L + seq_len(L), info$axis2[i]]) < thr
    }, TRUE)
    expect_identical(tw %in% rn, below)
    # the same samples as a data frame
    expect_same_as_ggir(st_frame_vs(b, f, sf, cs))
  }
})

test_that("rest rule: windows at the threshold to the ulp, values written with 17 digits (12.5 Hz)", {
  # As above on exact doubles: the csv holds each double (17 digits), so
  # that the tuned values are the samples and every target is met exactly
  # (one value moved by ulps); also gravcal's csv number parser against
  # fread's on 17-digit numbers. 12.5 Hz: windows of 125 samples. The
  # threshold here is another one, rmc.noise * 1.2 = 0.011 * 1.2 (the
  # lazy sds must follow GGIR's sdcriter, not 0.013).
  skip_if_not_installed("GGIR")
  sf <- 12.5
  L <- 125
  rec <- simulate_recording(hours = 3, sf = sf, seed = 102,
                            params = known_params(), resolution = 0,
                            tempoffset = c(0.002, -0.001, 0.0015))
  nwin <- nrow(rec) %/% L
  X <- as.matrix(rec[, c("x", "y", "z")])
  wsd <- vapply(1:3, function(a) apply(matrix(X[1:(nwin * L), a], L), 2, stats::sd),
                numeric(nwin))
  rest <- which(apply(wsd, 1, max) < 0.008)
  thr <- 0.011 * 1.2
  set.seed(8)
  tw <- sort(sample(rest[rest > 2], 200))
  offs <- c(-2, -1, 0, 0, 1, 2)
  target <- thr + offs[(seq_along(tw) %% length(offs)) + 1] * st_ulp(thr)
  axis <- (seq_along(tw) %% 3) + 1
  for (i in seq_along(tw)) {
    rows <- (tw[i] - 1) * L + seq_len(L)
    p <- if (i %% 2) stats::rnorm(L) else rep(c(-1, 1, 0), length.out = L)
    p <- p - mean(p)
    mu <- if (i %% 5 == 0) 1.999 else mean(X[rows, axis[i]])
    X[rows, axis[i]] <- st_hit_sd(mu + p * thr / stats::sd(p), target[i], st_step_ulp, 6)
  }
  # constant windows a double either side of 2 g and at 2 g
  edge2 <- setdiff(rest[rest > 2], c(tw, tw - 1, tw + 1))[1:30]
  for (k in seq_along(edge2)) {
    rows <- (edge2[k] - 1) * L + seq_len(L)
    X[rows, (k %% 3) + 1] <- c(2, 2 - 2^-52, 2 + 2^-51, -2, -2 + 2^-52)[(k %% 5) + 1]
  }
  rec[, c("x", "y", "z")] <- X
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- st_write_csv17(rec, f, sf, noise = 0.011)
  d <- as.matrix(data.table::fread(f, data.table = FALSE))
  expect_identical(unname(d[, 1:3]), unname(X))  # fread reads the doubles back
  got <- vapply(seq_along(tw), function(i) {
    stats::sd(d[(tw[i] - 1) * L + seq_len(L), axis[i]])
  }, 0)
  expect_gt(mean(got == target), 0.8)
  b <- run_both(f, c(pr, list(chunksize = 0.2)))
  expect_same_as_ggir(b)
  expect_identical(tw %in% as.integer(rownames(b$ggir$spheredata)), got < thr)
})

# --- 2. GGIR's duplicate-window filter (lazy R sds, exact ties) ----------

# Windows made from the window before: an exact copy (6 of 6 equal: GGIR
# keeps it), the same samples permuted (equal means; sds tie or not in R's
# last bit), all three axes shifted by a few 1/256 g (sds tie, means
# differ: 3 of 6, GGIR drops it, unless one R sd differs in its last bit),
# x permuted with y shifted and z new (mean x, sd x, sd y: 3), x and y
# reversed and shifted (4), x mirrored about its mean (sd x, sd y: 2 or 3).
st_dup_windows <- function(X, L, ks, seed) {
  set.seed(seed)
  W <- function(k) (k - 1) * L + seq_len(L)
  kind <- character(length(ks))
  for (i in seq_along(ks)) {
    k <- ks[i]
    a <- X[W(k - 1), , drop = FALSE]
    sh <- function() sample(c(-3:-1, 1:3), 1) / 256
    v <- i %% 6
    X[W(k), ] <- switch(v + 1,
      a,
      a[sample(L), ],
      cbind(a[, 1] + sh(), a[, 2] + sh(), a[, 3] + sh()),
      cbind(a[sample(L), 1], a[, 2] + sh(), X[W(k), 3]),
      cbind(rev(a[, 1]), rev(a[, 2]) + sh(), a[, 3] + sh()),
      cbind(2 * mean(a[, 1]) - a[, 1], a[, 2] + sh(), X[W(k), 3]))
    kind[i] <- c("copy", "perm", "shift", "perm_x", "rev", "mirror")[v + 1]
  }
  list(X = X, kind = kind)
}

test_that("duplicate filter: equal means and tied sds, GENEActiv .bin (exact sums)", {
  skip_if_quick()
  # slow tier; make quick keeps the duplicate filter against R's comparisons
  # (test-ggir.R) and lazy_r_sd() at the threshold (the rest-rule cases above)
  # Aims at lazy_r_sd()'s tie logic (may_tie(), the held and reference
  # windows): sds in double must become R's wherever GGIR's filter could
  # find 3 of 6 values equal. GENEActiv counts are multiples of 1/256 g, so
  # cumsum() is exact and equal sums give equal means; the sds tie or not
  # in R's long double arithmetic. Moving and resting windows alike; also
  # chains (a window made from one that was itself made) and windows on
  # both sides of GGIR's block boundaries (chunksize 0.2: every 2 hours).
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  sf <- 20
  L <- 200
  rec <- simulate_recording(hours = 5, sf = sf, seed = 202,
                            params = known_params(),
                            tempoffset = c(0.002, -0.001, 0.0015))
  nwin <- nrow(rec) %/% L
  set.seed(9)
  ks <- sort(unique(c(sample(seq(3, nwin - 3, by = 3), 450), 719:723,
                      1439:1443, 200:206)))
  ks <- ks[ks < 995 | ks > 1105]
  dw <- st_dup_windows(as.matrix(rec[, c("x", "y", "z")]), L, ks, 10)
  X <- round(dw$X * 256) / 256
  # a device lying still: windows 1000-1100 constant (all six equal)
  const <- (999 * L + 1):(1100 * L)
  X[const, ] <- rep(c(30, -60, 250) / 256, each = length(const))
  rec[, c("x", "y", "z")] <- X
  f <- tempfile(fileext = ".bin")
  on.exit(unlink(f))
  gravcal:::write_geneactiv_bin(rec, f, sf = sf)
  # the edges in the samples GGIR reads (one block at chunksize 1)
  ft <- st_features(X, 1, nwin, L)
  same <- rowSums(ft[-nwin, ] == ft[-1, ])
  moving <- apply(ft[, 4:6], 1, max) >= 0.013
  expect_gt(sum(same[ks - 1] == 3), 100)         # GGIR drops these
  expect_gt(sum(same[ks - 1] == 6), 50)          # and keeps these
  expect_gt(sum(same[ks - 1] == 3 & moving[ks]), 30)  # sds of moving windows
  for (cs in c(1, 0.2)) {
    b <- run_both(f, list(chunksize = cs))
    expect_same_as_ggir(b)
  }
})

test_that("duplicate filter: ties decided by R's last bit (csv, 15 digits)", {
  skip_if_quick()
  # As above on samples that are not multiples of 1/256 (15-digit
  # decimals): the means come from rounded cumulative sums and the sds of
  # shifted or permuted copies tie or not in their last bit, so GGIR's
  # "exactly 3 of 6" falls both ways on windows built the same way.
  skip_if_not_installed("GGIR")
  sf <- 20
  L <- 200
  rec <- simulate_recording(hours = 5, sf = sf, seed = 203,
                            params = known_params(), resolution = 0,
                            tempoffset = c(0.002, -0.001, 0.0015))
  nwin <- nrow(rec) %/% L
  set.seed(11)
  ks <- sort(unique(c(sample(seq(3, nwin - 3, by = 2), 700), 719:723, 1439:1443)))
  ks <- ks[ks < 995 | ks > 1105]
  dw <- st_dup_windows(st_csv15(as.matrix(rec[, c("x", "y", "z")])), L, ks, 12)
  # a device lying still, its values not multiples of a power of 2:
  # windows 1000-1100 constant, sds 0, means from rounded cumulative sums
  # equal or not
  const <- (999 * L + 1):(1100 * L)
  dw$X[const, ] <- rep(c(0.117187654321, -0.234567890123, 0.961234567891),
                       each = length(const))
  rec[, c("x", "y", "z")] <- st_csv15(dw$X)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- write_adhoc(rec, f, sf)
  d <- as.matrix(data.table::fread(f, data.table = FALSE))
  # GGIR's blocks at chunksize 0.2: 174000 rows, 2 whole hours used, the
  # rest carried: windows 1-720 and 721-1440 each from a fresh cumsum()
  ft <- rbind(st_features(d, 1, 720, L), st_features(d, 720 * L + 1, 720, L))
  same <- rowSums(ft[-nrow(ft), ] == ft[-1, ])
  kk <- ks[ks <= 1440]
  kind <- dw$kind[ks <= 1440]
  # shifted copies: sds mathematically equal; R's tie on all three axes
  # (3 equal: dropped) or not (kept)
  expect_gt(sum(kind == "shift" & same[kk - 1] == 3), 30)
  expect_gt(sum(kind == "shift" & same[kk - 1] < 3), 5)
  expect_gt(sum(same[kk - 1] == 3 & apply(ft[kk, 4:6], 1, max) >= 0.013), 30)
  # constant windows: their means equal or not in the last bit (so where
  # R's cumsum() accumulates in long double: in double, on an R without
  # it, these windows' means do not come out unequal)
  if (isTRUE(gravcal:::build_state$r_long_double)) expect_gt(sum(same[1000:1099] == 3), 2)
  expect_gt(sum(same[1000:1099] > 3), 10)
  b <- run_both(f, c(pr, list(chunksize = 0.2)))
  expect_same_as_ggir(b)
  expect_same_as_ggir(st_frame_vs(b, f, sf, 0.2))
})

# --- 3. the temperature check (run-length code, R's sd near 0.01) --------

test_that("temperature check: sd within rounding of 0.01, first values at 120", {
  skip_if_quick()
  # Aims at GgirBlocks' temperature check: sd from the run-length code with
  # a proven bound, R's sd() only near temp_min_sd (r_sd_below()); and at
  # the mean of a block's first 10 used temperatures against 120. GGIR's
  # blocks here (10 Hz, chunksize 0.2): block 1 reads 87000 rows and uses
  # rows 1-72000; block 2 uses the carried rows 72001-87000 and the last
  # 21000 (rows 72001-108000). Each case sets the used temperatures of one
  # block to a series whose R sd (of fread's values) is 0.01 to the ulp:
  # runs of 5 equal values (as devices store them) or all distinct, about
  # 25 degrees or about -5000 (wide error bounds); or the first 10 used
  # temperatures of a block (block 2: carried rows) to a mean of exactly
  # 120 or just above.
  skip_if_not_installed("GGIR")
  sf <- 10
  H <- 3600 * sf
  base <- simulate_recording(hours = 3, sf = sf, seed = 303,
                             params = known_params(),
                             tempoffset = c(0.002, -0.001, 0.0015))
  thr <- 0.01
  u <- st_ulp(thr)
  temp_series <- function(n, target, centre = 25, runs = 5) {
    p <- if (runs > 0) rep(c(-1, 1), each = runs, length.out = n) else stats::rnorm(n)
    p <- p - mean(p)
    st_hit_sd(st_fread15(centre + p * target / stats::sd(p)), target,
              function(x, k) st_fread15(x + k * 10^(floor(log10(abs(x))) - 14)), 3)
  }
  b1 <- 1:(2 * H)
  b2 <- 2 * H + 1:H
  cases <- list(
    b1_at = list(rows = b1, target = thr),
    b1_below = list(rows = b1, target = thr - u),
    b1_above_distinct = list(rows = b1, target = thr + u, runs = 0),
    b1_at_long_runs = list(rows = b1, target = thr, runs = 3000),
    b2_below = list(rows = b2, target = thr - u),
    b2_at_distinct = list(rows = b2, target = thr, runs = 0),
    b1_negative = list(rows = b1, target = thr - u, centre = -5000),
    first_120 = list(first = 1, above = FALSE),
    first_above_120 = list(first = 1, above = TRUE),
    b2_first_above_120 = list(first = 2 * H + 1, above = TRUE))
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  set.seed(4)
  for (nm in names(cases)) {
    cs <- cases[[nm]]
    rec <- base
    if (!is.null(cs$rows)) {
      rec$temperature[cs$rows] <- temp_series(
        length(cs$rows), cs$target, if (is.null(cs$centre)) 25 else cs$centre,
        if (is.null(cs$runs)) 5 else cs$runs)
    } else {
      v <- c(120.000000000001, 119.999999999999, 120.5, 119.5, rep(120, 6))
      if (cs$above) v[10] <- 120.000000000001
      rec$temperature[cs$first - 1 + 1:10] <- v
    }
    pr <- write_adhoc(rec, f, sf)
    tt <- data.table::fread(f, data.table = FALSE)$temperature
    if (!is.null(cs$rows)) {
      # the block's sd, as GGIR computes it, within a few ulps of 0.01
      s <- stats::sd(tt[cs$rows])
      expect_lt(abs(s - thr), if (is.null(cs$centre)) 6 * u else 40 * u,
                label = nm)
      if (!identical(cs$runs, 0) && is.null(cs$centre)) {
        if (capabilities("long.double")) {
          expect_identical(s, cs$target, label = nm)
        } else {
          # R's double accumulator cannot reach every ulp near 0.01: the
          # case stays on its side of the threshold
          expect_identical(sign(s - thr), sign(cs$target - thr), label = nm)
        }
      }
    } else {
      m <- mean(tt[cs$first - 1 + 1:10])
      if (cs$above) {
        expect_gt(m, 120)
        expect_lt(m, 120 + 1e-12)
      } else {
        expect_identical(m, 120)
      }
    }
    b <- run_both(f, c(pr, list(chunksize = 0.2, minloadcrit = 2)))
    expect_identical(nrow(b$ggir$bsc_qc), 2L, label = nm)
    expect_same_as_ggir(b)
    expect_same_as_ggir(st_frame_vs(b, f, sf, 0.2, minloadcrit = 2))
  }
})

# --- 4. block rules at rates and chunksizes ------------------------------

# A recording at sf whose GGIR blocks (chunksize cs, GGIR's sampling rate
# sf_g) straddle pages, windows and hours, with idle-sleep zeros (x = y = z
# = 0) on the edges: the file's first sample; the last sample of block 1
# (GGIR then overwrites the last kept sample with the one before it) and a
# few before it; with `full`, a run in block 2 that leaves it whole hours
# (GGIR then keeps the previous carry and puts it in front of block 3 as
# well) and a run over most of block 3 (less than an hour left: GGIR drops
# the block, the carry kept), running on into block 4; without, a run
# across the boundary of blocks 1 and 2. Temperature varies within the hour
# (so that the rest windows of every block differ in it).
st_block_case <- function(sf, cs, fmt, blocks, full, seed, sf_g = sf,
                          hot = FALSE) {
  H <- 3600 * sf_g
  pages <- round((14512 * (sf_g / 50)) * (cs * 0.5))
  B <- pages * 300
  n <- floor(blocks * pages) * 300
  rec <- simulate_recording(hours = n / sf / 3600 + 0.01, sf = sf, seed = seed,
                            params = known_params(),
                            tempoffset = c(0.002, -0.001, 0.0015))
  rec <- rec[seq_len(n), ]
  rec$temperature <- round(25 + 2 * sin(2 * pi * seq_len(n) / (3600 * sf)), 2)
  z <- rep(FALSE, n)
  z[1] <- TRUE
  z[B - c(0, 7, 14, 21)] <- TRUE
  if (sf != sf_g) z[B - 0:40] <- TRUE  # GGIR resamples: a run, not one sample
  if (full) {
    c1 <- st_block_plan(B, sum(z[1:B]), H)$carry
    z2 <- (c1 + B) %% H
    if (z2 > 0) z[B + 1000 + seq_len(z2)] <- TRUE
    z[(2 * B + 200):(3 * B + 500)] <- TRUE
  } else {
    z[(B - 100):(B + 60)] <- TRUE
    z[(2 * B - 30):(2 * B + 30)] <- TRUE
  }
  z <- z[seq_len(n)]
  rec[z, c("x", "y", "z")] <- 0
  nb <- ceiling(n / B)
  rows <- pmin(B, n - (seq_len(nb) - 1) * B)
  plan <- st_block_plan(rows, tabulate(ceiling(which(z) / B), nb), H)
  tie <- NA
  if (full) {
    # Block 3 is dropped and block 2 kept the carry of block 1, so GGIR's
    # window after block 2's last one is block 4's first, made of the
    # carried samples of block 1: make it a moving window whose sds tie
    # with that last window's (a shift by whole 1/256 g), so that GGIR's
    # duplicate filter compares the two across the dropped block.
    L <- 10 * sf
    r1 <- which(!z[1:B])
    first4 <- r1[plan$use[1] + seq_len(L)]
    last2 <- 2 * B - L + seq_len(L)
    X <- as.matrix(rec[, c("x", "y", "z")])
    X[last2, 1] <- X[last2, 1] + round(25.6 * sin(seq_len(L) / 3)) / 256
    for (shift in 1:20) {
      X[first4, ] <- sweep(X[last2, ], 2, c(shift, -2 * shift, 3) / 256, "+")
      ft <- rbind(st_features(X, min(last2), 1, L), st_features(X, min(first4), 1, L))
      tie <- sum(ft[1, ] == ft[2, ])
      if (tie == 3) break
    }
    rec[, c("x", "y", "z")] <- X
  }
  if (hot) {
    # block 2's first used temperatures (carried from block 1) above 120
    start2 <- which(!z[1:B])[plan$use[1] + 1]
    rec$temperature[start2 - 600 + 0:3600] <- 125
  }
  f <- tempfile(fileext = paste0(".", fmt))
  pr <- if (fmt == "csv") write_adhoc(rec, f, sf) else {
    gravcal:::write_geneactiv_bin(rec, f, sf = sf)
    list()
  }
  list(file = f, params = c(pr, list(chunksize = cs)), plan = plan, B = B,
       zero = z, sf = sf, tie = tie)
}

test_that("block rules: idle-sleep zeros at block ends, whole-hour and dropped blocks (10, 12.5 Hz)", {
  skip_if_quick()
  # Aims at GgirBlocks (the carry, GGIR's accidents) and at the decoders
  # writing into its buffer (writes end one sample past the current hour;
  # zeros dropped in place): csv (rows) and GENEActiv .bin (pages of 300).
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  for (cc in list(list(10, "csv"), list(10, "bin"), list(12.5, "csv"))) {
    k <- st_block_case(cc[[1]], 0.2, cc[[2]], blocks = 4.3, full = TRUE, seed = 401)
    # the edges are there: a block of whole hours, a dropped block, a zero
    # as the last sample of block 1
    expect_true(any(k$plan$use == k$plan$LD & k$plan$use > 0))
    expect_true(any(k$plan$use == 0))
    expect_true(k$zero[k$B])
    expect_identical(k$tie, 3L)  # exactly 3 of 6 equal across the dropped block
    b <- run_both(k$file, k$params)
    expect_same_as_ggir(b)
    expect_identical(nrow(b$ggir$bsc_qc), sum(k$plan$use > 0))
    if (cc[[2]] == "csv") {
      expect_same_as_ggir(st_frame_vs(b, k$file, k$sf, 0.2))
    }
    unlink(k$file)
  }
})

test_that("block rules at 12.5, 30, 50, 85.7 and 100 Hz (GENEActiv .bin, csv)", {
  skip_if_quick()
  # The same edges where blocks, pages (300 samples), windows (10 sf
  # samples) and hours (3600 sf) fall differently: GGIR resamples a .bin
  # at 12.5 Hz to 12 (and stops after block 1) and at 85.7 Hz to 86, block
  # by block; an ad hoc csv at 85.7 Hz is read at 85.7 (windows of 857
  # samples, hours of 308520).
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  cases <- list(list(12.5, "bin", 0.2, 12), list(30, "bin", 0.5, 30),
                list(50, "bin", 0.2, 50), list(85.7, "bin", 0.2, 86),
                list(100, "bin", 0.2, 100), list(85.7, "csv", 0.2, 85.7))
  for (cc in cases) {
    k <- st_block_case(cc[[1]], cc[[3]], cc[[2]], blocks = if (cc[[2]] == "csv") 1.4 else 2.3,
                       full = FALSE, seed = 402, sf_g = cc[[4]])
    b <- run_both(k$file, k$params)
    expect_same_as_ggir(b)
    if (cc[[2]] == "csv") expect_same_as_ggir(st_frame_vs(b, k$file, k$sf, cc[[3]]))
    unlink(k$file)
  }
})

test_that("block rules at chunksize 1 and 0.1 (GENEActiv .bin)", {
  # chunksize 1: GGIR's default 12-hour blocks (1451 pages at 10 Hz), zeros
  # at both block ends, and the page temperatures of block 1's carried
  # samples at 125 degrees (block 2's first 10 used values: GGIR stops
  # using temperature there); chunksize 0.1: a first block under two
  # hours, which GGIR takes for a file too short.
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  k <- st_block_case(10, 1, "bin", blocks = 2.2, full = FALSE, seed = 403,
                     hot = TRUE)
  b <- run_both(k$file, k$params)
  expect_same_as_ggir(b)
  expect_identical(nrow(b$ggir$bsc_qc), sum(k$plan$use > 0))
  expect_false(b$ggir$use.temp)
  expect_true(any(b$ggir$spheredata[[8]] == 99999))
  b <- run_both(k$file, list(chunksize = 0.1))
  expect_same_as_ggir(b)
  expect_match(b$ggir$QCmessage, "not enough data")
  unlink(k$file)
})

test_that("rates whose hour is not a whole number in double (33.3, 64.1 Hz, csv)", {
  skip_if_quick()
  # 3600 * 33.3 is 119879.99999999999 in double: GGIR's whole hours are
  # floor(LD / (3600 sf)) * 3600 sf, a number just below k * 119880; R's
  # `:` (with its fuzz) still takes k * 119880 rows for them, and GGIR's
  # carry data[(use + 1):LD, ] then starts at the last used row again and
  # leaves out the block's last row (beyond row 2^18 its fractional indices
  # round both ways); with LD exactly whole hours it is the last two used
  # rows, later first. GgirBlocks::shift_carry() takes the same rows.
  skip_if_not_installed("GGIR")
  cases <- list(list(sf = 33.3, hours = 2.5, chunksize = 1),
                list(sf = 33.3, hours = 5, chunksize = 0.2),
                list(sf = 64.1, hours = 3, chunksize = 0.2),
                # 1998 pages of 300 rows: the first block is exactly 5 hours
                list(sf = 33.3, hours = 7, chunksize = 0.41345))
  for (k in cases) {
    expect_lt(3600 * k$sf, round(3600 * k$sf))
    rec <- simulate_recording(hours = k$hours, sf = k$sf, seed = 404,
                              params = known_params())
    f <- tempfile(fileext = ".csv")
    pr <- write_adhoc(rec, f, k$sf)
    b <- run_both(f, c(pr, list(chunksize = k$chunksize)))
    expect_same_as_ggir(b)
    unlink(f)
  }
})

test_that("block counts on the edges: a first block of two hours, and whole blocks", {
  # GGIR takes a block with fewer than 2 h + 1 sample for the last one (the
  # first one then for a file too short): a csv of exactly 72000 rows at
  # 10 Hz, and of 72001, one with its last sample an idle-sleep zero; a
  # .bin of exactly two of GGIR's blocks (580 pages at chunksize 0.2), so
  # that no block is short and the third read finds nothing.
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  rec <- simulate_recording(hours = 5, sf = 10, seed = 405,
                            params = known_params(),
                            tempoffset = c(0.002, -0.001, 0.0015))
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  for (n in c(72000, 72001, 72002)) {
    r <- rec[seq_len(n), ]
    if (n == 72002) r[n, c("x", "y", "z")] <- 0
    pr <- write_adhoc(r, f, 10)
    b <- run_both(f, pr)
    expect_same_as_ggir(b)
    expect_identical(grepl("not enough data", b$ggir$QCmessage), n == 72000)
  }
  g <- tempfile(fileext = ".bin")
  on.exit(unlink(g), add = TRUE)
  gravcal:::write_geneactiv_bin(rec[seq_len(2 * 290 * 300), ], g, sf = 10)
  b <- run_both(g, list(chunksize = 0.2))
  expect_same_as_ggir(b)
  expect_identical(nrow(b$ggir$bsc_qc), 2L)
})

# --- 5. csv numbers in every form fread reads ------------------------------

test_that("csv numbers: forms fread reads as numbers, read as fread reads them", {
  skip_if_quick()
  # slow tier; make quick keeps the number parser against fread
  # (test-decode-csv.R: numbers of every shape) and the csv rest-rule cases
  # Aims at the csv decoder's number parser (fread 1.14.8's long double
  # product, its 18-digit limit, the fast path for plain numbers): each
  # value written in one of many forms, chosen per value: 15 and 17
  # significant digits, 22 decimals (beyond fread's 18 digits), scientific
  # notation, a leading '+', leading zeros, no leading zero, trailing
  # zeros, blanks around it; idle-sleep rows as "-0".
  skip_if_not_installed("GGIR")
  sf <- 10
  rec <- simulate_recording(hours = 3, sf = sf, seed = 501,
                            params = known_params(), resolution = 0,
                            tempoffset = c(0.002, -0.001, 0.0015))
  rec[c(40000:40100, 72000), c("x", "y", "z")] <- 0
  set.seed(5)
  forms <- function(v) {
    k <- sample(9, length(v), replace = TRUE)
    s <- sprintf("%.15g", v)
    s[k == 2] <- sprintf("%.17g", v[k == 2])
    s[k == 3] <- sprintf("%.22f", v[k == 3])
    s[k == 4] <- sprintf("%.12e", v[k == 4])
    s[k == 5] <- sprintf("%+.15g", v[k == 5])
    s[k == 6] <- paste0("00", sprintf("%.14f", abs(v[k == 6])))
    s[k == 6 & v < 0] <- paste0("-", s[k == 6 & v < 0])
    s[k == 7] <- sub("^(-?)0\\.", "\\1.", sprintf("%.15g", v[k == 7]))
    s[k == 8] <- sprintf("%.16f", v[k == 8])
    s[k == 9] <- paste0(" ", sprintf("%.15g", v[k == 9]), " ")
    s[v == 0] <- "-0"
    s
  }
  cols <- lapply(rec[, c("x", "y", "z", "temperature")], forms)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  writeLines(c("x,y,z,temperature", do.call(paste, c(cols, sep = ","))), f)
  pr <- list(rmc.firstrow.acc = 2, rmc.col.acc = 1:3, rmc.col.temp = 4,
             rmc.sf = sf, rmc.noise = 0.013 / 1.2, rmc.unit.acc = "g",
             rmc.unit.temp = "C")
  d <- data.table::fread(f, data.table = FALSE)
  expect_true(all(vapply(d, is.numeric, TRUE)))
  for (cs in c(0.2, 1)) {
    b <- run_both(f, c(pr, list(chunksize = cs)))
    expect_same_as_ggir(b)
  }
})

# --- 6. further corners of GGIR's procedure --------------------------------

test_that("not enough data: GGIR's spheredata holds every window, with R's sds", {
  # When the distinct windows are not more than minloadcrit - 21 (GGIR
  # compares windows with hours), GGIR returns all windows as spheredata,
  # moving ones included, so every sd there is R's sd() to the bit: the
  # moving windows' sds that lazy_r_sd() leaves in double are seen too.
  skip_if_not_installed("GGIR")
  rec <- simulate_recording(hours = 3, sf = 10, seed = 601,
                            params = known_params())
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- write_adhoc(rec, f, 10)
  b <- run_both(f, c(pr, list(minloadcrit = 2000)))
  expect_match(b$ggir$QCmessage, "not enough data")
  expect_gt(sum(apply(b$ggir$spheredata[, 5:7], 1, max) >= 0.013), 100)
  expect_same_as_ggir(b)
})

test_that("a window whose mean Euclidean norm is GGIR's fill value 99999", {
  # GGIR fills its window table with 99999 and drops rows whose first
  # column (mean norm) is 99999 before anything else: a window of samples
  # (99999, 0, 0) at the start of a block (fresh cumsum(): its mean norm is
  # exactly 99999) is dropped, and not counted in nhoursused.
  skip_if_not_installed("GGIR")
  rec <- simulate_recording(hours = 3, sf = 10, seed = 602,
                            params = known_params())
  rec[72000 + 1:100, c("x", "y", "z")] <- data.frame(99999, 0, 0)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- write_adhoc(rec, f, 10)
  b <- run_both(f, c(pr, list(chunksize = 0.2)))
  expect_same_as_ggir(b)
})

test_that("where GGIR's fit fails with an error, gravcal says why instead", {
  # GGIR fits after every block. Here block 1's rest windows all have the
  # same temperature (the first window, left out, another), so its fit has
  # an aliased temperature column: lm.wfit() gives NA and the next
  # iteration stops GGIR with an error, although the block's temperature
  # passes the sd check and the whole recording would fit. gravcal (see
  # ?g.calibrate) skips the fits that cannot stop the reading and goes on
  # past a fit that does not stay finite: the result is that of the last
  # block's fit, the same whatever minloadcrit made the earlier fits run.
  skip_if_not_installed("GGIR")
  rec <- simulate_recording(hours = 3, sf = 10, seed = 1,
                            params = known_params())
  rec$temperature[1:72000] <- 25
  rec$temperature[1:100] <- 26
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- write_adhoc(rec, f, 10)
  res <- list()
  for (mlc in c(168, 1)) {
    r <- st_run_both(f, c(pr, list(chunksize = 0.2, minloadcrit = mlc)))
    expect_true(inherits(r$ggir, "error"))  # the edge: GGIR's fit fails
    expect_false(inherits(r$gravcal, "error"))
    expect_true(all(is.finite(c(r$gravcal$scale, r$gravcal$offset, r$gravcal$tempoffset))))
    res[[length(res) + 1]] <- r$gravcal
  }
  for (nm in c("scale", "offset", "tempoffset", "cal.error.end", "npoints", "spheredata")) {
    expect_identical(res[[2]][[nm]], res[[1]][[nm]], label = nm)
  }
  # when the last fit itself does not stay finite (every rest window at one
  # temperature, the temperature varying only while moving), GGIR stops
  # with an error and gravcal returns no correction, with a message
  rec2 <- rec
  rec2$temperature[] <- 25
  moving <- which(stats::ave(rec2$x, (seq_len(nrow(rec2)) - 1) %/% 100,
                             FUN = stats::sd) > 0.05)
  rec2$temperature[moving] <- 25 + seq_along(moving) %% 7
  f2 <- tempfile(fileext = ".csv")
  on.exit(unlink(f2), add = TRUE)
  pr2 <- write_adhoc(rec2, f2, 10)
  r <- st_run_both(f2, c(pr2, list(chunksize = 1)))
  expect_true(inherits(r$ggir, "error"))
  expect_false(inherits(r$gravcal, "error"))
  expect_match(r$gravcal$QCmessage, "did not stay finite")
  expect_identical(r$gravcal$scale, c(1, 1, 1))
  expect_identical(r$gravcal$offset, c(0, 0, 0))
  fit <- suppressWarnings(calibrate(rec2[, c("x", "y", "z", "temperature")], sf = 10,
                                    method = "ggir", ggir_compat = TRUE))
  expect_identical(fit$status, "diverged")
})

test_that("missing samples in a data frame are left out of their window", {
  # GGIR reads "NA" in a csv as NA; its cumsum() then makes every later
  # window of the block NA (dropped). gravcal (see ?g.calibrate) leaves a
  # missing or infinite sample of a data frame out of its window and keeps
  # the rest of the block: its hours are the recording's, GGIR's fewer.
  skip_if_not_installed("GGIR")
  rec <- simulate_recording(hours = 3, sf = 10, seed = 603,
                            params = known_params())
  rec$x[5000] <- NA
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- write_adhoc(rec, f, 10)
  b <- st_frame_vs(run_both(f, c(pr, list(chunksize = 0.2))), f, 10, 0.2)
  expect_lt(b$ggir$nhoursused, 2)
  expect_identical(b$gravcal$nhoursused, 3)
  # the windows other than the one holding the missing sample are those of
  # the complete recording (up to the last bits of their means, which are
  # differences of the block's running sum, as in GGIR)
  full <- rec
  full$x[5000] <- 0.5
  G <- suppressWarnings(gravcal::g.calibrate(full[, c("x", "y", "z", "temperature")],
                                             sf = 10, chunksize = 0.2, verbose = FALSE,
                                             minloadcrit = 1e6))
  N <- suppressWarnings(gravcal::g.calibrate(rec[, c("x", "y", "z", "temperature")],
                                             sf = 10, chunksize = 0.2, verbose = FALSE,
                                             minloadcrit = 1e6))
  # minloadcrit beyond the recording: spheredata holds every window
  keep <- setdiff(intersect(rownames(G$spheredata), rownames(N$spheredata)), "50")
  expect_gt(length(keep), 1000)
  expect_equal(N$spheredata[keep, ], G$spheredata[keep, ], tolerance = 1e-12)
  expect_identical(N$spheredata[keep, 5:7], G$spheredata[keep, 5:7])  # sds: per window
  expect_gt(abs(N$spheredata["50", 2] - G$spheredata["50", 2]), 1e-4)
})
