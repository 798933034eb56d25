# Plausibility of every fit in a cohort (issue 31, item 1): a simulated
# cohort with known faults through calibrate_files(), and what its
# `plausibility` column finds.
#
#   Rscript bench/cohort-plausibility.R [hours, default 24] [sf, default 12.5]
#
# 20 devices (serials D01-D20), each with its own true coefficients
# (scales 1 + N(0, 0.01), offsets N(0, 0.02) g, temperature offsets
# N(0, 0.0005) g per degree C; van Hees et al. 2014, Table 2, reports gain
# SDs up to 0.014 and offset SDs up to 0.037 g), and 2 to 4 recordings of
# `hours` each (simulate_recording(), its own seed per recording), written
# as Axivity .cwa files carrying the device's serial: 60 recordings.
# Faults:
# * firmware-style attenuation (the raw signal of all three axes times a,
#   as in ActiGraph's notice 16CPAN03): D01 and D02 on every recording
#   (a = 0.93; the whole device), D03's first recording (a = 0.95), D15's
#   first two of four (a = 0.94), D18's first of two (a = 0.92; no
#   history);
# * one recording whose offset moved (D04's second: +0.05 g on x, as a
#   dropped device might): a device outlier;
# * contamination, not a fault of the device: idle-sleep stretches (the
#   last sample repeated for 4 hours, as a device that stops sampling while
#   still and writes its last value) in 5 recordings, stuck-sensor
#   stretches (one constant vector off the sphere, (0.31, -0.62, 0.95) g,
#   for 3 hours) in 5 others. Their clean versions (the same seed without
#   the stretch) are calibrated too, and the coefficients compared in units
#   of the clean recording's standard errors.
# The method: calibrate_files(method = "ggir") in gravcal's own mode; a
# summary for method = "lightweight" on the same files follows.
#
# Writes bench/results/cohort-plausibility.md and .csv.
suppressPackageStartupMessages(library(gravcal))
args <- commandArgs(trailingOnly = TRUE)
hours <- if (length(args) >= 1) as.numeric(args[1]) else 24
sf <- if (length(args) >= 2) as.numeric(args[2]) else 12.5
out_dir <- file.path("bench", "results")
dir.create(out_dir, showWarnings = FALSE, recursive = TRUE)
t_start <- Sys.time()
work <- file.path(tempdir(), "cohort-plausibility")
unlink(work, recursive = TRUE)
dir.create(file.path(work, "cohort"), recursive = TRUE)
dir.create(file.path(work, "clean"), recursive = TRUE)

set.seed(31)
n_dev <- 20
n_rec <- c(rep(3, 14), rep(4, 3), rep(2, 3))
devices <- lapply(seq_len(n_dev), function(d) list(
  serial = sprintf("D%02d", d), id = 1000 + d,
  params = c(1 + stats::rnorm(3, sd = 0.01), 0, 0, 0, stats::rnorm(3, sd = 0.02)),
  tempoffset = stats::rnorm(3, sd = 0.0005)))
recs <- do.call(rbind, lapply(seq_len(n_dev), function(d) {
  data.frame(device = d, serial = devices[[d]]$serial, k = seq_len(n_rec[d]),
             stringsAsFactors = FALSE)
}))
recs$file <- sprintf("%s-r%d.cwa", recs$serial, recs$k)
recs$seed <- 100 + seq_len(nrow(recs))
recs$attenuation <- 1
recs$attenuation[recs$serial %in% c("D01", "D02")] <- 0.93
recs$attenuation[recs$serial == "D03" & recs$k == 1] <- 0.95
recs$attenuation[recs$serial == "D15" & recs$k <= 2] <- 0.94
recs$attenuation[recs$serial == "D18" & recs$k == 1] <- 0.92
recs$offset_shift <- 0
recs$offset_shift[recs$serial == "D04" & recs$k == 2] <- 0.05
recs$contamination <- "none"
clean_rows <- which(recs$attenuation == 1 & recs$offset_shift == 0)
set.seed(32)
cont <- sample(clean_rows, 10)
recs$contamination[cont[1:5]] <- "idle_sleep"
recs$contamination[cont[6:10]] <- "stuck"
recs$expected <- ifelse(recs$attenuation != 1, "attenuated",
                        ifelse(recs$offset_shift != 0, "device_outlier", "ok"))

