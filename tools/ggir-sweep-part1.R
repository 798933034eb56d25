# Usage: R_LIBS=<gravcal's library> Rscript tools/ggir-sweep-part1.R [n] [seed]
#
# A randomized differential test of gravcal::g.part1() against
# GGIR::g.part1() (GGIR 3.3-9): n random cases (default 3; seed default 1).
# Each case is a small folder (or a vector of paths) of 1-3 recordings and
# a random draw of g.part1()'s arguments and GGIR parameters; GGIR's
# g.part1() writes into one metadatadir, gravcal's into another (same
# folder name, output_<case>), then the two are compared:
#   * the files under each metadatadir (meta/basic/*, results/QC/...);
#   * per meta file, whether it was written or left as it was (some cases
#     start with a marker meta file, a data_quality_report.csv, for
#     overwrite and backup.cal.coef = "retrieve"), and each saved object
#     identical() as tests/testthat/test-ggir-part1.R compares them
#     (p1_objects(): M's and C's bsc_qc replaced by their names); also
#     M$QClog's `start` and `end` dropped (wall clock where a file has no
#     time stamps), a difference only there noted, not counted.
# GGIR runs live; nothing is cached.
#
# Recordings: synthetic ones (tools/ggir-sweep.R's make_synthetic(): rest
# stretches for non-wear, clipped samples) of 3-30 hours as .cwa,
# GENEActiv .bin, .gt3x, ActiGraph csv and Parmay Matrix .bin, written once
# into SWEEP_FILES and linked into each case's folder under a drawn name
# (plain, its own, "meta_" prefixed or with a "_csv" stem, names GGIR's
# part 1 treats specially), ad hoc csv files (rmc.*) now and then, and the
# small device files GGIRread, GGIR and read.gt3x ship.
#
# Parameters drawn per case (draw_case()): f0, f1 (0 too; mostly the
# number of files, as GGIR::GGIR() gives it), datadir as a
# folder or as paths (gravcal then sometimes given outputdir + studyname
# instead of metadatadir), overwrite, do.cal, backup.cal.coef ("retrieve"
# with or without a part 2 report, "redo", a coefficient csv), minimumFileSizeMB,
# windowsizes, chunksize, dynrange, desiredtz, configtz, whole groups of
# the do.* metrics and the filters (tools/ggir-sweep.R's draw_args()),
# do.neishabouricounts, nonwear_approach, nonwear_range_threshold,
# spherecrit, minloadcrit, printsummary, interpolationType, frequency_tol,
# imputeTimegaps, recordingEndSleepHour with dayborder, print.filename,
# verbose, use_trycatch_serial, do.parallel, maxNcores, a myfun, and
# parameters g.part1() does not read (params_output's, idloc, ...). Each
# parameter goes in its list or as a legacy argument in `...`, by a draw.
#
# Outcomes: identical / differs (file set, which file was written, or
# which file, object, first difference) / refused (gravcal stops naming a
# parameter in backticks, GGIR does not) / both error / only GGIR errors /
# only gravcal errors; with the R code that reproduces the case.
#
# Results: <SWEEP_OUT>.md (a row per case, appended as cases run) and
# <SWEEP_OUT>.rds (all records, rewritten after each case). Default
# SWEEP_OUT /tmp/sweep-part1. Environment: SWEEP_FILES (folder of the
# recordings, kept; default /tmp/sweep-part1-files), SWEEP_CASES (the
# cases' folders, kept; default /tmp/sweep-part1-cases), SWEEP_DEADLINE
# (UTC time after which no case starts), SWEEP_THREADS (gravcal.threads).
#
# Sourcing this file runs nothing; run_case(spec) reruns a case from its
# record's `spec`.

`%||%` <- function(a, b) if (is.null(a)) b else a

