# GENEActiv's csv export (R/geneactiv-csv.R), written by write_geneactiv_csv()
# (R/write-csv.R): GGIR 3.3-9 refuses it (g.inspectfile() stops), and so
# does gravcal where GGIR's result is asked for; GGIR's advice, its rmc.*
# parameters, gives GGIR's result to the bit; gravcal's own verbs read it
# as it is.

geneactiv_csv_rec <- function(hours, sf, seed) {
  simulate_recording(hours = hours, sf = sf, seed = seed,
                     tempoffset = c(0.002, -0.001, 0.0015))
}

test_that("a GENEActiv csv export is read as it is, its rate from the header", {
  rec <- geneactiv_csv_rec(0.5, 10, 71)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  gravcal:::write_geneactiv_csv(rec, f, sf = 10)
  expect_true(gravcal:::is_geneactiv_csv(f))
  expect_identical(gravcal:::file_format(f), "geneactiv_csv")
  p <- gravcal:::geneactiv_csv_rmc(f)
  expect_identical(p$rmc.firstrow.acc, 101L)
  expect_identical(p$rmc.sf, 10)
  r <- read_recording(f)
  expect_identical(r$sf, 10)
  expect_identical(nrow(r$data), nrow(rec))
  # the numbers as written (4 decimals; temperature 1)
  expect_identical(r$data$x, as.numeric(sprintf("%.4f", rec$x)))
  expect_identical(r$data$z, as.numeric(sprintf("%.4f", rec$z)))
  expect_identical(r$data$temperature, as.numeric(sprintf("%.1f", rec$temperature)))
  # other csv files are not taken for one
  g <- tempfile(fileext = ".csv")
  on.exit(unlink(g), add = TRUE)
  utils::write.csv(data.frame(x = 1:3, y = 1:3, z = 1:3), g, row.names = FALSE)
  expect_false(gravcal:::is_geneactiv_csv(g))
  # a header without a rate, and one without sample lines: errors naming the file
  lines <- readLines(f)
  h <- tempfile(fileext = ".csv")
  on.exit(unlink(h), add = TRUE)
  writeLines(lines[!grepl("^Measurement Frequency", lines)], h)
  expect_error(read_recording(h), "gives no rate", fixed = TRUE)
  writeLines(lines[1:100], h)
  expect_error(read_recording(h), "without sample lines", fixed = TRUE)
})

test_that("g.calibrate() refuses a GENEActiv csv export as GGIR does, and GGIR's advice gives GGIR's result", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  rec <- geneactiv_csv_rec(30, 10, 72)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  gravcal:::write_geneactiv_csv(rec, f, sf = 10)
  # GGIR detects the written file as a GENEActiv csv export, and stops
  expect_error(keep_warn(suppressWarnings(GGIR::g.inspectfile(f))), "GENEActiv csv reading functionality is deprecated",
               fixed = TRUE)
  expect_error(g.calibrate(f, verbose = FALSE),
               "is a GENEActiv csv export, which GGIR does not read", fixed = TRUE)
  expect_error(calibrate(f, method = "ggir", ggir_compat = TRUE),
               "is a GENEActiv csv export, which GGIR does not read", fixed = TRUE)
  # the parameters the message names read it as GGIR's read.myacc.csv does
  msg <- tryCatch(g.calibrate(f, verbose = FALSE), error = conditionMessage)
  expect_match(msg, "rmc.firstrow.acc = 101L, rmc.col.acc = 2:4", fixed = TRUE)
  b <- run_both(f, gravcal:::geneactiv_csv_rmc(f))
  expect_same_as_ggir(b)
  expect_gt(b$ggir$npoints, 50)
  # gravcal's own method reads it as it is
  fit <- calibrate(f)
  expect_s3_class(fit, "gravcal_fit")
  expect_identical(fit$input$format, "geneactiv_csv")
  expect_identical(read_recording(f)$input$format, "geneactiv_csv")
})
