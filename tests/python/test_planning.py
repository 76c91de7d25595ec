"""Motion planning bindings: a Panda turns around a post it would hit on the straight line."""

import numpy as np
import pytest

import partsim


def panda_with_post():
    scene = partsim.Scene()
    scene.add_ground(0.0)
    robot = partsim.build_panda()
    arm = scene.add_articulation(robot.articulation)
    dof = [arm.find_joint_by_name(n).get_dof_index() for n in robot.arm_joints]

    def full(q):
        out = np.full(arm.dof, 0.04)
        out[dof] = q
        return out

    home = np.array(robot.home)
    km = partsim.KinematicModel.from_articulation(arm)
    tcp = km.link_pose(full(home), km.link_index(robot.ee_link), robot.tcp_in_ee)
    post = (scene.create_actor_builder().set_name("post")
            .add_box_collision(half_size=[0.04, 0.04, 0.12])
            .set_initial_pose(partsim.Pose(tcp.p)).build_static())
    start, goal = home.copy(), home.copy()
    start[0], goal[0] = -1.0, 1.0
    arm.set_qpos(full(start))
    return scene, robot, arm, home, start, goal


def test_plan_to_joints_goes_around_the_post():
    scene, robot, arm, home, start, goal = panda_with_post()
    planner = partsim.MotionPlanner(arm, robot.arm_joints)
    assert planner.get_joint_names() == robot.arm_joints
    valid, reason = planner.is_state_valid(home)
    assert not valid and "post" in reason
    options = partsim.PlannerOptions()
    options.clearance = 0.02
    before = scene.pack()
    result = planner.plan_to_joints(goal, options)
    assert result, result.message
    assert scene.pack() == before
    np.testing.assert_allclose(result.path[0], start, atol=1e-9)
    np.testing.assert_allclose(result.path[-1], goal, atol=1e-9)
    assert result.trajectory.duration() > 0 and result.planning_time > 0
    for q in result.path:
        assert planner.is_state_valid(q, 0.0)[0]


def test_failures_and_bad_input():
    scene, robot, arm, home, start, goal = panda_with_post()
    planner = partsim.MotionPlanner(arm, robot.arm_joints)
    result = planner.plan_to_joints(home)
    assert not result and "goal" in result.message
    with pytest.raises(partsim.PartsimError):
        planner.plan_to_joints(np.zeros(3))
    options = partsim.PlannerOptions()
    options.algorithm = "Teleport"
    with pytest.raises(partsim.PartsimError):
        planner.plan_to_joints(goal, options)
