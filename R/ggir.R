# The GGIR auto-calibration procedure (van Hees et al. 2014; GGIR's
# g.calibrate), block by block on gravcal's segmenter and ICP fit.
#
# GGIR-compatible mode reproduces GGIR 3.3's behaviour rule by rule, its
# quirks included. gravcal's own mode differs only where GGIR's behaviour is
# an accident (see ?calibrate, "The GGIR method"):
#   1. the fit runs to convergence instead of stopping on GGIR's statistic;
#   2. only windows identical to the next one in all six means and sds are
#      dropped as duplicates (GGIR drops a window when exactly 3 of the 6
#      values match, and keeps fully identical ones);
#   3. "enough data" means at least one hour of distinct windows (GGIR
#      compares the number of windows with minloadcrit - 21, a number of
#      hours);
#   4. samples left over at the end of a block always carry to the next
#      block, and the last sample before a run of idle-sleep zeros keeps its
#      own value (GGIR overwrites it with the sample before it).

ggir_messages <- c(
  done = "recalibration done, no problems detected",
  done_no_temp = "recalibration done, but temperature values not used",
  attempted = paste0("recalibration attempted with all available data, but ",
                     "possibly not good enough: Check calibration error ",
                     "variable to varify this"),
  no_decrease = "recalibration not done because recalibration does not decrease error",
  no_sphere = "recalibration not done because not enough points on all sides of the sphere",
  no_rest = "recalibration not done because no non-movement data available",
  no_data = paste0("recalibration not done because not enough data in the ",
                   "file or because file is corrupt")
)

# Remove idle-sleep samples (x = y = z = 0) from a block, as GGIR does.
drop_zero_samples <- function(m, compat) {
  z <- m[, 1] == 0 & m[, 2] == 0 & m[, 3] == 0
  z[is.na(z)] <- FALSE
  if (!any(z)) return(m)
  last_zero <- z[length(z)]
  m <- m[!z, , drop = FALSE]
  n <- nrow(m)
  if (compat && last_zero && n >= 2) m[n, 1:3] <- m[n - 1, 1:3]
  m
}

# The procedure handles a block as a list of "pieces": ranges [from, to)
# (0-based) of columns x, y, z and t (temperature, or NULL) that stay where
# they are (the caller's vectors for data in memory, the reader's for files),
# so that no sample is copied on the way to the segmenter. Only the samples
# carried from one block to the next (less than an hour) are copied.
piece <- function(x, y, z, t, from, to) {
  list(x = x, y = y, z = z, t = t, from = from, to = to)
}

pieces_n <- function(P) {
  n <- 0
  for (p in P) n <- n + (p$to - p$from)
  n
}

# The first n rows.
pieces_head <- function(P, n) {
  out <- list()
  for (p in P) {
    if (n <= 0) break
    k <- min(n, p$to - p$from)
    p$to <- p$from + k
    out[[length(out) + 1]] <- p
    n <- n - k
  }
  out
}

# All but the first n rows.
pieces_drop <- function(P, n) {
  out <- list()
  for (p in P) {
    len <- p$to - p$from
    if (n >= len) {
      n <- n - len
      next
    }
    p$from <- p$from + n
    n <- 0
    out[[length(out) + 1]] <- p
  }
  out
}

pieces_col <- function(P, col) {
  v <- lapply(P, function(p) p[[col]][seq.int(p$from + 1, length.out = p$to - p$from)])
  as.double(unlist(v, use.names = FALSE))
}

# One piece holding copies of the rows.
pieces_own <- function(P) {
  if (!length(P)) return(list())
  temp <- !is.null(P[[1]]$t)
  list(piece(pieces_col(P, "x"), pieces_col(P, "y"), pieces_col(P, "z"),
             if (temp) pieces_col(P, "t"), 0, pieces_n(P)))
}

pieces_matrix <- function(P) {
  temp <- length(P) && !is.null(P[[1]]$t)
  m <- cbind(pieces_col(P, "x"), pieces_col(P, "y"), pieces_col(P, "z"))
  if (temp) m <- cbind(m, pieces_col(P, "t"))
  m
}

pieces_zeros <- function(P) {
  n <- 0
  for (p in P) n <- n + gc_count_zero(p$x, p$y, p$z, p$from, p$to)
  n
}

