# The native GENEActiv .bin decoder (decode_geneactiv.hpp) against the
# reference reader GGIRread::readGENEActiv 1.2.0 (called as GGIR calls it:
# desiredtz = "", configtz = ""), on GGIRread's real test file and on files
# written by write_geneactiv_bin() from the format description.

# every column readGENEActiv gives (light: GGIRread 1.2.0's lux, see
# decode_geneactiv.hpp) is compared
cols <- c("x", "y", "z", "temperature", "time", "light")

ga_real <- function() {
  skip_if_not_installed("GGIRread")
  f <- system.file("testfiles", "GENEActiv_testfile.bin", package = "GGIRread")
  if (!nzchar(f)) skip("GGIRread has no GENEActiv_testfile.bin")
  f
}

ga_ref <- function(file, start = 0, end = 0) {
  out <- NULL
  # the reference prints "data error" for a page cut short; quiet here
  utils::capture.output(type = "message", out <- GGIRread::readGENEActiv(
    file, start = start, end = end, desiredtz = "", configtz = "")$data.out)
  out
}

# resample = 0: the decoder's output as GGIRread::readGENEActiv gives it,
# before GGIR's own resampling of rates that are not whole (see
# test-ggir.R for that)
ga_read <- function(file, ...) {
  opts <- utils::modifyList(list(resample = 0), list(...))
  gravcal:::native_read_all(file, "geneactiv", options = opts)
}

# A smooth recording with temperature; n samples at sf.
ga_sim <- function(n, sf, seed = 1) {
  set.seed(seed)
  t <- seq_len(n) / sf
  x <- 0.9 * sin(t / 7)
  y <- 0.4 * cos(t / 5)
  data.frame(x = x, y = y, z = sqrt(1 - x^2 - y^2) + stats::rnorm(n, 0, 0.02),
             temperature = 25 + 3 * sin(t / 100))
}

# Light over the whole 10-bit range, with status bits: sample i's light and
# status.
ga_light <- function(n) (seq_len(n) * 37 + seq_len(n) %/% 300) %% 1024
ga_status <- function(n) seq_len(n) %% 4

ga_write <- function(pages, sf = 100, eol = "\r\n", ...) {
  f <- tempfile(fileext = ".bin")
  n <- pages * 300
  gravcal:::write_geneactiv_bin(ga_sim(n, sf), f, sf = sf, eol = eol,
                                gain = c(25875, 25734, 25538),
                                offset = c(439, -662, -3056),
                                light = ga_light(n), status = ga_status(n), ...)
  f
}

# Lines of a small file, and back (damage is done line by line).
ga_lines <- function(f, eol = "\r\n") {
  strsplit(rawToChar(readBin(f, "raw", file.size(f))), eol, fixed = TRUE)[[1]]
}
ga_put <- function(lines, eol = "\r\n", tail = eol) {
  f <- tempfile(fileext = ".bin")
  writeBin(charToRaw(paste0(paste(lines, collapse = eol), tail)), f)
  f
}
# Line number of line k (1 = "Recorded Data", 10 = hex) of page p.
ga_line <- function(lines, p, k) which(lines == "Recorded Data")[p] + k - 1L

# Rows of page p (1-based) dropped.
drop_pages <- function(d, p) {
  rows <- unlist(lapply(p, function(q) (q - 1) * 300 + seq_len(300)))
  out <- d[-rows, ]
  rownames(out) <- NULL
  out
}

expect_same <- function(a, b, what = cols) {
  for (v in what) expect_identical(a[[v]], b[[v]], label = v)
}

# The columns of `what` in which a and b differ (many cases, one
# expectation: testthat's cost per expectation is the loops' cost).
# `undefined`: a's NaN times are not compared (the decoder's where the
# reference's are not defined).
differ <- function(a, b, what = cols, undefined = FALSE) {
  if (undefined) {
    und <- is.nan(a$time)
    if (length(und) == length(b$time)) b$time[und] <- NaN
  }
  if (!identical(nrow(a), nrow(b))) return("rows")
  what[!vapply(what, function(v) identical(a[[v]], b[[v]]), TRUE)]
}

# As expect_blocks(), the blocks of B pages that differ ("from page s: x").
blocks_differ <- function(file, B, capacity = B * 700) {
  h <- gravcal:::native_open(file, "geneactiv", list(resample = 0))
  on.exit(gravcal:::gc_decoder_close(h$ptr))
  out <- character(0)
  s <- 1
  repeat {
    ref <- ga_ref(file, s, s + B - 1)
    b <- gravcal:::native_block(h, B, capacity, TRUE, TRUE)
    got <- as.data.frame(lapply(b$cols[cols], function(v) v[seq_len(b$to)]))
    bad <- differ(got, ref, undefined = TRUE)
    if (length(bad)) out <- c(out, paste0("from page ", s, ": ", paste(bad, collapse = ", ")))
    if (nrow(ref) == 0 && b$to == 0) break
    s <- s + B
  }
  out
}

