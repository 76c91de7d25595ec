"""SAPIEN's `sapien.render` on partsim: materials, render bodies and shapes, cameras, lights and
the render system.

partsim renders each scene with its own backend (the EGL rasterizer, on a GPU when there is one,
else on the CPU; or the path tracer): SAPIEN's renderer settings are accepted, and
docs/sapien_compatibility.md says where a picture differs.
"""

from __future__ import annotations

import math

import numpy as np

from .. import _partsim as _p
from ._adapter import (BoxGeometry, CapsuleGeometry, PartsimError, Pose, SphereGeometry,
                       accessors, adapts, as_pose, color4, set_log_level, unsupported, unwrap,
                       wrap)
from ._entity import Component

WINDOW_MESSAGE = (
    "partsim has no on-screen window: its viewer runs in a web browser (scene.create_viewer() "
    "or partsim.sapien.utils.Viewer(scene) print the URL to open). For pictures: camera = "
    "scene.add_camera(name, width, height, fovy, near, far); scene.update_render(); "
    "camera.take_picture(); camera.get_picture('Color'), or run `partsim render`.")

# settings for scenes created later (set_camera_shader_dir)
defaults: dict = {}


# ------------------------------------------------------------------------------ materials


class RenderMaterial(_p.RenderMaterial):
    """A visual material: base_color (RGB or RGBA, linear), metallic, roughness; specular and
    SAPIEN's other PBR inputs (emission, transmission, ior) are kept and not used by partsim's
    shading. A partsim.RenderMaterial."""

    def __init__(self, base_color=None, metallic=None, roughness=None, specular=None,
                 emission=None, transmission=None, ior=None, transmission_roughness=None):
        super().__init__()
        self._kept = {"specular": 0.5, "emission": [0.0, 0.0, 0.0, 0.0], "transmission": 0.0,
                      "ior": 1.01, "transmission_roughness": 0.0}
        if base_color is not None:
            self.set_base_color(base_color)
        if metallic is not None:
            self.metallic = float(metallic)
        if roughness is not None:
            self.roughness = float(roughness)
        for k, v in (("specular", specular), ("emission", emission),
                     ("transmission", transmission), ("ior", ior),
                     ("transmission_roughness", transmission_roughness)):
            if v is not None:
                self._kept[k] = v

    def set_base_color(self, color):
        self.base_color = color4(color, "RenderMaterial.set_base_color").astype(np.float32)

    def get_base_color(self):
        return self.base_color

    def _kept_value(name):
        def get(self):
            return self._kept[name]

        def set(self, value):
            self._kept[name] = value

        return property(get, set, doc="Kept for SAPIEN scripts; not used by partsim's shading.")

    specular = _kept_value("specular")
    emission = _kept_value("emission")
    transmission = _kept_value("transmission")
    ior = _kept_value("ior")
    transmission_roughness = _kept_value("transmission_roughness")
    del _kept_value

    def set_diffuse_texture_from_file(self, path):
        self.diffuse_texture = str(path)

    def set_base_color_texture(self, texture):
        """A RenderTexture2D (from a file) as the base colour map."""
        self.diffuse_texture = texture.filename if isinstance(texture, RenderTexture2D) \
            else str(texture)

    set_diffuse_texture = set_base_color_texture

    def get_base_color_texture(self):
        return RenderTexture2D(self.diffuse_texture) if self.diffuse_texture else None

    get_diffuse_texture = get_base_color_texture
    base_color_texture = property(get_base_color_texture, set_base_color_texture)


accessors(RenderMaterial, metallic=float, roughness=float, specular=float, emission=list,
          transmission=float, ior=float, transmission_roughness=float)


class RenderTexture2D:
    """A texture read from an image file (partsim loads it when the scene renders)."""

    def __init__(self, filename, mipmap_levels=1, filter_mode="linear", address_mode="repeat",
                 srgb=True):
        self.filename = str(filename)

    def get_filename(self):
        return self.filename


class RenderTexture(RenderTexture2D):
    pass


