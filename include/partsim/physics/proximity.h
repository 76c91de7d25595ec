// Proximity of an articulation's collision shapes to everything else, at positions that are set
// without stepping: the collision check of sampling-based planners and of reachability tests.
// The query works on a private copy of the scene (Scene::Clone) taken when it is made or
// refreshed, so the scene itself, its contacts and its simulation are never disturbed.
#pragma once

#include <memory>
#include <vector>

#include "partsim/physics/scene.h"

namespace partsim {

/// A collision shape: of an actor (actor_id >= 0) or of a link of an articulation
/// (articulation_id >= 0, link_index >= 0); shape_index is its index in the body's collisions.
struct ShapeOwner {
  int actor_id = -1;
  int articulation_id = -1;
  int link_index = -1;
  int shape_index = -1;
};

/// Two shapes closer than the query's margin. At least shape0 belongs to the queried
/// articulation.
struct ShapeProximity {
  ShapeOwner shape0;
  ShapeOwner shape1;
  /// Signed distance, m: negative when they penetrate.
  double distance = 0.0;
};

/// Proximity queries of one articulation on a copy of its scene.
class ProximityQuery {
 public:
  /// Copies the articulation's scene as it is now. Throws partsim::Error for an empty or
  /// removed handle.
  explicit ProximityQuery(const Articulation& articulation);
  ~ProximityQuery();
  ProximityQuery(const ProximityQuery&) = delete;
  ProximityQuery& operator=(const ProximityQuery&) = delete;

  /// Copies the scene again (after bodies moved or were added).
  void Refresh();
  /// The copy of the articulation, to set joint positions (SetQpos) and the root pose on.
  Articulation& GetArticulation();
  /// The copy of the scene (its queried shapes keep the last query's margin).
  Scene& GetScene();

  /// Pairs of shapes at the copy's current positions closer than `margin` (m, >= 0), where
  /// one shape belongs to a link of the articulation whose entry in `links` is true (size: the
  /// articulation's links; empty means every link) and the other to anything that may collide
  /// with it (collision groups and disabled pairs respected), self-collisions included.
  /// Throws partsim::Error for a negative margin or a wrong size of `links`.
  std::vector<ShapeProximity> Query(double margin, const std::vector<bool>& links = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace partsim