# Reads `file` in blocks of B pages as GGIR does (readGENEActiv(start = s,
# end = s + B - 1)) and natively (read(out, B)); expects identical blocks.
# A time the decoder leaves NaN where the reference's is not defined (a
# page read at 0 Hz: the platform's conversion of NaN to an integer) is
# not compared.
expect_blocks <- function(file, B, capacity = B * 300) {
  h <- gravcal:::native_open(file, "geneactiv", list(resample = 0))
  on.exit(gravcal:::gc_decoder_close(h$ptr))
  s <- 1
  repeat {
    ref <- ga_ref(file, s, s + B - 1)
    b <- gravcal:::native_block(h, B, capacity, TRUE, TRUE)
    got <- lapply(b$cols[cols], function(v) v[seq_len(b$to)])
    expect_identical(as.integer(b$to), nrow(ref))
    und <- is.nan(got$time)
    if (any(und) && length(und) == nrow(ref)) {
      expect_gt(gravcal:::native_report(h)$counters[["ggir_time_undefined"]], 0)
      ref$time[und] <- NaN
    }
    for (v in cols) expect_identical(got[[v]], ref[[v]], label = paste(v, "from page", s))
    if (nrow(ref) == 0) break
    s <- s + B
  }
}

test_that("the real test file gives readGENEActiv's samples bit for bit", {
  f <- ga_real()
  d <- ga_read(f)
  ref <- ga_ref(f)
  # 16 whole pages and 231 samples of a 17th cut short (the file is the
  # first 64 KiB of a recording); the reference gives 5031 too
  expect_identical(nrow(d), 5031L)
  expect_same(d, ref)
  info <- attr(d, "info")
  expect_identical(info$serial, "012967")
  expect_identical(info$device, "GENEActiv 1.1")
  expect_identical(info$sf, 85.7)
  expect_identical(info$range_g, 8)
  expect_identical(info$start_time, ref$time[1])
  rep <- attr(d, "report")
  expect_true(rep$truncated)
  expect_identical(rep$counters[["truncated_page"]], 1)
  expect_identical(c(rep$units, rep$skipped, rep$gaps), c(17, 0, 0))
  # GGIR's blocks: round((14512 * (sf / 50)) * 0.5) pages; and small ones
  expect_blocks(f, round((14512 * (85.7 / 50)) * 0.5))
  expect_blocks(f, 3)
  expect_blocks(f, 1)
})

test_that("time stamps follow the session's time zone as the reference's do", {
  f <- ga_real()
  old_tz <- Sys.getenv("TZ", unset = NA)
  Sys.setenv(TZ = "America/New_York")
  on.exit(if (is.na(old_tz)) Sys.unsetenv("TZ") else Sys.setenv(TZ = old_tz))
  d <- ga_read(f)
  ref <- ga_ref(f)
  expect_same(d, ref, "time")
  # 10:12:54.5 New York summer time is 14:12:54.5 UTC
  expect_identical(d$time[1], as.numeric(as.POSIXct("2013-05-30 14:12:54", tz = "UTC")) + 0.5)
  expect_blocks(f, 4)
})

test_that("synthetic files (CRLF and LF, 100 and 85.7 Hz) match the reference", {
  skip_if_not_installed("GGIRread")
  for (eol in c("\r\n", "\n")) {
    for (sf in c(100, 85.7)) {
      f <- ga_write(12, sf = sf, eol = eol, start = "2024-03-31 01:59:58")
      d <- ga_read(f)
      expect_identical(nrow(d), 3600L)
      expect_same(d, ga_ref(f))
      expect_blocks(f, 5)
      expect_identical(attr(d, "report")$counters, stats::setNames(numeric(0), character(0)))
    }
  }
  # a block smaller than the buffer, a buffer smaller than a page: the same
  f <- ga_write(7)
  expect_blocks(f, 2, capacity = 7 * 300)
  a <- ga_read(f)
  expect_same(gravcal:::native_read_all(f, "geneactiv", list(resample = 0), chunk = 77), a)
})

test_that("pages at another rate are timed as the reference times them", {
  skip_if_not_installed("GGIRread")
  f <- ga_write(10, sf = 100, page_sf = rep(c(100, 50), each = 5))
  d <- ga_read(f)
  expect_same(d, ga_ref(f))
  expect_blocks(f, 4)
  rep <- attr(d, "report")
  expect_identical(rep$counters[["rate_changes"]], 1)
  expect_identical(rep$gaps, 0)
  # compat 0: page 6 starts 5 pages of 3 s after page 1, then 1 / 50 s steps
  d0 <- ga_read(f, compat = 0)
  t6 <- as.numeric(as.POSIXct("2024-01-01 00:00:15", tz = "UTC"))
  expect_identical(d0$time[1501:1502], t6 + c(0, 1) / 50)
})

