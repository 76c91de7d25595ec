"""SAPIEN's Scene, builders and URDF loader on partsim."""

from __future__ import annotations

import math
import os

import numpy as np

from .. import _partsim as _p
from . import physx, render
from ._adapter import (Handle, PartsimError, Pose, adapts, as_pose, color4, unsupported,
                       unwrap, wrap)
from ._entity import Entity

# SAPIEN's default angular damping of a dynamic body (PhysxRigidDynamicComponent's), given to
# the bodies the adapter builds unless a script sets its own
SAPIEN_ANGULAR_DAMPING = 0.05


@adapts(_p.Scene)
class Scene(Handle):
    """A SAPIEN scene on a partsim.Scene: Scene() (the defaults given to sapien.physx's
    set_scene_config, set_default_material, set_body_config and set_shape_config),
    Scene([PhysxCpuSystem(), RenderSystem()]) (SAPIEN 3), Scene(config) (a SceneConfig) or
    partsim's Scene(timestep, gravity)."""

    __slots__ = ("_handles", "_entities", "_physx", "_render", "_ambient")

    def __init__(self, *args, systems=None, **kwargs):
        if args and isinstance(args[0], (list, tuple)) and all(
                isinstance(s, (physx.PhysxSystem, render.RenderSystem)) for s in args[0]):
            systems, args = args[0], args[1:]
        if not args and not kwargs:
            p = _p.Scene(physx.SceneConfig())
        else:
            p = _p.Scene(*unwrap(args), **kwargs)
        object.__setattr__(self, "_p", p)
        object.__setattr__(self, "_handles", {})
        object.__setattr__(self, "_entities", [])
        object.__setattr__(self, "_ambient", np.zeros(3, dtype=np.float32))
        systems = list(systems or [])
        px = next((s for s in systems if isinstance(s, physx.PhysxSystem)), None) or \
            physx.PhysxCpuSystem()
        rs = next((s for s in systems if isinstance(s, render.RenderSystem)), None) or \
            render.RenderSystem()
        px._scene = rs._scene = self
        object.__setattr__(self, "_physx", px)
        object.__setattr__(self, "_render", rs)
        if render.defaults.get("backend"):
            p.set_render_backend(render.defaults["backend"])

    @classmethod
    def _adapt(cls, obj, scene):
        if scene is not None and scene._p is obj:
            return scene
        raise PartsimError("a partsim.Scene cannot become a SAPIEN scene after it was made: "
                           "create it with partsim.sapien.Scene()")

    @property
    def _scene(self):
        return self

    def _key(self):
        return ("scene", id(self._p))

    def _handle(self, key, make):
        h = self._handles.get(key)
        if h is None:
            h = self._handles[key] = make()
        return h

    # ----------------------------------------------------------------------- systems
    def get_physx_system(self):
        return self._physx

    def get_render_system(self):
        return self._render

    physx_system = property(get_physx_system)
    render_system = property(get_render_system)

    def get_timestep(self):
        return self._p.get_timestep()

    def set_timestep(self, timestep):
        self._p.set_timestep(float(timestep))

    timestep = property(get_timestep, set_timestep)

    def step(self, *args):
        self._p.step(*args)

    def update_render(self):
        self._p.update_render()

    # ----------------------------------------------------------------------- entities
    def _actor_entity(self, actor):
        key = ("actor", actor.get_id())
        e = self._handles.get(key)
        if e is None:
            e = Entity()
            rigid = physx.PhysxRigidStaticComponent() if actor.type == _p.ActorType.STATIC \
                else physx.PhysxRigidDynamicComponent()
            self._bind_entity(e, actor, [rigid, render.RenderBodyComponent()])
        return e

    def _link_entity(self, link):
        key = ("link-entity", link.get_articulation_id(), link.get_index())
        e = self._handles.get(key)
        if e is None:
            e = Entity()
            comp = physx.PhysxArticulationLinkComponent()
            self._handles[key] = e
            self._handles[("link", link.get_articulation_id(), link.get_index())] = comp
            self._bind_entity(e, link, [comp, render.RenderBodyComponent()])
        return e

    def _bind_entity(self, e, body, components):
        object.__setattr__(e, "_p", body)
        object.__setattr__(e, "_scene", self)
        e._in_scene = True
        for c in components:
            if c not in e._components:
                e._components.insert(0, c) if isinstance(c, physx.PhysxRigidBaseComponent) \
                    else e._components.append(c)
            c._bind(body, self, e)
        if isinstance(body, _p.Actor):
            self._handles[("actor", body.get_id())] = e

    def _camera_component(self, camera):
        key = ("camera", camera.get_id())
        c = self._handles.get(key)
        if c is None:
            c = render.RenderCameraComponent(camera.width, camera.height)
            c._bind(camera, self, None)
            self._handles[key] = c
        return c

    def add_entity(self, entity):
        """Adds an entity: its rigid body and render body become a partsim actor (static when it
        has no rigid body), its cameras are mounted on it, its lights are placed, and the
        on_add_to_scene(scene) of the script's own components is called."""
        if not isinstance(entity, Entity):
            raise PartsimError(f"add_entity: expected a sapien.Entity, got "
                               f"{type(entity).__name__}")
        if entity._in_scene:
            raise PartsimError(f"add_entity: entity '{entity.get_name()}' is in a scene already")
        rigid = entity.find_component_by_type(physx.PhysxRigidBaseComponent)
        body = entity.find_component_by_type(render.RenderBodyComponent)
        if rigid is not None or body is not None:
            actor = self._build_actor(entity, rigid, body)
            self._bind_entity(entity, actor, [c for c in (rigid, body) if c is not None])
        else:
            object.__setattr__(entity, "_scene", self)
            entity._in_scene = True
            self._entities.append(entity)
        for c in entity._components:
            if c not in (rigid, body):
                self._attach_later(entity, c)
        return entity

    def _build_actor(self, entity, rigid, body):
        b = self._p.create_actor_builder()
        shapes = rigid._shapes if rigid is not None else []
        for s in shapes:
            s._add_to(b)
        for s in (body._shapes if body is not None else []):
            s._add_to(b)
        dynamic = isinstance(rigid, physx.PhysxRigidDynamicComponent)
        if dynamic:
            props = rigid._mass_properties()
            if props[0] > 0 and (rigid._mass is not None or physx.mass_properties(
                    physx._ecs_specs(shapes)) is not None):
                b.set_mass_and_inertia(float(props[0]), props[1], np.asarray(props[2]))
        b.set_name(entity._name)
        b.set_initial_pose(entity._pose)
        if not dynamic:
            actor = b.build_static()
        elif rigid._kinematic:
            actor = b.build_kinematic()
        else:
            actor = b.build()
            pending = rigid._pending
            actor.set_damping(pending.get("linear_damping", 0.0),
                              pending.get("angular_damping", SAPIEN_ANGULAR_DAMPING))
            if "linear_velocity" in pending:
                actor.set_velocity(pending["linear_velocity"])
            if "angular_velocity" in pending:
                actor.set_angular_velocity(pending["angular_velocity"])
        built = actor.get_collision_shapes()
        if len(built) == len(shapes):
            for s, h in zip(shapes, built):
                if s._groups is not None:
                    h.set_collision_groups(s._groups)
                s._shape = h
        return actor

    def _attach_later(self, entity, component):
        """A component added to an entity already in the scene (or besides its bodies)."""
        if isinstance(component, (physx.PhysxRigidBaseComponent, render.RenderBodyComponent)) \
                and component._p is None:
            raise PartsimError(f"add_component: partsim builds an entity's bodies when it is "
                               f"added to the scene: add the {type(component).__name__} before")
        if isinstance(component, render.RenderCameraComponent):
            component._mount(self, entity)
        elif isinstance(component, render.RenderLightComponent):
            component._place(self)
            component._entity = entity
        elif component._p is None:
            object.__setattr__(component, "_scene", self)
            component._entity = entity
            hook = getattr(type(component), "on_add_to_scene", None)
            if hook is not None:
                hook(component, self)

    def _detach(self, entity, component):
        if isinstance(component, render.RenderCameraComponent) and component._p is not None:
            self._handles.pop(("camera", component._p.get_id()), None)
            self._p.remove_camera(component._p)
            object.__setattr__(component, "_p", None)
        elif isinstance(component, (physx.PhysxRigidBaseComponent, render.RenderBodyComponent)):
            raise PartsimError(f"remove_component: the {type(component).__name__} is built into "
                               "the actor: remove the entity from the scene instead")
        elif isinstance(component, render.RenderLightComponent):
            raise PartsimError("remove_component: partsim's lights stay in the scene once added")
        else:
            hook = getattr(type(component), "on_remove_from_scene", None)
            if hook is not None:
                hook(component, self)

    def _entity_moved(self, entity):
        for c in entity._components:
            if isinstance(c, render.RenderCameraComponent) and c._p is not None:
                c._p.set_local_pose(entity.get_pose() * c._spec["local_pose"])

    def remove_entity(self, entity):
        if entity._scene is not self or not entity._in_scene:
            raise PartsimError("remove_entity: the entity is not in this scene")
        body = entity._p
        if isinstance(body, _p.Link):
            raise PartsimError(f"remove_entity: link '{body.get_name()}' belongs to an "
                               "articulation: remove the articulation")
        for c in list(entity._components):
            if isinstance(c, render.RenderCameraComponent) and c._p is not None:
                self._detach(entity, c)
            elif not isinstance(c, (physx.PhysxRigidBaseComponent, render.RenderBodyComponent,
                                    render.RenderLightComponent)):
                self._detach(entity, c)
        if isinstance(body, _p.Actor):
            self._handles.pop(("actor", body.get_id()), None)
            self._p.remove_actor(body)
        elif entity in self._entities:
            self._entities.remove(entity)
        entity._in_scene = False

    def remove_actor(self, actor):
        self.remove_entity(actor)

    def remove_articulation(self, articulation):
        a = unwrap(articulation)
        aid = a.get_id()
        for k in [k for k in self._handles if k[0] in ("link", "link-entity", "art") and
                  k[1] == aid]:
            del self._handles[k]
        self._p.remove_articulation(a)

    def _actor_entities(self):
        return [self._actor_entity(a) for a in self._p.get_actors()]

    def get_entities(self):
        """The entities of the actors, of every articulation's links, and those without a body
        (cameras, lights)."""
        out = self._actor_entities()
        for a in self._p.get_articulations():
            out.extend(self._link_entity(link) for link in a.get_links())
        return out + list(self._entities)

    entities = property(get_entities)

    def get_all_actors(self):
        return self._actor_entities()

    get_actors = get_all_actors

    def get_all_articulations(self):
        return wrap(self._p.get_articulations(), self)

    get_articulations = get_all_articulations

    def find_actor_by_name(self, name):
        a = self._p.find_actor_by_name(name)
        return None if a is None else self._actor_entity(a)

    # ----------------------------------------------------------------------- builders
    def create_actor_builder(self):
        return ActorBuilder(self._p.create_actor_builder(), self)

    def create_articulation_builder(self):
        return ArticulationBuilder(self._p.create_articulation_builder(), self)

    def create_urdf_loader(self):
        return URDFLoader(self._p.create_urdf_loader(), self)

    def create_physical_material(self, static_friction, dynamic_friction, restitution):
        return physx.PhysxMaterial(static_friction, dynamic_friction, restitution)

    def get_default_physical_material(self):
        return self._p.get_config().default_material

    def set_default_physical_material(self, material):
        self._p.set_default_material(material)

    default_physical_material = property(get_default_physical_material,
                                         set_default_physical_material,
                                         doc="The material of shapes built with none (SAPIEN 2).")

    def add_ground(self, altitude=0.0, *args, **kwargs):
        """SAPIEN's add_ground(altitude, render=True, material=None, render_material=None,
        render_half_size=[10, 10]): render_material may be a RenderMaterial or a colour."""
        if args and isinstance(args[0], (bool, np.bool_)):
            names = ["render", "material", "render_material", "render_half_size"]
            if len(args) > len(names):
                raise PartsimError("add_ground: too many arguments")
            kwargs.update(zip(names, args))
            args = ()
        rm = kwargs.get("render_material")
        if rm is not None and not isinstance(rm, _p.RenderMaterial):
            kwargs["render_material"] = render.RenderMaterial(base_color=rm)
        return wrap(self._p.add_ground(altitude, *args, **kwargs), self)

    # ----------------------------------------------------------------------- contacts
    def _body_resolver(self):
        """A function from a partsim ContactBody to (its SAPIEN 2 handle, its component): the
        entity and the rigid component of an actor, the link component (twice) of a link;
        (None, None) for what names neither (a geom of an MJCF model). It reads the scene's
        actors and articulations once."""
        actors = {a.get_id(): a for a in self._p.get_actors()}
        arts = {a.get_id(): a for a in self._p.get_articulations()}
        links = {}

        def resolve(body):
            if body.kind == _p.ContactBody.Kind.ACTOR:
                a = actors.get(body.actor_id)
                if a is None:
                    return None, None
                e = self._actor_entity(a)
                return e, e.find_component_by_type(physx.PhysxRigidBaseComponent)
            if body.articulation_id not in links:
                art = arts.get(body.articulation_id)
                links[body.articulation_id] = art.get_links() if art is not None else []
            ls = links[body.articulation_id]
            if not 0 <= body.link_index < len(ls):
                return None, None
            comp = wrap(ls[body.link_index], self)
            return comp, comp

        return resolve

    def get_contacts(self):
        """Contacts of the last step (PhysxContact: bodies, actor0/actor1, points)."""
        contacts = self._p.get_contacts()
        if not contacts:
            return []
        handles = self._body_resolver()
        out = []
        for c in contacts:
            (a0, b0), (a1, b1) = handles(c.body0), handles(c.body1)
            out.append(physx.PhysxContact(c, (a0, a1), (b0, b1)))
        return out

    # ----------------------------------------------------------------------- cameras, lights
    def add_camera(self, name, width, height, fovy, near, far):
        """A camera fixed in the world (place it with set_pose, or camera.entity.set_pose)."""
        return self._camera_component(self._p.add_camera(name, width, height, fovy, near, far))

    def add_mounted_camera(self, name, mount=None, pose=None, width=None, height=None, *args,
                           actor=None, fovx=None, **kwargs):
        """add_mounted_camera(name, mount, pose, width, height, fovy, near, far); SAPIEN 2.0's
        (name, actor, pose, width, height, fovx, fovy, near, far) also works (fovx then follows
        from fovy and the size)."""
        if mount is None:
            mount = actor
        if len(args) == 4:
            args = args[1:]
        cam = self._p.add_mounted_camera(name, unwrap(mount), as_pose(pose), width, height,
                                         *args, **kwargs)
        return self._camera_component(cam)

    def get_cameras(self):
        return [self._camera_component(c) for c in self._p.get_cameras()]

    get_mounted_cameras = get_cameras

    def remove_camera(self, camera):
        self._handles.pop(("camera", camera._p.get_id()), None)
        self._p.remove_camera(camera._p)

    def set_ambient_light(self, color):
        c = np.asarray(color, dtype=np.float32).reshape(-1)[:3]
        self._ambient = c
        self._p.set_ambient_light(c)

    def get_ambient_light(self):
        return self._ambient

    ambient_light = property(get_ambient_light, set_ambient_light)

    def add_directional_light(self, direction, color, shadow=False, position=None, scale=10.0,
                              near=-10.0, far=10.0, shadow_map_size=2048):
        """SAPIEN's add_directional_light(direction, color, shadow=False, position, scale, near,
        far, shadow_map_size): partsim fits each shadow map to the scene, so the shadow volume
        arguments are accepted and not used."""
        return self._p.add_directional_light(direction, color, bool(shadow))

    def add_point_light(self, position, color, shadow=False, shadow_near=0.1, shadow_far=10.0,
                        shadow_map_size=2048):
        """SAPIEN's add_point_light(position, color, shadow=False, ...). Point lights cast no
        shadows in partsim's rasterizer (directional and spot lights do; the path tracer
        shadows every light)."""
        return self._p.add_point_light(position, color)

    def add_spot_light(self, position, direction, inner_fov=None, outer_fov=None, color=None,
                       shadow=False, shadow_near=0.1, shadow_far=10.0, shadow_map_size=2048,
                       inner_angle=None, outer_angle=None):
        """SAPIEN's add_spot_light(position, direction, inner_fov, outer_fov, color,
        shadow=False, ...): inner_fov and outer_fov are full cone angles (rad). partsim's half
        angles may be given as inner_angle and outer_angle instead."""
        if inner_angle is None:
            if inner_fov is None or outer_fov is None:
                raise PartsimError("add_spot_light: give inner_fov and outer_fov (full angles, "
                                   "rad) or inner_angle and outer_angle (half angles)")
            inner_angle, outer_angle = inner_fov / 2.0, outer_fov / 2.0
        if color is None:
            raise PartsimError("add_spot_light: color is required")
        return self._p.add_spot_light(position, direction, inner_angle, outer_angle, color,
                                      bool(shadow))

    def create_viewer(self, port=0, address="127.0.0.1", token=None):
        """The browser viewer of this scene (SAPIEN's name): starts its server on a free port
        (or `port`) and prints the URL to open on stderr."""
        from .utils import Viewer
        return Viewer(self, port=port, address=address, token=token)


