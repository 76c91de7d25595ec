"""Scene, builders and handles (physics bindings): the binding surface plus a few physics smoke
tests; the physics itself is tested in C++."""

import gc
import math
import threading
import time

import numpy as np
import pytest

import partsim
from conftest import assert_vec, build_box


# ---------------------------------------------------------------- scene construction

def test_scene_config_and_keywords():
    config = partsim.SceneConfig()
    config.timestep = 0.01
    config.gravity = [0, 0, -1]
    config.integrator = partsim.Integrator.RK4
    scene = partsim.Scene(config)
    assert scene.timestep == pytest.approx(0.01)
    np.testing.assert_allclose(scene.gravity, [0, 0, -1])
    assert scene.get_config().integrator == partsim.Integrator.RK4

    scene = partsim.Scene(timestep=0.004, gravity=[0, 0, -2])
    assert scene.get_timestep() == pytest.approx(0.004)
    assert_vec(scene.get_gravity(), (3,))
    scene.timestep = 0.002
    scene.gravity = [0, 0, -9.81]
    assert scene.timestep == pytest.approx(0.002)
    assert scene.get_time() == 0.0
    scene.step()
    assert scene.get_time() == pytest.approx(0.002)


def test_scene_rejects_bad_config():
    with pytest.raises(partsim.PartsimError, match="timestep"):
        partsim.Scene(timestep=-1.0)
    with pytest.raises(TypeError):
        partsim.Scene(gravity=[0, 0])


def test_materials():
    m = partsim.PhysicalMaterial(1.0, 0.8, 0.1)
    assert (m.static_friction, m.dynamic_friction, m.restitution) == (1.0, 0.8, 0.1)
    m2 = partsim.Scene.create_physical_material(0.3, 0.2, 0.0)
    assert m2.static_friction == 0.3
    scene = partsim.Scene()
    assert scene.create_physical_material(0.3, 0.2, 0.0).dynamic_friction == 0.2


# ---------------------------------------------------------------- actors

def test_actor_builder_all_shapes(scene):
    mat = scene.create_physical_material(1.0, 1.0, 0.0)
    builder = scene.create_actor_builder()
    # the adders return the builder itself, so calls chain
    assert builder.add_box_collision(half_size=[0.1, 0.2, 0.3], material=mat) is builder
    builder.add_sphere_collision(partsim.Pose([0, 0, 0.5]), 0.1, None, 500)
    builder.add_capsule_collision(radius=0.05, half_length=0.1)
    builder.add_cylinder_collision(radius=0.05, half_length=0.1, density=200)
    builder.add_box_visual(half_size=[0.1, 0.2, 0.3], color=[1, 0, 0, 1], name="body")
    builder.add_sphere_visual(radius=0.1).add_capsule_visual(radius=0.1, half_length=0.2)
    builder.add_cylinder_visual(radius=0.1, half_length=0.2)
    builder.set_name("thing").set_initial_pose(partsim.Pose([0, 0, 1]))
    desc = builder.get_desc()
    assert [c.type for c in desc.collisions] == [
        partsim.ShapeType.BOX, partsim.ShapeType.SPHERE, partsim.ShapeType.CAPSULE,
        partsim.ShapeType.CYLINDER]
    assert desc.collisions[0].material.static_friction == 1.0
    assert desc.collisions[1].material is None
    assert len(desc.visuals) == 4 and desc.visuals[0].name == "body"
    actor = builder.build()
    assert actor.name == "thing" and actor.get_name() == "thing"
    assert actor.type == partsim.ActorType.DYNAMIC
    assert actor.get_mass() > 0
    np.testing.assert_allclose(actor.get_pose().p, [0, 0, 1])


def test_build_static_and_kinematic(scene):
    b = scene.create_actor_builder().add_box_collision(half_size=[0.1] * 3)
    assert b.build_static().type == partsim.ActorType.STATIC
    b = scene.create_actor_builder().add_box_collision(half_size=[0.1] * 3)
    assert b.build_kinematic().type == partsim.ActorType.KINEMATIC
    b = scene.create_actor_builder().add_box_collision(half_size=[0.1] * 3)
    assert b.build(kinematic=True).type == partsim.ActorType.KINEMATIC


def test_set_mass_and_inertia(scene):
    b = scene.create_actor_builder().add_box_collision(half_size=[0.1] * 3)
    b.set_mass_and_inertia(2.5, partsim.Pose(), [0.01, 0.02, 0.03])
    assert b.build().get_mass() == pytest.approx(2.5)


