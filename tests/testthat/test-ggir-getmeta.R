# gravcal::g.getmeta() against GGIR 3.3-9's g.getmeta() on the same file and
# parameters: identical() on every element of M but bsc_qc (GGIR's wall
# clock and memory). References: GGIR::g.getmeta() itself, run here (its
# results cached in tests/ggir-cache by input bytes, parameters and
# platform; helper-ggir-cache.R).

meta_quiet <- function(expr) {
  out <- NULL
  utils::capture.output(out <- suppressWarnings(expr))
  out
}

# (its printed output dropped, its warnings kept)
meta_quiet_keep_warnings <- function(expr) {
  out <- NULL
  utils::capture.output(out <- expr)
  out
}

# GGIR's and gravcal's M for `file` with the same arguments (a list:
# params_metrics, params_rawdata, params_general, params_cleaning, offset,
# scale, tempoffset, meantempcal, daylimit; missing lists are GGIR's
# defaults).
meta_both <- function(file, args = list()) {
  skip_if_not_installed("GGIR")
  defaults <- GGIR::load_params()
  for (k in c("metrics", "rawdata", "general", "cleaning")) {
    nm <- paste0("params_", k)
    args[[nm]] <- utils::modifyList(defaults[[nm]], args[[nm]] %||% list())
  }
  # a myfun's functions enter the cache key as their text (a closure's
  # serialization holds its environment)
  key <- args
  if (!is.null(key$myfun)) {
    key$myfun <- lapply(key$myfun, function(v) if (is.function(v)) deparse(v) else v)
  }
  R <- ggir_cached("g.getmeta", file, key, {
    I <- meta_quiet(GGIR::g.inspectfile(file, params_rawdata = args$params_rawdata,
                                        params_general = args$params_general))
    meta_quiet(do.call(GGIR::g.getmeta, c(list(datafile = file, inspectfileobject = I,
                                               verbose = FALSE), args)))
  })
  G <- meta_quiet(do.call(gravcal::g.getmeta, c(list(datafile = file, verbose = FALSE), args)))
  list(ggir = R, gravcal = G)
}

`%||%` <- function(a, b) if (is.null(a)) b else a

# `clock`: QClog's start and end are GGIR's wall clock (a file without time
# stamps: g.imputeTimegaps() counts from Sys.time()), compared by type only
expect_same_meta <- function(b, clock = FALSE) {
  R <- b$ggir
  G <- b$gravcal
  expect_identical(names(G), names(R))
  if (clock) {
    for (k in c("start", "end")) {
      expect_identical(class(G$QClog[[k]]), class(R$QClog[[k]]))
      G$QClog[[k]] <- R$QClog[[k]] <- NULL
    }
  }
  for (nm in setdiff(names(R), "bsc_qc")) {
    expect_identical(G[[nm]], R[[nm]], label = paste0("gravcal's M$", nm),
                     expected.label = paste0("GGIR's M$", nm))
  }
  expect_true(is.data.frame(G$bsc_qc))
}

meta_recording <- function(format, sf, hours, seed = 7, start = "2024-03-04 09:07:23") {
  write_meta_recording(tempfile(fileext = if (format == "cwa") ".cwa" else ".bin"),
                       format, sf, hours, seed, start)
}

cal_args <- list(offset = c(0.01, -0.02, 0.005), scale = c(1.01, 0.99, 1.002),
                 tempoffset = c(0.001, -0.002, 0.0005), meantempcal = 24)

test_that("g.getmeta() is GGIR's on a .cwa recording: defaults, calibrated", {
  f <- meta_recording("cwa", 25, 30)
  b <- meta_both(f, cal_args)
  expect_same_meta(b)
  # the recording has what the comparison should see: two blocks, non-wear
  # from the flat stretches, a clipped epoch, the temperature column
  M <- b$gravcal
  expect_gt(nrow(M$metashort), 30 * 720 * 0.9)
  expect_true(any(M$metalong$nonwearscore >= 2))
  expect_true(any(M$metalong$clippingscore > 0))
  expect_true(all(c("temperaturemean", "lightmean", "lightpeak") %in% names(M$metalong)))
  expect_identical(names(M$metashort), c("timestamp", "anglez", "ENMO"))
})

test_that("g.getmeta() is GGIR's on a .cwa recording in zones of one offset (Asia/Kolkata, Asia/Tokyo)", {
  skip_if_quick()
  # GGIRread reads a .cwa file's calendar in the zone, whatever its rules;
  # gravcal's decoder read it as UTC in a zone whose offset never changes
  # (g.calibrate()'s result is the same either way), so M's time stamps
  # were the zone's offset late there. A start a fraction past the second
  f <- meta_recording("cwa", 25, 5, seed = 12, start = "2024-01-01 00:07:13.37")
  for (tz in c("Asia/Kolkata", "Asia/Tokyo")) {
    b <- meta_both(f, list(params_general = list(desiredtz = tz)))
    expect_same_meta(b)
    expect_identical(substr(b$gravcal$metashort$timestamp[1], 1, 19), "2024-01-01T00:15:00")
  }
  # configtz of one offset, desiredtz another
  b <- meta_both(f, list(params_general = list(desiredtz = "America/New_York", configtz = "Asia/Kolkata")))
  expect_same_meta(b)
  expect_identical(b$gravcal$metashort$timestamp[1], "2023-12-31T13:45:00-0500")
  # and g.calibrate() there, GGIR's to the bit (the decoder's times moved)
  pg <- utils::modifyList(GGIR::load_params()$params_general, list(desiredtz = "Asia/Kolkata"))
  pr <- GGIR::load_params()$params_rawdata
  R <- ggir_cached("g.calibrate", f, list(params_rawdata = pr, params_general = pg), {
    I <- meta_quiet(GGIR::g.inspectfile(f, params_rawdata = pr, params_general = pg))
    keep_warn(meta_quiet(GGIR::g.calibrate(f, params_rawdata = pr, params_general = pg,
                                           inspectfileobject = I, verbose = FALSE)))
  })
  G <- meta_quiet(gravcal::g.calibrate(f, params_rawdata = pr, params_general = pg, verbose = FALSE))
  for (nm in setdiff(names(R), "bsc_qc")) expect_identical(G[[nm]], R[[nm]], label = nm)
  unlink(f)
})

test_that("a .cwa recording across the spring and autumn changes: M is GGIR's, QClog too", {
  skip_if_quick()
  # spring: the device's calendar passes the hour Europe/Amsterdam skips;
  # GGIRread sees its block times step back and imputes every block from
  # there on (gravcal's decoder too), logging each in QClog (750 rows).
  # Autumn: the calendar's hour from 02:00 is read once, in summer time, so
  # the block after it starts an hour late: readAxivity imputes the hour
  # and logs two blocks. Before gravcal reproduced readAxivity's log, M$QClog
  # was NULL here (and a warning said so)
  f <- meta_recording("cwa", 25, 5, seed = 12, start = "2024-03-30 22:00:00")
  args <- list(params_general = list(desiredtz = "Europe/Amsterdam"))
  b <- meta_both(f, args)
  expect_gt(nrow(b$ggir$QClog), 100)
  expect_same_meta(b)
  expect_no_warning(utils::capture.output(do.call(gravcal::g.getmeta, c(list(f, verbose = FALSE), args))))
  unlink(f)
  f <- meta_recording("cwa", 25, 5, seed = 12, start = "2024-10-27 00:30:00")
  b <- meta_both(f, args)
  expect_identical(nrow(b$ggir$QClog), 2L)
  expect_true(all(b$ggir$QClog$imputed))
  expect_same_meta(b)
  unlink(f)
  # 10 hours from 2024-10-26 23:17:13 UTC read in GGIR's blocks of
  # chunksize 0.1: a block starts at a calendar time that exists twice in
  # the zone, where readAxivity's block time depends on R's conversions
  # before it: refused, as g.calibrate() refuses such a block (gravcal's
  # g.getmeta() gave an M that was not GGIR's here, metashort and metalong,
  # without a word)
  f <- tempfile(fileext = ".cwa")
  write_meta_recording(f, "cwa", 25, 10, 5, "2024-10-26 23:17:13")
  expect_error(meta_quiet(gravcal::g.getmeta(f, params_general = args$params_general,
                                             params_rawdata = list(chunksize = 0.1),
                                             verbose = FALSE)),
               "a block of GGIR's reading of this file starts or ends at a time that exists twice",
               fixed = TRUE)
  unlink(f)
})

test_that("a damaged .cwa recording: M is GGIR's, readAxivity's log of the damage (QClog) too", {
  skip_if_quick()
  # 16 hours at 25 Hz, 120 samples a block (12,000 blocks); chunksize 0.2
  # reads it in windows of 5,400 blocks (GGIR's get_nw_clip_block_params():
  # round(24 * 3600 * sf / 80 * chunksize)), chunksize 1 in one. Bad
  # checksums at the file's start, inside a window, on both sides of the
  # windows' edges (readAxivity's end block search runs over them, the next
  # window starts on them again) and at the file's end (never read); a
  # sequence break; a block starting 7 samples early (the rate of the one
  # before 6 % off: logged, not imputed) and one 25 samples late (imputed)
  f <- meta_recording("cwa", 25, 16, seed = 31, start = "2024-03-04 09:07:23")
  b <- readBin(f, raw(), file.size(f))
  at <- function(k) 1024 + 512 * k
  bad <- c(0, 1, 700:702, 5399:5401, 10800, 11998, 11999)
  for (k in bad) b[at(k) + 100] <- as.raw(bitwXor(as.integer(b[at(k) + 100]), 0x10))
  for (k in 8000:11999) {  # the sequence number jumps by 3 at block 8000
    id <- readBin(b[at(k) + 11:14], integer(), size = 4, endian = "little")
    b[at(k) + 11:14] <- writeBin(as.integer(id + 3), raw(), size = 4, endian = "little")
    if (!k %in% bad) b <- cwa_fix_checksum(b, k)
  }
  for (m in list(c(3000, 7), c(9000, -25))) {
    o <- readBin(b[at(m[1]) + 27:28], integer(), size = 2, signed = TRUE, endian = "little")
    b[at(m[1]) + 27:28] <- writeBin(as.integer(o + m[2]), raw(), size = 2, endian = "little")[1:2]
    b <- cwa_fix_checksum(b, m[1])
  }
  g <- tempfile(fileext = ".cwa")
  writeBin(b, g)
  for (cs in c(0.2, 1)) {
    bb <- meta_both(g, list(params_rawdata = list(chunksize = cs)))
    expect_same_meta(bb)
    log <- bb$ggir$QClog
    expect_true(any(!log$checksum_pass) && any(log$imputed) && any(log$checksum_pass & !log$imputed))
    expect_false(any(log$blockID_current %in% c(11998, 11999)))
  }
  # the damage said (GGIR's reader warns of each block)
  expect_warning(utils::capture.output(gravcal::g.getmeta(g, verbose = FALSE)),
                 "11 damaged blocks skipped, as GGIR's reader skips them")
  unlink(c(f, g))
})

test_that("a .cwa file GGIR's reader stops on (zeroed blocks): GGIR loses its block, gravcal's drop-ins refuse", {
  # readAxivity() stops (not "AX") on a zeroed block, in a window or in its
  # search for the file's last good block, and GGIR's reading loses the
  # whole block of it that holds it: this 10 h file is one block of
  # g.getmeta()'s (M: a corrupt file) and of g.calibrate()'s (no hour
  # used). Before, gravcal's drop-ins read on, gave every row and warned of
  # the QClog only. Found by a random damage sweep (stop 68)
  f <- meta_recording("cwa", 25, 10, seed = 41)
  b <- readBin(f, raw(), file.size(f))
  nb <- (length(b) - 1024) / 512
  mid <- b
  mid[1024 + 512 * 6000 + 1:512] <- as.raw(0)  # 8 h in
  cases <- list(`a zeroed block` = mid, `three zeroed blocks appended` = c(b, raw(3 * 512)))
  for (nm in names(cases)) {
    g <- tempfile(fileext = ".cwa")
    writeBin(cases[[nm]], g)
    G <- ggir_cached("g.getmeta", g, list(), {
      meta_quiet(GGIR::g.getmeta(g, inspectfileobject = meta_quiet(GGIR::g.inspectfile(g)),
                                 verbose = FALSE))
    })
    expect_true(G$filecorrupt && G$filetooshort && is.null(G$metashort), label = paste(nm, "(GGIR's M)"))
    C <- ggir_cached("g.calibrate", g, list(), {
      meta_quiet(GGIR::g.calibrate(g, inspectfileobject = meta_quiet(GGIR::g.inspectfile(g)),
                                   verbose = FALSE))
    })
    expect_identical(C$nhoursused, 0)  # GGIR's calibration read nothing
    why <- "GGIR's reader \\(readAxivity\\(\\)\\) stops instead of skipping the damage"
    expect_error(meta_quiet(gravcal::g.getmeta(g, verbose = FALSE)),
                 paste0(why, ".*bad_header in block ", if (grepl("appended", nm)) nb else 6000,
                        ".*GGIR's g.getmeta\\(\\) gives no result there"), label = nm)
    expect_error(meta_quiet(gravcal::g.calibrate(g, verbose = FALSE)),
                 paste0(why, ".*GGIR's g.calibrate\\(\\) gives no result there"), label = nm)
    # gravcal's own verb reads past it (the block skipped)
    fit <- calibrate(g, method = "ggir")
    expect_identical(fit$input$report$skipped, if (grepl("appended", nm)) 3 else 1, label = nm)
    unlink(g)
  }
  unlink(f)
})

