# Time-varying calibration (issue 20, item 1): coefficients per segment of
# the recording (a day, or a number of hours), neighbouring segments merged
# wherever the data show no change.
#
# Each segment's rest windows are fitted with the model the whole recording
# chose (same parameters, same reference temperature, so that their
# coefficients are comparable): the lightweight model (segment_fitter_lw())
# or GGIR's scale, offset and temperature offset (segment_fitter_ggir()).
# Then, repeatedly: a segment that cannot be fitted alone (too few distinct
# postures for the model) is merged with a neighbour; otherwise the pair of
# neighbours least different is merged when a Wald test of their
# difference (wald_test(): d' (V1 + V2)^-1 d against chi-squared with as
# many degrees of freedom as coefficients) has a p-value above
# `change_alpha` divided by the number of pairs left (a Bonferroni bound
# over the pairs, so that a recording without drift comes out as one
# segment in at least 1 - change_alpha of cases when the standard errors
# are right). A merged segment is refitted on the union of its windows.

# Seconds per segment from `segments`: "day" or a number of hours.
segment_seconds <- function(segments) {
  if (identical(segments, "day")) return(86400)
  if (is.numeric(segments) && length(segments) == 1 && is.finite(segments) &&
      segments >= 1 / 6) {
    return(segments * 3600)
  }
  abort("`segments` must be \"day\" or a number of hours (at least 1/6), ",
        "not ", describe(segments), ".")
}

# Whether a segment's fit `f` on points `pts` determines its coefficients:
# every standard error (the larger of the fit's and what the points'
# geometry allows at 2 mg of noise, design_se()) finite, and at most
# `max_se` but for the temperature offsets.
segment_determined <- function(f, pts, max_se) {
  if (is.null(f$vcov)) return(FALSE)
  se <- pmax(f$se[f$model], design_se(f, pts))
  all(is.finite(se)) && all(se[!f$model %in% c("t_x", "t_y", "t_z")] <= max_se)
}

# The lightweight method's fit of a segment: function(rows) of `rest` (the
# whole recording's guarded rest windows) giving a fit, or NULL when the
# rows do not determine the model `fit` chose. `fargs`: arguments for
# fit_gradient().
segment_fitter_lw <- function(fit, rest, fargs, choice) {
  model <- fit$settings$model
  tt <- isTRUE(fit$settings$use_temp)
  k <- sum(model_free(model)) + 3 * tt
  fargs <- utils::modifyList(list(algorithm = "lm", se = "robust"), fargs)
  function(rows) {
    pts <- select_points(rest[rows, , drop = FALSE], selection = "cells",
                         cell = choice$cell)
    if (nrow(pts) < 2 * k) return(NULL)
    f <- do.call(fit_gradient, c(list(
      pts = pts, model = model, use_temp = tt,
      meantemp = if (tt) fit$meantemp), fargs))
    if (f$status != "ok" || !segment_determined(f, pts, choice$max_se)) {
      return(NULL)
    }
    f
  }
}

# `fit`: the fit of the whole recording (status ok); `start`: the start of
# each window that fit_one() takes (its row numbers), in the units of
# `origin`, the start of the recording; fit_one(rows): the fit of those
# windows, NULL when they do not determine it (segment_fitter_lw(),
# segment_fitter_ggir()).
fit_segments <- function(fit, start, origin, fit_one, choice) {
  secs <- segment_seconds(choice$segments)
  id <- floor((as.numeric(start) - as.numeric(origin)) / secs)
  ids <- sort(unique(id))
  segs <- lapply(ids, function(i) {
    rows <- which(id == i)
    list(first = i, last = i, rows = rows, fit = fit_one(rows))
  })
  merge <- function(segs, i) {
    a <- segs[[i]]
    b <- segs[[i + 1]]
    rows <- c(a$rows, b$rows)
    segs[[i]] <- list(first = a$first, last = b$last, rows = rows,
                      fit = fit_one(rows))
    segs[-(i + 1)]
  }
  repeat {
    if (length(segs) == 1) break
    bad <- which(vapply(segs, function(s) is.null(s$fit), NA))
    if (length(bad)) {
      i <- bad[1]
      segs <- merge(segs, if (i > 1) i - 1 else i)
      next
    }
    p <- vapply(seq_len(length(segs) - 1), function(i) {
      wald_test(segs[[i]]$fit, segs[[i + 1]]$fit)
    }, 0)
    i <- which.max(p)
    if (p[i] <= choice$change_alpha / length(p)) break
    segs <- merge(segs, i)
  }
  tab <- do.call(rbind, lapply(seq_along(segs), function(i) {
    s <- segs[[i]]
    f <- if (length(segs) == 1 || is.null(s$fit)) fit else s$fit
    co <- stats::coef(f)
    se <- f$se[names(co)]
    data.frame(
      segment = i,
      from = as.numeric(origin) + s$first * secs,
      to = as.numeric(origin) + (s$last + 1) * secs,
      rest_windows = length(s$rows), points = NROW(f$points),
      as.list(co), stats::setNames(as.list(unname(se)),
                                   paste0(names(co), ".se")),
      check.names = FALSE)
  }))
  # the first segment reaches back and the last forward, so that every
  # sample of the recording falls in one
  tab$from[1] <- -Inf
  tab$to[nrow(tab)] <- Inf
  fit$segments <- tab
  fit$segment_settings <- list(segments = choice$segments, seconds = secs,
                               origin = as.numeric(origin),
                               change_alpha = choice$change_alpha)
  if (nrow(tab) > 1) {
    fit$message <- paste0(fit$message, sprintf(
      "; coefficients change over time: %d segments", nrow(tab)))
  }
  fit
}

