# Speed and memory of gravcal against GGIR's g.calibrate (issue 4).
#
# Every contender runs in this one R process on the same input:
#   1. end to end on a 7-day, 100 Hz recording with temperature held in
#      memory: GGIR::g.calibrate (fed from memory, see ggir_from_memory()),
#      gravcal::g.calibrate (GGIR-compatible), calibrate(method = "ggir"),
#      calibrate(method = "lightweight"); wall time (median of 5 runs taken
#      in turns),
#      ratio to GGIR, peak memory above the input, and the coefficients
#      compared;
#   2. the same from an ActiGraph csv file (a format GGIR reads), reader
#      included;
#   3. scaling over 1, 7, 14 and 28 days;
#   4. the segmenter alone against a C++ loop that only reads every sample
#      once (the memory-bandwidth floor), in samples per second;
#   5. one fit: fit_gradient() (18 points, 50 iterations) and fit_icp()
#      against stats::optim and GGIR's algorithm written as an R loop.
#
# Run from the package root with gravcal and GGIR installed:
#   Rscript bench/speed.R          (about 30 minutes; `make bench-speed`)
# The segmenter and the fits are measured first, in a fresh process.
#   GRAVCAL_BENCH_QUICK=1 Rscript bench/speed.R   (a 2-minute smoke run)
# Writes bench/results/speed.md and speed.csv.
#
# Peak memory is read from Linux's /proc/self/status (VmHWM, reset through
# /proc/self/clear_refs before each call): the most resident memory the
# process reached during the call, minus what it held before. Elsewhere it is
# reported as NA.
suppressPackageStartupMessages({
  library(gravcal)
  library(GGIR)
})

quick <- nzchar(Sys.getenv("GRAVCAL_BENCH_QUICK"))
runs <- if (quick) 1L else 3L
days_main <- if (quick) 1 else 7
days_scaling <- if (quick) c(1, 2) else c(1, 7, 14, 28)
sf <- 100
out_dir <- file.path("bench", "results")
dir.create(out_dir, showWarnings = FALSE, recursive = TRUE)
rows <- list()
record <- function(...) rows[[length(rows) + 1]] <<- data.frame(..., stringsAsFactors = FALSE)
say <- function(...) cat(format(Sys.time(), "%H:%M:%S"), ..., "\n")

source(file.path("bench", "measure.R"))

# --- input ---------------------------------------------------------------------

# One simulated day at 100 Hz, repeated for longer recordings (the speed of
# every contender depends on the number of samples, not on their values).
# The device errors are of the kind GGIR's model corrects (scale and offset
# per axis, a temperature effect; no cross-axis terms), so that GGIR's
# procedure reaches its "done" once it has more than 168 hours.
day <- simulate_recording(hours = 24, sf = sf, seed = 1,
                          params = c(1.015, 0.985, 1.01, 0, 0, 0, 0.03, -0.025, 0.02),
                          tempoffset = c(0.002, -0.001, 0.0015))
recording <- function(days) {
  k <- as.integer(days)
  data.frame(x = rep(day$x, k), y = rep(day$y, k), z = rep(day$z, k),
             temperature = rep(day$temperature, k))
}

# GGIR's g.calibrate reads only files. This gives it a route from memory: its
# reader, g.readaccfile, is replaced for the duration of the call by one that
# serves the rows of `data` in GGIR's blocks (blocksize * 300 rows, the size
# gravcal uses for data frames, which is GGIR's for csv input) and marks the
# block that reaches the end as the last. The device is declared a GENEActiv
# .bin, a monitor type for which g.calibrate has no special case in the
# steps that follow the reading.
ggir_from_memory <- function(data, sf, params = list()) {
  ns <- asNamespace("GGIR")
  original <- get("g.readaccfile", envir = ns)
  n <- nrow(data)
  fake <- function(filename, blocksize, blocknumber, filequality, ws,
                   PreviousEndPage = c(), inspectfileobject = c(), ...) {
    from <- if (length(PreviousEndPage)) PreviousEndPage + 1 else 1
    to <- min(from + blocksize * 300 - 1, n)
    P <- c()
    if (from <= n) {
      d <- data[from:to, , drop = FALSE]
      # plain row names, as GGIR's readers return (row names from:to would
      # follow every column GGIR takes out of the block and slow it down)
      rownames(d) <- NULL
      P <- list(data = d)
    }
    list(P = P, filequality = filequality, isLastBlock = to >= n,
         endpage = to, header = NULL)
  }
  utils::assignInNamespace("g.readaccfile", fake, ns = "GGIR")
  on.exit(utils::assignInNamespace("g.readaccfile", original, ns = "GGIR"))
  pr <- utils::modifyList(GGIR::load_params()$params_rawdata, params)
  INFI <- list(monc = GGIR:::MONITOR$GENEACTIV, dformc = GGIR:::FORMAT$BIN,
               sf = sf, filename = "memory")
  quiet(GGIR::g.calibrate("memory", params_rawdata = pr,
                          inspectfileobject = INFI, verbose = FALSE))
}

