"""The examples in examples/ (not examples/sapien/, see test_sapien_examples.py) run to the end
from a folder of their own with `--out DIR`, and every file they say they saved ("saved: PATH")
is there and holds something: PNGs decode at the size the example documents and are not one
flat colour, arrays and point clouds are not constant, JSON and CSV files have content."""

import ast
import glob
import json
import os
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from conftest import PYTHON_DIR, REPO

EXAMPLES = os.path.join(REPO, "examples")
SCRIPTS = sorted(os.path.basename(p) for p in glob.glob(os.path.join(EXAMPLES, "*.py")))

# files each example must save (relative to --out) and the size of its pictures (w, h)
EXPECTED = {
    "hello_scene.py": (["hello_scene.png"], (640, 480)),
    "panda_drives.py": (["panda.png", "panda_qpos.npy"], (640, 480)),
    "load_urdf.py": (["panda.json", "panda.png"], (640, 480)),
    "render_views.py": (["color.png", "depth.png", "depth.npy", "segmentation.png",
                         "segmentation.npy", "points.ply", "points.npy", "segmentation.json",
                         "camera.json"], (640, 480)),
    "cabinet_generator.py": (["rest.png", "moved.png"], (640, 480)),
    "drawer_env.py": (["frame_000.png", "frame_010.png", "rewards.csv"], (320, 240)),
    "ik_and_planning.py": (["start.png", "end.png", "path.npy"], (640, 480)),
}


def run(script, *args, cwd):
    # the examples that generate objects find the partsim command beside the package they
    # import (<build>/partsim) or on PATH, as they do for a user
    env = dict(os.environ, PYTHONPATH=os.path.abspath(PYTHON_DIR))
    p = subprocess.run([sys.executable, os.path.join(EXAMPLES, script), *args], cwd=cwd,
                       env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, f"{script} failed:\n{p.stdout}\n{p.stderr}"
    return p.stdout


def saved_paths(stdout):
    """The paths after 'saved: ' (a folder is printed with a trailing '/ (contents)')."""
    paths = []
    for line in stdout.splitlines():
        if line.startswith("saved: "):
            path = line[len("saved: "):]
            paths.append(path.split("/ (", 1)[0] if "/ (" in path else path)
    return paths


def check_file(path, png_size):
    """Asserts that `path` exists and holds something that is not trivially empty."""
    assert os.path.exists(path), path
    if os.path.isdir(path):
        assert os.listdir(path), f"{path} is empty"
        return
    assert os.path.getsize(path) > 0, path
    ext = os.path.splitext(path)[1]
    if ext == ".png":
        with Image.open(path) as image:
            image.load()
            if not os.path.basename(path).startswith("depth"):  # 16-bit depth: any size check
                assert image.size == png_size, (path, image.size)
            pixels = np.asarray(image)
        assert pixels.size and pixels.min() != pixels.max(), f"{path} is one flat value"
    elif ext == ".npy":
        array = np.load(path)
        assert array.size and array.min() != array.max(), f"{path} is constant"
    elif ext == ".ply":
        with open(path, "rb") as f:
            header = f.read(512).split(b"end_header")[0].decode()
        assert header.startswith("ply")
        count = int(header.split("element vertex ")[1].split()[0])
        assert count > 100, (path, count)
    elif ext == ".json":
        with open(path) as f:
            assert json.load(f), path
    elif ext == ".csv":
        with open(path) as f:
            assert len(f.read().splitlines()) > 1, path


def test_every_example_is_listed():
    assert SCRIPTS == sorted(EXPECTED), "add the new example to EXPECTED"


@pytest.mark.parametrize("script", SCRIPTS)
def test_example_has_a_docstring_saying_how_to_run_it(script):
    with open(os.path.join(EXAMPLES, script)) as f:
        doc = ast.get_docstring(ast.parse(f.read()))
    assert doc and f"examples/{script}" in doc and "--out" in doc


@pytest.mark.parametrize("script", SCRIPTS)
def test_example_runs_and_saves_what_it_says(script, tmp_path):
    out = tmp_path / "out"
    stdout = run(script, "--out", str(out), cwd=tmp_path)
    names, png_size = EXPECTED[script]
    paths = saved_paths(stdout)
    for name in names:
        assert str(out / name) in paths, f"{script} did not report saving {name}:\n{stdout}"
    for path in paths:
        assert os.path.dirname(os.path.abspath(path)).startswith(str(out)), path
        check_file(path, png_size)
    # nothing written outside --out
    assert os.listdir(tmp_path) == ["out"]


def test_default_out_is_below_the_current_folder(tmp_path):
    stdout = run("hello_scene.py", cwd=tmp_path)
    assert saved_paths(stdout) == [os.path.join("out", "hello_scene", "hello_scene.png")]
    assert (tmp_path / "out" / "hello_scene" / "hello_scene.png").stat().st_size > 1000
