# Flags that mean something (issue 44, items 2 and 3): the issue's cohort
# of 8 devices x 3-4 recordings whose recordings differ within a device by
# 1.5 mg (offsets) and 0.1 % (scales), through calibrate_files() with both
# methods, judged by this gravcal's rules and by those before issue 44
# (R/plausibility.R of `GRAVCAL_BEFORE`, default the commit 201160c,
# sourced over the installed namespace: the same table, the old judgement).
#
#   Rscript bench/cohort-flags.R [hours, default 26] [sf, default 12.5]
#
# Devices D1-D8 (ids 2001-2008): scales 1 + N(0, 0.01), cross-axis terms
# N(0, 0.01), offsets N(0, 0.02) g, temperature offsets N(0, 0.0005) g per
# degree C, the offsets stated at 28 degrees C. Each recording: the
# device's coefficients with offsets + N(0, 0.0015) g and scales
# x (1 + N(0, 0.001)), and its own temperature level (the simulated day's
# temperature shifted by U(-4, 4) degrees C; the signal carries the
# device's temperature offset at that level). Written as .cwa files.
# Faults: D2-r2 offset.x + 50 mg (a jump); D4-r1 the raw signal x 0.95
# (attenuation); D6-r3 scale.x 1.35 (an implausible gain); D8-r2 a stuck
# temperature sensor (its temperature column constant at its first value,
# the signal still drifting with the true temperature); D5-r2 three hours of
# vehicle-like near-rest (simulate_recording(vehicle = 3): norm 30-80 mg off
# 1 g, low sd; issue 44 item 1), whose twin without those hours (the same
# recording otherwise) is calibrated too: the coefficients of the two are
# compared in units of their combined standard errors, the offsets
# restated at the twin's mean temperature (the windows left out move the
# recording's mean temperature of its rest).
#
# Writes bench/results/cohort-flags.md.
suppressPackageStartupMessages(library(gravcal))
args <- commandArgs(trailingOnly = TRUE)
hours <- if (length(args) >= 1) as.numeric(args[1]) else 26
sf <- if (length(args) >= 2) as.numeric(args[2]) else 12.5
before <- Sys.getenv("GRAVCAL_BEFORE", "201160c")
# GRAVCAL_BENCH_KEEP: a folder to write the recordings and results into and
# keep (default: the session's temporary folder, removed)
keep <- Sys.getenv("GRAVCAL_BENCH_KEEP")
work <- if (nzchar(keep)) keep else file.path(tempdir(), "cohort-flags")
if (!nzchar(keep)) unlink(work, recursive = TRUE)
dir.create(file.path(work, "cohort"), recursive = TRUE)
t0 <- Sys.time()
set.seed(44)
n_rec <- rep(c(3, 4), 4)
devices <- lapply(1:8, function(d) list(
  serial = sprintf("D%d", d), id = 2000 + d,
  params = c(1 + stats::rnorm(3, sd = 0.01), stats::rnorm(3, sd = 0.01),
             stats::rnorm(3, sd = 0.02)),
  tempoffset = stats::rnorm(3, sd = 0.0005)))
recs <- do.call(rbind, lapply(1:8, function(d) data.frame(
  device = d, serial = devices[[d]]$serial, k = seq_len(n_rec[d]),
  stringsAsFactors = FALSE)))
