"""A 9-dof arm held by gravity compensation and driven to a target by an external PID loop, and
then by the joints' own PD drives: SAPIEN 2's robot-control tutorial on partsim.

Written against SAPIEN 2.2's API (`import sapien.core as sapien` becomes
`import partsim.core as sapien`). Each step: qf = compute_passive_force(gravity, Coriolis and
centrifugal) + PID(target - qpos), set_qf(qf), step. It prints the largest joint error after
each controller has run, and checks that both reach the target (the PID within 0.03 rad in 10 s: the tutorial's
gains are gentle).

    PYTHONPATH=build/python /usr/bin/python3 examples/sapien/robot_pid.py [panda.urdf]
"""

import os
import sys

import numpy as np

import partsim.core as sapien  # SAPIEN 2: import sapien.core as sapien

HERE = os.path.dirname(os.path.abspath(__file__))
PANDA = os.path.join(HERE, "..", "..", "tests", "data", "arm", "arm_description", "urdf",
                     "panda.urdf")


class SimplePID:
    def __init__(self, kp=0.0, ki=0.0, kd=0.0):
        self.p, self.i, self.d = kp, ki, kd
        self._ci = 0.0
        self._last_error = None

    def compute(self, error, dt):
        self._ci += error * dt
        derivative = 0.0 if self._last_error is None else (error - self._last_error) / dt
        self._last_error = error
        return self.p * error + self.i * self._ci + self.d * derivative


def pid_forward(pids, target_qpos, qpos, dt):
    return np.array([pid.compute(e, dt) for pid, e in zip(pids, target_qpos - qpos)])


def run(urdf, use_internal_drive, use_external_pid, dt=1 / 240.0, seconds=10.0):
    engine = sapien.Engine()
    scene = engine.create_scene(sapien.SceneConfig())
    scene.set_timestep(dt)
    scene.add_ground(0)
    loader = scene.create_urdf_loader()
    loader.fix_root_link = True
    robot = loader.load(urdf)
    robot.set_root_pose(sapien.Pose([0, 0, 0], [1, 0, 0, 0]))

    init_qpos = np.array([0, 0.2, 0, -2.6, 0, 2.9, 0.8, 0, 0])
    target_qpos = np.array([0.5, -0.3, 0.2, -2.0, 0.3, 2.2, 1.2, 0.02, 0.02])
    robot.set_qpos(init_qpos)
    active_joints = robot.get_active_joints()
    assert len(active_joints) == 9, [j.get_name() for j in active_joints]

    if use_internal_drive:
        for i, joint in enumerate(active_joints):
            joint.set_drive_property(stiffness=2000, damping=200)
            joint.set_drive_target(target_qpos[i])
    pids = []
    if use_external_pid:
        gains = [(40, 5, 2), (40, 5, 2), (40, 5, 2), (20, 5, 2), (5, 0.8, 2), (5, 0.8, 2),
                 (5, 0.8, 0.4), (0.1, 0, 0.02), (0.1, 0, 0.02)]
        pids = [SimplePID(*g) for g in gains]

    for _ in range(int(seconds / dt)):
        qf = robot.compute_passive_force(gravity=True, coriolis_and_centrifugal=True)
        if use_external_pid:
            qf += pid_forward(pids, target_qpos, robot.get_qpos(), dt)
        robot.set_qf(qf)
        scene.step()
    qpos = robot.get_qpos()
    assert np.all(np.isfinite(qpos)), qpos
    return np.abs(qpos - target_qpos)


def main(urdf):
    for label, internal, external in (("external PID", False, True),
                                      ("internal PD drives", True, False)):
        err = run(urdf, internal, external)
        print(f"{label}: largest arm joint error {err[:7].max():.4f} rad, fingers "
              f"{err[7:].max() * 1000:.1f} mm after 10 s at dt = 1/240 s")
        # the tutorial's gains are gentle: the integral term removes the last centiradians slowly
        assert err[:7].max() < 0.03, err
        assert err[7:].max() < 0.005, err
    print("robot pid: ok")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else PANDA)