# tools/ggir-sweep.R's functions (make_synthetic(), draw_recipe(),
# real_files(), draw_args(), run_quiet(), diff_element(), ...), in their own
# environment (sourcing it runs nothing)
sweep_dir <- function() {
  f <- tryCatch(normalizePath(sys.frame(1)$ofile), error = function(e) NULL)
  if (is.null(f)) {
    a <- grep("^--file=", commandArgs(FALSE), value = TRUE)
    if (length(a)) f <- normalizePath(sub("^--file=", "", a[1]))
  }
  if (is.null(f) || !file.exists(file.path(dirname(f), "ggir-sweep.R"))) return("tools")
  dirname(f)
}
sw <- new.env()
sys.source(file.path(sweep_dir(), "ggir-sweep.R"), envir = sw)

# ---- recordings ------------------------------------------------------------

# The pool of recordings: synthetic ones made once into `folder` (a
# recipe per file: tools/ggir-sweep.R's draw_recipe(), 3-30 hours), the
# real small files. Each: path, sf, ext, recipe, build (code).
make_pool <- function(folder, seed) {
  dir.create(folder, showWarnings = FALSE, recursive = TRUE)
  set.seed(seed)
  pool <- list()
  specs <- list(c("cwa", 3), c("cwa", 10), c("cwa", 26), c("geneactiv", 4), c("geneactiv", 12),
                c("gt3x", 5), c("gt3x", 20), c("actigraph_csv", 3), c("actigraph_csv", 8),
                c("parmay", 6), c("parmay", 14))
  for (s in specs) {
    fm <- s[1]
    r <- sw$draw_recipe(fm, seed = sample(1e4, 1))
    r$hours <- as.numeric(s[2])
    if (r$sf >= 60 && r$hours > 8) r$sf <- if (fm %in% c("gt3x", "geneactiv")) 30 else 25
    ext <- c(cwa = ".cwa", geneactiv = ".bin", gt3x = ".gt3x", actigraph_csv = ".csv",
             parmay = ".BIN")[[fm]]
    name <- sprintf("syn-%s-%gHz-%gh%s", fm, r$sf, r$hours, ext)
    path <- file.path(folder, name)
    if (!file.exists(path)) {
      t0 <- proc.time()[["elapsed"]]
      sw$make_synthetic(r, path)
      cat(sprintf("wrote %s (%.1f MB, start %s) in %.1f s\n", name, file.size(path) / 1e6,
                  r$start, proc.time()[["elapsed"]] - t0))
    }
    pool[[name]] <- list(path = path, sf = r$sf, ext = ext, recipe = r, kind = "synthetic",
                         build = paste0("sw$make_synthetic(", sw$compact(r), ", ", deparse(path), ")"))
  }
  # ad hoc csv files (their rmc.* list kept)
  for (k in 1:2) {
    r <- sw$draw_recipe("adhoc_csv", seed = sample(1e4, 1))
    r$hours <- c(4, 8)[k]
    r$gap <- NULL
    if (r$time == "none") r$time <- "UNIXsec"
    name <- sprintf("adhoc-%d-%gHz-%gh.csv", k, r$sf, r$hours)
    path <- file.path(folder, name)
    rmc <- attr(sw$make_synthetic(r, path), "rmc")
    pool[[name]] <- list(path = path, sf = r$sf, ext = ".csv", recipe = r, kind = "adhoc", rmc = rmc,
                         build = paste0("sw$make_synthetic(", sw$compact(r), ", ", deparse(path), ")"))
  }
  for (f in sw$real_files()) {
    sf <- tryCatch(sw$run_quiet(GGIR::g.inspectfile(f))$value$sf, error = function(e) NULL)
    ext <- paste0(".", tools::file_ext(f))
    pool[[basename(f)]] <- list(path = f, sf = if (length(sf)) sf else NA, ext = ext,
                                kind = "real", build = NULL)
  }
  pool
}

# ---- parameters ------------------------------------------------------------

