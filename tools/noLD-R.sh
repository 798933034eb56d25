#!/usr/bin/env bash
# Builds an R without long double (R's configure --disable-long-double,
# what CRAN's "noLD" additional check runs), and installs into its library
# what gravcal's GGIR-identity tests need: Rcpp, RcppEigen, testthat, and
# GGIR with its dependencies (through tools/install-ggir.sh, run with this
# R first on PATH). Idempotent: a step whose result exists is skipped.
#
#   GRAVCAL_NOLD_PREFIX  where R goes (default $HOME/.cache/gravcal/R-noLD)
#   GRAVCAL_NOLD_R       R version to build (default 4.2.2; from CRAN's
#                        src/base, or where that is not reachable, from
#                        Debian's source package of R, GRAVCAL_NOLD_DEBIAN_SRC:
#                        Debian 12's r-base 4.2.2.20221110, the system R here)
#   GRAVCAL_CRAN         CRAN mirror (default https://cloud.r-project.org)
#   GRAVCAL_NOLD_JOBS    make -j (default 2)
#
# Prints the prefix's bin directory as its last line.
set -euo pipefail
prefix="${GRAVCAL_NOLD_PREFIX:-$HOME/.cache/gravcal/R-noLD}"
rver="${GRAVCAL_NOLD_R:-4.2.2}"
cran="${GRAVCAL_CRAN:-https://cloud.r-project.org}"
jobs="${GRAVCAL_NOLD_JOBS:-2}"
here="$(cd "$(dirname "$0")" && pwd)"
rbin="$prefix/bin"

# R itself (tools/build-R.sh), then its check
. "$here/build-R.sh"
build_r noLD-R "$prefix" "$rver" "$jobs" \
  "${GRAVCAL_NOLD_DEBIAN_SRC:-http://deb.debian.org/debian/pool/main/r/r-base/r-base_4.2.2.20221110.orig.tar.gz}" \
  "$rver" --disable-long-double
ld=$("$rbin/Rscript" -e 'cat(capabilities("long.double"))')
if [ "$ld" != "FALSE" ]; then
  echo "noLD-R: $rbin/R has long double (capabilities(\"long.double\") is $ld)" >&2
  exit 1
fi

start=$(date +%s)
"$rbin/Rscript" --vanilla -e '
pk <- c("Rcpp", "RcppEigen", "testthat")
miss <- setdiff(pk, rownames(installed.packages()))
if (length(miss)) {
  message("noLD-R: from CRAN: ", paste(miss, collapse = ", "))
  install.packages(miss, repos = commandArgs(TRUE)[1], Ncpus = 2, quiet = TRUE)
}
still <- setdiff(pk, rownames(installed.packages()))
if (length(still)) stop("noLD-R: could not install ", paste(still, collapse = ", "))
' "$cran"
# testthat as Debian 12 has it (GRAVCAL_NOLD_TESTTHAT, default 3.1.6): the
# snapshots of error messages were recorded with it, and testthat 3.2
# prints conditions otherwise
"$rbin/Rscript" --vanilla -e '
a <- commandArgs(TRUE)
if (as.character(utils::packageVersion("testthat")) != a[1]) {
  # dependencies of 3.1 that current testthat no longer imports (a failed
  # install of the archived version removes the installed testthat)
  install.packages(c("ellipsis", "digest"), repos = a[2], quiet = TRUE)
  install.packages(sprintf("%s/src/contrib/Archive/testthat/testthat_%s.tar.gz", a[2], a[1]),
                   repos = NULL, type = "source", quiet = TRUE)
}
if (as.character(utils::packageVersion("testthat")) != a[1]) stop("noLD-R: testthat ", a[1], " not installed")
' "${GRAVCAL_NOLD_TESTTHAT:-3.1.6}" "$cran"
# MASS (signal's dependency, so GGIR's): R's recommended packages are not
# built here, and CRAN's current MASS needs R >= 4.4: the version for R 4.2
# from CRAN's archive (GRAVCAL_NOLD_MASS, default 7.3-58.3)
"$rbin/Rscript" --vanilla -e '
a <- commandArgs(TRUE)
if (!requireNamespace("MASS", quietly = TRUE)) {
  install.packages(sprintf("%s/src/contrib/Archive/MASS/MASS_%s.tar.gz", a[2], a[1]),
                   repos = NULL, type = "source", quiet = TRUE)
}
if (!requireNamespace("MASS", quietly = TRUE)) stop("noLD-R: MASS ", a[1], " not installed")
' "${GRAVCAL_NOLD_MASS:-7.3-58.3}" "$cran"
PATH="$rbin:$PATH" GRAVCAL_CRAN="$cran" nice -n 10 bash "$here/install-ggir.sh" </dev/null
# actilifecounts (GGIR's do.neishabouricounts; it needs GGIRread, above)
"$rbin/Rscript" --vanilla -e '
if (!requireNamespace("actilifecounts", quietly = TRUE)) {
  install.packages("actilifecounts", repos = commandArgs(TRUE)[1], Ncpus = 2, quiet = TRUE)
}
if (!requireNamespace("actilifecounts", quietly = TRUE)) stop("noLD-R: actilifecounts not installed")
' "$cran"
echo "noLD-R: packages ready in $(( $(date +%s) - start )) s"
echo "$rbin"
