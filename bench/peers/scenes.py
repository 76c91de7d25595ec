"""The three scenes of the peers bench, described once for every engine: their constants and the
URDF files that every engine loads.

* ``drawer``: the drawer task's cabinet (the first generated StorageFurniture object with a
  drawer, as ``partsim.find_task_objects`` and the drawer environments pick it), written to a
  URDF by partsim (``write_urdf`` of the task's cabinet: its box-shaped meshes as boxes, the
  root pose that stands it on the ground as a fixed joint to a ``world`` link). Fixed base,
  every drawer joint PD-driven toward DRAWER_TARGET.
* ``boxes``: BOX_COUNT free boxes dropped onto the ground from a jittered grid (a pile).
* ``robot``: the KUKA iiwa 14 of ../shared/realdata/kuka_iiwa/model.urdf, fixed base, PD drives
  on its 7 joints holding ROBOT_POSE under gravity; each engine also reports its final joint
  error max |q - ROBOT_POSE|.

The URDFs the engines load are copies made here: without <visual> (SAPIEN 3 makes render
components for visuals, and its renderer needs a Vulkan device the build VM lacks; the others
never draw in this bench), without partsim's own <partsim:...> elements (foreign to the peers),
and without the joints' <dynamics> (friction and damping mean different things in each engine:
PhysX takes URDF damping as its drive's damping and friction as a coefficient); all damping
comes from the PD drives, which every engine gets with the same stiffness and damping. Each
URDF has an SRDF beside it that disables collisions among its own links (partsim's and
SAPIEN's loaders read it; PyBullet does not collide a body's links by default; the MuJoCo
module applies the same pairs).
"""

import itertools
import os
import re

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
REALDATA = os.path.join(os.path.dirname(REPO), "shared", "realdata")
KUKA_URDF = os.path.join(REALDATA, "kuka_iiwa", "model.urdf")

SCENES = ("drawer", "boxes", "robot")
# default steps per measurement (each scene runs at least a second in the slowest engine here)
DEFAULT_STEPS = {"drawer": 150000, "boxes": 500, "robot": 150000}

GRAVITY = (0.0, 0.0, -9.81)
FRICTION = 0.5  # every contact's Coulomb coefficient (static = dynamic), restitution 0

# drawer: PD drives on the prismatic drawer joints
DRAWER_STIFFNESS = 1000.0  # N/m
DRAWER_DAMPING = 100.0  # N s/m
DRAWER_TARGET = 0.2  # m, within every drawer's range (0.32 m and more)

# boxes: a 10 x 10 x 3 grid of 10 cm cubes, jittered, falling onto the ground
BOX_COUNT = 300
BOX_HALF = 0.05  # m
BOX_DENSITY = 1000.0  # kg/m^3: 1 kg each


def box_poses(count=BOX_COUNT):
    """[(p (3,), q (4,) w, x, y, z)]: the boxes' start poses, the same in every engine."""
    rng = np.random.default_rng(0)
    out = []
    for k in range(count):
        layer, i, j = k // 100, (k % 100) // 10, k % 10
        p = np.array([0.13 * (i - 4.5), 0.13 * (j - 4.5), 0.1 + 0.2 * layer])
        p[:2] += rng.uniform(-0.02, 0.02, 2)
        axis = rng.normal(size=3)
        angle = rng.uniform(0, 0.6)
        q = np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * axis / np.linalg.norm(axis)])
        out.append((p, q))
    return out


# robot: the KUKA iiwa's joints 1-7, a bent pose within the limits, and gains a natural
# frequency near 50 rad/s on each joint's own inertia gives, critically damped or nearly, so
# that PyBullet's explicit PD (PD_CONTROL) stays stable at the common step
ROBOT_POSE = np.array([0.5, 0.6, -0.4, -1.2, 0.3, 0.8, 0.2])  # rad
ROBOT_STIFFNESS = np.array([3000.0, 3000.0, 1500.0, 1500.0, 300.0, 150.0, 30.0])  # N m/rad
ROBOT_DAMPING = np.array([100.0, 100.0, 50.0, 50.0, 3.0, 2.0, 0.3])  # N m s/rad
ROBOT_MAX_ERROR = 0.05  # rad: the test's bound on every engine's final joint error


