# What the calibration's uncertainty does to the outcome (issue 43, item
# 4): a recording's daily summaries of its epoch signals (mean ENMO, time
# above a threshold) and the standard error that the fit's coefficients'
# covariance puts on them, by the delta method. The gradient of each short
# epoch's ENMO with respect to the coefficients comes from the core, in the
# pass that computes the epochs (ggir_epochs.hpp enmo_gradient(), called per
# block by meta_run()).

# The fit's linear model for the core's ENMO gradient, or NULL when the fit
# has no covariance to propagate (no `vcov`, coefficients per segment of
# time, or not a gravcal_fit). `temp`: whether the calibration applied to
# the samples has its temperature term.
outcome_gradient_spec <- function(fit, temp) {
  if (!inherits(fit, "gravcal_fit") || is.null(fit$vcov) || segmented(fit)) return(NULL)
  list(K = unname(fit$K), offset = unname(as.double(fit$offset)),
       tempoffset = unname(as.double(fit$tempoffset)),
       meantemp = if (is.finite(fit$meantemp)) fit$meantemp else 0, temp = isTRUE(temp))
}

#' Daily outcomes of epoch signals and their calibration standard errors
#'
#' Summarises a recording's short epochs per calendar day: the mean ENMO
#' (mg) and the minutes above a threshold (GGIR-style: short epochs whose
#' ENMO exceeds `threshold` mg, times the epoch length), with the standard
#' error that the uncertainty of the calibration's coefficients puts on
#' each. [epoch_signals()] keeps this summary (default threshold) in its
#' result as `$summary`.
#'
#' @section Days:
#' Calendar days (midnight to midnight) in the time zone of the time stamps
#' (`tz` of [epoch_signals()], GGIR's `desiredtz`), as GGIR's part 2 reports
#' days; the first and last days are partial, and `hours` says how much of
#' each day the epochs cover. Every epoch counts: non-wear is not left out
#' or imputed (that is GGIR part 2's work). The whole recording's row
#' (`$recording`) gives the mean ENMO over all epochs and the minutes above
#' the threshold per 24 hours of epochs.
#'
#' @section Standard errors:
#' By the delta method. With `theta` the fit's coefficients and `V` their
#' covariance ([vcov.gravcal_fit()]), a summary `S(theta)` has standard
#' error `sqrt(g' V g)`, `g` its gradient at the fit. The gradient of each
#' epoch's ENMO, the mean over its samples of `[|a| > 1] (a / |a|)'
#' da/dtheta` (`a` the calibrated sample), is computed by the core in the
#' pass that computes the epochs; a day's mean ENMO has the mean of its
#' epochs' gradients. The minutes above the threshold are a count, not a
#' smooth function of `theta`: their gradient is that of the count's
#' expectation when each epoch's ENMO moves by its own calibration error
#' (standard deviation `s_e = sqrt(g_e' V g_e)`): `sum_e phi((E_e - c) /
#' h_e) / h_e g_e` times the epoch length in minutes, with `h_e = max(s_e,
#' 0.1 mg)` (GGIR rounds ENMO to 0.1 mg) and `c` the threshold moved half a
#' rounding step up (the rounded ENMO exceeds the threshold exactly when
#' the unrounded one exceeds `c`). A count also moves by whole epochs: the
#' variance adds the expected number of epochs that cross the threshold:
#' the same density of epochs at `c` times their mean absolute move,
#' `sum_e phi((E_e - c) / h_e) / h_e sqrt(2 / pi) s_e` (epochs squared), as
#' for a Poisson number of crossings. Without it the intervals of
#' recordings whose standard error is below an epoch cover too rarely
#' (`bench/results/outcome-se.md`).
#'
#' Why the delta method: it costs one pass over the samples, in the pass
#' that computes the epochs (on a week at 100 Hz, 2 s more than
#' [epoch_signals()]'s 8 s with a fit of GGIR's model), where Monte Carlo
#' over draws of the coefficients would repeat the whole epoch computation
#' per draw; the two agree on the mean ENMO, and on 200 simulated
#' recordings per method the intervals `estimate +- 1.96 se` cover the
#' outcome computed with the true calibration 94.5-95.5 % of the time
#' (`bench/results/outcome-se.md`).
#'
#' This is the uncertainty from the calibration's coefficients alone, as
#' their covariance states it; the summaries' other errors (sampling of
#' days, non-wear) are not in it. A fit without a covariance (GGIR's
#' `g.calibrate()` result, coefficients per segment of time, a status
#' other than `"ok"`) gives `NA` standard errors.
#'
#' @param object A `gravcal_epochs` object ([epoch_signals()]) with an
#'   `ENMO` column.
#' @param threshold The ENMO threshold in mg (default 100).
#' @param ... Unused.
#' @return A `summary.gravcal_epochs` object: a list with `days`, a data
#'   frame with a row per calendar day (`day`, a Date; `hours`; `enmo_mg`
#'   and `enmo_mg_se`; `min_above` and `min_above_se`), `recording`, the
#'   same for the whole recording in one row (`hours`, `enmo_mg`,
#'   `enmo_mg_se`, `min_above_day` and `min_above_day_se`: minutes per 24
#'   hours), `threshold` (mg), and `fitted`, the coefficients whose
#'   covariance was propagated (empty without one).
#' @seealso [epoch_signals()], [vcov.gravcal_fit()]; `calibrate_files(...,
#'   outcomes = TRUE)` puts the recording's row in the cohort table.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 30, sf = 10, seed = 1)
#' ep <- epoch_signals(rec, fit = calibrate(rec, sf = 10))
#' summary(ep)
#' summary(ep, threshold = 50)$days
summary.gravcal_epochs <- function(object, threshold = 100, ...) {
  if (!inherits(object, "gravcal_epochs") || !"ENMO" %in% names(object$short)) {
    abort("`object` must be epoch signals with ENMO (epoch_signals(metrics = ",
          "c(\"ENMO\", ...))).")
  }
  check_number(threshold, "threshold", min = 0)
  outcome_summary(object$short, object$windowsizes[1], object$enmo_gradient, object$vcov,
                  threshold)
}

