# The lightweight method on real recordings of daily life (issue 17):
# gravcal's default (`selection = "cells"`: one point per distinct posture,
# Levenberg-Marquardt, the model the points determine) against the GGIR
# method and the paper's procedure, on the real recordings in
# ../shared/data and on cases built from them.
#
#   Rscript bench/freeliving.R        (from the package root; about 1 minute)
#
# 1. Held-out error, the protocol of the paper's Table 3: the hours of a
#    recording are split into odd (the fitting set) and even (the checking
#    set). Each method is fitted, with calibrate(), on the samples of the
#    odd hours; every fit is scored on the same checking set, the rest
#    windows of the even hours (5 s, max - min < 0.12 g, norm within 0.3 g
#    of 1 g), as the mean | |a| - 1 | in mg. Cases from the agcounts
#    recording (ActiGraph, 20.7 h at 30 Hz of free-living wear): the whole,
#    its halves and quarters, and the whole with every 10 s window in one
#    orientation cut out (the axis more than 0.5 g towards + or -), six
#    cases, as a wearer who never rested that way. From GGIR's own
#    data.calibrate (84 h, 10,958 ten-second rest windows with temperature,
#    no raw samples): blocks of 360 windows alternate between the sets, the
#    GGIR method is fit_icp() with temperature and the lightweight method
#    the default selection and fit on the same windows (both with their
#    temperature term); also the GGIR method without it. Whether GGIR's sphere criterion passes (every axis below -0.3 g
#    and above 0.3 g, as GGIR's procedure decides it: its status is not
#    "sphere_not_covered") is reported: where it passes, the issue asks for
#    status "ok" and a held-out error at most 1.1 times the GGIR method's.
# 2. Windowing: the agcounts recording windowed four ways (5 s and 10 s
#    windows, each also started half a window later) and read in chunks of
#    two sizes; the largest difference of any coefficient between two
#    windowings, in units of its standard errors (sqrt(se1^2 + se2^2), and
#    the larger of the two se). The issue asks for agreement within 2 se.
# 3. Why one point per cell: the same held-out protocol and windowing check
#    for other rules: a greedy D-optimal design (the 9-parameter model's
#    Jacobian at the ideal sensor) of 100 and 200 points from the cells,
#    every rest window, and the paper's 18 points.
#
# Writes bench/results/freeliving.md and freeliving.csv.
suppressPackageStartupMessages(library(gravcal))
shared <- Sys.getenv("GRAVCAL_SHARED_DATA", file.path("..", "shared", "data"))
if (!dir.exists(file.path(shared, "agcounts"))) {
  stop("../shared/data/agcounts not found; set GRAVCAL_SHARED_DATA")
}
out_dir <- file.path("bench", "results")
dir.create(out_dir, showWarnings = FALSE, recursive = TRUE)
t_start <- Sys.time()

e <- new.env()
for (a in c("X", "Y", "Z")) {
  load(file.path(shared, "agcounts", paste0("calibration", a, "axis.RData")),
       envir = e)
}
ag <- data.frame(x = e$X, y = e$Y, z = e$Z)
sf <- 30

ident <- gravcal:::new_fit(method = "lightweight")
M <- function(w) as.matrix(w[, c("mean_x", "mean_y", "mean_z")])
score <- function(fit, chk) {
  if (is.null(fit) || !fit$status %in% c("ok", "high_error")) return(NA_real_)
  a <- gravcal:::calibrate_points(fit, M(chk), chk$temperature)
  1000 * mean(abs(sqrt(rowSums(a^2)) - 1))
}
checking_windows <- function(x) {
  w <- rest_windows(x, sf = sf)
  w <- w[w$rest, ]
  w[abs(sqrt(rowSums(M(w)^2)) - 1) <= 0.3, ]
}
hour_of <- function(n) floor((seq_len(n) - 1) / (sf * 3600))

# Cut out every 10 s window whose mean lies more than 0.5 g along +-axis.
without_orientation <- function(x, axis, sign) {
  win <- floor((seq_len(nrow(x)) - 1) / (10 * sf))
  m <- tapply(x[[axis]], win, mean)
  drop <- as.integer(names(m)[sign * m > 0.5])
  x[!win %in% drop, ]
}

