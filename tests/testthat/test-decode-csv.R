# The native csv decoder (inst/include/gravcal/decoders/decode_csv.hpp) against the
# reference readers: data.table::fread as GGIR 3.3.9's g.readaccfile calls it
# for ActiGraph csv (fread(skip = s, nrows = B, header = FALSE), columns 2:4
# when there are more than 3), and g.readaccfile itself where it can read
# the file (it needs "at N Hz" in the header). The synthetic files are
# written with data.table::fwrite.
skip_if_not_installed("data.table")

ggirread_file <- function(name) {
  skip_if_not_installed("GGIRread")
  p <- system.file("testfiles", name, package = "GGIRread")
  if (!nzchar(p)) skip(paste("GGIRread has no test file", name))
  p
}

# fread's blocks as g.readaccfile asks for them: skip 10, +1 when line 11's
# first field is not a number (its testheader check), then skip + B.
fread_blocks <- function(file, B) {
  skip_if_not_installed("data.table")
  th <- data.table::fread(file, nrows = 2, skip = 10, header = TRUE,
                          data.table = FALSE, showProgress = FALSE)
  s <- 10 + is.na(suppressWarnings(as.numeric(colnames(th)[1])))
  out <- list()
  repeat {
    d <- tryCatch(suppressWarnings(data.table::fread(
      file, nrows = B, skip = s, dec = ".", header = FALSE, data.table = FALSE,
      showProgress = FALSE)), error = function(e) NULL)
    if (is.null(d) || !nrow(d)) break
    if (ncol(d) > 3) d <- d[, 2:4]
    names(d) <- c("x", "y", "z")
    out[[length(out) + 1]] <- d
    s <- s + B
  }
  out
}

# g.readaccfile's own blocks (blocksize * 300 rows each).
ggir_blocks <- function(file, blocksize) {
  skip_if_not_installed("GGIR")
  params <- GGIR:::load_params()
  I <- GGIR:::g.inspectfile(file, params_rawdata = params$params_rawdata,
                            params_general = params$params_general)
  fq <- list(filecorrupt = FALSE, filetooshort = FALSE, NFilePagesSkipped = 0)
  out <- list()
  prev <- c()
  repeat {
    a <- GGIR:::g.readaccfile(file, blocksize = blocksize, blocknumber = length(out) + 1,
                              filequality = fq, ws = 0.001, PreviousEndPage = prev,
                              inspectfileobject = I,
                              params_rawdata = params$params_rawdata,
                              params_general = params$params_general)
    if (!length(a$P) || !nrow(a$P$data)) break
    out[[length(out) + 1]] <- a$P$data[, c("x", "y", "z")]
    prev <- a$endpage
    if (a$isLastBlock) break
  }
  out
}

# The decoder's blocks of B lines each.
native_blocks <- function(file, B, options = list(compat = 1)) {
  h <- gravcal:::native_open(file, "actigraph_csv", options)
  on.exit(gravcal:::gc_decoder_close(h$ptr))
  out <- list()
  repeat {
    b <- gravcal:::native_block(h, B, B, time = FALSE)
    if (b$to > 0) {
      out[[length(out) + 1]] <- data.frame(x = b$cols$x[seq_len(b$to)],
                                           y = b$cols$y[seq_len(b$to)],
                                           z = b$cols$z[seq_len(b$to)])
    }
    if (b$done) break
  }
  out
}

xyz <- function(d) as.data.frame(lapply(d[c("x", "y", "z")], as.numeric))
rbind_xyz <- function(l) xyz(do.call(rbind, l))

# A small synthetic recording: 30 Hz, values in 3 decimals as ActiLife
# writes them.
synthetic_samples <- function(n = 3000) {
  i <- seq_len(n)
  data.frame(x = round(sin(i / 50), 3), y = round(cos(i / 70) * 0.5, 3),
             z = round(-0.8 + (i %% 7) / 100, 3))
}

write_synth <- function(n = 3000, stamps = "actilife", ...) {
  f <- tempfile(fileext = ".csv")
  gravcal:::write_actigraph_csv_file(synthetic_samples(n), f, sf = 30, stamps = stamps, ...)
  f
}

read_csv_native <- function(file, ..., format = "actigraph_csv") {
  gravcal:::native_read_all(file, format, options = list(...))
}

