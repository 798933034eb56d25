test_that("fit_ellipsoid() recovers the model exactly from noise-free points", {
  set.seed(11)
  for (i in 1:5) {
    p <- random_params()
    cand <- simulate_points(200, noise = 0, params = p)
    fit <- fit_ellipsoid(cand)
    expect_identical(fit$status, "ok")
    expect_identical(fit$method, "ellipsoid")
    # exact up to rounding: the quadric through noise-free points is exact
    expect_equal(unname(fit$params), unname(p), tolerance = 1e-9)
    expect_true(all(fit$K[upper.tri(fit$K)] == 0))
  }
})

test_that("fit_ellipsoid() on noisy points is close to the least-squares fit", {
  set.seed(12)
  cand <- simulate_points(1000, noise = 0.002)
  pts <- select_points(cand)
  fe <- fit_ellipsoid(pts)
  fg <- fit_gradient(pts, max_iter = 5000, tol = 1e-12)
  # both calibrate the 18 points to within a few mg of the sphere
  expect_lt(fe$error_after, 0.004)
  expect_lt(fg$error_after, fe$error_after + 1e-4)
  expect_lt(max(abs(fe$params - attr(cand, "params"))), 0.02)
})

test_that("fit_ellipsoid() says when the points determine no ellipsoid", {
  expect_error(fit_ellipsoid(simulate_points(8)), "at least 9 points")
  # all points in one plane: the quadric is degenerate
  flat <- data.frame(mean_x = cos(1:20), mean_y = sin(1:20), mean_z = 0)
  f <- fit_ellipsoid(flat)
  expect_identical(f$status, "diverged")
  expect_identical(unname(f$params), c(1, 1, 1, 0, 0, 0, 0, 0, 0))
  expect_error(fit_ellipsoid(data.frame(mean_x = c(NA, 1:9), mean_y = 1, mean_z = 1)),
               "NA, NaN or Inf")
})
