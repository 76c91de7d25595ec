// `partsim info [OBJECT]`: the links (name, parent, mass), the joints (name, type, parent ->
// child, limits), the total mass and the degrees of freedom of an object, as text or JSON.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "arg_parser.h"
#include "commands.h"
#include "object_loader.h"

namespace partsim::tools {

namespace {

struct InfoArgs {
  ObjectArgs object;
  bool json = false;
};

std::string LimitText(double v) {
  if (std::isinf(v)) return v < 0 ? "-inf" : "inf";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

nlohmann::ordered_json LimitJson(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nullptr;
}

int Info(const InfoArgs& args) {
  LoadedObject l = LoadObject(args.object, SceneConfig());
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
      limits =
          "[" + LimitText(lim[0]) + ", " + LimitText(lim[1]) + "] " + JointUnit(joint.GetType());
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
