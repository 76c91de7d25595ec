"""Kinematics, IK, trajectories, controllers and the IMU (control bindings): the binding
surface and a few smoke tests; the behaviour itself is tested in C++ (tests/robot)."""

import gc
import math

import numpy as np
import pytest

import partsim
from conftest import assert_vec, build_box

X_TO_Z = [math.cos(-math.pi / 4), 0, math.sin(-math.pi / 4), 0]  # wxyz: the x axis onto z


def planar_arm(scene, l1=0.5, l2=0.4):
    """Two revolute joints about z (tip at l1 cos q1 + l2 cos(q1 + q2), ...) and a tip link."""
    b = scene.create_articulation_builder()
    b.set_name("planar")
    base = b.create_link_builder()
    base.set_name("base")
    upper = b.create_link_builder(base)
    upper.set_name("upper").set_joint_name("shoulder")
    upper.set_joint_properties("revolute", [-3, 3], partsim.Pose([0, 0, 0], X_TO_Z),
                               partsim.Pose([0, 0, 0], X_TO_Z))
    upper.add_capsule_collision(partsim.Pose([l1 / 2, 0, 0]), 0.02, l1 / 2 - 0.03)
    fore = b.create_link_builder(upper)
    fore.set_name("fore").set_joint_name("elbow")
    fore.set_joint_properties("revolute", [-3, 3], partsim.Pose([l1, 0, 0], X_TO_Z),
                              partsim.Pose([0, 0, 0], X_TO_Z))
    fore.add_capsule_collision(partsim.Pose([l2 / 2, 0, 0]), 0.02, l2 / 2 - 0.03)
    tip = b.create_link_builder(fore)
    tip.set_name("tip").set_joint_name("tip_joint")
    tip.set_joint_properties("fixed", [0, 0], partsim.Pose([l2, 0, 0]), partsim.Pose())
    tip.set_mass_and_inertia(0.01, partsim.Pose(), [1e-5] * 3)
    return b.build(fix_root_link=True)


def test_kinematics_and_ik():
    scene = partsim.Scene()
    arm = planar_arm(scene)
    model = partsim.KinematicModel.from_articulation(arm)
    assert model.dof() == 2 and model.num_links() == 4
    tip = model.link_index("tip")
    q = np.array([0.4, -1.1])
    pose = model.link_pose(q, tip)
    assert pose.p[0] == pytest.approx(0.5 * math.cos(0.4) + 0.4 * math.cos(-0.7))
    poses = model.forward_kinematics(q)
    assert len(poses) == 4
    arm.set_qpos(q)
    np.testing.assert_allclose(poses[tip].p, arm.get_links()[tip].get_pose().p, atol=1e-9)
    jac = model.jacobian(q, tip)
    assert_vec(jac, (6, 2))
    np.testing.assert_allclose(jac, arm.compute_link_jacobian(tip), atol=1e-9)
    assert_vec(model.limits(), (2, 2))

    options = partsim.IkOptions()
    options.position_only = True
    result = partsim.inverse_kinematics(model, tip, pose, np.array([0.1, -0.5]), options)
    assert result.success and bool(result)
    assert_vec(result.q, (2,))
    assert result.position_error <= options.position_tolerance
    far = partsim.inverse_kinematics(model, tip, partsim.Pose([3, 0, 0]), np.zeros(2), options)
    assert not far.success and "out of reach" in far.message
    with pytest.raises(partsim.PartsimError):
        partsim.inverse_kinematics(model, tip, pose, np.zeros(3))
    err = partsim.pose_error(partsim.Pose(), partsim.Pose([1, 0, 0]))
    assert_vec(err, (6,))
    np.testing.assert_allclose(err, [1, 0, 0, 0, 0, 0])


def test_trajectories():
    path = [np.zeros(2), np.array([1.0, 0.5]), np.array([0.0, 1.0])]
    traj = partsim.time_parameterize(path, np.array([1.0, 1.0]), np.array([2.0, 2.0]))
    assert len(traj.times) == 3 and traj.duration() > 0
    traj.validate(2)
    q, qd, qdd = traj.sample(traj.times[1])
    np.testing.assert_allclose(q, path[1], atol=1e-9)
    _, qd_end, _ = traj.sample(traj.duration())
    np.testing.assert_allclose(qd_end, 0, atol=1e-12)
    t = partsim.JointTrajectory()
    t.times = [0.0, 1.0]
    t.positions = [np.zeros(1), np.ones(1)]
    q, _, _ = t.sample(0.5)
    assert q[0] == pytest.approx(0.5)
    # a sampler gives the same values, fitted once
    t.times = [0.0, 0.4, 1.0]
    t.positions = [np.zeros(1), np.array([0.7]), np.ones(1)]
    sampler = partsim.TrajectorySampler(t)
    for time in (-1.0, 0.0, 0.2, 0.4, 0.77, 1.0, 2.0):
        for mine, theirs in zip(sampler.sample(time), t.sample(time)):
            assert np.array_equal(mine, theirs)
    assert sampler.trajectory.times == t.times
    with pytest.raises(partsim.PartsimError, match="no valid waypoints"):
        partsim.TrajectorySampler(partsim.JointTrajectory())
    with pytest.raises(partsim.PartsimError, match="waypoint"):
        t.times = [0.0, 0.0]
        t.positions = [np.zeros(1), np.ones(1)]
        t.validate(1)
    with pytest.raises(partsim.PartsimError):
        partsim.time_parameterize([], np.ones(1), np.ones(1))


