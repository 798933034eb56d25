# The formats added by issue 29 end to end from the file, against GGIR
# (issue 29's done-means: "a week at 100 Hz from the file at least 50 times
# faster than GGIR::g.calibrate(), peak memory under 250 MB; ad hoc csv at
# least 20 times faster"): GGIR's g.calibrate (its file inspection
# included, the same params_rawdata) against gravcal::g.calibrate
# (GGIR-compatible; its whole result compared with GGIR's by identical(),
# every element but bsc_qc), calibrate(method = "ggir") and
# calibrate(method = "lightweight"), on 7 days at 100 Hz written as
#
# * a Parmay Matrix .bin (with temperature);
# * an ad hoc csv file read by GGIR's rmc.* parameters: UNIX seconds, x, y,
#   z in mg, temperature in C, a line of column names;
# * the same with text time stamps ("%Y-%m-%d %H:%M:%OS", 3 decimals) and 2
#   header lines before the column names (the rate from the header);
# * an Axivity csv export (OMGUI, UNIX time stamps; the format has no
#   temperature), which GGIR and gravcal resample block by block.
#
# GENEActiv's csv export is not in the table: gravcal does not read it
# (R/formats.R). The ad hoc files set rmc.noise = 0.013 / 1.2 (g): GGIR's
# default, 13, is meant in mg but compared with sd in g, which would make
# every window a rest window; with it the rest rule is GGIR's 13 mg (as in
# tests/testthat/helper-ggir.R).
#
# As bench/files.R: every contender runs in an R process of its own
# (bench/files-one.R), so that the peak resident memory it reports is its
# own, R included; seconds are the call's CPU time (user + system), the
# median of 3 runs for gravcal's contenders, one run for GGIR (minutes and
# GBs on a week of csv). Every file is read once (`cat`) before its
# contenders run, so that all find it in the page cache. The floors: `cat`
# (the system reading the file) and the decoder's (gravcal's decoder
# reading and decoding the whole file in its own mode, samples dropped).
#
# Run from the package root with gravcal and GGIR installed (`make
# bench-formats`, about 30 minutes, half of it writing the files the first
# time; GRAVCAL_BENCH_QUICK=1 for a smoke run
# of 1-day files). The files (about 8 GB) are written once into
# GRAVCAL_BENCH_DATA (default: a folder in tempdir()'s parent) and kept for
# reruns, each with its parameters (<file>.params.rds). Writes
# bench/results/formats.md and formats.csv.
#
# The recording: one simulated day (simulate_recording(), seed 1, at 100
# Hz) repeated, with scale, offset and temperature errors of the kind
# GGIR's model corrects (bench/files.R's "typical" series).
suppressPackageStartupMessages(library(gravcal))

t_start <- Sys.time()
quick <- nzchar(Sys.getenv("GRAVCAL_BENCH_QUICK"))
runs <- if (quick) 1L else 3L       # gravcal's contenders: median of `runs`
sf <- 100
# GRAVCAL_BENCH_DAYS=<n>: n-day files instead; GRAVCAL_BENCH_OUT=<name>:
# results in bench/results/<name>.md and .csv (default "formats")
days <- if (nzchar(Sys.getenv("GRAVCAL_BENCH_DAYS"))) {
  as.integer(Sys.getenv("GRAVCAL_BENCH_DAYS"))
} else if (quick) 1L else 7L
out_name <- Sys.getenv("GRAVCAL_BENCH_OUT", "formats")
data_dir <- Sys.getenv("GRAVCAL_BENCH_DATA",
                       file.path(dirname(tempdir()), "gravcal-bench-formats"))
dir.create(data_dir, showWarnings = FALSE, recursive = TRUE)
out_dir <- file.path("bench", "results")
lib <- Sys.getenv("R_LIBS")
say <- function(...) cat(format(Sys.time(), "%H:%M:%S"), ..., "\n")

# --- the files ------------------------------------------------------------------

day <- NULL
one_day <- function() {
  if (is.null(day)) {
    day <<- simulate_recording(hours = 24, sf = sf, seed = 1,
                               params = c(1.015, 0.985, 1.01, 0, 0, 0, 0.03, -0.025, 0.02),
                               tempoffset = c(0.002, -0.001, 0.0015))
  }
  day
}
start <- as.POSIXct("2024-01-01 00:00:00", tz = "UTC")
per_day <- 24 * 3600 * sf

