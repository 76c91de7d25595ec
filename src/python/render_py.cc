// Bindings of the render subsystem: the scene's cameras, lights and backend, the Camera handle,
// and the image and point cloud writers.
//
// Pictures: camera.get_picture(name) returns a read-only numpy view of the C++ picture, no copy.
// The view holds the picture itself (not the camera), so it stays valid and unchanged after the
// next take_picture(), which then renders into a new buffer; with no view alive, take_picture()
// reuses the old buffer.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "partsim/core/error.h"
#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera.h"
#include "partsim/render/image_io.h"
#include "partsim/render/scene_render.h"
#include "partsim/render/video.h"

namespace partsim::python {
namespace {

using PictureRef = std::shared_ptr<const Picture>;

// A capsule that owns a reference to a picture: the base object of numpy views into it.
py::capsule PictureOwner(PictureRef picture) {
  // the capsule's destructor frees the heap-held reference
  auto* held = new PictureRef(std::move(picture));
  return py::capsule(held, [](void* p) { delete static_cast<PictureRef*>(p); });
}

template <typename T>
py::array ReadOnlyView(const std::vector<ssize_t>& shape, const std::vector<ssize_t>& strides,
                       const T* data, const py::capsule& owner) {
  py::array a(py::dtype::of<T>(), shape, strides, data, owner);
  a.attr("flags").attr("writeable") = false;
  return a;
}

// h x w x c view of one output of the camera's last picture
py::array PictureView(const Camera& camera, const std::string& name) {
  PictureRef picture = camera.GetSharedPicture();
  ssize_t h = picture->height, w = picture->width;
  if (name == "Segmentation") {
    const std::vector<uint32_t>& v = camera.GetUintPicture(name);
    ssize_t s = sizeof(uint32_t);
    return ReadOnlyView<uint32_t>({h, w, 2}, {w * 2 * s, 2 * s, s}, v.data(),
                                  PictureOwner(picture));
  }
  const std::vector<float>& v = camera.GetFloatPicture(name);
  ssize_t s = sizeof(float);
  return ReadOnlyView<float>({h, w, 4}, {w * 4 * s, 4 * s, s}, v.data(), PictureOwner(picture));
}

// numpy array that owns a moved-in vector
template <typename T>
py::array Owned(std::vector<T>&& v, const std::vector<ssize_t>& shape) {
  auto* held = new std::vector<T>(std::move(v));
  py::capsule owner(held, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, held->data(), owner);
}

PointCloudFrame FrameFromName(const std::string& frame) {
  if (frame == "camera") return PointCloudFrame::kCamera;
  if (frame == "world") return PointCloudFrame::kWorld;
  throw Error("frame: expected 'camera' or 'world', got '" + frame + "'");
}

template <typename T>
using CArray = py::array_t<T, py::array::c_style | py::array::forcecast>;

// checks that an image array is (h, w) or (h, w, c) and returns h, w, c
std::array<int, 3> ImageShape(const py::array& a, const char* what, bool allow_channels) {
  if (a.ndim() == 2) return {static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)), 1};
  if (allow_channels && a.ndim() == 3)
    return {static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)),
            static_cast<int>(a.shape(2))};
  throw Error(std::string(what) + ": expected an array of shape (h, w)" +
              (allow_channels ? " or (h, w, c)" : "") + ", got " + std::to_string(a.ndim()) +
              " dimensions");
}

std::vector<size_t> Shape(const py::array& a) {
  return std::vector<size_t>(a.shape(), a.shape() + a.ndim());
}

