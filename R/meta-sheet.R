# GGIR's metashort and metalong as its g.getmeta() fills them: character
# matrices written block by block from row `count`, rows repeated where a
# long time gap is imputed as whole epochs (its impute_at_epoch_level()),
# the rows from `count` on cut at the end. Here a sheet is a list of
# columns (numeric ones hold what GGIR's text will be read back as; text
# ones, a myfun's, hold GGIR's text) and `count`; a row past a column's end
# is GGIR's blank, " " (NA once read as a number).

sheet_new <- function(numeric = character(0), text = character(0)) {
  cols <- c(stats::setNames(rep(list(numeric(0)), length(numeric)), numeric),
            stats::setNames(rep(list(character(0)), length(text)), text))
  list(cols = cols, count = 1)
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
    end <- sh$count + length(v) - 1
    col <- sheet_extend(if (is.null(sh$cols[[nm]])) numeric(0) else sh$cols[[nm]], end)
    col[sh$count:end] <- v
    sh$cols[[nm]] <- col
  }
  sh
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
  sheet_extend(sh$cols[[nm]], sh$count - 1)[seq_len(sh$count - 1)]
}
