# GGIR's filtered metrics (gravcal/ggir/ggir_filters.hpp, R/ggir-filters.R):
# signal::filter() of a Butterworth Arma, and g.applymetrics()'s per-sample
# signals before averaging, to the bit. References: signal 1.8.1's
# filter() and GGIR 3.3-9's g.applymetrics() themselves, and R restatements
# of g.applymetrics()'s expressions written here.

skip_if_no_filter_refs <- function() {
  skip_if_not_installed("signal")
}

# bit for bit: identical() (NA told from NaN) and the same bytes (the sign
# of zeros, NaN payloads)
expect_same_bits <- function(got, ref) {
  expect_identical(got, ref)
  if (is.numeric(ref) && is.numeric(got)) {
    expect_identical(writeBin(as.double(got), raw()), writeBin(as.double(ref), raw()))
  }
}

r_filter <- function(co, x) as.vector(signal::filter(signal::Arma(co$b, co$a), x))

# the first 10 min of GGIRread's test .cwa (100 Hz), uncalibrated
ax3_xyz <- function() {
  skip_if_not_installed("GGIRread")
  f <- system.file("testfiles/ax3_testfile.cwa", package = "GGIRread")
  if (!nzchar(f)) skip("GGIRread's ax3_testfile.cwa not found")
  d <- GGIRread::readAxivity(f, start = 1, end = 1e6)$data
  cbind(x = d$x, y = d$y, z = d$z)
}

# agcounts' 20.7 h at 30 Hz, calibrated as g.getmeta() applies GGIR's
# coefficients (scale(data, center = -offset, scale = 1 / scale))
agcounts_xyz <- function() {
  e <- new.env()
  for (a in c("X", "Y", "Z")) {
    p <- skip_if_no_shared("agcounts", sprintf("calibration%saxis.RData", a))
    load(p, envir = e)
  }
  load(skip_if_no_shared("agcounts", "ggirCalibrate.RData"), envir = e)
  xyz <- cbind(x = e$X, y = e$Y, z = e$Z)
  unname(scale(xyz, center = -e$C$offset, scale = 1 / e$C$scale))
}

filter_types <- c("band", "low", "high", "zc")

test_that("GGIR's coefficient sets: hb capped below sf / 2 as GGIR caps it", {
  skip_if_no_filter_refs()
  expect_identical(gravcal:::ggir_filter_coefs(100)$hb, 15)
  expect_identical(gravcal:::ggir_filter_coefs(30)$hb, 14)    # round(15) - 1
  expect_identical(gravcal:::ggir_filter_coefs(25)$hb, 11)    # round(12.5) is 12
  expect_identical(gravcal:::ggir_filter_coefs(85.7)$hb, 15)
  co <- gravcal:::ggir_filter_coefs(85.7)
  expect_identical(co$low, {
    b <- signal::butter(4, c(15 / (85.7 / 2)), type = "low")
    list(b = b$b, a = b$a)
  })
  expect_length(co$band$b, 9)  # order 4 band pass
  expect_length(co$zc$b, 5)    # order 2 band pass
})

test_that("stats::filter's multiply-adds: the probe reads this R, the replay rounds once where told", {
  fu <- gravcal:::stats_filter_fused()
  expect_type(fu$conv, "logical")
  expect_type(fu$rec, "logical")
  f <- 1 + 2^-30
  x <- c(f, -(1 + 2^-29))
  # convolution: 0 + 1 * x[2] + f * x[1]; recursion: x[2] + f * r[1]
  expect_identical(gravcal:::gc_ggir_filter(c(1, f), 1, x, FALSE, FALSE)[2], 0)
  expect_identical(gravcal:::gc_ggir_filter(c(1, f), 1, x, TRUE, FALSE)[2], 2^-60)
  expect_identical(gravcal:::gc_ggir_filter(1, c(1, -f), x, FALSE, FALSE)[2], 0)
  expect_identical(gravcal:::gc_ggir_filter(1, c(1, -f), x, FALSE, TRUE)[2], 2^-60)
  # and this R's own stats::filter agrees with the replay the probe chose
  expect_identical(gravcal:::gc_ggir_filter(c(1, f), 1, x, fu$conv, fu$rec),
                   as.vector(stats::filter(c(0, x), c(1, f), sides = 1))[-1])
})

