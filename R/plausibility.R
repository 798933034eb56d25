# Plausibility of fits: the one table of coefficient bounds (used by every
# place that judges plausibility: guard_fit(), the GGIR method's own mode,
# print() and calibrate_files()), and each device's history in a cohort.

#' Plausible calibration coefficients: the bounds gravcal judges fits by
#'
#' One table, used everywhere gravcal judges whether coefficients are
#' plausible. Two levels per coefficient:
#'
#' * `refuse_lower`, `refuse_upper`: beyond these no real sensor needs
#'   correcting, and gravcal's own modes do not apply the fit (status
#'   `"implausible"`, identity coefficients; GGIR-compatible mode applies
#'   whatever GGIR applies). They are far wider than the correction factors
#'   van Hees et al. (2014, Table 2; `vignette("vanhees2014")`) report for
#'   the devices of four cohorts (mean gain 0.990-1.005 with SD up to
#'   0.014, mean offset -0.012 to 0.105 g with SD up to 0.037 g, mean
#'   temperature offset up to 0.004 g per degree C). The GGIR method's
#'   own mode checks scale, offset and temperature offset; the lightweight
#'   method scale, cross-axis terms and offset.
#' * `flag_lower`, `flag_upper`: the range check of omconvert (Open
#'   Movement, `omcalibrate.c`: at most 0.2 from 1 for scale, 0.41 g for
#'   offset, 0.02 g per degree C for temperature offset); a fit beyond them
#'   is applied but flagged `"out_of_bounds"` in [calibrate_files()]'s
#'   `plausibility` column and by `print()`. omconvert has no cross-axis
#'   terms; their flag bound, 0.1, is twice the half-width of the
#'   non-orthogonalities Farago et al. (2024) simulate ([random_params()]).
#'   GGIR and actipy check no coefficient, only the error after
#'   calibration (below 10 mg) and the spread of the rest points.
#'
#' The rules [calibrate_files()] uses to judge a recording against its
#' device's other recordings are in the attribute `"history"`: `min_recordings`
#' (a device needs at least this many calibrated recordings, pooled ones
#' left out, to have a history), `z` (a coefficient disagrees with its
#' device's reference when it differs by more than `z` times the combined
#' uncertainty: the recording's standard error, the reference's and the
#' device's robust spread, or the cohort's when larger, and by at least the
#' coefficient's `practical_min`, below), `attenuation` (the smallest common change of
#' the three scales called a firmware-style attenuation, relative to the
#' device's reference), `attenuation_absolute` (the same, relative to 1, for
#' a device without history or whose history shows it), `agreement` (the
#' three scales changed by the same factor: the smallest change at least
#' this fraction of the largest, all in one direction), `min_reference`
#' (a device's reference is computed again without the recordings a first
#' judgement flags, when at least this many remain; the second
#' judgement's flags are the result), `temperature_flat_sd` (a temperature
#' whose standard deviation over the rest windows is below this, in degrees
#' C, does not vary: GGIR's rule for leaving the temperature term out) and
#' `temperature_stuck_hours` (such a temperature over a recording of at
#' least this many hours is a stuck sensor by itself; a shorter one is,
#' when another recording of the same device has a temperature that
#' varies), and `temperature_range` (degrees C: a rest window's temperature
#' outside it, or a mean temperature outside it where the windows' are not
#' kept, flags `"temperature_implausible"`: no worn device nor one left in
#' a room, a car or on a radiator reads it, so the sensor is faulty or the
#' file's temperature misread, a Kelvin or raw reading say; the fit's
#' temperature term rests on it).
#'
#' **What a device's history shows that one recording does not.** Flagged:
#' a change of the coefficients beyond their uncertainty and practical size
#' (`"device_outlier"`: a knock, a repair, a swapped sensor), a common
#' change of the three scales (`"attenuated"`: firmware that scales the raw
#' signal) and a temperature that stays flat while the device's other
#' recordings vary (`"temperature_stuck"`, in recordings too short to tell
#' alone). Not flagged, because three or four recordings per device do not
#' show them reliably: a slow drift of the coefficients over a device's
#' life (it needs dated recordings over years, and a drift smaller than a
#' recording's uncertainty is what the practical minimum leaves alone),
#' recordings of two devices under one serial number (a bimodal history),
#' and a sensor whose noise grows (the rest windows' spread is not compared
#' across recordings).
#'
#' **Practical minimum.** `practical_min` is the smallest difference from
#' the device's reference that makes a `"device_outlier"`, whatever its
#' z: a change that moves a user's results. It is chosen from the change
#' of a day's ENMO (mean of `max(|a| - 1, 0)`) that a change of one
#' coefficient causes (`bench/enmo-sensitivity.R`): on a real free-living
#' day (20.7 h, ENMO 15 mg) a change of one axis' offset moves ENMO by 1 mg
#' at 6.2 mg on average over the axes and directions (3.5 mg on the most
#' sensitive), a scale's at 0.56 % (0.37 %); on simulated days at 12 mg and
#' 0.5 %. The minimum is 5 mg for offsets (compared at the device's
#' reference temperature) and 0.5 % of the reference for scales; 0.005 for
#' cross-axis terms (a term's change moves a calibrated axis by at most
#' what a scale change as large does); 1 mg per degree C for temperature
#' offsets, whose change `t` moves the signal by `t (T - meantemp)`: on a
#' real wrist recording `|T - meantemp|` is below 3.8 degrees C nine tenths
#' of the time, so 1 mg per degree C stays within the offsets' 5 mg.
#'
#' @return A data frame, one row per coefficient group (`scale`, `cross`,
#'   `offset`, `temperature_offset`), with columns `coefficient`, `unit`,
#'   `flag_lower`, `flag_upper`, `refuse_lower`, `refuse_upper`,
#'   `practical_min` (scales: a fraction of the reference; the others in
#'   `unit`), `source` and `practical_source`; attribute `history` (a list,
#'   see above).
#' @references
#' van Hees VT et al. (2014). Autocalibration of accelerometer data for
#' free-living physical activity assessment using local gravity and
#' temperature. J Appl Physiol 117(7), 738-744.
#'
#' Open Movement omconvert, `omcalibrate.c`, `OmCalibrateConfigInit()`:
#' <https://github.com/openmovementproject/omconvert>.
#' @seealso [calibrate_files()] (the `plausibility` column).
#' @export
#' @examples
#' plausible_bounds()
#' attr(plausible_bounds(), "history")
plausible_bounds <- function() {
  b <- data.frame(
    coefficient = c("scale", "cross", "offset", "temperature_offset"),
    unit = c("", "", "g", "g per degree C"),
    flag_lower = c(0.8, -0.1, -0.41, -0.02),
    flag_upper = c(1.2, 0.1, 0.41, 0.02),
    refuse_lower = c(0.7, -0.2, -0.6, -0.05),
    refuse_upper = c(1.3, 0.2, 0.6, 0.05),
    practical_min = c(0.005, 0.005, 0.005, 0.001),
    source = c(
      "flag: omconvert (|scale - 1| <= 0.2); refuse: gravcal, far beyond van Hees et al. (2014) Table 2",
      "flag: gravcal, twice Farago et al. (2024)'s simulated range; refuse: gravcal",
      "flag: omconvert (0.41 g); refuse: gravcal, far beyond van Hees et al. (2014) Table 2",
      "flag: omconvert (0.02 g per degree C); refuse: gravcal, far beyond van Hees et al. (2014) Table 2"),
    practical_source = c(
      "0.5 % of the device's reference: moves a day's ENMO by about 1 mg (bench/enmo-sensitivity.R)",
      "0.005: a cross-axis term moves a calibrated axis by at most what a scale change as large does",
      "5 mg: moves a day's ENMO by about 1 mg (bench/enmo-sensitivity.R)",
      "1 mg per degree C: at most a 5 mg offset over the wrist's usual 4 degrees C from its mean (bench/enmo-sensitivity.R)"),
    stringsAsFactors = FALSE)
  attr(b, "history") <- history_rules
  b
}

