# Running a cohort (calibrate_files(), R/cohort.R; g.part1(),
# R/ggir-meta-files.R): one future per recording on the session's plan
# (run_cohort()), the worker that calibrates one recording into its result
# slot, and the cohort table's row of a fit.

# The function each worker runs for recording i: calibrate, save at once.
cohort_worker <- function(paths, ids, slots, method, args, settings, outcomes = FALSE) {
  force(outcomes)
  force(paths)
  force(ids)
  force(slots)
  force(method)
  force(args)
  force(settings)
  function(i, p) {
    identity <- file_identity(paths[i])
    res <- calibrate_one(paths[i], ids[i], method, args)
    if (outcomes) res$outcomes <- outcome_row(paths[i], res$fit, sf_for_file(paths[i], args$sf))
    res$key <- list(identity = identity, settings = settings)
    write_bytes_atomic(serialize(res, NULL), slots[i])
    if (!is.null(p)) p(message = ids[i])
    invisible(NULL)
  }
}

# Run worker(i, progressor) for every i in todo, one future per recording
# on the plan the user set (a plain loop in this process where no plan is
# set: the future package not loaded, nor a plan named in the options or
# the environment; or without the future package).
# Returns why the recordings without a result have none, by index. When a
# worker dies, the recordings it was calibrating are reported; those that
# could not even start on the dead worker are run again once on fresh
# workers (the plan is set again, which restarts its workers).
# Whether the session has no future plan of the user's: the future
# package not loaded (plan() loads it) and no plan named by the option
# future.plan or R_FUTURE_PLAN. Then the files run in this process: the
# same as future's sequential plan, without its setup (0.1 s of a week's
# part 1: bench/ab.sh).
no_plan_set <- function() {
  !isNamespaceLoaded("future") && is.null(getOption("future.plan")) &&
    !nzchar(Sys.getenv("R_FUTURE_PLAN"))
}

run_cohort <- function(todo, worker, labels) {
  failures <- list()
  if (!length(todo)) return(failures)
  dead <- FALSE
  failed <- function(i) {
    force(i)
    function(e) {
      why <- conditionMessage(e)
      if (inherits(e, "FutureError")) {
        dead <<- TRUE
        why <- paste0("the R process calibrating it stopped (",
                      sub("[.] Post-mortem.*$", "", why), ")")
      }
      failures[[as.character(i)]] <<- why
      NULL
    }
  }
  p <- if (requireNamespace("progressr", quietly = TRUE)) {
    progressr::progressor(steps = length(todo))
  }
  if (no_plan_set() || !requireNamespace("future", quietly = TRUE)) {
    for (i in todo) tryCatch(worker(i, p), error = failed(i))
    return(failures)
  }
  # several workers: one thread each (options(gravcal.threads))
  one <- future::nbrOfWorkers() > 1
  run <- function(queue) {
    fs <- list()
    unstarted <- integer(0)
    for (i in queue) {
      f <- tryCatch(
        future::future({
          if (one) options(gravcal.threads = 1L)
          worker(i, p)
        }, globals = list(worker = worker, i = i, p = p, one = one),
        packages = "gravcal", seed = TRUE, label = labels[i]),
        error = function(e) e)
      if (inherits(f, "FutureError")) {
        # the worker it went to had died with an earlier recording
        dead <<- TRUE
        unstarted <- c(unstarted, i)
      } else if (inherits(f, "error")) {
        failed(i)(f)
      } else {
        fs[[as.character(i)]] <- f
      }
    }
    for (k in names(fs)) tryCatch(future::value(fs[[k]]), error = failed(k))
    unstarted
  }
  again <- run(todo)
  if (dead) {
    restart_workers()
    dead <- FALSE
  }
  if (length(again)) {
    again <- run(again)
    if (dead) restart_workers()
    for (i in again) {
      failures[[as.character(i)]] <- "no worker could start it (they had stopped)"
    }
  }
  failures
}

# Set the plan again: a cluster plan starts fresh workers.
restart_workers <- function() {
  strategies <- future::plan("list")
  future::plan(future::sequential)
  future::plan(strategies)
}

# One recording: the fit and its row, or a row saying what went wrong. The
# warnings raised while calibrating it go into its row.
calibrate_one <- function(file, id, method, args) {
  t0 <- proc.time()[["elapsed"]]
  cohort_fault("calibrate", file)
  cohort_fault("pause", file)
  warns <- character(0)
  err <- NULL
  fit <- tryCatch(
    withCallingHandlers(
      do.call(calibrate, c(list(x = file, method = method),
                           utils::modifyList(args, list(sf = sf_for_file(file, args$sf))))),
      warning = function(w) {
        warns <<- c(warns, conditionMessage(w))
        invokeRestart("muffleWarning")
      }),
    error = function(e) {
      err <<- conditionMessage(e)
      NULL
    })
  list(row = cohort_row(file, id, fit, err, unique(warns),
                        proc.time()[["elapsed"]] - t0, method),
       fit = fit)
}

# A fit's count of rest windows left out for `reason` (NA when its guards
# did not run).
excluded_count <- function(fit, reason) {
  ex <- if (!is.null(fit)) fit$excluded
  if (is.null(ex) || !reason %in% names(ex)) NA_integer_ else as.integer(ex[[reason]])
}

