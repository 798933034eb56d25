# epoch_signals(): GGIR part 1's epoch signals of a calibrated recording.
# References: gravcal::g.getmeta() (itself identical to GGIR's, see
# test-ggir-getmeta.R) and the metric's definition computed here in R.

test_that("epoch_signals() of a file with g.calibrate()'s coefficients is g.getmeta()'s M", {
  skip_if_quick()
  # slow tier: 27 hours at 25 Hz written, calibrated and read twice; make
  # quick keeps epoch_signals() of samples in memory (below) and g.getmeta()'s
  # identity (test-ggir-getmeta.R)
  rec <- simulate_recording(hours = 27, sf = 25, seed = 21,
                            start = as.POSIXct("2024-05-01 10:02:11", tz = "UTC"))
  f <- tempfile(fileext = ".cwa")
  gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), f, sf = 25,
                      start = as.numeric(rec$time[1]), temperature = rec$temperature)
  C <- gravcal::g.calibrate(f, verbose = FALSE)
  ep <- epoch_signals(f, fit = C, metrics = c("ENMO", "anglez", "MAD"))
  M <- gravcal::g.getmeta(f, offset = C$offset, scale = C$scale, tempoffset = C$tempoffset,
                          meantempcal = C$meantempcal, do.mad = TRUE, verbose = FALSE)
  expect_s3_class(ep, "gravcal_epochs")
  for (m in c("ENMO", "anglez", "MAD")) expect_identical(ep$short[[m]], M$metashort[[m]])
  for (m in names(M$metalong)[-1]) expect_identical(ep$long[[m]], M$metalong[[m]])
  expect_identical(format(ep$short$time, "%Y-%m-%dT%H:%M:%S%z"), M$metashort$timestamp)
  expect_identical(format(ep$short$time[1]), "2024-05-01 10:15:00")
  expect_output(print(ep), "epochs of 5 s")
})

test_that("epoch_signals() of samples in memory: ENMO by its definition, a fit's model applied", {
  rec <- simulate_recording(hours = 3, sf = 10, seed = 22,
                            start = as.POSIXct("2024-01-01 00:00:00", tz = "UTC"))
  ep <- epoch_signals(rec, metrics = c("ENMO", "EN"))
  # GGIR's ENMO: the mean of max(|a| - 1, 0) over 5 s (50 samples), to 4 decimals
  enmo <- pmax(sqrt(rec$x^2 + rec$y^2 + rec$z^2) - 1, 0)
  ref <- round(colMeans(matrix(enmo, nrow = 50)), 4)
  # (the cumulative sum's rounding may move a value across a rounding edge
  # of the 4th decimal, by one unit there)
  d <- abs(ep$short$ENMO - ref[seq_len(nrow(ep$short))])
  expect_lte(max(d), 1e-4 + 1e-12)
  expect_gt(mean(d == 0), 0.99)
  expect_identical(nrow(ep$short), 3L * 720L)
  expect_identical(nrow(ep$long), 12L)
  # a lightweight fit with cross-axis terms: its model, as apply_calibration() applies it
  fit <- calibrate(rec, sf = 10)
  a <- epoch_signals(rec, fit = fit, metrics = "ENMO")
  b <- epoch_signals(apply_calibration(rec, fit), metrics = "ENMO")
  expect_identical(a$short, b$short)
  expect_false(identical(a$short$ENMO, ep$short$ENMO))
  # a lightweight fit without cross-axis terms but with a temperature term:
  # that term applied too
  rt <- simulate_recording(hours = 30, sf = 10, seed = 25,
                           params = c(1.02, 0.98, 1.01, 0, 0, 0, 0.03, -0.02, 0.01),
                           tempoffset = c(0.002, -0.001, 0.0015),
                           start = as.POSIXct("2024-01-01 00:00:00", tz = "UTC"))
  ft <- calibrate(rt, sf = 10, model = "scale_offset")
  expect_true(all(ft$tempoffset != 0))
  expect_identical(epoch_signals(rt, fit = ft, metrics = "ENMO")$short,
                   epoch_signals(apply_calibration(rt, ft), metrics = "ENMO")$short)
  p <- tempfile(fileext = ".png")
  grDevices::png(p)
  expect_invisible(plot(a))
  grDevices::dev.off()
  expect_true(file.size(p) > 0)
})