# The summary of short epochs `s` (time, ENMO) of `ws3` seconds, with the
# epochs' ENMO gradient G (a matrix named as coef(), or NULL) and the fit's
# covariance V (or NULL).
outcome_summary <- function(s, ws3, G, V, threshold) {
  enmo <- s$ENMO
  day <- as.Date(format(s$time, "%Y-%m-%d"))
  days <- sort(unique(day))
  f <- factor(day, levels = as.character(days))
  n <- as.vector(table(f))
  c0 <- threshold / 1000
  above <- !is.na(enmo) & enmo > c0
  ep_min <- ws3 / 60
  out <- data.frame(day = days, hours = n * ws3 / 3600,
                    enmo_mg = 1000 * as.vector(tapply(enmo, f, mean, na.rm = TRUE)),
                    enmo_mg_se = NA_real_,
                    min_above = as.vector(tapply(above, f, sum)) * ep_min,
                    min_above_se = NA_real_)
  total <- data.frame(hours = length(enmo) * ws3 / 3600,
                      enmo_mg = 1000 * mean(enmo, na.rm = TRUE), enmo_mg_se = NA_real_,
                      min_above_day = sum(above) * ep_min * 86400 / (length(enmo) * ws3),
                      min_above_day_se = NA_real_)
  fitted <- character(0)
  if (!is.null(G) && !is.null(V) && nrow(G) == length(enmo)) {
    fitted <- colnames(V)
    se <- outcome_se(enmo, G[, fitted, drop = FALSE], V, f, c0)
    out$enmo_mg_se <- se$mean_day
    out$min_above_se <- se$count_day * ep_min
    per_day <- 86400 / (length(enmo) * ws3)
    total$enmo_mg_se <- se$mean_all
    total$min_above_day_se <- se$count_all * ep_min * per_day
  }
  structure(list(days = out, recording = total, threshold = threshold, fitted = fitted),
            class = "summary.gravcal_epochs")
}

