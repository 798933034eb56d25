# GGIR's g.inspectfile() result (`I`, saved in part 1's meta files), where
# GGIR's own function reads far more of the file than `I` holds.
#
# For a .gt3x file GGIR's g.inspectfile() unzips the whole file twice to read
# info.txt (read.gt3x::parse_gt3x_info()) and decodes its log to learn the
# decimal mark (g.dotorcomma()): on a week at 100 Hz that is 15 s and 1.9 GB,
# for a list of a header and six scalars. gravcal reads info.txt from the zip
# with its own decoder and hands it to read.gt3x::parse_gt3x_info() as an
# unzipped folder, so the header is read.gt3x's to the bit. The decimal mark GGIR takes from a numeric column, which is never
# text: it is R's `OutDec`, as GGIR's then is. Anything this does not
# cover goes to GGIR's g.inspectfile() (the registry's `ggir_inspect`).

# `I` for `datafile` as GGIR::g.inspectfile(datafile, desiredtz,
# params_rawdata, configtz) gives it: the registry's own builder where the
# file's format has one and it applies, else GGIR's function.
part1_inspect <- function(datafile, desiredtz, params_rawdata, configtz) {
  own <- NULL
  if (!length(params_rawdata[["rmc.firstrow.acc"]])) {
    fmt <- tryCatch(file_format(datafile, "datafile"), error = function(e) NULL)
    if (!is.null(fmt)) own <- format_entry(fmt)$ggir_inspect
  }
  I <- if (is.null(own)) NULL else own(datafile, desiredtz %||% "")
  if (is.null(I)) {
    I <- keep_warn_option(GGIR::g.inspectfile(datafile, desiredtz = desiredtz,
                                              params_rawdata = params_rawdata,
                                              configtz = configtz))
  }
  I
}

# GGIR's file name in `I`: what follows the path's last "/".
ggir_inspect_filename <- function(datafile) {
  parts <- strsplit(as.character(datafile), "/", fixed = TRUE)[[1]]
  parts[length(parts)]
}

# `I` of a .gt3x file, or NULL where GGIR's own function must say it: an
# extension GGIR does not take as .gt3x, a Movisens folder beside the file
# (GGIR then reads it as Movisens), an info.txt gravcal cannot read (GGIR
# warns and leaves `sf` NULL, or stops).
ggir_inspect_gt3x <- function(datafile, desiredtz, decoder) {
  ext <- utils::tail(strsplit(basename(datafile), ".", fixed = TRUE)[[1]], 1)
  if (!ext %in% c("gt3x", "GT3X") || dir.exists(datafile) ||
      file.exists(file.path(dirname(datafile), "unisens.xml")) ||
      !requireNamespace("read.gt3x", quietly = TRUE)) {
    return(NULL)
  }
  opened <- gc_decoder_open(path.expand(datafile), decoder, list())
  if (is.null(opened$ptr)) return(NULL)
  gc_decoder_close(opened$ptr)
  text <- opened$info$header_text
  if (!length(text) || !nzchar(text)) return(NULL)
  # read.gt3x's parse_gt3x_info() on a folder holding only info.txt: the
  # header as it reads it from the zip, whatever its version does with `tz`
  dir <- tempfile("gt3x-info")
  dir.create(dir)
  on.exit(unlink(dir, recursive = TRUE), add = TRUE)
  writeBin(charToRaw(text), file.path(dir, "info.txt"))
  info <- tryCatch(read.gt3x::parse_gt3x_info(dir, tz = desiredtz),
                   error = function(e) NULL)
  if (is.null(info)) return(NULL)
  info <- info[lengths(info) != 0]
  # GGIR's header: a row per field, named by it; times as format() shows
  # them, every value as text, both as factors
  value <- vapply(info, function(v) if (inherits(v, "POSIXct")) format(v) else as.character(v), "")
  field <- factor(names(info))
  header <- data.frame(value = factor(unname(value)), row.names = as.character(field),
                       stringsAsFactors = TRUE)
  sf <- as.numeric(value[names(info) == "Sample Rate"])
  decn <- getOption("OutDec")
  if (!length(decn)) decn <- "."
  list(header = header, monc = 3L, monn = "actigraph", dformc = 6L, dformn = "gt3x",
       sf = sf, decn = decn, filename = ggir_inspect_filename(datafile))
}
