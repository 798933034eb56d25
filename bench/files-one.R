# One contender of bench/files.R on one file, in a process of its own, so
# that the peak resident memory it reports (VmHWM: the most this process,
# R itself included, held at any time) is its own.
#
#   Rscript bench/files-one.R <contender> <file> [<params.rds> [<result.rds>]]
#
# <params.rds> (optional, "-" for none): a list of GGIR params_rawdata
# entries (e.g. an ad hoc csv file's rmc.* parameters) given to every
# contender: to GGIR over its defaults, to gravcal::g.calibrate as
# params_rawdata, to calibrate() as `rmc` (its rmc.* entries). <result.rds>
# (optional): where the g.calibrate contenders save the list they return,
# after the measurement, so that bench/formats.R can compare GGIR's and
# gravcal's with identical().
#
# Prints one line: RESULT <contender> <seconds> <peak MB> <baseline MB>
# <coefficients as exact hexadecimal doubles, comma-separated> <status>
# <CPU seconds> <user seconds> <system seconds>.
# <seconds> is the call's wall time, library loading excluded; <baseline MB>
# the resident memory after loading the packages, before the call.
args <- commandArgs(trailingOnly = TRUE)
contender <- args[1]
file <- args[2]
params <- if (length(args) >= 3 && args[3] != "-") readRDS(args[3]) else list()
save_to <- if (length(args) >= 4) args[4] else NULL
rmc <- params[grepl("^rmc[.]", names(params))]

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
    pr <- utils::modifyList(GGIR::load_params()$params_rawdata, params)
    I <- quiet(GGIR::g.inspectfile(file, params_rawdata = pr))
    r <- quiet(GGIR::g.calibrate(file, params_rawdata = pr,
                                 inspectfileobject = I, verbose = FALSE))
    list(coef = c(r$scale, r$offset, r$tempoffset), status = r$QCmessage, result = r)
  },
  "gravcal::g.calibrate" = function() {
    r <- if (length(params)) {
      quiet(gravcal::g.calibrate(file, params_rawdata = params, verbose = FALSE))
    } else {
      quiet(gravcal::g.calibrate(file, verbose = FALSE))
    }
    list(coef = c(r$scale, r$offset, r$tempoffset), status = r$QCmessage, result = r)
  },
  # GGIR part 1's epoch signals (uncalibrated: the calibration is another
  # contender's); `coef`: the epochs, and the md5 of metashort and metalong
  # (so that two builds are compared on every value)
  "gravcal::g.getmeta" = function() {
    M <- quiet(gravcal::g.getmeta(file, verbose = FALSE))
    f <- tempfile()
    saveRDS(list(M$metashort, M$metalong), f, compress = FALSE)
    list(coef = nrow(M$metashort), status = unname(tools::md5sum(f)))
  },
  # the same with every metric GGIR computes itself (every do.* but the
  # counts of other packages), as bench/part1.R's "every metric"
  "gravcal::g.getmeta, every metric" = function() {
    pm <- GGIR::load_params()$params_metrics
    for (k in grep("^do[.]", names(pm), value = TRUE)) {
      pm[[k]] <- !k %in% c("do.brondcounts", "do.neishabouricounts")
    }
    M <- quiet(gravcal::g.getmeta(file, params_metrics = pm, verbose = FALSE))
    f <- tempfile()
    saveRDS(list(M$metashort, M$metalong), f, compress = FALSE)
    list(coef = nrow(M$metashort), status = unname(tools::md5sum(f)))
  },
  # GGIR part 1 as g.part1() runs it on a folder holding the file (its
  # calibration applied, the meta file written); `coef`: the epochs, and
  # the md5 of the meta file's metashort and metalong
  "gravcal::g.part1" = function() {
    d <- tempfile("part1-in-")
    md <- tempfile("part1-out-")
    dir.create(d)
    file.symlink(normalizePath(file), file.path(d, basename(file)))
    quiet(gravcal::g.part1(datadir = d, metadatadir = md, f1 = 1, verbose = FALSE))
    e <- new.env()
    load(dir(file.path(md, "meta", "basic"), full.names = TRUE)[1], envir = e)
    f <- tempfile()
    saveRDS(list(e$M$metashort, e$M$metalong), f, compress = FALSE)
    list(coef = nrow(e$M$metashort), status = unname(tools::md5sum(f)))
  },
  "calibrate(method = \"ggir\")" = function() {
    f <- if (length(rmc)) {
      quiet(gravcal::calibrate(file, method = "ggir", rmc = rmc))
    } else {
      quiet(gravcal::calibrate(file, method = "ggir"))
    }
    list(coef = c(diag(f$K), f$offset), status = f$status)
  },
  "calibrate(method = \"lightweight\")" = function() {
    f <- if (length(rmc)) {
      quiet(gravcal::calibrate(file, method = "lightweight", rmc = rmc))
    } else {
      quiet(gravcal::calibrate(file, method = "lightweight"))
    }
    list(coef = c(diag(f$K), f$offset), status = f$status)
  },
  "decode (read-once floor of the decoder)" = function() {
    if (length(rmc) || gravcal:::file_format(file) == "axivity_csv") {
      # csv files whose layout the decoder is given (an ad hoc csv file's
      # rmc.* parameters; an Axivity export's rate from its time stamps)
      h <- gravcal:::open_source(file, compat = FALSE, rmc = gravcal:::rmc_values(rmc))$native
    } else {
      fmt <- gravcal:::file_format(file)
      h <- gravcal:::native_open(file, fmt, list(compat = 0))
    }
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
peak <- proc_mb("VmHWM")
if (!is.null(save_to) && !is.null(v$result)) saveRDS(v$result, save_to)
cat(sprintf("RESULT\t%s\t%.3f\t%.1f\t%.1f\t%s\t%s\t%.3f\t%.3f\t%.3f\n", contender, t,
            peak, base, hex(v$coef), status, cpu, st[["user.self"]], st[["sys.self"]]))