# A case: its files (pool names and the names they get), how datadir is
# given, what the metadatadirs hold before the run, g.part1()'s arguments
# (`args`: the lists and legacy arguments, as given to both), gravcal's
# way of naming its output (metadatadir or outputdir + studyname).
draw_case <- function(pool, defaults) {
  kinds <- vapply(pool, function(p) p$kind, "")
  adhoc <- stats::runif(1) < 0.1
  if (adhoc) {
    pick <- sample(names(pool)[kinds == "adhoc"], 1)
    if (stats::runif(1) < 0.4) pick <- c(pick, sample(names(pool)[kinds == "synthetic"], 1))
  } else {
    nf <- sample(1:3, 1, prob = c(0.35, 0.4, 0.25))
    pick <- character()
    for (k in seq_len(nf)) {
      left <- setdiff(names(pool)[kinds != "adhoc"], pick)
      w <- ifelse(kinds[left] == "synthetic", 0.65 / sum(kinds[left] == "synthetic"),
                  0.35 / sum(kinds[left] == "real"))
      pick <- c(pick, sample(left, 1, prob = w))
    }
  }
  style <- sample(c("own", "plain", "meta_", "_csv"), 1, prob = c(0.45, 0.35, 0.1, 0.1))
  names_in <- vapply(seq_along(pick), function(k) {
    ext <- pool[[pick[k]]]$ext
    switch(style, own = pick[k], plain = sprintf("p%d%s", k, ext),
           meta_ = if (k == 1) sprintf("meta_p%d%s", k, ext) else sprintf("p%d%s", k, ext),
           `_csv` = sprintf("s_csv%s", ext))
  }, "")
  if (anyDuplicated(tolower(names_in))) names_in <- sprintf("p%d-%s", seq_along(pick), names_in)
  sf <- suppressWarnings(min(vapply(pick, function(p) as.numeric(pool[[p]]$sf), 0), na.rm = TRUE))
  if (!is.finite(sf)) sf <- NA

  # metrics, filters, chunksize, dynrange, windowsizes, desiredtz, configtz,
  # nonwear_approach (tools/ggir-sweep.R's draws); its offset, scale... are
  # g.getmeta()'s, not g.part1()'s
  a <- sw$draw_args(defaults, sf)
  lists <- a[grep("^params_", names(a))]
  pm <- lists$params_metrics %||% list()
  pr <- lists$params_rawdata %||% list()
  pg <- lists$params_general %||% list()
  pc <- lists$params_cleaning %||% list()
  # whole groups (GGIR 3.3-9 stops on part of one: see draw_args()), but
  # in 1 case in 20
  if (stats::runif(1) < 0.95) {
    dm <- defaults$params_metrics
    val <- function(m) isTRUE(pm[[m]] %||% dm[[m]])
    for (g in list(paste0("do.roll_med_acc_", c("x", "y", "z")),
                   paste0("do.dev_roll_med_acc_", c("x", "y", "z")))) {
      if (any(vapply(g, val, TRUE))) for (m in g) pm[[m]] <- TRUE
    }
    if (any(vapply(paste0("do.hf", c("x", "y", "z")), val, TRUE))) pm$do.hfen <- TRUE
  }
  if (stats::runif(1) < 0.06) pm$do.neishabouricounts <- TRUE
  if (stats::runif(1) < 0.25) pr$minimumFileSizeMB <- 0 else if (stats::runif(1) < 0.2) {
    pr$minimumFileSizeMB <- sample(c(1, 5, 20), 1)
  }
  # (the real files are all under 2 MB)
  if (all(kinds[pick] == "real") && stats::runif(1) < 0.8) pr$minimumFileSizeMB <- 0
  if (stats::runif(1) < 0.2) pr$do.cal <- FALSE
  if (stats::runif(1) < 0.25) pr$spherecrit <- sample(c(0.1, 0.2, 0.5, 0.9), 1)
  if (stats::runif(1) < 0.35) pr$minloadcrit <- sample(c(1, 3, 6, 12, 24, 72), 1)
  if (stats::runif(1) < 0.1) pr$printsummary <- TRUE
  if (stats::runif(1) < 0.15) pr$interpolationType <- 2
  if (stats::runif(1) < 0.1) pr$frequency_tol <- sample(c(0, 0.05, 0.5), 1)
  if (stats::runif(1) < 0.1) pr$imputeTimegaps <- FALSE
  if (stats::runif(1) < 0.15) pr$nonwear_range_threshold <- sample(c(50, 100, 300), 1)
  if (stats::runif(1) < 0.12) {
    pg$recordingEndSleepHour <- sample(c(19, 20, 21, 22), 1)
    if (stats::runif(1) < 0.5) pg$dayborder <- sample(c(-2, 4, 12), 1)
  }
  if (stats::runif(1) < 0.2) pg$print.filename <- TRUE
  if (stats::runif(1) < 0.3) pg$use_trycatch_serial <- TRUE
  if (stats::runif(1) < 0.3) pg$do.parallel <- FALSE
  if (stats::runif(1) < 0.1) pg$maxNcores <- sample(1:4, 1)
  if (stats::runif(1) < 0.3) pg$overwrite <- TRUE
  # not read by g.part1()
  po <- list()
  if (stats::runif(1) < 0.15) po$save_ms5rawlevels <- TRUE
  if (stats::runif(1) < 0.15) po$epochvalues2csv <- TRUE
  if (stats::runif(1) < 0.1) pg$idloc <- 2
  if (stats::runif(1) < 0.1) pc$includedaycrit <- 10
  if (stats::runif(1) < 0.05) pg$dataFormat <- "raw"
  if (adhoc) {
    rmc <- pool[[pick[1]]]$rmc
    pr <- c(pr, rmc)
    pr$rmc.noise <- sample(c(0.01, 0.013), 1)
    pr$rmc.dynamic_range <- sample(c(8, 16), 1)
  }
  # each parameter in its list or, by a draw, a legacy argument
  args <- list()
  legacy <- list()
  for (nm in c("params_metrics", "params_rawdata", "params_general", "params_cleaning")) {
    v <- list(params_metrics = pm, params_rawdata = pr, params_general = pg,
              params_cleaning = pc)[[nm]]
    if (!length(v)) next
    asleg <- stats::runif(length(v)) < 0.3
    if (any(!asleg)) args[[nm]] <- v[!asleg]
    legacy <- c(legacy, v[asleg])
  }
  if (length(po)) {
    if (stats::runif(1) < 0.5) legacy$params_output <- po else legacy <- c(legacy, po)
  }
  args <- c(args, legacy)
  if (stats::runif(1) < 0.25) args$f0 <- sample(seq_len(length(pick) + 1), 1)
  # (GGIR's g.part1() stops on its own default f1 = c(), "argument is of
  # length zero": GGIR::GGIR() always gives it, the number of files)
  u <- stats::runif(1)
  args$f1 <- if (u < 0.04) NULL else if (u < 0.12) 0 else if (u < 0.3) {
    sample(seq_len(length(pick) + 1), 1)
  } else length(pick)
  if (stats::runif(1) < 0.25) args$verbose <- FALSE
  if (stats::runif(1) < 0.05 && !is.na(sf)) {
    args$myfun <- list(FUN = function(data, parameters) {
      i <- seq(1, floor(nrow(data) / 125) * 125, by = 125)
      round(data[i, 1] * parameters, 3)
    }, parameters = 10, expected_sample_rate = 25, expected_unit = "g", colnames = "x10",
    minlength = 5, outputres = 5, outputtype = "numeric")
  }
  # what the metadatadirs hold before: marker meta files, a part 2 report,
  # a coefficient file
  pre <- list(markers = character(), report = NULL, coef = NULL)
  if (stats::runif(1) < 0.3) {
    pre$markers <- names_in[stats::runif(length(names_in)) < 0.6]
    if (style == "_csv" && length(names_in)) pre$markers <- names_in[1]
  }
  coef_rows <- function() {
    who <- names_in[stats::runif(length(names_in)) < 0.6]
    if (!length(who)) return(NULL)
    n <- length(who)
    d <- data.frame(filename = ifelse(stats::runif(n) < 0.5, paste0("meta_", who, ".RData"), who),
                    cal.error.start = sample(100:300, n) / 10000,
                    cal.error.end = sample(10:200, n) / 10000,
                    scale.x = sample(9800:10200, n) / 10000, scale.y = sample(9800:10200, n) / 10000,
                    scale.z = sample(9800:10200, n) / 10000,
                    offset.x = sample(-200:200, n) / 10000, offset.y = sample(-200:200, n) / 10000,
                    offset.z = sample(-200:200, n) / 10000,
                    temperature.offset.x = 0, temperature.offset.y = 0, temperature.offset.z = 0,
                    QCmessage = "ok", n.10sec.windows = sample(100:900, n),
                    n.hours.considered = sample(3:30, n), use.temperature = FALSE,
                    stringsAsFactors = FALSE)
    if (stats::runif(1) < 0.4) {
      d$temperature.offset.x <- sample(-50:50, n) / 1e5
      d$meantempcal <- sample(2000:3000, n) / 100
      d$use.temperature <- TRUE
    }
    d
  }
  if (stats::runif(1) < 0.2) pre$report <- coef_rows()
  u <- stats::runif(1)
  bcc <- NULL
  if (u < 0.12) {
    pre$coef <- coef_rows()
    if (!is.null(pre$coef)) bcc <- "coef"
  } else if (u < 0.2) {
    bcc <- "redo"
  }
  datadir_as <- if (stats::runif(1) < 0.2) "paths" else "folder"
  gravcal_out <- if (stats::runif(1) < 0.2) "outputdir" else "metadatadir"
  list(pick = pick, names = names_in, style = style, args = args, pre = pre, bcc = bcc,
       datadir_as = datadir_as, gravcal_out = gravcal_out)
}

