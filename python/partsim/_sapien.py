"""SAPIEN's API on partsim, so that SAPIEN 2.2 and 3.x scripts run with `import partsim as sapien`.

partsim's own classes keep their methods; this module adds SAPIEN's names beside them, with
SAPIEN's argument shapes, defaults and meanings, and the SAPIEN-only classes (Engine,
SapienRenderer, the `render`, `physx` and `utils` submodules). Where a name exists in both and the
meanings differ, SAPIEN's meaning wins and partsim's own convenience keeps another name:

- `camera.get_picture("Position")`: the 4th channel is the OpenGL depth-buffer value in [0, 1]
  (1 where nothing was seen), as SAPIEN's; partsim's depth in metres is `camera.get_depth()`.
- `camera.get_picture("Segmentation")`: uint32 (h, w, 4), visual id then actor/link id then two
  zero channels, as SAPIEN's.
- `joint.get_limits()`: (dof, 2), as SAPIEN's; `joint.set_limits` takes that shape too.
- `scene.add_spot_light(position, direction, inner_fov, outer_fov, ...)`: full cone angles, as
  SAPIEN's; partsim's half angles are the keywords `inner_angle` and `outer_angle`.
- contacts: `contact.actor0/actor1` (SAPIEN 2) and `contact.bodies` (SAPIEN 3) are the handles;
  `point.impulse` is the impulse on actor0 (partsim's C++ convention is the same).

docs/sapien_compatibility.md lists every call with what is supported and what is not.
"""

from __future__ import annotations

import inspect
import math
import os
import sys
import types
import weakref

import numpy as np

from . import _partsim as _p

_WINDOW_MESSAGE = (
    "partsim has no on-screen window: its viewer runs in a web browser (scene.create_viewer() "
    "or partsim.Viewer(scene) print the URL to open). For pictures: camera = "
    "scene.add_camera(name, width, height, fovy, near, far); scene.update_render(); "
    "camera.take_picture(); camera.get_picture('Color'), or run `partsim render`.")


def _add(cls, name=None):
    """Decorator: sets the function as attribute `name` (default: its own name) of `cls`. A
    binding it replaces stays reachable as `__wrapped__` (scripts/gen_stubs.py reads it)."""

    def deco(fn):
        key = name or fn.__name__
        previous = cls.__dict__.get(key)
        if previous is not None and not inspect.isfunction(previous):
            fn.__wrapped__ = previous
        setattr(cls, key, fn)
        return fn

    return deco


def _wrap(cls, name):
    """Decorator: replaces method `name` of `cls`, passing the original as the first argument."""
    original = getattr(cls, name)

    def deco(fn):
        def method(self, *args, **kwargs):
            return fn(original, self, *args, **kwargs)

        method.__name__ = name
        method.__doc__ = (fn.__doc__ or "") + "\n\npartsim's own form: " + (original.__doc__ or "")
        method.__wrapped__ = original
        setattr(cls, name, method)
        return method

    return deco


def _color4(color, what):
    """RGBA from 3 or 4 numbers (alpha 1 when 3)."""
    c = np.asarray(color, dtype=np.float64).reshape(-1)
    if c.size == 3:
        c = np.append(c, 1.0)
    if c.size != 4 or not np.all(np.isfinite(c)):
        raise _p.PartsimError(f"{what}: expected 3 or 4 finite numbers (RGB or RGBA), got "
                              f"{np.asarray(color).tolist()}")
    return c


# ------------------------------------------------------------------------------ log levels

_LOG_LEVELS = {"off": "off", "critical": "error", "err": "error", "error": "error",
               "warn": "warning", "warning": "warning", "info": "warning", "debug": "warning",
               "trace": "warning"}
_set_log_level = _p.set_log_level


def set_log_level(level: str) -> None:
    """SAPIEN's levels ('off', 'critical', 'error', 'warn', 'info', 'debug') or partsim's
    ('off', 'error', 'warning'). partsim writes nothing below warnings: 'info', 'debug' and
    'trace' show warnings and errors."""
    key = str(level).lower()
    if key not in _LOG_LEVELS:
        raise _p.PartsimError(f"set_log_level: unknown level '{level}' (expected one of "
                              f"{', '.join(sorted(_LOG_LEVELS))})")
    _set_log_level(_LOG_LEVELS[key])


# ------------------------------------------------------------------------------ Pose

_pose_init = _p.Pose.__init__


@_add(_p.Pose, "__init__")
def _pose_init_sapien(self, *args, **kwargs):
    """Pose(p=[0,0,0], q=[1,0,0,0]) with q as w, x, y, z; or Pose(matrix) from a 4x4
    homogeneous transformation (SAPIEN 3)."""
    if len(args) == 1 and not kwargs and np.asarray(args[0]).shape == (4, 4):
        m = _p.Pose.from_transformation_matrix(np.asarray(args[0], dtype=np.float64))
        _pose_init(self, m.p, m.q)
    else:
        _pose_init(self, *args, **kwargs)


def _rpy_to_quat(roll, pitch, yaw):
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return np.array([cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy])


def _quat_to_rpy(q):
    w, x, y, z = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.array([roll, pitch, yaw])


@_add(_p.Pose)
def get_p(self):
    """Position (3,) in metres."""
    return self.p


@_add(_p.Pose)
def get_q(self):
    """Quaternion (4,) as w, x, y, z."""
    return self.q


@_add(_p.Pose)
def set_p(self, p):
    self.p = p


@_add(_p.Pose)
def set_q(self, q):
    self.q = q


@_add(_p.Pose)
def get_rpy(self):
    """Roll, pitch, yaw (rad): q = Rz(yaw) Ry(pitch) Rx(roll)."""
    return _quat_to_rpy(self.q)


@_add(_p.Pose)
def set_rpy(self, rpy):
    self.q = _rpy_to_quat(*rpy)


_p.Pose.rpy = property(get_rpy, set_rpy, doc="Roll, pitch, yaw (rad), as SAPIEN 3's.")


# ------------------------------------------------------------------------------ materials


