# The fit class, `gravcal_fit`: one shape for both methods (DESIGN.md), its
# constructor, the guards every fit passes, and its methods (coef, print,
# summary).

# The plausible coefficient ranges (`plausible`, the refusal bounds of
# plausible_bounds()) are in plausibility.R.

# A fit that does not lower the error or whose coefficients are implausible
# is not applied: identity coefficients and a status that says why.
guard_fit <- function(fit) {
  if (fit$status != "ok") return(fit)
  identity <- function(status, message) {
    fit$K[] <- diag(3)
    fit$offset[] <- 0
    fit$tempoffset[] <- 0
    if (!is.null(fit$params)) fit$params[] <- c(1, 1, 1, 0, 0, 0, 0, 0, 0)
    fit$status <- status
    fit$message <- message
    fit <- refresh_errors(clear_uncertainty(fit))
    fit
  }
  before <- fit$error_before
  after <- fit$error_after
  if (!(after < before)) {
    return(identity("no_improvement", sprintf(paste0(
      "calibration not applied: it does not lower the error on the rest ",
      "points (%.2f mg before, %.2f mg after)"), 1000 * before,
      1000 * after)))
  }
  K <- fit$K
  off <- abs(K[lower.tri(K)])
  if (any(diag(K) < plausible$scale[1] | diag(K) > plausible$scale[2]) ||
      any(off > plausible$cross) || any(abs(fit$offset) > plausible$offset)) {
    return(identity("implausible", paste0(
      "calibration not applied: coefficients outside plausible ranges ",
      "(scale ", plausible$scale[1], "-", plausible$scale[2],
      ", |cross-axis| <= ", plausible$cross, ", |offset| <= ",
      plausible$offset, " g)")))
  }
  fit
}

# Attach the rest windows and held-out errors.
finish_fit <- function(fit, rest) {
  fit$windows <- rest
  fit$n_windows <- attr(rest, "n_windows")
  used <- if (is.null(fit$points$row)) integer(0) else fit$points$row
  held <- rest[setdiff(seq_len(nrow(rest)), used), , drop = FALSE]
  fit$error_heldout_before <- NA_real_
  fit$error_heldout_after <- NA_real_
  if (nrow(held) > 0) {
    v <- point_matrix(held, "held")
    fit$error_heldout_before <- sphere_error(v)
    fit$error_heldout_after <- sphere_error(if (segmented(fit)) {
      calibrate_points_by_time(fit, v, held$start, held$temperature)
    } else calibrate_points(fit, v, held$temperature))
  }
  if (segmented(fit) && NROW(fit$points)) {
    v <- point_matrix(fit$points, "points")
    fit$error_after <- sphere_error(calibrate_points_by_time(
      fit, v, fit$points$start, fit$points$temperature))
  }
  fit
}

# Constructor of the one fit class both methods return.
new_fit <- function(K = diag(3), offset = c(0, 0, 0), tempoffset = c(0, 0, 0),
                    meantemp = NA_real_, points = NULL, method, iterations = 0L,
                    converged = FALSE, status = "ok", message = "", call = NULL) {
  dimnames(K) <- list(c("x", "y", "z"), c("x", "y", "z"))
  fit <- list(K = K, offset = stats::setNames(as.double(offset), c("x", "y", "z")),
              tempoffset = stats::setNames(as.double(tempoffset),
                                           c("x", "y", "z")),
              meantemp = meantemp, points = points,
              iterations = as.integer(iterations), converged = converged,
              status = status, message = message, method = method, call = call)
  class(fit) <- "gravcal_fit"
  fit <- refresh_errors(clear_uncertainty(fit))
  # the coefficients the model fitted, named as in coef() (none when the
  # fit is the identity)
  if (identical(status, "ok")) fit$model <- fitted_names(fit)
  fit
}

refresh_errors <- function(fit) {
  fit$error_before <- NA_real_
  fit$error_after <- NA_real_
  if (!is.null(fit$points) && nrow(fit$points) > 0) {
    v <- point_matrix(fit$points, "points")
    fit$error_before <- sphere_error(v)
    fit$error_after <- sphere_error(calibrate_points(fit, v,
                                                     fit$points$temperature))
  }
  fit
}

# Mean | |v| - 1 | over the rows of an n x 3 matrix.
sphere_error <- function(v) {
  mean(abs(sqrt(rowSums(v^2)) - 1))
}

