"""The motion-attribute baselines of partsim.perception.motion: the paper's seven-term loss
against a hand computation, the output squashing, the depth lifting, and both networks
overfitting the training split of the tiny perception benchmark (conftest's
`perception_data`), scored by partsim.vision.evaluate_motion."""

import math
import os
import time

import numpy as np
import pytest

from conftest import require

torch = require("torch", "Debian's python3-torch")

import partsim.vision as vision  # noqa: E402
from partsim.perception.motion import (  # noqa: E402
    MotionPointNet, MotionResNet, axis_output, lift_depth, motion_loss, motion_outputs)


def softplus(x):
    return math.log1p(math.exp(x))


def f64(values):
    return torch.tensor(values, dtype=torch.float64)


def loss_batch():
    """Three samples, raw outputs and labels, whose loss terms are worked out by hand in
    test_loss_terms_match_a_hand_computation."""
    raw = torch.zeros(3, 13, dtype=torch.float64)
    m = torch.zeros(3, 13, dtype=torch.float64)
    # A, a hinge: raw axis (3, 4, 0), output tanh((0.6, 0.8, 0)) against (1, 0, 0); pivot
    # (0.3, 0.4, 2.5) against the line through (0, 0, 2) along x: squared distance
    # 0.4^2 + 0.5^2 = 0.41; door sigmoid(0) = 0.5 against 0.25: 0.0625
    raw[0, :2] = f64([2.0, -1.0])
    raw[0, 2:5] = f64([0.3, 0.4, 2.5])
    raw[0, 5:8] = f64([3.0, 4.0, 0.0])
    m[0, :2] = f64([1.0, 0.0])
    m[0, 2:5] = f64([0.0, 0.0, 2.0])
    m[0, 5:8] = f64([1.0, 0.0, 0.0])
    m[0, 11] = 0.25
    # B, a slider: raw axis (-30, 0, 40), output tanh((-0.6, 0, 0.8)) against (0, 0, 2) (not
    # unit); drawer sigmoid(log 3) = 0.75 against 0.5: 0.0625
    raw[1, :2] = f64([-0.5, 1.5])
    raw[1, 8:11] = f64([-30.0, 0.0, 40.0])  # the length does not matter
    raw[1, 12] = math.log(3.0)
    m[1, :2] = f64([0.0, 1.0])
    m[1, 8:11] = f64([0.0, 0.0, 2.0])
    m[1, 12] = 0.5
    # C, a hinge: raw axis (0, 0.3, 0.4), output tanh((0, 0.6, 0.8)) against (0, 0, -1); pivot
    # (1, 1, 1) on the line through (1, 1, 0) along z: 0; door sigmoid(log 1/3) = 0.25
    # against 0.75: 0.25
    raw[2, :2] = f64([1.0, -2.0])
    raw[2, 2:5] = f64([1.0, 1.0, 1.0])
    raw[2, 5:8] = f64([0.0, 0.3, 0.4])
    raw[2, 11] = math.log(1.0 / 3.0)
    m[2, :2] = f64([1.0, 0.0])
    m[2, 2:5] = f64([1.0, 1.0, 0.0])
    m[2, 5:8] = f64([0.0, 0.0, -1.0])
    m[2, 11] = 0.75
    return raw, m


def test_loss_terms_match_a_hand_computation():
    raw, m = loss_batch()
    total, terms = motion_loss(raw, m)
    # the axis outputs: tanh of the unit raw vector; 1 - |cos| against the true axes
    t6, t8 = math.tanh(0.6), math.tanh(0.8)
    norm = math.hypot(t6, t8)
    d_a, d_b, d_c = 1 - t6 / norm, 1 - t8 / norm, 1 - t8 / norm
    # means over the samples of each type (A and C hinges, B the slider), BCE over all three
    expected = {
        "dr": (d_a + d_c) / 2,
        "p": (0.41 + 0.0) / 2,
        "door": (0.0625 + 0.25) / 2,
        "dt": d_b,
        "drawer": 0.0625,
        "Tr": (softplus(-2.0) + softplus(-0.5) + softplus(-1.0)) / 3,
        "Tt": (softplus(-1.0) + softplus(-1.5) + softplus(-2.0)) / 3,
    }
    assert set(terms) == set(expected)
    for k, v in expected.items():
        assert terms[k] == pytest.approx(v, abs=1e-9), k
    assert float(total) == pytest.approx(sum(expected.values()), abs=1e-9)
    # means: the same batch twice over gives the same loss
    total2, _ = motion_loss(torch.cat([raw, raw]), torch.cat([m, m]))
    assert float(total2) == pytest.approx(float(total), abs=1e-12)


