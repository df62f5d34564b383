#!/usr/bin/env bash
# The FreeCAD 1.0 leg: Debian 13 ("trixie": FreeCAD 1.0, Python 3.13, PySide2/Qt 5.15,
# OCCT 7.8, numpy 2) in a chroot on this Debian 12 machine, from the machine's own Debian
# mirror and PyPI. Installs only what is missing; a second run installs nothing.
#
#   sudo ci/freecad1.sh test [PYTEST ARGS]   set up (first time ~5 min, ~3.5 GB), then run the
#                                            whole suite on FreeCAD 1.0 against this checkout
#   sudo ci/freecad1.sh setup                set up only (this checkout as committed, the parts)
#   sudo ci/freecad1.sh run CMD...           run CMD in the chroot (project at /root/conformal)
#   sudo ci/freecad1.sh mount                mount what the chroot needs and leave it mounted
#                                            (benchmarks/plan_speed.py times runs in it)
#   sudo ci/freecad1.sh umount               unmount what a killed run left mounted
#
# Environment: ROOT (default /srv/trixie), MIRROR (default: the host's first Debian mirror),
# PARTS (default ../shared/parts beside the project).
# Why a chroot: Debian 12 has only FreeCAD 0.20.2, and installing trixie's FreeCAD on the host
# would replace the 0.20.2 the other leg tests.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ROOT="${ROOT:-/srv/trixie}"
PARTS="${PARTS:-$here/../shared/parts}"
export TMPDIR=/var/tmp DEBIAN_FRONTEND=noninteractive
[ "$(id -u)" = 0 ] || { echo "ci/freecad1.sh needs root (debootstrap, chroot, mounts)" >&2; exit 1; }

host_mirror() {
  local uri
  uri="$(grep -hE '^URIs:' /etc/apt/sources.list.d/*.sources 2>/dev/null | awk '{print $2}' \
         | grep -E '/debian/?$' | head -n1 || true)"
  [ -n "$uri" ] || uri="$(grep -hE '^deb ' /etc/apt/sources.list 2>/dev/null | awk '{print $2}' | head -n1 || true)"
  [ -n "$uri" ] || { echo "no Debian mirror configured on this machine; set MIRROR" >&2; exit 1; }
  echo "${uri%/}"
}
MIRROR="${MIRROR:-$(host_mirror)}"

# FreeCAD and what ./dev.sh test installs on Debian 12; python3-netifaces because OctoPrint's
# netifaces has no Python 3.13 wheel and the chroot has no compiler.
DEBS=(freecad xvfb xauth python3-shapely python3-numpy python3-matplotlib python3-venv
      python3-pip git ca-certificates linuxcnc-uspace python3-wxgtk4.0 python3-dbus
      fonts-dejavu-core python3-netifaces)
MOUNTS=(proc sys dev dev/pts)
MOUNTED=()

