"""URDF loader and mesh files (assets bindings)."""

import os

import numpy as np
import pytest

import partsim
from conftest import CABINET_URDF, assert_vec

# a unit cube (8 vertices, 12 triangles) as OBJ text
CUBE_OBJ = "\n".join(
    ["v %d %d %d" % (x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)] +
    ["f 1 3 4", "f 1 4 2", "f 5 6 8", "f 5 8 7", "f 1 2 6", "f 1 6 5",
     "f 3 7 8", "f 3 8 4", "f 1 5 7", "f 1 7 3", "f 2 4 8", "f 2 8 6"]) + "\n"


@pytest.fixture
def cube_obj(tmp_path):
    path = tmp_path / "cube.obj"
    path.write_text(CUBE_OBJ)
    return str(path)


def test_load_from_string_dof_and_limits(scene):
    loader = scene.create_urdf_loader()
    assert loader.fix_root_link
    art = loader.load_from_string(CABINET_URDF, ".")
    assert art.dof == 2
    assert [j.name for j in art.get_active_joints()] == ["hinge", "slide"]
    np.testing.assert_allclose(art.get_qlimits(), [[-1.5, 0.5], [0.0, 0.3]])
    assert art.get_links()[0].name == "base"
    assert art.has_fixed_root()


def test_load_file_and_loader_attributes(scene, tmp_path):
    path = tmp_path / "cabinet.urdf"
    path.write_text(CABINET_URDF)
    loader = scene.create_urdf_loader()
    loader.fix_root_link = False
    loader.scale = 2.0
    loader.density = 500.0
    loader.load_multiple_collisions_from_file = True
    loader.material = partsim.PhysicalMaterial(1.0, 1.0, 0.0)
    loader.package_dirs = {"pkg": str(tmp_path)}
    loader.link_overrides = {"door": partsim.UrdfLinkOverride(density=100.0)}
    assert loader.link_overrides["door"].density == 100.0
    assert loader.package_dirs == {"pkg": str(tmp_path)}
    art = loader.load(str(path))
    assert not art.has_fixed_root()
    # scale applies to prismatic limits
    np.testing.assert_allclose(art.get_qlimits()[1], [0.0, 0.6])


def test_parse_without_scene():
    desc = partsim.UrdfLoader().parse(CABINET_URDF, ".")
    assert isinstance(desc, partsim.ArticulationDesc)
    assert desc.name == "cabinet"
    assert [l.name for l in desc.links] == ["base", "door", "drawer"]
    assert desc.links[1].joint.type == partsim.JointType.REVOLUTE
    assert desc.links[2].joint.upper == pytest.approx(0.3)
    scene = partsim.Scene()
    assert scene.add_articulation(desc).dof == 2


def test_bad_urdf_raises(scene):
    loader = scene.create_urdf_loader()
    with pytest.raises(partsim.PartsimError, match="my.urdf"):
        loader.parse("<robot name='x'><link name='a'/>", ".", "my.urdf")
    bad_parent = CABINET_URDF.replace('<parent link="base"/><child link="door"/>',
                                      '<parent link="nowhere"/><child link="door"/>')
    with pytest.raises(partsim.PartsimError, match="nowhere"):
        loader.load_from_string(bad_parent, ".")
    with pytest.raises(partsim.PartsimError):
        loader.load("/nonexistent/file.urdf")


def test_mesh_loading(cube_obj):
    meshes = partsim.load_mesh_file(cube_obj)
    assert len(meshes) == 1
    mesh = meshes[0].mesh
    assert isinstance(meshes[0].material, partsim.RenderMaterial)
    assert_vec(mesh.vertices, (mesh.vertices.shape[0], 3), np.float32)
    assert_vec(mesh.faces, (12, 3), np.int32)
    np.testing.assert_allclose(mesh.vertices.max(axis=0), [1, 1, 1])
    merged = partsim.load_merged_mesh(cube_obj, [2, 2, 2])
    np.testing.assert_allclose(merged.vertices.max(axis=0), [2, 2, 2])
    assert len(partsim.split_connected_components(merged)) == 1
    assert len(partsim.load_convex_pieces(cube_obj)) == 1
    with pytest.raises(partsim.PartsimError, match="missing.obj"):
        partsim.load_mesh_file("/nonexistent/missing.obj")


