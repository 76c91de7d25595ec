"""SAPIEN 3's entities and components on partsim.

An Entity made by a script collects components (a rigid body with its collision shapes, a render
body with its visual shapes, cameras, lights, components of the script's own) and a pose; adding
it to a scene builds a partsim actor from them (or mounts the cameras and places the lights).
The entities partsim makes (builder.build(), the links of articulations) stand for their actor or
link and carry the matching components.
"""

from __future__ import annotations

from .. import _partsim as _p
from ._adapter import Handle, PartsimError, Pose, adapts, as_pose, unsupported, wrap


class Component(Handle):
    """SAPIEN 3's Component. Subclass it for components of your own: a script's component may
    define on_add_to_scene(scene) and on_remove_from_scene(scene), which are called when its
    entity enters and leaves a scene, and on_set_pose(pose), called when the entity is placed."""

    def __init__(self):
        Handle.__init__(self, None, None)
        object.__setattr__(self, "_entity", None)
        object.__setattr__(self, "_name", "")
        object.__setattr__(self, "_enabled", True)

    __setattr__ = object.__setattr__

    def _key(self):
        return (type(self), id(self))

    def get_entity(self):
        return self._entity

    entity = property(get_entity)

    def get_name(self):
        return self._name

    def set_name(self, name):
        self._name = str(name)

    name = property(lambda self: self.get_name(), lambda self, n: self.set_name(n))

    def get_entity_pose(self):
        if self._entity is None:
            raise PartsimError(f"{type(self).__name__}: not attached to an entity")
        return self._entity.get_pose()

    def set_entity_pose(self, pose):
        if self._entity is None:
            raise PartsimError(f"{type(self).__name__}: not attached to an entity")
        self._entity.set_pose(pose)

    entity_pose = property(lambda self: self.get_entity_pose(),
                           lambda self, p: self.set_entity_pose(p))
    # SAPIEN 3 keeps component.pose as the entity's pose (deprecated there)
    get_pose = get_entity_pose
    set_pose = set_entity_pose
    pose = entity_pose

    def enable(self):
        self._enabled = True

    def disable(self):
        """Marks the component disabled. partsim keeps a built body in the simulation: remove
        its entity from the scene to take it out."""
        self._enabled = False

    is_enabled = property(lambda self: self._enabled)

    def _bind(self, p, scene, entity):
        object.__setattr__(self, "_p", p)
        object.__setattr__(self, "_scene", scene)
        object.__setattr__(self, "_entity", entity)

    def __repr__(self):
        return f"<partsim.sapien.{type(self).__name__}>"


