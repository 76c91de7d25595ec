"""SAPIEN's names in partsim's SAPIEN adapter (partsim.sapien): each means what it means in
SAPIEN, and what partsim cannot do is refused with an error that says what to use instead."""

import math
import os
import re

import numpy as np
import pytest

import partsim
import partsim.sapien as sapien
from conftest import CABINET_URDF

G = 9.81


def box_scene(dt=1 / 100.0):
    scene = sapien.Scene()
    scene.set_timestep(dt)
    scene.add_ground(0)
    b = scene.create_actor_builder()
    b.add_box_collision(half_size=[0.1, 0.1, 0.1])
    b.add_box_visual(half_size=[0.1, 0.1, 0.1], color=[1, 0, 0])
    box = b.build(name="box")
    box.set_pose(sapien.Pose([0, 0, 0.1]))
    return scene, box


# ------------------------------------------------------------------------------ module

def test_sapien2_and_sapien3_entry_points():
    import partsim.core as core
    assert core is sapien
    engine = sapien.Engine()
    renderer = sapien.SapienRenderer()
    engine.set_renderer(renderer)
    assert engine.get_renderer() is renderer
    config = sapien.SceneConfig()
    config.gravity = np.array([0, 0, -5.0])
    config.default_static_friction = 0.9
    config.default_dynamic_friction = 0.7
    config.default_restitution = 0.2
    config.enable_pcm = False  # PhysX-only, kept
    scene = engine.create_scene(config)
    assert isinstance(scene, sapien.Scene)
    assert isinstance(sapien.partsim_object(scene), partsim.Scene)
    np.testing.assert_allclose(scene.get_gravity(), [0, 0, -5])
    m = scene.default_physical_material
    assert (m.static_friction, m.dynamic_friction, m.restitution) == pytest.approx((0.9, 0.7, 0.2))
    with pytest.raises(partsim.PartsimError, match="no field 'gravityy'"):
        sapien.SceneConfig(gravityy=[0, 0, 0])


def test_viewer_calls_give_the_browser_viewer():
    scene = sapien.Scene()
    viewer = scene.create_viewer()
    assert isinstance(viewer, partsim.Viewer) and viewer.url.startswith("http://127.0.0.1:")
    viewer.stop()
    # SAPIEN 2: Viewer(renderer), then set_scene
    for cls in (sapien.utils.Viewer, sapien.utils.viewer.Viewer):
        viewer = cls(sapien.SapienRenderer(), shader_dir="", resolutions=(800, 600))
        viewer.set_scene(scene)
        viewer.toggle_axes(False)
        viewer.toggle_camera_lines(False)
        viewer.render()
        assert not viewer.closed
        viewer.stop()
    with pytest.raises(partsim.PartsimError, match="no on-screen window.*browser"):
        sapien.SapienRenderer().create_window()
    with pytest.raises(partsim.PartsimError, match="set_render_backend\\('pathtracer'\\)"):
        sapien.KuafuRenderer()


def test_physx_defaults_apply_to_later_scenes():
    try:
        sapien.physx.set_scene_config(gravity=[0, 0, -3.0], enable_tgs=False)
        sapien.physx.set_default_material(0.4, 0.3, 0.05)
        sapien.physx.set_body_config(solver_position_iterations=25)
        scene = sapien.Scene()
        np.testing.assert_allclose(scene.get_gravity(), [0, 0, -3])
        assert scene.get_config().default_material.static_friction == pytest.approx(0.4)
        assert scene.get_config().solver_iterations == 25
        with pytest.raises(partsim.PartsimError, match="unknown field 'gravvity'"):
            sapien.physx.set_scene_config(gravvity=[0, 0, 0])
    finally:
        sapien.physx._defaults.clear()
    assert sapien.Scene().get_gravity()[2] == pytest.approx(-9.81)


