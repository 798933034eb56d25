#' Names of the nine orientation bins
#'
#' Bin `"x-"` holds points whose x coordinate lies in \[-1.25, -0.75\] g,
#' `"x0"` in \[-0.25, 0.25\] g, `"x+"` in \[0.75, 1.25\] g; likewise for y and
#' z (Farago et al. 2024, Eq. 10).
#' @return A character vector of the nine bin names, in the core's order.
#' @export
#' @examples
#' bin_names()
bin_names <- function() {
  paste0(rep(c("x", "y", "z"), each = 3), c("-", "0", "+"))
}

#' Select calibration points in 3 x 3 orientation bins
#'
#' Offers the rest windows, in time order, to the lightweight method's point
#' selector (Farago et al. 2024, Sec. II-B-1 and Fig. 6), exactly as a device
#' streaming its rest segments would. Each axis has three intervals,
#' negative \[-1.25, -0.75\], zero \[-0.25, 0.25\] and positive
#' \[0.75, 1.25\] g, giving nine bins. A rest mean is kept when
#' 1. it lies in at least one bin that still has room (fewer than `per_bin`
#'    points), and
#' 2. it is at least `min_distance` g (Euclidean) from every point kept so far.
#'
#' A point can lie in up to three bins (one per axis); it counts for exactly
#' one: its negative or positive bin when that bin has room (those caps cover
#' an eighth of the sphere each, the zero bands a quarter, so points that can
#' fill them should), otherwise the open zero bin whose axis coordinate is
#' nearest to 0, ties going to the earlier bin in [bin_names()] order. A
#' device lying flat on +z fills `z+` first, then `x0` or `y0`. Selection
#' stops when every bin is full; the fit may start once every bin holds
#' `min_per_bin` points.
#'
#' The paper does not print its novelty threshold. gravcal's default of 0.3 g
#' (about 17 degrees of tilt) spreads the points: on the paper's simulation it
#' lowers the mean absolute errors after 50 iterations by a third against
#' 0.1 g, because a spread set is better conditioned and the descent
#' converges faster (`bench/results/table2.md`). [calibrate()] gives
#' `min_distance = c(0.3, 0.1, 0.03)`: when a recording has too few distinct
#' postures for 0.3 g, the bins still short of points are filled with 0.1 g,
#' then 0.03 g, keeping the points already chosen.
#'
#' @param w Windows from [rest_windows()], or any data frame with numeric
#'   columns `mean_x`, `mean_y`, `mean_z` (and optionally a logical `rest`
#'   column; only rest rows are offered when it is present).
#' @param per_bin Maximum number of points per bin (paper: 2, so 18 points).
#' @param min_per_bin Points each bin needs before fitting (paper: 2).
#' @param min_distance Novelty threshold in g: the smallest distance from a new
#'   point to every kept point. Several values, in decreasing order, make
#'   successive passes: each keeps the points already chosen and fills only
#'   the bins still short of points with the next, smaller threshold, so the
#'   points stay spread (a single pass with a small threshold would pick
#'   points close together everywhere, and a poorly spread set calibrates
#'   worse; see `vignette("farago2024")`).
#' @param arithmetic Number type of the selector (see [fit_gradient()]):
#'   the coordinates are rounded to it, as a device holding them in fixed
#'   point would, so that R selects the points the device selects.
#' @return The selected rows of `w` (all its columns), in the order they were
#'   kept, with two more columns: `bin` (a factor with levels [bin_names()])
#'   and `row` (the row of `w` the point came from). Attributes: `counts`
#'   (points per bin), `complete` (every bin has `min_per_bin`), `per_bin`,
#'   `min_per_bin`, `min_distance` (the thresholds of the passes made),
#'   `offered` (rest rows considered).
#' @seealso [fit_gradient()]
#' @export
#' @examples
#' set.seed(1)
#' cand <- simulate_points(500, noise = 0.001)
#' pts <- select_points(cand)
#' table(pts$bin)
#' attr(pts, "complete")
select_points <- function(w, per_bin = 2, min_per_bin = per_bin,
                          min_distance = 0.3,
                          arithmetic = c("double", "float", "fixed32",
                                         "fixed16")) {
  arithmetic <- match_choice(arithmetic, "arithmetic")
  w <- as_epochs(w)
  check_number(per_bin, "per_bin", min = 1, max = 64, integer = TRUE)
  check_number(min_per_bin, "min_per_bin", min = 1, max = per_bin,
               integer = TRUE)
  if (!is.numeric(min_distance) || !length(min_distance) ||
      !all(is.finite(min_distance)) || any(min_distance < 0) ||
      is.unsorted(rev(min_distance))) {
    abort("`min_distance` must be one or more non-negative numbers in g, ",
          "in decreasing order, not ", describe(min_distance), ".")
  }
  rows <- seq_len(nrow(w))
  if ("rest" %in% names(w)) {
    if (!is.logical(w$rest)) {
      abort("Column `rest` of `w` must be logical, not ", class(w$rest)[1],
            ".")
    }
    rows <- rows[!is.na(w$rest) & w$rest]
  }
  ok <- is.finite(w$mean_x[rows]) & is.finite(w$mean_y[rows]) &
    is.finite(w$mean_z[rows])
  rows <- rows[ok]
  # One pass per threshold. A later pass first offers the points kept so far
  # (the selector keeps them again, in the same bins: they are further apart
  # than the smaller threshold), then the other windows in time order, so
  # it only fills the bins still short of points.
  kept_rows <- integer(0)
  for (md in min_distance) {
    offer <- c(kept_rows, setdiff(rows, kept_rows))
    sel <- gc_select_points(w$mean_x[offer], w$mean_y[offer], w$mean_z[offer],
                            as.integer(min_per_bin), as.integer(per_bin), md,
                            arithmetic)
    kept <- which(!is.na(sel$bin) & sel$bin >= 0)
    kept_rows <- offer[kept]
    kept_bins <- sel$bin[kept]
    if (isTRUE(sel$complete)) break
  }
  pts <- w[kept_rows, , drop = FALSE]
  pts$bin <- factor(bin_names()[kept_bins + 1], levels = bin_names())
  pts$row <- kept_rows
  rownames(pts) <- NULL
  counts <- stats::setNames(sel$counts, bin_names())
  attr(pts, "counts") <- counts
  attr(pts, "complete") <- sel$complete
  attr(pts, "per_bin") <- per_bin
  attr(pts, "min_per_bin") <- min_per_bin
  attr(pts, "min_distance") <- min_distance[seq_len(match(md, min_distance))]
  attr(pts, "offered") <- length(rows)
  pts
}

# Which bins lack points, as a readable string.
missing_bins <- function(pts) {
  counts <- attr(pts, "counts")
  need <- attr(pts, "min_per_bin")
  short <- counts < need
  paste(sprintf("%s (%d of %d)", names(counts)[short], counts[short], need),
        collapse = ", ")
}
