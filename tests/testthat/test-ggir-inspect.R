# g.part1()'s `I` for .gt3x files, built by gravcal (R/ggir-inspect.R),
# against GGIR 3.3-9's g.inspectfile() on the same file: identical() on the
# .gt3x files read.gt3x and GGIR ship and on files of the package's writer,
# in three time zones; files it does not cover go to GGIR's own function.

inspect_ggir <- function(f, tz) {
  keep_warn(suppressWarnings(GGIR::g.inspectfile(f, desiredtz = tz)))
}

# A fresh folder for a test's files (under the session's tempdir(), which
# R removes at its end).
inspect_dir <- function() {
  d <- tempfile("inspect-")
  dir.create(d)
  d
}

test_that("a .gt3x file's I is GGIR's g.inspectfile()'s, without reading the log", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("read.gt3x")
  files <- c(system.file("extdata", "TAS1H30182785_2019-09-17.gt3x", package = "read.gt3x"),
             system.file("testfiles", "actigraph_testfile.gt3x", package = "GGIR"))
  expect_true(all(file.exists(files)))
  d <- inspect_dir()
  # 2 h at 30 Hz across New York's change back to standard time, and an old
  # NEO file (activity.bin, no scale in info.txt)
  x <- simulate_recording(hours = 2, sf = 30, seed = 3)[, c("x", "y", "z")]
  files <- c(files, file.path(d, c("dst.gt3x", "neo.gt3x")))
  write_gt3x(x, files[3], 30, as.POSIXct("2024-11-03 00:30:00", tz = "UTC"))
  write_gt3x(x, files[4], 30, as.POSIXct("2023-05-11 09:00:00", tz = "UTC"),
             format = "activity")
  for (f in files[1:3]) {
    for (tz in c("", "Europe/Amsterdam", "America/New_York")) {
      got <- part1_inspect(f, tz, list(), NULL)
      expect_identical(got, inspect_ggir(f, tz), label = paste(basename(f), tz))
    }
  }
  # the old NEO file: GGIR's function stops (read.gt3x reads no batch of an
  # activity.bin), gravcal's gives the list GGIR's would, its header as
  # read.gt3x reads it
  expect_error(inspect_ggir(files[4], ""), "dotorcomma")
  neo <- part1_inspect(files[4], "", list(), NULL)
  info <- read.gt3x::parse_gt3x_info(files[4])
  expect_identical(neo$sf, 30)
  expect_identical(as.character(neo$header["Serial Number", "value"]), info[["Serial Number"]])
  expect_identical(as.character(neo$header["Acceleration Scale", "value"]), "341")
  expect_identical(neo[c("monc", "monn", "dformc", "dformn", "decn", "filename")],
                   list(monc = 3L, monn = "actigraph", dformc = 6L, dformn = "gt3x",
                        decn = ".", filename = "neo.gt3x"))
  expect_identical(rownames(ggir_inspect_gt3x(files[1], "", "gt3x")$header)[1], "Serial Number")
})

test_that("what gravcal's I does not cover goes to GGIR's g.inspectfile()", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("read.gt3x")
  d <- inspect_dir()
  src <- system.file("testfiles", "actigraph_testfile.gt3x", package = "GGIR")
  # a zip without info.txt: not gravcal's to say; GGIR warns and has no rate
  broken <- file.path(d, "noinfo.gt3x")
  bytes <- readBin(src, "raw", file.size(src))
  at <- grepRaw("info.txt", bytes, all = TRUE)
  for (a in at) bytes[a:(a + 7)] <- charToRaw("xnfo.txt")
  writeBin(bytes, broken)
  expect_null(ggir_inspect_gt3x(broken, "", "gt3x"))
  expect_identical(keep_warn(suppressWarnings(part1_inspect(broken, "", list(), NULL))),
                   inspect_ggir(broken, ""))
  # beside a Movisens recording's unisens.xml GGIR reads the file as Movisens
  mv <- file.path(d, "mv")
  dir.create(mv)
  file.copy(src, file.path(mv, "a.gt3x"))
  writeLines("<unisens/>", file.path(mv, "unisens.xml"))
  expect_null(ggir_inspect_gt3x(file.path(mv, "a.gt3x"), "", "gt3x"))
  # ad hoc csv parameters: GGIR reads the file as ad hoc csv whatever its name
  expect_null(format_entry("csv")$ggir_inspect)
})

test_that("an upper-case .GT3X is read in place, never renamed as GGIR renames it", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("read.gt3x")
  d <- inspect_dir()
  src <- system.file("testfiles", "actigraph_testfile.gt3x", package = "GGIR")
  up <- file.path(d, "A.GT3X")
  low <- file.path(d, "b.gt3x")
  file.copy(src, up)
  file.copy(src, low)
  got <- part1_inspect(up, "Europe/Amsterdam", list(), NULL)
  expect_identical(sort(list.files(d)), c("A.GT3X", "b.gt3x"))
  want <- inspect_ggir(low, "Europe/Amsterdam")
  want$filename <- "A.GT3X"
  expect_identical(got, want)
})