def _material_of(paint, what):
    """A RenderMaterial from a RenderMaterial, a colour or None."""
    if paint is None or isinstance(paint, _p.RenderMaterial):
        return paint
    return RenderMaterial(base_color=color4(paint, what))


# ------------------------------------------------------------------------------ shapes


class RenderShape:
    """A visual shape to attach to a RenderBodyComponent before its entity is added."""

    def __init__(self, material=None):
        self.local_pose = Pose()
        self.material = _material_of(material, type(self).__name__)
        self.name = ""
        self.front_face = "counterclockwise"

    def get_local_pose(self):
        return self.local_pose

    def set_local_pose(self, pose):
        self.local_pose = Pose._of(as_pose(pose))

    def get_material(self):
        return self.material

    def set_material(self, material):
        self.material = _material_of(material, "set_material")

    def get_name(self):
        return self.name

    def set_name(self, name):
        self.name = str(name)

    def _add_to(self, builder):
        count = builder.get_visual_count()
        self._add_visual(builder)
        if self.material is not None:
            for i in range(count, builder.get_visual_count()):
                builder.set_visual_material(i, self.material)


class RenderShapePrimitive(RenderShape):
    pass


class RenderShapeBox(BoxGeometry, RenderShapePrimitive):
    def _add_visual(self, b):
        b.add_box_visual(self.local_pose, self.half_size, name=self.name)


class RenderShapeSphere(SphereGeometry, RenderShapePrimitive):
    def _add_visual(self, b):
        b.add_sphere_visual(self.local_pose, self.radius, name=self.name)


class RenderShapeCapsule(CapsuleGeometry, RenderShapePrimitive):
    """Along the shape's x axis, as SAPIEN's."""

    def _add_visual(self, b):
        b.add_capsule_visual(self.local_pose, self.radius, self.half_length, name=self.name)


class RenderShapeCylinder(RenderShapeCapsule):
    def _add_visual(self, b):
        b.add_cylinder_visual(self.local_pose, self.radius, self.half_length, name=self.name)


class RenderShapeTriangleMesh(RenderShape):
    """RenderShapeTriangleMesh(filename, scale=[1, 1, 1], material=None): every sub-mesh of the
    file; `material` replaces the file's materials."""

    def __init__(self, filename, scale=(1, 1, 1), material=None):
        super().__init__(material)
        self.filename = str(filename)
        self.scale = np.asarray(scale, dtype=np.float64).reshape(3)

    def get_filename(self):
        return self.filename

    def get_scale(self):
        return self.scale

    def set_scale(self, scale):
        self.scale = np.asarray(scale, dtype=np.float64).reshape(3)

    def _add_visual(self, b):
        b.add_visual_from_file(self.filename, self.local_pose, self.scale, name=self.name)


class RenderShapePlane(RenderShape):
    def __init__(self, *args, **kwargs):
        raise PartsimError("RenderShapePlane: partsim draws the ground with "
                           "scene.add_ground(altitude, render=True, render_material=...), or use "
                           "a thin RenderShapeBox")


# ------------------------------------------------------------------------------ components


class RenderBodyComponent(Component):
    """The visual shapes of an entity: attached before the entity is added to a scene."""

    def __init__(self):
        super().__init__()
        self._shapes = []

    def attach(self, shape):
        if self._p is not None:
            raise PartsimError("RenderBodyComponent.attach: partsim builds an entity's visuals "
                               "when it is added to the scene: attach every shape first")
        if not isinstance(shape, RenderShape):
            raise PartsimError(f"attach: expected a RenderShape, got {type(shape).__name__}")
        self._shapes.append(shape)
        return self

    def get_render_shapes(self):
        return list(self._shapes)

    render_shapes = property(get_render_shapes)

    def get_visibility(self):
        return 1.0

    def set_visibility(self, visibility):
        if visibility != 1:
            raise PartsimError("set_visibility: partsim draws every visual fully: leave the "
                               "shape out of the render body, or remove the entity")

    visibility = property(get_visibility, set_visibility)
    shading_mode = property(lambda self: 0, lambda self, mode: None,
                            doc="Kept, no effect (partsim shades every body the same way).")

    def disable_render_id(self):
        raise PartsimError("disable_render_id: every body in partsim has its segmentation id")

    def is_render_id_disabled(self):
        return False