contenders_memory <- function(rec, params = list()) {
  list(
    "GGIR::g.calibrate" = function() ggir_from_memory(rec, sf, params),
    "gravcal::g.calibrate" = function() {
      quiet(do.call(gravcal::g.calibrate,
                    c(list(rec, sf = sf, verbose = FALSE), params)))
    },
    "calibrate(method = \"ggir\")" = function() {
      quiet(do.call(calibrate, c(list(rec, sf = sf, method = "ggir"), params)))
    },
    "calibrate(method = \"lightweight\")" = function() {
      quiet(calibrate(rec, sf = sf, method = "lightweight"))
    })
}

coefs <- function(v) {
  if (inherits(v, "gravcal_fit")) {
    c(diag(v$K), v$offset)
  } else {
    c(v$scale, v$offset)
  }
}

# --- 4. segmenter against the read-once floor ------------------------------------

rec <- recording(days_main)
cols <- list(rec$x, rec$y, rec$z, rec$temperature)
n_seg <- nrow(rec)
n <- n_seg
seg_run <- function(r_arith, L) {
  function() {
    src <- gravcal:::gc_source_columns(rec$x, rec$y, rec$z, rec$temperature)
    gravcal:::gc_pump(src, "windows",
                      list(window_samples = L, skip_zero = 0,
                           r_arithmetic = as.numeric(r_arith), temperature = 1,
                           rule = 1L, par = c(0.013, 2), block_units = -1,
                           want_table = 0))
  }
}
seg <- list(
  "read-once floor (C++ sum of 4 columns)" = function() gravcal:::gc_read_once(cols),
  "R: sum() of 4 columns" = function() sum(rec$x) + sum(rec$y) + sum(rec$z) + sum(rec$temperature),
  "segmenter, streaming arithmetic, 10 s windows" = seg_run(FALSE, 10 * sf),
  "segmenter, streaming arithmetic, 5 s windows" = seg_run(FALSE, 5 * sf),
  "segmenter, R-compatible arithmetic (GGIR), 10 s windows" = seg_run(TRUE, 10 * sf))
res_seg <- lapply(seg, function(f) repeat_measure(f, 5L))
floor_t <- res_seg[[1]]$time
for (nm in names(res_seg)) {
  r <- res_seg[[nm]]
  record(part = "segmenter", days = days_main, contender = nm, time_s = r$time,
         runs = paste(format(r$times, nsmall = 3), collapse = " "),
         speedup = r$time / floor_t, peak_mb = r$peak_mb, heap_mb = r$heap_mb, input_mb = NA_real_,
         max_coef_diff = n_seg / r$time / 1e6, identical = NA)
}
rm(rec, cols)

# --- 5. one fit --------------------------------------------------------------------

set.seed(3)
pts <- simulate_points(200, noise = 0.001)
sel <- select_points(pts)
w <- pts
ggir_points <- simulate_points(500, noise = 0.001,
                               params = c(1.02, 0.98, 1.01, 0, 0, 0, 0.03, -0.02, 0.015))
ggir_points$temperature <- 25 + stats::rnorm(500)

# GGIR's weighted ICP as an R loop, the algorithm g.calibrate runs: per
# iteration the current points projected on the unit sphere, one weighted
# least-squares fit per axis on (1, current value, temperature - mean),
# coefficients composed, weights 1 / |residual| capped at 100, and GGIR's
# stopping rule (its weighted statistic changes by less than 1e-10).
icp_r <- function(v, temp) {
  input <- as.matrix(v)
  n <- nrow(input)
  tc <- temp - mean(temp)
  scale <- c(1, 1, 1)
  offset <- c(0, 0, 0)
  toff <- c(0, 0, 0)
  weights <- rep(1, n)
  res <- Inf
  for (it in 1:1000) {
    curr <- (input + rep(offset, each = n)) * rep(scale, each = n) +
      tc * rep(toff, each = n)
    closest <- curr / sqrt(rowSums(curr^2))
    ch <- matrix(0, 3, 3)
    for (k in 1:3) {
      fit <- stats::lm.wfit(cbind(1, curr[, k], tc), closest[, k], w = weights)
      ch[k, ] <- fit$coefficients
      curr[, k] <- fit$fitted.values
    }
    offset <- offset + ch[, 1] / (scale * ch[, 2])
    toff <- toff * ch[, 2] + ch[, 3]
    scale <- scale * ch[, 2]
    res <- c(res, 3 * mean(weights * (curr - closest)^2 / sum(weights)))
    weights <- pmin(1 / sqrt(rowSums((curr - closest)^2)), 100)
    if (abs(res[it + 1] - res[it]) < 1e-10) break
  }
  list(scale = scale, offset = offset, tempoffset = toff, iterations = it)
}

