# The adaptive data budget (issue 20, item 3): calibrate(..., budget =
# "adaptive") against the whole recording, on simulated 28-day recordings.
#
#   Rscript bench/budget.R [recordings, default 10]
#
# Each recording: simulate_recording(hours = 28 * 24, sf = 5) with its own
# seed, random_params() and the simulator's temperature without effect.
# Both fits run on the samples in memory, each timed (CPU seconds of this
# process). Reported: the share of the recording read, how far each
# coefficient of the adaptive fit lies from the whole recording's in units
# of the adaptive fit's standard error, and the time ratio. The issue asks
# for at most half of the file read where the coefficients are stable, with
# coefficients within their standard errors of the full-file fit.
#
# Writes bench/results/budget.md and budget.csv.
suppressPackageStartupMessages(library(gravcal))
args <- commandArgs(trailingOnly = TRUE)
n_rec <- if (length(args) >= 1) as.integer(args[1]) else 10L
out_dir <- file.path("bench", "results")
t_start <- Sys.time()
cpu <- function(expr) {
  t0 <- proc.time()
  val <- force(expr)
  list(val = val, s = sum((proc.time() - t0)[c("user.self", "sys.self")]))
}
rows <- list()
for (i in seq_len(n_rec)) {
  seed <- 90000 + i
  set.seed(seed)
  p <- random_params()
  rec <- simulate_recording(hours = 28 * 24, sf = 5, params = p, seed = seed)
  a <- cpu(calibrate(rec, sf = 5, budget = "adaptive"))
  f <- cpu(calibrate(rec, sf = 5))
  nm <- f$val$model
  z <- abs(coef(a$val)[nm] - coef(f$val)[nm]) / a$val$se[nm]
  # both fits take one point per cell, so they share few windows: their
  # difference has about the variance se_a^2 + se_f^2
  zc <- abs(coef(a$val)[nm] - coef(f$val)[nm]) /
    sqrt(a$val$se[nm]^2 + f$val$se[nm]^2)
  rows[[i]] <- data.frame(
    seed = seed, status = a$val$status, stopped = a$val$budget$stopped,
    hours_read = a$val$budget$hours_read, hours_total = a$val$budget$hours_total,
    same_model = identical(a$val$model, nm), max_z = max(z),
    max_z_combined = max(zc),
    worst = names(z)[which.max(z)], adaptive_s = a$s, full_s = f$s)
  cat(i, "")
}
res <- do.call(rbind, rows)
utils::write.csv(res, file.path(out_dir, "budget.csv"), row.names = FALSE)
md <- c(
  "# The adaptive data budget",
  "",
  sprintf(paste0("`Rscript bench/budget.R %d`, %s, gravcal %s, %.0f s. ",
                 "See the script's header for the protocol."), n_rec,
          format(Sys.Date()), utils::packageVersion("gravcal"),
          as.numeric(Sys.time() - t_start, units = "secs")),
  "",
  "| seed | stopped early | hours read of 672 | share read | same model | max abs(adaptive - full) / se | the same / sqrt(se^2 + se_full^2) | coefficient | CPU s adaptive | CPU s full |",
  "|---|---|---|---|---|---|---|---|---|---|",
  sprintf("| %d | %s | %.0f | %.3f | %s | %.2f | %.2f | %s | %.2f | %.2f |",
          res$seed, res$stopped, res$hours_read, res$hours_read / res$hours_total,
          res$same_model, res$max_z, res$max_z_combined, res$worst,
          res$adaptive_s, res$full_s),
  "",
  sprintf(paste0("Stopped early in %d of %d; share of the recording read: ",
                 "median %.3f, largest %.3f. Coefficients: largest distance ",
                 "from the full fit %.2f standard errors of the adaptive fit, ",
                 "%.2f of the difference (sqrt(se^2 + se_full^2); the two ",
                 "fits share few windows). ",
                 "CPU time, adaptive / full: %.2f (median)."),
          sum(res$stopped), nrow(res),
          stats::median(res$hours_read / res$hours_total),
          max(res$hours_read / res$hours_total), max(res$max_z),
          max(res$max_z_combined),
          stats::median(res$adaptive_s / res$full_s)))
writeLines(md, file.path(out_dir, "budget.md"))
cat("\n", md, sep = "\n")
