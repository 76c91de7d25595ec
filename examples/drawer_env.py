"""The Gymnasium drawer-pulling environment (`partsim.envs.OpenCabinetEnv`): an episode
on a generated cabinet with the flying gripper starting closed on the drawer's handle, driven
by a few-line heuristic (pull along the drawer's axis, read from the "mobility" observation) or
by random actions; frames from `env.render()` and the rewards are saved.

`render_mode="rgb_array"` makes `env.render()` return the front camera's picture as an
(h, w, 3) uint8 array. No gymnasium package is needed: the spaces are partsim's own, with
Gymnasium's methods.

Run from any folder (with partsim importable: installed, or PYTHONPATH=<repo>/build/python):

    /usr/bin/python3 examples/drawer_env.py [--random] [--steps N] [--out DIR]

Saves into DIR (default ./out/drawer_env): frame_000.png, frame_010.png, ... (320x240, every
10th step and the last) and rewards.csv (step, reward, progress, success).
"""

import argparse
import os

import numpy as np

import partsim
import partsim.envs as envs


def main():
    parser = argparse.ArgumentParser(description="An episode of the drawer environment.")
    parser.add_argument("--random", action="store_true", help="random actions, not the heuristic")
    parser.add_argument("--steps", type=int, default=100, help="most steps (default 100)")
    parser.add_argument("--out", default=os.path.join("out", "drawer_env"),
                        help="output folder (default: ./out/drawer_env)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    env = envs.OpenCabinetEnv(task="drawer", obs_mode="mobility", render_mode="rgb_array",
                              camera_size=(320, 240))
    print(f"observation space {env.observation_space}, action space {env.action_space}")
    obs, info = env.reset(seed=0)
    print(f"object {info['object']}, target {info['target']}")

    def save_frame(step):
        path = os.path.join(args.out, f"frame_{step:03d}.png")
        partsim.write_png(path, env.render())
        print(f"saved: {path}")

    rows = ["step,reward,progress,success"]
    save_frame(0)
    for step in range(1, args.steps + 1):
        if args.random:
            action = env.action_space.sample()
        else:
            # mobility observation: axis origin (3), axis direction (3), normal (3), q, qdot,
            # then the robot state. Move the hand along the drawer's axis, gripper closed (-1).
            action = np.zeros(7, dtype=np.float32)
            action[:3] = 0.3 * obs[3:6]
            action[6] = -1.0
        obs, reward, terminated, truncated, info = env.step(action)
        rows.append(f"{step},{reward:.4f},{info['progress']:.4f},{int(info['success'])}")
        done = terminated or truncated
        if step % 10 == 0 or done:
            save_frame(step)
        if done:
            break
    print(f"after {step} steps: progress {info['progress']:.2f} of the drawer's range, "
          f"success {info['success']}")
    env.close()

    path = os.path.join(args.out, "rewards.csv")
    with open(path, "w") as f:
        f.write("\n".join(rows) + "\n")
    print(f"saved: {path}")


if __name__ == "__main__":
    main()