# c(mean, sd, n) of the temperature of the first `limit` rows, as R's mean()
# and sd() with na.rm = TRUE give them.
pieces_temp_stats <- function(P, limit) {
  gc_r_mean_sd(lapply(P, `[[`, "t"), vapply(P, `[[`, 0, "from"),
               vapply(P, `[[`, 0, "to"), limit)
}

# Is the sd of the temperature of the first `limit` rows below `threshold`
# (R's sd(, na.rm = TRUE) decides)? NA with fewer than 2 values.
pieces_sd_below <- function(P, limit, threshold) {
  gc_sd_below(lapply(P, `[[`, "t"), vapply(P, `[[`, 0, "from"),
              vapply(P, `[[`, 0, "to"), limit, threshold)
}

# A block from a source as a piece (see open_source() for the two forms).
block_piece <- function(blk, temp) {
  if (!is.null(blk$cols)) {
    cl <- blk$cols
    return(piece(cl$x, cl$y, cl$z, if (temp) cl$temperature, blk$from, blk$to))
  }
  d <- blk$data
  col <- function(v) {
    if (!is.numeric(v)) abort("The recording has a non-numeric acceleration or temperature column.")
    as.double(v)
  }
  piece(col(d$x), col(d$y), col(d$z), if (temp) col(d$temperature), 0, nrow(d))
}

block_rows <- function(blk) {
  if (!is.null(blk$cols)) blk$to - blk$from else NROW(blk$data)
}

block_has_temp <- function(blk) {
  if (!is.null(blk$cols)) !is.null(blk$cols$temperature) else
    "temperature" %in% names(blk$data)
}

ggir_feature_names <- function(temp) {
  c("Euclidean Norm", "meanx", "meany", "meanz", "sdx", "sdy", "sdz",
    if (temp) "temperature")
}

