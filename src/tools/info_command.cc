// `partsim info [OBJECT]`: the links (name, parent, mass), the joints (name, type, parent ->
// child, limits), the total mass and the degrees of freedom of an object, as text or JSON; for
// an MJCF file, what partsim made of its model and what MuJoCo keeps.
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "core/number_text.h"
#include "object_loader.h"

namespace partsim::tools {

namespace {

struct InfoArgs {
  ObjectArgs object;
  bool json = false;
};

nlohmann::ordered_json LimitJson(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nullptr;
}

// An MJCF model: what partsim made of it (articulations with their dofs, actors with their
// type), and what MuJoCo keeps as it defines it (actuators, tendons, bodies without a handle).
int MjcfInfo(const InfoArgs& args, const LoadedObject& l) {
  const MjcfModel& model = *l.mjcf;
  // the counts of the file's own model (the scene's adds partsim's drives)
  char error[1000] = "";
  std::unique_ptr<mjModel, void (*)(mjModel*)> own(
      mj_loadXML(model.GetPath().c_str(), nullptr, error, sizeof(error)), mj_deleteModel);
  if (!own) throw std::runtime_error(l.source + ": " + error);
  const mjModel* m = own.get();
  nlohmann::ordered_json j;
  j["source"] = l.source;
  j["format"] = "mjcf";
  j["name"] = model.GetName();
  j["timestep"] = m->opt.timestep;
  j["articulations"] = nlohmann::ordered_json::array();
  for (const Articulation& a : model.GetArticulations()) {
    nlohmann::ordered_json joints = nlohmann::ordered_json::array();
    for (const Joint& joint : a.GetActiveJoints()) joints.push_back(joint.GetName());
    j["articulations"].push_back({{"name", a.GetName()},
                                  {"links", a.GetLinks().size()},
                                  {"dof", a.Dof()},
                                  {"fix_root", a.HasFixedRoot()},
                                  {"joints", joints}});
  }
  j["actors"] = nlohmann::ordered_json::array();
  for (const Actor& a : model.GetActors())
    j["actors"].push_back({{"name", a.GetName()}, {"type", ActorTypeName(a.GetType())}});
  j["actuators"] = model.GetActuatorNames();
  j["tendons"] = model.GetTendonNames();
  j["bodies_without_handle"] = model.GetBodiesWithoutHandle();
  j["counts"] = {{"bodies", m->nbody - 1}, {"joints", m->njnt},    {"geoms", m->ngeom},
                 {"dof", m->nv},           {"actuators", m->nu},   {"tendons", m->ntendon},
                 {"equalities", m->neq},   {"sensors", m->nsensor}};
  if (args.json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::printf("MJCF model '%s' from %s (timestep %g s)\n", model.GetName().c_str(),
              l.source.c_str(), m->opt.timestep);
  std::printf(
      "MuJoCo: %ld bodies, %ld joints, %ld dof, %ld geoms, %ld actuators, %ld tendons, "
      "%ld equality constraints, %ld sensors\n",
      static_cast<long>(m->nbody - 1), static_cast<long>(m->njnt), static_cast<long>(m->nv),
      static_cast<long>(m->ngeom), static_cast<long>(m->nu), static_cast<long>(m->ntendon),
      static_cast<long>(m->neq), static_cast<long>(m->nsensor));
  std::printf("\narticulations (%zu):\n", model.GetArticulations().size());
  for (const Articulation& a : model.GetArticulations()) {
    std::string joints;
    for (const Joint& joint : a.GetActiveJoints())
      joints += (joints.empty() ? "" : ", ") + joint.GetName();
    std::printf("  %-24s %zu links, %d dof (%s root): %s\n", a.GetName().c_str(),
                a.GetLinks().size(), a.Dof(), a.HasFixedRoot() ? "fixed" : "free", joints.c_str());
  }
  std::printf("\nactors (%zu):\n", model.GetActors().size());
  for (const Actor& a : model.GetActors())
    std::printf("  %-24s %s\n", a.GetName().c_str(), ActorTypeName(a.GetType()));
  auto list = [](const char* what, const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& n : names) text += (text.empty() ? "" : ", ") + n;
    std::printf("\n%s (%zu): %s\n", what, names.size(), names.empty() ? "-" : text.c_str());
  };
  list("actuators", model.GetActuatorNames());
  list("tendons", model.GetTendonNames());
  if (!model.GetBodiesWithoutHandle().empty())
    list("bodies without a partsim handle (ball joints; MuJoCo simulates them)",
         model.GetBodiesWithoutHandle());
  return 0;
}

int Info(const InfoArgs& args) {
  LoadedObject l = LoadObject(args.object, SceneConfig());
  if (l.mjcf) return MjcfInfo(args, l);
  const ArticulationDesc& desc = l.art.GetDesc();
  std::vector<Link> links = l.art.GetLinks();
  const bool fix_root = args.object.fix_root;
  double total = 0.0;
  for (const Link& link : links) total += link.GetMass();

  if (args.json) {
    nlohmann::ordered_json j;
    j["source"] = l.source;
    j["name"] = desc.name;
    j["fix_root"] = fix_root;
    j["links"] = nlohmann::ordered_json::array();
    for (const Link& link : links) {
      int p = link.GetParentIndex();
      j["links"].push_back({{"name", link.GetName()},
                            {"parent", p < 0 ? nlohmann::ordered_json(nullptr)
                                             : nlohmann::ordered_json(links[p].GetName())},
                            {"mass", link.GetMass()}});
    }
    j["joints"] = nlohmann::ordered_json::array();
    for (const Joint& joint : l.art.GetJoints()) {
      Eigen::Vector2d lim = joint.GetLimits();
      j["joints"].push_back({{"name", joint.GetName()},
                             {"type", JointTypeName(joint.GetType())},
                             {"parent", joint.GetParentLink().GetName()},
                             {"child", joint.GetChildLink().GetName()},
                             {"dof", joint.GetDof()},
                             {"lower", LimitJson(lim[0])},
                             {"upper", LimitJson(lim[1])},
                             {"unit", JointUnit(joint.GetType())}});
    }
    j["total_mass"] = total;
    j["dof"] = l.art.Dof();
    std::cout << j.dump(2) << "\n";
    return 0;
  }

  std::printf("articulation '%s' from %s (%s root)\n", desc.name.c_str(), l.source.c_str(),
              fix_root ? "fixed" : "free");
  std::printf("\nlinks (%zu):\n", links.size());
  std::printf("  %-24s %-24s %12s\n", "name", "parent", "mass [kg]");
  for (const Link& link : links) {
    int p = link.GetParentIndex();
    std::printf(
        "  %-24s %-24s %12.4f\n", link.GetName().c_str(),
        p < 0 ? (fix_root ? "(world, fixed)" : "(world, free)") : links[p].GetName().c_str(),
        link.GetMass());
  }
  std::vector<Joint> joints = l.art.GetJoints();
  std::printf("\njoints (%zu):\n", joints.size());
  std::printf("  %-24s %-11s %-40s %s\n", "name", "type", "parent -> child", "limits");
  for (const Joint& joint : joints) {
    std::string link_pair =
        joint.GetParentLink().GetName() + " -> " + joint.GetChildLink().GetName();
    std::string limits = "-";
    if (joint.GetDof() > 0 || joint.GetType() != JointType::kFixed) {
      Eigen::Vector2d lim = joint.GetLimits();
      limits = "[" + internal::Significant(lim[0], 6) + ", " + internal::Significant(lim[1], 6) +
               "] " + JointUnit(joint.GetType());
    }
    std::printf("  %-24s %-11s %-40s %s\n", joint.GetName().c_str(), JointTypeName(joint.GetType()),
                link_pair.c_str(), limits.c_str());
  }
  std::printf("\ntotal mass: %.4f kg\n", total);
  std::printf("DOF: %d%s\n", l.art.Dof(), fix_root ? "" : " (+6 of the free root)");
  return 0;
}

}  // namespace

int RunInfoCommand(const std::vector<std::string>& args) {
  return RunWithExitCode("partsim info", "", [&] {
    InfoArgs a;
    ArgParser parser("partsim info", "partsim --help");
    AddObjectArgs(&parser, &a.object);
    parser.Switch("--json", [&] { a.json = true; });
    parser.Parse(args);
    return Info(a);
  });
}

}  // namespace partsim::tools
