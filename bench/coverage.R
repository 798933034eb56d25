# Coverage of the 95 % confidence intervals of calibrate()'s coefficients
# (issue 17, item 3): simulated recordings with known truth, both methods.
#
#   Rscript bench/coverage.R [seconds] [max recordings]
#
# Each recording: simulate_recording(hours = 24, sf = 10) with its own seed.
# Lightweight: random_params() (scale +-0.1, misalignment +-0.05, offset
# +-0.1 g), no temperature effect; calibrate(method = "lightweight") with
# its default selection and with selection = "paper", then confint()
# (estimate +- t(df) se) against the true parameters the model fitted.
# GGIR: the same with misalignment 0 (the GGIR model has no cross-axis
# terms) and a temperature offset drawn uniform in +-2 mg per degree C;
# fit_icp() on the GGIR rest windows. Its true offset in the fit's
# parametrisation is o + (meantemp_fit - meantemp_true) t / s, because
# the fit centres the temperature on the rest windows' mean.
# Runs recordings until `seconds` (default 3600) have passed or
# `max recordings` (default 500) are done; writes
# bench/results/coverage.md.
suppressPackageStartupMessages(library(gravcal))
args <- commandArgs(trailingOnly = TRUE)
budget <- if (length(args) >= 1) as.numeric(args[1]) else 3600
max_n <- if (length(args) >= 2) as.integer(args[2]) else 500L
t0 <- Sys.time()
light <- list()
paper <- list()
ggir <- list()
status <- list()
i <- 0L
while (i < max_n && as.numeric(Sys.time() - t0, units = "secs") < budget) {
  i <- i + 1L
  set.seed(1000 + i)
  p <- random_params()
  rec <- simulate_recording(hours = 24, sf = 10, params = p, seed = 1000 + i)
  fit <- calibrate(rec, sf = 10)
  fpap <- calibrate(rec, sf = 10, selection = "paper")
  status[[i]] <- c(light = fit$status, paper = fpap$status)
  keep <- function(fit) {
    nm <- fit$model
    ci <- confint(fit)[nm, , drop = FALSE]
    # (no temperature effect simulated: its true offsets are 0)
    truth <- c(p, t_x = 0, t_y = 0, t_z = 0)
    data.frame(rec = i, coef = nm, truth = unname(truth[nm]),
               est = unname(stats::coef(fit)[nm]), se = unname(fit$se[nm]),
               lower = ci[, 1], upper = ci[, 2], df = fit$df)
  }
  if (fit$status == "ok") light[[length(light) + 1]] <- keep(fit)
  if (fpap$status == "ok") paper[[length(paper) + 1]] <- keep(fpap)
  set.seed(5000 + i)
  p <- random_params(misalignment = 0)
  tof <- 2 * (stats::runif(3) - 0.5) * 0.002
  rec <- simulate_recording(hours = 24, sf = 10, params = p, tempoffset = tof,
                            seed = 5000 + i)
  fg <- fit_icp(rest_windows(rec, sf = 10, method = "ggir"))
  status[[i]] <- c(status[[i]], ggir = fg$status)
  if (fg$status == "ok" && isTRUE(fg$use_temp)) {
    s <- p[1:3]
    tr <- attr(rec, "truth")
    truth <- c(s, p[7:9] + (fg$meantemp - tr$meantemp) * tof / s, tof)
    nm <- c("k_xx", "k_yy", "k_zz", "o_x", "o_y", "o_z", "t_x", "t_y", "t_z")
    ci <- confint(fg)[nm, ]
    ggir[[length(ggir) + 1]] <- data.frame(
      rec = i, coef = nm, truth = unname(truth),
      est = unname(coef(fg)[nm]), se = unname(fg$se[nm]),
      lower = ci[, 1], upper = ci[, 2], df = fg$df)
  }
}
elapsed <- as.numeric(Sys.time() - t0, units = "secs")
light <- do.call(rbind, light)
paper <- do.call(rbind, paper)
ggir <- do.call(rbind, ggir)
st <- do.call(rbind, status)

