# Argument validation. Every message names the argument, what was expected
# and what was given.

abort <- function(...) {
  stop(paste0(...), call. = FALSE)
}

describe <- function(x) {
  if (is.null(x)) return("NULL")
  if (is.data.frame(x)) return(sprintf("a data frame with %d rows", nrow(x)))
  if (length(x) == 1 && is.atomic(x)) {
    return(if (is.character(x)) sprintf('"%s"', x) else format(x))
  }
  cl <- class(x)[1]
  sprintf("%s %s of length %d", if (grepl("^[aeiou]", cl)) "an" else "a", cl,
          length(x))
}

check_number <- function(x, arg, min = -Inf, max = Inf, min_inclusive = TRUE,
                         integer = FALSE, max_inclusive = TRUE) {
  ok <- is.numeric(x) && length(x) == 1 && !is.na(x) && is.finite(x)
  if (ok) ok <- if (min_inclusive) x >= min else x > min
  if (ok) ok <- if (max_inclusive) x <= max else x < max
  if (ok && integer) ok <- x == round(x)
  if (!ok) {
    what <- if (integer) "a whole number" else "a number"
    range <- if (is.finite(min) && is.finite(max)) {
      sprintf(" in %s%s, %s%s", if (min_inclusive) "[" else "(", format(min),
              format(max), if (max_inclusive) "]" else ")")
    } else if (is.finite(min)) {
      sprintf(" %s %s", if (min_inclusive) ">=" else ">", format(min))
    } else if (is.finite(max)) {
      sprintf(" %s %s", if (max_inclusive) "<=" else "<", format(max))
    } else ""
    abort("`", arg, "` must be ", what, range, ", not ", describe(x), ".")
  }
  invisible(x)
}

check_flag <- function(x, arg) {
  if (!(is.logical(x) && length(x) == 1 && !is.na(x))) {
    abort("`", arg, "` must be TRUE or FALSE, not ", describe(x), ".")
  }
  invisible(x)
}

check_sf <- function(sf) {
  check_number(sf, "sf", min = 0, min_inclusive = FALSE)
}

# `sf` given for a file that records its own sampling rate (the registry's
# `own_rate`, R/formats.R) must be that rate: the file's rate is the one
# used, so another would silently change nothing the user asked for. The
# same rate rounded to whole Hz agrees too (GGIR rounds GENEActiv's rate).
check_sf_agrees <- function(sf, file_sf, format, file, arg = "sf") {
  if (is.null(sf) || !isTRUE(format_entry(format)$own_rate)) return(invisible())
  if (isTRUE(sf == file_sf || round(sf) == round(file_sf))) return(invisible())
  abort("`", arg, "` = ", format(sf), " Hz, but \"", basename(file), "\" records its ",
        "own rate, ", format(file_sf), " Hz, which is the one used; leave `", arg, "` ",
        "out or give ", format(file_sf), ".")
}

# What `path` is, without opening it: "file", "directory", "fifo" (a named
# pipe: opening it waits for a writer), "device", "other" or "missing".
file_kind <- function(path) {
  if (!file.exists(path)) return("missing")
  k <- gc_file_kind(path.expand(path))
  if (k == "unknown") k <- if (dir.exists(path)) "directory" else "file"
  k
}

# An error naming `arg` unless `path` is a regular file (or does not exist
# and `missing_ok`).
check_regular_file <- function(path, arg, missing_ok = FALSE) {
  k <- file_kind(path)
  if (k == "file" || (missing_ok && k == "missing")) return(invisible(path))
  what <- switch(k, fifo = "a named pipe", device = "a device",
                 directory = "a folder", missing = "a missing file",
                 "a special file")
  abort("`", arg, "` must be a regular file, not ", what, ": \"", path, "\".")
}

# Sample columns are matched ignoring case: two columns that differ only in
# case (`x` in g beside `X` in mg) leave it unclear which is meant.
check_column_case <- function(nms, arg) {
  low <- tolower(nms)
  for (want in c("x", "y", "z", "temperature", "time")) {
    hit <- nms[low == want]
    if (length(hit) > 1) {
      abort("`", arg, "` has columns ", paste0("`", hit, "`", collapse = " and "),
            "; names are matched ignoring case, so it is not clear which is ",
            if (want %in% c("x", "y", "z")) "the acceleration in g" else
              paste("the", want), ".")
    }
  }
  invisible()
}

