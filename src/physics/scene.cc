// Scene: compile on change (carrying state over by name), stepping, contacts, pack/unpack.
#include "partsim/physics/scene.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>

#include "partsim/core/check.h"
#include "physics/dynamics.h"
#include "physics/scene_internal.h"

namespace partsim {

namespace internal {

SceneImpl::ActorEntry& SceneImpl::GetActor(int id) {
  for (auto& a : actors)
    if (a.id == id) return a;
  throw Error("actor " + std::to_string(id) +
              " does not exist (it was removed, or the handle is "
              "empty)");
}

SceneImpl::ArticulationEntry& SceneImpl::GetArticulation(int id) {
  for (auto& a : articulations)
    if (a.id == id) return a;
  throw Error("articulation " + std::to_string(id) +
              " does not exist (it was removed, or the handle is empty)");
}

const CompiledActor& SceneImpl::Compiled(const ActorEntry& a) {
  EnsureCompiled();
  return model.actors.at(a.id);
}

const CompiledArticulation& SceneImpl::Compiled(const ArticulationEntry& a) {
  EnsureCompiled();
  return model.articulations.at(a.id);
}

ArticulationData& SceneImpl::State(const ArticulationEntry& a) {
  EnsureCompiled();
  return data.articulations.at(a.id);
}

namespace {

// MuJoCo reports warnings through a global hook; while a scene steps they go to its warning
// list instead of MUJOCO_LOG.TXT in the working directory.
thread_local SceneImpl* stepping_scene = nullptr;

void OnMujocoWarning(const char* msg) {
  if (stepping_scene)
    stepping_scene->warnings.push_back(
        {stepping_scene->d() ? stepping_scene->d()->time : 0.0, msg});
  else
    std::fprintf(stderr, "partsim: MuJoCo warning: %s\n", msg);
}

// MuJoCo's default error handler prints "Press Enter to exit" and ends the process; partsim's
// throws, so that the caller gets partsim::Error and the process goes on (the step that hit it
// is abandoned and MuJoCo's stack released, see SceneImpl::Step).
void OnMujocoError(const char* msg) { throw Error(std::string("MuJoCo: ") + msg); }

struct InstallWarningHook {
  InstallWarningHook() {
    mju_user_warning = OnMujocoWarning;
    mju_user_error = OnMujocoError;
  }
} install_warning_hook;

// Empties MuJoCo's scratch stack, which an error thrown out of a step leaves marked.
void ReleaseStack(mjData* d) {
  d->pstack = 0;
  d->pbase = 0;
}

// Marks a scene as stepping on this thread (its warnings go to it) until destroyed; on the way
// out of a failed step it releases what MuJoCo held on its stack.
struct SteppingScope {
  SceneImpl* scene;
  SceneImpl* outer;  ///< a scope around this one (a compile within a step), put back after
  explicit SteppingScope(SceneImpl* s) : scene(s), outer(stepping_scene) { stepping_scene = s; }
  ~SteppingScope() {
    stepping_scene = outer;
    if (scene->d()) ReleaseStack(scene->d());
  }
};

// State of named MuJoCo elements, used to carry a state across a recompile.
struct NamedState {
  double time = 0;
  std::map<std::string, std::vector<double>> joint_qpos, joint_qvel, joint_warm, joint_qfrc;
  std::map<std::string, std::vector<double>> mocap;     // pos + quat
  std::map<std::string, std::vector<double>> actuator;  // ctrl, then its activations
};

NamedState SaveNamed(const mjModel* m, const mjData* d) {
  NamedState s;
  s.time = d->time;
  for (int j = 0; j < m->njnt; ++j) {
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    if (!name) continue;
    int nq = m->jnt_type[j] == mjJNT_FREE ? 7 : m->jnt_type[j] == mjJNT_BALL ? 4 : 1;
    int nv = m->jnt_type[j] == mjJNT_FREE ? 6 : m->jnt_type[j] == mjJNT_BALL ? 3 : 1;
    const double* q = d->qpos + m->jnt_qposadr[j];
    int v = m->jnt_dofadr[j];
    s.joint_qpos[name].assign(q, q + nq);
    s.joint_qvel[name].assign(d->qvel + v, d->qvel + v + nv);
    s.joint_warm[name].assign(d->qacc_warmstart + v, d->qacc_warmstart + v + nv);
    s.joint_qfrc[name].assign(d->qfrc_applied + v, d->qfrc_applied + v + nv);
  }
  for (int b = 0; b < m->nbody; ++b) {
    int id = m->body_mocapid[b];
    if (id < 0) continue;
    std::vector<double> v(d->mocap_pos + 3 * id, d->mocap_pos + 3 * id + 3);
    v.insert(v.end(), d->mocap_quat + 4 * id, d->mocap_quat + 4 * id + 4);
    s.mocap[mj_id2name(m, mjOBJ_BODY, b)] = v;
  }
  for (int a = 0; a < m->nu; ++a) {
    const char* name = mj_id2name(m, mjOBJ_ACTUATOR, a);
    if (!name) continue;
    std::vector<double> v = {d->ctrl[a]};
    if (m->actuator_actadr[a] >= 0)
      v.insert(v.end(), d->act + m->actuator_actadr[a],
               d->act + m->actuator_actadr[a] + m->actuator_actnum[a]);
    s.actuator[name] = v;
  }
  return s;
}

void RestoreNamed(const NamedState& s, const mjModel* m, mjData* d) {
  d->time = s.time;
  auto copy = [](const std::map<std::string, std::vector<double>>& from, const std::string& name,
                 double* to, size_t n) {
    auto it = from.find(name);
    if (it != from.end() && it->second.size() == n)
      std::copy(it->second.begin(), it->second.end(), to);
  };
  for (int j = 0; j < m->njnt; ++j) {
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    if (!name) continue;
    int nq = m->jnt_type[j] == mjJNT_FREE ? 7 : m->jnt_type[j] == mjJNT_BALL ? 4 : 1;
    int nv = m->jnt_type[j] == mjJNT_FREE ? 6 : m->jnt_type[j] == mjJNT_BALL ? 3 : 1;
    int v = m->jnt_dofadr[j];
    copy(s.joint_qpos, name, d->qpos + m->jnt_qposadr[j], nq);
    copy(s.joint_qvel, name, d->qvel + v, nv);
    copy(s.joint_warm, name, d->qacc_warmstart + v, nv);
    copy(s.joint_qfrc, name, d->qfrc_applied + v, nv);
  }
  for (int b = 0; b < m->nbody; ++b) {
    int id = m->body_mocapid[b];
    if (id < 0) continue;
    auto it = s.mocap.find(mj_id2name(m, mjOBJ_BODY, b));
    if (it == s.mocap.end()) continue;
    std::copy(it->second.begin(), it->second.begin() + 3, d->mocap_pos + 3 * id);
    std::copy(it->second.begin() + 3, it->second.end(), d->mocap_quat + 4 * id);
  }
  for (int a = 0; a < m->nu; ++a) {
    const char* name = mj_id2name(m, mjOBJ_ACTUATOR, a);
    if (!name) continue;
    auto it = s.actuator.find(name);
    const int nact = m->actuator_actadr[a] >= 0 ? static_cast<int>(m->actuator_actnum[a]) : 0;
    if (it == s.actuator.end() || it->second.size() != static_cast<size_t>(1 + nact)) continue;
    d->ctrl[a] = it->second[0];
    if (nact > 0)
      std::copy(it->second.begin() + 1, it->second.end(), d->act + m->actuator_actadr[a]);
  }
}

// MuJoCo's words for a scratch stack or arena too small for the model.
bool IsOutOfArena(const std::string& error) {
  return error.find("stack overflow") != std::string::npos ||
         error.find("Stack overflow") != std::string::npos ||
         error.find("arena") != std::string::npos;
}

// Compiles a model specification, or returns null with *error set (MuJoCo's message).
mjModel* Compile(mjSpec* spec, std::string* error) {
  mjModel* m = nullptr;
  try {
    m = mj_compile(spec, nullptr);
  } catch (const Error& e) {  // OnMujocoError
    *error = e.what();
  }
  if (!m && error->empty()) *error = mjs_getError(spec);
  return m;
}

}  // namespace

void SceneImpl::EnsureCompiled() {
  if (!dirty) return;
  // compiling, computing on the data (EnsureForward, EnsureKinematics) and changing it
  // (Invalidate, after every setter) are refused while another thread holds the scene; reading
  // the description and the compiled tables (names, counts, dof indices) is not
  CheckUser();
  std::string error;
  std::map<std::string, std::string> mesh_users;
  MjSpecPtr spec;
  mjModel* new_m = nullptr;
  {
    // MuJoCo's warnings while compiling join the scene's, but for the scene's options winning
    // over an MJCF model's (by design: the scene's settings hold for all it holds)
    const size_t warnings_before = warnings.size();
    SteppingScope scope(this);
    spec = BuildSpec(*this, &error, &mesh_users);
    new_m = spec ? Compile(spec.get(), &error) : nullptr;
    // the compiler's own use of MuJoCo's arena outgrew partsim's estimate: twice as much, again
    for (int tries = 0; spec && !new_m && tries < 6 && IsOutOfArena(error); ++tries) {
      arena_capacity = 2 * std::max<long long>(arena_capacity, 1 << 20);
      error.clear();
      spec = BuildSpec(*this, &error, &mesh_users);
      new_m = spec ? Compile(spec.get(), &error) : nullptr;
    }
    warnings.erase(
        std::remove_if(warnings.begin() + static_cast<long>(warnings_before), warnings.end(),
                       [](const Warning& w) {
                         return w.message.find("Attach conflict") != std::string::npos;
                       }),
        warnings.end());
  }
  if (!new_m) {
    std::string why = DescribeMjNames(*this, error, mesh_users);
    if (!uncompiled_actors.empty()) {
      // some actor added since the last compile breaks it: they are taken back out and put in
      // again one by one, and those that MuJoCo refuses stay out; the error names them
      std::vector<ActorEntry> pending;
      for (const ActorEntry& a : actors)
        if (IsUncompiled(a.id)) pending.push_back(a);
      actors.erase(std::remove_if(actors.begin(), actors.end(),
                                  [&](const ActorEntry& a) { return IsUncompiled(a.id); }),
                   actors.end());
      uncompiled_actors.clear();
      EnsureCompiled();  // as it compiled last
      std::string refused;
      int count = 0;
      for (const ActorEntry& a : pending) {
        actors.push_back(a);
        dirty = true;
        try {
          EnsureCompiled();
        } catch (const Error& e) {
          actors.pop_back();
          dirty = true;
          EnsureCompiled();
          if (++count <= 3) refused += std::string(count > 1 ? "; " : "") + e.what();
        }
      }
      if (count == 0) throw Error("MuJoCo could not compile the scene: " + why);
      throw Error(std::to_string(count) + " of the " + std::to_string(pending.size()) +
                  " actors added since the scene last compiled were refused and removed (the "
                  "others are in): " +
                  refused + (count > 3 ? "; ..." : ""));
    }
    throw Error("MuJoCo could not compile the scene: " + why);
  }
  Model new_model;
  new_model.mj.reset(new_m);
  MjDataPtr new_d(mj_makeData(new_m));
  if (!new_d)
    throw Error("MuJoCo could not allocate the data of the scene (an arena of " +
                std::to_string(new_m->narena) + " bytes): out of memory");
  // carry the state of everything that existed before: MuJoCo's by element name, partsim's by
  // articulation id (a new articulation's drives start at its description's targets)
  if (model.mj && data.mj)
    RestoreNamed(SaveNamed(model.mj.get(), data.mj.get()), new_m, new_d.get());
  else
    new_d->time = 0;
  new_model.spec = std::move(spec);
  BuildTables(*this, new_model);
  std::map<int, ArticulationData> states;
  for (const ArticulationEntry& a : articulations) {
    auto old = data.articulations.find(a.id);
    const CompiledArticulation& c = new_model.articulations.at(a.id);
    ArticulationData& state = states[a.id];
    if (old != data.articulations.end() && old->second.drive_target.size() == c.Dof()) {
      state = old->second;
      continue;
    }
    state.drive_target.resize(c.Dof());
    state.drive_velocity_target.resize(c.Dof());
    for (int k = 0; k < c.Dof(); ++k) {
      const DriveDesc& drive = a.desc.links[c.dof_links[k]].joint.drive;
      state.drive_target[k] = drive.target;
      state.drive_velocity_target[k] = drive.velocity_target;
    }
  }
  model = std::move(new_model);
  data.mj = std::move(new_d);
  data.articulations = std::move(states);
  data.xfrc_dirty = false;
  dirty = false;
  uncompiled_actors.clear();
  ++description_version;
  for (auto& a : articulations) {
    if (!a.desc.kinematic) continue;
    model.articulations.at(a.id).kinematics.emplace(a.desc);
    UpdateKinematicArticulation(a);
  }
  Invalidate();
}

void SceneImpl::EnsureForward() {
  CheckUser();
  EnsureCompiled();
  Forward(model, data);
}

void SceneImpl::EnsureKinematics() {
  CheckUser();
  EnsureCompiled();
  Kinematics(model, data);
}

void SceneImpl::UpdateKinematicArticulation(ArticulationEntry& a) {
  const CompiledArticulation& c = model.articulations.at(a.id);
  ArticulationData& state = data.articulations.at(a.id);
  // the model of the last compile, at the root pose of now
  KinematicModel kinematics = *c.kinematics;
  Pose X_WR = a.desc.root_pose;
  X_WR.q.normalize();
  kinematics.SetRootPose(X_WR);
  const int dof = kinematics.Dof();
  if (state.kin_qpos.size() != dof) state.kin_qpos = Eigen::VectorXd::Zero(dof);
  if (state.kin_qvel.size() != dof) state.kin_qvel = Eigen::VectorXd::Zero(dof);
  // the mocap bodies of the links, couplings included
  mjData* d = data.mj.get();
  const std::vector<Pose> X_WL = kinematics.ForwardKinematics(state.kin_qpos);
  for (size_t i = 0; i < X_WL.size(); ++i) {
    int mocap = c.link_mocap[i];
    Eigen::Quaterniond qn = X_WL[i].q.normalized();
    for (int k = 0; k < 3; ++k) d->mocap_pos[3 * mocap + k] = X_WL[i].p[k];
    d->mocap_quat[4 * mocap] = qn.w();
    d->mocap_quat[4 * mocap + 1] = qn.x();
    d->mocap_quat[4 * mocap + 2] = qn.y();
    d->mocap_quat[4 * mocap + 3] = qn.z();
  }
  Invalidate();
}

void SceneImpl::GrowArena(const std::string& why) {
  const long long old_arena = arena_capacity;
  const long long now = m()->narena;
  arena_capacity = 2 * now;
  dirty = true;
  try {
    EnsureCompiled();  // the state is carried over
  } catch (const Error& e) {
    // past what the machine can allocate: the scene stays as it was
    arena_capacity = old_arena;
    dirty = true;
    EnsureCompiled();
    throw Error("step: " + why + ", and MuJoCo cannot allocate an arena of " +
                std::to_string(2 * now) + " bytes for this scene (" + std::to_string(m()->nv) +
                " dofs): " + e.what() + ". Fewer bodies in contact at once, or fewer dofs, fit");
  }
  warnings.push_back(
      {d()->time, why + ": its arena grown to " + std::to_string(m()->narena) + " bytes"});
}

void SceneImpl::Step(int n) {
  if (n < 0) throw Error("step: n must be >= 0, got " + std::to_string(n));
  EnsureCompiled();
  SteppingScope scope(this);
  for (int i = 0; i < n; ++i) {
    // the model and data move when a step grows MuJoCo's arena (GrowArena recompiles)
    const mjModel* m = model.mj.get();
    mjData* d = data.mj.get();
    ApplyDrives(model, data);
    int bad_before = d->warning[mjWARN_BADQACC].number + d->warning[mjWARN_BADQPOS].number +
                     d->warning[mjWARN_BADQVEL].number;
    const int full_before =
        d->warning[mjWARN_CONTACTFULL].number + d->warning[mjWARN_CNSTRFULL].number;
    try {
      mj_step(m, d);
    } catch (const Error& e) {
      // MuJoCo's scratch stack ran out (contacts and dofs need more than the estimate): twice
      // the arena, recompiled with the state as it was, and the step again; a scene whose data
      // MuJoCo cannot allocate fails in EnsureCompiled, saying so
      if (!IsOutOfArena(e.what())) throw;
      ReleaseStack(d);
      GrowArena("MuJoCo's arena of " + std::to_string(m->narena) + " bytes ran out");
      --i;
      continue;
    }
    int bad_after = d->warning[mjWARN_BADQACC].number + d->warning[mjWARN_BADQPOS].number +
                    d->warning[mjWARN_BADQVEL].number;
    if (bad_after != bad_before)
      warnings.push_back({d->time,
                          "numerical instability (NaN or huge value in positions, "
                          "velocities or accelerations): MuJoCo reset the state to the "
                          "model's initial configuration"});
    if (data.xfrc_dirty) {
      std::fill(d->xfrc_applied, d->xfrc_applied + 6 * m->nbody, 0.0);
      data.xfrc_dirty = false;
    }
    // last: growing recompiles, and the model and data above are gone
    if (d->warning[mjWARN_CONTACTFULL].number + d->warning[mjWARN_CNSTRFULL].number != full_before)
      GrowArena("contacts filled MuJoCo's arena of " + std::to_string(m->narena) +
                " bytes (the excess was dropped for one step)");
  }
  Invalidate();
}

}  // namespace internal

using internal::CompiledActor;
using internal::CompiledArticulation;

// ---------------------------------------------------------------------------------------------
// Scene

Scene::Scene(const SceneConfig& config) : impl_(std::make_unique<Impl>()) {
  if (!(config.timestep > 0) || !std::isfinite(config.timestep))
    throw Error("SceneConfig.timestep must be finite and > 0, got " +
                FormatNumber(config.timestep));
  if (!config.gravity.allFinite()) throw Error("SceneConfig.gravity must be finite");
  if (config.solver_iterations < 1)
    throw Error("SceneConfig.solver_iterations must be >= 1, got " +
                std::to_string(config.solver_iterations));
  if (!(config.rest_offset >= 0) || !std::isfinite(config.rest_offset))
    throw Error("SceneConfig.rest_offset must be finite and >= 0, got " +
                FormatNumber(config.rest_offset));
  if (!(config.contact_offset >= config.rest_offset) || !std::isfinite(config.contact_offset))
    throw Error("SceneConfig.contact_offset must be finite and >= rest_offset (" +
                FormatNumber(config.rest_offset) + "), got " + FormatNumber(config.contact_offset));
  if (!(config.contact_impedance > 0 && config.contact_impedance <= 0.9999))
    throw Error("SceneConfig.contact_impedance must be in (0, 0.9999], got " +
                FormatNumber(config.contact_impedance));
  impl_->config = config;
  impl_->EnsureCompiled();
}

Scene::~Scene() = default;

std::unique_ptr<Scene> Scene::Clone() const {
  Impl& s = impl();
  s.EnsureCompiled();
  auto copy = std::make_unique<Scene>(s.config);
  Impl& c = copy->impl();
  // the three stages, copied: the description, the compiled model, the data
  c.actors = s.actors;
  c.articulations = s.articulations;
  c.next_id = s.next_id;
  c.next_visual_id = s.next_visual_id;
  c.arena_capacity = s.arena_capacity;
  c.mjcf_models = s.mjcf_models;
  c.next_mjcf_id = s.next_mjcf_id;
  c.description_version = s.description_version;
  c.model = s.model.Copy();
  c.data = s.data.CopyFor(c.model);
  c.dirty = false;
  c.warnings = s.warnings;
  // the observers' state (cameras, lights) after the bodies it may refer to
  for (const auto& [key, attachment] : impl().attachments)
    c.attachments[key] = attachment->CloneFor(*copy);
  return copy;
}

const SceneConfig& Scene::GetConfig() const { return impl().config; }
double Scene::GetTimestep() const { return impl().config.timestep; }

void Scene::SetTimestep(double dt) {
  if (!(dt > 0) || !std::isfinite(dt))
    throw Error("timestep must be finite and > 0, got " + FormatNumber(dt));
  impl().config.timestep = dt;
  // constraint time constants are derived from the timestep: recompile, keeping the state
  impl().dirty = true;
  impl().EnsureCompiled();
}

Eigen::Vector3d Scene::GetGravity() const { return impl().config.gravity; }

void Scene::SetGravity(const Eigen::Vector3d& g) {
  if (!g.allFinite()) throw Error("gravity must be finite");
  impl().config.gravity = g;
  impl().EnsureCompiled();
  for (int k = 0; k < 3; ++k) impl().m()->opt.gravity[k] = g[k];
  impl().Invalidate();
}

double Scene::GetTime() const {
  impl().EnsureCompiled();
  return impl().d()->time;
}

void Scene::SetDefaultMaterial(const PhysicalMaterial& material) {
  Validate(material, "set_default_material");
  impl().config.default_material = material;
  impl().dirty = true;
  impl().EnsureCompiled();
}

Actor Scene::AddGround(double altitude, const std::optional<PhysicalMaterial>& material,
                       const std::string& name, bool render,
                       const Eigen::Vector2d& render_half_size,
                       const std::optional<RenderMaterial>& render_material) {
  if (!std::isfinite(altitude)) throw Error("add_ground: altitude must be finite");
  if (!(render_half_size.minCoeff() > 0) || !render_half_size.allFinite())
    throw Error("add_ground: render_half_size must be finite and > 0, got (" +
                FormatNumber(render_half_size[0]) + ", " + FormatNumber(render_half_size[1]) + ")");
  ActorDesc desc;
  desc.name = name;
  desc.type = ActorType::kStatic;
  desc.pose.p.z() = altitude;
  CollisionShape plane;
  plane.type = ShapeType::kPlane;
  plane.material = material;
  desc.collisions.push_back(plane);
  VisualShape visual;
  visual.type = ShapeType::kPlane;
  visual.half_size = Eigen::Vector3d(render_half_size[0], render_half_size[1], 0);
  visual.material.base_color = Eigen::Vector4f(0.9f, 0.9f, 0.9f, 1.0f);
  if (render_material) visual.material = *render_material;
  if (render) desc.visuals.push_back(visual);
  return AddActor(desc);
}

namespace {

// Compiles a changed description; if MuJoCo refuses it, undoes the change and recompiles, so that
// the scene stays as it was, then rethrows.
template <typename Undo>
void CompileOrUndo(internal::SceneImpl& s, Undo undo) {
  s.dirty = true;
  try {
    s.EnsureCompiled();
  } catch (...) {
    undo();
    s.dirty = true;
    s.EnsureCompiled();
    throw;
  }
}

}  // namespace

Actor Scene::AddActor(const ActorDesc& given) {
  Validate(given);
  ActorDesc desc = given;
  NormalizeRotations(&desc);
  Impl& s = impl();
  s.CheckUser();  // added without compiling: the check EnsureCompiled would make
  // an actor's id is its entity id in segmentation pictures too (as SAPIEN's)
  int id = s.next_id;
  internal::SceneImpl::ActorEntry entry;
  entry.id = id;
  entry.desc = desc;
  entry.render_id = static_cast<uint32_t>(id);
  entry.visual_id_base = s.next_visual_id;
  s.actors.push_back(std::move(entry));
  // compiled with the next use of the model (EnsureCompiled): adding many actors one by one
  // compiles once
  s.uncompiled_actors.push_back(id);
  s.dirty = true;
  ++s.next_id;
  s.next_visual_id += static_cast<uint32_t>(desc.visuals.size());
  return Actor(this, id);
}

Articulation Scene::AddArticulation(const ArticulationDesc& given) {
  Validate(given);
  ArticulationDesc desc = given;
  NormalizeRotations(&desc);
  Impl& s = impl();
  s.EnsureCompiled();
  // its links take the ids (segmentation entity ids) after the articulation's own
  int id = s.next_id;
  internal::SceneImpl::ArticulationEntry entry;
  entry.id = id;
  entry.desc = desc;
  entry.render_id_base = static_cast<uint32_t>(id + 1);
  uint32_t visual_id = s.next_visual_id;
  for (const LinkDesc& l : desc.links) {
    entry.visual_id_base.push_back(visual_id);
    visual_id += static_cast<uint32_t>(l.visuals.size());
  }
  s.articulations.push_back(std::move(entry));
  CompileOrUndo(s, [&] { s.articulations.pop_back(); });
  s.next_id += 1 + static_cast<int>(desc.links.size());
  s.next_visual_id = visual_id;
  // a new articulation starts at q = 0 clamped into its limits
  Articulation art(this, id);
  Eigen::MatrixX2d lim = art.GetQlimits();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(art.Dof());
  for (int k = 0; k < art.Dof(); ++k) q[k] = std::min(std::max(0.0, lim(k, 0)), lim(k, 1));
  art.SetQpos(q);
  return art;
}

void Scene::RemoveActor(const Actor& actor) {
  Impl& s = impl();
  // ids are per scene: another scene's handle would name one of ours
  if (actor.GetScene() != this)
    throw Error("remove_actor: actor " + std::to_string(actor.GetId()) +
                " belongs to another scene");
  s.GetActor(actor.GetId());  // throws if absent
  s.actors.erase(std::remove_if(s.actors.begin(), s.actors.end(),
                                [&](const auto& a) { return a.id == actor.GetId(); }),
                 s.actors.end());
  s.uncompiled_actors.erase(
      std::remove(s.uncompiled_actors.begin(), s.uncompiled_actors.end(), actor.GetId()),
      s.uncompiled_actors.end());
  s.dirty = true;
  s.EnsureCompiled();
}

void Scene::RemoveArticulation(const Articulation& articulation) {
  Impl& s = impl();
  if (articulation.GetScene() != this)
    throw Error("remove_articulation: articulation " + std::to_string(articulation.GetId()) +
                " belongs to another scene");
  s.GetArticulation(articulation.GetId());
  s.articulations.erase(std::remove_if(s.articulations.begin(), s.articulations.end(),
                                       [&](const auto& a) { return a.id == articulation.GetId(); }),
                        s.articulations.end());
  s.dirty = true;
  s.EnsureCompiled();
}

std::vector<Actor> Scene::GetActors() const {
  std::vector<Actor> out;
  for (const auto& a : impl().actors) out.emplace_back(const_cast<Scene*>(this), a.id);
  return out;
}

std::vector<Articulation> Scene::GetArticulations() const {
  std::vector<Articulation> out;
  for (const auto& a : impl().articulations) out.emplace_back(const_cast<Scene*>(this), a.id);
  return out;
}

Actor Scene::FindActorByName(const std::string& name) const {
  for (const auto& a : impl().actors)
    if (a.desc.name == name) return Actor(const_cast<Scene*>(this), a.id);
  throw Error("no actor named '" + name + "'");
}

Articulation Scene::FindArticulationByName(const std::string& name) const {
  for (const auto& a : impl().articulations)
    if (a.desc.name == name) return Articulation(const_cast<Scene*>(this), a.id);
  throw Error("no articulation named '" + name + "'");
}

void Scene::Step(int n) {
  Use use(*this);  // waits for another thread's step; keeps other threads out meanwhile
  impl_->Step(n);
}

Scene::Use::Use(const Scene& scene) : scene_(&scene), owns_(true) {
  Impl& s = *scene.impl_;
  s.use_mutex.lock();
  if (s.use_depth++ == 0) s.user = std::this_thread::get_id();
}

Scene::Use::Use(const Scene& scene, std::try_to_lock_t) : scene_(&scene) {
  Impl& s = *scene.impl_;
  if (!s.use_mutex.try_lock()) return;
  owns_ = true;
  if (s.use_depth++ == 0) s.user = std::this_thread::get_id();
}

Scene::Use::~Use() {
  if (!owns_) return;
  Impl& s = *scene_->impl_;
  if (--s.use_depth == 0) s.user = std::thread::id();
  s.use_mutex.unlock();
}

Scene::Impl& Scene::impl() const { return *impl_; }

namespace internal {

void SceneImpl::CheckUser() const {
  const std::thread::id holder = user.load();
  if (holder != std::thread::id() && holder != std::this_thread::get_id())
    throw Error(
        "scene: another thread is stepping or rendering this scene; use a scene from one thread "
        "at a time (Step calls from several threads take turns; hold Scene::Use across other "
        "calls)");
}

}  // namespace internal

const std::vector<Warning>& Scene::GetWarnings() const { return impl().warnings; }
void Scene::ClearWarnings() { impl().warnings.clear(); }

const mjModel_* Scene::GetMjModel() const {
  impl().EnsureCompiled();
  return impl().m();
}

mjData_* Scene::GetMjData() const {
  impl().EnsureCompiled();
  return impl().d();
}

std::string Scene::GetMjcf() const {
  impl().EnsureCompiled();
  return internal::SaveMjcf(impl().model.spec.get());
}

// ---------------------------------------------------------------------------------------------
// contacts

std::vector<Contact> Scene::GetContacts() const {
  Impl& s = impl();
  s.EnsureCompiled();
  const mjModel* m = s.m();
  const mjData* d = s.d();
  auto body = [&](int geom) {
    ContactBody b;
    const internal::GeomOwner& o = s.model.geom_owner[geom];
    b.shape_index = o.shape_index;
    if (o.actor_id >= 0) {
      b.kind = ContactBody::Kind::kActor;
      b.actor_id = o.actor_id;
      b.name = s.GetActor(o.actor_id).desc.name;
    } else if (o.articulation_id >= 0) {
      b.kind = ContactBody::Kind::kLink;
      b.articulation_id = o.articulation_id;
      b.link_index = o.link_index;
      b.name = s.GetArticulation(o.articulation_id).desc.links[o.link_index].name;
    }
    return b;
  };
  // a static actor (the ground, a wall) is body 1 when the other body can move
  auto is_static = [&](int geom) {
    const internal::GeomOwner& o = s.model.geom_owner[geom];
    return o.actor_id >= 0 && s.GetActor(o.actor_id).desc.type == ActorType::kStatic;
  };
  std::map<std::pair<int, int>, size_t> index;
  std::vector<Contact> out;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    // 0: a contact with force, 1: within the detection gap, touching soon (no force yet)
    if (c.exclude > 1) continue;
    const bool swap = is_static(c.geom1) && !is_static(c.geom2);
    const int g0 = swap ? c.geom2 : c.geom1, g1 = swap ? c.geom1 : c.geom2;
    auto key = std::make_pair(g0, g1);
    auto it = index.find(key);
    if (it == index.end()) {
      Contact contact;
      contact.body0 = body(g0);
      contact.body1 = body(g1);
      it = index.emplace(key, out.size()).first;
      out.push_back(contact);
    }
    mjtNum f[6] = {0, 0, 0, 0, 0, 0};
    if (c.efc_address >= 0) mj_contactForce(m, d, i, f);
    Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> frame(c.frame);
    ContactPoint p;
    p.position = Eigen::Vector3d(c.pos[0], c.pos[1], c.pos[2]);
    // MuJoCo's normal points from geom1 to geom2 and its force acts on geom2; partsim's normal
    // points into body 0 and its force acts on body 0
    const double sign = swap ? 1.0 : -1.0;
    p.normal = sign * frame.row(0).transpose();
    p.force = sign * (frame.transpose() * Eigen::Vector3d(f[0], f[1], f[2]));
    p.impulse = p.force * m->opt.timestep;
    p.separation = c.dist;
    out[it->second].points.push_back(p);
  }
  return out;
}

