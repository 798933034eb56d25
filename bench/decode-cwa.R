# Benchmark: decoding a 7-day 100 Hz synthetic .cwa file with the native
# decoder (compat = 1 in GGIR's windows, and compat = 0) and with GGIRread's
# readAxivity in GGIR's windows, each in its own R process under
# /usr/bin/time -v (peak RSS). Prints a table. Run from the package root
# with gravcal installed:  Rscript bench/decode-cwa.R [days]
# (GRAVCAL_BENCH_DIR keeps the written file between runs; default tempdir()).
# "seconds" is the whole process (R start-up included), "decode_s" the
# reading loop alone.
args <- commandArgs(TRUE)
days <- if (length(args)) as.numeric(args[1]) else 7
sf <- 100
f <- file.path(Sys.getenv("GRAVCAL_BENCH_DIR", tempdir()), sprintf("bench-%gd.cwa", days))
if (!file.exists(f)) {
  n <- days * 86400 * sf
  tt <- seq_len(n) / sf
  x <- cbind(sin(tt / 7), 0.9 * cos(tt / 7), 0.3 + 0.1 * sin(tt))
  w <- system.time(gravcal:::write_cwa(x, f, sf = sf, start = 1.7e9 + 0.25))
  rm(x, tt)
  cat(sprintf("wrote %s (%.0f MB) in %.1f s\n", f, file.size(f) / 2^20, w[["elapsed"]]))
}
B <- round(12 * 3600 * sf / 80)  # GGIR's blocks per readAxivity call
code <- c(
  native = sprintf('t <- system.time({h <- gravcal:::native_open("%s", "cwa", list(compat = 1)); n <- 0
    repeat { b <- gravcal:::native_block(h, %d, %d, TRUE, TRUE); n <- n + b$to
             if (b$done || (b$to == 0 && b$units == 0)) break }}); cat(t[["elapsed"]], n, "\n")', f, B, B * 120 + 1000),
  native_raw = sprintf('t <- system.time({h <- gravcal:::native_open("%s", "cwa", list(compat = 0)); n <- 0
    repeat { b <- gravcal:::native_block(h, NULL, 1e6, TRUE, TRUE); n <- n + b$to
             if (b$done || (b$to == 0 && b$units == 0)) break }}); cat(t[["elapsed"]], n, "\n")', f),
  readAxivity = sprintf('t <- system.time({s <- 0; n <- 0; hd <- NULL
    repeat { P <- GGIRread::readAxivity("%s", start = s, end = s + %d, progressBar = FALSE,
               desiredtz = "", configtz = "", interpolationType = 1, frequency_tol = 0.1, header = hd)
             if (is.null(P$data)) break; hd <- P$header; n <- n + nrow(P$data); s <- s + %d }})
    cat(t[["elapsed"]], n, "\n")', f, B, B))
rows <- lapply(names(code), function(k) {
  script <- tempfile(fileext = ".R")
  writeLines(code[[k]], script)
  log <- tempfile()
  t0 <- Sys.time()
  out <- system2("/usr/bin/time", c("-v", "Rscript", script), stdout = TRUE, stderr = log)
  el <- as.numeric(Sys.time() - t0, units = "secs")
  v <- readLines(log)
  rss <- as.numeric(sub(".*: ", "", grep("Maximum resident", v, value = TRUE)))
  r <- as.numeric(strsplit(trimws(out[length(out)]), " ")[[1]])
  data.frame(reader = k, samples = r[2], seconds = round(el, 2), decode_s = r[1],
             MB_per_s = round(file.size(f) / 2^20 / r[1], 1), peak_rss_MB = round(rss / 1024))
})
print(do.call(rbind, rows), row.names = FALSE)