def test_log_levels_of_sapien():
    for level in ("warn", "info", "debug", "error", "critical", "off", "warning"):
        sapien.set_log_level(level)
        sapien.render.set_log_level(level)
    sapien.set_log_level("warning")
    assert partsim.get_log_level() == "warning"
    with pytest.raises(partsim.PartsimError, match="unknown level 'loud'"):
        sapien.set_log_level("loud")


def test_pose_from_matrix_and_rpy():
    m = np.eye(4)
    m[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]  # 90 degrees about z
    m[:3, 3] = [1, 2, 3]
    pose = sapien.Pose(m)
    np.testing.assert_allclose(pose.p, [1, 2, 3])
    np.testing.assert_allclose(pose.get_rpy(), [0, 0, math.pi / 2], atol=1e-12)
    pose.set_rpy([0.1, -0.2, 0.3])
    np.testing.assert_allclose(pose.rpy, [0.1, -0.2, 0.3], atol=1e-12)
    np.testing.assert_allclose(pose.to_transformation_matrix()[:3, 3], [1, 2, 3])
    pose.set_p([4, 5, 6])
    np.testing.assert_allclose(pose.get_p(), [4, 5, 6])


# ------------------------------------------------------------------------------ scene, actors

def test_add_ground_in_sapien_argument_order():
    scene = sapien.Scene()
    ground = scene.add_ground(0.5, False)  # SAPIEN: (altitude, render)
    assert ground.get_desc().visuals == []
    assert ground.get_pose().p[2] == pytest.approx(0.5)
    other = sapien.Scene()
    g = other.add_ground(altitude=0, render_material=[0.2, 0.3, 0.4], render_half_size=[2, 3])
    v = g.get_desc().visuals[0]
    np.testing.assert_allclose(v.material.base_color, [0.2, 0.3, 0.4, 1.0], atol=1e-6)
    np.testing.assert_allclose(v.half_size[:2], [2, 3])
    with pytest.raises(partsim.PartsimError, match="render_half_size"):
        other.add_ground(0, render_half_size=[0, 1])


def test_builders_take_names_colours_and_materials():
    scene = sapien.Scene()
    b = scene.create_actor_builder()
    b.add_box_collision(half_size=[0.1] * 3, patch_radius=0.01, min_patch_radius=0.005)
    b.add_box_visual(sapien.Pose(), [0.1] * 3, [0, 1, 0])  # positional 3-value colour
    mat = sapien.render.RenderMaterial(base_color=[0.1, 0.2, 0.3, 1], metallic=0.7,
                                       roughness=0.2)
    b.add_sphere_visual(radius=0.05, material=mat)
    renderer_mat = sapien.SapienRenderer().create_material()
    renderer_mat.set_base_color([0.5, 0.5, 0.1, 1])
    renderer_mat.set_metallic(0.3)
    b.add_capsule_visual(radius=0.02, half_length=0.1, material=renderer_mat)
    actor = b.build(name="thing")
    assert actor.name == "thing" and actor.get_name() == "thing"
    visuals = actor.get_desc().visuals
    np.testing.assert_allclose(visuals[0].material.base_color, [0, 1, 0, 1])
    assert visuals[1].material.metallic == pytest.approx(0.7)
    assert visuals[1].material.roughness == pytest.approx(0.2)
    np.testing.assert_allclose(visuals[2].material.base_color, [0.5, 0.5, 0.1, 1], atol=1e-6)
    assert visuals[2].material.metallic == pytest.approx(0.3)
    actor.name = "renamed"
    assert scene.find_actor_by_name("renamed").get_id() == actor.get_id()
    assert actor.mass == pytest.approx(8.0)
    with pytest.raises(partsim.PartsimError, match="3 or 4 finite numbers"):
        scene.create_actor_builder().add_box_visual(half_size=[1, 1, 1], color=[1, 0])
    with pytest.raises(partsim.PartsimError, match="trigger"):
        scene.create_actor_builder().add_box_collision(half_size=[1, 1, 1], is_trigger=True)
    with pytest.raises(partsim.PartsimError, match="convex shapes only"):
        scene.create_actor_builder().add_nonconvex_collision_from_file("x.obj")


