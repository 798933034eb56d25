# End to end from device files (issue 16): GGIR's g.calibrate (its file
# inspection included) against gravcal::g.calibrate (GGIR-compatible),
# calibrate(method = "ggir") and calibrate(method = "lightweight"), on
# recordings of 1, 7 and 28 days at 100 Hz with temperature written as
# Axivity .cwa, GENEActiv .bin, ActiGraph .gt3x and ActiGraph csv; plus the
# read-once floors of each file: the operating system's (`cat` to
# /dev/null, the file in the page cache) and the decoder's (gravcal's
# decoder reading and decoding the whole file, samples dropped).
#
# Every contender runs in an R process of its own (bench/files-one.R), so
# that the peak resident memory it reports is its own, R included. Every
# file is read once before its contenders run, so that all of them find it
# in the page cache.
#
# Run from the package root with gravcal and GGIR installed (`make
# bench-files`, about 30 minutes; GRAVCAL_BENCH_QUICK=1 for a smoke run of
# 1-day files). The files are written once into GRAVCAL_BENCH_DATA
# (default: a folder in tempdir()'s parent; about 9 GB) and kept for reruns.
# Writes bench/results/files.md and files.csv.
#
# The recordings: one simulated day (simulate_recording(), seed 1) repeated.
# "typical": scale, offset and temperature errors of the kind GGIR's model
# corrects, so that GGIR's procedure reaches its error target and stops
# reading once it has more than 168 hours (so on 28-day files; 7 days are
# not more than 168 hours, and are read whole). "never": the
# same with cross-axis terms, which GGIR's model does not have, so that the
# target (0.01 g) is never reached and the procedure keeps refitting to the
# end of the file; written as .bin only.
suppressPackageStartupMessages(library(gravcal))

quick <- nzchar(Sys.getenv("GRAVCAL_BENCH_QUICK"))
runs <- if (quick) 1L else 3L       # gravcal's contenders: median of `runs`
runs_ggir <- 1L                     # GGIR: one run (it takes minutes)
sf <- 100
data_dir <- Sys.getenv("GRAVCAL_BENCH_DATA",
                       file.path(dirname(tempdir()), "gravcal-bench-files"))
dir.create(data_dir, showWarnings = FALSE, recursive = TRUE)
out_dir <- file.path("bench", "results")
lib <- Sys.getenv("R_LIBS")
say <- function(...) cat(format(Sys.time(), "%H:%M:%S"), ..., "\n")

# --- the files ------------------------------------------------------------------

params <- list(
  typical = c(1.015, 0.985, 1.01, 0, 0, 0, 0.03, -0.025, 0.02),
  never = c(1.015, 0.985, 1.01, 0.04, -0.03, 0.035, 0.03, -0.025, 0.02))
day_of <- local({
  cache <- list()
  function(series) {
    if (is.null(cache[[series]])) {
      cache[[series]] <<- simulate_recording(hours = 24, sf = sf, seed = 1,
                                             params = params[[series]],
                                             tempoffset = c(0.002, -0.001, 0.0015))
    }
    cache[[series]]
  }
})
start <- as.POSIXct("2024-01-01 00:00:00", tz = "UTC")
per_day <- 24 * 3600 * sf

# Writes the file whole under a temporary name, then renames it, so that a
# file in data_dir is always complete.
write_file <- function(format, days, series, path) {
  d <- day_of(series)
  tmp <- paste0(path, ".part")
  xyz <- as.matrix(d[, c("x", "y", "z")])
  if (format == "cwa") {
    for (k in seq_len(days) - 1) {
      gravcal:::write_cwa(xyz, tmp, sf = sf, start = as.numeric(start) + k * 86400,
                          temperature = d$temperature, append = k > 0,
                          block0 = k * per_day / 120)
    }
  } else if (format == "bin") {
    for (k in seq_len(days) - 1) {
      gravcal:::write_geneactiv_bin(d, tmp, sf = sf, start = start + k * 86400,
                                    append = k > 0, page0 = k * per_day / 300,
                                    pages_total = days * per_day / 300)
    }
  } else if (format == "gt3x") {
    gravcal:::write_gt3x(xyz[rep(seq_len(per_day), days), ], tmp, sf = sf, start = start)
  } else if (format == "csv") {
    rows <- rep(seq_len(per_day), days)
    gravcal:::write_actigraph_csv_file(d[rows, c("x", "y", "z")], tmp, sf = sf,
                                       start = format(start, "%Y-%m-%d %H:%M:%S"))
  }
  file.rename(tmp, path)
}

