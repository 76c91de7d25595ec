"""SAPIEN 3's `sapien.physx` on partsim: materials, the scene configuration, rigid body and
articulation components, collision shapes, joints and the physics system.

partsim simulates with MuJoCo, not PhysX: the PhysX-only settings are kept and have no effect,
and docs/sapien_compatibility.md says where a result differs.
"""

from __future__ import annotations

import math

import numpy as np

from .. import _partsim as _p
from ._adapter import (BoxGeometry, CapsuleGeometry, Handle, PartsimError, Pose, SphereGeometry,
                       accessors, adapts, as_pose, unsupported, wrap)
from ._entity import Component

# ------------------------------------------------------------------------------ materials


class PhysxMaterial(_p.PhysicalMaterial):
    """PhysxMaterial(static_friction=0.3, dynamic_friction=0.3, restitution=0.1): a
    partsim.PhysicalMaterial (docs/physics.md says how partsim maps the three to MuJoCo's
    contacts)."""

    def __init__(self, static_friction=0.3, dynamic_friction=0.3, restitution=0.1):
        super().__init__(float(static_friction), float(dynamic_friction), float(restitution))


accessors(PhysxMaterial, static_friction=float, dynamic_friction=float, restitution=float)

# ------------------------------------------------------------------------------ configuration

# PhysX settings SAPIEN's scene configuration has and MuJoCo has no counterpart for: kept, not
# used
PHYSX_ONLY = {"bounce_threshold": 2.0, "sleep_threshold": 0.005, "solver_velocity_iterations": 1,
              "enable_pcm": True, "enable_tgs": True, "enable_ccd": False,
              "enable_enhanced_determinism": False, "enable_friction_every_iteration": True,
              "enable_adaptive_force": False, "disable_collision_visual": False}

# defaults for scenes created later (set_scene_config / set_default_material / set_body_config /
# set_shape_config)
_defaults: dict = {}


class SceneConfig(_p.SceneConfig):
    """Scene settings with SAPIEN's names too: gravity, default_static_friction,
    default_dynamic_friction, default_restitution, solver_iterations, contact_offset,
    rest_offset; the defaults given to sapien.physx.set_scene_config / set_default_material /
    set_body_config / set_shape_config first. PhysX-only fields (bounce_threshold,
    sleep_threshold, solver_velocity_iterations, enable_pcm, enable_tgs, enable_ccd,
    enable_enhanced_determinism, enable_friction_every_iteration, enable_adaptive_force) are
    kept and have no effect: MuJoCo has no such settings. A partsim.SceneConfig."""

    def __init__(self, **kwargs):
        super().__init__()
        for k, v in PHYSX_ONLY.items():
            object.__setattr__(self, k, v)
        for k, v in {**_defaults, **kwargs}.items():
            if not hasattr(self, k):
                raise PartsimError(f"SceneConfig: no field '{k}'")
            setattr(self, k, v)

    def _material_field(field):
        def get(self):
            return getattr(self.default_material, field)

        def set(self, value):
            m = self.default_material
            setattr(m, field, float(value))
            self.default_material = m

        return property(get, set, doc=f"default_material.{field} (SAPIEN's name).")

    default_static_friction = _material_field("static_friction")
    default_dynamic_friction = _material_field("dynamic_friction")
    default_restitution = _material_field("restitution")
    del _material_field


PhysxSceneConfig = SceneConfig


class PhysxBodyConfig:
    """SAPIEN 3's body configuration: solver_position_iterations become the solver iterations
    of scenes created afterwards (set_body_config); the others are PhysX's, kept, no effect."""

    def __init__(self):
        self.solver_position_iterations = 10
        self.solver_velocity_iterations = 1
        self.sleep_threshold = 0.005


class PhysxShapeConfig:
    """SAPIEN 3's shape configuration: contact_offset and rest_offset (MuJoCo's margin and
    gap), for scenes created afterwards (set_shape_config)."""

    def __init__(self):
        self.contact_offset = 0.01
        self.rest_offset = 0.0


def set_scene_config(config=None, **kwargs):
    """Defaults for scenes created afterwards with sapien.Scene(): gravity and SAPIEN's PhysX
    fields (kept, no effect: bounce_threshold, enable_pcm, enable_tgs, enable_ccd,
    enable_enhanced_determinism, enable_friction_every_iteration, cpu_workers)."""
    if config is not None:
        kwargs = {k: getattr(config, k) for k in ("gravity", *PHYSX_ONLY) if hasattr(config, k)}
    for k, v in kwargs.items():
        if k == "gravity":
            _defaults["gravity"] = np.asarray(v, dtype=np.float64)
        elif k in PHYSX_ONLY:
            _defaults[k] = v
        elif k == "cpu_workers":
            pass  # partsim steps each scene on the calling thread
        else:
            raise PartsimError(f"set_scene_config: unknown field '{k}'")


def get_scene_config():
    return SceneConfig()


def set_default_material(static_friction, dynamic_friction, restitution):
    """Default material of scenes created afterwards."""
    _defaults["default_material"] = PhysxMaterial(static_friction, dynamic_friction,
                                                  restitution)


def get_default_material():
    return _defaults.get("default_material") or PhysxMaterial(
        *(lambda m: (m.static_friction, m.dynamic_friction, m.restitution))(
            _p.SceneConfig().default_material))


def set_body_config(solver_position_iterations=None, solver_velocity_iterations=None,
                    sleep_threshold=None, config=None):
    """solver_position_iterations sets the solver iterations of scenes created afterwards (at
    least partsim's minimum); the others are PhysX-only and have no effect."""
    if isinstance(solver_position_iterations, PhysxBodyConfig):
        config, solver_position_iterations = solver_position_iterations, None
    if config is not None:
        solver_position_iterations = config.solver_position_iterations
    if solver_position_iterations is not None:
        _defaults["solver_iterations"] = max(1, int(solver_position_iterations))


