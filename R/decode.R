# Native decoders for device files (inst/include/gravcal/decoders/decode*.hpp), as
# seen from R: open a file, pull blocks of samples, read what was skipped.

# The one call that opens a native decoder: the options with what this R
# itself decides (with_resample_fused(): GGIRread's rounding, fread's rule
# for numbers; a Movisens unisens.xml's numbers as R's as.numeric() reads
# them; a .cwa calendar's offsets in GGIR's zone), as gc_decoder_open() answers (ptr NULL, with error or unsupported,
# when it cannot).
decoder_open <- function(file, format, options = list()) {
  # "zone": GGIR's zone, for the format's r_options() (R/formats.R)
  zone <- options$zone
  options$zone <- NULL
  add <- format_entry(format)$r_options
  if (!is.null(add)) options <- add(file, options, zone)
  # (a second thread inflates a .gt3x's data ahead of the decoder)
  if (is.null(options$threads)) options$threads <- gravcal_threads()
  gc_decoder_open(path.expand(file), format, with_resample_fused(options, format))
}

# What GGIRread 1.2.0's readGENEActiv() reads from a GENEActiv header for its
# light column, read as it reads it: among the file's first 69 lines
# (readLines()), the first with "Lux", the first with "Volts" (as.numeric()
# once "Lux:", "Volts:" are taken out; NA where there is none) and whether
# the first with "Device Model" ends in "1.1" once "Device Model:" and
# blanks are taken out. As options light_lux, light_volts, light_model11
# for the decoder (decode_geneactiv.hpp); nothing when the file's first
# 64 kB cannot be read as lines (the decoder reads the header itself).
geneactiv_light_header <- function(file) {
  b <- tryCatch(suppressWarnings(readBin(file, raw(), 65536)), error = function(e) raw(0))
  if (!length(b)) return(list())
  con <- rawConnection(b)
  on.exit(close(con))
  tryCatch(suppressWarnings({
    fh <- readLines(con, 69)
    first <- function(key) fh[grep(key, fh)[1]]
    model <- gsub(" ", "", gsub("Device Model:", "", first("Device Model")))
    list(light_lux = as.numeric(gsub("Lux:", "", first("Lux"))),
         light_volts = as.numeric(gsub("Volts:", "", first("Volts"))),
         light_model11 = as.numeric(grepl("1\\.1$", model)))
  }), error = function(e) list())
}

# Open `file` with the native decoder of `format`; `options` is a named list
# of single numbers or strings for the decoder. An error naming the file when
# it cannot be read as that format.
native_open <- function(file, format, options = list(), arg = "file") {
  r <- decoder_open(file, format, options)
  if (is.null(r$ptr)) native_open_error(file, format, r$error, arg)
  r
}

native_format_name <- function(format) format_entry(format)$label %||% format

# The next block of at most `max_units` format units (NULL: no limit) and
# `capacity` samples, as list(cols = list(x, y, z, temperature, time,
# light), from = 0, to = n, units, done). temperature, time and light are
# NULL unless asked for and the format has them (light: .cwa and GENEActiv
# .bin; h$info$light).
native_block <- function(h, max_units = NULL, capacity = 1e6,
                         temperature = TRUE, time = FALSE, light = TRUE) {
  b <- gc_decoder_read(h$ptr, if (is.null(max_units)) -1 else max_units,
                       capacity, temperature, time, light)
  list(cols = list(x = b$x, y = b$y, z = b$z, temperature = b$temperature,
                   time = b$time, light = b$light),
       from = 0, to = b$n, units = b$units, done = b$done)
}

# What the decoder has read and skipped so far, as a list (see Report in
# decode.hpp).
native_report <- function(h) gc_decoder_report(h$ptr)

# A whole file as a data frame (x, y, z, and temperature, time and light
# where the file has them and they are asked for), with attributes `sf`,
# `info` and `report`. For tests and read_recording(); calibration streams
# instead.
native_read_all <- function(file, format, options = list(), time = TRUE,
                            chunk = 65536, arg = "file", light = TRUE) {
  h <- native_open(file, format, options, arg)
  on.exit(gc_decoder_close(h$ptr))
  native_samples(h, time, chunk, light)
}

# Every sample of an open decoder `h`, through the pump (`chunk` samples a
# write), as native_read_all() gives them.
native_samples <- function(h, time = TRUE, chunk = 65536, light = TRUE) {
  d <- as.data.frame(gc_pump(gc_source_decoder(h$ptr), "samples",
                             list(time = as.numeric(time && isTRUE(h$info$time)),
                                  chunk = chunk,
                                  light = as.numeric(light && isTRUE(h$info$light)))))
  attr(d, "sf") <- h$info$sf
  attr(d, "info") <- h$info
  attr(d, "report") <- native_report(h)
  d
}