def test_loss_ignores_the_other_types_entries():
    raw, m = loss_batch()
    _, terms = motion_loss(raw, m)
    # the hinges' slider entries and the slider's hinge entries, in outputs and labels
    other = [(0, [8, 9, 10, 12]), (2, [8, 9, 10, 12]), (1, [2, 3, 4, 5, 6, 7, 11])]
    raw2, m2 = raw.clone(), m.clone()
    gen = torch.Generator().manual_seed(0)
    for i, cols in other:
        raw2[i, cols] = 5.0 * torch.randn(len(cols), generator=gen, dtype=torch.float64)
        m2[i, cols] = torch.rand(len(cols), generator=gen, dtype=torch.float64)
    _, terms2 = motion_loss(raw2, m2)
    for k in terms:
        assert terms2[k] == pytest.approx(terms[k], abs=1e-12), k
    # and no gradient flows into them
    raw2.requires_grad_(True)
    motion_loss(raw2, m2)[0].backward()
    for i, cols in other:
        assert torch.all(raw2.grad[i, cols] == 0), (i, cols)
    assert torch.all(raw2.grad[:, :2] != 0)


def test_loss_of_a_batch_without_sliders_has_zero_slider_terms():
    raw, m = loss_batch()
    total, terms = motion_loss(raw[[0, 2]], m[[0, 2]])
    assert terms["dt"] == 0.0 and terms["drawer"] == 0.0
    assert math.isfinite(float(total))


def test_outputs_ranges():
    raw = 10.0 * torch.randn(64, 13, generator=torch.Generator().manual_seed(1))
    out = motion_outputs(raw)
    assert out.shape == (64, 13)
    for col in (0, 1, 11, 12):  # probabilities and states
        assert torch.all((out[:, col] >= 0) & (out[:, col] <= 1)), col
    assert torch.all(out[:, 5:11].abs() <= 1)  # axes
    assert torch.equal(out[:, 2:5], raw[:, 2:5])  # pivot in metres, as is
    zero = motion_outputs(torch.zeros(1, 13))
    assert torch.allclose(zero[0, [0, 1, 11, 12]], torch.full((4,), 0.5))


def test_axis_outputs_depend_on_the_raw_direction_only():
    # tanh on raw values saturates once they grow (the cosine loss does not hold their length);
    # the axis output takes tanh of the unit raw vector, the same at any length
    raw = torch.randn(8, 3, generator=torch.Generator().manual_seed(2), dtype=torch.float64)
    assert torch.allclose(axis_output(raw), axis_output(1000.0 * raw))
    assert torch.allclose(axis_output(raw), torch.tanh(raw / raw.norm(dim=1, keepdim=True)))
    # where tanh of the raw values is flat (every component 50 or more away from 0), the
    # direction still gets a gradient
    raw = torch.tensor([[1.0, 2.0, 3.0], [-1.0, 1.0, 2.0], [2.0, -1.0, 1.0], [1.0, 1.0, -1.0]],
                       dtype=torch.float64)
    big = (50.0 * raw).requires_grad_(True)
    true = torch.tensor([[0.0, 0.0, 1.0]], dtype=torch.float64).expand(4, 3)
    cos = (axis_output(big) * true).sum(1) / axis_output(big).norm(dim=1)
    (1 - cos.abs()).sum().backward()
    assert float(big.grad.abs().max()) > 1e-4
    flat = (50.0 * raw).requires_grad_(True)
    cos = (torch.tanh(flat) * true).sum(1) / torch.tanh(flat).norm(dim=1)
    (1 - cos.abs()).sum().backward()
    assert float(flat.grad.abs().max()) < 1e-10


def test_lifted_points_project_back_onto_their_pixels():
    K = np.array([[100.0, 0, 31.5], [0, 90.0, 20.5], [0, 0, 1]])
    depth = np.zeros((40, 64), np.float32)
    depth[5:30, 10:50] = np.linspace(1.0, 3.0, 40, dtype=np.float32)
    points, pixels = lift_depth(depth, K)
    assert points.shape == (25 * 40, 3) and len(pixels) == 25 * 40
    uvw = points.astype(np.float64) @ K.T
    v, u = np.divmod(pixels, 64)
    np.testing.assert_allclose(uvw[:, 0] / uvw[:, 2], u, atol=1e-4)
    np.testing.assert_allclose(uvw[:, 1] / uvw[:, 2], v, atol=1e-4)
    np.testing.assert_allclose(points[:, 2], depth.reshape(-1)[pixels])