# Run the procedure on a source (see open_source()). Returns GGIR's list plus,
# in attribute "gravcal", what calibrate() needs.
ggir_run <- function(src, compat = TRUE, spherecrit = 0.3, minloadcrit = 168,
                     sdcriter = 0.013, verbose = FALSE, printsummary = FALSE,
                     max_iter = 1000, tol = 1e-10) {
  sf <- src$sf
  per_hour <- 3600 * sf
  seg <- gc_segmenter_new(10 * sf, FALSE, compat)
  S <- list()
  feats <- list()
  n_feat <- 0
  use.temp <- temp.available <- FALSE
  scale <- c(1, 1, 1)
  offset <- c(0, 0, 0)
  tempoffset <- NULL
  cal.error.start <- cal.error.end <- npoints <- NULL
  nhoursused <- 0
  QC <- NULL
  ft <- NULL
  ft_id <- integer(0)
  bsc_qc <- data.frame()
  icp <- NULL
  meantemp <- 0
  blocks <- 0
  pending <- FALSE
  i <- 1
  repeat {
    if (verbose) cat(if (i == 1) "\nLoading chunk: 1" else paste0(" ", i))
    if (i > 1 && isTRUE(src$from_file)) {
      # the previous block is garbage now: collect it before reading the
      # next, so that memory stays at about one block
      blk <- NULL
      invisible(gc(full = TRUE))
    }
    blk <- src$read(i)
    if (!is.null(blk)) {
      nr <- block_rows(blk)
      if (nr == 0) {
        blk <- NULL
      } else if (nr < per_hour * 2 + 1) {
        # GGIR: a short block is the last one; a short first block means the
        # file is too short to use
        blk$last <- TRUE
        if (i == 1) blk <- NULL
      }
    }
    last <- is.null(blk) || isTRUE(blk$last)
    if (i == 1) {
      use.temp <- temp.available <- !is.null(blk) && block_has_temp(blk)
    }
    added <- FALSE
    if (!is.null(blk)) {
      P <- c(S, list(block_piece(blk, temp.available)))
      if (pieces_zeros(P) > 0) {
        # idle-sleep samples: GGIR's removal, on a copy of this block
        m <- drop_zero_samples(pieces_matrix(P), compat)
        P <- list(piece(m[, 1], m[, 2], m[, 3],
                        if (temp.available) m[, 4], 0, nrow(m)))
        rm(m)
      }
      LD <- pieces_n(P)
      use <- floor(LD / per_hour) * per_hour
      if (use > 0) {
        if (use != LD) {
          S <- pieces_own(pieces_drop(P, use))
        } else if (!compat) {
          S <- list()
        }
        P <- pieces_head(P, use)
        if (use.temp) {
          first10 <- pieces_temp_stats(P, 10)[1]
          if (isTRUE(first10 > 120)) {
            warning("temperature not used for calibration: its first values ",
                    "exceed 120 (not degrees C?)", call. = FALSE)
            use.temp <- FALSE
          } else {
            flat <- pieces_sd_below(P, use, 0.01)
            if (is.na(flat)) {
              warning("temperature not used for calibration: it has fewer ",
                      "than 2 values", call. = FALSE)
              use.temp <- FALSE
            } else if (flat) {
              warning("temperature not used for calibration: it does not vary ",
                      "(sd < 0.01)", call. = FALSE)
              use.temp <- FALSE
            }
          }
        }
        gc_segmenter_new_block(seg)
        ws <- lapply(P, function(p) {
          gc_segmenter_push(seg, p$x, p$y, p$z, if (use.temp) p$t, p$from,
                            p$to, 1L, c(sdcriter, 2))
        })
        wcol <- function(name) unlist(lapply(ws, `[[`, name), use.names = FALSE)
        f <- cbind(wcol("mean_norm"), wcol("mean_x"), wcol("mean_y"),
                   wcol("mean_z"), wcol("sd_x"), wcol("sd_y"), wcol("sd_z"))
        if (temp.available) {
          f <- cbind(f, if (use.temp) wcol("temperature") else 99999)
        }
        rm(ws, P)
        n_feat <- n_feat + nrow(f)
        feats[[length(feats) + 1]] <- f
        added <- TRUE
        blocks <- blocks + 1
        # memory in use after the block, as GGIR records it (a minor
        # collection: GGIR's full one costs more than the block itself)
        mem <- gc(full = FALSE)[2, 2]
        bsc_qc <- rbind(bsc_qc, data.frame(time = format(Sys.time()),
                                           size = mem,
                                           stringsAsFactors = FALSE))
      } else if (!compat) {
        S <- pieces_own(P)
      }
    }
    stop_loading <- FALSE
    # GGIR fits after every block, but only the fit after the last block, or
    # one that can stop the loading (more than minloadcrit hours), decides
    # the result: the others are skipped (the window table only grows, so
    # the last fit is the same either way).
    due <- added || i == 1
    if (due && !last && n_feat * 10 / 3600 <= minloadcrit) {
      pending <- TRUE
      due <- FALSE
    }
    if (last && pending) due <- TRUE
    if (due) {
      pending <- FALSE
      spherepopulated <- FALSE
      ft <- if (length(feats)) do.call(rbind, feats) else
        matrix(numeric(0), 0, if (temp.available) 8 else 7)
      # ft_id: the window's number in the recording (GGIR's row names)
      ft_id <- seq_len(nrow(ft))
      keep <- !is.na(ft[, 4]) & !is.na(ft[, 1])
      ft <- ft[keep, , drop = FALSE]
      ft_id <- ft_id[keep]
      n <- nrow(ft)
      if (n > 1) {
        same <- rowSums(ft[1:(n - 1), 2:7, drop = FALSE] == ft[2:n, 2:7, drop = FALSE])
        cut <- which(same == if (compat) 3 else 6)
        if (length(cut)) {
          ft <- ft[-cut, , drop = FALSE]
          ft_id <- ft_id[-cut]
        }
      }
      nhoursused <- 0
      enough <- if (compat) nrow(ft) > (minloadcrit - 21) else nrow(ft) >= 360
      if (enough) {
        nhoursused <- (nrow(ft) * 10) / 3600
        ft <- ft[-1, , drop = FALSE]
        ft_id <- ft_id[-1]
        nomovement <- which(ft[, 5] < sdcriter & ft[, 6] < sdcriter &
                              ft[, 7] < sdcriter & abs(ft[, 2]) < 2 &
                              abs(ft[, 3]) < 2 & abs(ft[, 4]) < 2)
        if (length(nomovement) < 10) {
          QC <- ggir_messages[["no_rest"]]
          ft <- NULL
        } else {
          ft <- ft[nomovement, , drop = FALSE]
          ft_id <- ft_id[nomovement]
          npoints <- nrow(ft)
          e <- sqrt(ft[, 2]^2 + ft[, 3]^2 + ft[, 4]^2)
          cal.error.start <- round(mean(abs(e - 1)), digits = 5)
          tel <- 0
          for (a in 2:4) {
            if (min(ft[, a]) < -spherecrit && max(ft[, a]) > spherecrit) tel <- tel + 1
          }
          spherepopulated <- tel == 3
          if (!spherepopulated) QC <- ggir_messages[["no_sphere"]]
        }
      } else {
        QC <- ggir_messages[["no_data"]]
      }
      if (spherepopulated) {
        temp <- if (use.temp) ft[, 8] else NULL
        icp <- gc_fit_icp(ft[, 2], ft[, 3], ft[, 4], temp, use.temp,
                          if (compat) 0L else 1L, as.integer(max_iter), tol,
                          100, FALSE)
        scale <- icp$scale
        offset <- icp$offset
        tempoffset <- icp$tempoffset
        meantemp <- if (use.temp) icp$meantemp else 0
        a <- lapply(1:3, function(k) {
          v <- (ft[, k + 1] + offset[k]) / (1 / scale[k])
          if (use.temp) v <- v + (temp - meantemp) / (1 / tempoffset[k])
          v
        })
        e <- sqrt(a[[1]]^2 + a[[2]]^2 + a[[3]]^2)
        cal.error.end <- round(mean(abs(e - 1)), digits = 5)
        if (cal.error.end < cal.error.start && cal.error.end < 0.01 &&
            nhoursused > minloadcrit) {
          QC <- if (use.temp == temp.available) ggir_messages[["done"]] else
            ggir_messages[["done_no_temp"]]
          stop_loading <- TRUE
        } else {
          if (nhoursused > minloadcrit && verbose) {
            cat(paste0("\nnew calibration error: ", cal.error.end, " g"))
            cat(paste0("\nnpoints around sphere: ", npoints))
          }
          QC <- ggir_messages[["attempted"]]
        }
      }
    }
    if (last || stop_loading) break
    i <- i + 1
  }
  if (length(cal.error.end) > 0 && cal.error.end > cal.error.start) {
    QC <- ggir_messages[["no_decrease"]]
  }
  spheredata <- NULL
  if (!is.null(ft) && nrow(ft) > 0 && ncol(ft) > 0) {
    spheredata <- as.data.frame(unname(ft))
    attr(spheredata, "row.names") <- ft_id
    nm <- ggir_feature_names(use.temp)
    names(spheredata) <- c(nm, rep(NA_character_, ncol(ft) - length(nm)))
  }
  meantempcal <- if (use.temp && length(spheredata) > 0) mean(spheredata[, 8], na.rm = TRUE) else NULL
  if (printsummary && verbose) {
    cat("\nSummary of autocalibration procedure:\n")
    cat(paste0("\nStatus: ", QC))
    cat(paste0("\nCalibration error (g) before: ", cal.error.start))
    cat(paste0("\nCalibration error (g) after: ", cal.error.end))
    cat(paste0("\nOffset correction ", c("x", "y", "z"), ": ", offset))
    cat(paste0("\nScale correction ", c("x", "y", "z"), ": ", scale))
    cat(paste0("\nNumber of hours used: ", nhoursused))
    cat(paste0("\nNumber of 10 second windows around the sphere: ", npoints))
    cat(paste0("\nTemperature used (if available): ", use.temp))
    cat(paste0("\nTemperature offset (if temperature is available) ",
               c("x", "y", "z"), ": ", tempoffset))
    cat("\n")
  }
  if (verbose) cat("\n")
  out <- list(scale = scale, offset = offset, tempoffset = tempoffset,
              cal.error.start = cal.error.start, cal.error.end = cal.error.end,
              spheredata = spheredata, npoints = npoints,
              nhoursused = nhoursused, QCmessage = QC, use.temp = use.temp,
              meantempcal = meantempcal, bsc_qc = bsc_qc)
  attr(out, "gravcal") <- list(icp = icp, meantemp = meantemp, blocks = blocks,
                               temp.available = temp.available,
                               windows = n_feat)
  out
}