write_rec <- function(i, dir, contaminate) {
  r <- recs[i, ]
  dv <- devices[[r$device]]
  rec <- simulate_recording(hours = hours, sf = sf, params = dv$params,
                            tempoffset = dv$tempoffset, seed = r$seed)
  v <- as.matrix(rec[, c("x", "y", "z")])
  v[, 1] <- v[, 1] + r$offset_shift
  v <- round(v * r$attenuation * 256) / 256
  if (contaminate && r$contamination != "none") {
    n <- nrow(v)
    len <- round((if (r$contamination == "idle_sleep") 4 else 3) * 3600 * sf)
    # a stretch starting at a random place in the middle of the recording
    set.seed(r$seed)
    from <- sample(seq(round(0.2 * n), round(0.7 * n)), 1)
    idx <- from + seq_len(len) - 1
    v[idx, ] <- if (r$contamination == "idle_sleep") {
      matrix(v[from - 1, ], len, 3, byrow = TRUE)
    } else matrix(round(c(0.31, -0.62, 0.95) * 256) / 256, len, 3, byrow = TRUE)
  }
  gravcal:::write_cwa(v, file.path(dir, r$file), sf = sf, packed = FALSE,
                      temperature = rec$temperature, device_id = dv$id)
}
for (i in seq_len(nrow(recs))) write_rec(i, file.path(work, "cohort"), TRUE)
for (i in cont) write_rec(i, file.path(work, "clean"), FALSE)
t_written <- Sys.time()

res <- calibrate_files(file.path(work, "cohort"), method = "ggir",
                       outdir = file.path(work, "out-cohort"))
clean <- calibrate_files(file.path(work, "clean"), method = "ggir",
                         outdir = file.path(work, "out-clean"))
t_done <- Sys.time()
# the same files with the lightweight method
res_lw <- calibrate_files(file.path(work, "cohort"), method = "lightweight",
                          outdir = file.path(work, "out-cohort-lw"))
clean_lw <- calibrate_files(file.path(work, "clean"), method = "lightweight",
                            outdir = file.path(work, "out-clean-lw"))

m <- match(recs$file, res$file)
recs$serial_read <- res$serial[m]
recs$status <- res$status[m]
recs$plausibility <- res$plausibility[m]
recs$note <- res$plausibility_note[m]
recs$scale_x <- res$scale.x[m]
recs$scale_y <- res$scale.y[m]
recs$scale_z <- res$scale.z[m]

# the contaminated recordings against their clean versions, in units of the
# clean fit's standard errors. Offsets are those at the temperature the
# model is centred on, each recording's mean temperature, which the
# contamination moves (its hours are left out): the contaminated fit's
# offsets are restated at the clean fit's mean temperature first
# (o + (T_clean - T) K^-1 t, as compare_coefs() and the device history
# do); `raw_z` is the comparison without that.
co <- c("scale.x", "scale.y", "scale.z", "offset.x", "offset.y", "offset.z",
        "temperature.offset.x", "temperature.offset.y", "temperature.offset.z")
all_co <- c(co[1:3], "cross.xy", "cross.xz", "cross.yz", co[4:9])
restate <- function(row, tref) {
  cn <- intersect(all_co, names(row))
  v <- unlist(row[cn])
  se <- unlist(row[paste0(cn, ".se")])
  names(se) <- cn
  gravcal:::offsets_at_temperature(v, se, row$meantempcal, tref)$co
}
compare <- function(res, clean, co) do.call(rbind, lapply(cont, function(i) {
  a <- res[res$file == recs$file[i], ]
  b <- clean[clean$file == recs$file[i], ]
  raw_z <- (unlist(a[co]) - unlist(b[co])) / unlist(b[paste0(co, ".se")])
  z <- (restate(a, b$meantempcal)[co] - unlist(b[co])) /
    unlist(b[paste0(co, ".se")])
  data.frame(file = recs$file[i], contamination = recs$contamination[i],
             status = a$status, status_clean = b$status,
             rest_windows = a$rest_windows, rest_windows_clean = b$rest_windows,
             meantemp_shift = a$meantempcal - b$meantempcal,
             max_abs_z = max(abs(z), na.rm = TRUE),
             worst = names(z)[which.max(abs(z))],
             raw_z = max(abs(raw_z), na.rm = TRUE),
             plausibility = a$plausibility, plausibility_clean = b$plausibility,
             stringsAsFactors = FALSE)
}))
cmp <- compare(res, clean, co)

