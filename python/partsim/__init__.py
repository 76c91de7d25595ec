"""partsim: simulation of robots interacting with articulated objects, on MuJoCo 2.2.2.

The compiled extension `partsim._partsim` holds the bindings; everything public in it is
re-exported here, so `import partsim; partsim.Scene()` works.
"""

from ._partsim import *  # noqa: F401,F403
from ._partsim import PartsimError, PartsimIndexError  # noqa: F401  (explicit for readers)

__version__ = "0.1.0"