specs <- expand.grid(days = c(1, 7, 28), format = c("cwa", "bin", "gt3x", "csv"),
                     series = "typical", stringsAsFactors = FALSE)
specs <- rbind(specs, data.frame(days = c(1, 7, 28), format = "bin", series = "never"))
# .gt3x and csv stop at 7 days (a 28-day ActiGraph csv is 10 GB of text)
specs <- specs[!(specs$days == 28 & specs$format %in% c("gt3x", "csv")), ]
if (quick) specs <- specs[specs$days == 1, ]
specs$path <- file.path(data_dir, sprintf("%s-%dd.%s", specs$series, specs$days,
                                          specs$format))
for (i in seq_len(nrow(specs))) {
  if (!file.exists(specs$path[i])) {
    say("writing", basename(specs$path[i]))
    write_file(specs$format[i], specs$days[i], specs$series[i], specs$path[i])
  }
}
specs$mb <- file.size(specs$path) / 1e6

# --- the contenders ---------------------------------------------------------------

# GRAVCAL_BENCH_GGIR_FROM=<an earlier files.csv>: take GGIR's rows from it
# instead of running GGIR again (it takes most of the half hour), when only
# gravcal changed; the report says so.
ggir_from_path <- Sys.getenv("GRAVCAL_BENCH_GGIR_FROM")
ggir_from <- if (nzchar(ggir_from_path)) {
  utils::read.csv(ggir_from_path, stringsAsFactors = FALSE)
}
ggir_from_note <- if (nzchar(ggir_from_path)) {
  sprintf(" GGIR's rows are those of an earlier run of this script on the same files (%s), GGIR and the files being unchanged.",
          basename(ggir_from_path))
} else ""

contenders <- c("GGIR::g.calibrate", "gravcal::g.calibrate",
                "calibrate(method = \"ggir\")", "calibrate(method = \"lightweight\")",
                "decode (read-once floor of the decoder)")

run_one <- function(contender, path) {
  out <- system2(file.path(R.home("bin"), "Rscript"),
                 c("bench/files-one.R", shQuote(contender), shQuote(path)),
                 stdout = TRUE, stderr = TRUE, env = if (nzchar(lib)) paste0("R_LIBS=", lib))
  line <- grep("^RESULT\t", out, value = TRUE)
  if (length(line) != 1) {
    say("FAILED:", contender, basename(path), paste(utils::tail(out, 5), collapse = " | "))
    return(NULL)
  }
  f <- strsplit(line, "\t")[[1]]
  data.frame(seconds = as.numeric(f[8]), wall = as.numeric(f[3]),
             peak_mb = as.numeric(f[4]), base_mb = as.numeric(f[5]), coef = f[6],
             status = f[7])
}

cat_seconds <- function(path) {
  st <- system.time(system2("cat", shQuote(path), stdout = FALSE))
  c(cpu = st[["user.child"]] + st[["sys.child"]], wall = st[["elapsed"]])
}

