#!/usr/bin/env bash
# gravcal on Linux aarch64 with a real arm64 R: a Debian 12 (bookworm) arm64
# chroot run under qemu-user, with Debian's own arm64 R, GGIR installed from
# its CRAN source as tools/install-ggir.sh does, gravcal installed from this
# tree, and the GGIR-identity tests (then, with `all`, the whole suite) run
# against GGIR in that R. `make test-arm64` runs it; it is slow (qemu
# emulates every instruction) and not part of `make test`.
#
#   sudo bash tools/arm64-chroot.sh [identity|all|table]
# (table: only tools/identity-table.R, gravcal::g.calibrate() against
# GGIR on GGIRread's test files and synthetic 30-hour recordings)
#
# Root is needed (debootstrap, chroot, mounts). Idempotent: the chroot, its
# Debian packages and GGIR are set up once and reused; gravcal is copied
# and reinstalled every run. Environment:
#   GRAVCAL_ARM64_ROOT    the chroot (default $HOME/.cache/gravcal/arm64)
#   GRAVCAL_SHARED_DATA   the real recordings (default ../shared/data),
#                         bound read-only into the chroot when present
#   GRAVCAL_DEBIAN_MIRROR the Debian mirror (default http://deb.debian.org/debian)
#   GRAVCAL_CRAN          the CRAN mirror (tools/install-ggir.sh)
#   ARM64_FILES           with identity or all: run only these test files
#                         (space-separated names, e.g. the ones a run cut
#                         short did not reach), in the order given
# Logs and timings: _build/arm64/.
set -euo pipefail

scope=${1:-identity}
case "$scope" in identity | all | table) ;; *) echo "arm64-chroot: the argument is identity, all or table, not '$scope'" >&2; exit 2 ;; esac
if [ "$(id -u)" != 0 ]; then
  echo "arm64-chroot: needs root (debootstrap, chroot, mounts): sudo bash $0 $scope" >&2
  exit 2
fi

