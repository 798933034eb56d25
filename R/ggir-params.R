# GGIR's parameters, once. Each row: its name in g.calibrate() (GGIR's own
# name, as in GGIR's params_rawdata; NA where g.calibrate() does not take
# it), its name in calibrate(method = "ggir") (NA where that does not take
# it), its default and its check. The two front doors read names, defaults
# and checks from here: g.calibrate() through ggir_params(),
# calibrate(method = "ggir") through calibrate_ggir(). The constants behind
# the defaults, with their sources, are in ggir_constants (ggir.R).
# A function, so that it is built after ggir_constants whatever the order
# the package's files are read in.
ggir_param_table <- function() {
  k <- ggir_constants
  row <- function(ggir, own, default, check = NULL) {
    list(ggir = ggir, own = own, default = default, check = check)
  }
  at_least_0 <- function(x, arg) check_number(x, arg, min = 0)
  above_0 <- function(x, arg) check_number(x, arg, min = 0, min_inclusive = FALSE)
  # in calibrate()'s order (its message for an unknown argument lists them)
  list(
    row(NA, "use_temp", TRUE, check_flag),
    row("spherecrit", "spherecrit", k$spherecrit, at_least_0),
    row("minloadcrit", "minloadcrit", k$minloadcrit, at_least_0),
    row("chunksize", "chunksize", 1, function(x, arg) {
      check_number(x, arg, min = 0, max = 1, min_inclusive = FALSE)
    }),
    row(NA, "max_sd", k$max_sd, above_0),
    row(NA, "max_iter", k$max_iter, function(x, arg) {
      check_number(x, arg, min = 1, max = .Machine$integer.max, integer = TRUE)
    }),
    row(NA, "tol", k$tol, at_least_0),
    row(NA, "verbose", FALSE, check_flag),
    row("printsummary", NA, FALSE, check_flag),
    # GGIR reads rmc.noise (ad hoc csv files) only when given
    row("rmc.noise", NA, NULL, function(x, arg) if (!is.null(x)) above_0(x, arg)),
    row("rmc.sf", NA, NULL, function(x, arg) if (!is.null(x)) above_0(x, arg)),
    # GGIR's ad hoc csv files (R/adhoc-csv.R): GGIR 3.3-9's load_params()
    # defaults; rmc.firstrow.acc makes a file one
    row("rmc.firstrow.acc", NA, NULL, rmc_whole),
    row("rmc.firstrow.header", NA, NULL, rmc_whole),
    row("rmc.header.length", NA, NULL, rmc_whole),
    row("rmc.col.acc", NA, 1:3, function(x, arg) {
      if (!is.numeric(x) || length(x) != 3 || anyNA(x) || any(x < 1) ||
          any(x != round(x)) || anyDuplicated(x)) {
        abort("`", arg, "` must be 3 different column numbers, not ", describe(x), ".")
      }
    }),
    row("rmc.col.temp", NA, NULL, rmc_whole),
    row("rmc.col.time", NA, NULL, rmc_whole),
    row("rmc.unit.acc", NA, "g", rmc_choice(c("g", "mg", "bit"))),
    row("rmc.unit.temp", NA, "C", rmc_choice(c("C", "K", "F"))),
    row("rmc.unit.time", NA, "POSIX",
        rmc_choice(c("POSIX", "character", "UNIXsec", "UNIXmsec", "ActivPAL"))),
    row("rmc.format.time", NA, "%Y-%m-%d %H:%M:%OS", rmc_string),
    row("rmc.bitrate", NA, NULL, rmc_number_or_name),
    row("rmc.dynamic_range", NA, NULL, rmc_number_or_name),
    row("rmc.unsignedbit", NA, TRUE, check_flag),
    row("rmc.origin", NA, "1970-01-01", rmc_string),
    # time zones move time stamps only, which the calibration does not use
    row("rmc.desiredtz", NA, NULL, rmc_string),
    row("rmc.configtz", NA, NULL, rmc_string),
    row("rmc.headername.sf", NA, NULL, rmc_string),
    row("rmc.headername.sn", NA, NULL, rmc_string),
    row("rmc.headername.recordingid", NA, NULL, rmc_string),
    row("rmc.header.structure", NA, NULL, rmc_string),
    # not implemented: TRUE is refused where a file is read (rmc_layout())
    row("rmc.check4timegaps", NA, FALSE, check_flag),
    row("rmc.doresample", NA, FALSE, check_flag),
    # a wear column: g.calibrate() does not use it
    row("rmc.col.wear", NA, NULL, rmc_whole),
    row("rmc.dec", NA, ".", rmc_choice(c(".", ","))),
    row("rmc.scalefactor.acc", NA, 1, function(x, arg) check_number(x, arg)),
    # checked where the source is opened (open_source())
    row("reader", "reader", "native"),
    # calibrate(method = "ggir")'s ad hoc csv files: GGIR's rmc.* list
    row(NA, "rmc", NULL, function(x, arg) rmc_values(x, arg))
  )
}

