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
    row("rmc.sf", NA, NULL),
    # checked where the source is opened (open_source())
    row("reader", "reader", "native")
  )
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