void BindTypes(py::module_& m) {
  py::enum_<LightType>(m, "LightType",
                       "Light kinds: DIRECTIONAL (parallel rays along a direction), POINT (from "
                       "a position in all directions), SPOT (a cone from a position).")
      .value("DIRECTIONAL", LightType::kDirectional)
      .value("POINT", LightType::kPoint)
      .value("SPOT", LightType::kSpot);

  py::class_<LightDesc>(m, "LightDesc", "A light of the scene (read from scene.get_lights()).")
      .def_readonly("type", &LightDesc::type, "LightType: DIRECTIONAL, POINT or SPOT.")
      .def_readonly("color", &LightDesc::color, "Linear RGB radiance scale (3,), float32.")
      .def_readonly("position", &LightDesc::position, "(3,) world, m (point and spot).")
      .def_readonly("direction", &LightDesc::direction, "(3,) world, unit (directional, spot).")
      .def_readonly("inner_angle", &LightDesc::inner_angle, "Spot: half angle (rad).")
      .def_readonly("outer_angle", &LightDesc::outer_angle, "Spot: half angle (rad).")
      .def_readonly("shadow", &LightDesc::shadow,
                    "True when the light casts shadows (directional and spot lights in the "
                    "rasterizer).")
      .def_readonly("name", &LightDesc::name, "Light name ('' if none).");

  py::class_<RenderEntityInfo>(m, "RenderEntityInfo",
                               "A render id (segmentation channel 1) and the actor or link it "
                               "names.")
      .def_readonly("id", &RenderEntityInfo::id,
                    "The render id, equal to the actor's or link's scene-wide id (get_id()).")
      .def_readonly("is_link", &RenderEntityInfo::is_link,
                    "True for a link of an articulation, False for an actor.")
      .def_readonly("name", &RenderEntityInfo::name, "Actor or link name.")
      .def_readonly("actor_id", &RenderEntityInfo::actor_id, "The actor's id; -1 for a link.")
      .def_readonly("articulation_id", &RenderEntityInfo::articulation_id,
                    "The link's articulation id; -1 for an actor.")
      .def_readonly("link_index", &RenderEntityInfo::link_index,
                    "The link's index in its articulation; -1 for an actor.")
      .def_readonly("articulation_name", &RenderEntityInfo::articulation_name,
                    "Name of the link's articulation ('' for an actor).")
      .def_readonly("semantic_label", &RenderEntityInfo::semantic_label, "Part label, '' if none.")
      .def("__repr__", [](const RenderEntityInfo& self) {
        return "<RenderEntityInfo " + std::to_string(self.id) + " '" + self.name + "'>";
      });

  py::class_<RenderVisualInfo>(m, "RenderVisualInfo",
                               "A visual id (segmentation channel 0), its entity and its name.")
      .def_readonly("id", &RenderVisualInfo::id, "Scene-wide id of the visual shape (>= 1).")
      .def_readonly("entity_id", &RenderVisualInfo::entity_id,
                    "Id of the actor or link the visual belongs to (a RenderEntityInfo id).")
      .def_readonly("name", &RenderVisualInfo::name,
                    "The visual's name, e.g. a PartNet-Mobility part 'handle-15' ('' if none).")
      .def("__repr__", [](const RenderVisualInfo& self) {
        return "<RenderVisualInfo " + std::to_string(self.id) + " '" + self.name + "'>";
      });

  py::class_<RenderBackend>(m, "RenderBackend", "The scene's rendering backend.")
      .def("get_name", &RenderBackend::Name, "'rasterizer', 'pathtracer' or 'null'.")
      .def("get_device", &RenderBackend::Device, "Which device renders (e.g. GL_RENDERER).")
      .def(
          "get_counters",
          [](const RenderBackend& self) {
            const RenderCounters c = self.Counters();
            py::dict d;
            d["pictures"] = c.pictures;
            d["shadow_layers_drawn"] = c.shadow_layers_drawn;
            d["shadow_layers_reused"] = c.shadow_layers_reused;
            return d;
          },
          "What the backend did since it was made: {'pictures', 'shadow_layers_drawn', "
          "'shadow_layers_reused'} (shadow maps drawn, and kept unchanged from an earlier "
          "picture).")
      .def("begin_batch", &RenderBackend::BeginBatch,
           "Starts a batch of pictures from this thread (see __enter__).")
      .def("end_batch", &RenderBackend::EndBatch, "Ends the batch begun by begin_batch.")
      .def(
          "__enter__",
          [](RenderBackend& self) -> RenderBackend& {
            self.BeginBatch();
            return self;
          },
          py::return_value_policy::reference,
          "`with scene.get_render_backend():` takes the pictures of the block as one batch: "
          "the rasterizer keeps its GL context current on this thread between them, where "
          "each picture outside a batch takes and releases it. Pictures from another thread "
          "during the block raise PartsimError; blocks nest.")
      .def(
          "__exit__", [](RenderBackend& self, const py::args&) { self.EndBatch(); },
          "Ends the batch of the with block.");
}