def test_actor_state_arrays(scene):
    scene.gravity = [0, 0, 0]
    box = build_box(scene, z=1.0)
    for get in (box.get_velocity, box.get_angular_velocity):
        assert_vec(get(), (3,))
    box.set_velocity([1, 0, 0])
    box.set_angular_velocity([0, 0, 1])
    np.testing.assert_allclose(box.get_velocity(), [1, 0, 0])
    np.testing.assert_allclose(box.get_angular_velocity(), [0, 0, 1])
    box.set_pose(partsim.Pose([1, 2, 3], [0, 0, 0, 1]))
    np.testing.assert_allclose(box.get_pose().p, [1, 2, 3])
    # q and -q are the same rotation
    assert abs(abs(box.get_pose().q[3]) - 1) < 1e-9
    box.add_force_torque([0, 0, 1], [0, 0, 0])
    box.add_force_at_point([0, 0, 1], [1, 2, 3])
    scene.step()


def test_actor_list_and_removal(scene):
    ground = scene.add_ground(altitude=0.0)
    a = build_box(scene, name="a")
    b = build_box(scene, z=1.0, name="b")
    names = [x.name for x in scene.get_actors()]
    assert names == ["ground", "a", "b"]
    assert ground.type == partsim.ActorType.STATIC
    assert scene.find_actor_by_name("b") == b
    assert len({a, b, scene.find_actor_by_name("a")}) == 2
    scene.remove_actor(a)
    assert [x.name for x in scene.get_actors()] == ["ground", "b"]
    with pytest.raises(partsim.PartsimError):
        a.get_pose()
    with pytest.raises(partsim.PartsimError, match="nope"):
        scene.find_actor_by_name("nope")


def test_actor_desc_round_trip(scene):
    desc = partsim.ActorDesc()
    desc.name = "from_desc"
    shape = partsim.CollisionShape()
    shape.type = partsim.ShapeType.SPHERE
    shape.radius = 0.05
    desc.collisions = [shape]
    desc.pose = partsim.Pose([0, 0, 2])
    partsim.validate(desc)
    actor = scene.add_actor(desc)
    assert actor.get_desc().collisions[0].radius == pytest.approx(0.05)
    bad = partsim.ActorDesc()
    # list attributes are copies: edit the list, then assign it back
    shapes = [partsim.CollisionShape()]
    shapes[0].density = -1.0
    bad.collisions = shapes
    with pytest.raises(partsim.PartsimError, match="density"):
        partsim.validate(bad, "here")


# ---------------------------------------------------------------- articulations

def build_pendulum(scene, joint_type="revolute", fix=True):
    """A fixed base and one link on a joint about z (revolute) or along x (prismatic)."""
    ab = scene.create_articulation_builder()
    ab.set_name("pendulum")
    base = ab.create_link_builder()
    base.set_name("base").add_box_collision(half_size=[0.1] * 3)
    arm = ab.create_link_builder(base)
    arm.set_name("arm").set_joint_name("j0")
    arm.set_joint_properties(joint_type, [-1, 1], partsim.Pose([0, 0, 0.5], [0.7071068, 0, -0.7071068, 0]),
                             partsim.Pose(), 0.0, 0.1)
    arm.add_box_collision(partsim.Pose([0.2, 0, 0]), half_size=[0.2, 0.05, 0.05])
    arm.add_box_visual(partsim.Pose([0.2, 0, 0]), half_size=[0.2, 0.05, 0.05])
    return ab.build(fix_root_link=fix)


def test_articulation_builder(scene):
    art = build_pendulum(scene)
    assert art.dof == 1 and art.get_dof() == 1
    assert art.name == "pendulum"
    assert art.has_fixed_root() and not art.is_kinematic()
    assert [l.name for l in art.get_links()] == ["base", "arm"]
    assert [j.name for j in art.get_joints()] == ["j0"]
    joint = art.get_active_joints()[0]
    assert joint.type == partsim.JointType.REVOLUTE
    assert joint.get_dof() == 1 and joint.get_dof_index() == 0
    np.testing.assert_allclose(joint.get_limits(), [-1, 1])  # (lower, upper)
    assert joint.get_damping() == pytest.approx(0.1)
    assert joint.get_parent_link().name == "base"
    assert joint.get_child_link().name == "arm"
    assert art.find_link_by_name("arm").get_index() == 1
    assert art.find_joint_by_name("j0").get_index() == 1
    assert art.get_link(1).get_parent_index() == 0
    assert scene.get_articulations()[0] == art