#' Auto-calibration as GGIR's g.calibrate, on gravcal's core
#'
#' A drop-in replacement for `GGIR::g.calibrate()`: same arguments, same
#' procedure, same returned list, computed by gravcal's streaming C++ core.
#' It reads the recording in GGIR's blocks (about 12 hours; `chunksize`
#' scales them) and keeps whole hours only (the rest carries to the next
#' block; the last partial hour is dropped), removes idle-sleep samples (x =
#' y = z = 0), cuts 10-second windows, drops duplicate windows and the first
#' window, keeps the rest windows (sd below 13 mg and |mean| below 2 g on all
#' axes), checks that the sphere is covered (`spherecrit`), fits scale,
#' offset and temperature offset by weighted iterative closest point and,
#' after each block, decides whether to read on (`minloadcrit` hours). Every
#' rule is GGIR's, including the ones that look like accidents; see
#' [calibrate()] with `method = "ggir"` for gravcal's corrected variant.
#'
#' The returned numbers are GGIR's to the last bit (the window statistics
#' are computed in R's arithmetic, the fit with R's own least-squares
#' routine); the work is one pass over the samples in C++, without copying
#' them, so a week at 100 Hz held in memory takes about a second, some 55
#' times less than GGIR, and needs little memory beyond the input (the
#' window table and at most an hour of samples carried between blocks);
#' from a file, one block at a time. Figures: `bench/results/speed.md` in
#' the package sources.
#'
#' Unlike GGIR's, this function does not need `inspectfileobject` (it finds
#' the format and sampling rate itself) but accepts GGIR's; and `datafile`
#' may also be a data frame of raw samples (columns `x`, `y`, `z` in g,
#' optional `temperature`), read in the blocks GGIR uses for csv files, with
#' the sampling rate given as `sf = ` in `...` (or from a `time` column).
#'
#' Formats: ActiGraph csv exports, csv files with `x`, `y`, `z` columns,
#' `.rds` data frames, ActiGraph `.gt3x` (package read.gt3x), Axivity `.cwa`
#' and GENEActiv `.bin` (package GGIRread, the readers GGIR uses).
#'
#' @param datafile Path of the recording, or a data frame of raw samples.
#' @param params_rawdata,params_general,params_cleaning GGIR's parameter
#'   lists (as from `GGIR::load_params()`); gravcal uses `chunksize`,
#'   `spherecrit`, `minloadcrit`, `printsummary` and, for ad hoc data,
#'   `rmc.noise`, and ignores the rest. Missing entries take GGIR's defaults
#'   (`chunksize = 1`, `spherecrit = 0.3`, `minloadcrit = 168`,
#'   `printsummary = FALSE`).
#' @param inspectfileobject Optional: GGIR's `g.inspectfile()` result; its
#'   `sf` is used.
#' @param verbose Print progress (the blocks read) as GGIR does.
#' @param ... Legacy arguments that override the parameter lists, as in
#'   GGIR (`chunksize`, `spherecrit`, `minloadcrit`, `printsummary`), and
#'   `sf` for a data frame.
#' @return GGIR's list: `scale`, `offset`, `tempoffset` (empty when no fit
#'   ran), `cal.error.start`, `cal.error.end` (rounded to 5 digits),
#'   `spheredata` (the rest windows: `Euclidean Norm, meanx, meany, meanz,
#'   sdx, sdy, sdz` and `temperature` when used), `npoints`, `nhoursused`,
#'   `QCmessage`, `use.temp`, `meantempcal` and `bsc_qc` (time and memory
#'   in MB after each block). Invisibly, as GGIR.
#' @seealso [calibrate()] (`method = "ggir"`) for a `gravcal_fit`,
#'   [write_ggir_coefs()] to hand coefficients to GGIR.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 30, sf = 10, seed = 4)
#' C <- g.calibrate(rec, sf = 10, verbose = FALSE)
#' C$QCmessage
#' C$scale
#' C$offset
g.calibrate <- function(datafile, params_rawdata = c(), params_general = c(),
                        params_cleaning = c(), inspectfileobject = c(),
                        verbose = TRUE, ...) {
  dots <- list(...)
  if (length(dots) && (is.null(names(dots)) || any(names(dots) == ""))) {
    abort("All arguments in `...` must be named.")
  }
  pr <- ggir_params(params_rawdata, dots)
  check_flag(verbose, "verbose")
  sf <- dots$sf
  if (is.null(sf) && length(inspectfileobject) && !is.null(inspectfileobject$sf)) {
    sf <- inspectfileobject$sf
  }
  if (is.null(sf) && length(pr$rmc.sf)) sf <- pr$rmc.sf
  src <- open_source(datafile, sf = sf, chunksize = pr$chunksize)
  # GGIR uses rmc.noise only for ad hoc csv files (its "AD_HOC" monitor)
  sdcriter <- if (identical(src$format, "csv") && !is.null(pr$rmc.noise)) {
    pr$rmc.noise * 1.2
  } else {
    0.013
  }
  out <- ggir_run(src, compat = TRUE, spherecrit = pr$spherecrit,
                  minloadcrit = pr$minloadcrit,
                  sdcriter = sdcriter, verbose = verbose,
                  printsummary = pr$printsummary)
  attr(out, "gravcal") <- NULL
  invisible(out)
}

