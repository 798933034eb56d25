# Speed of the native csv decoder against the reference reader (fread as
# GGIR's g.readaccfile calls it) on a synthetic week at 100 Hz written as an
# ActiGraph csv with ActiLife time stamps (R/write-csv.R). Each reader runs
# in its own R process under /usr/bin/time -v (peak RSS).
#   Rscript bench/decode-csv.R [hours] [stamps]
# Needs gravcal installed (R_LIBS) and data.table.
args <- commandArgs(trailingOnly = TRUE)
hours <- if (length(args) >= 1) as.numeric(args[1]) else 168
stamps <- if (length(args) >= 2) args[2] else "actilife"
file <- file.path(tempdir(), sprintf("week-%s.csv", stamps))
sf <- 100
wt <- system.time(gravcal:::write_actigraph_csv_synthetic(file, hours, sf, stamps))[["elapsed"]]
mb <- file.size(file) / 1e6
cat(sprintf("wrote %.0f MB (%g h at %g Hz, stamps %s) in %.1f s\n", mb, hours, sf, stamps, wt))
B <- 300 * round((14512 * (sf / 50)) * 0.5)  # g.calibrate's rows per block
runs <- list(
  native_all = sprintf('d <- gravcal:::native_read_all("%s", "actigraph_csv"); n <- nrow(d)', file),
  native_blocks = sprintf('h <- gravcal:::native_open("%s", "actigraph_csv"); n <- 0
    repeat { b <- gravcal:::native_block(h, %d, %d, time = FALSE); n <- n + b$to; if (b$done) break }', file, B, B),
  fread_blocks = sprintf('s <- 11; n <- 0
    repeat { d <- tryCatch(data.table::fread("%s", nrows = %d, skip = s, dec = ".", header = FALSE,
      showProgress = FALSE, data.table = FALSE), error = function(e) NULL)
      if (is.null(d) || !nrow(d)) break; n <- n + nrow(d); s <- s + %d; rm(d); gc() }', file, B, B))
for (nm in names(runs)) {
  code <- sprintf('t <- system.time({%s})[["elapsed"]]; cat(sprintf("RESULT %%d %%.2f\\n", as.integer(n), t))', runs[[nm]])
  script <- tempfile(fileext = ".R")
  writeLines(code, script)
  out <- system2("/usr/bin/time", c("-v", file.path(R.home("bin"), "Rscript"), script),
                 stdout = TRUE, stderr = TRUE)
  res <- strsplit(sub("RESULT ", "", grep("^RESULT", out, value = TRUE)), " ")[[1]]
  rss <- as.numeric(sub(".*: ", "", grep("Maximum resident", out, value = TRUE))) / 1024
  secs <- as.numeric(res[2])
  cat(sprintf("%-14s %9s samples %7.1f s %7.0f MB/s  peak RSS %6.0f MB\n", nm, res[1],
              secs, mb / secs, rss))
}
unlink(file)