void BindCamera(py::module_& m) {
  py::class_<Camera>(m, "Camera",
                     "Handle to a camera (x forward, y left, z up). Pictures are read-only numpy "
                     "views that stay valid after the next take_picture().")
      .def("get_id", &Camera::GetId, "The camera's id in its scene.")
      .def("get_name", &Camera::GetName, "The camera's name.")
      .def_property_readonly("name", &Camera::GetName, "The camera's name.")
      .def_property_readonly("width", &Camera::GetWidth, "Image width in pixels.")
      .def_property_readonly("height", &Camera::GetHeight, "Image height in pixels.")
      .def("get_width", &Camera::GetWidth, "Image width in pixels.")
      .def("get_height", &Camera::GetHeight, "Image height in pixels.")
      .def_property_readonly("near", &Camera::GetNear, "Near clipping distance (m).")
      .def_property_readonly("far", &Camera::GetFar, "Far clipping distance (m).")
      .def("set_near_far", &Camera::SetNearFar, py::arg("near"), py::arg("far"),
           "Clipping distances (m), 0 < near < far.")
      .def_property("fovy", &Camera::GetFovy, &Camera::SetFovy,
                    "Vertical field of view (rad); setting it makes fx = fy and centres the "
                    "principal point.")
      .def_property_readonly("fovx", &Camera::GetFovx, "Horizontal field of view (rad).")
      .def("get_fovy", &Camera::GetFovy, "Vertical field of view (rad).")
      .def("set_fovy", &Camera::SetFovy, py::arg("fovy"),
           "Sets the vertical field of view (rad); fx = fy and the principal point goes to the "
           "image centre.")
      .def("get_fovx", &Camera::GetFovx, "Horizontal field of view (rad).")
      .def("set_intrinsics", &Camera::SetIntrinsics, py::arg("fx"), py::arg("fy"), py::arg("cx"),
           py::arg("cy"), "Focal lengths and principal point in pixels (OpenCV).")
      .def("get_intrinsic_matrix", &Camera::GetIntrinsicMatrix, "3x3 OpenCV K (pixels).")
      .def("get_extrinsic_matrix", &Camera::GetExtrinsicMatrix,
           "3x4 [R | t]: world -> OpenCV camera frame (x right, y down, z forward).")
      .def("get_model_matrix", &Camera::GetModelMatrix,
           "4x4: OpenGL camera frame (x right, y up, z backward) -> world.")
      .def("get_projection_matrix", &Camera::GetProjectionMatrix,
           "4x4 OpenGL projection from K, near and far.")
      .def("get_pose", &Camera::GetPose,
           "X_WC in the world (for a mounted camera: as of the last update_render()).")
      .def("set_pose", &Camera::SetLocalPose, py::arg("pose"),
           "Same as set_local_pose: the world pose of a free camera, the pose in the mount's "
           "frame of a mounted one.")
      .def("get_local_pose", &Camera::GetLocalPose,
           "World pose of a free camera, or pose in the mount's frame of a mounted one (camera "
           "frame: x forward, y left, z up).")
      .def(
          "set_parent",
          [](Camera& self, const py::object& parent, bool keep_pose) {
            if (parent.is_none())
              self.ClearParent(keep_pose);
            else if (py::isinstance<Actor>(parent))
              self.SetParent(parent.cast<const Actor&>(), keep_pose);
            else if (py::isinstance<Link>(parent))
              self.SetParent(parent.cast<const Link&>(), keep_pose);
            else
              throw Error("camera '" + self.GetName() +
                          "': set_parent expects an Actor, a Link or None, got " +
                          py::str(py::type::of(parent)).cast<std::string>());
          },
          py::arg("parent"), py::arg("keep_pose"),
          "Mounts the camera on an actor or a link (None: the world). keep_pose=True keeps its "
          "world pose; False keeps its local pose, now in the new parent's frame.")
      .def("set_local_pose", &Camera::SetLocalPose, py::arg("pose"),
           "World pose of a free camera, or pose in the mount's frame of a mounted one.")
      .def("look_at", &Camera::LookAt, py::arg("eye"), py::arg("target"),
           py::arg("up") = Eigen::Vector3d::UnitZ().eval(),
           "Places the camera at `eye` (3,) looking at `target` (3,), in metres, with its z (up "
           "in the picture) as close to `up` (3,) as possible: world frame for a free camera, "
           "the mount's frame for a mounted one (set_local_pose(Pose.look_at(eye, target, "
           "up))). Raises PartsimError naming the camera when eye and target coincide, up is "
           "zero or a value is not finite.")
      .def(
          "take_picture",
          [](Camera& self, const std::optional<std::vector<std::string>>& outputs) {
            unsigned mask = kAllOutputs;
            if (outputs) {
              mask = 0;
              for (const std::string& name : *outputs) mask |= PictureOutputFromName(name);
            }
            WithoutGil(*self.GetScene(), [&] { self.TakePicture(mask); });
          },
          py::arg("outputs") = py::none(),
          "Renders the scene as of the last update_render() (the first picture of a scene "
          "updates it first). The GIL is released meanwhile. `outputs`: the pictures to render "
          "(e.g. ['Color', 'Position']), None for all; get_picture of another one raises. Color "
          "and Position alone take the rasterizer's faster forward pass.")
      .def("get_picture", &PictureView, py::arg("name"),
           "'Color', 'Albedo', 'Normal', 'Position': float32 (h, w, 4); 'Segmentation': uint32 "
           "(h, w, 2) (visual id, actor/link id). A read-only view, no copy.")
      .def(
          "get_color_rgba8",
          [](const Camera& self) {
            return Owned(self.GetColorRGBA8(), {self.GetHeight(), self.GetWidth(), 4});
          },
          "Colour as uint8 (h, w, 4), sRGB-encoded.")
      .def(
          "get_depth",
          [](const Camera& self) {
            // the w channel of Position, viewed with a stride
            self.GetFloatPicture("Position");  // throws when it was not taken
            PictureRef picture = self.GetSharedPicture();
            ssize_t h = picture->height, w = picture->width, s = sizeof(float);
            return ReadOnlyView<float>({h, w}, {w * 4 * s, 4 * s}, picture->position.data() + 3,
                                       PictureOwner(picture));
          },
          "Depth in metres, float32 (h, w), 0 where nothing was seen (a view, no copy).")
      .def("__repr__", [](const Camera& self) { return "<Camera '" + self.GetName() + "'>"; });
}

