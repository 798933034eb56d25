# The GGIR procedure: gravcal::g.calibrate against GGIR::g.calibrate on the
# same input, gravcal's own mode against known truth, GGIR's coefficient
# file, and bad input.

test_that("g.calibrate matches today's GGIR on the agcounts recording", {
  skip_if_not_installed("GGIR")
  d <- skip_if_no_shared("agcounts", "calibrationXaxis.RData")
  d <- dirname(d)
  env <- new.env()
  for (v in c("X", "Y", "Z")) {
    load(file.path(d, paste0("calibration", v, "axis.RData")), envir = env)
  }
  load(file.path(d, "ggirCalibrate.RData"), envir = env)
  samples <- data.frame(x = env$X, y = env$Y, z = env$Z)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  gravcal:::write_actigraph_csv(samples, f, sf = 30)
  b <- run_both(f)
  expect_same_as_ggir(b)
  # the same samples as a data frame: the same answer
  G2 <- gravcal::g.calibrate(samples, sf = 30, verbose = FALSE)
  expect_lt(max(abs(G2$offset - b$ggir$offset)), 1e-8)
  expect_identical(G2$npoints, b$ggir$npoints)
  # Against the result stored with the samples (bhelsel/agcounts
  # inst/extdata/ggirCalibrate.RData, made by a 2023 GGIR): GGIR itself has
  # moved since by up to 6e-4 in offset and 3 in npoints.
  ref <- env$C
  expect_lt(max(abs(b$gravcal$offset - ref$offset)), 1e-3)
  expect_lt(abs(b$gravcal$npoints - ref$npoints), 5)
  expect_identical(b$gravcal$QCmessage, ref$QCmessage)
})

test_that("g.calibrate matches GGIR on synthetic ActiGraph csv files", {
  skip_if_not_installed("GGIR")
  rec <- simulate_recording(hours = 26, sf = 20, seed = 41,
                            params = known_params(), temperature = FALSE)
  # idle sleep: a run of zeros inside the recording and one at the end of
  # the first block
  rec[c(300001:320000, 1306190:1306199), c("x", "y", "z")] <- 0
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  gravcal:::write_actigraph_csv(rec, f, sf = 20)
  # default minloadcrit (168 h): all data used, "attempted"
  b <- run_both(f)
  expect_same_as_ggir(b)
  expect_match(b$gravcal$QCmessage, "attempted with all available data")
  # minloadcrit 12 h: accepted after the second block, loading stops early
  b12 <- run_both(f, list(minloadcrit = 12))
  expect_same_as_ggir(b12)
  expect_identical(b12$gravcal$QCmessage, "recalibration done, no problems detected")
  expect_equal(nrow(b12$gravcal$bsc_qc), 2L)
  # the memory record: MB in use after each block, at least R's own heap
  # (at least 10 MB with gravcal loaded) and far below the machine's size
  mb <- b12$gravcal$bsc_qc$size
  expect_true(all(is.finite(mb) & mb > 10 & mb < 1e6))
  # the same samples held in memory (blocks as ranges of the caller's
  # columns, idle-sleep blocks through the copying path): GGIR's answer
  samples <- rec[, c("x", "y", "z")]
  before <- unserialize(serialize(samples, NULL))
  G <- gravcal::g.calibrate(samples, sf = 20, verbose = FALSE)
  for (nm in c("scale", "offset")) expect_identical(G[[nm]], b$ggir[[nm]])
  expect_identical(G$npoints, b$ggir$npoints)
  expect_identical(G$QCmessage, b$ggir$QCmessage)
  expect_identical(rownames(G$spheredata), rownames(b$gravcal$spheredata))
  expect_identical(samples, before)
})

test_that("g.calibrate matches GGIR with temperature (ad hoc csv)", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  rec <- simulate_recording(hours = 26, sf = 20, seed = 42,
                            params = known_params(),
                            tempoffset = c(0.002, -0.001, 0.0015))
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- write_adhoc(rec, f, 20)
  b <- run_both(f, pr)
  expect_same_as_ggir(b)
  expect_true(b$gravcal$use.temp)
  expect_identical(names(b$gravcal$spheredata)[8], "temperature")
  b12 <- run_both(f, c(pr, list(minloadcrit = 12)))
  expect_same_as_ggir(b12)
  expect_identical(b12$gravcal$QCmessage, "recalibration done, no problems detected")
})

