"""``python3 -m partsim.distributed COMMAND ... --ray auto|ADDRESS``: what ``partsim COMMAND
... --ray`` runs (see :mod:`partsim.distributed`)."""

import sys

from . import main

if __name__ == "__main__":
    sys.exit(main())