# What the guards take out: the same 10 recordings in memory (the samples
# written to the files), each calibrated three ways in gravcal's own modes:
# clean; contaminated; and clean with the stretch's samples missing (NA:
# the data a perfect guard leaves). Contaminated against missing says
# whether anything of the contamination reaches the fit; missing against
# clean is what losing those hours of real data costs. Offsets compared at
# one temperature (the second fit's mean temperature), as above.
in_memory <- function(i, method) {
  r <- recs[i, ]
  dv <- devices[[r$device]]
  rec <- simulate_recording(hours = hours, sf = sf, params = dv$params,
                            tempoffset = dv$tempoffset, seed = r$seed)
  v <- round(as.matrix(rec[, c("x", "y", "z")]) * 256) / 256
  n <- nrow(v)
  len <- round((if (r$contamination == "idle_sleep") 4 else 3) * 3600 * sf)
  set.seed(r$seed)
  from <- sample(seq(round(0.2 * n), round(0.7 * n)), 1)
  idx <- from + seq_len(len) - 1
  mk <- function(w) data.frame(x = w[, 1], y = w[, 2], z = w[, 3],
                               temperature = rec$temperature)
  vc <- v
  vc[idx, ] <- if (r$contamination == "idle_sleep") {
    matrix(v[from - 1, ], len, 3, byrow = TRUE)
  } else matrix(round(c(0.31, -0.62, 0.95) * 256) / 256, len, 3, byrow = TRUE)
  vm <- v
  vm[idx, ] <- NA
  f <- lapply(list(clean = v, cont = vc, miss = vm), function(w)
    calibrate(mk(w), sf = sf, method = method))
  nm <- f$clean$model
  # coefficients of fit g with its offsets restated at fit h's mean
  # temperature (named as coef())
  at <- function(g, h) {
    v <- gravcal:::fit_table_coefs(g)
    se <- stats::setNames(unname(g$se), names(v))
    stats::setNames(gravcal:::offsets_at_temperature(v, se, g$meantemp,
                                                     h$meantemp)$co,
                    names(coef(g)))
  }
  zc <- (at(f$cont, f$miss)[nm] - coef(f$miss)[nm]) / f$miss$se[nm]
  zm <- (at(f$miss, f$clean)[nm] - coef(f$clean)[nm]) / f$clean$se[nm]
  off <- grep("^o_", nm, value = TRUE)
  data.frame(file = r$file, method = method, contamination = r$contamination,
             identical_left_out = f$cont$excluded[["identical"]],
             z_cont_vs_missing = max(abs(zc)),
             z_missing_vs_clean = max(abs(zm)),
             offset_mg_cont_vs_clean = 1000 * max(abs(at(f$cont, f$clean)[off] -
                                                     coef(f$clean)[off])),
             stringsAsFactors = FALSE)
}
mem <- do.call(rbind, c(lapply(cont, in_memory, method = "ggir"),
                        lapply(cont, in_memory, method = "lightweight")))

faulty <- recs$expected != "ok"
flagged <- !is.na(recs$plausibility) & recs$plausibility != "ok"
clean_dev <- !faulty & recs$contamination == "none"
utils::write.csv(recs[setdiff(names(recs), "note")],
                 file.path(out_dir, "cohort-plausibility.csv"), row.names = FALSE)

fmt <- function(x, d = 2) formatC(x, format = "f", digits = d)

