test_that("noise-free points give back the true parameters to 1e-6", {
  set.seed(31)
  for (i in 1:5) {
    cand <- simulate_points(1000, noise = 0)
    pts <- select_points(cand)
    # the forward difference biases the optimum by about h: the paper's
    # h = 1e-5 stops ~1e-5 from the truth, h = 1e-9 well within 1e-6
    coarse <- fit_gradient(pts, max_iter = 20000, tol = 1e-13)
    expect_gt(max(abs(coarse$params - attr(cand, "params"))), 1e-6)
    expect_lt(max(abs(coarse$params - attr(cand, "params"))), 1e-4)
    fit <- fit_gradient(pts, max_iter = 20000, tol = 1e-13, h = 1e-9)
    expect_equal(fit$status, "ok")
    expect_lt(max(abs(fit$params - attr(cand, "params"))), 1e-6)
    expect_true(fit$converged)
    expect_lt(fit$iterations, 20000)
  }
})

test_that("with the paper's settings (18 points, 50 iterations) the error falls", {
  set.seed(32)
  cand <- simulate_points(1000, noise = 0.001)
  fit <- fit_gradient(select_points(cand), trace = TRUE)
  expect_equal(fit$iterations, 50L)
  expect_equal(nrow(fit$trace), 50)
  expect_equal(colnames(fit$trace), c("iteration", param_names(), "f"))
  # the objective falls from the start and settles
  f <- fit$trace[, "f"]
  expect_lt(f[50], f[1] / 100)
  expect_lt(fit$error_after, fit$error_before / 10)
  # within a few mg of the truth on every parameter (1 mg noise)
  expect_lt(max(abs(fit$params - attr(cand, "params"))), 0.01)
  expect_equal(unname(fit$K[upper.tri(fit$K)]), c(0, 0, 0))
  expect_equal(unname(coef(fit)[1:9]), unname(fit$params))
})

test_that("the plain sum with the paper's rates diverges; the status says so", {
  set.seed(33)
  pts <- select_points(simulate_points(1000, noise = 0.001))
  fit <- fit_gradient(pts, objective = "sum")
  expect_equal(fit$status, "diverged")
  expect_equal(unname(fit$params), c(1, 1, 1, 0, 0, 0, 0, 0, 0))
  expect_match(fit$message, "diverged")
})

test_that("float arithmetic agrees with double to single precision", {
  set.seed(34)
  cand <- simulate_points(1000, noise = 0.001)
  pts <- select_points(cand)
  fd <- fit_gradient(pts)
  ff <- fit_gradient(pts, arithmetic = "float")
  expect_equal(ff$status, "ok")
  expect_lt(max(abs(ff$params - fd$params)), 2e-3)
  expect_false(identical(ff$params, fd$params))
})

test_that("points may be a matrix or x/y/z columns; bad input is named", {
  set.seed(35)
  pts <- select_points(simulate_points(1000, noise = 0.001))
  m <- as.matrix(pts[c("mean_x", "mean_y", "mean_z")])
  expect_equal(fit_gradient(unname(m))$params, fit_gradient(pts)$params)
  xyz <- data.frame(x = pts$mean_x, y = pts$mean_y, z = pts$mean_z)
  expect_equal(fit_gradient(xyz)$params, fit_gradient(pts)$params)
  expect_error(fit_gradient(pts[1:8, ]), "at least 9 points")
  bad <- pts
  bad$mean_x[2] <- NA
  expect_error(fit_gradient(bad), "must not contain NA")
  expect_error(fit_gradient(pts, max_iter = 0), "`max_iter`")
  expect_error(fit_gradient(pts, rates = c(1, 2)), "`rates` must be 3")
  expect_error(fit_gradient(pts, h = 0), "`h` must be")
  expect_error(fit_gradient(pts, arithmetic = "fixed8"), "should be one of")
})