std::optional<RayHit> Scene::Raycast(const Eigen::Vector3d& origin,
                                     const Eigen::Vector3d& direction, double distance) const {
  if (!origin.allFinite()) throw Error("raycast: the origin must be finite");
  const double length = direction.norm();
  if (!std::isfinite(length) || length <= 0.0)
    throw Error("raycast: the direction must be finite and non-zero");
  if (std::isnan(distance) || distance < 0.0) throw Error("raycast: the distance must be >= 0 (m)");
  Impl& s = impl();
  s.EnsureKinematics();
  const Eigen::Vector3d unit = direction / length;
  int geom = -1;
  mjtNum normal[3] = {0, 0, 0};
  const mjtNum dist =
      mj_ray(s.m(), s.d(), origin.data(), unit.data(), nullptr, 1, -1, &geom, normal);
  if (geom < 0 || dist < 0.0 || dist > distance) return std::nullopt;
  RayHit hit;
  hit.distance = dist;
  hit.position = origin + dist * unit;
  hit.normal = Eigen::Vector3d(normal[0], normal[1], normal[2]);
  const internal::GeomOwner& o = s.model.geom_owner[geom];
  hit.body.shape_index = o.shape_index;
  if (o.actor_id >= 0) {
    hit.body.actor_id = o.actor_id;
    hit.body.name = s.GetActor(o.actor_id).desc.name;
  } else if (o.articulation_id >= 0) {
    hit.body.kind = ContactBody::Kind::kLink;
    hit.body.articulation_id = o.articulation_id;
    hit.body.link_index = o.link_index;
    hit.body.name = s.GetArticulation(o.articulation_id).desc.links[o.link_index].name;
  }
  return hit;
}

