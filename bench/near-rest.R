# Rest that is really rest (issue 44, item 1): 28-hour recordings with
# three hours of vehicle-like near-rest (simulate_recording(vehicle = 3):
# a posture per 10 minutes, each 10 s window's norm 30-80 mg off 1 g of
# either sign, 5 mg of vibration), calibrated by both methods in gravcal's
# own modes, against the same recording without those hours (the rows cut
# out), before the rule (gravcal from `GRAVCAL_BEFORE_LIB`, a library
# holding the package before it, e.g. commit c14d57b installed with
# R CMD INSTALL -l) and after (the gravcal that runs this script).
#
#   GRAVCAL_BEFORE_LIB=/tmp/lib-before Rscript bench/near-rest.R [cases, default 6]
#
# Devices as in bench/cohort-flags.R: scales 1 + N(0, 0.01), cross-axis
# terms N(0, 0.01), offsets N(0, 0.02) g, temperature offsets N(0, 0.0005)
# g per degree C; samples rounded to 1/256 g (a .cwa's resolution), 12.5 Hz.
# The contaminated fit's coefficients are compared with the clean fit's in
# units of their combined standard error, sqrt(se^2 + se_clean^2), the
# contaminated fit's offsets first restated at the clean fit's mean
# temperature (offsets_at_temperature(): the hours left out move the
# temperature the model is centred on). Case 1 is also written as a .cwa
# file and calibrated from it (the stretch dated by the file's clock).
#
# Writes bench/results/near-rest.md.
args <- commandArgs(trailingOnly = TRUE)

# ---- the child: calibrate with the gravcal of a library -------------------
if (length(args) >= 1 && args[1] == "--calibrate") {
  lib <- args[2]
  suppressPackageStartupMessages(library(gravcal, lib.loc = if (nzchar(lib)) lib))
  job <- readRDS(args[3])
  res <- lapply(job$data, function(d) {
    lapply(c("lightweight", "ggir"), function(m) {
      f <- if (is.character(d)) calibrate(d, method = m) else
        calibrate(d, sf = job$sf, method = m)
      v <- gravcal:::fit_table_coefs(f)
      list(method = m, status = f$status, message = f$message,
           coef = coef(f), table_coefs = v,
           se = stats::setNames(unname(f$se), names(coef(f))),
           model = f$model, meantemp = f$meantemp,
           error_after = f$error_after, points = NROW(f$points),
           rejected = f$rejected, stretches = f$rejected_stretches)
    })
  })
  saveRDS(res, args[4])
  quit(save = "no")
}

# ---- the parent ------------------------------------------------------------
suppressPackageStartupMessages(library(gravcal))
n_cases <- if (length(args) >= 1) as.integer(args[1]) else 6
before_lib <- Sys.getenv("GRAVCAL_BEFORE_LIB", "")
sf <- 12.5
work <- file.path(tempdir(), "near-rest")
dir.create(work, showWarnings = FALSE)
t0 <- Sys.time()
set.seed(441)
cases <- lapply(seq_len(n_cases), function(i) {
  p <- c(1 + stats::rnorm(3, sd = 0.01), stats::rnorm(3, sd = 0.01),
         stats::rnorm(3, sd = 0.02))
  to <- stats::rnorm(3, sd = 0.0005)
  rec <- simulate_recording(hours = 28, sf = sf, params = p, tempoffset = to,
                            seed = 4400 + i, vehicle = 3,
                            start = as.POSIXct("2024-03-04 00:00:00", tz = "UTC"))
  rec[, c("x", "y", "z")] <- round(as.matrix(rec[, c("x", "y", "z")]) * 256) / 256
  cont <- attr(rec, "truth")$contaminated
  rows <- cont$from:cont$to
  list(rec = rec, clean = rec[-rows, ], from = rec$time[cont$from],
       hours = length(rows) / sf / 3600)
})
cwa <- file.path(work, "case1.cwa")
gravcal:::write_cwa(as.matrix(cases[[1]]$rec[, c("x", "y", "z")]), cwa, sf = sf,
                    packed = FALSE, temperature = cases[[1]]$rec$temperature,
                    start = as.numeric(cases[[1]]$rec$time[1]))
