#!/usr/bin/env python3
"""The perception baselines on a GPU: the device check of partsim.perception's four networks.

For each baseline (maskrcnn, insseg, motion-resnet, motion-pointnet), built as `partsim vision
train` builds it (the same options, `build_model`, `make_optimizer`, `load_batch`, `loss`), on
--device: (a) training throughput, one untimed warm-up batch then --batches timed batches
(loading, the move to the device, loss, backward, optimiser step), items/s and, for the point
networks, points/s, with the share of the time spent loading on the CPU; (b) forward-only
throughput, evaluation mode under torch.no_grad, the model called on batches already on the
device (Mask R-CNN and InsSeg's `predict` encode masks with partsim's compiled module and are
not called; the motion networks' `predict`, which needs none, is called once as a check);
(c) a short training run of --train-steps batches cycling over the items as the trainer does
(its epoch order and per-batch seeds), the loss of every step kept, every loss checked finite
(exit code 1 otherwise) and the means of the first and last 10 compared. Also the GPU, torch
and torchvision versions, the peak CUDA memory and the wall time of each baseline.

A GPU machine cannot import partsim's compiled module (built for the build machine's Python),
so the check runs in two steps:

1. `pack`, on the build machine with the real package: the first --train-items items of the
   train splits of a detection and a motion dataset, with what the baselines read of them, go
   into a bundle folder: one compressed .npz per item and bundle.json (categories, images,
   annotations without their RLE, samples, slider range, the split's sizes). Pictures larger
   than --size are subsampled (nearest pixel) to that side, K with them, boxes and areas from
   the subsampled masks; a view's point cloud is not stored but lifted again from its depth,
   K, colours and instance picture, which `pack` checks against the dataset's cloud files.
   The defaults (32 + 32 items, 256 px) made a bundle of 2.9 MiB from 512 x 512 datasets
   (10 MiB with --size 0, which keeps the pictures).
2. `run`, on the GPU machine, with only torch, torchvision, numpy and scipy: the networks'
   modules are loaded from this tree under a stand-in `partsim` package whose __init__ is not
   executed, over small datasets that read the bundle with the interface the baselines use.
   Exit code 0 when all went well, 1 when a loss was not finite, 2 when a baseline failed (its
   traceback printed and in the JSON file; the others still run), 3 when partsim's compiled
   module was imported all the same.

Usage, on the build machine (once, `echo /.gpu/ >> .git/info/exclude`: the bundle stays out of
git and travels only where a command carries it):

  PARTSIM_PYTHON_DIR=build/python .venv/bin/python bench/perception_gpu_check.py pack \\
      --detection DET --motion MOT --out .gpu/perception [--train-items 32] [--size 256]

then on the GPU machine, through the device tool's `run` with carry [".gpu/perception"] and
timeout_s 600:

  PYTHONUNBUFFERED=1 python3 bench/perception_gpu_check.py run --bundle .gpu/perception \\
      --out $OUT/perception_gpu.json --md $OUT/perception_gpu.md

  run options: [--device auto|cpu|cuda] [--baselines maskrcnn,insseg,motion-resnet,
  motion-pointnet] (NAME:INPUT for another input: maskrcnn:rgbd, insseg:xyzrgb) [--size 256]
  [--batch-size 8] [--batches 20] [--train-steps 200] [--points 10000] [--backbone resnet50]
  [--point-backbone ssg] [--lr LR] [--seed 0] [--minutes 8] [--out FILE.json] [--md FILE.md]

DET and MOT are folders of `partsim vision detection-dataset` / `motion-dataset`.

Time: the defaults are expected to take 3 to 6 minutes on one H200 (an estimate, not yet
measured there: about 220 training and 20 forward batches per baseline; the PointNet++
networks are the slow ones, their farthest point sampling a Python loop over up to 1,360
centres),
plus about 20 s for CUDA's start. --minutes (default 8, so that one 10-minute command holds it)
skips what is left of a baseline's parts, with a note, once the time since the start passes it;
the JSON file is written again after each baseline, so a killed run leaves what it measured. On
the build VM's 2 busy cores, `run --device cpu --size 64 --batch-size 2 --batches 2
--train-steps 6 --backbone resnet18 --points 512` on a bundle of 64 x 64 pictures (4 detection
views, 16 motion samples) takes 35 s, 25 s of it Mask R-CNN's.
"""

import argparse
import gc
import json
import math
import os
import platform
import shutil
import sys
import time
import traceback
import types

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PACKAGE = os.path.join(REPO, "python", "partsim")
FORMAT = "partsim-perception-gpu-bundle-1"
BUNDLE_FILE = "bundle.json"
ALL_BASELINES = "maskrcnn,insseg,motion-resnet,motion-pointnet"
PICTURE_BASELINES = ("maskrcnn", "motion-resnet")
POINT_BASELINES = ("insseg", "motion-pointnet")