def test_mesh_data_from_numpy(scene):
    mesh = partsim.MeshData()
    mesh.vertices = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]], np.float32)
    mesh.faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], np.int32)
    assert mesh.vertices.shape == (4, 3) and mesh.faces.shape == (4, 3)
    assert mesh.normals.shape == (0, 3) and mesh.uvs.shape == (0, 2)
    builder = scene.create_actor_builder().add_convex_collision_from_mesh(mesh)
    assert builder.get_desc().collisions[0].type == partsim.ShapeType.CONVEX_MESH
    assert builder.get_desc().collisions[0].mesh.vertices.shape == (4, 3)
    assert builder.build().get_mass() > 0


def test_builders_from_files(scene, cube_obj):
    builder = scene.create_actor_builder()
    builder.add_convex_collision_from_file(cube_obj, partsim.Pose(), [0.1, 0.1, 0.1])
    builder.add_multiple_convex_collisions_from_file(cube_obj, scale=[0.1, 0.1, 0.1])
    builder.add_visual_from_file(cube_obj, scale=[0.1, 0.1, 0.1], name="cube")
    desc = builder.get_desc()
    assert len(desc.collisions) == 2
    assert all(c.type == partsim.ShapeType.CONVEX_MESH for c in desc.collisions)
    assert desc.visuals[0].mesh is not None
    assert builder.build().get_mass() == pytest.approx(2 * 1000 * 0.001, rel=1e-3)
    ab = scene.create_articulation_builder()
    root = ab.create_link_builder()
    root.add_convex_collision_from_file(cube_obj, scale=[0.1, 0.1, 0.1])
    root.add_visual_from_file(cube_obj, scale=[0.1, 0.1, 0.1])
    assert ab.build(fix_root_link=True).dof == 0


def test_loader_without_scene_cannot_load():
    with pytest.raises(partsim.PartsimError, match="no scene"):
        partsim.UrdfLoader().load_from_string(CABINET_URDF, ".")


# two fingers, the second mimicking the first, and a fixed joint that carries a <mimic> too
MIMIC_URDF = """<robot name="gripper">
  <link name="palm"><collision><geometry><box size="0.1 0.1 0.02"/></geometry></collision></link>
  <link name="left"><collision><geometry><box size="0.02 0.02 0.06"/></geometry></collision></link>
  <link name="right"><collision><geometry><box size="0.02 0.02 0.06"/></geometry></collision></link>
  <link name="tip"/>
  <joint name="left_joint" type="prismatic"><parent link="palm"/><child link="left"/>
    <origin xyz="0 0.03 0.05"/><axis xyz="0 1 0"/><limit lower="0" upper="0.04"/></joint>
  <joint name="right_joint" type="prismatic"><parent link="palm"/><child link="right"/>
    <origin xyz="0 -0.03 0.05"/><axis xyz="0 -1 0"/><limit lower="0" upper="0.04"/>
    <mimic joint="left_joint"/></joint>
  <joint name="tip_joint" type="fixed"><parent link="left"/><child link="tip"/>
    <mimic joint="left_joint"/></joint>
</robot>
"""


def test_strict_and_last_report(scene):
    loader = scene.create_urdf_loader()
    assert loader.strict is False
    assert len(loader.last_report()) == 0 and not loader.last_report()
    art = loader.load_from_string(MIMIC_URDF, ".")
    # the mimic joint is a dof of its own; the fixed joint's <mimic> is ignored with a warning
    assert art.dof == 2
    assert [j.name for j in art.get_active_joints()] == ["left_joint", "right_joint"]
    report = loader.last_report()
    assert len(report) == 1
    w = report.warnings[0]
    assert w.file == "<string>"
    assert "joint 'tip_joint'" in w.message and "<mimic>" in w.message
    assert str(w) == w.file + ": " + w.message
    assert w.message in str(report)
    # strict loading refuses what it would otherwise repair, and the scene is left as it was
    loader.strict = True
    with pytest.raises(partsim.PartsimError, match="tip_joint.*strict"):
        loader.load_from_string(MIMIC_URDF, ".")
    assert len(scene.get_articulations()) == 1
