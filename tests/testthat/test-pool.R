# Pooling a device's recordings (issue 20, item 2).

# Samples of a device (parameters p) resting in `n_post` postures held
# `hold` s each, directions drawn within `cap` radians of `center` (or all
# directions when center is NULL), at sf Hz, noise 4 mg per axis.
device_rest <- function(p, n_post, center = NULL, cap = 0.35, hold = 60,
                        sf = 25, seed = 1) {
  set.seed(seed)
  u <- gravcal:::random_unit_vectors(60 * n_post)
  if (!is.null(center)) {
    center <- center / sqrt(sum(center^2))
    u <- u[acos(pmin(1, u %*% center)) <= cap, , drop = FALSE]
  }
  u <- u[seq_len(n_post), , drop = FALSE]
  v <- distort(u, p)
  v <- v[rep(seq_len(n_post), each = hold * sf), ]
  v + matrix(stats::rnorm(length(v), sd = 0.004), ncol = 3)
}

test_that("recordings too narrow to calibrate alone are calibrated pooled by device", {
  p <- c(1.03, 0.97, 1.02, 0.02, -0.015, 0.01, 0.04, -0.03, 0.02)
  dir <- tempfile("pool")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  centers <- list(c(1, 0, 0), c(-1, 0, 0), c(0, 1, 0), c(0, -1, 0),
                  c(0, 0, 1), c(0, 0, -1))
  # six 6-hour recordings of device 1234, each resting near one face
  for (k in seq_along(centers)) {
    v <- device_rest(p, 360, centers[[k]], seed = k)
    gravcal:::write_cwa(v, file.path(dir, sprintf("a%d.cwa", k)), sf = 25,
                        packed = FALSE, device_id = 1234)
  }
  # another device (5678) with one short recording only
  gravcal:::write_cwa(device_rest(p, 360, c(0, 0, 1), seed = 9),
                      file.path(dir, "b1.cwa"), sf = 25, packed = FALSE,
                      device_id = 5678)
  alone <- calibrate_files(dir, method = "lightweight",
                           outdir = file.path(dir, "alone"))
  expect_identical(alone$serial, c(rep("1234", 6), "5678"))
  expect_true(all(alone$status %in% gravcal:::poolable_status))
  expect_false(any(alone$pooled))
  res <- calibrate_files(dir, method = "lightweight",
                         outdir = file.path(dir, "pooled"), pool = "device")
  a <- res[res$serial == "1234", ]
  expect_true(all(a$pooled))
  expect_true(all(a$status == "ok"))
  expect_match(a$message[1], "rest windows of 6 recordings of device 1234")
  expect_match(a$message[1], "alone: ")
  # one device alone is not pooled, and says why
  b <- res[res$serial == "5678", ]
  expect_false(b$pooled)
  expect_match(b$message, "not pooled: no other recording of device 5678")
  # the pooled fit against one on a long recording of the same device
  long <- file.path(dir, "long.cwa")
  gravcal:::write_cwa(device_rest(p, 720, NULL, seed = 20), long, sf = 25,
                      packed = FALSE, device_id = 1234)
  fl <- calibrate(long)
  expect_identical(fl$status, "ok")
  fp <- attr(res, "fits")[["a1.cwa"]]
  expect_identical(fp$pooled$serial, "1234")
  set.seed(2)
  u <- gravcal:::random_unit_vectors(2000)
  map_mg <- function(fit) {
    a <- gravcal:::calibrate_points(fit, distort(u, p))
    1000 * mean(sqrt(rowSums((a - u)^2)))
  }
  expect_lt(abs(map_mg(fp) - map_mg(fl)), 1)
  expect_lt(map_mg(fp), 2)
  expect_identical(unname(unlist(a[1, c("offset.x", "offset.y", "offset.z")])),
                   unname(fp$offset))
  expect_error(calibrate_files(dir, outdir = file.path(dir, "x"), pool = "all"),
               "`pool` must be one of")
  # the GGIR method pools GGIR's rest windows the same way
  unlink(long)
  gg <- calibrate_files(dir, method = "ggir", outdir = file.path(dir, "ggir"),
                        pool = "device")
  g <- gg[gg$serial == "1234", ]
  expect_true(all(g$pooled))
  expect_true(all(g$status %in% c("ok", "high_error")))
  expect_match(g$message[1], "alone: sphere_not_covered")
  expect_lt(abs(g$offset.x[1] - fp$offset[["x"]]), 0.01)
})

test_that("a device whose recordings disagree is not pooled", {
  dir <- tempfile("pool2")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  p1 <- c(1.03, 0.97, 1.02, 0, 0, 0, 0.04, -0.03, 0.02)
  p2 <- c(1.03, 0.97, 1.02, 0, 0, 0, 0.09, -0.03, 0.02)
  # two recordings that calibrate alone, 50 mg apart in x offset, and a
  # narrow one: the same serial number
  gravcal:::write_cwa(device_rest(p1, 360, NULL, seed = 1),
                      file.path(dir, "c1.cwa"), sf = 25, packed = FALSE,
                      device_id = 42)
  gravcal:::write_cwa(device_rest(p2, 360, NULL, seed = 2),
                      file.path(dir, "c2.cwa"), sf = 25, packed = FALSE,
                      device_id = 42)
  gravcal:::write_cwa(device_rest(p1, 360, c(0, 0, 1), seed = 3),
                      file.path(dir, "c3.cwa"), sf = 25, packed = FALSE,
                      device_id = 42)
  res <- calibrate_files(dir, method = "lightweight",
                         outdir = file.path(dir, "out"), pool = "device")
  expect_identical(res$status[1:2], c("ok", "ok"))
  expect_false(any(res$pooled))
  expect_match(res$message[3], "not pooled: the recordings of device 42 that calibrate alone disagree")
})