# The device-history rules (documented in ?plausible_bounds).
history_rules <- list(min_recordings = 3L, z = 4, attenuation = 0.02,
                      attenuation_absolute = 0.03, agreement = 0.5,
                      min_reference = 2L, temperature_flat_sd = 0.01,
                      temperature_stuck_hours = 12,
                      temperature_range = c(-20, 70))

# The refusal bounds as guard_fit() and the GGIR method's own mode read them.
plausible <- local({
  b <- plausible_bounds()
  r <- function(k) b[b$coefficient == k, c("refuse_lower", "refuse_upper")]
  list(scale = unlist(r("scale"), use.names = FALSE),
       cross = r("cross")$refuse_upper, offset = r("offset")$refuse_upper,
       temp = r("temperature_offset")$refuse_upper)
})

# Which coefficients (named as in the cohort table) lie beyond the flag
# bounds: a character vector of "name = value" (empty when none). `co`: a
# named numeric vector with any of scale.*, cross.*, offset.*,
# temperature.offset.*.
beyond_flag_bounds <- function(co) {
  b <- plausible_bounds()
  group <- ifelse(startsWith(names(co), "scale."), "scale",
           ifelse(startsWith(names(co), "cross."), "cross",
           ifelse(startsWith(names(co), "offset."), "offset",
                  "temperature_offset")))
  i <- match(group, b$coefficient)
  out <- is.finite(co) & (co < b$flag_lower[i] | co > b$flag_upper[i])
  if (!any(out)) return(character(0))
  sprintf("%s = %s (bounds %s to %s)", names(co)[out],
          vapply(signif(co[out], 4), format, ""),
          b$flag_lower[i][out], b$flag_upper[i][out])
}

