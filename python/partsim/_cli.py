"""The `partsim` command of an installed wheel, and where the command line is.

A wheel carries the C++ command line in its package folder (``partsim/bin/partsim``); pip's
``partsim`` entry point calls :func:`main`, which runs it with this interpreter named in
``PARTSIM_PYTHON`` (so that ``partsim learn`` imports this very package).
"""

from __future__ import annotations

import os
import shutil
import sys

__all__ = ["find_cli", "main"]


def find_cli() -> str | None:
    """The partsim command line that goes with this package, or None: ``$PARTSIM_CLI``, then the
    wheel's ``partsim/bin/partsim``, the build tree's ``build/partsim`` (beside
    ``build/python/partsim``), an install prefix's ``PREFIX/bin/partsim`` (the package in
    ``PREFIX/lib/python3/dist-packages``), then ``partsim`` on PATH."""
    if os.environ.get("PARTSIM_CLI"):
        return os.environ["PARTSIM_CLI"]
    package = os.path.dirname(os.path.abspath(__file__))
    for candidate in (
        os.path.join(package, "bin", "partsim"),
        os.path.join(package, "..", "..", "partsim"),
        os.path.join(package, "..", "..", "..", "..", "bin", "partsim"),
    ):
        candidate = os.path.normpath(candidate)
        if os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return candidate
    return shutil.which("partsim")


def main() -> int:
    """Runs the wheel's command line with the arguments given (the ``partsim`` entry point)."""
    package = os.path.dirname(os.path.abspath(__file__))
    cli = os.path.join(package, "bin", "partsim")
    if not os.path.isfile(cli):
        sys.stderr.write(f"partsim: this package has no command line at {cli} (a build tree's "
                         "package: run build/partsim)\n")
        return 1
    os.environ.setdefault("PARTSIM_PYTHON", sys.executable)
    sys.stdout.flush()
    os.execv(cli, [cli] + sys.argv[1:])
    return 1  # not reached


if __name__ == "__main__":
    sys.exit(main())
