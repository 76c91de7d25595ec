// The renderer's state of a scene: cameras, lights, the backend and the render world built from
// the scene's visual bodies. It is attached to the scene (partsim/physics/observer.h), which owns
// it and copies it into its clones; physics knows nothing of it. Not part of the public API.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/observer.h"
#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"

namespace partsim::internal {

/// A camera: free (mount_actor < 0 and mount_articulation < 0) or mounted.
struct CameraEntry {
  int id;
  std::string name;
  int width, height;
  double fx, fy, cx, cy, near, far;
  Pose local_pose;
  int mount_actor = -1;
  int mount_articulation = -1;
  int mount_link = -1;
  Pose X_WC;  ///< world pose at the last UpdateRender
  /// The last picture; shared with the numpy views Python holds, so that TakePicture renders
  /// into a new one while an older one is still viewed.
  std::shared_ptr<Picture> picture;
  Pose picture_X_WC;  ///< the camera pose the picture was taken from
};

/// Where a render_world instance comes from: an actor, or a link of an articulation, and the
/// visual's pose in that body.
struct RenderSource {
  int actor_id = -1;
  int articulation_id = -1;
  int link_index = -1;
  Pose X_BV;
};

struct RenderState : SceneAttachment {
  std::vector<CameraEntry> cameras;
  std::vector<LightDesc> lights;
  Eigen::Vector3f ambient = Eigen::Vector3f::Constant(0.1f);
  std::unique_ptr<RenderBackend> render_backend;
  RenderWorld render_world;
  std::vector<RenderSource> render_sources;  ///< one per render_world.instances entry
  bool render_world_built = false;           ///< UpdateRender has run at least once
  uint64_t render_world_description = 0;     ///< GetDescriptionVersion the instances follow
  /// Meshes of primitive visuals by their parameters, kept across rebuilds so that the same
  /// primitive keeps the same pointer (backends cache their buffers by pointer).
  std::map<std::string, std::shared_ptr<const MeshData>> primitive_meshes;

  /// The clone's cameras (without pictures), lights and ambient light; its backend is made
  /// afresh on first use, its render world at its first UpdateRender.
  std::unique_ptr<SceneAttachment> CloneFor(Scene& clone) const override;
};

/// The scene's render state, made on first use.
RenderState& RenderOf(const Scene& scene);

}  // namespace partsim::internal