# A fit's coefficients named as in the cohort table (those it applies).
fit_table_coefs <- function(fit) {
  cf <- stats::coef(fit)
  stats::setNames(cf[c(1:3, 4:6, 7:9, 10:12)], c(
    "scale.x", "scale.y", "scale.z", "cross.xy", "cross.xz", "cross.yz",
    "offset.x", "offset.y", "offset.z", "temperature.offset.x",
    "temperature.offset.y", "temperature.offset.z"))
}

# A fit's plausibility without a device history (print() of a fit that
# calibrate_files() did not judge): list(flag, note) or NULL when the fit
# applies no coefficients.
fit_plausibility <- function(fit) {
  if (identical(fit$status, "implausible")) {
    return(list(flag = "out_of_bounds", note = paste0(
      "coefficients beyond the bounds at which gravcal refuses them ",
      "(plausible_bounds()); not applied")))
  }
  if (!fit$status %in% c("ok", "high_error")) return(NULL)
  out <- beyond_flag_bounds(fit_table_coefs(fit))
  if (length(out)) {
    return(list(flag = "out_of_bounds", note = paste0(
      "beyond omconvert's bounds (plausible_bounds()): ",
      paste(out, collapse = ", "))))
  }
  a <- attenuation_signature(fit_table_coefs(fit)[1:3], rep(NA_real_, 3),
                             c(1, 1, 1), c(0, 0, 0),
                             history_rules$attenuation_absolute)
  if (!is.null(a)) {
    return(list(flag = "attenuated", note = a))
  }
  tc <- fit$temperature_check
  if (isTRUE(tc$implausible)) {
    return(list(flag = "temperature_implausible", note = tc$range_note))
  }
  if (isTRUE(tc$stuck)) {
    return(list(flag = "temperature_stuck", note = tc$note))
  }
  list(flag = "ok", note = "")
}