def test_joint_type_enum_and_string(scene):
    ab = scene.create_articulation_builder()
    root = ab.create_link_builder()
    root.add_box_collision(half_size=[0.1] * 3)
    for i, t in enumerate([partsim.JointType.PRISMATIC, "prismatic", "fixed", "continuous",
                           partsim.JointType.REVOLUTE]):
        child = ab.create_link_builder(root)
        child.set_joint_properties(t, [-0.5, 0.5], partsim.Pose([0, 0, i]), partsim.Pose())
        child.add_sphere_collision(radius=0.05)
    art = ab.build(fix_root_link=True)
    assert [j.type for j in art.get_joints()] == [
        partsim.JointType.PRISMATIC, partsim.JointType.PRISMATIC, partsim.JointType.FIXED,
        partsim.JointType.CONTINUOUS, partsim.JointType.REVOLUTE]
    assert art.dof == 4


def test_unknown_joint_type_string(scene):
    ab = scene.create_articulation_builder()
    link = ab.create_link_builder(ab.create_link_builder())
    with pytest.raises(partsim.PartsimError, match="type.*hinge"):
        link.set_joint_properties("hinge", [0, 1], partsim.Pose(), partsim.Pose())


def test_articulation_arrays_shapes(cabinet):
    art = cabinet
    n = art.dof
    assert n == 2
    for get in (art.get_qpos, art.get_qvel, art.get_qacc, art.get_qf, art.get_drive_target,
                art.get_drive_velocity_target, art.compute_passive_force):
        assert_vec(get(), (n,))
    assert_vec(art.get_qlimits(), (n, 2))
    assert_vec(art.compute_manipulator_inertia_matrix(), (n, n))
    assert_vec(art.compute_link_jacobian(1), (6, n))
    nlinks = len(art.get_links())
    assert_vec(art.compute_world_cartesian_jacobian(), (6 * nlinks, n))
    assert_vec(art.compute_forward_dynamics(np.zeros(n)), (n,))
    assert_vec(art.compute_inverse_dynamics(np.zeros(n)), (n,))
    assert_vec(art.compute_passive_force(gravity=False, coriolis_and_centrifugal=False), (n,))
    for link in art.get_links():
        assert_vec(link.get_velocity(), (3,))
        assert_vec(link.get_angular_velocity(), (3,))
        assert_vec(link.get_inertia(), (3,))
        assert_vec(link.get_pose().p, (3,))
        assert_vec(link.get_cmass_pose().q, (4,))
        assert link.get_mass() > 0
    for joint in art.get_joints():
        assert joint.get_limits().shape == (2,)
        assert_vec(joint.get_global_axis(), (3,))
        assert isinstance(joint.get_global_pose(), partsim.Pose)
        assert isinstance(joint.get_pose_in_parent(), partsim.Pose)
        assert isinstance(joint.get_pose_in_child(), partsim.Pose)
    assert_vec(art.get_root_velocity(), (3,))
    assert_vec(art.get_root_angular_velocity(), (3,))


def test_articulation_setters_round_trip(cabinet):
    art = cabinet
    art.set_qpos([0.2, 0.1])
    np.testing.assert_allclose(art.get_qpos(), [0.2, 0.1])
    art.set_qpos(np.array([0.3, 0.05], dtype=np.float32))  # converted to float64
    np.testing.assert_allclose(art.get_qpos(), [0.3, 0.05], atol=1e-7)
    art.set_qvel([0.5, -0.5])
    np.testing.assert_allclose(art.get_qvel(), [0.5, -0.5])
    art.set_qf([1.0, 2.0])
    np.testing.assert_allclose(art.get_qf(), [1.0, 2.0])
    art.set_qacc([0.0, 0.0])
    art.set_qlimits(np.array([[-1.0, 0.4], [0.0, 0.2]]))
    np.testing.assert_allclose(art.get_qlimits(), [[-1.0, 0.4], [0.0, 0.2]])
    joint = art.find_joint_by_name("hinge")
    joint.set_limits(-1.5, 0.5)
    np.testing.assert_allclose(joint.get_limits(), [-1.5, 0.5])
    joint.set_friction(0.1)
    joint.set_damping(0.2)
    joint.set_armature(0.01)
    assert (joint.get_friction(), joint.get_damping(), joint.get_armature()) == \
        pytest.approx((0.1, 0.2, 0.01))
    assert joint.get_pitch() == 0.0
    pose = partsim.Pose([0, 0, 0.1])
    art.set_root_pose(pose)
    np.testing.assert_allclose(art.get_root_pose().p, [0, 0, 0.1])


