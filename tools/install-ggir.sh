#!/usr/bin/env bash
# Installs GGIR (the reference implementation that gravcal's tests compare
# against) on a machine with R 4.2 and no network beyond CRAN and Debian.
#
# GGIR 3.3-9 lists arrow and ActCR in Imports, but neither can be installed
# here: arrow >= 20 configures only with cmake >= 3.26 (Debian 12 has 3.25)
# and then builds the Arrow C++ library from source, downloading third-party
# sources this machine cannot reach; ActCR >= 0.4 needs R >= 4.4. GGIR's
# NAMESPACE imports neither: arrow is called as arrow:: only when writing
# parquet output, ActCR only for cosinor analyses, and gravcal's tests use
# neither (g.calibrate, g.inspectfile, GGIR parts 1-2). So GGIR is installed
# from its unmodified CRAN source with those two moved to Suggests in
# DESCRIPTION; no code of GGIR's is changed.
#
#   GRAVCAL_GGIR_VERSION  that version of GGIR (CRAN's current source, or
#                         else its archive's); default: CRAN's current
set -euo pipefail
cran="${GRAVCAL_CRAN:-https://cloud.r-project.org}"

if Rscript -e 'quit(status = !requireNamespace("GGIR", quietly = TRUE))' >/dev/null 2>&1; then
  exit 0
fi
start=$(date +%s)

if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
  deb="r-cran-data.table r-cran-foreach r-cran-doparallel r-cran-zoo r-cran-psych
r-cran-lubridate r-cran-matlab r-cran-bitops r-cran-readxl r-cran-jsonlite
r-cran-digest r-cran-xml r-cran-vroom r-cran-lpsolve r-cran-mass"
  missing=""
  for p in $deb; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
  if [ -n "$missing" ]; then
    echo "install-ggir: Debian packages:$missing"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >/dev/null
    apt-get install -y -qq --no-install-recommends $missing >/dev/null
  fi
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
Rscript --vanilla - "$cran" "$work" "${GRAVCAL_GGIR_VERSION:-}" <<'RSCRIPT'
args <- commandArgs(TRUE); cran <- args[1]; work <- args[2]; ver <- args[3]
deps <- c("data.table", "foreach", "doParallel", "signal", "zoo", "unisensR",
          "ineq", "psych", "irr", "lubridate", "GGIRread", "read.gt3x")
miss <- setdiff(deps, rownames(installed.packages()))
if (length(miss)) {
  message("install-ggir: from CRAN: ", paste(miss, collapse = ", "))
  install.packages(miss, repos = cran, Ncpus = 2, quiet = TRUE)
}
still <- setdiff(deps, rownames(installed.packages()))
if (length(still)) stop("install-ggir: could not install ", paste(still, collapse = ", "))
cur <- available.packages(repos = cran, type = "source")["GGIR", "Version"]
if (is.na(ver) || !nzchar(ver) || identical(ver, cur)) {
  tgz <- download.packages("GGIR", destdir = work, repos = cran, type = "source",
                           quiet = TRUE)[1, 2]
} else {
  tgz <- file.path(work, sprintf("GGIR_%s.tar.gz", ver))
  download.file(sprintf("%s/src/contrib/Archive/GGIR/GGIR_%s.tar.gz", cran, ver), tgz, quiet = TRUE)
}
utils::untar(tgz, exdir = work)
pkg <- file.path(work, "GGIR")
d <- read.dcf(file.path(pkg, "DESCRIPTION"))
drop <- c("arrow", "ActCR")
imp <- trimws(strsplit(d[1, "Imports"], ",")[[1]])
d[1, "Imports"] <- paste(imp[!sub("[ (].*", "", imp) %in% drop], collapse = ", ")
d[1, "Suggests"] <- paste(c(d[1, "Suggests"], drop), collapse = ", ")
write.dcf(d, file.path(pkg, "DESCRIPTION"))
lib <- .libPaths()[1]
status <- system2(file.path(R.home("bin"), "R"),
                  c("CMD", "INSTALL", "--no-docs", "--no-multiarch",
                    paste0("--library=", shQuote(lib)), shQuote(pkg)))
if (status != 0) stop("install-ggir: R CMD INSTALL GGIR failed")
RSCRIPT
echo "install-ggir: GGIR installed in $(( $(date +%s) - start )) s"