# Appends the bytes of `from` after its first `skip` bytes to `to`, in
# pieces of 64 MB.
append_bytes <- function(to, from, skip = 0) {
  out <- file(to, "ab")
  on.exit(close(out))
  inp <- file(from, "rb")
  on.exit(close(inp), add = TRUE)
  if (skip > 0) readBin(inp, "raw", skip)
  repeat {
    b <- readBin(inp, "raw", 2^26)
    if (!length(b)) break
    writeBin(b, out)
  }
}

# Writes `days` days, one at a time (day k starting k days after `start`):
# day 0 into `tmp`, the others into a file of their own appended to it.
# `write_day(d, file, k)` writes day k and returns the file's parameters
# for GGIR (list() when it needs none); `skip`: the bytes of a day's file
# (k > 0) not to append (a header).
by_day <- function(tmp, write_day, skip = 0) {
  p <- write_day(one_day(), tmp, 0)
  part <- paste0(tmp, ".day")
  for (k in seq_len(days - 1)) {
    write_day(one_day(), part, k)
    append_bytes(tmp, part, skip)
  }
  unlink(part)
  p
}

rmc_noise <- list(rmc.noise = 0.013 / 1.2)
writers <- list(
  parmay = function(tmp) {
    p <- by_day(tmp, function(d, file, k) {
      gravcal:::write_parmay_bin(d, file, sf = sf, start = as.numeric(start) + k * 86400,
                                 packet_seconds = 60)
      list()
    }, skip = 524)
    # the header's packet count: all days' packets
    con <- file(tmp, "r+b")
    seek(con, 516, rw = "write")
    writeBin(gravcal:::parmay_le(days * 1440, 4), con)
    close(con)
    p
  },
  adhoc_unix = function(tmp) {
    p <- by_day(tmp, function(d, file, k) {
      gravcal:::write_adhoc_csv(d, file, sf = sf, colnames = k == 0, unit = "mg",
                                time = "UNIXsec", temperature = TRUE,
                                start = start + k * 86400)
    })
    c(p, rmc_noise)
  },
  adhoc_text = function(tmp) {
    p <- by_day(tmp, function(d, file, k) {
      gravcal:::write_adhoc_csv(d, file, sf = sf, colnames = k == 0, unit = "g",
                                header = if (k == 0) "device,gravcal-bench" else character(),
                                sf_header = k == 0, time = "POSIX",
                                temperature = TRUE, start = start + k * 86400)
    })
    c(p, list(rmc.format.time = "%Y-%m-%d %H:%M:%OS"), rmc_noise)
  },
  axivity_csv = function(tmp) {
    by_day(tmp, function(d, file, k) {
      gravcal:::write_axivity_csv(d, file, true_sf = sf, start = start + k * 86400)
      list()
    })
  },
  # a unisens folder (its acc.bin is the file given to the contenders) at
  # Movisens' 64 Hz: the same simulated day at that rate, repeated, and 10
  # minutes more (GGIR 3.3-9 stops with "startIndex out of bounds" on a
  # recording of whole days: its reader of acc.bin asks for a block after
  # the last when the samples fill its last block exactly)
  movisens = function(tmp) {
    d64 <- simulate_recording(hours = 24, sf = 64, seed = 1,
                              params = c(1.015, 0.985, 1.01, 0, 0, 0, 0.03, -0.025, 0.02),
                              tempoffset = c(0.002, -0.001, 0.0015))
    d64 <- d64[c(rep(seq_len(nrow(d64)), days), seq_len(600 * 64)), c("x", "y", "z", "temperature")]
    dir <- dirname(tmp)
    part <- paste0(dir, ".part")
    unlink(c(part, dir), recursive = TRUE)
    gravcal:::write_movisens(d64, part, sf = 64, start = format(start, "%Y-%m-%d %H:%M:%S"))
    file.rename(part, dir)
    list()
  })

specs <- data.frame(
  kind = c("parmay", "adhoc_unix", "adhoc_text", "axivity_csv", "movisens"),
  label = c("Parmay Matrix .bin", "ad hoc csv: UNIX s, mg, temperature",
            "ad hoc csv: text time, 2 header lines, g, temperature",
            "Axivity csv export (no temperature)", "Movisens (unisens folder, 64 Hz)"),
  ext = c("bin", "csv", "csv", "csv", ""), stringsAsFactors = FALSE)
