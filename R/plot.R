#' Plot rest points before and after calibration
#'
#' Four panels: (1) the deviation of every rest window from the unit sphere
#' in 3-D, as in Farago et al. (2024), Fig. 8: each mean vector `v` is drawn
#' at `v (|v| - 1) / |v|`, so a perfectly calibrated point sits at the origin
#' and the distance from it is the error; (2-4) the x-y, x-z and y-z
#' projections of the rest means against the unit circle. Before calibration
#' in blue, after in red.
#'
#' @param x A `gravcal_fit`.
#' @param which Panels to draw, any of 1:4.
#' @param set `"windows"` (all rest windows, default when available) or
#'   `"points"` (only the fitting points).
#' @param theta,phi Viewing angles of the 3-D panel (see [graphics::persp()]).
#' @param ... Unused.
#' @return `x`, invisibly.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 12, sf = 10, seed = 3)
#' fit <- calibrate(rec, sf = 10)
#' plot(fit)
plot.gravcal_fit <- function(x, which = 1:4, set = c("windows", "points"),
                             theta = 35, phi = 20, ...) {
  set <- match_choice(set, "set")
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
