"""PartNet-Mobility reader and quality checks from Python (the binding surface)."""
import json
import math
import os

import pytest

import partsim
from conftest import REPO


def box_obj(c, h):
    lines = []
    for i in range(8):
        v = [c[k] + (1 if (i >> k) & 1 else -1) * h[k] for k in range(3)]
        lines.append("v %f %f %f" % tuple(v))
    lines += ["f 1 3 4 2", "f 5 6 8 7", "f 1 2 6 5", "f 3 7 8 4", "f 1 5 7 3", "f 2 4 8 6"]
    return "\n".join(lines) + "\n"


URDF = """<?xml version="1.0"?>
<robot name="box">
  <link name="base"/>
  <link name="link_1">
    <visual name="body-1"><geometry><mesh filename="textured_objs/original-1.obj"/></geometry></visual>
    <collision><geometry><mesh filename="textured_objs/original-1.obj"/></geometry></collision>
  </link>
  <joint name="joint_1" type="fixed">
    <origin rpy="1.570796326794897 0 -1.570796326794897"/><parent link="base"/><child link="link_1"/>
  </joint>
  <link name="link_0">
    <visual name="lid-2"><geometry><mesh filename="textured_objs/original-2.obj"/></geometry></visual>
    <visual name="handle-3"><geometry><mesh filename="textured_objs/original-3.obj"/></geometry></visual>
    <collision><geometry><mesh filename="textured_objs/original-2.obj"/></geometry></collision>
  </link>
  <joint name="joint_0" type="revolute">
    <origin xyz="0 0.11 -0.1"/><axis xyz="-1 0 0"/>
    <parent link="link_1"/><child link="link_0"/>
    <limit lower="0" upper="1.7453292519943295"/>
  </joint>
</robot>
"""


def write_box(root, semantics_label="rotation_lid", semantics_kind="hinge"):
    d = root / "Box" / "100"
    (d / "textured_objs").mkdir(parents=True)
    (d / "mobility.urdf").write_text(URDF)
    entries = [
        {"id": 0, "parent": 1, "joint": "hinge", "name": "lid",
         "parts": [{"id": 2, "name": "lid", "children": []}, {"id": 3, "name": "handle", "children": []}],
         "jointData": {"axis": {"origin": [0, 0.11, -0.1], "direction": [1, 0, 0]},
                       "limit": {"a": -100, "b": 0, "noLimit": False}}},
        {"id": 1, "parent": -1, "joint": "heavy", "name": "box_body",
         "parts": [{"id": 1, "name": "body", "children": []}], "jointData": {}},
    ]
    (d / "mobility_v2.json").write_text(json.dumps(entries))
    (d / "semantics.txt").write_text(
        "link_0 %s %s\nlink_1 heavy box_body\n" % (semantics_kind, semantics_label)
    )
    (d / "meta.json").write_text(json.dumps({"model_cat": "Box", "model_id": "100"}))
    (d / "bounding_box.json").write_text(json.dumps({"min": [-0.1, -0.1, -0.1], "max": [0.1, 0.12, 0.1]}))
    # body: a floor (open box would be truer; a slab suffices), lid above it hinged at its back
    (d / "textured_objs/original-1.obj").write_text(box_obj([0, 0, 0], [0.1, 0.1, 0.1]))
    (d / "textured_objs/original-2.obj").write_text(box_obj([0, 0.005, 0.1], [0.1, 0.004, 0.1]))
    (d / "textured_objs/original-3.obj").write_text(box_obj([0, 0.015, 0.19], [0.03, 0.005, 0.005]))
    return d


def test_reader_gives_labels_axes_and_parts(tmp_path):
    folder = write_box(tmp_path)
    obj = partsim.PartNetMobilityLoader().parse(str(folder))
    assert obj.category == "Box" and obj.model_id == "100"
    lid = obj.link(0)
    assert lid.joint == "hinge" and lid.semantic_label == "rotation_lid"
    assert lid.partnet_name == "lid" and lid.semantic_joint == "hinge"
    assert [p.visuals for p in lid.parts] == [[0], [1]]
    assert lid.limit_a == -100
    assert [p.name for p in lid.parts] == ["lid", "handle"]
    assert obj.part_visuals(0, "handle") == [1]
    desc = obj.articulation.links[obj.link_index(0)]
    # the file's axis is +x with limits [-100, 0] deg; the URDF's is -x with [0, 100] deg
    assert desc.semantic_label == "rotation_lid" and desc.partnet_name == "lid"
    assert desc.joint.upper == pytest.approx(math.radians(100))
    assert len(obj.report) == 0 and obj.links_with_label("rotation_lid") == [0]

    scene = partsim.Scene()
    loader = scene.create_partnet_mobility_loader()
    art = loader.load(str(folder))
    assert not loader.last_report()
    assert art.dof == 1
    assert art.get_name() == "Box_100"
    lid_link = art.find_link_by_name("link_0")
    assert lid_link.get_semantic_label() == "rotation_lid"
    assert lid_link.get_partnet_name() == "lid"
    # standing on a plane at z = 0.5 (10 um clear of it): the body's slab spans 0.2 m about
    # the root
    partsim.place_on_ground(art, 0.5)
    assert art.get_root_pose().p[2] == pytest.approx(0.6 + 1e-5, abs=1e-7)


def test_disagreeing_folder_warns_and_strict_loading_raises(tmp_path):
    folder = write_box(tmp_path, semantics_kind="slider")
    loader = partsim.PartNetMobilityLoader()
    obj = loader.parse(str(folder))
    report = loader.last_report()
    assert len(report) == 1 and len(obj.report) == 1
    warning = report.warnings[0]
    assert warning.file.endswith("semantics.txt") and "link_0" in warning.message
    assert "semantics.txt" in str(report)
    loader.strict = True
    with pytest.raises(partsim.PartsimError, match="semantics.txt"):
        loader.parse(str(folder))
    (folder / "mobility_v2.json").write_text("[{")
    batch = partsim.parse_partnet_mobility_batch(str(tmp_path), partsim.PartNetMobilityLoader())
    assert len(batch) == 1 and not batch[0].ok and "mobility_v2.json" in batch[0].error


REAL = os.path.join(REPO, "..", "shared", "realdata", "partnet-mobility-3763")


@pytest.mark.skipif(not os.path.isdir(REAL), reason="no ../shared/realdata")
def test_real_object_loads_with_both_vocabularies():
    scene = partsim.Scene()
    loader = scene.create_partnet_mobility_loader()
    loader.urdf.fix_root_link = False
    art = loader.load(REAL)
    assert art.dof == 2
    lid = art.find_link_by_name("link_0")
    assert lid.get_semantic_label() == "rotation_lid" and lid.get_partnet_name() == "lid"
    assert any("continuous" in w.message for w in loader.last_report().warnings)
    # z-up: the cap slides along the world's vertical
    axis = art.find_joint_by_name("joint_2").get_global_axis()
    assert abs(axis[2]) == pytest.approx(1.0, abs=1e-9)


def test_quality_checks_report_each_check(tmp_path):
    folder = write_box(tmp_path)
    options = partsim.QualityOptions()
    options.check_visibility = False
    report = partsim.check_partnet_object(str(folder), options)
    assert [c.name for c in report.checks] == ["labels", "load", "rest", "range"]
    assert report.movable_parts == 1
    assert report.passed(), str(report)
    stats = partsim.paper_statistics()
    assert len(stats) == 46 and sum(m for m, _ in stats.values()) == 2346