# GRAVCAL_BENCH_FORMATS=<kinds, comma-separated>: only these files; the
# other files' rows are kept from the existing formats.csv (of the same
# number of days)
kinds <- Sys.getenv("GRAVCAL_BENCH_FORMATS")
if (nzchar(kinds)) specs <- specs[specs$kind %in% strsplit(kinds, ",")[[1]], ]
specs$days <- days
specs$path <- file.path(data_dir, sprintf("%s-%dd.%s", gsub("_", "-", specs$kind),
                                          days, specs$ext))
# a Movisens recording is a folder: the contenders are given its acc.bin,
# and its parameters file sits beside the folder
mv <- specs$kind == "movisens"
specs$path[mv] <- file.path(data_dir, sprintf("movisens-%dd", days), "acc.bin")
specs$params <- ifelse(mv, paste0(dirname(specs$path), ".params.rds"), paste0(specs$path, ".params.rds"))
for (i in seq_len(nrow(specs))) {
  if (!file.exists(specs$path[i]) || !file.exists(specs$params[i])) {
    say("writing", basename(specs$path[i]))
    tmp <- paste0(specs$path[i], ".part")
    p <- writers[[specs$kind[i]]](tmp)
    saveRDS(p, specs$params[i])
    if (file.exists(tmp)) file.rename(tmp, specs$path[i])  # (a Movisens folder is in place already)
  }
}
day <- NULL
specs$mb <- file.size(specs$path) / 1e6
if (nzchar(Sys.getenv("GRAVCAL_BENCH_WRITE_ONLY"))) {
  say("files written (GRAVCAL_BENCH_WRITE_ONLY)")
  quit(save = "no")
}

# --- the contenders ---------------------------------------------------------------

contenders <- c("GGIR::g.calibrate", "gravcal::g.calibrate",
                "calibrate(method = \"ggir\")", "calibrate(method = \"lightweight\")",
                "decode (read-once floor of the decoder)")
keep_dir <- tempfile("formats-results")
dir.create(keep_dir)

# One run of `contender` on spec row `s`; `save`: where a g.calibrate
# contender saves its result.
# GRAVCAL_BENCH_GGIR_MAX_GB=<n>: GGIR's process may take at most n GB of
# address space (prlimit --as), so that GGIR on a big file cannot take the
# machine's memory from the other work on it; beyond it GGIR fails with
# "cannot allocate", and its row says so.
ggir_max_gb <- as.numeric(Sys.getenv("GRAVCAL_BENCH_GGIR_MAX_GB", "0"))
run_one <- function(contender, s, save = NULL) {
  params <- if (length(readRDS(s$params))) s$params else "-"
  cmd <- file.path(R.home("bin"), "Rscript")
  args <- c("bench/files-one.R", shQuote(contender), shQuote(s$path), shQuote(params),
            if (!is.null(save)) shQuote(save))
  if (contender == "GGIR::g.calibrate" && ggir_max_gb > 0) {
    args <- c(sprintf("--as=%.0f", ggir_max_gb * 2^30), cmd, args)
    cmd <- "prlimit"
  }
  out <- system2(cmd, args, stdout = TRUE, stderr = TRUE,
                 env = if (nzchar(lib)) paste0("R_LIBS=", lib))
  line <- grep("^RESULT\t", out, value = TRUE)
  if (length(line) != 1) {
    why <- paste(utils::tail(out, 5), collapse = " / ")
    say("FAILED:", contender, basename(s$path), why)
    return(data.frame(seconds = NA, user = NA, system = NA, wall = NA, peak_mb = NA, base_mb = NA,
                      coef = NA, status = paste("FAILED:", gsub("[[:space:]]+", " ", why))))
  }
  f <- strsplit(line, "\t")[[1]]
  data.frame(seconds = as.numeric(f[8]), user = as.numeric(f[9]), system = as.numeric(f[10]),
             wall = as.numeric(f[3]),
             peak_mb = as.numeric(f[4]), base_mb = as.numeric(f[5]), coef = f[6],
             status = f[7])
}

cat_seconds <- function(path) {
  st <- system.time(system2("cat", shQuote(path), stdout = FALSE))
  c(cpu = st[["user.child"]] + st[["sys.child"]], wall = st[["elapsed"]])
}