test_that("GGIRread's ActiGraph count exports read as GGIR's fread calls read them (option counts)", {
  for (name in c("ActiGraph13.csv", "ActiGraph13_timestamps_headers.csv", "ActiGraph61.csv")) {
    f <- ggirread_file(name)
    ref <- fread_blocks(f, 300)
    d <- read_csv_native(f, compat = 1, counts = 1)
    expect_identical(xyz(d), rbind_xyz(ref), label = name)
    expect_identical(lapply(native_blocks(f, 300, list(compat = 1, counts = 1)), xyz),
                     lapply(ref, xyz), label = name)
    expect_identical(attr(d, "report")$skipped, 0)
  }
  # 990 data lines after 10 header lines (wc -l gives 1000)
  expect_identical(nrow(read_csv_native(ggirread_file("ActiGraph13.csv"), counts = 1)), 990L)
})

test_that("ActiLife epoch exports (counts, not g) are refused by every verb that reads samples", {
  # GGIR's and GGIRread's test files: "Epoch Period (hh:mm:ss)" 00:00:15,
  # 00:00:01 and 00:00:05, no "at N Hz"; before, read_recording() gave the
  # counts as g at 1 / 15 Hz and calibrate() fitted them
  epoch <- c(ActiGraph13.csv = "00:00:15", ActiGraph13_timestamps_headers.csv = "00:00:01",
             ActiGraph61.csv = "00:00:05")
  for (name in names(epoch)) {
    f <- ggirread_file(name)
    why <- paste0("an ActiLife epoch export \\(\"Epoch Period \\(hh:mm:ss\\) ", epoch[[name]],
                  "\" and no \"at N Hz\".*counts per epoch, not samples in g")
    expect_error(read_recording(f), paste0("`file`.*", why), label = name)
    expect_error(calibrate(f), paste0("`x`.*", why), label = name)
    expect_error(epoch_signals(f), why, label = name)
    expect_error(g.calibrate(f, verbose = FALSE), paste0("`datafile`.*", why), label = name)
    expect_error(read_csv_native(f, compat = 1), why, label = name)
  }
  # a raw export's header keeps its epoch period 00:00:00: read as before
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  gravcal:::write_actigraph_csv_file(synthetic_samples(300), f, sf = 30)
  expect_identical(attr(read_recording(f)$data, "sf"), 30)
})

test_that("compat = 0 takes x, y, z from columns 1:3 when there is no time stamp", {
  f <- ggirread_file("ActiGraph61.csv")
  d0 <- read_csv_native(f, compat = 0, counts = 1)
  ref <- utils::read.csv(f, skip = 10, header = FALSE)
  expect_identical(d0$x, as.numeric(ref[[1]]))
  expect_identical(d0$z, as.numeric(ref[[3]]))
  info <- attr(d0, "info")
  expect_identical(info$serial, "MOS2D16160581")
  # "Epoch Period (hh:mm:ss) 00:00:05" and no "at N Hz": one sample per 5 s
  expect_equal(info$sf, 1 / 5)
  # Start Date 8/15/2016, Start Time 21:35:00
  expect_identical(info$start_time, as.numeric(as.POSIXct("2016-08-15 21:35:00", tz = "UTC")))
  expect_identical(d0$time[1:3], info$start_time + c(0, 5, 10))
})

test_that("read.gt3x's .csv.gz reads as GGIR's g.readaccfile reads it, block by block", {
  skip_if_not_installed("read.gt3x")
  f <- system.file("extdata", "TAS1H30182785_2019-09-17.csv.gz", package = "read.gt3x")
  ref <- ggir_blocks(f, 100)  # blocks of 30000 rows
  d <- read_csv_native(f)
  expect_identical(xyz(d), rbind_xyz(ref))
  # 240511 lines (zcat | wc -l) less 11 header lines
  expect_identical(nrow(d), 240500L)
  expect_identical(lapply(native_blocks(f, 30000), xyz), lapply(ref, xyz))
  info <- attr(d, "info")
  expect_identical(info$sf, 100)
  expect_identical(info$serial, "TAS1H30182785")
  t0 <- as.numeric(as.POSIXct("2019-09-17 18:40:00", tz = "UTC"))
  expect_identical(info$start_time, t0)
  expect_identical(d$time[c(1, 101, 240500)], t0 + c(0, 100, 240499) / 100)
})

