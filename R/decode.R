# Native decoders for device files (inst/include/gravcal/decode*.hpp), as
# seen from R: open a file, pull blocks of samples, read what was skipped.

# Open `file` with the native decoder of `format`; `options` is a named list
# of single numbers or strings for the decoder. An error naming the file when
# it cannot be read as that format.
native_open <- function(file, format, options = list(), arg = "file") {
  r <- gc_decoder_open(path.expand(file), format, options)
  if (is.null(r$ptr)) native_open_error(file, format, r$error, arg)
  r
}

native_format_name <- function(format) format_entry(format)$label %||% format

# The next block of at most `max_units` format units (NULL: no limit) and
# `capacity` samples, as list(cols = list(x, y, z, temperature, time), from
# = 0, to = n, units, done).
native_block <- function(h, max_units = NULL, capacity = 1e6,
                         temperature = TRUE, time = FALSE) {
  b <- gc_decoder_read(h$ptr, if (is.null(max_units)) -1 else max_units,
                       capacity, temperature, time)
  list(cols = list(x = b$x, y = b$y, z = b$z, temperature = b$temperature,
                   time = b$time),
       from = 0, to = b$n, units = b$units, done = b$done)
}

# What the decoder has read and skipped so far, as a list (see Report in
# decode.hpp).
native_report <- function(h) gc_decoder_report(h$ptr)

# A whole file as a data frame (x, y, z, and temperature and time where the
# file has them), with attributes `sf`, `info` and `report`. For tests and
# read_recording(); calibration streams instead.
native_read_all <- function(file, format, options = list(), time = TRUE,
                            chunk = 1e6, arg = "file") {
  h <- native_open(file, format, options, arg)
  on.exit(gc_decoder_close(h$ptr))
  parts <- list()
  repeat {
    b <- native_block(h, NULL, chunk, TRUE, time)
    n <- b$to
    if (n > 0) {
      cl <- b$cols
      keep <- Filter(Negate(is.null), cl)
      parts[[length(parts) + 1]] <- lapply(keep, function(v) v[seq_len(n)])
    }
    if (b$done) break
    if (n == 0 && b$units == 0) break
  }
  cols <- c("x", "y", "z", "temperature", "time")
  out <- lapply(stats::setNames(cols, cols), function(nm) {
    unlist(lapply(parts, `[[`, nm), use.names = FALSE)
  })
  out <- Filter(Negate(is.null), out)
  if (!length(out)) out <- list(x = numeric(0), y = numeric(0), z = numeric(0))
  d <- as.data.frame(out)
  attr(d, "sf") <- h$info$sf
  attr(d, "info") <- h$info
  attr(d, "report") <- native_report(h)
  d
}