# GGIR's and gravcal's lists: the same names, and every element but bsc_qc
# identical(). Returns c(compared, identical) and the names that differ.
compare_results <- function(ggir_rds, gravcal_rds) {
  R <- readRDS(ggir_rds)
  G <- readRDS(gravcal_rds)
  nms <- setdiff(names(R), "bsc_qc")
  same <- vapply(nms, function(nm) identical(G[[nm]], R[[nm]]), NA)
  list(compared = length(nms) + 1L,
       identical = sum(same) + identical(names(G), names(R)),
       differ = c(nms[!same], if (!identical(names(G), names(R))) "names"))
}

rows <- list()
for (i in seq_len(nrow(specs))) {
  s <- specs[i, ]
  cat_seconds(s$path)  # into the page cache
  floor_os <- vapply(seq_len(runs), function(r) cat_seconds(s$path), c(cpu = 0, wall = 0))
  rows[[length(rows) + 1]] <- data.frame(
    s[c("kind", "label", "days", "path", "mb")], contender = "cat (read-once floor of the system)",
    seconds = stats::median(floor_os["cpu", ]), user = NA, system = NA,
    wall = stats::median(floor_os["wall", ]),
    peak_mb = NA, base_mb = NA, coef = NA, status = NA, runs = runs,
    compared = NA, identical = NA, differ = NA)
  ggir_rds <- file.path(keep_dir, paste0(s$kind, "-ggir.rds"))
  for (cn in contenders) {
    n <- if (cn == "GGIR::g.calibrate") 1L else runs
    saves <- if (cn == "GGIR::g.calibrate") ggir_rds else if (cn == "gravcal::g.calibrate") {
      file.path(keep_dir, sprintf("%s-gravcal-%d.rds", s$kind, seq_len(n)))
    }
    rs <- do.call(rbind, lapply(seq_len(n), function(r) run_one(cn, s, saves[r])))
    if (all(is.na(rs$seconds)) && cn != "GGIR::g.calibrate") next
    rs <- if (all(is.na(rs$seconds))) rs[1, ] else rs[!is.na(rs$seconds), ]
    cmp <- list(compared = NA, identical = NA, differ = NA)
    if (cn == "gravcal::g.calibrate" && file.exists(ggir_rds)) {
      cs <- lapply(saves[file.exists(saves)], compare_results, ggir_rds = ggir_rds)
      cmp <- list(compared = sum(vapply(cs, `[[`, 0L, "compared")),
                  identical = sum(vapply(cs, `[[`, 0L, "identical")),
                  differ = paste(unique(unlist(lapply(cs, `[[`, "differ"))), collapse = " "))
    }
    say(basename(s$path), cn, sprintf("%.2f s CPU, %.2f s wall, %.0f MB%s", stats::median(rs$seconds),
                                      stats::median(rs$wall), max(rs$peak_mb),
                                      if (!is.na(cmp$compared)) sprintf(", %d/%d elements identical",
                                                                         cmp$identical, cmp$compared) else ""))
    rows[[length(rows) + 1]] <- data.frame(
      s[c("kind", "label", "days", "path", "mb")], contender = cn,
      seconds = stats::median(rs$seconds), user = stats::median(rs$user),
      system = stats::median(rs$system), wall = stats::median(rs$wall),
      peak_mb = max(rs$peak_mb), base_mb = stats::median(rs$base_mb),
      coef = rs$coef[nrow(rs)], status = rs$status[nrow(rs)], runs = nrow(rs),
      compared = cmp$compared, identical = cmp$identical, differ = cmp$differ)
  }
}
unlink(keep_dir, recursive = TRUE)
res <- do.call(rbind, rows)
kept_note <- ""
old_csv <- file.path(out_dir, paste0(out_name, ".csv"))
if (nzchar(kinds) && file.exists(old_csv)) {
  old <- utils::read.csv(old_csv, stringsAsFactors = FALSE)
  for (cl in setdiff(names(res), names(old))) old[[cl]] <- NA  # (columns added since)
  old <- old[!old$kind %in% res$kind & old$days == days, names(res)]
  if (nrow(old)) {
    old$path <- file.path(data_dir, old$path)
    res <- rbind(res, old)
    res <- res[order(match(res$kind, c("parmay", "adhoc_unix", "adhoc_text", "axivity_csv", "movisens"))), ]
    kept_note <- sprintf(" The rows of %s are from an earlier run of this script (GRAVCAL_BENCH_FORMATS), on the same files.",
                         paste(unique(old$kind), collapse = ", "))
  }
}
rownames(res) <- NULL

