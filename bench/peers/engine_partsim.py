"""partsim through its own Python API (``import partsim``: Scene, UrdfLoader, ActorBuilder,
Articulation drives); not its SAPIEN-compatible layer."""

import numpy as np

import scenes

NAME = "partsim"


def version():
    import partsim

    return partsim.__version__


def build(scene_name, assets, dt, sleep=False):
    """(step function, finish function returning a dict of results); `sleep` is for the
    engines that put resting bodies to sleep (this one never does)."""
    import partsim

    partsim.set_log_level("error")  # the loader's notes on the KUKA's meshes (convex hulls)
    scene = partsim.Scene(timestep=dt, gravity=np.array(scenes.GRAVITY))
    material = partsim.PhysicalMaterial(scenes.FRICTION, scenes.FRICTION, 0.0)
    scene.add_ground(0.0, material=material, render=False)
    finish = dict
    if scene_name in ("drawer", "robot"):
        loader = scene.create_urdf_loader()
        loader.fix_root_link = True
        loader.material = material
        urdf = f"{assets}/{'cabinet' if scene_name == 'drawer' else 'kuka'}.urdf"
        art = loader.load(urdf)  # reads the .srdf beside it
        joints = art.get_active_joints()
        if scene_name == "drawer":
            for j in joints:
                j.set_drive_property(scenes.DRAWER_STIFFNESS, scenes.DRAWER_DAMPING)
            art.set_drive_target(np.full(len(joints), scenes.DRAWER_TARGET))
            finish = lambda: {"q": art.get_qpos().tolist()}  # noqa: E731
        else:
            for j, kp, kd in zip(joints, scenes.ROBOT_STIFFNESS, scenes.ROBOT_DAMPING):
                j.set_drive_property(kp, kd)
            art.set_qpos(scenes.ROBOT_POSE)
            art.set_drive_target(scenes.ROBOT_POSE)
            finish = lambda: {  # noqa: E731
                "q": art.get_qpos().tolist(),
                "error": float(np.max(np.abs(art.get_qpos() - scenes.ROBOT_POSE))),
            }
    else:
        h = scenes.BOX_HALF
        boxes = []
        for p, q in scenes.box_poses():
            b = scene.create_actor_builder()
            b.add_box_collision(half_size=np.array([h, h, h]), material=material,
                                density=scenes.BOX_DENSITY)
            boxes.append(b.build())
            boxes[-1].set_pose(partsim.Pose(p, q))
        finish = lambda: {  # noqa: E731
            "mean_z": float(np.mean([a.get_pose().p[2] for a in boxes]))
        }
    return scene.step, finish
