#!/usr/bin/env bash
# Builds a newer R than the system's 4.2 (an ordinary build, with long
# double), and installs into its library what gravcal's GGIR-identity tests
# need: Rcpp, RcppEigen, testthat, future, and GGIR with its dependencies
# (through tools/install-ggir.sh, run with this R first on PATH), at the
# versions the system R's library has where GGIR's results or gravcal's
# build depend on them (GRAVCAL_RNEXT_PINS). GGIR behaves differently on
# R >= 4.3 in places, and most of its users run R 4.4 or 4.5. Idempotent: a
# step whose result exists is skipped.
#
#   GRAVCAL_RNEXT_PREFIX  where R goes (default $HOME/.cache/gravcal/R-next)
#   GRAVCAL_RNEXT_R       R version to build (default 4.4.3, the last 4.4;
#                         from CRAN's src/base, or where that is not
#                         reachable, from Debian's source package of R,
#                         GRAVCAL_RNEXT_DEBIAN_SRC: Debian 13's r-base 4.5.0,
#                         whose version is GRAVCAL_RNEXT_DEBIAN_R)
#   GRAVCAL_RNEXT_PINS    "package=version ..." installed at exactly that
#                         version (its source from GRAVCAL_RNEXT_SOURCES,
#                         CRAN's current or CRAN's archive; where none has
#                         it, CRAN's current version, said "NOT PINNED")
#   GRAVCAL_RNEXT_SOURCES a folder of <package>_<version>.tar.gz sources
#                         tried first (default $prefix.src/sources)
#   GRAVCAL_CRAN          CRAN mirror (default https://cloud.r-project.org)
#   GRAVCAL_RNEXT_JOBS    make -j (default 2)
#
# Prints the prefix's bin directory as its last line.
set -euo pipefail
prefix="${GRAVCAL_RNEXT_PREFIX:-$HOME/.cache/gravcal/R-next}"
rver="${GRAVCAL_RNEXT_R:-4.4.3}"
cran="${GRAVCAL_CRAN:-https://cloud.r-project.org}"
jobs="${GRAVCAL_RNEXT_JOBS:-2}"
# as in the system R 4.2's library: GGIR and the readers whose results the
# identity tests compare (GGIRread, read.gt3x, data.table's csv reading,
# signal's filters, lubridate's time parsing, unisensR), testthat (its
# snapshots of error messages were recorded with 3.1.6), and Rcpp and
# RcppEigen (the same Eigen as gravcal's build on R 4.2)
pins="${GRAVCAL_RNEXT_PINS:-Rcpp=1.0.10 RcppEigen=0.3.3.9.3 testthat=3.1.6 data.table=1.14.8 lubridate=1.9.2 signal=1.8-1 GGIRread=1.2.0 read.gt3x=1.2.0 unisensR=0.3.4 GGIR=3.3-9}"
here="$(cd "$(dirname "$0")" && pwd)"
rbin="$prefix/bin"

# R itself (tools/build-R.sh), then its check
. "$here/build-R.sh"
build_r Rnext-R "$prefix" "$rver" "$jobs" \
  "${GRAVCAL_RNEXT_DEBIAN_SRC:-http://deb.debian.org/debian/pool/main/r/r-base/r-base_4.5.0.orig.tar.gz}" \
  "${GRAVCAL_RNEXT_DEBIAN_R:-4.5.0}"
chk=$("$rbin/Rscript" -e 'cat(getRversion() >= "4.3.0", capabilities("long.double"))')
if [ "$chk" != "TRUE TRUE" ]; then
  echo "Rnext-R: $rbin/R is not an R >= 4.3 with long double (R >= 4.3, long.double: $chk)" >&2
  exit 1
fi

