# The core's one pump (gc_pump()) over blocks given one at a time: each
# element of `blocks` is a list (or data frame) with x, y, z and optionally
# temperature (or t); one block is one unit of the source.
blocks_source <- function(blocks) {
  as_block <- function(i) {
    if (i > length(blocks)) return(NULL)
    b <- blocks[[i]]
    t <- if (!is.null(b$temperature)) b$temperature else b$t
    list(x = as.double(b$x), y = as.double(b$y), z = as.double(b$z),
         temperature = if (!is.null(t)) as.double(t), last = i == length(blocks))
  }
  i <- 1
  gravcal:::gc_source_blocks(as_block(1), function() {
    i <<- i + 1
    as_block(i)
  })
}

# Columns [cuts[k], cuts[k + 1]) as blocks.
cut_blocks <- function(x, y, z, t, cuts) {
  lapply(seq_len(length(cuts) - 1), function(k) {
    r <- (cuts[k] + 1):cuts[k + 1]
    list(x = x[r], y = y[r], z = z[r], temperature = if (!is.null(t)) t[r])
  })
}

# GGIR's block rules alone (gc_pump(stage = "blocks")): per block, its
# windows (sd rule, 13 mg) and what the rules saw.
pump_blocks <- function(blocks, sf, compat, temperature = TRUE,
                        temp_min_sd = 0.01, per_hour = 3600 * sf) {
  gravcal:::gc_pump(blocks_source(blocks), "blocks",
                    list(sf = sf, compat = as.numeric(compat),
                         temperature = as.numeric(temperature),
                         per_hour = per_hour, temp_min_sd = temp_min_sd,
                         par = c(0.013, 2), block_units = 1))
}

# The segmenter alone over a source (gc_pump(stage = "windows")): windows of
# L samples, in R's arithmetic when r_arith; rule 0 (range; par = max_range,
# axes mask) or 1 (sd; par = max_sd, max_abs_mean).
pump_windows <- function(src, L, r_arith = FALSE, rule = 1L, par = c(0.013, 2),
                         skip_zero = FALSE, block_units = -1) {
  gravcal:::gc_pump(src, "windows",
                    list(window_samples = L, skip_zero = as.numeric(skip_zero),
                         r_arithmetic = as.numeric(r_arith), temperature = 1,
                         rule = rule, par = par, block_units = block_units,
                         want_table = 0))
}