# The temperature sensor of a fit in gravcal's own modes (both methods):
# list(available, flat, sd, value, hours, stuck, note). `available`: the
# recording has a temperature; `flat`: it does not vary (sd below
# history_rules$temperature_flat_sd, GGIR's rule for leaving the
# temperature term out); `stuck`: flat over a recording of at least
# history_rules$temperature_stuck_hours (see ?plausible_bounds). For the
# lightweight method `temps` are the rest windows' temperatures; for the
# GGIR method `flat` is the procedure's own verdict (its block's samples'
# sd below 0.01) and `temps` NULL. `implausible`: the rest windows'
# temperatures (else `mean_temp`, the fit's mean temperature) leave
# history_rules$temperature_range, with its note `range_note`.
temperature_check <- function(hours, available, temps = NULL, flat = NULL,
                              mean_temp = NULL) {
  rules <- history_rules
  sdv <- NA_real_
  value <- NA_real_
  seen <- if (!is.null(temps)) temps[is.finite(temps)] else
    if (length(mean_temp) == 1 && is.finite(mean_temp)) mean_temp else numeric(0)
  range_note <- if (available && length(seen)) temperature_range_note(range(seen)) else ""
  if (!is.null(temps)) {
    temps <- temps[is.finite(temps)]
    available <- available && length(temps) > 0
    if (length(temps) >= 2) {
      sdv <- stats::sd(temps)
      value <- stats::median(temps)
      flat <- sdv < rules$temperature_flat_sd
    } else {
      flat <- NA
    }
  }
  flat <- if (available) isTRUE(flat) else NA
  stuck <- isTRUE(flat) && isTRUE(hours >= rules$temperature_stuck_hours)
  list(available = available, flat = flat, sd = sdv, value = value,
       hours = hours, stuck = stuck,
       note = if (stuck) temperature_stuck_note(hours, value) else "",
       implausible = nzchar(range_note), range_note = range_note)
}

# The note of a temperature outside history_rules$temperature_range (`r`:
# the lowest and highest temperature seen, degrees C), or "" when inside.
temperature_range_note <- function(r) {
  lim <- history_rules$temperature_range
  if (!any(is.finite(r)) || (min(r) >= lim[1] && max(r) <= lim[2])) return("")
  paste0("temperature implausible: the sensor reads ",
         if (r[1] == r[2]) sprintf("%.1f", r[1]) else sprintf("%.1f to %.1f", r[1], r[2]),
         sprintf(" degrees C, outside the %g to %g degrees C any worn or resting device has", lim[1], lim[2]),
         ": a faulty sensor or a misread temperature (Kelvin, raw counts); the ",
         "calibration's temperature term rests on it")
}

# The temperature at which a device's recordings (rows `rows` of a cohort
# table) are compared: the median of the mean temperatures their
# temperature terms are centred on (NA when none has a temperature term).
device_reference_temp <- function(tab, rows) {
  if (!"meantempcal" %in% names(tab)) return(NA_real_)
  tc <- paste0("temperature.offset.", c("x", "y", "z"))
  if (!all(tc %in% names(tab))) return(NA_real_)
  t <- as.matrix(tab[rows, tc, drop = FALSE])
  m <- tab$meantempcal[rows]
  use <- is.finite(m) & rowSums(abs(t) > 0 & is.finite(t)) > 0
  if (!any(use)) return(NA_real_)
  stats::median(m[use])
}

# A cohort table row's coefficients `co` (named as its columns) and their
# standard errors `se`, with the offsets restated at temperature `tref`
# instead of the recording's mean temperature `m`: the model K (v + o) +
# (T - m) t is K (v + o + (tref - m) K^-1 t) + (T - tref) t, the same
# calibration. The offsets' standard errors take the temperature
# offsets' part, (tref - m) K^-1 se_t, as independent of theirs (the
# offset and the slope of a model centred on its points' mean temperature
# are nearly uncorrelated).
offsets_at_temperature <- function(co, se, m, tref) {
  oc <- paste0("offset.", c("x", "y", "z"))
  tc <- paste0("temperature.offset.", c("x", "y", "z"))
  if (!is.finite(tref) || !isTRUE(is.finite(m)) || !all(tc %in% names(co)) ||
      !all(is.finite(co[tc])) || !any(co[tc] != 0)) {
    return(list(co = co, se = se))
  }
  sc <- co[paste0("scale.", c("x", "y", "z"))]
  if (!all(is.finite(sc)) || any(sc == 0)) return(list(co = co, se = se))
  cr <- paste0("cross.", c("xy", "xz", "yz"))
  cross <- if (all(cr %in% names(co))) co[cr] else c(0, 0, 0)
  cross[!is.finite(cross)] <- 0
  K <- params_to_K(c(sc, cross))
  Ki <- solve(K)
  d <- tref - m
  co[oc] <- co[oc] + d * drop(Ki %*% co[tc])
  st <- se[tc]
  st[!is.finite(st)] <- 0
  se[oc] <- sqrt(se[oc]^2 + d^2 * drop(Ki^2 %*% st^2))
  list(co = co, se = se)
}