test_that("a damaged .gt3x file (cut short, damaged records): gravcal's drop-ins refuse", {
  # read.gt3x opens the archive by its central directory, at the file's
  # end: GGIR's M is a corrupt file's. gravcal's decoder reads the entries
  # from their local headers; before, its g.getmeta() gave 3 h of M and its
  # g.calibrate() coefficients, no warning. Found by a random damage sweep
  # (stop 68)
  f <- meta_recording("gt3x", 30, 5, seed = 43)
  g <- tempfile(fileext = ".gt3x")
  writeBin(readBin(f, raw(), file.size(f))[seq_len(round(0.6 * file.size(f)))], g)
  G <- ggir_cached("g.getmeta", g, list(), {
    meta_quiet(GGIR::g.getmeta(g, inspectfileobject = meta_quiet(GGIR::g.inspectfile(g)),
                               verbose = FALSE))
  })
  expect_true(G$filecorrupt && is.null(G$metashort))
  C <- ggir_cached("g.calibrate", g, list(), {
    meta_quiet(GGIR::g.calibrate(g, inspectfileobject = meta_quiet(GGIR::g.inspectfile(g)),
                                 verbose = FALSE))
  })
  expect_null(C)  # GGIR's inspection gets no rate ("File info could not be extracted")
  why <- "a zip archive whose central directory is missing or damaged.*read.gt3x\\) cannot open"
  expect_error(meta_quiet(gravcal::g.getmeta(g, verbose = FALSE)), why)
  expect_error(meta_quiet(gravcal::g.calibrate(g, verbose = FALSE)), why)
  # gravcal's own reader keeps what the local headers give, and says so
  r <- read_recording(g)
  expect_gt(nrow(r$data), 30 * 3600)
  expect_true(attr(r$data, "report")$truncated)
  # damaged records in log.bin (8 bytes of its deflated stream overwritten
  # half way): the decoder skips them, GGIR's reader does not read them
  # alike (on the damage sweep's files GGIR's g.calibrate() gave other
  # coefficients, silently, and its g.getmeta() other values or an error)
  b <- readBin(f, raw(), file.size(f))
  b[round(0.5 * length(b)) + 0:7] <- as.raw(1:8)
  writeBin(b, g)
  expect_gt(attr(read_recording(g)$data, "report")$skipped, 0)
  why <- "damaged records in log.bin \\(bad_checksum.*GGIR's reader \\(read.gt3x\\) does not read alike"
  expect_error(meta_quiet(gravcal::g.getmeta(g, verbose = FALSE)), why)
  expect_error(meta_quiet(gravcal::g.calibrate(g, verbose = FALSE)), why)
  unlink(c(f, g))
})

test_that("an ActiGraph csv export with damaged lines: gravcal's drop-ins refuse where GGIR reads otherwise", {
  # 3 h at 20 Hz. A line with a field too many, or too few, is skipped by
  # gravcal's decoder, not alike by GGIR's fread(): on the damage sweep's
  # files GGIR's g.calibrate() gave other coefficients, silently. An
  # unreadable time stamp changes only what g.getmeta() reads; a file cut
  # inside its last line is read alike by both. Found by a damage sweep
  # (stop 68)
  f <- tempfile(fileext = ".csv")
  rec <- simulate_recording(hours = 3, sf = 20, seed = 47,
                            start = as.POSIXct("2024-03-04 09:07:23", tz = "UTC"))
  write_recording(rec[, c("x", "y", "z")], f, sf = 20, format = "actigraph_csv",
                  start = "2024-03-04 09:07:23")
  l <- readLines(f)
  put <- function(lines) {
    g <- tempfile(fileext = ".csv")
    writeLines(lines, g)
    g
  }
  extra <- l
  extra[120011] <- paste0(extra[120011], ",0.5")
  g <- put(extra)
  why <- "1 damaged line \\(line 120011 .*too many fields.*GGIR's reader \\(fread\\(\\)\\) does not read alike"
  expect_error(meta_quiet(gravcal::g.getmeta(g, verbose = FALSE)), why)
  expect_error(meta_quiet(gravcal::g.calibrate(g, verbose = FALSE)), why)
  stamp <- l
  stamp[60011] <- sub("^[^,]*", "3/x/2024 17:27:23.000", stamp[60011])
  g2 <- put(stamp)
  expect_error(meta_quiet(gravcal::g.getmeta(g2, verbose = FALSE)), "unreadable time stamp")
  expect_same_as_ggir(run_both(g2))
  cut <- tempfile(fileext = ".csv")
  b <- readBin(f, raw(), file.size(f))
  writeBin(b[seq_len(round(0.7 * length(b)))], cut)
  expect_same_meta(meta_both(cut), clock = TRUE)
  unlink(c(f, g, g2, cut))
})

test_that("a file too short for a block: M's bsc_qc is GGIR's, without a row", {
  # GGIR's bsc_qc gains a row with each block it makes; a file too short
  # for one has none. Before, gravcal's had one (found by
  # tools/ggir-sweep-part1.R, stop 68)
  skip_if_not_installed("GGIRread")
  f <- system.file("testfiles", "ax3_testfile.cwa", package = "GGIRread")
  b <- meta_both(f)
  expect_true(b$ggir$filetooshort)
  expect_same_meta(b)
  expect_identical(b$gravcal$bsc_qc, b$ggir$bsc_qc)
})

# A GENEActiv recording's lines (meta_recording(): `hours` at 30 Hz), and
# a .bin file of them with CRLF line ends, as the device writes them.
ga_meta_lines <- function(hours = 3) {
  f <- meta_recording("geneactiv", 30, hours, seed = 5)
  on.exit(unlink(f))
  readLines(f)
}
ga_meta_put <- function(lines) {
  g <- tempfile(fileext = ".bin")
  writeBin(charToRaw(paste0(paste(lines, collapse = "\r\n"), "\r\n")), g)
  g
}
ga_meta_cut <- function(file, n) {
  g <- tempfile(fileext = ".bin")
  writeBin(readBin(file, "raw", file.size(file))[seq_len(n)], g)
  g
}

test_that("g.getmeta() is GGIR's on GENEActiv files with damaged pages, or cut short", {
  # GGIRread's reader keeps what it decodes of a damaged page (garbled
  # digits read as far as they go, the page ending at a group without one)
  # and closes up its time count after it; a block then short of samples
  # is GGIR's last. gravcal's decoder reads damaged pages so
  # (decode_geneactiv.hpp). GGIR's blocks of 871 pages (chunksize 0.1), the
  # damage in the first of two (page 300) or at the file's end
  args <- list(params_rawdata = list(chunksize = 0.1))
  lines <- ga_meta_lines()
  rd <- which(lines == "Recorded Data")
  hex <- rd[300] + 9
  damaged <- function(f) {
    l <- lines
    l <- f(l)
    ga_meta_put(l)
  }
  files <- list(
    "a non-hex character at a sample's start" = damaged(function(l) {
      substr(l[hex], 1201, 1201) <- "G"
      l
    }),
    "one inside a group" = damaged(function(l) {
      substr(l[hex], 1202, 1202) <- "G"
      l
    }),
    "a hex line cut short" = damaged(function(l) {
      l[hex] <- substr(l[hex], 1, 3000)
      l
    }),
    "a hex line too long" = damaged(function(l) {
      l[hex] <- paste0(l[hex], substr(l[hex], 1, 24))
      l
    }),
    "a garbled temperature" = damaged(function(l) {
      l[rd[300] + 5] <- "Temperature:2x.5"
      l
    }),
    "a line missing" = damaged(function(l) l[-(rd[300] + 4)]))
  clean <- ga_meta_put(lines)
  bytes <- file.size(clean)
  last <- tail(gregexpr("Recorded Data", rawToChar(readBin(clean, "raw", bytes)), fixed = TRUE)[[1]], 1)
  files[["cut inside the last hex line"]] <- ga_meta_cut(clean, bytes - 1000)
  files[["cut after the last page's \"Recorded Data\""]] <- ga_meta_cut(clean, last + 14)
  files[["cut inside its serial number's key"]] <- ga_meta_cut(clean, last + 30)
  for (nm in names(files)) {
    b <- meta_both(files[[nm]], args)
    expect_same_meta(b)
    # (a line missing: every page after it gives nothing, the first block
    # is too short)
    if (nm == "a line missing") {
      expect_true(b$gravcal$filetooshort)
    } else {
      expect_gt(nrow(b$gravcal$metashort), 500)
    }
  }
  # a block's last page read at another whole rate (29 Hz): GGIR times the
  # block by it (its start moves 300 s on, and the gap to the block before
  # is filled), and so does gravcal, though its first part was read before
  l4 <- ga_meta_lines(4)
  r4 <- which(l4 == "Recorded Data")
  l4[tail(r4, 1) + 8] <- "Measurement Frequency:29"
  b <- meta_both(ga_meta_put(l4), args)
  expect_same_meta(b)
  # what was read so is said
  expect_warning(meta_quiet_keep_warnings(gravcal::g.getmeta(files[[1]], verbose = FALSE)),
                 "1 damaged page .*read as GGIR's reader \\(GGIRread\\) reads them, so M is GGIR's")
  expect_warning(meta_quiet_keep_warnings(gravcal::g.getmeta(files[["a line missing"]],
                                                               verbose = FALSE)),
                 "780 pages after lines missing or extra")
  unlink(c(unlist(files), clean))
})

test_that("where GGIR's g.getmeta() stops on a damaged GENEActiv file, gravcal's stops too", {
  skip_if_not_installed("GGIR")
  lines <- ga_meta_lines()
  rd <- which(lines == "Recorded Data")
  pr <- utils::modifyList(GGIR::load_params()$params_rawdata, list(chunksize = 0.1))
  ggir_stops <- function(f, pattern) {
    # (GGIR's side: its error, cached; the slow tier)
    if (identical(Sys.getenv("GRAVCAL_TEST_TIER"), "quick")) return(invisible())
    # (GGIRread's "data error" lines on stderr dropped)
    utils::capture.output(type = "message", expect_match(ggir_error("g.getmeta", f, list(pr), {
      I <- keep_warn(meta_quiet(GGIR::g.inspectfile(f, params_rawdata = pr)))
      keep_warn(meta_quiet(GGIR::g.getmeta(f, params_rawdata = pr, inspectfileobject = I,
                                           verbose = FALSE)))
    }), pattern))
  }
  ours <- function(f) gravcal::g.getmeta(f, params_rawdata = pr, verbose = FALSE)
  # the last page cut in its temperature's number: GGIRread's rate of that
  # page (and of the second block) is 2 Hz, which moves the block's start
  # by hours: GGIR stops on the gap
  clean <- ga_meta_put(lines)
  at <- tail(grepRaw("Temperature:", readBin(clean, "raw", file.size(clean)), fixed = TRUE,
                     all = TRUE), 1)
  f <- ga_meta_cut(clean, at + 12)
  ggir_stops(f, "Time gap observed of more than 1 hour")
  expect_error(meta_quiet(ours(f)), "Time gap observed of more than 1 hour between data chunks")
  # cut in "Device Status:Rec...": rate 0, the block's times infinite
  at <- tail(grepRaw("Status:Rec", readBin(clean, "raw", file.size(clean)), fixed = TRUE,
                     all = TRUE), 1)
  f <- ga_meta_cut(clean, at + 9)
  ggir_stops(f, "Time gap observed of more than 1 hour")
  expect_error(meta_quiet(ours(f)), "Time gap observed of more than 1 hour between data chunks")
  # page 1's time garbled: GGIR's start NA
  l <- lines
  l[rd[1] + 3] <- "Page Tine:2024-03-04 09:07:23:000"
  f <- ga_meta_put(l)
  ggir_stops(f, "missing value where TRUE/FALSE needed")
  expect_error(meta_quiet(ours(f)), "first page whose \"Page Time:\" GGIR's reader does not read",
               fixed = TRUE)
  # a rate garbled to 0 in the first block: the reference's times after it
  # undefined (the platform's conversion of NaN: on x86-64 GGIR stops on
  # the gap they make)
  l <- lines
  l[rd[300] + 8] <- "Measurement Frequency:abc"
  f <- ga_meta_put(l)
  if (identical(R.version$arch, "x86_64")) ggir_stops(f, "Time gap observed of more than 1 hour")
  expect_error(meta_quiet(ours(f)), "has a page read at 0 Hz")
  # the file's header cut short: GGIR's g.inspectfile() finds no rate
  f <- ga_meta_put(lines[1:40])
  ggir_stops(f, "invalid 'nrow' value")
  expect_error(meta_quiet(ours(f)), "header truncated at byte")
  unlink(clean)
})

