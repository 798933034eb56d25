#' Plot rest points before and after calibration
#'
#' `type = "map"` (default): where on the sphere the recording rested, and
#' how far each rest window is from 1 g before and after calibration. Two
#' maps of directions, azimuth (`atan2(y, x)`, degrees) against elevation
#' (`asin(z / |v|)`, degrees), one point per rest window coloured by its
#' error `| |v| - 1 |` in mg (before calibration on the left, after on the
#' right, one colour scale); the windows the fit used are ringed in black.
#' Empty regions of the map are orientations the recording never rested
#' in, which the fit cannot learn from.
#'
#' `type = "panels"`: four panels: (1) the deviation of every rest window
#' from the unit sphere in 3-D, as in Farago et al. (2024), Fig. 8: each
#' mean vector `v` is drawn at `v (|v| - 1) / |v|`, so a perfectly
#' calibrated point sits at the origin and the distance from it is the
#' error; (2-4) the x-y, x-z and y-z projections of the rest means against
#' the unit circle. Before calibration in blue, after in red.
#'
#' @param x A `gravcal_fit`.
#' @param which For `type = "panels"`: the panels to draw, any of 1:4
#'   (giving `which` without `type` means `type = "panels"`).
#' @param set `"windows"` (all rest windows, default when available) or
#'   `"points"` (only the fitting points).
#' @param theta,phi Viewing angles of the 3-D panel (see [graphics::persp()]).
#' @param type `"map"`, `"panels"`, or `"segments"` (a fit with
#'   coefficients per segment of time, see [calibrate()]: the offsets,
#'   scales and, where fitted, cross-axis terms and temperature offsets of
#'   each segment over the hours of the recording, with bars of +- 2
#'   standard errors).
#' @param ... Unused.
#' @return `x`, invisibly.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 12, sf = 10, seed = 3)
#' fit <- calibrate(rec, sf = 10)
#' plot(fit)
#' plot(fit, type = "panels")
plot.gravcal_fit <- function(x, which = 1:4, set = c("windows", "points"),
                             theta = 35, phi = 20,
                             type = c("map", "panels", "segments"), ...) {
  set <- match_choice(set, "set")
  # panels chosen by number are the "panels" type's
  if (missing(type) && !missing(which)) type <- "panels"
  type <- match_choice(type, "type")
  if (type == "segments") {
    check_fit(x, "x")
    if (is.null(x$segments)) {
      abort("`x` has no segments: fit it with `calibrate(..., segments = ",
            "\"day\")` (or a number of hours).")
    }
    plot_segments(x)
    return(invisible(x))
  }
  if (!is.numeric(which) || !length(which) || !all(which %in% 1:4)) {
    abort("`which` must be a subset of 1:4, not ", describe(which), ".")
  }
  check_fit(x, "x")
  check_number(theta, "theta")
  check_number(phi, "phi")
  what <- if (set == "windows" && NROW(x$windows) > 0) "windows" else "points"
  d <- x[[what]]
  if (NROW(d) == 0) {
    abort("`x` has no rest points to plot (status: ", x$status, ").")
  }
  before <- point_matrix(d, paste0("x$", what))
  zero <- which(rowSums(before^2) == 0)
  if (length(zero)) {
    abort("`x$", what, "` must hold rest windows near 1 g; ", length(zero),
          " of them (row", if (length(zero) > 1) "s", " ",
          paste(utils::head(zero, 5), collapse = ", "),
          if (length(zero) > 5) ", ...", ") ", if (length(zero) > 1) "are" else
            "is", " the zero vector, which has no direction to plot.")
  }
  after <- calibrate_points(x, before, d$temperature)
  if (type == "map") {
    sphere_map(sphere_map_data(x, d, before, after))
    return(invisible(x))
  }
  col <- c(before = grDevices::adjustcolor("#1f78b4", 0.6),
           after = grDevices::adjustcolor("#e31a1c", 0.7))
  if (length(which) > 1) {
    old <- graphics::par(mfrow = c(2, 2), mar = c(4, 4, 2.5, 1))
    on.exit(graphics::par(old), add = TRUE)
  }
  if (1 %in% which) deviation_panel(before, after, col, theta, phi)
  planes <- list(c(1, 2), c(1, 3), c(2, 3))
  for (k in intersect(2:4, which)) {
    projection_panel(before, after, planes[[k - 1]], col)
  }
  invisible(x)
}

