# Speed of the native .gt3x decoder against read.gt3x on a 7-day 100 Hz file.
#
# Writes a week of ACTIVITY2 records (60.48 M samples, log.bin 368 MB) with
# write_gt3x() to tempdir(), deflated and stored, then decodes each file in
# its own R process under /usr/bin/time -v (peak resident memory):
#   - native blocks: native_block() of 1e6 samples, discarded (the decoder
#     and the glue, what streaming calibration costs);
#   - native whole: native_read_all() (a data frame of x, y, z, time);
#   - read.gt3x: read.gt3x(file, asDataFrame = TRUE), the reference.
# Run from the package root with gravcal and read.gt3x installed:
#   Rscript bench/decode-gt3x.R       (about 3 minutes)
# Prints a markdown table.
days <- as.numeric(Sys.getenv("GRAVCAL_BENCH_DAYS", "7"))
sf <- 100
dir <- tempfile("gt3x-bench")
dir.create(dir)
n <- days * 86400 * sf
set.seed(1)
x <- cbind(rnorm(n, 0, 0.3), rnorm(n, 0, 0.3), rnorm(n, 1, 0.3))
files <- c(deflated = file.path(dir, "week.gt3x"), stored = file.path(dir, "week-stored.gt3x"))
for (k in names(files)) {
  t0 <- proc.time()[["elapsed"]]
  gravcal:::write_gt3x(x, files[[k]], sf, 1600000000, deflate = k == "deflated")
  cat(sprintf("wrote %s: %.0f MB in %.1f s\n", k, file.size(files[[k]]) / 1e6,
              proc.time()[["elapsed"]] - t0))
}
rm(x)
invisible(gc())

code <- c(
  blocks = paste(
    "h <- gravcal:::native_open(f, 'gt3x', list()); n <- 0",
    "repeat { b <- gravcal:::native_block(h, NULL, 1e6, TRUE, TRUE); n <- n + b$to; if (b$done) break }",
    sep = "; "),
  whole = "n <- nrow(gravcal:::native_read_all(f, 'gt3x'))",
  read.gt3x = "n <- nrow(read.gt3x::read.gt3x(f, asDataFrame = TRUE))")

run <- function(f, what) {
  script <- tempfile(fileext = ".R")
  writeLines(c(sprintf("f <- '%s'", f), "t0 <- proc.time()[['elapsed']]", code[[what]],
               "cat('RESULT', n, proc.time()[['elapsed']] - t0, '\\n')"), script)
  out <- system2("/usr/bin/time", c("-v", file.path(R.home("bin"), "Rscript"), script),
                 stdout = TRUE, stderr = TRUE)
  res <- strsplit(grep("^RESULT", out, value = TRUE), " ")[[1]]
  rss <- as.numeric(sub(".*: ", "", grep("Maximum resident", out, value = TRUE)))
  data.frame(file = basename(f), reader = what, samples = as.numeric(res[2]),
             seconds = as.numeric(res[3]), mb_s = file.size(f) / 1e6 / as.numeric(res[3]),
             peak_rss_mb = rss / 1024)
}
tab <- do.call(rbind, lapply(files, function(f) do.call(rbind, lapply(names(code), run, f = f))))
cat("\n| file | reader | samples | seconds | MB/s (file) | peak RSS (MB) |\n|---|---|---|---|---|---|\n")
cat(sprintf("| %s | %s | %.0f | %.2f | %.0f | %.0f |\n", tab$file, tab$reader, tab$samples,
            tab$seconds, tab$mb_s, tab$peak_rss_mb), sep = "")
unlink(dir, recursive = TRUE)
