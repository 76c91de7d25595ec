"""partsim: simulation of robots interacting with articulated objects, on MuJoCo.

The compiled extension `partsim._partsim` holds the bindings; everything public in it is
re-exported here, so `import partsim; partsim.Scene()` works. SAPIEN's API is an adapter beside
partsim's own, imported on request: `import partsim.sapien as sapien` for SAPIEN 3 scripts,
`import partsim.core as sapien` for SAPIEN 2's `import sapien.core as sapien` (see
docs/sapien_compatibility.md); importing partsim changes none of partsim's classes. Where
Gymnasium is installed, the environments of partsim.envs are
registered with it (`gymnasium.make("partsim/OpenCabinetDrawer-v0")`).
"""


# The Debian 12 packages of the shared libraries the compiled module and the command line link
# (a wheel carries MuJoCo but not these): a missing one is named with the command that installs
# them all. Mesa's EGL and its CPU rasterizer (libegl-mesa0, libgl1-mesa-dri) are loaded when a
# renderer starts.
SYSTEM_PACKAGES = {
    "libEGL.so.1": "libegl1", "libOpenGL.so.0": "libopengl0", "libembree3.so.3": "libembree3-3",
    "libassimp.so.5": "libassimp5", "libompl.so.16": "libompl16",
    "libavcodec.so.59": "libavcodec59", "libavformat.so.59": "libavformat59",
    "libavutil.so.57": "libavutil57", "libswscale.so.6": "libswscale6",
    "libpng16.so.16": "libpng16-16", "libjpeg.so.62": "libjpeg62-turbo",
    "libqhull_r.so.8.0": "libqhull-r8.0", "libtinyxml2.so.9": "libtinyxml2-9",
    "libHACD.so.3.24": "libbullet-extras3.24", "libboost_thread.so.1.74.0": "libboost-thread1.74.0",
}
_MESA = ("libegl-mesa0", "libgl1-mesa-dri")


def _missing_library_message(error: ImportError) -> str:
    """The ImportError's text, with the Debian packages to install when it names a missing
    system library."""
    text = str(error)
    missing = next((lib for lib in SYSTEM_PACKAGES if lib in text), None)
    if missing is None and "cannot open shared object file" not in text:
        return text
    packages = " ".join(sorted(set(SYSTEM_PACKAGES.values()) | set(_MESA)))
    what = f"{missing} (Debian's {SYSTEM_PACKAGES[missing]})" if missing else "a system library"
    return (f"partsim's compiled module cannot load: {what} is missing ({text}). partsim needs "
            f"these Debian 12 packages: apt-get install {packages}")


def _check_numpy():
    """The compiled module is built with Debian 12's pybind11 (2.10), whose numpy arrays use
    numpy 1.x's C API: with numpy 2 the first array crashes the process, so refuse to load."""
    import numpy

    if int(numpy.__version__.split(".")[0]) >= 2:
        raise ImportError(
            f"partsim needs numpy 1.x (this is numpy {numpy.__version__} from "
            f"{numpy.__file__}): its compiled module is built with pybind11 2.10, which predates "
            "numpy 2's C API; install numpy<2 (pip install 'numpy<2')")


_check_numpy()
try:
    from ._partsim import *  # noqa: F401,F403
except ImportError as _e:
    raise ImportError(_missing_library_message(_e)) from _e
from ._partsim import PartsimError, PartsimIndexError  # noqa: F401  (explicit for readers)
from ._partsim import __version__  # noqa: F401  (the project's version, set by CMake)
from . import vision  # noqa: F401  (partsim.vision: COCO masks, the perception evaluators)
from ._cli import find_cli  # noqa: F401  (the command line that goes with this package)


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
