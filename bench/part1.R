# GGIR part 1's epoch signals (issue 43): GGIR's g.getmeta() against
# gravcal's, and GGIR's part 1 pair (g.calibrate() then g.getmeta()) against
# gravcal's, on a week at 100 Hz that looks like a person's week (nights at
# rest, sedentary hours: simulate_recording()'s day, seed 1, repeated),
# written as Axivity .cwa and GENEActiv .bin. Each contender runs in an R
# process of its own (Rscript), cold, the file in the page cache; the time
# is the process's elapsed time, the memory its peak resident set (GNU time).
# GGIR's results and gravcal's are compared (identical() on every element
# of M but bsc_qc) in a last process.
#
#   Rscript bench/part1.R       (from the package root, gravcal and GGIR
#                                installed; about 20 minutes)
#
# GRAVCAL_BENCH_DATA: where the week files are written and kept (default: a
# folder beside tempdir()). Writes bench/results/part1.md and part1.csv.
suppressPackageStartupMessages(library(gravcal))
sf <- 100
days <- as.numeric(Sys.getenv("GRAVCAL_BENCH_DAYS", "7"))
data_dir <- Sys.getenv("GRAVCAL_BENCH_DATA", file.path(dirname(tempdir()), "gravcal-bench-part1"))
dir.create(data_dir, showWarnings = FALSE, recursive = TRUE)
out_dir <- file.path("bench", "results")
say <- function(...) cat(format(Sys.time(), "%H:%M:%S"), ..., "\n")

files <- c(cwa = file.path(data_dir, sprintf("week%g.cwa", days)),
           bin = file.path(data_dir, sprintf("week%g.bin", days)))
# GRAVCAL_BENCH_FORMATS: some of them only ("cwa,bin")
only <- Sys.getenv("GRAVCAL_BENCH_FORMATS")
if (nzchar(only)) files <- files[intersect(names(files), strsplit(only, ",")[[1]])]
if (!all(file.exists(files))) {
  files <- c(cwa = file.path(data_dir, sprintf("week%g.cwa", days)),
             bin = file.path(data_dir, sprintf("week%g.bin", days)))[names(files)]
  say("writing the week files")
  day <- simulate_recording(hours = 24, sf = sf, seed = 1,
                            tempoffset = c(0.002, -0.001, 0.0015),
                            start = as.POSIXct("2024-03-04 08:00:00", tz = "UTC"))
  n <- nrow(day)
  wk <- day[rep(seq_len(n), days), ]
  wk$time <- day$time[1] + (seq_len(nrow(wk)) - 1) / sf
  if ("cwa" %in% names(files)) {
    gravcal:::write_cwa(as.matrix(wk[, c("x", "y", "z")]), files[["cwa"]], sf = sf,
                        start = as.numeric(wk$time[1]), temperature = wk$temperature)
  }
  if ("bin" %in% names(files)) {
    gravcal:::write_geneactiv_bin(wk, files[["bin"]], sf = sf, start = "2024-03-04 08:00:00")
  }
  rm(day, wk)
}

# One contender in a process of its own: elapsed seconds and peak RSS (MB).
run <- function(code, file) {
  script <- tempfile(fileext = ".R")
  writeLines(c(sprintf("f <- %s", deparse(file)), code), script)
  for (i in 1:2) invisible(readBin(file, "raw", 1))  # in the page cache
  tm <- tempfile()
  t0 <- Sys.time()
  status <- system2("/usr/bin/time", c("-f", "%M", "-o", tm, "Rscript", script),
                    stdout = FALSE, stderr = FALSE)
  el <- as.numeric(difftime(Sys.time(), t0, units = "secs"))
  if (status != 0) stop("contender failed: ", paste(code, collapse = "; "))
  c(seconds = el, rss_mb = as.numeric(readLines(tm)[1]) / 1024)
}
quiet <- "q <- function(e) { o <- NULL; utils::capture.output(o <- suppressWarnings(e)); o }"
contenders <- list(
  "GGIR g.getmeta" = c(quiet, "I <- q(GGIR::g.inspectfile(f))",
                       "M <- q(GGIR::g.getmeta(f, inspectfileobject = I, verbose = FALSE))"),
  "gravcal g.getmeta" = c(quiet, "M <- q(gravcal::g.getmeta(f, verbose = FALSE))"),
  "GGIR g.calibrate + g.getmeta" = c(quiet, "I <- q(GGIR::g.inspectfile(f))",
    "C <- q(GGIR::g.calibrate(f, inspectfileobject = I, verbose = FALSE))",
    paste("M <- q(GGIR::g.getmeta(f, inspectfileobject = I, verbose = FALSE, offset = C$offset,",
          "scale = C$scale, tempoffset = C$tempoffset, meantempcal = C$meantempcal))")),
  "gravcal g.calibrate + g.getmeta" = c(quiet, "C <- q(gravcal::g.calibrate(f, verbose = FALSE))",
    paste("M <- q(gravcal::g.getmeta(f, verbose = FALSE, offset = C$offset,",
          "scale = C$scale, tempoffset = C$tempoffset, meantempcal = C$meantempcal))")))
rows <- list()
for (fmt in names(files)) {
  for (nm in names(contenders)) {
    say(fmt, nm)
    r <- run(contenders[[nm]], files[[fmt]])
    rows[[length(rows) + 1]] <- data.frame(format = fmt, contender = nm, seconds = r[["seconds"]],
                                           rss_mb = r[["rss_mb"]])
  }
}
res <- do.call(rbind, rows)
# identical results?
same <- vapply(files, function(f) {
  q <- function(e) { o <- NULL; utils::capture.output(o <- suppressWarnings(e)); o }
  I <- q(GGIR::g.inspectfile(f))
  G <- q(GGIR::g.getmeta(f, inspectfileobject = I, verbose = FALSE))
  M <- q(gravcal::g.getmeta(f, verbose = FALSE))
  all(vapply(setdiff(names(G), "bsc_qc"), function(k) identical(G[[k]], M[[k]]), TRUE))
}, TRUE)
utils::write.csv(res, file.path(out_dir, "part1.csv"), row.names = FALSE)
ratio <- function(fmt, a, b) {
  res$seconds[res$format == fmt & res$contender == a] / res$seconds[res$format == fmt & res$contender == b]
}
md <- c("# GGIR part 1's epoch signals: GGIR against gravcal (bench/part1.R)", "",
        sprintf("%g days at %g Hz (simulate_recording()'s day, nights at rest, repeated), %s, R %s, GGIR %s, GGIRread %s; %s.",
                days, sf, R.version$platform, getRversion(), utils::packageVersion("GGIR"),
                utils::packageVersion("GGIRread"), format(Sys.Date())),
        "Each contender in a cold R process of its own; elapsed seconds and peak resident memory.", "",
        "| format | contender | seconds | peak MB |", "|---|---|---:|---:|",
        sprintf("| %s | %s | %.1f | %.0f |", res$format, res$contender, res$seconds, res$rss_mb), "",
        "| format | g.getmeta: GGIR / gravcal | part 1 pair: GGIR / gravcal | M identical (all but bsc_qc) |",
        "|---|---:|---:|---|",
        vapply(names(files), function(fmt) {
          sprintf("| %s | %.1fx | %.1fx | %s |", fmt,
                  ratio(fmt, "GGIR g.getmeta", "gravcal g.getmeta"),
                  ratio(fmt, "GGIR g.calibrate + g.getmeta", "gravcal g.calibrate + g.getmeta"),
                  same[[fmt]])
        }, ""))
writeLines(md, file.path(out_dir, "part1.md"))
cat(md, sep = "\n")
