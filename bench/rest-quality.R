# Rest that is really rest (issue 31, item 2): how many samples of real
# rest windows repeat the sample before them, and what the guard against
# runs of identical samples (calibrate(max_identical =), default 0.8) does
# to the coefficients.
#
#   Rscript bench/rest-quality.R [simulated recordings per kind, default 3]
#
# 1. Real recordings the tests reach (../shared/data, GGIRread's and
#    read.gt3x's test files): per recording, the rest windows of the
#    lightweight rule (rest_windows(), 5 s) and of GGIR's rule (10 s, sd <
#    13 mg), and the fraction of each window's samples (after its first)
#    equal in x, y and z to the sample before them (n_repeat / (n - 1)):
#    median, 99th percentile and maximum.
# 2. Fits with and without the guard (max_identical = 1: off) on the real
#    recordings long enough to fit, lightweight and GGIR's method in
#    gravcal's own mode: windows left out and the largest coefficient
#    change in units of its standard error.
# 3. Simulated recordings (simulate_recording(hours = 48, sf = 10), seeds
#    1..n, a sensor without cross-axis terms): the clean recording, and the
#    same with 6 hours of idle sleep (the sample before repeated, as
#    ActiGraph devices do) or of a stuck sensor (a constant 0.05-0.2 g per
#    axis off the last sample). Each fitted with the guard (default) and
#    without (max_identical = 1), and the clean recording with the
#    stretches missing; the largest |coefficient - clean coefficient| /
#    clean standard error, over the coefficients of the model.
#
# Writes bench/results/rest-quality.md and rest-quality.csv.
suppressPackageStartupMessages(library(gravcal))
args <- commandArgs(trailingOnly = TRUE)
n_sim <- if (length(args) >= 1) as.integer(args[1]) else 3L
out_dir <- file.path("bench", "results")
dir.create(out_dir, showWarnings = FALSE, recursive = TRUE)
t_start <- Sys.time()

shared <- Sys.getenv("GRAVCAL_SHARED_DATA", file.path("..", "shared", "data"))
gr <- system.file("testfiles", package = "GGIRread")
files <- c(
  agcounts = "agcounts",
  actigraph_gt3x = file.path(shared, "ggir", "actigraph_testfile.gt3x"),
  ax3_cwa = file.path(gr, "ax3_testfile.cwa"),
  ax6_cwa = file.path(gr, "ax6_testfile.cwa"),
  geneactiv_bin = file.path(gr, "GENEActiv_testfile.bin"),
  genea_bin = file.path(gr, "genea_testfile.bin"))

agcounts <- function() {
  d <- file.path(shared, "agcounts")
  if (!dir.exists(d)) return(NULL)
  e <- new.env()
  for (a in c("X", "Y", "Z")) {
    load(file.path(d, paste0("calibration", a, "axis.RData")), envir = e)
  }
  data.frame(x = e$X, y = e$Y, z = e$Z)
}

# x and sf (NULL: the file's own) of a recording, or NULL when absent
recording <- function(name) {
  if (name == "agcounts") {
    x <- agcounts()
    return(if (is.null(x)) NULL else list(x = x, sf = 30))
  }
  f <- files[[name]]
  if (!file.exists(f)) return(NULL)
  list(x = f, sf = NULL)
}

frac <- function(w) {
  valid <- w$n - w$n_invalid
  w$n_repeat / pmax(valid - 1, 1)
}

rows <- list()
fits <- list()
for (name in names(files)) {
  r <- recording(name)
  if (is.null(r)) next
  for (rule in c("lightweight", "ggir")) {
    w <- tryCatch(rest_windows(r$x, sf = r$sf, method = rule,
                               window = if (rule == "ggir") 10 else 5),
                  error = function(e) NULL)
    if (is.null(w)) next
    rest <- w[w$rest, , drop = FALSE]
    f <- frac(rest)
    rows[[length(rows) + 1]] <- data.frame(
      recording = name, rule = rule, windows = nrow(w), rest = nrow(rest),
      median = if (length(f)) stats::median(f) else NA,
      p99 = if (length(f)) unname(stats::quantile(f, 0.99)) else NA,
      max = if (length(f)) max(f) else NA,
      over_80 = sum(f > 0.8))
  }
  hours <- if (is.character(r$x)) NA else nrow(r$x) / r$sf / 3600
  if (name == "agcounts") {
    for (m in c("lightweight", "ggir")) {
      a <- calibrate(r$x, sf = r$sf, method = m)
      b <- calibrate(r$x, sf = r$sf, method = m, max_identical = 1)
      nm <- a$model
      z <- max(abs(coef(a)[nm] - coef(b)[nm]) / a$se[nm])
      fits[[length(fits) + 1]] <- data.frame(
        recording = name, method = m, status = a$status,
        left_out_identical = a$excluded[["identical"]],
        left_out_off = b$excluded[["identical"]], max_change_se = z)
    }
  }
}
real <- do.call(rbind, rows)
real_fits <- do.call(rbind, fits)

