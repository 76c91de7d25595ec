"""The SAPIEN adapter as an adapter: `import partsim` leaves partsim's classes as they are, and
SAPIEN 3's entity-component form (entities, rigid and render bodies, cameras, lights, a script's
own components) builds, places and reports what a script expects; each misuse names what is
wrong."""

import math
import os
import subprocess
import sys

import numpy as np
import pytest

import partsim
import partsim.sapien as sapien
from conftest import PYTHON_DIR

physx, render = sapien.physx, sapien.render


def test_importing_partsim_leaves_its_classes_as_they_are():
    # in a fresh process: the classes' members after `import partsim` and after importing the
    # adapter too are the same, and none of SAPIEN's names is among them
    code = """
import inspect, json, sys
import partsim, partsim._partsim as ext
def members():
    return {n: sorted(c.__dict__) for n, c in vars(ext).items() if inspect.isclass(c)}
first = members()
assert "partsim.sapien" not in sys.modules, "import partsim imported the adapter"
names = sorted(n for n in dir(partsim) if n in
               ("Engine", "physx", "render", "utils", "core", "SapienRenderer"))
import partsim.sapien, partsim.core
assert partsim.core is partsim.sapien
print(json.dumps([first == members(), names]))
"""
    env = dict(os.environ, PYTHONPATH=os.path.abspath(PYTHON_DIR))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    same, sapien_names = eval(out.stdout.strip().splitlines()[-1].replace("true", "True")
                              .replace("false", "False"))
    assert same and sapien_names == []
    # partsim's own meanings: Position's 4th channel is depth in metres, limits are (lo, hi)
    assert not hasattr(partsim.Pose, "get_rpy") and not hasattr(partsim.Scene, "add_entity")
    assert type(partsim.Camera.get_picture).__name__ == "instancemethod"


def box_entity(name, half, pose, density=1000.0, color=(1, 0, 0)):
    e = sapien.Entity()
    e.set_name(name)
    body = physx.PhysxRigidDynamicComponent()
    shape = physx.PhysxCollisionShapeBox(half, physx.PhysxMaterial(0.5, 0.5, 0.0))
    shape.set_density(density)
    body.attach(shape)
    looks = render.RenderBodyComponent()
    looks.attach(render.RenderShapeBox(half, render.RenderMaterial(base_color=[*color, 1])))
    e.add_component(body).add_component(looks)
    e.set_pose(pose)
    return e, body


def test_an_entity_becomes_an_actor_with_its_components():
    scene = sapien.Scene()
    scene.set_timestep(0.002)
    scene.add_ground(0)
    e, body = box_entity("box", [0.1, 0.2, 0.05], sapien.Pose([0, 0, 0.5]))
    # mass properties from the shapes before the entity is added, as SAPIEN's
    assert body.mass == pytest.approx(8.0)
    np.testing.assert_allclose(body.inertia, 8.0 / 3 * np.array([0.0425, 0.0125, 0.05]))
    assert e.scene is None
    scene.add_entity(e)
    assert e.scene is scene and e in scene.get_entities()
    assert isinstance(sapien.partsim_object(e), partsim.Actor)
    assert e.find_component_by_type(physx.PhysxRigidBaseComponent) is body
    assert body.entity is e and body.entity_pose.p[2] == pytest.approx(0.5)
    assert body.mass == pytest.approx(8.0)
    scene.step(500)
    assert e.pose.p[2] == pytest.approx(0.05, abs=2e-3)
    # the contact names the body component and the ground's
    (contact,) = [c for c in scene.get_contacts() if body in c.bodies]
    other = contact.bodies[1] if contact.bodies[0] is body else contact.bodies[0]
    assert isinstance(other, physx.PhysxRigidStaticComponent) and other.entity.name == "ground"
    # SAPIEN 2's actor calls reach the body from the entity
    assert e.mass == pytest.approx(8.0) and e.angular_damping == pytest.approx(0.05)
    e.remove_from_scene()
    assert e.scene is None and e not in scene.get_entities()


