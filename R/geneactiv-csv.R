# GENEActiv's csv export (GENEActiv PC software): a header of "name,value"
# lines (the rate in "Measurement Frequency", as "100 Hz"), 100 lines in
# the software's exports, then one line a sample: time stamp
# ("2013-10-21 10:00:07:500", milliseconds after a colon), x, y, z in g,
# light, button, temperature in degrees C.
#
# GGIR reads it no more (its g.inspectfile() stops, since GGIR 2.6-4,
# advising the .bin file or read.myacc.csv), so gravcal's g.calibrate(), and
# calibrate() with ggir_compat = TRUE, refuse it as GGIR does, naming the
# rmc.* parameters that read it as an ad hoc csv file. gravcal's own
# methods read it through the csv decoder with that ad hoc layout, the rate
# from its header (the time stamps are not read: samples are at the rate).

# Whether `file` begins as GENEActiv's csv export: "Device Type,GENEActiv".
is_geneactiv_csv <- function(file) {
  con <- if (grepl("\\.gz$", file, ignore.case = TRUE)) gzfile(file, "rb") else file(file, "rb")
  on.exit(close(con))
  b <- tryCatch(readBin(con, "raw", 64), error = function(e) raw(0))
  if (length(b) >= 3 && identical(b[1:3], as.raw(c(0xef, 0xbb, 0xbf)))) b <- b[-(1:3)]
  b <- b[b >= as.raw(32) & b < as.raw(127)]
  grepl("^\"?Device Type\"?,\"?GENEActiv", rawToChar(b), ignore.case = TRUE)
}

# GGIR's rmc.* parameters that read a GENEActiv csv export as an ad hoc csv
# file: the first sample line, x, y, z in columns 2 to 4 (g), temperature
# in column 7 where the lines have it, the rate from the header.
geneactiv_csv_rmc <- function(file, arg = "file") {
  con <- if (grepl("\\.gz$", file, ignore.case = TRUE)) gzfile(file, "r") else file(file, "r")
  on.exit(close(con))
  head <- tryCatch(readLines(con, n = 300, warn = FALSE), error = function(e) character(0))
  stamp <- "^\"?[0-9]{4}-[0-9]{2}-[0-9]{2} [0-9]{1,2}:[0-9]{2}:[0-9]{2}"
  first <- which(grepl(stamp, head) & lengths(strsplit(head, ",", fixed = TRUE)) >= 4)[1]
  if (is.na(first)) {
    abort("`", arg, "` \"", file, "\" is a GENEActiv csv export without sample lines ",
          "(a time stamp, x, y, z) in its first 300 lines.")
  }
  hdr <- strsplit(head[seq_len(first - 1)], ",", fixed = TRUE)
  name <- vapply(hdr, function(h) trimws(gsub("\"", "", h[1])), "")
  value <- vapply(hdr, function(h) if (length(h) > 1) trimws(gsub("\"", "", h[2])) else "", "")
  sf <- suppressWarnings(as.numeric(sub("[[:space:]]*Hz$", "",
                                        value[tolower(name) == "measurement frequency"][1],
                                        ignore.case = TRUE)))
  if (!isTRUE(is.finite(sf) && sf > 0)) {
    abort("`", arg, "` \"", file, "\" is a GENEActiv csv export whose header gives no ",
          "rate (\"Measurement Frequency,<rate> Hz\").")
  }
  nf <- length(strsplit(head[first], ",", fixed = TRUE)[[1]])
  p <- list(rmc.firstrow.acc = first, rmc.col.acc = 2:4, rmc.unit.acc = "g", rmc.sf = sf)
  if (nf >= 7) p <- c(p, list(rmc.col.temp = 7, rmc.unit.temp = "C"))
  p
}

# The refusal of a GENEActiv csv export where GGIR's result is asked for.
geneactiv_csv_refuse <- function(file, arg) {
  p <- tryCatch(geneactiv_csv_rmc(file, arg), error = function(e) NULL)
  show <- if (is.null(p)) "rmc.firstrow.acc = <its first sample line>, rmc.col.acc = 2:4, rmc.col.temp = 7, rmc.sf = <its rate>" else
    paste(vapply(names(p), function(n) paste(n, "=", deparse(p[[n]])), ""), collapse = ", ")
  abort("`", arg, "` \"", file, "\" is a GENEActiv csv export, which GGIR does not read ",
        "(its g.inspectfile() stops since GGIR 2.6-4): give the .bin file, or read it ",
        "as an ad hoc csv file with GGIR's rmc.* parameters, as GGIR advises: ", show,
        ". calibrate() (gravcal's own methods) reads it as it is.")
}