# Calibrated n x 3 matrix of a fit's model (apply_model()), with the
# temperature term where the fit has one and `temperature` is given.
calibrate_points <- function(fit, v, temperature = NULL) {
  dt <- if (any(fit$tempoffset != 0) && !is.null(temperature)) {
    temperature - fit$meantemp
  }
  unname(apply_model(v, fit$K, fit$offset, fit$tempoffset, dt))
}

#' @export
coef.gravcal_fit <- function(object, ...) {
  check_fit(object, "object")
  K <- object$K
  stats::setNames(c(diag(K), K[2, 1], K[3, 1], K[3, 2], object$offset,
                    object$tempoffset),
                  c(param_names(), "t_x", "t_y", "t_z"))
}

#' @export
print.gravcal_fit <- function(x, digits = 5, ...) {
  check_fit(x, "x")
  check_number(digits, "digits", min = 0, max = 15, integer = TRUE)
  cat("<gravcal_fit> ", x$method, " method, status: ", x$status, "\n",
      sep = "")
  if (nzchar(x$message)) cat("  ", x$message, "\n", sep = "")
  # the plausibility flag (calibrate_files()'s, with the device's history,
  # or the bounds of plausible_bounds() alone), when it is not "ok"
  pl <- if (is.null(x$plausibility)) fit_plausibility(x) else x$plausibility
  if (!is.null(pl) && !is.na(pl$flag) && pl$flag != "ok" &&
      x$status %in% c("ok", "high_error")) {
    cat("  plausibility: ", pl$flag, if (nzchar(pl$note)) paste0(" - ", pl$note),
        "\n", sep = "")
  }
  inp <- format_input(x$input)
  if (!is.null(inp)) cat("  input: ", inp, "\n", sep = "")
  np <- if (is.null(x$points)) 0L else nrow(x$points)
  nw <- if (is.null(x$windows)) NA else nrow(x$windows)
  cat(sprintf("  points: %d", np))
  if (!is.na(nw)) {
    cat(sprintf(" of %d rest windows (%s windows in all)", nw,
                format(x$n_windows)))
  }
  cat("\n")
  if (!is.null(x$excluded)) {
    cat("  rest windows left out: ", format_excluded(x$excluded, x$guards),
        "\n", sep = "")
  }
  print_rejected(x)
  if (identical(x$budget$budget, "adaptive")) {
    b <- x$budget
    cat(sprintf("  adaptive budget: read %.1f%s hours, %s\n", b$hours_read,
                if (is.finite(b$hours_total)) sprintf(" of %.1f", b$hours_total)
                else "", if (b$stopped) sprintf(paste0(
                  "stopped once every standard error was at most %s and ",
                  "the coefficients stable"), format(b$target_se)) else
                  "the target was not reached before the end"))
  }
  if (is.finite(x$error_before)) {
    cat(sprintf("  error on fitting points: %.2f mg -> %.2f mg\n",
                1000 * x$error_before, 1000 * x$error_after))
  }
  if (isTRUE(is.finite(x$error_heldout_before))) {
    cat(sprintf("  error on held-out rest:  %.2f mg -> %.2f mg\n",
                1000 * x$error_heldout_before, 1000 * x$error_heldout_after))
  }
  cat("  K (a = K (v + offset)):\n")
  K <- format(round(x$K, digits), nsmall = digits)
  cat(paste0("    ", apply(K, 1, paste, collapse = "  "), collapse = "\n"),
      "\n")
  cat("  offset (g):", format(round(x$offset, digits), nsmall = digits), "\n")
  if (any(x$tempoffset != 0)) {
    cat("  tempoffset (g/degree C):",
        format(signif(x$tempoffset, digits)), "\n")
    cat("  meantemp (degree C):", format(x$meantemp), "\n")
  }
  print_se(x$se, x$df)
  if (segmented(x)) {
    seg <- x$segments
    cat(sprintf("  %d segments over time (coefficients in fit$segments):\n",
                nrow(seg)))
    for (i in seq_len(nrow(seg))) {
      cat(sprintf("    %d: %s to %s, %d points, offset %s\n", i,
                  format_segment_time(x, seg$from[i]),
                  format_segment_time(x, seg$to[i]), seg$points[i],
                  paste(format(round(c(seg$o_x[i], seg$o_y[i], seg$o_z[i]),
                                     digits), nsmall = digits),
                        collapse = " ")))
    }
  }
  invisible(x)
}

