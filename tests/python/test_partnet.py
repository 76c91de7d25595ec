"""PartNet-Mobility reader and quality checks from Python (the binding surface)."""
import json
import math

import pytest

import partsim


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
  <joint name="joint_1" type="fixed"><parent link="base"/><child link="link_1"/></joint>
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


def write_box(root, semantics_label="lid"):
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
    (d / "semantics.txt").write_text("link_0 hinge %s\nlink_1 heavy box_body\n" % semantics_label)
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
    assert lid.joint == "hinge" and lid.semantic_label == "lid"
    assert lid.limit_a == -100
    assert [p.name for p in lid.parts] == ["lid", "handle"]
    assert obj.part_visuals(0, "handle") == [1]
    desc = obj.articulation.links[obj.link_index(0)]
    # the file's axis is +x with limits [-100, 0] deg; the URDF's is -x with [0, 100] deg
    assert desc.semantic_label == "lid"
    assert desc.joint.upper == pytest.approx(math.radians(100))

    scene = partsim.Scene()
    art = scene.create_partnet_mobility_loader().load(str(folder))
    assert art.dof == 1
    assert art.get_name() == "Box_100"


def test_inconsistent_folder_raises_naming_the_file(tmp_path):
    folder = write_box(tmp_path, semantics_label="door")
    with pytest.raises(partsim.PartsimError, match="semantics.txt"):
        partsim.PartNetMobilityLoader().parse(str(folder))
    batch = partsim.parse_partnet_mobility_batch(str(tmp_path), partsim.PartNetMobilityLoader())
    assert len(batch) == 1 and not batch[0].ok and "semantics.txt" in batch[0].error


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
