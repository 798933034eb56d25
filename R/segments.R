# Time-varying calibration (issue 20, item 1): coefficients per segment of
# the recording (a day, or a number of hours), neighbouring segments merged
# wherever the data show no change.
#
# Each segment's rest windows are fitted with the model the whole recording
# chose (same parameters, same reference temperature, so that their
# coefficients are comparable). Then, repeatedly: a segment that cannot be
# fitted alone (too few distinct postures for the model) is merged with a
# neighbour; otherwise the pair of neighbours least different is merged
# when a Wald test of their difference (wald_test(): d' (V1 + V2)^-1 d
# against chi-squared with as many degrees of freedom as coefficients) has a
# p-value above `change_alpha` divided by the number of pairs left (a
# Bonferroni bound over the pairs, so that a recording without drift comes
# out as one segment in at least 1 - change_alpha of cases when the
# standard errors are right). A merged segment is refitted on the union of
# its windows.

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

# `fit`: the lightweight fit of the whole recording (status ok), from
# `rest` (its guarded rest windows); `origin`: the start of the recording
# in the units of rest$start; `fargs`: arguments for fit_gradient().
fit_segments <- function(fit, rest, origin, fargs, choice) {
  secs <- segment_seconds(choice$segments)
  model <- fit$settings$model
  tt <- isTRUE(fit$settings$use_temp)
  k <- sum(model_free(model)) + 3 * tt
  fargs <- utils::modifyList(list(algorithm = "lm", se = "robust"), fargs)
  fit_one <- function(rows) {
    pts <- select_points(rest[rows, , drop = FALSE], selection = "cells",
                         cell = choice$cell)
    if (nrow(pts) < 2 * k) return(NULL)
    f <- do.call(fit_gradient, c(list(
      pts = pts, model = model, use_temp = tt,
      meantemp = if (tt) fit$meantemp), fargs))
    if (f$status != "ok" || is.null(f$vcov)) return(NULL)
    se <- pmax(f$se[f$model], design_se(f, pts))
    if (!all(is.finite(se)) || any(se[!f$model %in% c("t_x", "t_y", "t_z")] >
                                   choice$max_se)) {
      return(NULL)
    }
    f
  }
  id <- floor((as.numeric(rest$start) - as.numeric(origin)) / secs)
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
