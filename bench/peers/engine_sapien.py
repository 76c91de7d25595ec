"""SAPIEN 3 (the `sapien` wheel): PhysX on the CPU (``PhysxCpuSystem``), no render system.
PhysX's defaults otherwise: TGS, 10 position and 1 velocity solver iterations per body, sleeping
off (threshold 0; PhysX's default 0.005 with --sleep), contact offset 1 cm, PCM. Drives in force
mode (``mode="force"``)."""

import warnings

import numpy as np

import scenes

NAME = "sapien"


def version():
    import sapien

    return sapien.__version__


def build(scene_name, assets, dt, sleep=False):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "Failed to find system libvulkan": no renderer here
        import sapien

    if not sleep:  # PhysX puts bodies at rest to sleep; partsim and MuJoCo step every body
        config = sapien.physx.get_body_config()
        config.sleep_threshold = 0.0
        sapien.physx.set_body_config(config)
    scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    scene.set_timestep(dt)
    material = sapien.physx.PhysxMaterial(scenes.FRICTION, scenes.FRICTION, 0.0)
    scene.add_ground(0.0, render=False, material=material)
    finish = dict
    if scene_name in ("drawer", "robot"):
        loader = scene.create_urdf_loader()
        loader.fix_root_link = True
        loader.set_material(scenes.FRICTION, scenes.FRICTION, 0.0)
        urdf = f"{assets}/{'cabinet' if scene_name == 'drawer' else 'kuka'}.urdf"
        art = loader.load(urdf)  # with the .srdf beside it
        joints = art.get_active_joints()
        if scene_name == "drawer":
            for j in joints:
                j.set_drive_property(scenes.DRAWER_STIFFNESS, scenes.DRAWER_DAMPING, mode="force")
                j.set_drive_target(scenes.DRAWER_TARGET)
            finish = lambda: {"q": art.get_qpos().tolist()}  # noqa: E731
        else:
            for j, kp, kd, q in zip(joints, scenes.ROBOT_STIFFNESS, scenes.ROBOT_DAMPING,
                                    scenes.ROBOT_POSE):
                j.set_drive_property(kp, kd, mode="force")
                j.set_drive_target(q)
            art.set_qpos(scenes.ROBOT_POSE)
            finish = lambda: {  # noqa: E731
                "q": art.get_qpos().tolist(),
                "error": float(np.max(np.abs(art.get_qpos() - scenes.ROBOT_POSE))),
            }
    else:
        h = scenes.BOX_HALF
        boxes = []
        for p, q in scenes.box_poses():
            b = scene.create_actor_builder()
            b.add_box_collision(half_size=[h, h, h], material=material,
                                density=scenes.BOX_DENSITY)
            b.set_initial_pose(sapien.Pose(p, q))
            boxes.append(b.build())
        finish = lambda: {  # noqa: E731
            "mean_z": float(np.mean([a.get_pose().p[2] for a in boxes]))
        }
    return scene.step, finish
