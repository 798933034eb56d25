# The GGIR reference cache's own rules (helper-ggir-cache.R): which stored
# entries a run recomputes, and what a computation leaves beside its entry.

test_that("a run recomputes one key in 16 unless its GGIR call is known to be slow", {
  dir <- tempfile("cache")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE), add = TRUE)
  old <- Sys.getenv("GRAVCAL_GGIR_VERIFY_SECONDS", unset = NA)
  on.exit(if (is.na(old)) Sys.unsetenv("GRAVCAL_GGIR_VERIFY_SECONDS") else
    Sys.setenv(GRAVCAL_GGIR_VERIFY_SECONDS = old), add = TRUE)
  Sys.unsetenv("GRAVCAL_GGIR_VERIFY_SECONDS")
  note <- function(key, s) writeLines(s, file.path(dir, paste0(key, ".seconds")))
  note("0fast", "3.5")
  note("0slow", "85.0")
  note("1fast", "1.0")
  note("0bad", "not a number")
  expect_true(ggir_cache_spot_check(dir, "0fast"))
  expect_false(ggir_cache_spot_check(dir, "0slow"))
  expect_true(ggir_cache_spot_check(dir, "0unknown"))   # no time recorded
  expect_true(ggir_cache_spot_check(dir, "0bad"))
  expect_false(ggir_cache_spot_check(dir, "1fast"))     # not in the sixteenth
  Sys.setenv(GRAVCAL_GGIR_VERIFY_SECONDS = "100")
  expect_true(ggir_cache_spot_check(dir, "0slow"))
  Sys.setenv(GRAVCAL_GGIR_VERIFY_SECONDS = "2")
  expect_false(ggir_cache_spot_check(dir, "0fast"))
  Sys.setenv(GRAVCAL_GGIR_VERIFY_SECONDS = "twenty")
  expect_error(ggir_cache_spot_check(dir, "0fast"), "GRAVCAL_GGIR_VERIFY_SECONDS must be a number")
})

test_that("a computation leaves its CPU seconds beside the entry; an error leaves none", {
  dir <- tempfile("cache")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE), add = TRUE)
  v <- ggir_cache_timed(dir, "0abc", {
    x <- 0
    for (i in seq_len(2e6)) x <- x + i
    x
  })
  expect_identical(v, sum(as.numeric(seq_len(2e6))))
  s <- ggir_cache_seconds(dir, "0abc")
  expect_true(is.finite(s) && s >= 0)
  expect_identical(list.files(dir), "0abc.seconds")
  e <- ggir_cache_timed(dir, "0err", simpleError("GGIR stopped"))
  expect_s3_class(e, "error")
  expect_true(is.na(ggir_cache_seconds(dir, "0err")))
})
