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

# png() is needed (GGIR's part 2 draws its QC plots with it, and so do the
# epoch tests); built --without-x, R has it only through cairo, and png()'s
# default type (the option bitmapType) is "cairo" only with pango's cairo
# (else "Xlib": "X11 is not available", though capabilities("png") is
# TRUE): an R built here earlier without them is rebuilt in place (its
# library is kept)
png_ok() {
  [ "$("$rbin/Rscript" --vanilla -e 'p <- tempfile(fileext = ".png"); ok <- !inherits(try(grDevices::png(p), silent = TRUE), "try-error"); if (ok) invisible(grDevices::dev.off()); cat(ok)' 2>/dev/null)" = TRUE ]
}
if [ ! -x "$rbin/Rscript" ] || ! png_ok; then
  start=$(date +%s)
  if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
    need="gfortran libreadline-dev libpcre2-dev libbz2-dev liblzma-dev
zlib1g-dev libcurl4-openssl-dev libicu-dev make pkg-config libcairo2-dev libpango1.0-dev"
    missing=""
    for p in $need; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
    if [ -n "$missing" ]; then
      echo "noLD-R: Debian packages:$missing"
      export DEBIAN_FRONTEND=noninteractive
      apt-get update -qq -o DPkg::Lock::Timeout=600 >/dev/null
      apt-get install -y -qq -o DPkg::Lock::Timeout=600 --no-install-recommends $missing >/dev/null
    fi
  fi
  src="$prefix.src"
  mkdir -p "$src"
  tgz="$src/R-$rver.tar.gz"
  major="${rver%%.*}"
  deb="${GRAVCAL_NOLD_DEBIAN_SRC:-http://deb.debian.org/debian/pool/main/r/r-base/r-base_4.2.2.20221110.orig.tar.gz}"
  if [ ! -s "$tgz" ]; then
    curl -fsSL -o "$tgz" "$cran/src/base/R-$major/R-$rver.tar.gz" ||
      { echo "noLD-R: R's sources not on $cran; Debian's: $deb"; curl -fsSL -o "$tgz" "$deb"; }
  fi
  if [ ! -d "$src/R-$rver" ]; then
    mkdir -p "$src/R-$rver"
    tar -xzf "$tgz" -C "$src/R-$rver" --strip-components=1
  fi
  cd "$src/R-$rver"
  if [ ! -f Makeconf ]; then
    ./configure --prefix="$prefix" --disable-long-double --without-x \
      --with-readline=no --with-recommended-packages=no --disable-java \
      --enable-R-shlib=no > "$src/configure.log" 2>&1 ||
      { tail -30 "$src/configure.log"; exit 1; }
  fi
  nice -n 10 make -j"$jobs" > "$src/make.log" 2>&1 || { tail -30 "$src/make.log"; exit 1; }
  make install > "$src/install.log" 2>&1 || { tail -30 "$src/install.log"; exit 1; }
  cd "$here/.."
  rm -rf "$src/R-$rver"
  echo "noLD-R: R $rver built in $(( $(date +%s) - start )) s"
fi

if ! png_ok; then
  echo "noLD-R: png() fails in $rbin/R (configure found no cairo or pango: $prefix.src/configure.log)" >&2
  exit 1
fi
ld=$("$rbin/Rscript" -e 'cat(capabilities("long.double"))')
if [ "$ld" != "FALSE" ]; then
  echo "noLD-R: $rbin/R has long double (capabilities(\"long.double\") is $ld)" >&2
  exit 1
fi

# packages, into this R's own library (R_LIBS unset: nothing from the
# system R's libraries); testthat's dependency fs needs libuv's headers
unset R_LIBS R_LIBS_USER R_LIBS_SITE
if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ] && ! dpkg -s libuv1-dev >/dev/null 2>&1; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get install -y -qq -o DPkg::Lock::Timeout=600 --no-install-recommends libuv1-dev >/dev/null
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
echo "noLD-R: packages ready in $(( $(date +%s) - start )) s"
echo "$rbin"
