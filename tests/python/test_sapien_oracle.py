"""partsim's SAPIEN adapter against the real SAPIEN 3 (the `sapien` wheel from PyPI, PhysX on
the CPU) as the oracle: the same short scenario, written once in SAPIEN's API, runs in both, and
what a script observes is compared within the tolerance each test states.

Physics, kinematics and camera geometry: SAPIEN 3's renderer needs a Vulkan device it accepts,
and it refuses Mesa's CPU driver (lavapipe: "Failed to find a supported physical device"), so
SAPIEN's pictures cannot be made on a machine without a GPU; its camera components compute their
matrices without a device, and those are compared. For the same reason SAPIEN's scenes here hold
only the PhysX system, and URDFs are given to SAPIEN without their <visual> elements (its loader
makes render materials for them).

Differences by design, each stated where a test allows for it: PhysX and MuJoCo are different
solvers (a resting contact is 4 PhysX points against MuJoCo's 4 to 8, an impulse split
differently among them, while the total is the weight's); PhysX computes in float32; SAPIEN
does not normalize a ray's direction.
"""

import math
import os
import re

import numpy as np
import pytest

_LOCK = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "requirements.lock")
try:
    import sapien
except ImportError as e:
    # the lock installs SAPIEN: in the project's venv a failed import is a failure, not a skip
    if "\nsapien==" in open(_LOCK, encoding="utf-8").read():
        raise ImportError(f"SAPIEN 3 is in requirements.lock but does not import ({e}): run "
                          "scripts/setup_venv.sh") from e
    pytest.skip(f"SAPIEN 3 is not installed ({e})", allow_module_level=True)

import partsim  # noqa: E402
import partsim.sapien as psapien  # noqa: E402  partsim's SAPIEN adapter

REALDATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared",
                        "realdata")
G = 9.81
DT = 1 / 500.0


def new_scene(sp):
    """A scene with gravity and a 500 Hz step, in SAPIEN (PhysX only) or in partsim."""
    if sp is sapien:
        scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    else:
        scene = psapien.Scene()
    scene.set_timestep(DT)
    return scene


def add_ground(sp, scene):
    if sp is sapien:
        scene.add_ground(0, render=False)
    else:
        scene.add_ground(0)


def both(fn, *args):
    """fn(sapien, ...) and fn(partsim, ...)."""
    return fn(sapien, *args), fn(psapien, *args)


def same_rotation(q0, q1, tol):
    """Quaternions (w, x, y, z) of the same rotation, up to sign."""
    q0, q1 = np.asarray(q0, float), np.asarray(q1, float)
    return min(np.abs(q0 - q1).max(), np.abs(q0 + q1).max()) <= tol


# ------------------------------------------------------------------------------ kinematics

def urdf_without_visuals(path, tmp_path):
    """The URDF at `path` with its <visual> elements removed, beside links to its folders."""
    text = re.sub(r"<visual\b.*?</visual>", "", open(path).read(), flags=re.S)
    folder = os.path.dirname(path)
    for name in os.listdir(folder):
        if os.path.isdir(os.path.join(folder, name)):
            os.symlink(os.path.join(folder, name), tmp_path / name)
    out = tmp_path / os.path.basename(path)
    out.write_text(text)
    return str(out)


def link_poses(sp, path, qpos_list):
    scene = new_scene(sp)
    loader = scene.create_urdf_loader()
    loader.fix_root_link = True
    robot = loader.load(path)
    robot.root_pose = sp.Pose([0.1, -0.2, 0.3], [math.cos(0.3), 0, 0, math.sin(0.3)])
    out = []
    for q in qpos_list:
        robot.set_qpos(np.asarray(q, dtype=np.float32 if sp is sapien else np.float64))
        poses = {l.name: l.entity_pose for l in robot.links}
        out.append({name: (np.array(p.p), np.array(p.q)) for name, p in poses.items()})
    return robot.dof, out


