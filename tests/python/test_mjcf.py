"""MJCF models from Python: scene.load_mjcf on MuJoCo's own models (../shared/realdata/mjcf),
their controls, the handles partsim gives their bodies, MuJoCo's error for a bad file, and the
command line's info on an MJCF file."""

import json
import os
import subprocess

import numpy as np
import pytest

import partsim
from conftest import PYTHON_DIR, REPO

MJCF = os.path.join(REPO, "..", "shared", "realdata", "mjcf")
CLI = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                                 "partsim"))


def realdata(*parts):
    path = os.path.join(MJCF, *parts)
    if not os.path.exists(path):
        pytest.skip(f"{path} is absent (../shared)")
    return path


def test_the_car_drives_on_its_motors_and_tendons():
    scene = partsim.Scene()
    car = scene.load_mjcf(realdata("car", "car.xml"))
    assert car.name == "car" and car.prefix == "car/"
    assert car.get_actuator_names() == ["forward", "turn"]
    assert [m.name for m in scene.get_mjcf_models()] == ["car"]
    (art,) = car.get_articulations()
    start = art.get_root_pose().p.copy()
    car.set_ctrl("forward", 1.0)
    scene.step(1000)
    np.testing.assert_array_equal(car.get_ctrl(), [1.0, 0.0])
    assert np.linalg.norm(art.get_root_pose().p[:2] - start[:2]) > 0.1
    q = art.get_qpos()
    assert car.get_tendon_lengths()[0] == pytest.approx(0.5 * (q[0] + q[1]), abs=1e-9)
    # the model's slice of MuJoCo's state: the free root (7) and the two wheels
    assert car.get_qpos().shape == (9,) and car.get_qvel().shape == (8,)
    with pytest.raises(partsim.PartsimError, match="no actuator 'reverse'"):
        car.set_ctrl("reverse", 1.0)
    with pytest.raises(partsim.PartsimError, match="2 actuators"):
        car.set_ctrl(np.zeros(3))


def test_a_bad_file_gives_mujocos_message_and_the_scene_goes_on(tmp_path):
    scene = partsim.Scene()
    scene.add_ground(0.0)
    b = scene.create_actor_builder()
    b.add_box_collision(half_size=[0.05, 0.05, 0.05])
    b.set_name("box")
    box = b.build()
    box.set_pose(partsim.Pose([0, 0, 0.5]))
    scene.step(10)
    state = scene.pack()
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco>\n<worldbody>\n  <geom type=\"box\" size=\"1 1\" bogus=\"2\"/>\n"
                   "</worldbody>\n</mujoco>\n")
    with pytest.raises(partsim.PartsimError, match="bad.xml") as e:
        scene.load_mjcf(str(bad))
    assert "bogus" in str(e.value) and "line 3" in str(e.value)
    assert scene.pack() == state
    scene.step(500)
    assert box.get_pose().p[2] == pytest.approx(0.05, abs=2e-3)


def test_info_describes_an_mjcf_file():
    path = realdata("slider_crank", "slider_crank.xml")
    p = subprocess.run([CLI, "info", path, "--json"], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    info = json.loads(p.stdout)
    assert info["format"] == "mjcf"
    assert info["actuators"] == ["forward", "backward", "broken"]
    assert len(info["articulations"]) == 2
    assert info["counts"]["actuators"] == 3
    assert "its options are used" in p.stderr
    # as text too
    p = subprocess.run([CLI, "info", realdata("car", "car.xml")], capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 0, p.stderr
    assert "MJCF model 'car'" in p.stdout and "tendons (2): forward, turn" in p.stdout


def test_render_draws_an_mjcf_model(tmp_path):
    p = subprocess.run([CLI, "render", realdata("mug", "mug.xml"), "--out", str(tmp_path),
                        "--views", "1", "--width", "160", "--height", "120"],
                       capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 0, p.stderr
    from PIL import Image
    color = np.asarray(Image.open(tmp_path / "color_0.png").convert("RGB")).astype(float)
    # the mug fills part of the view: not a blank picture
    assert color.std() > 10


def test_simulate_records_an_mjcf_model_at_its_own_timestep(tmp_path):
    # newton's cradle has no tree; the slider-crank has two, each a hinge on the world
    out = tmp_path / "trajectory.json"
    p = subprocess.run([CLI, "simulate", realdata("replicate", "newton_cradle.xml"), "--steps",
                        "10"], capture_output=True, text=True, timeout=120)
    assert p.returncode != 0 and "no kinematic tree" in p.stderr
    p = subprocess.run([CLI, "simulate", realdata("slider_crank", "slider_crank.xml"), "--steps",
                        "100", "--out", str(out)], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    trajectory = json.loads(out.read_text())
    assert trajectory["dt"] == pytest.approx(0.002)
    assert len(trajectory["qpos"]) == 101 and len(trajectory["qpos"][0]) == 2
