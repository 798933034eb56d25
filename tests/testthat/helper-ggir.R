# GGIR 3.3-9's g.calibrate(), g.inspectfile(), read.myacc.csv() and
# g.getstarttime() set options(warn = -1) and set it back (to 0) only when
# they get that far: one that stops in between leaves warnings switched off
# for the rest of the session, and every later expect_snapshot() then
# records no warning (evaluate drops warnings while warn < 0). A call of
# GGIR's that may stop goes through keep_warn(), which restores the
# session's `warn` whatever happens.
keep_warn <- function(expr) {
  op <- options(warn = getOption("warn"))
  on.exit(options(op), add = TRUE)
  expr
}

# Run GGIR's g.calibrate and gravcal's on the same file, quietly.
run_both <- function(file, params = list()) {
  pr <- GGIR::load_params()$params_rawdata
  pr <- utils::modifyList(pr, params)
  quiet <- function(expr) {
    out <- NULL
    keep_warn(utils::capture.output(out <- suppressWarnings(expr)))
    out
  }
  R <- ggir_cached("g.calibrate", file, list(params_rawdata = pr), {
    I <- quiet(GGIR::g.inspectfile(file, params_rawdata = pr))
    quiet(GGIR::g.calibrate(file, params_rawdata = pr,
                            inspectfileobject = I, verbose = FALSE))
  })
  G <- quiet(gravcal::g.calibrate(file, params_rawdata = pr, verbose = FALSE))
  list(ggir = R, gravcal = G)
}

# gravcal's result has GGIR's structure and numbers: names, classes and
# lengths of every element, spheredata's columns and rows; coefficients,
# window statistics, counts, QC message and errors identical to the bit.
expect_same_as_ggir <- function(b) {
  R <- b$ggir
  G <- b$gravcal
  expect_identical(names(G), names(R))
  for (nm in setdiff(names(R), "bsc_qc")) {
    expect_identical(class(G[[nm]]), class(R[[nm]]), label = nm)
    expect_identical(length(G[[nm]]), length(R[[nm]]), label = nm)
  }
  expect_identical(names(G$bsc_qc), names(R$bsc_qc))
  expect_identical(nrow(G$bsc_qc), nrow(R$bsc_qc))
  expect_identical(sapply(G$bsc_qc, class), sapply(R$bsc_qc, class))
  for (nm in c("scale", "offset", "tempoffset", "meantempcal")) {
    expect_identical(G[[nm]], R[[nm]], label = nm)
  }
  for (nm in c("npoints", "nhoursused", "QCmessage", "use.temp",
               "cal.error.start", "cal.error.end")) {
    expect_identical(G[[nm]], R[[nm]], label = nm)
  }
  if (length(R$spheredata)) {
    expect_identical(names(G$spheredata), names(R$spheredata))
    expect_identical(dim(G$spheredata), dim(R$spheredata))
    expect_identical(as.integer(rownames(G$spheredata)),
                     as.integer(rownames(R$spheredata)))
    expect_identical(unname(as.matrix(G$spheredata)), unname(as.matrix(R$spheredata)))
  }
  # and base R's identical() on the whole, every element but bsc_qc: it
  # tells NA from NaN, which testthat's third edition (waldo before 0.5)
  # takes for equal
  nm <- setdiff(names(R), "bsc_qc")
  expect_true(identical(G[nm], R[nm]), label = "identical(gravcal[-bsc_qc], GGIR[-bsc_qc])")
}

known_params <- function() {
  c(k_xx = 1.02, k_yy = 0.98, k_zz = 1.01, k_xy = 0, k_xz = 0, k_yz = 0,
    o_x = 0.03, o_y = -0.02, o_z = 0.015)
}

# An ad hoc csv (x, y, z, temperature) and the GGIR parameters to read it.
write_adhoc <- function(rec, file, sf) {
  utils::write.csv(rec[, c("x", "y", "z", "temperature")], file,
                   row.names = FALSE)
  list(rmc.firstrow.acc = 2, rmc.col.acc = 1:3, rmc.col.temp = 4,
       rmc.sf = sf, rmc.noise = 0.013 / 1.2, rmc.unit.acc = "g",
       rmc.unit.temp = "C")
}