# How much fits of one real device vary between recordings: the agcounts
# recording (../shared/data; ActiGraph, 30 Hz, 20.7 h free-living) cut
# into three parts of 6.9 h, each calibrated alone as a "recording" of one
# device, and judged as calibrate_files() judges a device's history.
real_split <- function() {
  dir <- Sys.getenv("GRAVCAL_SHARED_DATA", "../shared/data")
  f <- file.path(dir, "agcounts", sprintf("calibration%saxis.RData", c("X", "Y", "Z")))
  if (!all(file.exists(f))) return("(skipped: ../shared/data/agcounts is absent)")
  e <- new.env()
  for (x in f) load(x, envir = e)
  n <- length(e$X)
  out <- character(0)
  for (method in c("lightweight", "ggir")) {
    rows <- lapply(1:3, function(j) {
      idx <- floor((j - 1) * n / 3) + seq_len(floor(n / 3))
      fit <- calibrate(data.frame(x = e$X[idx], y = e$Y[idx], z = e$Z[idx]),
                       sf = 30, method = method)
      r <- gravcal:::cohort_row("agcounts", sprintf("part%d", j), fit, NULL, "", 0, method)
      r$serial <- "agcounts"
      r
    })
    j <- gravcal:::cohort_plausibility(do.call(rbind, rows))$tab
    out <- c(out, sprintf("- %s, part %d: status %s, scales %s %s %s (se %s), offsets %s %s %s g (se %s), plausibility %s",
                          method, 1:3, j$status, fmt(j$scale.x, 4), fmt(j$scale.y, 4), fmt(j$scale.z, 4),
                          fmt(j$scale.x.se, 4), fmt(j$offset.x, 4), fmt(j$offset.y, 4),
                          fmt(j$offset.z, 4), fmt(j$offset.x.se, 4), j$plausibility))
  }
  c(paste0("The agcounts recording (ActiGraph, 30 Hz, 20.7 h free-living, ../shared/data) cut ",
           "into three parts of 6.9 h, each calibrated alone and judged as three recordings ",
           "of one device (one device: no cohort spread to lean on):"), "", out, "",
          paste0("Fits of short real recordings of one device differ by more than their ",
                 "standard errors say; a device with only such recordings can be flagged ",
                 "`device_outlier` without a fault (in a cohort, the median of the devices' ",
                 "spreads guards against this when its fits vary alike)."))
}
md <- c(
  "# Plausibility of every fit in a simulated cohort",
  "",
  sprintf(paste0("`Rscript bench/cohort-plausibility.R %g %g` (gravcal %s, %s). %d ",
                 "recordings of %d devices, %g h each at %g Hz, written as .cwa ",
                 "files with the device's serial; `calibrate_files(method = \"ggir\")` ",
                 "(gravcal's own mode). Writing the files took %.0f s, calibrating ",
                 "them (and the %d clean versions) %.0f s."),
          hours, sf, as.character(utils::packageVersion("gravcal")),
          format(Sys.Date()), nrow(recs), n_dev, hours, sf,
          as.numeric(difftime(t_written, t_start, units = "secs")), length(cont),
          as.numeric(difftime(t_done, t_written, units = "secs"))),
  "",
  "See the script's header for the simulation. Rules: `attr(plausible_bounds(), \"history\")`.",
  "",
  "## Faulty recordings",
  "",
  sprintf("%d faulty recordings (firmware-style attenuation or a moved offset): %d flagged; %d flagged as expected.",
          sum(faulty), sum(flagged & faulty),
          sum(faulty & recs$plausibility %in% recs$expected & recs$plausibility == recs$expected)),
  "",
  "| file | device recordings | fault | expected | status | plausibility | scales |",
  "|---|---|---|---|---|---|---|",
  sprintf("| %s | %d | %s | %s | %s | %s | %s %s %s |", recs$file[faulty],
          n_rec[recs$device[faulty]],
          ifelse(recs$attenuation[faulty] != 1,
                 sprintf("signal x%.2f", recs$attenuation[faulty]),
                 sprintf("offset.x %+.2f g", recs$offset_shift[faulty])),
          recs$expected[faulty], recs$status[faulty], recs$plausibility[faulty],
          fmt(recs$scale_x[faulty], 4), fmt(recs$scale_y[faulty], 4),
          fmt(recs$scale_z[faulty], 4)),
  "",
  "Faulty devices (any recording faulty), each with at least one recording flagged:",
  paste0(vapply(unique(recs$serial[faulty]), function(s) {
    sprintf("%s %s", s, if (any(flagged[recs$serial == s & faulty])) "yes" else "NO")
  }, ""), collapse = ", "),
  "",
  "## Clean recordings",
  "",
  sprintf(paste0("%d recordings without a fault or contamination: %d flagged (%s %%; ",
                 "target at most 2 %%). With contamination included (%d): %d flagged (%s %%)."),
          sum(clean_dev), sum(flagged & clean_dev), fmt(100 * mean(flagged[clean_dev]), 1),
          sum(!faulty), sum(flagged & !faulty), fmt(100 * mean(flagged[!faulty]), 1)),
  "",
  if (any(flagged & !faulty)) c(
    "| file | contamination | status | plausibility | note |", "|---|---|---|---|---|",
    sprintf("| %s | %s | %s | %s | %s |", recs$file[flagged & !faulty],
            recs$contamination[flagged & !faulty], recs$status[flagged & !faulty],
            recs$plausibility[flagged & !faulty],
            gsub("|", "/", recs$note[flagged & !faulty], fixed = TRUE)), ""),
  sprintf("Statuses of all recordings: %s.",
          paste(names(table(recs$status)), table(recs$status), sep = " ", collapse = ", ")),
  "",
  "## Contaminated recordings against their clean versions",
  "",
  paste("Largest |coefficient - clean coefficient| / clean standard error over the nine coefficients",
        "(target: at most 2), with the contaminated fit's offsets restated at the clean fit's mean",
        "temperature (`max z`); `raw z` compares the offsets as each fit states them, at its own mean",
        "temperature, which the contamination moves by `shift` degrees C (its hours are left out): a",
        "temperature offset of 0.5 mg per degree C then moves the offset by more than its standard error."),
  "",
  "| file | contamination | status (clean) | rest windows (clean) | shift | max z | coefficient | raw z | plausibility (clean) |",
  "|---|---|---|---|---|---|---|---|---|",
  sprintf("| %s | %s | %s (%s) | %s (%s) | %s | %s | %s | %s | %s (%s) |", cmp$file, cmp$contamination,
          cmp$status, cmp$status_clean, cmp$rest_windows, cmp$rest_windows_clean,
          fmt(cmp$meantemp_shift), fmt(cmp$max_abs_z), cmp$worst, fmt(cmp$raw_z),
          cmp$plausibility, cmp$plausibility_clean),
  "",
  sprintf("Within 2 standard errors: %d of %d.", sum(cmp$max_abs_z <= 2), nrow(cmp)),
  "",
  "## What the guards take out (in memory)",
  "",
  paste("The same 10 recordings' samples in memory, in gravcal's own modes: clean, contaminated, and clean",
        "with the stretch missing (NA). `z cont vs missing`: the contaminated fit against the fit without",
        "those samples, in the latter's standard errors (0: nothing of the contamination reaches the fit).",
        "`z missing vs clean`: what losing those hours of real rest data moves, in the clean fit's",
        "standard errors. Offsets compared at one temperature, as above. `offset mg`: the largest",
        "offset change, contaminated against clean."),
  "",
  "| file | method | contamination | windows left out (identical) | z cont vs missing | z missing vs clean | offset mg, cont vs clean |",
  "|---|---|---|---|---|---|---|",
  sprintf("| %s | %s | %s | %d | %s | %s | %s |", mem$file, mem$method, mem$contamination,
          as.integer(mem$identical_left_out), fmt(mem$z_cont_vs_missing), fmt(mem$z_missing_vs_clean),
          fmt(mem$offset_mg_cont_vs_clean, 3)),
  "",
  sprintf(paste("Contaminated fits within 2 standard errors of the fit without the stretch: %d of %d",
                "(largest %s); offsets within %s mg of the clean recording's."),
          sum(mem$z_cont_vs_missing <= 2), nrow(mem), fmt(max(mem$z_cont_vs_missing)),
          fmt(max(mem$offset_mg_cont_vs_clean), 3)),
  "",
  "## The lightweight method on the same files",
  "",
  local({
    m <- match(recs$file, res_lw$file)
    pl <- res_lw$plausibility[m]
    fl <- !is.na(pl) & pl != "ok"
    co_lw <- c(co, "cross.xy", "cross.xz", "cross.yz")
    c_lw <- compare(res_lw, clean_lw, co_lw)
    c(sprintf(paste0("`calibrate_files(method = \"lightweight\")`: statuses %s. Faulty ",
                     "recordings flagged: %d of %d (as expected: %d); clean recordings ",
                     "flagged: %d of %d; contaminated recordings flagged: %d of %d; ",
                     "contaminated within 2 standard errors of their clean versions: %d of %d ",
                     "(max z per recording: %s)."),
              paste(names(table(res_lw$status)), table(res_lw$status), collapse = ", "),
              sum(fl & faulty), sum(faulty), sum(faulty & pl %in% recs$expected & pl == recs$expected),
              sum(fl & clean_dev), sum(clean_dev),
              sum(fl & recs$contamination != "none"), sum(recs$contamination != "none"),
              sum(c_lw$max_abs_z <= 2), nrow(c_lw), paste(fmt(c_lw$max_abs_z, 1), collapse = ", ")),
      if (any(fl & !faulty)) paste0("Flagged without a fault: ", paste(sprintf(
        "%s (%s, %s)", recs$file[fl & !faulty], recs$contamination[fl & !faulty],
        pl[fl & !faulty]), collapse = "; "), "."),
      if (any(!fl & faulty)) paste0("Faulty, not flagged: ", paste(sprintf(
        "%s (%s)", recs$file[!fl & faulty], pl[!fl & faulty]), collapse = "; "), "."))
  }),
  "",
  "## A real recording split in three",
  "",
  real_split(),
  "",
  "## Device references (GGIR method)",
  "",
  "| serial | recordings | in reference | ref scale x y z | ref offset x y z (g) |",
  "|---|---|---|---|---|",
  with(attr(res, "devices"), sprintf("| %s | %d | %d | %s %s %s | %s %s %s |", serial,
       recordings, reference_recordings, fmt(ref.scale.x, 4), fmt(ref.scale.y, 4),
       fmt(ref.scale.z, 4), fmt(ref.offset.x, 4), fmt(ref.offset.y, 4), fmt(ref.offset.z, 4))))
writeLines(md, file.path(out_dir, "cohort-plausibility.md"))
cat(md, sep = "\n")
unlink(work, recursive = TRUE)
