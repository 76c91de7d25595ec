"""Robot models and URDF writing from Python: the binding surface (physics is tested in C++)."""

import os

import numpy as np
import pytest

import partsim


def test_flying_gripper_options_and_model(scene):
    options = partsim.FlyingGripperOptions()
    options.name = "hand"
    options.finger_travel = 0.04
    robot = partsim.build_flying_gripper(options=options)
    assert robot.articulation.name == "hand"
    assert robot.arm_joints == ["x", "y", "z", "yaw", "pitch", "roll"]
    assert robot.gripper_joints == ["left_finger_joint", "right_finger_joint"]
    assert robot.ee_link == "hand"
    assert robot.gripper_open == pytest.approx(0.04)
    assert len(robot.home) == len(robot.arm_velocity_limits) == len(robot.arm_effort_limits) == 6
    assert "hand" in repr(robot)

    art = scene.add_articulation(robot.articulation)
    assert art.dof == 8
    # at q = 0 the TCP frame is the root frame
    tcp = art.find_link_by_name(robot.ee_link).get_pose() * robot.tcp_in_ee
    np.testing.assert_allclose(tcp.p, [0, 0, 0], atol=1e-12)

    bad = partsim.FlyingGripperOptions()
    bad.finger_travel = -1
    with pytest.raises(partsim.PartsimError, match="finger_travel"):
        partsim.build_flying_gripper(bad)


def test_panda_flange_at_zero(scene):
    robot = partsim.build_panda(name="arm")
    assert robot.articulation.name == "arm"
    assert robot.arm_joints == ["panda_joint%d" % i for i in range(1, 8)]
    assert len(robot.home) == 7
    art = scene.add_articulation(robot.articulation)
    art.set_qpos(np.zeros(9))
    hand = art.find_link_by_name("panda_hand").get_pose()
    np.testing.assert_allclose(hand.p, [0.088, 0, 0.926], atol=1e-12)
    robot.home = [0.0] * 7
    assert robot.home == [0.0] * 7


def test_urdf_round_trip(scene, tmp_path):
    robot = partsim.build_panda()
    text = partsim.articulation_to_urdf(robot.articulation)
    assert "<partsim:drive" in text and "panda_joint7" in text
    path = str(tmp_path / "panda.urdf")
    partsim.write_urdf(articulation=robot.articulation, path=path)
    assert os.path.exists(path)
    loaded = scene.create_urdf_loader().load(path)
    original = scene.add_articulation(robot.articulation)
    q = np.array(robot.home + [0.02, 0.02])
    loaded.set_qpos(q)
    original.set_qpos(q)
    a = loaded.find_link_by_name("panda_hand").get_pose()
    b = original.find_link_by_name("panda_hand").get_pose()
    np.testing.assert_allclose(a.p, b.p, atol=1e-9)
    names = [j.get_name() for j in loaded.get_active_joints()]
    assert names == robot.arm_joints + robot.gripper_joints
    stiffness = [j.get_drive_stiffness() for j in loaded.get_active_joints()]
    assert stiffness == [j.get_drive_stiffness() for j in original.get_active_joints()]

    with pytest.raises(partsim.PartsimError, match="no_such_folder"):
        partsim.write_urdf(robot.articulation, "/no_such_folder/x/panda.urdf")