def overfit(cls, root, options, steps, lr):
    """Trains a `cls` baseline on the whole training split of `root` for `steps` full-batch
    Adam steps (seed 0), and scores its predictions on that split."""
    torch.manual_seed(0)
    train = vision.MotionDataset(root, "train")
    baseline = cls(train, dict(options, seed=0))
    model = baseline.build_model()
    optimizer = baseline.make_optimizer(model, lr)
    rng = np.random.default_rng(0)
    everything = list(range(len(train)))
    start = time.monotonic()
    model.train()
    for _ in range(steps):
        total, _ = baseline.loss(model, baseline.load_batch(train, everything, rng, True))
        optimizer.zero_grad()
        total.backward()
        optimizer.step()
    model.eval()
    predictions = baseline.predict(model, train, everything, "cpu", np.random.default_rng(1))
    scores = vision.evaluate_motion(os.path.join(root, "motion_train.json"),
                                    {"samples": predictions})
    print("%s %s: %d steps in %.1f s; H acc %.2f, S acc %.2f, H_o %.3f m, H_a %.1f deg, "
          "S_a %.1f deg, door %.1f deg, drawer %.3f m" % (
              cls.name, options, steps, time.monotonic() - start, scores.hinge_accuracy,
              scores.slider_accuracy, scores.hinge_origin_error, scores.hinge_axis_error,
              scores.slider_axis_error, scores.door_error, scores.drawer_error))
    return scores


def test_resnet_overfits_the_training_split(perception_data):
    require("torchvision", "Debian's python3-torchvision")
    # measured: H_a 3 deg, S_a 4 deg, H_o 0.03 m, door 4 deg, drawer 0.02 m (about a minute)
    s = overfit(MotionResNet, perception_data.mot, {"backbone": "resnet18", "size": 48},
                steps=60, lr=1e-3)
    assert s.hinges > 0 and s.sliders > 0
    assert s.hinge_accuracy == 1.0 and s.slider_accuracy == 1.0
    assert s.hinge_axis_error < 10.0 and s.slider_axis_error < 10.0
    assert s.hinge_origin_error < 0.1
    assert s.door_error < 15.0 and s.drawer_error < 0.06


def test_pointnet_overfits_the_training_split(perception_data):
    # measured: H_a 2 deg, S_a 7 deg, H_o 0.05 m, door 11 deg, drawer 0.03 m (about a minute)
    s = overfit(MotionPointNet, perception_data.mot, {"backbone": "small", "points": 512},
                steps=150, lr=1e-3)
    assert s.hinge_accuracy == 1.0 and s.slider_accuracy == 1.0
    assert s.hinge_axis_error < 20.0 and s.slider_axis_error < 20.0
    assert s.hinge_origin_error < 0.2
    assert s.door_error < 25.0 and s.drawer_error < 0.08


@pytest.mark.parametrize("cls, options", [
    (MotionResNet, {"backbone": "resnet18", "size": 32}),
    (MotionPointNet, {"backbone": "small", "width": 0.5, "points": 256}),
])
def test_predictions_follow_the_evaluators_format(perception_data, cls, options):
    if cls is MotionResNet:
        require("torchvision", "Debian's python3-torchvision")
    torch.manual_seed(0)
    train = vision.MotionDataset(perception_data.mot, "train")
    test = vision.MotionDataset(perception_data.mot, "test")
    baseline = cls(train, dict(options, seed=0, batch_size=3))
    assert baseline.kind == "motion" and baseline.options["input"] == cls.inputs[0]
    model = baseline.build_model().eval()
    # an untrained network, on the other split, in batches of 3 that do not divide it
    predictions = baseline.predict(model, test, range(len(test)), "cpu",
                                   np.random.default_rng(0))
    assert [p["sample_id"] for p in predictions] == [s["sample_id"] for s in test.samples]
    for p in predictions:
        assert set(p) == {"sample_id", "m"} and len(p["m"]) == 13
        assert all(isinstance(x, float) and math.isfinite(x) for x in p["m"])
    scores = vision.evaluate_motion(test.annotation_file, {"samples": predictions})
    assert scores.hinges + scores.sliders == len(test)


def test_bad_options_are_refused(perception_data):
    train = vision.MotionDataset(perception_data.mot, "train")
    with pytest.raises(ValueError, match="input 'xyz'"):
        MotionPointNet(train, {"input": "xyz"})
    with pytest.raises(ValueError, match="backbone 'vgg'"):
        MotionResNet(train, {"backbone": "vgg"})
    with pytest.raises(ValueError, match="points and width"):
        MotionPointNet(train, {"points": -5})
