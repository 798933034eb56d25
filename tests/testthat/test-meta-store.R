# The block store of g.getmeta() and epoch_signals() (ggir_block_store.hpp,
# gc_meta_store*()): a block held in the core must give back, bit for bit,
# the samples R would have held (GGIR's data[...] of each step), whatever
# the runs of its temperature, light and wear flags.

store_cols <- function(n, seed = 1) {
  set.seed(seed)
  list(x = stats::rnorm(n), y = stats::rnorm(n), z = stats::rnorm(n),
       # a value per "page" of 120 samples (.cwa), with NaN runs and a -0
       temperature = rep(c(20.5, NaN, 21, -0, 0, 21), length.out = ceiling(n / 120))[
         ceiling(seq_len(n) / 120)],
       time = 1.7e9 + (seq_len(n) - 1) / 100,
       # a value per sample: kept as plain values
       light = stats::runif(n),
       # wear flags (an ad hoc csv file's): long runs of 1, 0 and NaN
       wear = rep(c(1, 0, NaN, 1), length.out = ceiling(n / 700))[ceiling(seq_len(n) / 700)])
}

same_bits <- function(a, b) {
  expect_identical(length(a), length(b))
  # identical() takes -0 for 0 and any NaN for NaN: compare the bytes
  expect_identical(writeBin(a, raw()), writeBin(b, raw()))
}

test_that("rows put in come back bit for bit, after keep and replace too", {
  d <- store_cols(5000)
  st <- gravcal:::gc_meta_store(TRUE, TRUE, TRUE, TRUE)
  info <- gravcal:::gc_meta_store_put(st, d, -1)
  expect_identical(info$n, 5000)
  expect_identical(info$first_time, d$time[1])
  expect_identical(info$tail_time, rev(utils::tail(d$time, 2)))
  same_bits(info$head_temp, d$temperature[1:10])
  r <- gravcal:::gc_meta_store_rows(st, 0, 5000)
  for (k in names(d)) same_bits(r[[k]], d[[k]])
  # a slice kept (the carry), then rows appended after it
  expect_identical(gravcal:::gc_meta_store_keep(st, 1234, 1500), 1500)
  r <- gravcal:::gc_meta_store_rows(st, 0, 1500)
  for (k in names(d)) same_bits(r[[k]], d[[k]][1235:2734])
  e <- store_cols(700, seed = 2)
  gravcal:::gc_meta_store_put(st, e, -1)
  r <- gravcal:::gc_meta_store_rows(st, 0, 2200)
  for (k in names(d)) same_bits(r[[k]], c(d[[k]][1235:2734], e[[k]]))
  # the rows after the carry replaced (R's time-gap imputation)
  f <- store_cols(300, seed = 3)
  gravcal:::gc_meta_store_put(st, f, 1500)
  r <- gravcal:::gc_meta_store_rows(st, 0, gravcal:::gc_meta_store_size(st))
  for (k in names(d)) same_bits(r[[k]], c(d[[k]][1235:2734], f[[k]]))
  # columns a store does not keep are absent; absent columns given are NA
  st2 <- gravcal:::gc_meta_store(TRUE, FALSE, FALSE, FALSE)
  gravcal:::gc_meta_store_put(st2, d[c("x", "y", "z")], -1)
  r <- gravcal:::gc_meta_store_rows(st2, 0, 10)
  expect_named(r, c("x", "y", "z", "temperature"))
  expect_true(all(is.na(r$temperature)))
  expect_error(gravcal:::gc_meta_store_rows(st2, 4990, 20), "beyond the block")
  expect_error(gravcal:::gc_meta_store_keep(st2, 10, 5000), "beyond the block")
})

test_that("GGIR's gap fill: the carry's last row normalised and repeated, every column", {
  d <- store_cols(1000)
  st <- gravcal:::gc_meta_store(TRUE, TRUE, TRUE, TRUE)
  gravcal:::gc_meta_store_put(st, d, -1)
  gravcal:::gc_meta_store_put(st, store_cols(10, seed = 9), -1)
  gravcal:::gc_meta_store_fill_gap(st, 1000, 37)
  r <- gravcal:::gc_meta_store_rows(st, 0, gravcal:::gc_meta_store_size(st))
  expect_identical(length(r$x), 1047L)
  # as meta_run() did it in R: v / sqrt(sum(v^2)), rows repeated
  v <- c(d$x[1000], d$y[1000], d$z[1000])
  v <- v / sqrt(sum(v^2))
  expect_identical(c(r$x[1000], r$y[1000], r$z[1000]), v)
  for (k in c("x", "y", "z")) {
    expect_identical(r[[k]][1001:1037], rep(r[[k]][1000], 37))
  }
  for (k in c("temperature", "time", "light", "wear")) {
    same_bits(r[[k]][1000:1037], rep(d[[k]][1000], 38))
  }
  same_bits(r$light[1038:1047], store_cols(10, seed = 9)$light)
})