# Raw samples: a data frame or matrix with numeric columns x, y, z (any case),
# optional temperature and time. Returns a list of plain numeric vectors that
# point at the caller's memory (no copy for double columns).
# `temperature = "ignore"`: a temperature column that is not numeric is left
# out with a warning (for the lightweight method, which uses the temperature
# when it has one and calibrates without a temperature term otherwise).
as_samples <- function(x, arg = "x", temperature = c("use", "ignore")) {
  temperature <- temperature[1]
  if (is.matrix(x)) {
    if (is.null(colnames(x))) {
      if (ncol(x) != 3) {
        abort("`", arg, "` must have columns named x, y, z, or exactly 3 ",
              "unnamed columns, not ", ncol(x), " unnamed columns.")
      }
      colnames(x) <- c("x", "y", "z")
    }
    x <- as.data.frame(x, stringsAsFactors = FALSE)
  }
  if (!is.data.frame(x)) {
    abort("`", arg, "` must be a data frame or matrix of raw samples with ",
          "columns x, y, z (in g), not ", describe(x), ".")
  }
  check_column_case(names(x), arg)
  nm <- tolower(names(x))
  col <- function(name, required = TRUE) {
    i <- match(name, nm)
    if (is.na(i)) {
      if (required) {
        abort("`", arg, "` must have a column `", name, "` (acceleration in ",
              "g); it has columns: ", paste(names(x), collapse = ", "), ".")
      }
      return(NULL)
    }
    v <- x[[i]]
    if (!is.numeric(v) || is.object(v)) {
      abort("Column `", names(x)[i], "` of `", arg, "` must be numeric, not ",
            class(v)[1], ".")
    }
    if (!is.double(v)) v <- as.double(v)
    v
  }
  xs <- col("x")
  ys <- col("y")
  zs <- col("z")
  ti <- match("temperature", nm)
  if (temperature == "ignore" && !is.na(ti) && !is.numeric(x[[ti]])) {
    warning("Column `", names(x)[ti], "` of `", arg, "` is not numeric (",
            class(x[[ti]])[1], "); it is ignored, and the calibration has ",
            "no temperature term.", call. = FALSE)
    temp <- NULL
  } else {
    temp <- col("temperature", required = FALSE)
  }
  ti <- match("time", nm)
  time <- if (is.na(ti)) NULL else x[[ti]]
  list(x = xs, y = ys, z = zs, temperature = temp, time = time, n = length(xs))
}

# Epochs (window table) or points: needs mean_x, mean_y, mean_z.
as_epochs <- function(w, arg = "w", need = c("mean_x", "mean_y", "mean_z")) {
  if (is.matrix(w)) w <- as.data.frame(w)
  if (!is.data.frame(w)) {
    abort("`", arg, "` must be a data frame of windows with columns ",
          paste(need, collapse = ", "), ", not ", describe(w), ".")
  }
  missing <- setdiff(need, names(w))
  if (length(missing)) {
    abort("`", arg, "` must have columns ", paste(need, collapse = ", "),
          "; missing: ", paste(missing, collapse = ", "), ".")
  }
  for (nm in need) {
    if (!is.numeric(w[[nm]])) {
      abort("Column `", nm, "` of `", arg, "` must be numeric, not ",
            class(w[[nm]])[1], ".")
    }
  }
  w
}

check_fit <- function(fit, arg = "fit") {
  if (!inherits(fit, "gravcal_fit")) {
    abort("`", arg, "` must be a gravcal_fit (from calibrate(), ",
          "fit_gradient() or fit_icp()), not ", describe(fit), ".")
  }
  K <- fit$K
  ok <- is.numeric(K) && is.matrix(K) && all(dim(K) == 3) && all(is.finite(K))
  ok <- ok && is.numeric(fit$offset) && length(fit$offset) == 3 &&
    all(is.finite(fit$offset))
  ok <- ok && is.numeric(fit$tempoffset) && length(fit$tempoffset) == 3 &&
    all(is.finite(fit$tempoffset))
  ok <- ok && is.numeric(fit$meantemp) && length(fit$meantemp) == 1
  if (!ok) {
    abort("`", arg, "` is not a valid gravcal_fit: it needs a finite 3 x 3 ",
          "`K`, finite `offset` and `tempoffset` of length 3 and a `meantemp`.")
  }
  invisible(fit)
}

# match.arg() with an error that names the argument and the choices: `x` is
# the caller's argument `arg`, whose default in the caller's signature is the
# vector of choices (the first is the default).
match_choice <- function(x, arg, choices = NULL) {
  if (is.null(choices)) {
    caller <- sys.function(sys.parent())
    choices <- eval(formals(caller)[[arg]], envir = parent.frame())
  }
  if (identical(x, choices)) return(choices[1])
  if (!is.character(x) || length(x) != 1 || is.na(x) || !x %in% choices) {
    abort("`", arg, "` must be one of ", paste0("\"", choices, "\"", collapse = ", "),
          ", not ", describe(x), ".")
  }
  x
}

# The threads g.getmeta() (and so g.part1() and epoch_signals()) uses
# within a recording: the option `gravcal.threads`, 1 or 2 (more counts as
# 2: a second thread makes the running medians of GGIR's angles beside
# the other epoch signals, and the GGIR method's window sums beside its
# decoder), 2 where it is not set. The results do not
# depend on it. A cohort run on a plan with several workers sets 1 in them.
gravcal_threads <- function() {
  o <- getOption("gravcal.threads")
  if (is.null(o)) return(2L)
  check_number(o, "options(gravcal.threads)", min = 1, integer = TRUE)
  as.integer(min(o, 2))
}