start=$(date +%s)
# the pinned packages, in order (a package after those it needs): its
# source from GRAVCAL_RNEXT_SOURCES (a folder of <package>_<version>.tar.gz,
# default $prefix.src/sources), else CRAN's where that is its current
# version, else CRAN's archive's; first what that version's DESCRIPTION
# needs and is missing, at CRAN's current versions. A pinned version found
# nowhere: CRAN's current instead, said on a line "Rnext-R: NOT PINNED".
# Then MASS (signal's dependency; R's recommended packages are not built
# here), future and actilifecounts (GGIR's do.neishabouricounts).
"$rbin/Rscript" --vanilla - "$cran" "${GRAVCAL_RNEXT_SOURCES:-$prefix.src/sources}" $pins <<'RSCRIPT'
a <- commandArgs(TRUE); cran <- a[1]; local <- a[2]; pins <- a[-(1:2)]
options(repos = cran, Ncpus = 2)
base <- rownames(installed.packages(priority = "base"))
have <- function(p) tryCatch(as.character(packageVersion(p)), error = function(e) NA_character_)
avail <- available.packages(type = "source")
get_missing <- function(deps) {
  miss <- setdiff(deps, c(base, "R", rownames(installed.packages())))
  if (length(miss)) {
    message("Rnext-R: from CRAN: ", paste(miss, collapse = ", "))
    install.packages(miss, type = "source", quiet = TRUE)
  }
  still <- setdiff(miss, rownames(installed.packages()))
  if (length(still)) stop("Rnext-R: could not install ", paste(still, collapse = ", "))
}
work <- tempfile("rnext"); dir.create(work)
for (pv in pins) {
  p <- sub("=.*", "", pv); v <- sub(".*=", "", pv)
  if (identical(have(p), as.character(package_version(v)))) next
  if (p == "GGIR") next  # tools/install-ggir.sh, below
  tgz <- file.path(work, sprintf("%s_%s.tar.gz", p, v))
  where <- file.path(local, basename(tgz))
  cur <- if (p %in% rownames(avail)) avail[p, "Version"] else ""
  if (file.exists(where)) {
    file.copy(where, tgz)
  } else {
    url <- if (identical(cur, v)) sprintf("%s/src/contrib/%s", cran, basename(tgz)) else
      sprintf("%s/src/contrib/Archive/%s/%s", cran, p, basename(tgz))
    where <- url
    if (inherits(try(download.file(url, tgz, quiet = TRUE), silent = TRUE), "try-error")) {
      unlink(tgz)
      message("Rnext-R: NOT PINNED: ", p, " ", v, " is not in ", local, " nor at ", url,
              "; CRAN's current ", cur, " instead")
      get_missing(p)
      next
    }
  }
  utils::untar(tgz, files = paste0(p, "/DESCRIPTION"), exdir = work)
  d <- read.dcf(file.path(work, p, "DESCRIPTION"))
  f <- intersect(c("Depends", "Imports", "LinkingTo"), colnames(d))
  deps <- unlist(lapply(d[1, f], function(s) trimws(sub("\\(.*", "", strsplit(s, ",")[[1]]))))
  get_missing(deps[nzchar(deps)])
  message("Rnext-R: ", p, " ", v, " from ", where)
  install.packages(tgz, repos = NULL, type = "source", quiet = TRUE)
  if (!identical(have(p), as.character(package_version(v)))) {
    # R 4.5 no longer defines the legacy Calloc(), Realloc() and Free()
    # (data.table 1.14.8 calls them): again with them defined as R 4.2's
    # R_ext/RS.h did, as its R_Calloc(), R_Realloc() and R_Free()
    message("Rnext-R: ", p, " ", v, " again, with R 4.2's Calloc(), Realloc(), Free()")
    h <- file.path(work, "legacy-RS.h"); mk <- file.path(work, "legacy-RS.mk")
    writeLines(c("#include <R_ext/RS.h>",
                 "#ifndef Calloc", "#define Calloc(n, t) R_Calloc(n, t)", "#endif",
                 "#ifndef Realloc", "#define Realloc(p, n, t) R_Realloc(p, n, t)", "#endif",
                 "#ifndef Free", "#define Free(p) R_Free(p)", "#endif"), h)
    writeLines(paste("CPPFLAGS += -include", h), mk)
    old <- Sys.getenv("R_MAKEVARS_USER", NA)
    Sys.setenv(R_MAKEVARS_USER = mk)
    install.packages(tgz, repos = NULL, type = "source")
    if (is.na(old)) Sys.unsetenv("R_MAKEVARS_USER") else Sys.setenv(R_MAKEVARS_USER = old)
  }
  if (!identical(have(p), as.character(package_version(v))))
    stop("Rnext-R: ", p, " ", v, " not installed")
}
get_missing(c("MASS", "future", "actilifecounts"))
RSCRIPT
ggir=$(printf '%s\n' $pins | sed -n 's/^GGIR=//p')
PATH="$rbin:$PATH" GRAVCAL_CRAN="$cran" GRAVCAL_GGIR_VERSION="$ggir" nice -n 10 bash "$here/install-ggir.sh" </dev/null
"$rbin/Rscript" --vanilla -e '
for (pv in commandArgs(TRUE)) {
  p <- sub("=.*", "", pv); v <- sub(".*=", "", pv)
  got <- tryCatch(as.character(packageVersion(p)), error = function(e) "none")
  if (got == "none") stop("Rnext-R: ", p, " is not installed")
  cat("Rnext-R: ", p, " ", got, if (got != as.character(package_version(v))) paste0(" NOT PINNED (", v, ")"),
      "\n", sep = "")
}' $pins
echo "Rnext-R: R $("$rbin/Rscript" -e 'cat(as.character(getRversion()))'), packages ready in $(( $(date +%s) - start )) s"
echo "$rbin"
