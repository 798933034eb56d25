# The built documentation site, checked as a reader's browser sees it:
#   Rscript tools/site-test.R [SITE] [SHOTS]
# (defaults _build/site and _build/site-shots; run by `make site`).
# 1. Every built HTML file's internal links and images (href, src) resolve
#    to a file of the site; anchors, external URLs, mailto: and data: are
#    not followed. An <img> whose target is missing fails as a missing image.
# 2. Headless Chromium opens the home page and one reference page from
#    file:// URLs and takes a screenshot of each; a screenshot must be a PNG
#    that is not blank (more than a handful of distinct colours, and text:
#    dark pixels on the light page).
# Exit status 1 on any failure, with every failure listed.
args <- commandArgs(TRUE)
site <- normalizePath(if (length(args) >= 1) args[1] else "_build/site", mustWork = TRUE)
shots <- if (length(args) >= 2) args[2] else "_build/site-shots"
dir.create(shots, showWarnings = FALSE, recursive = TRUE)
shots <- normalizePath(shots)

failures <- character()
fail <- function(...) failures <<- c(failures, paste0(...))

# ---- 1. internal links and images ------------------------------------------
html <- list.files(site, pattern = "\\.html$", recursive = TRUE, full.names = TRUE)
if (length(html) < 10) fail("only ", length(html), " HTML files in ", site)

# attributes href= and src= of every element, with the element's name
refs_of <- function(file) {
  txt <- paste(readLines(file, warn = FALSE, encoding = "UTF-8"), collapse = "\n")
  # drop comments and the contents of <script> elements (their strings are
  # code, not links)
  txt <- gsub("<!--.*?-->", "", txt, perl = TRUE)
  txt <- gsub("(?s)(<script\\b[^>]*>).*?</script>", "\\1</script>", txt, perl = TRUE)
  tags <- regmatches(txt, gregexpr("<[A-Za-z][A-Za-z0-9]*\\b[^>]*>", txt, perl = TRUE))[[1]]
  out <- list()
  for (tag in tags) {
    el <- tolower(sub("^<([A-Za-z0-9]+).*", "\\1", tag, perl = TRUE))
    m <- regmatches(tag, gregexpr("\\s(href|src)\\s*=\\s*(\"[^\"]*\"|'[^']*')",
                                  tag, perl = TRUE))[[1]]
    for (a in m) {
      attr <- tolower(sub("^\\s*(href|src).*", "\\1", a, perl = TRUE, ignore.case = TRUE))
      val <- sub("^[^=]*=\\s*[\"'](.*)[\"']$", "\\1", a, perl = TRUE)
      out[[length(out) + 1]] <- c(element = el, attr = attr, value = val)
    }
  }
  if (length(out)) do.call(rbind, out) else
    matrix(character(), 0, 3, dimnames = list(NULL, c("element", "attr", "value")))
}

decode_url <- function(x) utils::URLdecode(gsub("&amp;", "&", x, fixed = TRUE))

n_links <- 0L
n_images <- 0L
for (f in html) {
  r <- refs_of(f)
  for (i in seq_len(nrow(r))) {
    v <- trimws(r[i, "value"])
    if (!nzchar(v) || startsWith(v, "#")) next
    if (grepl("^[A-Za-z][A-Za-z0-9+.-]*:", v) || startsWith(v, "//")) next  # external
    path <- sub("[?#].*$", "", decode_url(v))
    if (!nzchar(path)) next
    target <- if (startsWith(path, "/")) file.path(site, path) else file.path(dirname(f), path)
    if (endsWith(path, "/")) target <- file.path(target, "index.html")
    is_img <- r[i, "element"] == "img"
    if (is_img) n_images <- n_images + 1L else n_links <- n_links + 1L
    if (!file.exists(target) || (dir.exists(target) &&
                                 !file.exists(file.path(target, "index.html")))) {
      fail(if (is_img) "missing image " else "broken link ", v, " in ",
           substring(f, nchar(site) + 2))
    }
  }
}
cat(sprintf("site-test: %d HTML files, %d internal links and %d images resolved\n",
            length(html), n_links, n_images))

# ---- 2. screenshots in headless Chromium ------------------------------------
chromium <- Sys.getenv("CHROMIUM", "")
if (!nzchar(chromium)) {
  for (b in c("chromium", "chromium-browser", "google-chrome")) {
    if (nzchar(Sys.which(b))) { chromium <- Sys.which(b); break }
  }
}
if (!nzchar(chromium)) {
  fail("no Chromium found (Debian: apt-get install chromium; or set CHROMIUM)")
} else {
  ref_page <- file.path(site, "reference", "calibrate.html")
  pages <- c(home = file.path(site, "index.html"), reference = ref_page)
  profile <- tempfile("chromium-profile-")
  for (nm in names(pages)) {
    page <- pages[[nm]]
    png_file <- file.path(shots, paste0(nm, ".png"))
    unlink(png_file)
    if (!file.exists(page)) { fail("no page ", page); next }
    log <- suppressWarnings(system2(chromium, c(
      "--headless", "--disable-gpu", "--no-sandbox", "--hide-scrollbars",
      "--no-first-run", "--disable-extensions", "--disable-dev-shm-usage",
      paste0("--user-data-dir=", profile),
      "--window-size=1280,1600", "--virtual-time-budget=5000",
      paste0("--screenshot=", png_file), paste0("file://", page)),
      stdout = TRUE, stderr = TRUE))
    if (!file.exists(png_file) || file.size(png_file) == 0) {
      fail("no screenshot of the ", nm, " page; Chromium said:\n  ",
           paste(utils::tail(log, 10), collapse = "\n  "))
      next
    }
    sig <- readBin(png_file, "raw", 8)
    if (!identical(sig, as.raw(c(0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a)))) {
      fail("screenshot of the ", nm, " page is not a PNG")
      next
    }
    if (requireNamespace("png", quietly = TRUE)) {
      img <- png::readPNG(png_file)
      rgb <- img[, , 1:3, drop = FALSE]
      codes <- round(rgb[, , 1] * 255) * 65536 + round(rgb[, , 2] * 255) * 256 +
        round(rgb[, , 3] * 255)
      n_colours <- length(unique(as.vector(codes)))
      lum <- 0.299 * rgb[, , 1] + 0.587 * rgb[, , 2] + 0.114 * rgb[, , 3]
      dark <- mean(lum < 0.5)
      cat(sprintf("site-test: %s page screenshot %s: %d x %d, %d bytes, %d colours, %.1f%% dark pixels\n",
                  nm, png_file, dim(img)[2], dim(img)[1], file.size(png_file),
                  n_colours, 100 * dark))
      if (n_colours < 16) fail("screenshot of the ", nm, " page is blank (", n_colours, " colours)")
      if (dark < 0.002) fail("screenshot of the ", nm, " page shows no text")
    } else {
      cat(sprintf("site-test: %s page screenshot %s: %d bytes (png package absent: size checked only)\n",
                  nm, png_file, file.size(png_file)))
      if (file.size(png_file) < 20000) fail("screenshot of the ", nm, " page is nearly empty")
    }
  }
  unlink(profile, recursive = TRUE)
}

if (length(failures)) {
  cat("site-test: FAILED\n", paste0("  ", failures, "\n"), sep = "")
  quit(status = 1)
}
cat("site-test: OK\n")