// ---------------------------------------------------------------------------------------------
// pack / unpack

namespace {

constexpr uint32_t kPackMagic = 0x50534d32;  // "PSM2"

class Writer {
 public:
  template <typename T>
  void Put(const T& v) {
    const char* p = reinterpret_cast<const char*>(&v);
    buf.insert(buf.end(), p, p + sizeof(T));
  }
  void Put(const double* v, int n) {
    const char* p = reinterpret_cast<const char*>(v);
    buf.insert(buf.end(), p, p + sizeof(double) * n);
  }
  std::vector<char> buf;
};

class Reader {
 public:
  explicit Reader(const std::vector<char>& b) : buf(b) {}
  template <typename T>
  T Get() {
    T v;
    Need(sizeof(T));
    std::memcpy(&v, buf.data() + pos, sizeof(T));
    pos += sizeof(T);
    return v;
  }
  void Get(double* v, int n) {
    Need(sizeof(double) * n);
    std::memcpy(v, buf.data() + pos, sizeof(double) * n);
    pos += sizeof(double) * n;
  }
  void Skip(size_t n) {
    Need(n);
    pos += n;
  }
  void Need(size_t n) {
    if (pos + n > buf.size())
      throw Error("unpack: state is truncated (" + std::to_string(buf.size()) + " bytes)");
  }
  const std::vector<char>& buf;
  size_t pos = 0;
};

}  // namespace