gradient_objective <- function(p, v) {
  K <- matrix(c(p[1], p[4], p[5], 0, p[2], p[6], 0, 0, p[3]), 3)
  a <- (v + matrix(p[7:9], nrow(v), 3, byrow = TRUE)) %*% t(K)
  sum((rowSums(a^2) - 1)^2)
}
v18 <- as.matrix(sel[, c("mean_x", "mean_y", "mean_z")])
p0 <- c(1, 1, 1, 0, 0, 0, 0, 0, 0)
per_call <- function(f, reps) {
  t <- system.time(for (i in seq_len(reps)) f())[["elapsed"]]
  t / reps
}
fits <- list(
  "fit_gradient(), 18 points, 50 iterations" = list(
    function() fit_gradient(sel, max_iter = 50, tol = 0), 2000),
  "stats::optim(BFGS), same 18 points and objective" = list(
    function() stats::optim(p0, gradient_objective, v = v18, method = "BFGS"), 200),
  "fit_icp(), 500 points with temperature" = list(
    function() fit_icp(ggir_points, ggir_compat = TRUE), 200),
  "GGIR's ICP as an R loop (lm.wfit), same 500 points" = list(
    function() icp_r(ggir_points[, 1:3], ggir_points$temperature), 5))
# the R loop and fit_icp() agree (a check of the reference, reported)
fi <- fit_icp(ggir_points, ggir_compat = TRUE)
icp_check <- max(abs(unlist(icp_r(ggir_points[, 1:3], ggir_points$temperature)[1:3]) -
  c(diag(fi$K), fi$offset, fi$tempoffset)))
res_fit <- lapply(fits, function(f) per_call(f[[1]], if (quick) 2L else f[[2]]))
for (nm in names(res_fit)) {
  ref <- if (grepl("gradient|optim", nm)) res_fit[[2]] else res_fit[[4]]
  record(part = "one fit", days = NA_real_, contender = nm,
         time_s = res_fit[[nm]], runs = "", speedup = ref / res_fit[[nm]],
         peak_mb = NA_real_, heap_mb = NA_real_, input_mb = NA_real_, max_coef_diff = NA_real_,
         identical = NA)
}

# --- 1. end to end, in memory ------------------------------------------------

say("input: ", days_main, " days at ", sf, " Hz")
rec <- recording(days_main)
input_mb <- as.numeric(utils::object.size(rec)) / 2^20
# the contenders take turns, run after run, so that a slow spell of the
# machine does not fall on one of them only
cs <- contenders_memory(rec)
runs_main <- if (quick) 1L else 5L
meas <- list()
for (k in seq_len(runs_main)) {
  for (nm in names(cs)) {
    say("in memory, run ", k, ": ", nm)
    meas[[nm]][[k]] <- measure(cs[[nm]])
  }
}
res_mem <- lapply(names(meas), function(nm) {
  m <- meas[[nm]]
  mem <- peak_run(cs[[nm]])
  list(time = stats::median(vapply(m, `[[`, 0, "time")),
       times = vapply(m, `[[`, 0, "time"),
       peak_mb = mem[["peak_mb"]], heap_mb = mem[["heap_mb"]],
       value = m[[length(m)]]$value)
})
names(res_mem) <- names(meas)
rm(meas)
g_ref <- res_mem[["GGIR::g.calibrate"]]$value
for (nm in names(res_mem)) {
  r <- res_mem[[nm]]
  v <- r$value
  d <- max(abs(coefs(v) - coefs(g_ref)))
  record(part = "in memory", days = days_main, contender = nm,
         time_s = r$time, runs = paste(format(r$times, nsmall = 2), collapse = " "),
         speedup = res_mem[["GGIR::g.calibrate"]]$time / r$time,
         peak_mb = r$peak_mb, heap_mb = r$heap_mb, input_mb = input_mb,
         max_coef_diff = d,
         identical = if (nm == "gravcal::g.calibrate") identical(v$scale, g_ref$scale) &&
           identical(v$offset, g_ref$offset) && identical(v$tempoffset, g_ref$tempoffset) else NA)
}
rm(res_mem)

