// A hand-written PartNet-Mobility folder for tests (docs/partnet_mobility_format.md), laid out
// as the real dataset is: mobility.urdf turns the y-up meshes z-up at the fixed joint from
// "base" to the body; mobility_v2.json (PartNet names) and semantics.txt (movable-part labels)
// speak two vocabularies. A cabinet with a hinged door (negative limit), a drawer and a body.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <fstream>
#include <string>

namespace partsim::testing {

namespace fs = std::filesystem;

// An axis-aligned box OBJ (outward faces) centred at c with half sizes h.
inline std::string BoxObj(Eigen::Vector3d c, Eigen::Vector3d h) {
  std::string s = "mtllib original.mtl\nusemtl wood\n";
  for (int i = 0; i < 8; ++i) {
    Eigen::Vector3d v = c + Eigen::Vector3d((i & 1 ? 1 : -1) * h.x(), (i & 2 ? 1 : -1) * h.y(),
                                            (i & 4 ? 1 : -1) * h.z());
    s += "v " + std::to_string(v.x()) + " " + std::to_string(v.y()) + " " + std::to_string(v.z()) +
         "\n";
  }
  s += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  return s;
}

inline void Write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

// The object, in the file's y-up frame: a body 0.6 wide (x), 0.8 tall (y), 0.4 deep (z, front
// at +z); a door hinged about the vertical (y) axis at its left edge, opening to negative
// angles; a drawer sliding out along +z.
struct Folder {
  fs::path dir;
  std::string urdf, json, semantics;

  explicit Folder(const std::string& name) : dir(fs::temp_directory_path() / "partsim_pm" / name) {
    fs::remove_all(dir);
    urdf = R"(<?xml version="1.0"?>
<robot name="cabinet">
  <link name="base"/>
  <link name="link_2">
    <visual name="body-1"><geometry><mesh filename="textured_objs/original-1.obj"/></geometry></visual>
    <collision><geometry><mesh filename="textured_objs/original-1.obj"/></geometry></collision>
  </link>
  <joint name="joint_2" type="fixed">
    <origin rpy="1.570796326794897 0 -1.570796326794897" xyz="0 0 0"/>
    <parent link="base"/><child link="link_2"/>
  </joint>
  <link name="link_0">
    <visual name="door-2"><geometry><mesh filename="textured_objs/original-2.obj"/></geometry></visual>
    <visual name="handle-3"><geometry><mesh filename="textured_objs/original-3.obj"/></geometry></visual>
    <collision><geometry><mesh filename="textured_objs/original-2.obj"/></geometry></collision>
  </link>
  <joint name="joint_0" type="revolute">
    <origin xyz="-0.3 0.2 0.21"/><axis xyz="0 1 0"/>
    <parent link="link_2"/><child link="link_0"/>
    <limit lower="-1.5707963267948966" upper="0" effort="10" velocity="1"/>
  </joint>
  <link name="link_1">
    <visual name="drawer-4"><geometry><mesh filename="textured_objs/original-4.obj"/></geometry></visual>
    <collision><geometry><mesh filename="textured_objs/original-4.obj"/></geometry></collision>
  </link>
  <joint name="joint_1" type="prismatic">
    <origin xyz="0 -0.2 0"/><axis xyz="0 0 1"/>
    <parent link="link_2"/><child link="link_1"/>
    <limit lower="0" upper="0.3" effort="10" velocity="1"/>
  </joint>
</robot>
)";
    json = R"([
 {"id": 0, "parent": 2, "joint": "hinge", "name": "cabinet_door",
  "parts": [{"id": 2, "name": "door", "children": []}, {"id": 3, "name": "handle", "children": []}],
  "jointData": {"axis": {"origin": [-0.3, 0.5, 0.21], "direction": [0, 1, 0]},
                "limit": {"a": -90, "b": 0, "noLimit": false}}},
 {"id": 1, "parent": 2, "joint": "slider", "name": "drawer",
  "parts": [{"id": 4, "name": "drawer", "children": []}],
  "jointData": {"axis": {"origin": [0, 0, 0], "direction": [0, 0, 1]},
                "limit": {"a": 0, "b": 0.3, "noLimit": false, "rotates": false}}},
 {"id": 2, "parent": -1, "joint": "heavy", "name": "cabinet_frame",
  "parts": [{"id": 1, "name": "body", "children": []}], "jointData": {}}
])";
    semantics = "link_0 hinge rotation_door\nlink_1 slider drawer\nlink_2 heavy furniture_body\n";
    WriteAll();
  }

  void WriteAll() const {
    Write(dir / "mobility.urdf", urdf);
    Write(dir / "mobility_v2.json", json);
    Write(dir / "semantics.txt", semantics);
    Write(dir / "meta.json",
          R"({"model_cat": "StorageFurniture", "model_id": "9001", "anno_id": "a1"})");
    Write(dir / "bounding_box.json", R"({"min": [-0.3, -0.4, -0.2], "max": [0.3, 0.4, 0.22]})");
    Write(dir / "textured_objs/original.mtl", "newmtl wood\nKd 0.6 0.4 0.2\n");
    // body is a shell behind the door (three boxes would be more real; one thin back is enough)
    Write(dir / "textured_objs/original-1.obj", BoxObj({0, 0, -0.19}, {0.3, 0.4, 0.01}));
    Write(dir / "textured_objs/original-2.obj", BoxObj({0.15, 0.2, 0.0}, {0.14, 0.19, 0.005}));
    Write(dir / "textured_objs/original-3.obj", BoxObj({0.25, 0.2, 0.02}, {0.01, 0.05, 0.01}));
    Write(dir / "textured_objs/original-4.obj", BoxObj({0, -0.0, 0.0}, {0.25, 0.1, 0.15}));
  }
  std::string Path() const { return dir.string(); }
};

}  // namespace partsim::testing
