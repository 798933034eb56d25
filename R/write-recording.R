#' Write samples as a device file
#'
#' Writes accelerometer samples (for example a [simulate_recording()] with a
#' known calibration error) as a file of one of the device formats gravcal
#' and GGIR read: a recording whose truth is known, to test a pipeline from
#' its first step (GGIR's part 1, gravcal's calibration, a cohort run) on
#' the files it will meet. The files follow the formats' published
#' descriptions; they are what the package's own tests read.
#'
#' What each format keeps, as the devices do:
#' * `"cwa"` (Axivity, `.cwa`): samples packed as AX3 devices pack them
#'   (10 bits and an exponent, about 4 mg steps at +-8 g); temperature and
#'   light one value a block of 120 samples (the block's first); rates
#'   3200 / 2^k Hz (6.25 to 3200).
#' * `"geneactiv"` (GENEActiv, `.bin`): 12-bit counts (about 3 mg, +-8 g),
#'   temperature a page of 300 samples (its mean); a last part-page is
#'   left out, as the device's pages are whole.
#' * `"gt3x"` (ActiGraph, `.gt3x`): 16-bit counts of 1/256 g, no
#'   temperature (the format's log holds none: a temperature column is not
#'   written, with a warning); a whole number of Hz.
#' * `"actigraph_csv"` (ActiLife's csv export, `.csv`): ActiLife's header
#'   and its time stamps, values to 3 decimals.
#' * `"movisens"` (a unisens folder, `file` its path): acceleration in
#'   1/2048 g, temperature at 1 Hz.
#' * `"parmay"` (Parmay Matrix, `.bin`): 16-bit values over +-8 g,
#'   temperature two values a packet of 60 s; whole seconds for `start`.
#'
#' Values beyond a format's range are clipped, as a device clips them.
#'
#' @param x The samples: a data frame (or matrix) with columns `x`, `y`, `z`
#'   in g, optionally `temperature` (degree C) and `light` (0 to 1023, for
#'   `"cwa"`), and `time`; or a recording from [read_recording()].
#' @param file The path to write (for `"movisens"` a folder, which must not
#'   exist or be empty). An existing file is never replaced unless
#'   `overwrite = TRUE`.
#' @param sf Sampling rate in Hz; when not given, a recording's, or a
#'   [simulate_recording()]'s (its `truth`).
#' @param format One of `"cwa"`, `"geneactiv"`, `"gt3x"`, `"actigraph_csv"`,
#'   `"movisens"`, `"parmay"`; by default from `file`'s extension (`.cwa`,
#'   `.bin`: GENEActiv, `.gt3x`, `.csv`: ActiGraph's export).
#' @param start The first sample's time (POSIXct, or text read in UTC); by
#'   default `x$time[1]`, else 2024-01-01 00:00:00 UTC.
#' @param overwrite Replace an existing `file`.
#' @return `file`, invisibly.
#' @seealso [simulate_recording()], [read_recording()].
#' @export
#' @examples
#' rec <- simulate_recording(hours = 2, sf = 25, seed = 1)  # known errors: attr(rec, "truth")
#' f <- write_recording(rec, tempfile(fileext = ".cwa"), sf = 25)
#' back <- read_recording(f)
#' back$sf
#' head(back$data)
write_recording <- function(x, file, sf = NULL, format = NULL, start = NULL,
                            overwrite = FALSE) {
  if (is.list(x) && !is.data.frame(x) && !is.null(x$data)) {
    if (is.null(sf)) sf <- x$sf
    x <- x$data
  }
  if (is.matrix(x)) x <- as.data.frame(x)
  if (!is.data.frame(x) || !all(c("x", "y", "z") %in% names(x))) {
    abort("`x` must be a data frame with columns x, y and z (g), or a recording from ",
          "read_recording(), not ", describe(x), ".")
  }
  if (!nrow(x)) abort("`x` has no samples.")
  for (v in intersect(c("x", "y", "z", "temperature", "light"), names(x))) {
    if (!is.numeric(x[[v]]) || !all(is.finite(x[[v]]))) {
      abort("`x$", v, "` must be finite numbers.")
    }
  }
  if (is.null(sf)) sf <- attr(x, "sf") %||% attr(x, "truth")$sf
  if (is.null(sf)) abort("`sf` is needed: the sampling rate in Hz.")
  check_number(sf, "sf", min = 0, min_inclusive = FALSE)
  if (!is.character(file) || length(file) != 1 || is.na(file) || !nzchar(file)) {
    abort("`file` must be one path, not ", describe(file), ".")
  }
  check_flag(overwrite, "overwrite")
  if (is.null(format)) format <- write_format_of(file)
  fe <- write_entry(format)
  if (is.null(start)) {
    start <- if (inherits(x$time, "POSIXct")) x$time[1] else
      as.POSIXct("2024-01-01 00:00:00", tz = "UTC")
  }
  if (is.character(start)) {
    s <- as.POSIXct(start, tz = "UTC", tryFormats = c("%Y-%m-%d %H:%M:%OS", "%Y-%m-%d"),
                    optional = TRUE)
    if (length(s) != 1 || is.na(s)) {
      abort("`start` must be a time (POSIXct, or text such as \"2024-03-04 09:00:00\"), not ",
            describe(start), ".")
    }
    start <- s
  }
  if (!inherits(start, "POSIXct") || length(start) != 1 || is.na(start)) {
    abort("`start` must be one time (POSIXct), not ", describe(start), ".")
  }
  if (!dir.exists(dirname(file))) abort("`file`: the folder \"", dirname(file), "\" does not exist.")
  folder <- isTRUE(fe$folder)
  taken <- if (folder) dir.exists(file) && length(dir(file, all.files = TRUE, no.. = TRUE)) else
    file.exists(file)
  if (taken && !overwrite) {
    abort("`file`: \"", file, "\" exists; give `overwrite = TRUE` to replace it.")
  }
  if (!folder) check_regular_file(file, "file", missing_ok = TRUE)
  fe$check(x, sf, start)
  # written beside the target, then moved onto it: a failure leaves no
  # half-written file, and an existing one stays until the new one is whole
  tmp <- tempfile(".write-", tmpdir = dirname(file),
                  fileext = if (folder) "" else paste0(".", tools::file_ext(file)))
  on.exit(unlink(tmp, recursive = TRUE), add = TRUE)
  fe$write(x, tmp, sf, start)
  if (folder && dir.exists(file)) unlink(file, recursive = TRUE)
  if (!file.rename(tmp, file)) abort("Could not write \"", file, "\".")
  invisible(file)
}

