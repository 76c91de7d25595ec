#!/usr/bin/env bash
# Makes the project's Python environment, .venv, and installs requirements.lock into it.
# Usage: bash scripts/setup_venv.sh   (scripts/setup.sh runs it after the Debian packages)
#        PARTSIM_PYTHON=/path/to/python3.11 bash scripts/setup.sh   to make it from another CPython
#
# The venv is made from Debian's /usr/bin/python3 by default, with --system-site-packages:
# Debian's torch, matplotlib and ROS 1 modules stay in sight, and the lock adds (and, for numpy,
# pytest and pillow, overrides) what comes from PyPI. Another CPython 3.11 works the same way but
# sees its own site-packages instead of Debian's: partsim.learn (torch) and the ROS 1 tests are
# then skipped. The lock is installed with --require-hashes and --no-deps (it lists every
# dependency), and again only when it changed since the last install; a venv made from another
# interpreter than the one asked for is made again.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=.venv
python="${PARTSIM_PYTHON:-/usr/bin/python3}"
if ! command -v "$python" >/dev/null; then
  echo "partsim setup: PARTSIM_PYTHON=$python is not an interpreter" >&2
  exit 1
fi
python="$(command -v "$python")"
version="$("$python" -c 'import sys; print("%d.%d" % sys.version_info[:2])')"
if [ "$version" != "3.11" ]; then
  echo "partsim setup: $python is Python $version; partsim's lock file is for CPython 3.11" >&2
  exit 1
fi
base="$("$python" -c 'import sys; print(sys.base_prefix)')"
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import sys" 2>/dev/null ||
    [ "$("$venv/bin/python" -c 'import sys; print(sys.base_prefix)')" != "$base" ]; then
  rm -rf "$venv"
  echo "partsim setup: making $venv from $python"
  "$python" -m venv --system-site-packages "$venv"
fi
stamp="$venv/.partsim-requirements.sha256"
if ! sha256sum --check --status "$stamp" 2>/dev/null; then
  echo "partsim setup: installing requirements.lock into $venv"
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-cache-dir --require-hashes \
    --no-deps -r requirements.lock
  sha256sum requirements.lock >"$stamp"
fi
