# gravcal::g.getmeta() against GGIR::g.getmeta() on every format that
# write_recording() and write_axivity_csv() write, through time zones
# (desiredtz: UTC, one fixed offset, zones with daylight saving; configtz
# given or not) and starts a fraction past the second or across a spring
# or an autumn change: the identity of M (all but bsc_qc, and QClog's wall-clock start
# and end for formats without time stamps). GGIR runs here, live: a few
# minutes. Not part of make test (its cases that found bugs are tests in
# test-ggir-getmeta.R); run it after a change to time stamps or zones:
#   R_LIBS=<gravcal's library> Rscript tools/zone-sweep.R [out.md]
# Prints a line per case and exits with status 1 when any differs.
suppressMessages(library(gravcal))
if (!requireNamespace("GGIR", quietly = TRUE)) stop("zone-sweep: needs GGIR")
quiet <- function(expr) {
  out <- NULL
  utils::capture.output(out <- suppressWarnings(expr))
  out
}
defaults <- GGIR::load_params()

# one case: M of both, compared
compare <- function(file, tz, configtz) {
  pg <- utils::modifyList(defaults$params_general, list(desiredtz = tz))
  if (!is.null(configtz)) pg$configtz <- configtz
  I <- tryCatch(quiet(GGIR::g.inspectfile(file, params_rawdata = defaults$params_rawdata,
                                          params_general = pg)), error = function(e) NULL)
  R <- tryCatch(quiet(GGIR::g.getmeta(file, params_rawdata = defaults$params_rawdata,
                                      params_general = pg, params_metrics = defaults$params_metrics,
                                      params_cleaning = defaults$params_cleaning,
                                      inspectfileobject = I, verbose = FALSE)),
                error = function(e) paste("GGIR stops:", conditionMessage(e)))
  G <- tryCatch(quiet(gravcal::g.getmeta(file, params_general = pg, verbose = FALSE)),
                error = function(e) paste("gravcal stops:", conditionMessage(e)))
  if (is.character(R) || is.character(G)) {
    # both stop: the same outcome; one alone: a difference
    return(list(same = is.character(R) && is.character(G),
                note = substr(paste(if (is.character(R)) R else "GGIR gives M", "|",
                                    if (is.character(G)) G else "gravcal gives M"), 1, 200)))
  }
  for (k in c("start", "end")) {
    if (!is.null(R$QClog) && !is.null(G$QClog)) R$QClog[[k]] <- G$QClog[[k]] <- NULL
  }
  k <- setdiff(names(R), "bsc_qc")
  same <- vapply(k, function(x) identical(R[[x]], G[[x]]), TRUE)
  list(same = all(same), note = paste(c(R$metashort$timestamp[1], names(same)[!same]), collapse = " "))
}

rows <- list()
run <- function(label, file, tzs = c("UTC", "Asia/Kolkata", "America/New_York"),
                configtzs = list(NULL, "Europe/Amsterdam")) {
  for (tz in tzs) for (ctz in configtzs) {
    r <- compare(file, tz, ctz)
    row <- data.frame(case = label, desiredtz = tz, configtz = ctz %||% "-", identical = r$same,
                      note = r$note)
    cat(sprintf("%-42s %-17s %-17s %-5s %s\n", label, tz, row$configtz, r$same, r$note))
    rows[[length(rows) + 1]] <<- row
  }
}
`%||%` <- function(a, b) if (is.null(a)) b else a

starts <- c(fraction = "2024-01-01 00:07:13.37", spring = "2024-03-30 22:00:00",
            autumn = "2024-10-27 00:30:00")
devices <- list(cwa = list(ext = ".cwa", sf = 25), geneactiv = list(ext = ".bin", sf = 30),
                gt3x = list(ext = ".gt3x", sf = 30), actigraph_csv = list(ext = ".csv", sf = 30),
                movisens = list(ext = "", sf = 64), parmay = list(ext = ".bin", sf = 30))
for (fm in names(devices)) {
  if (fm == "movisens" && !requireNamespace("unisensR", quietly = TRUE)) next
  for (s in names(starts)) {
    dv <- devices[[fm]]
    rec <- simulate_recording(hours = 5, sf = dv$sf, seed = 41)
    if (fm == "gt3x") rec$temperature <- NULL
    st <- if (fm == "parmay") sub("[.].*", "", starts[[s]]) else starts[[s]]
    f <- tempfile(fileext = dv$ext)
    write_recording(rec, f, sf = dv$sf, format = fm, start = st)
    path <- if (fm == "movisens") file.path(f, "acc.bin") else f
    run(paste(fm, s), path, tzs = c("UTC", "Asia/Kolkata", "America/New_York", "Europe/Amsterdam"))
    unlink(f, recursive = TRUE)
  }
}
# Axivity csv exports: UNIX, OMGUI's text, as.POSIXct()'s text, ISO with Z
rec <- simulate_recording(hours = 5, sf = 10, seed = 21, temperature = FALSE)
styles <- list(unix = list(stamps = "unix"), omgui = list(stamps = "text"),
               slashes = list(stamps = "text", time_format = "%Y/%m/%d %H:%M:%S"),
               zulu = list(stamps = "text", suffix = "Z", decimals = 2))
for (nm in names(styles)) {
  f <- tempfile(fileext = ".csv")
  do.call(gravcal:::write_axivity_csv,
          c(list(rec, f, true_sf = 10.03, start = as.POSIXct(starts[["fraction"]], tz = "UTC")),
            styles[[nm]]))
  run(paste("axivity_csv", nm), f, tzs = c("UTC", "Asia/Kolkata", "Europe/Amsterdam"),
      configtzs = list(NULL))
  unlink(f)
}
tab <- do.call(rbind, rows)
cat(sprintf("\n%d cases, %d identical\n", nrow(tab), sum(tab$identical)))
out <- commandArgs(TRUE)[1]
if (!is.na(out)) {
  writeLines(c("# g.getmeta() through time zones: gravcal against GGIR (tools/zone-sweep.R)", "",
               sprintf("R %s, GGIR %s; %s.", getRversion(), utils::packageVersion("GGIR"), Sys.Date()), "",
               "| case | desiredtz | configtz | identical | first timestamp (GGIR), or what differs |",
               "|---|---|---|---|---|",
               sprintf("| %s | %s | %s | %s | %s |", tab$case, tab$desiredtz, tab$configtz,
                       tab$identical, gsub("|", "/", tab$note, fixed = TRUE))), out)
}
if (!all(tab$identical)) quit(status = 1)