test_that("compat = 0 gives the format's values and page times in UTC", {
  skip_if_not_installed("GGIRread")
  sim <- ga_sim(6 * 300, 100)
  f <- tempfile(fileext = ".bin")
  gain <- c(25875, 25734, 25538)
  off <- c(439, -662, -3056)
  gravcal:::write_geneactiv_bin(sim, f, sf = 100, gain = gain, offset = off,
                                start = "2024-01-01 10:00:00.250",
                                time_zone = "GMT +01:00")
  d0 <- ga_read(f, compat = 0)
  d1 <- ga_read(f)
  # (count * 100 - offset) / gain in double, from the counts written
  cnt <- gravcal:::ga_counts(sim$x, gain[1], off[1])
  cnt <- ifelse(cnt >= 2048, cnt - 4096, cnt)
  expect_identical(d0$x, (cnt * 100 - off[1]) / gain[1])
  expect_false(identical(d0$x, d1$x))
  expect_lt(max(abs(d0$x - d1$x)), 1e-6)  # float rounding only
  temp <- sprintf("%.1f", colMeans(matrix(sim$temperature, 300)))
  expect_identical(d0$temperature, rep(as.numeric(temp), each = 300))
  # 10:00:00.250 at GMT+1 is 09:00:00.250 UTC; then 1 / 100 s per sample
  t0 <- as.numeric(as.POSIXct("2024-01-01 09:00:00", tz = "UTC")) + 0.25
  expect_identical(attr(d0, "info")$start_time, t0)
  expect_identical(d0$time, rep(t0 + 3 * (0:5), each = 300) + (0:299) / 100)
})

test_that("other .bin files and non-files are refused with a clear error", {
  skip_if_not_installed("GGIRread")
  tf <- function(name) system.file("testfiles", name, package = "GGIRread")
  expect_error(ga_read(tf("genea_testfile.bin")), "looks like an older Genea file")
  for (m in c("mtx_12.5Hz_acc.BIN", "mtx_corrupted.bin")) {
    expect_error(ga_read(tf(m)), "looks like a Matrix/Parmay file")
  }
  g <- tempfile()
  writeLines(c("time,x,y,z", "1,2,3,4"), g)
  expect_error(ga_read(g), "first line is \"time,x,y,z\"")
  file.create(g)
  expect_error(ga_read(g), "empty file")
  # a header cut before its memory status
  lines <- ga_lines(ga_write(2))
  expect_error(ga_read(ga_put(lines[1:50])), "header truncated at byte")
  bad <- ga_lines(ga_write(2))
  bad[startsWith(bad, "y gain:")] <- "y gain:abc"
  expect_error(ga_read(ga_put(bad)), "bad calibration line \"y gain:\"")
  expect_error(ga_read(tempfile()), "cannot open")
})

# The ways a page gets damaged, on page `p` (5 unless given) of a file's
# lines: list(label, lines after the damage).
ga_damages <- function(lines, p = 5) {
  hex <- lines[ga_line(lines, p, 10)]
  at <- function(i, ch) {
    l <- lines
    substr(l[ga_line(l, p, 10)], i, i) <- ch
    l
  }
  line <- function(k, value) {
    l <- lines
    if (is.null(value)) l[-ga_line(l, p, k)] else {
      l[ga_line(l, p, k)] <- value
      l
    }
  }
  longer <- function(k) line(10, paste0(hex, substr(strrep(hex, 2), 1, k)))
  list(
    # a character that is not a hex digit: at a group's start (the page ends
    # there: its samples before are kept), inside a group (read as far as it
    # goes), in a light group, as a sign or a blank (read on)
    list("G at a sample's start", at(1201, "G")), list("G in x", at(1202, "G")),
    list("G in z's last digit", at(1209, "G")), list("G in light", at(1210, "G")),
    list("G first", at(1, "G")), list("G last", at(3600, "G")),
    list("'-' at a group's start", at(1204, "-")), list("' ' in a group", at(1205, " ")),
    list("'x' after a 0", at(1202, "x")),
    # a line cut short (a digit lost: every group after it shifted), too
    # long (more samples), empty
    list("a digit lost", line(10, substr(hex, 2, 3600))),
    list("cut to 3590", line(10, substr(hex, 1, 3590))),
    list("cut to 1234", line(10, substr(hex, 1, 1234))),
    list("one digit more", longer(1)), list("10 more", longer(10)),
    list("12 more", longer(12)), list("4000 more", longer(4000)),
    list("empty", line(10, "")),
    # page header lines: temperature and rate read as a stream reads them
    list("Temperature:2x.5", line(6, "Temperature:2x.5")),
    list("Temperature:abc", line(6, "Temperature:abc")),
    list("Temperature (no ':')", line(6, "Temperature")),
    list("Measurement Frequency: (no value)", line(9, "Measurement Frequency:")),
    list("Measurement Frequency:50", line(9, "Measurement Frequency:50")),
    list("Measurement Frequency:1x0", line(9, "Measurement Frequency:1x0")),
    list("Page Tine (garbled key)", line(4, "Page Tine:2024-01-01 00:00:12:000")),
    # a line missing or extra: ten lines a page from there on, misaligned
    list("Unassigned: missing", line(5, NULL)),
    list("a line extra", append(lines, "extra", ga_line(lines, p, 5))))
}

