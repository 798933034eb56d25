# calibrate_files()' result store: saved results per recording, files
# written atomically, the files gravcal owns in `outdir`, and the lock that
# keeps two runs out of one folder.

# One saved result per recording and method, named after the file and the
# MD5 of its full path and the method: unique however many recordings share
# a file name, and the same whatever the cohort's root (the identity, the
# path relative to it, changes when recordings from another folder join).
slot_names <- function(paths, method) {
  vapply(paths, function(f) {
    paste0(gsub("[^A-Za-z0-9._-]", "_", basename(f)), "-",
           substr(md5_raw(charToRaw(paste(f, method))), 1, 12))
  }, "", USE.NAMES = FALSE)
}

# What a recording is: its path, size, modification time and the MD5 of its
# first and last MiB. Hashing whole files (a week at 100 Hz is 0.3-1 GB)
# would read the cohort once more on every resume; a replaced recording has
# another header (device, start time) and another end, and an edited one
# another size or time, so these 2 MiB and the size tell them apart.
file_identity <- function(file, mib = 1) {
  info <- file.info(file, extra_cols = FALSE)
  n <- mib * 2^20
  con <- file(file, "rb", raw = TRUE)
  on.exit(close(con))
  head <- readBin(con, "raw", n)
  tail <- raw(0)
  if (info$size > n) {
    seek(con, max(n, info$size - n))
    tail <- readBin(con, "raw", n)
  }
  list(path = file, size = info$size, mtime = as.numeric(info$mtime),
       fingerprint = md5_raw(c(head, tail)))
}

# A saved result whose key matches: list(result = ); a stale one is removed
# (list()); a damaged one is removed and noted (list(note = )).
read_saved <- function(slot, identity, settings) {
  if (!file.exists(slot)) return(list())
  res <- tryCatch(readRDS(slot), error = function(e) e, warning = function(w) w)
  bad <- if (inherits(res, "condition")) {
    conditionMessage(res)
  } else if (!is.list(res) || !is.data.frame(res$row) || !is.list(res$key)) {
    "not a gravcal result"
  }
  if (!is.null(bad)) {
    unlink(slot)
    return(list(note = paste0("the saved result \"", slot, "\" could not be ",
                              "read (", bad, ") and was recomputed")))
  }
  # a result saved before the rows carried standard errors and the model's
  # size is stale too
  if (!identical(res$key$settings, settings) ||
      !all(c("scale.x.se", "parameters", "serial") %in% names(res$row)) ||
      (!is.null(identity) && !identical(res$key$identity, identity))) {
    unlink(slot)
    return(list())
  }
  list(result = res)
}

# Write bytes to `path`: under a name only gravcal uses, in the same
# folder, flushed and checked for its size, then renamed over `path`.
write_bytes_atomic <- function(bytes, path) {
  tmp <- tempfile(sprintf(".gravcal-%d-", Sys.getpid()), tmpdir = dirname(path),
                  fileext = ".part")
  n <- if (cohort_fault("write", path)) length(bytes) %/% 2 else length(bytes)
  err <- tryCatch({
    con <- file(tmp, "wb")
    tryCatch({
      writeBin(bytes[seq_len(n)], con)
      flush(con)
    }, finally = close(con))
    NULL
  }, error = conditionMessage, warning = conditionMessage)
  size <- file.size(tmp)
  if (is.null(err) && !identical(size, as.double(length(bytes)))) {
    err <- sprintf("%s of %d bytes reached the disk; is it full?",
                   format(size), length(bytes))
  }
  if (is.null(err) && !file.rename(tmp, path)) {
    err <- paste0("could not rename \"", tmp, "\" to it")
  }
  if (!is.null(err)) {
    unlink(tmp)
    abort("Could not write \"", path, "\" (", err, "); that file was left ",
          "as it was.")
  }
  invisible(path)
}

csv_bytes <- function(df) {
  con <- rawConnection(raw(0), "wb")
  on.exit(close(con))
  utils::write.csv(df, con, row.names = FALSE)
  rawConnectionValue(con)
}

# Half-written files of gravcal's that a killed run left: gravcal's names
# only, removed while the lock is held.
remove_parts <- function(dirs) {
  unlink(list.files(dirs, pattern = "^[.]gravcal-[0-9]+-.*[.]part$",
                    full.names = TRUE, all.files = TRUE))
}

# The files of outdir that gravcal wrote, with their MD5, in
# .gravcal/written.csv: gravcal overwrites or removes only those. They are
# all in outdir, so their file name is their identity there.
owned_table <- function(store) {
  f <- file.path(store, "written.csv")
  tab <- if (file.exists(f)) {
    tryCatch(utils::read.csv(f, stringsAsFactors = FALSE, colClasses = "character"),
             error = function(e) NULL)
  }
  if (is.null(tab) || !all(c("file", "md5") %in% names(tab))) {
    tab <- data.frame(file = character(0), md5 = character(0))
  }
  tab
}

is_owned <- function(path, store) {
  tab <- owned_table(store)
  i <- match(basename(path), tab$file)
  !is.na(i) && identical(unname(tools::md5sum(path)), tab$md5[i])
}

check_owned <- function(paths, store) {
  for (p in paths[file.exists(paths)]) {
    if (!is_owned(p, store)) {
      abort("`outdir` holds \"", p, "\", which gravcal did not write (or ",
            "which was changed since); gravcal does not overwrite it. Move ",
            "it away or choose another `outdir`.")
    }
  }
}

record_owned <- function(path, store, md5) {
  tab <- owned_table(store)
  tab <- tab[tab$file != basename(path), , drop = FALSE]
  if (!is.na(md5)) tab <- rbind(tab, data.frame(file = basename(path), md5 = md5))
  write_bytes_atomic(csv_bytes(tab), file.path(store, "written.csv"))
}

