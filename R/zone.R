# GGIR's zone for a .cwa file's times (configtz, else desiredtz; "" is the
# session's zone). GGIRread's readAxivity converts each block's calendar
# time (the device's clock, year, month, day, hour, minute, second) with
# as.POSIXct() in that zone, once a minute, and adds the seconds between
# blocks of the same minute. gravcal's decoder reads the calendar as UTC and
# subtracts the offset R gives that calendar minute (decode_cwa.hpp's
# ZoneTable), worked out here in the R the package runs in, so that the
# decoder follows that R's zone rules, however its platform resolves them.
#
# Where the offset changes (daylight saving), a calendar time can exist
# twice (clocks go back) or not at all (clocks go forward). What
# as.POSIXct() gives such a time depends on R's conversion before it (the C
# library keeps its last offset as the guess for the next). In readAxivity
# the conversion before a minute is the minute before it, so the table is
# made by converting the minutes around each change in order. The minutes
# whose offset would differ had the conversions come the other way (in
# reverse order) are marked: where one of them starts or ends a block of
# GGIR's reading, readAxivity's conversion before it is not the minute
# before, and g.calibrate() refuses rather than guess.

# The table for `tz` over the years a .cwa calendar can hold (2000 to
# 2063): list(at, off, amb_lo, amb_hi) in seconds (calendar read as UTC),
# or NULL when the offset never changes there (zone_options() gives the
# decoder that one offset). Cached for the session, by zone.
zone_table <- function(tz) {
  # "": the session's zone, which TZ names when set (else the system's,
  # fixed for the session)
  key <- if (nzchar(tz)) tz else paste0("|", Sys.getenv("TZ", unset = "(unset)"))
  if (is.null(build_state$zones)) build_state$zones <- list()
  if (!is.null(build_state$zones[[key]])) return(build_state$zones[[key]]$table)
  table <- zone_table_make(tz)
  build_state$zones[[key]] <- list(table = table)
  table
}

# By how much as.POSIXct() of each calendar time `at` (seconds, read as
# UTC; whole seconds: the text has no fraction) in the zone `tz` moves it,
# converted in the order given: the zone's UTC offset at that clock time,
# as R gives it (NA where R cannot convert).
civil_offset <- function(at, tz) {
  fmt <- "%Y-%m-%d %H:%M:%S"
  at - as.numeric(as.POSIXct(format(.POSIXct(at, tz = "UTC"), fmt), format = fmt, tz = tz))
}

zone_table_make <- function(tz, fast = TRUE) {
  off_of <- function(at) civil_offset(at, tz)
  changes <- function(v) which(v[-1] != v[-length(v)])
  lo <- as.numeric(as.POSIXct("2000-01-01", tz = "UTC"))
  hi <- as.numeric(as.POSIXct("2064-01-01", tz = "UTC"))
  days <- seq(lo, hi, by = 86400)
  # a zone whose UTC offset is one value at every day's start (the
  # instants' offsets, as.POSIXlt()'s gmtoff: no conversion of calendar
  # times, which take 0.1-0.2 s here) has no table; otherwise (or where R
  # gives no gmtoff) the calendar times are converted
  if (fast) {
    g <- as.POSIXlt(.POSIXct(days, tz = "UTC"), tz = tz)$gmtoff
    if (is.numeric(g) && length(g) == length(days) && !anyNA(g) && all(g == g[1])) return(NULL)
  }
  d_off <- off_of(days)
  if (anyNA(d_off)) {
    abort("`desiredtz`/`configtz` = \"", tz, "\": R cannot convert calendar times in this zone.")
  }
  if (!length(changes(d_off))) return(NULL)
  # each change found to the hour, then the minutes three hours either side
  # of it converted in order (forwards: the table; backwards: the marks)
  starts <- numeric(0)
  for (i in changes(d_off)) {
    h <- days[i] + 3600 * (0:24)
    starts <- c(starts, h[changes(off_of(h))])
  }
  at <- lo
  off <- d_off[1]
  amb <- matrix(numeric(0), ncol = 2)
  for (h in sort(unique(starts))) {
    m <- h + 60 * (-180:240)
    fwd <- off_of(m)
    bwd <- rev(off_of(rev(m)))
    if (anyNA(fwd) || anyNA(bwd)) {
      abort("`desiredtz`/`configtz` = \"", tz, "\": R cannot convert some calendar times ",
            "in this zone (near ", format(.POSIXct(h, tz = "UTC")), ").")
    }
    k <- changes(fwd)
    at <- c(at, m[k + 1])
    off <- c(off, fwd[k + 1])
    d <- which(fwd != bwd)
    if (length(d)) amb <- rbind(amb, cbind(m[d], m[d] + 60))
  }
  # steps in order, each a change of offset
  o <- order(at)
  at <- at[o]
  off <- off[o]
  keep <- c(TRUE, off[-1] != off[-length(off)])
  # marked minutes as spans, each run of minutes one span
  lo_span <- hi_span <- numeric(0)
  if (nrow(amb)) {
    amb <- unique(amb[order(amb[, 1]), , drop = FALSE])
    run <- cumsum(c(TRUE, amb[-1, 1] > amb[-nrow(amb), 2]))
    lo_span <- as.numeric(tapply(amb[, 1], run, min))
    hi_span <- as.numeric(tapply(amb[, 2], run, max))
  }
  list(at = at[keep], off = off[keep], amb_lo = lo_span, amb_hi = hi_span)
}

