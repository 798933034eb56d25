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
#' @param selection `"bins"` (default): the paper's selector above.
#'   `"cells"`: gravcal's selection for recordings of daily life, the
#'   default of [calibrate()]: every distinct posture the recording rested
#'   in, one point each. The rest means are put on a grid of cubes of side
#'   `cell` g; from each cube that holds any, the stillest window (smallest
#'   largest `range_*`, or `sd_*` for epochs without ranges; the first in
#'   time on ties) is a point. A recording that lay still in one posture
#'   for hours gives that posture one point, not hundreds, so the fit is
#'   not ruled by the postures people keep longest, and every orientation
#'   seen counts. The number of points is bounded by the grid (at most
#'   about `4 pi / cell^2`, some 5,000 for 0.05 g), whatever the length of
#'   the recording. `per_bin`, `min_per_bin`, `min_distance` and
#'   `arithmetic` are not used.
#' @param cell For `selection = "cells"`: the grid's side in g (default
#'   0.05 g, about 3 degrees of tilt).
#' @return The selected rows of `w` (all its columns), in the order they were
#'   kept (in time order for `"cells"`), with two more columns: `bin` (a
#'   factor with levels [bin_names()]; for `"cells"` the first of the
#'   paper's bins the point lies in, NA when in none) and `row` (the row of
#'   `w` the point came from). For `"cells"`, attributes `selection`,
#'   `cell`, `offered` and `counts` (points per bin they lie in). Attributes: `counts`
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
#' # every distinct posture, one point each
#' nrow(select_points(cand, selection = "cells"))
select_points <- function(w, per_bin = 2, min_per_bin = per_bin,
                          min_distance = 0.3,
                          arithmetic = c("double", "float", "fixed32",
                                         "fixed16"),
                          selection = c("bins", "cells"), cell = 0.05) {
  arithmetic <- match_choice(arithmetic, "arithmetic")
  selection <- match_choice(selection, "selection")
  w <- as_epochs(w)
  if (selection == "cells") return(select_cells(w, cell))
  check_number(per_bin, "per_bin", min = 1, max = 64, integer = TRUE)
  check_number(min_per_bin, "min_per_bin", min = 1, max = per_bin,
               integer = TRUE)
  if (!is.numeric(min_distance) || !length(min_distance) ||
      !all(is.finite(min_distance)) || any(min_distance < 0) ||
      is.unsorted(rev(min_distance))) {
    abort("`min_distance` must be one or more non-negative numbers in g, ",
          "in decreasing order, not ", describe(min_distance), ".")
  }
  rows <- rest_rows(w)
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

# One key per row of the means m: which cube of side `cell` it lies in. A
# number (17 bits a coordinate, exact in a double) while every cube index
# fits, which any mean within 3000 g does; text otherwise.
cell_keys <- function(m, cell) {
  i <- round(m / cell)
  if (all(abs(i) < 65535)) {
    (i[, 1] + 65536) * 2^34 + (i[, 2] + 65536) * 2^17 + (i[, 3] + 65536)
  } else {
    paste(i[, 1], i[, 2], i[, 3])
  }
}

# gravcal's selection: the stillest rest window of each cube of side `cell`
# g that holds rest means, in time order.
select_cells <- function(w, cell) {
  check_number(cell, "cell", min = 0.001, max = 1)
  rows <- rest_rows(w)
  m <- cbind(w$mean_x[rows], w$mean_y[rows], w$mean_z[rows])
  key <- cell_keys(m, cell)
  stillness <- function(prefix) {
    cols <- paste0(prefix, c("x", "y", "z"))
    if (!all(cols %in% names(w))) return(NULL)
    s <- pmax(w[[cols[1]]][rows], w[[cols[2]]][rows], w[[cols[3]]][rows])
    s[!is.finite(s)] <- Inf
    s
  }
  still <- stillness("range_")
  if (is.null(still)) still <- stillness("sd_")
  if (is.null(still)) still <- rep(0, length(rows))
  o <- order(key, still, rows, method = "radix")
  pick <- sort(o[!duplicated(key[o])])
  kept <- rows[pick]
  pts <- w[kept, , drop = FALSE]
  pts$bin <- factor(bin_names()[first_bin(m[pick, , drop = FALSE])],
                    levels = bin_names())
  pts$row <- kept
  rownames(pts) <- NULL
  attr(pts, "counts") <- bin_counts(m[pick, , drop = FALSE])
  attr(pts, "selection") <- "cells"
  attr(pts, "cell") <- cell
  attr(pts, "offered") <- length(rows)
  pts
}

# The rows offered as points: rest rows (all when there is no `rest`
# column) with finite means.
rest_rows <- function(w) {
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
  rows[ok]
}

# n x 9 membership of points in the paper's bins (Eq. 10), bin_names()
# order.
bin_membership <- function(m) {
  inside <- function(v, lo, hi) v >= lo & v <= hi
  out <- NULL
  for (j in 1:3) {
    out <- cbind(out, inside(m[, j], -1.25, -0.75), inside(m[, j], -0.25, 0.25),
                 inside(m[, j], 0.75, 1.25))
  }
  out
}

first_bin <- function(m) {
  b <- bin_membership(m)
  i <- max.col(b, ties.method = "first")
  i[rowSums(b) == 0] <- NA_integer_
  i
}

bin_counts <- function(m) {
  stats::setNames(as.integer(colSums(bin_membership(m))), bin_names())
}
