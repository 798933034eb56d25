#!/usr/bin/env bash
# Installs what gravcal needs to be built and run (make install, make demo),
# when it is missing: R, a C++17 compiler, make, zlib's headers, Rcpp and
# RcppEigen. Nothing the tests alone need (tools/setup-test.sh adds that).
# Debian's packages when we are root on Debian (fast), then Rcpp and
# RcppEigen from CRAN if still missing. Safe to run again: it skips what is
# there.
set -euo pipefail

cran="${GRAVCAL_CRAN:-https://cloud.r-project.org}"

deb_pkgs="r-base-core g++ make zlib1g-dev r-cran-rcpp r-cran-rcppeigen"

. "$(dirname "$0")/apt-missing.sh"
# shellcheck disable=SC2086
apt_missing $deb_pkgs

# the LinkingTo and Imports from CRAN (graphics, grDevices, stats and
# utils come with R)
Rscript --vanilla - "$cran" <<'RSCRIPT'
cran <- commandArgs(TRUE)[1]
need <- c("Rcpp", "RcppEigen")
miss <- setdiff(need, rownames(installed.packages()))
if (length(miss)) {
  message("setup: installing from CRAN: ", paste(miss, collapse = ", "))
  install.packages(miss, repos = cran, Ncpus = 2, quiet = TRUE)
}
still <- setdiff(need, rownames(installed.packages()))
if (length(still)) stop("setup: could not install ", paste(still, collapse = ", "))
RSCRIPT