recs$file <- sprintf("%s-r%d.cwa", recs$serial, recs$k)
recs$seed <- 400 + seq_len(nrow(recs))
recs$fault <- "none"
recs$fault[recs$file == "D2-r2.cwa"] <- "offset jump +50 mg"
recs$fault[recs$file == "D4-r1.cwa"] <- "attenuation x0.95"
recs$fault[recs$file == "D6-r3.cwa"] <- "implausible gain 1.35"
recs$fault[recs$file == "D8-r2.cwa"] <- "stuck temperature"
recs$fault[recs$file == "D5-r2.cwa"] <- "near-rest 3 h"
dir.create(file.path(work, "twin"))
for (i in seq_len(nrow(recs))) {
  r <- recs[i, ]
  dv <- devices[[r$device]]
  p <- dv$params
  p[7:9] <- p[7:9] + stats::rnorm(3, sd = 0.0015)
  p[1:3] <- p[1:3] * (1 + stats::rnorm(3, sd = 0.001))
  if (r$fault == "implausible gain 1.35") p[1] <- 1.35
  shift <- stats::runif(1, -4, 4)
  for (twin in if (r$fault == "near-rest 3 h") c(TRUE, FALSE) else FALSE) {
  rec <- simulate_recording(hours = hours, sf = sf, params = p,
                            tempoffset = dv$tempoffset, seed = r$seed,
                            vehicle = if (r$fault == "near-rest 3 h" && !twin) 3 else 0)
  K <- gravcal:::params_to_K(p[1:6])
  temp <- rec$temperature + shift
  # the device's offsets hold at 28 degrees C: at this recording's level
  # the raw signal moves by -K^-1 t (meantemp - 28)
  v <- sweep(as.matrix(rec[, c("x", "y", "z")]), 2,
             drop(solve(K, dv$tempoffset)) * (mean(temp) - 28))
  if (r$fault == "offset jump +50 mg") v[, 1] <- v[, 1] - 0.05
  if (r$fault == "attenuation x0.95") v <- v * 0.95
  if (r$fault == "stuck temperature") temp[] <- temp[1]
  v <- round(v * 256) / 256
  gravcal:::write_cwa(v, file.path(work, if (twin) "twin" else "cohort", r$file), sf = sf,
                      packed = FALSE, temperature = temp, device_id = dv$id)
  recs$temp_level[i] <- mean(temp)
  }
}
t_written <- Sys.time()
# the judgement before issue 44: that commit's plausibility.R over this
# namespace
old_env <- local({
  src <- tryCatch(system(paste("git show", shQuote(paste0(before, ":R/plausibility.R"))),
                         intern = TRUE), error = function(e) NULL, warning = function(w) NULL)
  if (is.null(src)) return(NULL)
  env <- new.env(parent = asNamespace("gravcal"))
  eval(parse(text = src), envir = env)
  env
})
runs <- list()
for (method in c("ggir", "lightweight")) {
  res <- calibrate_files(file.path(work, "cohort"), method = method,
                         outdir = file.path(work, paste0("out-", method)))
  old <- if (!is.null(old_env)) old_env$cohort_plausibility(res)$tab$plausibility
  m <- match(recs$file, res$file)
  runs[[method]] <- data.frame(file = recs$file, fault = recs$fault,
                               status = res$status[m],
                               before = if (is.null(old)) NA else old[m],
                               after = res$plausibility[m],
                               rejected_h = res$rejected_hours[m],
                               note = res$plausibility_note[m],
                               stringsAsFactors = FALSE)
  attr(runs[[method]], "devices") <- attr(res, "devices")
  # the near-rest recording against its twin: coefficient differences in
  # combined standard errors
  tw <- calibrate_files(file.path(work, "twin"), method = method,
                        outdir = file.path(work, paste0("twin-", method)))
  a <- res[res$file == "D5-r2.cwa", ]
  cols <- intersect(c(paste0("scale.", c("x", "y", "z")), paste0("offset.", c("x", "y", "z")),
                      paste0("temperature.offset.", c("x", "y", "z"))), names(res))
  cols <- cols[paste0(cols, ".se") %in% names(res)]
  # the offsets restated at the twin's mean temperature (the windows left
  # out move the contaminated recording's own mean temperature)
  se_cols <- paste0(cols, ".se")
  ra <- gravcal:::offsets_at_temperature(
    unlist(a[cols]), stats::setNames(unlist(a[se_cols]), cols),
    a$meantempcal, tw$meantempcal)
  z <- vapply(cols, function(k) (ra$co[[k]] - tw[[k]]) /
                sqrt(ra$se[[k]]^2 + tw[[paste0(k, ".se")]]^2), 0)
  attr(runs[[method]], "twin") <- list(z = z, status = c(a$status, tw$status),
                                       rejected = c(a$rejected_hours, tw$rejected_hours))
}
t_done <- Sys.time()
fmt <- function(x, d = 2) formatC(x, format = "f", digits = d)
md <- c("# Flags on the issue's cohort (issue 44, items 1 to 3)", "",
        sprintf(paste0("`Rscript bench/cohort-flags.R %g %g` (gravcal %s, %s): %d recordings of ",
                       "8 devices, %g h each at %g Hz, written as .cwa files (%.0f s); both methods ",
                       "calibrated in %.0f s. `before`: the judgement of R/plausibility.R at %s ",
                       "on the same table; `after`: this gravcal's."),
                hours, sf, as.character(utils::packageVersion("gravcal")), format(Sys.Date()),
                nrow(recs), hours, sf, as.numeric(difftime(t_written, t0, units = "secs")),
                as.numeric(difftime(t_done, t_written, units = "secs")), before),
        "", "See the script's header for the simulation.", "")
for (method in names(runs)) {
  r <- runs[[method]]
  clean <- r$fault == "none"
  md <- c(md, sprintf("## method = \"%s\"", method), "",
          sprintf(paste0("Clean recordings flagged: before %d of %d, after %d of %d. ",
                         "Faulty recordings flagged: before %d of %d, after %d of %d (near-rest: ",
                         "flagged when 2.5 h or more of its rest windows are left out)."),
                  sum(r$before[clean] != "ok", na.rm = TRUE), sum(clean),
                  sum(r$after[clean] != "ok", na.rm = TRUE), sum(clean),
                  sum(r$before[!clean] != "ok" | is.na(r$before[!clean])), sum(!clean),
                  sum(r$after[!clean] != "ok" | is.na(r$after[!clean]) |
                        (!is.na(r$rejected_h[!clean]) & r$rejected_h[!clean] >= 2.5)), sum(!clean)),
          "", "| file | fault | status | before | after | rejected h | note (after) |",
          "|---|---|---|---|---|---|---|",
          sprintf("| %s | %s | %s | %s | %s | %s | %s |", r$file, r$fault, r$status, r$before,
                  r$after, fmt(r$rejected_h, 1), gsub("|", "/", r$note, fixed = TRUE)),
          "", with(attr(r, "twin"), sprintf(paste0(
            "Near-rest D5-r2 against its twin without those hours: status %s (twin %s), ",
            "rejected %s h (twin %s h); largest coefficient difference %s combined se (%s)."),
            status[1], status[2], fmt(rejected[1], 1), fmt(rejected[2], 1),
            fmt(max(abs(z)), 2), names(z)[which.max(abs(z))])),
          "", "Device references (after):", "",
          "| serial | recordings | reference recordings | left out |", "|---|---|---|---|",
          with(attr(r, "devices"), sprintf("| %s | %d | %s | %s |", serial, recordings,
                                           reference_files, left_out_files)),
          "")
}
dir.create(file.path("bench", "results"), showWarnings = FALSE, recursive = TRUE)
writeLines(md, file.path("bench", "results", "cohort-flags.md"))
cat(md, sep = "\n")
if (!nzchar(keep)) unlink(work, recursive = TRUE)
