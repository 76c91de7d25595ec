"""The Franka Emika Panda under PD drives: `partsim.build_panda()` (a 9-dof model from the
Panda's published DH table: 7 arm joints and 2 finger joints) in a scene, set to a home pose,
then driven to a second pose with gravity compensation; joint positions and the hand pose are
printed, the trajectory and a picture saved.

Run from any folder (with partsim importable: installed, or PYTHONPATH=<repo>/build/python):

    /usr/bin/python3 examples/panda_drives.py [--out DIR]

Saves DIR/panda.png (640x480) and DIR/panda_qpos.npy (steps x 9 joint positions, rad and m);
DIR defaults to ./out/panda_drives.
"""

import argparse
import os

import numpy as np

import partsim


def main():
    parser = argparse.ArgumentParser(description="The Panda under PD drives.")
    parser.add_argument("--out", default=os.path.join("out", "panda_drives"),
                        help="output folder (default: ./out/panda_drives)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    scene = partsim.Scene(timestep=1 / 500)
    scene.add_ground(0.0)

    # the robot model: an articulation description plus its joint names, limits and home
    robot = partsim.build_panda()
    arm = scene.add_articulation(robot.articulation)
    names = [j.get_name() for j in arm.get_active_joints()]
    print(f"{arm.get_name()}: {arm.dof} dof {names}")
    assert names == robot.arm_joints + robot.gripper_joints

    # a home pose covering all 9 dof: the model's 7 arm angles (rad), both fingers open (m)
    home = np.array(robot.home + [robot.gripper_open] * 2)
    arm.set_qpos(home)

    # PD drives: the model comes with gains sized for the Panda; set them explicitly here
    # (stiffness N m/rad or N/m, damping N m s/rad or N s/m, force limit N m or N: the Panda's
    # torque limits for the arm) and aim at a second pose
    joints = arm.get_active_joints()
    for joint, torque in zip(joints[:7], robot.arm_effort_limits):
        joint.set_drive_property(stiffness=1500.0, damping=150.0, force_limit=torque)
    for joint in joints[7:]:
        joint.set_drive_property(stiffness=1000.0, damping=20.0, force_limit=35.0)
    target = home + np.array([0.4, 0.2, 0.0, 0.3, 0.0, -0.2, 0.5, -0.02, -0.02])
    arm.set_drive_target(target)

    # two seconds; the passive force (gravity, Coriolis) is applied as a feed-forward each step
    trajectory = []
    for _ in range(1000):
        arm.set_qf(arm.compute_passive_force(gravity=True, coriolis_and_centrifugal=True))
        scene.step()
        trajectory.append(arm.get_qpos())
    qpos = arm.get_qpos()
    hand = arm.find_link_by_name(robot.ee_link).get_pose()
    print(f"target = {np.round(target, 3)}")
    print(f"qpos   = {np.round(qpos, 3)}")
    print(f"largest joint error {np.abs(qpos - target).max():.2e}")
    print(f"{robot.ee_link} at p = {np.round(hand.p, 3)} m, q = {np.round(hand.q, 3)} (wxyz)")

    path = os.path.join(args.out, "panda_qpos.npy")
    np.save(path, np.array(trajectory))
    print(f"saved: {path}")

    scene.add_directional_light([0.4, 0.3, -1], [1, 1, 1], shadow=True)
    scene.set_ambient_light([0.3, 0.3, 0.3])
    camera = scene.add_camera("front", 640, 480, fovy=0.8, near=0.05, far=20)
    camera.look_at([1.6, -1.2, 1.1], [0.2, 0, 0.45])
    scene.update_render()
    camera.take_picture()
    path = os.path.join(args.out, "panda.png")
    partsim.write_png(path, camera.get_color_rgba8())
    print(f"saved: {path}")


if __name__ == "__main__":
    main()