def get_body_config():
    c = PhysxBodyConfig()
    if "solver_iterations" in _defaults:
        c.solver_position_iterations = _defaults["solver_iterations"]
    return c


def set_shape_config(contact_offset=0.01, rest_offset=0.0):
    """Contact and rest offsets of the shapes of scenes created afterwards (SceneConfig's
    contact_offset and rest_offset: MuJoCo's margin and gap)."""
    if isinstance(contact_offset, PhysxShapeConfig):
        contact_offset, rest_offset = contact_offset.contact_offset, contact_offset.rest_offset
    _defaults["contact_offset"] = float(contact_offset)
    _defaults["rest_offset"] = float(rest_offset)


def get_shape_config():
    c = PhysxShapeConfig()
    c.contact_offset = _defaults.get("contact_offset", c.contact_offset)
    c.rest_offset = _defaults.get("rest_offset", c.rest_offset)
    return c


def set_sdf_config(*args, **kwargs):
    """Accepted: partsim has no signed-distance-field collision (MuJoCo collides convex
    shapes)."""


def is_gpu_enabled():
    """False: partsim simulates on the CPU (MuJoCo)."""
    return False


def enable_gpu():
    raise PartsimError("sapien.physx.enable_gpu: partsim simulates on the CPU (MuJoCo); run "
                       "many scenes at once with partsim's vector environments "
                       "(gymnasium.make_vec) or several processes")


# ------------------------------------------------------------------------------ shapes


class PhysxCollisionShape:
    """A collision shape to attach to a rigid component before its entity is added to a scene:
    local_pose, physical_material, density, collision groups. patch_radius, min_patch_radius
    (PhysX torsional friction) and the contact and rest offsets are kept and not used per
    shape: partsim's offsets are the scene's (SceneConfig)."""

    def __init__(self, material=None):
        self.local_pose = Pose()
        self.physical_material = material
        self.density = 1000.0
        self.patch_radius = 0.0
        self.min_patch_radius = 0.0
        self.contact_offset = 0.01
        self.rest_offset = 0.0
        self._groups = None
        self._shape = None  # the partsim Shape once built

    def get_local_pose(self):
        return self.local_pose

    def set_local_pose(self, pose):
        self.local_pose = Pose._of(as_pose(pose))

    def get_collision_groups(self):
        if self._shape is not None:
            return list(self._shape.get_collision_groups())
        return list(self._groups) if self._groups is not None else [1, 1, 0, 0]

    def set_collision_groups(self, groups):
        """Four 32-bit words as SAPIEN's: shapes A and B collide iff ((A0 & B1) or (A1 & B0))
        and not ((A2 & B2) and (A3 & 0xffff) == (B3 & 0xffff))."""
        g = [int(x) for x in groups]
        if len(g) != 4:
            raise PartsimError(f"set_collision_groups: expected 4 integers, got {len(g)}")
        if self._shape is not None:
            self._shape.set_collision_groups(g)
        self._groups = g

    collision_groups = property(get_collision_groups)

    def _add_to(self, builder):  # pragma: no cover - each shape defines it
        raise NotImplementedError


accessors(PhysxCollisionShape, physical_material=None, density=float, patch_radius=float,
          min_patch_radius=float, contact_offset=float, rest_offset=float)


class PhysxCollisionShapeBox(BoxGeometry, PhysxCollisionShape):
    def _add_to(self, b):
        b.add_box_collision(self.local_pose, self.half_size, self.physical_material,
                            self.density)


class PhysxCollisionShapeSphere(SphereGeometry, PhysxCollisionShape):
    def _add_to(self, b):
        b.add_sphere_collision(self.local_pose, self.radius, self.physical_material,
                               self.density)


class PhysxCollisionShapeCapsule(CapsuleGeometry, PhysxCollisionShape):
    """A capsule along the shape's x axis, as SAPIEN's."""

    def _add_to(self, b):
        b.add_capsule_collision(self.local_pose, self.radius, self.half_length,
                                self.physical_material, self.density)


class PhysxCollisionShapeCylinder(PhysxCollisionShapeCapsule):
    """A cylinder along the shape's x axis, as SAPIEN's."""

    def _add_to(self, b):
        b.add_cylinder_collision(self.local_pose, self.radius, self.half_length,
                                 self.physical_material, self.density)