test_that("gravcal's own reading (compat 0) skips a damaged page whole and counts it", {
  skip_if_not_installed("GGIRread")
  f <- ga_write(12)
  clean0 <- ga_read(f, compat = 0)
  lines <- ga_lines(f)
  damage <- function(p, k, value) {
    l <- lines
    if (is.null(value)) l <- l[-ga_line(l, p, k)] else l[ga_line(l, p, k)] <- value
    ga_put(l)
  }
  hex5 <- lines[ga_line(lines, 5, 10)]
  cases <- list(
    list(5, 10, substr(hex5, 2, 3600), "bad_hex"),                      # a digit lost
    list(5, 10, paste0(hex5, "0"), "bad_hex"),                          # one too many
    list(5, 10, paste0(substr(hex5, 1, 1234), "G", substr(hex5, 1236, 3600)), "bad_hex"),           # not hex
    list(5, 10, "", "bad_hex"),                                         # empty
    list(3, 5, NULL, "bad_page_header"),                                # "Unassigned:" gone
    list(3, 6, "Temperature:2x.5", "bad_page_header"),                  # garbled value
    list(3, 9, "Measurement Frequency:", "bad_page_header"),            # no value
    list(3, 4, "Page Tine:2024-01-01 00:00:06:000", "bad_page_header")  # garbled key
  )
  for (cs in cases) {
    d <- ga_read(damage(cs[[1]], cs[[2]], cs[[3]]), compat = 0)
    expect_same(d, drop_pages(clean0, cs[[1]]))
    rep <- attr(d, "report")
    expect_identical(rep$counters[[cs[[4]]]], 1, label = cs[[4]])
    expect_identical(c(rep$units, rep$skipped, rep$gaps), c(11, 1, 0))
    expect_false(rep$truncated)
    expect_match(rep$notes[1], paste0("page ", cs[[1]], ", byte "))
  }
  # the same on the real file (NULs in its header: edit bytes): page 3's hex
  # with a non-hex digit
  r <- ga_real()
  rb <- readBin(r, "raw", file.size(r))
  at <- grepRaw("Recorded Data", rb, fixed = TRUE, all = TRUE)
  rb[at[4] - 2 - 3600 + 100] <- charToRaw("Z")
  g <- tempfile(fileext = ".bin")
  writeBin(rb, g)
  d <- ga_read(g, compat = 0)
  expect_same(d, drop_pages(ga_read(r, compat = 0), 3))
  expect_identical(attr(d, "report")$counters[["bad_hex"]], 1)
})

test_that("GGIR's mode reads a damaged page as readGENEActiv reads it, whole and in GGIR's blocks", {
  skip_if_not_installed("GGIRread")
  f <- ga_write(12)
  clean <- ga_read(f)
  bad <- character(0)
  for (eol in c("\r\n", "\n")) {
    lines <- ga_lines(ga_write(12, eol = eol), eol)
    for (cs in ga_damages(lines)) {
      g <- ga_put(cs[[2]], eol)
      d <- ga_read(g)
      lab <- paste0(cs[[1]], " (", nchar(eol), "-byte line ends)")
      bad <- c(bad, paste(lab, differ(d, ga_ref(g))))
      # a block from a damaged page on, up to it, one page: the reference's
      # strings and time count start again with each call
      if (eol == "\r\n") {
        for (B in c(5, 4, 1)) bad <- c(bad, paste(lab, "B", B, blocks_differ(g, B)))
      }
      rep <- attr(d, "report")
      said <- c("damaged_hex", "damaged_page_header", "misaligned_page", "rate_changes")
      if (rep$skipped != 0 || sum(c(rep$counters[said], 0), na.rm = TRUE) == 0) {
        bad <- c(bad, paste(lab, "not said"))
      }
      unlink(g)
    }
  }
  expect_identical(bad[!grepl("\\)( B [0-9]+)? ?$", bad)], character(0))
  lines <- ga_lines(f)
  dm <- stats::setNames(lapply(ga_damages(lines), function(cs) ga_read(ga_put(cs[[2]]))),
                        vapply(ga_damages(lines), `[[`, "", 1))
  # what was kept, and the time count closed up after it: 100 samples of
  # page 5 from a damaged group's start, every one where a group reads as
  # far as it goes; page 6 then starts 1 s after page 5, not 3
  expect_identical(nrow(dm[["G at a sample's start"]]), 3600L - 200L)
  expect_same(dm[["G at a sample's start"]], clean[-(1301:1500), ], c("x", "y", "z", "light"))
  t6 <- dm[["G at a sample's start"]]$time[1301]
  expect_identical(t6 - clean$time[1201], 1)
  expect_identical(nrow(dm[["G in x"]]), 3600L)
  expect_false(identical(dm[["G in x"]]$x[1301], clean$x[1301]))
  expect_same(dm[["G in x"]], clean, c("y", "z", "light", "time"))
  expect_identical(nrow(dm[["G first"]]), 3300L)   # page 5 gives nothing
  expect_identical(nrow(dm[["12 more"]]), 3601L)   # a 301st sample
  expect_identical(nrow(dm[["a digit lost"]]), 3600L)  # its groups shifted
  expect_identical(unique(dm[["Temperature:2x.5"]]$temperature[1201:1500]), 2)
  expect_identical(unique(dm[["Temperature:abc"]]$temperature[1201:1500]), 0)
  # page 4's temperature kept for page 5
  expect_identical(unique(dm[["Temperature (no ':')"]]$temperature[1201:1500]), clean$temperature[1200])
  expect_same(dm[["Temperature (no ':')"]], clean, setdiff(cols, "temperature"))
  expect_same(dm[["Page Tine (garbled key)"]], clean)
  # a line missing: every page after it misaligned, none of them decoded
  expect_identical(nrow(dm[["Unassigned: missing"]]), 1200L)
  expect_identical(attr(dm[["Unassigned: missing"]], "report")$counters[["misaligned_page"]], 7)
  # the real file (85.7 Hz, NULs in its header: bytes edited), page 3 with
  # a non-hex digit; and through GGIR's resampling onto 86 Hz
  r <- ga_real()
  rb <- readBin(r, "raw", file.size(r))
  at <- grepRaw("Recorded Data", rb, fixed = TRUE, all = TRUE)
  rb[at[4] - 2 - 3600 + 100] <- charToRaw("Z")
  g <- tempfile(fileext = ".bin")
  writeBin(rb, g)
  d <- ga_read(g)
  expect_same(d, ga_ref(g))
  # (a y group's second digit: read as far as it goes, the page kept)
  expect_identical(nrow(d), 5031L)
  expect_false(identical(d$y[609], ga_read(r)$y[609]))
  expect_blocks(g, 2)
  expect_identical(attr(d, "report")$counters[["damaged_hex"]], 1)
})