test_that("g.getmeta() is GGIR's with every metric, non-wear 2013 and shorter blocks", {
  skip_if_quick()
  skip_if_not_installed("signal")
  f <- meta_recording("cwa", 25, 30, seed = 8)
  pm <- GGIR::load_params()$params_metrics
  for (k in grep("^do[.]", names(pm), value = TRUE)) {
    pm[[k]] <- !k %in% c("do.brondcounts", "do.neishabouricounts")
  }
  b <- meta_both(f, c(cal_args, list(params_metrics = pm,
                                     params_cleaning = list(nonwear_approach = "2013"),
                                     params_rawdata = list(chunksize = 0.3))))
  expect_same_meta(b)
  expect_identical(ncol(b$gravcal$metashort), 31L)
})

test_that("g.getmeta() is GGIR's on a GENEActiv .bin recording, in a zone with an offset", {
  skip_if_quick()
  f <- meta_recording("bin", 50, 28, seed = 9, start = "2024-06-04 22:59:58")
  b <- meta_both(f, c(cal_args, list(params_general = list(desiredtz = "Europe/Amsterdam"),
                                     params_rawdata = list(nonwear_range_threshold = 100))))
  expect_same_meta(b)
  expect_match(b$gravcal$metashort$timestamp[1], "\\+0200$")
  # GGIR's half-size blocks (chunksize 0.5: about 12 h, three blocks over
  # the 28 hours and the carry between them)
  b2 <- meta_both(f, c(cal_args, list(params_general = list(desiredtz = "Europe/Amsterdam"),
                                      params_rawdata = list(nonwear_range_threshold = 100,
                                                            chunksize = 0.5))))
  expect_same_meta(b2)
  # the blocks' edges show (the angles' running median restarts per block)
  expect_false(identical(b2$gravcal$metashort, b$gravcal$metashort))
})

test_that("g.getmeta() is GGIR's without calibration, for a daylimit, and on a file too short", {
  skip_if_quick()
  # slow tier: two more 30-hour recordings; make quick keeps g.getmeta()'s
  # identity on a calibrated .cwa (above)
  f <- meta_recording("cwa", 25, 30, seed = 10)
  expect_same_meta(meta_both(f, list(daylimit = 1)))
  short <- meta_recording("cwa", 25, 1.5, seed = 11)
  b <- meta_both(short, cal_args)
  expect_same_meta(b)
  expect_true(b$gravcal$filetooshort)
})

# Three external functions of GGIR's myfun kind: a mean norm per second in
# mg, averaged to the epoch; two axes every 15 s at 10 Hz (resampled from
# the file's 25), with time stamps, repeated over the epochs; a posture as
# text per epoch, in m/s^2.
meta_myfuns <- function() {
  list(
    per_second = list(
      FUN = function(data, parameters) {
        en <- sqrt(rowSums(data[, 1:3]^2))
        n <- floor(length(en) / 25)
        matrix(colMeans(matrix(en[seq_len(n * 25)], 25)) * parameters, ncol = 1)
      },
      parameters = 2, expected_sample_rate = 25, expected_unit = "mg", colnames = "meanEN",
      minlength = 1, outputres = 1, outputtype = "numeric", aggfunction = mean),
    stamped = list(
      FUN = function(data, parameters) {
        i <- seq(1, floor(nrow(data) / 150) * 150, by = 150)
        cbind(a = data[i, 2] / 3, b = data[i, 1] - data[1, 1])
      },
      parameters = NULL, expected_sample_rate = 10, expected_unit = "g",
      colnames = c("t3", "dt"), minlength = 15, outputres = 15, outputtype = "numeric",
      timestamp = TRUE),
    posture = list(
      FUN = function(data, parameters) {
        i <- seq(1, floor(nrow(data) / 125) * 125, by = 125)
        ifelse(data[i, 3] > 0.5, "up", "down")
      },
      parameters = NULL, expected_sample_rate = 25, expected_unit = "ms2", colnames = "pos",
      minlength = 5, outputres = 5, outputtype = "character"))
}

test_that("g.getmeta() runs an external function (myfun) as GGIR runs it", {
  skip_if_quick()
  skip_if_not_installed("GGIRread")
  # two blocks (30 hours), calibrated with a temperature term
  f <- meta_recording("cwa", 25, 30, seed = 13)
  fns <- meta_myfuns()
  got <- list()
  for (nm in names(fns)) {
    b <- meta_both(f, c(cal_args, list(myfun = fns[[nm]])))
    got[[nm]] <- b$gravcal
    expect_same_meta(b)
    cols <- fns[[nm]]$colnames
    expect_identical(utils::tail(names(b$gravcal$metashort), length(cols)), cols)
    v <- b$gravcal$metashort[[cols[1]]]
    expect_true(sum(!is.na(v)) > 300, label = paste(nm, "has values"))
  }
  # dt: the time stamps the function was given, from its block's first, one
  # value every 15 s repeated over the three 5 s epochs
  expect_identical(got$stamped$metashort$dt[1:7], c(0, 0, 0, 15, 15, 15, 30))
  expect_identical(typeof(got$posture$metashort$pos), "character")
  expect_setequal(unique(got$posture$metashort$pos), c("up", "down"))
})

test_that("g.getmeta() gives Neishabouri's counts as GGIR does (actilifecounts per block)", {
  skip_if_quick()
  skip_if_not_installed("actilifecounts")
  # 8 hours at 50 Hz in blocks of 3.6 hours (chunksize 0.3): the counts'
  # filters restart in each block, as GGIR's call does
  f <- meta_recording("cwa", 50, 8, seed = 21)
  pm <- list(do.neishabouricounts = TRUE, do.enmo = TRUE, do.anglez = TRUE)
  b <- meta_both(f, c(cal_args, list(params_metrics = pm,
                                     params_rawdata = list(chunksize = 0.3))))
  expect_same_meta(b)
  ms <- b$gravcal$metashort
  cn <- paste0("NeishabouriCount_", c("x", "y", "z", "vm"))
  expect_identical(names(ms), c("timestamp", "anglez", "ENMO", cn))
  expect_true(sum(ms$NeishabouriCount_vm > 0, na.rm = TRUE) > 100)
  # the low-frequency extension, and the counts alone (no other metric)
  pm2 <- list(do.neishabouricounts = TRUE, do.enmo = FALSE, do.anglez = FALSE,
              actilife_LFE = TRUE)
  b2 <- meta_both(f, list(params_metrics = pm2, params_rawdata = list(chunksize = 0.3)))
  expect_same_meta(b2)
  expect_identical(names(b2$gravcal$metashort), c("timestamp", cn))
  expect_false(identical(b2$gravcal$metashort$NeishabouriCount_vm, ms$NeishabouriCount_vm))
  # with a myfun: GGIR writes the function's first column over
  # NeishabouriCount_vm and leaves its own last column blank
  skip_if_not_installed("GGIRread")
  mf <- meta_myfuns()$per_second
  b3 <- meta_both(f, c(cal_args, list(params_metrics = pm, myfun = mf,
                                      params_rawdata = list(chunksize = 0.3))))
  expect_same_meta(b3)
  expect_true(all(is.na(b3$gravcal$metashort[[mf$colnames]])))
})

test_that("no metric asked: GGIR stops on a recording's first block, and so does gravcal", {
  # every do.* FALSE: GGIR's g.getmeta() reads the first column of a block's
  # metrics (accmetrics[[1]]) and stops; found by tools/ggir-sweep.R
  none <- GGIR::load_params()$params_metrics
  for (k in grep("^do[.]", names(none), value = TRUE)) none[[k]] <- FALSE
  f <- meta_recording("cwa", 25, 3, seed = 12)
  expect_identical(ggir_error("g.getmeta", f, list(none), {
    I <- meta_quiet(GGIR::g.inspectfile(f))
    meta_quiet(GGIR::g.getmeta(f, params_metrics = none, inspectfileobject = I, verbose = FALSE))
  }), "subscript out of bounds")
  expect_error(gravcal::g.getmeta(f, params_metrics = none, verbose = FALSE),
               "No metric asked: every `do[.][*]` of `params_metrics`")
  # with a myfun and no metric GGIR stops the same way (its metrics, not the
  # function's columns); with Neishabouri's counts alone it does not
  mf <- meta_myfuns()$per_second
  expect_identical(ggir_error("g.getmeta", f, list(none, "myfun: meta_myfuns()$per_second"), {
    I <- meta_quiet(GGIR::g.inspectfile(f))
    meta_quiet(GGIR::g.getmeta(f, params_metrics = none, myfun = mf, inspectfileobject = I,
                               verbose = FALSE))
  }), "subscript out of bounds")
  expect_error(gravcal::g.getmeta(f, params_metrics = none, myfun = mf, verbose = FALSE),
               "No metric asked")
  # a recording too short for a block: GGIR's M (file too short), not an error
  short <- meta_recording("cwa", 25, 0.5, seed = 12)
  b <- meta_both(short, list(params_metrics = none))
  expect_true(b$ggir$filetooshort)
  expect_same_meta(b)
})

test_that("part of one of GGIR's groups of metrics: GGIR stops on it, and so does gravcal", {
  # GGIR's g.applymetrics() gives HFEN with any of HFX, HFY, HFZ, and all
  # three axes of roll_med_acc (dev_roll_med_acc) with any one; g.getmeta()
  # keeps the asked columns and names them all, and stops. Found by
  # tools/ggir-sweep.R (a .gt3x file, roll_med_acc_y and dev_roll_med_acc_y, _z)
  f <- meta_recording("cwa", 25, 3, seed = 12)
  parts <- list(hf = list(do.hfx = TRUE),
                roll = list(do.roll_med_acc_y = TRUE),
                dev = list(do.dev_roll_med_acc_y = TRUE, do.dev_roll_med_acc_z = TRUE))
  said <- c(hf = "`do.hfx` without `do.hfen`",
            roll = "`do.roll_med_acc_y` without `do.roll_med_acc_x`, `do.roll_med_acc_z`",
            dev = "`do.dev_roll_med_acc_y`, `do.dev_roll_med_acc_z` without `do.dev_roll_med_acc_x`")
  for (k in names(parts)) {
    # (the whole list, as meta_both() gives it: GGIR stops elsewhere on one
    # that lacks entries)
    pm <- utils::modifyList(GGIR::load_params()$params_metrics, parts[[k]])
    expect_match(ggir_error("g.getmeta", f, list(pm), {
      I <- meta_quiet(GGIR::g.inspectfile(f))
      meta_quiet(GGIR::g.getmeta(f, params_metrics = pm, inspectfileobject = I, verbose = FALSE))
    }), "'names' attribute \\[[0-9]+\\] must be the same length as the vector", label = k)
    expect_error(gravcal::g.getmeta(f, params_metrics = pm, verbose = FALSE), said[[k]],
                 fixed = TRUE, label = k)
  }
  # a group asked whole is GGIR's M (HFX with HFEN; the three axes)
  whole <- list(do.hfx = TRUE, do.hfen = TRUE, do.roll_med_acc_x = TRUE, do.roll_med_acc_y = TRUE,
                do.roll_med_acc_z = TRUE)
  expect_same_meta(meta_both(f, list(params_metrics = whole)))
  # epoch_signals() is not GGIR's drop-in: it computes what it is asked
  ep <- epoch_signals(f, metrics = c("HFX", "roll_med_acc_y"), se = FALSE)
  expect_identical(names(ep$short), c("time", "HFX", "roll_med_acc_y"))
})

test_that("a myfun GGIR would stop on is an error naming what is wrong", {
  f <- meta_recording("cwa", 25, 3, seed = 12)
  mf <- meta_myfuns()$per_second
  bad <- function(...) utils::modifyList(mf, list(...))
  expect_error(gravcal::g.getmeta(f, myfun = list(FUN = mean), verbose = FALSE),
               "`myfun`: lacks `parameters`")
  expect_error(gravcal::g.getmeta(f, myfun = c(mf, list(extra = 1)), verbose = FALSE),
               "unexpected element `extra`")
  expect_error(gravcal::g.getmeta(f, myfun = bad(expected_unit = "kg"), verbose = FALSE),
               "expected_unit")
  expect_error(gravcal::g.getmeta(f, myfun = bad(outputres = 3), verbose = FALSE),
               "multiples")
  expect_error(gravcal::g.getmeta(f, myfun = bad(outputtype = NULL), verbose = FALSE),
               "outputtype")
  expect_error(gravcal::g.getmeta(f, myfun = bad(aggfunction = NULL), verbose = FALSE),
               "aggfunction")
  expect_error(gravcal::g.getmeta(f, myfun = bad(colnames = c("a", "b")), verbose = FALSE),
               "gave 1 column but `colnames` names 2")
})

