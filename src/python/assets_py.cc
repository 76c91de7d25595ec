// Bindings of the assets subsystem: the URDF loader (and Scene.create_urdf_loader) and mesh files.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "partsim/assets/mesh.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/assets/quality.h"
#include "partsim/assets/urdf.h"
#include "partsim/physics/scene.h"

namespace partsim::python {

void BindAssets(py::module_& m) {
  const auto ka = py::keep_alive<0, 1>();

  py::class_<LoadWarning>(m, "LoadWarning", "A defect a loader repaired or ignored.")
      .def_readonly("file", &LoadWarning::file, "The file at fault.")
      .def_readonly("message", &LoadWarning::message,
                    "What was wrong and what the loader did, naming the element.")
      .def("__str__", &LoadWarning::ToString)
      .def("__repr__", [](const LoadWarning& w) { return "<LoadWarning " + w.ToString() + ">"; });
  py::class_<LoadReport>(m, "LoadReport",
                         "The warnings of one load (UrdfLoader.last_report(), "
                         "PartNetMobilityLoader.last_report()).")
      .def_readonly("warnings", &LoadReport::warnings, "list of LoadWarning, in file order.")
      .def("__len__", [](const LoadReport& r) { return r.warnings.size(); })
      .def("__bool__", [](const LoadReport& r) { return !r.Empty(); })
      .def("__str__", &LoadReport::ToString);

  py::class_<UrdfLinkOverride>(m, "UrdfLinkOverride", "Per-link overrides of a UrdfLoader.")
      .def(py::init([](std::optional<double> density, std::optional<PhysicalMaterial> material) {
             return UrdfLinkOverride{density, material};
           }),
           py::arg("density") = py::none(), py::arg("material") = py::none())
      .def_readwrite("density", &UrdfLinkOverride::density,
                     "kg/m^3 for the link's collision shapes, or None.")
      .def_readwrite("material", &UrdfLinkOverride::material, "PhysicalMaterial or None.");

  py::class_<UrdfLoader>(
      m, "UrdfLoader",
      "Loads URDF files (SAPIEN's URDFLoader). Get one from Scene.create_urdf_loader(); one "
      "made with UrdfLoader() has no scene and can only parse. Dict attributes are copies: "
      "assign a whole dict to change them.")
      .def(py::init<>())
      .def_readwrite("fix_root_link", &UrdfLoader::fix_root_link)
      .def_readwrite("scale", &UrdfLoader::scale,
                     "Uniform scale on geometry, origins and prismatic limits.")
      .def_readwrite("load_multiple_collisions_from_file",
                     &UrdfLoader::load_multiple_collisions_from_file,
                     "Each mesh file (and each connected component) becomes its own convex piece.")
      .def_readwrite("density", &UrdfLoader::density, "kg/m^3 for links without <inertial>.")
      .def_readwrite("material", &UrdfLoader::material,
                     "Default PhysicalMaterial of collision shapes, or None.")
      .def_readwrite("link_overrides", &UrdfLoader::link_overrides,
                     "dict: link name -> UrdfLinkOverride.")
      .def_readwrite("package_dirs", &UrdfLoader::package_dirs,
                     "dict: package name -> folder, for package:// paths.")
      .def_readwrite("strict", &UrdfLoader::strict,
                     "Defects the loader would repair with a warning are errors instead.")
      .def_readwrite("srdf_file", &UrdfLoader::srdf_file,
                     "SRDF whose <disable_collisions> pairs apply; \"\" looks for "
                     "<urdf stem>.srdf beside the URDF file.")
      .def("last_report", &UrdfLoader::LastReport, py::return_value_policy::copy,
           "The warnings of the last parse or load (a LoadReport).")
      .def("parse", &UrdfLoader::Parse, py::arg("text"), py::arg("base_dir"),
           py::arg("source") = "<string>",
           "Parses URDF text into an ArticulationDesc; `source` names the text in error "
           "messages, `base_dir` resolves relative mesh paths.")
      .def("parse_file", &UrdfLoader::ParseFile, py::arg("path"))
      .def("load", &UrdfLoader::Load, py::arg("path"), ka,
           "Parses a URDF file and adds it to the scene.")
      .def("load_from_string", &UrdfLoader::LoadFromString, py::arg("text"),
           py::arg("base_dir") = ".", ka, "Parses URDF text and adds it to the scene.");

  py::class_<Scene, std::shared_ptr<Scene>>(m.attr("Scene"))
      .def("create_urdf_loader", &Scene::CreateUrdfLoader, ka);

  py::class_<LoadedMesh>(m, "LoadedMesh", "One sub-mesh of a file with its render material.")
      .def(py::init<>())
      .def_readwrite("mesh", &LoadedMesh::mesh)
      .def_readwrite("material", &LoadedMesh::material);

  m.def("load_mesh_file", &LoadMeshFile, py::arg("path"),
        py::arg("scale") = Eigen::Vector3d::Ones().eval(),
        "Every sub-mesh of a mesh file, node transforms applied, vertices multiplied by `scale` "
        "(3,), in metres.");
  m.def("load_merged_mesh", &LoadMergedMesh, py::arg("path"),
        py::arg("scale") = Eigen::Vector3d::Ones().eval(),
        "All sub-meshes of a file merged into one MeshData.");
  m.def("split_connected_components", &SplitConnectedComponents, py::arg("mesh"),
        "Connected components of a mesh (positions welded within 1e-7 m).");
  m.def("load_convex_pieces", &LoadConvexPieces, py::arg("path"),
        py::arg("scale") = Eigen::Vector3d::Ones().eval(),
        "Collision pieces of a file: one per sub-mesh and connected component.");

  // PartNet-Mobility objects
  py::class_<PartNetPart>(m, "PartNetPart",
                          "An annotated part piece: a visual named '<name>-<id>'.")
      .def_readonly("id", &PartNetPart::id)
      .def_readonly("name", &PartNetPart::name, "PartNet part name, e.g. 'handle'.")
      .def_readonly("visuals", &PartNetPart::visuals,
                    "Indices of the part's visuals in its link's visuals.");
  py::class_<PartNetLink>(m, "PartNetLink",
                          "One entry of mobility_v2.json: a link's motion, axis (file frame, "
                          "y-up), limits (degrees for hinges, metres for sliders) and parts.")
      .def_readonly("id", &PartNetLink::id)
      .def_readonly("parent", &PartNetLink::parent)
      .def_readonly("joint", &PartNetLink::joint,
                    "mobility_v2.json motion: hinge, slider, free, heavy or static.")
      .def_readonly("semantic_label", &PartNetLink::semantic_label,
                    "semantics.txt label ('drawer', 'rotation_door', ...).")
      .def_readonly("semantic_joint", &PartNetLink::semantic_joint,
                    "semantics.txt joint kind: hinge, slider, slider+, free, heavy, static.")
      .def_readonly("partnet_name", &PartNetLink::partnet_name,
                    "mobility_v2.json name, the PartNet vocabulary ('cabinet_door', ...).")
      .def_readonly("parts", &PartNetLink::parts)
      .def_readonly("has_axis", &PartNetLink::has_axis)
      .def_readonly("axis_origin", &PartNetLink::axis_origin)
      .def_readonly("axis_direction", &PartNetLink::axis_direction)
      .def_readonly("limit_a", &PartNetLink::limit_a)
      .def_readonly("limit_b", &PartNetLink::limit_b)
      .def_readonly("no_limit", &PartNetLink::no_limit)
      .def_readonly("rotates", &PartNetLink::rotates)
      .def_readonly("no_rotation_limit", &PartNetLink::no_rotation_limit)
      .def_readonly("rotation_limit", &PartNetLink::rotation_limit);
  py::class_<PartNetMobilityObject>(m, "PartNetMobilityObject",
                                    "A parsed PartNet-Mobility folder: its articulation "
                                    "(mobility.urdf as it is: z-up, root 'base') and its "
                                    "annotations (frame X_BF, y-up).")
      .def_readonly("folder", &PartNetMobilityObject::folder)
      .def_readonly("category", &PartNetMobilityObject::category)
      .def_readonly("model_id", &PartNetMobilityObject::model_id)
      .def_readonly("articulation", &PartNetMobilityObject::articulation)
      .def_readonly("links", &PartNetMobilityObject::links)
      .def_readonly("bbox_min", &PartNetMobilityObject::bbox_min)
      .def_readonly("bbox_max", &PartNetMobilityObject::bbox_max)
      .def_readonly("X_BF", &PartNetMobilityObject::X_BF,
                    "The annotation files' frame F (y-up) in the root link 'base'.")
      .def_readonly("report", &PartNetMobilityObject::report, "What the reader worked around.")
      .def("links_with_label", &PartNetMobilityObject::LinksWithLabel, py::arg("label"),
           "link ids whose semantics label is `label` (e.g. 'drawer').")
      .def("link", &PartNetMobilityObject::Link, py::arg("id"), py::return_value_policy::copy,
           "The mobility_v2.json entry of link_<id>.")
      .def("link_index", &PartNetMobilityObject::LinkIndex, py::arg("id"),
           "Index of link_<id> in the articulation.")
      .def("part_visuals", &PartNetMobilityObject::PartVisuals, py::arg("id"), py::arg("part_name"),
           "Indices of the visuals of part `part_name` on link_<id> (e.g. its handle).");
  py::class_<PartNetMobilityLoader>(
      m, "PartNetMobilityLoader",
      "Reads PartNet-Mobility folders. Get one from Scene.create_partnet_mobility_loader(); one "
      "made with PartNetMobilityLoader() can only parse. `urdf` holds the URDF options.")
      .def(py::init<>())
      .def_readwrite("urdf", &PartNetMobilityLoader::urdf)
      .def_readwrite("strict", &PartNetMobilityLoader::strict,
                     "Cross-file disagreements and missing files become errors (dataset QA).")
      .def("last_report", &PartNetMobilityLoader::LastReport, py::return_value_policy::copy,
           "The warnings of the last parse or load (a LoadReport).")
      .def("parse", &PartNetMobilityLoader::Parse, py::arg("folder"),
           "Reads and cross-checks a folder; raises PartsimError naming the file and entry.")
      .def("load", &PartNetMobilityLoader::Load, py::arg("folder"), ka,
           "Parses a folder and adds its articulation to the scene.");
  py::class_<Scene, std::shared_ptr<Scene>>(m.attr("Scene"))
      .def(
          "create_partnet_mobility_loader",
          [](Scene& scene) { return PartNetMobilityLoader(&scene); }, ka);
  m.def("standing_root_pose", &StandingRootPose, py::arg("articulation"), py::arg("altitude") = 0.0,
        "Root pose that makes the articulation stand on z = altitude at its current joint "
        "positions (orientation and x, y kept).");
  m.def(
      "place_on_ground",
      [](Articulation articulation, double altitude) { PlaceOnGround(articulation, altitude); },
      py::arg("articulation"), py::arg("altitude") = 0.0,
      "Moves the articulation's root so that its lowest point touches z = altitude.");
  py::class_<PartNetBatchEntry>(m, "PartNetBatchEntry")
      .def_readonly("folder", &PartNetBatchEntry::folder)
      .def_readonly("ok", &PartNetBatchEntry::ok)
      .def_readonly("error", &PartNetBatchEntry::error)
      .def_readonly("object", &PartNetBatchEntry::object);
  m.def("parse_partnet_mobility_batch", &ParsePartNetMobilityBatch, py::arg("root"),
        py::arg("loader"),
        "Parses every object folder under `root`; bad folders carry their error, the rest load.");

  // quality checks
  py::class_<QualityOptions>(m, "QualityOptions")
      .def(py::init<>())
      .def_readwrite("rest_seconds", &QualityOptions::rest_seconds)
      .def_readwrite("rest_tolerance", &QualityOptions::rest_tolerance)
      .def_readwrite("range_seconds", &QualityOptions::range_seconds)
      .def_readwrite("range_fraction", &QualityOptions::range_fraction)
      .def_readwrite("check_visibility", &QualityOptions::check_visibility)
      .def_readwrite("render_backend", &QualityOptions::render_backend)
      .def_readwrite("image_size", &QualityOptions::image_size);
  py::class_<QualityCheck>(m, "QualityCheck")
      .def_readonly("name", &QualityCheck::name)
      .def_readonly("passed", &QualityCheck::passed)
      .def_readonly("detail", &QualityCheck::detail);
  py::class_<ObjectQualityReport>(m, "ObjectQualityReport")
      .def_readonly("folder", &ObjectQualityReport::folder)
      .def_readonly("category", &ObjectQualityReport::category)
      .def_readonly("model_id", &ObjectQualityReport::model_id)
      .def_readonly("movable_parts", &ObjectQualityReport::movable_parts)
      .def_readonly("checks", &ObjectQualityReport::checks)
      .def("passed", &ObjectQualityReport::Passed)
      .def("__str__", &ObjectQualityReport::ToString);
  m.def("check_partnet_object", &CheckPartNetObject, py::arg("folder"),
        py::arg("options") = QualityOptions(), py::call_guard<py::gil_scoped_release>(),
        "Runs the quality checks (load, labels, rest, range, visible) on one folder.");
  m.def("paper_statistics", &PaperStatistics,
        "The SAPIEN paper's models and movable parts per category.");
}

}  // namespace partsim::python
