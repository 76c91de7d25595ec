"""The SAPIEN-style example scripts (examples/sapien/) run to the end with partsim standing in for
SAPIEN, and print what they check: the box rests and the contact force equals its weight with
SAPIEN's sign, a box set down on a box is held by its contacts from the first step, the car
drives straight on the ground at dt = 0.01 s, the PID arm reaches its target, the camera's point
cloud lies on the objects; the entity-component tutorials build a scene from components and run
components of their own."""

import os
import subprocess
import sys

import pytest

from conftest import PYTHON_DIR, REPO

EXAMPLES = os.path.join(REPO, "examples", "sapien")


def run_example(name, *args, cwd):
    env = dict(os.environ, PYTHONPATH=os.path.abspath(PYTHON_DIR))
    env.setdefault("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                               "partsim"))
    p = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), *args], cwd=cwd, env=env,
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, f"{name} failed:\n{p.stdout}\n{p.stderr}"
    return p.stdout


def value_after(text, marker):
    """The number that follows `marker` in text."""
    rest = text.split(marker, 1)[1].strip()
    return float(rest.split()[0].rstrip(",;"))


def test_hello_world_box_rests_and_contact_force_is_its_weight(tmp_path):
    out = run_example("hello_world.py", cwd=tmp_path)
    assert "hello world: ok" in out
    assert value_after(out, "box rests at z =") == pytest.approx(0.5, abs=2e-3)
    force, weight = value_after(out, "contact force ="), value_after(out, "weight =")
    assert force > 0 and force == pytest.approx(weight, rel=0.01)
    assert "actor0 = box, actor1 = ground" in out


def test_contact_a_box_set_down_on_a_box_is_held_from_the_first_step(tmp_path):
    # SAPIEN 2's contact example: a 0.5 m cube placed exactly on a kinematic cube at dt = 0.01 s;
    # after one step the contact impulses add up to m g dt within 1e-3, and the box stays
    out = run_example("contact.py", cwd=tmp_path)
    assert "contact: ok" in out
    impulse, expected = value_after(out, "contact impulse ="), value_after(out, "m g dt =")
    assert impulse == pytest.approx(expected, rel=1e-3)
    assert value_after(out, "box moved") < 1e-5
    assert "contact box-base" in out or "contact base-box" in out


def test_hello_world_v3_renders_the_red_box(tmp_path):
    out = run_example("hello_world_v3.py", str(tmp_path / "box.png"), cwd=tmp_path)
    assert "hello world v3: ok" in out
    assert "viewer: http://127.0.0.1:" in out
    assert (tmp_path / "box.png").stat().st_size > 1000


def test_articulation_built_link_by_link_reaches_its_targets(tmp_path):
    out = run_example("articulation.py", cwd=tmp_path)
    assert "articulation: ok" in out
    assert "drawer_slide: limits [[0.0, 0.35]]" in out


def test_car_drives_straight_on_the_ground_at_a_hundredth_of_a_second(tmp_path):
    out = run_example("car.py", cwd=tmp_path)
    assert "car: ok" in out
    assert "at dt = 0.01" in out
    assert value_after(out, "drove (") > 2.0


def test_pid_arm_reaches_its_target(tmp_path):
    out = run_example("robot_pid.py", cwd=tmp_path)
    assert "robot pid: ok" in out
    assert value_after(out, "external PID: largest arm joint error") < 0.02


def test_camera_takes_every_picture(tmp_path):
    out = run_example("camera.py", str(tmp_path), cwd=tmp_path)
    assert "camera: ok" in out
    for name in ("color.png", "label0.png", "label1.png", "points.npy"):
        assert (tmp_path / name).stat().st_size > 1000, name


def test_load_urdf_robot_and_partnet_mobility_object(tmp_path):
    out = run_example("load_urdf.py", cwd=tmp_path)
    assert "load urdf: ok" in out
    assert "9 dof" in out


def test_load_urdf_real_partnet_mobility_object(tmp_path):
    real = os.path.join(REPO, "..", "shared", "realdata", "partnet-mobility-3763")
    if not os.path.isdir(real):
        pytest.skip(f"{real} is absent")
    panda = os.path.join(REPO, "tests", "data", "arm", "arm_description", "urdf", "panda.urdf")
    out = run_example("load_urdf.py", panda, real, cwd=tmp_path)
    assert "load urdf: ok" in out


def test_ecs_hello_world_builds_the_scene_from_components(tmp_path):
    out = run_example("ecs_hello_world.py", str(tmp_path / "box.png"), cwd=tmp_path)
    assert "ecs hello world: ok" in out
    assert value_after(out, "mass") == pytest.approx(12.0)
    assert value_after(out, "box rests at z =") == pytest.approx(0.1, abs=2e-3)
    assert value_after(out, "contact impulse") == pytest.approx(value_after(out, "m g dt ="),
                                                                rel=0.01)
    assert value_after(out, "cx") == pytest.approx(80.0)  # SAPIEN's principal point: width / 2
    assert (tmp_path / "box.png").stat().st_size > 1000


def test_ecs_components_of_the_scripts_own_drive_and_count(tmp_path):
    out = run_example("ecs_components.py", cwd=tmp_path)
    assert "ecs components: ok" in out
    assert value_after(out, "box pushed") == pytest.approx(0.57, abs=0.02)
    assert value_after(out, "touched in") > 100