std::vector<char> Scene::Pack() const {
  Impl& s = impl();
  s.EnsureCompiled();
  const mjModel* m = s.m();
  const mjData* d = s.d();
  Writer w;
  w.Put(kPackMagic);
  for (int n : {m->nq, m->nv, m->nu, m->na, m->nbody, m->nmocap}) w.Put(n);
  w.Put(static_cast<int>(s.articulations.size()));
  w.Put(d->time);
  w.Put(d->qpos, m->nq);
  w.Put(d->qvel, m->nv);
  w.Put(d->qacc, m->nv);
  w.Put(d->qacc_warmstart, m->nv);
  w.Put(d->qfrc_applied, m->nv);
  w.Put(d->xfrc_applied, 6 * m->nbody);
  w.Put(d->act, m->na);
  w.Put(d->mocap_pos, 3 * m->nmocap);
  w.Put(d->mocap_quat, 4 * m->nmocap);
  for (const auto& a : s.articulations) {
    const internal::ArticulationData& state = s.data.articulations.at(a.id);
    const int dof = static_cast<int>(state.drive_target.size());
    w.Put(dof);
    w.Put(state.drive_target.data(), dof);
    w.Put(state.drive_velocity_target.data(), dof);
    w.Put(static_cast<int>(state.kin_qpos.size()));
    w.Put(state.kin_qpos.data(), static_cast<int>(state.kin_qpos.size()));
    w.Put(state.kin_qvel.data(), static_cast<int>(state.kin_qvel.size()));
  }
  return w.buf;
}