test_that("signal::filter, bit for bit, on GGIRread's .cwa at several sf, every filter type", {
  skip_if_no_filter_refs()
  xyz <- ax3_xyz()
  for (sf in c(30, 85.7, 100)) {
    co <- gravcal:::ggir_filter_coefs(sf)
    for (type in filter_types) for (i in 1:3) {
      expect_same_bits(gravcal:::ggir_filter(co[[type]], xyz[, i]), r_filter(co[[type]], xyz[, i]))
    }
  }
  # other orders and bounds (n odd, a high order, GGIR's low zc.order)
  for (n in c(1, 3, 8)) {
    co <- gravcal:::ggir_filter_coefs(100, n = n, lb = 0.5, hb = 10, zc.order = n)
    for (type in filter_types) {
      expect_same_bits(gravcal:::ggir_filter(co[[type]], xyz[, 3]), r_filter(co[[type]], xyz[, 3]))
    }
  }
})

test_that("signal::filter, bit for bit, on a calibrated day block at 30 Hz (shared data)", {
  skip_if_no_filter_refs()
  skip_if_quick()
  xyz <- agcounts_xyz()
  co <- gravcal:::ggir_filter_coefs(30)
  for (type in filter_types) for (i in 1:3) {
    expect_same_bits(gravcal:::ggir_filter(co[[type]], xyz[, i]), r_filter(co[[type]], xyz[, i]))
  }
})

test_that("signal::filter's NA, NaN and Inf: lengths after na.omit, NA or NaN, R's errors", {
  skip_if_no_filter_refs()
  co <- gravcal:::ggir_filter_coefs(100)
  set.seed(3)
  base <- sin(seq_len(200) / 7) + stats::rnorm(200, sd = 0.1)
  cases <- list(
    lead_nan = c(NaN, base), lead_na = c(NA, NA, base), trail_na = c(base, NA),
    trail_nan = c(base, NaN, NaN), both_ends = c(NA, base, NaN),
    internal_na = replace(base, 50, NA), internal_nan = replace(base, 50, NaN),
    inf_mid = replace(base, 100, Inf), ninf_end = replace(base, 200, -Inf),
    inf_start = c(Inf, base), all_na = c(NA_real_, NaN, NA), one = 0.5,
    empty = numeric(0), three = c(1, 2, 3), zeros = rep(0, 20),
    negative_zeros = c(-0, -0, 1, -0), huge = base * 1e306, subnormal = base * 1e-310)
  for (nm in names(cases)) for (type in filter_types) {
    x <- cases[[nm]]
    ref <- tryCatch(r_filter(co[[type]], x), error = function(e) conditionMessage(e))
    got <- tryCatch(gravcal:::ggir_filter(co[[type]], x), error = function(e) conditionMessage(e))
    expect_same_bits(got, ref)
  }
  # the cases do reach each branch
  expect_length(r_filter(co$low, cases$lead_nan), 196)
  expect_error(r_filter(co$band, cases$inf_mid), "internal NAs")
  expect_true(anyNA(r_filter(co$low, cases$inf_mid)))
  expect_identical(r_filter(co$low, cases$all_na), cases$all_na)
})