case_list <- list(whole = ag)
half <- nrow(ag) %/% 2
quarter <- nrow(ag) %/% 4
case_list$`first half` <- ag[seq_len(half), ]
case_list$`second half` <- ag[(half + 1):nrow(ag), ]
for (q in 1:4) {
  case_list[[paste("quarter", q)]] <- ag[((q - 1) * quarter + 1):(q * quarter), ]
}
for (axis in c("x", "y", "z")) for (s in c(-1, 1)) {
  case_list[[paste0("no rest ", axis, if (s < 0) "-" else "+")]] <-
    without_orientation(ag, axis, s)
}

rows <- list()
for (nm in names(case_list)) {
  x <- case_list[[nm]]
  odd <- hour_of(nrow(x)) %% 2 == 1
  fit_x <- x[odd, ]
  chk <- checking_windows(x[!odd, ])
  fl <- calibrate(fit_x, sf = sf)
  fp <- calibrate(fit_x, sf = sf, selection = "paper")
  fg <- suppressWarnings(calibrate(fit_x, sf = sf, method = "ggir"))
  rows[[nm]] <- data.frame(
    recording = "agcounts", case = nm, hours = nrow(x) / sf / 3600,
    sphere = fg$status != "sphere_not_covered", n_check = nrow(chk),
    before_mg = score(ident, chk),
    ggir_status = fg$status, ggir_mg = score(fg, chk),
    default_status = fl$status, default_model = length(fl$model),
    default_points = nrow(fl$points), default_mg = score(fl, chk),
    paper_status = fp$status, paper_mg = score(fp, chk))
  cat(nm, "\n")
}

# GGIR's data.calibrate: rest windows only (10 s, with temperature)
load(file.path(shared, "ggir", "data.calibrate.RData"), envir = e)
sd0 <- e$data.calibrate$spheredata
ep <- data.frame(mean_x = sd0$meanx, mean_y = sd0$meany, mean_z = sd0$meanz,
                 sd_x = sd0$sdx, sd_y = sd0$sdy, sd_z = sd0$sdz,
                 temperature = sd0$temperature, rest = TRUE)
block <- floor((seq_len(nrow(ep)) - 1) / 360) %% 2 == 1
ep_fit <- ep[block, ]
ep_chk <- ep[!block, ]
fg <- fit_icp(ep_fit)
fg_notemp <- fit_icp(ep_fit, use_temp = FALSE)
fl <- gravcal:::fit_chosen_model(
  select_points(ep_fit, selection = "cells"), list(),
  list(selection = "cells", cell = 0.05, max_se = 0.01, model = "auto",
       use_temp = TRUE),
  function(status, message, points) list(status = status, model = NULL,
                                         points = points))
fp <- fit_gradient(select_points(ep_fit, min_distance = c(0.3, 0.1, 0.03)),
                   max_iter = 5000, tol = 1e-10)
rows$ggir <- data.frame(
  recording = "GGIR data.calibrate", case = "whole (epochs)", hours = 84,
  sphere = fg$status != "sphere_not_covered", n_check = nrow(ep_chk),
  before_mg = score(ident, ep_chk),
  ggir_status = fg$status, ggir_mg = score(fg, ep_chk),
  default_status = fl$status, default_model = length(fl$model),
  default_points = nrow(fl$points), default_mg = score(fl, ep_chk),
  paper_status = fp$status, paper_mg = score(fp, ep_chk))
ggir_notemp_mg <- score(fg_notemp, ep_chk)
held <- do.call(rbind, rows)
rownames(held) <- NULL
held$ratio <- held$default_mg / held$ggir_mg

# 2. Windowing
windowings <- list(
  "5 s" = list(x = ag, window = 5),
  "5 s, started 2.5 s later" = list(x = ag[-seq_len(2.5 * sf), ], window = 5),
  "10 s" = list(x = ag, window = 10),
  "10 s, started 5 s later" = list(x = ag[-seq_len(5 * sf), ], window = 10),
  "5 s, chunks of 10,000 samples" = list(x = ag, window = 5, chunk = 1e4))
