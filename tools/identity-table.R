# One line per recording: gravcal::g.calibrate() against GGIR::g.calibrate()
# on the R this runs in, every element but bsc_qc compared with base R's
# identical() (issue 30's platform table). GGIRread's test files and
# synthetic 30-hour recordings written by gravcal's writers.
#   Rscript tools/identity-table.R [output.md]
# Run from the package root, with gravcal, GGIR and GGIRread installed (on
# x86-64 Linux, on R without long double: make test-noLD's R, and in the
# arm64 chroot of make test-arm64).
suppressPackageStartupMessages(library(gravcal))
source(file.path("tests", "testthat", "helper-ggir-cache.R"))
source(file.path("tests", "testthat", "helper-ggir.R"))
out <- commandArgs(TRUE)[1]
tf <- function(f) system.file("testfiles", f, package = "GGIRread")
rec30 <- function(sf, seed) {
  simulate_recording(hours = 30, sf = sf, seed = seed, params = known_params(),
                     tempoffset = c(0.002, -0.001, 0.0015))
}
synth <- list(
  cwa = function() {
    r <- rec30(25, 61); f <- tempfile(fileext = ".cwa")
    gravcal:::write_cwa(as.matrix(r[, c("x", "y", "z")]), f, sf = 25, start = 1.7e9,
                        temperature = r$temperature, range = 8)
    f
  },
  # the end of daylight saving in the session's zone (desiredtz = ""):
  # readAxivity's block times jump an hour (R/zone.R)
  `cwa across a change of UTC offset (TZ Europe/Amsterdam)` = function() {
    r <- rec30(25, 68); f <- tempfile(fileext = ".cwa")
    start <- as.numeric(as.POSIXct("2023-10-28 12:00:00", tz = "UTC"))
    gravcal:::write_cwa(as.matrix(r[, c("x", "y", "z")]), f, sf = 25, start = start,
                        temperature = r$temperature, range = 8)
    list(file = f, tz = "Europe/Amsterdam")
  },
  `GENEActiv bin` = function() {
    r <- rec30(20, 62); f <- tempfile(fileext = ".bin")
    gravcal:::write_geneactiv_bin(r, f, sf = 20)
    f
  },
  gt3x = function() {
    r <- rec30(30, 63); f <- tempfile(fileext = ".gt3x")
    gravcal:::write_gt3x(as.matrix(r[, c("x", "y", "z")]), f, 30, 1600000000)
    f
  },
  `ActiGraph csv` = function() {
    r <- rec30(30, 64); f <- tempfile(fileext = ".csv")
    gravcal:::write_actigraph_csv_file(r, f, sf = 30)
    f
  },
  `ad hoc csv (g, temperature column)` = function() {
    r <- rec30(20, 65); f <- tempfile(fileext = ".csv")
    list(file = f, params = write_adhoc(r, f, 20))
  },
  Movisens = function() {
    r <- rec30(64, 67); d <- tempfile("movisens")
    gravcal:::write_movisens(r, d, sf = 64)
    file.path(d, "acc.bin")
  },
  `Parmay Matrix` = function() {
    r <- rec30(25, 66); f <- tempfile(fileext = ".BIN")
    gravcal:::write_parmay_bin(r, f, sf = 25)
    f
  })
`%||%` <- function(a, b) if (is.null(a)) b else a
ggirread <- c("ax3_testfile.cwa", "ax3_testfile_corrupt_blocks_0_13_14_142_143_144.cwa",
              "ax6_testfile.cwa", "GENEActiv_testfile.bin", "mtx_12.5Hz_acc.BIN",
              "mtx_25Hz_acc_HR.BIN", "mtx_100Hz_acc_HR_temp.BIN", "mtx_corrupted.bin")
files <- c(setNames(lapply(ggirread, tf), paste("GGIRread", ggirread)),
           setNames(synth, paste("30 h", names(synth))))
platform <- sprintf("%s, R %s, long double %s (sizeof %d), gravcal's R accumulator %s, GGIRread::resample fused %s, data.table %s (fread rule %d)",
                    R.version$platform, getRversion(), capabilities("long.double"),
                    .Machine$sizeof.longdouble,
                    if (isTRUE(gravcal:::build_state$r_long_double)) "long double" else "double",
                    gravcal:::ggir_resample_fused(), packageVersion("data.table"),
                    gravcal:::fread_number_rule())
lines <- c(paste0("Platform: ", platform), "",
           "| recording | identical() | elements | rest windows | seconds |", "|---|---|---|---|---|")
cat(lines, sep = "\n")
for (nm in names(files)) {
  t0 <- Sys.time()
  row <- tryCatch({
    f <- files[[nm]]
    if (is.function(f)) f <- f()
    params <- list()
    tz <- NULL
    if (is.list(f)) { params <- f$params %||% list(); tz <- f$tz; f <- f$file }
    old_tz <- Sys.getenv("TZ", unset = NA)
    if (!is.null(tz)) Sys.setenv(TZ = tz)
    b <- tryCatch(run_both(f, params),
                  finally = if (is.na(old_tz)) Sys.unsetenv("TZ") else Sys.setenv(TZ = old_tz))
    R <- b$ggir; G <- b$gravcal
    el <- setdiff(names(R), "bsc_qc")
    bad <- el[!vapply(el, function(k) identical(G[[k]], R[[k]]), TRUE)]
    sprintf("%s | %d of %d%s | %s", identical(G[el], R[el]), length(el) - length(bad), length(el),
            if (length(bad)) paste0(" (differ: ", paste(bad, collapse = ", "), ")") else "",
            if (length(R$npoints)) format(R$npoints) else "none (too short)")
  }, error = function(e) paste("ERROR |", conditionMessage(e), "|"))
  line <- sprintf("| %s | %s | %.0f |", nm, row, as.numeric(Sys.time() - t0, units = "secs"))
  lines <- c(lines, line)
  cat(line, "\n")
}
if (!is.na(out)) writeLines(lines, out)
