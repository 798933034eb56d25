# Axivity's csv export (OMGUI): no header, one line per sample: time stamp
# (UNIX seconds), x, y, z in g. GGIR 3.3-9 (g.inspectfile(),
# g.readaccfile()) takes a csv file whose first line is not ActiGraph's and
# whose lines have 4 or more fields for one of these; it finds the rate from
# the time stamps of lines 2 to 100001 (samples over seconds, rounded down
# to a multiple of 5 Hz) and resamples every block of lines linearly onto
# that rate, from the block's first time stamp to its last (the grid's last
# point dropped). gravcal's csv decoder reads the lines and its resampler
# (decode_ggir_resample.hpp) does the rest in GGIR-compatible mode; its own
# reads keep the samples as stored.

# Whether `file` looks like an Axivity csv export: not ActiGraph's, a first
# line of at least 4 comma-separated fields with numbers in fields 2 to 4
# (so not a line of column names) and a number or date-time in field 1.
is_axivity_csv <- function(file) {
  if (is_actigraph_csv(file)) return(FALSE)
  # the first line's bytes: a binary file named .csv is not text
  con <- if (grepl("\\.gz$", file, ignore.case = TRUE)) gzfile(file, "rb") else file(file, "rb")
  on.exit(close(con))
  b <- readBin(con, "raw", 512)
  nl <- match(as.raw(10), b)
  if (is.na(nl)) return(FALSE)
  b <- b[seq_len(nl - 1)]
  b <- b[b != as.raw(13)]
  if (!length(b) || any(b < as.raw(32) | b >= as.raw(127))) return(FALSE)
  f <- trimws(strsplit(rawToChar(b), ",", fixed = TRUE)[[1]])
  if (length(f) < 4) return(FALSE)
  num <- !is.na(suppressWarnings(as.numeric(f[1:4])))
  all(num[2:4]) && (num[1] || grepl("^[0-9]{4}-[0-9]{2}-[0-9]{2}", f[1]))
}

# The rate GGIR finds in an Axivity csv export: n / (t[n] - t[1]) over the
# time stamps of lines 2 to 100001, rounded down to a multiple of 5.
axivity_csv_sf <- function(file) {
  t <- utils::read.csv(file, nrows = 1e5)[[1]]
  if (!is.numeric(t)) {
    abort("\"", file, "\" is an Axivity csv export with text time stamps; gravcal reads ",
          "those with UNIX time stamps (OMGUI's export option), as GGIR advises.")
  }
  sf <- floor((length(t) / (t[length(t)] - t[1])) / 5) * 5
  if (!isTRUE(sf > 0)) {
    abort("The sampling frequency of the Axivity csv export \"", file, "\" is unknown: give `sf`.")
  }
  sf
}

# The csv decoder's layout for an Axivity csv export (time stamp, x, y, z),
# and its rate: `sf` when given, else GGIR's.
axivity_csv_layout <- function(file, sf = NULL) {
  if (is.null(sf)) sf <- axivity_csv_sf(file)
  check_sf(sf)
  list(sf = sf, opts = list(sf = as.numeric(sf), grid_sf = as.numeric(sf), skip = 0,
                            col_time = 1, time_div = 1, col_x = 2, col_y = 3, col_z = 4))
}

# The file block by block through data.table::fread() and GGIRread's
# resampling (reader = "reference").
source_axivity_csv <- function(file, sf, chunksize) {
  if (!requireNamespace("data.table", quietly = TRUE)) {
    abort("Reading Axivity csv files with reader = \"reference\" needs the data.table package.")
  }
  need_ggirread("Axivity csv")
  sf <- axivity_csv_layout(file, sf)$sf
  B <- format_block_units("axivity_csv", sf, chunksize)
  list(format = "axivity_csv", sf = sf, temperature = FALSE,
       read = function(i) {
         d <- tryCatch(data.table::fread(file, skip = (i - 1) * B, nrows = B, header = FALSE,
                                         showProgress = FALSE, data.table = FALSE),
                       error = function(e) NULL)
         if (is.null(d) || nrow(d) < 2 || ncol(d) < 4) return(NULL)
         t <- as.numeric(d[[1]])
         grid <- seq(t[1], t[length(t)], by = 1 / sf)
         grid <- grid[-length(grid)]
         a <- GGIRread::resample(as.matrix(d[, 2:4]), t, grid, nrow(d), 1L)
         list(data = data.frame(x = a[, 1], y = a[, 2], z = a[, 3]), last = nrow(d) < B)
       })
}