deviation_panel <- function(before, after, col, theta, phi) {
  dev <- function(v) {
    r <- sqrt(rowSums(v^2))
    v * (r - 1) / r
  }
  db <- 1000 * dev(before)
  da <- 1000 * dev(after)
  lim <- max(abs(c(db, da)), 1) * c(-1, 1)
  pm <- graphics::persp(lim, lim, matrix(lim[1], 2, 2), zlim = lim,
                        theta = theta, phi = phi, border = NA, col = NA,
                        box = TRUE, ticktype = "detailed", nticks = 3,
                        xlab = "x (mg)", ylab = "y (mg)", zlab = "z (mg)",
                        cex.axis = 0.7, cex.lab = 0.8)
  pb <- grDevices::trans3d(db[, 1], db[, 2], db[, 3], pm)
  pa <- grDevices::trans3d(da[, 1], da[, 2], da[, 3], pm)
  graphics::points(pb, pch = 16, cex = 0.5, col = col[["before"]])
  graphics::points(pa, pch = 16, cex = 0.5, col = col[["after"]])
  graphics::title(main = "Deviation from 1 g", cex.main = 0.9)
  graphics::legend("topleft", c("before", "after"), pch = 16, col = col,
                   bty = "n", cex = 0.7)
}

projection_panel <- function(before, after, axes, col) {
  nm <- c("x", "y", "z")
  graphics::plot(NA, xlim = c(-1.3, 1.3), ylim = c(-1.3, 1.3), asp = 1,
                 xlab = paste(nm[axes[1]], "(g)"),
                 ylab = paste(nm[axes[2]], "(g)"))
  a <- seq(0, 2 * pi, length.out = 361)
  graphics::lines(cos(a), sin(a), col = "grey50")
  graphics::points(before[, axes], pch = 16, cex = 0.5, col = col[["before"]])
  graphics::points(after[, axes], pch = 16, cex = 0.5, col = col[["after"]])
  graphics::title(main = paste0(nm[axes[1]], "-", nm[axes[2]], " projection"),
                  cex.main = 0.9)
}

# One row per rest window: its direction (azimuth and elevation in degrees,
# from the uncalibrated mean), its error before and after calibration (mg),
# and whether the fit used it.
sphere_map_data <- function(fit, d, before, after) {
  r <- sqrt(rowSums(before^2))
  key <- function(m) paste(m[, 1], m[, 2], m[, 3])
  used <- if (!NROW(fit$points)) {
    rep(FALSE, nrow(before))
  } else if (identical(d, fit$windows) && !is.null(fit$points$row)) {
    # the points are rows of the rest windows (identical windows stay apart)
    seq_len(nrow(d)) %in% fit$points$row
  } else {
    key(before) %in% key(as.matrix(fit$points[, c("mean_x", "mean_y", "mean_z")]))
  }
  data.frame(azimuth = atan2(before[, 2], before[, 1]) * 180 / pi,
             elevation = asin(pmax(-1, pmin(1, before[, 3] / r))) * 180 / pi,
             error_before_mg = 1000 * abs(r - 1),
             error_after_mg = 1000 * abs(sqrt(rowSums(after^2)) - 1),
             used = used)
}

