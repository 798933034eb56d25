# The recording formats gravcal reads, once. Everything that depends on a
# file's format asks here: file_format() (which format a file is),
# calibrate_files() (which files in a folder are recordings), the messages
# (what a format, its unit and the readable files are called), the native
# reader (which decoder, and GGIR's block in the decoder's units) and the
# reference readers.
#
# For each format, under its name (the `format` of sources, fits and
# tables), in the order messages list them:
# * ext: its file name extensions (lower case), each with the words the
#   list of readable files gives it (NA where a format before it, sharing
#   the extension, already does);
# * detect: for formats that share an extension, whether a file is this one
#   (a file is the first format of its extension whose detector says yes or
#   that has none);
# * local_clock: where GGIR's reader takes the file's clock times for times
#   in configtz (else desiredtz) and the native decoder gives them as UTC
#   (g.getmeta() moves them: meta_zone_shift()): "block" (GGIRread converts
#   a block's first time) or "sample" (lubridate::force_tz() on each);
# * ggir_getmeta: TRUE where g.getmeta() (GGIR part 1) reads the format;
# * ggir_monitor: GGIR's monitor (its MONITOR code's name, lower case), for
#   the rules GGIR keys on it (g.getmeta(): ActiGraph serial numbers'
#   dynamic range);
# * ggir_start(file, p): where GGIR's g.getmeta() starts a recording whose
#   reader gives no time stamps (as POSIXlt in desiredtz);
# * ggir_time: FALSE where GGIR's reader gives no time stamps although the
#   native decoder does (g.getmeta() drops them);
# * ggir_inspect(file, tz): GGIR's g.inspectfile() result for the file,
#   built without GGIR's whole-file reads (R/ggir-inspect.R), or NULL where
#   GGIR's own function must give it;
# * ggir_timegaps: GGIR's g.getmeta() fills the recording's time gaps
#   (g.imputeTimegaps(), when imputeTimegaps = TRUE);
# * ggir_qclog(src): the QClog GGIR's reader gives with the first block
#   (g.getmeta() returns it in M$QClog), from the open native source;
# * ggir_stops(src): why GGIR's reader stops on the file (g.getmeta() then
#   refuses it, saying so), or NULL;
# * own_rate: TRUE for a device format whose file records its sampling
#   rate (that rate is used; an `sf` that disagrees is an error);
# * label: the format in messages ("as an Axivity .cwa file");
# * unit: what its native decoder reads and skips by (".. blocks skipped");
# * block_units: the size of one of GGIR's blocks in those units, from the
#   sampling rate and chunksize (g.calibrate's blocksize; chunksize = 1 is
#   about 12 hours; NULL: not read natively);
# * decoder: the name of its native decoder (src/decoders.h), or NULL;
# * read(file, sf, reader, arg): the whole file by the reference reader (or
#   the native one where the reference reads blocks: read_blocks());
# * source(file, sf, chunksize, arg): the file block by block, without a
#   native decoder (see open_source()).
# * write: for write_recording(), list(check(x, sf, start): an error where
#   the format cannot hold the samples as given, write(x, file, sf, start):
#   the file; `x` a data frame x, y, z (g), maybe temperature and light,
#   `start` POSIXct; folder = TRUE where `file` is a folder).
recording_formats <- list(
  actigraph_csv = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "actigraph", ggir_timegaps = TRUE, ggir_time = FALSE,
    ggir_start = function(file, p) actigraph_csv_start(file, p),
    ext = c(csv = ".csv (ActiGraph or x,y,z columns)", csv.gz = ".csv.gz"),
    detect = function(file) is_actigraph_csv(file),
    label = "an ActiGraph csv export", unit = "line",
    block_units = function(sf, chunksize) ggir_pages(sf, chunksize) * 300,
    decoder = "actigraph_csv",
    read = function(file, sf, reader, arg) read_blocks(file, sf, reader),
    write = list(
      check = function(x, sf, start) write_check_whole_hz(sf),
      write = function(x, file, sf, start) {
        write_actigraph_csv_file(x, file, sf, start = format(start, "%Y-%m-%d %H:%M:%OS3", tz = "UTC"),
                                 stamps = "actilife")
      }),
    source = function(file, sf, chunksize, arg) source_csv(file, sf, chunksize)),
  # GENEActiv's csv export: refused where GGIR's result is asked for (GGIR
  # reads it no more), else read as the ad hoc csv file its header
  # describes (R/geneactiv-csv.R)
  geneactiv_csv = list(
    ggir_monitor = "geneactiv",
    ext = c(csv = NA, csv.gz = NA), detect = function(file) is_geneactiv_csv(file),
    label = "a GENEActiv csv export", unit = "line", own_rate = TRUE,
    block_units = function(sf, chunksize) ggir_pages(sf, chunksize) * 300,
    decoder = NULL,
    read = function(file, sf, reader, arg) {
      d <- read_adhoc(file, reader, rmc_values(geneactiv_csv_rmc(file, arg)))$data
      if (is.list(attr(d, "input"))) attr(d, "input")$format <- "geneactiv_csv"
      d
    },
    source = function(file, sf, chunksize, arg) {
      open_source(file, sf, chunksize, arg, compat = FALSE)
    }),
  # Axivity's csv export (OMGUI): no header, lines of UNIX time stamp, x,
  # y, z; GGIR resamples each block onto the rate it finds from the first
  # 100000 time stamps (R/axivity-csv.R)
  axivity_csv = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "axivity", ggir_timegaps = TRUE, local_clock = "sample",
    ext = c(csv = NA, csv.gz = NA), detect = function(file) is_axivity_csv(file),
    label = "an Axivity csv export", unit = "line",
    block_units = function(sf, chunksize) ggir_pages(sf, chunksize) * 300,
    decoder = "axivity_csv",
    read = function(file, sf, reader, arg) read_blocks(file, sf, reader),
    source = function(file, sf, chunksize, arg) source_axivity_csv(file, sf, chunksize)),
  csv = list(
    ext = c(csv = NA, csv.gz = NA), detect = NULL,
    label = "a csv file of samples", unit = "line",
    block_units = function(sf, chunksize) ggir_pages(sf, chunksize) * 300,
    decoder = "csv",
    read = function(file, sf, reader, arg) read_plain_csv(file, arg),
    source = function(file, sf, chunksize, arg) source_csv(file, sf, chunksize)),
  # GGIR's ad hoc csv: never found from the file itself, but chosen by the
  # rmc.* parameters (rmc.firstrow.acc; R/adhoc-csv.R), which give its
  # layout to the csv decoder (and to `source`, as `layout`)
  adhoc_csv = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "ad_hoc", ggir_timegaps = TRUE,
    ext = c(csv = NA, csv.gz = NA), detect = function(file) FALSE,
    label = "an ad hoc csv file (GGIR's rmc.* parameters)", unit = "line",
    block_units = function(sf, chunksize) ggir_pages(sf, chunksize) * 300,
    decoder = "adhoc_csv",
    read = function(file, sf, reader, arg) {
      abort("Reading \"", file, "\" as an ad hoc csv file needs its rmc.* parameters.")
    },
    source = function(file, sf, chunksize, arg, layout = NULL) {
      source_adhoc(file, sf, chunksize, arg, layout)
    }),
  rds = list(
    ext = c(rds = ".rds"), detect = NULL,
    label = "an .rds file", unit = "unit", block_units = NULL, decoder = NULL,
    read = function(file, sf, reader, arg) read_rds(file, arg),
    source = function(file, sf, chunksize, arg) {
      rec <- read_file(file, sf, "native", arg)
      source_frame(rec$data, rec$sf, chunksize, arg)
    }),
  gt3x = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "actigraph",
    ext = c(gt3x = ".gt3x"), detect = NULL,
    label = "an ActiGraph .gt3x file", unit = "record", own_rate = TRUE,
    local_clock = "sample", ggir_timegaps = TRUE,
    ggir_inspect = function(file, tz) ggir_inspect_gt3x(file, tz),
    block_units = function(sf, chunksize) (12 * 3600) * chunksize,  # seconds
    decoder = "gt3x",
    read = function(file, sf, reader, arg) read_gt3x_file(file),
    write = list(
      check = function(x, sf, start) {
        write_check_whole_hz(sf)
        if (!is.null(x$temperature)) {
          warning("`x$temperature` is not written: the .gt3x format holds no temperature.",
                  call. = FALSE)
        }
      },
      write = function(x, file, sf, start) {
        write_gt3x(x[c("x", "y", "z")], file, sf = sf, start = start)
      }),
    source = function(file, sf, chunksize, arg) source_gt3x(file, chunksize)),
  cwa = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "axivity",
    ext = c(cwa = ".cwa"), detect = NULL,
    label = "an Axivity .cwa file", unit = "block", own_rate = TRUE,
    # 512-byte blocks of 80 samples (GGIR's count, whatever the packing)
    block_units = function(sf, chunksize) round(12 * 3600 * sf / 80 * chunksize),
    decoder = "cwa",
    read = function(file, sf, reader, arg) read_blocks(file, sf, reader),
    write = list(
      check = function(x, sf, start) {
        k <- log2(3200 / sf)
        if (!isTRUE(abs(k - round(k)) < 1e-9 && k >= 0 && k <= 9)) {
          abort("`sf`: an Axivity .cwa file holds 3200 / 2^k Hz (6.25, 12.5, 25, 50, 100, ",
                "200, ... 3200), not ", sf, ".")
        }
        if (!is.null(x$light) && any(x$light < 0 | x$light > 1023)) {
          abort("`x$light` must be the light sensor's raw value, 0 to 1023.")
        }
      },
      write = function(x, file, sf, start) {
        write_cwa(as.matrix(x[c("x", "y", "z")]), file, sf = sf, start = start,
                  temperature = if (is.null(x$temperature)) 25 else x$temperature,
                  light = if (is.null(x$light)) 0 else x$light)
      }),
    source = function(file, sf, chunksize, arg) source_cwa(file, chunksize)),
  # Movisens: a unisens folder (unisens.xml, acc.bin, temp.bin), named by
  # the folder or its acc.bin (GGIR's filename); GGIR reads it in blocks of
  # sf * 60 * 1440 / 2 samples whatever chunksize, and assumes 64 Hz
  movisens = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "movisens",
    ggir_start = function(file, p) movisens_start(file, p),
    ext = c(bin = "Movisens (a unisens folder or its acc.bin)"),
    detect = function(file) is_movisens_bin(file),
    label = "a Movisens recording", unit = "sample", own_rate = TRUE,
    block_units = function(sf, chunksize) movisens_block(),
    decoder = "movisens",
    read = function(file, sf, reader, arg) read_blocks(file, sf, reader),
    write = list(
      folder = TRUE,
      check = function(x, sf, start) NULL,
      write = function(x, file, sf, start) {
        write_movisens(x, file, sf = sf, start = start, temp = !is.null(x$temperature))
      }),
    source = function(file, sf, chunksize, arg) source_movisens(file)),
  geneactiv = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "geneactiv",
    ext = c(bin = "GENEActiv .bin"), detect = function(file) !is_parmay_bin(file),
    label = "a GENEActiv .bin file", unit = "page", own_rate = TRUE, local_clock = "block",
    block_units = function(sf, chunksize) ggir_pages(sf, chunksize),
    decoder = "geneactiv",
    read = function(file, sf, reader, arg) read_blocks(file, sf, reader),
    write = list(
      check = function(x, sf, start) {
        if (nrow(x) < 300) abort("`x` has ", nrow(x), " samples, fewer than one GENEActiv page (300).")
      },
      write = function(x, file, sf, start) {
        write_geneactiv_bin(x, file, sf = sf, start = format(start, "%Y-%m-%d %H:%M:%OS3", tz = "UTC"))
      }),
    source = function(file, sf, chunksize, arg) source_geneactiv(file, chunksize)),
  # Parmay Matrix: "MDTC" at byte 512. GGIRread's reader reads from the
  # block's first packet to the end of the file whatever end it is given, so
  # GGIR's first block is the whole file (and its last). Its times are the
  # packets' UTC seconds, read in no zone (no local_clock); GGIR's
  # g.getmeta() takes the dynamic range from the header (meta_nonwear())
  # and returns the reader's log of the packets as M$QClog
  # (parmay_qclog())
  parmay = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "parmay_mtx",
    ggir_qclog = function(src) parmay_qclog(src),
    ggir_stops = function(src) parmay_ggir_stops(src),
    ext = c(bin = "Parmay Matrix .bin"), detect = function(file) is_parmay_bin(file),
    label = "a Parmay Matrix .bin file", unit = "packet", own_rate = TRUE,
    block_units = function(sf, chunksize) 2^52,
    decoder = "parmay",
    read = function(file, sf, reader, arg) read_blocks(file, sf, reader),
    write = list(
      check = function(x, sf, start) {
        if (as.numeric(start) != round(as.numeric(start))) {
          abort("`start`: a Parmay Matrix file's packets start on whole seconds.")
        }
        if (sf * 60 != round(sf * 60)) {
          abort("`sf`: a Parmay Matrix packet of 60 s must hold a whole number of samples (",
                sf, " Hz).")
        }
      },
      write = function(x, file, sf, start) {
        write_parmay_bin(x, file, sf = sf, start = as.numeric(start))
      }),
    source = function(file, sf, chunksize, arg) source_parmay(file))
)