# ---- a case ------------------------------------------------------------------

marker <- "sweep-part1 marker"

# The case's folders: <id>/ (the recordings, hard links to the pool's),
# ggir/ and gravcal/ (each output_<id>/, with the files drawn in `pre`).
setup_case <- function(spec, pool, dir) {
  unlink(dir, recursive = TRUE)
  # (named as the case: GGIR::GGIR()'s output_<folder> and
  # output_<studyname> are then both output_<id>)
  data <- file.path(dir, spec$id)
  dir.create(data, recursive = TRUE)
  for (k in seq_along(spec$pick)) {
    to <- file.path(data, spec$names[k])
    if (!suppressWarnings(file.link(pool[[spec$pick[k]]]$path, to))) file.copy(pool[[spec$pick[k]]]$path, to)
  }
  md <- c(ggir = file.path(dir, "ggir", paste0("output_", spec$id)),
          gravcal = file.path(dir, "gravcal", paste0("output_", spec$id)))
  for (m in md) {
    dir.create(dirname(m), recursive = TRUE, showWarnings = FALSE)
    if (length(spec$pre$markers) || !is.null(spec$pre$report)) {
      for (s in c("meta/basic", "results/QC")) dir.create(file.path(m, s), recursive = TRUE)
      for (f in spec$pre$markers) {
        e <- new.env()
        e$M <- marker
        save(M, envir = e, file = file.path(m, "meta", "basic", paste0("meta_", f, ".RData")))
      }
      if (!is.null(spec$pre$report)) {
        utils::write.csv(spec$pre$report, file.path(m, "results", "QC", "data_quality_report.csv"),
                         row.names = FALSE)
      }
    }
  }
  coef <- NULL
  if (!is.null(spec$pre$coef)) {
    coef <- file.path(dir, "coef.csv")
    utils::write.csv(spec$pre$coef, coef, row.names = FALSE)
  }
  list(data = data, md = md, coef = coef,
       datadir = if (spec$datadir_as == "paths") file.path(data, spec$names) else data)
}