# Do three scales `s` (standard errors `se`) differ from the reference
# `ref` (its uncertainty `u_ref`, per axis) by one common factor, as a
# firmware attenuation of the raw signal would make them (a signal
# attenuated by a needs scales 1/a)? NULL when not, else a note.
attenuation_signature <- function(s, se, ref, u_ref, min_change) {
  if (!all(is.finite(s)) || !all(is.finite(ref))) return(NULL)
  r <- unname(s / ref)
  d <- r - 1
  if (!(all(d > 0) || all(d < 0))) return(NULL)
  f <- mean(r)
  if (abs(f - 1) < min_change) return(NULL)
  if (min(abs(d)) < history_rules$agreement * max(abs(d))) return(NULL)
  se[!is.finite(se)] <- 0
  u <- sqrt(unname(se)^2 + unname(u_ref)^2) / unname(ref)
  if (any(abs(d) <= history_rules$z * u)) return(NULL)
  sprintf(paste0("all three scales x%.3f (%.3f, %.3f, %.3f) relative to %s: ",
                 "a raw signal %s by %.1f %%"), f, r[1], r[2], r[3],
          if (all(ref == 1)) "1" else "the device's reference",
          if (f > 1) "attenuated" else "amplified", 100 * abs(1 - 1 / f))
}