test_that("g.getmeta() refuses what it does not compute, naming it", {
  f <- meta_recording("cwa", 25, 3, seed = 12)
  expect_error(gravcal::g.getmeta(f, do.brondcounts = TRUE, verbose = FALSE),
               "do.brondcounts")
  expect_error(gravcal::g.getmeta(f, actilife_LFE = NA, verbose = FALSE), "actilife_LFE")
  expect_error(gravcal::g.getmeta(f, windowsizes = c(5, 900), verbose = FALSE), "windowsizes")
  expect_error(gravcal::g.getmeta(f, nonwear_approach = "2019", verbose = FALSE),
               "nonwear_approach")
  expect_error(gravcal::g.getmeta(f, nonwear_approach = 2019, verbose = FALSE),
               "nonwear_approach")
  # a number (GGIR's config.csv read back gives 2023, and GGIR's own
  # test_recordingEndSleepHour.R runs part 1 so): GGIR's %in% and == read
  # it as its text, and so does gravcal
  for (a in c("2013", "2023")) {
    M1 <- gravcal::g.getmeta(f, nonwear_approach = as.numeric(a), verbose = FALSE)
    M2 <- gravcal::g.getmeta(f, nonwear_approach = a, verbose = FALSE)
    M1$bsc_qc <- M2$bsc_qc <- NULL
    expect_identical(M1, M2)
  }
  expect_error(gravcal::g.getmeta(f, offset = c(0, 0), verbose = FALSE), "offset")
  expect_error(gravcal::g.getmeta(f, rmc.firstrow.acc = 2, verbose = FALSE), "rmc.col.time")
  expect_warning(gravcal::g.getmeta(f, do.enmoo = TRUE, verbose = FALSE), "`do.enmoo`")
})

test_that("g.getmeta() on an Axivity csv export is GGIR's (each block resampled)", {
  skip_if_quick()
  skip_if_not_installed("GGIRread")
  skip_if_not_installed("data.table")
  rec <- simulate_recording(hours = 30, sf = 10, seed = 21, temperature = FALSE)
  f <- tempfile(fileext = ".csv")
  # clocks off the 10 Hz GGIR takes them for: every block resampled onto it
  for (true_sf in c(10.03, 13.1)) {
    gravcal:::write_axivity_csv(rec, f, true_sf = true_sf)
    b <- meta_both(f, list(params_general = list(desiredtz = "Europe/Amsterdam")))
    expect_same_meta(b)
    expect_identical(b$gravcal$metashort$timestamp[1], "2024-01-01T00:00:00+0100")
  }
  # 10 minutes and 3 hours of lines missing: GGIR's resampling bridges them
  # within a block
  L <- readLines(f)
  n <- length(L)
  writeLines(L[-c(round(0.3 * n) + 0:6000, round(0.6 * n) + 0:108000)], f)
  b <- meta_both(f, cal_args[c("offset", "scale")])
  expect_same_meta(b)
  expect_lt(nrow(b$gravcal$metashort), 30 * 720)
  # text and ISO 8601 stamps, a first stamp a fraction of a second past the
  # whole second, in zones (GGIR forces fread()'s date-times into the zone,
  # reads other text in it with as.POSIXct(): the decoder does both, and
  # the block logic must not move them again; gravcal gave each stamp the
  # zone's offset twice, and the fraction once more)
  short <- simulate_recording(hours = 5, sf = 10, seed = 22, temperature = FALSE)
  t0 <- as.POSIXct("2024-01-01 00:07:00", tz = "UTC") + 0.25
  styles <- list(
    list(tz = "Asia/Kolkata"),                                          # 2024-01-01 00:07:00.250
    list(tz = "Europe/Amsterdam", time_format = "%Y/%m/%d %H:%M:%S"),   # as.POSIXct()'s path
    list(tz = "Europe/Amsterdam", suffix = "Z", decimals = 2),
    list(tz = "Asia/Kolkata", suffix = "+01:00"),
    list(tz = "Europe/Amsterdam", start = "2024-03-30 23:00:00",        # across the spring change
         time_format = "%Y/%m/%d %H:%M:%S"))
  for (s in styles) {
    do.call(gravcal:::write_axivity_csv,
            c(list(short, f, true_sf = 10.03, stamps = "text", start = s$start %||% t0),
              s[setdiff(names(s), c("tz", "start"))]))
    b <- meta_both(f, list(params_general = list(desiredtz = s$tz)))
    expect_same_meta(b)
    if (is.null(s$suffix)) {
      at <- if (is.null(s$start)) "2024-01-01T00:15:00" else "2024-03-30T23:00:00"
      expect_identical(substr(b$gravcal$metashort$timestamp[1], 1, 19), at)
    }
  }
  # UNIX and ISO 8601 stamps across Europe/Amsterdam's changes, which GGIR
  # forces into the zone (gravcal refused these). Autumn (2024-10-27, 01:00
  # UTC): the clock times after 02:00, which exist twice, at the later
  # offset, so that the stamps jump an hour ahead there and GGIR's
  # resampling fills that hour: the lines span 4.99 hours (5 hours of
  # samples at 10.03 Hz), the grid 5.99, whose whole long epochs are 5.75
  # hours of short ones (4.75 without the hour). Spring (2024-03-31): the
  # stamps of 02:00 to 03:00 NA, where GGIRread::resample()'s search stops,
  # so that every sample after them in the block is NA, and so are the
  # epochs' ENMO and EN
  for (st in c("unix", "text")) {
    gravcal:::write_axivity_csv(short, f, true_sf = 10.03, stamps = st,
                                start = "2024-10-27 00:00:00")
    b <- meta_both(f, list(params_general = list(desiredtz = "Europe/Amsterdam")))
    expect_same_meta(b)
    expect_identical(b$gravcal$metashort$timestamp[1], "2024-10-27T00:00:00+0200")
    expect_identical(nrow(b$gravcal$metashort), 23L * 180L)
    gravcal:::write_axivity_csv(short, f, true_sf = 10.03, stamps = st,
                                start = "2024-03-31 00:00:00")
    b <- meta_both(f, list(params_general = list(desiredtz = "Europe/Amsterdam")))
    expect_same_meta(b)
    na <- is.na(b$gravcal$metashort$ENMO)
    expect_true(any(na) && !all(na), label = paste(st, "some ENMO NA"))
    en <- b$gravcal$metalong$EN
    expect_true(!anyNA(en[1:7]) && all(is.na(en[-(1:8)])), label = paste(st, "EN NA after 02:00"))
  }
  # 8 hours of UNIX stamps from 22:47:13 UTC, chunksize 0.1: a non-wear
  # window of the block after the skipped hour holds one value that is not
  # NA, whose sd() is NA, on which GGIR's if() stops; gravcal's g.getmeta()
  # gave an M (found by probing 24 exports: three kinds of stamp, two
  # zones, both changes, chunksize 0.1 and 0.25)
  eight <- simulate_recording(hours = 8, sf = 10, seed = 31, temperature = FALSE)
  gravcal:::write_axivity_csv(eight, f, true_sf = 10.03, stamps = "unix",
                              start = "2024-03-30 22:47:13")
  pg <- utils::modifyList(GGIR::load_params()$params_general, list(desiredtz = "Europe/Amsterdam"))
  pr <- utils::modifyList(GGIR::load_params()$params_rawdata, list(chunksize = 0.1))
  expect_match(ggir_error("g.getmeta", f, list(pr, pg), {
    I <- meta_quiet(GGIR::g.inspectfile(f, params_rawdata = pr, params_general = pg))
    keep_warn(meta_quiet(GGIR::g.getmeta(f, params_rawdata = pr, params_general = pg,
                                         inspectfileobject = I, verbose = FALSE)))
  }), "missing value where TRUE/FALSE needed", fixed = TRUE)
  expect_error(meta_quiet(gravcal::g.getmeta(f, params_rawdata = pr, params_general = pg,
                                             verbose = FALSE)),
               "holds one value that is not NA: GGIR's g.getmeta() stops there too", fixed = TRUE)
  # text stamps read in the zone, a block of GGIR's (chunksize 0.1: 87,000
  # lines, 2.4 hours) starting at 02:34 on 2024-10-27, a time that exists
  # twice in Europe/Amsterdam: refused as g.calibrate() refuses it (GGIR's
  # time there depends on R's conversions before it; gravcal's g.getmeta()
  # gave an M that was not GGIR's, silently)
  gravcal:::write_axivity_csv(short, f, true_sf = 10.03, stamps = "text",
                              time_format = "%Y/%m/%d %H:%M:%S", start = "2024-10-27 00:10:00")
  expect_error(meta_quiet(gravcal::g.getmeta(f, params_general = list(desiredtz = "Europe/Amsterdam"),
                                             params_rawdata = list(chunksize = 0.1), verbose = FALSE)),
               "`desiredtz` = \"Europe/Amsterdam\": a block of GGIR's reading of this file starts or ends at a time that exists twice",
               fixed = TRUE)
  # GGIR's own test file: too short for GGIR, and for gravcal
  csv <- system.file("testfiles", "ax3_testfile_unix_timestamps.csv", package = "GGIR")
  b <- meta_both(csv)
  expect_same_meta(b)
  expect_true(b$gravcal$filetooshort)
})

test_that("g.getmeta() is GGIR's on real free-living data (agcounts' 20.7 h of an ActiGraph)", {
  skip_if_quick()
  skip_if_not_installed("signal")
  # ../shared/data/agcounts: 2,239,620 samples at 30 Hz of a worn
  # ActiGraph (bhelsel/agcounts), written as the .gt3x the device would
  # have made (1/256 g counts), calibrated with GGIR's own coefficients for
  # it (ggirCalibrate.RData: g.calibrate() on these samples), in blocks of
  # 4.8 h, with the filtered metrics on real movement
  e <- new.env()
  for (a in c("X", "Y", "Z")) {
    load(skip_if_no_shared("agcounts", sprintf("calibration%saxis.RData", a)), envir = e)
  }
  load(skip_if_no_shared("agcounts", "ggirCalibrate.RData"), envir = e)
  f <- tempfile(fileext = ".gt3x")
  write_recording(data.frame(x = e$X, y = e$Y, z = e$Z), f, sf = 30,
                  start = "2024-05-06 08:00:00")
  args <- list(offset = e$C$offset, scale = e$C$scale,
               params_metrics = list(do.enmo = TRUE, do.anglez = TRUE, do.mad = TRUE,
                                     do.bfen = TRUE, do.hfenplus = TRUE, do.lfenmo = TRUE),
               params_rawdata = list(chunksize = 0.4),
               params_general = list(desiredtz = "America/Chicago"))
  b <- meta_both(f, args)
  expect_same_meta(b)
  # what the comparison saw: a day of real wear, in several blocks, with
  # movement (ENMO above 100 mg) and rest
  M <- b$gravcal
  expect_gt(nrow(M$metashort), 20 * 720)
  expect_gt(sum(M$metashort$ENMO > 0.1), 100)
  expect_gt(sum(M$metashort$ENMO < 0.01), 1000)
  expect_identical(names(M$metashort),
                   c("timestamp", "BFEN", "LFENMO", "HFENplus", "anglez", "ENMO", "MAD"))
  unlink(f)
})

test_that("g.getmeta() is GGIR's on a .gt3x recording with idle sleep (time gaps imputed)", {
  skip_if_quick()
  rec <- simulate_recording(hours = 28, sf = 30, seed = 13,
                            start = as.POSIXct("2024-03-04 09:07:23", tz = "UTC"))
  f <- tempfile(fileext = ".gt3x")
  # idle sleep (seconds without records): 30 min, 1 min, 5 s, and 3 s at the
  # start of GGIR's second block (24 h of stored seconds later)
  idle <- c(3600 * 15 + 0:1800, 3600 * 20 + 0:59, 3600 * 25 + 0:4, 3600 * 24.6 + 0:2)
  gravcal:::write_gt3x(as.matrix(rec[, c("x", "y", "z")]), f, sf = 30, start = rec$time[1],
                       idle = idle)
  b <- meta_both(f, cal_args[c("offset", "scale")])
  expect_same_meta(b)
  # the gaps were imputed: GGIR's QClog counts them per block
  expect_identical(sum(b$gravcal$QClog$timegaps_n), 4L)
  b2 <- meta_both(f, list(params_general = list(desiredtz = "America/New_York"),
                          params_metrics = list(do.anglex = TRUE)))
  expect_same_meta(b2)
  expect_match(b2$gravcal$metashort$timestamp[1], "-0500$")
})