# The calls of a case as R code (`d`: the case folder's setup list).
case_calls <- function(spec, d) {
  a <- spec$args
  if (identical(spec$bcc, "coef")) a$backup.cal.coef <- d$coef
  if (identical(spec$bcc, "redo")) a$backup.cal.coef <- "redo"
  a_txt <- paste(deparse(a, width.cutoff = 500L, control = c("keepNA", "keepInteger", "niceNames",
                                                                 "showAttributes")), collapse = "\n")
  gr_out <- if (spec$gravcal_out == "outputdir") {
    paste0("outputdir = ", deparse(dirname(d$md[["gravcal"]])),
           if (spec$datadir_as == "paths") paste0(", studyname = ", deparse(spec$id)))
  } else paste0("metadatadir = ", deparse(d$md[["gravcal"]]))
  list(args = a, a_txt = a_txt,
       R = paste0("do.call(GGIR::g.part1, c(list(datadir = datadir, metadatadir = ",
                  deparse(d$md[["ggir"]]), "), a))"),
       G = paste0("do.call(gravcal::g.part1, c(list(datadir = datadir, ", gr_out, "), a))"))
}

# What a metadatadir holds: its files (recursive) and per meta file its
# objects (as p1_objects() gives them) or "marker" (left as it was).
read_output <- function(md) {
  files <- sort(dir(md, recursive = TRUE, all.files = TRUE))
  meta <- list()
  basic <- file.path(md, "meta", "basic")
  for (f in sort(dir(basic))) {
    e <- new.env()
    ok <- tryCatch({
      load(file.path(basic, f), envir = e)
      TRUE
    }, error = function(err) FALSE)
    if (!ok) {
      meta[[f]] <- "unreadable"
      next
    }
    v <- mget(sort(ls(e, all.names = TRUE)), envir = e)
    if (identical(v$M, marker)) {
      meta[[f]] <- "marker"
      next
    }
    for (nm in intersect(c("M", "C"), names(v))) {
      if (is.list(v[[nm]]) && !is.null(v[[nm]]$bsc_qc)) v[[nm]]$bsc_qc <- names(v[[nm]]$bsc_qc)
    }
    meta[[f]] <- v
  }
  list(files = files, meta = meta)
}