# 3. simulated contamination. The sensor has no cross-axis terms
# (random_params(misalignment = 0)), so that GGIR's model (scale and offset
# per axis) fits it as well as the lightweight one.
sim <- list()
for (seed in seq_len(n_sim)) {
  set.seed(seed)
  p <- random_params(misalignment = 0)
  base <- list(hours = 48, sf = 10, seed = seed, params = p)
  clean <- do.call(simulate_recording, base)
  for (m in c("lightweight", "ggir")) {
    fc <- calibrate(clean, sf = 10, method = m)
    nm <- fc$model
    for (kind in c("idle_sleep", "stuck")) {
      rec <- do.call(simulate_recording, c(base, stats::setNames(list(6), kind)))
      # the clean recording with the stretches missing: what a guard that
      # leaves out exactly the contaminated windows can fit
      st <- attr(rec, "truth")$contaminated
      twin <- clean
      for (i in seq_len(nrow(st))) twin[st$from[i]:st$to[i], c("x", "y", "z")] <- NA
      ft <- suppressWarnings(calibrate(twin, sf = 10, method = m))
      on <- calibrate(rec, sf = 10, method = m)
      off <- calibrate(rec, sf = 10, method = m, max_identical = 1)
      dev <- function(f, ref = fc) {
        if (!f$status %in% c("ok", "high_error")) return(NA_real_)
        max(abs(coef(f)[nm] - coef(ref)[nm]) / ref$se[nm])
      }
      sim[[length(sim) + 1]] <- data.frame(
        seed = seed, method = m, kind = kind, clean_status = fc$status,
        status_guard = on$status, status_off = off$status,
        identical_left_out = on$excluded[["identical"]],
        dev_se_guard = dev(on), dev_se_off = dev(off),
        dev_se_missing = dev(ft), dev_se_guard_vs_missing = dev(on, ft),
        dev_mg_guard = 1000 * max(abs(coef(on)[nm] - coef(fc)[nm])),
        dev_mg_off = 1000 * max(abs(coef(off)[nm] - coef(fc)[nm])))
    }
  }
}
sim <- do.call(rbind, sim)
utils::write.csv(sim, file.path(out_dir, "rest-quality.csv"), row.names = FALSE)

fmt <- function(d) {
  d[] <- lapply(d, function(v) if (is.numeric(v)) signif(v, 3) else v)
  c(paste0("| ", paste(names(d), collapse = " | "), " |"),
    paste0("|", paste(rep("---", ncol(d)), collapse = "|"), "|"),
    apply(d, 1, function(r) paste0("| ", paste(r, collapse = " | "), " |")))
}
md <- c(
  "# Rest that is really rest: runs of identical samples",
  "",
  paste0("Made by `Rscript bench/rest-quality.R ", n_sim, "` (",
         format(Sys.Date()), ", gravcal ", utils::packageVersion("gravcal"),
         ", ", format(round(as.numeric(difftime(Sys.time(), t_start,
                                                 units = "mins")), 1)),
         " min on a shared 2-core machine)."),
  "",
  "## Real rest windows: the fraction of samples equal to the one before",
  "",
  paste0("Per recording and rest rule, over its rest windows: the fraction ",
         "of each window's samples (after its first) equal in x, y and z to ",
         "the sample before them; `over_80`: rest windows the guard ",
         "(`max_identical = 0.8`, the default) would leave out."),
  "",
  fmt(real),
  "",
  "## Real recordings: fits with and without the guard",
  "",
  paste0("`max_change_se`: the largest change of a coefficient, guard on ",
         "vs off (`max_identical = 1`), in units of its standard error."),
  "",
  if (!is.null(real_fits)) fmt(real_fits) else "(no recording long enough)",
  "",
  "## Simulated idle sleep and stuck sensors",
  "",
  paste0("`simulate_recording(hours = 48, sf = 10, seed = s, params = ",
         "random_params(misalignment = 0))`, clean and with 6 h of ",
         "`idle_sleep` or `stuck` (12 stretches of 30 min). `dev_se_*`: the ",
         "largest |coefficient - clean coefficient| over the model's ",
         "coefficients, in units of the clean fit's standard error: ",
         "`guard` with the guard (the default), `off` without ",
         "(`max_identical = 1`), `missing` the clean recording with the ",
         "stretches' samples missing (NA: the data a perfect guard leaves), ",
         "`guard_vs_missing` the guarded fit against that one (in its ",
         "standard errors). `dev_mg_*`: the same differences in mg (scale in ",
         "1/1000). GGIR's method in gravcal's own mode already drops all but ",
         "the last window of a run of equal windows (its duplicate filter) ",
         "and windows of a norm far from 1 g, so without the guard it moves ",
         "less than the lightweight method; its counts are of the table ",
         "before that filter."),
  "",
  fmt(sim),
  "",
  sprintf(paste0("With the guard, the largest deviation from the clean ",
                 "fit is %.2f standard errors (from the fit on the clean ",
                 "recording without the stretches: %.3g); without it, %.2f. ",
                 "Losing the stretches' real rest windows alone moves the ",
                 "fit by up to %.2f standard errors."),
          max(sim$dev_se_guard, na.rm = TRUE),
          max(sim$dev_se_guard_vs_missing, na.rm = TRUE),
          max(sim$dev_se_off, na.rm = TRUE),
          max(sim$dev_se_missing, na.rm = TRUE)))
writeLines(md, file.path(out_dir, "rest-quality.md"))
cat(md, sep = "\n")
