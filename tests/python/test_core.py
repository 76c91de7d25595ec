"""Pose and the exception types (core bindings)."""

import math
import pickle

import numpy as np
import pytest

import partsim
from conftest import assert_vec


def test_pose_defaults_and_dtypes():
    pose = partsim.Pose()
    assert_vec(pose.p, (3,))
    assert_vec(pose.q, (4,))
    np.testing.assert_array_equal(pose.p, [0, 0, 0])
    np.testing.assert_array_equal(pose.q, [1, 0, 0, 0])


def test_pose_q_is_wxyz():
    # 90 degrees about z, given as w, x, y, z
    c = math.cos(math.pi / 4)
    pose = partsim.Pose([1, 2, 3], [c, 0, 0, c])
    np.testing.assert_allclose(pose.q, [c, 0, 0, c])
    np.testing.assert_allclose(pose.transform([1, 0, 0]), [1, 3, 3], atol=1e-12)
    m = pose.to_transformation_matrix()
    assert_vec(m, (4, 4))
    np.testing.assert_allclose(m[:3, 0], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(m[:3, 3], [1, 2, 3])


def test_pose_keyword_arguments_and_setters():
    pose = partsim.Pose(p=[0.5, 0, 0], q=[0, 1, 0, 0])
    np.testing.assert_allclose(pose.q, [0, 1, 0, 0])
    pose.p = [1, 1, 1]
    pose.q = [0, 0, 1, 0]
    np.testing.assert_allclose(pose.p, [1, 1, 1])
    np.testing.assert_allclose(pose.q, [0, 0, 1, 0])
    # the getters return copies: writing into them does not change the pose
    p = pose.p
    p[0] = 7
    assert pose.p[0] == 1


def test_pose_composition_inverse_and_matrix_round_trip():
    a = partsim.Pose([1, 2, 3], [math.cos(0.3), math.sin(0.3), 0, 0])
    b = partsim.Pose([-1, 0.5, 2], [math.cos(0.7), 0, 0, math.sin(0.7)])
    ab = a * b
    np.testing.assert_allclose(ab.to_transformation_matrix(),
                               a.to_transformation_matrix() @ b.to_transformation_matrix(),
                               atol=1e-12)
    ident = a * a.inv()
    np.testing.assert_allclose(ident.p, [0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(abs(ident.q[0]), 1, atol=1e-12)
    back = partsim.Pose.from_transformation_matrix(ab.to_transformation_matrix())
    np.testing.assert_allclose(back.p, ab.p, atol=1e-12)
    # q and -q are the same rotation
    assert min(np.abs(back.q - ab.q).max(), np.abs(back.q + ab.q).max()) < 1e-12


def test_pose_repr_and_pickle():
    pose = partsim.Pose([1, 2, 3], [0, 1, 0, 0])
    assert repr(pose).startswith("Pose(")
    clone = pickle.loads(pickle.dumps(pose))
    np.testing.assert_array_equal(clone.p, pose.p)
    np.testing.assert_array_equal(clone.q, pose.q)
    assert pose.is_valid()
    assert not partsim.Pose([math.nan, 0, 0]).is_valid()


def test_pose_rejects_wrong_sizes():
    with pytest.raises(TypeError):
        partsim.Pose([1, 2])
    with pytest.raises(TypeError):
        partsim.Pose([0, 0, 0], [1, 0, 0])


def test_exception_hierarchy():
    assert issubclass(partsim.PartsimError, ValueError)
    assert issubclass(partsim.PartsimIndexError, IndexError)
    assert issubclass(partsim.PartsimIndexError, partsim.PartsimError)


def test_version_is_the_projects_everywhere():
    import os
    import re
    import subprocess

    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    with open(os.path.join(repo, "CMakeLists.txt")) as f:
        project = re.search(r"project\(partsim VERSION ([0-9.]+)", f.read()).group(1)
    assert partsim.__version__ == project
    cli = os.path.join(os.path.dirname(os.path.dirname(partsim.__file__)), "..", "partsim")
    if os.path.exists(cli):  # the build tree's command line beside build/python
        out = subprocess.run([cli, "--version"], capture_output=True, text=True, timeout=30)
        assert out.stdout.startswith("partsim " + project + " "), out.stdout