test_that("a synthetic time-stamped export reads as fread and g.readaccfile read it", {
  f <- write_synth(3000)
  ref <- ggir_blocks(f, 2)  # blocks of 600 rows
  d <- read_csv_native(f)
  expect_identical(xyz(d), rbind_xyz(ref))
  expect_identical(xyz(d), xyz(synthetic_samples(3000)))
  expect_identical(lapply(native_blocks(f, 600), xyz), lapply(ref, xyz))
  # time stamps: R's own parse of the stamps as written
  stamps <- data.table::fread(f, skip = 11, header = FALSE, select = 1)[[1]]
  tr <- as.numeric(as.POSIXct(stamps, format = "%m/%d/%Y %H:%M:%OS", tz = "UTC"))
  expect_identical(d$time, tr)
  expect_identical(attr(d, "report")$gaps, 0)
  # the package's older writer (R/read.R) gives a file read the same way
  g <- tempfile(fileext = ".csv")
  gravcal:::write_actigraph_csv(synthetic_samples(900), g, sf = 30, timestamps = TRUE)
  expect_identical(xyz(read_csv_native(g)), rbind_xyz(fread_blocks(g, 300)))
})

test_that("numbers equal fread's (compat = 1) or are correctly rounded (compat = 0)", {
  s <- c("1.358931", "1.897258", "-0.468639", "0.729435", "-1.10116583029324",
         "0.123", "-1.0039", "1e-3")
  f <- tempfile(fileext = ".csv")
  writeLines(c(gravcal:::actigraph_csv_header(30, "2023-05-11 09:00:00", 8),
               paste(s, s, s, sep = ",")), f)
  ref <- rbind_xyz(fread_blocks(f, 100))
  d1 <- read_csv_native(f, compat = 1)
  expect_identical(xyz(d1), ref)
  d0 <- read_csv_native(f, compat = 0)
  # correctly rounded values: Python's float(s).hex()
  expect_identical(sprintf("%a", d0$x),
                   c("0x1.5be2e6ea85447p+0", "0x1.e5b2b3461309cp+0", "-0x1.dfe2e6ea85447p-2",
                     "0x1.7578811b1d92bp-1", "-0x1.19e600fc9507fp+0", "0x1.f7ced916872bp-4",
                     "-0x1.00ff972474539p+0", "0x1.0624dd2f1a9fcp-10"))
  # fread scales the digits by a power of ten in long double and rounds that
  # to double: where it differs from the correctly rounded value, by one
  # unit in the last place. With x87's 64-bit long double (x86) it differs
  # for the first five by data.table 1.14.8's rule and for three of them by
  # 1.18.6.1's (counted with each); with IEEE quad (aarch64) the double
  # rounding seldom shows, so elsewhere only the bound is checked
  diff <- d0$x != d1$x
  expect_true(all(abs(d0$x[diff] - d1$x[diff]) <= 2^-52 * abs(d0$x[diff])))
  if (Sys.info()[["machine"]] %in% c("x86_64", "amd64", "i386", "i686") &&
      .Machine$sizeof.longdouble >= 10) {
    expect_identical(sum(diff), if (gravcal:::fread_number_rule() == 1L) 5L else 3L)
  }
})

test_that("the number rule of the installed data.table is found from its fread", {
  # data.table before 1.15.0 multiplies the digits by 10^-k, from 1.15.0 it
  # divides them by 10^k (its issue 4461): "-6.94352849999999" is 1 ulp
  # apart by the two rules with x87's long double (bits from data.table
  # 1.14.8 and 1.18.6.1 on x86-64 Linux)
  s <- gravcal:::fread_probe_numbers
  r1 <- gravcal:::gc_csv_numbers(s, 1L)
  r2 <- gravcal:::gc_csv_numbers(s, 2L)
  if (.Machine$sizeof.longdouble >= 10 && Sys.info()[["machine"]] %in% c("x86_64", "amd64")) {
    expect_identical(sprintf("%a", c(r1[1], r2[1])),
                     c("-0x1.bc62c55c96025p+2", "-0x1.bc62c55c96026p+2"))
  }
  p <- gravcal:::fread_rule_probe()
  got <- data.table::fread(text = c("v", s), colClasses = "numeric")[[1]]
  expect_identical(got, gravcal:::gc_csv_numbers(s, p$rule))
  expect_identical(p$rule, if (packageVersion("data.table") >= "1.15.0") 2L else 1L)
  # and a file's numbers are the installed fread's (the decoder is given
  # the rule: with_resample_fused())
  f <- tempfile(fileext = ".csv")
  writeLines(c("x,y,z", paste(s, rev(s), s, sep = ",")), f)
  d <- gravcal:::native_read_all(f, "csv", options = gravcal:::with_resample_fused(list(compat = 1, sf = 30), "csv"))
  ref <- data.table::fread(f, colClasses = "numeric")
  expect_identical(xyz(d), xyz(as.data.frame(ref)))
  # the other rule gives other bits where the two differ
  other <- gravcal:::native_read_all(f, "csv", options = list(compat = 1, sf = 30, fread_rule = 3 - p$rule))
  expect_identical(other$x != d$x, r1 != r2)
})