rows <- list()
for (i in seq_len(nrow(specs))) {
  p <- specs$path[i]
  cat_seconds(p)  # into the page cache
  floor_os <- vapply(seq_len(runs), function(r) cat_seconds(p), c(cpu = 0, wall = 0))
  rows[[length(rows) + 1]] <- data.frame(specs[i, ], contender = "cat (read-once floor of the system)",
                                         seconds = stats::median(floor_os["cpu", ]),
                                         wall = stats::median(floor_os["wall", ]),
                                         peak_mb = NA, base_mb = NA,
                                         coef = NA, status = NA, runs = runs)
  for (cn in contenders) {
    n <- if (cn == "GGIR::g.calibrate") runs_ggir else runs
    if (cn == "GGIR::g.calibrate" && !is.null(ggir_from)) {
      # GGIR's row from an earlier run on the same file (GGIR unchanged)
      old <- ggir_from[ggir_from$path == basename(p) &
                         ggir_from$contender == cn, ]
      if (nrow(old) == 1) {
        rows[[length(rows) + 1]] <- data.frame(
          specs[i, ], contender = cn, seconds = old$seconds, wall = old$wall,
          peak_mb = old$peak_mb, base_mb = old$base_mb, coef = old$coef,
          status = old$status, runs = old$runs)
        next
      }
    }
    rs <- do.call(rbind, lapply(seq_len(n), function(r) run_one(cn, p)))
    if (is.null(rs)) next
    say(basename(p), cn, sprintf("%.2f s CPU, %.2f s wall, %.0f MB", stats::median(rs$seconds),
                                 stats::median(rs$wall), max(rs$peak_mb)))
    rows[[length(rows) + 1]] <- data.frame(specs[i, ], contender = cn,
                                           seconds = stats::median(rs$seconds),
                                           wall = stats::median(rs$wall),
                                           peak_mb = max(rs$peak_mb),
                                           base_mb = stats::median(rs$base_mb),
                                           coef = rs$coef[n], status = rs$status[n], runs = n)
  }
}
res <- do.call(rbind, rows)
rownames(res) <- NULL

# --- ratios and the report ------------------------------------------------------------

key <- paste(res$series, res$format, res$days)
ggir_s <- res$seconds[res$contender == "GGIR::g.calibrate"][
  match(key, key[res$contender == "GGIR::g.calibrate"])]
ggir_coef <- res$coef[res$contender == "GGIR::g.calibrate"][
  match(key, key[res$contender == "GGIR::g.calibrate"])]
decode_s <- res$seconds[res$contender == "decode (read-once floor of the decoder)"][
  match(key, key[res$contender == "decode (read-once floor of the decoder)"])]
cat_s <- res$seconds[res$contender == "cat (read-once floor of the system)"][
  match(key, key[res$contender == "cat (read-once floor of the system)"])]
res$speedup_vs_ggir <- ggir_s / res$seconds
ggir_w <- res$wall[res$contender == "GGIR::g.calibrate"][
  match(key, key[res$contender == "GGIR::g.calibrate"])]
res$wall_speedup_vs_ggir <- ggir_w / res$wall
res$over_decode_floor <- res$seconds / decode_s
res$seconds_per_day <- res$seconds / res$days
res$same_coef_as_ggir <- ifelse(res$contender == "gravcal::g.calibrate",
                                res$coef == ggir_coef, NA)
res$decode_over_cat <- ifelse(res$contender == "decode (read-once floor of the decoder)",
                              res$seconds / cat_s, NA)
res$ggir_status <- res$status[res$contender == "GGIR::g.calibrate"][
  match(key, key[res$contender == "GGIR::g.calibrate"])]
res$path <- basename(res$path)
dir.create(out_dir, showWarnings = FALSE, recursive = TRUE)
utils::write.csv(res, file.path(out_dir, "files.csv"), row.names = FALSE)

cpu <- tryCatch({
  l <- grep("model name", readLines("/proc/cpuinfo"), value = TRUE)[1]
  trimws(sub(".*:", "", l))
}, error = function(e) "unknown")
fmt_s <- function(s) ifelse(is.na(s), "", ifelse(s < 10, sprintf("%.2f", s), sprintf("%.1f", s)))
fmt_x <- function(r) ifelse(is.na(r), "", sprintf("%.0fx", r))
md <- c("# End to end from device files",
        "",
        sprintf("Written by `bench/files.R` on %s; %s, %d cores, R %s, GGIR %s, GGIRread %s, gravcal %s.%s",
                format(Sys.Date()), cpu, parallel::detectCores(),
                getRversion(), utils::packageVersion("GGIR"),
                utils::packageVersion("GGIRread"), utils::packageVersion("gravcal"),
                paste0(if (quick) " Quick run (GRAVCAL_BENCH_QUICK)." else "",
                       ggir_from_note)),
        sprintf("Each contender in its own R process (all single-threaded). Seconds are the call's CPU time, user + system (median of %d runs for gravcal, %d for GGIR): the machine's two cores were shared with other work, which inflates wall time unevenly; `files.csv` has the wall times too. Ratios are GGIR's seconds over the contender's. Peak is that process's peak resident memory, R included (an R process that has loaded gravcal holds about %.0f MB before the call). Files in the page cache. x decode: the call's time over the decoder's read-once floor on the same file.",
                runs, runs_ggir, stats::median(res$base_mb[grepl("gravcal|calibrate\\(", res$contender)], na.rm = TRUE)),
        "")