job <- list(sf = sf, data = c(unlist(lapply(cases, function(cs)
  list(cs$rec, cs$clean)), recursive = FALSE), list(cwa)))
job_file <- file.path(work, "job.rds")
saveRDS(job, job_file)
run <- function(lib) {
  out <- file.path(work, paste0("out-", if (nzchar(lib)) "before" else "after", ".rds"))
  rscript <- file.path(R.home("bin"), "Rscript")
  self <- sub("^--file=", "", grep("^--file=", commandArgs(FALSE), value = TRUE))
  env <- if (nzchar(lib)) character(0) else
    paste0("R_LIBS=", paste(.libPaths(), collapse = .Platform$path.sep))
  st <- system2(rscript, c(shQuote(self), "--calibrate", shQuote(lib),
                           shQuote(job_file), shQuote(out)), env = env)
  if (st != 0) stop("the calibration with ", if (nzchar(lib)) lib else "this gravcal", " failed")
  readRDS(out)
}
after <- run("")
before <- if (nzchar(before_lib)) run(before_lib)

# contaminated against clean: max |z| over the clean fit's model, offsets
# restated at the clean fit's mean temperature
compare <- function(a, b) {
  nm <- b$model
  co <- stats::setNames(gravcal:::offsets_at_temperature(
    a$table_coefs, stats::setNames(a$se, names(a$table_coefs)), a$meantemp,
    b$meantemp)$co, names(a$coef))
  # a coefficient the contaminated fit lacks (not fitted: 0, no standard
  # error) counts against the clean fit's standard error alone
  sa <- a$se[nm]
  sa[!is.finite(sa)] <- 0
  z <- (co[nm] - b$coef[nm]) / sqrt(sa^2 + b$se[nm]^2)
  z_clean <- (co[nm] - b$coef[nm]) / b$se[nm]
  off <- grep("^o_", nm, value = TRUE)
  list(z = max(abs(z)), worst = names(z)[which.max(abs(z))],
       z_clean = max(abs(z_clean)),
       se_ratio = stats::median(a$se[nm] / b$se[nm], na.rm = TRUE),
       missing = paste(setdiff(nm, a$model), collapse = " "),
       offset_mg = 1000 * max(abs(co[off] - b$coef[off])))
}
rows <- list()
for (i in seq_len(n_cases)) for (j in 1:2) {
  for (which in c("before", "after")) {
    res <- if (which == "before") before else after
    if (is.null(res)) next
    a <- res[[2 * i - 1]][[j]]
    b <- res[[2 * i]][[j]]
    cmp <- compare(a, b)
    s <- a$stretches
    rows[[length(rows) + 1]] <- data.frame(
      case = i, method = a$method, version = which, status = a$status,
      status_clean = b$status,
      error_after_mg = round(1000 * a$error_after, 2),
      error_after_clean_mg = round(1000 * b$error_after, 2),
      max_z = round(cmp$z, 2), worst = cmp$worst,
      max_z_clean_se = round(cmp$z_clean, 1), se_ratio = round(cmp$se_ratio, 2),
      not_fitted = cmp$missing, max_offset_diff_mg = round(cmp$offset_mg, 2),
      left_out = if (is.null(a$rejected)) NA_integer_ else a$rejected$windows,
      left_out_clean = if (is.null(b$rejected)) NA_integer_ else b$rejected$windows,
      stretch = if (NROW(s)) paste(gravcal:::format_stretches(s), collapse = "; ") else "",
      start_error_s = if (NROW(s)) as.numeric(s$start[1]) - as.numeric(cases[[i]]$from) else NA_real_,
      stringsAsFactors = FALSE)
  }
}
tab <- do.call(rbind, rows)
print(tab[, c("case", "method", "version", "status", "error_after_mg", "max_z",
              "worst", "max_z_clean_se", "se_ratio", "left_out",
              "left_out_clean", "start_error_s")])