# The GGIR procedure on each recording alone, with calibrate_files()'s
# settings, then fit_icp() (the method's ICP, gravcal's convergence rule) on
# the union of the rest windows it kept (spheredata): what pooling must give.
manual_ggir_pool <- function(files, sf = NULL, chunksize = 1, spherecrit = 0.3,
                             minloadcrit = 168, max_sd = 0.013) {
  sd <- lapply(files, function(f) {
    src <- gravcal:::open_source(f, sf = sf, chunksize = chunksize, compat = FALSE)
    suppressWarnings(gravcal:::ggir_run(src, compat = FALSE, spherecrit = spherecrit,
                                        minloadcrit = minloadcrit,
                                        sdcriter = max_sd)$spheredata)
  })
  fit_icp(do.call(rbind, sd))
}

faces <- list(c(1, 0, 0), c(-1, 0, 0), c(0, 1, 0), c(0, -1, 0), c(0, 0, 1),
              c(0, 0, -1))

test_that("GGIR pooling takes each recording's rest windows from GGIR's procedure, with the user's settings", {
  p <- c(1.03, 0.97, 1.02, 0.02, -0.015, 0.01, 0.04, -0.03, 0.02)
  dir <- tempfile("poolggir")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  # six recordings of one device, each resting near one face; temperature
  # varies, so that the temperature term is fitted
  files <- file.path(dir, sprintf("f%d.cwa", seq_along(faces)))
  for (k in seq_along(faces)) {
    v <- device_rest(p, 360, faces[[k]], seed = 30 + k)
    gravcal:::write_cwa(v, files[k], sf = 25, packed = FALSE, device_id = 77,
                        temperature = 20 + k + 4 * sin(seq_len(nrow(v)) / 5e4))
  }
  set <- list(spherecrit = 0.25, minloadcrit = 3, max_sd = 0.015, chunksize = 0.5)
  res <- do.call(calibrate_files, c(list(files, method = "ggir", pool = "device",
                                         outdir = file.path(dir, "out")), set))
  expect_true(all(res$pooled))
  expect_true(all(grepl("alone: sphere_not_covered", res$message)))
  fp <- attr(res, "fits")[["f1.cwa"]]
  expect_identical(fp$status, "ok")
  expect_true(fp$use_temp)
  ref <- do.call(manual_ggir_pool, c(list(files), set))
  expect_identical(coef(fp), coef(ref))
  expect_identical(fp$meantemp, ref$meantemp)
  expect_identical(nrow(fp$points), nrow(ref$points))
  expect_identical(res$offset.x, rep(unname(ref$offset[1]), 6))
  # the pooled windows must cover the sphere at the user's spherecrit:
  # without the face at -z, z reaches about -0.35 g only
  five <- calibrate_files(files[1:5], method = "ggir", pool = "device",
                          outdir = file.path(dir, "five"), spherecrit = 0.5)
  expect_false(any(five$pooled))
  expect_true(all(five$status == "sphere_not_covered"))
  expect_true(all(grepl(paste0("not pooled: pooled, the 5 recordings of device 77 ",
                               "still do not calibrate \\(sphere_not_covered\\)"),
                        five$message)))
})

test_that("GGIR pooling reads each recording at the sampling rate given", {
  p <- c(1.03, 0.97, 1.02, 0.02, -0.015, 0.01, 0, 0, 0)
  dir <- tempfile("poolsf")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE))
  # ActiGraph csv exports of one device (one serial number) whose headers
  # say 50 Hz; the samples are at 25 Hz, as `sf` says
  files <- file.path(dir, sprintf("g%d.csv", seq_along(faces)))
  for (k in seq_along(faces)) {
    gravcal:::write_actigraph_csv(device_rest(p, 180, faces[[k]], seed = 60 + k),
                                  files[k], sf = 50)
  }
  res <- calibrate_files(dir, method = "ggir", pool = "device", sf = 25,
                         outdir = file.path(dir, "out"))
  expect_true(all(res$pooled))
  fp <- attr(res, "fits")[[1]]
  ref <- manual_ggir_pool(files, sf = 25)
  expect_identical(coef(fp), coef(ref))
  # at the header's rate each recording is 1.5 hours, too short for GGIR's
  # procedure, which then keeps no rest windows: nothing to pool
  head_rate <- calibrate_files(dir, method = "ggir", pool = "device",
                               outdir = file.path(dir, "header"))
  expect_true(all(head_rate$status == "too_short"))
  expect_false(any(head_rate$pooled))
  expect_true(all(grepl("not pooled: the pooled fit failed: no recording of the device has rest windows",
                        head_rate$message)))
})