test_that("GGIR's block rules: zeros, whole hours, carry, temperature", {
  # an independent restatement of g.calibrate's block handling in R (GGIR
  # 3.3: idle-sleep rows removed, whole hours kept, the rest carried, R's
  # mean and sd of the used temperatures), against the core's GgirBlocks
  set.seed(5)
  sf <- 1
  H <- 3600 * sf
  n1 <- 2 * H + 1234
  n2 <- 3 * H + 17
  mk <- function(n) {
    d <- data.frame(x = stats::rnorm(n), y = stats::rnorm(n), z = stats::rnorm(n),
                    t = 25 + cumsum(stats::rnorm(n, sd = 0.01)))
    d
  }
  b1 <- mk(n1)
  b2 <- mk(n2)
  zero <- c(1, 4096, 4097, 5000:5100, n1)  # the block ends on a zero
  b1[zero, 1:3] <- 0
  b1$x[100] <- b1$y[100] <- 0  # not idle sleep: z is not zero
  b1$t[c(3, 500)] <- NA
  ref_block <- function(P, last_zero, compat) {
    if (compat && last_zero) P[nrow(P), 1:3] <- P[nrow(P) - 1, 1:3]
    use <- floor(nrow(P) / H) * H
    list(used = P[seq_len(use), ], rest = P[-seq_len(use), ])
  }
  for (compat in c(TRUE, FALSE)) {
    res <- pump_blocks(list(b1, b2), sf, compat, per_hour = H)
    r1 <- res[[1]]
    keep <- !(b1$x == 0 & b1$y == 0 & b1$z == 0)
    e1 <- ref_block(b1[keep, ], TRUE, compat)
    expect_identical(r1$rows, as.numeric(n1))
    expect_identical(r1$zeros, as.numeric(sum(!keep)))
    expect_identical(r1$used, as.numeric(nrow(e1$used)))
    expect_identical(r1$carried, as.numeric(nrow(e1$rest)))
    expect_identical(r1$first_mean, mean(e1$used$t[1:10], na.rm = TRUE))
    # the temperature's sd only decides whether it varies: from the
    # run-length code, to rounding (compatible mode: R's decision, see the
    # next test)
    expect_equal(r1$temp_sd, stats::sd(e1$used$t, na.rm = TRUE), tolerance = 1e-13)
    expect_identical(length(r1$windows$mean_x), nrow(e1$used) %/% 10L)
    # window means as GGIR forms them (compatible mode): differences of the
    # block's cumulative sum; gravcal's own arithmetic: to rounding
    gmean <- diff(c(0, cumsum(e1$used$x)[seq(10, 50, by = 10)])) / 10
    if (compat) {
      expect_identical(r1$windows$mean_x[1:5], gmean)
    } else {
      expect_equal(r1$windows$mean_x[1:5], gmean, tolerance = 1e-14)
    }
    # the carry goes in front of the next block
    r2 <- res[[2]]
    e2 <- ref_block(rbind(e1$rest, b2), FALSE, compat)
    expect_identical(r2$used, as.numeric(nrow(e2$used)))
    expect_equal(r2$temp_sd, stats::sd(e2$used$t, na.rm = TRUE), tolerance = 1e-13)
    if (compat) {
      expect_identical(r2$windows$sd_y[1], stats::sd(e2$used$y[1:10]))
    } else {
      expect_equal(r2$windows$sd_y[1], stats::sd(e2$used$y[1:10]), tolerance = 1e-14)
    }
  }
  # a block of whole hours: gravcal carries nothing; GGIR's compatible mode
  # puts the previous carry in front once more
  for (compat in c(TRUE, FALSE)) {
    res <- pump_blocks(list(mk(H + 5), mk(2 * H - 5), mk(H)), sf, compat,
                       temperature = FALSE, per_hour = H)
    expect_identical(res[[2]]$used, 2 * H)
    expect_identical(res[[3]]$ld, if (compat) H + 5 else H)
  }
})