def test_build_kinds_and_static_actors_can_be_placed():
    scene = sapien.Scene()
    for kind, expected in (("static", partsim.ActorType.STATIC),
                           ("kinematic", partsim.ActorType.KINEMATIC),
                           ("dynamic", partsim.ActorType.DYNAMIC)):
        b = scene.create_actor_builder()
        b.add_box_collision(half_size=[0.1] * 3)
        b.set_physx_body_type(kind)
        a = b.build(name=kind)
        assert a.type == expected and a.name == kind
        dynamic = a.find_component_by_type(sapien.physx.PhysxRigidDynamicComponent)
        static = a.find_component_by_type(sapien.physx.PhysxRigidStaticComponent)
        assert (dynamic is not None, static is not None) == (kind != "static", kind == "static")
        assert a.find_component_by_type(sapien.render.RenderBodyComponent) is not None
        if dynamic is not None:
            assert dynamic.kinematic == (kind == "kinematic") and dynamic.entity is a
    b = scene.create_actor_builder()
    b.add_box_collision(half_size=[0.1] * 3)
    wall = b.build_static(name="wall")
    wall.set_pose(sapien.Pose([1, 2, 0.1]))
    np.testing.assert_allclose(wall.get_pose().p, [1, 2, 0.1])
    # a box dropped onto the moved static box lands on it
    b = scene.create_actor_builder()
    b.add_box_collision(half_size=[0.05] * 3)
    falling = b.build(name="falling")
    falling.set_pose(sapien.Pose([1, 2, 0.5]))
    scene.step(500)
    assert falling.get_pose().p[2] == pytest.approx(0.25, abs=2e-3)
    with pytest.raises(partsim.PartsimError, match="'dynamic', 'kinematic' or 'static'"):
        scene.create_actor_builder().set_physx_body_type("ghost")


def test_actor_damping_in_sapien_2_and_3_forms():
    scene = sapien.Scene()
    scene.set_timestep(0.01)
    physx = sapien.physx
    scene.set_gravity([0, 0, 0])
    b = scene.create_actor_builder()
    b.add_sphere_collision(radius=0.1)
    ball = b.build(name="ball")
    ball.set_pose(sapien.Pose([0, 0, 1]))
    ball.set_damping(0.5, 2.0)  # SAPIEN 2
    assert (ball.linear_damping, ball.angular_damping) == (0.5, 2.0)
    comp = ball.find_component_by_type(physx.PhysxRigidDynamicComponent)
    comp.linear_damping = 3.0  # SAPIEN 3, one rate at a time
    comp.set_angular_damping(4.0)
    assert (ball.get_linear_damping(), ball.get_angular_damping()) == (3.0, 4.0)
    ball.set_velocity([2, 0, 0])
    ball.set_angular_velocity([0, 0, 1])
    scene.step(50)
    assert ball.get_velocity()[0] == pytest.approx(2 * 1.03 ** -50, rel=1e-3)
    assert ball.get_angular_velocity()[2] == pytest.approx(1.04 ** -50, rel=1e-3)
    with pytest.raises(partsim.PartsimError, match="finite and >= 0"):
        ball.set_damping(-1, 0)
    wall = scene.create_actor_builder().add_box_collision(half_size=[0.1] * 3).build_static("w")
    with pytest.raises(partsim.PartsimError, match="only dynamic actors"):
        wall.set_damping(1, 1)


def test_contacts_name_their_actors_and_impulse_is_on_actor0():
    scene, box = box_scene()
    scene.step(100)
    contacts = scene.get_contacts()
    assert contacts
    total = np.zeros(3)
    for c in contacts:
        assert c.actor0.get_id() == box.get_id() and c.actor1.name == "ground"
        assert c.bodies[0].get_id() == box.get_id()
        for p in c.points:
            assert p.normal[2] > 0.99  # from the ground into the box
            total += p.impulse
    assert total[2] == pytest.approx(box.mass * G * scene.get_timestep(), rel=0.01)