class PhysxCollisionShapeConvexMesh(PhysxCollisionShape):
    """PhysxCollisionShapeConvexMesh(filename, scale, material) or (vertices, scale, material):
    the convex hull of the file's or the given points."""

    def __init__(self, filename=None, scale=(1, 1, 1), material=None, *, vertices=None):
        super().__init__(material)
        if filename is not None and not isinstance(filename, (str, bytes)) and \
                not hasattr(filename, "__fspath__"):
            filename, vertices = None, filename
        self.filename = None if filename is None else str(filename)
        self.scale = np.asarray(scale, dtype=np.float64).reshape(3)
        if self.filename is None:
            v = np.asarray(vertices, dtype=np.float64)
            if v.ndim != 2 or v.shape[1] != 3 or len(v) < 4:
                raise PartsimError("PhysxCollisionShapeConvexMesh: vertices must be (n, 3) with "
                                   f"n >= 4, got shape {v.shape}")
            self._vertices = v * self.scale
        else:
            self._vertices = None

    @staticmethod
    def load_multiple(filename, scale=(1, 1, 1), material=None):
        """One convex piece per sub-mesh of the file (the convex hull of each)."""
        meshes = _p.load_mesh_file(str(filename), np.asarray(scale, dtype=np.float64))
        return [PhysxCollisionShapeConvexMesh(vertices=np.asarray(m.mesh.vertices), scale=(1, 1, 1),
                                              material=material) for m in meshes]

    def get_scale(self):
        return self.scale

    def get_vertices(self):
        if self._vertices is None:
            raise PartsimError("PhysxCollisionShapeConvexMesh.get_vertices: read before the "
                               "shape is built from its file; use vertices= to give points")
        return self._vertices

    vertices = property(get_vertices)

    def _add_to(self, b):
        if self._vertices is not None:
            mesh = _p.MeshData()
            mesh.vertices = np.asarray(self._vertices, dtype=np.float32)
            b.add_convex_collision_from_mesh(mesh, self.local_pose, self.physical_material,
                                             self.density)
        else:
            b.add_convex_collision_from_file(self.filename, self.local_pose, self.scale,
                                             self.physical_material, self.density)


class PhysxCollisionShapePlane(PhysxCollisionShape):
    def __init__(self, *args, **kwargs):
        raise PartsimError("PhysxCollisionShapePlane: partsim's plane is the ground: "
                           "scene.add_ground(altitude)")


class PhysxCollisionShapeTriangleMesh(PhysxCollisionShape):
    def __init__(self, *args, **kwargs):
        raise PartsimError("PhysxCollisionShapeTriangleMesh: partsim collides convex shapes only "
                           "(MuJoCo): use PhysxCollisionShapeConvexMesh.load_multiple (one "
                           "convex piece per sub-mesh) or decompose the mesh first (`partsim "
                           "assets decompose`)")


# ------------------------------------------------------------------------------ rigid bodies

_FORCE_MODES = ("force", "acceleration", "velocity_change", "impulse")


class PhysxBaseComponent(Component):
    """Base of the physics components."""


class PhysxRigidBaseComponent(PhysxBaseComponent):
    """A rigid body: collision shapes attached before its entity is added to a scene."""

    def __init__(self):
        super().__init__()
        self._shapes = []

    def attach(self, collision_shape):
        if self._p is not None:
            raise PartsimError(f"{type(self).__name__}.attach: partsim builds a body's shapes "
                               "when its entity is added to the scene: attach every shape first")
        if not isinstance(collision_shape, PhysxCollisionShape):
            raise PartsimError(f"attach: expected a PhysxCollisionShape, got "
                               f"{type(collision_shape).__name__}")
        self._shapes.append(collision_shape)
        return self

    def get_collision_shapes(self):
        if self._p is None:
            return list(self._shapes)
        return wrap(self._p.get_collision_shapes(), self._scene)

    collision_shapes = property(get_collision_shapes)

    def get_global_aabb_fast(self):
        return self.compute_global_aabb_tight()

    def compute_global_aabb_tight(self):
        """(2, 3): the world box around the body's collision shapes (from their bounding
        spheres: not tight for boxes turned off the axes)."""
        raise PartsimError("compute_global_aabb_tight: not provided by partsim yet")


class PhysxRigidStaticComponent(PhysxRigidBaseComponent):
    """A static body."""