void BindSceneRender(py::module_& m) {
  const auto ka = py::keep_alive<0, 1>();
  auto scene = py::reinterpret_borrow<py::class_<Scene, std::shared_ptr<Scene>>>(m.attr("Scene"));
  scene
      .def("add_camera", &AddCamera, py::arg("name"), py::arg("width"), py::arg("height"),
           py::arg("fovy"), py::arg("near"), py::arg("far"), ka,
           "A camera fixed in the world: size in pixels (1 to 16384), vertical field of view "
           "(rad), clipping distances (m). Place it with set_pose.")
      .def("add_mounted_camera",
           py::overload_cast<Scene&, const std::string&, const Actor&, const Pose&, int, int,
                             double, double, double>(&AddMountedCamera),
           py::arg("name"), py::arg("mount"), py::arg("pose"), py::arg("width"), py::arg("height"),
           py::arg("fovy"), py::arg("near"), py::arg("far"), ka,
           "A camera moving with an actor; `pose` is its pose in the actor's frame.")
      .def("add_mounted_camera",
           py::overload_cast<Scene&, const std::string&, const Link&, const Pose&, int, int, double,
                             double, double>(&AddMountedCamera),
           py::arg("name"), py::arg("mount"), py::arg("pose"), py::arg("width"), py::arg("height"),
           py::arg("fovy"), py::arg("near"), py::arg("far"), ka,
           "A camera moving with a link; `pose` is its pose in the link's frame.")
      .def("remove_camera", &RemoveCamera, py::arg("camera"),
           "Removes a camera; raises PartsimError when it was removed already or belongs to "
           "another scene.")
      .def(
          "get_cameras",
          [](py::object self) { return HandleList(GetCameras(self.cast<const Scene&>()), self); },
          "Handles of every camera of the scene, fixed and mounted.")
      .def("add_directional_light", &AddDirectionalLight, py::arg("direction"), py::arg("color"),
           py::arg("shadow") = false,
           "Light travelling along `direction` (3,) (world); color (3,) linear RGB.")
      .def("add_point_light", &AddPointLight, py::arg("position"), py::arg("color"),
           "Point light at `position` (3,) (m, world).")
      .def("add_spot_light", &AddSpotLight, py::arg("position"), py::arg("direction"),
           py::arg("inner_angle"), py::arg("outer_angle"), py::arg("color"),
           py::arg("shadow") = false,
           "Spot light; half angles in radians, 0 <= inner <= outer <= pi/2.")
      .def("set_ambient_light", &SetAmbientLight, py::arg("color"),
           "Ambient light (3,), linear RGB.")
      .def("get_lights", &GetLights,
           "list of LightDesc: the scene's directional, point and spot lights.")
      .def("set_render_backend", py::overload_cast<Scene&, const std::string&>(&SetRenderBackend),
           py::arg("name"), "'rasterizer' (the default), 'pathtracer' or 'null'.")
      .def("get_render_backend", &GetRenderBackend, py::return_value_policy::reference, ka,
           "The backend (created on first use: the rasterizer unless another was set).")
      .def("update_render", &UpdateRender,
           "Copies the current poses of everything visible (and mounted cameras) into the "
           "render world.")
      .def(
          "take_pictures",
          [](Scene& self, const std::optional<std::vector<Camera>>& cameras,
             const std::optional<std::vector<std::string>>& outputs) {
            unsigned mask = kAllOutputs;
            if (outputs) {
              mask = 0;
              for (const std::string& name : *outputs) mask |= PictureOutputFromName(name);
            }
            const std::vector<Camera> set = cameras ? *cameras : GetCameras(self);
            WithoutGil(self, [&] { TakePictures(set, mask); });
          },
          py::arg("cameras") = py::none(), py::arg("outputs") = py::none(),
          "take_picture() of each camera (None: every camera of the scene), rendered together: "
          "the rasterizer uploads the scene once and reads one picture back while it draws the "
          "next. Each picture is the one take_picture() gives. `outputs` as for take_picture(). "
          "The GIL is released meanwhile.")
      .def("get_render_entities", &GetRenderEntities,
           "What the actor/link ids of segmentation (channel 1) name.")
      .def("get_render_visuals", &GetRenderVisuals,
           "What the visual ids of segmentation (channel 0) name.");
}