def test_contacts_with_links_name_the_link():
    scene = sapien.Scene()
    scene.add_ground(0)
    loader = scene.create_urdf_loader()
    loader.fix_root_link = False
    cabinet = loader.load_from_string(CABINET_URDF)
    cabinet.set_root_pose(sapien.Pose([0, 0, 0.3]))
    scene.step(300)
    names = {(c.actor0.name, c.actor1.name) for c in scene.get_contacts()}
    assert ("base", "ground") in names
    link = [c.actor0 for c in scene.get_contacts() if c.actor0.name == "base"][0]
    assert isinstance(link, sapien.physx.PhysxArticulationLinkComponent)
    assert isinstance(sapien.partsim_object(link), partsim.Link)
    assert link.entity.find_component_by_type(sapien.physx.PhysxArticulationLinkComponent) == link


# ------------------------------------------------------------------------------ articulations

def build_two_links(scene, joint_type, limits):
    builder = scene.create_articulation_builder()
    root = builder.create_link_builder()
    root.set_name("root")
    root.add_box_collision(half_size=[0.1] * 3)
    child = builder.create_link_builder(root)
    child.set_name("child")
    child.set_joint_name("j")
    child.add_box_collision(sapien.Pose([0.3, 0, 0]), half_size=[0.05] * 3)
    # the joint's axis (its x) along the world's y: the child sticks out along x, across it
    about_y = [math.sqrt(0.5), 0, 0, math.sqrt(0.5)]
    child.set_joint_properties(joint_type, limits, sapien.Pose([0, 0, 0.3], about_y),
                               sapien.Pose([0, 0, 0], about_y))
    return builder.build(fix_root_link=True)


def test_joint_properties_and_limits_in_sapien_shapes():
    scene = sapien.Scene()
    a = build_two_links(scene, "revolute", [[-1.0, 2.0]])
    joint = a.get_active_joints()[0]
    assert joint.get_limits().shape == (1, 2)
    np.testing.assert_allclose(joint.get_limits(), [[-1, 2]])
    joint.set_limits([[-0.5, 0.5]])
    np.testing.assert_allclose(joint.limits, [[-0.5, 0.5]])
    joint.set_limits(-0.25, 0.25)  # partsim's form
    np.testing.assert_allclose(a.get_qlimits(), [[-0.25, 0.25]])
    welded = build_two_links(sapien.Scene(), "fixed", [])
    assert welded.dof == 0
    fixed = [j for j in welded.get_joints() if j.get_dof() == 0]
    assert fixed and fixed[0].get_limits().shape == (0, 2)

    free = build_two_links(sapien.Scene(), "revolute", [[-np.inf, np.inf]])
    joint = free.get_active_joints()[0]
    assert joint.type == "revolute"  # SAPIEN's name for a revolute joint with or without limits
    assert sapien.partsim_object(joint).type == partsim.JointType.CONTINUOUS
    assert build_two_links(sapien.Scene(), "prismatic", [[0, 0.4]]).dof == 1
    with pytest.raises(partsim.PartsimError, match="unknown joint type 'spherical'"):
        build_two_links(sapien.Scene(), "spherical", [])
    with pytest.raises(partsim.PartsimError, match="one row per dof"):
        build_two_links(sapien.Scene(), "revolute", [[0, 1], [0, 1]])