class PhysxRigidBodyComponent(PhysxRigidBaseComponent):
    """A moving body: mass and inertia (computed from the shapes' densities unless set),
    velocities, damping, forces."""

    def __init__(self):
        super().__init__()
        self._mass = None
        self._inertia = None
        self._cmass = None
        self._pending = {}

    def _before(self, name, value):
        self._pending[name] = value

    # mass properties
    def _mass_properties(self):
        """(mass, cmass_local_pose, inertia): set explicitly, or computed from the shapes as
        PhysX does (primitives; MuJoCo computes meshes' when the body is built)."""
        if self._p is None:
            auto = mass_properties(_ecs_specs(self._shapes)) or (0.0, Pose(), np.zeros(3))
            return (self._mass if self._mass is not None else auto[0],
                    self._cmass if self._cmass is not None else auto[1],
                    self._inertia if self._inertia is not None else auto[2])
        body = self._p
        return (body.get_mass(), Pose._of(body.get_pose().inv() * body.get_cmass_pose()),
                np.asarray(body.get_inertia()))

    def get_mass(self):
        if self._p is not None:
            return self._p.get_mass()
        return self._mass_properties()[0]

    def set_mass(self, mass):
        self._set_mass_properties(mass=float(mass))

    mass = property(get_mass, set_mass)

    def get_inertia(self):
        return self._mass_properties()[2]

    def set_inertia(self, inertia):
        self._set_mass_properties(inertia=np.asarray(inertia, dtype=np.float64).reshape(3))

    inertia = property(get_inertia, set_inertia)

    def get_cmass_local_pose(self):
        return self._mass_properties()[1]

    def set_cmass_local_pose(self, pose):
        self._set_mass_properties(cmass=Pose._of(as_pose(pose)))

    cmass_local_pose = property(get_cmass_local_pose, set_cmass_local_pose)

    def get_auto_compute_mass(self):
        return self._mass is None

    auto_compute_mass = property(get_auto_compute_mass)

    def _set_mass_properties(self, mass=None, inertia=None, cmass=None):
        if self._p is not None:
            raise PartsimError(f"{type(self).__name__}: partsim fixes mass and inertia when the "
                               "entity is added to the scene: set them before")
        if mass is not None:
            self._mass = mass
        if inertia is not None:
            self._inertia = inertia
        if cmass is not None:
            self._cmass = cmass

    # velocities and forces
    def get_linear_velocity(self):
        return self._partsim().get_velocity() if self._p is not None else \
            self._pending.get("linear_velocity", np.zeros(3))

    def get_angular_velocity(self):
        return self._partsim().get_angular_velocity() if self._p is not None else \
            self._pending.get("angular_velocity", np.zeros(3))

    linear_velocity = property(get_linear_velocity)
    angular_velocity = property(get_angular_velocity)

    def _force(self, force, mode, what):
        f = np.asarray(force, dtype=np.float64).reshape(3)
        if mode not in _FORCE_MODES:
            raise PartsimError(f"{what}: mode '{mode}' (expected one of "
                               f"{', '.join(_FORCE_MODES)})")
        m, dt = self.get_mass(), self._scene._p.get_timestep()
        # partsim applies forces for one step: an impulse J is J / dt over the step, an
        # acceleration a is m a (torques: the principal inertia is not used for these modes)
        return {"force": f, "acceleration": m * f, "impulse": f / dt,
                "velocity_change": m * f / dt}[mode]

    def add_force_torque(self, force, torque, mode="force"):
        """World-frame force at the centre of mass and torque, for the next step; mode
        'force', 'impulse' (divided by dt over the step), 'acceleration' or 'velocity_change'
        (times the mass; torques in these two modes are taken as torques)."""
        f = self._force(force, mode, "add_force_torque")
        t = np.asarray(torque, dtype=np.float64).reshape(3)
        if mode in ("impulse", "velocity_change"):
            t = t / self._scene._p.get_timestep()
        self._partsim().add_force_torque(f, t)

    def add_force_at_point(self, force, point, mode="force"):
        self._partsim().add_force_at_point(self._force(force, mode, "add_force_at_point"),
                                           np.asarray(point, dtype=np.float64).reshape(3))

    # damping
    def get_linear_damping(self):
        return self._partsim().get_linear_damping() if self._p is not None else \
            self._pending.get("linear_damping", 0.0)

    def set_linear_damping(self, damping):
        if self._p is None:
            return self._before("linear_damping", float(damping))
        self._p.set_damping(float(damping), self._p.get_angular_damping())

    def get_angular_damping(self):
        return self._partsim().get_angular_damping() if self._p is not None else \
            self._pending.get("angular_damping", 0.0)

    def set_angular_damping(self, damping):
        if self._p is None:
            return self._before("angular_damping", float(damping))
        self._p.set_damping(self._p.get_linear_damping(), float(damping))

    linear_damping = property(get_linear_damping, set_linear_damping)
    angular_damping = property(get_angular_damping, set_angular_damping)

    # PhysX's limits and switches: kept, no effect
    def _physx_value(name, default, doc):
        def get(self):
            return self._pending.get(name, default)

        def set(self, value):
            self._pending[name] = value

        return property(get, set, doc=doc)

    max_linear_velocity = _physx_value("max_linear_velocity", 1e16, "PhysX's: kept, no effect.")
    max_angular_velocity = _physx_value("max_angular_velocity", 100.0,
                                        "PhysX's: kept, no effect.")
    max_depenetration_velocity = _physx_value("max_depenetration_velocity", 1e16,
                                              "PhysX's: kept, no effect.")
    max_contact_impulse = _physx_value("max_contact_impulse", 1e32, "PhysX's: kept, no effect.")
    del _physx_value

    def get_disable_gravity(self):
        return False

    def set_disable_gravity(self, disable):
        if disable:
            raise PartsimError("set_disable_gravity(True): partsim applies the scene's gravity to "
                               "every body; cancel it with add_force_torque(-mass * gravity, 0) "
                               "each step")

    disable_gravity = property(get_disable_gravity, set_disable_gravity)


class PhysxRigidDynamicComponent(PhysxRigidBodyComponent):
    """A dynamic (or kinematic) body."""

    def __init__(self):
        super().__init__()
        self._kinematic = False

    def set_linear_velocity(self, velocity):
        v = np.asarray(velocity, dtype=np.float64).reshape(3)
        if self._p is None:
            return self._before("linear_velocity", v)
        self._p.set_velocity(v)

    def set_angular_velocity(self, velocity):
        w = np.asarray(velocity, dtype=np.float64).reshape(3)
        if self._p is None:
            return self._before("angular_velocity", w)
        self._p.set_angular_velocity(w)

    linear_velocity = property(PhysxRigidBodyComponent.get_linear_velocity, set_linear_velocity)
    angular_velocity = property(PhysxRigidBodyComponent.get_angular_velocity,
                                set_angular_velocity)

    def get_kinematic(self):
        if self._p is not None:
            return self._p.type == _p.ActorType.KINEMATIC
        return self._kinematic

    def set_kinematic(self, kinematic):
        if self._p is not None:
            if bool(kinematic) != self.get_kinematic():
                raise PartsimError("set_kinematic: partsim fixes a body's type when its entity is "
                                   "added to the scene: set it before")
            return
        self._kinematic = bool(kinematic)

    kinematic = property(get_kinematic, set_kinematic)

    def get_kinematic_target(self):
        return self._partsim().get_pose() if self._p is not None else Pose()

    def set_kinematic_target(self, target):
        """Moves a kinematic body to `target` (partsim places it at once)."""
        if not self.get_kinematic():
            raise PartsimError("set_kinematic_target: the body is not kinematic")
        self._partsim().set_pose(as_pose(target))

    kinematic_target = property(get_kinematic_target, set_kinematic_target)

    def get_locked_motion_axes(self):
        return [False] * 6

    def set_locked_motion_axes(self, axes):
        if any(axes):
            raise PartsimError("set_locked_motion_axes: partsim cannot lock a free body's axes; "
                               "build it as an articulation with the joints that should move")

    locked_motion_axes = property(get_locked_motion_axes)

    # PhysX sleeping: partsim's bodies never sleep
    def is_sleeping(self):
        return False

    def wake_up(self):
        """No effect: partsim's bodies never sleep."""

    def put_to_sleep(self):
        """No effect: partsim's bodies never sleep."""

    sleep_threshold = property(lambda self: 0.0, lambda self, v: None,
                               doc="PhysX's: kept, no effect (bodies never sleep).")
    solver_position_iterations = property(
        lambda self: self._scene._p.get_config().solver_iterations if self._scene else 10,
        lambda self, v: None, doc="The scene's solver iterations (read only in partsim).")
    solver_velocity_iterations = property(lambda self: 1, lambda self, v: None,
                                          doc="PhysX's: kept, no effect.")


