#!/usr/bin/env bash
# gravcal.dll for 64-bit Windows, built with Debian's mingw-w64 cross
# compiler as Rtools builds a package: src/*.cpp compiled to real objects
# (-O2 -Wall -Wextra -Werror) and linked with -Wl,--no-undefined, so a
# symbol that neither R, the C and C++ runtimes nor zlib provide fails the
# link.
#
# R's Windows headers and R.dll are not here: the objects are compiled
# against this R's headers (the same API; Rconfig.h is this system's), and
# R.dll is stood in for by an import library made from a .def file that
# lists the symbols the objects take from R: the objects' undefined symbols
# that this R's libR.so exports (data, which R's headers import with
# __declspec(dllimport), as DATA). zlib is mingw-w64's (libz-mingw-w64-dev,
# linked statically as Rtools does). Debian's mingw-w64 links msvcrt, not
# Rtools' UCRT.
#
#   bash tools/win-dll.sh [build directory]     (default _build/win)
# prints what the DLL imports and the 64-bit file-position calls it makes.
set -euo pipefail

cd "$(dirname "$0")/.."
out="${1:-_build/win}"
host=x86_64-w64-mingw32
# the posix threads model, as Rtools' compilers (std::thread: g.getmeta()'s
# second thread); Debian's default mingw g++ is the win32 model, which has
# none (the core then builds on one thread: GRAVCAL_NO_THREADS)
cxx="${MINGW_CXX:-$(command -v $host-g++-posix || echo $host-g++)}"
rscript="${RSCRIPT:-Rscript}"

r_inc=$("$rscript" -e 'cat(R.home("include"))')
r_lib=$("$rscript" -e 'cat(file.path(R.home("lib"), "libR.so"))')
rcpp_inc=$("$rscript" -e 'cat(system.file("include", package = "Rcpp"))')
eigen_inc=$("$rscript" -e 'cat(system.file("include", package = "RcppEigen"))')
[ -f "$r_lib" ] || { echo "win-dll: $r_lib not found (R built without --enable-R-shlib?)" >&2; exit 1; }

rm -rf "$out"
mkdir -p "$out"
out=$(cd "$out" && pwd)
# the package's own flags for Windows, as R reads them (from src/)
pkg_cppflags=$(sed -n 's/^PKG_CPPFLAGS *= *//p' src/Makevars.win)
pkg_libs=$(sed -n 's/^PKG_LIBS *= *//p' src/Makevars.win)
# R's compile line on Windows (-DNDEBUG as R's Makeconf); -Wno-cast-function-type:
# R's routine registration casts every entry to DL_FUNC. WIN_JOBS (2)
# files at a time; any failure fails the script.
compile() {
  # shellcheck disable=SC2086
  "$cxx" -std=gnu++17 -O2 -DNDEBUG -Wall -Wextra -Wno-cast-function-type -Werror \
    -I"$r_inc" $pkg_cppflags -isystem "$rcpp_inc" -isystem "$eigen_inc" \
    -c "$1" -o "$out/${1%.cpp}.o" &&
    echo "mingw-w64: src/$1 compiles (-O2 -Wall -Wextra -Werror)"
}
export -f compile
export cxx r_inc pkg_cppflags rcpp_inc eigen_inc out
cd src
printf '%s\n' *.cpp | xargs -P "${WIN_JOBS:-2}" -I{} bash -c 'compile "$1"' _ {} ||
  { echo "win-dll: src/*.cpp do not all compile for Windows (above)" >&2; exit 1; }