# Delta-method standard errors (see summary.gravcal_epochs()): of the mean
# ENMO in mg (per level of f, and over all epochs), and of the number of
# epochs above c0 (g), smoothed by each epoch's own calibration error, with
# the expected number of crossings added to its variance.
outcome_se <- function(enmo, G, V, f, c0) {
  ok <- !is.na(enmo) & stats::complete.cases(G)
  G[!ok, ] <- 0
  quad <- function(A) sqrt(pmax(rowSums((A %*% V) * A), 0))
  n <- as.vector(table(f[ok]))
  gm <- rowsum(G, f, reorder = TRUE) / pmax(n, 1)
  mean_day <- 1000 * quad(gm)
  mean_day[n == 0] <- NA_real_
  mean_all <- 1000 * quad(matrix(colSums(G) / max(sum(ok), 1), 1))
  s <- quad(G)
  h <- pmax(s, 1e-4)
  # the rounded ENMO (0.1 mg steps) exceeds c0 when the unrounded one
  # exceeds c0 + 0.05 mg
  d <- ifelse(ok, enmo - (c0 + 0.5e-4), Inf)
  w <- stats::dnorm(d / h) / h
  gc <- rowsum(G * w, f, reorder = TRUE)
  # the expected number of epochs crossing c0: the density of epochs there
  # times E|shift| = sqrt(2 / pi) s_e (the rounded ENMO cannot say where
  # within its 0.1 mg an epoch lies, so a kernel, not each epoch's own
  # distance)
  cross <- sqrt(2 / pi) * w * s
  cross_day <- as.vector(tapply(cross, f, sum))
  count_day <- sqrt(quad(gc)^2 + cross_day)
  count_all <- sqrt(quad(matrix(colSums(G * w), 1))^2 + sum(cross))
  list(mean_day = mean_day, mean_all = mean_all, count_day = count_day,
       count_all = count_all)
}

#' @export
print.summary.gravcal_epochs <- function(x, ...) {
  r <- x$recording
  cat("Epoch signals: ", format(round(r$hours, 1)), " hours; ENMO > ", format(x$threshold),
      " mg as minutes\n", sep = "")
  if (length(x$fitted)) {
    cat("(standard errors from the calibration's covariance: ",
        paste(x$fitted, collapse = ", "), ")\n", sep = "")
  } else {
    cat("(no standard errors: the fit has no covariance)\n")
  }
  d <- x$days
  num <- vapply(d, is.numeric, TRUE)
  d[num] <- lapply(d[num], function(v) signif(v, 4))
  print(d, row.names = FALSE)
  cat("\nWhole recording: mean ENMO ", format(signif(r$enmo_mg, 4)), " mg (se ",
      format(signif(r$enmo_mg_se, 2)), "), ", format(signif(r$min_above_day, 4)),
      " min above per 24 h (se ", format(signif(r$min_above_day_se, 2)), ")\n", sep = "")
  invisible(x)
}

# ---- the cohort table's outcome columns (calibrate_files(outcomes = TRUE))

outcome_columns <- c("enmo_mg", "enmo_mg_se", "min_above_100mg_day", "min_above_100mg_day_se")

# A recording's whole-recording outcomes with `fit` (summary.gravcal_epochs()
# at 100 mg): list(row = a one-row data frame of outcome_columns, note = why
# they are missing, or the warnings raised, or NULL). The epoch signals are
# computed from the file where epoch_signals() reads its format, else from
# the samples read_recording() gives.
outcome_row <- function(file, fit, sf) {
  row <- as.data.frame(stats::setNames(as.list(rep(NA_real_, 4)), outcome_columns))
  if (is.null(fit)) return(list(row = row, note = NULL))
  warns <- character(0)
  err <- NULL
  s <- tryCatch(withCallingHandlers({
    ep <- if (file_format(file) %in% meta_formats()) {
      epoch_signals(file, fit = fit, sf = sf, metrics = "ENMO")
    } else {
      r <- read_recording(file, sf = sf)
      epoch_signals(r$data, fit = fit, sf = r$sf, metrics = "ENMO")
    }
    ep$summary$recording
  }, warning = function(w) {
    warns <<- c(warns, conditionMessage(w))
    invokeRestart("muffleWarning")
  }), error = function(e) {
    err <<- conditionMessage(e)
    NULL
  })
  if (!is.null(s)) {
    row[1, ] <- list(s$enmo_mg, s$enmo_mg_se, s$min_above_day, s$min_above_day_se)
  }
  note <- if (!is.null(err)) paste0("outcomes not computed: ", sub("[.]$", "", err))
  else if (length(warns)) paste0("outcomes: ", paste(unique(warns), collapse = "; "))
  list(row = row, note = note)
}