# case 1 from its .cwa file (this gravcal)
cwa_fit <- after[[length(after)]]
cwa_lines <- vapply(cwa_fit, function(f) sprintf(
  "| %s | %s | %.2f | %d | %s |", f$method, f$status, 1000 * f$error_after,
  f$rejected$windows, paste(gravcal:::format_stretches(f$stretches), collapse = "; ")), "")

md <- c(
  "# Rest that is really rest: vehicle-like near-rest (issue 44, item 1)",
  "",
  sprintf("`Rscript bench/near-rest.R %d`, %s; R %s, gravcal %s%s.", n_cases,
          format(Sys.Date()), getRversion(), utils::packageVersion("gravcal"),
          if (!is.null(before)) paste0("; before: `GRAVCAL_BEFORE_LIB` (", before_lib, ")") else ""),
  "",
  paste0("Each case: a 28-hour recording at ", sf, " Hz of a device with cross-axis terms ",
         "and temperature offsets (scales 1 + N(0, 0.01), cross-axis N(0, 0.01), offsets ",
         "N(0, 0.02) g, temperature offsets N(0, 0.0005) g per degree C), with three hours ",
         "of vehicle-like near-rest (`simulate_recording(vehicle = 3)`: a posture per 10 ",
         "minutes, each 10 s window's norm 30-80 mg off 1 g of either sign, 5 mg of ",
         "vibration), calibrated by both methods in gravcal's own modes, against the same ",
         "recording without those hours (the rows cut out)."),
  "",
  paste0("`max_z`: the largest |difference| of a coefficient of the clean fit's model, ",
         "contaminated minus clean, in units of their combined standard error ",
         "sqrt(se^2 + se_clean^2), the contaminated fit's offsets restated at the clean ",
         "fit's mean temperature; `not_fitted`: coefficients the clean fit has and the ",
         "contaminated one lacks (counted with the clean fit's standard error alone); ",
         "`max_z (clean se)`: the same in units of the clean fit's standard error alone; ",
         "`se ratio`: the median ratio of the contaminated fit's standard errors to the ",
         "clean fit's (the fit's uncertainty: that of what is left); ",
         "`left_out`: rest windows left out as not on the sphere (contaminated; clean ",
         "recording); `start_error_s`: the reported stretch's start minus the true start."),
  "",
  "| case | method | version | status | error after (mg) | max_z | worst | max_z (clean se) | se ratio | not fitted | max offset diff (mg) | left out | left out (clean) | start error (s) | stretch |",
  "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
  sprintf("| %d | %s | %s | %s | %.2f | %.2f | %s | %.1f | %.2f | %s | %.2f | %s | %s | %s | %s |",
          tab$case, tab$method, tab$version, tab$status, tab$error_after_mg,
          tab$max_z, tab$worst, tab$max_z_clean_se, tab$se_ratio,
          tab$not_fitted, tab$max_offset_diff_mg,
          ifelse(is.na(tab$left_out), "-", tab$left_out),
          ifelse(is.na(tab$left_out_clean), "-", tab$left_out_clean),
          ifelse(is.na(tab$start_error_s), "-", format(tab$start_error_s)),
          tab$stretch),
  "",
  "Case 1 written as a `.cwa` file and calibrated from it (the stretch dated by the file's clock):",
  "",
  "| method | status | error after (mg) | left out | stretch |",
  "|---|---|---|---|---|",
  cwa_lines,
  "",
  sprintf("Largest max_z after: %.2f (lightweight), %.2f (ggir); before: %s.",
          max(tab$max_z[tab$version == "after" & tab$method == "lightweight"]),
          max(tab$max_z[tab$version == "after" & tab$method == "ggir"]),
          if (is.null(before)) "not run" else sprintf("%.2f (lightweight), %.2f (ggir)",
            max(tab$max_z[tab$version == "before" & tab$method == "lightweight"]),
            max(tab$max_z[tab$version == "before" & tab$method == "ggir"]))),
  "",
  sprintf("Wall time: %.1f min.", as.numeric(difftime(Sys.time(), t0, units = "mins"))))
out <- file.path("bench", "results", "near-rest.md")
if (!dir.exists(dirname(out))) out <- "near-rest.md"
writeLines(md, out)
cat("wrote", out, "\n")