# The device-history judgement of a cohort table (calibrate_files()):
# the table with columns `plausibility` and `plausibility_note`, and the
# devices' reference values (attribute "devices" of the result). See
# calibrate_files()'s documentation. Two passes: every recording is judged
# against its device's reference; then each reference is computed again
# without the recordings the first pass flagged, and every recording is
# judged again against it (the second pass's flags are the result).
cohort_plausibility <- function(tab) {
  rules <- history_rules
  n <- nrow(tab)
  cols <- c(paste0("scale.", c("x", "y", "z")), paste0("cross.", c("xy", "xz", "yz")),
            paste0("offset.", c("x", "y", "z")),
            paste0("temperature.offset.", c("x", "y", "z")))
  cols <- cols[cols %in% names(tab)]
  co <- as.matrix(tab[, cols, drop = FALSE])
  se <- as.matrix(tab[, paste0(cols, ".se"), drop = FALSE])
  colnames(se) <- cols
  raw <- co
  applied <- tab$status %in% c("ok", "high_error")
  refused <- tab$status == "implausible"
  bounds <- lapply(seq_len(n), function(i) {
    if (applied[i]) beyond_flag_bounds(raw[i, ]) else character(0)
  })
  pooled <- applied & tab$pooled %in% TRUE
  scales <- cols[1:3]
  serial <- tab$serial
  key <- ifelse(is.na(serial), paste0("\r", seq_len(n)), serial)
  files <- if (is.null(tab$file)) as.character(seq_len(n)) else tab$file
  stuck <- temperature_stuck_notes(tab, applied, pooled, key)
  # a mean temperature outside any a worn or resting device has
  hot <- vapply(seq_len(n), function(i) {
    m <- if ("meantempcal" %in% names(tab)) tab$meantempcal[i] else NA_real_
    if (applied[i] && isTRUE(is.finite(m))) temperature_range_note(c(m, m)) else ""
  }, "")
  # each device's history (its recordings, offsets restated at one
  # temperature, the attenuation signature relative to 1)
  hists <- list()
  other <- list()
  for (k in unique(key[applied])) {
    idx <- which(key == k & applied)
    hist <- idx[!pooled[idx]]
    # offsets depend on the temperature the model is centred on (each
    # recording's own mean temperature): the device's recordings are
    # compared at one, the median of theirs
    tref <- device_reference_temp(tab, hist)
    for (i in hist) {
      r <- offsets_at_temperature(co[i, ], se[i, ], tab$meantempcal[i], tref)
      co[i, ] <- r$co
      se[i, ] <- r$se
    }
    # firmware-style attenuation relative to 1 (no device history needed)
    abs_note <- lapply(hist, function(i) {
      attenuation_signature(co[i, scales], se[i, scales], c(1, 1, 1),
                            c(0, 0, 0), rules$attenuation_absolute)
    })
    abs_att <- !vapply(abs_note, is.null, NA)
    h <- list(key = k, serial = serial[idx[1]], idx = idx, hist = hist,
              tref = tref, abs_note = abs_note, abs_att = abs_att)
    if (length(hist) < rules$min_recordings) {
      other[[length(other) + 1]] <- h
    } else {
      hists[[length(hists) + 1]] <- h
    }
  }
  # a device's reference from the recordings `use`: the median of each
  # coefficient, their robust spread, the median's uncertainty
  reference <- function(use) {
    list(use = use,
         ref = apply(co[use, , drop = FALSE], 2, stats::median),
         spread = apply(co[use, , drop = FALSE], 2, stats::mad),
         # uncertainty of the median: 1.2533 times that of the mean
         u_ref = 1.2533 * apply(se[use, , drop = FALSE], 2, function(v) {
           v <- v[is.finite(v)]
           if (length(v)) stats::median(v) else NA_real_
         }) / sqrt(length(use)))
  }
  # the spread between a device's recordings: its own, or the median of
  # all devices' when larger (a device whose few recordings happen to agree
  # does not set a tighter rule than the cohort shows)
  cohort_spread <- function(refs) {
    if (!length(refs)) return(NULL)
    apply(do.call(rbind, lapply(refs, `[[`, "spread")), 2, stats::median,
          na.rm = TRUE)
  }
  # one pass: each device's recordings judged against reference `R`; a
  # list of (kind, note) per recording of `hist`, kind "attenuated",
  # "device_outlier" or NA
  judge <- function(h, R, cspread) {
    ref <- R$ref
    spread <- pmax(R$spread, cspread, na.rm = TRUE)
    u_ref <- R$u_ref
    use <- R$use
    hist <- h$hist
    abs_att <- h$abs_att
    refnote <- sprintf("device %s reference (median of %d recordings): scale %s, offset %s g%s",
                       h$serial, length(use),
                       paste(sprintf("%.4f", ref[scales]), collapse = " "),
                       paste(sprintf("%.4f", ref[paste0("offset.", c("x", "y", "z"))]),
                             collapse = " "),
                       if (is.finite(h$tref)) sprintf(" at %.1f degrees C", h$tref) else "")
    lapply(seq_along(hist), function(j) {
      i <- hist[j]
      # relative to the device's reference where it has a history of its
      # own, else (the whole device shows it) relative to 1
      a <- if (length(use) < length(hist) || !any(abs_att)) {
        attenuation_signature(co[i, scales], se[i, scales], ref[scales],
                              sqrt(u_ref[scales]^2 + spread[scales]^2),
                              rules$attenuation)
      }
      if (!is.null(a)) a <- paste0(a, " (", refnote, ")")
      if (is.null(a) && abs_att[j]) a <- h$abs_note[[j]]
      if (!is.null(a)) return(list(kind = "attenuated", note = a))
      # statistically (beyond z combined uncertainties) and practically
      # (at least the coefficient's practical minimum) different
      u <- sqrt(se[i, ]^2 + u_ref^2 + spread^2)
      z <- (co[i, ] - ref) / u
      d <- practical_change(co[i, ], ref)
      out <- is.finite(z) & abs(z) > rules$z & is.finite(d$size) & d$size >= d$min
      if (!any(out)) return(list(kind = NA_character_, note = ""))
      cand <- which(out)
      worst <- cand[order(-abs(z[cand]))][seq_len(min(3, length(cand)))]
      list(kind = "device_outlier", note = sprintf(
        "disagrees with its device's other recordings: %s (%s)",
        paste(sprintf("%s %s (%s, z = %.1f)", names(z)[worst],
                      format(signif(co[i, worst], 4)), d$text[worst], z[worst]),
              collapse = ", "), refnote))
    })
  }
  # pass 1: the reference of the recordings without the attenuation
  # signature when there are enough of them, else all (the whole device
  # shows it)
  refs1 <- lapply(hists, function(h) {
    reference(if (sum(!h$abs_att) >= rules$min_recordings) h$hist[!h$abs_att] else h$hist)
  })
  cs1 <- cohort_spread(refs1)
  pass1 <- lapply(seq_along(hists), function(d) judge(hists[[d]], refs1[[d]], cs1))
  # pass 2: each reference without the recordings pass 1 flagged (any
  # flag), when at least min_reference remain
  flagged1 <- function(d) {
    h <- hists[[d]]
    vapply(seq_along(h$hist), function(j) {
      i <- h$hist[j]
      !is.na(pass1[[d]][[j]]$kind) || length(bounds[[i]]) > 0 || nzchar(stuck[i]) || nzchar(hot[i])
    }, NA)
  }
  refs2 <- lapply(seq_along(hists), function(d) {
    h <- hists[[d]]
    keep <- h$hist[!flagged1(d)]
    if (length(keep) >= rules$min_reference) reference(keep) else refs1[[d]]
  })
  cs2 <- cohort_spread(refs2)
  pass2 <- lapply(seq_along(hists), function(d) judge(hists[[d]], refs2[[d]], cs2))

  flag <- rep(NA_character_, n)
  note <- rep("", n)
  add <- function(i, s) note[i] <<- ifelse(nzchar(note[i]), paste0(note[i], "; ", s), s)
  flag[applied] <- "ok"
  flag[refused] <- "out_of_bounds"
  note[refused] <- paste0("coefficients beyond the bounds at which gravcal ",
                          "refuses them (plausible_bounds()); not applied")
  att <- rep(FALSE, n)
  outlier <- rep(FALSE, n)
  for (h in other) {
    if (any(pooled[h$idx])) add(h$idx[pooled[h$idx]], "pooled: not judged against the device's history")
    for (j in which(h$abs_att)) add(h$hist[j], h$abs_note[[j]])
    att[h$hist[h$abs_att]] <- TRUE
    if (!is.na(h$serial)) {
      add(h$hist, sprintf(paste0("no device history (%d calibrated ",
                                 "recording(s) of device %s, %d needed)"),
                          length(h$hist), h$serial, rules$min_recordings))
    }
  }
  devices <- list()
  for (d in seq_along(hists)) {
    h <- hists[[d]]
    R <- refs2[[d]]
    if (any(pooled[h$idx])) add(h$idx[pooled[h$idx]], "pooled: not judged against the device's history")
    left <- setdiff(h$hist, R$use)
    devices[[length(devices) + 1]] <- data.frame(
      serial = h$serial, recordings = length(h$hist),
      reference_recordings = length(R$use),
      reference_files = paste(files[R$use], collapse = "; "),
      left_out_files = paste(files[left], collapse = "; "),
      reference_temp = h$tref,
      t(stats::setNames(R$ref, paste0("ref.", cols))),
      t(stats::setNames(pmax(R$spread, cs2, na.rm = TRUE), paste0("spread.", cols))),
      check.names = FALSE, stringsAsFactors = FALSE)
    for (j in seq_along(h$hist)) {
      i <- h$hist[j]
      v <- pass2[[d]][[j]]
      if (is.na(v$kind)) next
      if (v$kind == "attenuated") att[i] <- TRUE else outlier[i] <- TRUE
      add(i, v$note)
    }
  }
  for (i in which(applied)) {
    if (length(bounds[[i]])) {
      add(i, paste0("beyond omconvert's bounds (plausible_bounds()): ",
                    paste(bounds[[i]], collapse = ", ")))
    }
    if (nzchar(stuck[i])) add(i, stuck[i])
    if (nzchar(hot[i])) add(i, hot[i])
  }
  flag[outlier] <- "device_outlier"
  flag[applied & nzchar(stuck)] <- "temperature_stuck"
  flag[applied & nzchar(hot)] <- "temperature_implausible"
  flag[applied & lengths(bounds) > 0] <- "out_of_bounds"
  flag[att] <- "attenuated"
  tab$plausibility <- flag
  tab$plausibility_note <- note
  devs <- if (length(devices)) do.call(rbind, devices) else NULL
  list(tab = tab, devices = devs)
}