test_that("the temperature check decides as R's sd() at the threshold", {
  # Compatible mode takes the temperature's sd from its run-length code and
  # repeats R's arithmetic only when that sd lies within rounding of
  # temp_min_sd (r_sd_below() in r_arith.hpp). Blocks whose R sd() is the
  # threshold itself, or one or two doubles either side of it, must go
  # R's way, and those sds must be R's to the bit.
  sf <- 1
  H <- 3600 * sf
  thr <- gravcal:::ggir_constants$temp_min_sd
  # two temperatures in runs (as device files store them) whose sd is the
  # threshold to about 1e-13; then the first value moved by whole doubles
  # (one double of 25 is 2^-48) to where R's sd() crosses the threshold
  d <- thr * sqrt((H - 1) / H)
  base <- 25 + rep(c(-d, d), each = 5, length.out = H)
  sd_of <- function(k) {
    t <- base
    t[1] <- t[1] + k * 2^-48
    t
  }
  below <- function(k) stats::sd(sd_of(k)) < thr
  lo <- 0
  hi <- 2^20
  expect_true(!below(lo) && below(hi))
  while (hi - lo > 1) {
    m <- (lo + hi) %/% 2
    if (below(m)) hi <- m else lo <- m
  }
  near <- hi + (-3:2)
  sds <- vapply(near, function(k) stats::sd(sd_of(k)), 0)
  # both sides, and (here) the threshold itself
  expect_true(any(sds < thr) && any(sds > thr) && any(sds == thr))
  for (k in near) {
    t <- sd_of(k)
    for (compat in c(TRUE, FALSE)) {
      r <- pump_blocks(list(list(x = rep(0.1, H), y = rep(0.2, H),
                                 z = rep(0.97, H), t = t)),
                       sf, compat, temp_min_sd = thr, per_hour = H)[[1]]
      expect_identical(r$used, as.numeric(H))
      if (compat) {
        expect_true(r$temp_sd_exact)
        expect_identical(r$temp_sd, stats::sd(t))
      } else {
        expect_equal(r$temp_sd, stats::sd(t), tolerance = 1e-13)
      }
    }
  }
  # far from the threshold the fast sd decides; R's decision all the same
  for (spread in c(0, 1e-3, 0.5 * thr, 0.999999 * thr, 1.000001 * thr, 3)) {
    t <- 25 + spread * rep(c(-1, 1), each = 7, length.out = H)
    r <- pump_blocks(list(list(x = rep(0.1, H), y = rep(0.2, H),
                               z = rep(0.97, H), t = t)),
                     sf, TRUE, temp_min_sd = thr, per_hour = H)[[1]]
    expect_false(r$temp_sd_exact)
    expect_identical(r$temp_sd < thr, stats::sd(t) < thr)
    expect_equal(r$temp_sd, stats::sd(t), tolerance = 1e-13)
  }
})

test_that("g.calibrate matches GGIR where its rules compare window sds", {
  skip_if_quick()
  # Compatible mode computes a window's sds in R's arithmetic only where
  # GGIR's rules can tell (Segmenter::lazy_r_sd()): at rest or near the
  # rest threshold, and when the duplicate filter could find an sd equal to
  # the previous window's. Windows that repeat the one before with their
  # samples reversed or rotated (R's sds then often tie while sds in
  # double do not), whole repeats, and windows scaled to the threshold:
  # GGIR's answer to the bit.
  skip_if_not_installed("GGIR")
  sf <- 20
  rec <- simulate_recording(hours = 26, sf = sf, seed = 44,
                            params = known_params(),
                            tempoffset = c(0.002, -0.001, 0.0015))
  n <- 10 * sf
  set.seed(3)
  for (k in sample(seq(2, nrow(rec) / n - 2), 1500)) {
    a <- (k - 1) * n + seq_len(n)
    b <- k * n + seq_len(n)
    p <- switch(k %% 3 + 1, rev(seq_len(n)), c(2:n, 1), seq_len(n))
    rec[b, c("x", "y", "z")] <- rec[a[p], c("x", "y", "z")]
  }
  # windows whose x sd is the threshold to about a double
  thr <- 0.013
  for (k in sample(seq(2, nrow(rec) / n - 2), 300)) {
    b <- k * n + seq_len(n)
    v <- rec$x[b]
    rec$x[b] <- mean(v) + (v - mean(v)) * thr / stats::sd(v)
  }
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  pr <- write_adhoc(rec, f, sf)
  b <- run_both(f, c(pr, list(minloadcrit = 12)))
  expect_same_as_ggir(b)
  b <- run_both(f, pr)
  expect_same_as_ggir(b)
})