# Lines of the common shape are parsed where they lie in the read buffer
# (decode_csv.hpp, read_plain_as()); option fast = 0 sends every line
# through the general parser instead. Both must give fread's numbers.
bits <- function(d) lapply(d[c("x", "y", "z")], function(v) sprintf("%a", v))

number_shapes <- function(n = 3000) {
  set.seed(11)
  v <- c(runif(n, -8, 8), runif(n / 10, -1e-3, 1e-3), runif(n / 10, -1e6, 1e6))
  c("0.121", "-0.891", "+1.5", "-0.000", "0", "-0", "12", "-7", "+3", ".5", "5.", "-.25",
    "1e-3", "1.5E+2", "-2.5e-10", "+3e2", "7E0", "0.000000000000000001",
    "123456789012345678", "-1.234567890123456789", "0.12345678901234567",
    "0.1234567890123456789012", "1.10116583029324", "-1.358931", "9007199254740993.5",
    "000000000000000000001.25", "1.0000000000000000000001",
    sprintf("%.3f", v), sprintf("%.4f", v), sprintf("%.6f", v), sprintf("%+.3f", v),
    sprintf("%.14g", v), sprintf("%.15g", v), sprintf("%.16g", v), sprintf("%.17g", v),
    sprintf("%.18g", v), sprintf("%.19g", v), sprintf("%.6e", v),
    # halfway between neighbouring 3- and 6-decimal values, and next to it
    sprintf("%.3f5", v), sprintf("%.6f5", v), sprintf("%.6f49999999", v),
    sprintf("%.6f50000001", v))
}

test_that("numbers of every shape read as fread reads them, in place and line by line", {
  s <- number_shapes()
  n <- length(s)
  # every shape in every column
  lines <- paste(s, s[c(2:n, 1)], s[c(3:n, 1:2)], sep = ",")
  f <- tempfile(fileext = ".csv")
  writeLines(c(gravcal:::actigraph_csv_header(30, "2023-05-11 09:00:00", n),
               "Accelerometer X,Accelerometer Y,Accelerometer Z", lines), f)
  ref <- rbind_xyz(fread_blocks(f, 1e6))
  expect_identical(nrow(ref), n)
  fast <- read_csv_native(f, compat = 1)
  slow <- read_csv_native(f, compat = 1, fast = 0)
  expect_identical(bits(fast), bits(ref))
  expect_identical(bits(slow), bits(ref))
  expect_identical(attr(fast, "report")$skipped, 0)
  # correctly rounded (compat = 0): the two parsers agree; fread's product
  # differs in the last bit for some of the longer numbers only
  fast0 <- read_csv_native(f, compat = 0)
  expect_identical(bits(fast0), bits(read_csv_native(f, compat = 0, fast = 0)))
  short <- !grepl("[eE]", s) & nchar(sub("^[-+]?0*\\.?0*", "", s)) <= 5
  expect_identical(fast0$x[short], fast$x[short])
  # a plain csv with time and temperature, columns in another order, CRLF
  d <- data.frame(temperature = s[c(5:n, 1:4)], z = s, time = 1.7e9 + seq_len(n) / 50,
                  x = s[c(2:n, 1)], y = s[c(3:n, 1:2)])
  g <- tempfile(fileext = ".csv")
  data.table::fwrite(d, g, eol = "\r\n", quote = FALSE)
  ref <- data.table::fread(g, data.table = FALSE, colClasses = "numeric")
  for (compat in 1) {
    a <- read_csv_native(g, format = "csv", compat = compat)
    b <- read_csv_native(g, format = "csv", compat = compat, fast = 0)
    expect_identical(bits(a), bits(ref))
    expect_identical(bits(b), bits(ref))
    expect_identical(sprintf("%a", a$temperature), sprintf("%a", ref$temperature))
    expect_identical(a$time, b$time)
  }
})

