pt <- function(...) {
  m <- rbind(...)
  data.frame(mean_x = m[, 1], mean_y = m[, 2], mean_z = m[, 3])
}

test_that("bins follow the paper's intervals (Eq. 10)", {
  expect_equal(bin_names(), c("x-", "x0", "x+", "y-", "y0", "y+", "z-",
                              "z0", "z+"))
  p <- pt(c(0, 0, 1), c(0, 0, 0.75), c(0, 0, 1.25), c(0, 0, 1.26),
          c(0, 0, 0.74), c(0.5, 0.5, 0.5))
  s <- select_points(p, per_bin = 5, min_distance = 0)
  # 1.26, 0.74 (z) lie in x0 and y0 only (tie: x0); (0.5, 0.5, 0.5) in none
  expect_equal(as.character(s$bin), c("z+", "z+", "z+", "x0", "x0"))
  expect_equal(s$row, 1:5)
})

test_that("a point counts for its pole bin first, else the nearest zero bin", {
  # (0.2, 0, 0.95) lies in x0, y0 and z+ -> z+
  # (0.2, 0.05, 0.6) lies in x0 (|x| = 0.2) and y0 (|y| = 0.05) -> y0
  p <- pt(c(0.2, 0, 0.95), c(0.2, 0.05, 0.6))
  s <- select_points(p, per_bin = 2, min_distance = 0)
  expect_equal(as.character(s$bin), c("z+", "y0"))
  # when the pole bin is full, the nearest open zero bin takes the point
  p2 <- pt(c(0, 0, 1), c(0, 0.01, 0.99), c(0.02, 0, 1), c(0.01, 0, 1))
  s2 <- select_points(p2, per_bin = 2, min_distance = 0)
  expect_equal(as.character(s2$bin), c("z+", "z+", "y0", "y0"))
})

test_that("the novelty threshold rejects points too close to kept ones", {
  p <- pt(c(0, 0, 1), c(0, 0.05, 1), c(0, 0.11, 0.99))
  s <- select_points(p, min_distance = 0.1)
  expect_equal(s$row, c(1L, 3L))
  expect_equal(nrow(select_points(p, min_distance = 0)), 3)
})

test_that("selection stops when bins are full; complete needs every minimum", {
  set.seed(8)
  cand <- simulate_points(2000, noise = 0.001)
  s <- select_points(cand)
  expect_equal(nrow(s), 18)
  expect_true(attr(s, "complete"))
  expect_equal(unname(attr(s, "counts")), rep(2L, 9))
  expect_equal(as.vector(table(s$bin)), rep(2L, 9))
  # kept points are at least min_distance apart
  d <- as.matrix(dist(s[c("mean_x", "mean_y", "mean_z")]))
  expect_true(min(d[upper.tri(d)]) >= 0.3)
  s3 <- select_points(cand, per_bin = 3, min_per_bin = 1)
  expect_equal(nrow(s3), 27)
  few <- select_points(pt(c(0, 0, 1), c(0, 0, -1), c(1, 0, 0)))
  expect_false(attr(few, "complete"))
  expect_match(gravcal:::missing_bins(few), "x- \\(0 of 2\\)")
})

test_that("only rest windows with finite means are offered", {
  p <- pt(c(0, 0, 1), c(0, 0, -1), c(NA, 0, 1))
  p$rest <- c(FALSE, TRUE, TRUE)
  s <- select_points(p)
  expect_equal(s$row, 2L)
  p$rest <- c("yes", "no", "no")
  expect_error(select_points(p), "`rest` of `w` must be logical")
})

test_that("bad arguments are named", {
  p <- pt(c(0, 0, 1))
  expect_error(select_points(p, per_bin = 0), "`per_bin` must be a whole")
  expect_error(select_points(p, per_bin = 2, min_per_bin = 3),
               "`min_per_bin` must be a whole number in \\[1, 2\\]")
  expect_error(select_points(p, min_distance = -1), "`min_distance`")
  expect_error(select_points(data.frame(a = 1)), "missing: mean_x")
  expect_error(select_points("x"), "must be a data frame of windows")
})