# GGIR's parameters with defaults; legacy arguments in `dots` win.
ggir_params <- function(params_rawdata, dots) {
  p <- list(chunksize = 1, spherecrit = 0.3, minloadcrit = 168,
            printsummary = FALSE, rmc.noise = NULL, rmc.sf = NULL)
  if (length(params_rawdata)) {
    if (!is.list(params_rawdata)) {
      abort("`params_rawdata` must be a list (as from GGIR::load_params()), ",
            "not ", describe(params_rawdata), ".")
    }
    for (nm in intersect(names(p), names(params_rawdata))) p[nm] <- list(params_rawdata[[nm]])
  }
  for (nm in intersect(names(p), names(dots))) p[nm] <- list(dots[[nm]])
  known <- c(names(p), "sf", "desiredtz", "configtz", "do.cal", "use.temp",
             "windowsizes", "outputdir", "studyname", "overwrite")
  extra <- setdiff(names(dots), known)
  if (length(extra)) {
    warning("g.calibrate(): ignored argument", if (length(extra) > 1) "s",
            " ", paste0("`", extra, "`", collapse = ", "), call. = FALSE)
  }
  check_number(p$chunksize, "chunksize", min = 0, max = 1, min_inclusive = FALSE)
  check_number(p$spherecrit, "spherecrit", min = 0)
  check_number(p$minloadcrit, "minloadcrit", min = 0)
  check_flag(p$printsummary, "printsummary")
  if (!is.null(p$rmc.noise)) {
    check_number(p$rmc.noise, "rmc.noise", min = 0, min_inclusive = FALSE)
  }
  p
}

