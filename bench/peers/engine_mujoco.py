"""MuJoCo's Python bindings (`mujoco`). URDFs are read by MuJoCo's own URDF reader (a copy with
the <mujoco><compiler .../></mujoco> element MuJoCo asks for: no path stripping, visuals
discarded), then edited through mjSpec: the ground plane, partsim's options (its default
integrator, implicitfast, and 50 iterations; MuJoCo's defaults otherwise: Newton, pyramidal
cones, tolerance 1e-8), one position actuator per driven joint (kp, kv), every geom's friction,
and collision bits that keep a URDF's own geoms from colliding with each other (the SRDF's
pairs) while they still meet the ground. The boxes are written as MJCF (free joints, box
geoms). mj_step one step at a time."""

import os
import re

import numpy as np

import scenes

NAME = "mujoco"


def version():
    import mujoco

    return mujoco.__version__


def _load_urdf(urdf):
    """mjSpec of a URDF through MuJoCo's reader (a copy beside it with the <mujoco> element)."""
    import mujoco

    with open(urdf, encoding="utf-8") as f:
        text = f.read()
    element = ('<mujoco><compiler strippath="false" discardvisual="true" '
               'balanceinertia="true" fusestatic="true"/></mujoco>')
    text = re.sub(r"(<robot\b[^>]*>)", r"\1" + element, text, count=1)
    path = os.path.splitext(urdf)[0] + "_mujoco.urdf"
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    return mujoco.MjSpec.from_file(path)


def _boxes_spec():
    import mujoco

    h = scenes.BOX_HALF
    bodies = "".join(
        f'<body pos="{p[0]} {p[1]} {p[2]}" quat="{q[0]} {q[1]} {q[2]} {q[3]}"><freejoint/>'
        f'<geom type="box" size="{h} {h} {h}" density="{scenes.BOX_DENSITY}"/></body>'
        for p, q in scenes.box_poses()
    )
    return mujoco.MjSpec.from_string(f"<mujoco><worldbody>{bodies}</worldbody></mujoco>")


def build(scene_name, assets, dt, sleep=False):
    """(step function, finish function returning a dict of results); `sleep` is for the
    engines that put resting bodies to sleep (this one never does)."""
    import mujoco

    if scene_name in ("drawer", "robot"):
        spec = _load_urdf(f"{assets}/{'cabinet' if scene_name == 'drawer' else 'kuka'}.urdf")
        for g in spec.geoms:  # not with each other, but with the ground
            g.contype, g.conaffinity = 2, 1
        joints = [j for j in spec.joints if j.type in (mujoco.mjtJoint.mjJNT_SLIDE,
                                                       mujoco.mjtJoint.mjJNT_HINGE)]
        if scene_name == "drawer":
            gains = [(scenes.DRAWER_STIFFNESS, scenes.DRAWER_DAMPING)] * len(joints)
        else:
            gains = list(zip(scenes.ROBOT_STIFFNESS, scenes.ROBOT_DAMPING))
        for j, (kp, kd) in zip(joints, gains):
            a = spec.add_actuator(target=j.name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
            a.set_to_position(kp=float(kp), kv=float(kd))
    else:
        spec = _boxes_spec()
    spec.option.timestep = dt
    spec.option.gravity = scenes.GRAVITY
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST  # partsim's default
    spec.option.iterations = 50
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 1])
    for g in spec.geoms:
        g.friction[0] = scenes.FRICTION
    model = spec.compile()
    data = mujoco.MjData(model)
    finish = dict
    if scene_name == "drawer":
        data.ctrl[:] = scenes.DRAWER_TARGET
        finish = lambda: {"q": data.qpos.tolist()}  # noqa: E731
    elif scene_name == "robot":
        data.qpos[:] = scenes.ROBOT_POSE
        data.ctrl[:] = scenes.ROBOT_POSE
        finish = lambda: {  # noqa: E731
            "q": data.qpos.tolist(),
            "error": float(np.max(np.abs(data.qpos - scenes.ROBOT_POSE))),
        }
    else:
        finish = lambda: {"mean_z": float(np.mean(data.qpos.reshape(-1, 7)[:, 2]))}  # noqa: E731

    def step():
        mujoco.mj_step(model, data)

    return step, finish
