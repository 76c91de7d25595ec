"""An articulation built link by link with SAPIEN's builder: a cabinet with a drawer and a door.

Written against SAPIEN 2.2's API (`import sapien.core as sapien` becomes
`import partsim.core as sapien`). The drawer slides on a prismatic joint, the door turns on a
revolute joint; limits are given per dof as [[lower, upper]], the joint's x axis is its axis.
It drives both open with PD drives and prints the joint states.

    PYTHONPATH=build/python /usr/bin/python3 examples/sapien/articulation.py
"""

import numpy as np
from transforms3d.euler import euler2quat

import partsim.core as sapien  # SAPIEN 2: import sapien.core as sapien


def create_cabinet(scene):
    builder = scene.create_articulation_builder()
    body = builder.create_link_builder()
    body.set_name("body")
    # a box open at the front (+x): back, two sides, top, bottom
    for p, half in [([-0.28, 0, 0.3], [0.02, 0.3, 0.3]), ([0, 0.28, 0.3], [0.3, 0.02, 0.3]),
                    ([0, -0.28, 0.3], [0.3, 0.02, 0.3]), ([0, 0, 0.58], [0.3, 0.3, 0.02]),
                    ([0, 0, 0.02], [0.3, 0.3, 0.02])]:
        body.add_box_collision(sapien.Pose(p), half_size=half)
        body.add_box_visual(sapien.Pose(p), half_size=half, color=[0.8, 0.6, 0.4])
    # a shelf splitting the drawer (below) from the door's compartment (above)
    body.add_box_collision(sapien.Pose([0, 0, 0.25]), half_size=[0.28, 0.26, 0.01])
    body.add_box_visual(sapien.Pose([0, 0, 0.25]), half_size=[0.28, 0.26, 0.01],
                        color=[0.8, 0.6, 0.4])

    drawer = builder.create_link_builder(body)
    drawer.set_name("drawer")
    drawer.set_joint_name("drawer_slide")
    drawer.add_box_collision(sapien.Pose([0, 0, -0.09]), half_size=[0.24, 0.22, 0.01])
    drawer.add_box_collision(sapien.Pose([0.25, 0, 0]), half_size=[0.01, 0.25, 0.1])
    drawer.add_box_visual(sapien.Pose([0.25, 0, 0]), half_size=[0.01, 0.25, 0.1],
                          color=[0.3, 0.5, 0.8])
    drawer.set_joint_properties("prismatic", limits=[[0.0, 0.35]],
                                pose_in_parent=sapien.Pose([0.02, 0, 0.13]),
                                pose_in_child=sapien.Pose(), friction=0.0, damping=5.0)

    door = builder.create_link_builder(body)
    door.set_name("door")
    door.set_joint_name("door_hinge")
    door.add_box_collision(sapien.Pose([0, -0.25, 0]), half_size=[0.01, 0.25, 0.15])
    door.add_box_visual(sapien.Pose([0, -0.25, 0]), half_size=[0.01, 0.25, 0.15],
                        color=[0.3, 0.8, 0.5])
    # the hinge is vertical (the joint's x axis turned onto z) at the front right edge
    hinge = sapien.Pose([0.31, 0.27, 0.41], euler2quat(0, -np.pi / 2, 0))
    door.set_joint_properties("revolute", limits=[[0.0, np.pi / 2]], pose_in_parent=hinge,
                              pose_in_child=sapien.Pose([0, 0, 0], euler2quat(0, -np.pi / 2, 0)),
                              friction=0.0, damping=1.0)
    cabinet = builder.build(fix_root_link=True)
    cabinet.set_name("cabinet")
    return cabinet


def main():
    engine = sapien.Engine()
    scene = engine.create_scene()
    scene.set_timestep(1 / 240.0)
    scene.add_ground(0)
    cabinet = create_cabinet(scene)

    print("name:", cabinet.get_name(), "dof:", cabinet.dof)
    for joint in cabinet.get_active_joints():
        print(f"  {joint.get_name()}: limits {joint.get_limits().tolist()}")
    print("qlimits:", cabinet.get_qlimits().tolist())
    targets = {"drawer_slide": 0.3, "door_hinge": np.pi / 3}
    for joint in cabinet.get_active_joints():
        joint.set_drive_property(stiffness=200.0, damping=40.0)
        joint.set_drive_target(targets[joint.get_name()])
    for _ in range(240 * 3):
        scene.step()
    qpos = cabinet.get_qpos()
    print("qpos after 3 s:", np.round(qpos, 3).tolist())
    door = [link for link in cabinet.get_links() if link.get_name() == "door"][0]
    print("door link at", np.round(door.get_pose().p, 3).tolist())
    assert np.allclose(qpos, [targets["drawer_slide"], targets["door_hinge"]], atol=0.02), qpos
    assert cabinet.get_active_joints()[0].get_limits().shape == (1, 2)
    print("articulation: ok")


if __name__ == "__main__":
    main()
