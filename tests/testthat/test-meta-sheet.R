# g.getmeta()'s sheets (R/meta-sheet.R): the blocks' writes kept apart and
# laid in when a column is read must give the column that writing each one
# into it in turn gives (the sheet as it was before stop 68, here as the
# reference).

eager_put <- function(cols, count, values) {
  for (nm in names(values)) {
    v <- values[[nm]]
    if (!length(v)) next
    end <- count + length(v) - 1
    col <- gravcal:::sheet_extend(if (is.null(cols[[nm]])) numeric(0) else cols[[nm]], end)
    col[count:end] <- v
    cols[[nm]] <- col
  }
  cols
}

test_that("a sheet's columns are those of its writes made in turn", {
  set.seed(3)
  for (case in 1:20) {
    sh <- gravcal:::sheet_new(c("a", "b"), "txt")
    ref <- sh$cols
    count <- 1
    for (block in 1:5) {
      n <- sample(0:7, 1)
      values <- list(a = round(stats::rnorm(n), 4),
                     # a write longer than the block, overwritten by the next
                     b = if (block != 3) stats::runif(n + sample(0:2, 1)),
                     txt = stats::rnorm(n) / 3,  # a number into a text column: R's text
                     new = if (block >= 2) seq_len(n))
      # a text write into a numeric column (GGIR's myfun beside the counts):
      # the column and the blanks after it become text (block 3 writes no a)
      if (case %% 4 == 0 && block == 2) values$a <- rep("x", n)
      if (case %% 4 == 0 && block == 3) values$a <- NULL
      sh <- gravcal:::sheet_put(sh, values)
      ref <- eager_put(ref, count, values)
      if (block == 4 && n >= 2) {  # two rows repeated, as a long time gap imputes them
        at <- count + c(0, n - 1)
        sh <- gravcal:::sheet_impute(sh, at, c(2, 3), list(a = 0))
        ref <- lapply(ref, gravcal:::sheet_extend, max(lengths(ref), at))
        ref$a[at] <- 0
        rows <- rep(seq_along(ref$a), replace(rep(1, length(ref$a)), at, c(2, 3)))
        ref <- lapply(ref, function(col) col[rows])
        count <- count + 3
      }
      sh <- gravcal:::sheet_advance(sh, n)
      count <- count + n
    }
    expect_identical(sh$count, count, label = paste("case", case))
    for (nm in names(ref)) {
      want <- gravcal:::sheet_extend(ref[[nm]], count - 1)[seq_len(count - 1)]
      expect_identical(gravcal:::sheet_column(sh, nm), want, label = paste("case", case, nm))
    }
  }
})