sphere_map <- function(m) {
  old <- graphics::par(no.readonly = TRUE)
  on.exit(graphics::par(old), add = TRUE)
  graphics::layout(matrix(1:3, 1), widths = c(1, 1, 0.22))
  graphics::par(mar = c(4.5, 4, 3, 1))
  # one colour scale for both maps, on a square-root scale of the error
  top <- max(c(m$error_before_mg, m$error_after_mg, 1), na.rm = TRUE)
  pal <- grDevices::hcl.colors(64, "viridis", rev = TRUE)
  colour <- function(e) pal[pmin(64, 1 + floor(63 * sqrt(pmax(e, 0) / top)))]
  for (k in 1:2) {
    e <- if (k == 1) m$error_before_mg else m$error_after_mg
    graphics::plot(NA, xlim = c(-180, 180), ylim = c(-90, 90), xaxt = "n",
                   yaxt = "n", xlab = "azimuth (degrees)",
                   ylab = "elevation (degrees)")
    graphics::axis(1, at = seq(-180, 180, 90))
    graphics::axis(2, at = seq(-90, 90, 45))
    graphics::abline(h = 0, v = c(-90, 0, 90), col = "grey85")
    o <- order(e)
    graphics::points(m$azimuth[o], m$elevation[o], pch = 16, cex = 0.7,
                     col = colour(e[o]))
    graphics::points(m$azimuth[m$used], m$elevation[m$used], pch = 1,
                     cex = 1.1, lwd = 1.2)
    graphics::title(main = sprintf("%s calibration: mean error %.1f mg",
                                   if (k == 1) "Before" else "After",
                                   mean(e)), cex.main = 0.9, line = 1.6)
    graphics::mtext(sprintf("%d rest windows, %d used by the fit (ringed)",
                            nrow(m), sum(m$used)), side = 3, line = 0.3,
                    cex = 0.65)
  }
  # the colour scale
  graphics::par(mar = c(4.5, 0.5, 3, 3))
  ticks <- pretty(c(0, top), n = 5)
  ticks <- ticks[ticks <= top]
  yy <- seq(0, 1, length.out = 65)
  graphics::plot(NA, xlim = c(0, 1), ylim = c(0, 1), axes = FALSE, xlab = "",
                 ylab = "")
  graphics::rect(0, yy[-65], 0.5, yy[-1], col = pal, border = NA)
  graphics::axis(4, at = sqrt(ticks / top), labels = ticks, las = 1,
                 cex.axis = 0.8, pos = 0.5)
  graphics::title(main = "error (mg)", cex.main = 0.8)
}

# Each segment's coefficients over time, +- 2 se, one panel per group.
plot_segments <- function(fit) {
  seg <- fit$segments
  st <- fit$segment_settings
  last <- max(as.numeric(fit$windows$start), seg$from[is.finite(seg$from)],
              na.rm = TRUE)
  from <- ifelse(is.finite(seg$from), seg$from, st$origin)
  to <- ifelse(is.finite(seg$to), seg$to, pmax(last, from + st$seconds))
  h0 <- (from - st$origin) / 3600
  h1 <- (to - st$origin) / 3600
  groups <- list(offset = c("o_x", "o_y", "o_z"),
                 scale = c("k_xx", "k_yy", "k_zz"),
                 "cross-axis" = c("k_xy", "k_xz", "k_yz"),
                 "temperature offset" = c("t_x", "t_y", "t_z"))
  fitted <- vapply(groups, function(g) any(g %in% fit$model), NA)
  groups <- groups[fitted]
  cols <- c("#1f77b4", "#d62728", "#2ca02c")
  op <- graphics::par(mfrow = c(length(groups), 1), mar = c(3.6, 4.5, 2, 1),
                      mgp = c(2.2, 0.7, 0))
  on.exit(graphics::par(op))
  for (g in names(groups)) {
    nm <- groups[[g]]
    est <- as.matrix(seg[nm])
    se <- as.matrix(seg[paste0(nm, ".se")])
    se[!is.finite(se)] <- 0
    lim <- range(c(est - 2 * se, est + 2 * se), finite = TRUE)
    graphics::plot(NA, xlim = range(c(h0, h1)), ylim = lim,
                   xlab = "hours from the start", ylab = g,
                   main = sprintf("%s, %d segment%s", g, nrow(seg),
                                  if (nrow(seg) > 1) "s" else ""))
    for (j in seq_along(nm)) {
      mid <- (h0 + h1) / 2
      graphics::segments(h0, est[, j], h1, est[, j], col = cols[j], lwd = 2)
      graphics::arrows(mid, est[, j] - 2 * se[, j], mid, est[, j] + 2 * se[, j],
                       angle = 90, code = 3, length = 0.03, col = cols[j])
    }
    graphics::legend("topright", legend = sub("^[a-z]_", "", nm), col = cols,
                     lwd = 2, bty = "n", horiz = TRUE, cex = 0.8)
  }
}