unsupported(RenderBodyComponent, {
    "set_property": "custom shader properties are not supported: partsim's shaders are its own",
    "set_texture": "custom shader textures are not supported: give textures through "
                   "RenderMaterial.set_base_color_texture",
    "set_texture_array": "custom shader textures are not supported",
})


# SAPIEN 3's picture names and what partsim gives for each
PICTURE_NAMES = ("Color", "Albedo", "Normal", "Position", "Segmentation", "PositionSegmentation")


def sapien_position(camera, position):
    """Position with the 4th channel as the OpenGL depth-buffer value (1 where nothing)."""
    out = np.array(position, dtype=np.float32, copy=True)
    z = out[..., 3]  # partsim: depth in metres, 0 for nothing
    n, f = camera.near, camera.far
    seen = z > 0
    d = np.ones_like(z)
    d[seen] = (f * (z[seen] - n)) / (z[seen] * (f - n))
    out[..., 3] = d
    return out


@adapts(_p.Camera)
class RenderCameraComponent(Component):
    """A camera (SAPIEN 3's RenderCameraComponent, SAPIEN 2's CameraEntity):
    RenderCameraComponent(width, height) is mounted on the entity it is added to; the scene's
    add_camera makes one fixed in the world. Intrinsics as SAPIEN's: fovy pi/2, near 0.01, far 10
    by default."""

    def __init__(self, width, height, shader_dir=""):
        super().__init__()
        self._spec = {"width": int(width), "height": int(height), "fovy": math.pi / 2,
                      "near": 0.01, "far": 10.0, "local_pose": Pose(), "fx": None}

    @classmethod
    def _adapt(cls, camera, scene):
        if scene is None:
            c = cls(camera.width, camera.height)
            c._bind(camera, None, None)
            return c
        return scene._camera_component(camera)

    def _key(self):
        return ("camera", id(self._scene), self._p.get_id()) if self._p is not None else \
            (type(self), id(self))

    def _get(self, name):
        if self._p is None:
            return self._spec[name]
        return getattr(self._p, name)

    # size and intrinsics
    def get_width(self):
        return self._get("width")

    def get_height(self):
        return self._get("height")

    width = property(get_width)
    height = property(get_height)

    def get_near(self):
        return self._get("near")

    def get_far(self):
        return self._get("far")

    def set_near(self, near):
        self._set_near_far(float(near), self.get_far())

    def set_far(self, far):
        self._set_near_far(self.get_near(), float(far))

    def _set_near_far(self, near, far):
        if self._p is None:
            self._spec["near"], self._spec["far"] = near, far
        else:
            self._p.set_near_far(near, far)

    near = property(get_near, set_near)
    far = property(get_far, set_far)

    def get_fovy(self):
        return self._p.get_fovy() if self._p is not None else self._spec["fovy"]

    def get_fovx(self):
        if self._p is not None:
            return self._p.get_fovx()
        w, h = self._spec["width"], self._spec["height"]
        return 2 * math.atan(math.tan(self._spec["fovy"] / 2) * w / h)

    fovy = property(get_fovy)
    fovx = property(get_fovx)

    def set_fovy(self, fov, compute_x=True):
        if self._p is None:
            self._spec["fovy"] = float(fov)
            self._spec["fx"] = None
        else:
            self._p.set_fovy(float(fov))

    def set_fovx(self, fov, compute_y=True):
        w, h = self.get_width(), self.get_height()
        self.set_fovy(2 * math.atan(math.tan(float(fov) / 2) * h / w))

    def get_intrinsic_matrix(self):
        """3x3 intrinsics in pixels as SAPIEN's: pixel (i, j) covers [j, j + 1) x [i, i + 1),
        so the principal point of a centred camera is (width / 2, height / 2). (partsim's own
        Camera.get_intrinsic_matrix puts pixel centres at whole numbers: half a pixel less.)"""
        if self._p is not None:
            k = np.array(self._p.get_intrinsic_matrix(), dtype=np.float64)
            k[0, 2] += 0.5
            k[1, 2] += 0.5
            return k
        s = self._spec
        if s["fx"] is not None:
            fx, fy, cx, cy = s["fx"]
        else:
            fy = s["height"] / 2 / math.tan(s["fovy"] / 2)
            fx, cx, cy = fy, s["width"] / 2, s["height"] / 2
        return np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1]])

    fx = property(lambda self: self.get_intrinsic_matrix()[0, 0])
    fy = property(lambda self: self.get_intrinsic_matrix()[1, 1])
    cx = property(lambda self: self.get_intrinsic_matrix()[0, 2])
    cy = property(lambda self: self.get_intrinsic_matrix()[1, 2])

    def set_focal_lengths(self, fx, fy):
        k = self.get_intrinsic_matrix()
        self._set_intrinsics(float(fx), float(fy), k[0, 2], k[1, 2])

    def set_principal_point(self, cx, cy):
        k = self.get_intrinsic_matrix()
        self._set_intrinsics(k[0, 0], k[1, 1], float(cx), float(cy))

    def _set_intrinsics(self, fx, fy, cx, cy):
        if self._p is None:
            self._spec["fx"] = (fx, fy, cx, cy)
            self._spec["fovy"] = 2 * math.atan(self._spec["height"] / 2 / fy)
        else:
            self._p.set_intrinsics(fx, fy, cx - 0.5, cy - 0.5)

    def set_perspective_parameters(self, near, far, fx, fy, cx, cy, skew=0.0):
        """Clipping distances (m) and OpenCV intrinsics (pixels); skew must be 0."""
        if skew != 0:
            raise PartsimError(f"camera: skew {skew} is not supported (0 only)")
        self._set_near_far(float(near), float(far))
        self._set_intrinsics(fx, fy, cx, cy)

    def get_skew(self):
        return 0.0

    def set_skew(self, skew):
        if skew != 0:
            raise PartsimError(f"camera: skew {skew} is not supported (0 only)")

    skew = property(get_skew, set_skew)

    def get_mode(self):
        return "perspective"

    mode = property(get_mode)

    # poses
    def get_local_pose(self):
        return wrap(self._p.get_local_pose()) if self._p is not None else \
            self._spec["local_pose"]

    def set_local_pose(self, pose):
        pose = Pose._of(as_pose(pose))
        if self._p is None:
            self._spec["local_pose"] = pose
        elif self._entity is not None and self._entity._p is None:
            # on an entity of its own (no body): the entity's pose places it
            self._spec["local_pose"] = pose
            self._p.set_local_pose(self._entity.get_pose() * pose)
        else:
            self._p.set_local_pose(pose)

    local_pose = property(get_local_pose, set_local_pose)

    def get_global_pose(self):
        if self._p is not None:
            return wrap(self._p.get_pose())
        base = self._entity.get_pose() if self._entity is not None else Pose()
        return base * self._spec["local_pose"]

    global_pose = property(get_global_pose)

    def get_model_matrix(self):
        """4x4: the camera's OpenGL frame (x right, y up, z back) in the world."""
        if self._p is not None:
            return np.asarray(self._p.get_model_matrix())
        gl_to_cv = np.array([[0, 0, -1, 0], [-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1.0]])
        return self.get_global_pose().to_transformation_matrix() @ gl_to_cv

    def get_extrinsic_matrix(self):
        """3x4 OpenCV extrinsics: world to the camera's OpenCV frame (x right, y down, z
        forward)."""
        if self._p is not None:
            return np.asarray(self._p.get_extrinsic_matrix())
        model_cv = self.get_model_matrix() @ np.diag([1.0, -1.0, -1.0, 1.0])
        return np.linalg.inv(model_cv)[:3]

    def get_projection_matrix(self):
        return np.asarray(self._partsim().get_projection_matrix())

    # pictures
    def take_picture(self):
        self._partsim().take_picture()

    def get_picture_names(self):
        return list(PICTURE_NAMES)

    def get_picture(self, name):
        """'Color', 'Albedo', 'Normal': float32 (h, w, 4); 'Position': float32 (h, w, 4), x, y, z
        in the OpenGL camera frame (m) and the depth-buffer value in [0, 1] (1 where nothing was
        seen; keep pixels with [..., 3] < 1), as SAPIEN's; 'Segmentation': uint32 (h, w, 4):
        visual id, actor/link id, 0, 0 as SAPIEN's; 'PositionSegmentation': int16 (h, w, 4): x,
        y, z in millimetres in the OpenGL camera frame (0 where nothing was seen) and the
        actor/link id, as SAPIEN 3's. partsim's depth in metres is get_depth()."""
        cam = self._partsim()
        if name == "PositionSegmentation":
            pos = np.asarray(cam.get_picture("Position"))
            seg = np.asarray(cam.get_picture("Segmentation"))
            out = np.zeros(pos.shape[:2] + (4,), dtype=np.int16)
            seen = pos[..., 3] > 0
            mm = np.clip(np.rint(pos[..., :3] * 1000.0), -32768, 32767)
            out[..., :3] = np.where(seen[..., None], mm, 0).astype(np.int16)
            out[..., 3] = seg[..., 1].astype(np.int16)
            return out
        p = cam.get_picture(name)
        if name == "Position":
            return sapien_position(cam, p)
        if name == "Segmentation":
            out = np.zeros(p.shape[:2] + (4,), dtype=np.uint32)
            out[..., :2] = p
            return out
        return p

    get_float_texture = get_picture
    get_uint32_texture = get_picture

    def get_color_rgba(self):
        return self._partsim().get_picture("Color")

    def get_albedo_rgba(self):
        return self._partsim().get_picture("Albedo")

    def get_normal_rgba(self):
        return self._partsim().get_picture("Normal")

    def get_visual_actor_segmentation(self):
        return np.asarray(self._partsim().get_picture("Segmentation"))

    def get_visual_segmentation(self):
        return np.asarray(self._partsim().get_picture("Segmentation")[..., 0])

    def get_actor_segmentation(self):
        return np.asarray(self._partsim().get_picture("Segmentation")[..., 1])

    # SAPIEN 2's camera entity
    def get_pose(self):
        return self.get_global_pose()

    def set_pose(self, pose):
        if self._p is not None and self._entity is None:
            self._p.set_local_pose(as_pose(pose))
        elif self._entity is not None and self._entity._p is None:
            self._entity.set_pose(Pose._of(as_pose(pose)) * self._spec["local_pose"].inv())
        else:
            raise PartsimError("set_pose: this camera moves with its body: set_local_pose "
                               "places it on the body")

    pose = property(get_pose, set_pose)

    def get_name(self):
        return self._p.get_name() if self._p is not None else self._name

    def get_entity(self):
        return self._entity if self._entity is not None else _CameraEntity(self)

    entity = property(get_entity)

    def set_parent(self, parent, keep_pose):
        self._partsim().set_parent(unwrap(parent), bool(keep_pose))

    def _mount(self, scene, entity):
        """Adds the camera to the scene: on the entity's body, or placed by the entity."""
        s = self._spec
        mount = entity._p if entity is not None else None
        name = self._name or (entity.get_name() if entity is not None else "") or "camera"
        if mount is not None:
            cam = scene._p.add_mounted_camera(name, mount, s["local_pose"], s["width"],
                                              s["height"], s["fovy"], s["near"], s["far"])
        else:
            cam = scene._p.add_camera(name, s["width"], s["height"], s["fovy"], s["near"],
                                      s["far"])
            base = entity.get_pose() if entity is not None else Pose()
            cam.set_local_pose(base * s["local_pose"])
        if s["fx"] is not None:
            fx, fy, cx, cy = s["fx"]
            cam.set_intrinsics(fx, fy, cx - 0.5, cy - 0.5)
        self._bind(cam, scene, entity)
        scene._handles[("camera", cam.get_id())] = self