test_that("the duplicate filter cuts the windows R's comparisons cut", {
  # GGIR's own expression on its window table (columns 2 to 7: means and
  # sds): a window goes when it equals the next in exactly 3 of them
  # (gravcal's own mode: all 6); a comparison with NA or NaN makes the count
  # NA, which never matches
  r_cut <- function(full, idx, need) {
    n <- length(idx)
    same <- integer(n - 1)
    for (j in 2:7) {
      col <- full[idx, j]
      same <- same + (col[-n] == col[-1])
    }
    which(same == need)
  }
  set.seed(12)
  vals <- c(0, -0, 1, 0.5, NA, NaN, 2^-1074, -1)
  for (rep in 1:40) {
    nr <- sample(2:300, 1)
    full <- matrix(sample(vals, nr * 8, replace = TRUE,
                          prob = c(4, 2, 4, 4, 1, 1, 1, 2)), nr, 8)
    idx <- sort(sample(nr, sample(2:nr, 1)))
    for (need in c(3L, 6L, 0L)) {
      expect_identical(gravcal:::gc_ggir_duplicates(full, idx, need),
                       r_cut(full, idx, need))
    }
  }
  expect_length(gravcal:::gc_ggir_duplicates(matrix(0, 3, 8), 2L, 3L), 0)
  expect_error(gravcal:::gc_ggir_duplicates(matrix(0, 3, 8), c(1L, 4L), 3L),
               "out of range")
  expect_error(gravcal:::gc_ggir_duplicates(matrix(0, 3, 6), 1:2, 3L),
               "7 columns")
})

test_that("g.calibrate matches GGIR when it cannot calibrate", {
  skip_if_not_installed("GGIR")
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  # too little rest: the wearer never keeps still
  moving <- simulate_recording(hours = 3, sf = 20, seed = 43, noise = 0.05,
                               rest_fraction = 0, temperature = FALSE)
  gravcal:::write_actigraph_csv(moving, f, sf = 20)
  b <- run_both(f)
  expect_same_as_ggir(b)
  expect_identical(b$gravcal$QCmessage,
                   "recalibration not done because no non-movement data available")
  # one orientation only: the sphere is not covered
  n <- 3 * 3600 * 20
  set.seed(44)
  flat <- data.frame(x = round(rnorm(n, 0.02, 0.003), 3),
                     y = round(rnorm(n, -0.01, 0.003), 3),
                     z = round(rnorm(n, 1.01, 0.003), 3))
  gravcal:::write_actigraph_csv(flat, f, sf = 20)
  b <- run_both(f)
  expect_same_as_ggir(b)
  expect_identical(b$gravcal$QCmessage, paste0(
    "recalibration not done because not enough points on all sides of the ",
    "sphere"))
  # a very short file (1.5 h: under GGIR's two hours for a first block)
  short <- simulate_recording(hours = 1.5, sf = 20, seed = 45,
                              temperature = FALSE)
  gravcal:::write_actigraph_csv(short, f, sf = 20)
  b <- run_both(f)
  expect_same_as_ggir(b)
  expect_identical(b$gravcal$QCmessage, paste0(
    "recalibration not done because not enough data in the file or because ",
    "file is corrupt"))
  expect_null(b$gravcal$spheredata)
})