@adapts(_p.Actor)
class Entity(Handle):
    """SAPIEN 3's Entity (SAPIEN 2's Actor): a name, a pose and components. Once in a scene it
    stands for the partsim actor or link built from it, and partsim's actor methods
    (get_velocity, add_force_torque, get_collision_shapes, ...) are reachable from it."""

    def __init__(self):
        Handle.__init__(self, None, None)
        object.__setattr__(self, "_name", "")
        object.__setattr__(self, "_pose", Pose())
        object.__setattr__(self, "_components", [])
        object.__setattr__(self, "_in_scene", False)

    def _body_component(self):
        if object.__getattribute__(self, "_p") is None:
            return None
        for c in object.__getattribute__(self, "_components"):
            if isinstance(c, Handle) and type(c).__name__.startswith("Physx"):
                return c
        return None

    def __getattr__(self, name):
        # SAPIEN 2's actor calls (mass, linear_damping, set_linear_velocity, ...) are the body
        # component's in SAPIEN 3: an entity in a scene answers them too
        if not name.startswith("_"):
            comp = self._body_component()
            if comp is not None and hasattr(type(comp), name):
                return getattr(comp, name)
        return Handle.__getattr__(self, name)

    def __setattr__(self, name, value):
        if not name.startswith("_") and not hasattr(type(self), name):
            comp = self._body_component()
            if comp is not None and hasattr(type(comp), name):
                return setattr(comp, name, value)
        object.__setattr__(self, name, value)

    @classmethod
    def _adapt(cls, actor, scene):
        if scene is None:
            raise PartsimError("an actor outside an adapter scene: create scenes with "
                               "partsim.sapien.Scene()")
        return scene._actor_entity(actor)

    def _key(self):
        p = object.__getattribute__(self, "_p")
        if isinstance(p, _p.Actor):
            return ("actor", id(self._scene), p.get_id())
        if isinstance(p, _p.Link):
            return ("link", id(self._scene), p.get_articulation_id(), p.get_index())
        return ("entity", id(self))

    # name and pose
    def get_name(self):
        return self._p.get_name() if self._p is not None else self._name

    def set_name(self, name):
        if isinstance(self._p, _p.Link):
            raise PartsimError(f"set_name: link '{self._p.get_name()}' keeps its name")
        if self._p is not None:
            self._p.set_name(str(name))
        self._name = str(name)

    name = property(lambda self: self.get_name(), lambda self, n: self.set_name(n))

    def get_pose(self):
        if self._p is not None:
            return wrap(self._p.get_pose())
        return self._pose

    def set_pose(self, pose):
        pose = Pose._of(as_pose(pose))
        if isinstance(self._p, _p.Link):
            raise PartsimError(f"set_pose: link '{self._p.get_name()}' is placed by its "
                               "articulation: set the articulation's root_pose and qpos")
        if self._p is not None:
            self._p.set_pose(pose)
        self._pose = pose
        if self._in_scene and self._p is None:
            self._scene._entity_moved(self)
        for c in self._components:
            hook = getattr(type(c), "on_set_pose", None)
            if hook is not None:
                hook(c, pose)

    pose = property(lambda self: self.get_pose(), lambda self, p: self.set_pose(p))
    # SAPIEN 2 actors and SAPIEN 3 components name these entity_pose too
    get_entity_pose = get_pose
    set_entity_pose = set_pose
    entity_pose = pose

    # components
    def add_component(self, component):
        if not isinstance(component, Component):
            raise PartsimError(f"add_component: expected a sapien Component, got "
                               f"{type(component).__name__}")
        if component._entity is not None:
            raise PartsimError(f"add_component: the {type(component).__name__} belongs to "
                               "another entity already")
        if self._in_scene:
            self._scene._attach_later(self, component)
        component._entity = self
        self._components.append(component)
        return self

    def remove_component(self, component):
        if component not in self._components:
            raise PartsimError(f"remove_component: the {type(component).__name__} is not a "
                               "component of this entity")
        if self._in_scene:
            self._scene._detach(self, component)
        self._components.remove(component)
        component._entity = None

    def get_components(self):
        return list(self._components)

    components = property(get_components)

    def find_component_by_type(self, cls):
        for c in self._components:
            if isinstance(c, cls):
                return c
        return None

    # the scene
    def add_to_scene(self, scene):
        scene.add_entity(self)
        return self

    def remove_from_scene(self):
        if not self._in_scene:
            raise PartsimError("remove_from_scene: the entity is not in a scene")
        self._scene.remove_entity(self)

    def get_scene(self):
        return self._scene if self._in_scene else None

    scene = property(get_scene)

    def get_per_scene_id(self):
        """The id pictures' segmentation shows for this entity (its actor's or link's id); 0
        for an entity with no body."""
        return self._p.get_id() if self._p is not None else 0

    per_scene_id = property(get_per_scene_id)
    get_global_id = get_per_scene_id
    global_id = per_scene_id

    # SAPIEN 2's actor calls on the entity itself
    def get_entity(self):
        return self

    entity = property(get_entity)

    def __repr__(self):
        return f"<partsim.sapien.Entity '{self.get_name()}'>"


unsupported(Entity, {
    "hide_visual": "visuals cannot be hidden one by one: leave them out of the builder",
    "get_visual_bodies": "visual bodies are not exposed: read the actor's description "
                         "(partsim_object(entity).get_desc().visuals)",
    "get_collision_visual_bodies": "collision shapes are not drawn as visuals: read "
                                   "partsim_object(entity).get_desc().collisions",
})