# How far a recording's coefficients `co` lie from the reference `ref`
# in the units of their practical minimum (plausible_bounds()'s
# `practical_min`): list(size, min, text), one element per coefficient.
# Scales are compared relative to the reference (a fraction), the others
# as differences.
practical_change <- function(co, ref) {
  b <- plausible_bounds()
  nm <- names(co)
  group <- coefficient_group(nm)
  rel <- group == "scale"
  size <- ifelse(rel, abs(co / ref - 1), abs(co - ref))
  d <- ifelse(rel, co / ref - 1, co - ref)
  text <- ifelse(group == "scale", sprintf("%+.2f %%", 100 * d),
          ifelse(group == "offset", sprintf("%+.1f mg", 1000 * d),
          ifelse(group == "temperature_offset",
                 sprintf("%+.2f mg per degree C", 1000 * d),
                 sprintf("%+.4f", d))))
  list(size = stats::setNames(size, nm),
       min = b$practical_min[match(group, b$coefficient)], text = text)
}

# The coefficient group (a row of plausible_bounds()) of cohort table names.
coefficient_group <- function(nm) {
  ifelse(startsWith(nm, "scale."), "scale",
  ifelse(startsWith(nm, "cross."), "cross",
  ifelse(startsWith(nm, "offset."), "offset", "temperature_offset")))
}

