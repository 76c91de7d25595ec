"""The built-in cabinet in SAPIEN's viewer loop, for the browser tests (tests/python/
test_viewer_browser.py) and the bench (bench/viewer_bench.mjs).

    while not viewer.closed:
        scene.step(); scene.update_render(); viewer.render()

Standard output, one JSON object per line:
  first  {"url", "camera": {"position", "target", "fovy_deg", "width", "height"}, "mask", ...}:
         the viewer's URL and a partsim camera's pose, with the silhouette that camera sees
         (mask PNG: 255 where the cabinet is) for comparison with the page's picture;
  then   {"wall", "step", "qpos": {joint: q}} about 10 times a second while the loop runs;
  last   {"closed": true, "step", "qpos"} when the page's close button ends the loop (or
         {"timeout": true, ...} after --max-seconds).
The loop keeps simulated time at most at wall-clock time (as a viewer loop does).
Usage: cabinet_viewer.py --out DIR [--max-seconds S] [--scene cabinet|panda|actors [--count N]]
"""

import argparse
import json
import math
import os
import sys
import time

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.environ.get("PARTSIM_PYTHON_DIR", os.path.join(REPO, "build", "python")))

import numpy as np  # noqa: E402

import partsim  # noqa: E402

LABELS = {"body": "furniture_body", "drawer": "drawer", "door": "rotation_door"}


def _box(xyz, size, rgba, rpy=(0, 0, 0)):
    o = f'<origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="{rpy[0]} {rpy[1]} {rpy[2]}"/>'
    g = f'<geometry><box size="{size[0]} {size[1]} {size[2]}"/></geometry>'
    m = f'<material name="c{abs(hash(tuple(rgba))) % 997}"><color rgba="{" ".join(map(str, rgba))}"/></material>'
    return f"<visual>{o}{g}{m}</visual><collision>{o}{g}</collision>"


def _bar(xyz, length, rpy, rgba):
    o = f'<origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="{rpy[0]} {rpy[1]} {rpy[2]}"/>'
    g = f'<geometry><cylinder radius="0.01" length="{length}"/></geometry>'
    m = f'<material name="metal"><color rgba="{" ".join(map(str, rgba))}"/></material>'
    return f"<visual>{o}{g}{m}</visual><collision>{o}{g}</collision>"


def _inertial(mass):
    i = 0.01 * mass
    return (f'<inertial><mass value="{mass}"/><inertia ixx="{i}" iyy="{i}" izz="{i}" '
            'ixy="0" ixz="0" iyz="0"/></inertial>')


def fallback_cabinet_urdf():
    """A cabinet laid out as partsim's built-in one (MakeCabinetUrdf): body 0.5 x 0.6 x 0.8 m
    (x out of the front, origin at the bottom's centre), drawer_0 on a prismatic joint above,
    door_0 on a revolute hinge below. Used only while Python has no binding for the built-in."""
    wood, front, metal = (0.62, 0.45, 0.30, 1), (0.80, 0.68, 0.50, 1), (0.7, 0.7, 0.72, 1)
    body = "".join([
        _box((-0.241, 0, 0.4), (0.018, 0.6, 0.8), wood),
        _box((0, 0.291, 0.4), (0.5, 0.018, 0.8), wood),
        _box((0, -0.291, 0.4), (0.5, 0.018, 0.8), wood),
        _box((0, 0, 0.791), (0.5, 0.6, 0.018), wood),
        _box((0, 0, 0.009), (0.5, 0.6, 0.018), wood),
        _box((0, 0, 0.553), (0.5, 0.6, 0.018), wood),
    ])
    drawer = "".join([
        _box((0.241, 0, 0), (0.018, 0.56, 0.2), front),
        _box((0.0, 0, -0.09), (0.46, 0.54, 0.018), front),
        _bar((0.29, 0, 0), 0.16, (1.5707963, 0, 0), metal),
    ])
    door = "".join([
        _box((0.009, 0.29, 0), (0.018, 0.58, 0.52), front),
        _bar((0.05, 0.5, 0), 0.16, (0, 0, 0), metal),
    ])
    return f"""<?xml version="1.0"?>
<robot name="cabinet">
  <link name="body">{_inertial(20)}{body}</link>
  <link name="drawer_0">{_inertial(2)}{drawer}</link>
  <link name="door_0">{_inertial(2)}{door}</link>
  <joint name="drawer_0_joint" type="prismatic">
    <parent link="body"/><child link="drawer_0"/><origin xyz="0 0 0.672"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.4" effort="100" velocity="1"/><dynamics damping="0.5" friction="0.1"/>
  </joint>
  <joint name="door_0_joint" type="revolute">
    <parent link="body"/><child link="door_0"/><origin xyz="0.25 -0.29 0.281"/><axis xyz="0 0 -1"/>
    <limit lower="0" upper="1.6" effort="100" velocity="1"/><dynamics damping="0.5" friction="0.1"/>
  </joint>
</robot>
"""


def cabinet_urdf():
    make = getattr(partsim, "make_cabinet_urdf", None)
    return (make(), "built-in") if make else (fallback_cabinet_urdf(), "fallback")


