// The gallery of a PartNet-Mobility tree in the browser viewer (`partsim view --dataset ROOT`,
// docs/viewer.md "The gallery"): the objects' list (/api/gallery.json), thumbnails rendered by
// the rasterizer (/api/thumbnail/I.png), and the services /partsim/open (an object becomes the
// viewer's scene, its joints animated) and /partsim/gallery (back to the grid). It is added to a
// Viewer in synchronous mode; Run() is the loop of the thread that owns the scenes.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "partsim/core/pose.h"
#include "partsim/viewer/viewer.h"

namespace partsim {

class Scene;

struct GalleryOptions {
  std::string root;            ///< folder holding object folders (mobility.urdf), at any depth
  std::string category;        ///< only objects of this meta.json model_cat ("": all)
  double timestep = 0.002;     ///< physics step of an opened object (s)
  int thumbnail_width = 160;   ///< pixels
  int thumbnail_height = 120;  ///< pixels
  double cycle_seconds = 4.0;  ///< one sweep of every joint's range and back (s)
};

/// One object of the gallery.
struct GalleryObject {
  std::string folder;               ///< its path
  std::string name;                 ///< folder relative to the root
  std::string category;             ///< meta.json model_cat ("" when missing)
  int parts = 0;                    ///< movable parts (links on a hinge or a slider)
  std::vector<std::string> labels;  ///< their semantics.txt labels, distinct, in link order
};

/// A folder that could not be read.
struct GalleryError {
  std::string name;  ///< folder relative to the root
  std::string error;
};

/// Where a camera looks at an object at rest: from its front (-x of its root, as PartNet-Mobility
/// objects face) turned `azimuth` rad about z and `elevation` rad above, at the distance that
/// keeps the bounding sphere of the world box [lo, hi] within the vertical field of view `fovy`
/// (times `margin`). Returns X_WC for Camera::SetLocalPose / LookAt's eye and target.
Pose FrameObjectCameraPose(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                           const Eigen::Vector3d& front, double fovy, double azimuth = -0.5,
                           double elevation = 0.45, double margin = 1.05);

class Gallery {
 public:
  /// Scans `options.root` (each object folder's labels and joints, no collision shapes); folders
  /// that cannot be read are kept in Errors(). Throws partsim::Error naming the root when it is
  /// missing or not a folder, or holds no object (of `options.category`, when given).
  explicit Gallery(const GalleryOptions& options);
  ~Gallery();
  Gallery(const Gallery&) = delete;
  Gallery& operator=(const Gallery&) = delete;

  /// Adds /api/gallery.json, /api/thumbnail/I.png, /partsim/open and /partsim/gallery to
  /// `viewer` (synchronous mode, before its Start()) and gives it the gallery's empty scene.
  /// The viewer must outlive the gallery's use of it (Run).
  void AttachTo(Viewer* viewer);
  /// The loop of the thread that owns the scenes: steps the opened object in real time,
  /// animating its joints, and calls the viewer's Render() (which runs the page's commands,
  /// thumbnails included, also while paused), until the viewer closes or `keep_going` says no
  /// (asked every turn, at least 10 times a second).
  void Run(const std::function<bool()>& keep_going);

  const std::vector<GalleryObject>& Objects() const { return objects_; }
  const std::vector<GalleryError>& Errors() const { return errors_; }
  /// /api/gallery.json's text.
  std::string GalleryJson() const;
  /// The object open (-1: none).
  int OpenIndex() const { return open_; }

  // On the thread that owns the scenes (Run's, through the viewer's commands):
  /// Opens object `index` (its scene replaces the viewer's); throws partsim::Error naming the
  /// range for an unknown index.
  void Open(int index);
  /// Closes the object open: the viewer shows the empty scene.
  void CloseObject();
  /// The PNG of object `index`'s thumbnail (rendered once, then kept).
  std::string Thumbnail(int index);
  /// Sets the opened object's drive targets for simulated time `t` (s).
  void Animate(double t);

 private:
  GalleryOptions options_;
  std::vector<GalleryObject> objects_;
  std::vector<GalleryError> errors_;
  std::map<std::string, int> category_counts_;
  /// each object's bounds at rest in its root frame (from the scan), for framing cameras
  std::vector<Eigen::Vector3d> bounds_lo_, bounds_hi_;
  Viewer* viewer_ = nullptr;
  std::unique_ptr<Scene> empty_, opened_, thumbs_;
  std::atomic<int> open_{-1};
  struct Sweep {
    int articulation = -1, joint = -1;
    double lo = 0, hi = 0;
  };
  std::vector<Sweep> sweeps_;
  mutable std::mutex mutex_;
  std::map<int, std::string> thumbnails_;  ///< PNGs rendered (mutex_)
};

}  // namespace partsim