def default_timestep():
    """partsim's default step (SceneConfig().timestep), the common dt of every engine."""
    import partsim

    return partsim.Scene().get_timestep()


def _strip(text, mesh_dir=None):
    """URDF text without <visual>, <partsim:...> and <dynamics> elements; relative mesh paths made
    absolute from mesh_dir."""
    text = re.sub(r"<visual\b.*?</visual>", "", text, flags=re.S)
    text = re.sub(r"<partsim:[^>]*/>", "", text)
    text = re.sub(r"<dynamics\b[^>]*/>", "", text)
    text = text.replace(' xmlns:partsim="https://partsim.dev/urdf"', "")
    # partsim writes effort="0" velocity="0" for "no limit"; MuJoCo reads effort as a force range
    text = re.sub(r'\s(effort|velocity)="0"', "", text)
    if mesh_dir:
        text = re.sub(
            r'filename="(?!/)([^"]+)"',
            lambda m: f'filename="{os.path.join(mesh_dir, m.group(1))}"',
            text,
        )
    return re.sub(r"\n\s*\n", "\n", text)


def _write_srdf(urdf_path, text):
    """<urdf stem>.srdf disabling every pair of the URDF's links; returns the pairs."""
    # 'world' is no body in partsim's and MuJoCo's readers (the fixed joint to it fixes the root)
    links = [n for n in re.findall(r'<link\s+name="([^"]+)"', text) if n != "world"]
    pairs = list(itertools.combinations(links, 2))
    lines = ['<?xml version="1.0"?>', '<robot name="peers">']
    lines += [f'  <disable_collisions link1="{a}" link2="{b}" reason="bench"/>' for a, b in pairs]
    lines.append("</robot>")
    with open(os.path.splitext(urdf_path)[0] + ".srdf", "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    return pairs


def prepare_assets(out_dir):
    """Writes out_dir/cabinet.urdf (+ .srdf, meshes) and out_dir/kuka.urdf (+ .srdf); returns a
    dict of facts the report prints (the cabinet's object index, links, joints, boxes)."""
    import partsim

    os.makedirs(out_dir, exist_ok=True)
    info = {}
    # the drawer task's cabinet, as the task builds it (boxes for box meshes), written by partsim
    o = partsim.TaskOptions()
    o.type = partsim.TaskType.PULL_DRAWER
    o.object_index = partsim.find_task_objects(partsim.TaskType.PULL_DRAWER, 1, 0)[0]
    o.cameras = False
    task = partsim.ArticulationTask(o)
    full = os.path.join(out_dir, "cabinet_partsim.urdf")
    partsim.write_urdf(task.object.get_desc(), full)
    with open(full, encoding="utf-8") as f:
        text = _strip(f.read(), out_dir)
    path = os.path.join(out_dir, "cabinet.urdf")
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    _write_srdf(path, text)
    info["cabinet_object_index"] = o.object_index
    info["cabinet_joints"] = len(re.findall(r'type="prismatic"', text))
    info["cabinet_boxes"] = text.count("<box ")
    info["cabinet_meshes"] = text.count("<mesh ")
    # the KUKA iiwa
    with open(KUKA_URDF, encoding="utf-8") as f:
        text = _strip(f.read(), os.path.dirname(KUKA_URDF))
    path = os.path.join(out_dir, "kuka.urdf")
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    _write_srdf(path, text)
    return info


def srdf_pairs(urdf_path):
    """The (link1, link2) pairs the SRDF beside urdf_path disables."""
    with open(os.path.splitext(urdf_path)[0] + ".srdf", encoding="utf-8") as f:
        return re.findall(r'link1="([^"]+)" link2="([^"]+)"', f.read())
