"""The machinery of partsim's SAPIEN adapter: handles that stand for partsim's objects.

partsim's own classes are never changed. The adapter's value types (Pose, materials, the scene
configuration) are Python subclasses of partsim's, so they pass to any partsim function. Its
handles (entities, components, articulations, joints, cameras, builders, loaders) hold the
partsim object they stand for in `_p` and answer SAPIEN's names; a name they do not define is
looked up on the partsim object, with partsim objects in the result turned into the adapter's
(`wrap`) and the adapter's in the arguments turned back into partsim's (`unwrap`). So a SAPIEN
script sees SAPIEN's types throughout, and partsim's own methods stay reachable from them.
`partsim_object(handle)` gives the partsim object for use with partsim's own API.
"""

from __future__ import annotations

import math

import numpy as np

from .. import _partsim as _p

PartsimError = _p.PartsimError


class UnsupportedError(_p.PartsimError, AttributeError):
    """A SAPIEN name partsim does not provide (docs/sapien_compatibility.md, status "no"): a
    PartsimError that says what to use instead, and an AttributeError, so that hasattr() is
    False as for any missing name."""


# ------------------------------------------------------------------------------ Pose


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


class Pose(_p.Pose):
    """SAPIEN's Pose: Pose(p=[0,0,0], q=[1,0,0,0]) with q as w, x, y, z, or Pose(matrix) from a
    4x4 homogeneous transformation (SAPIEN 3). A partsim.Pose, so it passes to partsim's own
    functions too."""

    def __init__(self, *args, **kwargs):
        if len(args) == 1 and not kwargs and np.asarray(args[0]).shape == (4, 4):
            m = _p.Pose.from_transformation_matrix(np.asarray(args[0], dtype=np.float64))
            super().__init__(m.p, m.q)
        else:
            super().__init__(*args, **kwargs)

    @classmethod
    def _of(cls, pose):
        return pose if type(pose) is cls else cls(pose.p, pose.q)

    def get_p(self):
        """Position (3,) in metres."""
        return self.p

    def get_q(self):
        """Quaternion (4,) as w, x, y, z."""
        return self.q

    def set_p(self, p):
        self.p = p

    def set_q(self, q):
        self.q = q

    def get_rpy(self):
        """Roll, pitch, yaw (rad): q = Rz(yaw) Ry(pitch) Rx(roll)."""
        return _quat_to_rpy(self.q)

    def set_rpy(self, rpy):
        self.q = _rpy_to_quat(*rpy)

    rpy = property(get_rpy, set_rpy, doc="Roll, pitch, yaw (rad), as SAPIEN 3's.")

    def __mul__(self, other):
        out = _p.Pose.__mul__(self, other)
        return Pose._of(out) if isinstance(out, _p.Pose) else out

    def inv(self):
        return Pose._of(_p.Pose.inv(self))

    @staticmethod
    def from_transformation_matrix(matrix):
        return Pose(np.asarray(matrix, dtype=np.float64))

    def __getstate__(self):
        return (tuple(self.p), tuple(self.q))

    def __setstate__(self, state):
        _p.Pose.__init__(self, state[0], state[1])

    def __reduce__(self):
        return (Pose, (tuple(self.p), tuple(self.q)))


# ------------------------------------------------------------------------------ wrap / unwrap

# partsim class -> function(obj, scene) giving the adapter's object
_ADAPTERS: dict = {}


def adapts(partsim_cls):
    """Class decorator: `wrap` turns partsim_cls objects into this adapter class."""

    def deco(cls):
        _ADAPTERS[partsim_cls] = cls._adapt
        return cls

    return deco


def wrap(obj, scene=None):
    """The adapter's object for a partsim object (lists and tuples element by element); other
    values as they are. `scene` is the adapter Scene the object belongs to, when known."""
    if isinstance(obj, Handle):
        return obj
    t = type(obj)
    if t is _p.Pose:
        return Pose(obj.p, obj.q)
    adapt = _ADAPTERS.get(t)
    if adapt is not None:
        return adapt(obj, scene)
    if t is list:
        return [wrap(x, scene) for x in obj]
    if t is tuple:
        return tuple(wrap(x, scene) for x in obj)
    return obj


def unwrap(obj):
    """The partsim object behind an adapter handle (lists, tuples and dict values element by
    element); other values as they are."""
    if isinstance(obj, Handle):
        return obj._partsim()
    t = type(obj)
    if t is list:
        return [unwrap(x) for x in obj]
    if t is tuple:
        return tuple(unwrap(x) for x in obj)
    if t is dict:
        return {k: unwrap(v) for k, v in obj.items()}
    return obj


def partsim_object(handle):
    """The partsim object a SAPIEN handle stands for (an Actor, Link, Joint, Articulation,
    Camera, Scene, builder or loader), for partsim's own functions. Anything else is returned
    as it is."""
    return unwrap(handle)


