"""Collision filtering from Python: SAPIEN-style collision groups on builders and shapes,
articulation.disable_collision and UrdfLoader.srdf_file (the physics is tested in C++)."""

import pytest

import partsim

ALL = 0xFFFFFFFF


def stacked_boxes(lower_groups=None, upper_groups=None):
    """A box resting on the ground and another just above it; groups given to the builders as a
    list (lower) and as four ints (upper)."""
    scene = partsim.Scene()
    scene.add_ground(0)
    boxes = []
    for name, z, groups in (("lower", 0.1, lower_groups), ("upper", 0.31, upper_groups)):
        b = scene.create_actor_builder().set_name(name)
        b.add_box_collision(half_size=[0.1, 0.1, 0.1])
        if groups is not None:
            if name == "lower":
                b.set_collision_groups(groups)
            else:
                b.set_collision_groups(*groups)
        boxes.append(b.set_initial_pose(partsim.Pose([0, 0, z])).build())
    return scene, boxes[0], boxes[1]


def test_builder_groups_as_a_list_or_four_ints():
    scene, lower, upper = stacked_boxes()
    scene.step(300)
    assert upper.get_pose().p[2] == pytest.approx(0.3, abs=0.01)

    # g2 shares a bit and g3 is equal: ignored, the upper box sinks to the ground
    scene, lower, upper = stacked_boxes([1, ALL, 4, 7], [1, ALL, 6, 7])
    assert lower.get_collision_shapes()[0].get_collision_groups() == [1, ALL, 4, 7]
    assert upper.get_desc().collisions[0].collision_groups == [1, ALL, 6, 7]
    scene.step(300)
    assert upper.get_pose().p[2] == pytest.approx(0.1, abs=0.01)

    # different g3: they collide
    scene, _, upper = stacked_boxes([1, ALL, 4, 7], [1, ALL, 4, 8])
    scene.step(300)
    assert upper.get_pose().p[2] == pytest.approx(0.3, abs=0.01)


def test_shape_groups_at_run_time():
    scene, lower, upper = stacked_boxes()
    shapes = upper.get_collision_shapes()
    assert len(shapes) == 1 and shapes[0].get_index() == 0
    assert shapes[0].get_collision_groups() == [1, ALL, 0, 0]
    assert shapes[0].get_desc().type == partsim.ShapeType.BOX
    # g0 / g1 disjoint both ways (SAPIEN 3 list, then SAPIEN 2 four ints)
    lower.get_collision_shapes()[0].set_collision_groups([1, 1, 0, 0])
    shapes[0].set_collision_groups(2, 2, 0, 0)
    assert upper.get_collision_shapes()[0].get_collision_groups() == [2, 2, 0, 0]
    scene.step(300)
    assert upper.get_pose().p[2] == pytest.approx(0.1, abs=0.01)
    with pytest.raises(TypeError):
        shapes[0].set_collision_groups([1, 2, 3])
    with pytest.raises(TypeError):
        shapes[0].set_collision_groups([-1, 0, 0, 0])


def test_link_shapes_and_link_builder_groups():
    scene = partsim.Scene()
    b = scene.create_articulation_builder()
    root = b.create_link_builder()
    root.add_box_collision(half_size=[0.1, 0.1, 0.1]).set_collision_groups([1, 1, 2, 3])
    art = b.build(fix_root_link=True)
    shape = art.get_links()[0].get_collision_shapes()[0]
    assert shape.get_collision_groups() == [1, 1, 2, 3]
    desc = partsim.CollisionShape()
    desc.collision_groups = [5, 6, 7, 8]
    assert desc.collision_groups == [5, 6, 7, 8]


# An arm whose tip hangs from its second link and reaches into the fixed base: two moving joints
# apart, they collide unless disabled.
ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"><collision><geometry><box size="0.4 0.4 0.1"/></geometry></collision></link>
  <link name="column"><collision><origin xyz="0 0 0.1"/><geometry><box size="0.04 0.04 0.2"/></geometry></collision></link>
  <link name="upper"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.04 0.04 0.1"/></geometry></collision></link>
  <link name="tip"><collision><origin xyz="0 0 -0.04"/><geometry><box size="0.06 0.06 0.12"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="column"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="100" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="column"/><child link="upper"/><origin xyz="0 0 0.2"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="100" velocity="1"/></joint>
  <joint name="tip_joint" type="fixed"><parent link="upper"/><child link="tip"/><origin xyz="0.1 0 -0.2"/></joint>
</robot>
"""


def base_tip_contacts(scene):
    return [c for c in scene.get_contacts() if {c.body0.name, c.body1.name} == {"base", "tip"}]


def test_disable_collision():
    scene = partsim.Scene(gravity=[0, 0, 0])
    arm = scene.create_urdf_loader().load_from_string(ARM)
    scene.step(20)
    assert base_tip_contacts(scene)
    q = arm.get_qpos()
    arm.disable_collision(arm.find_link_by_name("base"), arm.find_link_by_name("tip"))
    assert (arm.get_qpos() == q).all()
    assert arm.get_desc().disabled_collisions == [("base", "tip")]
    scene.step(20)
    assert not base_tip_contacts(scene)


def test_srdf_file(tmp_path):
    srdf = tmp_path / "arm.srdf"
    srdf.write_text('<robot name="arm">\n'
                    '  <disable_collisions link1="tip" link2="base" reason="Never"/>\n'
                    '  <disable_collisions link1="tip" link2="gripper" reason="Never"/>\n'
                    '</robot>\n')
    scene = partsim.Scene(gravity=[0, 0, 0])
    loader = scene.create_urdf_loader()
    assert loader.srdf_file == ""
    loader.srdf_file = str(srdf)
    arm = loader.load_from_string(ARM)
    assert arm.get_desc().disabled_collisions == [("tip", "base")]
    warnings = loader.last_report().warnings
    assert len(warnings) == 1 and "'gripper'" in warnings[0].message
    scene.step(20)
    assert not base_tip_contacts(scene)