void Scene::Unpack(const std::vector<char>& state) {
  Impl& s = impl();
  s.EnsureCompiled();
  mjModel* m = s.m();
  mjData* d = s.d();
  Reader r(state);
  if (r.Get<uint32_t>() != kPackMagic) throw Error("unpack: not a partsim state (bad header)");
  const char* names[] = {"nq", "nv", "nu", "na", "nbody", "nmocap"};
  const int expect[] = {static_cast<int>(m->nq),    static_cast<int>(m->nv),
                        static_cast<int>(m->nu),    static_cast<int>(m->na),
                        static_cast<int>(m->nbody), static_cast<int>(m->nmocap)};
  for (int k = 0; k < 6; ++k) {
    int got = r.Get<int>();
    if (got != expect[k])
      throw Error("unpack: state has " + std::string(names[k]) + " = " + std::to_string(got) +
                  ", this scene has " + std::to_string(expect[k]) +
                  " (was it packed from a scene with other actors or articulations?)");
  }
  if (r.Get<int>() != static_cast<int>(s.articulations.size()))
    throw Error("unpack: state has another number of articulations than this scene");
  // two passes over the same layout: the first only checks it, so that a truncated or foreign
  // state changes nothing; the second writes
  const size_t body = r.pos;
  for (bool write : {false, true}) {
    r.pos = body;
    auto get = [&](double* dst, int n) {
      if (write)
        r.Get(dst, n);
      else
        r.Skip(sizeof(double) * n);
    };
    get(&d->time, 1);
    get(d->qpos, m->nq);
    get(d->qvel, m->nv);
    get(d->qacc, m->nv);
    get(d->qacc_warmstart, m->nv);
    get(d->qfrc_applied, m->nv);
    get(d->xfrc_applied, 6 * m->nbody);
    get(d->act, m->na);
    get(d->mocap_pos, 3 * m->nmocap);
    get(d->mocap_quat, 4 * m->nmocap);
    for (auto& a : s.articulations) {
      internal::ArticulationData& state = s.data.articulations.at(a.id);
      int dof = r.Get<int>();
      if (dof != state.drive_target.size())
        throw Error("unpack: articulation '" + a.desc.name + "' has another number of dofs");
      get(state.drive_target.data(), dof);
      get(state.drive_velocity_target.data(), dof);
      int n = r.Get<int>();
      if (n != state.kin_qpos.size()) throw Error("unpack: kinematic articulation size differs");
      get(state.kin_qpos.data(), n);
      get(state.kin_qvel.data(), n);
    }
    if (r.pos != state.size()) throw Error("unpack: state has trailing bytes");
  }
  s.data.xfrc_dirty = true;
  s.Invalidate();
}

}  // namespace partsim
