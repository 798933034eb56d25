# GGIR's reference results, cached.
#
# The identity tests compare gravcal with GGIR on the same input. GGIR's side
# costs minutes per 30-hour recording and is the same every run, so its
# result is kept in tests/ggir-cache/, one .rds per call, under a key made of
# everything the result depends on:
# - what was called (a label such as "g.calibrate") and its arguments,
#   serialized (the full parameter lists, not only the changed ones);
# - the bytes of the input files (MD5 of each; a folder: of every file in it,
#   with its relative name; a Movisens acc.bin: its folder) and the
#   extension, never their path;
# - GGIR's, GGIRread's and data.table's versions, R's version and platform,
#   the width of its long double and the time zone.
# gravcal's side always runs. A key not in the cache is computed by GGIR and
# written there (so a run on a new platform, GGIR version or test input fills
# it; commit the new files). Results that are errors are never cached.
#
# The cache is checked against GGIR on every run: the entries whose key
# starts with "0" (one in 16, spread over the tests by the hash) and whose
# GGIR call took at most GRAVCAL_GGIR_VERIFY_SECONDS (default 20) seconds of
# CPU when it was last computed (<key>.seconds beside the entry; an entry
# without it is recomputed) are recomputed and must be identical() to the
# stored ones (bsc_qc, GGIR's wall-clock log, by its shape:
# same_ggir_result()); `make test-ggir-cache` recomputes them all, the
# slow ones too. GRAVCAL_GGIR_CACHE_MODE:
#   "use"    (default) as above;
#   "verify" recompute every entry, compare, and write the missing ones;
#   "trust"  never recompute a stored entry (make test's sanitizer run, whose
#            check beside it recomputes the sixteenth);
#   "off"    always compute, never read or write.
# GRAVCAL_GGIR_CACHE: the folder (make passes tests/ggir-cache's absolute
# path; without it, tests/ggir-cache is found from tests/testthat or from the
# repository's root, where tools/flags-check.R and tools/identity-table.R
# run).

ggir_cache_dir <- function() {
  d <- Sys.getenv("GRAVCAL_GGIR_CACHE")
  if (!nzchar(d)) {
    # tests/ggir-cache, from tests/testthat or from the repository's root
    d <- if (basename(getwd()) == "testthat") file.path("..", "ggir-cache") else
      file.path("tests", "ggir-cache")
    if (!dir.exists(dirname(d))) return(NULL)
  }
  if (!dir.exists(d)) {
    ok <- suppressWarnings(dir.create(d, recursive = TRUE))
    if (!ok) return(NULL)
  }
  normalizePath(d)
}

ggir_cache_mode <- function() {
  m <- Sys.getenv("GRAVCAL_GGIR_CACHE_MODE", "use")
  if (!m %in% c("use", "verify", "trust", "off")) {
    stop("GRAVCAL_GGIR_CACHE_MODE must be \"use\", \"verify\", \"trust\" or \"off\", not \"",
         m, "\"", call. = FALSE)
  }
  m
}

# MD5 of an R object's serialization (version 2: no encoding header) or of
# files' bytes
md5_object <- function(x) {
  f <- tempfile(fileext = ".bin")
  on.exit(unlink(f))
  con <- file(f, "wb")
  serialize(x, con, version = 2L)
  close(con)
  unname(tools::md5sum(f))
}

md5_inputs <- function(files) {
  out <- character()
  for (p in files) {
    # a Movisens recording is its folder (GGIR reads temp.bin and
    # unisens.xml beside acc.bin)
    if (!dir.exists(p) && file.exists(file.path(dirname(p), "unisens.xml"))) {
      p <- dirname(p)
    }
    if (dir.exists(p)) {
      rel <- sort(list.files(p, recursive = TRUE, all.files = TRUE))
      out <- c(out, paste0(rel, "=", tools::md5sum(file.path(p, rel))))
    } else {
      # the extension too: GGIR tells formats by it
      out <- c(out, paste0(tools::file_ext(p), "=", tools::md5sum(p)))
    }
  }
  out
}

ggir_platform_key <- function() {
  ver <- function(p) {
    if (requireNamespace(p, quietly = TRUE)) as.character(utils::packageVersion(p)) else ""
  }
  list(GGIR = ver("GGIR"), GGIRread = ver("GGIRread"),
       data.table = ver("data.table"), R = R.version.string,
       platform = R.version$platform,
       longdouble = .Machine$sizeof.longdouble,
       tz = c(Sys.getenv("TZ"), suppressWarnings(Sys.timezone())))
}

