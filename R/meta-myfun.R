# g.getmeta()'s `myfun`: an external function of the calibrated samples of
# each block, whose values become columns of metashort, as GGIR 3.3-9 runs
# it (its check_myfun() and applyExtFunction(), read from their behaviour):
# the block's calibrated x, y, z in the unit the function expects, resampled
# to its rate (GGIRread::resample(), GGIR's own resampler) when that differs,
# with time stamps from the first block's start when asked, its output
# aggregated or repeated to the short epoch, written into metashort as text.
# The function is the user's: it runs in R, once a block.

# The elements a myfun list may have, and those it must have (GGIR's).
myfun_known <- c("FUN", "parameters", "expected_sample_rate", "expected_unit", "colnames",
                 "minlength", "outputres", "outputtype", "aggfunction", "timestamp",
                 "reporttype", "clevels", "ilevels", "qlevels", "ebout.dur", "ebout.th.cad",
                 "ebout.th.acc", "ebout.criter", "ebout.condition", "name")
myfun_needed <- c("FUN", "parameters", "expected_sample_rate", "expected_unit", "colnames",
                  "minlength", "outputres")

# `myfun` checked as GGIR checks it (an error naming the element where GGIR
# stops), and outputtype, which GGIR's g.getmeta() reads without checking
# (it stops on its absence in the middle of the first block).
meta_myfun_check <- function(myfun, ws3) {
  bad <- function(...) abort("`myfun`: ", ...)
  if (!is.list(myfun)) bad("must be a list (GGIR's external function object), not ",
                           describe(myfun), ".")
  extra <- setdiff(names(myfun), myfun_known)
  if (length(extra) || is.null(names(myfun)) || any(names(myfun) == "")) {
    bad("unexpected element", if (length(extra) > 1) "s", " ",
        paste0("`", extra, "`", collapse = ", "), " (GGIR's myfun has ",
        paste(myfun_known, collapse = ", "), ").")
  }
  missing <- setdiff(myfun_needed, names(myfun))
  if (length(missing)) {
    bad("lacks ", paste0("`", missing, "`", collapse = ", "), ".")
  }
  if (!is.function(myfun$FUN)) bad("`FUN` must be a function, not ", describe(myfun$FUN), ".")
  if (!is.numeric(myfun$expected_sample_rate) || length(myfun$expected_sample_rate) != 1 ||
      !is.finite(myfun$expected_sample_rate) || myfun$expected_sample_rate <= 0) {
    bad("`expected_sample_rate` must be one positive number of Hz, not ",
        describe(myfun$expected_sample_rate), ".")
  }
  if (sum(myfun$expected_unit %in% c("mg", "g", "ms2")) != 1 || length(myfun$expected_unit) != 1) {
    bad("`expected_unit` must be \"g\", \"mg\" or \"ms2\", not ", describe(myfun$expected_unit), ".")
  }
  if (!is.character(myfun$colnames) || !length(myfun$colnames)) {
    bad("`colnames` must name the function's output columns (character), not ",
        describe(myfun$colnames), ".")
  }
  for (nm in c("minlength", "outputres")) {
    v <- myfun[[nm]]
    if (!is.numeric(v) || length(v) != 1 || !is.finite(v) || v <= 0) {
      bad("`", nm, "` must be one positive number, not ", describe(v), ".")
    }
  }
  if (myfun$outputres != round(myfun$outputres)) {
    bad("`outputres` must be a whole number of seconds, not ", myfun$outputres, ".")
  }
  r <- myfun$outputres / ws3
  if (r != round(r) && 1 / r != round(1 / r)) {
    bad("`outputres` (", myfun$outputres, " s) and the short epoch (", ws3,
        " s, windowsizes[1]) must be multiples of each other.")
  }
  if (!is.character(myfun$outputtype) || length(myfun$outputtype) != 1 ||
      !myfun$outputtype %in% c("numeric", "character")) {
    bad("`outputtype` must be \"numeric\" or \"character\" (GGIR's g.getmeta() stops ",
        "without it), not ", describe(myfun$outputtype), ".")
  }
  if ("aggfunction" %in% names(myfun) && !is.function(myfun$aggfunction)) {
    bad("`aggfunction` must be a function, not ", describe(myfun$aggfunction), ".")
  }
  if (myfun$outputres < ws3 && !is.function(myfun$aggfunction)) {
    bad("`aggfunction` is needed: the output (every ", myfun$outputres,
        " s) is aggregated to the short epoch (", ws3, " s).")
  }
  if (!is.null(myfun$timestamp) && !(is.logical(myfun$timestamp) && length(myfun$timestamp) == 1 &&
                                     !is.na(myfun$timestamp))) {
    bad("`timestamp` must be TRUE or FALSE, not ", describe(myfun$timestamp), ".")
  }
  if (!is.null(myfun$FUN) && !requireNamespace("GGIRread", quietly = TRUE)) {
    bad("needs the GGIRread package (GGIR's resampler): install.packages(\"GGIRread\").")
  }
  myfun
}