test_that("CRLF, a BOM, blanks and quotes read as the clean file", {
  clean <- read_csv_native(write_synth(500))
  f <- write_synth(500, eol = "\r\n")
  expect_identical(xyz(read_csv_native(f)), xyz(clean))
  expect_identical(xyz(read_csv_native(f)), rbind_xyz(fread_blocks(f, 1000)))
  lines <- readLines(write_synth(500))
  lines[1] <- paste0("\ufeff", lines[1])
  lines[20:30] <- gsub(",", " , ", lines[20:30])
  lines[40:50] <- gsub("([^,]+)", "\"\\1\"", lines[40:50])
  g <- tempfile(fileext = ".csv")
  writeLines(enc2utf8(lines), g, useBytes = TRUE)
  d <- read_csv_native(g)
  expect_identical(xyz(d), xyz(clean))
  expect_identical(d$time, clean$time)
  expect_identical(attr(d, "report")$skipped, 0)
})

# Damage: the decoder keeps every good line and counts the others.
damage <- function(f, lines_to, what) {
  l <- readLines(f)
  l[lines_to] <- what
  g <- tempfile(fileext = ".csv")
  writeLines(l, g)
  g
}

test_that("malformed lines are skipped and counted, every good line is kept", {
  f <- write_synth(3000)
  clean <- read_csv_native(f)
  # data line k is file line 11 + k
  cases <- list(short_lines = "5/11/2023 09:00:10.000,0.1,0.2",
                blank_lines = "",
                non_numeric_lines = "5/11/2023 09:00:10.000,abc,0.2,0.3",
                long_lines = "5/11/2023 09:00:10.000,0,123,-1,0039,0,995")
  for (kind in names(cases)) {
    g <- damage(f, 11 + c(100, 2000), cases[[kind]])
    for (compat in 0:1) {
      d <- read_csv_native(g, compat = compat)
      expect_identical(d[names(clean)], clean[-c(100, 2000), ], ignore_attr = TRUE, label = kind)
      r <- attr(d, "report")
      expect_identical(r$skipped, 2, label = kind)
      expect_identical(unname(r$counters[kind]), 2, label = kind)
      expect_identical(r$units, 3000, label = kind)
      expect_match(r$notes[1], "line 111 \\(byte [0-9]+\\)", label = kind)
    }
    # blocks keep GGIR's boundaries: B lines each, less the damaged lines
    nb <- native_blocks(g, 600)
    expect_identical(vapply(nb, nrow, 1L), c(599L, 600L, 600L, 599L, 600L), label = kind)
  }
})

test_that("a file cut anywhere gives every whole line before the cut", {
  f <- write_synth(1000)
  clean <- read_csv_native(f)
  bytes <- readBin(f, "raw", file.size(f))
  l <- readLines(f)
  hdr <- sum(nchar(l[1:11], "bytes") + 1)
  ends <- hdr + cumsum(nchar(l[-(1:11)], "bytes") + 1)  # byte after each data line
  for (cut in c(ends[200], ends[499] - 3, ends[700] + 30, ends[999] - 1)) {
    g <- tempfile(fileext = ".csv")
    writeBin(bytes[seq_len(cut)], g)
    d <- read_csv_native(g)
    r <- attr(d, "report")
    whole <- sum(ends <= cut)
    part <- cut > ends[whole]
    # a cut line is skipped (truncated) unless it still holds every field:
    # then it is kept, as fread keeps it, with its last value cut
    keep_cut <- part && !r$truncated
    expect_identical(xyz(d)[seq_len(whole), ], xyz(clean)[seq_len(whole), ], label = cut)
    expect_identical(nrow(d), whole + keep_cut, label = cut)
    expect_identical(unname(r$counters["truncated_lines"]) %in% 1, part && !keep_cut)
    expect_identical(unname(r$counters["no_final_line_end"]) %in% 1, keep_cut)
  }
  # the cut 3 bytes before a line end holds every field
  expect_identical(nrow(read_csv_native({g <- tempfile(); writeBin(bytes[seq_len(ends[499] - 3)], g); g})), 499L)
  # no whole data line: the layout cannot be learnt, open() fails and says so
  g <- tempfile(fileext = ".csv")
  writeBin(bytes[seq_len(hdr + 5)], g)  # "5/11/" of line 12
  expect_error(read_csv_native(g), "line 12 is \"5/11/\" \\(the file ends there\\)")
  # header cut: open() fails with a clear error
  writeBin(bytes[seq_len(200)], g)
  expect_error(read_csv_native(g), "header truncated at line")
})

