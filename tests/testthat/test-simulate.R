test_that("distort() is the exact inverse of the model (paper Eq. 7-9)", {
  set.seed(11)
  p <- random_params()
  a <- matrix(rnorm(300), ncol = 3)
  v <- distort(a, p)
  fit <- gravcal:::new_fit(K = gravcal:::params_to_K(p), offset = p[7:9],
                           method = "lightweight")
  back <- gravcal:::calibrate_points(fit, v)
  expect_equal(back, a, tolerance = 1e-12)
  # written out from Eq. 7-9 independently of the package
  u <- sweep(v, 2, p[7:9], `+`)
  ax <- p[["k_xx"]] * u[, 1]
  ay <- p[["k_xy"]] * u[, 1] + p[["k_yy"]] * u[, 2]
  az <- p[["k_xz"]] * u[, 1] + p[["k_yz"]] * u[, 2] + p[["k_zz"]] * u[, 3]
  expect_equal(cbind(ax, ay, az), a, tolerance = 1e-12, ignore_attr = TRUE)
})

test_that("the paper's Eq. 19 as printed is not the inverse (sign slips)", {
  p <- c(1.05, 0.95, 1.02, 0.03, -0.04, 0.02, 0.08, -0.06, 0.05)
  a <- c(0.3, 0.5, sqrt(1 - 0.34))
  cx <- a[1] / p[1] - p[7]
  cy_paper <- (a[2] - (cx - p[7]) * p[4]) / p[2] - p[8]
  cy_right <- distort(matrix(a, 1), p)[2]
  expect_false(isTRUE(all.equal(cy_paper, cy_right)))
})

test_that("random_params() draws in the paper's ranges (Eq. 17-18)", {
  set.seed(3)
  P <- t(replicate(2000, random_params()))
  expect_true(all(P[, 1:3] > 0.9 & P[, 1:3] < 1.1))
  expect_true(all(abs(P[, 7:9]) < 0.1))
  # k_xy = S_y T_xy, with |T| < 0.05
  expect_true(all(abs(P[, "k_xy"] / P[, "k_yy"]) < 0.05))
  expect_true(all(abs(P[, "k_yz"] / P[, "k_zz"]) < 0.05))
  expect_equal(colnames(P), param_names())
})

test_that("simulate_points() gives unit vectors distorted with noise", {
  set.seed(4)
  p <- random_params()
  s0 <- simulate_points(200, noise = 0, params = p)
  fit <- gravcal:::new_fit(K = gravcal:::params_to_K(p), offset = p[7:9],
                           method = "lightweight")
  a <- gravcal:::calibrate_points(fit, as.matrix(s0))
  expect_equal(sqrt(rowSums(a^2)), rep(1, 200), tolerance = 1e-12)
  s5 <- simulate_points(5000, noise = 0.005, params = p)
  a5 <- gravcal:::calibrate_points(fit, as.matrix(s5))
  expect_equal(sd(sqrt(rowSums(a5^2)) - 1), 0.005, tolerance = 0.1)
  expect_identical(attr(s5, "params"), stats::setNames(p, param_names()))
  expect_error(simulate_points(10, params = 1:3), "`params` must be 9")
})

test_that("simulate_recording() is reproducible and leaves the RNG alone", {
  set.seed(99)
  before <- .Random.seed
  r1 <- simulate_recording(hours = 0.2, sf = 10, seed = 5)
  expect_identical(.Random.seed, before)
  r2 <- simulate_recording(hours = 0.2, sf = 10, seed = 5)
  expect_identical(r1, r2)
  expect_equal(nrow(r1), 0.2 * 3600 * 10)
  expect_named(r1, c("time", "x", "y", "z", "temperature"))
  tr <- attr(r1, "truth")
  expect_equal(tr$sf, 10)
  expect_length(tr$params, 9)
  expect_error(simulate_recording(hours = -1), "`hours` must be")
  expect_error(simulate_recording(hours = 1, temperature = FALSE,
                                  tempoffset = c(0.001, 0, 0)),
               "`tempoffset` needs")
})

test_that("simulators: out-of-range or non-numeric arguments are named", {
  p <- c(1.05, 0.97, 1.02, 0.01, -0.02, 0.03, 0.05, -0.03, 0.02)
  expect_snapshot(error = TRUE, random_params(scale = -1))
  expect_snapshot(error = TRUE, random_params(scale = 1))
  expect_snapshot(error = TRUE, random_params(scale = "a"))
  expect_snapshot(error = TRUE, random_params(misalignment = NA))
  expect_snapshot(error = TRUE, random_params(offset = Inf))
  expect_snapshot(error = TRUE, random_params(scale = 1:3))
  expect_snapshot(error = TRUE, distort("a", p))
  expect_snapshot(error = TRUE, distort(matrix(1:4, 2), p))
  expect_snapshot(error = TRUE, distort(matrix(c(1, NA, Inf), 1), p))
  expect_snapshot(error = TRUE, distort(diag(3), rep("a", 9)))
  expect_snapshot(error = TRUE, distort(diag(3), c(0, p[-1])))
  expect_snapshot(error = TRUE, distort(diag(3), 1:3))
  expect_snapshot(error = TRUE, simulate_points("a"))
  expect_snapshot(error = TRUE, simulate_points(1e12))
  expect_snapshot(error = TRUE, simulate_recording(hours = "3"))
  expect_snapshot(error = TRUE, simulate_recording(hours = 1, sf = -1))
  expect_snapshot(error = TRUE, simulate_recording(hours = 1, noise = NA))
  expect_snapshot(error = TRUE, simulate_recording(hours = 1, rest_fraction = 2))
  expect_snapshot(error = TRUE, simulate_recording(hours = 1, params = rep("a", 9)))
  expect_snapshot(error = TRUE, simulate_recording(hours = 1, start = "x"))
  expect_snapshot(error = TRUE, simulate_recording(hours = 1e9))
  # a data frame or a single vector of three is a matrix of true vectors
  expect_equal(distort(data.frame(x = 1, y = 0, z = 0), p), distort(diag(3)[1, , drop = FALSE], p))
  expect_equal(distort(c(0, 0, 1), p), distort(diag(3)[3, , drop = FALSE], p))
})