write_owned <- function(bytes, path, store) {
  check_owned(path, store)
  write_bytes_atomic(bytes, path)
  record_owned(path, store, unname(tools::md5sum(path)))
}

remove_owned <- function(path, store) {
  if (file.exists(path) && is_owned(path, store)) {
    unlink(path)
    record_owned(path, store, NA_character_)
  }
}

# The lock on outdir: a folder created atomically, holding its owner's
# process id and host. A lock whose owner was on this host and is gone is
# taken over.
lock_outdir <- function(store) {
  lock <- file.path(store, "lock")
  host <- Sys.info()[["nodename"]]
  for (attempt in 1:2) {
    if (dir.create(lock, showWarnings = FALSE)) {
      owner <- c(paste0("pid=", Sys.getpid()), paste0("host=", host),
                 paste0("started=", format(Sys.time(), "%Y-%m-%d %H:%M:%S")))
      tryCatch(
        write_bytes_atomic(charToRaw(paste0(owner, "\n", collapse = "")),
                           file.path(lock, "owner")),
        error = function(e) {
          unlink(lock, recursive = TRUE)
          stop(e)
        })
      return(lock)
    }
    if (!dir.exists(lock)) {
      abort("Could not create the lock \"", lock, "\" on `outdir` (is the ",
            "disk full or the folder read-only?).")
    }
    owner <- lock_owner(lock)
    if (attempt == 2 || !lock_stale(owner, host)) break
    # move the stale lock aside (atomic), check it is the one we judged
    aside <- tempfile(sprintf(".gravcal-%d-", Sys.getpid()), tmpdir = store,
                      fileext = ".part")
    if (!file.rename(lock, aside)) next
    if (!identical(lock_owner(aside), owner)) {
      file.rename(aside, lock)
      break
    }
    unlink(aside, recursive = TRUE)
    message("gravcal: took over the lock of a run that is no longer ",
            "running (", lock_describe(owner), ").")
  }
  owner <- lock_owner(lock)
  abort("`outdir` \"", dirname(store), "\" is in use by another ",
        "calibrate_files() run (", lock_describe(owner), "; lock \"", lock,
        "\"). Wait for it to end. If no such run is going on (it was killed ",
        "on another machine), remove the lock: unlink(\"", lock,
        "\", recursive = TRUE).")
}

lock_owner <- function(lock) {
  lines <- tryCatch(suppressWarnings(readLines(file.path(lock, "owner"))),
                    error = function(e) character(0))
  kv <- strsplit(lines[grepl("=", lines)], "=", fixed = TRUE)
  stats::setNames(vapply(kv, function(x) paste(x[-1], collapse = "="), ""),
                  vapply(kv, `[`, "", 1))
}

lock_describe <- function(owner) {
  if (!length(owner) || is.na(owner["pid"])) return("owner unknown")
  paste0("process ", owner["pid"], " on ", owner["host"], ", started ",
         owner["started"])
}

# Stale: taken on this host by a process that no longer exists. `os`,
# `run` (system2()) and `signal` (tools::pskill()) are arguments for the
# tests of the Windows branch, which must never signal.
lock_stale <- function(owner, host, os = .Platform$OS.type, run = system2,
                       signal = tools::pskill) {
  pid <- suppressWarnings(as.integer(owner["pid"]))
  if (is.na(pid) || !identical(unname(owner["host"]), host) ||
      pid == Sys.getpid()) {
    return(FALSE)
  }
  if (identical(os, "windows")) {
    # tools::pskill() terminates the process on Windows whatever the
    # signal (signal 0 does not probe there): ask tasklist instead, and
    # keep the lock when it cannot tell
    return(identical(windows_pid_running(pid, run), FALSE))
  }
  if (dir.exists("/proc/self")) {
    if (!dir.exists(file.path("/proc", pid))) return(TRUE)
    # a process that has ended but is not yet reaped by its parent (a
    # zombie) holds nothing: its state, after the name in parentheses
    stat <- tryCatch(readLines(file.path("/proc", pid, "stat"), n = 1L, warn = FALSE),
                     error = function(e) character(0))
    state <- sub("^.*\\) ([A-Za-z]).*$", "\\1", stat)
    return(length(state) == 1L && state %in% c("Z", "X"))
  }
  !isTRUE(suppressWarnings(signal(pid, 0L)))
}

# Whether process `pid` runs, on Windows, from tasklist's table (one
# quoted CSV row per process, without header: "image","pid",...), which
# signals nothing; NA when tasklist fails or says nothing. Its message
# for no match (kept with stderr) is in the system's language, so only
# the presence of the process's row is read.
windows_pid_running <- function(pid, run = system2) {
  out <- tryCatch(
    suppressWarnings(run("tasklist", c("/FI", paste0("\"PID eq ", pid, "\""),
                                       "/FO", "CSV", "/NH"),
                         stdout = TRUE, stderr = TRUE)),
    error = function(e) NULL)
  status <- attr(out, "status")
  if (is.null(out) || (!is.null(status) && !identical(as.integer(status), 0L))) {
    return(NA)
  }
  rows <- grepl("^\"[^\"]*\",\"[0-9]+\"", out)
  if (any(rows)) {
    return(any(grepl(paste0("^\"[^\"]*\",\"", pid, "\""), out[rows])))
  }
  # no row: no such process, if tasklist said anything at all
  if (length(out) && any(nzchar(trimws(out)))) FALSE else NA
}

unlock_outdir <- function(lock) {
  owner <- lock_owner(lock)
  if (identical(unname(owner["pid"]), as.character(Sys.getpid()))) {
    unlink(lock, recursive = TRUE)
  }
}