# Differences between GGIR's and gravcal's outputs: a character vector.
compare_outputs <- function(R, G) {
  out <- character()
  note <- character()
  if (!identical(R$files, G$files)) {
    out <- c(out, paste0("files: only GGIR's ", paste(setdiff(R$files, G$files), collapse = ","),
                         "; only gravcal's ", paste(setdiff(G$files, R$files), collapse = ",")))
  }
  for (f in intersect(names(R$meta), names(G$meta))) {
    r <- R$meta[[f]]
    g <- G$meta[[f]]
    if (is.character(r) || is.character(g)) {
      if (!identical(r, g)) {
        out <- c(out, sprintf("%s: GGIR's %s, gravcal's %s", f,
                              if (is.character(r)) r else "written",
                              if (is.character(g)) g else "written"))
      }
      next
    }
    if (!identical(names(r), names(g))) {
      out <- c(out, sprintf("%s: objects GGIR %s, gravcal %s", f, paste(names(r), collapse = ","),
                            paste(names(g), collapse = ",")))
      next
    }
    for (nm in names(r)) {
      if (identical(r[[nm]], g[[nm]])) next
      if (nm == "M" && is.list(r$M) && is.list(g$M)) {
        d <- sw$compare_meta(r$M, g$M)
        if (!length(d)) {
          # (compare_meta() leaves bsc_qc out; the tests compare its names)
          if (!identical(r$M$bsc_qc, g$M$bsc_qc)) {
            out <- c(out, sprintf("%s: M$bsc_qc's names: GGIR %s, gravcal %s", f,
                                  sw$compact(r$M$bsc_qc), sw$compact(g$M$bsc_qc)))
          } else {
            note <- c(note, paste0(f, ": M$QClog start/end differ (dropped)"))
          }
          next
        }
        out <- c(out, paste0(f, ": M: ", paste(vapply(d, function(x) {
          sprintf("%s[%s, %s]: GGIR %s, gravcal %s (%s)", x$element, x$row, x$column,
                  x$ggir, x$gravcal, x$note)
        }, ""), collapse = " / ")))
      } else if (is.list(r[[nm]]) && is.list(g[[nm]]) && !is.data.frame(r[[nm]])) {
        els <- union(names(r[[nm]]), names(g[[nm]]))
        bad <- els[!vapply(els, function(k) identical(r[[nm]][[k]], g[[nm]][[k]]), TRUE)]
        if (!length(bad)) bad <- "(order or attributes of the list)"
        k <- bad[1]
        out <- c(out, sprintf("%s: %s$%s: GGIR %s, gravcal %s", f, nm, paste(bad, collapse = ","),
                              paste(utils::capture.output(utils::str(r[[nm]][[k]], vec.len = 3)), collapse = " "),
                              paste(utils::capture.output(utils::str(g[[nm]][[k]], vec.len = 3)), collapse = " ")))
      } else {
        x <- sw$diff_element(nm, r[[nm]], g[[nm]])
        out <- c(out, sprintf("%s: %s[%s, %s]: GGIR %s, gravcal %s (%s)", f, nm, x$row, x$column,
                              x$ggir, x$gravcal, x$note))
      }
    }
  }
  structure(out, note = note)
}