# values the bindings' objects cannot hold (PhysX-only settings, SAPIEN's specular), kept beside
# each object
_extra: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _extra_property(cls, name, default, doc):
    def get(self):
        return _extra.get(self, {}).get(name, default)

    def set(self, value):
        _extra.setdefault(self, {})[name] = value

    setattr(cls, name, property(get, set, doc=doc))


RenderMaterial = _p.RenderMaterial
_render_material_init = _p.RenderMaterial.__init__


@_add(_p.RenderMaterial, "__init__")
def _render_material_init_sapien(self, base_color=None, metallic=None, roughness=None,
                                 specular=None, emission=None, transmission=None, ior=None):
    """A visual material (SAPIEN's RenderMaterial): base_color (RGB or RGBA, linear), metallic,
    roughness; specular and SAPIEN's other PBR inputs are accepted and not used."""
    _render_material_init(self)
    if base_color is not None:
        self.set_base_color(base_color)
    if metallic is not None:
        self.metallic = float(metallic)
    if roughness is not None:
        self.roughness = float(roughness)
    if specular is not None:
        self.specular = float(specular)


_extra_property(_p.RenderMaterial, "specular", 0.5,
                "Accepted for SAPIEN scripts; partsim's shading derives specular from metallic.")


@_add(_p.RenderMaterial)
def set_base_color(self, color):
    self.base_color = _color4(color, "RenderMaterial.set_base_color").astype(np.float32)


_add(_p.RenderMaterial, "get_base_color")(lambda self: self.base_color)
_add(_p.RenderMaterial, "set_metallic")(lambda self, v: setattr(self, "metallic", float(v)))
_add(_p.RenderMaterial, "get_metallic")(lambda self: self.metallic)
_add(_p.RenderMaterial, "set_roughness")(lambda self, v: setattr(self, "roughness", float(v)))
_add(_p.RenderMaterial, "get_roughness")(lambda self: self.roughness)
_add(_p.RenderMaterial, "set_specular")(lambda self, v: setattr(self, "specular", float(v)))
_add(_p.RenderMaterial, "get_specular")(lambda self: self.specular)
_add(_p.RenderMaterial, "set_diffuse_texture_from_file")(
    lambda self, path: setattr(self, "diffuse_texture", str(path)))


def _physical_material(static_friction=0.3, dynamic_friction=0.3, restitution=0.1):
    return _p.PhysicalMaterial(static_friction, dynamic_friction, restitution)


# ------------------------------------------------------------------------------ SceneConfig

def _material_property(field):
    def get(self):
        return getattr(self.default_material, field)

    def set(self, value):
        m = self.default_material
        setattr(m, field, float(value))
        self.default_material = m

    return property(get, set, doc=f"SAPIEN's name for default_material.{field}.")


_p.SceneConfig.default_static_friction = _material_property("static_friction")
_p.SceneConfig.default_dynamic_friction = _material_property("dynamic_friction")
_p.SceneConfig.default_restitution = _material_property("restitution")

# PhysX settings SAPIEN's SceneConfig has and MuJoCo has no counterpart for: kept, not used
_PHYSX_ONLY = {"bounce_threshold": 2.0, "sleep_threshold": 0.005, "solver_velocity_iterations": 1, "enable_pcm": True, "enable_tgs": True,
               "enable_ccd": False, "enable_enhanced_determinism": False,
               "enable_friction_every_iteration": True, "enable_adaptive_force": False,
               "disable_collision_visual": False}


for _k, _v in _PHYSX_ONLY.items():
    _extra_property(_p.SceneConfig, _k, _v, "PhysX's setting: kept, no effect in partsim.")

SceneConfig = _p.SceneConfig
_scene_config_init = _p.SceneConfig.__init__


@_add(_p.SceneConfig, "__init__")
def _scene_config_init_sapien(self, **kwargs):
    """Scene settings with SAPIEN's names too: gravity, default_static_friction,
    default_dynamic_friction, default_restitution, solver_iterations, contact_offset,
    rest_offset; the defaults given to sapien.physx.set_scene_config / set_default_material /
    set_body_config / set_shape_config first. PhysX-only fields (bounce_threshold,
    sleep_threshold, solver_velocity_iterations,
    enable_pcm, enable_tgs, enable_ccd, enable_enhanced_determinism,
    enable_friction_every_iteration, enable_adaptive_force) are kept and have no effect: MuJoCo
    has no such settings."""
    _scene_config_init(self)
    for k, v in {**_physx_defaults, **kwargs}.items():
        if not hasattr(self, k):
            raise _p.PartsimError(f"SceneConfig: no field '{k}'")
        setattr(self, k, v)


# defaults for scenes created later (sapien.physx.set_scene_config / set_default_material)
_physx_defaults: dict = {}
_render_defaults: dict = {}

# ------------------------------------------------------------------------------ Engine, renderer


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
        """A new partsim.Scene with `config` (SceneConfig; default settings when None)."""
        return _p.Scene(config if config is not None else SceneConfig())

    def create_physical_material(self, static_friction, dynamic_friction, restitution):
        return _physical_material(static_friction, dynamic_friction, restitution)

    def set_log_level(self, level):
        set_log_level(level)


class SapienRenderer:
    """SAPIEN's renderer object. partsim renders each scene with its own backend (the EGL
    rasterizer, on a GPU when there is one, else on the CPU); this object only makes materials."""

    def __init__(self, offscreen_only=False, max_num_materials=128, max_num_textures=512,
                 default_mipmaps_levels=1, device="", culling="back", do_not_load_texture=False):
        self.offscreen_only = offscreen_only

    def create_material(self):
        return RenderMaterial()

    def create_window(self, *args, **kwargs):
        raise _p.PartsimError(_WINDOW_MESSAGE)

    @staticmethod
    def set_log_level(level):
        set_log_level(level)


VulkanRenderer = SapienRenderer


class KuafuRenderer:
    """SAPIEN 2's ray tracer: in partsim, the path tracer of each scene."""

    def __init__(self, *args, **kwargs):
        raise _p.PartsimError(
            "KuafuRenderer: partsim's ray tracer is a scene backend: "
            "scene.set_render_backend('pathtracer') (or sapien.render.set_camera_shader_dir('rt') "
            "before creating the scene)")