def test_inverse_dynamics_of_forward_dynamics(cabinet):
    # binding check that arguments go in and results come out in the same order
    cabinet.set_qpos([0.3, 0.1])
    qf = np.array([1.5, -2.0])
    qacc = cabinet.compute_forward_dynamics(qf)
    np.testing.assert_allclose(cabinet.compute_inverse_dynamics(qacc), qf, atol=1e-8)


def test_drive_reaches_target():
    scene = partsim.Scene(gravity=[0, 0, 0])
    loader = scene.create_urdf_loader()
    from conftest import CABINET_URDF
    art = loader.load_from_string(CABINET_URDF, ".")
    art.set_drive_property(200.0, 20.0)
    art.set_drive_target([0.4, 0.15])
    np.testing.assert_allclose(art.get_drive_target(), [0.4, 0.15])
    art.set_drive_velocity_target([0.0, 0.0])
    hinge = art.find_joint_by_name("hinge")
    assert hinge.get_drive_stiffness() == 200.0 and hinge.get_drive_damping() == 20.0
    assert math.isinf(hinge.get_drive_force_limit())
    hinge.set_drive_property(300.0, 30.0, force_limit=50.0)
    hinge.set_drive_target(-0.4)
    hinge.set_drive_velocity_target(0.0)
    assert hinge.get_drive_target() == -0.4 and hinge.get_drive_velocity_target() == 0.0
    assert hinge.get_drive_force_limit() == 50.0
    scene.step(3000)
    np.testing.assert_allclose(art.get_qpos(), [-0.4, 0.15], atol=1e-3)
    assert hinge.get_qpos() == pytest.approx(-0.4, abs=1e-3)
    assert abs(hinge.get_qvel()) < 1e-3


# ---------------------------------------------------------------- contacts and state

def test_dropped_box_comes_to_rest(scene, resting_box):
    assert resting_box.get_pose().p[2] == pytest.approx(0.1, abs=1e-3)
    assert np.linalg.norm(resting_box.get_velocity()) < 1e-3


def test_contacts_carry_the_weight(scene, resting_box):
    contacts = scene.get_contacts()
    assert contacts
    total = np.zeros(3)
    for c in contacts:
        assert {c.body0.name, c.body1.name} == {"ground", "box"}
        assert c.body0.kind == partsim.ContactBody.Kind.ACTOR
        # the static ground is body1; the force is on body0
        assert (c.body0.name, c.body1.name) == ("box", "ground")
        sign = 1.0 if c.body0.name == "box" else -1.0
        assert c.points
        for p in c.points:
            for v in (p.position, p.normal, p.impulse, p.force):
                assert_vec(v, (3,))
            assert isinstance(p.separation, float)
            total += sign * p.force
    weight = resting_box.get_mass() * 9.81
    assert total[2] == pytest.approx(weight, rel=0.02)


def test_pack_unpack_reproduces_state(cabinet, scene):
    scene.add_ground(altitude=-1.0)
    box = build_box(scene, z=0.8)
    cabinet.set_drive_property(50.0, 5.0)
    cabinet.set_drive_target([0.3, 0.2])
    scene.step(10)
    state = scene.pack()
    assert isinstance(state, bytes)
    scene.step(200)
    qpos, p = cabinet.get_qpos(), box.get_pose().p
    scene.unpack(state)
    scene.step(200)
    np.testing.assert_array_equal(cabinet.get_qpos(), qpos)
    np.testing.assert_array_equal(box.get_pose().p, p)
    with pytest.raises(partsim.PartsimError, match="unpack"):
        scene.unpack(b"not a state")


def test_clone_has_same_state(cabinet, scene):
    cabinet.set_qpos([0.25, 0.05])
    other = scene.clone()
    assert isinstance(other, partsim.Scene)
    art = other.get_articulations()[0]
    np.testing.assert_array_equal(art.get_qpos(), [0.25, 0.05])
    art.set_qpos([0.0, 0.0])
    np.testing.assert_array_equal(cabinet.get_qpos(), [0.25, 0.05])


def test_remove_articulation(cabinet, scene):
    scene.remove_articulation(cabinet)
    assert scene.get_articulations() == []