# g.applymetrics()'s expressions for one metric's per-sample signal,
# restated (process_axes(), EuclideanNorm(), zerocross()).
ref_signal <- function(xyz, metric, co) {
  axes <- function(c1) {
    dp <- xyz
    for (i in 1:3) dp[, i] <- signal::filter(signal::Arma(c1$b, c1$a), xyz[, i])
    dp
  }
  en <- function(m) sqrt((m[, 1]^2) + (m[, 2]^2) + (m[, 3]^2))
  k <- match(substring(metric, 3), c("X", "Y", "Z"))
  switch(substr(metric, 1, 2),
    BF = if (metric == "BFEN") en(abs(axes(co$band))) else abs(axes(co$band))[, k],
    LF = if (metric == "LFENMO") {
      v <- en(abs(axes(co$low))) - 1
      v[which(v < 0)] <- 0
      v
    } else if (metric == "LFEN") en(abs(axes(co$low))) else abs(axes(co$low))[, k],
    HF = if (metric == "HFENplus") {
      gcp <- en(axes(co$low)) - 1
      v <- en(axes(co$high)) + gcp
      v[which(v < 0)] <- 0
      v
    } else if (metric == "HFEN") en(abs(axes(co$high))) else abs(axes(co$high))[, k],
    ZC = {
      v <- axes(co$zc)[, k]
      v[which(abs(v) < co$zc_sb)] <- 0
      v <- ifelse(v >= 0, 1, -1)
      n <- length(v)
      tmp <- abs(sign(v[2:n]) - sign(v[1:(n - 1)])) * 0.5
      c(tmp[1], tmp)
    })
}

filtered_metrics <- c("BFEN", "BFX", "BFY", "BFZ", "LFENMO", "LFEN", "LFX", "LFY", "LFZ",
                      "HFEN", "HFX", "HFY", "HFZ", "HFENplus", "ZCX", "ZCY", "ZCZ")

test_that("the per-sample signals: g.applymetrics()'s expressions, bit for bit", {
  skip_if_no_filter_refs()
  xyz <- ax3_xyz()
  for (sf in c(30, 85.7, 100)) {
    co <- gravcal:::ggir_filter_coefs(sf)
    for (m in filtered_metrics) {
      expect_same_bits(gravcal:::ggir_filtered_signal(xyz, m, co), ref_signal(xyz, m, co))
    }
  }
  # NA at a block's end: a shorter filtered axis, recycled by R's matrix
  # assignment when its length divides the block's, else R's error
  co <- gravcal:::ggir_filter_coefs(100)
  short <- xyz[1:200, ]
  short[101:200, 1] <- NA                          # 100 values left: recycled
  for (m in c("BFEN", "BFX", "LFENMO", "HFENplus", "ZCX")) {
    expect_same_bits(gravcal:::ggir_filtered_signal(short, m, co), ref_signal(short, m, co))
  }
  short[200, 2] <- NaN                             # 199 left on y: R stops
  for (m in c("BFEN", "BFY")) {
    expect_identical(
      tryCatch(gravcal:::ggir_filtered_signal(short, m, co), error = conditionMessage),
      tryCatch(ref_signal(short, m, co), error = conditionMessage))
  }
  expect_error(gravcal:::ggir_filtered_signal(xyz, "ENMO", co), "filtered metrics")
})