# The parameter lists of `a` completed from GGIR::load_params() (GGIR's
# g.part1() takes a list given as complete), as the tests do.
complete_lists <- function(a) {
  d <- GGIR::load_params()
  for (nm in intersect(names(a), c("params_metrics", "params_rawdata", "params_general",
                                   "params_cleaning"))) {
    a[[nm]] <- utils::modifyList(d[[nm]], a[[nm]])
  }
  a
}

param_names <- function(defaults) {
  c(sw$param_names(defaults), "f0", "f1", "datadir", "metadatadir", "myfun", "outputdir",
    "studyname", "verbose")
}

run_case <- function(spec, pool, cases_dir, pnames) {
  d <- setup_case(spec, pool, file.path(cases_dir, spec$id))
  cc <- case_calls(spec, d)
  env <- new.env()
  env$datadir <- d$datadir
  env$a <- complete_lists(cc$args)
  gg <- sw$run_quiet(eval(str2lang(cc$R), env))
  gc <- sw$run_quiet(eval(str2lang(cc$G), env))
  R <- read_output(d$md[["ggir"]])
  G <- read_output(d$md[["gravcal"]])
  diffs <- compare_outputs(R, G)
  refused <- if (!is.null(gc$error)) sw$named_param(gc$error, pnames) else NA_character_
  outcome <- if (is.null(gg$error) && is.null(gc$error)) {
    if (length(diffs)) "differs" else "identical"
  } else if (!is.null(gg$error) && !is.null(gc$error)) {
    "both error"
  } else if (!is.null(gc$error)) {
    if (!is.na(refused)) "refused" else "only gravcal errors"
  } else "only GGIR errors"
  written <- sprintf("GGIR wrote %d, gravcal %d meta file(s)",
                     sum(!vapply(R$meta, is.character, TRUE)), sum(!vapply(G$meta, is.character, TRUE)))
  detail <- switch(outcome,
    identical = paste0(written, if (length(attr(diffs, "note"))) paste0("; ", paste(attr(diffs, "note"), collapse = "; "))),
    differs = paste(diffs, collapse = " // "),
    `both error` = paste0("GGIR: ", gg$error, " | gravcal: ", gc$error,
                          if (length(diffs)) paste0(" | outputs differ: ", paste(diffs, collapse = " // "))),
    refused = paste0("gravcal (", refused, "): ", gc$error),
    `only gravcal errors` = paste0("gravcal: ", gc$error, " | ", written),
    `only GGIR errors` = paste0("GGIR: ", gg$error, " | ", written))
  if (outcome %in% c("only GGIR errors", "only gravcal errors", "refused") && length(diffs)) {
    detail <- paste0(detail, " | outputs differ: ", paste(diffs, collapse = " // "))
  }
  repro <- c("source(\"tools/ggir-sweep-part1.R\")  # its functions; nothing runs",
             paste0("datadir <- ", paste(deparse(d$datadir), collapse = " "),
                    "  # (case folder kept; rebuilt by setup_case(spec, make_pool(...), dir))"),
             paste0("a <- ", cc$a_txt),
             "a <- complete_lists(a)  # the lists given, completed from GGIR::load_params()",
             if (length(spec$pre$markers) || !is.null(spec$pre$report)) {
               "# (both metadatadirs start with the marker meta files / report of spec$pre)"
             },
             paste0("R <- ", cc$R), paste0("G <- ", cc$G))
  list(id = spec$id, spec = spec, files = spec$names, pool = spec$pick, outcome = outcome,
       refused = refused, detail = detail, diffs = as.vector(diffs), ggir_error = gg$error,
       gravcal_error = gc$error, ggir_warnings = gg$warnings, gravcal_warnings = gc$warnings,
       ggir_files = R$files, gravcal_files = G$files, seconds_ggir = gg$seconds,
       seconds_gravcal = gc$seconds, repro = repro, time = format(Sys.time(), tz = "UTC"))
}