# The decoder options for the table of `tz`; a fixed offset is a table of
# one step (the times move by it: GGIR's time stamps in g.getmeta(), where
# g.calibrate()'s result would not change).
zone_options <- function(tz) {
  z <- zone_table(tz)
  if (is.null(z)) {
    lo <- as.numeric(as.POSIXct("2000-01-01", tz = "UTC"))
    return(list(tz_n = 1, tz_amb_n = 0, tz_at_0 = lo, tz_off_0 = civil_offset(lo, tz)))
  }
  n <- length(z$at)
  na <- length(z$amb_lo)
  if (n > 4096 || na > 4096) {
    abort("`desiredtz`/`configtz` = \"", tz, "\" changes its UTC offset more often than ",
          "gravcal's .cwa decoder holds (4096 changes).")
  }
  opts <- c(list(tz_n = n, tz_amb_n = na),
            stats::setNames(as.list(z$at), paste0("tz_at_", seq_len(n) - 1L)),
            stats::setNames(as.list(z$off), paste0("tz_off_", seq_len(n) - 1L)))
  if (na) {
    opts <- c(opts, stats::setNames(as.list(z$amb_lo), paste0("tz_amb_lo_", seq_len(na) - 1L)),
              stats::setNames(as.list(z$amb_hi), paste0("tz_amb_hi_", seq_len(na) - 1L)))
  }
  opts
}

# lubridate::force_tz()'s reading of clock times in the zone `tz` (GGIR's
# ActivPAL days, read.myacc.csv()), as decoder options for the calendar
# seconds [lo, hi] (read as UTC): the clock time less the zone's offset at
# that clock time; a clock time that exists twice (clocks go back) takes
# the later offset, one that does not exist (clocks go forward) is NA
# (force_tz()'s roll_dst = c("NA", "post"), lubridate 1.9.0 and later).
# Worked out from the UTC offsets R gives each instant in the zone: at each
# change from o1 to o2 (at the instant T), the clock times [T + o1, T + o2)
# do not exist where o2 > o1, and from T + o2 on o2 holds. Options tz_n,
# tz_at_i, tz_off_i, tz_na_n, tz_na_lo_k, tz_na_hi_k (decode.hpp
# ZoneTable), or NULL when the offset does not change over [lo, hi].
zone_force_options <- function(tz, lo, hi) {
  gmtoff <- function(u) as.POSIXlt(.POSIXct(u, tz = "UTC"), tz = tz)$gmtoff
  # the instants half an hour apart, a day either side (offsets change at
  # most once in half an hour in every zone R knows)
  u <- seq(floor(lo) - 2 * 86400, ceiling(hi) + 2 * 86400, by = 1800)
  g <- gmtoff(u)
  if (anyNA(g)) {
    abort("`desiredtz` = \"", tz, "\": R gives no UTC offset in this zone for some of the ",
          "recording's times.")
  }
  k <- which(g[-1] != g[-length(g)])
  if (!length(k)) return(NULL)
  at <- u[1] + g[1] - 1e9  # before every clock time of the recording
  off <- g[1]
  na_lo <- na_hi <- numeric(0)
  for (i in k) {
    # the instant of the change, to the second: the first with the new offset
    a <- u[i]
    b <- u[i + 1]
    while (b - a > 1) {
      m <- floor((a + b) / 2)
      if (gmtoff(m) == g[i]) a <- m else b <- m
    }
    o1 <- g[i]
    o2 <- g[i + 1]
    if (o2 > o1) {
      na_lo <- c(na_lo, b + o1)
      na_hi <- c(na_hi, b + o2)
    }
    at <- c(at, b + o2)
    off <- c(off, o2)
  }
  named <- function(v, nm) {
    if (length(v)) stats::setNames(as.list(as.numeric(v)), paste0(nm, seq_along(v) - 1L))
  }
  c(list(tz_n = length(at), tz_amb_n = 0, tz_na_n = length(na_lo)), named(at, "tz_at_"),
    named(off, "tz_off_"), named(na_lo, "tz_na_lo_"), named(na_hi, "tz_na_hi_"))
}

# The offset zone_force_options()'s table `o` gives clock times `v`
# (seconds read as UTC): NA where they do not exist.
zone_force_offset <- function(v, o) {
  at <- unlist(o[paste0("tz_at_", seq_len(o$tz_n) - 1L)])
  off <- unlist(o[paste0("tz_off_", seq_len(o$tz_n) - 1L)])
  r <- off[pmax(findInterval(v, at), 1L)]
  for (j in seq_len(o$tz_na_n)) {
    lo <- o[[paste0("tz_na_lo_", j - 1L)]]
    hi <- o[[paste0("tz_na_hi_", j - 1L)]]
    r[v >= lo & v < hi] <- NA_real_
  }
  r
}