@pytest.mark.parametrize("urdf", ["kuka_iiwa/model.urdf", "partnet-mobility-3763/mobility.urdf"])
def test_link_poses_of_a_urdf_at_given_qpos(urdf, tmp_path):
    path = os.path.join(REALDATA, urdf)
    if not os.path.isfile(path):
        pytest.skip(f"{path} is not there (../shared/realdata)")
    rng = np.random.default_rng(0)
    scene = new_scene(psapien)
    loader = scene.create_urdf_loader()
    loader.fix_root_link = True
    limits = loader.load(path).get_qlimits()
    lo = np.where(np.isfinite(limits[:, 0]), limits[:, 0], -math.pi)
    hi = np.where(np.isfinite(limits[:, 1]), limits[:, 1], math.pi)
    qs = [lo + (hi - lo) * rng.random(len(lo)) for _ in range(5)]
    qs = [np.round(q, 6) for q in qs]  # exact in float32 and float64 alike, to 1e-7
    (dof_s, real), (dof_p, ours) = link_poses(sapien, urdf_without_visuals(path, tmp_path),
                                              qs), link_poses(psapien, path, qs)
    assert dof_s == dof_p
    for k, (a, b) in enumerate(zip(real, ours)):
        assert sorted(a) == sorted(b)
        for name in a:
            # PhysX keeps poses in float32: 1e-6 m and 1e-6 in the quaternion
            np.testing.assert_allclose(a[name][0], b[name][0], atol=1e-6, err_msg=f"{name} q{k}")
            assert same_rotation(a[name][1], b[name][1], 2e-6), (name, k, a[name][1], b[name][1])


# ------------------------------------------------------------------------------ contacts

def box_on_box(sp):
    """A 0.2 m box on a fixed 0.4 m box after 1 s: (contact points between them, the summed
    impulse on the top box per step, its height)."""
    scene = new_scene(sp)
    base = scene.create_actor_builder()
    base.add_box_collision(half_size=[0.2, 0.2, 0.2])
    base = base.build_static(name="base")
    base.set_pose(sp.Pose([0, 0, 0.2]))
    top = scene.create_actor_builder()
    top.add_box_collision(half_size=[0.1, 0.1, 0.1])
    top = top.build(name="top")
    top.set_pose(sp.Pose([0, 0, 0.5]))
    for _ in range(500):
        scene.step()
    points, impulse = 0, np.zeros(3)
    for c in scene.get_contacts():
        names = {b.entity.name for b in c.bodies}
        if names != {"base", "top"}:
            continue
        sign = 1.0 if c.bodies[0].entity.name == "top" else -1.0
        for p in c.points:
            points += 1
            impulse += sign * np.asarray(p.impulse)
    mass = top.find_component_by_type(sp.physx.PhysxRigidDynamicComponent).mass
    return points, impulse, float(top.pose.p[2]), mass


def test_a_box_resting_on_a_box():
    (n_s, imp_s, z_s, m_s), (n_p, imp_p, z_p, m_p) = both(box_on_box)
    assert m_s == pytest.approx(8.0, rel=1e-5) and m_p == pytest.approx(8.0, rel=1e-9)
    # resting 0.1 above the base's top (PhysX keeps a contact offset of its own: 1 mm)
    assert z_s == pytest.approx(0.5, abs=2e-3) and z_p == pytest.approx(0.5, abs=2e-3)
    # the impulse on the top box per step is its weight times the step, in both
    for imp in (imp_s, imp_p):
        assert abs(imp[2]) == pytest.approx(8.0 * G * DT, rel=0.02)
        assert np.abs(imp[:2]).max() < 1e-3 * abs(imp[2])
    # PhysX: the 4 corners of the face; MuJoCo: from 4 to 8 points on the face
    assert n_s == 4 and 4 <= n_p <= 8


# ------------------------------------------------------------------------------ drives

