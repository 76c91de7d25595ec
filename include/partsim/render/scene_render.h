// A scene's rendering: its cameras, lights, render backend and the render world that backends
// draw (SAPIEN's scene.add_camera, add_directional_light, update_render, ...). They are free
// functions of the render layer over a physics Scene, as MuJoCo's mjv_ functions take the model
// and data they show: a program that links only physics sees none of them. The render state
// lives in a per-scene attachment (partsim/physics/observer.h) that the scene owns and copies
// into its clones (cameras and lights; not pictures, the backend or the render world).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/physics/scene.h"
#include "partsim/render/backend.h"
#include "partsim/render/camera.h"

namespace partsim {

// --- cameras ---

/// A camera fixed in the world: image size (pixels, 1 to 16384), vertical field of view (rad,
/// in (0, pi)), clipping distances (m, 0 < near < far). Place it with Camera::SetLocalPose.
/// Throws partsim::Error naming the camera and the argument at fault.
Camera AddCamera(Scene& scene, const std::string& name, int width, int height, double fovy,
                 double near, double far);
/// A camera that moves with an actor or a link of `scene`; `local_pose` is X_MC in the mount's
/// frame. Other arguments as AddCamera.
Camera AddMountedCamera(Scene& scene, const std::string& name, const Actor& mount,
                        const Pose& local_pose, int width, int height, double fovy, double near,
                        double far);
Camera AddMountedCamera(Scene& scene, const std::string& name, const Link& mount,
                        const Pose& local_pose, int width, int height, double fovy, double near,
                        double far);
/// Removes a camera; throws partsim::Error when it was removed already or belongs to another
/// scene.
void RemoveCamera(Scene& scene, const Camera& camera);
/// Every camera of the scene, fixed and mounted, in the order added.
std::vector<Camera> GetCameras(const Scene& scene);

// --- lights ---

/// Light travelling along `direction` (world frame, normalized here); `color` linear RGB >= 0.
void AddDirectionalLight(Scene& scene, const Eigen::Vector3d& direction,
                         const Eigen::Vector3f& color, bool shadow = false);
/// Point light at `position` (m, world frame).
void AddPointLight(Scene& scene, const Eigen::Vector3d& position, const Eigen::Vector3f& color);
/// Spot light at `position` (m, world) along `direction` (world); half angles in radians,
/// 0 <= inner_angle <= outer_angle <= pi/2.
void AddSpotLight(Scene& scene, const Eigen::Vector3d& position, const Eigen::Vector3d& direction,
                  double inner_angle, double outer_angle, const Eigen::Vector3f& color,
                  bool shadow = false);
/// Ambient light, linear RGB >= 0 (0.1 each until set).
void SetAmbientLight(Scene& scene, const Eigen::Vector3f& color);
/// The directional, point and spot lights, in the order added.
const std::vector<LightDesc>& GetLights(const Scene& scene);

// --- backend and render world ---

/// Chooses the backend by name: "rasterizer" (the default), "pathtracer" or "null"; throws
/// partsim::Error naming an unknown one.
void SetRenderBackend(Scene& scene, const std::string& name);
/// Uses the given backend (not null).
void SetRenderBackend(Scene& scene, std::unique_ptr<RenderBackend> backend);
/// The scene's backend, made on first use (the rasterizer unless another was set).
RenderBackend& GetRenderBackend(Scene& scene);
/// Copies the current poses of everything visible, and of mounted cameras, into the render
/// world; rebuilds its instances when actors or articulations changed.
void UpdateRender(Scene& scene);
/// What backends draw, as of the last UpdateRender.
const RenderWorld& GetRenderWorld(const Scene& scene);
/// What the entity ids of segmentation pictures (channel 1) name: actors and links.
std::vector<RenderEntityInfo> GetRenderEntities(const Scene& scene);
/// What the visual ids of segmentation pictures (channel 0) name.
std::vector<RenderVisualInfo> GetRenderVisuals(const Scene& scene);

}  // namespace partsim