class _CameraEntity:
    """The entity of a camera the scene made (scene.add_camera): placing it places the
    camera."""

    def __init__(self, camera):
        self._camera = camera

    def set_pose(self, pose):
        self._camera._p.set_local_pose(as_pose(pose))

    def get_pose(self):
        return self._camera.get_global_pose()

    pose = property(get_pose, set_pose)
    name = property(lambda self: self._camera.get_name())


unsupported(RenderCameraComponent, {
    "get_dl_tensor": "no GPU tensor sharing: get_picture() gives numpy arrays",
    "get_picture_cuda": "no GPU tensor sharing: get_picture() gives numpy arrays",
    "set_gpu_pose_batch_index": "no GPU batches: render each scene's cameras in turn",
    "set_orthographic_parameters": "partsim's cameras are perspective: set_perspective_parameters",
    "set_property": "custom shader properties are not supported: partsim's shaders are its own",
    "set_texture": "custom shader textures are not supported: partsim's shaders are its own",
    "set_texture_array": "custom shader textures are not supported",
})


# ------------------------------------------------------------------------------ lights


class RenderLightComponent(Component):
    """A light placed by its entity's pose (and local_pose) when the entity is added to the
    scene; it shines along its frame's x axis, as SAPIEN's. partsim's lights stay where they
    were added: move a light by adding another entity."""

    def __init__(self):
        super().__init__()
        self.color = np.ones(3, dtype=np.float32)
        self.shadow = False
        self.local_pose = Pose()
        self.shadow_near = 0.1
        self.shadow_far = 10.0
        self.shadow_map_size = 2048

    def set_color(self, color):
        self.color = np.asarray(color, dtype=np.float32).reshape(-1)[:3]

    def enable_shadow(self):
        self.shadow = True

    def disable_shadow(self):
        self.shadow = False

    def set_local_pose(self, pose):
        self.local_pose = Pose._of(as_pose(pose))

    def get_local_pose(self):
        return self.local_pose

    def get_global_pose(self):
        base = self._entity.get_pose() if self._entity is not None else Pose()
        return base * self.local_pose

    global_pose = property(get_global_pose)

    def _axis(self):
        return self.get_global_pose().to_transformation_matrix()[:3, 0]

    def _place(self, scene):  # pragma: no cover - each light defines it
        raise NotImplementedError