unsupported(PhysxRigidBaseComponent, {
    "get_gpu_index": "no GPU simulation: partsim runs on the CPU",
    "get_gpu_pose_index": "no GPU simulation: partsim runs on the CPU",
})


# ------------------------------------------------------------------------------ articulations

@adapts(_p.Articulation)
class PhysxArticulation(Handle):
    """An articulation (SAPIEN 2's Articulation, SAPIEN 3's PhysxArticulation)."""

    __slots__ = ()

    @classmethod
    def _adapt(cls, obj, scene):
        return scene._handle(("art", obj.get_id()), lambda: cls(obj, scene)) if scene else \
            cls(obj, scene)

    def _key(self):
        return ("art", self._p.get_id())

    def get_name(self):
        return self._p.get_name()

    def set_name(self, name):
        self._p.set_name(name)

    name = property(get_name, set_name)

    def get_links(self):
        return wrap(self._p.get_links(), self._scene)

    def get_joints(self):
        return wrap(self._p.get_joints(), self._scene)

    def get_active_joints(self):
        return wrap(self._p.get_active_joints(), self._scene)

    links = property(get_links)
    joints = property(get_joints)
    active_joints = property(get_active_joints)

    def get_root(self):
        return self.get_links()[0]

    root = property(get_root)

    def get_pose(self):
        return wrap(self._p.get_root_pose())

    def set_pose(self, pose):
        self._p.set_root_pose(as_pose(pose))

    pose = property(get_pose, set_pose, doc="Root pose.")
    get_root_pose = get_pose
    set_root_pose = set_pose
    root_pose = property(get_pose, set_pose, doc="Root link's pose (SAPIEN 3).")

    def get_root_linear_velocity(self):
        return self._p.get_root_velocity()

    def set_root_linear_velocity(self, v):
        self._p.set_root_velocity(v)

    root_linear_velocity = property(get_root_linear_velocity, set_root_linear_velocity)
    root_angular_velocity = property(lambda self: self._p.get_root_angular_velocity(),
                                     lambda self, w: self._p.set_root_angular_velocity(w))

    def get_dof(self):
        return self._p.get_dof()

    dof = property(get_dof)

    def get_qlimits(self):
        return self._p.get_qlimits()

    get_qlimit = get_qlimits
    qlimits = property(get_qlimits)
    qlimit = qlimits

    qpos = property(lambda self: self._p.get_qpos(), lambda self, v: self._p.set_qpos(v))
    qvel = property(lambda self: self._p.get_qvel(), lambda self, v: self._p.set_qvel(v))
    qacc = property(lambda self: self._p.get_qacc(), lambda self, v: self._p.set_qacc(v))
    qf = property(lambda self: self._p.get_qf(), lambda self, v: self._p.set_qf(v))

    def find_link_by_name(self, name):
        return wrap(self._p.find_link_by_name(name), self._scene)

    def find_joint_by_name(self, name):
        return wrap(self._p.find_joint_by_name(name), self._scene)

    def compute_passive_force(self, gravity=True, coriolis_and_centrifugal=True,
                              external=True):
        return self._p.compute_passive_force(gravity, coriolis_and_centrifugal, external)

    def get_link_incoming_joint_forces(self):
        """(links, 6): for each link, the spatial force its parent exerts on it through its
        joint: force then torque about the joint's origin, in the joint's frame on the child,
        as SAPIEN's (PhysX's incoming joint force); the root's row is zero."""
        return self._p.get_link_incoming_joint_forces()

    link_incoming_joint_forces = property(get_link_incoming_joint_forces)

    def create_pinocchio_model(self, *args, **kwargs):
        """Refused: partsim's kinematics is KinematicModel.from_articulation (forward
        kinematics, Jacobians) and partsim.inverse_kinematics."""
        raise PartsimError("create_pinocchio_model: partsim has no Pinocchio; use "
                           "partsim.KinematicModel.from_articulation(articulation) and "
                           "partsim.inverse_kinematics (with partsim.sapien.partsim_object)")

    # PhysX's per-articulation solver settings: kept, no effect
    sleep_threshold = property(lambda self: 0.0, lambda self, v: None)
    solver_position_iterations = property(lambda self: self._p.get_config().solver_iterations
                                          if hasattr(self._p, "get_config") else 10,
                                          lambda self, v: None)
    solver_velocity_iterations = property(lambda self: 1, lambda self, v: None)


unsupported(PhysxArticulation, {
    "create_fixed_tendon": "no tendons: couple joints with an articulation description's "
                           "JointCoupling (partsim.ArticulationDesc.couplings)",
    "get_gpu_index": "no GPU simulation: partsim runs on the CPU",
    "clone_links": "build the links again with create_articulation_builder()",
})


