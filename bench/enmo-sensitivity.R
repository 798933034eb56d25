# The practical minimum changes of plausible_bounds() (`practical_min`,
# issue 44, item 2): how much a change of one calibration coefficient moves
# a day's ENMO (mean of max(|a| - 1, 0), in mg), so that a recording is
# called a device outlier only for a difference that changes a user's
# results by about 1 mg of ENMO or more.
#
#   Rscript bench/enmo-sensitivity.R
#
# Two days:
# * real: the agcounts recording (../shared/data/agcounts; ActiGraph,
#   30 Hz, 20.7 h of free-living wear), calibrated with GGIR's own
#   coefficients for it (ggirCalibrate.RData);
# * simulated: simulate_recording(hours = 24, sf = 30) with identity
#   coefficients, three seeds.
# Each coefficient is changed on one axis at a time, in both directions, by
# a few sizes; the table gives the change of ENMO. `per 1 mg`: the change
# of the coefficient that moves ENMO by 1 mg, averaged over the three axes
# and both directions (linear interpolation between the sizes tried).
# Temperature offsets: a change t moves the calibrated signal by
# t (T - meantemp); on the real wrist recording with temperature
# (../shared/data/ggir/data.calibrate.RData, 84 h, GGIR's rest windows) the
# 90th percentile of |T - meantemp| is given, and the practical minimum is
# the offset's divided by it.
#
# Writes bench/results/enmo-sensitivity.md.
suppressPackageStartupMessages(library(gravcal))
dir <- Sys.getenv("GRAVCAL_SHARED_DATA", "../shared/data")
enmo <- function(v) 1000 * mean(pmax(sqrt(rowSums(v^2)) - 1, 0))
days <- list()
f <- file.path(dir, "agcounts", sprintf("calibration%saxis.RData", c("X", "Y", "Z")))
if (all(file.exists(f))) {
  e <- new.env()
  for (x in f) load(x, envir = e)
  load(file.path(dir, "agcounts", "ggirCalibrate.RData"), envir = e)
  C <- e$C
  days$real <- cbind((e$X + C$offset[1]) * C$scale[1], (e$Y + C$offset[2]) * C$scale[2],
                     (e$Z + C$offset[3]) * C$scale[3])
}
for (seed in 1:3) {
  rec <- simulate_recording(hours = 24, sf = 30, params = c(1, 1, 1, 0, 0, 0, 0, 0, 0),
                            seed = seed, resolution = 0, temperature = FALSE)
  days[[sprintf("simulated (seed %d)", seed)]] <- as.matrix(rec[, c("x", "y", "z")])
}
sizes <- list(offset = c(0.002, 0.005, 0.01, 0.02), scale = c(0.002, 0.005, 0.01))
rows <- list()
for (nm in names(days)) {
  v <- days[[nm]]
  e0 <- enmo(v)
  for (what in names(sizes)) for (d in sizes[[what]]) for (ax in 1:3) for (s in c(-1, 1)) {
    w <- v
    w[, ax] <- if (what == "offset") w[, ax] + s * d else w[, ax] * (1 + s * d)
    rows[[length(rows) + 1]] <- data.frame(day = nm, enmo = e0, what = what, size = d,
                                           axis = c("x", "y", "z")[ax], sign = s,
                                           change = enmo(w) - e0)
  }
}
r <- do.call(rbind, rows)
# mean |change| per day, coefficient and size
m <- aggregate(abs(change) ~ day + what + size, r, mean)
names(m)[4] <- "mean_abs"
mx <- aggregate(abs(change) ~ day + what + size, r, max)
m$max_abs <- mx[[4]]
per1 <- do.call(rbind, lapply(split(m, list(m$day, m$what), drop = TRUE), function(g) {
  g <- g[order(g$size), ]
  data.frame(day = g$day[1], what = g$what[1],
             per_1mg = stats::approx(c(0, g$mean_abs), c(0, g$size), xout = 1, rule = 2)$y,
             per_1mg_worst = stats::approx(c(0, g$max_abs), c(0, g$size), xout = 1, rule = 2)$y)
}))
tq <- NA_real_
tf <- file.path(dir, "ggir", "data.calibrate.RData")
if (file.exists(tf)) {
  e <- new.env()
  load(tf, envir = e)
  tt <- e$data.calibrate$spheredata$temperature
  tq <- stats::quantile(abs(tt - mean(tt)), c(0.5, 0.9, 1))
}
b <- plausible_bounds()
fmt <- function(x, d = 3) formatC(x, format = "f", digits = d)
md <- c(
  "# How much a coefficient's change moves a day's ENMO",
  "",
  sprintf("`Rscript bench/enmo-sensitivity.R` (gravcal %s, %s). See the script's header.",
          as.character(utils::packageVersion("gravcal")), format(Sys.Date())),
  "",
  "Days: ", paste0("- ", names(days), ": ENMO ",
                   vapply(days, function(v) fmt(enmo(v), 1), ""), " mg, ",
                   vapply(days, function(v) fmt(nrow(v) / 30 / 3600, 1), ""), " h"),
  "",
  "## Change of ENMO (mg), mean and largest over the three axes and both directions",
  "",
  "| day | coefficient | change | mean abs | max abs |", "|---|---|---|---|---|",
  sprintf("| %s | %s | %s | %s | %s |", m$day, m$what,
          ifelse(m$what == "offset", paste(1000 * m$size, "mg"), paste(100 * m$size, "%")),
          fmt(m$mean_abs), fmt(m$max_abs)),
  "",
  "## The change that moves ENMO by 1 mg",
  "",
  "| day | coefficient | mean over axes and directions | most sensitive axis and direction |",
  "|---|---|---|---|",
  sprintf("| %s | %s | %s | %s |", per1$day, per1$what,
          ifelse(per1$what == "offset", paste(fmt(1000 * per1$per_1mg, 1), "mg"),
                 paste(fmt(100 * per1$per_1mg, 2), "%")),
          ifelse(per1$what == "offset", paste(fmt(1000 * per1$per_1mg_worst, 1), "mg"),
                 paste(fmt(100 * per1$per_1mg_worst, 2), "%"))),
  "",
  sprintf(paste("Temperature: |T - meantemp| on the real wrist recording with temperature",
                "(data.calibrate, GGIR's rest windows): median %s, 90th percentile %s, largest %s degrees C."),
          fmt(tq[1], 2), fmt(tq[2], 2), fmt(tq[3], 2)),
  "",
  "## Chosen (plausible_bounds()$practical_min)",
  "",
  sprintf("- %s: %s (%s)", b$coefficient, b$practical_min, b$practical_source))
dir.create(file.path("bench", "results"), showWarnings = FALSE, recursive = TRUE)
writeLines(md, file.path("bench", "results", "enmo-sensitivity.md"))
cat(md, sep = "\n")