test_that("a page read at 0 Hz: its times left NaN where the reference's are not defined", {
  skip_if_not_installed("GGIRread")
  f <- ga_write(12)
  lines <- ga_lines(f)
  lines[ga_line(lines, 5, 9)] <- "Measurement Frequency:abc"  # reads as 0
  g <- ga_put(lines)
  d <- ga_read(g)
  ref <- ga_ref(g)
  # (the reference converts NaN and infinite times to integers: what it
  # gives is the platform's) every other value the reference's
  expect_same(d, ref, setdiff(cols, "time"))
  expect_identical(d$time[1:1200], ref$time[1:1200])
  expect_true(all(is.nan(d$time[-(1:1200)])))
  rep <- attr(d, "report")
  expect_identical(rep$counters[["ggir_time_undefined"]], 8)
  # in blocks of 4 pages: the second block's times undefined, the third's
  # the reference's
  h <- gravcal:::native_open(g, "geneactiv", list(resample = 0))
  on.exit(gravcal:::gc_decoder_close(h$ptr))
  for (s in c(1, 5, 9)) {
    b <- gravcal:::native_block(h, 4, 1200, TRUE, TRUE)
    ref <- ga_ref(g, s, s + 3)
    if (s == 5) {
      expect_true(all(is.nan(b$cols$time)))
    } else {
      expect_identical(b$cols$time, ref$time)
    }
    expect_identical(b$cols$x, ref$x)
  }
})

test_that("sequence numbers and page times are checked; gaps are reported", {
  skip_if_not_installed("GGIRread")
  f <- ga_write(12)
  clean <- ga_read(f)
  clean0 <- ga_read(f, compat = 0)
  lines <- ga_lines(f)
  # a wrong sequence number: page kept, counted
  l <- lines
  l[ga_line(l, 4, 3)] <- "Sequence Number:99"
  g <- ga_put(l)
  d <- ga_read(g)
  expect_same(d, clean)
  expect_same(d, ga_ref(g))  # the reference does not look at them
  expect_identical(attr(d, "report")$counters[["bad_sequence"]], 1)
  # one page's time an hour off: page kept, timed as predicted
  l <- lines
  l[ga_line(l, 6, 4)] <- "Page Time:2024-01-01 01:00:15:000"
  g <- ga_put(l)
  expect_same(ga_read(g), ga_ref(g))
  for (compat in 1:0) {
    d <- ga_read(g, compat = compat)
    expect_same(d, if (compat) clean else clean0)
    rep <- attr(d, "report")
    expect_identical(rep$counters[["bad_page_time"]], 1)
    expect_identical(rep$gaps, 0)
  }
  # pages 8 and 9 missing (sequence and time jump): a gap of 2 pages of 3 s;
  # compat 1 times as the reference's (which closes the gap up)
  l <- lines[-(ga_line(lines, 8, 1):ga_line(lines, 9, 10))]
  g <- ga_put(l)
  d <- ga_read(g)
  rep <- attr(d, "report")
  expect_identical(c(rep$gaps, rep$gap_seconds, rep$skipped), c(1, 6, 0))
  expect_same(d, ga_ref(g))
  d0 <- ga_read(g, compat = 0)
  expect_same(d0, drop_pages(clean0, 8:9))
  # the clock really moves (two pages agree on the new time): one gap
  l <- lines
  for (p in 6:12) {
    l[ga_line(l, p, 4)] <- paste0("Page Time:", gravcal:::ga_stamp(
      as.numeric(as.POSIXct("2024-01-01", tz = "UTC")) + 600 + (p - 1) * 3))
  }
  rep <- attr(ga_read(ga_put(l)), "report")
  expect_identical(c(rep$gaps, rep$gap_seconds), c(1, 600))
  expect_identical(rep$counters[["bad_page_time"]], 1)
})