test_that("a block read from a decoder is the samples the decoder gives, in GGIR's blocks", {
  skip_if_not_installed("GGIRread")
  f <- system.file("testfiles", "ax3_testfile.cwa", package = "GGIRread")
  if (!nzchar(f)) skip("GGIRread has no test file ax3_testfile.cwa")
  # the decoder's own blocks of `units` units, as R read them before the
  # store (the blocks matter: the decoder replays GGIRread's arithmetic per
  # block)
  decoded <- function(units) {
    h <- gravcal:::gc_decoder_open(f, "cwa", list())
    on.exit(gravcal:::gc_decoder_close(h$ptr))
    ref <- list()
    repeat {
      b <- gravcal:::gc_decoder_read(h$ptr, units, 1000, TRUE, TRUE, TRUE)
      if (b$n > 0) {
        i <- seq_len(b$n)
        ref[[length(ref) + 1]] <- lapply(b[c("x", "y", "z", "temperature", "time", "light")],
                                         function(v) v[i])
      }
      if (b$n == 0 && b$units == 0) break
    }
    lapply(stats::setNames(nm = names(ref[[1]])), function(k) unlist(lapply(ref, `[[`, k)))
  }
  ref <- decoded(20)
  h2 <- gravcal:::gc_decoder_open(f, "cwa", list())
  on.exit(gravcal:::gc_decoder_close(h2$ptr), add = TRUE)
  st <- gravcal:::gc_meta_store(TRUE, TRUE, TRUE, TRUE)
  n <- 0
  repeat {
    info <- gravcal:::gc_meta_store_read(st, h2$ptr, 20, 1000, TRUE)
    if (info$n == 0) break
    n <- n + info$n
  }
  expect_gt(n, 10000)
  r <- gravcal:::gc_meta_store_rows(st, 0, n)
  for (k in names(ref)) same_bits(r[[k]], ref[[k]])
  expect_identical(info$tail_time, rev(utils::tail(ref$time, 2)))
  # without a time column: the block's first and last times still known
  ref <- decoded(40)
  h3 <- gravcal:::gc_decoder_open(f, "cwa", list())
  on.exit(gravcal:::gc_decoder_close(h3$ptr), add = TRUE)
  st3 <- gravcal:::gc_meta_store(TRUE, FALSE, TRUE, FALSE)
  info <- gravcal:::gc_meta_store_read(st3, h3$ptr, 40, 1000, TRUE)
  expect_identical(info$first_time, ref$time[1])
  expect_identical(info$tail_time, rev(ref$time[info$n - 1:0]))
  r <- gravcal:::gc_meta_store_rows(st3, 0, info$n)
  expect_named(r, c("x", "y", "z", "temperature", "light"))
  for (k in names(r)) same_bits(r[[k]], ref[[k]][seq_len(info$n)])
})

test_that("the long epochs' temperature and light: R's cumulative sums, a run at a time only where exact", {
  # gc_meta_store_epochs() sums a column a run at a time (a run's value
  # times its length) only where every running sum is exact in R's
  # accumulator (ggir_epochs.hpp run_sums_exact()): a .cwa file's
  # temperature (multiples of 2^-8) and light (whole numbers). Elsewhere
  # row by row, as R's cumsum(). Both against R's own arithmetic: GGIR's
  # long-epoch mean, diff(cumsum(c(0, v))[round(seq(1, n + 1, by = M))]) / M,
  # and its lightpeak, max(light[((li - 1) * M):(li * M)]).
  sf <- 10
  ws <- c(5, 60, 120)
  M <- ws[2] * sf
  n <- 12000
  per_page <- function(v) rep(v, length.out = ceiling(n / 120))[ceiling(seq_len(n) / 120)]
  set.seed(4)
  runs <- list(
    # a .cwa file's: raw * 75 / 256 - 50 (run by run)
    cwa = per_page(sample(0:1023, 60, replace = TRUE) * 75 / 256 - 50),
    # decimals (GENEActiv's text): row by row
    decimal = per_page(round(stats::runif(60, 18, 32), 1)),
    # whole multiples of 2^-38 whose running sums pass 2^33: each addition
    # of 1 + 2^-31 - 2^-38 rounds down by almost half a unit of R's long
    # double accumulator (2^-30 there), thousands of times, where a product
    # per run would round once a run: most epochs' means differ in double.
    # Row by row
    fine = per_page(c(2^27, rep(1 + 2^-31 - 2^-38, 99))),
    # with NaN and infinite runs: row by row
    nonfinite = per_page(c(20, NaN, 21, Inf, 22))
  )
  light <- list(whole = per_page(as.numeric(sample(0:1023, 50, replace = TRUE))),
                nan = per_page(c(5, 7, NaN, 9, 11, 13)))
  rmean <- function(v) diff(cumsum(c(0, v))[round(seq(1, n + 1, by = M))]) / M
  rpeak <- function(v) {
    vapply(seq_len(n / M), function(li) max(v[((li - 1) * M):(li * M)]), 0)
  }
  nw <- list(clipthres = 7.5, sdcriter = 0.013, racriter = 0.05, approach = "2023")
  cal <- list(offset = c(0, 0, 0), inv_scale = c(1, 1, 1))
  for (k in seq_along(runs)) {
    li <- light[[1 + (k %% 2)]]
    d <- list(x = stats::rnorm(n, 0, 0.01), y = stats::rnorm(n, 0, 0.01), z = 1 + stats::rnorm(n, 0, 0.01),
              temperature = runs[[k]], light = li)
    st <- gravcal:::gc_meta_store(TRUE, FALSE, TRUE, FALSE)
    gravcal:::gc_meta_store_put(st, d, -1)
    out <- gravcal:::gc_meta_store_epochs(st, cal, NULL, TRUE, sf, ws, "ENMO", nw, NULL, FALSE, FALSE,
                                          n, 1L)
    gravcal:::gc_meta_store_release(st)
    same_bits(out$temperature, rmean(runs[[k]]))
    same_bits(out$lightmean, rmean(li))
    same_bits(out$lightpeak, rpeak(li))
  }
})
