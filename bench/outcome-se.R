# What the calibration's uncertainty does to the outcome (issue 43, item
# 4): do the standard errors of summary.gravcal_epochs() cover the outcome
# computed with the true calibration at their nominal rate? And what do
# they cost on a week at 100 Hz?
#
#   Rscript bench/outcome-se.R [recordings per method, default 200]
#                              [Monte-Carlo recordings, default 10]
#                              [cost: "week" (default) or "none"]
#
# Coverage. Per method, recordings simulate_recording(hours = 24, sf = 10)
# from midnight (one calendar day each), seeds 1001... (lightweight) and
# 5001... (GGIR), devices as in bench/coverage.R: lightweight
# random_params() (scale +-0.1, misalignment +-0.05, offset +-0.1 g), no
# temperature effect; GGIR random_params(misalignment = 0) (its model has no
# cross-axis terms) and a temperature offset uniform in +-2 mg per degree
# C. Each is fitted by calibrate() in the method's own mode (gravcal's
# defaults), its epoch signals computed with the fit (epoch_signals(), 5 s
# epochs), and the day's mean ENMO and minutes above 100 mg (with their
# standard errors, summary.gravcal_epochs()) compared with those of the
# same samples calibrated with the true parameters, a = K (v + o) + (T -
# meantemp) t, computed here. The interval is estimate +- 1.96 se.
#
# Monte Carlo. For the first recordings of each method, the standard
# deviation of each outcome over 100 draws of the coefficients from
# N(theta_hat, V) (epoch_signals() run again per draw, on the samples in
# memory), against the delta method's standard error.
#
# Cost. A week at 100 Hz written as .cwa (simulate_recording()'s day, seed
# 1, repeated, as bench/part1.R; kept in GRAVCAL_BENCH_DATA, default a
# folder beside tempdir()), calibrated by each method, then
# epoch_signals(file, fit) with se = FALSE and se = TRUE, each three times
# (the median).
#
# Writes bench/results/outcome-se.md.
suppressPackageStartupMessages(library(gravcal))
args <- commandArgs(trailingOnly = TRUE)
n_rec <- if (length(args) >= 1) as.integer(args[1]) else 200L
n_mc <- if (length(args) >= 2) as.integer(args[2]) else 10L
cost <- if (length(args) >= 3) args[3] else "week"
say <- function(...) cat(format(Sys.time(), "%H:%M:%S"), ..., "\n")
sf <- 10
t_start <- Sys.time()

# The device of recording i for a method, and the recording.
simulated <- function(i, method) {
  seed <- (if (method == "lightweight") 1000 else 5000) + i
  set.seed(seed)
  if (method == "lightweight") {
    p <- random_params()
    tof <- c(0, 0, 0)
  } else {
    p <- random_params(misalignment = 0)
    tof <- 2 * (stats::runif(3) - 0.5) * 0.002
  }
  simulate_recording(hours = 24, sf = sf, params = p, tempoffset = tof, seed = seed)
}

# The samples calibrated with the true parameters (the model written out).
true_calibrated <- function(rec) {
  tr <- attr(rec, "truth")
  u <- cbind(rec$x, rec$y, rec$z) + matrix(tr$offset, nrow(rec), 3, byrow = TRUE)
  a <- u %*% t(tr$K)
  if (any(tr$tempoffset != 0)) a <- a + outer(rec$temperature - tr$meantemp, tr$tempoffset)
  out <- rec
  out$x <- a[, 1]
  out$y <- a[, 2]
  out$z <- a[, 3]
  out
}

one <- function(i, method) {
  rec <- simulated(i, method)
  fit <- calibrate(rec, sf = sf, method = method)
  if (fit$status != "ok" || is.null(fit$vcov)) {
    return(data.frame(method = method, rec = i, status = fit$status, day = NA,
                      enmo = NA, enmo_true = NA, enmo_se = NA, above = NA, above_true = NA,
                      above_se = NA, hours = NA))
  }
  est <- epoch_signals(rec, fit = fit, metrics = "ENMO")$summary$days
  tru <- summary(epoch_signals(true_calibrated(rec), sf = sf, metrics = "ENMO"))$days
  m <- merge(est, tru, by = "day", suffixes = c("", "_true"))
  data.frame(method = method, rec = i, status = fit$status, day = as.character(m$day),
             enmo = m$enmo_mg, enmo_true = m$enmo_mg_true, enmo_se = m$enmo_mg_se,
             above = m$min_above, above_true = m$min_above_true, above_se = m$min_above_se,
             hours = m$hours)
}