test_that("a file cut short keeps every whole sample and says so", {
  skip_if_not_installed("GGIRread")
  f <- ga_write(12)
  clean <- ga_read(f)
  bytes <- readBin(f, "raw", file.size(f))
  starts <- gregexpr("Recorded Data", rawToChar(bytes), fixed = TRUE)[[1]]
  cut <- function(n) {
    g <- tempfile(fileext = ".bin")
    writeBin(bytes[seq_len(n)], g)
    g
  }
  # 1-based position of page 10's first hex digit (its CRLF ends it)
  line10 <- starts[11] - 2 - 3600
  # inside page 10's header lines: the reference gives page 9's samples
  # again as page 10 (std::getline at the end of the input leaves its
  # string as it was), and so does GGIR's mode; gravcal's own drops it
  g <- cut(starts[10] + 180)
  d <- ga_read(g)
  ref <- ga_ref(g)
  expect_same(d, ref)
  expect_identical(ref$x[2701:3000], ref$x[2401:2700])
  expect_true(attr(d, "report")$truncated)
  expect_identical(attr(d, "report")$counters[["truncated_page"]], 1)
  d0 <- ga_read(g, compat = 0)
  expect_same(d0, ga_read(f, compat = 0)[1:2700, ])
  expect_identical(attr(d0, "report")$skipped, 1)
  # inside page 10's hex line after r digits: whole samples kept, and a tail
  # of 10 or 11 digits (x, y, z whole) as the reference keeps it
  # (10 or 11 digits: the light of that sample from its 1 or 2 light digits)
  for (r in c(1200, 1205, 1210, 1211, 3599)) {
    g <- cut(line10 - 1 + r)
    d <- ga_read(g)
    rep <- attr(d, "report")
    expect_true(rep$truncated)
    expect_identical(rep$counters[["truncated_page"]], 1)
    expect_same(d, ga_ref(g))
    expect_identical(nrow(d), as.integer(2700 + r %/% 12 + (r %% 12 >= 10)))
    expect_same(d, clean[seq_len(nrow(d)), ], setdiff(cols, "light"))
    whole <- 2700 + r %/% 12  # a cut sample's light is from its digits
    expect_identical(d$light[seq_len(whole)], clean$light[seq_len(whole)])
  }
  # cut at a page boundary, or before the last CRLF: nothing lost
  expect_identical(nrow(ga_read(cut(starts[11] - 1))), 3000L)
  d <- ga_read(cut(length(bytes) - 2))
  expect_same(d, clean)
  expect_false(attr(d, "report")$truncated)
  # compat 0 keeps whole 12-digit samples only
  d0 <- ga_read(cut(line10 - 1 + 1210), compat = 0)
  expect_identical(nrow(d0), 2700L + 100L)
})

test_that("a file cut anywhere in its last page is read as readGENEActiv reads it", {
  skip_if_not_installed("GGIRread")
  # every byte from the end of page 3 to 30 digits into page 4's hex line:
  # where the cut falls in page 4's header lines, the reference gives page
  # 3's samples again, with what its strings then read as temperature and
  # rate (a cut line's number: "Temperature:2" gives 2, "Sequence
  # Number:3" gives 3 for both; in "Recorded Data", page 3's rate for
  # both), none where page 4 starts a call of its own. A rate of 0 ("Device
  # Status:Rec", a serial number cut to "0"): times not defined (NaN), the
  # rest the reference's
  for (eol in c("\r\n", "\n")) {
    f <- ga_write(4, eol = eol)
    bytes <- readBin(f, "raw", file.size(f))
    starts <- gregexpr("Recorded Data", rawToChar(bytes), fixed = TRUE)[[1]]
    undefined <- 0
    bad <- character(0)
    for (n in (starts[4] - 2):(length(bytes) - 3600 - nchar(eol) + 30)) {
      g <- tempfile(fileext = ".bin")
      writeBin(bytes[seq_len(n)], g)
      d <- ga_read(g)
      und <- is.nan(d$time)
      if (any(und)) {
        undefined <- undefined + 1
        if (!identical(which(und), 901:1200) ||
            !isTRUE(attr(d, "report")$counters[["ggir_time_undefined"]] > 0)) {
          bad <- c(bad, paste("undefined times not as said, cut at", n))
        }
      }
      cut <- paste0("cut at byte ", n, ": ")
      bad <- c(bad, paste0(cut, differ(d, ga_ref(g), undefined = TRUE)))
      if (attr(d, "report")$skipped != 0) bad <- c(bad, paste0(cut, "skipped"))
      # GGIR's blocks: the last page alone, and with the page before
      if (eol == "\r\n" && n %% 4 == 0) {
        for (B in 1:2) bad <- c(bad, paste0(cut, "B ", B, " ", blocks_differ(g, B)))
      }
      unlink(g)
    }
    expect_identical(bad[!grepl(": (B [0-9] )?$", bad)], character(0))
    expect_gt(undefined, 10)
  }
})

