"""SAPIEN 2's `sapien.core` on partsim: `import partsim.core as sapien` gives partsim.sapien, the
SAPIEN adapter (partsim's own API is `import partsim`)."""

import sys as _sys

from . import sapien as _sapien

_sys.modules[__name__] = _sapien
