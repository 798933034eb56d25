# Native decoders for device files (inst/include/gravcal/decode*.hpp), as
# seen from R: open a file, pull blocks of samples, read what was skipped.

# The one call that opens a native decoder: the options with what this R
# itself decides (with_resample_fused(): GGIRread's rounding, fread's rule
# for numbers; a Movisens unisens.xml's numbers as R's as.numeric() reads
# them; a .cwa calendar's offsets in GGIR's zone), as gc_decoder_open() answers (ptr NULL, with error or unsupported,
# when it cannot).
decoder_open <- function(file, format, options = list()) {
  # "zone": GGIR's zone for a GGIR-compatible .cwa read (R/zone.R)
  if (!is.null(tz <- options$zone)) {
    options$zone <- NULL
    if (format == "cwa" && !identical(as.numeric(options$compat %||% 1), 0)) {
      zo <- zone_options(tz)
      options[names(zo)] <- zo
    }
  }
  if (format == "movisens") {
    nums <- unisens_r_numbers(file)
    options[names(nums)] <- nums
  }
  gc_decoder_open(path.expand(file), format, with_resample_fused(options, format))
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
