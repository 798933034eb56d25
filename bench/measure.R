# Measuring helpers shared by bench/speed.R and bench/memory.R.

proc_kb <- function(field) {
  f <- "/proc/self/status"
  if (!file.exists(f)) return(NA_real_)
  l <- grep(paste0("^", field, ":"), readLines(f), value = TRUE)
  if (!length(l)) return(NA_real_)
  as.numeric(gsub("[^0-9]", "", l))
}

reset_peak <- function() {
  ok <- tryCatch({
    cat("5", file = "/proc/self/clear_refs")
    TRUE
  }, error = function(e) FALSE, warning = function(w) FALSE)
  ok
}

# Time one evaluation of `f()`; peak memory (MB) above the resident memory
# before the call.
# Time one evaluation of `f()` (after a full gc). Memory in a separate
# evaluation (peak_run()): returning freed memory to the system before a
# call, which a fair peak needs, makes the call's own allocations fault in
# fresh pages, which costs time on this virtual machine.
measure <- function(f) {
  invisible(gc(full = TRUE))
  t <- system.time(value <- f(), gcFirst = FALSE)[["elapsed"]]
  list(time = t, value = value)
}

# Peak resident memory above the resident memory before the call (MB), and
# the peak of R's own heap above what it held before (gc()'s "max used": R
# objects only, without memory-mapped files; data.table's fread maps the
# csv file, whose pages count in the resident memory).
peak_run <- function(f) {
  g0 <- gc(full = TRUE, reset = TRUE)
  gravcal:::gc_release_memory()
  can_peak <- reset_peak()
  before <- proc_kb("VmRSS")
  f()
  peak <- if (can_peak) (proc_kb("VmHWM") - before) / 1024 else NA_real_
  g1 <- gc()
  c(peak_mb = peak, heap_mb = sum(g1[, 6]) - sum(g0[, 2]))
}

# Median time over `n` runs, the last value, and the memory of one more run.
repeat_measure <- function(f, n = runs) {
  m <- lapply(seq_len(n), function(i) measure(f))
  mem <- peak_run(f)
  list(time = stats::median(vapply(m, `[[`, 0, "time")),
       times = vapply(m, `[[`, 0, "time"),
       peak_mb = mem[["peak_mb"]], heap_mb = mem[["heap_mb"]],
       value = m[[n]]$value)
}

quiet <- function(expr) {
  out <- NULL
  utils::capture.output(out <- suppressWarnings(expr))
  out
}

