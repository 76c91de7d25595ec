// Bindings of the assets subsystem: the URDF loader (and Scene.create_urdf_loader) and mesh files.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "partsim/assets/mesh.h"
#include "partsim/assets/urdf.h"
#include "partsim/physics/scene.h"

namespace partsim::python {

void BindAssets(py::module_& m) {
  const auto ka = py::keep_alive<0, 1>();

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
}

}  // namespace partsim::python