accessors(RenderLightComponent, color=None, shadow=bool, shadow_near=float, shadow_far=float,
          shadow_map_size=int)


class RenderPointLightComponent(RenderLightComponent):
    """A point light (no shadows in partsim's rasterizer)."""

    def _place(self, scene):
        scene._p.add_point_light(self.get_global_pose().p, self.color)


class RenderDirectionalLightComponent(RenderLightComponent):
    """A light travelling along its frame's x axis; partsim fits its shadow map to the scene, so
    shadow_half_size is kept and not used."""

    def __init__(self):
        super().__init__()
        self.shadow_half_size = 10.0

    def _place(self, scene):
        scene._p.add_directional_light(self._axis(), self.color, bool(self.shadow))


class RenderSpotLightComponent(RenderLightComponent):
    """A spot light along its frame's x axis; inner_fov and outer_fov are full cone angles
    (rad)."""

    def __init__(self):
        super().__init__()
        self.inner_fov = 0.0
        self.outer_fov = math.pi / 2

    def _place(self, scene):
        scene._p.add_spot_light(self.get_global_pose().p, self._axis(), self.inner_fov / 2,
                                self.outer_fov / 2, self.color, bool(self.shadow))


accessors(RenderDirectionalLightComponent, shadow_half_size=float)
accessors(RenderSpotLightComponent, inner_fov=float, outer_fov=float)