for (series in unique(res$series)) {
  md <- c(md, sprintf("## %s", if (series == "typical")
    "A device GGIR's model fits (GGIR's procedure stops reading once it has more than 168 hours and a small error: 28-day files are read in part)" else
      "A device with cross-axis error (GGIR's error target is never reached)"), "",
    "| file | size (MB) | GGIR::g.calibrate (s, peak MB) | gravcal::g.calibrate (s, ratio, peak MB, x decode, same coefficients) | calibrate ggir (s, ratio, peak MB, x decode) | calibrate lightweight (s, ratio, peak MB, x decode) | decode floor (s, x cat) | cat (s) |",
    "|---|---|---|---|---|---|---|---|")
  for (k in unique(key[res$series == series])) {
    r <- res[key == k, ]
    g <- function(cn) r[r$contender == cn, ]
    cell <- function(cn, same = FALSE) {
      x <- g(cn)
      if (!nrow(x)) return("")
      paste0(fmt_s(x$seconds), " s, ", fmt_x(x$speedup_vs_ggir), ", ",
             sprintf("%.0f MB", x$peak_mb), sprintf(", %.1fx decode", x$over_decode_floor),
             if (same) paste0(", ", if (isTRUE(x$same_coef_as_ggir)) "identical" else "DIFFERENT"))
    }
    gg <- g("GGIR::g.calibrate")
    dd <- g("decode (read-once floor of the decoder)")
    md <- c(md, sprintf("| %s | %.0f | %s | %s | %s | %s | %s | %s |", r$path[1], r$mb[1],
                        if (nrow(gg)) sprintf("%s s, %.0f MB", fmt_s(gg$seconds), gg$peak_mb) else "",
                        cell("gravcal::g.calibrate", TRUE), cell("calibrate(method = \"ggir\")"),
                        cell("calibrate(method = \"lightweight\")"),
                        if (nrow(dd)) sprintf("%s s, %.1fx", fmt_s(dd$seconds), dd$decode_over_cat) else "",
                        sprintf("%.3f", g("cat (read-once floor of the system)")$seconds)))
  }
  md <- c(md, "")
}
md <- c(md, "## Time per day (seconds per day of recording)", "",
        "| series | format | contender | 1 d | 7 d | 28 d |", "|---|---|---|---|---|---|")
for (series in unique(res$series)) for (fm in unique(res$format[res$series == series])) {
  for (cn in c("GGIR::g.calibrate", "gravcal::g.calibrate", "calibrate(method = \"ggir\")",
               "calibrate(method = \"lightweight\")")) {
    r <- res[res$series == series & res$format == fm & res$contender == cn, ]
    if (!nrow(r)) next
    v <- vapply(c(1, 7, 28), function(d) {
      s <- r$seconds_per_day[r$days == d]
      if (length(s)) sprintf("%.3f", s) else ""
    }, "")
    md <- c(md, sprintf("| %s | %s | %s | %s |", series, fm, cn, paste(v, collapse = " | ")))
  }
}
md <- c(md, "", "GGIR's QC message on each file:", "")
for (k in unique(key)) {
  r <- res[key == k & res$contender == "GGIR::g.calibrate", ]
  if (nrow(r)) md <- c(md, sprintf("- %s: %s", r$path, gsub("_", " ", r$status)))
}
writeLines(md, file.path(out_dir, "files.md"))
say("wrote", file.path(out_dir, "files.md"))
