# The format registry (R/formats.R) and the native decoders' table
# (inst/include/gravcal/decoders/decoder_table.hpp): every place that depends on a file's format reads them.

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

# Every decision that depends on a recording format is a field of the
# format's registry entry (R/formats.R): no other R file compares a format
# with a name or lists format names. The scan reads the package's R sources
# (parsed, so comments and documentation do not count): a string equal to
# a registry name, a name of switch() equal to one, or `format` / `fmt`
# compared (==, !=, %in% c(...)) with a literal.
registry_name_uses <- function(dir, names) {
  out <- NULL
  for (f in list.files(dir, pattern = "\\.[Rr]$", full.names = TRUE)) {
    if (basename(f) == "formats.R") next
    pd <- utils::getParseData(parse(f, keep.source = TRUE))
    callee <- function(id) {  # the function a call (expression `id`) calls
      kids <- pd[pd$parent == id, ]
      first <- kids[order(kids$line1, kids$col1), ][1, ]
      fn <- pd$text[pd$parent == first$id & pd$token == "SYMBOL_FUNCTION_CALL"]
      if (length(fn)) fn[1] else ""
    }
    tk <- pd[pd$terminal, ]
    tk <- tk[order(tk$line1, tk$col1), ]
    n <- nrow(tk)
    str <- ifelse(tk$token == "STR_CONST", substr(tk$text, 2, nchar(tk$text) - 1), NA)
    hit <- tk$token == "STR_CONST" & str %in% names
    sub <- which(tk$token == "SYMBOL_SUB" & tk$text %in% names)
    hit[sub] <- vapply(tk$parent[sub], callee, "") == "switch"
    cmp <- tk$token %in% c("EQ", "NE") | (tk$token == "SPECIAL" & tk$text == "%in%")
    left <- c("", tk$text[-n])
    right <- c(tk$text[-1], "")
    right_tok <- c(tk$token[-1], "")
    hit <- hit | (cmp & left %in% c("format", "fmt") &
                    (right_tok == "STR_CONST" | right == "c"))
    code <- readLines(f, warn = FALSE)
    for (i in which(hit)) {
      out <- rbind(out, data.frame(file = basename(f), line = tk$line1[i],
                                   code = trimws(code[tk$line1[i]])))
    }
  }
  out
}

test_that("no R file but R/formats.R branches on a recording format's name", {
  # the source tree's R/, or under R CMD check the sources it unpacked
  # beside the tests (gravcal.Rcheck/00_pkg_src/gravcal/R)
  dirs <- c(test_path("..", "..", "R"),
            test_path("..", "..", "00_pkg_src", "gravcal", "R"))
  dir <- dirs[dir.exists(dirs)][1]
  if (is.na(dir)) skip("the package's R sources are not here (an installed package's tests)")
  expect_true(file.exists(file.path(dir, "formats.R")))
  # uses of such names that are not recording formats: file and line text
  allowed <- list(
    # coefficient file formats (write_coefs()/read_coefs()), not recordings
    list(file = "coef-formats.R", code = 'format == "auto"'),
    list(file = "coef-formats.R", code = 'fmt != "skdh"'),
    list(file = "coef-formats.R", code = 'format == "ggir"'),
    # write_gt3x()'s kind of data (activity samples), not a recording format
    list(file = "write-gt3x.R", code = 'format == "activity"'),
    # GGIR's own names: g.inspectfile()'s test of a .gt3x file's extension
    # and its data format name (dformn), which ggir_inspect_gt3x() rebuilds
    list(file = "ggir-inspect.R", code = 'c("gt3x", "GT3X")'),
    list(file = "ggir-inspect.R", code = 'dformn = "gt3x"')
  )
  uses <- registry_name_uses(dir, names(gravcal:::recording_formats))
  expect_false(is.null(uses))  # the allowed ones are found: the scan works
  ok <- vapply(seq_len(nrow(uses)), function(i) {
    any(vapply(allowed, function(a) a$file == uses$file[i] &&
                 grepl(a$code, uses$code[i], fixed = TRUE), TRUE))
  }, TRUE)
  bad <- uses[!ok, ]
  expect(nrow(bad) == 0, paste0(
    "recording formats named outside R/formats.R (make it a field of the registry):\n",
    paste0(bad$file, ":", bad$line, ": ", bad$code, collapse = "\n")))
  # every allow-list entry is still needed
  used <- vapply(allowed, function(a) {
    any(uses$file == a$file & grepl(a$code, uses$code, fixed = TRUE))
  }, TRUE)
  expect(all(used), paste("allow-list entries no longer used:",
                          paste(vapply(allowed[!used], `[[`, "", "code"), collapse = ", ")))
})