# ---- main --------------------------------------------------------------------

main <- function() {
  st <- sw$sweep_settings(3L, "/tmp/sweep-part1")
  n <- st$n
  seed <- st$seed
  out <- st$out
  deadline <- st$deadline
  files <- Sys.getenv("SWEEP_FILES", "/tmp/sweep-part1-files")
  cases <- Sys.getenv("SWEEP_CASES", "/tmp/sweep-part1-cases")
  suppressMessages(library(gravcal))
  defaults <- GGIR::load_params()
  pnames <- param_names(defaults)
  pool <- make_pool(files, 1000 + seed)
  set.seed(seed)
  writeLines(c(sprintf("# g.part1(): gravcal against GGIR %s, random folders and parameters (tools/ggir-sweep-part1.R %d %d)",
                       utils::packageVersion("GGIR"), n, seed), "",
               sprintf("R %s, gravcal %s, started %s UTC.", getRversion(),
                       utils::packageVersion("gravcal"), format(Sys.time(), tz = "UTC")), "",
               "| case | files | arguments (non-default) | outcome | detail | GGIR s | gravcal s |",
               "|---|---|---|---|---|---|---|"), paste0(out, ".md"))
  results <- list()
  if (file.exists(paste0(out, ".rds")) && nzchar(Sys.getenv("SWEEP_APPEND"))) results <- readRDS(paste0(out, ".rds"))
  for (i in seq_len(n)) {
    if (!is.null(deadline) && Sys.time() > deadline) {
      cat("deadline passed: stopping before case", i, "\n")
      break
    }
    spec <- draw_case(pool, defaults)
    spec$id <- sprintf("s%d-%03d", seed, i)
    r <- run_case(spec, pool, cases, pnames)
    results[[length(results) + 1]] <- r
    saveRDS(results, paste0(out, ".rds"))
    shown <- sw$compact(c(spec$args[setdiff(names(spec$args), "myfun")],
                          if (!is.null(spec$args$myfun)) list(myfun = "(test's x10)"),
                          list(style = spec$style, datadir = spec$datadir_as, gravcal_out = spec$gravcal_out),
                          if (length(spec$pre$markers)) list(markers = spec$pre$markers),
                          if (!is.null(spec$pre$report)) list(report = spec$pre$report$filename),
                          if (!is.null(spec$bcc)) list(bcc = spec$bcc)))
    cat(sprintf("| %s | %s | %s | %s | %s | %.1f | %.1f |\n", spec$id,
                sw$md_cell(paste(sprintf("%s (%s)", spec$names, spec$pick), collapse = ", ")),
                sw$md_cell(shown, 3000), r$outcome, sw$md_cell(r$detail, 800),
                r$seconds_ggir, r$seconds_gravcal), file = paste0(out, ".md"), append = TRUE)
    cat(sprintf("%s %-20s GGIR %6.1f s gravcal %5.1f s  %s\n", spec$id, r$outcome,
                r$seconds_ggir, r$seconds_gravcal, substr(r$detail, 1, 200)))
  }
  sw$sweep_summary(results, out)
}

if (sys.nframe() == 0L) main()