def test_warnings_and_mjcf(scene, resting_box):
    assert isinstance(scene.get_warnings(), list)
    scene.clear_warnings()
    assert scene.get_warnings() == []
    mjcf = scene.get_mjcf()
    assert isinstance(mjcf, str) and "<mujoco" in mjcf


# ---------------------------------------------------------------- errors

def test_wrong_size_arrays_raise_naming_the_argument(cabinet):
    with pytest.raises(partsim.PartsimError, match="qpos"):
        cabinet.set_qpos([0.1, 0.2, 0.3])
    with pytest.raises(partsim.PartsimError, match="qvel"):
        cabinet.set_qvel([0.1])
    with pytest.raises(partsim.PartsimError, match="qf"):
        cabinet.set_qf(np.zeros(5))
    with pytest.raises(partsim.PartsimError):
        cabinet.set_drive_target([0.1])
    with pytest.raises(partsim.PartsimError):
        cabinet.compute_inverse_dynamics(np.zeros(3))
    # wrong number of dimensions is caught by the conversion
    with pytest.raises(TypeError):
        cabinet.set_qpos(np.zeros((2, 2)))
    with pytest.raises(TypeError):
        cabinet.set_qlimits(np.zeros((2, 3)))


def test_nan_pose_raises(scene):
    box = build_box(scene)
    with pytest.raises(partsim.PartsimError, match="pose"):
        box.set_pose(partsim.Pose([math.nan, 0, 0]))
    with pytest.raises(partsim.PartsimError):
        box.set_pose(partsim.Pose([0, 0, 0], [2, 0, 0, 0]))


def test_out_of_range_index_raises_index_error(cabinet):
    with pytest.raises(IndexError):
        cabinet.get_link(99)
    with pytest.raises(partsim.PartsimIndexError):
        cabinet.get_joint(-5)
    with pytest.raises(IndexError):
        cabinet.compute_link_jacobian(99)


def test_step_rejects_negative_n(scene):
    with pytest.raises(partsim.PartsimError, match="n"):
        scene.step(-1)


# ---------------------------------------------------------------- lifetime and threads

def test_handles_keep_the_scene_alive():
    scene = partsim.Scene()
    scene.add_ground()
    box = build_box(scene)
    links = None
    loader = scene.create_urdf_loader()
    from conftest import CABINET_URDF
    art = loader.load_from_string(CABINET_URDF, ".")
    links = art.get_links()
    joints = art.get_active_joints()
    actors = scene.get_actors()
    builder = scene.create_actor_builder()
    del scene, loader, art
    gc.collect()
    box.get_pose()
    assert links[2].name == "drawer"
    joints[0].get_qpos()
    assert actors[0].name == "ground"
    builder.add_box_collision(half_size=[0.1] * 3)
    assert builder.build().get_mass() > 0


def test_link_builder_keeps_articulation_builder_alive():
    scene = partsim.Scene()
    root = scene.create_articulation_builder().create_link_builder()
    gc.collect()
    root.set_name("root").add_box_collision(half_size=[0.1] * 3)
    assert root.get_index() == 0


def test_handles_release_the_scene_when_gone():
    import weakref
    scene = partsim.Scene()
    box = build_box(scene)
    ref = weakref.ref(scene)
    del scene
    gc.collect()
    assert ref() is not None
    del box
    gc.collect()
    assert ref() is None


def _ticks_during_step(scene, n):
    """Steps n times while another thread records a timestamp every millisecond; returns the
    step's duration and the number of ticks well inside it."""
    ticks = []
    stop = threading.Event()

    def ticker():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    thread = threading.Thread(target=ticker)
    thread.start()
    time.sleep(0.02)
    start = time.perf_counter()
    scene.step(n)
    end = time.perf_counter()
    stop.set()
    thread.join()
    # a step that held the GIL would let no tick happen well inside [start, end]
    return end - start, len([t for t in ticks if start + 0.05 < t < end - 0.05])


def test_step_releases_the_gil():
    scene = partsim.Scene()
    scene.add_ground()
    for i in range(5):
        build_box(scene, z=0.2 + 0.3 * i, name="box%d" % i)
    # grow n until stepping takes long enough to tell (0.3 s or more)
    n = 1000
    while True:
        duration, inside = _ticks_during_step(scene, n)
        if duration > 0.3 or n > 10**7:
            break
        n *= 4
    assert duration > 0.3
    assert inside > 10