# The row of fit$segments each time falls in.
segment_of <- function(fit, t) {
  i <- findInterval(as.numeric(t), fit$segments$from)
  pmax(i, 1L)
}

# Calibrated n x 3 matrix with each row's segment's coefficients
# (apply_model(), segment by segment).
calibrate_points_by_time <- function(fit, v, t, temperature = NULL) {
  seg <- fit$segments
  i <- segment_of(fit, t)
  temp <- !is.null(temperature) && any(seg[c("t_x", "t_y", "t_z")] != 0)
  a <- matrix(0, nrow(v), 3)
  for (j in unique(i)) {
    rows <- which(i == j)
    p <- unlist(seg[j, c(param_names(), "t_x", "t_y", "t_z")])
    a[rows, ] <- apply_model(v[rows, , drop = FALSE], params_to_K(p), p[7:9],
                             p[10:12],
                             dt = if (temp) temperature[rows] - fit$meantemp)
  }
  a
}

segmented <- function(fit) {
  !is.null(fit$segments) && NROW(fit$segments) > 1
}

# GGIR's method's fit of a segment: function(rows) of `fit`'s points
# (GGIR's spheredata: the rest windows the whole recording's fit used)
# giving a fit, or NULL. The procedure's last stages on those rows
# (gc_ggir_fit_table(): at least min_rest windows, every axis beyond
# -+spherecrit, the ICP to convergence, GGIR's errors; ggir_fit()'s status
# and plausibility), with the temperature term when the whole fit used it.
# GGIR's ICP centres the temperature on its points' mean, so each
# segment's fit is referred to the whole recording's `meantemp`
# (ggir_rereference()), so that neighbours compare.
# `a`: calibrate(method = "ggir")'s settings; `sf`: the sampling rate.
segment_fitter_ggir <- function(fit, a, sf) {
  sd <- fit$ggir$spheredata
  tt <- isTRUE(fit$use_temp)
  tab <- unname(as.matrix(sd[, seq_len(if (tt) 8 else 7)]))
  k <- 6 + 3 * tt
  opts <- ggir_options(FALSE, sf, a$spherecrit, a$minloadcrit, a$max_sd,
                       a$max_iter, a$tol, FALSE)
  function(rows) {
    if (length(rows) < 2 * k) return(NULL)
    r <- gc_ggir_fit_table(tab[rows, , drop = FALSE], tt,
                           length(rows) * ggir_constants$window / 3600, opts)
    r$warnings <- character(0)
    f <- ggir_fit(ggir_result(r, data.frame(), list(source = "segment")),
                  FALSE, call = NULL, a$minloadcrit)
    if (!f$status %in% c("ok", "high_error") || !identical(f$use_temp, tt)) {
      return(NULL)
    }
    f <- ggir_rereference(f, fit$meantemp)
    if (!segment_determined(f, f$points, default_max_se)) return(NULL)
    f
  }
}

# calibrate(method = "ggir")'s fit `fit` with the choices beyond one fit
# (`over`, ggir_over_time()): coefficients per segment of its rest windows'
# time (seconds from the first sample: window i of the procedure's table
# starts at (i - 1) * 10 s) when the fit was applied, and the adaptive
# budget's record. `early`: the procedure stopped reading before the end;
# `hours_total`: the recording's hours when known (samples in memory).
ggir_over_time_fit <- function(fit, over, a, sf, early, hours_total) {
  if (is.null(over)) return(fit)
  if (!is.null(over$segments) && fit$status %in% c("ok", "high_error") &&
      NROW(fit$ggir$spheredata) > 0) {
    rows <- as.numeric(row.names(fit$ggir$spheredata))
    choice <- list(segments = over$segments, change_alpha = over$change_alpha)
    fit <- fit_segments(fit, (rows - 1) * ggir_constants$window, 0,
                        segment_fitter_ggir(fit, a, sf), choice)
    fit$segment_settings$time <- "seconds"
    fit$segment_settings$sf <- sf
  }
  if (identical(over$budget, "adaptive")) {
    fit$budget <- list(budget = "adaptive", target_se = over$target_se,
                       check_hours = over$check_hours, stopped = early,
                       hours_read = fit$hours,
                       hours_total = hours_total %||% NA_real_)
  }
  fit
}
