"""Inverse kinematics and motion planning on the Panda (`partsim.build_panda()`): IK finds joint
angles that put the tool centre point (TCP) at a target pose; the planner (OMPL's RRTConnect,
collisions checked by MuJoCo on a private copy of the scene) finds a path to that pose around a
post that blocks the direct swing; a joint trajectory controller executes the timed path in the
scene. Errors, planning time and contacts with the post are printed; pictures and the path saved.

Run from any folder (with partsim importable: installed, or PYTHONPATH=<repo>/build/python):

    /usr/bin/python3 examples/ik_and_planning.py [--out DIR]

Saves into DIR (default ./out/ik_and_planning): start.png and end.png (640x480) and path.npy
(waypoints x 7 arm joint angles, rad).
"""

import argparse
import os

import numpy as np

import partsim


def picture(scene, camera, path):
    scene.update_render()
    camera.take_picture()
    partsim.write_png(path, camera.get_color_rgba8())
    print(f"saved: {path}")


def main():
    parser = argparse.ArgumentParser(description="IK and motion planning on the Panda.")
    parser.add_argument("--out", default=os.path.join("out", "ik_and_planning"),
                        help="output folder (default: ./out/ik_and_planning)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    scene = partsim.Scene(timestep=1 / 500)
    scene.add_ground(0.0)
    robot = partsim.build_panda()
    arm = scene.add_articulation(robot.articulation)
    fingers = [robot.gripper_open] * 2

    # kinematics without touching the simulation: forward kinematics of the TCP frame
    model = partsim.KinematicModel.from_articulation(arm)
    hand = model.link_index(robot.ee_link)
    home = np.array(robot.home)
    start, goal = home.copy(), home.copy()
    start[0], goal[0] = -1.0, 1.0  # swing the first joint from -1 to +1 rad
    target = model.link_pose(np.r_[goal, fingers], hand, robot.tcp_in_ee)
    print(f"target TCP pose: p = {np.round(target.p, 3)} m, q = {np.round(target.q, 3)}")

    # inverse kinematics from the start: damped least squares within the joint limits, arm only
    options = partsim.IkOptions()
    options.offset = robot.tcp_in_ee
    options.active = [True] * 7 + [False] * 2
    result = partsim.inverse_kinematics(model, hand, target, np.r_[start, fingers], options)
    reached = model.link_pose(result.q, hand, robot.tcp_in_ee)
    print(f"IK: success {result.success} in {result.iterations} iterations, position error "
          f"{result.position_error * 1e3:.3f} mm, rotation error {result.rotation_error:.2e} rad")
    print(f"    q = {np.round(result.q[:7], 3)}; FK of q puts the TCP "
          f"{np.linalg.norm(reached.p - target.p) * 1e3:.3f} mm from the target")

    # a post where the TCP passes at home: the straight swing of joint 1 would hit it
    tcp_home = model.link_pose(np.r_[home, fingers], hand, robot.tcp_in_ee)
    post = (scene.create_actor_builder().set_name("post")
            .add_box_collision(half_size=[0.04, 0.04, 0.12])
            .add_box_visual(half_size=[0.04, 0.04, 0.12], color=[0.9, 0.5, 0.1, 1])
            .set_initial_pose(partsim.Pose(tcp_home.p)).build_static())
    arm.set_qpos(np.r_[start, fingers])
    arm.set_drive_target(np.r_[start, fingers])

    scene.add_directional_light([0.4, 0.3, -1], [1, 1, 1], shadow=True)
    scene.set_ambient_light([0.3, 0.3, 0.3])
    camera = scene.add_camera("front", 640, 480, fovy=0.8, near=0.05, far=20)
    camera.look_at([1.3, -1.5, 1.3], [0.2, 0, 0.4])
    picture(scene, camera, os.path.join(args.out, "start.png"))

    # plan to the target pose around the post, keeping 2 cm clearance
    planner = partsim.MotionPlanner(arm, robot.arm_joints)
    valid, reason = planner.is_state_valid(home)
    print(f"home pose collision-free: {valid} ({reason})")
    plan_options = partsim.PlannerOptions()
    plan_options.clearance = 0.02
    plan_options.time_limit = 10.0
    plan = planner.plan_to_pose(robot.ee_link, robot.tcp_in_ee, target, plan_options)
    print(f"plan: success {plan.success} in {plan.planning_time:.2f} s, {len(plan.path)} "
          f"waypoints, trajectory {plan.trajectory.duration():.2f} s")
    if not plan.success:
        raise SystemExit(f"planning failed: {plan.message}")
    path = os.path.join(args.out, "path.npy")
    np.save(path, np.array(plan.path))
    print(f"saved: {path}")

    # execute: a joint trajectory controller (PD plus inverse dynamics feed-forward) at 100 Hz
    controller_options = partsim.JointControllerOptions()
    controller_options.control_rate = 100.0
    controller = partsim.JointTrajectoryController(arm, robot.arm_joints, controller_options)
    controller.set_trajectory(plan.trajectory)
    loop = partsim.ControlLoop(scene)
    loop.add(controller)
    touches = 0
    steps = int((plan.trajectory.duration() + 1.0) / scene.get_timestep())
    for _ in range(steps // 10):
        loop.step(10)
        touches += any("post" in (c.body0.name, c.body1.name) for c in scene.get_contacts())
    status = controller.get_status()
    print(f"controller: {status.state.name} {status.message}".rstrip())
    tcp = arm.find_link_by_name(robot.ee_link).get_pose() * robot.tcp_in_ee
    print(f"TCP {np.linalg.norm(tcp.p - target.p) * 1e3:.2f} mm from the target; "
          f"touched the post in {touches} of {steps // 10} checks")
    picture(scene, camera, os.path.join(args.out, "end.png"))


if __name__ == "__main__":
    main()