cd ..
n_src=$(ls src/*.cpp | wc -l)
n_obj=$(ls "$out"/*.o | wc -l)
[ "$n_obj" -eq "$n_src" ] || { echo "win-dll: $n_obj objects for $n_src sources" >&2; exit 1; }

# the symbols the objects take from R
"$host-nm" -u "$out"/*.o | awk 'NF == 2 && $1 == "U" { print $2 }' | sort -u > "$out/undefined.txt"
"$host-nm" --defined-only "$out"/*.o | awk 'NF == 3 { print $3 }' | sort -u > "$out/defined.txt"
nm -D --defined-only "$r_lib" | awk 'NF == 3 { print $3 }' | sort -u > "$out/libR-exports.txt"
comm -23 "$out/undefined.txt" "$out/defined.txt" > "$out/external.txt"
{
  echo "LIBRARY R.dll"
  echo "EXPORTS"
  # data: referenced as __imp_NAME only
  sed -n 's/^__imp_//p' "$out/external.txt" | sort -u | comm -12 - "$out/libR-exports.txt" |
    while read -r s; do
      if grep -qx "$s" "$out/external.txt"; then echo "  $s"; else echo "  $s DATA"; fi
    done
  # functions called directly
  grep -v '^__imp_' "$out/external.txt" | comm -12 - "$out/libR-exports.txt" |
    while read -r s; do
      grep -qx "__imp_$s" "$out/external.txt" || echo "  $s"
    done
} > "$out/R.def"
n_r=$(($(wc -l < "$out/R.def") - 2))
[ "$n_r" -gt 0 ] || { echo "win-dll: no R symbols found in the objects" >&2; exit 1; }
"$host-dlltool" -d "$out/R.def" -l "$out/libR.a"
echo "mingw-w64: import library for R.dll from $n_r of R's symbols ($out/R.def)"

# the link, as R's SHLIB on Windows (Makevars.win's PKG_LIBS), static
# runtimes (libgcc, libstdc++, winpthread) and zlib
# shellcheck disable=SC2086
"$cxx" -shared -static -s -o "$out/gravcal.dll" "$out"/*.o $pkg_libs -L"$out" -lR \
  -Wl,--no-undefined -Wl,--fatal-warnings
echo "mingw-w64: gravcal.dll links (-Wl,--no-undefined): $(stat -c %s "$out/gravcal.dll") bytes"

# what it needs from Windows, and that R finds its entry point
"$host-objdump" -p "$out/gravcal.dll" > "$out/objdump.txt"
dlls=$(sed -n 's/^\tDLL Name: //p' "$out/objdump.txt" | sort -u | tr '\n' ' ')
echo "mingw-w64: gravcal.dll imports from: $dlls"
for d in $(sed -n 's/^\tDLL Name: //p' "$out/objdump.txt"); do
  case "$d" in
    R.dll|KERNEL32.dll|msvcrt.dll|api-ms-win-*|ucrtbase.dll|USER32.dll|ADVAPI32.dll) ;;
    *) echo "win-dll: gravcal.dll imports from $d, which a Windows R does not provide" >&2; exit 1 ;;
  esac
done
grep -q 'R_init_gravcal' "$out/objdump.txt" ||
  { echo "win-dll: R_init_gravcal is not exported" >&2; exit 1; }

# files over 2 GiB: the objects seek and tell in 64 bits (_fseeki64,
# _ftelli64, imported from the C runtime: __imp_), never through
# fseek/ftell (a 32-bit long on Windows). mingw-w64's msvcrt library
# supplies the two over fgetpos/fsetpos (a 64-bit fpos_t), hence those in
# the DLL's imports; UCRT (Rtools) has them itself.
narrow=$(grep -xE '(__imp_)?(fseek|ftell)' "$out/undefined.txt" || true)
if [ -n "$narrow" ]; then
  echo "win-dll: the objects call $(echo "$narrow" | tr '\n' ' ')(32-bit positions on Windows)" >&2
  exit 1
fi
for s in _fseeki64 _ftelli64; do
  grep -qxE "(__imp_)?$s" "$out/undefined.txt" || { echo "win-dll: the objects do not call $s" >&2; exit 1; }
done
echo "mingw-w64: file positions through _fseeki64/_ftelli64, no fseek/ftell"