# ------------------------------------------------------------------------------ Scene

_scene_init = _p.Scene.__init__


@_add(_p.Scene, "__init__")
def _scene_init_sapien(self, *args, systems=None, **kwargs):
    """Scene(config=SceneConfig()) or Scene(timestep, gravity). With no arguments, the settings
    given to sapien.physx.set_scene_config / set_default_material / set_body_config apply."""
    if not args and not kwargs:
        _scene_init(self, SceneConfig())
    else:
        _scene_init(self, *args, **kwargs)
    if _render_defaults.get("backend"):
        self.set_render_backend(_render_defaults["backend"])


@_wrap(_p.Scene, "add_ground")
def _add_ground(original, self, altitude=0.0, *args, **kwargs):
    """SAPIEN's add_ground(altitude, render=True, material=None, render_material=None,
    render_half_size=[10, 10]): render_material may be a RenderMaterial or a colour."""
    if args and isinstance(args[0], (bool, np.bool_)):
        names = ["render", "material", "render_material", "render_half_size"]
        if len(args) > len(names):
            raise _p.PartsimError("add_ground: too many arguments")
        kwargs.update(zip(names, args))
        args = ()
    rm = kwargs.get("render_material")
    if rm is not None and not isinstance(rm, _p.RenderMaterial):
        kwargs["render_material"] = RenderMaterial(base_color=rm)
    return original(self, altitude, *args, **kwargs)


def _get_default_material(self):
    return self.get_config().default_material


_p.Scene.default_physical_material = property(
    _get_default_material, lambda self, m: self.set_default_material(m),
    doc="The material of shapes built with none (SAPIEN 2).")


@_add(_p.Scene)
def get_all_actors(self):
    return self.get_actors()


@_add(_p.Scene)
def get_all_articulations(self):
    return self.get_articulations()


@_add(_p.Scene)
def get_mounted_cameras(self):
    return self.get_cameras()


@_add(_p.Scene)
def get_entities(self):
    """SAPIEN 3: the actors and the links of every articulation."""
    out = list(self.get_actors())
    for a in self.get_articulations():
        out.extend(a.get_links())
    return out


@_wrap(_p.Scene, "add_directional_light")
def _add_directional_light(original, self, direction, color, shadow=False, position=None,
                           scale=10.0, near=-10.0, far=10.0, shadow_map_size=2048):
    """SAPIEN's add_directional_light(direction, color, shadow=False, position, scale, near, far,
    shadow_map_size): partsim fits each shadow map to the scene, so the shadow volume arguments
    are accepted and not used."""
    return original(self, direction, color, bool(shadow))


@_wrap(_p.Scene, "add_point_light")
def _add_point_light(original, self, position, color, shadow=False, shadow_near=0.1,
                     shadow_far=10.0, shadow_map_size=2048):
    """SAPIEN's add_point_light(position, color, shadow=False, ...). Point lights cast no
    shadows in partsim's rasterizer (directional and spot lights do; the path tracer shadows
    every light)."""
    return original(self, position, color)


@_wrap(_p.Scene, "add_spot_light")
def _add_spot_light(original, self, position, direction, inner_fov=None, outer_fov=None,
                    color=None, shadow=False, shadow_near=0.1, shadow_far=10.0,
                    shadow_map_size=2048, inner_angle=None, outer_angle=None):
    """SAPIEN's add_spot_light(position, direction, inner_fov, outer_fov, color, shadow=False,
    ...): inner_fov and outer_fov are full cone angles (rad). partsim's half angles may be given
    as inner_angle and outer_angle instead."""
    if inner_angle is None:
        if inner_fov is None or outer_fov is None:
            raise _p.PartsimError("add_spot_light: give inner_fov and outer_fov (full angles, rad) "
                                  "or inner_angle and outer_angle (half angles)")
        inner_angle, outer_angle = inner_fov / 2.0, outer_fov / 2.0
    if color is None:
        raise _p.PartsimError("add_spot_light: color is required")
    return original(self, position, direction, inner_angle, outer_angle, color, bool(shadow))


@_wrap(_p.Scene, "add_mounted_camera")
def _add_mounted_camera(original, self, name, mount=None, pose=None, width=None, height=None,
                        *args, actor=None, fovx=None, **kwargs):
    """add_mounted_camera(name, mount, pose, width, height, fovy, near, far); SAPIEN 2.0's
    (name, actor, pose, width, height, fovx, fovy, near, far) also works (fovx then follows from
    fovy and the size)."""
    if mount is None:
        mount = actor
    if len(args) == 4:
        args = args[1:]
    return original(self, name, mount, pose if pose is not None else _p.Pose(), width, height,
                    *args, **kwargs)


class SapienContact:
    """One contact as SAPIEN reports it: actor0 and actor1 (Actor or Link handles; `bodies` in
    SAPIEN 3) and the points, each with the impulse on actor0 over the last step. When one side
    is a static actor (the ground) it is actor1. partsim's body0/body1 descriptions stay
    available."""

    __slots__ = ("actor0", "actor1", "points", "body0", "body1")

    def __init__(self, contact, actor0, actor1):
        self.actor0 = actor0
        self.actor1 = actor1
        self.points = contact.points
        self.body0 = contact.body0
        self.body1 = contact.body1

    @property
    def bodies(self):
        return (self.actor0, self.actor1)

    @property
    def shapes(self):
        return (self.body0, self.body1)

    def __repr__(self):
        return (f"<Contact '{self.body0.name}' - '{self.body1.name}', {len(self.points)} "
                "points>")


_get_contacts = _p.Scene.get_contacts


@_add(_p.Scene, "get_contacts")
def _get_contacts_sapien(self):
    """Contacts of the last step (SapienContact: actor0/actor1 handles, points)."""
    contacts = _get_contacts(self)
    if not contacts:
        return []
    actors = {a.get_id(): a for a in self.get_actors()}
    arts = {a.get_id(): a for a in self.get_articulations()}
    links = {}

    def handle(body):
        if body.kind == _p.ContactBody.Kind.ACTOR:
            return actors.get(body.actor_id)
        if body.articulation_id not in links:
            art = arts.get(body.articulation_id)
            links[body.articulation_id] = art.get_links() if art is not None else []
        ls = links[body.articulation_id]
        return ls[body.link_index] if 0 <= body.link_index < len(ls) else None

    return [SapienContact(c, handle(c.body0), handle(c.body1)) for c in contacts]