test_that("a jump in the time stamps is a reported gap", {
  f <- write_synth(3000)
  l <- readLines(f)
  g <- tempfile(fileext = ".csv")
  # drop 10 minutes' worth of lines (18000 lines would be a real gap; here
  # lines 1001..1600 of data, 20 s at 30 Hz)
  writeLines(l[-(11 + 1001:1600)], g)
  d <- read_csv_native(g)
  r <- attr(d, "report")
  expect_identical(r$gaps, 1)
  expect_equal(r$gap_seconds, 600 / 30, tolerance = 1e-3)
  expect_match(paste(r$notes, collapse = " "), "line 1012 .*time jumps")
  expect_identical(nrow(d), 2400L)
  # a damaged time stamp keeps its sample
  h <- damage(f, 11 + 50, sub("^[^,]+", "5/11/20x3 09:00:01.633", l[11 + 50]))
  d2 <- read_csv_native(h)
  expect_identical(xyz(d2), xyz(read_csv_native(f)))
  expect_identical(unname(attr(d2, "report")$counters["bad_timestamps"]), 1)
})

test_that("semicolon-separated files with decimal commas are read", {
  f <- write_synth(300, stamps = "none")
  l <- readLines(f)
  l[12:length(l)] <- gsub(".", ",", gsub(",", ";", l[12:length(l)], fixed = TRUE), fixed = TRUE)
  l[11] <- gsub(",", ";", l[11])
  g <- tempfile(fileext = ".csv")
  writeLines(l, g)
  ref <- data.table::fread(g, skip = 11, header = FALSE, dec = ",", sep = ";", data.table = FALSE)
  d <- read_csv_native(g)
  expect_identical(xyz(d), setNames(ref, c("x", "y", "z")))
  expect_identical(xyz(d), xyz(synthetic_samples(300)))
})

test_that("plain csv: any column order, temperature, sf from time as sf_from_time()", {
  s <- synthetic_samples(2000)
  t0 <- as.numeric(as.POSIXct("2024-03-01 12:00:00", tz = "UTC"))
  d <- data.frame(temperature = round(25 + seq_len(2000) / 1000, 2), Z = s$z,
                  time = t0 + (seq_len(2000) - 1) / 50, acc_x = s$x, Y = s$y)
  f <- tempfile(fileext = ".csv")
  gravcal:::write_plain_csv(d, f)
  ref <- data.table::fread(f, data.table = FALSE)
  n <- read_csv_native(f, format = "csv")
  expect_identical(n$x, ref$acc_x)
  expect_identical(n$y, ref$Y)
  expect_identical(n$temperature, ref$temperature)
  expect_identical(n$time, ref$time)
  expect_identical(attr(n, "sf"), gravcal:::sf_from_time(ref$time))
  expect_identical(attr(n, "sf"), 50)
  # ISO date-time text (fwrite's POSIXct), sf from it; option sf wins
  d$time <- as.POSIXct(d$time, origin = "1970-01-01", tz = "UTC")
  gravcal:::write_plain_csv(d, f)
  n2 <- read_csv_native(f, format = "csv")
  expect_identical(attr(n2, "sf"), 50)
  expect_identical(n2$time, as.numeric(d$time))
  expect_identical(attr(read_csv_native(f, format = "csv", sf = 25), "sf"), 25)
  # a csv that is an ActiGraph export is read as one under "csv" too
  g <- write_synth(300)
  expect_identical(read_csv_native(g, format = "csv"), read_csv_native(g), ignore_attr = TRUE)
})

