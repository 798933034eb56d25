# Rest that is really rest (issue 44): rest windows whose residual after a
# fit is far outside the rest of the recording's are left out and the fit
# is done again on what is left; sustained runs of them are reported as
# stretches of time. Both methods in gravcal's own modes (the lightweight
# method's default selection, the GGIR method with ggir_compat = FALSE);
# never GGIR-compatible mode, whose rest windows are GGIR's.
#
# The rule (see ?calibrate, "Rest that is not rest"): after a fit, each
# rest window's residual r_i = |a_i| - 1 (a_i its calibrated mean vector,
# the temperature term included); the centre m and spread s of the
# residuals of the windows kept so far (s = 1.4826 MAD, the sd of normal
# residuals, robust to the windows it is to find); a window is left out
# when |r_i - m| > max(k s, floor). Then the fit again on the windows kept,
# the residuals of all rest windows again (a window may come back), until
# the windows left out do not change (at most max_rounds fits). Runs of
# windows left out that last min_stretch or more are stretches, and every
# window within a stretch's span is left out with them (near_rest_widen()).
# A trimmed
# refit of this kind is the concentration step of least trimmed squares
# (Rousseeuw & Van Driessen 2006) with a data-driven cut-off in place of a
# fixed share.
near_rest_rule <- list(
  # cut-off in units of the robust spread: 5 s is beyond any residual of
  # normal noise in a week of 10 s windows (P(|z| > 5) = 5.7e-7, about
  # 0.03 windows of 60,000), so a clean recording loses none to chance
  k = 5,
  # a window within 5 mg of the sphere (after the fit) is never left out,
  # whatever the spread: 5 mg is the smallest offset change that matters
  # to a user's results (plausible_bounds()$practical_min, about 1 mg of a
  # day's ENMO), and simulated or unusually clean recordings have spreads
  # well under 1 mg, so 5 s alone would cut into the tails of real rest
  floor = 0.005,
  # at most a third of the rest windows: the spread is the clean windows',
  # so they must be a clear majority (the MAD breaks down at a half); when
  # more would be left out the recording's rest as a whole is in doubt (or
  # the model does not fit the device), nothing is left out and the fit
  # says so
  max_share = 1 / 3,
  max_rounds = 5,
  # a run of windows left out is a stretch when it lasts 30 minutes or
  # more, successive windows at most 5 minutes apart (kept and moving
  # windows in between do not break it: a vehicle stops at lights, the arm
  # moves)
  min_stretch = 1800,
  max_gap = 300)

# The rule on residuals `r` given the windows left out so far (`out`):
# list(out, centre, spread, threshold) (g).
near_rest_cut <- function(r, out = rep(FALSE, length(r)),
                          k = near_rest_rule$k) {
  kept <- r[!out & is.finite(r)]
  m <- stats::median(kept)
  s <- 1.4826 * stats::median(abs(kept - m))
  thr <- max(k * s, near_rest_rule$floor)
  list(out = !is.finite(r) | abs(r - m) > thr, centre = m, spread = s,
       threshold = thr)
}

# Residuals |a| - 1 of window means v (n x 3) under a fit, with its
# temperature term where it has one.
near_rest_residuals <- function(fit, v, temperature) {
  sqrt(rowSums(calibrate_points(fit, v, temperature)^2)) - 1
}

# Runs of windows left out: `start` (seconds) of every rest window, `out`
# which are left out, `window` their length (s). A data frame of the runs
# (from, to in seconds, the indices `i` of their windows left out, in time
# order, as a list column), successive windows left out at most
# near_rest_rule$max_gap apart, those lasting near_rest_rule$min_stretch or
# more only.
near_rest_runs <- function(start, out, window) {
  i <- which(out)
  if (!length(i)) {
    return(data.frame(from = numeric(0), to = numeric(0), i = I(list())))
  }
  i <- i[order(start[i])]
  t <- start[i]
  run <- cumsum(c(TRUE, diff(t) > near_rest_rule$max_gap))
  idx <- unname(split(i, run))
  from <- vapply(idx, function(j) start[j[1]], 0)
  to <- vapply(idx, function(j) start[j[length(j)]] + window, 0)
  keep <- to - from >= near_rest_rule$min_stretch
  data.frame(from = from[keep], to = to[keep], i = I(idx[keep]))
}

# The windows of a stretch share its cause: a window inside a stretch's
# time span that happens to lie near the sphere (a vehicle's norm passes
# through 1 g, or its residual is within the cut-off of a spread widened
# by a model that does not fit the device exactly) is not rest either.
# `out` widened to every window whose start lies within a stretch.
near_rest_widen <- function(out, start, window) {
  if (is.null(start)) return(out)
  runs <- near_rest_runs(start, out, window)
  for (j in seq_len(nrow(runs))) {
    out <- out | (start >= runs$from[j] & start < runs$to[j])
  }
  out
}