wfits <- lapply(windowings, function(a) {
  calibrate(a$x, sf = sf, window = a$window,
            block_samples = if (is.null(a$chunk)) 1e6 else a$chunk)
})
coefs <- sapply(wfits, function(f) stats::coef(f)[param_names()])
ses <- sapply(wfits, function(f) f$se[param_names()])
pair_z <- function(P, S) {
  out <- NULL
  for (i in seq_len(ncol(P) - 1)) for (j in (i + 1):ncol(P)) {
    d <- abs(P[, i] - P[, j])
    out <- rbind(out, data.frame(
      a = colnames(P)[i], b = colnames(P)[j],
      max_z = max(d / sqrt(S[, i]^2 + S[, j]^2)),
      max_z_larger_se = max(d / pmax(S[, i], S[, j])),
      worst = rownames(P)[which.max(d / sqrt(S[, i]^2 + S[, j]^2))]))
  }
  out
}
wz <- pair_z(coefs, ses)

# 3. Other rules, on the whole agcounts recording
design_rows <- function(v) {
  2 * cbind(v[, 1]^2, v[, 2]^2, v[, 3]^2, v[, 1] * v[, 2], v[, 1] * v[, 3],
            v[, 2] * v[, 3], v[, 1], v[, 2], v[, 3])
}
d_optimal <- function(pts, n) {
  Fm <- design_rows(M(pts))
  Minv <- diag(1e6, 9)
  avail <- rep(TRUE, nrow(Fm))
  sel <- integer(0)
  for (k in seq_len(min(n, nrow(Fm)))) {
    d <- rowSums((Fm %*% Minv) * Fm)
    d[!avail] <- -Inf
    i <- which.max(d)
    sel <- c(sel, i)
    avail[i] <- FALSE
    mf <- Minv %*% Fm[i, ]
    Minv <- Minv - (mf %*% t(mf)) / (1 + sum(Fm[i, ] * mf))
  }
  pts[sort(sel), ]
}
rules <- list(
  "one per cell (default)" = function(w) select_points(w, selection = "cells"),
  "D-optimal, 100 of the cells" = function(w)
    d_optimal(select_points(w, selection = "cells"), 100),
  "D-optimal, 200 of the cells" = function(w)
    d_optimal(select_points(w, selection = "cells"), 200),
  "every rest window" = function(w) w[w$rest, ],
  "paper's 18" = function(w) select_points(w, min_distance = c(0.3, 0.1, 0.03)))
guarded <- function(w) {
  w <- w[w$rest, ]
  w[abs(sqrt(rowSums(M(w)^2)) - 1) <= 0.3, ]
}
odd <- hour_of(nrow(ag)) %% 2 == 1
w_odd <- guarded(rest_windows(ag[odd, ], sf = sf))
chk <- checking_windows(ag[!odd, ])
wins <- lapply(windowings[1:4], function(a) guarded(rest_windows(a$x, sf = sf,
                                                             window = a$window)))
alt <- do.call(rbind, lapply(names(rules), function(r) {
  paper <- grepl("paper", r)
  fitr <- function(w) {
    fit_gradient(rules[[r]](w), algorithm = if (paper) "descent" else "lm",
                 max_iter = if (paper) 5000 else 100, tol = 1e-10,
                 se = if (paper) "classic" else "robust")
  }
  f <- fitr(w_odd)
  fw <- lapply(wins, fitr)
  z <- pair_z(sapply(fw, function(f) stats::coef(f)[param_names()]),
              sapply(fw, function(f) f$se[param_names()]))
  data.frame(rule = r, points = nrow(f$points), heldout_mg = score(f, chk),
             windowing_max_z = max(z$max_z),
             windowing_max_z_larger_se = max(z$max_z_larger_se))
}))

