# The lightweight method's choices: which points, which model (nine
# parameters, scale and offset, or offset alone) the data determine, and
# the adaptive budget.

# The arguments that choose points and model: selection ("cells", the
# default, or "paper"), cell (g), max_se and model ("auto" or one of
# fit_gradient()'s models).
check_choice_args <- function(choice, sargs) {
  selection <- match_choice(choice$selection %||% "cells", "selection",
                            c("cells", "paper"))
  cell <- choice$cell %||% 0.05
  check_number(cell, "cell", min = 0.001, max = 1)
  max_se <- choice$max_se %||% default_max_se
  check_number(max_se, "max_se", min = 0, min_inclusive = FALSE)
  model <- match_choice(choice$model %||% "auto", "model",
                        c("auto", "full", "scale_offset", "offset"))
  if (selection == "cells" && length(sargs)) {
    abort("`", names(sargs)[1], "` sets the paper's orientation bins; give ",
          "it with `selection = \"paper\"` (the default, `\"cells\"`, ",
          "takes one point per distinct posture).")
  }
  if (selection == "paper" && model == "auto") model <- "full"
  use_temp <- choice$use_temp %||% TRUE
  check_flag(use_temp, "use_temp")
  segments <- choice$segments
  if (!is.null(segments)) {
    segment_seconds(segments)
    if (selection != "cells") {
      abort("`segments` needs the default `selection = \"cells\"`: the ",
            "paper's 18 points cannot be split over time.")
    }
  }
  change_alpha <- choice$change_alpha %||% 0.01
  check_number(change_alpha, "change_alpha", min = 0, max = 1,
               min_inclusive = FALSE, max_inclusive = FALSE)
  budget <- match_choice(choice$budget %||% "all", "budget",
                         c("all", "adaptive"))
  target_se <- choice$target_se %||% default_target_se
  check_number(target_se, "target_se", min = 0, min_inclusive = FALSE)
  check_hours <- choice$check_hours %||% 6
  check_number(check_hours, "check_hours", min = 0, min_inclusive = FALSE)
  if (budget == "adaptive" && selection != "cells") {
    abort("`budget = \"adaptive\"` needs the default `selection = ",
          "\"cells\"`.")
  }
  list(selection = selection, cell = cell, max_se = max_se, model = model,
       use_temp = use_temp, segments = segments, change_alpha = change_alpha,
       budget = budget, target_se = target_se, check_hours = check_hours)
}

# The adaptive data budget's target: every standard error of the fitted
# coefficients at most 1 mg (g, or g per degree C for a temperature
# offset), so that each is known to about +-2 mg at 95 %: below the
# 2-5 mg a calibrated device keeps on real rest windows
# (bench/results/freeliving.md).
default_target_se <- 0.001

# The stop rule of the adaptive budget: at each check, fit the rest
# windows read so far as calibrate() would; stop once every standard error
# is at most target_se and the coefficients moved by less than two
# standard errors of their difference since the previous check (the same
# model both times).
budget_rule <- function(fargs, choice, max_norm_error, range_g,
                        max_identical = default_max_identical) {
  prev <- NULL
  function(w) {
    rest <- w[!is.na(w$rest) & w$rest, , drop = FALSE]
    rest <- rest[is.na(guard_windows(rest, max_norm_error, range_g,
                                     max_identical)), ,
                 drop = FALSE]
    if (nrow(rest) == 0) return(FALSE)
    pts <- select_points(rest, selection = "cells", cell = choice$cell)
    f <- fit_chosen_model(pts, fargs, choice, function(status, message,
                                                       points) {
      list(status = status)
    })
    if (!identical(f$status, "ok")) {
      prev <<- NULL
      return(FALSE)
    }
    done <- budget_met(f, prev, choice$target_se)
    prev <<- f
    done
  }
}