mount_all() {
  local d
  for d in "${MOUNTS[@]}"; do
    if ! mountpoint -q "$ROOT/$d"; then mount --bind "/$d" "$ROOT/$d"; MOUNTED+=("$d"); fi
  done
}
umount_list() {
  local i
  for ((i=$#; i>=1; i--)); do
    local d="${!i}"
    if mountpoint -q "$ROOT/$d"; then umount "$ROOT/$d" || umount -l "$ROOT/$d"; fi
  done
}
umount_mine() { [ ${#MOUNTED[@]} -eq 0 ] || umount_list "${MOUNTED[@]}"; }
in_root() { chroot "$ROOT" env -u PIP_FIND_LINKS HOME=/root TMPDIR=/var/tmp "$@"; }

setup() {
  if ! command -v debootstrap >/dev/null; then
    apt-get update -q && apt-get install -y -q debootstrap
  fi
  if [ ! -x "$ROOT/usr/bin/apt-get" ]; then
    echo "== debootstrap trixie into $ROOT from $MIRROR"
    mkdir -p "$ROOT"
    debootstrap --variant=minbase trixie "$ROOT" "$MIRROR"
  fi
  printf 'deb %s trixie main\ndeb %s trixie-updates main\ndeb %s trixie-security main\n' \
    "$MIRROR" "$MIRROR" "${MIRROR%/debian}/debian-security" > "$ROOT/etc/apt/sources.list"
  printf '#!/bin/sh\nexit 101\n' > "$ROOT/usr/sbin/policy-rc.d"    # no daemons in the chroot
  chmod +x "$ROOT/usr/sbin/policy-rc.d"
  cp -f /etc/resolv.conf "$ROOT/etc/resolv.conf" 2>/dev/null || true
  chmod 755 "$ROOT/root"      # a test runs a subprocess as 'nobody' that reaches /root/venv
  mount_all
  local missing=() pkg
  for pkg in "${DEBS[@]}"; do
    in_root dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" \
      || missing+=("$pkg")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "== apt-get install (chroot): ${missing[*]}"
    in_root apt-get update -q
    in_root apt-get install -y -q --no-install-recommends "${missing[@]}"
    in_root apt-get clean
  fi
  # The host reaches PyPI through the CAs in /usr/local/share/ca-certificates: trust them too.
  if compgen -G "/usr/local/share/ca-certificates/*.crt" >/dev/null; then
    mkdir -p "$ROOT/usr/local/share/ca-certificates"
    if ! cmp -s <(cat /usr/local/share/ca-certificates/*.crt) \
                <(cat "$ROOT"/usr/local/share/ca-certificates/*.crt 2>/dev/null); then
      cp -f /usr/local/share/ca-certificates/*.crt "$ROOT/usr/local/share/ca-certificates/"
      in_root update-ca-certificates
    fi
  fi
  if [ ! -x "$ROOT/root/venv/bin/python" ]; then
    in_root python3 -m venv --system-site-packages /root/venv
  fi
  local site
  site="$(in_root /root/venv/bin/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
  echo /usr/lib/freecad-python3/lib > "$ROOT$site/freecad.pth"
  echo /root/conformal > "$ROOT$site/conformal-checkout.pth"
  # This checkout, as committed (CI tests a clean clone).
  rm -rf "$ROOT/root/conformal"
  git clone -q "$here" "$ROOT/root/conformal"
  if [ -d "$PARTS" ]; then
    mkdir -p "$ROOT/root/shared"
    rm -rf "$ROOT/root/shared/parts"
    cp -a "$PARTS" "$ROOT/root/shared/parts"
  fi
  local digest stamp="$ROOT/root/venv/.conformal-stamp"
  digest="$(cat "$here/requirements.txt" "$here/requirements-test.txt" | sha256sum | cut -d' ' -f1)"
  if [ "$(cat "$stamp" 2>/dev/null)" != "$digest" ]; then
    in_root /root/venv/bin/pip install -q --disable-pip-version-check \
      -r /root/conformal/requirements.txt -r /root/conformal/requirements-test.txt
    echo "$digest" > "$stamp"
  fi
  in_root /root/venv/bin/python -c 'import FreeCAD, sys; print("== FreeCAD", ".".join(FreeCAD.Version()[:3]), "on Python", sys.version.split()[0])'
}

trap umount_mine EXIT
case "${1:-test}" in
  test)
    shift || true
    setup
    # The parts are copied to /root/shared/parts: a host path in CONFORMAL_PARTS means nothing
    # inside the chroot.
    in_root env CONFORMAL_PARTS=/root/shared/parts bash -c 'cd /root/conformal && \
      CONFORMAL_REQUIRE_PARTS=${CONFORMAL_REQUIRE_PARTS:-0} \
      /root/venv/bin/python -m pytest -q -p no:cacheprovider "$@"' pytest "$@"
    ;;
  setup) setup ;;
  run) shift; mount_all; in_root "$@" ;;
  mount) mount_all; MOUNTED=() ;;
  umount) umount_list "${MOUNTS[@]}" ;;
  *) echo "usage: $0 test [PYTEST ARGS] | setup | run CMD... | mount | umount" >&2; exit 2 ;;
esac