def test_articulation_names_poses_and_properties():
    scene = sapien.Scene()
    a = build_two_links(scene, "revolute", [[-1.0, 1.0]])
    a.set_name("arm")
    assert a.get_name() == "arm" and a.name == "arm"
    assert scene.find_articulation_by_name("arm").get_id() == a.get_id()
    a.set_pose(sapien.Pose([0.5, 0, 1]))
    np.testing.assert_allclose(a.get_pose().p, [0.5, 0, 1])
    np.testing.assert_allclose(a.pose.p, [0.5, 0, 1])
    a.qpos = np.array([0.3])
    np.testing.assert_allclose(a.qpos, [0.3])
    assert [j.name for j in a.active_joints] == ["j"]
    assert a.root.name == "root" and [l.name for l in a.links] == ["root", "child"]
    ids = {l.get_id() for l in a.links} | {a.get_id()}
    assert len(ids) == 3  # scene-wide ids
    with pytest.raises(partsim.PartsimError, match="mode 'acceleration' is not supported"):
        a.get_active_joints()[0].set_drive_property(100, 10, mode="acceleration")
    a.get_active_joints()[0].set_drive_property(100, 10, 50, "force")
    assert a.get_active_joints()[0].get_drive_force_limit() == 50
    with pytest.raises(partsim.PartsimError, match="KinematicModel"):
        a.create_pinocchio_model()


def test_compute_passive_force_with_external_forces_holds_the_arm_still():
    scene = sapien.Scene()
    scene.set_timestep(1 / 500)
    a = build_two_links(scene, "revolute", [[-3.0, 3.0]])
    a.set_qpos(np.array([0.4]))
    child = a.get_links()[1]
    for _ in range(200):
        child.add_force_at_point([0, 0, 30.0], child.get_pose().p + [0.3, 0, 0])
        qf = a.compute_passive_force(gravity=True, coriolis_and_centrifugal=True, external=True)
        a.set_qf(qf)
        scene.step()
    assert a.get_qpos()[0] == pytest.approx(0.4, abs=1e-4)
    # without the external part, the push moves it
    child.add_force_at_point([0, 0, 30.0], child.get_pose().p + [0.3, 0, 0])
    with_ext = a.compute_passive_force(True, True, True)
    without = a.compute_passive_force(True, True, False)
    assert abs(with_ext[0] - without[0]) > 1.0


# ------------------------------------------------------------------------------ URDF loader

def test_urdf_load_with_package_dir_config_and_kinematic(tmp_path):
    pkg = tmp_path / "pkgs" / "mybot" / "meshes"
    pkg.mkdir(parents=True)
    (pkg / "box.obj").write_text(
        "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nv 0.1 0.1 0.1\nf 1 2 3\nf 1 2 4\nf 1 3 4\n"
        "f 2 3 5\nf 2 4 5\nf 3 4 5\n")
    urdf = tmp_path / "robot" / "bot.urdf"
    urdf.parent.mkdir()
    urdf.write_text("""<?xml version="1.0"?>
<robot name="bot">
  <link name="base"><collision><geometry><mesh filename="package://mybot/meshes/box.obj"/>
  </geometry></collision></link>
  <link name="tip"><collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision>
  </link>
  <joint name="j" type="prismatic"><parent link="base"/><child link="tip"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 0 1"/><limit lower="0" upper="0.1" effort="10"
    velocity="1"/></joint>
</robot>""")
    scene = sapien.Scene()
    loader = scene.create_urdf_loader()
    loader.fix_root_link = True
    mat = scene.create_physical_material(0.9, 0.8, 0.0)
    bot = loader.load(str(urdf), package_dir=str(tmp_path / "pkgs"),
                      config={"density": 500.0, "link": {"tip": {"material": mat}}})
    assert bot.dof == 1
    assert bot.get_links()[1].mass == pytest.approx(500.0 * 0.05 ** 3)
    kin = loader.load_kinematic(str(urdf), package_dir=str(tmp_path / "pkgs"))
    assert kin.is_kinematic()
    with pytest.raises(partsim.PartsimError, match="package_dir .* is not a folder"):
        loader.load(str(urdf), package_dir=str(tmp_path / "nowhere"))


# ------------------------------------------------------------------------------ cameras

def camera_scene():
    scene, box = box_scene()
    scene.set_ambient_light([0.5, 0.5, 0.5])
    scene.add_directional_light([0, 1, -1], [0.5, 0.5, 0.5])
    cam = scene.add_camera("cam", 96, 72, np.deg2rad(60), 0.1, 10.0)
    cam.set_pose(sapien.Pose([-0.6, 0, 0.3], [0.9659, 0, 0.2588, 0]))  # 30 degrees down
    scene.update_render()
    cam.take_picture()
    return scene, box, cam