# The rows of a block GGIR's myfun minimum length leaves (g.getmeta()'s
# `use` cut to a whole number of `minlength`).
meta_myfun_use <- function(use, myfun) {
  if (is.null(myfun)) return(use)
  k <- use / myfun$minlength
  if (k != floor(k)) use <- floor(k) * myfun$minlength
  use
}

# A block's calibrated x, y, z as GGIR's g.getmeta() computes them in R
# (scale() with the reciprocal scale, then the temperature term around
# meantempcal): `rows` the block's raw columns, `cal` meta_calibration()'s.
meta_myfun_xyz <- function(rows, cal, use_temp) {
  m <- cbind(x = rows$x, y = rows$y, z = rows$z)
  m[, c("x", "y", "z")] <- scale(m, center = -cal$offset, scale = cal$inv_scale)
  if (use_temp && !is.null(cal$meantemp)) {
    tt <- rows$temperature
    m[, c("x", "y", "z")] <- m[, c("x", "y", "z")] +
      scale(cbind(tt, tt, tt), center = rep(cal$meantemp, 3), scale = cal$inv_tempoffset)
  }
  m
}

# The function's output for one block: `xyz` the calibrated samples (a
# matrix, columns x, y, z), `start` the first block's start (POSIXlt) for
# time stamps. A character matrix of its rows per short epoch, as GGIR
# writes it into metashort.
meta_myfun_block <- function(xyz, myfun, sf, ws3, start, interpolation) {
  unit <- switch(myfun$expected_unit, g = 1, mg = 1000, ms2 = 9.81)
  rate <- myfun$expected_sample_rate
  resample <- function(a) {
    t_old <- seq(0, nrow(a) / sf, 1 / sf)[-1]
    t_new <- seq(0, nrow(a) / sf, 1 / rate)[-1]
    GGIRread::resample(a, t_old, t_new, nrow(a), type = interpolation)
  }
  stamp <- isTRUE(myfun$timestamp)
  if (stamp) {
    if (sf != rate) xyz <- resample(xyz)
    t0 <- as.numeric(start)
    tt <- seq(t0, t0 + round(nrow(xyz) / rate), by = 1 / rate)
    n <- nrow(xyz)
    if (length(tt) > n) {
      tt <- tt[seq_len(n)]
    } else if (length(tt) < n) {
      tt <- c(tt, tt[length(tt)] + seq_len(n - length(tt)) / rate)
    }
    out <- myfun$FUN(cbind(time2beAdded = tt, xyz) * unit, myfun$parameters)
  } else {
    out <- myfun$FUN((if (sf != rate) resample(xyz) else xyz) * unit, myfun$parameters)
  }
  if (is.null(dim(out))) {
    out <- as.matrix(out)
    if (ncol(out) != 1 && nrow(out) == 1) out <- t(out)
  }
  per <- ws3 / myfun$outputres
  if (myfun$outputres < ws3) {
    # GGIR's grouping: consecutive runs of `per` rows, labels offset by 3 per
    level <- rep(seq_len(nrow(out)) + 3 * per, each = per)[seq_len(nrow(out))]
    df <- data.frame(out, agglevel = level)
    agg <- stats::aggregate(df, by = list(df$agglevel), FUN = myfun$aggfunction)
    out <- as.matrix(agg[, -c(1, ncol(agg))])
  } else if (myfun$outputres > ws3) {
    out <- as.matrix(out[rep(seq_len(nrow(out)), each = myfun$outputres / ws3), ])
  }
  if (ncol(out) != length(myfun$colnames)) {
    abort("`myfun`: its function gave ", ncol(out), " column", if (ncol(out) != 1) "s",
          " but `colnames` names ", length(myfun$colnames), ".")
  }
  out
}

# GGIR's do.neishabouricounts for one block: actilifecounts::get_counts() on
# the block's calibrated samples (`xyz`), per short epoch, rounded as GGIR
# rounds its metrics; columns named `names` (x, y, z, vector magnitude).
meta_counts_block <- function(xyz, sf, ws3, lfe, names) {
  m <- actilifecounts::get_counts(raw = xyz, sf = sf, epoch = ws3, lfe_select = lfe,
                                  verbose = FALSE)
  if (sf < 30) {
    warning("Neishabouri's counts (actilifecounts) assume a rate of 30 Hz or more, not ", sf,
            " Hz (GGIR warns of this too).", call. = FALSE)
  }
  m <- round(matrix(as.numeric(m[, 1:4]), ncol = 4), 4)
  colnames(m) <- names
  m
}