def say(text=""):
    print(text, flush=True)


# --- what both commands share ------------------------------------------------------------------

def lift_cloud(depth, K, rgb, instance, labels):
    """A detection view's partial point cloud as DetectionDataset.point_cloud gives it, from
    the view's pictures: one point per pixel with depth > 0, in row-major order, lifted into the
    OpenCV camera frame with K (pixel centres at integer coordinates); its colour, its instance
    number and that instance's category id (labels[k - 1] for instance k, 0 for none)."""
    depth = np.asarray(depth, dtype=np.float64)
    pixels = np.flatnonzero(depth > 0)
    v, u = np.divmod(pixels, depth.shape[1])
    z = depth.reshape(-1)[pixels]
    xyz = np.stack([(u - K[0, 2]) * z / K[0, 0], (v - K[1, 2]) * z / K[1, 1], z], axis=1)
    inst = instance.reshape(-1)[pixels].astype(np.int32)
    table = np.concatenate([[0], np.asarray(labels, dtype=np.int64)]).astype(np.int32)
    label = np.where(inst < len(table), table[np.minimum(inst, len(table) - 1)], 0)
    return {"xyz": xyz.astype(np.float32), "rgb": rgb.reshape(-1, 3)[pixels],
            "instance": inst, "label": label.astype(np.int32)}


def folder_bytes(path):
    total = 0
    for root, _, files in os.walk(path):
        total += sum(os.path.getsize(os.path.join(root, f)) for f in files)
    return total


def mib(n):
    return f"{n / 2**20:.1f} MiB"


# --- pack (the build machine, the real partsim) ------------------------------------------------

def _plan(h, w, size):
    """Row and column indices that subsample an (h, w) picture to at most ``size`` on its larger
    side (nearest pixel), or None when it already fits."""
    if not size or max(h, w) <= size:
        return None
    s = size / max(h, w)
    nh, nw = max(1, int(round(h * s))), max(1, int(round(w * s)))
    rows = np.minimum(((np.arange(nh) + 0.5) * h / nh).astype(np.int64), h - 1)
    cols = np.minimum(((np.arange(nw) + 0.5) * w / nw).astype(np.int64), w - 1)
    return rows, cols


def _subsample(a, plan):
    """Picture ``a`` (h, w) or (h, w, c) at the plan's pixels."""
    rows, cols = plan
    return a[rows][:, cols]


