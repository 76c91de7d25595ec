// ProximityQuery: MuJoCo's collision detection (mj_kinematics + mj_collision) on a copy of the
// scene, with the queried links' shapes given the margin as MuJoCo's detection gap.
#include "partsim/physics/proximity.h"

#include <cmath>
#include <string>

#include "partsim/core/check.h"
#include "partsim/core/error.h"
#include "physics/scene_internal.h"

namespace partsim {

struct ProximityQuery::Impl {
  Articulation source;
  std::unique_ptr<Scene> world;
  Articulation arm;
  std::vector<int> geom_link;  ///< per MuJoCo geom of the copy: link of the articulation, or -1
  std::vector<double> gaps;    ///< per MuJoCo geom: the detection gap it has now
};

ProximityQuery::ProximityQuery(const Articulation& articulation) : impl_(std::make_unique<Impl>()) {
  if (!articulation.GetScene()) throw Error("ProximityQuery: the articulation handle is empty");
  articulation.GetName();  // throws for a removed articulation
  impl_->source = articulation;
  Refresh();
}

ProximityQuery::~ProximityQuery() = default;

void ProximityQuery::Refresh() {
  Impl& p = *impl_;
  p.world = p.source.GetScene()->Clone();
  p.arm = Articulation(p.world.get(), p.source.GetId());
  internal::SceneImpl& s = p.world->impl();
  s.EnsureCompiled();
  const int ngeom = s.m()->ngeom;
  p.geom_link.assign(ngeom, -1);
  for (int g = 0; g < ngeom; ++g)
    if (s.model.geom_owner[g].articulation_id == p.source.GetId())
      p.geom_link[g] = s.model.geom_owner[g].link_index;
  p.gaps.assign(s.m()->geom_gap, s.m()->geom_gap + ngeom);
}

Articulation& ProximityQuery::GetArticulation() { return impl_->arm; }
Scene& ProximityQuery::GetScene() { return *impl_->world; }

std::vector<ShapeProximity> ProximityQuery::Query(double margin, const std::vector<bool>& links) {
  Impl& p = *impl_;
  if (!(margin >= 0) || !std::isfinite(margin))
    throw Error("ProximityQuery: margin must be finite and >= 0, got " + FormatNumber(margin));
  const size_t nlinks = p.arm.GetDesc().links.size();
  if (!links.empty() && links.size() != nlinks)
    throw Error("ProximityQuery: links has " + std::to_string(links.size()) +
                " entries, the articulation has " + std::to_string(nlinks) + " links");
  auto queried = [&](int link) { return link >= 0 && (links.empty() || links[link]); };
  internal::SceneImpl& s = p.world->impl();
  s.EnsureCompiled();
  mjModel* m = s.m();
  mjData* d = s.d();
  // MuJoCo finds contacts closer than the sum of a pair's margins (the shapes' inflation) and
  // gaps (detection beyond it): the queried links' shapes get the margin as their gap, and the
  // pairs found are kept when they are closer than the margin
  for (int g = 0; g < m->ngeom; ++g) m->geom_gap[g] = queried(p.geom_link[g]) ? margin : p.gaps[g];
  mj_kinematics(m, d);
  mj_collision(m, d);
  s.Invalidate();
  std::vector<ShapeProximity> out;
  auto owner = [&](int g) {
    const internal::GeomOwner& o = s.model.geom_owner[g];
    return ShapeOwner{o.actor_id, o.articulation_id, o.link_index, o.shape_index};
  };
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    // 0: a contact with force, 1: within the gap (no force)
    if (c.exclude > 1 || c.dist >= margin) continue;
    const int l1 = p.geom_link[c.geom1], l2 = p.geom_link[c.geom2];
    if (!queried(l1) && !queried(l2)) continue;
    const bool swap = !queried(l1);
    out.push_back({owner(swap ? c.geom2 : c.geom1), owner(swap ? c.geom1 : c.geom2), c.dist});
  }
  return out;
}

}  // namespace partsim