res <- list()
for (method in c("lightweight", "ggir")) {
  say(method, ":", n_rec, "recordings")
  for (i in seq_len(n_rec)) {
    res[[length(res) + 1]] <- one(i, method)
    if (i %% 20 == 0) say("  ", i)
  }
}
res <- do.call(rbind, res)
t_cov <- as.numeric(Sys.time() - t_start, units = "secs")

cover_row <- function(d, what) {
  est <- d[[what]]
  tru <- d[[paste0(what, "_true")]]
  se <- d[[paste0(what, "_se")]]
  z <- (est - tru) / se
  hit <- abs(z) <= stats::qnorm(0.975)
  n <- length(hit)
  p <- mean(hit)
  data.frame(outcome = c(enmo = "mean ENMO (mg)", above = "minutes above 100 mg")[[what]],
             n = n, coverage = 100 * p, binom_se = 100 * sqrt(0.95 * 0.05 / n),
             mean_se = mean(se), sd_error = stats::sd(est - tru), sd_z = stats::sd(z),
             mean_z = mean(z), zero_error = 100 * mean(est == tru))
}
full <- res[res$status == "ok" & res$hours == 24, ]
tabs <- lapply(c("lightweight", "ggir"), function(m) {
  d <- full[full$method == m, ]
  rbind(cover_row(d, "enmo"), cover_row(d, "above"))
})
names(tabs) <- c("lightweight", "ggir")

# ---- Monte Carlo against the delta method -------------------------------
mc <- list()
if (n_mc > 0) {
  for (method in c("lightweight", "ggir")) {
    for (i in seq_len(n_mc)) {
      say("Monte Carlo", method, i)
      rec <- simulated(i, method)
      fit <- calibrate(rec, sf = sf, method = method)
      if (fit$status != "ok" || is.null(fit$vcov)) next
      s0 <- epoch_signals(rec, fit = fit, metrics = "ENMO")$summary$days
      V <- vcov(fit)
      R <- chol(V)
      draws <- t(replicate(100, {
        f <- fit
        th <- stats::coef(fit)[colnames(V)] + drop(stats::rnorm(ncol(V)) %*% R)
        K <- f$K
        ks <- c(k_xx = 1, k_yy = 5, k_zz = 9, k_xy = 2, k_xz = 3, k_yz = 6)
        for (nm in intersect(names(th), names(ks))) K[ks[[nm]]] <- th[[nm]]
        f$K <- K
        for (j in 1:3) {
          o <- c("o_x", "o_y", "o_z")[j]
          tt <- c("t_x", "t_y", "t_z")[j]
          if (o %in% names(th)) f$offset[j] <- th[[o]]
          if (tt %in% names(th)) f$tempoffset[j] <- th[[tt]]
        }
        d <- epoch_signals(rec, fit = f, metrics = "ENMO", se = FALSE)$summary$days
        c(d$enmo_mg[1], d$min_above[1])
      }))
      mc[[length(mc) + 1]] <- data.frame(
        method = method, rec = i, enmo_se = s0$enmo_mg_se[1], enmo_mc = stats::sd(draws[, 1]),
        above_se = s0$min_above_se[1], above_mc = stats::sd(draws[, 2]))
    }
  }
  mc <- do.call(rbind, mc)
}

# ---- cost on a week at 100 Hz ------------------------------------------
cost_tab <- NULL
if (cost == "week") {
  data_dir <- Sys.getenv("GRAVCAL_BENCH_DATA", file.path(dirname(tempdir()), "gravcal-bench-part1"))
  dir.create(data_dir, showWarnings = FALSE, recursive = TRUE)
  f <- file.path(data_dir, "week7.cwa")
  if (!file.exists(f)) {
    say("writing the week file")
    day <- simulate_recording(hours = 24, sf = 100, seed = 1,
                              tempoffset = c(0.002, -0.001, 0.0015),
                              start = as.POSIXct("2024-03-04 08:00:00", tz = "UTC"))
    wk <- day[rep(seq_len(nrow(day)), 7), ]
    wk$time <- day$time[1] + (seq_len(nrow(wk)) - 1) / 100
    gravcal:::write_cwa(as.matrix(wk[, c("x", "y", "z")]), f, sf = 100,
                        start = as.numeric(wk$time[1]), temperature = wk$temperature)
    rm(day, wk)
    invisible(gc())
  }
  cost_tab <- do.call(rbind, lapply(c("ggir", "lightweight"), function(m) {
    say("cost:", m)
    fit <- calibrate(f, method = m)
    tm <- function(se) {
      stats::median(replicate(3, {
        invisible(gc())
        system.time(ep <- epoch_signals(f, fit = fit, se = se))[["elapsed"]]
      }))
    }
    a <- tm(FALSE)
    b <- tm(TRUE)
    s <- epoch_signals(f, fit = fit)$summary$recording
    data.frame(method = m, parameters = length(fit$model), without_se = a, with_se = b,
               ratio = b / a, enmo_mg = s$enmo_mg, enmo_mg_se = s$enmo_mg_se,
               min_above_day = s$min_above_day, min_above_day_se = s$min_above_day_se)
  }))
}

