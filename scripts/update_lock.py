#!/usr/bin/env python3
"""Writes requirements.lock from requirements.in: every package pip resolves for them on this
platform (Linux x86_64, CPython 3.11), each pinned to one version with its file's sha256.

Usage: .venv/bin/python scripts/update_lock.py   (needs PyPI; touches nothing but the lock)
"""

import json
import os
import re
import subprocess
import sys
import tempfile

HEADER = """\
# partsim's Python packages from PyPI, exact versions with their hashes: the one lock file that
# scripts/setup.sh installs into the project's venv (`pip install --require-hashes --no-deps`).
# Written by scripts/update_lock.py from requirements.in (edit that file, not this one): the
# packages named there and every dependency pip resolves for them on Linux x86_64, CPython 3.11.
# Debian's modules that the venv also sees (torch, matplotlib, rospy) are not listed here.
"""


NO_DEPS = "# lock: no-deps"


def resolve(requirements: list, tmp: str, no_deps: bool) -> list:
    """pip's install report for ``requirements`` (lines of a requirements file), resolved for
    this platform as if nothing were installed; with ``no_deps``, the packages alone."""
    req = os.path.join(tmp, "no-deps.in" if no_deps else "requirements.in")
    with open(req, "w", encoding="utf-8") as f:
        f.write("\n".join(requirements) + "\n")
    report = os.path.join(tmp, "report-no-deps.json" if no_deps else "report.json")
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--dry-run", "--ignore-installed",
         "--quiet", "--disable-pip-version-check", "--report", report, "-r", req]
        + (["--no-deps"] if no_deps else []),
        check=True,
    )
    with open(report, encoding="utf-8") as f:
        return json.load(f)["install"]


def main() -> int:
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with open(os.path.join(root, "requirements.in"), encoding="utf-8") as f:
        lines_in = [line.rstrip("\n") for line in f]
    # a pin marked "# lock: no-deps" is locked alone: its declared dependencies are not
    # resolved (they are pinned on their own lines, or come from Debian); the lock is installed
    # with --no-deps, so pip never checks them
    alone = [line.split("#")[0].strip() for line in lines_in if NO_DEPS in line]
    rest = [line for line in lines_in if NO_DEPS not in line]
    with tempfile.TemporaryDirectory() as tmp:
        items = resolve(rest, tmp, no_deps=False)
        if alone:
            items += resolve(alone, tmp, no_deps=True)
    lines = [HEADER]
    for item in sorted(items, key=lambda i: i["metadata"]["name"].lower()):
        name, version = item["metadata"]["name"], item["metadata"]["version"]
        hashes = item["download_info"].get("archive_info", {}).get("hashes", {})
        if "sha256" not in hashes:
            print(f"update_lock: pip gave no sha256 for {name} {version}", file=sys.stderr)
            return 1
        name = re.sub(r"[-_.]+", "-", name).lower()  # the normalised name (PEP 503)
        lines.append(f"{name}=={version} \\\n    --hash=sha256:{hashes['sha256']}\n")
    with open(os.path.join(root, "requirements.lock"), "w", encoding="utf-8") as f:
        f.writelines(lines)
    print(f"update_lock: {len(items)} packages written to requirements.lock")
    return 0


if __name__ == "__main__":
    sys.exit(main())