test_that("g.getmeta() is GGIR's on a .gt3x recording across a daylight-saving change (the clock's jump filled as a gap)", {
  skip_if_quick()
  # 2024-10-27 03:00 in Amsterdam: GGIR's reader reads the file's clock in
  # the zone sample by sample, so that the clock time 03:00 after 02:59:59
  # (an hour taken as summer time, the next as winter time) jumps by an
  # hour, and g.imputeTimegaps() fills the jump as a time gap (the
  # decoder's clock table, meta_clock_table())
  rec <- simulate_recording(hours = 30, sf = 10, seed = 23,
                            start = as.POSIXct("2024-10-26 12:03:07", tz = "UTC"))
  f <- tempfile(fileext = ".gt3x")
  on.exit(unlink(f))
  gravcal:::write_gt3x(as.matrix(rec[, c("x", "y", "z")]), f, sf = 10, start = rec$time[1],
                       idle = 3600 * 20 + 0:40)
  b <- meta_both(f, list(params_general = list(desiredtz = "Europe/Amsterdam")))
  expect_same_meta(b)
  # the idle 41 s and the clock's hour
  expect_gt(sum(b$gravcal$QClog$timegaps_min), 60)
  expect_identical(sum(b$gravcal$QClog$timegaps_n), 2L)
  # and in spring (2024-03-31 02:00), where the clock steps back: no gap
  rec$time <- rec$time - as.difftime(210, units = "days")
  gravcal:::write_gt3x(as.matrix(rec[, c("x", "y", "z")]), f, sf = 10, start = rec$time[1],
                       idle = 3600 * 20 + 0:40)
  b <- meta_both(f, list(params_general = list(desiredtz = "Europe/Amsterdam")))
  expect_same_meta(b)
  expect_identical(sum(b$gravcal$QClog$timegaps_n), 1L)
})

test_that("g.getmeta() takes an ActiGraph's dynamic range from its serial number, as GGIR", {
  skip_if_quick()
  rec <- simulate_recording(hours = 27, sf = 30, seed = 15,
                            start = as.POSIXct("2024-03-04 09:07:23", tz = "UTC"))
  n <- nrow(rec)
  rec$x[round(0.3 * n) + 0:60] <- 5.8   # beyond a CLE's 6 g - 0.5, within 8 g - 0.5
  f <- tempfile(fileext = ".gt3x")
  gravcal:::write_gt3x(as.matrix(rec[, c("x", "y", "z")]), f, sf = 30, start = rec$time[1],
                       serial = "CLE2A2123456")
  b <- meta_both(f, list(params_rawdata = list(dynrange = 8)))
  expect_same_meta(b)
  expect_true(any(b$gravcal$metalong$clippingscore > 0))
})

test_that("g.getmeta() is GGIR's on an ActiGraph csv export (start from its header, zeros and gaps)", {
  skip_if_quick()
  rec <- simulate_recording(hours = 27, sf = 30, seed = 16,
                            start = as.POSIXct("2024-03-04 09:07:23", tz = "UTC"))
  n <- nrow(rec)
  # 10 minutes and 4 samples of idle-sleep zeros: removed, then filled as gaps
  for (i in list(round(0.4 * n) + 0:(30 * 600), round(0.7 * n) + 0:3)) {
    rec$x[i] <- 0
    rec$y[i] <- 0
    rec$z[i] <- 0
  }
  f <- tempfile(fileext = ".csv")
  gravcal:::write_actigraph_csv(rec, f, sf = 30, start = "2024-03-04 09:07:23")
  b <- meta_both(f, c(cal_args[c("offset", "scale")],
                      list(params_general = list(desiredtz = "Europe/London"))))
  expect_same_meta(b, clock = TRUE)
  expect_identical(b$gravcal$metashort$timestamp[1], "2024-03-04T09:15:00+0000")
  expect_identical(b$gravcal$QClog$timegaps_n, c(1L, 0L))
})

test_that("ActiLife epoch exports (counts, not samples): GGIR's inspection stops, gravcal's g.getmeta() refuses", {
  # GGIR's own test files: "Epoch Period (hh:mm:ss)" 00:00:15, 00:00:05 and
  # 00:00:01, no "at N Hz"; before, gravcal read the counts as g (an M of
  # 2,880 rows for ActiGraph13.csv, NaN in every other row). Found by
  # tools/ggir-sweep.R
  for (nm in c("ActiGraph13.csv", "ActiGraph61.csv", "ActiGraph13_timestamps_headers.csv")) {
    f <- system.file("testfiles", nm, package = "GGIR")
    expect_true(file.exists(f), label = nm)
    expect_false(is.na(ggir_error("g.inspectfile", f, list(), {
      meta_quiet(GGIR::g.inspectfile(f))
    })), label = paste(nm, "(GGIR's g.inspectfile() stops)"))
    expect_error(gravcal::g.getmeta(f, verbose = FALSE),
                 "ActiLife epoch export \\(\"Epoch Period \\(hh:mm:ss\\) 00:00:[0-9]+\" and no",
                 label = nm)
  }
})

test_that("the date order of an ActiGraph header, by GGIR's rules", {
  top <- function(fmt) make.names(paste("--- date format", fmt, "Filter Normal ---"))
  expect_identical(gravcal:::actigraph_date_order(top("M/d/yyyy")), "mdY")
  expect_identical(gravcal:::actigraph_date_order(top("dd.MM.yyyy")), "dmY")
  expect_identical(gravcal:::actigraph_date_order(top("yyyy-MM-dd")), "Ymd")
  expect_identical(gravcal:::actigraph_date_order(top("d-MMM-yy")), "dby")
  expect_identical(gravcal:::actigraph_date_order(top("MMM/dd/yyyy")), "bdY")
  expect_identical(gravcal:::actigraph_date_order(top("none")), NA_character_)
})

# GGIR 3.3-9 imputes a time gap over its limit (90 minutes) at epoch level,
# reading the gap's time of day with data.table::hour() of a number: R
# before 4.3 stops there (as.POSIXlt() wants an origin). On such an R,
# GGIR's result is computed with as.POSIXlt() of a number given R 4.3's
# default (read from 1970, in the session's zone), put back afterwards.
with_r43_posixlt <- function(expr) {
  if (getRversion() >= "4.3.0") return(expr)
  base <- baseenv()
  old <- get("as.POSIXlt.numeric", envir = base)
  put <- function(f) {
    unlockBinding("as.POSIXlt.numeric", base)
    assign("as.POSIXlt.numeric", f, envir = base)
    lockBinding("as.POSIXlt.numeric", base)
    registerS3method("as.POSIXlt", "numeric", f, envir = base)
  }
  put(function(x, tz = "", origin, ...) {
    if (missing(origin)) return(as.POSIXlt(.POSIXct(x, tz), tz = tz))
    as.POSIXlt(as.POSIXct(origin, tz = "GMT", ...) + x, tz = tz)
  })
  on.exit(put(old), add = TRUE)
  expr
}

test_that("time gaps over GGIR's limit are imputed as whole epochs, as GGIR does", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  # .gt3x weeks' nights of idle sleep: two gaps in a block, one a few
  # seconds after the other; a gap across a block's end; across a change of
  # clock (Amsterdam, New York); other windowsizes; a zone off the hour
  cases <- list(
    list(h = 60, sf = 10, start = "2024-03-30 20:13:07", tz = "Europe/Amsterdam",
         ws = c(5, 900, 3600), idle = c(3600 * 3 + 0:(2 * 3600 + 123), 3600 * 10 + 0:(95 * 60),
                                        3600 * 10 + 95 * 60 + 30 + 0:(100 * 60))),
    list(h = 50, sf = 30, start = "2024-11-02 22:00:03", tz = "America/New_York",
         ws = c(5, 900, 3600), idle = c(3600 * 20 + 0:(5 * 3600 + 17), 3600 * 30 + 0:(91 * 60 + 1))),
    list(h = 40, sf = 10, start = "2024-06-01 10:00:00", tz = "", ws = c(10, 600, 3600),
         idle = 3600 * 23 + 0:(3 * 3600 + 7)),
    list(h = 40, sf = 10, start = "2024-06-01 10:00:00", tz = "Asia/Kolkata",
         ws = c(5, 900, 3600), idle = 3600 * 23.9 + 0:(3 * 3600 + 7)))
  for (k in seq_along(cases)) {
    cc <- cases[[k]]
    rec <- simulate_recording(hours = cc$h, sf = cc$sf, seed = 20 + k)
    f <- tempfile(fileext = ".gt3x")
    gravcal:::write_gt3x(as.matrix(rec[, c("x", "y", "z")]), f, sf = cc$sf,
                         start = as.POSIXct(cc$start, tz = "UTC"), idle = cc$idle)
    args <- list(desiredtz = cc$tz, windowsizes = cc$ws, do.en = TRUE, do.mad = TRUE)
    G <- ggir_cached("g.getmeta", f, c(args, list(posixlt = "R 4.3")), {
      I <- meta_quiet(GGIR::g.inspectfile(f, desiredtz = cc$tz))
      with_r43_posixlt(meta_quiet(do.call(GGIR::g.getmeta, c(list(f, inspectfileobject = I,
                                                                  verbose = FALSE), args))))
    })
    R <- meta_quiet(do.call(gravcal::g.getmeta, c(list(f, verbose = FALSE), args)))
    expect_same_meta(list(ggir = G, gravcal = R))
    # what the comparison saw: the gaps' long epochs non-wear (3), their
    # short epochs' ENMO 0 and EN 1
    gaps <- R$metalong$nonwearscore == 3
    expect_gt(sum(gaps), 6)
    expect_true(all(R$QClog$timegaps_min[R$QClog$imputed] > 90))
    expect_gt(sum(R$metashort$EN == 1 & R$metashort$ENMO == 0), 0.5 * sum(gaps) * cc$ws[2] / cc$ws[1])
  }
})

test_that("the zone GGIR reads a long gap's time of day in, by R version", {
  start <- as.numeric(as.POSIXct("2024-03-30 12:00:00", tz = "UTC"))
  expect_identical(gravcal:::meta_local_zone(start, version = c("4", "1.3")), "")
  expect_identical(gravcal:::meta_local_zone(start, version = c("4", "2.0")), "")
  withr_tz <- function(tz, expr) {
    old <- Sys.getenv("TZ", unset = NA)
    Sys.setenv(TZ = tz)
    on.exit(if (is.na(old)) Sys.unsetenv("TZ") else Sys.setenv(TZ = old))
    expr
  }
  expect_identical(withr_tz("UTC", gravcal:::meta_local_zone(start, version = c("4", "3.1"))), "")
  z <- withr_tz("Europe/Amsterdam", gravcal:::meta_local_zone(start, 10, c("4", "4.0")))
  v <- as.numeric(strsplit(z, " ", fixed = TRUE)[[1]])
  # 1 h before the change (Sunday 31 March, 01:00 UTC), 2 h from it
  expect_identical(v[c(2, 4)], c(3600, 7200))
  expect_identical(v[3], as.numeric(as.POSIXct("2024-03-31 01:00:00", tz = "UTC")))
})

test_that("g.getmeta() is GGIR's on a Movisens recording (start from unisens.xml)", {
  skip_if_quick()
  skip_if_not_installed("unisensR")
  rec <- simulate_recording(hours = 27, sf = 64, seed = 17,
                            start = as.POSIXct("2024-03-04 09:07:23", tz = "UTC"))
  d <- tempfile("movisens-")
  dir.create(d)
  gravcal:::write_movisens(rec[, c("x", "y", "z")], d, sf = 64, start = "2024-03-04 09:07:23",
                           temperature = rec$temperature[seq(1, nrow(rec), by = 64)])
  f <- file.path(d, "acc.bin")
  b <- meta_both(f, cal_args)
  expect_same_meta(b)
  b2 <- meta_both(f, list(params_general = list(desiredtz = "Europe/Amsterdam",
                                                configtz = "Europe/Amsterdam")))
  expect_same_meta(b2)
  expect_identical(b2$gravcal$metashort$timestamp[1], "2024-03-04T09:15:00+0100")
  expect_true("temperaturemean" %in% names(b$gravcal$metalong))
})

# Parmay Matrix: GGIRread's reader gives the whole file as GGIR's one block,
# its time stamps the packets' UTC seconds (configtz changes nothing), the
# dynamic range from the header (the clipping threshold, whatever dynrange
# says), and its log of the packets, which GGIR keeps as M$QClog.
mtx_test_files <- function() {
  skip_if_not_installed("GGIRread")
  td <- system.file("testfiles", package = "GGIRread")
  f <- list.files(td, pattern = "^mtx_.*Hz.*[.]BIN$", full.names = TRUE)
  f <- c(f, file.path(td, "mtx_corrupted.bin"))
  f <- f[file.exists(f)]
  if (length(f) < 5) skip("GGIRread has not its Matrix test files")
  f
}