# ------------------------------------------------------------------------------ builders

def _shape_kwargs(what, kwargs):
    """Drops the PhysX-only shape arguments; refuses triggers."""
    if kwargs.pop("is_trigger", False):
        raise _p.PartsimError(f"{what}: trigger shapes (is_trigger=True) are not supported by "
                              "partsim; read contacts with scene.get_contacts() instead")
    kwargs.pop("patch_radius", None)
    kwargs.pop("min_patch_radius", None)
    return kwargs


# SAPIEN's positional parameters of each visual adder; the colour slot takes a colour or a
# RenderMaterial (SAPIEN 2.2 calls it color, SAPIEN 3 material)
_VISUAL_PARAMS = {
    "add_box_visual": ("pose", "half_size", "color", "name"),
    "add_sphere_visual": ("pose", "radius", "color", "name"),
    "add_capsule_visual": ("pose", "radius", "half_length", "color", "name"),
    "add_cylinder_visual": ("pose", "radius", "half_length", "color", "name"),
    "add_visual_from_file": ("filename", "pose", "scale", "color", "name"),
}


def _visual_adder(name):
    params = _VISUAL_PARAMS[name]

    def deco(original, self, *args, **kwargs):
        if len(args) > len(params):
            raise _p.PartsimError(f"{name}: at most {len(params)} positional arguments "
                                  f"({', '.join(params)})")
        for k, v in zip(params, args):
            if k in kwargs:
                raise _p.PartsimError(f"{name}: '{k}' given twice")
            kwargs[k] = v
        color = kwargs.pop("color", None)
        material = kwargs.pop("material", None)
        if color is not None and material is not None:
            raise _p.PartsimError(f"{name}: give color or material, not both")
        paint = material if material is not None else color
        render_material = None
        if isinstance(paint, _p.RenderMaterial):
            render_material = paint
        elif paint is not None:
            rgba = _color4(paint, name).astype(np.float32)
            if name == "add_visual_from_file":
                render_material = RenderMaterial(base_color=rgba)
            else:
                kwargs["color"] = rgba
        count = self.get_visual_count()
        original(self, **kwargs)
        if render_material is not None:
            for i in range(count, self.get_visual_count()):
                self.set_visual_material(i, render_material)
        return self

    deco.__doc__ = (f"SAPIEN's {name}({', '.join(params)}): the colour as RGB or RGBA, or "
                    "material= a RenderMaterial or a colour (for a file, it replaces the "
                    "file's materials).")
    return deco


def _collision_adder(name):
    def deco(original, self, *args, **kwargs):
        return original(self, *args, **_shape_kwargs(name, kwargs))

    deco.__doc__ = (f"SAPIEN's {name}: patch_radius and min_patch_radius (PhysX torsional "
                    "friction) are accepted and not used; is_trigger=True is refused.")
    return deco


for _builder in (_p.ActorBuilder, _p.LinkBuilder):
    for _n in ("add_box_visual", "add_sphere_visual", "add_capsule_visual", "add_cylinder_visual",
               "add_visual_from_file"):
        _wrap(_builder, _n)(_visual_adder(_n))
    for _n in ("add_box_collision", "add_sphere_collision", "add_capsule_collision",
               "add_cylinder_collision", "add_convex_collision_from_file"):
        _wrap(_builder, _n)(_collision_adder(_n))

    @_add(_builder)
    def add_collision_from_file(self, filename, pose=None, scale=(1, 1, 1), material=None,
                                density=1000.0, **kwargs):
        """SAPIEN's name for add_convex_collision_from_file."""
        _shape_kwargs("add_collision_from_file", kwargs)
        return self.add_convex_collision_from_file(filename, pose or _p.Pose(), scale, material,
                                                   density)

    @_add(_builder)
    def add_nonconvex_collision_from_file(self, filename, *args, **kwargs):
        """Refused: MuJoCo collides convex shapes only."""
        raise _p.PartsimError(
            f"add_nonconvex_collision_from_file('{filename}'): partsim collides convex shapes "
            "only (MuJoCo); use add_multiple_convex_collisions_from_file (one convex piece per "
            "sub-mesh) or decompose the mesh first (`partsim assets decompose`)")

@_add(_p.ActorBuilder)
def add_multiple_collisions_from_file(self, filename, pose=None, scale=(1, 1, 1), material=None,
                                      density=1000.0, **kwargs):
    """SAPIEN's name for add_multiple_convex_collisions_from_file: one convex piece per sub-mesh
    (or connected component) of the file."""
    _shape_kwargs("add_multiple_collisions_from_file", kwargs)
    return self.add_multiple_convex_collisions_from_file(filename, pose or _p.Pose(), scale,
                                                         material, density)


_build_types: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


@_add(_p.ActorBuilder)
def set_physx_body_type(self, body_type):
    """SAPIEN 3: 'dynamic', 'kinematic' or 'static', used by build()."""
    if body_type not in ("dynamic", "kinematic", "static"):
        raise _p.PartsimError(f"set_physx_body_type: expected 'dynamic', 'kinematic' or "
                              f"'static', got '{body_type}'")
    _build_types[self] = body_type
    return self


_actor_build = _p.ActorBuilder.build
_actor_build_kinematic = _p.ActorBuilder.build_kinematic
_actor_build_static = _p.ActorBuilder.build_static


@_add(_p.ActorBuilder, "build")
def _build(self, name=None, kinematic=None):
    """build(name='') as SAPIEN's (the body type set by set_physx_body_type, dynamic by
    default); partsim's build(kinematic=False) also works."""
    if isinstance(name, (bool, np.bool_)):
        name, kinematic = None, bool(name)
    if name:
        self.set_name(name)
    kind = "kinematic" if kinematic else _build_types.get(self, "dynamic")
    if kind == "static":
        return _actor_build_static(self)
    if kind == "kinematic":
        return _actor_build_kinematic(self)
    return _actor_build(self)


