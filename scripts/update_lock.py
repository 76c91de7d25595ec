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


def main() -> int:
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with tempfile.TemporaryDirectory() as tmp:
        report = os.path.join(tmp, "report.json")
        subprocess.run(
            [sys.executable, "-m", "pip", "install", "--dry-run", "--ignore-installed",
             "--quiet", "--disable-pip-version-check", "--report", report,
             "-r", os.path.join(root, "requirements.in")],
            check=True,
        )
        with open(report, encoding="utf-8") as f:
            items = json.load(f)["install"]
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