# The loop: `fit` the first fit (applied: "ok" or "high_error"), `v` and
# `temperature` the rest windows it was fitted to, `refit(keep)` the same
# fit on the windows `keep` (logical), giving a fit; `start` the windows'
# starts (seconds on one time line; NULL: no stretches, as for pooled
# recordings) and `window` their length (s). Each round leaves out the
# windows beyond the cut-off and, with `start`, every window within the
# stretches they form (near_rest_widen()). Returns list(fit, out,
# rejected): `out` the windows left out (all FALSE when none or when the
# rule was not applied), `rejected` what fit$rejected reports.
near_rest_trim <- function(fit, v, temperature, refit,
                           k = near_rest_rule$k, start = NULL, window = NULL) {
  n <- nrow(v)
  out <- rep(FALSE, n)
  cut <- NULL
  note <- ""
  rounds <- 0L
  beyond <- 0L
  applied <- function(f) f$status %in% c("ok", "high_error")
  first <- fit
  if (applied(fit) && n > 0) {
    repeat {
      cut <- near_rest_cut(near_rest_residuals(fit, v, temperature), out, k)
      beyond <- sum(cut$out)
      cut$out <- near_rest_widen(cut$out, start, window)
      if (identical(cut$out, out) || rounds >= near_rest_rule$max_rounds) break
      if (mean(cut$out) > near_rest_rule$max_share) {
        note <- sprintf(paste0(
          "%.0f %% of the rest windows are more than %.1f mg off the ",
          "others after the fit, more than a third: none left out (the ",
          "recording's rest as a whole is in doubt, or the model does not ",
          "fit the device)"), 100 * mean(cut$out), 1000 * cut$threshold)
        fit <- first
        out[] <- FALSE
        break
      }
      f <- refit(!cut$out)
      rounds <- rounds + 1L
      if (!applied(f)) {
        note <- sprintf(paste0(
          "%d rest windows are more than %.1f mg off the others after the ",
          "fit, but the fit without them fails (%s): none left out"),
          sum(cut$out), 1000 * cut$threshold, f$status)
        fit <- first
        out[] <- FALSE
        break
      }
      fit <- f
      out <- cut$out
    }
  }
  rejected <- list(
    windows = sum(out), of = n, share = if (n > 0) mean(out) else 0,
    in_stretch = if (any(out)) as.integer(sum(out) - min(beyond, sum(out))) else 0L,
    threshold = if (is.null(cut)) NA_real_ else cut$threshold,
    spread = if (is.null(cut)) NA_real_ else cut$spread,
    k = k, floor = near_rest_rule$floor,
    max_share = near_rest_rule$max_share, rounds = rounds, note = note)
  list(fit = fit, out = out, rejected = rejected)
}

# Stretches of windows left out: `start` (seconds, numeric) of every rest
# window in time order, `out` which were left out, `r` their residuals (g),
# `window` the windows' length (s), `clock` the time of second 0 (POSIXct)
# or NULL. A data frame: start, end (POSIXct with a clock, else seconds from
# the first sample), hours, windows, median_mg (the median | |a| - 1 | of
# its windows after the fit, mg).
near_rest_stretches <- function(start, out, r, window, clock = NULL) {
  empty <- data.frame(start = if (is.null(clock)) numeric(0) else clock[0],
                      end = if (is.null(clock)) numeric(0) else clock[0],
                      hours = numeric(0), windows = integer(0),
                      median_mg = numeric(0))
  s <- near_rest_runs(start, out, window)
  if (!nrow(s)) return(empty)
  s$hours <- (s$to - s$from) / 3600
  s$windows <- lengths(s$i)
  s$median_mg <- vapply(s$i, function(j) 1000 * stats::median(abs(r[j])), 0)
  data.frame(start = if (is.null(clock)) s$from else clock + s$from,
             end = if (is.null(clock)) s$to else clock + s$to,
             hours = s$hours, windows = s$windows, median_mg = s$median_mg,
             row.names = NULL)
}

# The clock time of a fit's second 0, when known: a data frame's first
# `time` (POSIXct), or a device file's start (its decoder's, UNIX seconds,
# shown in UTC as the file's clock).
near_rest_clock <- function(x, input) {
  if (is.data.frame(x)) {
    tcol <- names(x)[tolower(names(x)) == "time"]
    if (length(tcol) && inherits(x[[tcol[1]]], "POSIXct") && nrow(x)) {
      return(x[[tcol[1]]][1])
    }
    return(NULL)
  }
  st <- input$start_time
  if (is.numeric(st) && length(st) == 1 && is.finite(st)) {
    return(as.POSIXct(st, origin = "1970-01-01", tz = "UTC"))
  }
  NULL
}