void BindImageIo(py::module_& m) {
  m.def(
      "get_point_cloud",
      [](const Camera& camera, const std::string& frame) {
        PointCloud c = MakePointCloud(camera, FrameFromName(frame));
        ssize_t n = static_cast<ssize_t>(c.Size());
        py::dict out;
        out["positions"] = Owned(std::move(c.positions), {n, 3});
        // colours and ids are empty when the picture did not take them
        ssize_t nc = static_cast<ssize_t>(c.colors.size() / 4);
        ssize_t ni = static_cast<ssize_t>(c.visual_ids.size());
        out["colors"] = Owned(std::move(c.colors), {nc, 4});
        out["visual_ids"] = Owned(std::move(c.visual_ids), {ni});
        out["entity_ids"] = Owned(std::move(c.entity_ids), {ni});
        return out;
      },
      py::arg("camera"), py::arg("frame") = "camera",
      "Points of the camera's last picture that see a surface, in the 'camera' (OpenGL: x "
      "right, y up, z backward) or 'world' frame: dict of positions float32 (N, 3) m, colors "
      "uint8 (N, 4) sRGB, visual_ids and entity_ids uint32 (N,); colors (0, 4) and ids (0,) "
      "when the picture did not take Color or Segmentation.");
  m.def(
      "write_png",
      [](const std::string& path, const py::array& image) {
        std::array<int, 3> s = ImageShape(image, "write_png", true);
        const char kind = image.dtype().kind();
        if (kind == 'u' && image.itemsize() == 1) {
          WritePng(path, s[1], s[0], s[2], CArray<uint8_t>::ensure(image).data());
        } else if (kind == 'f') {
          CArray<float> values = CArray<float>::ensure(image);
          std::vector<uint8_t> bytes;
          try {
            bytes = UnitFloatsToUint8(values.data(), values.size());
          } catch (const Error& e) {
            throw Error(std::string("write_png: image ") + e.what());
          }
          WritePng(path, s[1], s[0], s[2], bytes.data());
        } else if (kind == 'b') {
          CArray<bool> mask = CArray<bool>::ensure(image);
          std::vector<uint8_t> bytes(mask.data(), mask.data() + mask.size());
          for (uint8_t& b : bytes) b = b ? 255 : 0;
          WritePng(path, s[1], s[0], s[2], bytes.data());
        } else {
          throw py::type_error("write_png: image has dtype " +
                               py::str(image.dtype()).cast<std::string>() +
                               "; expected uint8 (0 to 255), a float type (0 to 1) or bool "
                               "(a mask); convert it first, e.g. image.astype(numpy.uint8)");
        }
      },
      py::arg("path"), py::arg("image"),
      "8-bit PNG from an image (h, w) grey or (h, w, c) with c = 2, 3 or 4: uint8 written as "
      "is; float16/32/64 in [0, 1], clipped to [0, 1], times 255 and rounded (NaN raises "
      "PartsimError, a ValueError); bool as 0 or 255. Other dtypes (uint16, int64, ...) raise "
      "TypeError: their range is the caller's to map to 0 to 255.");
  m.def(
      "write_depth_png",
      [](const std::string& path, const CArray<float>& depth) {
        std::array<int, 3> s = ImageShape(depth, "write_depth_png", false);
        WriteDepthPng(path, s[1], s[0], depth.data());
      },
      py::arg("path"), py::arg("depth"),
      "16-bit PNG in millimetres from depth (h, w) in metres (0 stays 0).");
  m.def(
      "write_segmentation_png",
      [](const std::string& path, const CArray<uint32_t>& ids) {
        std::array<int, 3> s = ImageShape(ids, "write_segmentation_png", false);
        WriteSegmentationPng(path, s[1], s[0], ids.data());
      },
      py::arg("path"), py::arg("ids"),
      "RGB PNG of ids (h, w) (e.g. picture[..., 1]), one fixed colour per id, 0 black.");
  m.def(
      "get_segmentation_color",
      [](uint32_t id) {
        std::array<uint8_t, 3> c = SegmentationColor(id);
        return std::vector<int>(c.begin(), c.end());
      },
      py::arg("id"), "The [r, g, b] colour of an id in write_segmentation_png.");
  m.def(
      "write_ply",
      [](const std::string& path, const CArray<float>& positions,
         const std::optional<CArray<uint8_t>>& colors,
         const std::optional<CArray<uint32_t>>& visual_ids,
         const std::optional<CArray<uint32_t>>& entity_ids, bool binary) {
        PointCloud c;
        c.positions.assign(positions.data(), positions.data() + positions.size());
        if (colors) c.colors.assign(colors->data(), colors->data() + colors->size());
        if (visual_ids)
          c.visual_ids.assign(visual_ids->data(), visual_ids->data() + visual_ids->size());
        if (entity_ids)
          c.entity_ids.assign(entity_ids->data(), entity_ids->data() + entity_ids->size());
        WritePly(path, c, binary);
      },
      py::arg("path"), py::arg("positions"), py::arg("colors") = py::none(),
      py::arg("visual_ids") = py::none(), py::arg("entity_ids") = py::none(),
      py::arg("binary") = true,
      "PLY point cloud: positions (N, 3), colors uint8 (N, 4) (white if None), ids uint32 (N,) "
      "(0 if None); binary little-endian or ASCII.");
  m.def(
      "write_npy",
      [](const std::string& path, const py::array& array) {
        if (array.dtype().equal(py::dtype::of<float>())) {
          auto a = CArray<float>::ensure(array);
          WriteNpy(path, a.data(), Shape(a));
        } else if (array.dtype().equal(py::dtype::of<uint32_t>())) {
          auto a = CArray<uint32_t>::ensure(array);
          WriteNpy(path, a.data(), Shape(a));
        } else {
          throw Error("write_npy: array must be float32 or uint32, got " +
                      std::string(py::str(array.dtype())));
        }
      },
      py::arg("path"), py::arg("array"), "NumPy .npy of a float32 or uint32 array.");
}