test_that("g.getmeta() is GGIR's on GGIRread's Parmay Matrix test files", {
  skip_if_not_installed("GGIR")
  n <- 0
  for (f in mtx_test_files()) {
    for (it in 1:2) {
      # minutes of data: 1-minute long epochs, a 2-minute non-wear window
      b <- meta_both(f, list(params_general = list(windowsizes = c(5, 60, 120)),
                             params_rawdata = list(interpolationType = it)))
      expect_same_meta(b)
      n <- n + 1
    }
  }
  expect_identical(n, 10)
  # what the comparison saw: epochs (but for the file of under 4 minutes,
  # too short for GGIR), the temperature column, the packets' log with the
  # damaged one (its checksum failed, GGIR's reader keeps it as (0, 0, 1) g)
  M <- meta_both(mtx_test_files()[1], list(params_general = list(windowsizes = c(5, 60, 120))))$gravcal
  expect_gt(nrow(M$metashort), 50)
  expect_true("temperaturemean" %in% names(M$metalong))
  expect_identical(nrow(M$QClog), 4L)
  short <- meta_both(grep("gyro", mtx_test_files(), value = TRUE),
                     list(params_general = list(windowsizes = c(5, 60, 120))))$gravcal
  expect_true(short$filetooshort)
  expect_null(short$QClog)
  bad <- meta_both(grep("corrupted", mtx_test_files(), value = TRUE),
                   list(params_general = list(windowsizes = c(5, 60, 120))))$gravcal
  expect_identical(bad$QClog$checksum_pass, c(FALSE, TRUE, TRUE, TRUE))
})

test_that("g.getmeta() is GGIR's on hours written as a Parmay Matrix file: calibrated, in a zone, across a clock change", {
  skip_if_quick()
  skip_if_not_installed("GGIRread")
  # 24 hours at 25 Hz from 2024-03-31 00:07:23 UTC: Amsterdam's clock
  # moves forward at 01:00 UTC; rest on a table for over 1.5 hours
  # (non-wear) and samples at 7.9 g (clipping)
  f <- meta_recording("parmay", 25, 24, seed = 31, start = "2024-03-31 00:07:23")
  b <- meta_both(f, c(cal_args, list(params_general = list(desiredtz = "Europe/Amsterdam"))))
  expect_same_meta(b)
  M <- b$gravcal
  expect_identical(M$metashort$timestamp[1], "2024-03-31T01:15:00+0100")
  expect_match(M$metashort$timestamp[nrow(M$metashort)], "\\+0200$")
  expect_gt(nrow(M$metashort), 23 * 720)
  expect_true(any(M$metalong$nonwearscore >= 2))
  expect_true(any(M$metalong$clippingscore > 0))
  expect_true("temperaturemean" %in% names(M$metalong))
  expect_identical(nrow(M$QClog), 720L)
  expect_true(all(M$QClog$checksum_pass))
  # configtz: GGIR's reader of these files reads no clock in a zone
  b2 <- meta_both(f, c(cal_args, list(params_general = list(desiredtz = "Europe/Amsterdam",
                                                            configtz = "America/New_York",
                                                            windowsizes = c(5, 600, 1200)))))
  expect_same_meta(b2)
  expect_identical(b2$gravcal$metashort$timestamp[1], "2024-03-31T01:10:00+0100")
  # an external function with time stamps (the one block's, from its start)
  mf <- meta_myfuns()$stamped
  b3 <- meta_both(f, list(myfun = mf, params_general = list(windowsizes = c(5, 600, 1200))))
  expect_same_meta(b3)
  expect_gt(sum(!is.na(b3$gravcal$metashort$t3)), 1000)
})

test_that("g.getmeta() takes a Parmay Matrix's dynamic range from its header, as GGIR", {
  skip_if_quick()
  skip_if_not_installed("GGIRread")
  # a range of 4 g: the 7.9 g samples stored as 4 g, over GGIR's 3.5 g
  # threshold (clipping), under 7.5 (dynrange's, which GGIR sets aside)
  f <- tempfile(fileext = ".BIN")
  write_meta_recording(f, "parmay", 12.5, 5, 32, "2024-03-04 09:07:23", range = 4)
  b <- meta_both(f, list(params_rawdata = list(dynrange = 8, interpolationType = 2)))
  expect_same_meta(b)
  expect_true(any(b$gravcal$metalong$clippingscore > 0))
})

# `b` with packet k's header times moved by `by` seconds from packet k on
# and their checksums made again (a device that paused between packets).
mtx_shift_packets <- function(b, k, by) {
  starts <- grepRaw("MDTCPACK", b, fixed = TRUE, all = TRUE)
  ends <- c(starts[-1] - 1, length(b))
  for (i in k:length(starts)) {
    at <- starts[i]
    for (o in c(12, 16)) {
      v <- readBin(b[at + o + 0:3], "integer", size = 4, endian = "little")
      b[at + o + 0:3] <- gravcal:::parmay_le(v + by, 4)
    }
    b[at + 8:11] <- gravcal:::parmay_le(gravcal:::gc_crc32(b[(at + 12):ends[i]]), 4)
  }
  b
}

test_that("g.getmeta() on damaged Parmay Matrix files: GGIR's result where GGIR gives one", {
  skip_if_quick()
  skip_if_not_installed("GGIRread")
  f <- meta_recording("parmay", 25, 8, seed = 33, start = "2024-05-06 10:00:03")
  b <- readBin(f, raw(), file.size(f))
  starts <- grepRaw("MDTCPACK", b, fixed = TRUE, all = TRUE)
  args <- c(cal_args, list(params_general = list(desiredtz = "Europe/Amsterdam",
                                                 windowsizes = c(5, 600, 1200))))
  g <- tempfile(fileext = ".BIN")
  on.exit(unlink(g))
  put <- function(bytes) {
    writeBin(bytes, g)
    g
  }
  # a byte of packet 100 changed: its checksum fails, GGIR's reader keeps
  # its samples as (0, 0, 1) g and its temperature from its neighbours
  b1 <- b
  b1[starts[100] + 500] <- xor(b1[starts[100] + 500], as.raw(0x5a))
  m <- meta_both(put(b1), args)
  expect_same_meta(m)
  expect_identical(which(!m$gravcal$QClog$checksum_pass), 100L)
  expect_identical(which(m$gravcal$QClog$imputed), 100L)
  # cut inside packet 200's samples: the rest of that packet as GGIR's
  # reader reads what the file holds
  m <- meta_both(put(b[seq_len(starts[200] + 1000)]), args)
  expect_same_meta(m)
  expect_identical(nrow(m$gravcal$QClog), 200L)
  # a pause of 7 s before packet 150: GGIR's reader moves that packet's
  # start back to the end of the one before (its log says by how much)
  m <- meta_both(put(mtx_shift_packets(b, 150, 7)), args)
  expect_same_meta(m)
  q <- m$gravcal$QClog
  expect_identical(q$gap_with_previous_block_secs[150], 7)
  expect_identical(q$start_time_adjustment_secs[150], -7)
  expect_identical(sum(q$gap_with_previous_block_secs != 0), 1L)
})

test_that("g.getmeta() refuses the Parmay Matrix files GGIR's reader fails on, saying why", {
  skip_if_not_installed("GGIR")
  f <- grep("12.5Hz_acc[.]BIN", mtx_test_files(), value = TRUE)
  b <- readBin(f, raw(), file.size(f))
  starts <- grepRaw("MDTCPACK", b, fixed = TRUE, all = TRUE)
  g <- tempfile(fileext = ".BIN")
  on.exit(unlink(g))
  ggir <- function() {
    meta_quiet(GGIR::g.getmeta(g, inspectfileobject = meta_quiet(GGIR::g.inspectfile(g)),
                               verbose = FALSE, windowsizes = c(5, 60, 120)))
  }
  grav <- function() gravcal::g.getmeta(g, verbose = FALSE, windowsizes = c(5, 60, 120))
  # cut inside the second packet's header
  writeBin(b[seq_len(starts[2] + 20)], g)
  expect_error(ggir())
  expect_error(grav(), "`datafile`\\) has a packet cut inside its header at its end")
  # a short packet within the file (GGIR's reader reads on into the next)
  writeBin(c(b[seq_len(starts[2] + 20)], b[starts[2]:length(b)]), g)
  expect_error(grav(), "too short for its header within it")
  # a negative sample count
  b2 <- b
  b2[starts[2] + 20:23] <- as.raw(0xff)
  writeBin(b2, g)
  expect_error(ggir())
  expect_error(grav(), "a negative sample count \\(GGIR's reader fails on it")
  # a header that declares no packet
  b3 <- b
  b3[517:520] <- as.raw(0)
  writeBin(b3, g)
  expect_error(ggir())
  expect_error(grav(), "declares 0 packets.*gravcal's refuses the file")
  # no accelerometer sample in any packet: GGIR's "file empty" result
  b4 <- b
  for (at in starts) b4[at + 20:23] <- as.raw(0)
  writeBin(b4, g)
  m <- list(ggir = ggir(), gravcal = meta_quiet(grav()))
  expect_same_meta(m)
  expect_true(m$gravcal$filecorrupt)
  # and the file itself is GGIR's
  writeBin(b, g)
  expect_same_meta(list(ggir = ggir(), gravcal = meta_quiet(grav())))
})

# An ad hoc csv recording (GGIR's rmc.* files) for g.getmeta(): `hours` of
# simulated samples with 72 minutes flat on a table (GGIR's non-wear) and 41
# samples at 7.9 g (clipped beyond rmc.dynamic_range = 6), written by
# write_adhoc_csv() after two free header lines at `true_sf` Hz, lines
# `drop` left out (time gaps) and samples `zeros` set to 0, 0, 0. Returns
# the file and its rmc.* list with chunksize 0.1 (at 10 Hz, GGIR's blocks
# of g.getmeta() are 87000 lines: a recording of 4 hours is two of them).
# `wear`: a function of the number of samples giving a wear column's text
# (rmc.col.wear), or NULL.
meta_adhoc <- function(..., hours = 4, true_sf = 10, seed = 31, drop = integer(),
                       zeros = integer(), wear = NULL) {
  rec <- simulate_recording(hours = hours, sf = 10, seed = seed,
                            tempoffset = c(0.001, -0.002, 0.0005))
  n <- nrow(rec)
  i <- round(0.3 * n):round(0.6 * n)
  rec$x[i] <- 0.02 + 0.001 * sin(i)
  rec$y[i] <- -0.01 + 0.001 * cos(i)
  rec$z[i] <- 0.99 + 0.001 * sin(i / 3)
  rec$x[round(0.8 * n) + 0:40] <- 7.9
  rec[zeros, c("x", "y", "z")] <- 0
  f <- tempfile(fileext = ".csv")
  pr <- gravcal:::write_adhoc_csv(rec, f, sf = true_sf, header = c("device,sim", "serial,S1"),
                                  drop = drop, wear = if (!is.null(wear)) wear(n), ...)
  list(file = f, pr = c(pr, list(chunksize = 0.1)))
}