def add_cabinet(scene):
    urdf, source = cabinet_urdf()
    loader = scene.create_urdf_loader()
    loader.fix_root_link = True
    desc = loader.parse(urdf, ".")
    for link in desc.links:
        for prefix, label in LABELS.items():
            if link.name == prefix or link.name.startswith(prefix + "_"):
                link.semantic_label = label
    return scene.add_articulation(desc), source


def add_actors(scene, n):
    """n boxes on a grid, each nudged every step (for the bench's 1,000-actor scene)."""
    side = int(math.ceil(math.sqrt(n)))
    actors = []
    for i in range(n):
        b = scene.create_actor_builder()
        b.add_box_collision(half_size=[0.04] * 3)
        b.add_box_visual(half_size=[0.04] * 3, color=[0.2 + 0.6 * (i % 7) / 6, 0.5, 0.8, 1])
        b.set_name(f"box_{i}")
        b.set_initial_pose(partsim.Pose([0.12 * (i % side), 0.12 * (i // side), 0.5]))
        actors.append(b.build_kinematic())
    return actors


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--max-seconds", type=float, default=240.0)
    ap.add_argument("--scene", default="cabinet", choices=["cabinet", "panda", "actors"])
    ap.add_argument("--count", type=int, default=1000)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    ap.add_argument("--step-log", default="",
                    help="JSON file written at exit: [[sim time, wall time before render()], ...]")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    scene = partsim.Scene()
    scene.set_ambient_light([0.4, 0.4, 0.4])
    scene.add_directional_light(np.array([-1.0, -0.5, -1.0]), np.array([1.0, 1.0, 1.0]))
    info = {"scene": args.scene}
    if args.scene == "cabinet":
        cabinet, info["cabinet"] = add_cabinet(scene)
        articulation = cabinet
        eye, target = np.array([1.6, 0.9, 1.1]), np.array([0.0, 0.0, 0.4])
    elif args.scene == "panda":
        articulation = scene.add_articulation(partsim.build_panda().articulation)
        eye, target = np.array([1.6, 0.9, 1.1]), np.array([0.0, 0.0, 0.5])
    else:
        articulation = None
        actors = add_actors(scene, args.count)
        base = [a.get_pose().p.copy() for a in actors]
        eye, target = np.array([3.0, 3.0, 3.0]), np.array([0.0, 0.0, 0.4])

    camera = scene.add_camera("front", args.width, args.height, math.radians(50.0), 0.05, 50.0)
    camera.look_at(eye, target, np.array([0.0, 0.0, 1.0]))
    scene.update_render()
    camera.take_picture()
    depth = np.asarray(camera.get_depth())
    mask = ((depth > 0) * 255).astype(np.uint8)
    from PIL import Image

    mask_path = os.path.join(args.out, "partsim_mask.png")
    Image.fromarray(mask).save(mask_path)
    color = np.asarray(camera.get_color_rgba8())
    Image.fromarray(color[..., :3].copy()).save(os.path.join(args.out, "partsim_color.png"))

    viewer = scene.create_viewer()
    joints = [j for j in articulation.get_active_joints()] if articulation else []
    names = [j.get_name() for j in joints]
    info.update({
        "url": viewer.url,
        "camera": {"position": eye.tolist(), "target": target.tolist(),
                   "fovy_deg": math.degrees(camera.fovy), "width": args.width,
                   "height": args.height},
        "mask": mask_path,
        "joints": names,
    })
    print(json.dumps(info), flush=True)

    def qpos():
        if articulation is None:
            return {}
        q = articulation.get_qpos()
        return {n: float(v) for n, v in zip(names, q)}

    dt = scene.get_timestep()
    start = time.time()
    deadline = start + args.max_seconds
    steps = 0
    last_print = 0.0
    timed_out = False
    step_log = []
    while not viewer.closed:
        scene.step()
        steps += 1
        if articulation is None and steps % 8 == 0:  # every actor moves, ~60 times a second
            t = steps * dt
            for i, a in enumerate(actors):
                a.set_pose(partsim.Pose([base[i][0], base[i][1], 0.5 + 0.05 * math.sin(4 * t + i)]))
        scene.update_render()
        if args.step_log:
            step_log.append((scene.get_time(),
                             time.time()))
        viewer.render()
        now = time.time()
        if now - last_print >= 0.1:
            print(json.dumps({"wall": now, "step": steps, "qpos": qpos()}), flush=True)
            last_print = now
        if now > deadline:
            timed_out = True
            break
        ahead = steps * dt - (now - start)
        if ahead > 0:
            time.sleep(ahead)
        elif ahead < -0.1:  # after a pause: go on from now rather than catch up
            start = now - steps * dt
    print(json.dumps({"closed": viewer.closed, "timeout": timed_out, "step": steps, "qpos": qpos()}),
          flush=True)
    viewer.stop()
    if args.step_log:
        with open(args.step_log, "w") as f:
            json.dump(step_log, f)


if __name__ == "__main__":
    main()
