// Bindings of the assets subsystem: the URDF loader (and Scene.create_urdf_loader) and mesh files.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <string>

#include "bindings.h"
#include "partsim/assets/default_objects.h"
#include "partsim/assets/mesh.h"
#include "partsim/assets/partnet_mobility.h"
#include "partsim/assets/quality.h"
#include "partsim/assets/urdf.h"
#include "partsim/physics/scene.h"
#include "partsim/render/visibility.h"

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
           py::arg("density") = py::none(), py::arg("material") = py::none(),
           "Overrides with a density (kg/m^3) and a PhysicalMaterial; None keeps the loader's.")
      .def_readwrite("density", &UrdfLinkOverride::density,
                     "kg/m^3 for the link's collision shapes, or None.")
      .def_readwrite("material", &UrdfLinkOverride::material, "PhysicalMaterial or None.");

  py::class_<UrdfLoader>(
      m, "UrdfLoader",
      "Loads URDF files (SAPIEN's URDFLoader). Get one from Scene.create_urdf_loader(); one "
      "made with UrdfLoader() has no scene and can only parse. Dict attributes are copies: "
      "assign a whole dict to change them.")
      .def(py::init<>(), "A loader without a scene: parse and parse_file only.")
      .def_readwrite("fix_root_link", &UrdfLoader::fix_root_link,
                     "True (default): the root link is welded to the world; False: a free "
                     "root.")
      .def_readwrite("scale", &UrdfLoader::scale,
                     "Uniform scale on geometry, origins and prismatic limits.")
      .def_readwrite("load_multiple_collisions_from_file",
                     &UrdfLoader::load_multiple_collisions_from_file,
                     "Each mesh file (and each connected component) becomes its own convex piece.")
      .def_readwrite("load_collisions", &UrdfLoader::load_collisions,
                     "True (default); False skips every <collision> element: for scenes that are "
                     "only rendered, which load faster and hold no contact shapes.")
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
      .def("parse_file", &UrdfLoader::ParseFile, py::arg("path"),
           "Parses a URDF file into an ArticulationDesc without adding it to a scene; relative "
           "mesh paths resolve from the file's folder. Raises PartsimError naming the file and "
           "element at fault.")
      .def("load", &UrdfLoader::Load, py::arg("path"), ka,
           "Parses a URDF file and adds it to the scene; returns the Articulation. Raises "
           "PartsimError naming the file and element at fault, or when the loader has no "
           "scene.")
      .def("load_from_string", &UrdfLoader::LoadFromString, py::arg("text"),
           py::arg("base_dir") = ".", ka, "Parses URDF text and adds it to the scene.");

  py::class_<Scene, std::shared_ptr<Scene>>(m.attr("Scene"))
      .def("create_urdf_loader", &CreateUrdfLoader, ka,
           "A UrdfLoader whose load() adds to this scene.");

  py::class_<LoadedMesh>(m, "LoadedMesh", "One sub-mesh of a file with its render material.")
      .def(py::init<>())
      .def_readwrite("mesh", &LoadedMesh::mesh,
                     "MeshData: vertices in metres (scale applied), node transforms applied.")
      .def_readwrite("material", &LoadedMesh::material,
                     "RenderMaterial of the sub-mesh from the file's materials.");

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
      .def_readonly("id", &PartNetPart::id,
                    "The part's id in mobility_v2.json; its visuals are named '<name>-<id>'.")
      .def_readonly("name", &PartNetPart::name, "PartNet part name, e.g. 'handle'.")
      .def_readonly("visuals", &PartNetPart::visuals,
                    "Indices of the part's visuals in its link's visuals.");
  py::class_<PartNetLink>(m, "PartNetLink",
                          "One entry of mobility_v2.json: a link's motion, axis (file frame, "
                          "y-up), limits (degrees for hinges, metres for sliders) and parts.")
      .def_readonly("id", &PartNetLink::id, "N of link_N.")
      .def_readonly("parent", &PartNetLink::parent,
                    "Id of the parent link_M, -1 for the body on 'base'.")
      .def_readonly("joint", &PartNetLink::joint,
                    "mobility_v2.json motion: hinge, slider, free, heavy or static.")
      .def_readonly("semantic_label", &PartNetLink::semantic_label,
                    "semantics.txt label ('drawer', 'rotation_door', ...).")
      .def_readonly("semantic_joint", &PartNetLink::semantic_joint,
                    "semantics.txt joint kind: hinge, slider, slider+, free, heavy, static.")
      .def_readonly("partnet_name", &PartNetLink::partnet_name,
                    "mobility_v2.json name, the PartNet vocabulary ('cabinet_door', ...).")
      .def_readonly("parts", &PartNetLink::parts, "list of PartNetPart on this link.")
      .def_readonly("has_axis", &PartNetLink::has_axis,
                    "True when the entry gives a joint axis (hinges and sliders).")
      .def_readonly("axis_origin", &PartNetLink::axis_origin,
                    "A point (3,) on the axis, metres, in the file frame F (y-up).")
      .def_readonly("axis_direction", &PartNetLink::axis_direction,
                    "Unit axis direction (3,) in the file frame F (y-up).")
      .def_readonly("limit_a", &PartNetLink::limit_a,
                    "One end of the range as in the file: degrees (hinge) or metres (slider); "
                    "the range is [min(limit_a, limit_b), max(limit_a, limit_b)].")
      .def_readonly("limit_b", &PartNetLink::limit_b,
                    "The other end of the range: degrees (hinge) or metres (slider).")
      .def_readonly("no_limit", &PartNetLink::no_limit,
                    "True for a hinge without limits (mobility_v2.json's noLimit).")
      .def_readonly("rotates", &PartNetLink::rotates,
                    "True for a slider that also turns about its axis (a screw cap).")
      .def_readonly("no_rotation_limit", &PartNetLink::no_rotation_limit,
                    "True when a turning slider's rotation is unlimited.")
      .def_readonly("rotation_limit", &PartNetLink::rotation_limit,
                    "A turning slider's rotation range [0, rotation_limit], degrees.");
  py::class_<PartNetMobilityObject>(m, "PartNetMobilityObject",
                                    "A parsed PartNet-Mobility folder: its articulation "
                                    "(mobility.urdf as it is: z-up, root 'base') and its "
                                    "annotations (frame X_BF, y-up).")
      .def_readonly("folder", &PartNetMobilityObject::folder, "The object's folder.")
      .def_readonly("category", &PartNetMobilityObject::category,
                    "meta.json's model_cat, e.g. 'StorageFurniture' ('' when meta.json is "
                    "missing).")
      .def_readonly("model_id", &PartNetMobilityObject::model_id,
                    "The dataset's model id (the folder name, e.g. '45135').")
      .def_readonly("articulation", &PartNetMobilityObject::articulation,
                    "ArticulationDesc of mobility.urdf (z-up, root link 'base').")
      .def_readonly("links", &PartNetMobilityObject::links,
                    "list of PartNetLink: the mobility_v2.json entries, in id order.")
      .def_readonly("bbox_min", &PartNetMobilityObject::bbox_min,
                    "Lower corner (3,) of the bounds at rest in the annotation frame F, metres.")
      .def_readonly("bbox_max", &PartNetMobilityObject::bbox_max,
                    "Upper corner (3,) of the bounds at rest in the annotation frame F, metres.")
      .def_readonly("X_BF", &PartNetMobilityObject::X_BF,
                    "The annotation files' frame F (y-up) in the root link 'base'.")
      .def_readonly("report", &PartNetMobilityObject::report, "What the reader worked around.")
      .def("links_with_label", &PartNetMobilityObject::LinksWithLabel, py::arg("label"),
           "link ids whose semantics label is `label` (e.g. 'drawer').")
      .def("link", &PartNetMobilityObject::Link, py::arg("id"), py::return_value_policy::copy,
           "The mobility_v2.json entry of link_<id>; raises PartsimError if there is none.")
      .def("link_index", &PartNetMobilityObject::LinkIndex, py::arg("id"),
           "Index of link_<id> in the articulation; raises PartsimError if there is none.")
      .def("part_visuals", &PartNetMobilityObject::PartVisuals, py::arg("id"), py::arg("part_name"),
           "Indices of the visuals of part `part_name` on link_<id> (e.g. its handle).");
  py::class_<PartNetMobilityLoader>(
      m, "PartNetMobilityLoader",
      "Reads PartNet-Mobility folders. Get one from Scene.create_partnet_mobility_loader(); one "
      "made with PartNetMobilityLoader() can only parse. `urdf` holds the URDF options.")
      .def(py::init<>(), "A loader without a scene: parse only.")
      .def_readwrite("urdf", &PartNetMobilityLoader::urdf,
                     "UrdfLoader holding the options for mobility.urdf (scale, density, "
                     "material, fix_root_link, load_multiple_collisions_from_file).")
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
          [](Scene& scene) { return PartNetMobilityLoader(&scene); }, ka,
          "A PartNetMobilityLoader whose load() adds to this scene.");
  m.def(
      "make_cabinet_urdf",
      [](double height, double width, double depth, double drawer_travel, double door_limit,
         bool door_hinge_left, std::uint32_t seed, const std::string& name) {
        CabinetOptions o;
        o.height = height;
        o.width = width;
        o.depth = depth;
        o.drawer_travel = drawer_travel;
        o.door_limit = door_limit;
        o.door_hinge_left = door_hinge_left;
        o.seed = seed;
        o.name = name;
        return MakeCabinetUrdf(o);
      },
      py::arg("height") = CabinetOptions().height, py::arg("width") = CabinetOptions().width,
      py::arg("depth") = CabinetOptions().depth,
      py::arg("drawer_travel") = CabinetOptions().drawer_travel,
      py::arg("door_limit") = CabinetOptions().door_limit, py::arg("door_hinge_left") = false,
      py::arg("seed") = 0, py::arg("name") = "cabinet",
      "The built-in cabinet (the CLI's default object) as a URDF string: links 'body', "
      "'drawer_0' (prismatic joint 'drawer_0_joint' along +x, 0 to drawer_travel m) and 'door_0' "
      "(revolute 'door_0_joint', 0 to door_limit rad), boxes and cylinders only, with explicit "
      "inertials. Sizes in metres: its frame is the centre of its bottom face, x out of the "
      "front, z up. A non-zero seed varies the sizes within +-15% and picks the hinge side. "
      "Load it with scene.create_urdf_loader().load_from_string(urdf, '.'); raises PartsimError "
      "naming an option out of range.");
  m.def("standing_root_pose", &StandingRootPose, py::arg("articulation"), py::arg("altitude") = 0.0,
        "Root pose that makes the articulation stand on z = altitude at its current joint "
        "positions (orientation and x, y kept), its lowest point 10 micrometres clear of it.");
  m.def(
      "place_on_ground",
      [](Articulation articulation, double altitude) { PlaceOnGround(articulation, altitude); },
      py::arg("articulation"), py::arg("altitude") = 0.0,
      "Moves the articulation's root so that it stands on z = altitude (its lowest point 10 "
      "micrometres clear of it).");
  py::class_<PartNetBatchEntry>(m, "PartNetBatchEntry",
                                "One folder of parse_partnet_mobility_batch: its object, or the "
                                "error that stopped it.")
      .def_readonly("folder", &PartNetBatchEntry::folder, "The object folder.")
      .def_readonly("ok", &PartNetBatchEntry::ok, "True when the folder parsed.")
      .def_readonly("error", &PartNetBatchEntry::error,
                    "The error message when ok is False, else ''.")
      .def_readonly("object", &PartNetBatchEntry::object,
                    "The PartNetMobilityObject when ok is True.");
  m.def("parse_partnet_mobility_batch", &ParsePartNetMobilityBatch, py::arg("root"),
        py::arg("loader"),
        "Parses every object folder under `root`; bad folders carry their error, the rest load.");

  // quality checks
  py::class_<QualityOptions>(m, "QualityOptions", "Settings of check_partnet_object.")
      .def(py::init<>(), "The defaults.")
      .def_readwrite("rest_seconds", &QualityOptions::rest_seconds,
                     "Simulated time (s) the object rests undriven (default 1).")
      .def_readwrite("rest_tolerance", &QualityOptions::rest_tolerance,
                     "Largest joint motion allowed at rest, rad or m (default 2e-3).")
      .def_readwrite("range_seconds", &QualityOptions::range_seconds,
                     "Simulated time (s) to drive a part to each limit (default 1).")
      .def_readwrite("range_fraction", &QualityOptions::range_fraction,
                     "Fraction of its range a part must cover each way (default 0.95).")
      .def_readwrite("check_visibility", &QualityOptions::check_visibility,
                     "Render segmentation from several viewpoints to check that each movable "
                     "part shows (default True).")
      .def_readwrite("render_backend", &QualityOptions::render_backend,
                     "Backend of the visibility views: 'rasterizer' (default), 'pathtracer' "
                     "or 'null'.")
      .def_readwrite("image_size", &QualityOptions::image_size,
                     "Pixels per side of the visibility views (default 96).");
  py::class_<QualityCheck>(m, "QualityCheck", "The outcome of one quality check.")
      .def_readonly("name", &QualityCheck::name,
                    "Which check: 'load', 'labels', 'rest', 'range' or 'visible'.")
      .def_readonly("passed", &QualityCheck::passed, "True when the check passed.")
      .def_readonly("detail", &QualityCheck::detail, "What was found, in words.");
  py::class_<ObjectQualityReport>(m, "ObjectQualityReport",
                                  "The quality checks of one PartNet-Mobility object.")
      .def_readonly("folder", &ObjectQualityReport::folder, "The object folder.")
      .def_readonly("category", &ObjectQualityReport::category,
                    "meta.json's model_cat ('' when unknown).")
      .def_readonly("model_id", &ObjectQualityReport::model_id, "The dataset's model id.")
      .def_readonly("movable_parts", &ObjectQualityReport::movable_parts,
                    "Number of links with a hinge or slider motion.")
      .def_readonly("checks", &ObjectQualityReport::checks, "list of QualityCheck, in run order.")
      .def("passed", &ObjectQualityReport::Passed,
           "True when there is at least one check and every check passed.")
      .def("__str__", &ObjectQualityReport::ToString);
  m.def(
      "check_partnet_object",
      [](const std::string& folder, QualityOptions options) {
        // the visibility check renders through the render layer's finder
        if (options.check_visibility && !options.hidden_parts)
          options.hidden_parts =
              HiddenMovingLinksFinder(options.render_backend, options.image_size);
        return CheckPartNetObject(folder, options);
      },
      py::arg("folder"), py::arg("options") = QualityOptions(),
      py::call_guard<py::gil_scoped_release>(),
      "Runs the quality checks (load, labels, rest, range, visible) on one folder and "
      "returns an ObjectQualityReport; never raises for a bad object (the failure is in the "
      "report). Releases the GIL.");
  m.def("paper_statistics", &PaperStatistics,
        "The SAPIEN paper's models and movable parts per category.");
}

}  // namespace partsim::python