table_of <- function(d) {
  d$cover <- d$truth >= d$lower & d$truth <= d$upper
  d$cover_z <- abs(d$est - d$truth) <= 1.96 * d$se
  d$z <- (d$est - d$truth) / d$se
  nm <- unique(d$coef)
  out <- do.call(rbind, lapply(nm, function(k) {
    x <- d[d$coef == k, ]
    data.frame(coef = k, n = nrow(x),
               coverage_t = 100 * mean(x$cover),
               coverage_z = 100 * mean(x$cover_z),
               mean_se = mean(x$se), sd_error = stats::sd(x$est - x$truth),
               sd_z = stats::sd(x$z), mean_bias_in_se = mean(x$z))
  }))
  all <- data.frame(coef = "all", n = nrow(d), coverage_t = 100 * mean(d$cover),
                    coverage_z = 100 * mean(d$cover_z), mean_se = NA,
                    sd_error = NA, sd_z = stats::sd(d$z),
                    mean_bias_in_se = mean(d$z))
  rbind(out, all)
}
fmt <- function(tab) {
  tab$coverage_t <- sprintf("%.1f", tab$coverage_t)
  tab$coverage_z <- sprintf("%.1f", tab$coverage_z)
  tab$mean_se <- ifelse(is.na(tab$mean_se), "", sprintf("%.2e", tab$mean_se))
  tab$sd_error <- ifelse(is.na(tab$sd_error), "", sprintf("%.2e", tab$sd_error))
  tab$sd_z <- sprintf("%.2f", tab$sd_z)
  tab$mean_bias_in_se <- sprintf("%+.2f", tab$mean_bias_in_se)
  c(paste0("| ", paste(names(tab), collapse = " | "), " |"),
    paste0("|", paste(rep("---", ncol(tab)), collapse = "|"), "|"),
    apply(tab, 1, function(r) paste0("| ", paste(r, collapse = " | "), " |")))
}
tl <- table_of(light)
tp <- table_of(paper)
tg <- table_of(ggir)
print(tl)
print(tg)
saveRDS(list(light = light, paper = paper, ggir = ggir, status = st),
        file.path(tempdir(), "coverage.rds"))
out <- c(
  "# Coverage of the 95 % intervals (bench/coverage.R)", "",
  sprintf(paste0("%d simulated recordings per method (24 h at 10 Hz each, ",
                 "seeds 1001-%d and 5001-%d), %.0f s on one core, %s; ",
                 "gravcal %s."), i, 1000 + i, 5000 + i, elapsed,
          format(Sys.Date()), utils::packageVersion("gravcal")),
  sprintf(paste0("Lightweight, gravcal's default: %d of %d fits `ok` (all ",
                 "9 parameters in %d; the recordings have a temperature ",
                 "channel without effect, and the criterion added a ",
                 "temperature offset, true value 0, in %d); the paper's selection: %d of %d `ok`; ",
                 "GGIR (`fit_icp()`): %d of %d `ok` with the temperature term."),
          sum(st[, "light"] == "ok"), i,
          sum(table(light$rec) >= 9),
          length(unique(light$rec[light$coef == "t_x"])),
          sum(st[, "paper"] == "ok"), i,
          length(unique(ggir$rec)), i),
  "",
  "Columns: `coverage_t`, % of recordings whose interval `confint()` gives",
  "(estimate +- t(df) se, 95 %) holds the true coefficient; `coverage_z`,",
  "the same with +- 1.96 se; `mean_se`, the mean reported standard error;",
  "`sd_error`, the standard deviation of estimate - truth across recordings",
  "(what the standard error should match); `sd_z` and `mean_bias_in_se`, the",
  "standard deviation and mean of (estimate - truth) / se (1 and 0 if the",
  "errors are right). With n recordings a true coverage of 95 % gives an",
  sprintf("observed one within +-%.1f points (2 binomial standard errors).",
          200 * sqrt(0.95 * 0.05 / i)), "",
  paste("## Lightweight method, gravcal's default (one point per 0.05 g",
        "cell, Levenberg-Marquardt, robust HC3 standard errors)"), "",
  fmt(tl), "",
  paste("## Lightweight method, the paper's selection (18 points, 9",
        "residual df, classic standard errors)"), "",
  fmt(tp), "",
  "## GGIR method (scale, offset, temperature offset; weighted)", "",
  fmt(tg), "")
writeLines(out, "bench/results/coverage.md")
cat(out, sep = "\n")