# Checks of the rmc.* rows (NULL is each one's "not given").
rmc_whole <- function(x, arg) {
  if (!is.null(x)) check_number(x, arg, min = 1, integer = TRUE)
}
rmc_string <- function(x, arg) {
  if (!is.null(x) && !(is.character(x) && length(x) == 1 && !is.na(x))) {
    abort("`", arg, "` must be a string, not ", describe(x), ".")
  }
}
rmc_choice <- function(choices) {
  function(x, arg) {
    if (!(is.character(x) && length(x) == 1 && x %in% choices)) {
      abort("`", arg, "` must be one of ", paste0("\"", choices, "\"", collapse = ", "),
            ", not ", describe(x), ".")
    }
  }
}
rmc_number_or_name <- function(x, arg) {
  if (is.character(x)) rmc_string(x, arg) else if (!is.null(x)) check_number(x, arg, min = 0)
}

# The rmc.* parameters, checked, with GGIR's defaults: from `rmc` (a list;
# calibrate(), read_recording()) or from the values of g.calibrate()'s
# table. An unknown name is an error.
rmc_values <- function(rmc, arg = "rmc") {
  if (is.null(rmc)) return(NULL)
  if (!is.list(rmc) || (length(rmc) && is.null(names(rmc)))) {
    abort("`", arg, "` must be a named list of GGIR's rmc.* parameters, not ",
          describe(rmc), ".")
  }
  rows <- Filter(function(p) grepl("^rmc[.]", p$ggir), ggir_param_table())
  nms <- vapply(rows, `[[`, "", "ggir")
  bad <- setdiff(names(rmc), nms)
  if (length(bad)) {
    abort("Unknown parameter", if (length(bad) > 1) "s", " in `", arg, "`: ",
          paste0("`", bad, "`", collapse = ", "), ". Known: ", paste(nms, collapse = ", "), ".")
  }
  out <- stats::setNames(lapply(rows, `[[`, "default"), nms)
  for (nm in names(rmc)) out[nm] <- list(rmc[[nm]])
  for (p in rows) if (!is.null(p$check)) p$check(out[[p$ggir]], p$ggir)
  out
}

# The rows a front door takes: door "ggir" (g.calibrate()) or "own"
# (calibrate(method = "ggir")).
ggir_param_rows <- function(door) {
  Filter(function(p) !is.na(p[[door]]), ggir_param_table())
}

ggir_param_names <- function(door) {
  vapply(ggir_param_rows(door), `[[`, "", door)
}

# A front door's parameters under its own names: each the value in the last
# list of `given` that names it, else its default; then each checked, in
# the table's order (an error names the argument).
ggir_param_values <- function(door, given = list()) {
  rows <- ggir_param_rows(door)
  nms <- ggir_param_names(door)
  out <- stats::setNames(lapply(rows, `[[`, "default"), nms)
  for (g in given) {
    for (nm in intersect(nms, names(g))) out[nm] <- list(g[[nm]])
  }
  for (p in rows) {
    if (!is.null(p$check)) p$check(out[[p[[door]]]], p[[door]])
  }
  out
}