# A stuck temperature sensor (see ?plausible_bounds, attribute history):
# for each row of a cohort table, the note that flags it, or "". Reads the
# column `temperature_flat` (TRUE: the recording has a temperature that does
# not vary; absent or NA: not known) and `hours`.
temperature_stuck_notes <- function(tab, applied, pooled, key) {
  n <- nrow(tab)
  out <- rep("", n)
  if (!"temperature_flat" %in% names(tab)) return(out)
  flat <- tab$temperature_flat %in% TRUE
  varies <- tab$temperature_flat %in% FALSE
  hours <- if ("hours" %in% names(tab)) tab$hours else rep(NA_real_, n)
  for (i in which(applied & flat & !pooled)) {
    others <- which(key == key[i] & applied & !pooled & varies)
    others <- setdiff(others, i)
    long <- isTRUE(hours[i] >= history_rules$temperature_stuck_hours)
    if (!long && !length(others)) next
    out[i] <- temperature_stuck_note(hours[i], NA_real_, if (length(others)) {
      sprintf("while %d other recording(s) of device %s vary", length(others),
              tab$serial[i])
    })
  }
  out
}

# The note of a stuck temperature sensor.
temperature_stuck_note <- function(hours, value, history = NULL) {
  paste0("temperature stuck: the temperature ",
         if (is.finite(value)) sprintf("reads %.2f degrees C", value) else
           "does not vary",
         sprintf(" (sd < %g degrees C)", history_rules$temperature_flat_sd),
         if (is.finite(hours)) sprintf(" over %.1f h", hours),
         if (!is.null(history)) paste0(" ", history),
         "; a working sensor follows the skin and the room by degrees. The ",
         "calibration has no temperature term")
}
