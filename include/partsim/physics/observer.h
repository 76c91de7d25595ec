// What a scene shows to the subsystems that observe it without being physics (the renderer):
// its bodies with their visual shapes, ids and a version that changes with the description, and
// attachments, the per-scene state such a subsystem keeps (cameras, lights, a render backend),
// owned by the scene and copied into its clones. Physics knows nothing of what an attachment
// holds: it builds and runs without the renderer.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "partsim/physics/description.h"

namespace partsim {

class Scene;

/// A body that carries visual shapes: an actor, or a link of an articulation.
struct VisualBody {
  int actor_id = -1;         ///< the actor's id, or -1 for a link
  int articulation_id = -1;  ///< the link's articulation, or -1 for an actor
  int link_index = -1;       ///< the link's index in its articulation, or -1
  /// Entity id in segmentation pictures: an actor's id, or the link's (the articulation's id
  /// + 1 + link index).
  uint32_t entity_id = 0;
  /// Visual j of the body has the scene-wide visual id visual_id_base + j (0 is background).
  uint32_t visual_id_base = 0;
  std::string name;               ///< the actor's or the link's
  std::string articulation_name;  ///< the link's articulation, "" for an actor
  std::string semantic_label;
  std::vector<VisualShape> visuals;  ///< in the body's frame
};

/// Every actor (in the order added) and then every link of every articulation (articulations in
/// the order added, links in index order), with their visuals; bodies without visuals too.
std::vector<VisualBody> GetVisualBodies(const Scene& scene);

/// A number that changes whenever the scene's actors, articulations or their descriptions
/// change (add, remove, recompile); an observer rebuilds what it derived from GetVisualBodies
/// when it differs from the one it built with. Compiles what was added since the last compile.
uint64_t GetDescriptionVersion(const Scene& scene);

/// A fresh id from the scene's counter, which actors, articulations and their links share, for
/// other entities of the scene (cameras), so that no two entities have the same id.
int NewEntityId(Scene& scene);

/// Whether the actor (articulation) of this id is in the scene.
bool HasActor(const Scene& scene, int actor_id);
bool HasArticulation(const Scene& scene, int articulation_id);

/// Per-scene state of an observing subsystem.
class SceneAttachment {
 public:
  virtual ~SceneAttachment() = default;
  /// The state `clone`, a Scene::Clone() of the scene this is attached to, starts with.
  virtual std::unique_ptr<SceneAttachment> CloneFor(Scene& clone) const = 0;
};

/// The attachment stored under `key`, made by `make` on first use. The scene owns it until it
/// is destroyed; Scene::Clone attaches CloneFor(clone) of each under the same key.
SceneAttachment& GetAttachment(const Scene& scene, const std::string& key,
                               const std::function<std::unique_ptr<SceneAttachment>()>& make);
/// The attachment stored under `key`, or nullptr.
SceneAttachment* FindAttachment(const Scene& scene, const std::string& key);

}  // namespace partsim
