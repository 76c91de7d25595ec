"""PyBullet (Bullet's multibody, DIRECT mode). The step is set to the common dt (PyBullet's
default is 1/240 s), no substeps; its solver otherwise at its defaults (sequential impulses,
50 iterations). URDFs are loaded with their own inertias (URDF_USE_INERTIA_FROM_FILE) and a
fixed base; PyBullet does not collide a body's links with each other by default. Drives:
PD_CONTROL, an explicit PD in Bullet's C++ (force = kp (q* - q) - kd q' each step), after the
default velocity motors are switched off (force 0). Bullet multiplies the two friction
coefficients of a contact: every body gets sqrt(FRICTION), so every pair gets FRICTION. Bodies
never sleep (ACTIVATION_STATE_DISABLE_SLEEPING) unless --sleep leaves Bullet's deactivation on."""

import math

import numpy as np

import scenes

NAME = "pybullet"
BIG_FORCE = 1e6  # PD_CONTROL's force limit: none in effect


def version():
    import pybullet

    return f"{pybullet.getAPIVersion()}"


def build(scene_name, assets, dt, sleep=False):
    import pybullet as pb

    NO_SLEEP = pb.ACTIVATION_STATE_DISABLE_SLEEPING  # noqa: N806
    c = pb.connect(pb.DIRECT)
    pb.setTimeStep(dt, physicsClientId=c)
    pb.setGravity(*scenes.GRAVITY, physicsClientId=c)
    mu = math.sqrt(scenes.FRICTION)
    plane = pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=c)
    ground = pb.createMultiBody(0, plane, physicsClientId=c)
    pb.changeDynamics(ground, -1, lateralFriction=mu, restitution=0, physicsClientId=c)
    finish = dict
    if scene_name in ("drawer", "robot"):
        urdf = f"{assets}/{'cabinet' if scene_name == 'drawer' else 'kuka'}.urdf"
        body = pb.loadURDF(urdf, useFixedBase=True, flags=pb.URDF_USE_INERTIA_FROM_FILE,
                           physicsClientId=c)
        for link in range(-1, pb.getNumJoints(body, physicsClientId=c)):
            pb.changeDynamics(body, link, lateralFriction=mu, physicsClientId=c)
        if not sleep:
            pb.changeDynamics(body, -1, activationState=NO_SLEEP, physicsClientId=c)
        joints = [i for i in range(pb.getNumJoints(body, physicsClientId=c))
                  if pb.getJointInfo(body, i, physicsClientId=c)[2] in
                  (pb.JOINT_REVOLUTE, pb.JOINT_PRISMATIC)]
        n = len(joints)
        pb.setJointMotorControlArray(body, joints, pb.VELOCITY_CONTROL, forces=[0.0] * n,
                                     physicsClientId=c)
        if scene_name == "drawer":
            target = [scenes.DRAWER_TARGET] * n
            kp, kd = [scenes.DRAWER_STIFFNESS] * n, [scenes.DRAWER_DAMPING] * n
        else:
            target = scenes.ROBOT_POSE.tolist()
            kp, kd = scenes.ROBOT_STIFFNESS.tolist(), scenes.ROBOT_DAMPING.tolist()
            for i, q in zip(joints, target):
                pb.resetJointState(body, i, q, 0.0, physicsClientId=c)
        pb.setJointMotorControlArray(body, joints, pb.PD_CONTROL, targetPositions=target,
                                     targetVelocities=[0.0] * n, positionGains=kp,
                                     velocityGains=kd, forces=[BIG_FORCE] * n,
                                     physicsClientId=c)

        def qpos():
            return np.array([s[0] for s in pb.getJointStates(body, joints, physicsClientId=c)])

        if scene_name == "drawer":
            finish = lambda: {"q": qpos().tolist()}  # noqa: E731
        else:
            finish = lambda: {  # noqa: E731
                "q": qpos().tolist(),
                "error": float(np.max(np.abs(qpos() - scenes.ROBOT_POSE))),
            }
    else:
        h = scenes.BOX_HALF
        shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[h, h, h], physicsClientId=c)
        mass = scenes.BOX_DENSITY * (2 * h) ** 3
        boxes = []
        for p, q in scenes.box_poses():
            b = pb.createMultiBody(mass, shape, basePosition=p.tolist(),
                                   baseOrientation=[q[1], q[2], q[3], q[0]], physicsClientId=c)
            pb.changeDynamics(b, -1, lateralFriction=mu, restitution=0, physicsClientId=c)
            if not sleep:
                pb.changeDynamics(b, -1, activationState=NO_SLEEP, physicsClientId=c)
            boxes.append(b)
        finish = lambda: {  # noqa: E731
            "mean_z": float(np.mean([pb.getBasePositionAndOrientation(b, physicsClientId=c)[0][2]
                                     for b in boxes]))
        }

    def step():
        pb.stepSimulation(physicsClientId=c)

    return step, finish