# calibrate(method = "ggir"): the procedure, then a gravcal_fit.
calibrate_ggir <- function(x, sf, compat, dots, call) {
  args <- split_dots(dots, list(ggir = c(
    "use_temp", "spherecrit", "minloadcrit", "chunksize", "max_sd",
    "max_iter", "tol", "verbose")))$ggir
  a <- utils::modifyList(list(use_temp = TRUE, spherecrit = 0.3,
                              minloadcrit = 168, chunksize = 1, max_sd = 0.013,
                              max_iter = 1000, tol = 1e-10, verbose = FALSE),
                         args)
  check_flag(a$use_temp, "use_temp")
  check_number(a$spherecrit, "spherecrit", min = 0)
  check_number(a$minloadcrit, "minloadcrit", min = 0)
  check_number(a$chunksize, "chunksize", min = 0, max = 1, min_inclusive = FALSE)
  check_number(a$max_sd, "max_sd", min = 0, min_inclusive = FALSE)
  check_number(a$max_iter, "max_iter", min = 1)
  check_number(a$tol, "tol", min = 0)
  check_flag(a$verbose, "verbose")
  if (is.null(sf) && !is.character(x) && is.null(attr(x, "sf")) &&
      !("time" %in% tolower(colnames(x)))) {
    abort("`sf` (sampling frequency in Hz) is missing.")
  }
  src <- open_source(x, sf = sf, chunksize = a$chunksize, arg = "x")
  if (!a$use_temp) src$read <- drop_temperature(src$read)
  res <- ggir_run(src, compat = compat, spherecrit = a$spherecrit,
                  minloadcrit = a$minloadcrit, sdcriter = a$max_sd,
                  verbose = a$verbose, max_iter = a$max_iter, tol = a$tol)
  fit <- ggir_fit(res, compat, call, a$minloadcrit)
  if (is.character(x)) fit$file <- basename(x)
  fit
}

