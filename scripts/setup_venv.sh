#!/usr/bin/env bash
# Makes the project's Python environment, .venv, and installs requirements.lock into it.
# Usage: bash scripts/setup_venv.sh   (scripts/setup.sh runs it after the Debian packages)
#
# The venv is made from Debian's /usr/bin/python3 with --system-site-packages: Debian's numpy,
# pytest, torch and ROS 1 modules stay in sight, and the lock adds what comes from PyPI. The lock
# is installed with --require-hashes and --no-deps (every package from PyPI is in it, with its
# dependencies), and again only when it changed since the last install.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=.venv
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import sys" 2>/dev/null; then
  rm -rf "$venv"
  /usr/bin/python3 -m venv --system-site-packages "$venv"
fi
stamp="$venv/.partsim-requirements.sha256"
if ! sha256sum --check --status "$stamp" 2>/dev/null; then
  echo "partsim setup: installing requirements.lock into $venv"
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-cache-dir --require-hashes \
    --no-deps -r requirements.lock
  sha256sum requirements.lock >"$stamp"
fi
