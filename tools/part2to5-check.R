# GGIR's parts 2 to 5 after gravcal's part 1, against GGIR's own run: the
# reports (every csv file GGIR writes under results/) compared cell by cell.
#
# For each format (.cwa, GENEActiv .bin, .gt3x) a folder holds one simulated
# recording of `hours` hours (simulate_recording(): long rest bouts at night,
# movement and short rests by day, a temperature offset) written by
# write_recording(). Then, each in a fresh output folder:
#   GGIR:    GGIR::GGIR(mode = 1:5)
#   gravcal: gravcal::g.part1(), then GGIR::GGIR(mode = 2:5)
# with GGIR's default parameters on both sides (do.report = c(2, 4, 5)),
# and every csv under output_<folder>/results/ read as text and compared
# cell by cell. Run-time columns (none in GGIR 3.3-9's reports, checked by
# name: a column whose name says time of processing is left aside and
# listed) are reported, not compared.
#
#   Rscript tools/part2to5-check.R [hours] [out.md]
# (make test-part2to5; slow: GGIR's parts 1 to 5 twice per format; not part
# of make test.) Exits with status 1 when a report differs or is missing.

args <- commandArgs(trailingOnly = TRUE)
hours <- if (length(args) >= 1) as.numeric(args[[1]]) else 74
out_md <- if (length(args) >= 2) args[[2]] else "bench/results/part2to5.md"
# each format at a rate its devices record at
rates <- c(cwa = 25, bin = 30, gt3x = 30)

suppressPackageStartupMessages({
  library(gravcal)
  library(GGIR)
})

quiet <- function(expr) {
  utils::capture.output(r <- suppressWarnings(suppressMessages(expr)))
  r
}

# PART2TO5_KEEP=folder keeps the recordings and both sides' output there
keep <- Sys.getenv("PART2TO5_KEEP")
root <- if (nzchar(keep)) keep else tempfile("part2to5-")
dir.create(root, showWarnings = FALSE, recursive = TRUE)
if (!nzchar(keep)) on.exit(unlink(root, recursive = TRUE), add = TRUE)

formats <- c(cwa = "cwa", bin = "bin", gt3x = "gt3x")
rows <- list()
failed <- FALSE
for (i in seq_along(formats)) {
  ext <- formats[[i]]
  sf <- rates[[ext]]
  data <- file.path(root, paste0("data-", ext))
  dir.create(data)
  rec <- simulate_recording(hours = hours, sf = sf, seed = 40 + i,
                            start = as.POSIXct("2024-03-04 10:00:00", tz = "UTC"),
                            tempoffset = c(0.001, -0.002, 0.0005))
  if (ext == "gt3x") rec$temperature <- NULL  # a .gt3x holds no temperature
  write_recording(rec, file.path(data, paste0("rec01.", ext)), sf = sf)

  run_side <- function(side) {
    out <- file.path(root, paste0("out-", ext, "-", side))
    dir.create(out)
    md <- file.path(out, paste0("output_", basename(data)))
    t1 <- system.time(quiet(if (side == "ggir") {
      GGIR::GGIR(mode = 1, datadir = data, outputdir = out, do.parallel = FALSE,
                 verbose = FALSE, visualreport = FALSE)
    } else {
      dir.create(md)
      gravcal::g.part1(datadir = data, metadatadir = md, f0 = 1, f1 = 1, verbose = FALSE)
    }))[["elapsed"]]
    t25 <- system.time(quiet(
      GGIR::GGIR(mode = 2:5, datadir = data, outputdir = out, do.report = c(2, 4, 5),
                 do.parallel = FALSE, verbose = FALSE, visualreport = FALSE,
                 overwrite = FALSE)))[["elapsed"]]
    res <- file.path(md, "results")
    csv <- sort(list.files(res, pattern = "[.]csv$", recursive = TRUE))
    list(dir = res, csv = csv, part1 = t1, part25 = t25)
  }
  G <- run_side("ggir")
  R <- run_side("gravcal")

  for (f in union(G$csv, R$csv)) {
    row <- data.frame(format = ext, file = f, rows = NA_integer_, columns = NA_integer_,
                      cells = NA_integer_, differing = NA_integer_, aside = "",
                      stringsAsFactors = FALSE)
    if (!f %in% G$csv || !f %in% R$csv) {
      row$aside <- if (f %in% G$csv) "missing after gravcal's part 1" else "only after gravcal's part 1"
      failed <- TRUE
    } else {
      rd <- function(side) {
        utils::read.csv(file.path(side$dir, f), colClasses = "character", check.names = FALSE,
                        na.strings = character(0))
      }
      a <- rd(G)
      b <- rd(R)
      aside <- grep("processing|process_time|runtime|run time", names(a), ignore.case = TRUE,
                    value = TRUE)
      keep <- setdiff(names(a), aside)
      row$rows <- nrow(a)
      row$columns <- ncol(a)
      row$aside <- paste(aside, collapse = "; ")
      if (!identical(names(a), names(b)) || nrow(a) != nrow(b)) {
        row$aside <- paste(row$aside, "columns or rows differ")
        failed <- TRUE
      } else {
        row$cells <- nrow(a) * length(keep)
        row$differing <- sum(as.matrix(a[keep]) != as.matrix(b[keep]))
        if (row$differing > 0) failed <- TRUE
      }
    }
    rows[[length(rows) + 1]] <- row
  }
  rows[[length(rows) + 1]] <- data.frame(format = ext, file = "(seconds: part 1, parts 2-5)",
                                         rows = NA, columns = NA, cells = NA, differing = NA,
                                         aside = sprintf("GGIR %.1f, %.1f; gravcal %.1f, %.1f",
                                                         G$part1, G$part25, R$part1, R$part25))
}
tab <- do.call(rbind, rows)
print(tab, row.names = FALSE)

md <- c(
  "# GGIR's parts 2 to 5 after gravcal's part 1 (tools/part2to5-check.R)", "",
  sprintf(paste0("One simulated recording of %g h per format (.cwa at 25 Hz, .bin and .gt3x at 30 Hz; simulate_recording(), written by ",
                 "write_recording()); GGIR::GGIR(mode = 1:5) against gravcal::g.part1() then ",
                 "GGIR::GGIR(mode = 2:5), GGIR's default parameters, do.report = c(2, 4, 5). ",
                 "Every csv under results/ read as text and compared cell by cell. %s, R %s, GGIR %s, ",
                 "gravcal %s; %s."),
          hours, R.version$platform, getRversion(), packageVersion("GGIR"),
          packageVersion("gravcal"), format(Sys.Date())), "",
  "| format | report | rows | columns | cells compared | cells differing | note |",
  "|---|---|---:|---:|---:|---:|---|",
  sprintf("| %s | %s | %s | %s | %s | %s | %s |", tab$format, tab$file,
          ifelse(is.na(tab$rows), "", tab$rows), ifelse(is.na(tab$columns), "", tab$columns),
          ifelse(is.na(tab$cells), "", tab$cells), ifelse(is.na(tab$differing), "", tab$differing),
          tab$aside), "",
  if (failed) "**A report differs or is missing.**" else "Every report is the same, cell for cell.")
dir.create(dirname(out_md), showWarnings = FALSE, recursive = TRUE)
writeLines(md, out_md)
cat("written:", out_md, "\n")
quit(status = as.integer(failed))