# --- 2. from a file (ActiGraph csv, no temperature) ---------------------------

csv <- tempfile(fileext = ".csv")
say("writing ", csv)
gravcal:::write_actigraph_csv(rec[, c("x", "y", "z")], csv, sf = sf)
file_mb <- file.size(csv) / 2^20
rm(rec)
pr <- GGIR::load_params()$params_rawdata
I <- quiet(GGIR::g.inspectfile(csv, params_rawdata = pr))
cf <- list(
  "GGIR::g.calibrate" = function() {
    quiet(GGIR::g.calibrate(csv, params_rawdata = pr, inspectfileobject = I,
                            verbose = FALSE))
  },
  "gravcal::g.calibrate" = function() {
    quiet(gravcal::g.calibrate(csv, params_rawdata = pr, verbose = FALSE))
  },
  "calibrate(method = \"ggir\")" = function() quiet(calibrate(csv, method = "ggir")),
  "calibrate(method = \"lightweight\")" = function() quiet(calibrate(csv, method = "lightweight")))
res_file <- list()
file_runs <- if (quick) 1L else 2L
for (nm in names(cf)) {
  say("file: ", nm)
  res_file[[nm]] <- repeat_measure(cf[[nm]], file_runs)
}
g_ref <- res_file[["GGIR::g.calibrate"]]$value
for (nm in names(res_file)) {
  r <- res_file[[nm]]
  record(part = "csv file", days = days_main, contender = nm, time_s = r$time,
         runs = paste(format(r$times, nsmall = 2), collapse = " "),
         speedup = res_file[["GGIR::g.calibrate"]]$time / r$time,
         peak_mb = r$peak_mb, heap_mb = r$heap_mb, input_mb = file_mb,
         max_coef_diff = max(abs(coefs(r$value) - coefs(g_ref))),
         identical = if (nm == "gravcal::g.calibrate") identical(r$value$scale, g_ref$scale) &&
           identical(r$value$offset, g_ref$offset) else NA)
}
unlink(csv)
rm(res_file)

# --- 3. scaling ------------------------------------------------------------------

# Default parameters: GGIR (and the compatible mode) stop reading once more
# than minloadcrit = 168 hours calibrate well. "whole recording" rows raise
# minloadcrit above the recording's length, so that every sample is used.
for (days in days_scaling) {
  rec <- recording(days)
  input_mb <- as.numeric(utils::object.size(rec)) / 2^20
  cs <- contenders_memory(rec)
  cs[["calibrate(method = \"ggir\"), whole recording"]] <- function() {
    quiet(calibrate(rec, sf = sf, method = "ggir", minloadcrit = 24 * days + 1))
  }
  for (nm in names(cs)) {
    say("scaling: ", days, " days: ", nm)
    n <- if (grepl("^GGIR", nm)) 1L else runs
    r <- tryCatch(repeat_measure(cs[[nm]], n),
                  error = function(e) list(time = NA_real_, times = NA_real_,
                                           peak_mb = NA_real_, heap_mb = NA_real_,
                                           value = conditionMessage(e)))
    record(part = "scaling", days = days, contender = nm, time_s = r$time,
           runs = paste(format(r$times, nsmall = 2), collapse = " "),
           speedup = NA_real_, peak_mb = r$peak_mb, heap_mb = r$heap_mb, input_mb = input_mb,
           max_coef_diff = NA_real_,
           identical = if (is.character(r$value)) r$value else NA)
  }
  rm(rec, cs)
}

# --- results -------------------------------------------------------------------

tab <- do.call(rbind, rows)
if (!quick) utils::write.csv(tab, file.path(out_dir, "speed.csv"), row.names = FALSE)
machine <- c(
  paste("R", getRversion(), "on", R.version$platform),
  paste("CPU:", tryCatch({
    l <- grep("model name", readLines("/proc/cpuinfo"), value = TRUE)
    paste0(sub(".*: ", "", l[1]), ", ", length(l), " cores")
  }, error = function(e) "unknown")),
  paste("GGIR", utils::packageVersion("GGIR"), "; gravcal",
        utils::packageVersion("gravcal")),
  paste("Date:", format(Sys.time(), "%Y-%m-%d")))