test_that("trailing garbage and stray lines are skipped and counted", {
  skip_if_not_installed("GGIRread")
  f <- ga_write(4)
  clean <- ga_read(f)
  g <- tempfile(fileext = ".bin")
  file.copy(f, g)
  con <- file(g, "ab")
  writeBin(c(charToRaw("garbage\r\n"), as.raw(c(1, 2, 0, 255, 10)),
             charToRaw(strrep("F", 20000))), con)
  close(con)
  d <- ga_read(g, compat = 0)
  expect_same(d, ga_read(f, compat = 0))
  rep <- attr(d, "report")
  expect_identical(rep$counters[["stray_lines"]], 3)
  expect_identical(rep$skipped, 0)
  # GGIR's mode: the reference takes the garbage for a page, whose hex line
  # it never reaches (the input ends in its third line): page 4 again. The
  # 20000-character line is longer than the decoder keeps: its value (had
  # it a ':' further on) is not known, and that is counted
  # (readGENEActiv with end = 0 stops at the header's page count; GGIR
  # gives an end)
  d <- ga_read(g)
  expect_same(d, ga_ref(g, 1, 100))
  expect_identical(nrow(d), 1500L)
  expect_identical(attr(d, "report")$counters[["ggir_not_reproduced"]], 1)
  expect_same(d[1:1200, ], clean)
})

# A block of whole pages whose last page does not fit the glue's fixed
# 65,536-sample buffer: 219 pages are 65,700 samples, so the buffer fills
# 164 samples into the 219th. Every sample of the block's pages must come
# with the block (before the fix the block ended where the buffer filled,
# and in GGIR's procedure a block short of its pages ends the recording:
# on a 28-day .bin the fit then used 38 of 56 blocks).
test_that("a block gives every sample of its pages when the buffer fills inside the last", {
  f <- tempfile(fileext = ".bin")
  on.exit(unlink(f))
  gravcal:::write_geneactiv_bin(ga_sim(700 * 300, 100), f, sf = 100)
  for (compat in 0:1) {
    h <- gravcal:::native_open(f, "geneactiv", list(compat = compat))
    got <- pump_windows(gravcal:::gc_source_decoder(h$ptr), 1000, compat == 1,
                        rule = 0L, par = c(0.05, 7), block_units = 219)$blocks
    gravcal:::gc_decoder_close(h$ptr)
    got <- matrix(got, ncol = 2, byrow = TRUE)
    expect_identical(got[, 1], c(219, 219, 219, 43))
    expect_identical(got[, 2], got[, 1] * 300)
    # GGIR's blocks: the block rules' rows are the block's pages' samples
    h <- gravcal:::native_open(f, "geneactiv", list(compat = compat))
    res <- gravcal:::gc_pump(gravcal:::gc_source_decoder(h$ptr), "blocks",
                             list(sf = 100, compat = compat, temperature = 1,
                                  per_hour = 360000, temp_min_sd = 0.1,
                                  par = c(0.013, 2), block_units = 219))
    gravcal:::gc_decoder_close(h$ptr)
    expect_identical(vapply(res, `[[`, 0, "rows"), c(219, 219, 219, 43) * 300)
  }
})

test_that("light is readGENEActiv's: the hex digits over 4, times Lux / Volts", {
  # the real file (GENEActiv 1.1, Lux:800, Volts:300): from its bytes, page
  # 1's light is each sample's last 3 hex digits, over 4 (integer), times
  # 800 / 300
  f <- ga_real()
  d <- ga_read(f)
  hex <- suppressWarnings(readLines(f, 69))[69]
  l12 <- strtoi(substring(hex, seq(10, 3600, 12), seq(12, 3600, 12)), 16L)
  expect_identical(d$light[1:300], (l12 %/% 4) * (800 / 300))
  expect_gt(length(unique(d$light)), 10)
  expect_true(attr(d, "info")$light)
  # synthetic: every 10-bit value and status bits; a model other than 1.1
  # maps the value as GGIRread does; Lux and Volts as the header gives them,
  # NA (every light NA) where a line is missing; compared with readGENEActiv
  # as GGIR calls it, whole and in blocks inside the file
  n <- 12 * 300
  l <- ga_light(n)
  map <- ifelse(l < 256, l, ifelse(l < 512, (l - 128) * 2,
                                   ifelse(l < 768, (l - 320) * 4, (l - 656) * 16)))
  headers <- list(
    list(model = "1.1", lux_line = "Lux:800", volts_line = "Volts:300",
         want = l * (800 / 300)),
    list(model = "1.2", lux_line = "Lux:800", volts_line = "Volts:300",
         want = map * (800 / 300)),
    list(model = " 1.1   ", lux_line = "Lux: 1000 ", volts_line = "Volts:250",
         want = l * (1000 / 250)),
    list(model = "1.1", lux_line = "Lx:800", volts_line = "Volts:300",
         want = rep(NA_real_, n)),
    list(model = "1.1", lux_line = "Lux:800", volts_line = "Volts:0",
         want = l * (800 / 0)))
  for (hd in headers) {
    g <- ga_write(12, model = hd$model, lux_line = hd$lux_line, volts_line = hd$volts_line)
    lab <- paste(hd$model, hd$lux_line, hd$volts_line)
    d <- ga_read(g)
    expect_identical(d$light, hd$want, label = lab)
    expect_same(d, ga_ref(g))
    expect_blocks(g, 5)
    expect_identical(ga_read(g, compat = 0)$light, hd$want, label = lab)
    # the decoder's own reading of the header (without R's options) agrees
    h <- gravcal:::gc_decoder_open(g, "geneactiv", list(resample = 0))
    own <- gravcal:::native_samples(h)
    gravcal:::gc_decoder_close(h$ptr)
    expect_identical(own$light, hd$want, label = lab)
  }
  # light = FALSE: no column, nothing else changes
  g <- ga_write(3)
  a <- gravcal:::native_read_all(g, "geneactiv", list(resample = 0))
  b <- gravcal:::native_read_all(g, "geneactiv", list(resample = 0), light = FALSE)
  expect_identical(names(b), cols[1:5])
  expect_same(b, a, cols[1:5])
  # asked only from the second block on: the page already read ahead (the
  # second block's first) has no light (NaN), the rest has
  h <- gravcal:::native_open(g, "geneactiv", list(resample = 0))
  b1 <- gravcal:::native_block(h, 1, 300, TRUE, TRUE, light = FALSE)
  b2 <- gravcal:::native_block(h, 2, 600, TRUE, TRUE, light = TRUE)
  gravcal:::gc_decoder_close(h$ptr)
  expect_null(b1$cols$light)
  expect_true(all(is.nan(b2$cols$light[1:300])))
  expect_identical(b2$cols$light[301:600], a$light[601:900])
  expect_identical(b2$cols$x, a$x[301:900])
})

