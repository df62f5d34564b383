#!/usr/bin/env bash
# Set-up and entry point for a fresh Debian 12 machine (see README.md).
#   ./dev.sh demo   installs what is missing, then runs the main job on the built-in sample part
#   ./dev.sh test   installs what is missing (test tools too), then runs the whole test suite
# Both are idempotent: a second run installs nothing.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$here"
venv="$here/.venv"
export TMPDIR="${TMPDIR:-/var/tmp}"   # apt sometimes loses its temporary files in /tmp

as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

need_debs() {
  local missing=()
  for pkg in "$@"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "== installing Debian packages: ${missing[*]}"
    as_root env DEBIAN_FRONTEND=noninteractive apt-get update -q
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${missing[@]}"
  fi
}

need_venv() {
  local requirements=("$@") stamp="$venv/.conformal-stamp" digest
  if [ ! -x "$venv/bin/python" ]; then
    echo "== creating venv $venv (system site packages: FreeCAD, PySide2, scipy)"
    /usr/bin/python3 -m venv --system-site-packages "$venv"
  fi
  # FreeCAD's modules live outside sys.path; a .pth file makes `import FreeCAD` work in the venv.
  local site; site="$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
  echo "/usr/lib/freecad-python3/lib" > "$site/freecad.pth"
  # The checkout itself, so `python -m freecad_conformal` works from any folder.
  echo "$here" > "$site/conformal-checkout.pth"
  digest="$(cat "${requirements[@]}" | sha256sum | cut -d' ' -f1)"
  if [ "$(cat "$stamp" 2>/dev/null)" != "$digest" ]; then
    echo "== installing Python packages: ${requirements[*]}"
    "$venv/bin/python" -m pip install -q --disable-pip-version-check $(printf -- '-r %s ' "${requirements[@]}")
    echo "$digest" > "$stamp"
  fi
}

case "${1:-}" in
  demo)
    need_debs freecad python3-venv
    need_venv requirements.txt
    shift
    exec "$venv/bin/python" -m freecad_conformal demo --out out "$@"
    ;;
  test)
    need_debs freecad python3-venv xvfb xauth linuxcnc-uspace python3-wxgtk4.0 python3-dbus fonts-dejavu-core
    need_venv requirements.txt requirements-test.txt
    shift
    exec "$venv/bin/python" -m pytest -q -p no:cacheprovider "$@"
    ;;
  *)
    echo "usage: ./dev.sh demo|test [extra arguments]" >&2
    exit 2
    ;;
esac
