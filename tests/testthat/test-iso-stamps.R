# M's time stamps (metashort and metalong, "%Y-%m-%dT%H:%M:%S%z" in
# desiredtz) made in C++ (gc_iso_stamps(), through iso_stamps()) must be
# R's strftime() text of the same times, character for character, or left
# to R where the fast path is not certain.

r_stamps <- function(tt, tz) {
  strftime(as.POSIXlt(tt, origin = "1970-01-01", tz = tz), format = "%Y-%m-%dT%H:%M:%S%z")
}

test_that("time stamps are strftime()'s in every kind of zone, across its changes", {
  zones <- c("UTC", "GMT", "", "Europe/Amsterdam", "Europe/London", "America/New_York",
             "America/St_Johns",      # -03:30, daylight saving -02:30
             "Asia/Kolkata",          # +05:30
             "Asia/Kathmandu",        # +05:45
             "Australia/Lord_Howe",   # a half-hour daylight saving change
             "Pacific/Chatham",       # +12:45 / +13:45
             "Pacific/Kiritimati",    # +14
             "Etc/GMT+12", "Africa/Casablanca")
  # 5 s steps over two days around each of 2024's spring and autumn
  # changes in Europe and America, and a year in 15 min steps
  tt <- c(seq(1711846800 - 86400, by = 5, length.out = 2 * 17280),
          seq(1730595600 - 86400, by = 5, length.out = 2 * 17280),
          seq(1704067200, by = 900, length.out = 366 * 96))
  for (tz in zones) {
    expect_identical(gravcal:::iso_stamps(tt, tz), r_stamps(tt, tz), info = tz)
  }
  # the fast path was taken (a stamp R would write with an offset)
  lt <- unclass(as.POSIXlt(tt[1:3], origin = "1970-01-01", tz = "Asia/Kathmandu"))
  expect_identical(gravcal:::gc_iso_stamps(lt$year, lt$mon, lt$mday, lt$hour, lt$min, lt$sec,
                                           lt$isdst, lt$gmtoff),
                   r_stamps(tt[1:3], "Asia/Kathmandu"))
})

test_that("where the fast path is not certain, R formats: years, fractions, offsets", {
  # a local mean time of 1172 s before 1900 (R writes "+0019"), a year
  # of three digits and one of five, seconds not whole, a leap of the
  # offset by more than a day: all as R writes them
  tt <- c(-2.5e9, -5e10, 3e11, 1.7e9 + 0.5, 1.7e9)
  for (tz in c("Europe/Amsterdam", "UTC", "America/New_York")) {
    for (i in seq_along(tt)) {
      expect_identical(gravcal:::iso_stamps(tt[i], tz), r_stamps(tt[i], tz),
                       info = paste(tz, tt[i]))
    }
  }
  lt <- unclass(as.POSIXlt(c(1.7e9, -5e10), origin = "1970-01-01", tz = "Europe/Amsterdam"))
  expect_null(gravcal:::gc_iso_stamps(lt$year, lt$mon, lt$mday, lt$hour, lt$min, lt$sec,
                                      lt$isdst, lt$gmtoff))
  lt <- unclass(as.POSIXlt(1.7e9 + 0.5, origin = "1970-01-01", tz = "Europe/Amsterdam"))
  expect_null(gravcal:::gc_iso_stamps(lt$year, lt$mon, lt$mday, lt$hour, lt$min, lt$sec,
                                      lt$isdst, lt$gmtoff))
  # isdst unknown: the C library writes no offset
  expect_null(gravcal:::gc_iso_stamps(124L, 0L, 1L, 0L, 0L, 0, -1L, 3600L))
  # an offset that is not given as R's integers: R formats
  expect_null(gravcal:::gc_iso_stamps(124L, 0L, 1L, 0L, 0L, 0, 0L, 3600))
  # the sign of an offset of less than a minute, and minutes dropped
  # toward zero: R's formatter on the same fields is the reference
  lt <- as.POSIXlt(1704067200 + c(0, 0, 59), origin = "1970-01-01", tz = "Europe/Amsterdam")
  lt$gmtoff <- c(-30L, 1172L, -19859L)
  u <- unclass(lt)
  expect_identical(gravcal:::gc_iso_stamps(u$year, u$mon, u$mday, u$hour, u$min, u$sec, u$isdst,
                                           u$gmtoff),
                   strftime(lt, format = "%Y-%m-%dT%H:%M:%S%z"))
  expect_error(gravcal:::gc_iso_stamps(124L, 0L, 1L, 0L, 0L, c(0, 0), 0L, 0L), "differ in length")
})