# GGIR's blocks of a GENEActiv file through g.readaccfile (readGENEActiv,
# then, at a rate that is not whole, GGIRread::resample() of every column,
# light too) and the compatible decoder (resampling on), B pages a block.
expect_ggir_blocks <- function(f, B) {
  pr <- GGIR::load_params()
  I <- suppressWarnings(GGIR::g.inspectfile(f, params_rawdata = pr$params_rawdata))
  fq <- list(filetooshort = FALSE, filecorrupt = FALSE,
             filedoesnotholdday = FALSE, NFilePagesSkipped = 0)
  h <- gravcal:::native_open(f, "geneactiv", list(compat = 1))
  on.exit(gravcal:::gc_decoder_close(h$ptr))
  expect_identical(h$info$sf, I$sf)
  prev <- c()
  k <- 1
  repeat {
    g <- NULL
    utils::capture.output(type = "message", g <- GGIR:::g.readaccfile(
      f, blocksize = B, blocknumber = k, filequality = fq, ws = 1,
      PreviousEndPage = prev, inspectfileobject = I,
      params_rawdata = pr$params_rawdata, params_general = pr$params_general))
    b <- gravcal:::native_block(h, B, B * 600, TRUE, TRUE)
    n <- b$to
    ref <- g$P$data
    if (is.null(ref) || !nrow(ref)) break
    expect_identical(as.integer(n), nrow(ref), label = paste("rows of block", k))
    for (v in cols) {
      expect_identical(b$cols[[v]][seq_len(n)], ref[[v]], label = paste(v, "block", k, "B", B))
    }
    if (isTRUE(g$isLastBlock)) break
    prev <- g$endpage
    k <- k + 1
  }
  k
}

test_that("at a rate that is not whole, light is resampled as GGIR resamples it", {
  skip_if_not_installed("GGIR")
  skip_if_not_installed("GGIRread")
  # the real file at 85.7 Hz onto 86 Hz: GGIR's block (round(14512 * (sf /
  # 50)) pages: g.getmeta's, 24874) and blocks inside the file
  f <- ga_real()
  for (B in c(24874, 5, 3)) expect_gt(expect_ggir_blocks(f, B), if (B < 17) 2 else 0)
  # synthetic at 85.7 Hz, light over the whole range
  g <- ga_write(12, sf = 85.7)
  for (B in c(5, 4)) expect_ggir_blocks(g, B)
  # a copy cut inside page 10's hex line after 1211 digits (the last
  # sample's light from 2 digits): GGIR's blocks still, light too
  bytes <- readBin(g, "raw", file.size(g))
  starts <- gregexpr("Recorded Data", rawToChar(bytes), fixed = TRUE)[[1]]
  cut <- tempfile(fileext = ".bin")
  writeBin(bytes[seq_len(starts[11] - 2 - 3600 - 1 + 1211)], cut)
  for (B in c(4, 3)) expect_ggir_blocks(cut, B)
  # damaged pages (readGENEActiv's reading of them) resampled as GGIR
  # resamples them: page 5 cut short, page 9 with a garbled digit
  lines <- ga_lines(g)
  lines[ga_line(lines, 5, 10)] <- substr(lines[ga_line(lines, 5, 10)], 1, 2000)
  substr(lines[ga_line(lines, 9, 10)], 602, 602) <- "Q"
  dmg <- ga_put(lines)
  for (B in c(4, 3)) expect_ggir_blocks(dmg, B)
  d <- gravcal:::native_read_all(g, "geneactiv", list(compat = 1))
  expect_false(anyNA(d$light))
  expect_gt(stats::sd(d$light), 100)
})