def test_position_fourth_channel_is_the_depth_buffer_value():
    scene, box, cam = camera_scene()
    pos = cam.get_picture("Position")
    assert pos.shape == (72, 96, 4) and pos.dtype == np.float32
    depth = np.asarray(cam.get_depth())
    seen = depth > 0
    assert seen.any() and (~seen).any() is not None
    assert np.all(pos[..., 3][seen] < 1) and np.all(pos[..., 3][~seen] == 1)
    n, f = cam.near, cam.far
    # the OpenGL depth-buffer value of a point at distance z along the view axis
    z = -pos[..., 2][seen]
    np.testing.assert_allclose(pos[..., 3][seen], f * (z - n) / (z * (f - n)), rtol=1e-5)
    # SAPIEN's point cloud recipe
    points = pos[..., :3][pos[..., 3] < 1]
    m = cam.get_model_matrix()
    world = points @ m[:3, :3].T + m[:3, 3]
    assert world[:, 2].min() > -1e-3 and world[:, 2].max() < 0.2 + 1e-3
    np.testing.assert_allclose(cam.get_float_texture("Position"), pos)


def test_segmentation_is_four_channels_with_sapien_ids():
    scene, box, cam = camera_scene()
    seg = cam.get_picture("Segmentation")
    assert seg.shape == (72, 96, 4) and seg.dtype == np.uint32
    assert np.all(seg[..., 2:] == 0)
    assert np.count_nonzero(seg[..., 1] == box.get_id()) > 100  # actor id = entity id
    ground = scene.find_actor_by_name("ground")
    assert np.count_nonzero(seg[..., 1] == ground.get_id()) > 100
    np.testing.assert_array_equal(cam.get_uint32_texture("Segmentation"), seg)
    np.testing.assert_array_equal(cam.get_actor_segmentation(), seg[..., 1])
    np.testing.assert_array_equal(cam.get_visual_segmentation(), seg[..., 0])
    rgba = cam.get_color_rgba()
    red = rgba[seg[..., 1] == box.get_id()][:, :3].mean(axis=0)
    assert red[0] > 2 * max(red[1], red[2])


def test_link_ids_are_segmentation_ids():
    scene = sapien.Scene()
    scene.set_ambient_light([1, 1, 1])
    loader = scene.create_urdf_loader()
    loader.fix_root_link = True
    cab = loader.load_from_string(CABINET_URDF.replace(
        "<collision>", "<visual><geometry><box size=\"0.4 0.4 0.4\"/></geometry></visual>"
        "<collision>", 1))
    cam = scene.add_camera("cam", 64, 64, 1.0, 0.05, 10)
    cam.set_pose(sapien.Pose([-1.5, 0, 0.2]))
    scene.update_render()
    cam.take_picture()
    seg = cam.get_picture("Segmentation")
    base = cab.get_links()[0]
    assert np.count_nonzero(seg[..., 1] == base.get_id()) > 50
    info = {e.name: e.id for e in scene.get_render_entities()}
    assert info["base"] == base.get_id()


def test_camera_set_parent_keeps_or_moves_the_pose():
    scene, box = box_scene()
    cam = scene.add_camera("cam", 32, 32, 1.0, 0.1, 10)
    cam.set_pose(sapien.Pose([1, 0, 0.5]))
    cam.set_parent(box, keep_pose=True)
    np.testing.assert_allclose(cam.get_pose().p, [1, 0, 0.5], atol=1e-9)
    np.testing.assert_allclose(cam.get_local_pose().p, [1, 0, 0.4], atol=1e-6)
    box.set_pose(sapien.Pose([0, 1, 0.1]))
    scene.update_render()
    np.testing.assert_allclose(cam.get_pose().p, [1, 1, 0.5], atol=1e-6)  # follows the box
    cam.set_parent(None, keep_pose=False)  # the local pose is now the world pose
    np.testing.assert_allclose(cam.get_pose().p, [1, 0, 0.4], atol=1e-6)
    with pytest.raises(partsim.PartsimError, match="an Actor, a Link or None"):
        cam.set_parent("box", keep_pose=True)
    other, other_box = box_scene()
    with pytest.raises(partsim.PartsimError, match="another scene"):
        cam.set_parent(other_box, keep_pose=True)