def test_velocities_damping_and_forces_set_before_and_after_adding():
    scene = sapien.Scene()
    scene.set_timestep(0.01)
    scene.set_gravity([0, 0, 0])
    e, body = box_entity("b", [0.1] * 3, sapien.Pose([0, 0, 1]))
    body.set_linear_velocity([1, 0, 0])
    body.linear_damping = 0.0
    body.angular_damping = 0.0
    scene.add_entity(e)
    np.testing.assert_allclose(body.linear_velocity, [1, 0, 0])
    scene.step(10)
    assert e.pose.p[0] == pytest.approx(0.1, abs=1e-6)
    # an impulse of m * 1 m/s along y over one step
    body.add_force_torque([0, body.mass, 0], [0, 0, 0], mode="impulse")
    scene.step()
    np.testing.assert_allclose(body.linear_velocity, [1, 1, 0], atol=1e-9)
    with pytest.raises(partsim.PartsimError, match="mode 'push'"):
        body.add_force_at_point([1, 0, 0], [0, 0, 1], mode="push")


def test_cameras_and_lights_on_entities():
    scene = sapien.Scene()
    box, _ = box_entity("box", [0.1] * 3, sapien.Pose([0, 0, 0.1]), color=(0, 1, 0))
    scene.add_entity(box)
    # a camera on an entity of its own, and one mounted on the box
    viewpoint = sapien.Entity()
    cam = render.RenderCameraComponent(64, 48)
    cam.set_fovy(1.0)
    viewpoint.add_component(cam)
    viewpoint.set_pose(sapien.Pose([-1, 0, 0.1]))
    light = sapien.Entity()
    sun = render.RenderDirectionalLightComponent()
    sun.set_color([1, 1, 1])
    light.add_component(sun)
    light.set_pose(sapien.Pose([0, 0, 2], [math.cos(math.pi / 4), 0, math.sin(math.pi / 4), 0]))
    scene.add_entity(viewpoint)
    scene.add_entity(light)
    onboard = render.RenderCameraComponent(32, 32)
    onboard.set_local_pose(sapien.Pose([0, 0, 0.2]))
    box.add_component(onboard)  # added after the box is in the scene: mounted at once
    assert len(scene.get_cameras()) == 2 and len(partsim_lights(scene)) == 1
    # the light shines along its frame's x axis: straight down here
    np.testing.assert_allclose(partsim_lights(scene)[0].direction, [0, 0, -1], atol=1e-6)
    scene.update_render()
    cam.take_picture()
    color = cam.get_picture("Color")
    assert color.shape == (48, 64, 4) and color[24, 32, 1] > color[24, 32, 0]
    ps = cam.get_picture("PositionSegmentation")
    assert ps.dtype == np.int16
    assert ps[24, 32, 2] == pytest.approx(-900, abs=2)  # the box's face 0.9 m ahead, in mm
    assert ps[24, 32, 3] == box.per_scene_id and ps[0, 0, 3] == 0
    # moving the camera's entity moves the camera
    viewpoint.set_pose(sapien.Pose([-2, 0, 0.1]))
    np.testing.assert_allclose(cam.get_global_pose().p, [-2, 0, 0.1])
    np.testing.assert_allclose(onboard.get_global_pose().p, [0, 0, 0.3], atol=1e-9)
    viewpoint.remove_component(cam)
    assert len(scene.get_cameras()) == 1


def partsim_lights(scene):
    return sapien.partsim_object(scene).get_lights()


def test_a_scripts_own_component_hears_its_entity():
    heard = []

    class Tag(sapien.Component):
        def __init__(self, label):
            super().__init__()
            self.label = label

        def on_add_to_scene(self, scene):
            heard.append(("add", self.label))

        def on_remove_from_scene(self, scene):
            heard.append(("remove", self.label))

        def on_set_pose(self, pose):
            heard.append(("pose", round(float(pose.p[0]), 3)))

    scene = sapien.Scene()
    e, _ = box_entity("tagged", [0.1] * 3, sapien.Pose())
    tag = Tag("crate")
    e.add_component(tag)
    scene.add_entity(e)
    e.set_pose(sapien.Pose([0.5, 0, 0]))
    assert e.find_component_by_type(Tag) is tag and tag.entity is e
    e.remove_from_scene()
    assert heard == [("add", "crate"), ("pose", 0.5), ("remove", "crate")]