test_that("g.getmeta() is GGIR's on ad hoc csv files: units, time columns, header, zones", {
  skip_if_quick()
  skip_if_not_installed("data.table")
  # mg after free header lines, UNIX seconds, temperature: calibrated with
  # a temperature term; GGIR's default rmc.noise (13: non-wear by the range
  # alone), no clipping threshold (no rmc.dynamic_range: GGIR's clipping
  # score is 0)
  a <- meta_adhoc(unit = "mg", time = "UNIXsec")
  b <- meta_both(a$file, c(list(params_rawdata = a$pr), cal_args))
  expect_same_meta(b)
  M <- b$gravcal
  expect_identical(nrow(M$QClog), 2L)
  expect_true(any(M$metalong$nonwearscore > 0))
  expect_true(all(M$metalong$clippingscore == 0))
  expect_true("temperaturemean" %in% names(M$metalong))
  expect_identical(M$metashort$timestamp[1], "2024-01-01T00:00:00+0000")
  # GGIR's g.inspectfile() result taken (GGIR's own call needs it)
  I <- meta_quiet(GGIR::g.inspectfile(a$file, params_rawdata = utils::modifyList(
    GGIR::load_params()$params_rawdata, a$pr)))
  G2 <- meta_quiet(do.call(gravcal::g.getmeta, c(list(a$file, inspectfileobject = I,
                                                      verbose = FALSE, params_rawdata = a$pr),
                                                 cal_args)))
  expect_identical(G2$metashort, M$metashort)
  expect_identical(G2$metalong, M$metalong)
  # g, text time in %d/%m/%Y %H:%M:%OS (its first line, a text stamp, lost
  # as GGIR loses it: GGIR starts at the next long epoch) read in
  # Europe/Amsterdam, no temperature; rmc.noise and rmc.dynamic_range:
  # GGIR's sd criterion and clipping threshold
  a <- meta_adhoc(time = "character", temperature = FALSE, colnames = FALSE)
  pr <- c(a$pr, list(rmc.noise = 0.01, rmc.dynamic_range = 6))
  b <- meta_both(a$file, list(params_rawdata = pr,
                              params_general = list(desiredtz = "Europe/Amsterdam")))
  expect_same_meta(b)
  M <- b$gravcal
  expect_identical(M$metashort$timestamp[1], "2024-01-01T00:15:00+0100")
  expect_true(any(M$metalong$clippingscore > 0))
  expect_true(any(M$metalong$nonwearscore > 0))
  expect_false("temperaturemean" %in% names(M$metalong))
  # bits (unsigned, 12 over +-8 g), UNIX milliseconds, the rate from the
  # header (rmc.firstrow.header, rmc.headername.sf), in Asia/Kolkata;
  # dynrange (clipping beyond 7 - 0.5 g, whatever rmc.dynamic_range)
  a <- meta_adhoc(unit = "bit", time = "UNIXmsec", sf_header = TRUE)
  b <- meta_both(a$file, list(params_rawdata = c(a$pr, list(dynrange = 7)),
                              params_general = list(desiredtz = "Asia/Kolkata"),
                              params_metrics = list(do.anglex = TRUE, do.mad = TRUE)))
  expect_same_meta(b)
  expect_match(b$gravcal$metashort$timestamp[1], "[+]0530$")
  expect_true(any(b$gravcal$metalong$clippingscore > 0))
  # "POSIX" text that fread() reads as text (not ISO 8601): GGIR reads it
  # as "character"; in desiredtz, not in the deprecated rmc.desiredtz
  # (g.readaccfile() hands read.myacc.csv its zone)
  a <- meta_adhoc(time = "character", unit = "mg")
  pr <- c(a$pr[names(a$pr) != "rmc.unit.time"],
          list(rmc.unit.time = "POSIX", rmc.desiredtz = "Asia/Kolkata"))
  b <- meta_both(a$file, list(params_rawdata = pr))
  expect_same_meta(b)
  expect_identical(b$gravcal$metashort$timestamp[1], "2024-01-01T00:15:00+0000")
  # UNIX seconds since rmc.origin (1994 + 2000-01-01: 2024), in New York
  a <- meta_adhoc(time = "UNIXsec", start = "1994-01-01 00:00:00")
  b <- meta_both(a$file, list(params_rawdata = c(a$pr, list(rmc.origin = "2000-01-01")),
                              params_general = list(desiredtz = "America/New_York")))
  expect_same_meta(b)
  expect_identical(b$gravcal$metashort$timestamp[1], "2023-12-31T19:00:00-0500")
})

test_that("g.getmeta() is GGIR's on ad hoc csv files with time gaps, zeros and resampling", {
  skip_if_quick()
  skip_if_not_installed("data.table")
  skip_if_not_installed("GGIRread")
  # lines missing (0.3 s and 9.7 s around a single line, a minute, 5 s
  # between GGIR's first block and its second (its line 87000 is sample
  # 87701: 701 lines missing before), 0.4 s): g.getmeta()'s imputeTimegaps
  # fills them, the one between blocks from the first block's last sample
  # (its QClog counts them; after the single line GGIR's times slip by two
  # rows, decode_ggir_timegaps.hpp), and without it GGIR's blocks keep them
  # out
  drop <- c(5000:5002, 5004:5100, 40000:40600, 87702:87751, 100000:100003)
  a <- meta_adhoc(time = "UNIXsec", drop = drop)
  b <- meta_both(a$file, c(list(params_rawdata = a$pr), cal_args))
  expect_same_meta(b)
  expect_identical(b$gravcal$QClog$timegaps_n, c(3L, 2L))
  b <- meta_both(a$file, list(params_rawdata = c(a$pr, list(imputeTimegaps = FALSE))))
  expect_same_meta(b)
  expect_null(b$gravcal$QClog)
  # ActivPAL days (read.myacc.csv(): v * 86400 from 1899-12-30, forced
  # into desiredtz with lubridate::force_tz()): in Asia/Kolkata (+05:30),
  # the gaps filled by g.getmeta(); in Europe/London in winter (a zone with
  # daylight saving, one offset over the recording) with a deprecated
  # rmc.desiredtz (GGIR's ActivPAL zone where desiredtz is ""), the gaps
  # filled by rmc.check4timegaps
  a <- meta_adhoc(time = "ActivPAL", drop = drop, start = "2024-01-01 10:00:00")
  b <- meta_both(a$file, list(params_rawdata = a$pr,
                              params_general = list(desiredtz = "Asia/Kolkata")))
  expect_same_meta(b)
  expect_identical(b$gravcal$metashort$timestamp[1], "2024-01-01T10:15:00+0530")
  expect_identical(b$gravcal$QClog$timegaps_n, c(3L, 2L))
  pr <- c(a$pr, list(rmc.check4timegaps = TRUE, rmc.desiredtz = "Europe/London"))
  b <- meta_both(a$file, list(params_rawdata = pr))
  expect_same_meta(b)
  expect_identical(b$gravcal$metashort$timestamp[1], "2024-01-01T10:15:00+0000")
  # rmc.check4timegaps (read.myacc.csv fills them first, each block from
  # the block before), text time, idle-sleep zeros
  # (g.getmeta()'s own filling then finds one gap: GGIR's slipped times)
  a <- meta_adhoc(time = "character", drop = drop[drop < 1e5], zeros = 20000:20050)
  b <- meta_both(a$file, list(params_rawdata = c(a$pr, list(rmc.check4timegaps = TRUE))))
  expect_same_meta(b)
  expect_identical(b$gravcal$QClog$timegaps_n, c(1L, 0L))
  # text time across the autumn change in Europe/Amsterdam (the clock's
  # hour 02 read as as.POSIXct() reads it, in order); a block of GGIR's
  # starting within that hour refused, as by g.calibrate()
  a <- meta_adhoc(time = "character", start = "2024-10-26 23:00:00")
  b <- meta_both(a$file, list(params_rawdata = a$pr,
                              params_general = list(desiredtz = "Europe/Amsterdam")))
  expect_same_meta(b)
  expect_identical(b$gravcal$metashort$timestamp[1], "2024-10-26T23:15:00+0200")
  a <- meta_adhoc(time = "character", start = "2024-10-27 00:30:00", hours = 2.6)
  expect_error(meta_quiet(gravcal::g.getmeta(a$file, params_rawdata = a$pr,
                                             desiredtz = "Europe/Amsterdam", verbose = FALSE)),
               "`desiredtz` = \"Europe/Amsterdam\": a block of GGIR's reading")
  # rmc.doresample: a 10.3 Hz clock taken for 10 Hz, each block resampled
  a <- meta_adhoc(time = "UNIXsec", true_sf = 10.3, unit = "mg")
  pr <- utils::modifyList(a$pr, list(rmc.sf = 10, rmc.doresample = TRUE))
  b <- meta_both(a$file, list(params_rawdata = pr, params_general = list(windowsizes = c(5, 600, 3600))))
  expect_same_meta(b)
  expect_lt(nrow(b$gravcal$metashort), 4 * 720)
  # the same clock's time as ActivPAL days, forced into Asia/Kolkata
  a <- meta_adhoc(time = "ActivPAL", true_sf = 10.3, start = "2024-01-01 10:00:00")
  pr <- utils::modifyList(a$pr, list(rmc.sf = 10, rmc.doresample = TRUE))
  b <- meta_both(a$file, list(params_rawdata = pr, params_general = list(
    windowsizes = c(5, 600, 3600), desiredtz = "Asia/Kolkata")))
  expect_same_meta(b)
  expect_lt(nrow(b$gravcal$metashort), 4 * 720)
  # and rmc.check4timegaps before it (imputeTimegaps = FALSE: GGIR carries
  # read.myacc.csv's last sample before the resampling to the next block)
  a <- meta_adhoc(time = "UNIXsec", true_sf = 10.3, drop = drop, zeros = 20000:20050)
  pr <- utils::modifyList(a$pr, list(rmc.sf = 10, rmc.doresample = TRUE,
                                     rmc.check4timegaps = TRUE, imputeTimegaps = FALSE))
  expect_same_meta(meta_both(a$file, list(params_rawdata = pr)))
  # 100 minutes missing, over GGIR's 90-minute limit: filled to the next
  # long epoch, the rest imputed as whole epochs (GGIR on R 4.3 or later;
  # its reference on R 4.2 with R 4.3's as.POSIXlt(), as above)
  # The gap's time of day is read in the session's zone: in Asia/Kathmandu
  # (+05:45), with long epochs of 20 minutes, 145 minutes missing end
  # elsewhere in their epoch than in UTC (the decoder's zone table from the
  # first time stamp)
  long_gap <- function(hours, drop, ws, session_tz) {
    old <- Sys.getenv("TZ", unset = NA)
    Sys.setenv(TZ = session_tz)
    on.exit(if (is.na(old)) Sys.unsetenv("TZ") else Sys.setenv(TZ = old))
    a <- meta_adhoc(time = "UNIXsec", hours = hours, drop = drop)
    pr <- utils::modifyList(GGIR::load_params()$params_rawdata, a$pr)
    R <- ggir_cached("g.getmeta", a$file, list(params_rawdata = pr, windowsizes = ws,
                                                posixlt = "R 4.3", session_tz = session_tz), {
      I <- meta_quiet(GGIR::g.inspectfile(a$file, params_rawdata = pr))
      with_r43_posixlt(meta_quiet(GGIR::g.getmeta(a$file, params_rawdata = pr,
                                                  inspectfileobject = I, verbose = FALSE,
                                                  windowsizes = ws)))
    })
    G <- meta_quiet(gravcal::g.getmeta(a$file, params_rawdata = pr, verbose = FALSE,
                                       windowsizes = ws))
    expect_same_meta(list(ggir = R, gravcal = G))
    expect_gt(sum(G$metalong$nonwearscore == 3), 4)
    expect_true(any(G$QClog$timegaps_min > 90))
  }
  long_gap(5, 30000:90000, c(5, 900, 3600), "UTC")
  long_gap(8, 30000:116999, c(5, 1200, 3600), "Asia/Kathmandu")
})

test_that("ActivPAL days across daylight saving: GGIR's M, force_tz()'s NA hour and jump", {
  skip_if_quick()
  skip_if_not_installed("data.table")
  # read.myacc.csv() forces ActivPAL days into desiredtz with
  # lubridate::force_tz(): the clock's hour that Europe/London skips
  # (2024-03-31 01:00 to 02:00) is NA, inside GGIR's first block of
  # reading here (its blocks: 87000 lines, 2 h 25 min); the hour it
  # repeats (2024-10-27 01:00 to 02:00) takes the later offset, so the
  # stamps jump an hour: a gap g.getmeta() fills (imputeTimegaps), or
  # read.myacc.csv() does first (rmc.check4timegaps)
  gen <- list(desiredtz = "Europe/London")
  spring <- meta_adhoc(time = "ActivPAL", start = "2024-03-31 00:00:00")
  for (pr in list(list(), list(imputeTimegaps = FALSE))) {
    b <- meta_both(spring$file, list(params_rawdata = c(spring$pr, pr), params_general = gen))
    expect_same_meta(b)
    M <- b$gravcal
    expect_identical(M$metashort$timestamp[c(1, nrow(M$metashort))],
                     c("2024-03-31T00:00:00+0000", "2024-03-31T04:59:55+0100"))
  }
  fall <- meta_adhoc(time = "ActivPAL", start = "2024-10-27 00:10:00")
  b <- meta_both(fall$file, list(params_rawdata = fall$pr, params_general = gen))
  expect_same_meta(b)
  expect_identical(b$gravcal$QClog$timegaps_n, c(1L, 0L))
  expect_identical(b$gravcal$metashort$timestamp[nrow(b$gravcal$metashort)],
                   "2024-10-27T03:59:55+0000")
  b <- meta_both(fall$file, list(params_rawdata = c(fall$pr, list(rmc.check4timegaps = TRUE)),
                                 params_general = gen))
  expect_same_meta(b)
  expect_identical(b$gravcal$QClog$timegaps_n, c(0L, 0L))
  # where GGIR's start, or a block's first stamp or the last before it, is
  # NA, GGIR's g.getmeta() stops (g.imputeTimegaps(): "missing value where
  # TRUE/FALSE needed"): an error saying so
  gm <- function(a) {
    gravcal::g.getmeta(a$file, params_rawdata = a$pr, desiredtz = "Europe/London", verbose = FALSE)
  }
  ggir <- function(a) {
    pr <- utils::modifyList(GGIR::load_params()$params_rawdata, a$pr)
    I <- meta_quiet(GGIR::g.inspectfile(a$file, params_rawdata = pr,
                                        params_general = list(desiredtz = "Europe/London")))
    meta_quiet(GGIR::g.getmeta(a$file, params_rawdata = pr, desiredtz = "Europe/London",
                               inspectfileobject = I, verbose = FALSE))
  }
  for (start in c("2024-03-31 01:10:00", "2024-03-30 23:05:00")) {
    a <- meta_adhoc(time = "ActivPAL", start = start, hours = 3)
    expect_error(ggir(a), "missing value where TRUE/FALSE needed")
    expect_error(gm(a), if (start == "2024-03-31 01:10:00") {
      "starts in an hour the clocks of `desiredtz` = \"Europe/London\" skip"
    } else {
      "a block of GGIR's reading starts or ends in an hour the clocks"
    })
  }
})

