# Sourced by tools/setup.sh and tools/setup-test.sh: apt_missing PKG...
# installs the Debian packages among PKG that are not installed yet, when
# apt-get is there and we are root (else it does nothing: the caller's
# later steps say what is still missing).
apt_missing() {
  command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ] || return 0
  local missing="" p
  for p in "$@"; do
    dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
  done
  [ -n "$missing" ] || return 0
  echo "setup: installing Debian packages:$missing"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq >/dev/null
  # shellcheck disable=SC2086
  apt-get install -y -qq --no-install-recommends $missing >/dev/null
}
