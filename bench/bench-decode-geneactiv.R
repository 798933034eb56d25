# Benchmark of the native GENEActiv decoder against GGIRread::readGENEActiv
# on a synthetic 100 Hz recording written to tempdir(). Each reader runs in
# its own R process under /usr/bin/time -v (peak RSS). Prints a table.
#   Rscript bench/bench-decode-geneactiv.R [days] [lib]
# The file is read in GGIR's blocks (round(14512 * sf / 50 * 0.5) pages,
# readGENEActiv(start = s, end = s + B - 1) against read(out, B)), and whole
# by native_read_all() when `days` <= 2 (a week as one data frame is 2.4 GB).
args <- commandArgs(trailingOnly = TRUE)
days <- if (length(args) >= 1) as.numeric(args[1]) else 7
lib <- if (length(args) >= 2) args[2] else .libPaths()[1]
library(gravcal, lib.loc = lib)
sf <- 100
n <- round(days * 86400 * sf / 300) * 300
f <- file.path(tempdir(), sprintf("bench_%gd.bin", days))
wt <- system.time({
  # three smooth axes, no temperature column (the writer gives 20 C): about
  # 1.5 GB for a week
  x <- 0.9 * sin(seq_len(n) / 700)
  y <- 0.4 * cos(seq_len(n) / 500)
  rec <- data.frame(x = x, y = y, z = sqrt(1 - x^2 - y^2))
  rm(x, y)
  gravcal:::write_geneactiv_bin(rec, f, sf = sf, eol = "\r\n",
                                gain = c(25875, 25734, 25538),
                                offset = c(439, -662, -3056))
  rm(rec)
})[["elapsed"]]
mb <- file.size(f) / 1e6
B <- round((14512 * (sf / 50)) * 0.5)
run <- function(code) {
  script <- tempfile(fileext = ".R")
  writeLines(c(sprintf("library(gravcal, lib.loc = '%s')", lib), sprintf("f <- '%s'", f),
               sprintf("B <- %d", B), code), script)
  out <- system2("/usr/bin/time", c("-v", "Rscript", script), stdout = TRUE, stderr = TRUE)
  el <- as.numeric(sub(".*: ", "", grep("^ELAPSED", out, value = TRUE)))
  rss <- as.numeric(sub(".*: ", "", grep("Maximum resident", out, value = TRUE))) / 1024
  n <- as.numeric(sub(".*: ", "", grep("^SAMPLES", out, value = TRUE)))
  c(seconds = el, peak_rss_mb = rss, samples = n)
}
native_blocks <- '
t0 <- proc.time()[["elapsed"]]; n <- 0
h <- gravcal:::native_open(f, "geneactiv")
repeat { b <- gravcal:::native_block(h, B, B * 300, TRUE, TRUE); n <- n + b$to
  if (b$done || b$to == 0) break }
cat("ELAPSED:", proc.time()[["elapsed"]] - t0, "\nSAMPLES:", n, "\n")'
ref_blocks <- '
t0 <- proc.time()[["elapsed"]]; n <- 0; s <- 1
repeat { d <- GGIRread::readGENEActiv(f, start = s, end = s + B - 1, desiredtz = "",
  configtz = "")$data.out; n <- n + nrow(d); if (nrow(d) == 0) break; s <- s + B }
cat("ELAPSED:", proc.time()[["elapsed"]] - t0, "\nSAMPLES:", n, "\n")'
native_all <- '
t0 <- proc.time()[["elapsed"]]
d <- gravcal:::native_read_all(f, "geneactiv")
cat("ELAPSED:", proc.time()[["elapsed"]] - t0, "\nSAMPLES:", nrow(d), "\n")'
res <- rbind(native_blocks = run(native_blocks), readGENEActiv_blocks = run(ref_blocks))
if (days <= 2) res <- rbind(res, native_read_all = run(native_all))
res <- cbind(res, mb_per_s = mb / res[, "seconds"])
cat(sprintf("file: %.0f MB, %d samples (%g days at %g Hz), written in %.1f s\n",
            mb, n, days, sf, wt))
print(round(res, 2))
unlink(f)