# The rest windows the fit left out as not on the sphere, and their
# stretches of time (near-rest.R), for print() and summary().
print_rejected <- function(x) {
  line <- format_rejected(x$rejected)
  if (is.null(line)) return(invisible())
  cat("  off the sphere, left out: ", line, "\n", sep = "")
  for (s in format_stretches(x$rejected_stretches)) cat("    ", s, "\n", sep = "")
  invisible()
}

# A segment boundary for people: hours from the start of the recording.
format_segment_time <- function(fit, t) {
  if (!is.finite(t)) return(if (t < 0) "start" else "end")
  sprintf("%.1f h", (t - fit$segment_settings$origin) / 3600)
}

# The standard errors that exist, by group.
print_se <- function(se, df) {
  if (is.null(se) || !any(is.finite(se))) return(invisible())
  cat(sprintf("  standard errors (%d residual df):\n", as.integer(df)))
  groups <- list("scale" = c("k_xx", "k_yy", "k_zz"),
                 "cross-axis" = c("k_xy", "k_xz", "k_yz"),
                 "offset (g)" = c("o_x", "o_y", "o_z"),
                 "tempoffset (g/degree C)" = c("t_x", "t_y", "t_z"))
  for (g in names(groups)) {
    v <- se[groups[[g]]]
    if (any(is.finite(v))) {
      cat("    ", g, ": ", paste(format(signif(v, 2)), collapse = " "),
          "\n", sep = "")
    }
  }
  invisible()
}

#' @export
summary.gravcal_fit <- function(object, ...) {
  check_fit(object, "object")
  co <- stats::coef(object)
  num <- function(v) if (length(v) == 1 && is.numeric(v)) v else NA_real_
  err <- data.frame(set = "fitting points", n = NROW(object$points),
                    before_mg = 1000 * num(object$error_before),
                    after_mg = 1000 * num(object$error_after))
  # the held-out set: rest windows not used as points, where the fit keeps
  # its rest windows apart from its points (the lightweight method)
  if (!is.null(object$windows) && !is.null(object$points$row)) {
    err <- rbind(err, data.frame(
      set = "held-out rest windows",
      n = NROW(object$windows) - length(unique(object$points$row)),
      before_mg = 1000 * num(object$error_heldout_before),
      after_mg = 1000 * num(object$error_heldout_after)))
  }
  err$improvement <- err$before_mg / err$after_mg
  bins <- NULL
  if (!is.null(object$points$bin)) bins <- table(object$points$bin)
  se <- object$se
  if (is.null(se)) se <- stats::setNames(rep(NA_real_, length(co)), names(co))
  co <- cbind(estimate = co, se = unname(se[names(co)]))
  structure(list(method = object$method, status = object$status,
                 message = object$message, coefficients = co, errors = err,
                 df = if (is.null(object$df)) NA_integer_ else object$df,
                 bins = bins, iterations = object$iterations,
                 converged = object$converged, rejected = object$rejected,
                 rejected_stretches = object$rejected_stretches),
            class = "summary.gravcal_fit")
}

#' @export
print.summary.gravcal_fit <- function(x, ...) {
  cat("gravcal calibration (", x$method, " method)\n", sep = "")
  cat("status: ", x$status, if (nzchar(x$message)) paste0(" - ", x$message),
      "\n\n", sep = "")
  cat("Coefficients:\n")
  co <- x$coefficients
  if (any(is.finite(co[, "se"]))) {
    cat("(standard errors on ", x$df, " residual df; NA: not fitted)\n",
        sep = "")
    print(cbind(estimate = round(co[, "estimate"], 6),
                se = signif(co[, "se"], 3)))
  } else {
    print(round(co[, "estimate"], 6))
  }
  cat("\nError | |a| - 1 | (mg):\n")
  e <- x$errors
  e$before_mg <- round(e$before_mg, 2)
  e$after_mg <- round(e$after_mg, 2)
  e$improvement <- round(e$improvement, 2)
  print(e, row.names = FALSE)
  if (!is.null(format_rejected(x$rejected)) &&
      (x$rejected$windows > 0 || nzchar(x$rejected$note))) {
    cat("\nRest windows off the sphere, left out:\n")
    print_rejected(x)
  }
  if (!is.null(x$bins)) {
    cat("\nPoints per orientation bin:\n")
    print(x$bins)
  }
  cat("\niterations:", x$iterations, "\n")
  invisible(x)
}