test_that("epoch_signals() says what is wrong with its arguments", {
  rec <- simulate_recording(hours = 3, sf = 10, seed = 23)
  expect_error(epoch_signals(rec, metrics = "ENMOX"), "unknown \"ENMOX\"")
  xyz <- rec[, c("x", "y", "z")]
  expect_error(epoch_signals(xyz, sf = 10), "give `start`")
  expect_error(epoch_signals(rec, tz = 3), "`tz`")
  short <- simulate_recording(hours = 1, sf = 10, seed = 24)
  expect_error(epoch_signals(short), "too short")
})

test_that("g.getmeta() gives the same M on one thread and on two; options(gravcal.threads) is checked", {
  # the running medians of the angles are made on a second thread beside
  # the other signals (ggir_epochs.hpp short_metrics()): every sum whole on
  # one thread, so M may not depend on the threads. 8 hours at 50 Hz in
  # blocks of about 2 hours (chunksize 0.1), the medians' metrics, a
  # filtered one and MAD beside ENMO
  rec <- simulate_recording(hours = 8, sf = 50, seed = 31,
                            start = as.POSIXct("2024-03-04 09:00:00", tz = "UTC"))
  f <- tempfile(fileext = ".cwa")
  on.exit(unlink(f), add = TRUE)
  gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), f, sf = 50,
                      start = as.numeric(rec$time[1]), temperature = rec$temperature)
  meta <- function(threads) {
    old <- options(gravcal.threads = threads)
    on.exit(options(old))
    # (each of GGIR's groups of three axes whole: GGIR stops on a part of one)
    gravcal::g.getmeta(f, chunksize = 0.1, do.anglex = TRUE, do.angley = TRUE,
                       do.roll_med_acc_x = TRUE, do.roll_med_acc_y = TRUE,
                       do.roll_med_acc_z = TRUE, do.dev_roll_med_acc_x = TRUE,
                       do.dev_roll_med_acc_y = TRUE, do.dev_roll_med_acc_z = TRUE, do.mad = TRUE,
                       do.bfen = TRUE, desiredtz = "UTC", verbose = FALSE)
  }
  one <- meta(1)
  two <- meta(2)
  expect_gt(nrow(one$metashort), 5000)
  expect_true(all(c("anglex", "angley", "anglez", "roll_med_acc_y", "dev_roll_med_acc_z",
                    "MAD", "BFEN", "ENMO") %in% names(one$metashort)))
  expect_gt(stats::sd(one$metashort$anglez), 1)  # angles that move
  # (all but bsc_qc, which has the time of the run, as in the comparisons with GGIR)
  for (k in setdiff(names(one), "bsc_qc")) expect_identical(two[[k]], one[[k]], label = k)
  expect_identical(meta(5)$metashort, one$metashort)  # (more counts as 2)
  # without filters or MAD, the first thread makes the last part of z's
  # medians and the second the rest (short_metrics()'s share): the same M
  shared <- function(threads) {
    old <- options(gravcal.threads = threads)
    on.exit(options(old))
    gravcal::g.getmeta(f, chunksize = 0.1, do.anglex = TRUE, do.roll_med_acc_x = TRUE,
                       do.roll_med_acc_y = TRUE, do.roll_med_acc_z = TRUE,
                       do.dev_roll_med_acc_x = TRUE, do.dev_roll_med_acc_y = TRUE,
                       do.dev_roll_med_acc_z = TRUE, desiredtz = "UTC", verbose = FALSE)
  }
  s1 <- shared(1)
  s2 <- shared(2)
  expect_true(all(c("anglex", "anglez", "roll_med_acc_z", "dev_roll_med_acc_x") %in% names(s1$metashort)))
  expect_identical(s1$metashort$anglez, one$metashort$anglez)
  for (k in setdiff(names(s1), "bsc_qc")) expect_identical(s2[[k]], s1[[k]], label = k)
  old <- options(gravcal.threads = 0)
  on.exit(options(old), add = TRUE)
  expect_error(gravcal::g.getmeta(f, verbose = FALSE), "options\\(gravcal.threads\\)` must be a whole number >= 1")
})