test_that("gravcal's own mode is 10 times closer to the truth than GGIR's", {
  rec <- simulate_recording(hours = 48, sf = 10, seed = 21,
                            params = known_params(),
                            tempoffset = c(0.002, -0.001, 0.0015))
  tr <- attr(rec, "truth")
  compat <- calibrate(rec, sf = 10, method = "ggir", ggir_compat = TRUE)
  own <- calibrate(rec, sf = 10, method = "ggir")
  expect_equal(c(compat$status, own$status), c("ok", "ok"))
  # truth in GGIR's parametrisation: the fit's meantemp moves the offset by
  # (meantemp - true meantemp) * tempoffset / scale
  err <- function(f) {
    off <- tr$offset + (f$meantemp - tr$meantemp) * tr$tempoffset / diag(tr$K)
    c(offset = max(abs(f$offset - off)),
      tempoffset = max(abs(f$tempoffset - tr$tempoffset)))
  }
  e_compat <- err(compat)
  e_own <- err(own)
  expect_lt(e_own[["offset"]], e_compat[["offset"]] / 10)
  expect_lt(e_own[["tempoffset"]], e_compat[["tempoffset"]] / 10)
  # the compatible mode is GGIR's answer on the same windows
  expect_equal(compat$ggir$QCmessage, own$ggir$QCmessage)
  expect_true(own$converged)
})

test_that("calibrate(method = 'ggir') gives a usable gravcal_fit", {
  rec <- simulate_recording(hours = 26, sf = 10, seed = 46,
                            params = known_params(),
                            tempoffset = c(0.001, 0, -0.001))
  fit <- calibrate(rec, sf = 10, method = "ggir")
  expect_s3_class(fit, "gravcal_fit")
  expect_equal(fit$status, "ok")
  expect_true(all(fit$K[row(fit$K) != col(fit$K)] == 0))
  expect_output(print(fit), "ggir")
  expect_lt(fit$error_after, fit$error_before / 10)
  cal <- apply_calibration(rec, fit)
  w <- rest_windows(cal, sf = 10, method = "ggir")
  expect_lt(err_mg(as.matrix(w[w$rest, c("mean_x", "mean_y", "mean_z")])), 1)
  # GGIR's per-sample formula, written out independently
  s <- diag(fit$K)
  gx <- (rec$x + fit$offset[[1]]) * s[1] +
    (rec$temperature - fit$meantemp) * fit$tempoffset[[1]]
  expect_equal(cal$x, gx, tolerance = 1e-12)
  # failures: identity coefficients, status and GGIR's message
  short <- simulate_recording(hours = 1, sf = 10, seed = 47)
  f0 <- calibrate(short, sf = 10, method = "ggir")
  expect_equal(f0$status, "too_short")
  expect_equal(unname(f0$K), diag(3))
  expect_identical(apply_calibration(short, f0)$x, short$x)
  expect_error(calibrate(rec, sf = 10, method = "ggir", bogus = 1), "bogus")
})