def test_misuse_names_what_is_wrong():
    scene = sapien.Scene()
    e, body = box_entity("box", [0.1] * 3, sapien.Pose())
    scene.add_entity(e)
    with pytest.raises(partsim.PartsimError, match="attach every shape first"):
        body.attach(physx.PhysxCollisionShapeSphere(0.1))
    with pytest.raises(partsim.PartsimError, match="in a scene already"):
        scene.add_entity(e)
    with pytest.raises(partsim.PartsimError, match="add the PhysxRigidDynamicComponent before"):
        e.add_component(physx.PhysxRigidDynamicComponent())
    with pytest.raises(partsim.PartsimError, match="set them before"):
        body.set_mass(3.0)
    with pytest.raises(partsim.PartsimError, match="convex shapes only"):
        physx.PhysxCollisionShapeTriangleMesh("mesh.obj", [1, 1, 1], None)
    with pytest.raises(partsim.PartsimError, match="belongs to another entity"):
        sapien.Entity().add_component(body)
    with pytest.raises(partsim.PartsimError, match="expected a sapien.Entity"):
        scene.add_entity("box")
    with pytest.raises(partsim.PartsimError, match="skew"):
        render.RenderCameraComponent(8, 8).set_skew(0.1)
    # SAPIEN names partsim does not have: a PartsimError that is also an AttributeError
    with pytest.raises(sapien.UnsupportedError, match="get_picture_cuda.*numpy"):
        render.RenderCameraComponent(8, 8).get_picture_cuda
    assert not hasattr(e, "hide_visual")
    # the scene and the entity survive each of these
    scene.step()
    assert e.scene is scene


def test_loader_parse_has_sapiens_meaning(tmp_path):
    from conftest import CABINET_URDF
    path = tmp_path / "cabinet.urdf"
    path.write_text(CABINET_URDF)
    scene = sapien.Scene()
    loader = scene.create_urdf_loader()
    builders, actors, cameras = loader.parse(str(path))
    assert len(builders) == 1 and actors == [] and cameras == []
    cabinet = builders[0].build()
    assert isinstance(cabinet, physx.PhysxArticulation) and cabinet.dof >= 1
    arts, lone = loader.load_multiple(str(path))
    assert len(arts) == 1 and lone == []
    assert len(scene.get_all_articulations()) == 2


def test_convex_mesh_shapes_from_points_and_from_a_file():
    from conftest import REPO
    scene = sapien.Scene()
    scene.set_timestep(0.002)
    scene.add_ground(0)
    corners = np.array([[x, y, z] for x in (-.1, .1) for y in (-.1, .1) for z in (-.05, .05)])
    body = physx.PhysxRigidDynamicComponent()
    body.attach(physx.PhysxCollisionShapeConvexMesh(corners, [1, 1, 1], None))
    pieces = physx.PhysxCollisionShapeConvexMesh.load_multiple(
        os.path.join(REPO, "tests", "data", "meshes", "cube.obj"), [0.1, 0.1, 0.1])
    assert len(pieces) == 1 and pieces[0].vertices.shape[1] == 3
    e = sapien.Entity()
    e.add_component(body)
    e.set_pose(sapien.Pose([0, 0, 0.3]))
    scene.add_entity(e)
    # MuJoCo computes a mesh body's mass properties from its hull: 0.2 x 0.2 x 0.1 m of water
    assert body.mass == pytest.approx(4.0, rel=1e-5)
    np.testing.assert_allclose(sorted(body.inertia), [4 / 12 * 0.05, 4 / 12 * 0.05,
                                                      4 / 12 * 0.08], rtol=1e-5)
    scene.step(500)
    assert e.pose.p[2] == pytest.approx(0.05, abs=2e-3)
    with pytest.raises(partsim.PartsimError, match="n >= 4"):
        physx.PhysxCollisionShapeConvexMesh(corners[:3], [1, 1, 1], None)


def test_raycasts_name_the_component_they_meet():
    scene = sapien.Scene()
    scene.add_ground(0)
    e, body = box_entity("box", [0.1, 0.2, 0.3], sapien.Pose([1, 0, 0.3]))
    scene.add_entity(e)
    hit = scene.physx_system.raycast([0, 0, 0.2], [1, 0, 0], 10)
    assert hit.component is body and hit.distance == pytest.approx(0.9)
    np.testing.assert_allclose(hit.normal, [-1, 0, 0], atol=1e-9)
    assert hit.shape.get_index() == 0
    assert scene.physx_system.raycast([0, 0, 1], [0, 0, -1], 10).component.entity.name == \
        "ground"
    assert scene.physx_system.raycast([0, 0, 0.2], [-1, 0, 0], 10) is None
    with pytest.raises(partsim.PartsimError, match="direction"):
        scene.physx_system.raycast([0, 0, 0.2], [0, 0, 0], 10)
