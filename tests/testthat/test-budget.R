# The adaptive data budget (issue 20, item 3) and rest_windows(stop =).

test_that("rest_windows() stops reading when `stop` says so", {
  rec <- simulate_recording(hours = 12, sf = 10, seed = 9)
  seen <- integer(0)
  w <- rest_windows(rec, sf = 10, block_samples = 36000, stop_every = 2,
                    stop = function(w) {
                      seen <<- c(seen, nrow(w))
                      nrow(w) >= 2000
                    })
  # every 2 hours of samples (whole chunks of 1 h), until 2000 windows
  expect_identical(seen, c(1440L, 2880L))
  expect_true(attr(w, "stopped"))
  expect_identical(nrow(w), 2880L)
  expect_identical(attr(w, "samples"), 4 * 36000)
  full <- rest_windows(rec, sf = 10)
  expect_false(attr(full, "stopped"))
  expect_identical(w, structure(full[seq_len(2880), ], samples = NULL),
                   ignore_attr = TRUE)
  # from a file, block by block
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  utils::write.csv(data.frame(time = as.numeric(rec$time), rec[c("x", "y", "z")]),
                   f, row.names = FALSE)
  calls <- 0
  wf <- rest_windows(f, stop_every = 1, stop = function(w) {
    calls <<- calls + 1
    TRUE
  })
  expect_identical(calls, 1)
  expect_lte(nrow(wf), nrow(full))
  expect_error(rest_windows(rec, sf = 10, stop = TRUE), "`stop` must be NULL or a function")
  expect_error(rest_windows(rec, sf = 10, stop_every = 0), "`stop_every` must be")
})

test_that("an adaptive budget reads until the coefficients are known", {
  set.seed(5)
  p <- random_params()
  rec <- simulate_recording(hours = 96, sf = 5, params = p, seed = 5)
  fa <- calibrate(rec, sf = 5, budget = "adaptive")
  ff <- calibrate(rec, sf = 5)
  expect_identical(fa$status, "ok")
  b <- fa$budget
  expect_true(b$stopped)
  expect_equal(b$hours_total, 96)
  expect_lt(b$hours_read, 48)
  expect_equal(fa$hours, b$hours_read)
  expect_true(all(fa$se[fa$model] <= 0.001))
  # the coefficients agree with the whole recording's within their errors
  nm <- ff$model
  expect_identical(fa$model, nm)
  expect_true(all(abs(coef(fa)[nm] - coef(ff)[nm]) <= 3 * fa$se[nm]))
  expect_output(print(fa), "adaptive budget: read [0-9.]+ of 96.0 hours, stopped")
  # an unreachable target reads everything, and says so
  fu <- calibrate(rec, sf = 5, budget = "adaptive", target_se = 1e-9)
  expect_false(fu$budget$stopped)
  expect_equal(fu$budget$hours_read, 96)
  expect_identical(coef(fu), coef(ff))
  expect_output(print(fu), "the target was not reached")
  expect_identical(ff$budget$budget, "all")
  expect_error(calibrate(rec, sf = 5, budget = "half"), "`budget` must be one of")
  expect_error(calibrate(rec, sf = 5, budget = "adaptive", target_se = 0),
               "`target_se` must be")
  expect_error(calibrate(rec, sf = 5, budget = "adaptive", selection = "paper"),
               "needs the default")
})
