# One contender of bench/files.R on one file, in a process of its own, so
# that the peak resident memory it reports (VmHWM: the most this process,
# R itself included, held at any time) is its own.
#
#   Rscript bench/files-one.R <contender> <file>
#
# Prints one line: RESULT <contender> <seconds> <peak MB> <baseline MB>
# <coefficients as exact hexadecimal doubles, comma-separated> <status>
# <CPU seconds>.
# <seconds> is the call's wall time, library loading excluded; <baseline MB>
# the resident memory after loading the packages, before the call.
args <- commandArgs(trailingOnly = TRUE)
contender <- args[1]
file <- args[2]

proc_mb <- function(field) {
  l <- grep(paste0("^", field, ":"), readLines("/proc/self/status"), value = TRUE)
  as.numeric(gsub("[^0-9]", "", l)) / 1024
}
quiet <- function(expr) {
  out <- NULL
  utils::capture.output(out <- suppressWarnings(expr))
  out
}
hex <- function(v) paste(sprintf("%a", as.numeric(v)), collapse = ",")

if (contender == "GGIR::g.calibrate") {
  invisible(suppressPackageStartupMessages(loadNamespace("GGIR")))
} else {
  invisible(suppressPackageStartupMessages(loadNamespace("gravcal")))
}
base <- proc_mb("VmRSS")

run <- switch(contender,
  "GGIR::g.calibrate" = function() {
    pr <- GGIR::load_params()$params_rawdata
    I <- quiet(GGIR::g.inspectfile(file, params_rawdata = pr))
    r <- quiet(GGIR::g.calibrate(file, params_rawdata = pr,
                                 inspectfileobject = I, verbose = FALSE))
    list(coef = c(r$scale, r$offset, r$tempoffset), status = r$QCmessage)
  },
  "gravcal::g.calibrate" = function() {
    r <- quiet(gravcal::g.calibrate(file, verbose = FALSE))
    list(coef = c(r$scale, r$offset, r$tempoffset), status = r$QCmessage)
  },
  "calibrate(method = \"ggir\")" = function() {
    f <- quiet(gravcal::calibrate(file, method = "ggir"))
    list(coef = c(diag(f$K), f$offset), status = f$status)
  },
  "calibrate(method = \"lightweight\")" = function() {
    f <- quiet(gravcal::calibrate(file, method = "lightweight"))
    list(coef = c(diag(f$K), f$offset), status = f$status)
  },
  "decode (read-once floor of the decoder)" = function() {
    fmt <- gravcal:::file_format(file)
    h <- gravcal:::native_open(file, fmt, list(compat = 0))
    on.exit(gravcal:::gc_decoder_close(h$ptr))
    n <- gravcal:::gc_decoder_drain(h$ptr)
    list(coef = n, status = "decoded")
  },
  # the same in GGIR-compatible mode (what g.calibrate reads: for .cwa with
  # GGIRread's resampling onto a regular grid)
  "decode, compatible mode" = function() {
    fmt <- gravcal:::file_format(file)
    h <- gravcal:::native_open(file, fmt, list(compat = 1))
    on.exit(gravcal:::gc_decoder_close(h$ptr))
    n <- gravcal:::gc_decoder_drain(h$ptr)
    list(coef = n, status = "decoded")
  },
  stop("unknown contender ", contender))

st <- system.time(v <- run(), gcFirst = FALSE)
t <- st[["elapsed"]]
cpu <- st[["user.self"]] + st[["sys.self"]]
status <- gsub("[[:space:]]+", "_", paste(v$status, collapse = "_"))
if (!nzchar(status)) status <- "-"
cat(sprintf("RESULT\t%s\t%.3f\t%.1f\t%.1f\t%s\t%s\t%.3f\n", contender, t,
            proc_mb("VmHWM"), base, hex(v$coef), status, cpu))