drop_temperature <- function(read) {
  force(read)
  function(i) {
    b <- read(i)
    if (!is.null(b$cols)) b$cols$temperature <- NULL
    if (!is.null(b$data)) b$data$temperature <- NULL
    b
  }
}

# GGIR's result as a gravcal_fit, with a status code beside GGIR's message.
ggir_plausible <- function(scale, offset, tempoffset) {
  to <- if (length(tempoffset)) tempoffset else 0
  all(is.finite(c(scale, offset, to))) &&
    all(scale >= plausible$scale[1] & scale <= plausible$scale[2]) &&
    all(abs(offset) <= plausible$offset) && all(abs(to) <= plausible$temp)
}

ggir_fit <- function(res, compat, call, minloadcrit) {
  info <- attr(res, "gravcal")
  attr(res, "gravcal") <- NULL
  sd <- res$spheredata
  pts <- NULL
  if (length(sd) > 0 && nrow(sd) > 0) {
    pts <- data.frame(mean_x = sd[[2]], mean_y = sd[[3]], mean_z = sd[[4]],
                      sd_x = sd[[5]], sd_y = sd[[6]], sd_z = sd[[7]],
                      mean_norm = sd[[1]],
                      temperature = if (isTRUE(res$use.temp)) sd[[8]] else NA_real_)
  }
  qc <- res$QCmessage
  key <- names(ggir_messages)[match(qc, ggir_messages)]
  icp <- info$icp
  status <- switch(key,
    done = , done_no_temp = "ok",
    attempted = if (!is.null(res$cal.error.end) && res$cal.error.end < 0.01) "ok" else "high_error",
    no_decrease = "no_improvement",
    no_sphere = "sphere_not_covered",
    no_rest = "no_rest",
    no_data = "too_short")
  if (!is.null(icp) && !isTRUE(icp$finite)) status <- "diverged"
  detail <- switch(status,
    ok = if (identical(key, "attempted")) sprintf(
      "calibrated on all %g hours of the recording (fewer than minloadcrit = %g hours)",
      res$nhoursused, minloadcrit) else "",
    high_error = sprintf(paste0(
      "coefficients kept, as GGIR applies them, but the error after ",
      "calibration is %.2f mg (GGIR accepts < 10 mg)"), 1000 * res$cal.error.end),
    too_short = "fewer distinct 10 s windows than the procedure needs",
    diverged = "the fit did not stay finite", "")
  # gravcal's own mode does not apply coefficients outside the ranges real
  # devices show (GGIR, and so compatible mode, applies them)
  if (!compat && status %in% c("ok", "high_error") &&
      !ggir_plausible(res$scale, res$offset, res$tempoffset)) {
    status <- "implausible"
    detail <- paste0("calibration not applied: coefficients outside plausible ",
                     "ranges (scale ", plausible$scale[1], "-", plausible$scale[2],
                     ", |offset| <= ", plausible$offset, " g, |temperature offset| <= ",
                     plausible$temp, " g per degree C)")
  }
  applied <- status %in% c("ok", "high_error")
  fit <- new_fit(
    K = if (applied) diag(res$scale, 3) else diag(3),
    offset = if (applied) res$offset else c(0, 0, 0),
    tempoffset = if (applied && length(res$tempoffset)) res$tempoffset else c(0, 0, 0),
    meantemp = if (length(res$meantempcal)) res$meantempcal else NA_real_,
    points = pts, method = "ggir",
    iterations = if (is.null(icp)) 0L else icp$iterations,
    converged = !is.null(icp) && isTRUE(icp$converged), status = status,
    message = if (nzchar(detail)) paste0(detail, " [GGIR: ", qc, "]") else qc,
    call = call)
  fit$ggir <- res
  fit$QCmessage <- qc
  fit$ggir_compat <- compat
  fit$use_temp <- isTRUE(res$use.temp)
  fit$n_windows <- info$windows
  fit$hours <- info$windows * 10 / 3600
  fit
}
