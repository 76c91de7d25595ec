"""Loads a URDF robot and a PartNet-Mobility object with SAPIEN's URDF loader, as SAPIEN's
loading tutorial does, and moves a part of the object.

Written against SAPIEN 3's API (`import sapien` becomes `import partsim.sapien as sapien`). A
PartNet-Mobility object is loaded from its mobility.urdf, like any URDF. With no argument it
loads partsim's Panda and a StorageFurniture object made by `partsim assets generate` (into a
temporary folder); give a robot URDF and a PartNet-Mobility folder (e.g. the dataset's 179/) to
load those instead.

    PYTHONPATH=build/python /usr/bin/python3 examples/sapien/load_urdf.py [robot.urdf OBJ_DIR]
"""

import os
import subprocess
import sys
import tempfile

import numpy as np

import partsim.sapien as sapien  # SAPIEN 3: import sapien

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.join(HERE, "..", "..")
PANDA = os.path.join(REPO, "tests", "data", "arm", "arm_description", "urdf", "panda.urdf")


def generated_object(tmp):
    """One generated PartNet-Mobility folder (partsim's generator, not SAPIEN)."""
    cli = os.environ.get("PARTSIM_CLI", os.path.join(REPO, "build", "partsim"))
    subprocess.run([cli, "assets", "generate", "--out", tmp, "--categories", "StorageFurniture",
                    "--seed", "7"], check=True, stdout=subprocess.DEVNULL)
    return os.path.join(tmp, sorted(os.listdir(tmp))[0])


def main(robot_urdf, object_dir):
    scene = sapien.Scene()
    scene.set_timestep(1 / 240.0)
    scene.add_ground(0)

    loader = scene.create_urdf_loader()
    loader.fix_root_link = True
    robot = loader.load(robot_urdf)
    robot.set_root_pose(sapien.Pose([-1.0, 0, 0], [1, 0, 0, 0]))
    print(f"robot '{robot.name}': {robot.dof} dof, links {[l.name for l in robot.links][:4]}...")

    loader = scene.create_urdf_loader()
    loader.fix_root_link = True
    loader.scale = 1.0
    obj = loader.load(os.path.join(object_dir, "mobility.urdf"))
    obj.set_root_pose(sapien.Pose([0.5, 0, 1.0]))
    print(f"object '{obj.name}' from {os.path.basename(os.path.normpath(object_dir))}: "
          f"{obj.dof} dof")
    for joint in obj.get_active_joints():
        print(f"  joint {joint.name}: {joint.type}, limits {np.round(joint.get_limits(), 3).tolist()}")

    # a kinematic copy: moved by set_qpos only
    kinematic = loader.load_kinematic(os.path.join(object_dir, "mobility.urdf"))
    kinematic.set_root_pose(sapien.Pose([0.5, 2.0, 1.0]))

    # drive the first movable part to the middle of its range; the passive force holds the
    # parts against gravity (a real object's parts can be heavy), the drive moves them
    joint = obj.get_active_joints()[0]
    lo, hi = joint.get_limits()[0]
    if not np.isfinite(lo) or not np.isfinite(hi):
        lo, hi = 0.0, 1.0
    target = (lo + hi) / 2
    joint.set_drive_property(stiffness=1000.0, damping=100.0)
    joint.set_drive_target(target)
    for _ in range(480):
        obj.set_qf(obj.compute_passive_force(gravity=True, coriolis_and_centrifugal=True))
        scene.step()
    reached = obj.get_qpos()[0]
    kinematic_q = np.array(kinematic.get_qpos())
    kinematic_q[0] = target
    kinematic.set_qpos(kinematic_q)
    print(f"part '{joint.name}' driven to {reached:.3f} (target {target:.3f}); kinematic copy "
          f"set to {kinematic.get_qpos()[0]:.3f}")
    assert robot.dof == 9 and obj.dof >= 1
    assert abs(reached - target) < 0.02 * max(1.0, hi - lo), (reached, target)
    assert abs(kinematic.get_qpos()[0] - target) < 1e-9
    print("load urdf: ok")


if __name__ == "__main__":
    if len(sys.argv) == 3:
        main(sys.argv[1], sys.argv[2])
    else:
        with tempfile.TemporaryDirectory() as tmp:
            main(PANDA, generated_object(tmp))