test_that("g.getmeta() on ad hoc csv files: what it does not reproduce is an error naming it", {
  a <- meta_adhoc(hours = 0.2, time = "character")
  gm <- function(..., I = c()) {
    gravcal::g.getmeta(a$file, params_rawdata = utils::modifyList(a$pr, list(...)),
                       inspectfileobject = I, verbose = FALSE)
  }
  # GGIR's g.getmeta() stops without time stamps ("Timestamps not found")
  expect_error(gm(rmc.col.time = NULL, rmc.col.acc = 2:4), "`rmc.col.time` is not given")
  # GGIR's reads stop on a zone of the deprecated rmc.* parameters other
  # than the one g.readaccfile() hands read.myacc.csv
  expect_error(gm(rmc.configtz = "Asia/Kolkata"), "`rmc.configtz` = \"Asia/Kolkata\"")
  expect_error(gravcal::g.getmeta(a$file, params_rawdata = c(a$pr, list(rmc.desiredtz = "UTC")),
                                  params_general = list(desiredtz = "Europe/Amsterdam"),
                                  verbose = FALSE), "rmc.desiredtz")
  # ActivPAL days through the hour desiredtz's clocks skip: GGIR's gap
  # filling of NA time stamps (lubridate::force_tz()'s) is not reproduced
  ap <- meta_adhoc(hours = 0.2, time = "ActivPAL", start = "2024-03-31 01:55:00")
  expect_error(gravcal::g.getmeta(ap$file, params_rawdata = c(ap$pr, list(rmc.check4timegaps = TRUE)),
                                  desiredtz = "Europe/Paris", verbose = FALSE),
               "`rmc.check4timegaps` = TRUE with `rmc.unit.time` = \"ActivPAL\".*\"Europe/Paris\".*skips")
  expect_error(gm(rmc.check4timegaps = TRUE, rmc.doresample = TRUE), "rmc.doresample.*imputeTimegaps")
  expect_error(gm(rmc.dynamic_range = "range"), "rmc.dynamic_range")
  expect_error(gravcal::g.getmeta(a$file, params_rawdata = c(a$pr, list(rmc.noise = NULL)),
                                  verbose = FALSE), "rmc.noise")
  expect_error(gm(rmc.col.tme = 1), "rmc.col.tme")
  expect_error(gm(rmc.unit.acc = "G"), "rmc.unit.acc")
  # a text time its format does not read; ISO 8601 text as "POSIX", which
  # GGIR reads through fread() without its fractions of a second
  expect_error(gm(rmc.format.time = "%Y-%m-%d %H:%M:%OS"), "rmc.format.time")
  iso <- meta_adhoc(hours = 0.2, time = "POSIX")
  expect_error(gravcal::g.getmeta(iso$file, params_rawdata = iso$pr, verbose = FALSE),
               "rmc.col.time.*POSIX")
  # an inspectfileobject of another rate, or of a file read otherwise
  expect_error(gm(I = list(monc = 0, dformc = 5, sf = 20)), "inspectfileobject\\$sf")
  expect_error(gm(I = list(monc = 4, dformc = 4, sf = 10)), "inspectfileobject")
  unlink(c(a$file, iso$file, ap$file))
})

test_that("g.getmeta() takes non-wear from a wear column (rmc.col.wear) as GGIR does", {
  skip_if_quick()
  skip_if_not_installed("data.table")
  # GGIR's rule (detect_nonwear_clipping()): each long epoch's score is the
  # most frequent flag in its non-wear window, times 3 (a tie goes to
  # TRUE), whatever the axes say. The flags: TRUE, FALSE over a quarter of
  # the recording (across the axes' own non-wear, 30-60 %), missing (empty)
  # over 2 %; the block's rows repeated and dropped with the samples'
  flags <- function(n) {
    w <- rep("TRUE", n)
    w[round(0.25 * n):round(0.5 * n)] <- "FALSE"
    w[round(0.7 * n):round(0.72 * n)] <- NA
    w
  }
  drop <- c(5000:5002, 5004:5100, 40000:40600, 87702:87751, 100000:100003)
  # gaps and zero samples filled by g.getmeta()'s imputeTimegaps, the gap
  # between GGIR's two blocks from the first block's last row (nonwear
  # approach "2023", GGIR's default)
  a <- meta_adhoc(time = "UNIXsec", drop = drop, zeros = 20000:20050, wear = flags)
  b <- meta_both(a$file, c(list(params_rawdata = a$pr), cal_args))
  expect_same_meta(b)
  nw <- b$gravcal$metalong$nonwearscore
  expect_setequal(unique(nw), c(0, 3))
  # (GGIR's counts: the zero samples are a gap more in the first block)
  expect_identical(b$gravcal$QClog$timegaps_n, c(4L, 2L))
  # rmc.check4timegaps (read.myacc.csv's filling, text time), approach
  # "2013", other windows
  a2 <- meta_adhoc(time = "character", drop = drop[drop < 1e5], zeros = 20000:20050, wear = flags)
  expect_same_meta(meta_both(a2$file, list(
    params_rawdata = c(a2$pr, list(rmc.check4timegaps = TRUE)),
    params_cleaning = list(nonwear_approach = "2013"),
    params_general = list(windowsizes = c(5, 600, 1800)))))
  # ties (TRUE and FALSE alternate: every window is scored 3); the
  # spelling true/false, changing to TRUE/FALSE from GGIR's second block
  # (fread() reads each block's column on its own)
  alt <- meta_adhoc(time = "UNIXsec", hours = 2.5,
                    wear = function(n) ifelse(seq_len(n) %% 2 == 0, "TRUE", "FALSE"))
  b <- meta_both(alt$file, list(params_rawdata = alt$pr))
  expect_same_meta(b)
  expect_true(all(b$gravcal$metalong$nonwearscore == 3))
  sp <- meta_adhoc(time = "UNIXsec", wear = function(n) {
    w <- flags(n)
    w[1:87000] <- tolower(w[1:87000])
    w
  })
  expect_same_meta(meta_both(sp$file, list(params_rawdata = sp$pr)))
  # what GGIR stops on, gravcal stops on: flags fread() reads as numbers
  # (1/0) or as text (two spellings in a block): GGIR's reader's "Corrupt
  # file"; a non-wear window without a flag (GGIR's empty table)
  stops <- function(wear, msg) {
    s <- meta_adhoc(time = "UNIXsec", hours = 2.5, wear = wear)
    pr <- utils::modifyList(GGIR::load_params()$params_rawdata, s$pr)
    # (keep_warn(): GGIR's functions that stop may leave warnings off)
    ggir_msg <- ggir_error("g.getmeta", s$file, list(pr), {
      I <- keep_warn(meta_quiet(GGIR::g.inspectfile(s$file, params_rawdata = pr)))
      keep_warn(meta_quiet(GGIR::g.getmeta(s$file, params_rawdata = pr, inspectfileobject = I,
                                           verbose = FALSE)))
    })
    expect_false(is.na(ggir_msg), label = "GGIR's g.getmeta() stopped")
    expect_error(meta_quiet(gravcal::g.getmeta(s$file, params_rawdata = pr, verbose = FALSE)), msg)
    unlink(s$file)
  }
  stops(function(n) ifelse(flags(n) %in% "TRUE", "1", "0"),
        "wear column .*`rmc.col.wear`.* holds [0-9]+ values.*\"1\" is not TRUE, FALSE or empty")
  stops(function(n) replace(flags(n), 100, "true"),
        "1 value .*line 103 .*\"true\" is not spelt as the block's other")
  stops(function(n) replace(flags(n), 1:40000, NA),
        "no TRUE/FALSE value in the non-wear window of long epoch 1 .*GGIR's g.getmeta\\(\\) stops")
  # a resampled wear column (GGIR's reader stops: no longer TRUE/FALSE)
  expect_error(gravcal::g.getmeta(a$file, params_rawdata = c(a$pr, list(rmc.doresample = TRUE)),
                                  verbose = FALSE),
               "`rmc.col.wear` with `rmc.doresample` = TRUE")
  unlink(c(a$file, a2$file, alt$file, sp$file))
})

test_that("M's text round trip, taken once per distinct value, is R's element by element", {
  # GGIR's character matrices: as.numeric(as.character(v)) on each column
  set.seed(43)
  v <- c(round(rnorm(2000, 0, 30), 4), rep(0, 500), -0, NA, NaN, Inf, -Inf, 1e15 + 0.5,
         123456789.123456789, 1 / 3, .Machine$double.xmax, 5e-324, rep(c(0.1 + 0.2, 0.3), 50))
  v <- sample(v)
  expect_identical(text_round_trip(v), as.numeric(as.character(v)))
  expect_identical(text_round_trip(numeric(0)), numeric(0))
  # the text does not give back every value: the round trip is not the identity
  expect_false(identical(text_round_trip(1 / 3), 1 / 3))
})

test_that("GGIR's parameter check, where GGIR's g.getmeta() and g.calibrate() run it: chunksize, windowsizes, dataFormat", {
  skip_if_quick()
  skip_if_not_installed("GGIR")
  # GGIR 3.3-9's g.getmeta() and g.calibrate() pass their parameters through
  # extract_params() and check_params() when an argument comes in `...` or
  # a list is not given: chunksize below 0.1 becomes 0.1, windowsizes are
  # made multiples of each other (with warnings); given every list, they
  # are taken as they are. gravcal gave the values as given either way
  # (found by probing: file too short at chunksize 0.05, other epochs).
  f <- meta_recording("cwa", 25, 6, seed = 3)
  I <- meta_quiet(GGIR::g.inspectfile(f))
  both <- function(label, ...) {
    args <- list(...)
    warned <- function(expr) {
      w <- character()
      v <- withCallingHandlers(meta_quiet_keep_warnings(expr), warning = function(x) {
        w <<- c(w, conditionMessage(x))
        invokeRestart("muffleWarning")
      })
      list(v = v, w = w)
    }
    R <- ggir_cached("g.getmeta", f, c(list(check = label), args), {
      meta_quiet(do.call(GGIR::g.getmeta, c(list(datafile = f, inspectfileobject = I,
                                                  verbose = FALSE), args)))
    })
    G <- warned(do.call(gravcal::g.getmeta, c(list(datafile = f, inspectfileobject = I,
                                                   verbose = FALSE), args)))
    list(ggir = R, gravcal = G$v, warnings = G$w)
  }
  b <- both("chunksize", chunksize = 0.05)
  expect_same_meta(b)
  expect_false(b$gravcal$filetooshort)
  pr <- GGIR::load_params()$params_rawdata
  pr$chunksize <- 0.05
  expect_same_meta(both("list", params_rawdata = pr))
  for (ws in list(c(5, 930, 3600), c(7, 900, 3600), c(5, 900, 4000))) {
    b <- both("windowsizes", windowsizes = ws)
    expect_same_meta(b)
    expect_false(identical(b$gravcal$windowsizes, ws))
    expect_match(b$warnings, "GGIR's parameter check makes it", all = FALSE)
  }
  # every list given: no check, the values as given (GGIR's too)
  L <- GGIR::load_params()
  L$params_general$windowsizes <- c(5, 930, 3600)
  b <- both("all lists", params_metrics = L$params_metrics, params_rawdata = L$params_rawdata,
            params_general = L$params_general, params_cleaning = L$params_cleaning)
  expect_same_meta(b)
  expect_identical(b$gravcal$windowsizes, c(5, 930, 3600))
  # a short epoch halfway between two of GGIR's: its check gives both
  expect_error(meta_quiet(gravcal::g.getmeta(f, inspectfileobject = I, verbose = FALSE,
                                             windowsizes = c(17.5, 900, 3600))),
               "would replace it by two values at once")
  # epoch data: GGIR turns the metrics of raw data off (its g.getmeta()
  # then stops on some files, "subscript out of bounds"): refused, naming it
  pg <- L$params_general
  pg$dataFormat <- "ukbiobank"
  expect_error(meta_quiet(gravcal::g.getmeta(f, inspectfileobject = I, verbose = FALSE,
                                             params_general = pg)),
               "`dataFormat` = \"ukbiobank\": epoch data")
  # g.calibrate(): chunksize 0.05 in `...` is GGIR's 0.1
  C <- ggir_cached("g.calibrate", f, list(check = "chunksize", chunksize = 0.05), {
    meta_quiet(GGIR::g.calibrate(f, inspectfileobject = I, verbose = FALSE, chunksize = 0.05))
  })
  G <- meta_quiet(gravcal::g.calibrate(f, inspectfileobject = I, verbose = FALSE,
                                       chunksize = 0.05))
  for (nm in setdiff(names(C), "bsc_qc")) expect_identical(G[[nm]], C[[nm]], label = nm)
})