def _subsample_K(K, shape, plan):
    """The intrinsics of the subsampled picture: exact where the side shrinks by a whole factor
    f (pixel u' is pixel f u' + f // 2), else the scaled pixel centres."""
    (h, w), (rows, cols) = shape, plan
    K = np.array(K, dtype=np.float64)
    for axis, (n, m) in enumerate(((w, len(cols)), (h, len(rows)))):
        if n % m == 0:
            f = n // m
            K[axis, axis] /= f
            K[axis, 2] = (K[axis, 2] - f // 2) / f
        else:
            K[axis, axis] *= m / n
            K[axis, 2] = (K[axis, 2] + 0.5) * m / n - 0.5
    return K


def _boxes(masks):
    """COCO [x, y, width, height] and pixel counts of masks (n, h, w) (zeros for an empty one)."""
    boxes = np.zeros((len(masks), 4), dtype=np.float64)
    for k, m in enumerate(masks):
        ys, xs = np.nonzero(m)
        if len(xs):
            boxes[k] = [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1]
    return boxes, masks.reshape(len(masks), -1).sum(axis=1).astype(np.int64)


def _fresh(folder):
    """``folder`` emptied of a previous pack's .npz files (and created)."""
    if os.path.isdir(folder):
        for name in os.listdir(folder):
            if name.endswith(".npz"):
                os.remove(os.path.join(folder, name))
    os.makedirs(folder, exist_ok=True)


def pack_detection(vision, data, out, count, size):
    ds = vision.DetectionDataset(data, "train")
    n = min(count, len(ds))
    folder = os.path.join(out, "detection")
    _fresh(folder)
    per_image = {}
    for a in ds.coco.get("annotations", []):
        per_image[a["image_id"]] = per_image.get(a["image_id"], 0) + 1
    images, annotations, items = [], [], []
    checked, cloud_mismatch, cloud_missing, worst = 0, 0, 0, 0.0
    for i in range(n):
        item = ds[i]
        image = dict(ds.images[i])
        if item["cloud_path"]:
            cloud = ds.point_cloud(i)
            lifted = lift_cloud(item["depth"], item["K"], item["rgb"], item["instance"],
                                item["labels"])
            same = (len(cloud["xyz"]) == len(lifted["xyz"])
                    and all(np.array_equal(cloud[k], lifted[k])
                            for k in ("rgb", "instance", "label")))
            if same and len(cloud["xyz"]):
                # the files' float32 arithmetic against float64 here: some micrometres
                gap = float(np.abs(cloud["xyz"] - lifted["xyz"]).max())
                worst = max(worst, gap)
                same = gap <= 1e-4
            checked += 1
            cloud_mismatch += 0 if same else 1
        else:
            cloud_missing += 1
        arrays = {k: item[k] for k in ("rgb", "depth", "instance", "masks", "labels", "boxes",
                                       "areas", "iscrowd", "annotation_ids", "K", "extrinsic",
                                       "qpos")}
        plan = _plan(*item["depth"].shape, size)
        if plan is not None:
            shape = item["depth"].shape
            for k in ("rgb", "depth", "instance"):
                arrays[k] = np.ascontiguousarray(_subsample(item[k], plan))
            arrays["masks"] = np.ascontiguousarray(item["masks"][:, plan[0]][:, :, plan[1]])
            arrays["K"] = _subsample_K(item["K"], shape, plan)
            arrays["boxes"], arrays["areas"] = _boxes(arrays["masks"])
        h, w = arrays["depth"].shape
        arrays["image_id"] = np.array(int(item["image_id"]), dtype=np.int64)
        name = f"{i:05d}.npz"
        np.savez_compressed(os.path.join(folder, name), **arrays)
        image.update(height=int(h), width=int(w))
        images.append(image)
        for k in range(len(arrays["labels"])):
            annotations.append({
                "id": int(arrays["annotation_ids"][k]), "image_id": int(item["image_id"]),
                "category_id": int(arrays["labels"][k]),
                "bbox": [float(x) for x in arrays["boxes"][k]],
                "area": int(arrays["areas"][k]), "iscrowd": int(arrays["iscrowd"][k])})
        items.append({"file": f"detection/{name}", "image_id": int(item["image_id"]),
                      "object": item["object"], "view": item["view"],
                      "category": item["category"], "has_cloud": bool(item["cloud_path"])})
    first = ds.images[0] if len(ds) else {}
    return {
        "source": os.path.abspath(data), "split": "train", "split_items": len(ds),
        "split_annotations": len(ds.coco.get("annotations", [])),
        "split_most_annotations_per_image": max(per_image.values(), default=0),
        "source_picture": [first.get("height"), first.get("width")],
        "categories": ds.categories, "images": images, "annotations": annotations,
        "items": items,
        "cloud_check": {"items_checked": checked, "mismatches": cloud_mismatch,
                        "items_without_cloud": cloud_missing, "largest_xyz_gap_m": worst},
    }


def pack_motion(vision, data, out, count, size):
    ds = vision.MotionDataset(data, "train")
    n = min(count, len(ds))
    folder = os.path.join(out, "motion")
    _fresh(folder)
    samples, items = [], []
    for i in range(n):
        item = ds[i]
        arrays = {k: item[k] for k in ("rgb", "depth", "mask", "m", "K", "extrinsic", "qpos",
                                       "pivot", "axis")}
        plan = _plan(*item["depth"].shape, size)
        if plan is not None:
            for k in ("rgb", "depth", "mask"):
                arrays[k] = np.ascontiguousarray(_subsample(item[k], plan))
            arrays["K"] = _subsample_K(item["K"], item["depth"].shape, plan)
        name = f"{i:05d}.npz"
        np.savez_compressed(os.path.join(folder, name), **arrays)
        s = ds.samples[i]
        sample = {k: s[k] for k in ("sample_id", "object", "category", "link", "label", "type",
                                    "state", "m") if k in s}
        samples.append(sample)
        items.append({"file": f"motion/{name}", "sample_id": s["sample_id"]})
    first = ds.samples[0]["camera"] if len(ds) else {}
    return {"source": os.path.abspath(data), "split": "train", "split_items": len(ds),
            "source_picture": [first.get("height"), first.get("width")],
            "slider_range": ds.slider_range, "samples": samples, "items": items}


def cmd_pack(a):
    sys.path.insert(0, os.path.abspath(
        os.environ.get("PARTSIM_PYTHON_DIR", os.path.join(REPO, "build", "python"))))
    from partsim import vision

    if not a.detection and not a.motion:
        sys.exit("pack: give --detection DET and/or --motion MOT")
    if os.path.isdir(a.out) and os.listdir(a.out) and not os.path.exists(
            os.path.join(a.out, BUNDLE_FILE)):
        sys.exit(f"pack: '{a.out}' is a folder that holds no bundle: give an empty or new one")
    os.makedirs(a.out, exist_ok=True)
    t = time.perf_counter()
    bundle = {"format": FORMAT, "created": time.strftime("%Y-%m-%d %H:%M:%S"),
              "train_items": a.train_items, "size": a.size, "detection": None, "motion": None}
    for kind, data, fn in (("detection", a.detection, pack_detection),
                           ("motion", a.motion, pack_motion)):
        if data:
            bundle[kind] = fn(vision, data, a.out, a.train_items, a.size)
        elif os.path.isdir(os.path.join(a.out, kind)):
            shutil.rmtree(os.path.join(a.out, kind))
    with open(os.path.join(a.out, BUNDLE_FILE), "w", encoding="utf-8") as f:
        json.dump(bundle, f, indent=1)
    say(f"bundle '{a.out}' in {time.perf_counter() - t:.1f} s:")
    for kind in ("detection", "motion"):
        part = bundle[kind]
        if part is None:
            continue
        side = np.load(os.path.join(a.out, part["items"][0]["file"]))["depth"].shape \
            if part["items"] else None
        say(f"  {kind}: {len(part['items'])} of the {part['split_items']} train items of "
            f"'{part['source']}', pictures {part['source_picture']} -> {list(side or [])}, "
            f"{mib(folder_bytes(os.path.join(a.out, kind)))}")
    check = (bundle["detection"] or {}).get("cloud_check")
    if check:
        say(f"  point clouds lifted from depth and K: {check['items_checked']} views checked "
            f"against the dataset's cloud files, {check['mismatches']} differ (largest gap "
            f"{check['largest_xyz_gap_m'] * 1e6:.0f} um), {check['items_without_cloud']} "
            "without a cloud file")
        if check["mismatches"] or check["items_without_cloud"]:
            say("  WARNING: insseg on this bundle does not see the dataset's own clouds")
    total = folder_bytes(a.out)
    say(f"  total {mib(total)} ({total:,} bytes)")
    if total > 48 * 2**20:
        say("  WARNING: over 48 MiB; the working tree that travels to the GPU machine is "
            "limited to 64 MiB: lower --train-items or --size")
    return 0


# --- run (any machine with torch; partsim's compiled module never imported) --------------------

def stand_in_package():
    """Makes ``partsim.perception`` importable from this tree without running
    python/partsim/__init__.py (which imports the compiled module)."""
    existing = sys.modules.get("partsim")
    if existing is not None:
        if getattr(existing, "__file__", None):
            sys.exit("run: the real partsim package is already imported")
        return
    package = types.ModuleType("partsim")
    package.__path__ = [PACKAGE]
    package.__doc__ = "stand-in of partsim for bench/perception_gpu_check.py (no compiled module)"
    sys.modules["partsim"] = package


def _compiled_imported():
    return sorted(m for m in ("partsim._partsim", "partsim.vision") if m in sys.modules)


class BundleDetection:
    """A packed detection train split with what the baselines read of a DetectionDataset:
    ``len``, items (``rgb``, ``depth``, ``instance``, ``masks``, ``labels``, ``boxes``,
    ``areas``, ``iscrowd``, ``annotation_ids``, ``K``, ``extrinsic``, ``qpos``, ``image_id``,
    ``object``, ``view``, ``category``), ``categories``, ``images``, ``coco`` (annotations
    without segmentation) and ``point_cloud(i)``. Items are read from their .npz file on each
    access, as the real dataset reads its files."""

    def __init__(self, root, doc):
        self.root = root
        self.split = "train"
        self.categories = list(doc["categories"])
        self.images = list(doc["images"])
        self.coco = {"images": self.images, "categories": self.categories,
                     "annotations": list(doc["annotations"])}
        self._items = list(doc["items"])

    def __len__(self):
        return len(self._items)

    def __getitem__(self, index):
        meta = self._items[index]
        with np.load(os.path.join(self.root, meta["file"])) as z:
            item = {k: z[k] for k in z.files}
        item["image_id"] = int(item["image_id"])
        item.update({k: meta[k] for k in ("object", "view", "category")})
        return item

    def point_cloud(self, index):
        item = self[index]
        return lift_cloud(item["depth"], item["K"], item["rgb"], item["instance"],
                          item["labels"])


class BundleMotion:
    """A packed motion train split with what the baselines read of a MotionDataset: ``len``,
    items (``rgb``, ``depth``, ``mask``, ``m``, ``K``, ``extrinsic``, ``qpos``, ``pivot``,
    ``axis`` and the sample's names), ``samples`` and ``slider_range``."""

    def __init__(self, root, doc):
        self.root = root
        self.split = "train"
        self.slider_range = float(doc["slider_range"])
        self.samples = list(doc["samples"])
        self._items = list(doc["items"])

    def __len__(self):
        return len(self._items)

    def __getitem__(self, index):
        with np.load(os.path.join(self.root, self._items[index]["file"])) as z:
            item = {k: z[k] for k in z.files}
        item.update({k: v for k, v in self.samples[index].items() if k != "m"})
        return item


def _sync(device):
    import torch
    if device == "cuda":
        torch.cuda.synchronize()


def _peak(device):
    import torch
    return int(torch.cuda.max_memory_allocated()) if device == "cuda" else None


def _reset_memory(device):
    import torch
    gc.collect()
    if device == "cuda":
        torch.cuda.empty_cache()
        torch.cuda.reset_peak_memory_stats()


def run_options(cls, name, inp, a, doc):
    """The options `partsim vision train NAME` would give the baseline (train.Run's defaults,
    the baseline's own, then the command's)."""
    from partsim.perception.train import Run

    options = {k: v for k, v in Run.COMMON.items()}
    for k, v in cls.defaults.items():
        if options.get(k) is None:
            options[k] = v
    options.update(input=inp, batch_size=a.batch_size, seed=a.seed)
    if a.lr is not None:
        options["lr"] = a.lr
    if name in PICTURE_BASELINES:
        options.update(size=a.size, backbone=a.backbone)
    else:
        options.update(points=a.points, backbone=a.point_backbone)
    if name == "insseg":
        # the network's K from the whole split (the bundle holds only some of its annotations)
        most = int(doc.get("split_most_annotations_per_image") or 0)
        options["instances"] = a.instances or max(cls.default_instances, most)
    return options


def forward(name, baseline, model, batch):
    """The network on a batch already on the device, as prediction calls it."""
    if name == "maskrcnn":
        return model(batch[0])
    if name == "insseg":
        return model(batch["xyz"], batch["features"])
    from partsim.perception.motion import motion_outputs
    return motion_outputs(baseline._forward(model, batch))


def bench_baseline(name, inp, dataset, doc, a, device, deadline):
    import torch
    from partsim.perception import baseline_class
    from partsim.perception.train import batch_seed, epoch_order

    cls = baseline_class(name)
    if inp not in cls.inputs:
        raise ValueError(f"{name} takes input {' or '.join(cls.inputs)}, not {inp!r}")
    options = run_options(cls, name, inp, a, doc)
    rec = {"baseline": name, "input": inp, "options": options, "notes": [],
           "train": None, "forward": None, "training_run": None, "finite": True}
    start = time.perf_counter()
    baseline = cls(dataset, options)
    rec["config"] = baseline.config()
    points = options.get("points") if name in POINT_BASELINES else None
    bs, n = a.batch_size, len(dataset)
    lr = float(options["lr"])

    def late(what):
        if time.perf_counter() > deadline:
            rec["notes"].append(f"{what} skipped: past --minutes {a.minutes:g}")
            say(f"  {name}: {what} skipped (past --minutes {a.minutes:g})")
            return True
        return False

    def indices(k):
        return [int((k * bs + j) % n) for j in range(bs)]

    def step(model, optimizer, idx, rng):
        t = time.perf_counter()
        batch = baseline.load_batch(dataset, idx, rng, True)
        load = time.perf_counter() - t
        batch = baseline.to_device(batch, device)
        loss, _ = baseline.loss(model, batch)
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        optimizer.step()
        return loss.detach(), load

    # (a) training throughput, (b) forward-only throughput
    _reset_memory(device)
    torch.manual_seed(a.seed)
    model = baseline.build_model().to(device)
    optimizer = baseline.make_optimizer(model, lr)
    rec["parameters"] = int(sum(p.numel() for p in model.parameters()))
    if not late("training throughput"):
        model.train()
        rng = np.random.default_rng(a.seed)
        t = time.perf_counter()
        step(model, optimizer, indices(0), rng)  # warm-up: allocations, cuDNN's kernels
        _sync(device)
        warm = time.perf_counter() - t
        losses, load, done = [], 0.0, 0
        t = time.perf_counter()
        for k in range(1, a.batches + 1):
            if time.perf_counter() > deadline:
                rec["notes"].append(f"training throughput cut at {done} batches (--minutes)")
                break
            loss, seconds = step(model, optimizer, indices(k), rng)
            losses.append(loss)
            load += seconds
            done += 1
        _sync(device)
        seconds = time.perf_counter() - t
        values = [float(x) for x in losses]
        finite = all(math.isfinite(x) for x in values)
        rec["finite"] &= finite
        rate = done * bs / seconds if done else None
        rec["train"] = {"batches": done, "seconds": seconds, "warm_up_seconds": warm,
                        "items_per_s": rate,
                        "points_per_s": rate * points if rate and points else None,
                        "load_share": load / seconds if done else None,
                        "losses_finite": finite}
        say(f"  {name}: training {done} x {bs} items in {seconds:.2f} s"
            + (f" ({rate:.2f} items/s, loading {100 * load / seconds:.0f}%)" if done else "")
            + f"; warm-up batch {warm:.2f} s")
    if not late("forward throughput"):
        model.eval()
        rng = np.random.default_rng([a.seed, 1])
        with torch.no_grad():
            batches = [baseline.to_device(baseline.load_batch(dataset, indices(k), rng, False),
                                          device) for k in range(max(1, a.batches))]
            forward(name, baseline, model, batches[0])  # warm-up
            _sync(device)
            done = 0
            t = time.perf_counter()
            for batch in batches:
                if time.perf_counter() > deadline:
                    rec["notes"].append(f"forward throughput cut at {done} batches (--minutes)")
                    break
                forward(name, baseline, model, batch)
                done += 1
            _sync(device)
            seconds = time.perf_counter() - t
            rate = done * bs / seconds if done else None
            rec["forward"] = {"batches": done, "seconds": seconds, "items_per_s": rate,
                              "points_per_s": rate * points if rate and points else None}
            if cls.kind == "motion":  # predict needs no compiled module: check that it runs
                entries = baseline.predict(model, dataset, indices(0), device, rng)
                ok = len(entries) == bs and all(len(e["m"]) == 13 for e in entries)
                rec["forward"]["predict_check"] = ok
                if not ok:
                    rec["notes"].append("predict() gave unexpected entries")
            del batches
        say(f"  {name}: forward {done} x {bs} items in {seconds:.2f} s"
            + (f" ({rate:.2f} items/s)" if done else ""))
    rec["peak_memory_throughput"] = _peak(device)
    del model, optimizer

    # (c) a short training run from a new network, as the trainer cycles over the items
    if a.train_steps > 0 and not late("training run"):
        _reset_memory(device)
        torch.manual_seed(a.seed)
        model = baseline.build_model().to(device)
        optimizer = baseline.make_optimizer(model, lr)
        model.train()
        per_epoch = (n + bs - 1) // bs
        epoch, batch, order = 0, 0, epoch_order(a.seed, 0, n)
        losses, items, stop = [], 0, None
        t = time.perf_counter()
        for s in range(a.train_steps):
            if time.perf_counter() > deadline:
                stop = f"training run cut at {s} of {a.train_steps} steps (--minutes)"
                break
            if batch == per_epoch:
                epoch, batch = epoch + 1, 0
                order = epoch_order(a.seed, epoch, n)
            idx = [int(i) for i in order[batch * bs:(batch + 1) * bs]]
            rng = np.random.default_rng(batch_seed(a.seed, epoch, batch))
            loss, _ = step(model, optimizer, idx, rng)
            value = float(loss)
            losses.append(value)
            items += len(idx)
            batch += 1
            if not math.isfinite(value):
                stop = f"loss {value} at step {s + 1} (epoch {epoch + 1}, batch {batch})"
                rec["finite"] = False
                break
            if (s + 1) % 10 == 0 or s + 1 == a.train_steps:
                window = losses[-10:]
                say(f"  {name}: step {s + 1}/{a.train_steps}, loss "
                    f"{sum(window) / len(window):.4g} (mean of the last {len(window)}), "
                    f"{items / (time.perf_counter() - t):.2f} items/s")
        _sync(device)
        seconds = time.perf_counter() - t
        if stop:
            rec["notes"].append(stop)
            say(f"  {name}: {stop}")
        k = min(10, len(losses))
        rec["training_run"] = {
            "steps": len(losses), "items": items, "seconds": seconds,
            "items_per_s": items / seconds if items else None, "epochs_seen": epoch + 1,
            "losses": losses,
            "curve": [[j + len(losses[j:j + 10]), sum(losses[j:j + 10]) / len(losses[j:j + 10])]
                      for j in range(0, len(losses), 10)],
            "first10": sum(losses[:k]) / k if k else None,
            "last10": sum(losses[-k:]) / k if k else None,
            "all_finite": all(math.isfinite(x) for x in losses)}
        rec["finite"] &= rec["training_run"]["all_finite"]
        rec["peak_memory_training_run"] = _peak(device)
        del model, optimizer
    peaks = [p for p in (rec.get("peak_memory_throughput"), rec.get("peak_memory_training_run"))
             if p is not None]
    rec["peak_memory"] = max(peaks) if peaks else None
    rec["wall_s"] = time.perf_counter() - start
    _reset_memory(device)
    return rec


def _fmt(x, digits=2):
    return "" if x is None else f"{x:,.{digits}f}"


def table_row(rec):
    name = rec["baseline"]
    if rec.get("error"):
        return (f"| {name} | {rec['input']} | | {rec.get('batch_size', '')} | FAILED: "
                f"{rec['error'].strip().splitlines()[-1][:120]} | | | | | | "
                f"{rec['wall_s']:.0f} s |")
    o = rec["options"]
    shape = (f"{o.get('size')} px" if name in PICTURE_BASELINES
             else f"{o.get('points'):,} points")
    tr, fw, run = rec.get("train") or {}, rec.get("forward") or {}, rec.get("training_run") or {}
    points = tr.get("points_per_s")
    loss = (f"{run['first10']:.4g} → {run['last10']:.4g}"
            if run.get("first10") is not None else "")
    if run and not run.get("all_finite", True):
        loss += " (NOT FINITE)"
    peak = rec.get("peak_memory")
    share = tr.get("load_share")
    return (f"| {name} | {rec['input']} | {shape} | {o['batch_size']} | "
            f"{_fmt(tr.get('items_per_s'))} | {_fmt(points, 0)} | "
            f"{_fmt(fw.get('items_per_s'))} | "
            f"{'' if share is None else f'{100 * share:.0f}%'} | "
            f"{loss} | {'' if peak is None else mib(peak)} | {rec['wall_s']:.0f} s |")


TABLE_HEAD = ("| baseline | input | size or points | batch | train items/s | train points/s | "
              "forward items/s | loading | loss first 10 → last 10 | peak memory | wall |\n"
              "|---|---|---|---:|---:|---:|---:|---:|---|---:|---:|")


def cmd_run(a):
    t_start = time.perf_counter()
    deadline = t_start + 60.0 * a.minutes
    stand_in_package()
    import torch
    import torchvision

    from partsim._device import resolve_device

    bundle_file = os.path.join(a.bundle, BUNDLE_FILE)
    with open(bundle_file, encoding="utf-8") as f:
        bundle = json.load(f)
    if bundle.get("format") != FORMAT:
        sys.exit(f"run: '{bundle_file}' is not a bundle of `pack` ({FORMAT})")
    device = resolve_device(a.device)
    if device == "cuda":
        props = torch.cuda.get_device_properties(0)
        machine = (f"{props.name}, {props.total_memory / 2**30:.0f} GiB, "
                   f"{props.multi_processor_count} SMs, {os.cpu_count()} CPU cores")
    else:
        machine = (f"CPU {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
                   f"{torch.get_num_threads()} torch threads")
    datasets = {}
    if bundle.get("detection"):
        datasets["detection"] = (BundleDetection(a.bundle, bundle["detection"]),
                                 bundle["detection"])
    if bundle.get("motion"):
        datasets["motion"] = (BundleMotion(a.bundle, bundle["motion"]), bundle["motion"])
    result = {
        "format": "partsim-perception-gpu-check-1", "device": device, "machine": machine,
        "gpu": torch.cuda.get_device_name(0) if device == "cuda" else None,
        "torch": torch.__version__, "torchvision": torchvision.__version__,
        "cuda": torch.version.cuda, "cudnn": (torch.backends.cudnn.version()
                                              if device == "cuda" else None),
        "python": platform.python_version(), "numpy": np.__version__,
        "bundle": {"path": os.path.abspath(a.bundle), "bytes": folder_bytes(a.bundle),
                   "created": bundle.get("created"),
                   "detection_items": len(datasets["detection"][0]) if "detection" in datasets
                   else 0,
                   "motion_items": len(datasets["motion"][0]) if "motion" in datasets else 0,
                   "pictures": {kind: list(ds[0]["depth"].shape) if len(ds) else None
                                for kind, (ds, _) in datasets.items()}},
        "settings": {k: getattr(a, k) for k in ("baselines", "size", "batch_size", "batches",
                                                "train_steps", "points", "backbone",
                                                "point_backbone", "lr", "seed", "minutes")},
        "baselines": [], "notes": []}
    pictures = ", ".join(f"{kind} {v[1]}x{v[0]}"
                         for kind, v in result["bundle"]["pictures"].items() if v)
    head = (f"device: {device} ({machine}); torch {torch.__version__}, torchvision "
            f"{torchvision.__version__}, CUDA {torch.version.cuda}, Python "
            f"{platform.python_version()}; bundle {result['bundle']['detection_items']} "
            f"detection + {result['bundle']['motion_items']} motion items ({pictures}); "
            f"batch {a.batch_size}, {a.batches} timed batches, {a.train_steps} training steps")
    say(head)
    say(TABLE_HEAD.splitlines()[0])  # each baseline's row follows its progress lines

    def save():
        result["total_s"] = time.perf_counter() - t_start
        result["compiled_module_imported"] = _compiled_imported()
        if a.out:
            with open(a.out, "w", encoding="utf-8") as f:
                json.dump(result, f, indent=1)

    from partsim.perception import baseline_class

    wanted = []
    for entry in a.baselines.split(","):
        name, _, inp = entry.strip().partition(":")
        try:
            cls = baseline_class(name)
        except ValueError as e:
            sys.exit(f"run: --baselines: {e}")
        wanted.append((name, cls, inp or cls.inputs[0]))
    rows = []
    for name, cls, inp in wanted:
        if cls.kind not in datasets:
            note = f"{name}: skipped, the bundle has no {cls.kind} items"
            result["notes"].append(note)
            say(note)
            continue
        if time.perf_counter() > deadline:
            note = f"{name} ({inp}): skipped, past --minutes {a.minutes:g}"
            result["notes"].append(note)
            say(note)
            continue
        say(f"{name} ({inp}):")
        dataset, doc = datasets[cls.kind]
        t = time.perf_counter()
        try:
            rec = bench_baseline(name, inp, dataset, doc, a, device, deadline)
        except Exception:  # the other baselines still run; the exit code says it failed
            error = traceback.format_exc()
            say(error)
            rec = {"baseline": name, "input": inp, "batch_size": a.batch_size, "error": error,
                   "notes": [f"failed: {error.strip().splitlines()[-1]}"], "finite": True,
                   "wall_s": time.perf_counter() - t}
            _reset_memory(device)
        result["baselines"].append(rec)
        rows.append(table_row(rec))
        say(rows[-1])
        save()
    finite = all(r["finite"] for r in result["baselines"])
    failed = [r["baseline"] for r in result["baselines"] if r.get("error")]
    result["all_finite"] = finite
    result["failed"] = failed
    compiled = _compiled_imported()
    lines = [head, "", TABLE_HEAD] + rows
    notes = result["notes"] + [f"{r['baseline']}: {n}" for r in result["baselines"]
                               for n in r["notes"]]
    if notes:
        lines += [""] + [f"- {n}" for n in notes]
    lines += ["", f"losses finite: {finite}; failed: {', '.join(failed) or 'none'}; "
                  f"partsim's compiled module imported: "
                  f"{', '.join(compiled) if compiled else 'no'}; "
                  f"{time.perf_counter() - t_start:.0f} s in all"]
    text = "\n".join(lines)
    say("")
    say(text)
    save()
    if a.md:
        with open(a.md, "w", encoding="utf-8") as f:
            f.write(text + "\n")
    if compiled:
        say(f"ERROR: {', '.join(compiled)} imported: the check must run without it")
        return 3
    if failed:
        return 2
    return 0 if finite else 1


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)
    k = sub.add_parser("pack", help="bundle dataset items for the GPU machine (build machine)")
    k.add_argument("--detection", help="folder of `partsim vision detection-dataset`")
    k.add_argument("--motion", help="folder of `partsim vision motion-dataset`")
    k.add_argument("--out", required=True, help="the bundle's folder (e.g. .gpu/perception)")
    k.add_argument("--train-items", type=int, default=32,
                   help="items of each train split to pack, the first ones (32)")
    k.add_argument("--size", type=int, default=256,
                   help="larger pictures are subsampled to this side (256; 0 keeps them)")
    r = sub.add_parser("run", help="the baselines on --device over a bundle (GPU machine)")
    r.add_argument("--bundle", required=True)
    r.add_argument("--device", default="auto")
    r.add_argument("--baselines", default=ALL_BASELINES,
                   help="comma-separated NAME or NAME:INPUT (default: each one's first input)")
    r.add_argument("--size", type=int, default=256,
                   help="picture side of maskrcnn and motion-resnet (256)")
    r.add_argument("--batch-size", type=int, default=8)
    r.add_argument("--batches", type=int, default=20, help="timed batches, training and forward")
    r.add_argument("--train-steps", type=int, default=200)
    r.add_argument("--points", type=int, default=10000,
                   help="points per view of insseg and motion-pointnet (10,000)")
    r.add_argument("--backbone", default="resnet50", help="maskrcnn's and motion-resnet's")
    r.add_argument("--point-backbone", default="ssg",
                   help="the PointNet++ preset of insseg and motion-pointnet (ssg or small)")
    r.add_argument("--instances", type=int, help="insseg's K (default: as a run would choose)")
    r.add_argument("--lr", type=float, help="default: each baseline's own")
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--minutes", type=float, default=8.0,
                   help="time budget: parts not started by then are skipped (8)")
    r.add_argument("--out", help="JSON results (written again after each baseline)")
    r.add_argument("--md", help="the Markdown table")
    a = p.parse_args()
    if a.command == "pack":
        return cmd_pack(a)
    if a.batch_size < 1 or a.batches < 0 or a.train_steps < 0:
        p.error("--batch-size must be positive, --batches and --train-steps not negative")
    return cmd_run(a)


if __name__ == "__main__":
    sys.exit(main())