# The adaptive budget's test on a fit `f` and the previous check's `prev`
# (NULL: none): every standard error of f's coefficients at most
# `target_se`, and each moved by less than two standard errors of the
# difference since `prev`, which fitted the same coefficients. Shared by
# both methods (budget_rule(), ggir_budget_rule()).
budget_met <- function(f, prev, target_se) {
  nm <- f$model
  se <- f$se[nm]
  length(nm) > 0 && all(is.finite(se)) && all(se <= target_se) &&
    !is.null(prev) && identical(prev$model, nm) &&
    all(abs(stats::coef(f)[nm] - stats::coef(prev)[nm]) <=
          2 * sqrt(se^2 + prev$se[nm]^2))
}

# The largest standard error (HC3) a fitted parameter may have for its
# group to be fitted: 0.01 is 10 mg of error on a 1 g axis, about the
# error calibration is to remove; a parameter known no better than that
# is noise.
default_max_se <- 0.01

# The offsets-only model needs, on every axis, rest points beyond
# +-offset_coverage g on both sides (GGIR's sphere criterion, 0.3 g): with
# an axis seen on one side only, an offset cannot be told from a scale
# error. The axes that fail, as text ("" when none).
offset_coverage <- 0.3

one_sided_axes <- function(pts) {
  m <- cbind(pts$mean_x, pts$mean_y, pts$mean_z)
  lo <- apply(m, 2, min) < -offset_coverage
  hi <- apply(m, 2, max) > offset_coverage
  bad <- !(lo & hi)
  if (!any(bad)) return("")
  paste(sprintf("%s: %s", c("x", "y", "z")[bad],
                ifelse(!lo[bad] & !hi[bad], "neither side",
                       ifelse(lo[bad], "none above", "none below"))),
        collapse = ", ")
}

# Bayesian information criterion of a lightweight fit on its points: n
# log(RSS / n) + k log(n), RSS the sum of the squared residuals of the
# objective (|a|^2 - 1, or |a| - 1 with use_sqrt) and k the parameters
# fitted (Schwarz 1978).
model_bic <- function(fit, pts) {
  v <- point_matrix(pts, "pts")
  temp <- if (any(c("t_x", "t_y", "t_z") %in% fit$model)) pts$temperature
  r <- residual_jacobian(fit, v, temp, isTRUE(fit$settings$use_sqrt))$r
  n <- length(r)
  n * log(sum(r^2) / n) + length(fit$model) * log(n)
}

# The standard errors the points' geometry alone allows: those of a fit
# whose residuals had the sd `floor_sigma` (in the objective's units,
# |a|^2 - 1, about twice |a| - 1). Real rest windows fit to 2-5 mg at
# best; a simulated or unusually clean recording can fit far better, and
# a parameter that only its lack of noise determines (the x offset of a
# device that rested flat on its back) is not determined.
design_se <- function(fit, pts, floor_sigma = 0.004) {
  v <- point_matrix(pts, "pts")
  temp <- if (any(c("t_x", "t_y", "t_z") %in% fit$model)) pts$temperature
  J <- residual_jacobian(fit, v, temp)$J[, fit$model, drop = FALSE]
  A <- crossprod(J)
  inv <- tryCatch(solve(A), error = function(e) NULL)
  if (is.null(inv) || rcond(A) < 1e-12) return(rep(Inf, ncol(J)))
  floor_sigma * sqrt(pmax(diag(inv), 0))
}

