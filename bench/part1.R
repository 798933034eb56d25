# GGIR part 1's epoch signals (issue 43): GGIR's g.getmeta() against
# gravcal's, and GGIR's part 1 pair (g.calibrate() then g.getmeta()) against
# gravcal's, on a week at 100 Hz that looks like a person's week (nights at
# rest, sedentary hours: simulate_recording()'s day, seed 1, repeated),
# written as Axivity .cwa and GENEActiv .bin. Each contender runs in an R
# process of its own (Rscript), cold, the file in the page cache; the time
# is the process's elapsed time, the memory its peak resident set (GNU time).
# GGIR's results and gravcal's are compared (identical() on every element
# of M but bsc_qc) in a last process. Contenders: g.getmeta() alone (GGIR's
# given its g.inspectfile()), and part 1 as a GGIR user runs it, g.part1()
# on a folder holding the file (inspection, calibration, the epoch signals,
# the meta file), with the default metrics and (.cwa) with every metric
# GGIR computes itself (all do.* but the counts of external packages).
#
#   Rscript bench/part1.R       (from the package root, gravcal and GGIR
#                                installed; about 40 minutes)
#
# GRAVCAL_BENCH_DATA: where the week files are written and kept (default: a
# folder beside tempdir()). GRAVCAL_BENCH_FORMATS ("cwa,bin,gt3x") and
# GRAVCAL_BENCH_CONTENDERS (a regular expression on the contenders' names)
# run some of them; GRAVCAL_BENCH_EVERY ("cwa,bin,gt3x", default "cwa")
# the formats of the every-metric pairs; GRAVCAL_BENCH_NAME names the
# results (default "part1": bench/results/part1.md and part1.csv).
suppressPackageStartupMessages(library(gravcal))
sf <- 100
days <- as.numeric(Sys.getenv("GRAVCAL_BENCH_DAYS", "7"))
data_dir <- Sys.getenv("GRAVCAL_BENCH_DATA", file.path(dirname(tempdir()), "gravcal-bench-part1"))
dir.create(data_dir, showWarnings = FALSE, recursive = TRUE)
out_dir <- file.path("bench", "results")
say <- function(...) cat(format(Sys.time(), "%H:%M:%S"), ..., "\n")

files <- c(cwa = file.path(data_dir, sprintf("week%g.cwa", days)),
           bin = file.path(data_dir, sprintf("week%g.bin", days)),
           gt3x = file.path(data_dir, sprintf("week%g.gt3x", days)))
# GRAVCAL_BENCH_FORMATS: some of them only ("cwa,bin")
only <- Sys.getenv("GRAVCAL_BENCH_FORMATS")
if (nzchar(only)) files <- files[intersect(names(files), strsplit(only, ",")[[1]])]
if (!all(file.exists(files))) {
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
  if ("bin" %in% names(files) && !file.exists(files[["bin"]])) {
    gravcal:::write_geneactiv_bin(wk, files[["bin"]], sf = sf, start = "2024-03-04 08:00:00")
  }
  if ("gt3x" %in% names(files) && !file.exists(files[["gt3x"]])) {
    gravcal:::write_gt3x(as.matrix(wk[, c("x", "y", "z")]), files[["gt3x"]], sf = sf,
                         start = wk$time[1])
  }
  rm(day, wk)
}
# each file alone in a folder (g.part1() reads folders), as a link
folders <- vapply(names(files), function(fmt) {
  d <- file.path(data_dir, paste0("folder-", fmt))
  dir.create(d, showWarnings = FALSE)
  l <- file.path(d, basename(files[[fmt]]))
  if (!file.exists(l)) file.symlink(normalizePath(files[[fmt]]), l)
  d
}, "")

