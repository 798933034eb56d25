# Usage: Rscript tools/ggir-damage-sweep.R [n] [seed]
#   (with gravcal installed: R_LIBS=<gravcal's library> Rscript tools/ggir-damage-sweep.R 60 2)
#
# A random sweep of damaged device files through GGIR's g.getmeta() (GGIR
# 3.3-9, live, nothing cached) and gravcal's, with GGIR's default
# parameters: n cases (default 10; seed default 1), each a file (synthetic
# recordings of 3 to 10 hours as .cwa, GENEActiv .bin, .gt3x, ActiGraph
# csv and Parmay Matrix .bin, written by tools/ggir-sweep.R's
# make_synthetic(); the small device files GGIRread ships) damaged once at
# random, past its first tenth: cut short there, 1 to 8 bytes overwritten
# with random ones, or a run of 16 to 65,536 bytes zeroed. M is compared as
# the tests compare it (every element but bsc_qc, QClog's wall-clock start
# and end dropped).
#
# Outcome of a case:
#   identical            every element of M but bsc_qc identical()
#   differs              the elements that are not
#   refused              gravcal stops saying GGIR gives no result there that
#                        it reproduces (with GGIR's filecorrupt and rows)
#   both error           / only GGIR errors / only gravcal errors
# One line a case, printed and appended to <out>.md; a case that is not
# identical, refused or both error keeps its damaged file as
# <out>-case<i>.<ext>, to be run again.
#
# Environment: SWEEP_OUT (default /tmp/damage-sweep), SWEEP_DEADLINE (a UTC
# time: no case starts after it).

suppressPackageStartupMessages(library(gravcal))
source(file.path(local({
  a <- commandArgs(FALSE)
  f <- sub("^--file=", "", a[grep("^--file=", a)][1])
  if (is.na(f)) "tools" else dirname(f)
}), "ggir-sweep.R"))
options(gravcal.threads = 1)
args <- commandArgs(TRUE)
n <- if (length(args) >= 1) as.integer(args[1]) else 10L
seed <- if (length(args) >= 2) as.integer(args[2]) else 1L
out <- Sys.getenv("SWEEP_OUT", "/tmp/damage-sweep")
deadline <- Sys.getenv("SWEEP_DEADLINE")
deadline <- if (nzchar(deadline)) as.POSIXct(deadline, tz = "UTC") else Inf
quiet <- function(e) { o <- NULL; utils::capture.output(o <- suppressWarnings(e)); o }

dir <- tempfile("damage-files")
dir.create(dir)
recipes <- list(
  cwa = list(format = "cwa", sf = 25, hours = 10, ext = ".cwa"),
  cwa100 = list(format = "cwa", sf = 100, hours = 3, ext = ".cwa"),
  bin = list(format = "geneactiv", sf = 20, hours = 10, ext = ".bin"),
  gt3x = list(format = "gt3x", sf = 30, hours = 5, ext = ".gt3x"),
  csv = list(format = "actigraph_csv", sf = 20, hours = 3, ext = ".csv"),
  parmay = list(format = "parmay", sf = 20, hours = 6, ext = ".BIN"))
src <- vapply(names(recipes), function(k) {
  r <- c(recipes[[k]], list(seed = 5, start = "2024-03-04 09:07:23",
                            rests = list(c(0.20, 0.27), c(0.55, 0.58))))
  as.character(make_synthetic(r, file.path(dir, paste0(k, r$ext))))
}, "")
shipped <- c(ax3 = "ax3_testfile.cwa", gen = "GENEActiv_testfile.bin",
             mtx = "mtx_12.5Hz_acc.BIN")
src <- c(src, vapply(shipped, function(f) system.file("testfiles", f, package = "GGIRread"), ""))
src <- src[nzchar(src) & file.exists(src)]

set.seed(seed)
for (i in seq_len(n)) {
  if (Sys.time() > deadline) break
  k <- sample(names(src), 1)
  f0 <- src[[k]]
  raw <- readBin(f0, "raw", file.size(f0))
  L <- length(raw)
  kind <- sample(c("cut", "bytes", "zeros"), 1)
  at <- as.integer(L * stats::runif(1, 0.1, 0.95))
  if (kind == "cut") raw <- raw[seq_len(at)]
  if (kind == "bytes") {
    p <- at + sample(0:2000, sample(1:8, 1))
    p <- p[p <= L]
    raw[p] <- as.raw(sample(0:255, length(p), TRUE))
  }
  if (kind == "zeros") raw[at:min(L, at + sample(c(16, 512, 4096, 65536), 1) - 1)] <- as.raw(0)
  f <- file.path(dir, sprintf("d%03d.%s", i, tools::file_ext(f0)))
  writeBin(raw, f)
  G <- tryCatch(quiet(GGIR::g.getmeta(f, inspectfileobject = quiet(GGIR::g.inspectfile(f)),
                                      verbose = FALSE)), error = function(e) e)
  M <- tryCatch(quiet(gravcal::g.getmeta(f, verbose = FALSE)), error = function(e) e)
  ge <- inherits(G, "error")
  me <- inherits(M, "error")
  res <- if (ge && me) {
    "both error"
  } else if (ge) {
    "only GGIR errors"
  } else if (me && grepl("gives no result there that gravcal reproduces", conditionMessage(M))) {
    sprintf("refused (GGIR: filecorrupt %s, %d rows)", isTRUE(G$filecorrupt), NROW(G$metashort))
  } else if (me) {
    "only gravcal errors"
  } else {
    G$QClog$start <- G$QClog$end <- M$QClog$start <- M$QClog$end <- NULL
    el <- setdiff(names(G), "bsc_qc")
    bad <- el[!vapply(el, function(nm) identical(G[[nm]], M[[nm]]), TRUE)]
    if (length(bad)) paste("differs:", paste(bad, collapse = ", ")) else "identical"
  }
  msg <- paste(c(if (ge) paste("GGIR:", conditionMessage(G)),
                 if (me) paste("gravcal:", conditionMessage(M))), collapse = " / ")
  line <- sprintf("| %d | %s | %s at byte %d of %d | %s | %s |", i, k, kind, at, L, res,
                  substr(gsub("[|\n]", " ", msg), 1, 240))
  cat(line, "\n")
  cat(line, "\n", file = paste0(out, ".md"), append = TRUE)
  if (grepl("^differs|^only", res)) {
    file.copy(f, sprintf("%s-case%03d.%s", out, i, tools::file_ext(f0)), overwrite = TRUE)
  }
  unlink(f)
}
unlink(dir, recursive = TRUE)
