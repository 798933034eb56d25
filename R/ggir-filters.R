# GGIR's filtered metrics (g.applymetrics(): BFEN, LFENMO, HFEN, HFENplus,
# ZC*, ...): their Butterworth coefficients, built as GGIR builds them, and
# the per-sample signals from the core (gravcal/ggir/ggir_filters.hpp). Internal:
# GGIR's part 1 is being reproduced around them.

# The coefficient sets of one block's sample rate, from signal::butter()
# called as g.applymetrics() calls it (process_axes(): hf_lf_filter() and
# bf_filter()), with GGIR's rule hb = round(sf / 2) - 1 when sf <= 2 hb.
# The low filter takes hb whatever its cut point (GGIR's process_axes(), also
# for HFENplus); the zero-crossing band keeps zc.hb uncapped, as GGIR does.
ggir_filter_coefs <- function(sf, n = 4, lb = 0.2, hb = 15, zc.lb = 0.25, zc.hb = 3,
                              zc.sb = 0.01, zc.order = 2) {
  if (!requireNamespace("signal", quietly = TRUE)) {
    stop("GGIR's filtered metrics need the 'signal' package.", call. = FALSE)
  }
  if (sf <= (hb * 2)) hb <- round(sf / 2) - 1
  arma <- function(co) list(b = as.double(co$b), a = as.double(co$a))
  hf_lf <- function(bound, type) arma(signal::butter(n, c(bound / (sf / 2)), type = type))
  band <- function(lb, hb, n) {
    Wc <- matrix(0, 2, 1)
    Wc[1, 1] <- lb / (sf / 2)
    Wc[2, 1] <- hb / (sf / 2)
    arma(signal::butter(n, Wc, type = c("pass")))
  }
  list(band = band(lb, hb, n), low = hf_lf(hb, "low"), high = hf_lf(lb, "high"),
       zc = band(zc.lb, zc.hb, zc.order), zc_sb = zc.sb, hb = hb)
}

# Whether this R's stats::filter() (filter.c's cfilter and rfilter, compiled
# with R's flags) fuses its multiply-adds, asked of stats::filter() itself:
# z + f * v with f = v = 1 + 2^-30 and z = -(1 + 2^-29) is 0 rounded twice
# (f * v rounds to 1 + 2^-29) and 2^-60 fused. list(conv, rec), found once
# per session.
stats_filter_fused <- function() {
  if (is.null(build_state$stats_filter)) {
    f <- 1 + 2^-30
    x <- c(f, -(1 + 2^-29))
    conv <- as.vector(stats::filter(x, c(1, f), sides = 1))[2]
    rec <- as.vector(stats::filter(x, f, method = "recursive"))[2]
    build_state$stats_filter <- list(conv = !identical(conv, 0), rec = !identical(rec, 0))
  }
  build_state$stats_filter
}

# signal::filter(coef, x) (coef: list(b, a), an Arma), as GGIR calls it.
ggir_filter <- function(coef, x) {
  fu <- stats_filter_fused()
  gc_ggir_filter(as.double(coef$b), as.double(coef$a), as.double(x), fu$conv, fu$rec)
}

# The per-sample signals of filtered metrics before g.applymetrics()
# averages them per epoch; xyz: a block's calibrated samples (3 columns),
# coefs: ggir_filter_coefs(). One metric: its signal; several: a list
# named by them (each filter run once for all). `fused`: whether R's
# stats::filter() fuses its multiply-adds (this R's, or as given). `chunk`:
# the parts of the block filtered at a time (g.getmeta()'s 4096), for
# tests of the parts' seams.
ggir_filtered_signal <- function(xyz, metric, coefs, fused = stats_filter_fused(),
                                 chunk = 4096) {
  out <- gc_ggir_filtered_signal(as.double(xyz[, 1]), as.double(xyz[, 2]), as.double(xyz[, 3]),
                                 metric, coefs, fused$conv, fused$rec, chunk)
  if (length(metric) == 1) out[[1]] else out
}