def test_position_controller_and_loop():
    scene = partsim.Scene()
    arm = planar_arm(scene)
    options = partsim.JointControllerOptions()
    options.control_rate = 100
    ctrl = partsim.JointPositionController(arm, [], options)
    assert ctrl.period() == 5
    assert ctrl.get_joint_names() == ["shoulder", "elbow"]
    assert ctrl.status.state == partsim.ControllerState.IDLE
    loop = partsim.ControlLoop(scene)
    loop.add(ctrl)
    ctrl.set_target(np.array([0.5, -0.4]))
    assert loop.run_until_done(3.0), ctrl.get_status()
    np.testing.assert_allclose(arm.get_qpos(), [0.5, -0.4], atol=1e-2)
    ctrl.set_target(np.array([5.0, 0.0]))  # beyond the limit: clamped, failed
    assert ctrl.get_status().state == partsim.ControllerState.FAILED
    assert "shoulder" in ctrl.get_status().message
    with pytest.raises(partsim.PartsimError):
        ctrl.set_target(np.array([np.nan, 0.0]))
    with pytest.raises(partsim.PartsimError):
        partsim.JointPositionController(arm, ["nope"])
    loop.step(10)


def test_other_controllers_construct_and_run():
    scene = partsim.Scene()
    arm = planar_arm(scene)
    loop = partsim.ControlLoop(scene)
    vel = partsim.JointVelocityController(arm, ["shoulder"])
    loop.add(vel)
    vel.set_target(np.array([0.3]))
    loop.step(100)
    loop.remove(vel)
    traj = partsim.JointTrajectoryController(arm, [])
    traj.path_tolerance = 0.2
    loop.add(traj)
    traj.set_path([arm.get_qpos(), np.array([0.2, 0.3])], np.ones(2), np.ones(2))
    assert loop.run_until_done(5.0), traj.get_status()
    loop.remove(traj)
    ee = partsim.EndEffectorController(arm, [], "tip", partsim.Pose())
    ee.ik.position_only = True
    loop.add(ee)
    ee.set_target_pose(partsim.Pose([3, 0, 0]))
    assert ee.get_status().state == partsim.ControllerState.FAILED
    ee.set_target_twist(np.zeros(6), partsim.ControlFrame.BASE)
    assert isinstance(ee.get_end_effector_pose(), partsim.Pose)
    effort = partsim.JointEffortController(arm)
    effort.set_target(np.array([0.0, 0.0]))
    assert effort.get_status().state == partsim.ControllerState.REACHED


@pytest.mark.parametrize("name, value, printed", [
    ("control_rate", -100.0, "-100"), ("stiffness", -1.0, "-1"), ("damping", math.nan, "nan"),
    ("force_limit", 0.0, "0"), ("position_tolerance", -0.01, "-0.01"),
    ("velocity_tolerance", math.nan, "nan"), ("timeout", -5.0, "-5")])
def test_bad_controller_options_raise_naming_the_option_and_value(name, value, printed):
    scene = partsim.Scene()
    arm = planar_arm(scene)
    options = partsim.JointControllerOptions()
    setattr(options, name, value)
    with pytest.raises(partsim.PartsimError, match=f"{name} must .*, got {printed}$"):
        partsim.JointPositionController(arm, [], options)


def test_bad_controller_settings_raise_where_they_are_used():
    scene = partsim.Scene()
    arm = planar_arm(scene)
    loop = partsim.ControlLoop(scene)
    ee = partsim.EndEffectorController(arm, [], "tip", partsim.Pose())
    ee.ik.position_only = True
    loop.add(ee)
    ee.set_target_twist(np.zeros(6))
    # a negative speed limit would flip the twist: refused when set, and by the next update
    ee.max_linear_speed = -0.5
    with pytest.raises(partsim.PartsimError, match="max_linear_speed must be > 0, got -0.5"):
        ee.set_target_twist(np.array([0.2, 0, 0, 0, 0, 0]))
    with pytest.raises(partsim.PartsimError, match="max_linear_speed"):
        loop.step(5)
    ee.max_linear_speed = 0.5
    ee.ik.damping = -1.0
    with pytest.raises(partsim.PartsimError, match="ik.damping"):
        ee.set_target_pose(ee.get_end_effector_pose())
    ee.ik.damping = 0.01
    loop.step(5)
    loop.remove(ee)
    traj = partsim.JointTrajectoryController(arm, [])
    traj.path_tolerance = math.nan
    with pytest.raises(partsim.PartsimError, match="path_tolerance must be > 0, got nan"):
        traj.set_path([arm.get_qpos(), np.array([0.2, 0.3])], np.ones(2), np.ones(2))


def test_controller_keeps_scene_alive():
    scene = partsim.Scene()
    arm = planar_arm(scene)
    ctrl = partsim.JointPositionController(arm)
    loop = partsim.ControlLoop(scene)
    loop.add(ctrl)
    del scene, arm
    gc.collect()
    ctrl.set_target(np.array([0.1, 0.1]))
    loop.step(5)
    assert_vec(ctrl.get_qpos(), (2,))


def test_imu_reads_gravity():
    scene = partsim.Scene()
    scene.add_ground()
    box = build_box(scene, z=0.1)
    scene.step(500)
    reading = partsim.Imu(box).read()
    assert_vec(reading.linear_acceleration, (3,))
    np.testing.assert_allclose(reading.linear_acceleration, [0, 0, 9.81], atol=0.05)
    np.testing.assert_allclose(reading.angular_velocity, 0, atol=1e-3)
    assert_vec(reading.orientation, (4,))
    assert reading.time == pytest.approx(1.0)