# The words print() and the message give for a stretch: "3.0 h from
# 2024-03-04 08:00 look like rest but are not on the sphere (median 52 mg
# off)".
format_stretches <- function(s) {
  if (!NROW(s)) return(character(0))
  at <- if (inherits(s$start, "POSIXct")) {
    format(s$start, "%Y-%m-%d %H:%M")
  } else {
    sprintf("%.1f h into the recording", s$start / 3600)
  }
  sprintf("%.1f h from %s look like rest but are not on the sphere (median %.0f mg off)",
          s$hours, at, s$median_mg)
}

# What the fit's message adds: the count left out and the stretches, or
# the note when nothing was.
near_rest_message <- function(rejected, stretches) {
  if (nzchar(rejected$note)) return(rejected$note)
  if (rejected$windows == 0) return("")
  paste0(sprintf(paste0(
    "%d rest windows (%.1f %%) left out, more than %.1f mg off the others ",
    "after the fit%s"), rejected$windows, 100 * rejected$share,
    1000 * rejected$threshold, format_in_stretch(rejected)),
    if (NROW(stretches)) paste0(": ", paste(format_stretches(stretches),
                                            collapse = "; ")))
}

# Attach the rule's outcome to a fit.
add_near_rest <- function(fit, rejected, stretches) {
  fit$rejected <- rejected
  fit$rejected_stretches <- stretches
  msg <- near_rest_message(rejected, stretches)
  if (nzchar(msg)) {
    fit$message <- paste0(fit$message, if (nzchar(fit$message)) "; ", msg)
  }
  fit
}

# " or within the stretches they form (N)" when the widening left out more.
format_in_stretch <- function(rejected) {
  n <- rejected$in_stretch
  if (is.null(n) || n == 0) return("")
  sprintf(" or within the stretches they form (%d)", n)
}

# The one-line summary print() shows (NULL when the rule did not run).
format_rejected <- function(rejected) {
  if (is.null(rejected)) return(NULL)
  if (is.na(rejected$threshold)) return(NULL)
  sprintf(paste0("%d of %d rest windows (%.1f %%): more than %.1f mg off ",
                 "the others after the fit (%g x robust spread %.2f mg, at ",
                 "least %g mg)%s%s"),
          rejected$windows, rejected$of, 100 * rejected$share,
          1000 * rejected$threshold, rejected$k, 1000 * rejected$spread,
          1000 * rejected$floor, format_in_stretch(rejected),
          if (nzchar(rejected$note)) " - none left out, see the message" else "")
}

# The GGIR method's own mode: the rule on the rest windows of the
# procedure's last fit (GGIR's `res`, its spheredata; `fit` = ggir_fit(res)),
# the fit again by the procedure's last stages on the windows kept
# (gc_ggir_fit_table(): sphere check, ICP to convergence, GGIR's errors and
# QC message, with the hours the procedure read). Returns the fit of what is
# left (ggir_fit()), with `rejected`, `rejected_stretches` and
# `rejected_windows` (the procedure's window number `window`, its `start`
# in seconds from the first sample, its means, temperature and residual).
# `a`: calibrate(method = "ggir")'s settings; `clock`: near_rest_clock().
ggir_near_rest <- function(res, fit, a, sf, call, clock = NULL,
                           k = near_rest_rule$k) {
  sd <- res$spheredata
  info <- attr(res, "gravcal")
  tt <- isTRUE(res$use.temp)
  tab <- unname(as.matrix(sd[, seq_len(if (tt) 8 else 7)]))
  rows <- as.integer(row.names(sd))
  v <- tab[, 2:4, drop = FALSE]
  temp <- if (tt) tab[, 8]
  opts <- ggir_options(FALSE, sf, a$spherecrit, a$minloadcrit, a$max_sd,
                       a$max_iter, a$tol, FALSE)
  refit <- function(keep) {
    r <- gc_ggir_fit_table(tab[keep, , drop = FALSE], tt, res$nhoursused, opts)
    r$warnings <- character(0)
    out <- ggir_result(r, res$bsc_qc, info$input)
    if (NROW(out$spheredata) == sum(keep)) {
      attr(out$spheredata, "row.names") <- rows[keep]
    }
    g <- attr(out, "gravcal")
    attr(out, "gravcal") <- utils::modifyList(
      info, list(icp = g$icp, meantemp = g$meantemp))
    ggir_fit(out, FALSE, call, a$minloadcrit)
  }
  secs <- (rows - 1) * ggir_constants$window
  nr <- near_rest_trim(fit, v, temp, refit, k, start = secs,
                       window = ggir_constants$window)
  f <- nr$fit
  r <- near_rest_residuals(f, v, temp)
  stretches <- near_rest_stretches(secs, nr$out, r, ggir_constants$window,
                                   clock)
  f <- add_near_rest(f, nr$rejected, stretches)
  i <- which(nr$out)
  f$rejected_windows <- data.frame(
    window = rows[i], start = secs[i], mean_x = v[i, 1], mean_y = v[i, 2],
    mean_z = v[i, 3], temperature = if (tt) temp[i] else rep(NA_real_, length(i)),
    residual = r[i])
  f
}
