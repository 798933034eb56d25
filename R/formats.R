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
#   a block's first time) or "sample" (lubridate::force_tz() on each); or
#   a function of the file and the zone giving one of them or NULL
#   (format_local_clock());
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
# * ggir_block_qclog(src, from): the QClog GGIR's reader gives with each of
#   its blocks: the rows its native decoder logged after the first `from`
#   (a data frame, or NULL when none);
# * ggir_stops(src): why GGIR's reader stops on the file (g.getmeta() then
#   refuses it, saying so), or NULL;
# * ggir_read_stops(src, part): the same from what the native decoder has
#   read so far, asked after each of g.getmeta()'s blocks (`part`
#   "getmeta") and after g.calibrate() ("calibrate"): where GGIR's reader
#   stops, or reads what gravcal's decoder does not follow;
# * ggir_damage_warning(src): g.getmeta()'s warning of the damage its
#   native decoder read as GGIR's reader reads it;
# * own_rate: TRUE for a device format whose file records its sampling
#   rate (that rate is used; an `sf` that disagrees is an error);
# * label: the format in messages ("as an Axivity .cwa file");
# * unit: what its native decoder reads and skips by (".. blocks skipped");
# * block_units: the size of one of GGIR's blocks in those units, from the
#   sampling rate and chunksize (g.calibrate's blocksize; chunksize = 1 is
#   about 12 hours; NULL: not read natively);
# * decoder: the name of its native decoder (find_decoder() in inst/include/gravcal/decoders/decoder_table.hpp), or NULL;
# * read(file, sf, reader, arg): the whole file by the reference reader (or
#   the native one where the reference reads blocks: read_blocks());
# * source(file, sf, chunksize, arg): the file block by block, without a
#   native decoder (see open_source()).
# * write: for write_recording(), list(check(x, sf, start): an error where
#   the format cannot hold the samples as given, write(x, file, sf, start):
#   the file; `x` a data frame x, y, z (g), maybe temperature and light,
#   `start` POSIXct; folder = TRUE where `file` is a folder).
#
# What the readers, GGIR's drop-ins and messages decide by format (a field
# left out is FALSE / NULL / nothing to do):
# * block_units(sf, chunksize, part): as above; `part` is "calibrate" or
#   "getmeta" (Movisens: GGIR's block is a fixed number of samples by part,
#   whatever chunksize);
# * source(file, sf, chunksize, arg, format): `format` is the entry's name
#   (the source's `format`);
# * rmc: TRUE for the format the rmc.* parameters choose (rmc_format());
# * adhoc_layout(file, arg, compat): read as that format, with this layout
#   (rmc_layout()); an error where GGIR's result is asked for (compat) and
#   GGIR does not read the file;
# * decoder_options(file, opts, sf, read): the native decoder's options
#   (and the rate) for this format, as list(opts, sf); `read` is list(whole
#   = TRUE for read_recording()'s whole read, else a source's stream,
#   compat, format, chunksize, part, zone, zone_arg);
# * r_options(file, options, zone): options this R itself decides, added
#   on every opening of the decoder (decoder_open()); `zone` is GGIR's zone
#   where the caller gave one;
# * resample_fused, fread_rule: TRUE where a GGIR-compatible read replays
#   GGIRread::resample / data.table::fread's numbers (with_resample_fused());
# * ggir_read_opts: the decoder options GGIR's reading parameters set for
#   this format (reader = "reference" takes GGIR's defaults only:
#   check_reference_opts());
# * ggir_check_sf(file, sf): an error where GGIR's reading of the file at
#   that rate would be wrong (compatible reads);
# * ggir_short_rows(units): GGIR takes a block with fewer rows than this
#   for the last (compatible reads; 0 where not given);
# * empty_why: why a file that gave no sample holds none, where nothing
#   was skipped ("it holds no samples" where not given); long_lines_hint:
#   what to add when the decoder counted lines too long to read;
# * ggir_noise: "default" where GGIR's g.calibrate takes rmc.noise (its
#   default where not given) for the sd criterion, "given" where gravcal
#   takes it only when given (GGIR reads no such file);
# * ggir_codes: GGIR's g.inspectfile() monitor and data format codes, as
#   "monc dformc" (ggir_inspect_format());
# * ggir_decimal: a csv export whose decimal mark GGIR takes from
#   g.inspectfile()'s `decn` (gravcal reads decimal points);
# * ggir_zone_ambiguous: a GGIR-compatible native read counts blocks that
#   start at a time that is ambiguous in the zone (ggir_check_zone_read());
# * ggir_calendar: GGIR's own reader converts each block's calendar time in
#   configtz / desiredtz (ggir_check_tz());
# * ggir_clip: g.getmeta()'s clipping threshold where no dynamic range is
#   known (7.5 where not given).
recording_formats <- list(
  actigraph_csv = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "actigraph", ggir_timegaps = TRUE, ggir_time = FALSE,
    ggir_codes = "3 2", ggir_decimal = TRUE, fread_rule = TRUE,
    empty_why = "it has a header but no data lines",
    ggir_start = function(file, p) actigraph_csv_start(file, p),
    ggir_read_stops = function(src, part) actigraph_csv_ggir_stops(src, part),
    ext = c(csv = ".csv (ActiGraph or x,y,z columns)", csv.gz = ".csv.gz"),
    detect = function(file) is_actigraph_csv(file),
    label = "an ActiGraph csv export", unit = "line",
    block_units = function(sf, chunksize, part) ggir_pages(sf, chunksize) * 300,
    decoder = "actigraph_csv",
    read = function(file, sf, reader, arg) read_blocks(file, sf, reader),
    write = list(
      check = function(x, sf, start) write_check_whole_hz(sf),
      write = function(x, file, sf, start) {
        write_actigraph_csv_file(x, file, sf, start = format(start, "%Y-%m-%d %H:%M:%OS3", tz = "UTC"),
                                 stamps = "actilife")
      }),
    source = function(file, sf, chunksize, arg, format) source_csv(file, sf, chunksize, format)),
  # GENEActiv's csv export: refused where GGIR's result is asked for (GGIR
  # reads it no more), else read as the ad hoc csv file its header
  # describes (R/geneactiv-csv.R)
  geneactiv_csv = list(
    ggir_monitor = "geneactiv", ggir_codes = "2 2",
    ext = c(csv = NA, csv.gz = NA), detect = function(file) is_geneactiv_csv(file),
    adhoc_layout = function(file, arg, compat) {
      if (isTRUE(compat)) geneactiv_csv_refuse(file, arg)
      rmc_layout(rmc_values(geneactiv_csv_rmc(file, arg)), file, ggir = FALSE)
    },
    label = "a GENEActiv csv export", unit = "line", own_rate = TRUE,
    block_units = function(sf, chunksize, part) ggir_pages(sf, chunksize) * 300,
    decoder = NULL,
    read = function(file, sf, reader, arg) {
      d <- read_adhoc(file, reader, rmc_values(geneactiv_csv_rmc(file, arg)))$data
      if (is.list(attr(d, "input"))) attr(d, "input")$format <- "geneactiv_csv"
      d
    },
    source = function(file, sf, chunksize, arg, format) {
      open_source(file, sf, chunksize, arg, compat = FALSE)
    }),
  # Axivity's csv export (OMGUI): no header, lines of UNIX time stamp, x,
  # y, z; GGIR resamples each block onto the rate it finds from the first
  # 100000 time stamps (R/axivity-csv.R)
  axivity_csv = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "axivity", ggir_timegaps = TRUE,
    # GGIR forces UNIX stamps into the zone after reading them (a clock per
    # sample); text and ISO 8601 stamps the decoder reads in the zone itself,
    # and stamps across a change of the zone's offset it forces itself
    # (axivity_csv_zone(), axivity_csv_clock())
    local_clock = function(file, zone) axivity_csv_clock(file, zone),
    ggir_codes = "4 2", ggir_decimal = TRUE, ggir_zone_ambiguous = TRUE,
    ggir_read_opts = "interpolation", resample_fused = TRUE, fread_rule = TRUE,
    # the time stamps' layout and GGIR's rate (R/axivity-csv.R); in GGIR's
    # blocks of lines when streamed
    decoder_options = function(file, opts, sf, read) {
      # (found_sf: the rate an earlier opening of the file found, in place
      # of reading its first 100,000 stamps again)
      lay <- if (read$whole) axivity_csv_layout(file, sf) else {
        axivity_csv_layout(file, sf %||% read$found_sf, compat = isTRUE(read$compat),
                           zone = read$zone %||% "",
                           zone_arg = read$zone_arg %||% "desiredtz")
      }
      sf <- lay$sf
      opts[names(lay$opts)] <- lay$opts
      if (!read$whole) opts$block_lines <- format_block_units(read$format, sf, read$chunksize)
      list(opts = opts, sf = sf)
    },
    ext = c(csv = NA, csv.gz = NA), detect = function(file) is_axivity_csv(file),
    label = "an Axivity csv export", unit = "line",
    block_units = function(sf, chunksize, part) ggir_pages(sf, chunksize) * 300,
    decoder = "axivity_csv",
    read = function(file, sf, reader, arg) read_blocks(file, sf, reader),
    source = function(file, sf, chunksize, arg, format) source_axivity_csv(file, sf, chunksize, format)),
  csv = list(
    ext = c(csv = NA, csv.gz = NA), detect = NULL,
    fread_rule = TRUE, ggir_noise = "given",
    empty_why = "it has a header but no data lines",
    long_lines_hint = "Fields with comma decimals must be separated by semicolons",
    label = "a csv file of samples", unit = "line",
    block_units = function(sf, chunksize, part) ggir_pages(sf, chunksize) * 300,
    decoder = "csv",
    read = function(file, sf, reader, arg) read_plain_csv(file, arg),
    source = function(file, sf, chunksize, arg, format) source_csv(file, sf, chunksize, format)),
  # GGIR's ad hoc csv: never found from the file itself, but chosen by the
  # rmc.* parameters (rmc.firstrow.acc; R/adhoc-csv.R), which give its
  # layout to the csv decoder (and to `source`, as `layout`)
  adhoc_csv = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "ad_hoc", ggir_timegaps = TRUE, ggir_codes = "0 5", rmc = TRUE,
    ggir_noise = "default", ggir_zone_ambiguous = TRUE, resample_fused = TRUE, fread_rule = TRUE,
    # GGIR's block of lines: where its first line's text time is ambiguous
    # in a zone with daylight saving (rmc_time_opts())
    decoder_options = function(file, opts, sf, read) {
      if (!read$whole && !is.null(sf)) {
        opts$block_lines <- format_block_units(read$format, sf, read$chunksize)
      }
      list(opts = opts, sf = sf)
    },
    ext = c(csv = NA, csv.gz = NA), detect = function(file) FALSE,
    label = "an ad hoc csv file (GGIR's rmc.* parameters)", unit = "line",
    block_units = function(sf, chunksize, part) ggir_pages(sf, chunksize) * 300,
    decoder = "adhoc_csv",
    read = function(file, sf, reader, arg) {
      abort("Reading \"", file, "\" as an ad hoc csv file needs its rmc.* parameters.")
    },
    source = function(file, sf, chunksize, arg, format, layout = NULL) {
      source_adhoc(file, sf, chunksize, arg, layout, format)
    }),
  rds = list(
    ext = c(rds = ".rds"), detect = NULL,
    label = "an .rds file", unit = "unit", block_units = NULL, decoder = NULL,
    read = function(file, sf, reader, arg) read_rds(file, arg),
    source = function(file, sf, chunksize, arg, format) {
      rec <- read_file(file, sf, "native", arg)
      source_frame(rec$data, rec$sf, chunksize, arg)
    }),
  gt3x = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "actigraph", ggir_codes = "3 6",
    ext = c(gt3x = ".gt3x"), detect = NULL,
    # idle sleep: GGIR's batches leave it out; gravcal's own streams put it
    # back as zeros where it was, as a whole read does (as read.gt3x's
    # imputeZeroes = TRUE, to its last sample time; calibration skips them)
    decoder_options = function(file, opts, sf, read) {
      if (read$whole) opts$compat <- 1
      if (read$whole || !isTRUE(read$compat)) opts$impute_zeroes <- 1
      list(opts = opts, sf = sf)
    },
    label = "an ActiGraph .gt3x file", unit = "record", own_rate = TRUE,
    local_clock = "sample", ggir_timegaps = TRUE,
    ggir_read_stops = function(src, part) gt3x_ggir_stops(src),
    ggir_inspect = function(file, tz) ggir_inspect_gt3x(file, tz, decoder = "gt3x"),
    block_units = function(sf, chunksize, part) (12 * 3600) * chunksize,  # seconds
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
    source = function(file, sf, chunksize, arg, format) source_gt3x(file, chunksize, format)),
  cwa = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "axivity", ggir_codes = "4 4", ggir_zone_ambiguous = TRUE,
    ggir_calendar = TRUE, resample_fused = TRUE,
    ggir_read_opts = c("interpolation", "frequency_tol"),
    ext = c(cwa = ".cwa"), detect = NULL,
    # GGIR's zone for a GGIR-compatible read (R/zone.R)
    r_options = function(file, options, zone) {
      if (!is.null(zone) && !identical(as.numeric(options$compat %||% 1), 0)) {
        zo <- zone_options(zone)
        options[names(zo)] <- zo
      }
      options
    },
    ggir_block_qclog = function(src, from) cwa_qclog(src, from),
    ggir_read_stops = function(src, part) cwa_ggir_stops(src),
    label = "an Axivity .cwa file", unit = "block", own_rate = TRUE,
    # 512-byte blocks of 80 samples (GGIR's count, whatever the packing)
    block_units = function(sf, chunksize, part) round(12 * 3600 * sf / 80 * chunksize),
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
    source = function(file, sf, chunksize, arg, format) source_cwa(file, chunksize, format)),
  # Movisens: a unisens folder (unisens.xml, acc.bin, temp.bin), named by
  # the folder or its acc.bin (GGIR's filename); GGIR reads it in blocks of
  # sf * 60 * 1440 / 2 samples whatever chunksize, and assumes 64 Hz
  movisens = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "movisens", ggir_codes = "5 1", ggir_clip = 15.5,
    ggir_read_opts = "interpolation", resample_fused = TRUE,
    decoder_options = function(file, opts, sf, read) {
      if (!read$whole) opts$block_samples <- movisens_block(file, read$part)
      list(opts = opts, sf = sf)
    },
    r_options = function(file, options, zone) {
      nums <- unisens_r_numbers(file)
      options[names(nums)] <- nums
      options
    },
    # GGIR takes every Movisens recording for 64 Hz (g.inspectfile)
    ggir_check_sf = function(file, sf) {
      if (!identical(sf, 64)) {
        abort("\"", file, "\" is a Movisens recording at ", format(sf), " Hz; GGIR ",
              "reads every Movisens recording as 64 Hz, so its results for this one ",
              "would be wrong: use calibrate() (gravcal's own methods) instead.")
      }
    },
    ggir_start = function(file, p) movisens_start(file, p),
    ext = c(bin = "Movisens (a unisens folder or its acc.bin)"),
    detect = function(file) is_movisens_bin(file),
    label = "a Movisens recording", unit = "sample", own_rate = TRUE,
    block_units = function(sf, chunksize, part) movisens_block(NULL, part),
    decoder = "movisens",
    read = function(file, sf, reader, arg) read_blocks(file, sf, reader),
    write = list(
      folder = TRUE,
      check = function(x, sf, start) NULL,
      write = function(x, file, sf, start) {
        write_movisens(x, file, sf = sf, start = start, temp = !is.null(x$temperature))
      }),
    source = function(file, sf, chunksize, arg, format) source_movisens(file, format)),
  geneactiv = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "geneactiv", ggir_codes = "2 1",
    ggir_read_opts = "interpolation", resample_fused = TRUE,
    # GGIR's g.readaccfile takes a block with fewer rows than its pages hold
    # for the last one; after its resampling of a rate that rounds down
    # (12.5 Hz to 12) every block has fewer, so GGIR stops after the first
    ggir_short_rows = function(units) units * 300,
    # damaged pages: read as GGIRread reads them (decode_geneactiv.hpp),
    # but where it stops or goes where the decoder does not follow
    ggir_stops = function(src) geneactiv_ggir_stops(src, "getmeta"),
    ggir_read_stops = function(src, part) geneactiv_ggir_stops(src, part),
    ggir_damage_warning = function(src) geneactiv_damage_warning(src),
    r_options = function(file, options, zone) {
      lo <- geneactiv_light_header(file)
      lo <- lo[setdiff(names(lo), names(options))]
      options[names(lo)] <- lo
      options
    },
    ext = c(bin = "GENEActiv .bin"), detect = function(file) !is_parmay_bin(file),
    label = "a GENEActiv .bin file", unit = "page", own_rate = TRUE, local_clock = "block",
    block_units = function(sf, chunksize, part) ggir_pages(sf, chunksize),
    decoder = "geneactiv",
    read = function(file, sf, reader, arg) read_blocks(file, sf, reader),
    write = list(
      check = function(x, sf, start) {
        if (nrow(x) < 300) abort("`x` has ", nrow(x), " samples, fewer than one GENEActiv page (300).")
      },
      write = function(x, file, sf, start) {
        write_geneactiv_bin(x, file, sf = sf, start = format(start, "%Y-%m-%d %H:%M:%OS3", tz = "UTC"))
      }),
    source = function(file, sf, chunksize, arg, format) source_geneactiv(file, chunksize, format)),
  # Parmay Matrix: "MDTC" at byte 512. GGIRread's reader reads from the
  # block's first packet to the end of the file whatever end it is given, so
  # GGIR's first block is the whole file (and its last). Its times are the
  # packets' UTC seconds, read in no zone (no local_clock); GGIR's
  # g.getmeta() takes the dynamic range from the header (meta_nonwear())
  # and returns the reader's log of the packets as M$QClog
  # (parmay_qclog())
  parmay = list(
    ggir_getmeta = TRUE,
    ggir_monitor = "parmay_mtx", ggir_codes = "7 1",
    ggir_read_opts = "interpolation", resample_fused = TRUE,
    ggir_qclog = function(src) parmay_qclog(src),
    ggir_stops = function(src) parmay_ggir_stops(src),
    ext = c(bin = "Parmay Matrix .bin"), detect = function(file) is_parmay_bin(file),
    label = "a Parmay Matrix .bin file", unit = "packet", own_rate = TRUE,
    block_units = function(sf, chunksize, part) 2^52,
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
    source = function(file, sf, chunksize, arg, format) source_parmay(file, format))
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

# The format's local_clock (see the top of this file) for `file` read in
# `zone` (configtz, else desiredtz): where GGIR's reader takes the file's
# clock times as times in the zone and the decoder gives them as UTC
# ("block", "sample"), or NULL.
format_local_clock <- function(format, file, zone) {
  lc <- format_entry(format)$local_clock
  if (is.function(lc)) lc(file, zone) else lc
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

format_block_units <- function(format, sf, chunksize, part = "calibrate") {
  format_entry(format)$block_units(sf, chunksize, part)
}

# Samples in memory (a data frame) are cut as a csv file of samples.
frame_block_units <- function(sf, chunksize) {
  format_block_units("csv", sf, chunksize)
}

# The format the rmc.* parameters choose (GGIR's ad hoc csv).
rmc_format <- function() {
  names(Filter(function(f) isTRUE(f$rmc), recording_formats))
}

# The native decoder's options and rate for `format` (its
# decoder_options(), where it has one): list(opts, sf).
format_decoder_options <- function(format, file, opts, sf, read) {
  f <- format_entry(format)$decoder_options
  if (is.null(f)) return(list(opts = opts, sf = sf))
  read$format <- format
  f(file, opts, sf, read)
}
