# The format registry (R/formats.R) and the native decoders' table
# (src/decoders.h): every place that depends on a file's format reads them.

test_that("a file's format comes from its extension and, for csv, its first line", {
  d <- snap_dir("formats")
  on.exit(unlink(d, recursive = TRUE))
  path <- function(name) file.path(d, name)
  writeLines("x,y,z\n0,0,1", path("plain.CSV"))
  rec <- simulate_recording(hours = 0.01, sf = 10, seed = 1)
  gravcal:::write_actigraph_csv(rec, path("acti.csv"), sf = 10)
  file.copy(path("acti.csv"), path("acti2.csv.gz"))  # the name decides the extension
  for (nm in c("a.rds", "a.gt3x", "a.cwa", "a.bin", "a.b.cwa")) file.create(path(nm))
  got <- vapply(c("plain.CSV", "acti.csv", "acti2.csv.gz", "a.rds", "a.gt3x",
                  "a.cwa", "a.bin", "a.b.cwa"),
                function(f) gravcal:::file_format(path(f)), "")
  expect_identical(unname(got), c("csv", "actigraph_csv", "actigraph_csv", "rds",
                                  "gt3x", "cwa", "geneactiv", "cwa"))
  # a .bin (or .BIN) with "MDTC" at byte 512 is a Parmay Matrix file
  writeBin(c(as.raw(rep(0, 512)), charToRaw("MDTC")), path("m.BIN"))
  expect_identical(gravcal:::file_format(path("m.BIN")), "parmay")
  # acc.bin beside a unisens.xml is a Movisens recording (its temp.bin is not)
  dir.create(path("mv"))
  file.create(path(c("mv/unisens.xml", "mv/acc.bin", "mv/temp.bin")))
  expect_identical(gravcal:::file_format(path("mv/acc.bin")), "movisens")
  expect_identical(gravcal:::file_format(path("mv/temp.bin")), "geneactiv")
  expect_identical(gravcal:::unisens_acc(path("mv")), path("mv/acc.bin"))
  expect_identical(gravcal:::in_unisens_folder(path(c("mv/acc.bin", "mv/temp.bin", "a.bin"))),
                   c(FALSE, TRUE, FALSE))
  unlink(path("mv"), recursive = TRUE)
  # the message lists what gravcal reads, as it did before the registry
  file.create(path("a.xyz"))
  expect_error(read_recording(path("a.xyz")), paste0(
    "`file` has an unsupported extension \".xyz\"; gravcal reads .csv ",
    "(ActiGraph or x,y,z columns), .csv.gz, .rds, .gt3x, .cwa, Movisens (a unisens ",
    "folder or its acc.bin), GENEActiv .bin and Parmay Matrix .bin."),
    fixed = TRUE)
  # calibrate_files() takes exactly the files of those extensions
  files <- calibrate_files
  expect_identical(formals(files)$pattern, quote(format_file_pattern()))
  p <- gravcal:::format_file_pattern()
  taken <- grepl(p, c("a.csv", "a.CSV.GZ", "a.rds", "a.gt3x", "a.cwa", "a.bin",
                      "a.xyz", "a.csv.zip", "a.gz", "cwa"), ignore.case = TRUE)
  expect_identical(taken, c(rep(TRUE, 6), rep(FALSE, 4)))
  e <- tempfile("empty")
  dir.create(e)
  on.exit(unlink(e, recursive = TRUE), add = TRUE)
  expect_error(calibrate_files(e, outdir = tempdir()), paste0(
    "no recordings in \"", e, "\" (pattern \"\\.(csv|csv\\.gz|rds|gt3x|cwa|bin)$\")."),
    fixed = TRUE)
})

test_that("each format's words, unit and GGIR block come from the registry", {
  expect_identical(gravcal:::native_format_name("cwa"), "an Axivity .cwa file")
  expect_identical(gravcal:::native_format_name("data.frame"), "data.frame")
  expect_identical(gravcal:::unit_name("geneactiv", 2), "pages")
  expect_identical(gravcal:::unit_name("gt3x", 1), "record")
  expect_identical(gravcal:::unit_name("data.frame", 3), "units")
  # GGIR's block (g.calibrate's blocksize at chunksize 1, in the format's
  # units): 12 h of 512-byte .cwa blocks of 80 samples, GENEActiv pages of
  # 300 samples, .gt3x seconds, csv lines (in whole 300-line steps)
  units <- function(f, sf, cs = 1) gravcal:::format_block_units(f, sf, cs)
  expect_identical(units("cwa", 100), 54000)
  expect_identical(units("geneactiv", 100), 14512)
  expect_identical(units("gt3x", 30), 43200)
  expect_identical(units("csv", 30), 1306200)
  expect_identical(units("actigraph_csv", 30, 0.2), 261300)
  # Movisens: sf * 60 * 1440 / 2 samples with GGIR's 64 Hz, whatever chunksize
  expect_identical(units("movisens", 64, 0.2), 2764800)
  expect_false(gravcal:::format_has_decoder("rds"))
})

test_that("R's registry and the C++ table of decoders name the same decoders", {
  f <- tempfile(fileext = ".bin")
  writeBin(as.raw(1:64), f)
  on.exit(unlink(f))
  reg <- gravcal:::recording_formats
  decoders <- unlist(lapply(reg, `[[`, "decoder"), use.names = FALSE)
  expect_setequal(decoders, c("actigraph_csv", "axivity_csv", "csv", "adhoc_csv", "gt3x",
                              "cwa", "geneactiv", "parmay", "movisens"))
  for (d in decoders) {
    # a decoder that exists fails on these bytes, as its format
    h <- gravcal:::gc_decoder_open(f, d, list())
    if (!is.null(h$ptr)) gravcal:::gc_decoder_close(h$ptr)
    expect_false(isTRUE(h$unsupported), label = d)
  }
  h <- gravcal:::gc_decoder_open(f, "rds", list())
  expect_true(h$unsupported)
  expect_match(h$error, "no native decoder for format rds")
})