# gravcal's lightweight fit: Levenberg-Marquardt on the paper's objective
# over the points, with the model the points determine. "auto" tries all
# nine parameters, then scale and offset, then offset alone, and keeps the
# first whose every standard error is at most max_se; a model needs at
# least twice as many points as parameters.
fit_chosen_model <- function(pts, fargs, choice, fail) {
  if (!is.null(fargs$arithmetic) && fargs$arithmetic != "double" &&
      is.null(fargs$algorithm)) {
    fargs$algorithm <- "descent"
  }
  fargs <- utils::modifyList(list(algorithm = "lm", se = "robust"), fargs)
  if (identical(fargs$algorithm, "descent")) {
    fargs <- utils::modifyList(list(max_iter = 5000, tol = 1e-10), fargs)
  }
  # the temperature term, where the points have a temperature that varies
  # and the fit is Levenberg-Marquardt
  temp_sd <- if (is.numeric(pts$temperature) &&
                 all(is.finite(pts$temperature)) && nrow(pts) > 1) {
    stats::sd(pts$temperature)
  } else 0
  with_temp <- isTRUE(choice$use_temp) && temp_sd > 0 &&
    identical(fargs$algorithm, "lm")
  models <- if (choice$model == "auto") c("full", "scale_offset", "offset")
    else choice$model
  tries <- expand.grid(temp = if (with_temp) c(TRUE, FALSE) else FALSE,
                       model = models, stringsAsFactors = FALSE)
  why <- character(0)
  cand <- list()
  table <- data.frame(model = tries$model, temperature = tries$temp,
                      parameters = NA_integer_, determined = FALSE,
                      bic = NA_real_, chosen = FALSE)
  for (i in seq_len(nrow(tries))) {
    m <- tries$model[i]
    tt <- tries$temp[i]
    k <- as.integer(sum(model_free(m)) + 3 * tt)
    table$parameters[i] <- k
    what <- sprintf("%d parameters (%s%s)", k,
                    switch(m, full = "scale, cross-axis, offset",
                           scale_offset = "scale, offset", offset = "offset"),
                    if (tt) ", temperature offset" else "")
    if (nrow(pts) < 2 * k) {
      why <- c(why, sprintf("%d points are too few for %s", nrow(pts), what))
      next
    }
    if (m == "offset" && nzchar(one_sided <- one_sided_axes(pts))) {
      # offsets alone assume scales of 1: where an axis rested on one side
      # only, its offset would absorb its scale error
      why <- c(why, sprintf(paste0(
        "%s not determined: offsets alone need rest beyond %s g on both ",
        "sides of every axis (%s)"), what, format(offset_coverage),
        one_sided))
      next
    }
    fit <- do.call(fit_gradient, c(list(pts = pts, model = m, use_temp = tt),
                                   fargs))
    if (fit$status != "ok") return(fit)
    if (choice$model != "auto" && (!tt || i == nrow(tries))) return(fit)
    # standard errors against max_se; a temperature offset's (g per degree
    # C) at one standard deviation of the points' temperature
    se <- pmax(fit$se[fit$model], design_se(fit, pts))
    tcols <- fit$model %in% c("t_x", "t_y", "t_z")
    se[tcols] <- se[tcols] * temp_sd
    bad <- !is.finite(se) | se > choice$max_se
    if (!any(bad)) {
      table$determined[i] <- TRUE
      table$bic[i] <- model_bic(fit, pts)
      cand[[i]] <- fit
      # a forced model: the first determined form (with temperature first)
      if (choice$model != "auto") break
      next
    }
    worst <- which.max(ifelse(is.finite(se), se, Inf))
    why <- c(why, sprintf(paste0(
      "%s not determined by the rest points (standard error of %s%s %s > ",
      "max_se = %s)"), what, names(se)[worst],
      if (tcols[worst]) " times the temperature's sd" else "",
      format(signif(se[worst], 2)), format(choice$max_se)))
  }
  if (any(table$determined)) {
    best <- which(table$determined)[which.min(table$bic[table$determined])]
    table$chosen[best] <- TRUE
    fit <- cand[[best]]
    fit$message <- paste0(fit$message, sprintf(" on %d points", nrow(pts)))
    if (sum(table$determined) > 1) {
      fit$message <- paste0(fit$message, sprintf(
        ": of the %d models these points determine, the one with the lowest BIC",
        sum(table$determined)))
    }
    if (length(why)) {
      fit$message <- paste0(fit$message, "; ", paste(why, collapse = "; "))
    }
    fit$models <- table
    return(fit)
  }
  need <- 2 * min(vapply(models, function(m) sum(model_free(m)), 0))
  fail("sphere_not_covered", paste0(
    "not calibrated: the rest windows do not cover enough of the sphere (",
    nrow(pts), " distinct posture", if (nrow(pts) != 1) "s", " in cells of ",
    format(choice$cell), " g); ", if (nrow(pts) < need) {
      sprintf("at least %d are needed to fit %d parameters", need, need / 2)
    } else paste(why, collapse = "; ")), points = pts)
}
