# compare_coefs(): two sets of coefficients (any tool's, read_coefs()) set
# side by side, as the calibrated vectors they give on the sphere, and its
# print method.

#' Compare two tools' coefficients for the same recordings
#'
#' Matches the recordings of `a` and `b` by file name (without folder and
#' extension, and without the UK Biobank pipeline's `-summary` suffix), and
#' gives for each the difference of every coefficient (`b - a`), the z value
#' of that difference where standard errors exist (gravcal's fits and
#' [calibrate_files()] tables have them: `z = (b - a) / sqrt(se_a^2 +
#' se_b^2)`, with the standard errors there are), and the largest
#' difference between the two calibrations over orientations: `max |a_A(u)
#' - a_B(u)|` in mg over 2000 unit vectors `u` spread evenly over the
#' sphere.
#'
#' Offsets depend on the temperature the model is centred on, so both sets
#' are first expressed at one reference temperature (`a`'s mean
#' temperature, else `b`'s; the offsets `o + t (T_ref - m) / s`), and the
#' calibrations are compared at that temperature. A standard error of an
#' offset is the one at its fit's own mean temperature.
#'
#' @param a,b Coefficients: data frames from [read_coefs()] or
#'   [calibrate_files()], `gravcal_fit`s of GGIR's model, or named lists of
#'   them.
#' @return A data frame (class `gravcal_coef_comparison`), one row per
#'   recording in both: `file`, `tool_a`, `tool_b`, `reference_temp`, the
#'   differences `d_scale.x` ... `d_temperature.offset.z`, the z values
#'   `z_scale.x` ... (NA without standard errors), `max_abs_z` and
#'   `mapping_mg`. The recordings in only one of them are in
#'   `attr(, "only_a")` and `attr(, "only_b")`.
#' @export
#' @examples
#' rec <- simulate_recording(hours = 30, sf = 10, seed = 4,
#'                           tempoffset = c(0.002, -0.001, 0.001))
#' fit <- calibrate(rec, sf = 10, method = "ggir")
#' out <- file.path(tempdir(), "p01.txt")
#' write_coefs(list(p01 = fit), out, format = "omconvert")
#' compare_coefs(list(p01 = fit), read_coefs(out))
compare_coefs <- function(a, b) {
  ca <- as_coefs(a, "a")
  cb <- as_coefs(b, "b")
  ka <- coef_key(ca$file)
  kb <- coef_key(cb$file)
  for (k in list(list(ka, "a"), list(kb, "b"))) {
    if (anyDuplicated(k[[1]])) {
      abort("`", k[[2]], "` holds two recordings named \"",
            k[[1]][anyDuplicated(k[[1]])], "\" (without folder and ",
            "extension); they cannot be matched.")
    }
  }
  both <- intersect(ka, kb)
  if (!length(both)) {
    abort("`a` and `b` have no recording in common (by file name without ",
          "folder and extension): `a` has ", paste0("\"", utils::head(ka, 3),
                                                   "\"", collapse = ", "),
          ", `b` has ", paste0("\"", utils::head(kb, 3), "\"",
                               collapse = ", "), ".")
  }
  u <- sphere_points(2000)
  rows <- lapply(both, function(k) {
    ra <- ca[match(k, ka), ]
    rb <- cb[match(k, kb), ]
    tref <- if (is.finite(ra$meantemp)) ra$meantemp else
      if (is.finite(rb$meantemp)) rb$meantemp else 0
    va <- at_temperature(ra, tref)
    vb <- at_temperature(rb, tref)
    d <- vb - va
    sea <- se_of(ra)
    seb <- se_of(rb)
    se <- sqrt(ifelse(is.na(sea), 0, sea^2) + ifelse(is.na(seb), 0, seb^2))
    se[is.na(sea) & is.na(seb)] <- NA
    z <- d / se
    # both calibrations at the reference temperature, measured v = u
    map <- function(v) sweep(sweep(u, 2, v[4:6], "+"), 2, v[1:3], "*")
    diff <- map(vb) - map(va)
    out <- data.frame(file = ra$file, tool_a = ra$tool, tool_b = rb$tool,
                      reference_temp = tref, stringsAsFactors = FALSE)
    out[paste0("d_", coef_names())] <- as.list(unname(d))
    out[paste0("z_", coef_names())] <- as.list(unname(z))
    out$max_abs_z <- if (all(is.na(z))) NA_real_ else max(abs(z), na.rm = TRUE)
    out$mapping_mg <- 1000 * max(sqrt(rowSums(diff^2)))
    out
  })
  out <- do.call(rbind, rows)
  rownames(out) <- NULL
  attr(out, "only_a") <- ca$file[!ka %in% both]
  attr(out, "only_b") <- cb$file[!kb %in% both]
  class(out) <- c("gravcal_coef_comparison", "data.frame")
  out
}

coef_key <- function(f) {
  b <- basename(as.character(f))
  b <- sub("-summary[.]json$", "", b, ignore.case = TRUE)
  sub("[.][^.]*$", "", b)
}

# The 9 coefficients with the offsets moved to reference temperature tref.
at_temperature <- function(r, tref) {
  v <- unlist(r[coef_names()])
  if (any(v[7:9] != 0)) v[4:6] <- v[4:6] + v[7:9] * (tref - r$meantemp) / v[1:3]
  v
}

se_of <- function(r) {
  n <- paste0(coef_names(), ".se")
  if (!all(n %in% names(r))) return(rep(NA_real_, 9))
  unname(unlist(r[n]))
}

# n unit vectors spread evenly over the sphere (a Fibonacci lattice).
sphere_points <- function(n) {
  i <- seq_len(n) - 0.5
  z <- 1 - 2 * i / n
  r <- sqrt(1 - z^2)
  phi <- i * pi * (3 - sqrt(5))
  cbind(r * cos(phi), r * sin(phi), z)
}

#' @export
print.gravcal_coef_comparison <- function(x, digits = 3, ...) {
  cat("<gravcal_coef_comparison> ", nrow(x), " recording(s) in both",
      sep = "")
  oa <- attr(x, "only_a")
  ob <- attr(x, "only_b")
  if (length(oa) || length(ob)) {
    cat(sprintf(" (%d only in `a`, %d only in `b`)", length(oa), length(ob)))
  }
  cat("\n")
  if (!nrow(x)) return(invisible(x))
  cat(sprintf("  largest mapping difference: %.*f mg (%s)\n", digits,
              max(x$mapping_mg), x$file[which.max(x$mapping_mg)]))
  if (any(is.finite(x$max_abs_z))) {
    cat(sprintf("  largest |z| of a coefficient difference: %.*f\n", digits,
                max(x$max_abs_z, na.rm = TRUE)))
  }
  show <- data.frame(file = x$file, tools = paste(x$tool_a, "vs", x$tool_b),
                     mapping_mg = round(x$mapping_mg, digits),
                     max_abs_z = round(x$max_abs_z, digits),
                     d_scale = signif(apply(abs(as.matrix(
                       x[paste0("d_", coef_names()[1:3])])), 1, max), digits),
                     d_offset_g = signif(apply(abs(as.matrix(
                       x[paste0("d_", coef_names()[4:6])])), 1, max), digits),
                     stringsAsFactors = FALSE)
  print(show, row.names = FALSE)
  invisible(x)
}
