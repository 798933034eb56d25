# The other tools' coefficient files, one reader and one writer each
# (read_coefs() and write_coefs() in R/coef-formats.R choose them): GGIR's
# csv, actipy's and the UK Biobank pipeline's JSON and csv, omconvert's
# and scikit-digital-health's output (their JSON read by R/json.R).

read_text <- function(f) {
  bytes <- readBin(f, "raw", n = file.size(f))
  # a byte order mark (files saved by some Windows editors)
  bom <- as.raw(c(0xef, 0xbb, 0xbf))
  if (length(bytes) >= 3 && identical(bytes[1:3], bom)) {
    bytes <- bytes[-(1:3)]
  }
  if (any(bytes == as.raw(0))) {
    abort("`file`: \"", f, "\" is not a text file of coefficients.")
  }
  text <- rawToChar(bytes)
  Encoding(text) <- "UTF-8"
  text
}

detect_coef_format <- function(text, f) {
  if (grepl("^\\s*\\{", text)) {
    if (grepl("\"Calib[xyz]Slope\"", text)) return("actipy")
    if (grepl("\"calibration-[xyz]Offset\\(g\\)\"", text)) return("ukb")
    if (grepl("\"scale\"", text) && grepl("\"offset\"", text)) return("skdh")
  } else {
    first <- sub("[\r\n].*$", "", text)
    if (grepl("(^|,)\"?scale\\.x\"?(,|$)", first) &&
        grepl("(^|,)\"?filename\"?(,|$)", first)) return("ggir")
    if (grepl("^\"?fileName\"?,\"?calOffset\"?", first)) return("ukb")
    if (grepl("(^|[\r\n])Calibration:", text)) return("omconvert")
  }
  abort("`format`: the coefficients in \"", f, "\" are of none of the ",
        "forms read (GGIR csv, actipy / UK Biobank / skdh json, omconvert ",
        "info); give `format` to have its error say what is missing.")
}

read_ggir_file <- function(f) {
  d <- tryCatch(utils::read.csv(f, stringsAsFactors = FALSE,
                                check.names = FALSE,
                                fileEncoding = "UTF-8-BOM"),
                error = function(e) abort("`file`: \"", f, "\" cannot be ",
                                          "read as csv (", conditionMessage(e),
                                          ")."))
  miss <- setdiff(c("filename", coef_names()), names(d))
  if (length(miss)) {
    abort("`file`: \"", f, "\" is not a GGIR coefficient file: it lacks the ",
          "column(s) ", paste0("`", miss, "`", collapse = ", "), ".")
  }
  if (!nrow(d)) abort("`file`: \"", f, "\" holds no recordings.")
  ggir_frame_coefs(d, f)
}

# The coefficients of the rows of a GGIR coefficient table `d` (read from
# the file `f`, or written by write_coefs()).
ggir_frame_coefs <- function(d, f) {
  rows <- lapply(seq_len(nrow(d)), function(i) {
    v <- suppressWarnings(vapply(coef_names(),
                                 function(n) as.double(d[[n]][i]), 0))
    if (!all(is.finite(v))) {
      abort("`file`: in \"", f, "\", the coefficients of \"", d$filename[i],
            "\" are not all finite numbers.")
    }
    mt <- if ("meantempcal" %in% names(d)) as.double(d$meantempcal[i]) else
      NA_real_
    coefs_row(as.character(d$filename[i]), "ggir", v[1:3], v[4:6], v[7:9],
              if (any(v[7:9] != 0)) mt else NA_real_, NA_character_)
  })
  do.call(rbind, rows)
}

# The value of "key" in parsed JSON (json_parse(), R/json.R) as numbers (a
# number or an array of them, flattened; null is NA; a string is read as a
# number), NULL when the key is absent.
json_numbers <- function(obj, key, f) {
  v <- json_find(obj, key)
  if (is.null(v)) return(NULL)
  # the array's values, depth first; NULL where it holds an object
  flat <- function(x) {
    if (!is.list(x)) return(list(x))
    if (!is.null(names(x))) return(NULL)
    parts <- lapply(x, flat)
    if (any(vapply(parts, is.null, TRUE))) NULL else do.call(c, parts)
  }
  vals <- flat(v)
  num <- function(x) {
    if (is.numeric(x)) return(x)
    if (is.logical(x)) return(if (is.na(x)) NA_real_ else NULL)
    if (x == "NaN") return(NaN)
    r <- suppressWarnings(as.double(x))
    if (is.na(r)) NULL else r
  }
  out <- lapply(vals, num)
  if (!length(vals) || any(vapply(out, is.null, TRUE))) {
    abort("`file`: in \"", f, "\", the value of \"", key, "\" is not a ",
          "number or an array of numbers.")
  }
  unlist(out)
}

json_string <- function(obj, key) {
  v <- json_find(obj, key)
  if (is.character(v) && length(v) == 1) v else NULL
}