# --- ratios and the report ------------------------------------------------------------

of <- function(col, cn) res[[col]][res$contender == cn][match(res$kind, res$kind[res$contender == cn])]
# a GGIR run that failed (e.g. at GRAVCAL_BENCH_GGIR_MAX_GB): the CPU
# seconds it had used when it stopped (R's "Timing stopped at: user system
# elapsed"), a lower bound of what it needs
stopped <- regmatches(res$status, regexec("Timing stopped at: ([0-9.]+) ([0-9.]+)", res$status))
res$seconds_at_failure <- vapply(stopped, function(m) {
  if (length(m) == 3) as.numeric(m[2]) + as.numeric(m[3]) else NA_real_
}, 0)
res$speedup_vs_ggir <- of("seconds", "GGIR::g.calibrate") / res$seconds
# the same by user time alone: what the system time (GGIR's: mostly the
# kernel's page faults for its gigabytes, whose cost varies from machine
# to machine) leaves out
res$user_speedup_vs_ggir <- of("user", "GGIR::g.calibrate") / res$user
res$speedup_at_least <- of("seconds_at_failure", "GGIR::g.calibrate") / res$seconds
res$wall_speedup_vs_ggir <- of("wall", "GGIR::g.calibrate") / res$wall
res$same_coef_as_ggir <- ifelse(res$contender == "gravcal::g.calibrate",
                                res$coef == of("coef", "GGIR::g.calibrate"), NA)
res$ggir_status <- of("status", "GGIR::g.calibrate")
# (a Movisens folder's acc.bin named with its folder)
res$path <- ifelse(basename(res$path) == "acc.bin", file.path(basename(dirname(res$path)), "acc.bin"),
                   basename(res$path))
minutes <- as.numeric(difftime(Sys.time(), t_start, units = "mins"))
dir.create(out_dir, showWarnings = FALSE, recursive = TRUE)
utils::write.csv(res, file.path(out_dir, paste0(out_name, ".csv")), row.names = FALSE)

cpu <- tryCatch({
  l <- grep("model name", readLines("/proc/cpuinfo"), value = TRUE)[1]
  trimws(sub(".*:", "", l))
}, error = function(e) "unknown")
fmt_s <- function(s) ifelse(is.na(s), "", ifelse(s < 10, sprintf("%.2f", s), sprintf("%.1f", s)))
fmt_x <- function(r) ifelse(is.na(r), "", sprintf("%.0fx", r))
md <- c("# The formats of issue 29 end to end from the file",
        "",
        sprintf("Written by `bench/formats.R` on %s in %.0f minutes; %s, %d cores, R %s, GGIR %s, GGIRread %s, gravcal %s.%s",
                format(Sys.Date()), minutes, cpu, parallel::detectCores(), getRversion(),
                utils::packageVersion("GGIR"), utils::packageVersion("GGIRread"),
                utils::packageVersion("gravcal"),
                paste0(if (quick) " Quick run (GRAVCAL_BENCH_QUICK)." else "", kept_note)),
        sprintf("%d days at 100 Hz (one simulated day repeated; scale, offset and temperature errors GGIR's model fits). Each contender in its own R process, given the same params_rawdata. Seconds are the call's CPU time, user + system (median of %d runs for gravcal, one for GGIR): the machine's two cores were shared with other work, which inflates wall time unevenly; `%s.csv` has the wall times too. Ratios are GGIR's seconds over the contender's (the targets' lines give the ratio of user time alone too: GGIR's system time is mostly the kernel's page faults for its gigabytes, which cost more on some machines than on others). Peak is that process's peak resident memory, R included (an R process that has loaded gravcal holds about %.0f MB before the call). Files in the page cache. identical: gravcal::g.calibrate's returned list against GGIR's by `identical()`, element by element (every element but `bsc_qc`, and the names), in each of its runs.",
                days, runs, out_name, stats::median(res$base_mb[grepl("gravcal|calibrate\\(", res$contender)], na.rm = TRUE)),
        "",
        "| file | size (MB) | GGIR::g.calibrate (s, peak MB) | gravcal::g.calibrate (s, ratio, peak MB, identical) | calibrate ggir (s, ratio, peak MB) | calibrate lightweight (s, ratio, peak MB) | decode floor (s) | cat (s) |",
        "|---|---|---|---|---|---|---|---|")
