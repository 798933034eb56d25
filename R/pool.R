# Device pooling (calibrate_files(pool = "device")): recordings of one
# device that cannot be calibrated alone, calibrated on their rest windows
# together.

# Statuses of a recording that cannot be calibrated alone, for pooling.
poolable_status <- c("sphere_not_covered", "bins_incomplete", "too_short",
                     "no_rest")

# calibrate_files(pool = "device"): see its documentation.
pool_devices <- function(paths, ids, tab, fits, method, args, alpha = 0.01) {
  need <- tab$status %in% poolable_status & !is.na(tab$serial)
  for (s in unique(tab$serial[need])) {
    idx <- which(tab$serial == s & !is.na(tab$serial))
    todo <- idx[need[idx]]
    note <- function(why) {
      tab$message[todo] <<- join_notes(tab$message[todo], paste0(
        "not pooled: ", why))
    }
    if (length(idx) < 2) {
      note(sprintf("no other recording of device %s", s))
      next
    }
    alone <- idx[tab$status[idx] == "ok" & !vapply(fits[idx], is.null, NA)]
    p <- pairwise_wald(fits[alone])
    if (length(p) && any(p <= alpha / length(p))) {
      note(sprintf(paste0("the recordings of device %s that calibrate alone ",
                          "disagree (Wald test, smallest p = %.2g)"), s,
                   min(p)))
      next
    }
    pf <- tryCatch(pooled_fit(paths[idx], fits[idx], method, args),
                   error = function(e) e)
    if (inherits(pf, "error")) {
      note(sprintf("the pooled fit failed: %s", conditionMessage(pf)))
      next
    }
    if (!identical(pf$status, "ok")) {
      note(sprintf(paste0("pooled, the %d recordings of device %s still do ",
                          "not calibrate (%s)"), length(idx), s, pf$status))
      next
    }
    # the recordings whose rest windows were pooled
    from <- if (is.null(pf$pooled$used)) idx else idx[pf$pooled$used]
    pf$pooled <- list(serial = s, files = ids[from])
    if (is.null(pf$input)) pf$input <- list(source = "pooled")
    pf$input$serial <- s
    for (i in todo) {
      row <- cohort_row(paths[i], ids[i], pf, NULL, "", tab$seconds[i], method)
      row$pooled <- TRUE
      row$message <- sprintf(paste0(
        "calibrated with the rest windows of %d recordings of device %s ",
        "(%s), pooled; alone: %s"), length(from), s,
        paste(ids[from], collapse = ", "), tab$status[i])
      row$hours <- tab$hours[i]
      row$samples <- tab$samples[i]
      tab[i, ] <- row
      fits[[i]] <- pf
    }
  }
  list(tab = tab, fits = fits)
}

# p-values of the Wald tests (wald_test()) of every pair of fits' common
# coefficients, pairs without any left out.
pairwise_wald <- function(fits) {
  if (length(fits) < 2) return(numeric(0))
  pairs <- utils::combn(length(fits), 2)
  p <- apply(pairs, 2, function(ij) wald_test(fits[[ij[1]]], fits[[ij[2]]]))
  p[!is.na(p)]
}

# One fit on the rest windows of several recordings of a device: `paths`
# and `fits`, their calibrations alone.
pooled_fit <- function(paths, fits, method, args) {
  if (method == "ggir") return(pooled_ggir(fits, args))
  la <- lightweight_args(args[names(args) != "sf"])
  rargs <- la$args$rest_windows[intersect(names(la$args$rest_windows),
                                          c("window", "max_range", "axes",
                                            "skip_zero", "reader"))]
  ws <- lapply(paths, function(f) {
    do.call(rest_windows, c(list(x = f, sf = sf_for_file(f, args$sf)), rargs))
  })
  w <- do.call(rbind, ws)
  attr(w, "sf") <- attr(ws[[1]], "sf")
  attr(w, "window") <- attr(ws[[1]], "window")
  attr(w, "samples") <- sum(vapply(ws, function(x) attr(x, "samples"), 0))
  attr(w, "samples_total") <- NA_real_
  inp <- attr(ws[[1]], "input")
  inp$source <- "pooled"
  inp$samples <- attr(w, "samples")
  inp$report <- NULL
  attr(w, "input") <- inp
  # segments and the adaptive budget are for one recording
  la$choice$segments <- NULL
  la$choice$budget <- "all"
  lightweight_from_windows(w, la$args, la$choice, la$max_norm_error,
                           la$range_g, call = NULL, file = NULL,
                           max_identical = la$max_identical,
                           off_sphere = la$off_sphere)
}

# The GGIR method pooled. Each recording's rest windows are those GGIR's
# procedure kept when it calibrated that recording alone (its spheredata,
# in fit$ggir): block rules, duplicate filter, temperature checks and the
# user's settings (sf, chunksize, max_sd, use_temp, reader, ggir_compat)
# applied, and nothing decoded twice. minloadcrit stays a rule of each
# recording's reading, as in GGIR: a recording that could not calibrate
# alone never reached the error target, so it gives all its rest windows; one
# that could gives those its own fit used. A recording too short for the
# procedure (GGIR's spheredata then holds all its windows, not its rest
# windows) gives none. Then the procedure's last step on the union: at least
# min_rest windows, every axis beyond -+spherecrit, the method's ICP, GGIR's
# errors, its QC message (minloadcrit against the hours of the pool) and
# gravcal's status (ggir_fit()). The temperature term is fitted when every
# recording pooled used it.
pooled_ggir <- function(fits, args) {
  k <- ggir_constants
  a <- utils::modifyList(
    list(spherecrit = k$spherecrit, minloadcrit = k$minloadcrit,
         max_iter = k$max_iter, tol = k$tol, ggir_compat = FALSE),
    args[intersect(names(args), c("spherecrit", "minloadcrit", "max_iter",
                                  "tol", "ggir_compat"))])
  res <- lapply(fits, function(f) f[["ggir"]])
  has <- vapply(res, function(r) {
    NROW(r$spheredata) > 0 && !identical(r$QCmessage, ggir_messages[["no_data"]])
  }, NA)
  if (!any(has)) abort("no recording of the device has rest windows")
  res <- res[has]
  temp <- vapply(res, function(r) isTRUE(r$use.temp), NA)
  cols <- seq_len(if (all(temp)) 8 else 7)
  ft <- do.call(rbind, lapply(res, function(r) unname(as.matrix(r$spheredata[, cols]))))
  hours <- sum(vapply(res, function(r) r$nhoursused, 0))
  # the procedure's last stages (sphere check, fit, errors, QC) on the
  # pooled rest windows
  sf <- fits[has][[1]]$input$sf %||% 1
  opts <- ggir_options(a$ggir_compat, sf, a$spherecrit, a$minloadcrit,
                       ggir_constants$max_sd, a$max_iter, a$tol, FALSE)
  r <- gc_ggir_fit_table(ft, any(temp), hours, opts)
  r$windows <- sum(vapply(fits[has], function(f) as.numeric(f$n_windows), 0))
  out <- ggir_result(r, data.frame(), list(source = "pooled"))
  fit <- ggir_fit(out, a$ggir_compat, call = NULL, a$minloadcrit)
  fit$pooled <- list(used = has)
  fit
}
