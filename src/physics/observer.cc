// The observer interface of a scene (partsim/physics/observer.h).
#include "partsim/physics/observer.h"

#include "partsim/core/error.h"
#include "physics/scene_internal.h"

namespace partsim {

std::vector<VisualBody> GetVisualBodies(const Scene& scene) {
  const internal::SceneImpl& s = scene.impl();
  std::vector<VisualBody> out;
  for (const auto& a : s.actors) {
    VisualBody b;
    b.actor_id = a.id;
    b.entity_id = a.render_id;
    b.visual_id_base = a.visual_id_base;
    b.name = a.desc.name;
    b.semantic_label = a.desc.semantic_label;
    b.visuals = a.desc.visuals;
    out.push_back(std::move(b));
  }
  for (const auto& a : s.articulations) {
    for (size_t i = 0; i < a.desc.links.size(); ++i) {
      const LinkDesc& l = a.desc.links[i];
      VisualBody b;
      b.articulation_id = a.id;
      b.link_index = static_cast<int>(i);
      b.entity_id = a.render_id_base + static_cast<uint32_t>(i);
      b.visual_id_base = a.visual_id_base[i];
      b.name = l.name;
      b.articulation_name = a.desc.name;
      b.semantic_label = l.semantic_label;
      b.visuals = l.visuals;
      out.push_back(std::move(b));
    }
  }
  return out;
}

uint64_t GetDescriptionVersion(const Scene& scene) {
  internal::SceneImpl& s = scene.impl();
  s.EnsureCompiled();  // actors added since the last compile join the description now
  return s.description_version;
}

int NewEntityId(Scene& scene) { return scene.impl().next_id++; }

bool HasActor(const Scene& scene, int actor_id) {
  for (const auto& a : scene.impl().actors)
    if (a.id == actor_id) return true;
  return false;
}

bool HasArticulation(const Scene& scene, int articulation_id) {
  for (const auto& a : scene.impl().articulations)
    if (a.id == articulation_id) return true;
  return false;
}

SceneAttachment& GetAttachment(const Scene& scene, const std::string& key,
                               const std::function<std::unique_ptr<SceneAttachment>()>& make) {
  auto& slot = scene.impl().attachments[key];
  if (!slot) {
    slot = make();
    if (!slot) throw Error("scene attachment '" + key + "': nothing was made");
  }
  return *slot;
}

SceneAttachment* FindAttachment(const Scene& scene, const std::string& key) {
  auto& all = scene.impl().attachments;
  auto it = all.find(key);
  return it == all.end() ? nullptr : it->second.get();
}

}  // namespace partsim