@adapts(_p.Link)
class PhysxArticulationLinkComponent(PhysxRigidBodyComponent):
    """A link of an articulation (SAPIEN 2's Link): a rigid body whose entity is placed by the
    articulation."""

    @classmethod
    def _adapt(cls, obj, scene):
        if scene is None:
            return cls._bound(obj, None)
        return scene._handle(("link", obj.get_articulation_id(), obj.get_index()),
                             lambda: scene._link_entity(obj).find_component_by_type(cls))

    @classmethod
    def _bound(cls, link, scene):
        c = cls()
        object.__setattr__(c, "_p", link)
        object.__setattr__(c, "_scene", scene)
        return c

    def _key(self):
        return ("link", self._p.get_articulation_id(), self._p.get_index())

    def get_name(self):
        return self._p.get_name()

    def set_name(self, name):
        raise PartsimError(f"set_name: link '{self._p.get_name()}' keeps the name it was built "
                           "with")

    name = property(get_name, set_name)

    def get_pose(self):
        return wrap(self._p.get_pose())

    pose = property(get_pose)
    get_entity_pose = get_pose

    def set_entity_pose(self, pose):
        raise PartsimError(f"set_entity_pose: link '{self._p.get_name()}' is placed by its "
                           "articulation: set the articulation's root_pose and qpos")

    entity_pose = property(get_pose, set_entity_pose)

    def get_mass(self):
        return self._p.get_mass()

    mass = property(get_mass)

    def get_inertia(self):
        return self._p.get_inertia()

    inertia = property(get_inertia)

    def get_cmass_local_pose(self):
        return wrap(self._p.get_pose().inv() * self._p.get_cmass_pose())

    cmass_local_pose = property(get_cmass_local_pose)

    def get_linear_velocity(self):
        return self._p.get_linear_velocity()

    def get_angular_velocity(self):
        return self._p.get_angular_velocity()

    linear_velocity = property(get_linear_velocity)
    angular_velocity = property(get_angular_velocity)
    get_velocity = get_linear_velocity

    def get_articulation(self):
        return wrap(self._articulation(), self._scene)

    def _articulation(self):
        aid = self._p.get_articulation_id()
        for a in self._scene._p.get_articulations():
            if a.get_id() == aid:
                return a
        raise PartsimError(f"link '{self._p.get_name()}': its articulation was removed")

    articulation = property(get_articulation)

    def get_index(self):
        return self._p.get_index()

    index = property(get_index)

    def get_parent(self):
        i = self._p.get_parent_index()
        return None if i < 0 else self.get_articulation().get_links()[i]

    parent = property(get_parent)

    def get_children(self):
        i = self._p.get_index()
        return [link for link in self.get_articulation().get_links()
                if link._p.get_parent_index() == i]

    children = property(get_children)

    def get_joint(self):
        return self.get_articulation().get_joints()[self._p.get_index()]

    joint = property(get_joint)

    def is_root(self):
        return self._p.get_parent_index() < 0

    def get_collision_shapes(self):
        return wrap(self._p.get_collision_shapes(), self._scene)

    collision_shapes = property(get_collision_shapes)

    def add_force_torque(self, force, torque, mode="force"):
        raise PartsimError("add_force_torque on a link: partsim applies forces to links at a "
                           "point: add_force_at_point(force, point), or set the joints' qf")

    def put_to_sleep(self):
        """No effect: partsim's bodies never sleep."""

    def wake_up(self):
        """No effect: partsim's bodies never sleep."""

    sleeping = property(lambda self: False)



@adapts(_p.Joint)
class PhysxArticulationJoint(Handle):
    """A joint of an articulation (SAPIEN 2's Joint)."""

    __slots__ = ()

    def _key(self):
        return ("joint", id(self._scene), self._p.get_name(), self._p.get_index())

    def get_name(self):
        return self._p.get_name()

    name = property(get_name)

    def get_type(self):
        """'fixed', 'revolute' (limited or not, as SAPIEN's), 'prismatic' or 'screw'."""
        t = str(self._p.type).rsplit(".", 1)[-1].lower()
        return "revolute" if t == "continuous" else t

    type = property(get_type)

    def get_dof(self):
        return self._p.get_dof()

    dof = property(get_dof)

    def get_limits(self):
        """Limits (dof, 2) as SAPIEN's: [[lower, upper]] for a moving joint, (0, 2) for a fixed
        one; +-inf when unlimited."""
        if self._p.get_dof() == 0:
            return np.zeros((0, 2))
        return np.asarray(self._p.get_limits(), dtype=np.float64).reshape(1, 2)

    def set_limits(self, limits, upper=None):
        """set_limits([[lower, upper]]) as SAPIEN's, or set_limits(lower, upper)."""
        if upper is not None:
            return self._p.set_limits(float(limits), float(upper))
        lo, hi = limits_pair(limits, "revolute", f"joint '{self._p.get_name()}' set_limits")
        return self._p.set_limits(lo, hi)

    limits = property(get_limits, set_limits)
    get_limit = get_limits
    set_limit = set_limits
    limit = limits

    def set_drive_property(self, stiffness, damping, force_limit=math.inf, mode="force"):
        """SAPIEN's set_drive_property(stiffness, damping, force_limit=inf, mode='force'). Only
        the 'force' mode exists in partsim."""
        if mode != "force":
            raise PartsimError(
                f"joint '{self._p.get_name()}': set_drive_property mode '{mode}' is not "
                "supported (partsim drives are force drives: force = stiffness (target - q) + "
                "damping (velocity_target - qdot)); use mode='force'")
        return self._p.set_drive_property(stiffness, damping, force_limit)

    set_drive_properties = set_drive_property

    def get_drive_mode(self):
        return "force"

    drive_mode = property(get_drive_mode)
    stiffness = property(lambda self: self._p.get_drive_stiffness())
    damping = property(lambda self: self._p.get_drive_damping())
    force_limit = property(lambda self: self._p.get_drive_force_limit())
    get_stiffness = lambda self: self._p.get_drive_stiffness()  # noqa: E731
    get_force_limit = lambda self: self._p.get_drive_force_limit()  # noqa: E731

    def get_damping(self):
        return self._p.get_drive_damping()

    drive_target = property(lambda self: self._p.get_drive_target(),
                            lambda self, t: self._p.set_drive_target(t))
    drive_velocity_target = property(lambda self: self._p.get_drive_velocity_target(),
                                     lambda self, v: self._p.set_drive_velocity_target(v))
    friction = property(lambda self: self._p.get_friction(),
                        lambda self, f: self._p.set_friction(f))
    armature = property(lambda self: self._p.get_armature(),
                        lambda self, a: self._p.set_armature(a))

    def get_parent_link(self):
        return wrap(self._p.get_parent_link(), self._scene)

    def get_child_link(self):
        return wrap(self._p.get_child_link(), self._scene)

    parent_link = property(get_parent_link)
    child_link = property(get_child_link)
    pose_in_parent = property(lambda self: wrap(self._p.get_pose_in_parent()))
    pose_in_child = property(lambda self: wrap(self._p.get_pose_in_child()))
    global_pose = property(lambda self: wrap(self._p.get_global_pose()))

    def get_global_pose(self):
        return wrap(self._p.get_global_pose())

    max_velocity = property(lambda self: math.inf, lambda self, v: None,
                            doc="PhysX's joint speed limit: kept, no effect.")

    def get_max_velocity(self):
        return math.inf

    def set_max_velocity(self, velocity):
        """PhysX's joint speed limit: no effect in partsim."""