# One contender in a process of its own: elapsed seconds, peak RSS (MB),
# user and system CPU seconds and minor page faults (GNU time). The last
# two say what the machine charges for fresh memory: on a virtual machine
# whose page faults are dear (stop 61's: about 3 us a 4 KB page, and freed
# memory handed back to the host), a process that allocates much pays in
# elapsed time what elsewhere it would not.
# env: "NAME=value" strings for the contender's process (the huge-page
# contender below).
run <- function(code, file, folder, env = character()) {
  script <- tempfile(fileext = ".R")
  out <- tempfile("part1-out-")
  writeLines(c(sprintf("f <- %s", deparse(file)), sprintf("d <- %s", deparse(folder)),
               sprintf("md <- %s", deparse(file.path(out, "output_folder"))),
               # the folders GGIR::GGIR() makes before it calls g.part1()
               "for (s in c('meta/basic', 'results/QC')) dir.create(file.path(md, s), recursive = TRUE)",
               code), script)
  on.exit(unlink(out, recursive = TRUE))
  for (i in 1:2) invisible(readBin(file, "raw", 1))  # in the page cache
  tm <- tempfile()
  t0 <- Sys.time()
  status <- system2("/usr/bin/time", c("-f", shQuote("%M %U %S %R"), "-o", tm, "Rscript", script),
                    stdout = FALSE, stderr = FALSE, env = env)
  el <- as.numeric(difftime(Sys.time(), t0, units = "secs"))
  if (status != 0) stop("contender failed: ", paste(code, collapse = "; "))
  g <- as.numeric(strsplit(utils::tail(readLines(tm), 1), " ", fixed = TRUE)[[1]])
  # the M of the meta file a g.part1() wrote (compared below)
  meta <- list.files(file.path(out, "output_folder", "meta", "basic"), full.names = TRUE)
  M <- NULL
  if (length(meta) == 1) {
    e <- new.env()
    load(meta, envir = e)
    M <- e$M
  }
  list(stats = c(seconds = el, rss_mb = g[1] / 1024, user = g[2], sys = g[3], faults = g[4]),
       M = M)
}
quiet <- "q <- function(e) { o <- NULL; utils::capture.output(o <- suppressWarnings(e)); o }"
contenders <- list(
  "GGIR g.getmeta" = c(quiet, "I <- q(GGIR::g.inspectfile(f))",
                       "M <- q(GGIR::g.getmeta(f, inspectfileobject = I, verbose = FALSE))"),
  "gravcal g.getmeta" = c(quiet, "M <- q(gravcal::g.getmeta(f, verbose = FALSE))"),
  "GGIR g.part1" = c(quiet, "q(GGIR::g.part1(datadir = d, metadatadir = md, f1 = 1, verbose = FALSE))"),
  "gravcal g.part1" = c(quiet, "q(gravcal::g.part1(datadir = d, metadatadir = md, f1 = 1, verbose = FALSE))"))
every <- c("pm <- GGIR::load_params()$params_metrics",
           "for (k in grep('^do[.]', names(pm), value = TRUE)) pm[[k]] <- !k %in% c('do.brondcounts', 'do.neishabouricounts')")
contenders[["GGIR g.part1, every metric"]] <- c(quiet, every,
  "q(GGIR::g.part1(datadir = d, metadatadir = md, f1 = 1, verbose = FALSE, params_metrics = pm))")
contenders[["gravcal g.part1, every metric"]] <- c(quiet, every,
  "q(gravcal::g.part1(datadir = d, metadatadir = md, f1 = 1, verbose = FALSE, params_metrics = pm))")
# GGIR's part 1 at its best on a machine whose fresh memory is dear: glibc's
# malloc asked to advise transparent huge pages for what it maps (glibc >=
# 2.35), so that R's large vectors, given back to the kernel when freed and
# fresh when allocated again, fault 2 MB at a time (bench/speed-notes.md,
# "Fresh memory"). Users do not run it so; it is here so that a ratio can be
# read against the fastest GGIR this machine gives.
hugepages <- "GLIBC_TUNABLES=glibc.malloc.hugetlb=1"
contenders[["GGIR g.part1, huge pages"]] <- contenders[["GGIR g.part1"]]
contenders[["gravcal g.part1, huge pages"]] <- contenders[["gravcal g.part1"]]
contenders[["GGIR g.part1, every metric, huge pages"]] <- contenders[["GGIR g.part1, every metric"]]
contender_env <- list("GGIR g.part1, huge pages" = hugepages, "gravcal g.part1, huge pages" = hugepages,
                      "GGIR g.part1, every metric, huge pages" = hugepages)