def test_mounted_camera_in_sapien_2_0_form_and_spot_light_fovs():
    scene, box = box_scene()
    cam = scene.add_mounted_camera("m", box, sapien.Pose([0, 0, 0.5]), 64, 48,
                                   np.deg2rad(70), np.deg2rad(50), 0.1, 10)
    assert cam.fovy == pytest.approx(np.deg2rad(50))
    cam2 = scene.add_mounted_camera(name="k", actor=box, pose=sapien.Pose(), width=32,
                                    height=32, fovx=1.0, fovy=0.8, near=0.1, far=5)
    assert cam2.fovy == pytest.approx(0.8)
    scene.add_spot_light([0, 0, 2], [0, 0, -1], np.deg2rad(40), np.deg2rad(60), [1, 1, 1],
                         shadow=True)
    spot = [l for l in scene.get_lights() if l.type == partsim.LightType.SPOT][0]
    assert spot.inner_angle == pytest.approx(np.deg2rad(20))
    assert spot.outer_angle == pytest.approx(np.deg2rad(30))
    scene.add_spot_light([0, 0, 2], [0, 0, -1], inner_angle=0.1, outer_angle=0.2, color=[1, 1, 1])
    assert scene.get_lights()[-1].outer_angle == pytest.approx(0.2)
    scene.add_point_light([0, 0, 2], [1, 1, 1], shadow=True)
    scene.add_directional_light([0, 0, -1], [1, 1, 1], True, [0, 0, 0], 10, -10, 10, 2048)
    cam.set_perspective_parameters(0.05, 20, 40, 40, 32, 24)
    assert cam.near == pytest.approx(0.05)
    with pytest.raises(partsim.PartsimError, match="skew"):
        cam.set_perspective_parameters(0.05, 20, 40, 40, 32, 24, 0.1)


# ------------------------------------------------------------------------------ SAPIEN 3 names

def test_root_pose_and_entity_pose():
    scene = sapien.Scene()
    a = build_two_links(scene, "revolute", [[-1.0, 1.0]])
    a.root_pose = sapien.Pose([0.5, 0, 1])
    np.testing.assert_allclose(a.root_pose.p, [0.5, 0, 1])
    np.testing.assert_allclose(a.get_root_pose().p, [0.5, 0, 1])
    child = a.links[1]
    np.testing.assert_allclose(child.entity_pose.p, child.get_pose().p)
    np.testing.assert_allclose(child.get_entity_pose().q, child.get_pose().q)
    with pytest.raises(partsim.PartsimError, match="set the articulation's root_pose and qpos"):
        child.entity_pose = sapien.Pose([0, 0, 3])
    _, box = box_scene()
    box.entity_pose = sapien.Pose([0, 1, 2])
    np.testing.assert_allclose(box.get_pose().p, [0, 1, 2])
    box.set_entity_pose(sapien.Pose([0, 0, 1]))
    np.testing.assert_allclose(box.get_entity_pose().p, [0, 0, 1])


def unsupported_names_in_the_docs():
    """The names of docs/sapien_compatibility.md's rows marked "no" (calls, not arguments)."""
    doc = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "docs",
                       "sapien_compatibility.md")
    names = set()
    for line in open(doc, encoding="utf-8"):
        cells = [c.strip() for c in line.split("|")]
        if len(cells) > 3 and cells[2] == "no":
            for token in re.findall(r"`([^`]+)`", cells[1]):
                if "=" not in token:
                    names.add(token.rstrip("()").split(".")[-1])
    return names