for (k in unique(res$kind)) {
  r <- res[res$kind == k, ]
  g <- function(cn) r[r$contender == cn, ]
  cell <- function(cn, same = FALSE) {
    x <- g(cn)
    if (!nrow(x)) return("")
    ratio <- if (!is.na(x$speedup_vs_ggir)) fmt_x(x$speedup_vs_ggir) else
      if (!is.na(x$speedup_at_least)) paste0("at least ", fmt_x(x$speedup_at_least)) else ""
    paste0(fmt_s(x$seconds), " s, ", ratio, ", ", sprintf("%.0f MB", x$peak_mb),
           if (same) {
             if (is.na(x$compared)) ", not compared" else
               sprintf(", %d/%d identical%s", x$identical, x$compared,
                       if (!is.na(x$differ) && nzchar(x$differ)) paste0(" (differ: ", x$differ, ")") else "")
           })
  }
  gg <- g("GGIR::g.calibrate")
  dd <- g("decode (read-once floor of the decoder)")
  md <- c(md, sprintf("| %s<br>`%s` | %.0f | %s | %s | %s | %s | %s | %.3f |", r$label[1], r$path[1], r$mb[1],
                      if (!nrow(gg)) "" else if (is.na(gg$seconds)) {
                        sprintf("failed%s (see below)", if (is.na(gg$seconds_at_failure)) "" else
                          sprintf(" after %s s", fmt_s(gg$seconds_at_failure)))
                      } else
                        sprintf("%s s%s, %.0f MB", fmt_s(gg$seconds),
                                if (is.na(gg$user)) "" else
                                  sprintf(" (%s user, %s system)", fmt_s(gg$user), fmt_s(gg$system)),
                                gg$peak_mb),
                      cell("gravcal::g.calibrate", TRUE), cell("calibrate(method = \"ggir\")"),
                      cell("calibrate(method = \"lightweight\")"),
                      if (nrow(dd)) sprintf("%s s", fmt_s(dd$seconds)) else "",
                      g("cat (read-once floor of the system)")$seconds))
}
if (ggir_max_gb > 0) {
  md <- c(md, "", sprintf("GGIR ran with at most %g GB of address space (GRAVCAL_BENCH_GGIR_MAX_GB, so as not to take the shared machine's memory); a failed GGIR row ran out of it (GGIR then stops with a later error: its reader's failure is caught and ignored), and its ratios are lower bounds: the CPU seconds GGIR had used when it stopped over the contender's.", ggir_max_gb))
}
md <- c(md, "", "Issue 29's targets: binary decoders at least 50 times faster than GGIR with a peak under 250 MB; ad hoc csv at least 20 times faster.", "")
for (k in unique(res$kind)) {
  x <- res[res$kind == k & res$contender == "gravcal::g.calibrate", ]
  if (!nrow(x)) next
  r <- if (!is.na(x$speedup_vs_ggir)) x$speedup_vs_ggir else x$speedup_at_least
  if (is.na(r)) next
  binary <- k %in% c("parmay", "movisens")
  target <- if (binary) 50 else 20
  md <- c(md, sprintf("- %s: gravcal::g.calibrate %s%.0fx (target %dx: %s%s), peak %.0f MB%s.", x$label,
                      if (is.na(x$speedup_vs_ggir)) "at least " else "", r, target,
                      if (r >= target) "met" else if (is.na(x$speedup_vs_ggir)) "not shown" else "NOT met",
                      if (is.na(x$user_speedup_vs_ggir)) "" else
                        sprintf("; by user time alone %.0fx", x$user_speedup_vs_ggir),
                      x$peak_mb,
                      if (binary) sprintf(" (target 250 MB: %s)", if (x$peak_mb < 250) "met" else "NOT met") else ""))
}
md <- c(md, "", "GGIR's QC message on each file:", "")
for (k in unique(res$kind)) {
  r <- res[res$kind == k & res$contender == "GGIR::g.calibrate", ]
  if (nrow(r)) md <- c(md, sprintf("- %s: %s", r$path, gsub("|", "/", gsub("_", " ", r$status), fixed = TRUE)))
}
writeLines(md, file.path(out_dir, paste0(out_name, ".md")))
say("wrote", file.path(out_dir, paste0(out_name, ".md")), sprintf("(%.1f minutes)", minutes))