# `file`: the recording's path; `id`: its identity in the cohort.
cohort_row <- function(file, id, fit, error, warnings, seconds, method) {
  na <- is.null(fit)
  cf <- if (na) rep(NA_real_, 12) else unname(stats::coef(fit))
  coefs <- stats::setNames(as.list(cf[c(1:3, 7:12)]), c(
    "scale.x", "scale.y", "scale.z", "offset.x", "offset.y", "offset.z",
    "temperature.offset.x", "temperature.offset.y", "temperature.offset.z"))
  if (method == "lightweight") {
    coefs[c("cross.xy", "cross.xz", "cross.yz")] <- as.list(cf[4:6])
  }
  # their standard errors, same order, named with a .se suffix
  se <- if (na || is.null(fit$se)) rep(NA_real_, 12) else unname(fit$se)
  se <- se[c(1:3, 7:12, 4:6)[seq_along(coefs)]]
  coefs[paste0(names(coefs), ".se")] <- as.list(se)
  num <- function(v) if (is.null(v)) NA_real_ else as.numeric(v)[1]
  inp <- if (na) NULL else fit$input
  rep <- inp$report
  # the reader's (an ad hoc csv file is one by its rmc.* list, not its name)
  format <- if (is.character(inp$format)) inp$format else
    tryCatch(file_format(file), error = function(e) NA_character_)
  rest <- if (na) NA_real_ else if (method == "ggir") {
    as.numeric(NROW(fit$points))
  } else as.numeric(NROW(fit$windows))
  data.frame(
    file = id,
    status = if (na) "failed" else fit$status,
    message = if (na) paste(error, collapse = "; ") else fit$message,
    coefs,
    parameters = if (na) NA_integer_ else length(fit$model),
    points = if (na) NA_integer_ else NROW(fit$points),
    meantempcal = if (na) NA_real_ else num(fit$meantemp),
    error_before_mg = if (na) NA_real_ else 1000 * fit$error_before,
    error_after_mg = if (na) NA_real_ else 1000 * fit$error_after,
    format = format,
    serial = if (na || is.null(fit$input$serial)) NA_character_ else
      as.character(fit$input$serial),
    pooled = FALSE,
    hours = if (na) NA_real_ else fit_hours(fit),
    windows = if (na) NA_real_ else num(fit$n_windows),
    rest_windows = rest,
    # rest windows the guards left out, by reason (gravcal's own modes;
    # NA where no guard ran: GGIR-compatible mode, given coefficients)
    excluded_norm = excluded_count(fit, "norm"),
    excluded_clipped = excluded_count(fit, "clipped"),
    excluded_identical = excluded_count(fit, "identical"),
    # rest windows left out as not on the sphere, and the hours of their
    # stretches (near-rest.R; NA where the rule does not run)
    rejected_windows = if (na || is.null(fit$rejected)) NA_integer_ else
      as.integer(fit$rejected$windows),
    rejected_hours = if (na || is.null(fit$rejected)) NA_real_ else
      sum(fit$rejected_stretches$hours),
    # what the reader read and skipped (native decoders)
    reader = if (is.null(inp$reader)) NA_character_ else inp$reader,
    samples = num(inp$samples),
    skipped = num(rep$skipped), gaps = num(rep$gaps),
    gap_seconds = num(rep$gap_seconds),
    truncated = if (is.null(rep)) NA else isTRUE(rep$truncated),
    read_notes = if (length(rep$notes)) paste(rep$notes, collapse = "; ") else "",
    warnings = paste(warnings, collapse = "; "),
    seconds = seconds, stringsAsFactors = FALSE, check.names = FALSE)
}

# Hours of samples read (the GGIR method's own count holds only the whole
# hours it used).
fit_hours <- function(fit) {
  inp <- fit$input
  if (isTRUE(is.finite(inp$samples) && is.finite(inp$sf) && inp$sf > 0)) {
    return(as.numeric(inp$samples) / inp$sf / 3600)
  }
  if (is.null(fit$hours)) NA_real_ else as.numeric(fit$hours)
}

# Notes joined with "; " (vectorised: pool_devices() notes several rows).
join_notes <- function(a, b) {
  ifelse(is.na(a) | !nzchar(a), b, paste0(a, "; ", b))
}

# ---- writing: atomic files, owned outputs, the lock -----------------------

# Test hook: fault injection for the fault-injection tests,
# set through the environment so that workers inherit it.
# GRAVCAL_FAULT="write:REGEX" writes half the bytes of files whose path
# matches (a full disk); "calibrate:REGEX" kills the R process that starts
# to calibrate a matching recording (a worker dying mid-file); "pause:REGEX"
# waits 3 s before calibrating a matching recording (a long one).
cohort_fault <- function(stage, path) {
  f <- Sys.getenv("GRAVCAL_FAULT")
  if (!nzchar(f) || !startsWith(f, paste0(stage, ":"))) return(FALSE)
  if (!grepl(substring(f, nchar(stage) + 2), path)) return(FALSE)
  if (stage == "calibrate") tools::pskill(Sys.getpid(), tools::SIGKILL)
  if (stage == "pause") Sys.sleep(3)
  TRUE
}