# ---- the report -----------------------------------------------------------
md <- function(d, digits = 3) {
  f <- vapply(d, function(v) if (is.numeric(v)) "num" else "chr", "")
  rows <- apply(d, 1, function(r) r)
  cells <- lapply(seq_along(d), function(j) {
    v <- d[[j]]
    if (is.numeric(v)) format(signif(v, digits), trim = TRUE) else as.character(v)
  })
  lines <- c(paste0("| ", paste(names(d), collapse = " | "), " |"),
             paste0("|", paste(rep("---", ncol(d)), collapse = "|"), "|"))
  for (i in seq_len(nrow(d))) {
    lines <- c(lines, paste0("| ", paste(vapply(cells, `[`, "", i), collapse = " | "), " |"))
  }
  lines
}
status <- table(res$method, res$status)
out <- c(
  "# The outcome's uncertainty from the calibration's (bench/outcome-se.R)", "",
  sprintf(paste0("%d simulated recordings per method (24 h from midnight at 10 Hz, one ",
                 "calendar day each), %.0f s for the coverage on this machine (2 cores ",
                 "shared with other work), %s; gravcal %s."),
          n_rec, t_cov, format(Sys.Date()), as.character(utils::packageVersion("gravcal"))),
  paste0("Fits: ", paste(vapply(rownames(status), function(m) {
           paste0(m, ": ", paste(sprintf("%d %s", status[m, ], colnames(status))[status[m, ] > 0],
                                 collapse = ", "))
         }, ""), collapse = "; "), "."), "",
  "Columns: `coverage`, % of recordings whose interval estimate +- 1.96 se holds",
  "the outcome computed with the true calibration; `binom_se`, the binomial",
  "standard error of a 95 % coverage with n recordings (a true 95 % gives",
  "an observed one within +-2 of them 95 % of the time); `mean_se`, the mean",
  "stated standard error; `sd_error`, the standard deviation of estimate - truth",
  "(what the standard error should match); `sd_z`, `mean_z`, of (estimate -",
  "truth) / se (1 and 0 if right); `zero_error`, % of recordings whose",
  "estimate equals the truth exactly (a count that did not move).", "")
for (m in names(tabs)) {
  out <- c(out, paste0("## ", c(lightweight = "Lightweight method, gravcal's default",
                                 ggir = "GGIR method, gravcal's own mode")[[m]]), "",
           md(tabs[[m]]), "")
}
if (length(mc)) {
  out <- c(out, "## Monte Carlo against the delta method", "",
           paste0("The delta method's standard error against the standard deviation ",
                  "over 100 draws of the coefficients from N(theta_hat, V), per recording ",
                  "(the draws' own sampling error is about 7 %)."), "",
           md(mc), "",
           sprintf(paste0("Ratio delta / Monte Carlo, median: mean ENMO %.2f, minutes ",
                          "above %.2f."), stats::median(mc$enmo_se / mc$enmo_mc),
                   stats::median(mc$above_se / mc$above_mc, na.rm = TRUE)), "")
}
if (!is.null(cost_tab)) {
  out <- c(out, "## Cost on a week at 100 Hz (.cwa)", "",
           paste0("epoch_signals(file, fit) without and with the standard errors ",
                  "(seconds, median of 3; the ENMO gradient is computed in the same ",
                  "pass by the core; the lightweight fit's cross-axis model is applied ",
                  "in R, as without)."), "",
           md(cost_tab), "")
}
writeLines(out, file.path("bench", "results", "outcome-se.md"))
saveRDS(list(res = res, mc = mc, cost = cost_tab), file.path(tempdir(), "outcome-se.rds"))
say("done")
cat(out, sep = "\n")
