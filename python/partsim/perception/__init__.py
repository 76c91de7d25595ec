"""The SAPIEN paper's perception baselines, trained and scored on partsim's datasets.

- Movable-part detection (the paper's Table 1): ``maskrcnn`` (torchvision's Mask R-CNN on RGB
  or RGB-D) and ``insseg`` (PointNet++ instance segmentation of the lifted partial scan, XYZ or
  XYZRGB), predicting COCO results for ``partsim vision evaluate-detection``.
- Motion attributes (Table 2): ``motion-resnet`` (ResNet-50 on RGB, depth and the target's
  mask) and ``motion-pointnet`` (PointNet++ on the camera-frame RGB point cloud), with the
  paper's seven-term loss, predicting for ``partsim vision evaluate-motion``.

``partsim vision train NAME --data DIR --out RUN`` trains one (checkpoints, resume, CSV log,
curves), ``partsim vision predict RUN`` writes and scores its predictions, ``partsim vision
table RUN...`` prints the paper's tables beside the runs' (docs/vision.md). In Python:
:func:`baseline_class` and :mod:`partsim.perception.train`. Needs PyTorch (and torchvision
for ``maskrcnn`` and ``motion-resnet``).

The networks, their batches and losses need only PyTorch and NumPy: partsim's compiled module
(``partsim.vision``) is imported where the datasets are opened and predictions encoded and
scored, so a machine with another Python (a GPU node) can run them on dataset items packed
elsewhere (bench/perception_gpu_check.py).
"""

import importlib

# command-line name -> (module, class)
BASELINES = {
    "maskrcnn": ("partsim.perception.maskrcnn", "MaskRCNN"),
    "insseg": ("partsim.perception.insseg", "InsSeg"),
    "motion-resnet": ("partsim.perception.motion", "MotionResNet"),
    "motion-pointnet": ("partsim.perception.motion", "MotionPointNet"),
}


def baseline_class(name):
    """The Baseline subclass of the command-line name ``name`` (one of BASELINES). Raises
    ValueError naming the known ones."""
    if name not in BASELINES:
        raise ValueError("unknown baseline '%s' (known: %s)" % (name, ", ".join(BASELINES)))
    module, cls = BASELINES[name]
    return getattr(importlib.import_module(module), cls)