def one_joint(sp, scene, joint_type, limits):
    """A fixed base and a child on one joint about (or along) the world's y, the child 0.3 m
    out along x."""
    builder = scene.create_articulation_builder()
    root = builder.create_link_builder()
    root.set_name("root")
    root.add_box_collision(half_size=[0.05] * 3)
    child = builder.create_link_builder(root)
    child.set_name("child")
    child.set_joint_name("j")
    child.add_box_collision(sp.Pose([0.3, 0, 0]), half_size=[0.05] * 3)
    about_y = [math.sqrt(0.5), 0, 0, math.sqrt(0.5)]
    child.set_joint_properties(joint_type, limits, sp.Pose([0, 0, 1.0], about_y),
                               sp.Pose([0, 0, 0], about_y))
    robot = builder.build(fix_root_link=True)
    return robot, robot.get_active_joints()[0]


def driven(sp, joint_type, limits, target, stiffness, damping):
    """The joint's position every 0.05 s over 2 s, driven to `target` by a PD drive."""
    scene = new_scene(sp)
    robot, joint = one_joint(sp, scene, joint_type, limits)
    joint.set_drive_property(stiffness, damping)
    joint.set_drive_target(target)
    trace = []
    for k in range(1000):
        scene.step()
        if k % 25 == 24:
            trace.append(float(robot.get_qpos()[0]))
    return np.array(trace)


def test_a_pendulum_under_a_pd_drive_follows_the_same_trajectory():
    # a 1 kg box 0.3 m out on a hinge: gravity against a stiff drive, under-damped
    real, ours = both(driven, "revolute", [[-math.pi, math.pi]], 0.5, 300.0, 5.0)
    # the two solvers' drives (PhysX's implicit spring, partsim's PD) and integrators differ:
    # 0.02 rad over 2 s, and the same rest
    np.testing.assert_allclose(ours, real, atol=0.02)
    assert ours[-1] == pytest.approx(real[-1], abs=2e-3)


def test_a_drawer_under_a_pd_drive_follows_the_same_trajectory():
    # the slide is horizontal (along the world's y): gravity does not move it
    real, ours = both(driven, "prismatic", [[0.0, 0.4]], 0.3, 200.0, 20.0)
    np.testing.assert_allclose(ours, real, atol=5e-3)
    assert ours[-1] == pytest.approx(0.3, abs=1e-4)
    # PhysX puts a slow body to sleep where it is (the drawer froze at 0.3024, 0.55 s in, its
    # overshoot not yet damped); partsim's bodies never sleep
    assert real[-1] == pytest.approx(0.3, abs=5e-3)


def test_joint_limits_hold_a_drive_that_pulls_past_them():
    real, ours = both(driven, "revolute", [[-0.5, 0.5]], 1.5, 300.0, 5.0)
    # both stop at the limit (PhysX lets a limit be passed by its contact distance; MuJoCo's
    # soft limit by a few mrad under the drive's pull)
    assert real[-1] == pytest.approx(0.5, abs=0.02)
    assert ours[-1] == pytest.approx(0.5, abs=0.02)
    assert ours.max() < 0.55 and real.max() < 0.55


# ------------------------------------------------------------------------------ entities

def ecs_body(sp):
    """A body of a box and a denser sphere built from components (SAPIEN 3's entity-component
    form) and dropped on the ground: its mass properties before and after it joins the scene,
    its rest pose, and its default damping."""
    scene = new_scene(sp)
    add_ground(sp, scene)
    material = sp.physx.PhysxMaterial(0.5, 0.5, 0.0)
    box = sp.physx.PhysxCollisionShapeBox([0.1, 0.05, 0.02], material)
    ball = sp.physx.PhysxCollisionShapeSphere(0.03, material)
    ball.set_local_pose(sp.Pose([0.08, 0.0, 0.05]))
    ball.set_density(3000)
    body = sp.physx.PhysxRigidDynamicComponent()
    body.attach(box)
    body.attach(ball)

    def props():
        m = body.cmass_local_pose.to_transformation_matrix()
        rot = m[:3, :3]
        return body.mass, rot @ np.diag(body.inertia) @ rot.T, m[:3, 3].copy()

    before = props()
    entity = sp.Entity()
    entity.set_name("body")
    entity.add_component(body)
    entity.set_pose(sp.Pose([0, 0, 0.3]))
    scene.add_entity(entity)
    after = props()
    for _ in range(1000):
        scene.step()
    same = entity.find_component_by_type(sp.physx.PhysxRigidDynamicComponent) is body
    return before, after, entity.pose, same, body.angular_damping, body.linear_damping