@_add(_p.ActorBuilder, "build_kinematic")
def _build_kinematic(self, name=""):
    if name:
        self.set_name(name)
    return _actor_build_kinematic(self)


@_add(_p.ActorBuilder, "build_static")
def _build_static(self, name=""):
    if name:
        self.set_name(name)
    return _actor_build_static(self)


_JOINT_TYPES = {"revolute": "revolute", "revolute_unwrapped": "revolute",
                "continuous": "continuous", "prismatic": "prismatic", "fixed": "fixed",
                "screw": "screw"}


def _limits_pair(limits, joint_type, what):
    """(lower, upper) from SAPIEN's [[lo, hi]] (one row per dof), [] for fixed, or (lo, hi)."""
    a = np.asarray(limits if limits is not None else [], dtype=np.float64)
    if a.size == 0:
        if joint_type not in ("fixed",):
            return (-math.inf, math.inf)
        return (0.0, 0.0)
    if a.shape in ((1, 2), (2,)):
        return tuple(a.reshape(2))
    raise _p.PartsimError(f"{what}: limits must be [[lower, upper]] (one row per dof), [] or "
                          f"(lower, upper), got shape {a.shape}")


_set_joint_properties = _p.LinkBuilder.set_joint_properties


@_add(_p.LinkBuilder, "set_joint_properties")
def _set_joint_properties_sapien(self, type, limits=None, pose_in_parent=None, pose_in_child=None,
                                 friction=0.0, damping=0.0):
    """SAPIEN's set_joint_properties(type, limits, pose_in_parent, pose_in_child, friction,
    damping): type 'fixed', 'revolute' (or 'revolute_unwrapped'), 'continuous', 'prismatic' or
    'screw'; limits [[lower, upper]] per dof ([] for fixed; [[-inf, inf]] for an unlimited
    revolute), or partsim's (lower, upper). The joint's x axis is its axis."""
    if isinstance(type, str):
        key = type.lower()
        if key not in _JOINT_TYPES:
            raise _p.PartsimError(f"set_joint_properties: unknown joint type '{type}' (fixed, "
                                  "revolute, continuous, prismatic, screw)")
        type = _JOINT_TYPES[key]
        lo, hi = _limits_pair(limits, type, "set_joint_properties")
        if type == "revolute" and math.isinf(lo) and math.isinf(hi):
            type = "continuous"
    else:
        lo, hi = _limits_pair(limits, str(type), "set_joint_properties")
    return _set_joint_properties(self, type, np.array([lo, hi]), pose_in_parent or _p.Pose(),
                                 pose_in_child or _p.Pose(), friction, damping)


# ------------------------------------------------------------------------------ handles

def _alias_property(cls, name, getter, setter=None, doc=None):
    prop = property(getter, setter, doc=doc)
    previous = cls.__dict__.get(name)
    setattr(cls, name, prop)
    if previous is not None:
        _replaced_properties[(cls, name)] = previous


# bindings' properties that a SAPIEN property replaced (scripts/gen_stubs.py reads them)
_replaced_properties: dict = {}


for _cls in (_p.Actor, _p.Link):
    _alias_property(_cls, "mass", lambda self: self.get_mass(), doc="kg (SAPIEN's mass).")
    _alias_property(_cls, "pose", lambda self: self.get_pose(),
                    (lambda self, p: self.set_pose(p)) if _cls is _p.Actor else None,
                    doc="World pose (SAPIEN 3).")
    _alias_property(_cls, "entity", lambda self: self, doc="The handle itself (SAPIEN 3).")
    _add(_cls, "get_linear_velocity")(lambda self: self.get_velocity())
    _add(_cls, "get_entity")(lambda self: self)

_alias_property(_p.Actor, "name", lambda self: self.get_name(), lambda self, n: self.set_name(n))
_add(_p.Actor, "set_linear_velocity")(lambda self, v: self.set_velocity(v))
_alias_property(_p.Actor, "linear_velocity", lambda self: self.get_velocity(),
                lambda self, v: self.set_velocity(v))
_alias_property(_p.Actor, "angular_velocity", lambda self: self.get_angular_velocity(),
                lambda self, w: self.set_angular_velocity(w))
# SAPIEN 3's PhysxRigidDynamicComponent damping, one rate at a time (SAPIEN 2: set_damping)
_alias_property(_p.Actor, "linear_damping", lambda self: self.get_linear_damping(),
                lambda self, v: self.set_damping(v, self.get_angular_damping()),
                doc="Linear velocity damping (1/s).")
_alias_property(_p.Actor, "angular_damping", lambda self: self.get_angular_damping(),
                lambda self, v: self.set_damping(self.get_linear_damping(), v),
                doc="Angular velocity damping (1/s).")
_add(_p.Actor, "set_linear_damping")(
    lambda self, v: self.set_damping(v, self.get_angular_damping()))
_add(_p.Actor, "set_angular_damping")(
    lambda self, v: self.set_damping(self.get_linear_damping(), v))


@_add(_p.Actor)
def find_component_by_type(self, cls):
    """SAPIEN 3: the actor stands for its own physical components (rigid dynamic, kinematic or
    static, matching its type) and its render body; None for another component type."""
    t = self.type
    kinds = {physx.PhysxRigidBaseComponent, physx.PhysxRigidBodyComponent,
             RenderBodyComponent}
    if t == _p.ActorType.DYNAMIC:
        kinds.add(physx.PhysxRigidDynamicComponent)
    elif t == _p.ActorType.KINEMATIC:
        kinds.add(physx.PhysxRigidDynamicComponent)
    else:
        kinds.add(physx.PhysxRigidStaticComponent)
    return self if cls in kinds else None


class RenderBodyComponent:
    """SAPIEN 3's render body component: find_component_by_type(RenderBodyComponent) returns the
    actor itself."""


_alias_property(_p.Articulation, "name", lambda self: self.get_name(),
                lambda self, n: self.set_name(n))