test_that("every filtered metric at once (each filter run once, the three axes side by side) gives each one's own bits", {
  # g.getmeta() asks for all its filtered metrics in one call: the filters
  # run once per coefficient set and axis, and the three axes' recursions
  # side by side where no axis has NA. The result must be each metric's
  # signal computed alone (one axis at a time), under both of R's possible
  # multiply-add arithmetics, with NA, NaN and Inf in the block, and R's
  # error for the first metric (in the order asked) that R cannot compute.
  skip_if_no_filter_refs()
  xyz <- ax3_xyz()[1:3000, ]
  co <- gravcal:::ggir_filter_coefs(100)
  nan_x <- xyz
  nan_x[1:7, 1] <- NaN                              # x shorter, not recycled: R stops
  inf_y <- xyz
  inf_y[1500, 2] <- Inf                             # y: NaN from Inf - Inf mid-block
  tail_z <- xyz
  tail_z[1501:3000, 3] <- NA                        # z: half the block, recycled
  blocks <- list(clean = xyz, nan_x = nan_x, inf_y = inf_y, tail_z = tail_z)
  one_by_one <- function(b, ms, fused) {
    lapply(stats::setNames(ms, ms), function(m) {
      tryCatch(gravcal:::ggir_filtered_signal(b, m, co, fused), error = conditionMessage)
    })
  }
  arithmetics <- list(plain = list(conv = FALSE, rec = FALSE), fused = list(conv = TRUE, rec = TRUE),
                      mixed = list(conv = FALSE, rec = TRUE))
  orders <- list(ggir = filtered_metrics, reversed = rev(filtered_metrics),
                 some = c("HFENplus", "LFX", "BFEN", "ZCY"))
  for (fu in names(arithmetics)) for (bn in names(blocks)) for (ms in orders) {
    b <- blocks[[bn]]
    alone <- one_by_one(b, ms, arithmetics[[fu]])
    together <- tryCatch(gravcal:::ggir_filtered_signal(b, ms, co, arithmetics[[fu]]),
                         error = conditionMessage)
    failed <- vapply(alone, is.character, TRUE)
    if (any(failed)) {
      # R stops at the first metric it cannot compute
      expect_identical(together, alone[[which(failed)[1]]], info = paste(fu, bn))
    } else {
      expect_identical(names(together), ms)
      expect_same_bits(unlist(together), unlist(alone))
    }
  }
  # the cases reach each path: a clean block is computed, a NaN at the
  # start stops R, an Inf gives NaN values, a half-NA axis is recycled
  expect_false(anyNA(unlist(gravcal:::ggir_filtered_signal(xyz, filtered_metrics, co))))
  expect_error(gravcal:::ggir_filtered_signal(nan_x, "BFX", co), "replacement length")
  expect_true(anyNA(gravcal:::ggir_filtered_signal(inf_y, "LFY", co)))
  expect_same_bits(gravcal:::ggir_filtered_signal(tail_z, "BFZ", co), ref_signal(tail_z, "BFZ", co))
  # R's own signal for each, with this R's arithmetic
  together <- gravcal:::ggir_filtered_signal(xyz, filtered_metrics, co)
  for (m in filtered_metrics) expect_same_bits(together[[m]], ref_signal(xyz, m, co))
})

test_that("the block filtered in parts (each filter's state carried across the seams) gives the whole block's bits", {
  # g.getmeta() filters a block in parts of 4096 samples: the convolution
  # reads the samples before the part, the recursion its last outputs, the
  # zero crossings the sign before. Parts of every size (1 sample left at
  # the end, parts shorter than the recursion's history, one part) must
  # give R's own signal; a NA met after some parts were given starts the
  # block over whole (R's NA rules), with R's values or R's error.
  skip_if_no_filter_refs()
  xyz <- ax3_xyz()[1:3000, ]
  co <- gravcal:::ggir_filter_coefs(100)
  inf_y <- xyz
  inf_y[1500, 2] <- Inf                             # NaN from the middle on: met after parts
  tail_z <- xyz
  tail_z[1501:3000, 3] <- NA                        # recycled by R: met after parts
  late_x <- xyz
  late_x[2000, 1] <- NA                             # inside: R stops
  arithmetics <- list(plain = list(conv = FALSE, rec = FALSE), fused = list(conv = TRUE, rec = TRUE))
  whole <- function(b, fu) {
    tryCatch(gravcal:::ggir_filtered_signal(b, filtered_metrics, co, fu, chunk = 1e6),
             error = conditionMessage)
  }
  for (fu in names(arithmetics)) {
    ref <- whole(xyz, arithmetics[[fu]])
    for (k in c(2, 3, 7, 8, 9, 100, 2999, 3000)) {
      parts <- gravcal:::ggir_filtered_signal(xyz, filtered_metrics, co, arithmetics[[fu]], chunk = k)
      expect_identical(names(parts), filtered_metrics)
      expect_same_bits(unlist(parts), unlist(ref))
    }
    for (b in list(inf_y, tail_z, late_x)) {
      expect_identical(
        tryCatch(gravcal:::ggir_filtered_signal(b, filtered_metrics, co, arithmetics[[fu]], chunk = 7),
                 error = conditionMessage),
        whole(b, arithmetics[[fu]]))
    }
  }
  # R's own expressions, from parts of 7 (this R's arithmetic)
  parts <- gravcal:::ggir_filtered_signal(xyz, filtered_metrics, co, chunk = 7)
  for (m in filtered_metrics) expect_same_bits(parts[[m]], ref_signal(xyz, m, co))
  expect_same_bits(gravcal:::ggir_filtered_signal(tail_z, "HFENplus", co, chunk = 7),
                   ref_signal(tail_z, "HFENplus", co))
  expect_error(gravcal:::ggir_filtered_signal(late_x, "BFX", co, chunk = 7), "internal NAs")
  expect_true(anyNA(gravcal:::ggir_filtered_signal(inf_y, "LFY", co, chunk = 7)))
  expect_error(gravcal:::ggir_filtered_signal(xyz, "BFX", co, chunk = 0), "chunk")
})

