"""Shared fixtures of the Python binding tests.

The built package is found through PARTSIM_PYTHON_DIR (default: <repo>/build/python), the
folder that holds partsim/ with the compiled _partsim extension.
"""

import importlib
import os
import sys

import numpy as np
import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PYTHON_DIR = os.environ.get("PARTSIM_PYTHON_DIR", os.path.join(REPO, "build", "python"))
sys.path.insert(0, os.path.abspath(PYTHON_DIR))

import partsim  # noqa: E402


def require(module, package):
    """Imports `module` for a test module, `package` being what provides it (a pin of
    requirements.lock or a Debian package of scripts/setup.sh). Where it does not import, the
    module is skipped, except in a run of scripts/test.sh, which sets PARTSIM_REQUIRE_PINNED=1:
    there the package is meant to be installed, and its absence fails, naming it."""
    if os.environ.get("PARTSIM_REQUIRE_PINNED") == "1":
        try:
            return importlib.import_module(module)
        except ImportError as e:
            error = e
        # a collection error: pytest stops the run there, naming the package
        pytest.fail(f"{package} is pinned but '{module}' does not import ({error}): run "
                    "scripts/setup.sh (PARTSIM_REQUIRE_PINNED=1 turns this skip into a failure)",
                    pytrace=False)
    return pytest.importorskip(module, reason=f"{package} is not installed ('{module}')")

# A fixed cabinet-like object: a base, a door on a revolute hinge and a drawer on a prismatic
# slide; explicit inertials so the numbers do not depend on the shapes.
CABINET_URDF = """<?xml version="1.0"?>
<robot name="cabinet">
  <link name="base">
    <inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.4 0.4"/></geometry></collision>
  </link>
  <link name="door">
    <inertial><origin xyz="0 0.1 0"/><mass value="1"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0.1 0"/><geometry><box size="0.02 0.2 0.3"/></geometry></collision>
  </link>
  <link name="drawer">
    <inertial><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.05"/></geometry></collision>
  </link>
  <joint name="hinge" type="revolute">
    <parent link="base"/><child link="door"/>
    <origin xyz="0.25 -0.1 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="0.5" effort="100" velocity="10"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="base"/><child link="drawer"/>
    <origin xyz="0 0 1.0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.3" effort="100" velocity="1"/>
  </joint>
</robot>
"""


@pytest.fixture
def scene():
    return partsim.Scene()


@pytest.fixture
def cabinet(scene):
    loader = scene.create_urdf_loader()
    loader.fix_root_link = True
    return loader.load_from_string(CABINET_URDF, ".")


def build_box(scene, half=0.1, z=0.5, name="box", density=1000.0):
    """A dynamic box of half extent `half` with its centre at height z."""
    builder = scene.create_actor_builder()
    builder.add_box_collision(half_size=[half] * 3, density=density)
    builder.add_box_visual(half_size=[half] * 3, color=[1, 0, 0, 1])
    builder.set_name(name)
    builder.set_initial_pose(partsim.Pose([0, 0, z]))
    return builder.build()


@pytest.fixture
def resting_box(scene):
    """A 0.2 m box dropped on the ground and left to settle for 2 s."""
    scene.add_ground()
    box = build_box(scene)
    scene.step(1000)
    return box


def assert_vec(a, shape, dtype=np.float64):
    assert isinstance(a, np.ndarray), type(a)
    assert a.shape == shape, (a.shape, shape)
    assert a.dtype == dtype, a.dtype


class PerceptionData:
    """A tiny perception benchmark made by the command line: `tree` (two generated
    StorageFurniture objects, seed 1), `det` (its detection dataset) and `mot` (its motion
    dataset), 4 views each at 64 x 64, seed 5. The split puts one object in train and one in
    test; the baselines' tests overfit the training split and score it."""


@pytest.fixture(scope="session")
def perception_data(tmp_path_factory):
    import subprocess
    cli = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                                     "partsim"))
    base = tmp_path_factory.mktemp("perception_data")
    d = PerceptionData()
    d.cli = cli
    d.tree, d.det, d.mot = str(base / "tree"), str(base / "det"), str(base / "mot")
    common = ["--views", "4", "--size", "64", "--seed", "5", "--quiet"]
    for args in (["assets", "generate", "--out", d.tree, "--categories", "StorageFurniture",
                  "--per-category", "2", "--seed", "1"],
                 ["vision", "detection-dataset", "--dataset", d.tree, "--out", d.det] + common,
                 ["vision", "motion-dataset", "--dataset", d.tree, "--out", d.mot] + common):
        r = subprocess.run([cli] + args, capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, "partsim %s: %s%s" % (" ".join(args), r.stdout, r.stderr)
    return d
