#' Read a raw accelerometer recording from a file
#'
#' Reads the whole file into memory and returns its samples in g with the
#' sampling frequency. Formats, by file extension:
#' * `.rds`: a data frame as written by `saveRDS()` (for example the bundled
#'   example, see [gravcal_example()]); `sf` from its `sf` attribute or its
#'   `time` column;
#' * `.csv`, `.csv.gz`: a header line with columns `x`, `y`, `z` and
#'   optionally `time` and `temperature`; `sf` from `time` or the argument;
#' * `.gt3x`: ActiGraph, through the read.gt3x package (a Suggests package);
#'   idle-sleep gaps come back as zeros, which [rest_windows()] skips.
#'
#' @param file Path of the file.
#' @param sf Sampling frequency in Hz, when the file does not give it.
#' @return A list with `data` (a data frame with `x`, `y`, `z` and, where the
#'   file has them, `time` and `temperature`) and `sf`.
#' @export
#' @examples
#' rec <- read_recording(gravcal_example())
#' rec$sf
#' head(rec$data)
read_recording <- function(file, sf = NULL) {
  if (!is.character(file) || length(file) != 1 || is.na(file)) {
    abort("`file` must be a single file path, not ", describe(file), ".")
  }
  if (!file.exists(file)) abort("`file` does not exist: \"", file, "\".")
  ext <- tolower(sub(".*?\\.((csv\\.gz)|[^.]+)$", "\\1", basename(file)))
  data <- switch(ext,
    rds = readRDS(file),
    csv = , "csv.gz" = utils::read.csv(file, stringsAsFactors = FALSE),
    gt3x = read_gt3x_file(file),
    abort("`file` has an unsupported extension \".", ext, "\"; gravcal ",
          "reads .rds, .csv, .csv.gz and .gt3x."))
  if (!is.data.frame(data)) {
    abort("`file` does not hold a data frame of samples: \"", file, "\".")
  }
  names(data) <- tolower(names(data))
  if (is.null(sf)) sf <- attr(data, "sf")
  if (is.null(sf) && !is.null(attr(data, "sample_rate"))) {
    sf <- attr(data, "sample_rate")
  }
  if (is.null(sf) && "time" %in% names(data)) sf <- sf_from_time(data$time)
  if (is.null(sf)) {
    abort("The sampling frequency of \"", file, "\" is unknown: give `sf`.")
  }
  check_sf(sf)
  list(data = data, sf = sf)
}

read_gt3x_file <- function(file) {
  if (!requireNamespace("read.gt3x", quietly = TRUE)) {
    abort("Reading .gt3x files needs the read.gt3x package: ",
          "install.packages(\"read.gt3x\").")
  }
  d <- read.gt3x::read.gt3x(file, asDataFrame = TRUE, imputeZeroes = TRUE,
                            verbose = FALSE)
  sf <- attr(d, "sample_rate")
  out <- data.frame(time = d$time, x = d$X, y = d$Y, z = d$Z)
  if ("temperature" %in% tolower(names(d))) {
    out$temperature <- d[[which(tolower(names(d)) == "temperature")[1]]]
  }
  attr(out, "sf") <- sf
  out
}

# Sampling frequency from time stamps: the median step, in Hz.
sf_from_time <- function(time) {
  t <- as.numeric(time)
  if (length(t) < 2) return(NULL)
  step <- stats::median(diff(t[seq_len(min(length(t), 10000))]))
  if (!is.finite(step) || step <= 0) return(NULL)
  signif(1 / step, 6)
}

#' Path of the bundled example recording
#'
#' A 12-hour recording at 10 Hz with temperature, made by
#' [simulate_recording()] with known calibration errors (script
#' `data-raw/example.R`); its truth is in `attr(readRDS(path), "truth")`.
#' @return The path of the `.rds` file.
#' @export
#' @examples
#' rec <- readRDS(gravcal_example())
#' attr(rec, "truth")$params
gravcal_example <- function() {
  system.file("extdata", "example.rds", package = "gravcal", mustWork = TRUE)
}
