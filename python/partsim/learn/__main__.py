"""``python3 -m partsim.learn``: the command line of :mod:`partsim.learn.protocol` (the same as
``partsim learn``)."""

import sys

from .protocol import main

if __name__ == "__main__":
    sys.exit(main())
