"""Loading a URDF: the robot's links, joints, joint limits and masses printed, a summary saved
as JSON and a picture of it saved as a PNG.

With no argument it loads tests/data/arm/arm_description/urdf/panda.urdf from this checkout
(found from the script's own location): a Panda-like 7-joint test arm with a two-finger
gripper, box-shaped Collada visuals and STL collisions, and `package://` mesh paths. Give any
URDF file to load that instead.

Run from any folder (with partsim importable: installed, or PYTHONPATH=<repo>/build/python):

    /usr/bin/python3 examples/load_urdf.py [FILE.urdf] [--free-root] [--out DIR]

Saves DIR/<robot>.json (links, joints, limits, masses) and DIR/<robot>.png (640x480); DIR
defaults to ./out/load_urdf.
"""

import argparse
import json
import os

import numpy as np

import partsim

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_URDF = os.path.join(HERE, "..", "tests", "data", "arm", "arm_description", "urdf",
                            "panda.urdf")


def finite(x):
    """JSON has no infinity: unlimited bounds become None."""
    return float(x) if np.isfinite(x) else None


def main():
    parser = argparse.ArgumentParser(description="Load a URDF and list its links and joints.")
    parser.add_argument("urdf", nargs="?", default=os.path.normpath(DEFAULT_URDF),
                        help="URDF file (default: the test arm of this checkout)")
    parser.add_argument("--free-root", action="store_true",
                        help="leave the root free instead of fixing it to the world")
    parser.add_argument("--out", default=os.path.join("out", "load_urdf"),
                        help="output folder (default: ./out/load_urdf)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    scene = partsim.Scene()
    scene.add_ground(0.0)
    loader = scene.create_urdf_loader()
    loader.fix_root_link = not args.free_root
    robot = loader.load(args.urdf)  # package:// paths resolve from the file's folders
    print(f"{args.urdf}: robot '{robot.get_name()}', {robot.dof} dof, "
          f"{len(robot.get_links())} links, {len(robot.get_joints())} joints")
    for warning in loader.last_report().warnings:
        print(f"  load warning: {warning.message}")

    summary = {"file": os.path.abspath(args.urdf), "name": robot.get_name(), "dof": robot.dof,
               "links": [], "joints": []}
    print("links:")
    for link in robot.get_links():
        parent = link.get_parent_index()
        parent_name = robot.get_link(parent).get_name() if parent >= 0 else "-"
        print(f"  {link.get_index():2d} {link.get_name():20s} parent {parent_name:20s} "
              f"mass {link.get_mass():.3f} kg")
        summary["links"].append({"name": link.get_name(), "parent": parent_name,
                                 "mass": link.get_mass()})
    print("joints (limits in rad or m):")
    for joint in robot.get_joints():
        kind = joint.type.name
        line = f"  {joint.get_name():22s} {kind:10s} {joint.get_parent_link().get_name()} -> " \
               f"{joint.get_child_link().get_name()}"
        entry = {"name": joint.get_name(), "type": kind,
                 "parent": joint.get_parent_link().get_name(),
                 "child": joint.get_child_link().get_name()}
        if joint.get_dof() > 0:
            lower, upper = joint.get_limits()
            line += f", limits [{lower:.3f}, {upper:.3f}], dof index {joint.get_dof_index()}"
            entry.update(lower=finite(lower), upper=finite(upper), dof_index=joint.get_dof_index())
        print(line)
        summary["joints"].append(entry)

    # joints in the middle of their range (0 where a side is unlimited), for the picture
    limits = robot.get_qlimits()
    middle = np.where(np.isfinite(limits).all(axis=1), limits.mean(axis=1), 0.0)
    robot.set_qpos(middle)
    summary["picture_qpos"] = middle.tolist()

    path = os.path.join(args.out, f"{robot.get_name()}.json")
    with open(path, "w") as f:
        json.dump(summary, f, indent=2)
    print(f"saved: {path}")

    # frame the robot: a camera looking at the middle of its links from a three-quarter view
    origins = np.array([link.get_pose().p for link in robot.get_links()])
    centre = (origins.min(axis=0) + origins.max(axis=0)) / 2
    size = max(float(np.ptp(origins, axis=0).max()), 0.2)
    scene.add_directional_light([0.4, 0.3, -1], [1, 1, 1], shadow=True)
    scene.set_ambient_light([0.3, 0.3, 0.3])
    camera = scene.add_camera("front", 640, 480, fovy=0.8, near=0.02, far=100)
    camera.look_at(centre + np.array([1.0, -0.8, 0.6]) * 1.6 * size, centre)
    scene.update_render()
    camera.take_picture()
    path = os.path.join(args.out, f"{robot.get_name()}.png")
    partsim.write_png(path, camera.get_color_rgba8())
    print(f"saved: {path}")


if __name__ == "__main__":
    main()
