# Sourced by tools/noLD-R.sh and tools/Rnext-R.sh: builds an R of its own
# from source into a prefix, with png() through cairo and pango, and the
# headers the test packages' builds need. Not run on its own.
#
# build_r NAME PREFIX VERSION JOBS DEBIAN_SRC DEBIAN_VERSION [configure flags]
#   NAME: what the messages start with ("noLD-R");
#   PREFIX: where R goes (its sources and logs in PREFIX.src);
#   VERSION: from CRAN's src/base; where CRAN does not have it, Debian's
#     source package DEBIAN_SRC (a URL) is built instead, whose R is
#     DEBIAN_VERSION;
#   the configure flags are added to the ones every build here has.
# An R already in PREFIX whose png() works is kept (its library too); one
# without a working png() is rebuilt in place. Exits on failure.

# png() is needed (GGIR's part 2 draws its QC plots with it, and so do the
# epoch tests); built --without-x, R has it only through cairo, and png()'s
# default type (the option bitmapType) is "cairo" only with pango's cairo
# (else "Xlib": "X11 is not available", though capabilities("png") is TRUE)
r_png_ok() {
  [ "$("$1/bin/Rscript" --vanilla -e 'p <- tempfile(fileext = ".png"); ok <- !inherits(try(grDevices::png(p), silent = TRUE), "try-error"); if (ok) invisible(grDevices::dev.off()); cat(ok)' 2>/dev/null)" = TRUE ]
}

# Debian packages, when we are root on Debian: those missing are installed
r_apt() {
  local name="$1" missing="" p
  shift
  command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ] || return 0
  for p in "$@"; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
  [ -n "$missing" ] || return 0
  echo "$name: Debian packages:$missing"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq -o DPkg::Lock::Timeout=600 >/dev/null
  # shellcheck disable=SC2086
  apt-get install -y -qq -o DPkg::Lock::Timeout=600 --no-install-recommends $missing >/dev/null
}

build_r() {
  local name="$1" prefix="$2" rver="$3" jobs="$4" deb="$5" debver="$6"
  shift 6
  local cran="${GRAVCAL_CRAN:-https://cloud.r-project.org}"
  local top
  top="$(pwd)"
  if [ ! -x "$prefix/bin/Rscript" ] || ! r_png_ok "$prefix"; then
    local start src tgz major
    start=$(date +%s)
    r_apt "$name" gfortran libreadline-dev libpcre2-dev libbz2-dev liblzma-dev zlib1g-dev \
      libcurl4-openssl-dev libicu-dev make pkg-config libcairo2-dev libpango1.0-dev
    src="$prefix.src"
    mkdir -p "$src"
    major="${rver%%.*}"
    tgz="$src/R-$rver.tar.gz"
    if [ ! -s "$tgz" ]; then
      if ! curl -fsSL -o "$tgz" "$cran/src/base/R-$major/R-$rver.tar.gz"; then
        rm -f "$tgz"
        echo "$name: R $rver's sources not on $cran; Debian's: $deb"
        rver="$debver"
        tgz="$src/R-$rver.tar.gz"
        [ -s "$tgz" ] || curl -fsSL -o "$tgz" "$deb"
      fi
    fi
    if [ ! -d "$src/R-$rver" ]; then
      mkdir -p "$src/R-$rver"
      tar -xzf "$tgz" -C "$src/R-$rver" --strip-components=1
    fi
    cd "$src/R-$rver"
    if [ ! -f Makeconf ]; then
      ./configure --prefix="$prefix" --without-x "$@" \
        --with-readline=no --with-recommended-packages=no --disable-java \
        --enable-R-shlib=no > "$src/configure.log" 2>&1 ||
        { tail -30 "$src/configure.log"; exit 1; }
    fi
    nice -n 10 make -j"$jobs" > "$src/make.log" 2>&1 || { tail -30 "$src/make.log"; exit 1; }
    make install > "$src/install.log" 2>&1 || { tail -30 "$src/install.log"; exit 1; }
    cd "$top"
    rm -rf "$src/R-$rver"
    echo "$name: R $rver built in $(( $(date +%s) - start )) s"
  fi
  if ! r_png_ok "$prefix"; then
    echo "$name: png() fails in $prefix/bin/R (configure found no cairo or pango: $prefix.src/configure.log)" >&2
    exit 1
  fi
  # the packages go into this R's own library (R_LIBS unset: nothing from
  # the system R's libraries); testthat's dependency fs needs libuv's headers
  unset R_LIBS R_LIBS_USER R_LIBS_SITE
  r_apt "$name" libuv1-dev
}