test_that("the per-sample signals, on a calibrated day block at 30 Hz (shared data)", {
  skip_if_no_filter_refs()
  skip_if_quick()
  xyz <- agcounts_xyz()
  co <- gravcal:::ggir_filter_coefs(30)
  for (m in c("BFEN", "LFENMO", "HFEN", "HFENplus", "ZCY")) {
    expect_same_bits(gravcal:::ggir_filtered_signal(xyz, m, co), ref_signal(xyz, m, co))
  }
})

# GGIR's averagePerEpoch and sumPerEpoch, restated
per_epoch <- function(x, sf, epochsize, mean = TRUE) {
  x2 <- cumsum(c(0, x))
  select <- round(seq(1, length(x2), by = sf * epochsize))
  if (mean) diff(x2[select]) / abs(diff(select)) else diff(x2[select])
}

# GGIR:::g.applymetrics with every filtered metric on and the others off
ggir_filtered_metrics <- function(xyz, sf, ws3, ...) {
  flags <- unique(regmatches(deparse(GGIR:::g.applymetrics),
                             gregexpr("do\\.[A-Za-z_]+", deparse(GGIR:::g.applymetrics))))
  flags <- unique(unlist(flags))
  on <- paste0("do.", c("bfen", "bfx", "bfy", "bfz", "lfenmo", "lfen", "lfx", "lfy", "lfz",
                        "hfen", "hfx", "hfy", "hfz", "hfenplus", "zcx", "zcy", "zcz"))
  metrics2do <- as.data.frame(stats::setNames(as.list(flags %in% on), flags))
  colnames(xyz) <- c("x", "y", "z")
  GGIR:::g.applymetrics(data = xyz, sf = sf, ws3 = ws3, metrics2do = metrics2do, ...)
}

test_that("end to end: the signals averaged per epoch are GGIR:::g.applymetrics's metrics", {
  skip_if_no_filter_refs()
  skip_if_not_installed("GGIR")
  xyz <- ax3_xyz()
  runs <- list(list(sf = 100, ws3 = 5, args = list()),
               list(sf = 85.7, ws3 = 5, args = list()),
               list(sf = 30, ws3 = 5, args = list()),
               list(sf = 100, ws3 = 1, args = list(n = 3, lb = 0.5, hb = 10, zc.lb = 0.3,
                                                   zc.hb = 4, zc.sb = 0.02, zc.order = 3)))
  for (r in runs) {
    ggir <- do.call(ggir_filtered_metrics, c(list(xyz, r$sf, r$ws3), r$args))
    expect_setequal(names(ggir), filtered_metrics)
    co <- do.call(gravcal:::ggir_filter_coefs, c(list(r$sf), r$args))
    for (m in filtered_metrics) {
      got <- per_epoch(gravcal:::ggir_filtered_signal(xyz, m, co), r$sf, r$ws3,
                       mean = !startsWith(m, "ZC"))
      expect_same_bits(got, ggir[[m]])
    }
  }
})

test_that("end to end on a calibrated day block at 30 Hz (shared data)", {
  skip_if_no_filter_refs()
  skip_if_not_installed("GGIR")
  skip_if_quick()
  xyz <- agcounts_xyz()
  ggir <- ggir_filtered_metrics(xyz, 30, 5)
  co <- gravcal:::ggir_filter_coefs(30)
  for (m in filtered_metrics) {
    got <- per_epoch(gravcal:::ggir_filtered_signal(xyz, m, co), 30, 5,
                     mean = !startsWith(m, "ZC"))
    expect_same_bits(got, ggir[[m]])
  }
})