test_that("files that cannot be read say why", {
  f <- tempfile(fileext = ".csv")
  writeLines(c("a,b,c", "1,2,3"), f)
  expect_error(read_csv_native(f), "not an ActiGraph csv export: first line is \"a,b,c\"")
  expect_error(read_csv_native(f, format = "csv"), "names no x, y, z columns")
  writeLines(c("x,y,z", "1,2,3"), f)
  expect_error(read_csv_native(f, format = "csv"), "sampling frequency .* is unknown: give `sf`")
  expect_identical(nrow(read_csv_native(f, format = "csv", sf = 10)), 1L)
  file.create(f)
  expect_error(read_csv_native(f), "the file is empty")
  l <- gravcal:::actigraph_csv_header(30, "2023-05-11 09:00:00", 3)
  writeLines(c(l, "1,2"), f)
  expect_error(read_csv_native(f), "do not have 3 fields")
})

test_that("a small read buffer (lines across refills) gives the same samples", {
  f <- write_synth(2000)
  g <- damage(f, 11 + c(7, 1500), c("", "5/11/2023 09:00:50.000,0.1"))
  for (file in c(f, g)) {
    big <- read_csv_native(file)
    small <- read_csv_native(file, buffer = 400)
    expect_identical(small, big, ignore_attr = TRUE)
    expect_identical(attr(small, "report")$counters, attr(big, "report")$counters)
  }
})

test_that("lines parsed in place give what the general parser gives, damage included", {
  f <- write_synth(3000)
  g <- damage(f, 11 + c(5, 100, 101, 2000, 2999),
              c("", "5/11/2023 09:00:10.000,0.1,0.2", "5/11/2023 09:00:10.000, 0.1 ,\"0.2\",0.3",
                "5/11/2023 09:00:10.000,1e-1,0.2,NA", "5/11/2023 09:00:10.000,0,123,-1,0039,0,995"))
  for (file in c(f, g, write_synth(500, eol = "\r\n"), write_synth(500, stamps = "none"))) {
    for (compat in 0:1) {
      a <- read_csv_native(file, compat = compat)
      b <- read_csv_native(file, compat = compat, fast = 0)
      expect_identical(a, b)
      expect_identical(read_csv_native(file, compat = compat, buffer = 300), b)
      expect_identical(native_blocks(file, 600, list(compat = compat)),
                       native_blocks(file, 600, list(compat = compat, fast = 0)))
    }
  }
})

test_that("an Axivity csv export through spring's skipped hour: GGIR's NA samples, no undefined arithmetic", {
  skip_if(is.null(gravcal:::zone_table("Europe/Amsterdam")),
          "this R has no daylight saving rules for Europe/Amsterdam")
  # UNIX stamps forced into Europe/Amsterdam (as GGIR forces them): those
  # of 02:00 to 03:00 on 2024-03-31 do not exist there (NA), and the
  # resampler reads them as GGIRread::resample() does, every later sample
  # of the block NA (test-ggir-getmeta.R and test-axivity-csv.R compare
  # with GGIR; this runs the path in the sanitizer lane, GGIR not needed)
  rec <- simulate_recording(hours = 4, sf = 10, seed = 33, temperature = FALSE)
  f <- tempfile(fileext = ".csv")
  on.exit(unlink(f))
  gravcal:::write_axivity_csv(rec, f, true_sf = 10.03, stamps = "unix",
                              start = "2024-03-31 00:00:00")
  pg <- list(desiredtz = "Europe/Amsterdam")
  M <- suppressWarnings(gravcal::g.getmeta(f, params_general = pg, verbose = FALSE))
  enmo <- M$metashort$ENMO
  # 2 hours (forced: 01:00 to 03:00 local) of epochs before the hour, NA
  # after it to the end of the block (the whole file here)
  expect_false(anyNA(enmo[1:(2 * 720 - 1)]))
  expect_true(all(is.na(enmo[(2 * 720 + 1):length(enmo)])))
  expect_gt(length(enmo), 2 * 720 + 100)
  C <- suppressWarnings(gravcal::g.calibrate(f, params_general = pg, verbose = FALSE))
  expect_true(all(is.finite(C$offset)))
  # the same export read in UTC: no NA
  M0 <- suppressWarnings(gravcal::g.getmeta(f, params_general = list(desiredtz = "UTC"),
                                             verbose = FALSE))
  expect_false(anyNA(M0$metashort$ENMO))
})