def limits_pair(limits, joint_type, what):
    """(lower, upper) from SAPIEN's [[lo, hi]] (one row per dof), [] for fixed, or (lo, hi)."""
    a = np.asarray(limits if limits is not None else [], dtype=np.float64)
    if a.size == 0:
        if joint_type not in ("fixed",):
            return (-math.inf, math.inf)
        return (0.0, 0.0)
    if a.shape in ((1, 2), (2,)):
        return tuple(a.reshape(2))
    raise PartsimError(f"{what}: limits must be [[lower, upper]] (one row per dof), [] or "
                       f"(lower, upper), got shape {a.shape}")


# ------------------------------------------------------------------------------ contacts


class PhysxContactPoint:
    """One contact point: position, normal (from body 0 to body 1), impulse on body 0 over the
    last step, separation."""

    __slots__ = ("position", "normal", "impulse", "separation")

    def __init__(self, point):
        self.position = point.position
        self.normal = point.normal
        self.impulse = point.impulse
        self.separation = point.separation


class PhysxContact:
    """One contact as SAPIEN reports it: `bodies` (SAPIEN 3: the two rigid components),
    `actor0`/`actor1` (SAPIEN 2: the entities of actors, the link components of links), the
    points, each with the impulse on body 0 over the last step. When one side is a static
    actor (the ground) it is body 1. `shapes` are partsim's descriptions of the two bodies."""

    __slots__ = ("actor0", "actor1", "bodies", "points", "body0", "body1")

    def __init__(self, contact, handle0, handle1):
        self.actor0, self.actor1 = handle0
        self.bodies = handle1
        self.points = [PhysxContactPoint(p) for p in contact.points]
        self.body0 = contact.body0
        self.body1 = contact.body1

    @property
    def shapes(self):
        return (self.body0, self.body1)

    def __repr__(self):
        return (f"<Contact '{self.body0.name}' - '{self.body1.name}', {len(self.points)} "
                "points>")


# ------------------------------------------------------------------------------ the system


class PhysxRayHit:
    """Where a ray met a shape: position, normal (the surface's, outward), distance (m), the
    rigid body (or link) component hit and the index of its collision shape."""

    __slots__ = ("position", "normal", "distance", "component", "shape_index")

    def __init__(self, hit, scene):
        self.position = hit.position
        self.normal = hit.normal
        self.distance = hit.distance
        self.component = scene._body_resolver()(hit.body)[1]
        self.shape_index = hit.body.shape_index

    @property
    def shape(self):
        """The collision shape hit (partsim's handle of it), None for a geom of an MJCF model."""
        if self.component is None or self.shape_index < 0:
            return None
        return self.component.get_collision_shapes()[self.shape_index]

    def __repr__(self):
        return (f"PhysxRayHit(position={np.round(self.position, 6).tolist()}, "
                f"distance={self.distance:.6g})")