test_that("several thresholds top up the bins and keep the first pass's points", {
  set.seed(46)
  # postures clustered around the six poles, 0.12 g apart within a cluster:
  # 0.3 g fills one point per bin at most where a cluster is the only source
  poles <- rbind(diag(3), -diag(3))
  post <- do.call(rbind, lapply(1:6, function(i) {
    e <- poles[i, ]
    o <- diag(3)[-which(e != 0), ]
    rbind(e + 0.12 * o[1, ], e - 0.12 * o[1, ], e + 0.12 * o[2, ])
  }))
  post <- post / sqrt(rowSums(post^2))
  w <- data.frame(mean_x = post[, 1], mean_y = post[, 2], mean_z = post[, 3])
  w <- w[sample(nrow(w)), ]
  one <- select_points(w, min_distance = 0.3)
  expect_false(attr(one, "complete"))
  two <- select_points(w, min_distance = c(0.3, 0.1))
  expect_true(attr(two, "complete"))
  expect_identical(attr(two, "min_distance"), c(0.3, 0.1))
  # the first pass's points are all still there, in the same bins
  m <- match(one$row, two$row)
  expect_false(anyNA(m))
  expect_identical(as.character(two$bin[m]), as.character(one$bin))
  # a complete first pass makes no second pass
  cand <- simulate_points(500, noise = 0.001)
  a <- select_points(cand)
  b <- select_points(cand, min_distance = c(0.3, 0.1, 0.03))
  expect_true(attr(a, "complete"))
  expect_identical(b$row, a$row)
  expect_identical(attr(b, "min_distance"), 0.3)
  expect_error(select_points(cand, min_distance = c(0.1, 0.3)), "decreasing order")
  expect_error(select_points(cand, min_distance = -1), "non-negative")
  expect_error(select_points(cand, min_distance = NA), "`min_distance`")
})

test_that("select_points() in a device's arithmetic rounds as the device does", {
  # x = 0.75 - 1e-6 is outside [0.75, 1.25] in double, but rounds to 0.75 in
  # Q1.14 (resolution 6.1e-5) and in Q3.29 stays below it
  w <- data.frame(mean_x = 0.75 - 1e-6, mean_y = 0.5, mean_z = 0.5)
  expect_identical(nrow(select_points(w)), 0L)
  expect_identical(nrow(select_points(w, arithmetic = "fixed32")), 0L)
  p16 <- select_points(w, arithmetic = "fixed16")
  expect_identical(as.character(p16$bin), "x+")
  set.seed(5)
  cand <- simulate_points(500, noise = 0.002)
  expect_identical(select_points(cand, arithmetic = "fixed32")$row,
                   select_points(cand)$row)
  expect_error(select_points(cand, arithmetic = "int8"), "`arithmetic` must be one of")
})

test_that("cells: numeric cube keys pick what text keys pick, and far means still work", {
  # an independent reference: one key per cube as text, the stillest window
  # of each (ties to the earlier), in time order
  ref_cells <- function(w, cell) {
    k <- paste(round(w$mean_x / cell), round(w$mean_y / cell), round(w$mean_z / cell))
    s <- pmax(w$range_x, w$range_y, w$range_z)
    keep <- vapply(seq_along(k), function(i) {
      same <- which(k == k[i])
      best <- same[s[same] == min(s[same])]
      i == best[1]
    }, logical(1))
    which(keep)
  }
  set.seed(3)
  n <- 400
  u <- matrix(stats::rnorm(3 * n), n)
  u <- u / sqrt(rowSums(u^2))
  w <- data.frame(mean_x = u[, 1], mean_y = u[, 2], mean_z = u[, 3],
                  range_x = stats::runif(n, 0, 0.01), range_y = stats::runif(n, 0, 0.01),
                  range_z = round(stats::runif(n, 0, 0.01), 3), rest = TRUE)
  for (cell in c(0.05, 0.2, 0.5)) {
    expect_identical(select_points(w, selection = "cells", cell = cell)$row,
                     ref_cells(w, cell))
  }
  # a mean beyond the numeric keys' reach (3000 g) falls back to text keys
  far <- w
  far$mean_x[1:3] <- c(5000, 5000, -7000)
  expect_identical(select_points(far, selection = "cells", cell = 0.05)$row,
                   ref_cells(far, 0.05))
})