test_that("write_coefs() writes what GGIR reads, and GGIR uses it", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  # GGIR's part 2 draws its QC plots with png(), which an R built without
  # X11 and cairo (make test-noLD's) does not have
  skip_if_not(isTRUE(capabilities("png")), "this R has no png() device (GGIR's part 2 needs it)")
  dir <- tempfile("ggir")
  dir.create(file.path(dir, "data"), recursive = TRUE)
  dir.create(file.path(dir, "out"))
  on.exit(unlink(dir, recursive = TRUE))
  rec <- simulate_recording(hours = 26, sf = 20, seed = 31,
                            params = known_params(), temperature = FALSE)
  f <- file.path(dir, "data", "rec01.csv")
  gravcal:::write_actigraph_csv(rec, f, sf = 20)
  fit <- calibrate(f, method = "ggir")   # gravcal's converged fit
  coefs <- file.path(dir, "coefs.csv")
  write_coefs(fit, coefs)
  out <- utils::read.csv(coefs)
  expect_identical(out$filename, "rec01.csv")
  expect_identical(names(out)[1:10], c(
    "filename", "scale.x", "scale.y", "scale.z", "offset.x", "offset.y",
    "offset.z", "temperature.offset.x", "temperature.offset.y",
    "temperature.offset.z"))
  utils::capture.output(suppressWarnings(GGIR::GGIR(
    datadir = file.path(dir, "data"), outputdir = file.path(dir, "out"),
    mode = 1:2, do.report = 2, backup.cal.coef = coefs, overwrite = TRUE,
    do.parallel = FALSE, verbose = FALSE)))
  rep <- list.files(file.path(dir, "out"), "data_quality_report.csv",
                    recursive = TRUE, full.names = TRUE)
  expect_length(rep, 1)
  q <- utils::read.csv(rep)
  expect_equal(q$scale.x, unname(diag(fit$K))[1], tolerance = 1e-12)
  expect_equal(q$offset.z, unname(fit$offset)[3], tolerance = 1e-12)
  # GGIR's own early-stopping fit differs from it, so the report shows ours
  own <- gravcal::g.calibrate(f, verbose = FALSE)
  expect_gt(abs(q$offset.x - own$offset[1]), 1e-7)
  # a g.calibrate result needs a name; lightweight fits are refused
  expect_error(write_coefs(own, coefs), "named")
  expect_silent(write_coefs(list(rec01.csv = own), coefs))
  # (a lightweight fit with cross-axis terms; the default leaves them out
  # of a device without them, and such a fit can be written)
  lw <- calibrate(rec, sf = 20, model = "full")
  expect_error(write_coefs(list(a.csv = lw), coefs), "cross-axis")
  expect_error(write_coefs(fit, NA), "file")
})

test_that("bad input: clear errors or GGIR's QC outcome, never a crash", {
  expect_error(g.calibrate("no/such/file.bin", verbose = FALSE), "does not exist")
  expect_error(g.calibrate(42, verbose = FALSE), "file path or a data frame")
  f <- tempfile(fileext = ".xyz")
  writeLines("a", f)
  expect_error(g.calibrate(f, verbose = FALSE), "unsupported extension")
  junk <- tempfile(fileext = ".csv")
  writeLines(c("------------ Data File Created By ActiGraph at 30 Hz", rep("junk", 30)), junk)
  # no line of samples at all: an error naming the file and what it holds
  expect_error(g.calibrate(junk, verbose = FALSE), "ActiGraph csv export.*junk")
  empty <- tempfile(fileext = ".csv")
  file.create(empty)
  expect_error(g.calibrate(empty, verbose = FALSE), "empty")
  if (requireNamespace("GGIRread", quietly = TRUE)) {
    bad <- tempfile(fileext = ".cwa")
    writeBin(as.raw(sample(0:255, 5000, TRUE)), bad)
    expect_error(suppressWarnings(g.calibrate(bad, verbose = FALSE)), "cwa")
  }
  on.exit(unlink(c(f, junk, empty)))
  # data frames: no sf, non-numeric columns, bad parameters
  rec <- simulate_recording(hours = 3, sf = 10, seed = 48)
  expect_error(g.calibrate(rec[, c("x", "y", "z")], verbose = FALSE), "sf")
  expect_error(g.calibrate(rec, sf = 10, chunksize = 2, verbose = FALSE),
               "chunksize")
  expect_error(g.calibrate(rec, sf = 10, params_rawdata = "x"), "params_rawdata")
  expect_warning(g.calibrate(rec, sf = 10, nonsense = 1, verbose = FALSE),
                 "nonsense")
  # temperature constant, or absurd: not used, with a warning
  r2 <- simulate_recording(hours = 26, sf = 10, seed = 49,
                           params = known_params())
  r2$temperature <- 25
  expect_warning(C <- g.calibrate(r2, sf = 10, minloadcrit = 12, verbose = FALSE),
                 "does not vary")
  expect_false(C$use.temp)
  expect_identical(C$QCmessage, "recalibration done, but temperature values not used")
  r2$temperature <- 400
  expect_warning(C <- g.calibrate(r2, sf = 10, verbose = FALSE), "120")
  expect_false(C$use.temp)
  # clipped data: windows with |mean| >= 2 g are not rest; no crash
  r3 <- simulate_recording(hours = 26, sf = 10, seed = 50)
  r3$x <- pmin(r3$x * 3, 2.5)
  C <- g.calibrate(r3, sf = 10, verbose = FALSE)
  expect_type(C$QCmessage, "character")
  expect_true(all(abs(C$spheredata$meanx) < 2))
  # NA samples: windows with them are not rest
  r4 <- simulate_recording(hours = 3, sf = 10, seed = 51)
  r4$x[1000:5000] <- NA
  expect_type(g.calibrate(r4, sf = 10, verbose = FALSE)$QCmessage, "character")
})

