// Loading the object of info, simulate and render: a URDF file, a PartNet-Mobility folder (or
// its mobility.urdf) or the built-in cabinet.
#include "object_loader.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>

#include "partsim/assets/default_objects.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/assets/urdf.h"

namespace partsim::tools {

namespace {

// The built-in cabinet's part labels, in the PartNet-Mobility vocabulary of semantics.txt that
// generated objects and the tasks use.
void LabelCabinetParts(ArticulationDesc* desc) {
  for (LinkDesc& link : desc->links) {
    if (link.name == "body")
      link.semantic_label = "furniture_body";
    else if (link.name.rfind("drawer_", 0) == 0)
      link.semantic_label = "drawer";
    else if (link.name.rfind("door_", 0) == 0)
      link.semantic_label = "rotation_door";
  }
}

// The PartNet-Mobility folder that `file` names: the folder itself, or the folder of a
// mobility.urdf that has the dataset's annotation files beside it; "" for any other file.
std::string PartNetFolder(const std::string& file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path path(file);
  if (fs::is_directory(path, ec)) return file;
  if (path.filename() != "mobility.urdf") return "";
  const fs::path folder = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  for (const char* annotation : {"mobility_v2.json", "semantics.txt", "meta.json"})
    if (fs::is_regular_file(folder / annotation, ec)) return folder.string();
  return "";
}

}  // namespace

void AddObjectArgs(ArgParser* parser, ObjectArgs* args) {
  parser->Positional([args](const FlagValue& v) {
    if (!args->file.empty())
      v.Fail("unexpected extra argument '" + v.Text() + "' (one file at most)");
    args->file = v.Text();
  });
  parser->Switch("--fix-root", [args] { args->fix_root = true; });
  parser->Switch("--free-root", [args] { args->fix_root = false; });
}

LoadedObject LoadObject(const ObjectArgs& args, const SceneConfig& config) {
  LoadedObject out;
  out.scene = std::make_unique<Scene>(config);
  UrdfLoader loader = CreateUrdfLoader(*out.scene);
  loader.fix_root_link = args.fix_root;
  if (args.file.empty()) {
    std::cerr << "partsim: no file given, using the built-in cabinet (a drawer and a door)\n";
    ArticulationDesc desc = loader.Parse(MakeCabinetUrdf(), ".");
    LabelCabinetParts(&desc);
    out.art = out.scene->AddArticulation(desc);
    out.source = "built-in cabinet";
    return out;
  }
  // a PartNet-Mobility object loads through the dataset's loader, whichever of the folder
  // and its mobility.urdf is named: same articulation, with the labels of semantics.txt
  if (const std::string folder = PartNetFolder(args.file); !folder.empty()) {
    if (folder != args.file) {
      std::cerr << "partsim: " << args.file << " belongs to a PartNet-Mobility folder; loading "
                << folder << " (part labels from semantics.txt)\n";
    }
    PartNetMobilityLoader partnet(out.scene.get());
    partnet.urdf = loader;
    out.art = partnet.Load(folder);
    out.source = args.file;
    return out;
  }
  // a missing file is reported with the system's reason
  std::ifstream probe(args.file);
  if (!probe) {
    throw std::runtime_error("cannot open '" + args.file + "': " + std::strerror(errno));
  }
  // MuJoCo's own format: a scene with the file's options, the model with partsim's handles
  if (IsMjcfFile(args.file)) {
    const SceneConfig file_config = SceneConfigFromMjcf(args.file);
    std::cerr << "partsim: " << args.file << " is an MJCF model: its options are used (timestep "
              << file_config.timestep << " s)\n";
    out.scene = std::make_unique<Scene>(file_config);
    out.mjcf = LoadMjcf(*out.scene, args.file);
    for (const Articulation& a : out.mjcf->GetArticulations())
      if (!out.art.GetScene() || a.Dof() > out.art.Dof()) out.art = a;
    out.source = args.file;
    return out;
  }
  out.art = loader.Load(args.file);
  out.source = args.file;
  return out;
}

const char* JointUnit(JointType type) {
  return type == JointType::kPrismatic ? "m" : type == JointType::kFixed ? "" : "rad";
}

}  // namespace partsim::tools