fmt <- function(x, d = 2) ifelse(is.na(x), "", formatC(x, format = "f", digits = d))
md <- c("# gravcal speed and memory against GGIR", "",
        "Made by `Rscript bench/speed.R` (see the script for the method).", "",
        paste0("- ", machine), "")
part_table <- function(part, header, cols) {
  t <- tab[tab$part == part, ]
  c(header, "",
    paste0("| ", paste(names(cols), collapse = " | "), " |"),
    paste0("|", paste(rep("---", length(cols)), collapse = "|"), "|"),
    vapply(seq_len(nrow(t)), function(i) {
      paste0("| ", paste(vapply(cols, function(f) f(t[i, ]), ""), collapse = " | "), " |")
    }, ""), "")
}
md <- c(md, part_table("in memory", sprintf(paste0(
  "## 1. End to end, %g days at %d Hz with temperature, in memory (%.0f MB)\n\n",
  "Median of %d runs, the contenders taking turns. Peak (one more run): ",
  "resident memory above the input during the call. Coefficient difference: largest ",
  "|difference| from GGIR's scale and offset; identical: `identical()` on ",
  "scale, offset and tempoffset."),
  days_main, sf, tab$input_mb[tab$part == "in memory"][1], runs_main), list(
    contender = function(r) r$contender, "time (s)" = function(r) fmt(r$time_s),
    "x faster than GGIR" = function(r) fmt(r$speedup, 1),
    "peak (MB)" = function(r) fmt(r$peak_mb, 0),
    "R heap peak (MB)" = function(r) fmt(r$heap_mb, 0),
    "coef. diff." = function(r) formatC(r$max_coef_diff, format = "g", digits = 2),
    "identical" = function(r) ifelse(is.na(r$identical), "", as.character(r$identical)))))
md <- c(md, part_table("csv file", sprintf(paste0(
  "## 2. From an ActiGraph csv file (%g days, %.0f MB, no temperature), reader included\n\n",
  "Median of %d runs. The resident peak includes the pages of the csv file, ",
  "which data.table's fread maps into memory; the R heap peak is R's objects."),
  days_main, file_mb, file_runs), list(
    contender = function(r) r$contender, "time (s)" = function(r) fmt(r$time_s),
    "x faster than GGIR" = function(r) fmt(r$speedup, 1),
    "peak (MB)" = function(r) fmt(r$peak_mb, 0),
    "R heap peak (MB)" = function(r) fmt(r$heap_mb, 0),
    "coef. diff." = function(r) formatC(r$max_coef_diff, format = "g", digits = 2),
    "identical" = function(r) ifelse(is.na(r$identical), "", as.character(r$identical)))))
md <- c(md, part_table("scaling", paste0(
  "## 3. Scaling, in memory\n\nGGIR one run, gravcal median of ", runs,
  " runs. Peak: above the input (whose size is given)."), list(
    days = function(r) format(r$days), contender = function(r) r$contender,
    "time (s)" = function(r) fmt(r$time_s), "s per day" = function(r) fmt(r$time_s / r$days, 3),
    "input (MB)" = function(r) fmt(r$input_mb, 0),
    "peak above input (MB)" = function(r) fmt(r$peak_mb, 0),
    "R heap peak (MB)" = function(r) fmt(r$heap_mb, 0),
    note = function(r) ifelse(is.na(r$identical), "", as.character(r$identical)))))
md <- c(md, part_table("segmenter", sprintf(paste0(
  "## 4. Segmenter alone, %g days at %d Hz (%.1f M samples, 4 columns)\n\nMedian of 5 runs."),
  days_main, sf, n_seg / 1e6), list(
    loop = function(r) r$contender, "time (s)" = function(r) fmt(r$time_s, 3),
    "M samples/s" = function(r) fmt(r$max_coef_diff, 0),
    "x floor" = function(r) fmt(r$speedup, 2))))
md <- c(md, part_table("one fit", paste0(
  "## 5. One fit, time per call\n\nThe R loop and `fit_icp(ggir_compat = TRUE)` ",
  "agree to ", formatC(icp_check, format = "g", digits = 2), " in every coefficient."), list(
    fit = function(r) r$contender, "ms per call" = function(r) fmt(1000 * r$time_s, 3),
    "x faster than the R reference" = function(r) fmt(r$speedup, 1))))
if (!quick) writeLines(md, file.path(out_dir, "speed.md"))
cat(md, sep = "\n")