_add(_p.Articulation, "get_pose")(lambda self: self.get_root_pose())
_add(_p.Articulation, "set_pose")(lambda self, pose: self.set_root_pose(pose))
_alias_property(_p.Articulation, "pose", lambda self: self.get_root_pose(),
                lambda self, p: self.set_root_pose(p), doc="Root pose (SAPIEN 3).")
for _n in ("qpos", "qvel", "qacc", "qf"):
    _alias_property(_p.Articulation, _n, lambda self, _g="get_" + _n: getattr(self, _g)(),
                    lambda self, v, _s="set_" + _n: getattr(self, _s)(v),
                    doc=f"SAPIEN 3's {_n}.")
_alias_property(_p.Articulation, "qlimits", lambda self: self.get_qlimits())
_alias_property(_p.Articulation, "active_joints", lambda self: self.get_active_joints())
_alias_property(_p.Articulation, "joints", lambda self: self.get_joints())
_alias_property(_p.Articulation, "links", lambda self: self.get_links())
_add(_p.Articulation, "get_root")(lambda self: self.get_links()[0])
_alias_property(_p.Articulation, "root", lambda self: self.get_links()[0])
_alias_property(_p.Articulation, "root_pose", lambda self: self.get_root_pose(),
                lambda self, p: self.set_root_pose(p), doc="Root link's pose (SAPIEN 3).")


# SAPIEN 3's components name their entity's pose entity_pose (component.pose is deprecated
# there): an actor or a link is its own entity here
def _set_link_entity_pose(self, pose):
    raise _p.PartsimError(f"set_entity_pose: link '{self.name}' is placed by its articulation: "
                          "set the articulation's root_pose and qpos")


for _cls, _setter in ((_p.Actor, lambda self, p: self.set_pose(p)),
                      (_p.Link, _set_link_entity_pose)):
    _alias_property(_cls, "entity_pose", lambda self: self.get_pose(), _setter,
                    doc="World pose of the entity (SAPIEN 3).")
    _add(_cls, "get_entity_pose")(lambda self: self.get_pose())
    _add(_cls, "set_entity_pose")(_setter)


class UnsupportedError(_p.PartsimError, AttributeError):
    """A SAPIEN name partsim does not provide (docs/sapien_compatibility.md, status "no"): a
    PartsimError that says what to use instead, and an AttributeError, so that hasattr() is
    False as for any missing name."""


# SAPIEN names marked "no" in docs/sapien_compatibility.md, by class: reading one raises
# UnsupportedError with the reason and what to use instead
UNSUPPORTED = {
    _p.Scene: {
        "create_drive": "partsim has no actor-to-actor drive: join the two with an articulation "
                        "joint and drive it",
        "physx_system": "partsim has no entity-component system: the scene itself is the "
                        "physics system (set_timestep, get_contacts, step)",
        "render_system": "partsim has no entity-component system: cameras and lights belong to "
                         "the scene (add_camera, add_point_light)",
        "add_entity": "partsim has no entity-component system: build actors with "
                      "create_actor_builder() and articulations with create_urdf_loader() or "
                      "create_articulation_builder()",
    },
    _p.Actor: {
        "hide_visual": "visuals cannot be hidden one by one: leave them out of the builder",
        "get_visual_bodies": "visual bodies are not exposed: read the actor's description "
                             "(get_desc().visuals)",
        "get_collision_visual_bodies": "collision shapes are not drawn as visuals: read "
                                       "get_desc().collisions",
    },
    _p.Camera: {
        "get_dl_tensor": "no GPU tensor sharing: get_picture() gives numpy arrays",
    },
    _p.UrdfLoader: {
        "load_file_as_articulation_builder": "use loader.parse_file(path) (an ArticulationDesc) "
                                             "and scene.add_articulation(desc)",
    },
}


def _unsupported_property(cls, name, why):
    def get(self):
        raise UnsupportedError(f"{cls.__name__}.{name}: not supported by partsim: {why}")
    setattr(cls, name, property(get, doc=f"Not supported by partsim: {why}."))


for _cls, _names in UNSUPPORTED.items():
    for _n, _why in _names.items():
        _unsupported_property(_cls, _n, _why)


@_add(_p.Articulation)
def create_pinocchio_model(self):
    """Refused: partsim's kinematics is KinematicModel.from_articulation (forward kinematics,
    Jacobians) and partsim.inverse_kinematics."""
    raise _p.PartsimError("create_pinocchio_model: partsim has no Pinocchio; use "
                          "partsim.KinematicModel.from_articulation(articulation) and "
                          "partsim.inverse_kinematics")


_joint_get_limits = _p.Joint.get_limits
_joint_set_limits = _p.Joint.set_limits


@_add(_p.Joint, "get_limits")
def _joint_get_limits_sapien(self):
    """Limits (dof, 2) as SAPIEN's: [[lower, upper]] for a moving joint, (0, 2) for a fixed one;
    +-inf when unlimited."""
    if self.get_dof() == 0:
        return np.zeros((0, 2))
    return np.asarray(_joint_get_limits(self), dtype=np.float64).reshape(1, 2)


@_add(_p.Joint, "set_limits")
def _joint_set_limits_sapien(self, limits, upper=None):
    """set_limits([[lower, upper]]) as SAPIEN's, or set_limits(lower, upper)."""
    if upper is not None:
        return _joint_set_limits(self, float(limits), float(upper))
    lo, hi = _limits_pair(limits, "revolute", f"joint '{self.get_name()}' set_limits")
    return _joint_set_limits(self, lo, hi)


_alias_property(_p.Joint, "limits", _joint_get_limits_sapien, _joint_set_limits_sapien)


@_wrap(_p.Joint, "set_drive_property")
def _set_drive_property(original, self, stiffness, damping, force_limit=math.inf, mode="force"):
    """SAPIEN's set_drive_property(stiffness, damping, force_limit=inf, mode='force'). Only the
    'force' mode exists in partsim."""
    if mode != "force":
        raise _p.PartsimError(
            f"joint '{self.get_name()}': set_drive_property mode '{mode}' is not supported "
            "(partsim drives are force drives: force = stiffness (target - q) + damping "
            "(velocity_target - qdot)); use mode='force'")
    return original(self, stiffness, damping, force_limit)