def test_a_body_built_from_components_has_physx_mass_properties_and_rests_alike():
    real, ours = both(ecs_body)
    for (m_s, i_s, c_s), (m_p, i_p, c_p) in ((real[0], ours[0]), (real[1], ours[1])):
        # computed from the shapes as PhysX does, before and after joining the scene (float32
        # in PhysX): the inertia tensor about the centre of mass, in the body's frame
        assert m_p == pytest.approx(m_s, rel=1e-5)
        np.testing.assert_allclose(i_p, i_s, rtol=1e-4, atol=1e-9)
        np.testing.assert_allclose(c_p, c_s, atol=1e-6)
    assert real[3] and ours[3]
    # SAPIEN's default damping of a dynamic body: 0.05 angular, none linear
    assert (ours[4], ours[5]) == pytest.approx((real[4], real[5]), abs=1e-7)
    # it lies flat on the box's bottom face in both
    assert ours[2].p[2] == pytest.approx(real[2].p[2], abs=2e-3)
    assert same_rotation(ours[2].q, real[2].q, 1e-3)


# ------------------------------------------------------------------------------ cameras

LOOK = [math.cos(0.2), 0.0, math.sin(0.2), 0.0]  # pitched down by 0.4 rad about y


def camera_on_entity(sp, entity_pose, **parameters):
    """A 128 x 96 camera on an entity of its own (SAPIEN 3's camera component). SAPIEN computes
    the matrices without a render device, so they can be compared here."""
    cam = sp.render.RenderCameraComponent(128, 96)
    cam.set_fovy(0.9)
    cam.near, cam.far = 0.05, 20.0
    if parameters:
        cam.set_perspective_parameters(**parameters)
    entity = sp.Entity()
    entity.add_component(cam)
    entity.set_pose(entity_pose)
    return cam, entity


def camera_matrices(cam):
    return (np.asarray(cam.get_intrinsic_matrix(), float),
            np.asarray(cam.get_extrinsic_matrix(), float),
            np.asarray(cam.get_model_matrix(), float))


@pytest.mark.parametrize("parameters", [
    {}, dict(near=0.05, far=20.0, fx=70.0, fy=72.0, cx=60.0, cy=50.0, skew=0.0)])
def test_camera_intrinsics_and_extrinsics_are_sapiens(parameters):
    real_cam, real_entity = camera_on_entity(sapien, sapien.Pose([-1.0, 0.2, 0.8], LOOK),
                                             **parameters)
    real = camera_matrices(real_cam)  # (SAPIEN's component lives as long as its entity)
    cam, entity = camera_on_entity(psapien, psapien.Pose([-1.0, 0.2, 0.8], LOOK), **parameters)
    before = camera_matrices(cam)
    scene = psapien.Scene()
    scene.add_entity(entity)
    after = camera_matrices(cam)  # now partsim's camera's, read through the adapter
    for ours in (before, after):
        np.testing.assert_allclose(ours[0], real[0], atol=1e-4)  # K: principal point w/2, h/2
        np.testing.assert_allclose(ours[1], real[1], atol=1e-5)  # world to OpenCV camera
        np.testing.assert_allclose(ours[2], real[2], atol=1e-5)  # OpenGL camera in the world


def test_a_world_point_lands_on_the_pixel_sapiens_matrices_give():
    point = np.array([0.3, -0.1, 0.1])
    real_cam, real_entity = camera_on_entity(sapien, sapien.Pose([-1.0, 0.2, 0.8], LOOK))
    k, ext, _ = camera_matrices(real_cam)
    u, v, w = k @ (ext @ np.append(point, 1.0))
    u, v = u / w, v / w  # SAPIEN: pixel (i, j) covers [j, j + 1) x [i, i + 1)
    cam, entity = camera_on_entity(psapien, psapien.Pose([-1.0, 0.2, 0.8], LOOK))
    scene = psapien.Scene()
    scene.set_ambient_light([1, 1, 1])
    scene.add_entity(entity)
    dot = scene.create_actor_builder()
    dot.add_sphere_visual(radius=0.03, material=[1, 0, 0])
    dot.build_static(name="dot").set_pose(psapien.Pose(point))
    scene.update_render()
    cam.take_picture()
    seg = cam.get_picture("Segmentation")[..., 1]
    rows, cols = np.nonzero(seg == scene.find_actor_by_name("dot").per_scene_id)
    assert len(rows) >= 4
    # the dot's pixels centre on the point: within a quarter pixel of SAPIEN's projection
    assert cols.mean() + 0.5 == pytest.approx(u, abs=0.25)
    assert rows.mean() + 0.5 == pytest.approx(v, abs=0.25)