void BindVideo(py::module_& m) {
  py::class_<VideoWriter>(
      m, "VideoWriter",
      "An MP4 video (H.264, yuv420p) written frame by frame; it goes to PATH.partial and is "
      "renamed to PATH by close(), so PATH is whole or absent. Also a context manager that "
      "closes on exit. An odd width or height loses its last column or row.")
      .def(py::init([](const std::string& path, int width, int height, double fps, int quality,
                       const Eigen::Vector3f& background) {
             VideoOptions o;
             o.fps = fps;
             o.quality = quality;
             o.background = background;
             return std::make_unique<VideoWriter>(path, width, height, o);
           }),
           py::arg("path"), py::arg("width"), py::arg("height"), py::arg("fps") = 25.0,
           py::arg("quality") = 20, py::arg("background") = Eigen::Vector3f(0.80f, 0.84f, 0.90f),
           "Opens PATH for frames of width x height pixels at `fps` frames per second; "
           "`quality` is H.264's constant rate factor (0 lossless .. 51 worst, default 20); "
           "`background` (3,) linear RGB under transparent pixels. Raises PartsimError naming "
           "the path on bad arguments or when the file cannot be written.")
      .def(
          "add_frame",
          [](VideoWriter& self, const CArray<uint8_t>& frame) {
            if (frame.ndim() != 3 || (frame.shape(2) != 3 && frame.shape(2) != 4))
              throw Error("video '" + self.Path() +
                          "': add_frame expects a uint8 array of shape (h, w, 3) or (h, w, 4)");
            self.CheckFrameSize(static_cast<int>(frame.shape(1)), static_cast<int>(frame.shape(0)));
            const int channels = static_cast<int>(frame.shape(2));
            py::gil_scoped_release release;
            self.AddFrame(frame.data(), channels);
          },
          py::arg("frame"),
          "Appends a frame: uint8 (h, w, 3) RGB or (h, w, 4) RGBA, sRGB-encoded as "
          "Camera.get_color_rgba8() returns it, of the video's size.")
      .def(
          "add_picture",
          [](VideoWriter& self, const Camera& camera) { self.AddFrame(camera.GetPictureData()); },
          py::arg("camera"),
          "Appends the Color of the camera's last picture (its size must be the video's).")
      .def("close", &VideoWriter::Close, py::call_guard<py::gil_scoped_release>(),
           "Finishes the file and renames it into place; further frames raise, a second close "
           "does nothing.")
      .def_property_readonly("frame_count", &VideoWriter::FrameCount, "Frames added so far.")
      .def_property_readonly("codec", &VideoWriter::Codec,
                             "The encoder: 'libx264', or 'mpeg4' where H.264 is missing.")
      .def_property_readonly("path", &VideoWriter::Path, "The video's final path.")
      .def(
          "__enter__", [](VideoWriter& self) -> VideoWriter& { return self; },
          py::return_value_policy::reference, "Returns the writer itself.")
      .def(
          "__exit__", [](VideoWriter& self, py::args) { self.Close(); },
          "Closes the video (also when the block raised).");
}

}  // namespace

void BindRender(py::module_& m) {
  BindTypes(m);
  BindCamera(m);
  BindSceneRender(m);
  BindImageIo(m);
  BindVideo(m);
}

}  // namespace partsim::python
