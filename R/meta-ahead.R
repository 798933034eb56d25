# g.part1()'s first block of g.getmeta() read beside g.calibrate()'s pass.
#
# GGIR's part 1 calibrates (one pass over the file, on one thread), then
# g.getmeta() reads the file again, block by block. g.part1() opens the
# file for g.getmeta() before it calibrates; the core's pump then reads
# g.getmeta()'s first block into its store on a second thread while it
# makes the calibration's pass (gc_pump()'s `beside`), and g.getmeta()
# takes the open file, the block already read. The block is read by the
# same decoder, into the same store, with the same arguments as g.getmeta()
# would read it: only when it is read changes.
#
# The read ahead is left out (g.getmeta() opens the file itself, in GGIR's
# order) where opening the file errs, warns or prints anything (so that the
# user sees those where GGIR shows them), where the reader imputes time
# gaps or reads an ad hoc csv file (their counters and logs are read around
# the block's read), and on one thread (options(gravcal.threads = 1)).

ahead_state <- new.env(parent = emptyenv())

# Opens `datafile` for g.getmeta() as g.part1() calls it (the parameter
# lists pm, pr, pg, pc; inspectfileobject I), with its block store, and
# leaves it for meta_ahead_spec() and meta_ahead_take(). Returns TRUE when
# it did, FALSE when the file is not read ahead. meta_ahead_close() closes
# what was not taken.
meta_ahead_open <- function(datafile, pm, pr, pg, pc, I) {
  meta_ahead_close()
  if (gravcal_threads() < 2) return(FALSE)
  quiet <- TRUE
  got <- NULL
  said <- utils::capture.output(got <- tryCatch(withCallingHandlers({
    p <- meta_params(pm, pr, pg, pc, list())
    # (a reader that imputes time gaps, or an ad hoc csv file, is known
    # before the file is opened: not opened twice)
    fmt <- if (is.null(p$.rmc)) file_format(datafile, "datafile")
    gaps <- is.null(fmt) || (isTRUE(p$imputeTimegaps) && isTRUE(format_entry(fmt)$ggir_timegaps))
    list(p = p, src = if (!gaps) meta_open(datafile, p, I))
  }, warning = function(w) {
    quiet <<- FALSE
    invokeRestart("muffleWarning")
  }, message = function(m) {
    quiet <<- FALSE
    invokeRestart("muffleMessage")
  }), error = function(e) NULL))
  if (is.null(got$src)) return(FALSE)
  src <- got$src
  ms <- NULL
  if (quiet && !length(said) && is.null(got$p$.rmc) && !isTRUE(src$getmeta_timegaps) &&
      !isTRUE(src$epoch_gaps)) {
    ms <- meta_store(src, time = FALSE)
  }
  if (is.null(ms) || ms$wear) {
    if (!is.null(ms)) gc_meta_store_release(ms$store)
    gc_decoder_close(src$native$ptr)
    return(FALSE)
  }
  src$ahead_store <- ms
  ahead_state$pending <- list(
    datafile = datafile, p = got$p, inspect = I, src = src, started = FALSE,
    spec = list(store = ms$store, decoder = src$native$ptr, units = src$units,
                chunk = ms$chunk, want_time = ms$want_time))
  TRUE
}

# The read the pump makes beside its pass (gc_pump()'s `beside`): once, for
# the first pump after meta_ahead_open(); NULL otherwise.
meta_ahead_spec <- function() {
  a <- ahead_state$pending
  if (is.null(a) || a$started) return(NULL)
  ahead_state$pending$started <- TRUE
  a$spec
}

# The source meta_ahead_open() left, for g.getmeta() on the same file with
# the same parameters and inspectfileobject (NULL otherwise: then what was
# left is closed).
meta_ahead_take <- function(datafile, p, inspectfileobject) {
  a <- ahead_state$pending
  if (is.null(a)) return(NULL)
  ahead_state$pending <- NULL
  if (identical(a$datafile, datafile) && identical(a$p, p) &&
      identical(a$inspect, inspectfileobject)) {
    ahead_state$taken <- (ahead_state$taken %||% 0) + 1  # (for the tests)
    return(a$src)
  }
  gc_meta_store_release(a$spec$store)
  gc_decoder_close(a$src$native$ptr)
  NULL
}

# What meta_ahead_open() left and g.getmeta() did not take, closed (g.part1()
# calls this when a file is done, or failed).
meta_ahead_close <- function() {
  a <- ahead_state$pending
  if (is.null(a)) return(invisible())
  ahead_state$pending <- NULL
  gc_meta_store_release(a$spec$store)
  gc_decoder_close(a$src$native$ptr)
  invisible()
}