class Handle:
    """Base of the adapter's handles: `_p` is the partsim object, `_scene` the adapter Scene.
    Names the class does not define are partsim's, reached through the object (results wrapped,
    arguments unwrapped). Names in `_unsupported` raise UnsupportedError."""

    __slots__ = ("_p", "_scene", "__weakref__")
    _unsupported: dict = {}

    def __init__(self, p, scene=None):
        object.__setattr__(self, "_p", p)
        object.__setattr__(self, "_scene", scene)

    @classmethod
    def _adapt(cls, obj, scene):
        return cls(obj, scene)

    def _partsim(self):
        p = object.__getattribute__(self, "_p")
        if p is None:
            raise PartsimError(f"{type(self).__name__}: not in a scene yet (add its entity to "
                               "a scene first)")
        return p

    def _key(self):
        return (type(self), id(self._p))

    def __getattr__(self, name):
        why = type(self)._unsupported.get(name)
        if why is not None:
            raise UnsupportedError(f"{type(self).__name__}.{name}: not supported by partsim: "
                                   f"{why}")
        if name.startswith("__") or name in Handle.__slots__:
            raise AttributeError(name)
        target = object.__getattribute__(self, "_p")
        if target is None:
            raise AttributeError(f"{type(self).__name__} has no attribute '{name}' (partsim's "
                                 "own names are reachable once its entity is in a scene)")
        attr = getattr(target, name)
        if callable(attr) and not isinstance(attr, type):
            scene = self._scene

            def call(*args, **kwargs):
                return wrap(attr(*unwrap(args), **unwrap(kwargs)), scene)

            call.__name__ = name
            call.__doc__ = getattr(attr, "__doc__", None)
            return call
        return wrap(attr, self._scene)

    def __setattr__(self, name, value):
        p = object.__getattribute__(self, "_p")
        if name in Handle.__slots__ or hasattr(type(self), name) or p is None or \
                not hasattr(p, name):
            object.__setattr__(self, name, value)
        else:
            setattr(p, name, unwrap(value))

    def __eq__(self, other):
        return isinstance(other, Handle) and self._key() == other._key()

    def __hash__(self):
        return hash(self._key())

    def __dir__(self):
        names = set(dir(type(self)))
        p = object.__getattribute__(self, "_p")
        if p is not None:
            names.update(n for n in dir(p) if not n.startswith("_"))
        return sorted(names)

    def __repr__(self):
        p = object.__getattribute__(self, "_p")
        return f"<partsim.sapien.{type(self).__name__} of {p!r}>"


def unsupported(cls, names):
    """Marks SAPIEN names of cls as unsupported: reading one raises UnsupportedError naming
    what to use instead (`names`: name -> the reason and the alternative)."""
    cls._unsupported = {**cls._unsupported, **names}
    UNSUPPORTED[cls] = {**UNSUPPORTED.get(cls, {}), **names}


# SAPIEN names marked "no" in docs/sapien_compatibility.md, by adapter class
UNSUPPORTED: dict = {}


def color4(color, what):
    """RGBA from 3 or 4 numbers (alpha 1 when 3)."""
    c = np.asarray(color, dtype=np.float64).reshape(-1)
    if c.size == 3:
        c = np.append(c, 1.0)
    if c.size != 4 or not np.all(np.isfinite(c)):
        raise PartsimError(f"{what}: expected 3 or 4 finite numbers (RGB or RGBA), got "
                           f"{np.asarray(color).tolist()}")
    return c


def as_pose(pose):
    """A partsim.Pose from a Pose, None (identity) or a 4x4 matrix."""
    if pose is None:
        return Pose()
    if isinstance(pose, _p.Pose):
        return pose
    return Pose(pose)


_LOG_LEVELS = {"off": "off", "critical": "error", "err": "error", "error": "error",
               "warn": "warning", "warning": "warning", "info": "warning", "debug": "warning",
               "trace": "warning"}


def set_log_level(level: str) -> None:
    """SAPIEN's levels ('off', 'critical', 'error', 'warn', 'info', 'debug') or partsim's
    ('off', 'error', 'warning'). partsim writes nothing below warnings: 'info', 'debug' and
    'trace' show warnings and errors."""
    key = str(level).lower()
    if key not in _LOG_LEVELS:
        raise PartsimError(f"set_log_level: unknown level '{level}' (expected one of "
                           f"{', '.join(sorted(_LOG_LEVELS))})")
    _p.set_log_level(_LOG_LEVELS[key])


def accessors(cls, **fields):
    """Adds SAPIEN's get_NAME() and set_NAME(value) for plain attributes of cls: `fields` maps
    each name to the conversion its setter applies (float, int, list, ...; None: as given).
    Methods the class defines itself are kept."""
    for name, convert in fields.items():
        if "get_" + name not in cls.__dict__:
            setattr(cls, "get_" + name, lambda self, _n=name: getattr(self, _n))
        if "set_" + name not in cls.__dict__:
            setattr(cls, "set_" + name,
                    lambda self, value, _n=name, _c=convert: setattr(
                        self, _n, value if _c is None else _c(value)))
    return cls


# ------------------------------------------------------------------------------ shape geometry
# what a collision shape and a visual shape of one kind share: the sizes and SAPIEN's getters
# (the shape classes put these before their base, which takes the material)


class BoxGeometry:
    def __init__(self, half_size, material=None):
        super().__init__(material)
        self.half_size = np.asarray(half_size, dtype=np.float64).reshape(3)

    def get_half_size(self):
        return self.half_size


class SphereGeometry:
    def __init__(self, radius, material=None):
        super().__init__(material)
        self.radius = float(radius)

    def get_radius(self):
        return self.radius


class CapsuleGeometry(SphereGeometry):
    """Along the shape's x axis, as SAPIEN's (cylinders too)."""

    def __init__(self, radius, half_length, material=None):
        super().__init__(radius, material)
        self.half_length = float(half_length)

    def get_half_length(self):
        return self.half_length
