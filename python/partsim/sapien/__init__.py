"""SAPIEN's API on partsim: `import partsim.sapien as sapien` runs SAPIEN 3 scripts, and
`import partsim.core as sapien` SAPIEN 2.2 ones (for `import sapien.core as sapien`).

This is an adapter beside partsim's own API, not a change of it: `import partsim` gives
partsim's classes as they are. The adapter's objects stand for partsim's (`partsim_object(x)`
gives the partsim object, for partsim's own functions); SAPIEN's names answer with SAPIEN's
argument shapes, defaults and meanings, and where a name exists in both with different
meanings, SAPIEN's meaning wins here:

- `camera.get_picture("Position")`: the 4th channel is the OpenGL depth-buffer value in [0, 1]
  (1 where nothing was seen), as SAPIEN's; partsim's depth in metres is `camera.get_depth()`.
- `camera.get_picture("Segmentation")`: uint32 (h, w, 4), visual id then actor/link id then two
  zero channels, as SAPIEN's; "PositionSegmentation" as SAPIEN 3's.
- `joint.get_limits()`: (dof, 2), as SAPIEN's; `joint.set_limits` takes that shape too.
- `scene.add_spot_light(position, direction, inner_fov, outer_fov, ...)`: full cone angles.
- `loader.parse(urdf_file)`: SAPIEN's (builders), not partsim's (URDF text).
- contacts: `contact.bodies` (SAPIEN 3, components) and `contact.actor0/actor1` (SAPIEN 2);
  `point.impulse` is the impulse on body 0.

Modules as SAPIEN's: `physx`, `render`, `utils` (the browser viewer). Names the adapter does not
define are partsim's own (`sapien.KinematicModel`, ...). docs/sapien_compatibility.md lists every
call with what is supported and what is not.
"""

from __future__ import annotations

from .. import _partsim as _p
from . import physx, render, utils  # noqa: F401
from ._adapter import (UNSUPPORTED, PartsimError, Pose, UnsupportedError,  # noqa: F401
                       partsim_object, set_log_level)
from ._entity import Component, Entity  # noqa: F401
from ._scene import (ActorBuilder, ArticulationBuilder, LinkBuilder, Scene,  # noqa: F401
                     URDFLoader)
from .physx import SceneConfig  # noqa: F401
from .render import RenderBodyComponent, RenderMaterial, SapienRenderer  # noqa: F401

__version__ = _p.__version__


class Engine:
    """SAPIEN 2's Engine: creates scenes. partsim needs none; this one exists so that SAPIEN 2
    scripts run unchanged."""

    def __init__(self, thread_count=0, tolerance_length=0.1, tolerance_speed=0.2):
        self._renderer = None

    def set_renderer(self, renderer):
        self._renderer = renderer

    def get_renderer(self):
        return self._renderer

    renderer = property(get_renderer, set_renderer)

    def create_scene(self, config=None):
        """A new Scene with `config` (SceneConfig; default settings when None)."""
        return Scene(config if config is not None else SceneConfig())

    def create_physical_material(self, static_friction, dynamic_friction, restitution):
        return physx.PhysxMaterial(static_friction, dynamic_friction, restitution)

    def set_log_level(self, level):
        set_log_level(level)


VulkanRenderer = SapienRenderer


class KuafuRenderer:
    """SAPIEN 2's ray tracer: in partsim, the path tracer of each scene."""

    def __init__(self, *args, **kwargs):
        raise PartsimError(
            "KuafuRenderer: partsim's ray tracer is a scene backend: "
            "scene.set_render_backend('pathtracer') (or sapien.render.set_camera_shader_dir('rt') "
            "before creating the scene)")


class System:
    """Base of SAPIEN 3's systems (physx.PhysxCpuSystem, render.RenderSystem)."""


class Widget:
    """SAPIEN 3's viewer plug-in base: the browser viewer has no plug-ins."""


# SAPIEN 2's names for the same handles
Actor = ActorBase = ActorStatic = ActorDynamicBase = Entity
Articulation = ArticulationBase = KinematicArticulation = physx.PhysxArticulation
Link = LinkBase = KinematicLink = physx.PhysxArticulationLinkComponent
Joint = JointBase = KinematicJoint = physx.PhysxArticulationJoint
CameraEntity = render.RenderCameraComponent
PhysicalMaterial = physx.PhysxMaterial
Contact = SapienContact = physx.PhysxContact
ContactPoint = physx.PhysxContactPoint
Viewer = utils.Viewer


def __getattr__(name):
    """partsim's own names (sapien.ActorType, sapien.KinematicModel, ...)."""
    try:
        return getattr(_p, name)
    except AttributeError:
        raise AttributeError(f"module 'partsim.sapien' has no attribute '{name}'") from None
