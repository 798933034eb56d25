# Is gravcal's part 1 linear in the recording's length? gravcal::g.part1()
# (calibration and meta file) on 1, 3 and 7 days of the same kind
# (simulate_recording()'s day at 100 Hz, nights at rest, repeated: the
# files of bench/part1.R), each run in a cold R process of its own, the day
# lengths interleaved, `reps` times each. Reports elapsed and CPU seconds
# (user + system, which load on the machine moves less than the elapsed
# time), peak resident memory, and the straight line through the CPU
# seconds (a fixed cost, a cost per day) with each length's departure.
#
#   Rscript bench/part1-linear.R [reps] [format]
# (GRAVCAL_BENCH_DATA: the folder of bench/part1.R's files, written when
# absent.) Results: bench/results/part1-linear.{md,csv}.

args <- commandArgs(trailingOnly = TRUE)
reps <- if (length(args) >= 1) as.integer(args[[1]]) else 3L
fmt <- if (length(args) >= 2) args[[2]] else "cwa"
sf <- 100
data_dir <- Sys.getenv("GRAVCAL_BENCH_DATA", file.path(dirname(tempdir()), "gravcal-bench-part1"))
dir.create(data_dir, showWarnings = FALSE, recursive = TRUE)
out_dir <- file.path("bench", "results")
suppressPackageStartupMessages(library(gravcal))
say <- function(...) message(format(Sys.time(), "%H:%M:%S "), ...)

# the day and the week, each alone in a folder (g.part1() reads folders)
make <- function(days) {
  f <- file.path(data_dir, sprintf("week%g.%s", days, fmt))
  if (!file.exists(f)) {
    say("writing ", f)
    day <- simulate_recording(hours = 24, sf = sf, seed = 1,
                              tempoffset = c(0.002, -0.001, 0.0015),
                              start = as.POSIXct("2024-03-04 08:00:00", tz = "UTC"))
    wk <- day[rep(seq_len(nrow(day)), days), ]
    wk$time <- day$time[1] + (seq_len(nrow(wk)) - 1) / sf
    write_recording(wk, f, sf = sf)
  }
  d <- file.path(data_dir, sprintf("folder-%s-%gd", fmt, days))
  dir.create(d, showWarnings = FALSE)
  l <- file.path(d, basename(f))
  if (!file.exists(l)) file.symlink(normalizePath(f), l)
  d
}
days <- c(1, 3, 7)
folders <- stats::setNames(vapply(days, make, ""), paste0(days, "d"))

run <- function(folder) {
  script <- tempfile(fileext = ".R")
  out <- tempfile("part1-linear-")
  on.exit(unlink(out, recursive = TRUE))
  writeLines(c(sprintf("d <- %s", deparse(folder)),
               sprintf("md <- %s", deparse(file.path(out, "output_folder"))),
               "invisible(utils::capture.output(suppressWarnings(",
               "  gravcal::g.part1(datadir = d, metadatadir = md, f1 = 1, verbose = FALSE))))"), script)
  for (f in dir(folder, full.names = TRUE)) invisible(readBin(f, "raw", 1))
  tm <- tempfile()
  status <- system2("/usr/bin/time", c("-f", "'%e %U %S %M'", "-o", tm, "Rscript", script),
                    stdout = FALSE, stderr = FALSE)
  if (status != 0) stop("g.part1() failed on ", folder)
  v <- as.numeric(strsplit(readLines(tm)[1], " ")[[1]])
  c(seconds = v[1], cpu = v[2] + v[3], rss_mb = v[4] / 1024)
}

rows <- list()
for (i in seq_len(reps)) {
  for (k in names(folders)) {
    say(k, " ", i)
    r <- run(folders[[k]])
    rows[[length(rows) + 1]] <- data.frame(format = fmt, length = k, rep = i, seconds = r[["seconds"]],
                                           cpu = r[["cpu"]], rss_mb = r[["rss_mb"]])
  }
}
res <- do.call(rbind, rows)
dir.create(out_dir, showWarnings = FALSE)
utils::write.csv(res, file.path(out_dir, "part1-linear.csv"), row.names = FALSE)
med <- function(k, v) stats::median(res[[v]][res$length == k])
cpu <- vapply(names(folders), med, 0, v = "cpu")
line <- stats::lm(cpu ~ days)
fixed <- unname(stats::coef(line)[1])
per_day <- unname(stats::coef(line)[2])
dep <- 100 * (cpu - stats::fitted(line)) / cpu
startup <- system.time(system2("Rscript", c("-e", shQuote("invisible(loadNamespace('gravcal'))"))))[["elapsed"]]
md <- c("# gravcal's part 1: 1, 3 and 7 days (bench/part1-linear.R)", "",
        sprintf(paste0("gravcal::g.part1() on 1, 3 and 7 days at %g Hz (.%s, simulate_recording()'s day repeated), ",
                       "each run in a cold R process, interleaved, %d runs each; medians. %s, R %s, gravcal %s; %s. ",
                       "Load on the machine during the run: %s."),
                sf, fmt, reps, R.version$platform, getRversion(), utils::packageVersion("gravcal"),
                format(Sys.Date()), paste(round(as.numeric(strsplit(readLines("/proc/loadavg"), " ")[[1]][1:3]), 1), collapse = ", ")),
        "", "| days | elapsed s | CPU s | peak MB | CPU off the line |", "|---:|---:|---:|---:|---:|",
        sprintf("| %g | %.2f | %.2f | %.0f | %+.1f %% |", days,
                vapply(names(folders), med, 0, v = "seconds"), cpu,
                vapply(names(folders), med, 0, v = "rss_mb"), dep), "",
        sprintf(paste0("CPU seconds = %.2f + %.3f per day (least squares over the three lengths): linear, with a ",
                       "fixed cost that a cold R process which only loads gravcal (%.2f s elapsed) accounts for ",
                       "most of. Peak memory grows with the recording only up to GGIR's 24-hour block."),
                fixed, per_day, startup))
writeLines(md, file.path(out_dir, "part1-linear.md"))
cat(md, sep = "\n")