pick <- Sys.getenv("GRAVCAL_BENCH_CONTENDERS")
if (nzchar(pick)) contenders <- contenders[grepl(pick, names(contenders))]
name <- Sys.getenv("GRAVCAL_BENCH_NAME", "part1")
# the formats of the every-metric pairs (GGIR takes 4 to 12 minutes a week
# for each): GRAVCAL_BENCH_EVERY, comma-separated, default the .cwa only
every_formats <- strsplit(Sys.getenv("GRAVCAL_BENCH_EVERY", "cwa"), ",", fixed = TRUE)[[1]]
rows <- list()
metas <- list()  # the M of each g.part1() contender's meta file
for (fmt in names(files)) {
  for (nm in names(contenders)) {
    if (grepl("every metric", nm) && !fmt %in% every_formats) next
    say(fmt, nm)
    env <- if (is.null(contender_env[[nm]])) character() else contender_env[[nm]]
    out <- run(contenders[[nm]], files[[fmt]], folders[[fmt]], env = env)
    r <- out$stats
    if (!is.null(out$M)) metas[[paste(fmt, nm)]] <- out$M
    rows[[length(rows) + 1]] <- data.frame(format = fmt, contender = nm, seconds = r[["seconds"]],
                                           rss_mb = r[["rss_mb"]], user_s = r[["user"]],
                                           sys_s = r[["sys"]], minor_faults = r[["faults"]])
  }
}
res <- do.call(rbind, rows)
# identical results? GGIR's part 1 and gravcal's, the M of their meta files
# where both ran; otherwise g.getmeta() of each on the file
same_M <- function(G, M) all(vapply(setdiff(names(G), "bsc_qc"), function(k) identical(G[[k]], M[[k]]), TRUE))
same <- vapply(names(files), function(fmt) {
  G <- metas[[paste(fmt, "GGIR g.part1")]]
  if (is.null(G)) G <- metas[[paste(fmt, "GGIR g.part1, huge pages")]]
  M <- metas[[paste(fmt, "gravcal g.part1")]]
  if (!is.null(G) && !is.null(M)) return(same_M(G, M))
  f <- files[[fmt]]
  q <- function(e) { o <- NULL; utils::capture.output(o <- suppressWarnings(e)); o }
  I <- q(GGIR::g.inspectfile(f))
  G <- q(GGIR::g.getmeta(f, inspectfileobject = I, verbose = FALSE))
  M <- q(gravcal::g.getmeta(f, verbose = FALSE))
  same_M(G, M)
}, TRUE)
utils::write.csv(res, file.path(out_dir, paste0(name, ".csv")), row.names = FALSE)
ratio <- function(fmt, a, b) {
  r <- res$seconds[res$format == fmt & res$contender == a] / res$seconds[res$format == fmt & res$contender == b]
  if (length(r)) sprintf("%.1fx", r) else "-"
}
md <- c("# GGIR part 1's epoch signals: GGIR against gravcal (bench/part1.R)", "",
        sprintf("%g days at %g Hz (simulate_recording()'s day, nights at rest, repeated), %s, R %s, GGIR %s, GGIRread %s; %s.",
                days, sf, R.version$platform, getRversion(), utils::packageVersion("GGIR"),
                utils::packageVersion("GGIRread"), format(Sys.Date())),
        paste("Each contender in a cold R process of its own; elapsed seconds, peak resident memory,",
              "user and system CPU seconds, minor page faults (thousands)."), "",
        "| format | contender | seconds | peak MB | user s | system s | faults (k) |",
        "|---|---|---:|---:|---:|---:|---:|",
        sprintf("| %s | %s | %.1f | %.0f | %.1f | %.1f | %.0f |", res$format, res$contender,
                res$seconds, res$rss_mb, res$user_s, res$sys_s, res$minor_faults / 1000), "",
        paste("| format | g.getmeta: GGIR / gravcal | g.part1: GGIR / gravcal |",
              "g.part1: GGIR with huge pages / gravcal |",
              "g.part1, every metric | g.part1, every metric: GGIR with huge pages / gravcal | M identical (all but bsc_qc; the two part 1 meta files where both ran) |"),
        "|---|---:|---:|---:|---:|---:|---|",
        vapply(names(files), function(fmt) {
          sprintf("| %s | %s | %s | %s | %s | %s | %s |", fmt,
                  ratio(fmt, "GGIR g.getmeta", "gravcal g.getmeta"),
                  ratio(fmt, "GGIR g.part1", "gravcal g.part1"),
                  ratio(fmt, "GGIR g.part1, huge pages", "gravcal g.part1"),
                  ratio(fmt, "GGIR g.part1, every metric", "gravcal g.part1, every metric"),
                  ratio(fmt, "GGIR g.part1, every metric, huge pages", "gravcal g.part1, every metric"),
                  same[[fmt]])
        }, ""))
writeLines(md, file.path(out_dir, paste0(name, ".md")))
cat(md, sep = "\n")