# Whether `file` is the acc.bin of a unisens folder (a Movisens recording).
is_movisens_bin <- function(file) {
  tolower(basename(file)) == "acc.bin" &&
    file.exists(file.path(dirname(file), "unisens.xml"))
}

# A unisens folder stands for its acc.bin (what GGIR's `datafile` names);
# any other path is returned as it is.
unisens_acc <- function(path) {
  if (is.character(path) && length(path) == 1 && !is.na(path) && dir.exists(path) &&
      file.exists(file.path(path, "unisens.xml"))) {
    return(file.path(path, "acc.bin"))
  }
  path
}

# A recording's name as GGIR gives it (its coefficient file's rows, the
# source of a fit): the file name, or for a Movisens recording its
# folder's name (GGIR's datadir2fnames and g.inspectfile).
ggir_file_name <- function(path) {
  mv <- vapply(path, is_movisens_bin, TRUE, USE.NAMES = FALSE)
  ifelse(mv, basename(dirname(path)), basename(path))
}

# Files of a unisens folder other than its acc.bin are not recordings of
# their own (calibrate_files()' listing of a folder).
in_unisens_folder <- function(path) {
  file.exists(file.path(dirname(path), "unisens.xml")) & tolower(basename(path)) != "acc.bin"
}

# Whether `file` is a Parmay Matrix file ("MDTC" at byte 512).
is_parmay_bin <- function(file) {
  con <- file(file, "rb")
  on.exit(close(con))
  b <- readBin(con, "raw", n = 516)
  length(b) == 516 && identical(b[513:516], charToRaw("MDTC"))
}

