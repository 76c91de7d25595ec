"""Throughput of the perception baselines (partsim.perception): training and prediction items
per second of each network, on the CPU or a GPU, and the time one epoch of the paper-size
datasets would take at that rate.

For each baseline asked for: the network is built as `partsim vision train` builds it, one
untimed warm-up batch runs, then `--batches` training batches (load, forward, backward,
optimiser step) and `--batches` prediction batches are timed, each repeated `--repeats` times;
the table gives the medians. Loading is included (as in training), so the figures are what a
run sees. Points per second for the point-cloud networks are items/s times the points per item.

The paper-size datasets: the detection dataset of all 46 categories at 20 views per object is
46,920 pictures (2,346 objects), 75% of them for training; the motion dataset of doors and
drawers, 1,308 targets at 20 samples, 26,160 samples, 75% for training.

Usage:
  PARTSIM_PYTHON_DIR=build/python .venv/bin/python bench/perception_bench.py \\
      --detection DET --motion MOT [--baselines maskrcnn,insseg,motion-resnet,motion-pointnet]
      [--size 256] [--batch-size 4] [--batches 5] [--repeats 3] [--device auto]
      [--backbone resnet50] [--point-backbone ssg] [--points 10000] [--out FILE.md]

DET and MOT are folders of `partsim vision detection-dataset` / `motion-dataset`.
"""

import argparse
import os
import platform
import statistics
import sys
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(
    0, os.path.abspath(os.environ.get("PARTSIM_PYTHON_DIR", os.path.join(REPO, "build", "python")))
)

import torch  # noqa: E402

from partsim._device import resolve_device  # noqa: E402
from partsim.perception import baseline_class  # noqa: E402
from partsim.perception.train import open_split  # noqa: E402

PAPER_TRAIN_ITEMS = {"detection": int(46920 * 0.75), "motion": int(26160 * 0.75)}


def _sync(device):
    if device == "cuda":
        torch.cuda.synchronize()


def measure(name, data, options, batch_size, batches, repeats, device):
    cls = baseline_class(name)
    train = open_split(cls.kind, data, "train")
    baseline = cls(train, options)
    torch.manual_seed(0)
    model = baseline.build_model().to(device)
    optimizer = baseline.make_optimizer(model, 1e-4)
    n = len(train)
    rng = np.random.default_rng(0)

    def indices(k):
        return [int((k * batch_size + j) % n) for j in range(batch_size)]

    def train_batches(count):
        model.train()
        for k in range(count):
            batch = baseline.to_device(baseline.load_batch(train, indices(k), rng, True), device)
            loss, _ = baseline.loss(model, batch)
            optimizer.zero_grad(set_to_none=True)
            loss.backward()
            optimizer.step()
        _sync(device)

    def predict_batches(count):
        model.eval()
        with torch.no_grad():
            for k in range(count):
                baseline.predict(model, train, indices(k), device, rng)
        _sync(device)

    rates = {"train": [], "predict": []}
    train_batches(1)  # warm-up: allocations, lazy initialisation
    predict_batches(1)
    for _ in range(repeats):
        for what, fn in (("train", train_batches), ("predict", predict_batches)):
            t = time.perf_counter()
            fn(batches)
            rates[what].append(batches * batch_size / (time.perf_counter() - t))
    params = sum(p.numel() for p in model.parameters())
    return cls.kind, {k: statistics.median(v) for k, v in rates.items()}, params


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--detection")
    p.add_argument("--motion")
    p.add_argument("--baselines", default="maskrcnn,insseg,motion-resnet,motion-pointnet")
    p.add_argument("--size", type=int, default=256)
    p.add_argument("--batch-size", type=int, default=4)
    p.add_argument("--batches", type=int, default=5)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--device", default="auto")
    p.add_argument("--backbone", default="resnet50", help="of maskrcnn and motion-resnet")
    p.add_argument("--point-backbone", default="ssg",
                   help="the PointNet++ preset of insseg and motion-pointnet (ssg or small)")
    p.add_argument("--points", type=int, default=10000)
    p.add_argument("--out")
    a = p.parse_args()
    device = resolve_device(a.device)
    machine = (torch.cuda.get_device_name(0) if device == "cuda"
               else f"CPU ({os.cpu_count()} cores, {torch.get_num_threads()} torch threads)")
    lines = [f"device: {device}, {machine}; torch {torch.__version__}, "
             f"Python {platform.python_version()}; size {a.size}, batch {a.batch_size}, "
             f"{a.batches} batches x {a.repeats} repeats (medians)", "",
             "| baseline | input | parameters | train items/s | predict items/s | "
             "train points/s | one paper-size epoch |",
             "|---|---|---:|---:|---:|---:|---:|"]
    for name in a.baselines.split(","):
        cls = baseline_class(name)
        data = a.detection if cls.kind == "detection" else a.motion
        if not data:
            print(f"skipping {name}: no --{cls.kind} dataset", file=sys.stderr)
            continue
        for inp in cls.inputs:
            point_net = name in ("insseg", "motion-pointnet")
            options = {"input": inp, "size": a.size, "seed": 0, "points": a.points,
                       "backbone": a.point_backbone if point_net else a.backbone}
            kind, rates, params = measure(name, data, options, a.batch_size, a.batches,
                                          a.repeats, device)
            points = (f"{rates['train'] * a.points:,.0f}"
                      if name in ("insseg", "motion-pointnet") else "")
            epoch_h = PAPER_TRAIN_ITEMS[kind] / rates["train"] / 3600
            lines.append(f"| {name} | {inp} | {params / 1e6:.1f} M | {rates['train']:.2f} | "
                         f"{rates['predict']:.2f} | {points} | {epoch_h:.1f} h |")
            print(lines[-1], file=sys.stderr, flush=True)
    text = "\n".join(lines)
    print(text)
    if a.out:
        with open(a.out, "w", encoding="utf-8") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
