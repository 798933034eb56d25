# Recordings for GGIR part 1's tests (test-ggir-getmeta.R, test-ggir-part1.R):
# simulate_recording() of `hours` with temperature offsets, two stretches at
# rest on a table (flat, 1 mg noise: GGIR's non-wear) and 41 samples at 7.9
# g (clipping), written to `file` as a .cwa ("cwa"), GENEActiv .bin ("bin"),
# .gt3x ("gt3x") or Parmay Matrix .bin ("parmay": packets of 2 minutes, a
# range of `range` g). The bytes depend only on the arguments (the cached
# GGIR results are keyed by them); the session's random numbers are left as
# they were.
write_meta_recording <- function(file, format, sf, hours, seed, start, range = 8) {
  rec <- simulate_recording(hours = hours, sf = sf, seed = seed,
                            start = as.POSIXct(start, tz = "UTC"),
                            tempoffset = c(0.001, -0.002, 0.0005))
  n <- nrow(rec)
  g <- globalenv()
  old <- if (exists(".Random.seed", envir = g, inherits = FALSE)) get(".Random.seed", envir = g)
  on.exit(if (is.null(old)) rm(".Random.seed", envir = g) else assign(".Random.seed", old, envir = g))
  set.seed(seed)
  for (s in list(c(0.20, 0.27), c(0.55, 0.58))) {
    i <- round(s[1] * n):round(s[2] * n)
    rec$x[i] <- 0.02 + stats::rnorm(length(i), 0, 0.001)
    rec$y[i] <- -0.01 + stats::rnorm(length(i), 0, 0.001)
    rec$z[i] <- 0.99 + stats::rnorm(length(i), 0, 0.001)
  }
  rec$x[round(0.8 * n) + 0:40] <- 7.9
  if (format == "gt3x") {
    gravcal:::write_gt3x(as.matrix(rec[, c("x", "y", "z")]), file, sf = sf,
                         start = as.POSIXct(start, tz = "UTC"))
  } else if (format == "parmay") {
    gravcal:::write_parmay_bin(rec, file, sf = sf, start = as.numeric(rec$time[1]),
                               range = range, packet_seconds = 120)
  } else if (format == "cwa") {
    gravcal:::write_cwa(as.matrix(rec[, c("x", "y", "z")]), file, sf = sf,
                        start = as.numeric(rec$time[1]), temperature = rec$temperature)
  } else {
    gravcal:::write_geneactiv_bin(rec, file, sf = sf, start = start)
  }
  invisible(file)
}

# The objects of the meta files (or ms2.out files) in `folder`, by file,
# with M's and C's bsc_qc (wall-clock times and memory) replaced by their
# column names.
p1_objects <- function(folder) {
  out <- list()
  for (f in sort(dir(folder))) {
    e <- new.env()
    load(file.path(folder, f), envir = e)
    v <- mget(sort(ls(e, all.names = TRUE)), envir = e)
    for (nm in intersect(c("M", "C"), names(v))) {
      if (!is.null(v[[nm]]$bsc_qc)) v[[nm]]$bsc_qc <- names(v[[nm]]$bsc_qc)
    }
    out[[f]] <- v
  }
  out
}