test_that("g.calibrate matches GGIR on the devices' own files (cwa, bin)", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  for (f in c(system.file("testfiles", "ax3_testfile.cwa", package = "GGIRread"),
              system.file("testfiles", "GENEActiv_testfile.bin", package = "GGIRread"))) {
    b <- run_both(f)
    expect_same_as_ggir(b)
  }
})

test_that("g.calibrate matches GGIR on a GENEActiv .bin of several blocks", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  # 30 hours at 20 Hz: GGIR reads a .bin in blocks of about 12 hours, so this
  # crosses two block boundaries, with the carry-over between blocks
  rec <- simulate_recording(hours = 30, sf = 20, seed = 21,
                            tempoffset = c(0.002, -0.001, 0.0015))
  f <- tempfile(fileext = ".bin")
  on.exit(unlink(f))
  gravcal:::write_geneactiv_bin(rec, f, sf = 20)
  b <- run_both(f)
  expect_gt(b$ggir$npoints, 50)
  expect_same_as_ggir(b)
})

test_that("an ActiGraph csv with a time stamp column gives the same calibration", {
  skip_if_quick()
  # slow tier: 14 hours at 20 Hz written and read twice; make quick keeps the
  # ActiGraph csv identity without a time column (above)
  skip_if_not_installed("GGIR")
  rec <- simulate_recording(hours = 14, sf = 20, seed = 31)
  f1 <- tempfile(fileext = ".csv")
  f2 <- tempfile(fileext = ".csv")
  on.exit(unlink(c(f1, f2)))
  gravcal:::write_actigraph_csv(rec, f1, sf = 20)
  gravcal:::write_actigraph_csv(rec, f2, sf = 20, timestamps = TRUE)
  expect_match(readLines(f2, n = 12)[12], "^5/11/2023 09:00:00.000,")
  a <- calibrate(f1, method = "ggir")
  b <- calibrate(f2, method = "ggir")
  expect_identical(coef(b), coef(a))
  expect_identical(b$points, a$points)
  expect_identical(b$n_windows, a$n_windows)
  expect_identical(b$hours, a$hours)
  # and GGIR agrees on the file with time stamps
  expect_same_as_ggir(run_both(f2))
})

test_that("a GENEActiv .bin at a rate that is not whole: GGIR's resampling, to the bit", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  # 12.5 Hz: GGIR's g.readaccfile interpolates each block onto 12 Hz (R's
  # round), block by block; 30 hours cross two of its blocks (1741 pages)
  rec <- simulate_recording(hours = 30, sf = 12.5, seed = 24,
                            tempoffset = c(0.002, -0.001, 0.0015))
  f <- tempfile(fileext = ".bin")
  on.exit(unlink(f))
  gravcal:::write_geneactiv_bin(rec, f, sf = 12.5)
  pr <- GGIR::load_params()
  I <- suppressWarnings(GGIR::g.inspectfile(f, params_rawdata = pr$params_rawdata))
  expect_identical(I$sf, 12)
  B <- round((14512 * (I$sf / 50)) * 0.5)
  fq <- list(filetooshort = FALSE, filecorrupt = FALSE,
             filedoesnotholdday = FALSE, NFilePagesSkipped = 0)
  h <- gravcal:::native_open(f, "geneactiv", list(compat = 1))
  expect_identical(h$info$sf, 12)
  prev <- c()
  for (k in 1:2) {
    g <- GGIR:::g.readaccfile(f, blocksize = B, blocknumber = k, filequality = fq,
                              ws = 3600, PreviousEndPage = prev,
                              inspectfileobject = I,
                              params_rawdata = pr$params_rawdata,
                              params_general = pr$params_general)
    prev <- g$endpage
    b <- gravcal:::native_block(h, B, B * 600, TRUE, TRUE)
    n <- b$to
    expect_identical(as.integer(n), nrow(g$P$data))
    for (col in c("x", "y", "z", "temperature", "time")) {
      expect_identical(b$cols[[col]][seq_len(n)], g$P$data[[col]], label = col)
    }
  }
  # GGIR takes the first block, resampled to fewer rows than its pages
  # hold, for the last one and stops there; compatible mode does the same
  b <- run_both(f)
  expect_identical(nrow(b$ggir$bsc_qc), 1L)
  expect_same_as_ggir(b)
  # 85.7 Hz, GENEActiv's common rate, onto 86 Hz: 26 hours, three blocks
  rec <- simulate_recording(hours = 26, sf = 85.7, seed = 25)
  gravcal:::write_geneactiv_bin(rec, f, sf = 85.7)
  b <- run_both(f)
  expect_identical(nrow(b$ggir$bsc_qc), 3L)
  expect_same_as_ggir(b)
})