class RenderTexturedLightComponent(RenderSpotLightComponent):
    def __init__(self, *args, **kwargs):
        raise PartsimError("RenderTexturedLightComponent: partsim's lights are not textured: use "
                           "a RenderSpotLightComponent")


class RenderParallelogramLightComponent(RenderLightComponent):
    def __init__(self, *args, **kwargs):
        raise PartsimError("RenderParallelogramLightComponent: partsim has no area lights: use "
                           "point or spot lights (the path tracer shades them with soft "
                           "falloff)")


# ------------------------------------------------------------------------------ system, renderer


class RenderSystem:
    """SAPIEN 3's render system of a scene: partsim's scene renders itself; this gives SAPIEN's
    names for its cameras, lights and ambient light."""

    def __init__(self, device=None):
        self._scene = None

    def _s(self):
        if self._scene is None:
            raise PartsimError("RenderSystem: not part of a scene yet: "
                               "sapien.Scene([PhysxCpuSystem(), RenderSystem()])")
        return self._scene

    def get_ambient_light(self):
        return self._s()._ambient

    def set_ambient_light(self, color):
        self._s().set_ambient_light(color)

    ambient_light = property(get_ambient_light, set_ambient_light)

    def get_cameras(self):
        return [wrap(c, self._s()) for c in self._s()._p.get_cameras()]

    cameras = property(get_cameras)

    def get_lights(self):
        return self._s()._p.get_lights()

    lights = property(get_lights)

    def get_render_bodies(self):
        return [c for e in self._s().get_entities() for c in e.get_components()
                if isinstance(c, RenderBodyComponent)]

    render_bodies = property(get_render_bodies)

    def step(self):
        self._s()._p.update_render()

    def get_cubemap(self):
        return None

    def set_cubemap(self, cubemap):
        raise PartsimError("set_cubemap: partsim lights scenes with its lights and an ambient "
                           "term; environment maps are not supported")