tree=$(cd "$(dirname "$0")/.." && pwd)
root=${GRAVCAL_ARM64_ROOT:-$HOME/.cache/gravcal/arm64}
data=${GRAVCAL_SHARED_DATA:-$tree/../shared/data}
mirror=${GRAVCAL_DEBIAN_MIRROR:-http://deb.debian.org/debian}
cran=${GRAVCAL_CRAN:-https://cloud.r-project.org}
logs=$tree/_build/arm64
mkdir -p "$logs"
t_all=$(date +%s)
stamp() { echo "arm64-chroot: $1 ($(( $(date +%s) - $2 )) s)" | tee -a "$logs/timings.txt"; }
: > "$logs/timings.txt"

# --- the host: qemu-user with binfmt (the F flag: the interpreter is opened
# on the host, so the chroot needs no copy of it), debootstrap
t=$(date +%s)
missing=""
for p in qemu-user-static binfmt-support debootstrap; do
  dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "arm64-chroot: installing on the host:$missing"
  DEBIAN_FRONTEND=noninteractive apt-get update -qq >/dev/null
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing >/dev/null
fi
update-binfmts --enable qemu-aarch64 >/dev/null 2>&1 || true
if [ ! -e /proc/sys/fs/binfmt_misc/qemu-aarch64 ]; then
  echo "arm64-chroot: qemu-aarch64 is not registered with binfmt_misc (update-binfmts --enable qemu-aarch64)" >&2
  exit 1
fi

# --- the chroot: debootstrap bookworm arm64 once (two stages, the second
# run under qemu)
if [ ! -x "$root/usr/bin/apt-get" ] || [ ! -e "$root/etc/debian_version" ]; then
  echo "arm64-chroot: debootstrap bookworm arm64 into $root"
  mkdir -p "$root"
  debootstrap --arch=arm64 --variant=minbase --foreign bookworm "$root" "$mirror" > "$logs/debootstrap.log" 2>&1
  chroot "$root" /debootstrap/debootstrap --second-stage >> "$logs/debootstrap.log" 2>&1
  echo "deb $mirror bookworm main" > "$root/etc/apt/sources.list"
fi

# --- mounts, undone on exit whatever happens
mounted=()
cleanup() {
  local i
  for (( i = ${#mounted[@]} - 1; i >= 0; i-- )); do umount "${mounted[$i]}" 2>/dev/null || umount -l "${mounted[$i]}" || true; done
}
trap cleanup EXIT
mount_once() {  # mount_once TARGET mount-arguments...
  local target=$1; shift
  mkdir -p "$target"
  if ! mountpoint -q "$target"; then mount "$@" "$target"; mounted+=("$target"); fi
}
mount_once "$root/proc" -t proc proc
mount_once "$root/dev/pts" -t devpts devpts
have_data=0
if [ -d "$data" ]; then
  # a bind left by an earlier run may hold a folder since replaced (an
  # empty view): bind afresh, and check that the recordings show
  if mountpoint -q "$root/shared/data"; then umount "$root/shared/data" 2>/dev/null || umount -l "$root/shared/data"; fi
  mount_once "$root/shared/data" --bind "$data"
  mount -o remount,bind,ro "$root/shared/data" 2>/dev/null || true
  if [ "$(ls -A "$data" | wc -l)" != "$(ls -A "$root/shared/data" | wc -l)" ]; then
    echo "arm64-chroot: $data does not show in the chroot at /shared/data" >&2
    exit 1
  fi
  have_data=1
else
  echo "arm64-chroot: no recordings at $data: the tests that need them skip"
fi
# DNS and the host's certificate authorities (a proxy's own CA included)
cp /etc/resolv.conf "$root/etc/resolv.conf"
mkdir -p "$root/usr/local/share/ca-certificates" "$root/etc/ssl/certs"
cp /etc/ssl/certs/ca-certificates.crt "$root/etc/ssl/certs/ca-certificates.crt"
if compgen -G "/usr/local/share/ca-certificates/*" >/dev/null; then
  cp -r /usr/local/share/ca-certificates/. "$root/usr/local/share/ca-certificates/"
fi
stamp "host and chroot ready" "$t"

in_chroot() {  # in_chroot LOGNAME script (bash, run as root in the chroot)
  chroot "$root" /usr/bin/env -i HOME=/root LANG=C.UTF-8 PATH=/usr/sbin:/usr/bin:/sbin:/bin \
    GRAVCAL_CRAN="$cran" HAVE_DATA="$have_data" SCOPE="$scope" \
    /bin/bash -c "$2" > "$logs/$1.log" 2>&1 || { tail -40 "$logs/$1.log"; echo "arm64-chroot: $1 failed (log: $logs/$1.log)" >&2; exit 1; }
}

# --- Debian's arm64 R and every prebuilt r-cran-* package there is for
# gravcal's build, its test Suggests and GGIR's dependencies (compiling
# them from CRAN under qemu takes many times longer)
t=$(date +%s)
suggests=$(sed -n '/^Suggests:/,/^[A-Z][A-Za-z]*:/p' "$tree/DESCRIPTION" | sed '1s/^Suggests://;$d' |
  tr ',' '\n' | sed 's/(.*//; s/[[:space:]]//g' | grep -v '^$' | tr '\n' ' ')
# (one line: the list goes into the chroot's script as words of a for loop)
ggir_deps="data.table foreach doParallel signal zoo unisensR ineq psych irr lubridate GGIRread \
read.gt3x matlab bitops readxl jsonlite digest XML vroom lpSolve MASS"
in_chroot apt "
  set -e
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  want='r-base-dev zlib1g-dev binutils r-cran-rcpp r-cran-rcppeigen'
  for p in $suggests $ggir_deps; do
    d=r-cran-\$(echo \"\$p\" | tr 'A-Z' 'a-z')
    if apt-cache show \"\$d\" >/dev/null 2>&1; then want=\"\$want \$d\"; else echo \"not in Debian: \$p\"; fi
  done
  missing=''
  for d in \$want; do dpkg -s \"\$d\" >/dev/null 2>&1 || missing=\"\$missing \$d\"; done
  if [ -n \"\$missing\" ]; then apt-get install -y -qq --no-install-recommends \$missing; fi
  echo \"Debian packages: \$want\"
"
stamp "Debian's R and r-cran-* packages" "$t"

# --- GGIR as tools/install-ggir.sh installs it (from CRAN sources: what
# Debian lacks, GGIRread's C++ among it, compiled by this R's g++ with its
# default flags, as a user's would be)
t=$(date +%s)
rm -rf "$root"/usr/local/lib/R/site-library/00LOCK-*
mkdir -p "$root/tmp/gravcal-tools"
cp "$tree/tools/install-ggir.sh" "$root/tmp/gravcal-tools/"
in_chroot ggir "bash /tmp/gravcal-tools/install-ggir.sh"
stamp "GGIR and GGIRread" "$t"

# GRAVCAL_ARM64_CROSS=1: gravcal's objects compiled on the host by Debian's
# aarch64 cross g++ (the same GCC 12.2 as the chroot's, with the chroot's
# R, Rcpp and RcppEigen headers and R's own flags from R CMD config), then
# linked and installed by the chroot's R: g++ under qemu takes about an hour
# for gravcal on a busy two-core machine, the cross compiler minutes. The
# default compiles in the chroot, as a user's R would.
cross=${GRAVCAL_ARM64_CROSS:-0}
cross_objects() {
  # (Debian's g++-aarch64-linux-gnu conflicts with g++-multilib, which
  # make test's setup installs for the 32-bit build of the core's tests:
  # installing one removes the other, so do not run both at once)
  # (dpkg -s succeeds for a removed package whose configuration is left:
  # ask for the compiler itself)
  command -v aarch64-linux-gnu-g++ >/dev/null 2>&1 ||
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends g++-aarch64-linux-gnu >/dev/null
  local cfg
  cfg=$(chroot "$root" /bin/sh -c 'echo "$(R CMD config CXX17) $(R CMD config CXX17STD)|$(R CMD config CXXPICFLAGS) $(R CMD config CXX17FLAGS) $(R CMD config CPPFLAGS)"')
  local std=${cfg%%|*} flags=${cfg#*|}
  std=${std#* }  # drop the compiler's name: the cross compiler replaces it
  echo "arm64-chroot: cross-compiling gravcal's objects: aarch64-linux-gnu-g++ $std $flags" | tee "$logs/cross.log"
  ls "$root"/gravcal/src/*.cpp | xargs -P 2 -I{} sh -c "aarch64-linux-gnu-g++ $std \
    -I$root/usr/share/R/include -DNDEBUG -I$root/gravcal/inst/include \
    -I$root/usr/lib/R/site-library/Rcpp/include -I$root/usr/lib/R/site-library/RcppEigen/include \
    $flags -c {} -o \$(echo {} | sed 's/cpp\$/o/')" >> "$logs/cross.log" 2>&1
  touch "$root"/gravcal/src/*.o
}

# --- gravcal from this tree (a fresh copy: no objects of the host's),
# rebuilt only when the copy changed since the last install
t=$(date +%s)
src_tar="$root/tmp/gravcal-src.tar"
tar -C "$tree" --exclude=./_build --exclude=./.git --exclude='*.o' --exclude='*.so' \
  --exclude='*.Rcheck' --exclude='*.tar.gz' --sort=name --mtime=@0 --owner=0 --group=0 \
  -cf "$src_tar" .
sum=$(sha256sum < "$src_tar" | cut -c1-64)
if [ "$(cat "$root/gravcal-lib/.source-sha256" 2>/dev/null)" != "$sum" ]; then
  rm -rf "$root/gravcal" "$root/gravcal-lib"
  mkdir -p "$root/gravcal" "$root/gravcal-lib"
  tar -C "$root/gravcal" -xf "$src_tar"
  cp "$tree/tools/fma-count.sh" "$root/tmp/gravcal-tools/"
  if [ "$cross" = 1 ]; then cross_objects; fi
  in_chroot install "
    set -e
    cd /gravcal
    GRAVCAL_KEEP_SYMBOLS=1 R CMD INSTALL --no-multiarch -l /gravcal-lib .
    echo; R CMD config CXX17; R CMD config CXX17FLAGS
    sh /tmp/gravcal-tools/fma-count.sh /gravcal-lib/gravcal/libs/gravcal.so
  "
  echo "$sum" > "$root/gravcal-lib/.source-sha256"
  tail -4 "$logs/install.log"
  stamp "gravcal built and installed" "$t"
else
  # the tests run from the copy: refresh it (same sources, so no rebuild)
  rm -rf "$root/gravcal"; mkdir -p "$root/gravcal"; tar -C "$root/gravcal" -xf "$src_tar"
  stamp "gravcal already installed from these sources" "$t"
fi

# --- the tests: the GGIR-identity files (GGIR's and GGIRread's test files,
# the real recordings, the synthetic 30-hour recordings), then with `all`
# the whole suite
t=$(date +%s)
if [ "$scope" = table ]; then
  # only the table of gravcal::g.calibrate() against GGIR's on GGIRread's
  # test files and synthetic 30-hour recordings (tools/identity-table.R)
  in_chroot table "cd /gravcal && R_LIBS=/gravcal-lib Rscript tools/identity-table.R /tmp/identity-table.md && cp /tmp/identity-table.md /gravcal-lib/identity-table.md"
  cp "$root/gravcal-lib/identity-table.md" "$logs/identity-table.md" 2>/dev/null || true
  stamp "table" "$t"
  stamp "total" "$t_all"
  exit 0
fi
identity="test-fp-build.R test-ggir.R test-ggir-params.R test-ggir-interpolation.R test-ggir-segments.R
test-ggir-stress.R test-decode-cwa.R test-decode-geneactiv.R test-decode-gt3x.R test-decode-csv.R
test-decode-parmay.R test-decode-movisens.R test-axivity-csv.R test-adhoc-csv.R test-windows.R
test-fit-icp.R test-simd.R test-formats.R test-ggir-getmeta.R test-ggir-filters.R test-ggir-part1.R test-epochs.R test-meta-store.R"
# with `all`, every test file once: the identity files first, then the rest
# (so a run cut short still has them); one row printed as each file ends
in_chroot tests "
  cd /gravcal/tests/testthat
  export R_LIBS=/gravcal-lib NOT_CRAN=true
  [ \"\$HAVE_DATA\" = 1 ] && export GRAVCAL_SHARED_DATA=/shared/data
  Rscript -e 'cat(R.version.string, Sys.info()[[\"machine\"]], \"long double:\", capabilities(\"long.double\"),
                  .Machine\$sizeof.longdouble, \"bytes; GGIR\", format(packageVersion(\"GGIR\")), \"GGIRread\",
                  format(packageVersion(\"GGIRread\")), \"\n\"); library(gravcal);
              cat(\"GGIRread::resample fused here:\", gravcal:::ggir_resample_fused(), \"\n\")'
  Rscript -e '
    suppressPackageStartupMessages({ library(testthat); library(gravcal) })
    options(testthat.summary.max_reports = 10000L)
    files <- strsplit(\"$(echo $identity)\", \" \")[[1]]
    if (\"$scope\" == \"all\") files <- c(files, setdiff(sort(list.files(\".\", \"^test-.*[.]R\$\")), files))
    only <- strsplit(\"$(echo ${ARM64_FILES:-})\", \" \")[[1]]
    if (length(only)) {
      if (!all(file.exists(only))) stop(\"ARM64_FILES names no test file: \", paste(only[!file.exists(only)], collapse = \" \"))
      files <- only
    }
    row <- function(f) {
      t0 <- proc.time()[[3]]
      r <- as.data.frame(test_file(f, reporter = \"summary\", package = \"gravcal\", load_package = \"installed\"))
      d <- data.frame(file = f, tests = nrow(r), expectations = sum(r\$nb), failed = sum(r\$failed) + sum(r\$error),
                      skipped = sum(r\$skipped), seconds = round(proc.time()[[3]] - t0))
      cat(sprintf(\"file-row: %-28s %4d tests %6d expectations %3d failed %3d skipped %6d s\n\", d\$file, d\$tests,
                  d\$expectations, d\$failed, d\$skipped, d\$seconds))
      d
    }
    res <- do.call(rbind, lapply(files, row))
    print(res, row.names = FALSE)
    cat(sprintf(\"%s files: %d files, %d tests, %d expectations, %d failed, %d skipped\n\", \"$scope\", nrow(res),
                sum(res\$tests), sum(res\$expectations), sum(res\$failed), sum(res\$skipped)))
    quit(status = sum(res\$failed) > 0)'
"
grep -E "^file-row:|(identity|all) files:|fused here|R version" "$logs/tests.log" || true
stamp "tests ($scope)" "$t"
stamp "total" "$t_all"