class PhysxSystem:
    """SAPIEN 3's physics system of a scene: partsim's scene is its own physics system; this
    gives SAPIEN's names for its timestep, contacts and state."""

    def __init__(self, scene=None):
        self._scene = scene

    def _s(self):
        if self._scene is None:
            raise PartsimError("PhysxCpuSystem: not part of a scene yet: "
                               "sapien.Scene([PhysxCpuSystem(), RenderSystem()])")
        return self._scene

    def get_timestep(self):
        return self._s()._p.get_timestep()

    def set_timestep(self, timestep):
        self._s()._p.set_timestep(float(timestep))

    timestep = property(get_timestep, set_timestep)

    def get_config(self):
        return self._s()._p.get_config()

    config = property(get_config)

    def get_contacts(self):
        return self._s().get_contacts()

    def pack(self):
        return self._s()._p.pack()

    def unpack(self, data):
        self._s()._p.unpack(data)

    def step(self):
        self._s()._p.step()

    def _rigid_components(self, cls):
        found = (e.find_component_by_type(cls) for e in self._s()._actor_entities())
        return [c for c in found if c is not None]

    def get_rigid_dynamic_components(self):
        return self._rigid_components(PhysxRigidDynamicComponent)

    def get_rigid_static_components(self):
        return self._rigid_components(PhysxRigidStaticComponent)

    def get_articulation_link_components(self):
        return [link for a in self._s().get_all_articulations() for link in a.get_links()]

    rigid_dynamic_components = property(get_rigid_dynamic_components)
    rigid_static_components = property(get_rigid_static_components)
    articulation_link_components = property(get_articulation_link_components)

    def raycast(self, position, direction, distance):
        """The first collision shape a ray from `position` along `direction` meets within
        `distance` (m): a PhysxRayHit, or None when it meets nothing."""
        scene = self._s()
        hit = scene._p.raycast(np.asarray(position, dtype=np.float64).reshape(3),
                               np.asarray(direction, dtype=np.float64).reshape(3),
                               float(distance))
        return None if hit is None else PhysxRayHit(hit, scene)

    scene_collision_id = property(lambda self: 0)


class PhysxCpuSystem(PhysxSystem):
    """The CPU physics system (partsim's scene on MuJoCo)."""


class PhysxGpuSystem(PhysxSystem):
    def __init__(self, *args, **kwargs):
        raise PartsimError("PhysxGpuSystem: partsim simulates on the CPU (MuJoCo); run many "
                           "scenes at once with gymnasium.make_vec or several processes")


class PhysxDriveComponent(PhysxBaseComponent):
    def __init__(self, *args, **kwargs):
        raise PartsimError("PhysxDriveComponent: partsim has no actor-to-actor drive: join the "
                           "two bodies with an articulation joint and drive it")


class PhysxDistanceJointComponent(PhysxDriveComponent):
    pass


class PhysxGearComponent(PhysxDriveComponent):
    pass


__all__ = [n for n in dir() if n.startswith("Physx") or n in (
    "set_scene_config", "get_scene_config", "set_default_material", "get_default_material",
    "set_body_config", "get_body_config", "set_shape_config", "get_shape_config",
    "set_sdf_config", "is_gpu_enabled", "enable_gpu", "SceneConfig")]


# ------------------------------------------------------------------------------ mass properties


def _shape_mass(kind, dims, density):
    """Mass and principal inertia about the shape's centre, in the shape's frame (capsules and
    cylinders along x), for a uniform density."""
    if kind == "box":
        a, b, c = dims
        m = density * 8 * a * b * c
        return m, m / 3 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    if kind == "sphere":
        (r,) = dims
        m = density * 4 / 3 * math.pi * r ** 3
        return m, np.full(3, 0.4 * m * r * r)
    r, h = dims
    mc = density * math.pi * r * r * 2 * h
    if kind == "cylinder":
        return mc, np.array([mc * r * r / 2, *(2 * [mc * (3 * r * r + 4 * h * h) / 12])])
    ms = density * 4 / 3 * math.pi * r ** 3  # capsule: a cylinder and two half spheres
    along = mc * r * r / 2 + ms * 0.4 * r * r
    across = mc * (r * r / 4 + h * h / 3) + ms * (0.4 * r * r + h * h + 0.75 * h * r)
    return mc + ms, np.array([along, across, across])


def mass_properties(shapes):
    """(mass, cmass_local_pose, principal inertia) of a body from its primitive shapes, each
    (kind, dims, local pose, density), as PhysX computes them: the shapes' tensors moved to the
    common centre of mass and added, then diagonalised (the body's axes kept when the sum is
    diagonal already). None when a shape is not a primitive (MuJoCo computes those)."""
    parts = []
    for kind, dims, pose, density in shapes:
        if kind not in ("box", "sphere", "capsule", "cylinder"):
            return None
        m, principal = _shape_mass(kind, dims, density)
        rot = pose.to_transformation_matrix()[:3, :3]
        parts.append((m, np.asarray(pose.p, dtype=np.float64), rot @ np.diag(principal) @ rot.T))
    total = sum(m for m, _, _ in parts)
    if not parts or total <= 0:
        return None
    com = sum(m * c for m, c, _ in parts) / total
    tensor = np.zeros((3, 3))
    for m, c, inertia in parts:
        d = c - com
        tensor += inertia + m * (d @ d * np.eye(3) - np.outer(d, d))
    off = tensor - np.diag(np.diag(tensor))
    if np.abs(off).max() <= 1e-12 * max(1e-300, np.abs(tensor).max()):
        return total, Pose(com, [1, 0, 0, 0]), np.diag(tensor).copy()
    values, vectors = np.linalg.eigh(tensor)
    if np.linalg.det(vectors) < 0:
        vectors[:, 2] *= -1
    frame = np.eye(4)
    frame[:3, :3], frame[:3, 3] = vectors, com
    return total, Pose(frame), values


def _ecs_specs(shapes):
    out = []
    for s in shapes:
        kind = {PhysxCollisionShapeBox: "box", PhysxCollisionShapeSphere: "sphere",
                PhysxCollisionShapeCapsule: "capsule",
                PhysxCollisionShapeCylinder: "cylinder"}.get(type(s), "mesh")
        dims = {"box": lambda: tuple(s.half_size), "sphere": lambda: (s.radius,)}.get(
            kind, lambda: (getattr(s, "radius", 0.0), getattr(s, "half_length", 0.0)))()
        out.append((kind, dims, s.local_pose, s.density))
    return out
