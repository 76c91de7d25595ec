"""The contract every perception baseline of partsim.perception follows.

A baseline (Mask R-CNN, PointNet++ instance segmentation, the two motion-attribute networks)
is a subclass of :class:`Baseline`: it says which dataset it reads, builds its network, turns
dataset items into batches, computes its loss and writes predictions in the evaluator's format.
The training loop, checkpoints, resume, logs, curves and the command line
(``partsim vision train|predict|table``, :mod:`partsim.perception.train`) are shared and know
nothing of the model.
"""

import numpy as np


class Baseline:
    """One of the paper's perception baselines.

    Class attributes a subclass sets:

    - ``name``: the command-line name (``maskrcnn``, ``insseg``, ``motion-resnet``,
      ``motion-pointnet``);
    - ``kind``: ``"detection"`` (reads :class:`partsim.vision.DetectionDataset`, predictions in
      COCO's results format for ``partsim vision evaluate-detection``) or ``"motion"`` (reads
      :class:`partsim.vision.MotionDataset`, predictions ``{"sample_id", "m"}`` for
      ``evaluate-motion``);
    - ``inputs``: the accepted ``--input`` values, the first the default (``rgb``/``rgbd``,
      ``xyz``/``xyzrgb``);
    - ``defaults``: ``{"epochs", "batch_size", "lr", "size"}``, the command's defaults.

    ``__init__(train, options)``: ``train`` is the training split's dataset (categories,
    ``slider_range``); ``options`` a dict with at least ``input``, ``size`` (the square side
    pictures are resized to; ``None`` keeps them), ``seed`` and the baseline's own keys
    (``backbone``, ``points``, ...). Whatever decides the network's shapes goes in
    :meth:`config`, which the run records and checks when it resumes.
    """

    name = ""
    kind = ""
    inputs = ()
    defaults = {"epochs": 10, "batch_size": 4, "lr": 1e-3, "size": None}

    def __init__(self, train, options):
        self.options = dict(options)

    def config(self):
        """The JSON-serialisable options that decide the network (run.json's ``model``)."""
        return {}

    def build_model(self):
        """A new torch.nn.Module, on the CPU, initialised from the seed torch was given."""
        raise NotImplementedError

    def load_weights(self, model, path):
        """Loads the weights file ``path`` (``--init``) into a new ``model``: by default the
        tensors of its state dict whose names and shapes match (another run's ``model.pt`` or
        checkpoint). Returns ``(loaded, skipped)``, lists of the file's keys."""
        from .train import load_matching
        return load_matching(model, path)

    def make_optimizer(self, model, lr):
        """The optimiser over ``model``'s parameters (Adam unless the baseline says otherwise)."""
        import torch
        return torch.optim.Adam([p for p in model.parameters() if p.requires_grad], lr=lr)

    def load_batch(self, dataset, indices, rng, train):
        """Items ``indices`` of ``dataset`` as one batch of CPU tensors (any structure that
        :meth:`to_device` and :meth:`loss` understand). ``rng`` (numpy Generator) draws any
        random sampling or augmentation; ``train`` is False for prediction."""
        raise NotImplementedError

    def to_device(self, batch, device):
        """``batch`` moved to ``device`` (default: tensors, and lists/tuples/dicts of them)."""
        return _to_device(batch, device)

    def loss(self, model, batch):
        """``(total, terms)``: the scalar loss tensor to minimise and a dict of its named terms
        as floats (logged per step). ``model`` is in training mode."""
        raise NotImplementedError

    def predict(self, model, dataset, indices, device, rng):
        """Predictions for items ``indices`` of ``dataset`` (``model`` in evaluation mode, under
        ``torch.no_grad``), as a list of JSON-serialisable entries: detection, COCO results
        ``{"image_id", "category_id", "segmentation" (compressed RLE dict, the picture's full
        size), "score"}``; motion, ``{"sample_id", "m": [13 floats]}``."""
        raise NotImplementedError


def _to_device(x, device):
    if hasattr(x, "to") and not isinstance(x, np.ndarray):
        return x.to(device)
    if isinstance(x, dict):
        return {k: _to_device(v, device) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return type(x)(_to_device(v, device) for v in x)
    return x