ggir_cache_key <- function(label, files, args) {
  md5_object(list(label = label, inputs = md5_inputs(files), args = args,
                  platform = ggir_platform_key()))
}

# GGIR's result of `compute` (an expression evaluated only when needed), for
# the call named `label` on `files` with `args`.
ggir_cached <- function(label, files, args, compute) {
  mode <- ggir_cache_mode()
  dir <- if (mode != "off") ggir_cache_dir()
  if (is.null(dir)) return(compute)
  key <- ggir_cache_key(label, files, args)
  path <- file.path(dir, paste0(key, ".rds"))
  if (file.exists(path)) {
    stored <- readRDS(path)$value
    if (mode == "verify" || (mode == "use" && ggir_cache_spot_check(dir, key))) {
      fresh <- ggir_cache_timed(dir, key, compute)
      testthat::expect_true(same_ggir_result(fresh, stored),
        label = sprintf("GGIR's %s (cache %s.rds) identical to the cached result",
                        label, key))
      return(fresh)
    }
    return(stored)
  }
  value <- ggir_cache_timed(dir, key, compute)
  if (!inherits(value, "error")) {
    tmp <- tempfile(tmpdir = dir, fileext = ".tmp")
    saveRDS(list(value = value,
                 about = list(label = label, files = basename(files),
                              platform = ggir_platform_key(),
                              made = format(Sys.time(), "%Y-%m-%d"))),
            tmp, compress = "xz")
    file.rename(tmp, path)   # atomic: the sanitizer run may write beside us
  }
  value
}

# The message of GGIR's error for a call a test expects to fail, or NA when
# the call returned. GGIR's failing the same way on the same input is a
# reference result like any other, so it is cached (and spot-checked) as
# the others are; an error of the caching itself is not caught.
ggir_error <- function(label, files, args, compute) {
  ggir_cached(paste(label, "(its error)"), files, args,
              tryCatch({
                compute
                NA_character_
              }, error = conditionMessage))
}

# Whether a run in "use" mode recomputes the stored entry `key`: one in 16
# by the key, unless its GGIR call is known to take more than
# GRAVCAL_GGIR_VERIFY_SECONDS of CPU (those are left to make
# test-ggir-cache).
ggir_cache_spot_check <- function(dir, key) {
  if (!startsWith(key, "0")) return(FALSE)
  limit <- suppressWarnings(as.numeric(Sys.getenv("GRAVCAL_GGIR_VERIFY_SECONDS", "20")))
  if (is.na(limit)) {
    stop("GRAVCAL_GGIR_VERIFY_SECONDS must be a number of seconds, not \"",
         Sys.getenv("GRAVCAL_GGIR_VERIFY_SECONDS"), "\"", call. = FALSE)
  }
  s <- ggir_cache_seconds(dir, key)
  is.na(s) || s <= limit
}

# The CPU seconds GGIR took for the entry `key` when last computed (NA when
# not recorded).
ggir_cache_seconds <- function(dir, key) {
  f <- file.path(dir, paste0(key, ".seconds"))
  if (!file.exists(f)) return(NA_real_)
  s <- suppressWarnings(as.numeric(readLines(f, n = 1, warn = FALSE)))
  if (length(s) != 1) NA_real_ else s
}

# `compute` evaluated, its CPU seconds (this process's) written beside the
# entry `key` (atomically: the sanitizer run may write beside us); errors
# are not timed (they are not cached).
ggir_cache_timed <- function(dir, key, compute) {
  t0 <- proc.time()
  value <- compute
  if (!inherits(value, "error")) {
    used <- proc.time() - t0
    tmp <- tempfile(tmpdir = dir, fileext = ".tmp")
    writeLines(sprintf("%.1f", used[["user.self"]] + used[["sys.self"]]), tmp)
    file.rename(tmp, file.path(dir, paste0(key, ".seconds")))
  }
  value
}

# identical(), the way the identity tests read GGIR's results: base
# identical() (it tells NA from NaN) on every element but bsc_qc, whose rows
# are wall-clock times and memory sizes; of bsc_qc its columns, their
# classes and its rows
same_ggir_result <- function(a, b) {
  if (!is.list(a) || !is.list(b) || !"bsc_qc" %in% names(a)) return(identical(a, b))
  keep <- setdiff(names(a), "bsc_qc")
  identical(names(a), names(b)) && identical(a[keep], b[keep]) &&
    identical(names(a$bsc_qc), names(b$bsc_qc)) &&
    identical(nrow(a$bsc_qc), nrow(b$bsc_qc)) &&
    identical(lapply(a$bsc_qc, class), lapply(b$bsc_qc, class))
}