# Three values of keys named by axis, e.g. "Calib%sSlope".
json_axes <- function(obj, fmt, f, required = TRUE) {
  v <- lapply(c("x", "y", "z"),
              function(a) json_numbers(obj, sprintf(fmt, a), f))
  present <- !vapply(v, is.null, TRUE)
  if (!any(present) && !required) return(NULL)
  if (!all(present)) {
    abort("`file`: \"", f, "\" lacks the key \"",
          sprintf(fmt, c("x", "y", "z")[!present][1]), "\".")
  }
  v <- unlist(v)
  if (length(v) != 3 || !all(is.finite(v))) {
    abort("`file`: in \"", f, "\", the values of \"", sprintf(fmt, "x"),
          "\" ... are not 3 finite numbers (", paste(v, collapse = ", "),
          ").")
  }
  v
}

file_id <- function(f) {
  sub("[.](json|txt|csv|info)$", "", basename(f), ignore.case = TRUE)
}

flag_status <- function(v) {
  if (is.null(v) || length(v) != 1 || is.na(v)) NA_character_ else
    if (v == 1) "ok" else "failed"
}

read_actipy <- function(text, f) {
  text <- json_parse(text, f)
  intercept <- json_axes(text, "Calib%sIntercept", f)
  slope <- json_axes(text, "Calib%sSlope", f)
  slope_t <- json_axes(text, "Calib%sSlopeT", f, required = FALSE)
  if (is.null(slope_t)) slope_t <- c(0, 0, 0)
  from_intercept(file_id(f), "actipy", intercept, slope, slope_t, 0,
                 flag_status(json_numbers(text, "CalibOK", f)))
}

read_ukb <- function(text, f) {
  if (!grepl("^\\s*\\{", text)) return(read_ukb_files_csv(f))
  text <- json_parse(text, f)
  id <- json_string(text, "file-name")
  id <- if (is.null(id)) file_id(f) else basename(id)
  status <- flag_status(json_numbers(text, "quality-goodCalibration", f))
  intercept <- json_axes(text, "calibration-%sOffset(g)", f)
  if (!is.null(json_numbers(text, "calibration-xSlope", f))) {
    # since pull request #184: temperature not centred
    slope <- json_axes(text, "calibration-%sSlope", f)
    slope_t <- json_axes(text, "calibration-%sSlopeTemp", f, required = FALSE)
    if (is.null(slope_t)) slope_t <- c(0, 0, 0)
    return(from_intercept(id, "ukb", intercept, slope, slope_t, 0, status))
  }
  # before it: centred on the mean device temperature
  slope <- json_axes(text, "calibration-%sSlope(g)", f)
  slope_t <- json_axes(text, "calibration-%sTemp(C)", f)
  m <- json_numbers(text, "calibration-meanDeviceTemp(C)", f)
  if (length(m) != 1 || !is.finite(m)) {
    abort("`file`: \"", f, "\" has the UK Biobank pipeline's centred ",
          "temperature coefficients but no finite ",
          "\"calibration-meanDeviceTemp(C)\".")
  }
  from_intercept(id, "ukb", intercept, slope, slope_t, m, status)
}

read_ukb_files_csv <- function(f) {
  d <- utils::read.csv(f, stringsAsFactors = FALSE, colClasses = "character",
                       fileEncoding = "UTF-8-BOM")
  miss <- setdiff(c("fileName", "calOffset", "calSlope", "calTemp"), names(d))
  if (length(miss)) {
    abort("`file`: \"", f, "\" is not a UK Biobank files.csv: it lacks the ",
          "column(s) ", paste0("`", miss, "`", collapse = ", "), ".")
  }
  triple <- function(s, what, i) {
    v <- suppressWarnings(as.double(strsplit(trimws(s), "\\s+")[[1]]))
    if (length(v) != 3 || !all(is.finite(v))) {
      abort("`file`: in \"", f, "\", `", what, "` of \"", d$fileName[i],
            "\" is not 3 finite numbers separated by spaces: \"", s, "\".")
    }
    v
  }
  rows <- lapply(seq_len(nrow(d)), function(i) {
    m <- if ("meanTemp" %in% names(d)) as.double(d$meanTemp[i]) else 0
    from_intercept(basename(d$fileName[i]), "ukb",
                   triple(d$calOffset[i], "calOffset", i),
                   triple(d$calSlope[i], "calSlope", i),
                   triple(d$calTemp[i], "calTemp", i), m)
  })
  do.call(rbind, rows)
}