unsupported(Scene, {
    "create_drive": "partsim has no actor-to-actor drive: join the two with an articulation "
                    "joint and drive it",
    "add_system": "the scene's systems are fixed: pass them to sapien.Scene([...])",
    "get_system": "use scene.physx_system and scene.render_system",
})


# ------------------------------------------------------------------------------ builders

def _shape_kwargs(what, kwargs):
    """Drops the PhysX-only shape arguments; refuses triggers."""
    if kwargs.pop("is_trigger", False):
        raise PartsimError(f"{what}: trigger shapes (is_trigger=True) are not supported by "
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

    def add(self, *args, **kwargs):
        if len(args) > len(params):
            raise PartsimError(f"{name}: at most {len(params)} positional arguments "
                               f"({', '.join(params)})")
        for k, v in zip(params, args):
            if k in kwargs:
                raise PartsimError(f"{name}: '{k}' given twice")
            kwargs[k] = v
        color = kwargs.pop("color", None)
        material = kwargs.pop("material", None)
        if color is not None and material is not None:
            raise PartsimError(f"{name}: give color or material, not both")
        paint = material if material is not None else color
        render_material = None
        if isinstance(paint, _p.RenderMaterial):
            render_material = paint
        elif paint is not None:
            rgba = color4(paint, name).astype(np.float32)
            if name == "add_visual_from_file":
                render_material = render.RenderMaterial(base_color=rgba)
            else:
                kwargs["color"] = rgba
        if kwargs.get("pose") is not None:
            kwargs["pose"] = as_pose(kwargs["pose"])
        else:
            kwargs.pop("pose", None)
        count = self._p.get_visual_count()
        getattr(self._p, name)(**kwargs)
        if render_material is not None:
            for i in range(count, self._p.get_visual_count()):
                self._p.set_visual_material(i, render_material)
        return self

    add.__name__ = name
    add.__doc__ = (f"SAPIEN's {name}({', '.join(params)}): the colour as RGB or RGBA, or "
                   "material= a RenderMaterial or a colour (for a file, it replaces the "
                   "file's materials).")
    return add


def _collision_adder(name):
    def add(self, *args, **kwargs):
        if "pose" in kwargs:
            kwargs["pose"] = as_pose(kwargs["pose"])
        args = tuple(as_pose(a) if i == 0 and isinstance(a, _p.Pose) else a
                     for i, a in enumerate(args))
        getattr(self._p, name)(*args, **_shape_kwargs(name, kwargs))
        return self

    add.__name__ = name
    add.__doc__ = (f"SAPIEN's {name}: patch_radius and min_patch_radius (PhysX torsional "
                   "friction) are accepted and not used; is_trigger=True is refused.")
    return add


class _BodyBuilder(Handle):
    """What actor and link builders share: SAPIEN's collision and visual adders."""

    __slots__ = ()

    def add_collision_from_file(self, filename, pose=None, scale=(1, 1, 1), material=None,
                                density=1000.0, **kwargs):
        """SAPIEN's name for add_convex_collision_from_file."""
        _shape_kwargs("add_collision_from_file", kwargs)
        self._p.add_convex_collision_from_file(filename, as_pose(pose), scale, material, density)
        return self

    def add_multiple_convex_collisions_from_file(self, filename, pose=None, scale=(1, 1, 1),
                                                 material=None, density=1000.0, **kwargs):
        """One convex piece per sub-mesh (or connected component) of the file."""
        _shape_kwargs("add_multiple_convex_collisions_from_file", kwargs)
        if not hasattr(self._p, "add_multiple_convex_collisions_from_file"):
            raise PartsimError("add_multiple_convex_collisions_from_file: a link takes one "
                               "convex piece per call (add_convex_collision_from_file)")
        self._p.add_multiple_convex_collisions_from_file(filename, as_pose(pose), scale,
                                                         material, density)
        return self

    add_multiple_collisions_from_file = add_multiple_convex_collisions_from_file

    def add_nonconvex_collision_from_file(self, filename, *args, **kwargs):
        """Refused: MuJoCo collides convex shapes only."""
        raise PartsimError(
            f"add_nonconvex_collision_from_file('{filename}'): partsim collides convex shapes "
            "only (MuJoCo); use add_multiple_convex_collisions_from_file (one convex piece per "
            "sub-mesh) or decompose the mesh first (`partsim assets decompose`)")

    def add_plane_collision(self, *args, **kwargs):
        raise PartsimError("add_plane_collision: partsim's plane is the ground: "
                           "scene.add_ground(altitude)")

    def add_plane_visual(self, *args, **kwargs):
        raise PartsimError("add_plane_visual: scene.add_ground(altitude, render=True) draws the "
                           "ground; otherwise use a thin box visual")

    def set_mass_and_inertia(self, mass, cmass_local_pose, inertia):
        self._p.set_mass_and_inertia(float(mass), as_pose(cmass_local_pose),
                                     np.asarray(inertia, dtype=np.float64).reshape(3))
        return self

    def set_name(self, name):
        self._p.set_name(str(name))
        return self


for _n in _VISUAL_PARAMS:
    setattr(_BodyBuilder, _n, _visual_adder(_n))
for _n in ("add_box_collision", "add_sphere_collision", "add_capsule_collision",
           "add_cylinder_collision", "add_convex_collision_from_file"):
    setattr(_BodyBuilder, _n, _collision_adder(_n))
del _n


@adapts(_p.ActorBuilder)
class ActorBuilder(_BodyBuilder):
    """SAPIEN's actor builder: shapes, then build() (an Entity)."""

    __slots__ = ("_body_type", "_initial_pose")

    def __init__(self, p, scene):
        super().__init__(p, scene)
        object.__setattr__(self, "_body_type", "dynamic")
        object.__setattr__(self, "_initial_pose", None)

    def set_physx_body_type(self, body_type):
        """SAPIEN 3: 'dynamic', 'kinematic' or 'static', used by build()."""
        if body_type not in ("dynamic", "kinematic", "static"):
            raise PartsimError(f"set_physx_body_type: expected 'dynamic', 'kinematic' or "
                               f"'static', got '{body_type}'")
        object.__setattr__(self, "_body_type", body_type)
        return self

    def set_initial_pose(self, pose):
        self._p.set_initial_pose(as_pose(pose))
        return self

    def build(self, name=None, kinematic=None):
        """build(name='') as SAPIEN's (the body type set by set_physx_body_type, dynamic by
        default): an Entity. partsim's build(kinematic=False) also works."""
        if isinstance(name, (bool, np.bool_)):
            name, kinematic = None, bool(name)
        if name:
            self._p.set_name(name)
        kind = "kinematic" if kinematic else self._body_type
        if kind == "static":
            actor = self._p.build_static()
        elif kind == "kinematic":
            actor = self._p.build_kinematic()
        else:
            actor = self._p.build()
            actor.set_damping(0.0, SAPIEN_ANGULAR_DAMPING)
        return self._scene._actor_entity(actor)

    def build_kinematic(self, name=""):
        return self.set_physx_body_type("kinematic").build(name or None)

    def build_static(self, name=""):
        return self.set_physx_body_type("static").build(name or None)

    def build_entity(self):
        """SAPIEN 3: the entity, added to the scene (partsim builds bodies into a scene)."""
        return self.build()


_JOINT_TYPES = {"revolute": "revolute", "revolute_unwrapped": "revolute",
                "continuous": "continuous", "prismatic": "prismatic", "fixed": "fixed",
                "screw": "screw"}


@adapts(_p.LinkBuilder)
class LinkBuilder(_BodyBuilder):
    """SAPIEN's link builder: shapes and the joint to the parent."""

    __slots__ = ()

    def set_joint_properties(self, type, limits=None, pose_in_parent=None, pose_in_child=None,
                             friction=0.0, damping=0.0):
        """SAPIEN's set_joint_properties(type, limits, pose_in_parent, pose_in_child, friction,
        damping): type 'fixed', 'revolute' (or 'revolute_unwrapped'), 'continuous', 'prismatic'
        or 'screw'; limits [[lower, upper]] per dof ([] for fixed; [[-inf, inf]] for an
        unlimited revolute), or partsim's (lower, upper). The joint's x axis is its axis."""
        if isinstance(type, str):
            key = type.lower()
            if key not in _JOINT_TYPES:
                raise PartsimError(f"set_joint_properties: unknown joint type '{type}' (fixed, "
                                   "revolute, continuous, prismatic, screw)")
            type = _JOINT_TYPES[key]
            lo, hi = physx.limits_pair(limits, type, "set_joint_properties")
            if type == "revolute" and math.isinf(lo) and math.isinf(hi):
                type = "continuous"
        else:
            lo, hi = physx.limits_pair(limits, str(type), "set_joint_properties")
        self._p.set_joint_properties(type, np.array([lo, hi]), as_pose(pose_in_parent),
                                     as_pose(pose_in_child), friction, damping)
        return self

    def set_joint_name(self, name):
        self._p.set_joint_name(str(name))
        return self

    def set_parent(self, parent):
        raise PartsimError("set_parent: give the parent to create_link_builder(parent)")


@adapts(_p.ArticulationBuilder)
class ArticulationBuilder(Handle):
    """SAPIEN's articulation builder: create_link_builder(parent), then build()."""

    __slots__ = ()

    def create_link_builder(self, parent=None):
        return LinkBuilder(self._p.create_link_builder(unwrap(parent)), self._scene)

    def set_initial_pose(self, pose):
        self._p.set_initial_pose(as_pose(pose))
        return self

    def build(self, fix_root_link=None, name=None):
        if name:
            self._p.set_name(name)
        return wrap(self._p.build(bool(fix_root_link)) if fix_root_link is not None
                    else self._p.build(), self._scene)

    def build_kinematic(self):
        return wrap(self._p.build_kinematic(), self._scene)


class _DescArticulationBuilder:
    """An articulation read from a file, built into the scene by build() (what SAPIEN's
    loader.parse gives and load_file_as_articulation_builder returns)."""

    def __init__(self, desc, scene):
        self._desc = desc
        self._scene = scene
        self.initial_pose = None

    def get_desc(self):
        return self._desc

    def set_initial_pose(self, pose):
        self.initial_pose = Pose._of(as_pose(pose))
        return self

    def build(self, fix_root_link=None):
        if fix_root_link is not None:
            self._desc.fix_root_link = bool(fix_root_link)
        if self.initial_pose is not None:
            self._desc.root_pose = self.initial_pose
        return wrap(self._scene._p.add_articulation(self._desc), self._scene)

    def build_kinematic(self):
        self._desc.kinematic = True
        return self.build()


# ------------------------------------------------------------------------------ URDF loader


@adapts(_p.UrdfLoader)
class URDFLoader(Handle):
    """SAPIEN's URDF loader: load(urdf_file, srdf_file=None, package_dir=None), load_multiple,
    load_kinematic, parse (SAPIEN's: articulation builders, actor builders, cameras), the
    material and density settings."""

    __slots__ = ()

    def _apply(self, config=None, package_dir=None, srdf_file=None):
        loader = self._p
        if package_dir is not None:
            # package://NAME/... resolves to package_dir/NAME/...
            root = os.path.abspath(os.fspath(package_dir))
            if not os.path.isdir(root):
                raise PartsimError(f"load: package_dir '{package_dir}' is not a folder")
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

    def _srdf_package(self, a, b):
        """SAPIEN 3 takes (srdf_file, package_dir); SAPIEN 2 took (config, package_dir)."""
        if isinstance(a, dict):
            return None, a
        return a, None

    def load(self, filename, srdf_file=None, package_dir=None, config=None):
        """The URDF as an articulation: load(urdf_file, srdf_file=None, package_dir=None) as
        SAPIEN 3's; SAPIEN 2's load(filename, config, package_dir) also works (config gives
        'material' and 'density' for every link and a 'link' table of per-link ones)."""
        srdf, conf = self._srdf_package(srdf_file, None)
        self._apply(config or conf, package_dir, srdf)
        return wrap(self._p.load(str(filename)), self._scene)

    def load_kinematic(self, filename, srdf_file=None, package_dir=None, config=None):
        """The URDF as a kinematic articulation (moved by set_qpos and set_root_pose only,
        never by forces)."""
        srdf, conf = self._srdf_package(srdf_file, None)
        self._apply(config or conf, package_dir, srdf)
        desc = self._p.parse_file(str(filename))
        desc.kinematic = True
        return wrap(self._scene._p.add_articulation(desc), self._scene)

    def parse(self, urdf_file, srdf_file=None, package_dir=None):
        """SAPIEN's parse: ([articulation builder], [actor builders], [cameras]) of the file;
        partsim reads a URDF as one articulation, so the second list is empty, and the third
        too (URDF cameras are not read)."""
        self._apply(None, package_dir, srdf_file)
        return [_DescArticulationBuilder(self._p.parse_file(str(urdf_file)), self._scene)], [], []

    def load_multiple(self, urdf_file, srdf_file=None, package_dir=None):
        """([articulation], []): partsim reads a URDF as one articulation."""
        return [self.load(urdf_file, srdf_file, package_dir)], []

    def load_file_as_articulation_builder(self, urdf_file, srdf_file=None, package_dir=None):
        self._apply(None, package_dir, srdf_file)
        return _DescArticulationBuilder(self._p.parse_file(str(urdf_file)), self._scene)

    # SAPIEN 3's settings
    def set_material(self, static_friction, dynamic_friction, restitution):
        self._p.material = physx.PhysxMaterial(static_friction, dynamic_friction, restitution)

    def set_density(self, density):
        self._p.density = float(density)

    def _override(self, link, density=None, material=None):
        overrides = dict(self._p.link_overrides)
        old = overrides.get(link)
        overrides[link] = _p.UrdfLinkOverride(
            density=density if density is not None else (old.density if old else None),
            material=material if material is not None else (old.material if old else None))
        self._p.link_overrides = overrides

    def set_link_material(self, link_name, static_friction, dynamic_friction, restitution):
        self._override(link_name, material=physx.PhysxMaterial(static_friction,
                                                               dynamic_friction, restitution))

    def set_link_density(self, link_name, density):
        self._override(link_name, density=float(density))

    def set_patch_radius(self, radius):
        """PhysX's torsional friction patch: accepted, not used."""

    set_min_patch_radius = set_patch_radius

    def set_link_patch_radius(self, link_name, radius):
        """PhysX's torsional friction patch: accepted, not used."""

    set_link_min_patch_radius = set_link_patch_radius

    collision_is_visual = property(lambda self: False, lambda self, v: self._refuse_cv(v))
    revolute_unwrapped = property(lambda self: False, lambda self, v: None,
                                  doc="Accepted: partsim's revolute joints are not wrapped.")

    def _refuse_cv(self, value):
        if value:
            raise PartsimError("collision_is_visual: partsim reads a URDF's visuals as they are")


unsupported(URDFLoader, {
    "multiple_collisions_decomposition": "decompose meshes with `partsim assets decompose`",
})