class SapienRenderer:
    """SAPIEN's renderer object. partsim renders each scene with its own backend (the EGL
    rasterizer, on a GPU when there is one, else on the CPU); this object only makes
    materials."""

    def __init__(self, offscreen_only=False, max_num_materials=128, max_num_textures=512,
                 default_mipmaps_levels=1, device="", culling="back", do_not_load_texture=False):
        self.offscreen_only = offscreen_only

    def create_material(self):
        return RenderMaterial()

    def create_window(self, *args, **kwargs):
        raise PartsimError(WINDOW_MESSAGE)

    @staticmethod
    def set_log_level(level):
        set_log_level(level)


def set_global_config(max_num_materials=128, max_num_textures=512, default_mipmap_levels=1,
                      **kwargs):
    """Accepted for SAPIEN scripts: partsim has no fixed-size material or texture pools."""


def set_camera_shader_dir(shader_dir):
    """'rt' (SAPIEN's ray-tracing shaders) makes scenes created afterwards render with partsim's
    path tracer; 'default' or 'minimal' with the rasterizer. Another folder is refused:
    partsim's shaders are its own (custom GLSL goes through the rasterizer's options)."""
    key = str(shader_dir).rstrip("/").rsplit("/", 1)[-1]
    if key == "rt":
        defaults["backend"] = "pathtracer"
    elif key in ("default", "minimal", "ibl"):
        defaults["backend"] = "rasterizer"
    else:
        raise PartsimError(f"set_camera_shader_dir('{shader_dir}'): partsim knows 'rt' "
                           "(path tracer), 'default' and 'minimal' (rasterizer)")


def set_viewer_shader_dir(shader_dir):
    """Accepted, no effect: the browser viewer has its own shaders."""


def set_ray_tracing_samples_per_pixel(spp):
    """Accepted: the path tracer's samples are set per picture (scene.set_render_backend and the
    path tracer's options)."""


def set_ray_tracing_denoiser(name):
    """Accepted: partsim's path tracer has its own denoising settings."""


def get_device_summary():
    return "partsim renders with EGL (a GPU when there is one, else Mesa's CPU rasterizer)"


__all__ = [n for n in dir() if n.startswith("Render") or n in (
    "SapienRenderer", "set_global_config", "set_camera_shader_dir", "set_viewer_shader_dir",
    "set_log_level", "set_ray_tracing_samples_per_pixel", "set_ray_tracing_denoiser",
    "get_device_summary", "PICTURE_NAMES")]

