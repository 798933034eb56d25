#!/usr/bin/env bash
# Installs what gravcal's tests need (make test and the targets it calls),
# when it is missing: first what it needs to be built and run
# (tools/setup.sh), then the Suggests, the tools of the test targets
# (Chromium, pandoc, pngquant for the vignettes' figures, qpdf, tidy, valgrind, clang with libFuzzer and libc++,
# the Cortex-M and mingw-w64 cross compilers, wine64 to run the Windows
# build of the core tests, qemu, 32-bit multilib) and
# GGIR. Debian's prebuilt r-cran-* packages when we are root on Debian
# (fast), then anything still missing from CRAN. Safe to run again: it
# skips what is there.
set -euo pipefail

bash "$(dirname "$0")/setup.sh"

cran="${GRAVCAL_CRAN:-https://cloud.r-project.org}"

deb_pkgs="r-cran-testthat r-cran-knitr
r-cran-rmarkdown r-cran-data.table r-cran-future r-cran-future.apply
r-cran-progressr r-cran-deoptim r-cran-batchtools r-cran-future.batchtools r-cran-pkgdown r-cran-png chromium pandoc pngquant qpdf tidy valgrind gcc-arm-none-eabi
libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib qemu-system-arm clang libclang-rt-14-dev
libc++-dev libc++abi-dev g++-multilib g++-mingw-w64-x86-64 libz-mingw-w64-dev wine64"

. "$(dirname "$0")/apt-missing.sh"
# shellcheck disable=SC2086
apt_missing $deb_pkgs

# CRAN packages: the Imports and LinkingTo, and the Suggests so that every
# test runs (tests skip only when a Suggests package is really absent).
Rscript --vanilla - "$cran" <<'RSCRIPT'
cran <- commandArgs(TRUE)[1]
need <- c("Rcpp", "RcppEigen", "testthat", "knitr", "rmarkdown", "read.gt3x",
          "tibble", "data.table", "future", "future.apply", "progressr",
          "DEoptim", "signal", "batchtools", "future.batchtools", "actilifecounts")
have <- rownames(installed.packages())
miss <- setdiff(need, have)
if (length(miss)) {
  message("setup: installing from CRAN: ", paste(miss, collapse = ", "))
  install.packages(miss, repos = cran, Ncpus = 2, quiet = TRUE)
}
still <- setdiff(need, rownames(installed.packages()))
if (length(still)) stop("setup: could not install ", paste(still, collapse = ", "))
RSCRIPT

# GGIR and GGIRread (Suggests): the reference implementation the tests
# compare against; see tools/install-ggir.sh for why it is installed that way.
bash "$(dirname "$0")/install-ggir.sh"