utils::write.csv(held, file.path(out_dir, "freeliving.csv"), row.names = FALSE)
f2 <- function(v) ifelse(is.na(v), "-", formatC(v, format = "f", digits = 2))
md <- c(
  "# The lightweight method on recordings of daily life",
  "",
  paste0("`Rscript bench/freeliving.R`, ", format(Sys.Date()), ", gravcal ",
         utils::packageVersion("gravcal"), ", R ", getRversion(), ". ",
         "See the script's header for the protocol."),
  "",
  "## Held-out error (paper's Table 3 protocol), mg",
  "",
  paste("Fitting set: odd hours (agcounts) or odd blocks of 360 windows",
        "(GGIR's data.calibrate); checking set: the rest windows of the",
        "others. *sphere*: GGIR's sphere criterion on the fitting set.",
        "*model*: parameters the default fitted. *ratio*: default / GGIR."),
  "",
  "| recording | case | hours | sphere | checking windows | before | GGIR method | default (points, model) | ratio | paper's 18 points |",
  "|---|---|---|---|---|---|---|---|---|---|",
  sprintf("| %s | %s | %.1f | %s | %d | %s | %s%s | %s (%d, %s)%s | %s | %s%s |",
          held$recording, held$case, held$hours,
          ifelse(held$sphere, "passes", "fails"), held$n_check,
          f2(held$before_mg), f2(held$ggir_mg),
          ifelse(held$ggir_status == "ok", "", paste0(" ", held$ggir_status)),
          f2(held$default_mg), held$default_points,
          ifelse(held$default_model > 0, held$default_model, "-"),
          ifelse(held$default_status == "ok", "",
                 paste0(" ", held$default_status)),
          f2(held$ratio), f2(held$paper_mg),
          ifelse(held$paper_status == "ok", "", paste0(" ", held$paper_status))),
  "",
  sprintf(paste0("Where the sphere criterion passes (%d cases): default ",
                 "status ok in %d; ratio to the GGIR method at most %.2f ",
                 "(median %.2f). In all %d cases: ratio at most %.2f."),
          sum(held$sphere), sum(held$sphere & held$default_status == "ok"),
          max(held$ratio[held$sphere], na.rm = TRUE),
          stats::median(held$ratio[held$sphere], na.rm = TRUE), nrow(held),
          max(held$ratio, na.rm = TRUE)),
  "",
  sprintf(paste0("GGIR's data.calibrate has a temperature channel (17 ",
                 "degrees C of range): both methods fit a temperature offset ",
                 "(model 12: the nine parameters and three temperature ",
                 "offsets). The GGIR method without it: %.2f mg."),
          ggir_notemp_mg),
  "",
  "## Windowing (agcounts, whole recording)",
  "",
  "Each pair of windowings: the largest difference of a coefficient, over its standard errors.",
  "",
  "| windowing | windowing | max abs diff / sqrt(se1^2 + se2^2) | max abs diff / larger se | coefficient |",
  "|---|---|---|---|---|",
  sprintf("| %s | %s | %.2f | %.2f | %s |", wz$a, wz$b, wz$max_z,
          wz$max_z_larger_se, wz$worst),
  "",
  "Coefficients and standard errors:",
  "",
  paste0("| | ", paste(param_names(), collapse = " | "), " |"),
  paste0("|---|", strrep("---|", 9)),
  sprintf("| %s | %s |", colnames(coefs), apply(
    matrix(sprintf("%.4f (%.4f)", coefs, ses), nrow = 9), 2, paste,
    collapse = " | ")),
  "",
  "## Other point rules (agcounts, whole recording)",
  "",
  "| rule | points | held-out mg | windowing: max z | max diff / larger se |",
  "|---|---|---|---|---|",
  sprintf("| %s | %d | %.2f | %.2f | %.2f |", alt$rule, alt$points,
          alt$heldout_mg, alt$windowing_max_z, alt$windowing_max_z_larger_se),
  "",
  sprintf("Run time %.0f s.", as.numeric(Sys.time() - t_start, units = "secs")))
writeLines(md, file.path(out_dir, "freeliving.md"))
cat(md, sep = "\n")
