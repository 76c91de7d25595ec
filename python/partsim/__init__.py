"""partsim: simulation of robots interacting with articulated objects, on MuJoCo.

The compiled extension `partsim._partsim` holds the bindings; everything public in it is
re-exported here, so `import partsim; partsim.Scene()` works. SAPIEN's names are added beside
partsim's own (see partsim._sapien and docs/sapien_compatibility.md), so that SAPIEN 2.2 and 3.x
scripts run with `import partsim as sapien` (or `import partsim.core as sapien` for SAPIEN 2's
`import sapien.core as sapien`). Where Gymnasium is installed, the environments of partsim.envs are
registered with it (`gymnasium.make("partsim/OpenCabinetDrawer-v0")`).
"""

import sys as _sys

from ._partsim import *  # noqa: F401,F403
from ._partsim import PartsimError, PartsimIndexError  # noqa: F401  (explicit for readers)
from ._partsim import __version__  # noqa: F401  (the project's version, set by CMake)
from ._sapien import (  # noqa: F401
    Engine, KuafuRenderer, RenderBodyComponent, RenderMaterial, SapienContact, SapienRenderer,
    SceneConfig, Viewer, VulkanRenderer, physx, render, set_log_level, utils)
from . import vision  # noqa: F401  (partsim.vision: COCO masks, the perception evaluators)


# SAPIEN 2 scripts say `import sapien.core as sapien`: partsim.core is partsim itself
core = _sys.modules[__name__]
_sys.modules[__name__ + ".core"] = core


def _register_gymnasium_envs():
    """Registers partsim.envs' environments with Gymnasium, when it is installed:
    ``partsim/OpenCabinetDrawer-v0`` and ``partsim/OpenCabinetDoor-v0``, for ``gymnasium.make``
    and ``gymnasium.make_vec``. The entry points are strings: partsim.envs is imported by the
    first make. An id already registered is left as it is (no warning on a second import)."""
    try:
        import gymnasium
    except ImportError:
        return
    for env_id, task in (("partsim/OpenCabinetDrawer-v0", "drawer"),
                         ("partsim/OpenCabinetDoor-v0", "door")):
        if env_id in gymnasium.registry:
            continue
        gymnasium.register(
            id=env_id,
            entry_point="partsim.envs:OpenCabinetEnv",
            vector_entry_point="partsim.envs:VectorOpenCabinetEnv",
            max_episode_steps=250,  # OpenCabinetEnv's default
            kwargs={"task": task},
        )


_register_gymnasium_envs()