_alias_property(_p.Joint, "drive_target", lambda self: self.get_drive_target(),
                lambda self, t: self.set_drive_target(t))

# ------------------------------------------------------------------------------ URDF loader


@_wrap(_p.UrdfLoader, "load")
def _urdf_load(original, self, filename, config=None, package_dir=None, srdf_file=None):
    """SAPIEN's load(filename, config=None, package_dir=None): config may give 'material' and
    'density' for every link and a 'link' table of per-link ones; package_dir resolves
    package:// paths."""
    _apply_urdf_args(self, config, package_dir, srdf_file)
    return original(self, filename)


def _apply_urdf_args(loader, config, package_dir, srdf_file):
    if package_dir is not None:
        # package://NAME/... resolves to package_dir/NAME/...
        root = os.path.abspath(os.fspath(package_dir))
        if not os.path.isdir(root):
            raise _p.PartsimError(f"load: package_dir '{package_dir}' is not a folder")
        dirs = dict(loader.package_dirs)
        for entry in sorted(os.listdir(root)):
            if os.path.isdir(os.path.join(root, entry)):
                dirs.setdefault(entry, os.path.join(root, entry))
        loader.package_dirs = dirs
    if srdf_file is not None:
        loader.srdf_file = str(srdf_file)
    if config:
        if "material" in config:
            loader.material = config["material"]
        if "density" in config:
            loader.density = float(config["density"])
        overrides = dict(loader.link_overrides)
        for link, c in config.get("link", {}).items():
            overrides[link] = _p.UrdfLinkOverride(density=c.get("density"),
                                                  material=c.get("material"))
        loader.link_overrides = overrides


@_add(_p.UrdfLoader)
def load_kinematic(self, filename, config=None, package_dir=None):
    """SAPIEN's load_kinematic: the URDF as a kinematic articulation (moved by set_qpos and
    set_root_pose only, never by forces)."""
    _apply_urdf_args(self, config, package_dir, None)
    desc = self.parse_file(filename)
    desc.kinematic = True
    scene = _loader_scenes.get(self)
    if scene is None:
        raise _p.PartsimError("load_kinematic: use a loader from scene.create_urdf_loader()")
    return scene.add_articulation(desc)


_loader_scenes: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
_create_urdf_loader = _p.Scene.create_urdf_loader


@_add(_p.Scene, "create_urdf_loader")
def _create_urdf_loader_sapien(self):
    """A URDF loader adding to this scene (SAPIEN's URDFLoader)."""
    loader = _create_urdf_loader(self)
    _loader_scenes[loader] = self
    return loader


# ------------------------------------------------------------------------------ cameras

_get_picture = _p.Camera.get_picture


def _sapien_position(camera, position):
    """Position with the 4th channel as the OpenGL depth-buffer value (1 where nothing)."""
    out = np.array(position, dtype=np.float32, copy=True)
    z = out[..., 3]  # partsim: depth in metres, 0 for nothing
    n, f = camera.near, camera.far
    seen = z > 0
    d = np.ones_like(z)
    d[seen] = (f * (z[seen] - n)) / (z[seen] * (f - n))
    out[..., 3] = d
    return out


@_add(_p.Camera, "get_picture")
def _get_picture_sapien(self, name):
    """'Color', 'Albedo', 'Normal': float32 (h, w, 4) (a read-only view); 'Position': float32
    (h, w, 4), x, y, z in the OpenGL camera frame (m) and the depth-buffer value in [0, 1] (1
    where nothing was seen; keep pixels with [..., 3] < 1), as SAPIEN's; 'Segmentation': uint32
    (h, w, 4): visual id, actor/link id, 0, 0 as SAPIEN's. partsim's depth in metres is
    get_depth()."""
    p = _get_picture(self, name)
    if name == "Position":
        return _sapien_position(self, p)
    if name == "Segmentation":
        out = np.zeros(p.shape[:2] + (4,), dtype=np.uint32)
        out[..., :2] = p
        return out
    return p


_add(_p.Camera, "get_float_texture")(
    lambda self, name: _get_picture_sapien(self, name))
_add(_p.Camera, "get_uint32_texture")(
    lambda self, name: _get_picture_sapien(self, name))
_add(_p.Camera, "get_color_rgba")(lambda self: _get_picture(self, "Color"))
_add(_p.Camera, "get_albedo_rgba")(lambda self: _get_picture(self, "Albedo"))
_add(_p.Camera, "get_normal_rgba")(lambda self: _get_picture(self, "Normal"))
_add(_p.Camera, "get_visual_actor_segmentation")(
    lambda self: np.asarray(_get_picture(self, "Segmentation")))
_add(_p.Camera, "get_visual_segmentation")(
    lambda self: np.asarray(_get_picture(self, "Segmentation")[..., 0]))
_add(_p.Camera, "get_actor_segmentation")(
    lambda self: np.asarray(_get_picture(self, "Segmentation")[..., 1]))
_add(_p.Camera, "get_global_pose")(lambda self: self.get_pose())
_alias_property(_p.Camera, "local_pose", lambda self: self.get_local_pose(),
                lambda self, p: self.set_local_pose(p))


@_add(_p.Camera)
def set_perspective_parameters(self, near, far, fx, fy, cx, cy, skew=0.0):
    """Clipping distances (m) and OpenCV intrinsics (pixels); skew must be 0."""
    if skew != 0:
        raise _p.PartsimError(f"camera '{self.get_name()}': skew {skew} is not supported (0 only)")
    self.set_near_far(near, far)
    self.set_intrinsics(fx, fy, cx, cy)


class _CameraEntity:
    """SAPIEN 3's camera.entity: placing it places the camera."""

    def __init__(self, camera):
        self._camera = camera

    def set_pose(self, pose):
        self._camera.set_local_pose(pose)

    def get_pose(self):
        return self._camera.get_pose()

    pose = property(get_pose, set_pose)


_alias_property(_p.Camera, "entity", lambda self: _CameraEntity(self))