# constructors and functions the table marks "no" that refuse by raising when called
REFUSED_CALLS = {
    "KuafuRenderer": lambda: sapien.KuafuRenderer(),
    "create_window": lambda: sapien.SapienRenderer().create_window(),
    "create_pinocchio_model": lambda: build_two_links(sapien.Scene(), "revolute",
                                                      [[-1, 1]]).create_pinocchio_model(),
    "add_nonconvex_collision_from_file":
        lambda: sapien.Scene().create_actor_builder().add_nonconvex_collision_from_file("m.obj"),
    "add_plane_collision": lambda: sapien.Scene().create_actor_builder().add_plane_collision(),
    "PhysxCollisionShapePlane": lambda: sapien.physx.PhysxCollisionShapePlane(None),
    "PhysxCollisionShapeTriangleMesh":
        lambda: sapien.physx.PhysxCollisionShapeTriangleMesh("m.obj", [1, 1, 1], None),
    "PhysxGpuSystem": lambda: sapien.physx.PhysxGpuSystem(),
    "enable_gpu": lambda: sapien.physx.enable_gpu(),
    "PhysxDriveComponent": lambda: sapien.physx.PhysxDriveComponent(None),
    "PhysxDistanceJointComponent": lambda: sapien.physx.PhysxDistanceJointComponent(None),
    "PhysxGearComponent": lambda: sapien.physx.PhysxGearComponent(None),
    "set_locked_motion_axes":
        lambda: sapien.physx.PhysxRigidDynamicComponent().set_locked_motion_axes([1] * 6),
    "set_disable_gravity":
        lambda: sapien.physx.PhysxRigidDynamicComponent().set_disable_gravity(True),
    "RenderShapePlane": lambda: sapien.render.RenderShapePlane([1, 1, 1], None),
    "RenderTexturedLightComponent": lambda: sapien.render.RenderTexturedLightComponent(),
    "RenderParallelogramLightComponent":
        lambda: sapien.render.RenderParallelogramLightComponent(),
    "set_cubemap": lambda: sapien.Scene().render_system.set_cubemap(None),
    "set_visibility": lambda: sapien.render.RenderBodyComponent().set_visibility(0.5),
    "disable_render_id": lambda: sapien.render.RenderBodyComponent().disable_render_id(),
}


def test_every_call_the_table_marks_unsupported_raises_partsim_error():
    from partsim.sapien import UNSUPPORTED, UnsupportedError
    listed = {n for names in UNSUPPORTED.values() for n in names}
    documented = unsupported_names_in_the_docs()
    assert documented == listed | set(REFUSED_CALLS), \
        "docs/sapien_compatibility.md's 'no' rows and the adapter differ"
    for name, call in REFUSED_CALLS.items():
        with pytest.raises(partsim.PartsimError, match=".{20}"):
            call()
    scene, box = box_scene()
    art = build_two_links(scene, "revolute", [[-1, 1]])
    objects = {sapien.Scene: scene, sapien.Entity: box,
               sapien.render.RenderCameraComponent: scene.add_camera("c", 32, 32, 1.0, 0.1, 10),
               sapien.URDFLoader: scene.create_urdf_loader(),
               sapien.physx.PhysxRigidBaseComponent:
                   box.find_component_by_type(sapien.physx.PhysxRigidDynamicComponent),
               sapien.physx.PhysxArticulation: art,
               sapien.render.RenderBodyComponent:
                   box.find_component_by_type(sapien.render.RenderBodyComponent)}
    assert set(UNSUPPORTED) <= set(objects)
    for cls, names in UNSUPPORTED.items():
        for name, why in names.items():
            with pytest.raises(partsim.PartsimError, match=re.escape(why)) as e:
                getattr(objects[cls], name)
            assert isinstance(e.value, (AttributeError, UnsupportedError))
            assert not hasattr(objects[cls], name)  # as SAPIEN scripts test for a feature