# ------------------------------------------------------------------------------ queries

def rays(sp):
    """Rays against a box on the ground and a link of an articulation: (distance, position,
    normal, the name of the entity hit) for each, None for a miss."""
    scene = new_scene(sp)
    add_ground(sp, scene)
    b = scene.create_actor_builder()
    b.add_box_collision(half_size=[0.1, 0.2, 0.3])
    box = b.build_static(name="box")
    box.set_pose(sp.Pose([1, 0, 0.3], [math.cos(0.2), 0, 0, math.sin(0.2)]))
    robot, _ = one_joint(sp, scene, "revolute", [[-1, 1]])
    robot.set_root_pose(sp.Pose([-1, 0, 0]))
    scene.step()
    out = []
    for origin, direction in (([0, 0, 0.2], [1, 0, 0]), ([0, 0, 0.2], [1, 0.1, 0]),
                              ([0, 0, 1], [0, 0, -1]), ([0, 0, 0.2], [0, 1, 0]),
                              ([-1.0, 0.01, 2], [0, 0, -1])):
        hit = scene.physx_system.raycast(origin, direction, 10)
        out.append(None if hit is None else (hit.distance, np.array(hit.position),
                                             np.array(hit.normal), hit.component.entity.name))
    return out


def test_rays_meet_the_same_shapes_at_the_same_points():
    real, ours = both(rays)
    for k, (r, o) in enumerate(zip(real, ours)):
        assert (r is None) == (o is None)
        if r is None:
            continue
        assert o[3] == r[3]
        np.testing.assert_allclose(o[1], r[1], atol=1e-5)  # PhysX: float32
        np.testing.assert_allclose(o[2], r[2], atol=1e-4)
        if k == 1:
            # a direction of length 1.005: partsim normalizes it and reports metres; SAPIEN
            # hands it to PhysX as it is and reports the ray's parameter (metres / 1.005)
            assert o[0] == pytest.approx(np.linalg.norm(o[1] - [0, 0, 0.2]), abs=1e-9)
            assert r[0] == pytest.approx(o[0] / np.linalg.norm([1, 0.1, 0]), abs=1e-5)
        else:
            assert o[0] == pytest.approx(r[0], abs=1e-5)


def incoming_forces(sp):
    """A 1 kg box 0.3 m out on a hinge, held level by a stiff drive under a turned root, at rest:
    the links' incoming joint forces."""
    scene = new_scene(sp)
    robot, joint = one_joint(sp, scene, "revolute", [[-3, 3]])
    robot.set_root_pose(sp.Pose([0.5, 0.2, 0], [math.cos(0.3), 0, 0, math.sin(0.3)]))
    joint.set_drive_property(1e4, 100)
    joint.set_drive_target(0.0)
    for _ in range(2000):
        scene.step()
    return np.asarray(robot.get_link_incoming_joint_forces(), dtype=float)


def test_incoming_joint_forces_hold_the_same_weight_and_moment():
    real, ours = both(incoming_forces)
    assert real.shape == ours.shape == (2, 6)
    np.testing.assert_allclose(ours[0], 0.0)
    # force then torque about the hinge, in its frame: the weight (9.81 N up) and the moment
    # 9.81 N x 0.3 m the drive holds; PhysX in float32 and a drive offset of 3e-4 rad
    np.testing.assert_allclose(ours[1], real[1], atol=5e-3)
    assert ours[1, 2] == pytest.approx(G, rel=1e-3)