# names of the extension that the package exports as the SAPIEN-aware Python versions above
EXPORT_OVERRIDES = ("set_log_level", "Viewer")

# ------------------------------------------------------------------------------ submodules

def _submodule(name, doc):
    mod = types.ModuleType(f"{_p.__name__.rsplit('.', 1)[0]}.{name}", doc)
    sys.modules[mod.__name__] = mod
    return mod


render = _submodule("render", "SAPIEN's sapien.render names on partsim.")
render.RenderMaterial = RenderMaterial
render.RenderBodyComponent = RenderBodyComponent
render.set_log_level = set_log_level
render.SapienRenderer = SapienRenderer


def _set_global_config(max_num_materials=128, max_num_textures=512, default_mipmap_levels=1,
                       **kwargs):
    """Accepted for SAPIEN scripts: partsim has no fixed-size material or texture pools."""


def _set_camera_shader_dir(shader_dir):
    """'rt' (SAPIEN's ray-tracing shaders) makes scenes created afterwards render with partsim's
    path tracer; 'default' or 'minimal' with the rasterizer. Another folder is refused:
    partsim's shaders are its own (custom GLSL goes through the rasterizer's options)."""
    key = str(shader_dir).rstrip("/").rsplit("/", 1)[-1]
    if key == "rt":
        _render_defaults["backend"] = "pathtracer"
    elif key in ("default", "minimal", "ibl"):
        _render_defaults["backend"] = "rasterizer"
    else:
        raise _p.PartsimError(f"set_camera_shader_dir('{shader_dir}'): partsim knows 'rt' "
                              "(path tracer), 'default' and 'minimal' (rasterizer)")


render.set_global_config = _set_global_config
render.set_camera_shader_dir = _set_camera_shader_dir
render.set_viewer_shader_dir = lambda shader_dir: None

physx = _submodule("physx", "SAPIEN 3's sapien.physx names on partsim.")


def _set_scene_config(config=None, **kwargs):
    """Defaults for scenes created afterwards with sapien.Scene(): gravity and SAPIEN's PhysX
    fields (kept, no effect: bounce_threshold, enable_pcm, enable_tgs, enable_ccd,
    enable_enhanced_determinism, enable_friction_every_iteration, cpu_workers)."""
    if config is not None:
        kwargs = {k: getattr(config, k) for k in ("gravity",) if hasattr(config, k)}
    for k, v in kwargs.items():
        if k == "gravity":
            _physx_defaults["gravity"] = np.asarray(v, dtype=np.float64)
        elif k in _PHYSX_ONLY:
            _physx_defaults[k] = v
        elif k == "cpu_workers":
            pass  # partsim steps each scene on the calling thread
        else:
            raise _p.PartsimError(f"set_scene_config: unknown field '{k}'")


def _set_default_material(static_friction, dynamic_friction, restitution):
    """Default material of scenes created afterwards."""
    _physx_defaults["default_material"] = _physical_material(static_friction, dynamic_friction,
                                                             restitution)


def _set_body_config(solver_position_iterations=None, solver_velocity_iterations=None,
                     sleep_threshold=None):
    """solver_position_iterations sets the solver iterations of scenes created afterwards (at
    least partsim's minimum); the others are PhysX-only and have no effect."""
    if solver_position_iterations is not None:
        _physx_defaults["solver_iterations"] = max(1, int(solver_position_iterations))


class _Component:
    """SAPIEN 3 component type used with find_component_by_type."""


physx.set_scene_config = _set_scene_config
physx.set_default_material = _set_default_material
physx.get_default_material = lambda: _physx_defaults.get("default_material",
                                                          _p.SceneConfig().default_material)
physx.set_body_config = _set_body_config
def _set_shape_config(contact_offset=0.01, rest_offset=0.0):
    """Contact and rest offsets of the shapes of scenes created afterwards (SceneConfig's
    contact_offset and rest_offset: MuJoCo's margin and gap)."""
    _physx_defaults["contact_offset"] = float(contact_offset)
    _physx_defaults["rest_offset"] = float(rest_offset)


physx.set_shape_config = _set_shape_config
physx.PhysxMaterial = _physical_material
physx.PhysxSceneConfig = SceneConfig
for _n in ("PhysxRigidBaseComponent", "PhysxRigidBodyComponent", "PhysxRigidDynamicComponent",
           "PhysxRigidStaticComponent", "PhysxArticulationLinkComponent"):
    setattr(physx, _n, type(_n, (_Component,), {"__doc__": f"SAPIEN 3's {_n} type."}))

utils = _submodule("utils", "SAPIEN's sapien.utils names on partsim.")


@_add(_p.Viewer)
def toggle_axes(self, show):
    """SAPIEN's viewer.toggle_axes: accepted, no effect (the page has its own toggles)."""


@_add(_p.Viewer)
def toggle_camera_lines(self, show):
    """SAPIEN's viewer.toggle_camera_lines: accepted, no effect (the page has its own
    toggles)."""


@_add(_p.Scene)
def create_viewer(self, port=0, address="127.0.0.1", token=None):
    """A partsim.Viewer of this scene (SAPIEN's name): starts the browser viewer's server on a
    free port (or `port`) and prints the URL to open on stderr."""
    return Viewer(self, port=port, address=address, token=token)


class Viewer(_p.Viewer):
    """The browser viewer, taking SAPIEN's arguments too: Viewer(scene, port=0, ...) as
    partsim's, or SAPIEN 2's Viewer(renderer, shader_dir="", resolutions=...) followed by
    viewer.set_scene(scene) (the renderer, shader folder and window size are ignored: the page
    draws in the browser)."""

    def __init__(self, scene=None, *args, shader_dir=None, resolutions=None, **kwargs):
        if scene is not None and not isinstance(scene, _p.Scene):
            scene, args = None, ()  # SAPIEN: a renderer, then shader_dir and resolutions
        super().__init__(scene, *args, **kwargs)


utils.Viewer = Viewer
utils.viewer = _submodule("utils.viewer", "SAPIEN 2's sapien.utils.viewer.")
utils.viewer.Viewer = Viewer
