# GGIR's metashort and metalong as its g.getmeta() fills them: character
# matrices written block by block from row `count`, rows repeated where a
# long time gap is imputed as whole epochs (its impute_at_epoch_level()),
# the rows from `count` on cut at the end. Here a sheet is a list of
# columns (numeric ones hold what GGIR's text will be read back as; text
# ones, a myfun's, hold GGIR's text) and `count`; a row past a column's end
# is GGIR's blank, " " (NA once read as a number).
#
# Each column is its written values (`cols`) and the blocks' writes not yet
# laid into it (`puts`: list(at, v) in the order written), laid in when the
# column is read (sheet_flat()): a week's columns grown block by block
# would copy every earlier block at each write, garbage that R's collector
# leaves in the process while the block store is held (tens of MB with
# every metric).

sheet_new <- function(numeric = character(0), text = character(0)) {
  cols <- c(stats::setNames(rep(list(numeric(0)), length(numeric)), numeric),
            stats::setNames(rep(list(character(0)), length(text)), text))
  list(cols = cols, puts = stats::setNames(rep(list(list()), length(cols)), names(cols)),
       count = 1)
}

sheet_blank <- function(col, n) if (is.character(col)) rep(" ", n) else rep(NA_real_, n)

sheet_extend <- function(col, n) {
  if (length(col) < n) col <- c(col, sheet_blank(col, n - length(col)))
  col
}

# `values`: a named list of vectors (or a matrix, by column names), written
# from row `count` (a number into a text column becomes R's text of it, as
# in GGIR's matrix); a column not yet in the sheet is a numeric one.
sheet_put <- function(sh, values) {
  if (is.matrix(values)) {
    values <- stats::setNames(lapply(seq_len(ncol(values)), function(j) values[, j]),
                              colnames(values))
  }
  for (nm in names(values)) {
    v <- values[[nm]]
    if (!length(v)) next
    if (is.null(sh$cols[[nm]])) sh$cols[[nm]] <- numeric(0)
    sh$puts[[nm]] <- c(sh$puts[[nm]], list(list(at = sh$count, v = v)))
  }
  sh
}

# Column `nm` with its writes laid in, as writing each in turn would leave
# it: extended with blanks of the column's type at each write, a text write
# into a numeric column turning it (and the blanks after it) into text.
# Where no write changes the column's type, it is extended once.
sheet_flat <- function(sh, nm) {
  col <- sh$cols[[nm]]
  puts <- sh$puts[[nm]]
  if (!length(puts)) return(col)
  same_type <- is.character(col) ||
    all(vapply(puts, function(w) is.numeric(w$v) || is.logical(w$v), TRUE))
  if (same_type) {
    col <- sheet_extend(col, max(vapply(puts, function(w) w$at + length(w$v) - 1, 0)))
  }
  for (w in puts) {
    end <- w$at + length(w$v) - 1
    if (!same_type) col <- sheet_extend(col, end)
    col[w$at:end] <- w$v
  }
  col
}

sheet_advance <- function(sh, n) {
  sh$count <- sh$count + n
  sh
}

# GGIR's epoch-level imputation: rows `gap_index` take the values `set`
# (a named list) and are repeated `gapsize` times; `count` moves on by the
# rows added. Repeated indices are merged first, as GGIR merges them (its
# loop over the repeated values, negative indexing and all: an index found
# three times leaves no gap).
sheet_impute <- function(sh, gap_index, gapsize, set) {
  if (any(duplicated(gap_index))) {
    for (d in gap_index[which(duplicated(gap_index))]) {
      same <- which(gap_index == d)
      drop <- same[-1]
      gap_index <- gap_index[-drop]
      gapsize[same[1]] <- sum(gapsize[same]) - (length(same) - 1)
      gapsize <- gapsize[-drop]
    }
  }
  for (nm in names(sh$cols)) sh$cols[[nm]] <- sheet_flat(sh, nm)
  sh$puts[] <- list(list())
  n <- max(c(lengths(sh$cols), gap_index))
  sh$cols <- lapply(sh$cols, sheet_extend, n)
  for (nm in names(set)) sh$cols[[nm]][gap_index] <- set[[nm]]
  times <- rep(1, n)
  times[gap_index] <- as.numeric(gapsize)
  rows <- rep(seq_len(n), times)
  sh$cols <- lapply(sh$cols, function(col) col[rows])
  sh$count <- sh$count + (length(rows) - n)
  sh
}

# The rows written, 1 to count - 1 (GGIR's cut), of column `nm`.
sheet_column <- function(sh, nm) {
  sheet_extend(sheet_flat(sh, nm), sh$count - 1)[seq_len(sh$count - 1)]
}