test_that("from a file, calibrate(method = 'ggir') fits the rest windows rest_windows() finds", {
  # the one-call path and the verbs see the same windows: GGIR's rules leave
  # out the recording's first window, and calibrate() fits on the rest
  rec <- simulate_recording(hours = 26, sf = 10, seed = 48,
                            params = known_params(),
                            tempoffset = c(0.001, 0, -0.001))
  f <- tempfile(fileext = ".bin")
  on.exit(unlink(f))
  write_geneactiv_bin(rec, f, sf = 10)
  w <- rest_windows(f, method = "ggir")
  fit <- calibrate(f, method = "ggir")
  expect_equal(fit$status, "ok")
  rest <- w[w$rest & seq_len(nrow(w)) > 1, c("mean_x", "mean_y", "mean_z")]
  expect_equal(nrow(fit$points), nrow(rest))
  expect_identical(unname(as.matrix(fit$points[, c("mean_x", "mean_y", "mean_z")])),
                   unname(as.matrix(rest)))
})

test_that("write_coefs() takes a fit_icp() fit (no `$ggir` partial match)", {
  rec <- simulate_recording(hours = 24, sf = 10, seed = 2,
                            params = c(1.02, 0.98, 1.01, 0, 0, 0, 0.03, -0.02, 0.01))
  fi <- fit_icp(rest_windows(rec, sf = 10, method = "ggir"))
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  write_coefs(list(rec.csv = fi), f)
  out <- utils::read.csv(f)
  expect_equal(out$cal.error.start, fi$error_before)
  expect_equal(out$cal.error.end, fi$error_after)
})

test_that("g.calibrate() gives the same result on one thread and on two", {
  # with two threads the segmenter takes each hour's 10 s windows on the
  # second while the decoder reads the next hour (ggir_blocks.hpp async()):
  # the same windows in the same order, so the same fit, to the bit. 30
  # hours at 25 Hz in GGIR's blocks of 12 hours (carries, idle sleep)
  rec <- simulate_recording(hours = 30, sf = 25, seed = 17, idle_sleep = 0.02,
                            start = as.POSIXct("2024-05-06 07:00:00", tz = "UTC"))
  f <- tempfile(fileext = ".cwa")
  on.exit(unlink(f), add = TRUE)
  gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), f, sf = 25,
                      start = as.numeric(rec$time[1]), temperature = rec$temperature)
  cal <- function(threads) {
    old <- options(gravcal.threads = threads)
    on.exit(options(old))
    list(ggir = gravcal::g.calibrate(f, verbose = FALSE),
         own = coef(gravcal::calibrate(f, method = "ggir", ggir_compat = FALSE)))
  }
  one <- cal(1)
  two <- cal(2)
  expect_gt(one$ggir$npoints, 100)  # a fit on the recording's rest
  expect_gt(one$ggir$nhoursused, 24)
  # (all but bsc_qc, which has the time of the run)
  for (k in setdiff(names(one$ggir), "bsc_qc")) expect_identical(two$ggir[[k]], one$ggir[[k]], label = k)
  expect_identical(two$own, one$own)
})