# The format a path's extension names, for write_recording(): the first
# format in the registry with that extension whose writer writes a file
# (.bin: GENEActiv, before Parmay Matrix; .csv: ActiGraph's export).
write_format_of <- function(file) {
  ext <- tolower(tools::file_ext(file))
  w <- names(Filter(function(e) !isTRUE(e$folder), write_formats()))
  has <- vapply(w, function(f) ext %in% names(recording_formats[[f]]$ext), TRUE)
  f <- if (nzchar(ext) && any(has)) w[has][1]
  if (is.null(f)) {
    abort("`format`: \"", basename(file), "\" has no extension that names a format ",
          "(.cwa, .bin, .gt3x, .csv); give `format` (one of ",
          paste0("\"", names(write_formats()), "\"", collapse = ", "), ").")
  }
  f
}

write_entry <- function(format) {
  w <- write_formats()
  if (!is.character(format) || length(format) != 1 || !format %in% names(w)) {
    abort("`format` must be one of ", paste0("\"", names(w), "\"", collapse = ", "),
          ", not ", describe(format), ".")
  }
  w[[format]]
}

# The formats write_recording() writes: the registry's entries with a
# `write` (R/formats.R), by name.
write_formats <- function() {
  w <- lapply(recording_formats, `[[`, "write")
  w[!vapply(w, is.null, TRUE)]
}

write_check_whole_hz <- function(sf) {
  if (sf != round(sf)) abort("`sf`: this format holds a whole number of Hz, not ", sf, ".")
}