read_omconvert <- function(text, f) {
  lines <- strsplit(text, "\r?\n")[[1]]
  cal <- grep("^Calibration:", lines, value = TRUE)
  if (length(cal) != 1) {
    abort("`file`: \"", f, "\" must have one \"Calibration:\" line ",
          "(omconvert's -info file), not ", length(cal), ".")
  }
  v <- suppressWarnings(as.double(strsplit(sub("^Calibration:", "", cal),
                                           ",")[[1]]))
  if (length(v) != 10 || !all(is.finite(v))) {
    abort("`file`: in \"", f, "\", the \"Calibration:\" line must hold 10 ",
          "finite numbers (scale x,y,z, offset x,y,z, tempOffset x,y,z, ",
          "referenceTemperature): \"", cal, "\".")
  }
  res <- grep("^Calibration-Result:", lines, value = TRUE)
  status <- if (length(res) == 1) {
    code <- suppressWarnings(as.integer(sub("^Calibration-Result:", "", res)))
    if (is.na(code)) NA_character_ else if (code == 0) "ok" else "failed"
  } else NA_character_
  to <- v[7:9]
  coefs_row(file_id(f), "omconvert", v[1:3], v[4:6], to,
            if (any(to != 0)) v[10] else NA_real_, status)
}

read_skdh <- function(text, f, meantemp) {
  text <- json_parse(text, f)
  get3 <- function(key, required = TRUE) {
    v <- json_numbers(text, key, f)
    if (is.null(v) && !required) return(NULL)
    if (length(v) != 3 || !all(is.finite(v))) {
      abort("`file`: in \"", f, "\", \"", key, "\" must be 3 finite numbers",
            if (is.null(v)) " but is absent" else
              paste0(", not ", paste(v, collapse = ", ")), ".")
    }
    v
  }
  scale <- get3("scale")
  offset <- get3("offset")
  ts <- get3("temperature scale", required = FALSE)
  if (is.null(ts)) ts <- c(0, 0, 0)
  m <- json_numbers(text, "temperature mean", f)
  if (!is.null(m) && !is.null(meantemp)) {
    abort("`meantemp`: \"", f, "\" holds its own \"temperature mean\" (",
          format(m), ").")
  }
  if (is.null(m)) m <- meantemp
  if (any(ts != 0) && (length(m) != 1 || !is.finite(m))) {
    abort("`meantemp` is needed: \"", f, "\" has a temperature scale but ",
          "scikit-digital-health's results do not hold the mean temperature ",
          "it is centred on; give it as `meantemp`.")
  }
  coefs_row(file_id(f), "skdh", scale, offset, ts,
            if (any(ts != 0)) m else NA_real_)
}

# ---- writing ----------------------------------------------------------------

json_object <- function(keys, values) {
  paste0("{\n", paste0("    \"", keys, "\": ", values, collapse = ",\n"),
         "\n}\n")
}

status_flag <- function(s) {
  if (is.na(s)) NULL else if (s == "ok") "1" else "0"
}

actipy_text <- function(r) {
  u <- to_intercept(r)
  keys <- c(sprintf("Calib%sIntercept", c("x", "y", "z")),
            sprintf("Calib%sSlope", c("x", "y", "z")))
  vals <- num17(c(u$intercept, u$slope))
  if (any(u$slope_t != 0)) {
    keys <- c(keys, sprintf("Calib%sSlopeT", c("x", "y", "z")))
    vals <- c(vals, num17(u$slope_t))
  }
  ok <- status_flag(r$status)
  if (!is.null(ok)) {
    keys <- c("CalibOK", keys)
    vals <- c(ok, vals)
  }
  json_object(keys, vals)
}

ukb_text <- function(r) {
  u <- to_intercept(r)
  keys <- c("file-name",
            sprintf("calibration-%sOffset(g)", c("x", "y", "z")),
            sprintf("calibration-%sSlope", c("x", "y", "z")),
            sprintf("calibration-%sSlopeTemp", c("x", "y", "z")))
  vals <- c(json_quote(r$file), num17(c(u$intercept, u$slope, u$slope_t)))
  ok <- status_flag(r$status)
  if (!is.null(ok)) {
    keys <- c(keys, "quality-goodCalibration")
    vals <- c(vals, ok)
  }
  json_object(keys, vals)
}

json_quote <- function(s) {
  s <- gsub("\\\\", "\\\\\\\\", s)
  paste0("\"", gsub("\"", "\\\\\"", s), "\"")
}

omconvert_text <- function(r) {
  v <- unlist(r[coef_names()])
  m <- if (any(v[7:9] != 0)) r$meantemp else 0
  paste0(if (!is.na(r$status)) sprintf("Calibration-Result: %d\n",
                                       if (r$status == "ok") 0L else -1L),
         "Calibration: ", paste(num17(c(v, m)), collapse = ","), "\n")
}

skdh_text <- function(r) {
  v <- unlist(r[coef_names()])
  arr <- function(x) paste0("[", paste(num17(x), collapse = ", "), "]")
  keys <- c("offset", "scale", "temperature scale")
  vals <- c(arr(v[4:6]), arr(v[1:3]), paste0("[", arr(v[7:9]), "]"))
  if (any(v[7:9] != 0)) {
    keys <- c(keys, "temperature mean")
    vals <- c(vals, num17(r$meantemp))
  }
  json_object(keys, vals)
}

# ---- comparing ---------------------------------------------------------------