# The number of packets a Parmay Matrix file's header declares (int32 at
# byte 516), NA when the file is shorter.
parmay_declared <- function(file) {
  con <- file(file, "rb")
  on.exit(close(con))
  b <- readBin(con, "raw", n = 520)
  if (length(b) < 520) return(NA_integer_)
  readBin(b[517:520], "integer", size = 4, endian = "little")
}

# The `sf` a cohort's setting gives `file`: none for a file that records
# its own rate (the setting is for the files that do not; see
# check_sf_agrees()).
sf_for_file <- function(file, sf) {
  if (is.null(sf)) return(NULL)
  format <- tryCatch(file_format(file, "files"), error = function(e) NA)
  if (isTRUE(format_entry(format)$own_rate)) NULL else sf
}

# The registry's entry for `format`; NULL for a format it does not hold
# (samples in memory: "data.frame").
format_entry <- function(format) {
  if (format %in% names(recording_formats)) recording_formats[[format]]
}

# Every extension, once, in the registry's order.
format_extensions <- function() {
  unique(unlist(lapply(recording_formats, function(f) names(f$ext)),
                use.names = FALSE))
}

# A regular expression for the file names of recordings (calibrate_files()).
format_file_pattern <- function() {
  paste0("\\.(", paste(gsub(".", "\\.", format_extensions(), fixed = TRUE),
                       collapse = "|"), ")$")
}

# "gravcal reads .csv (...), .csv.gz, ... and GENEActiv .bin.", for messages.
format_readable <- function() {
  says <- unlist(lapply(recording_formats, `[[`, "ext"), use.names = FALSE)
  says <- says[!is.na(says)]
  n <- length(says)
  paste0("gravcal reads ", paste(says[-n], collapse = ", "), " and ", says[n], ".")
}

# Whether the format has a native decoder (whether this build runs it is the
# decoder's to say: gc_decoder_open() answers `unsupported`).
format_has_decoder <- function(format) !is.null(format_entry(format)$decoder)

# The size of GGIR's block for `format` in its decoder's units.
# GGIR's block of GENEActiv pages (300 samples each; g.calibrate's
# blocksize, chunksize = 1 about 12 hours): the block, in rows, of every
# format GGIR reads by rows too.
ggir_pages <- function(sf, chunksize) {
  round((14512 * (sf / 50)) * (chunksize * 0.5))
}

format_block_units <- function(format, sf, chunksize) {
  format_entry(format)$block_units(sf, chunksize)
}
