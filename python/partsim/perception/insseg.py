"""PartNet-InsSeg, the SAPIEN paper's movable-part detection baseline on partial point clouds
(Table 1, "PC (XYZ)" and "PC (XYZRGB)").

Each view of a detection dataset of `partsim vision detection-dataset` is lifted into its
partial point cloud (one point per pixel with depth, in the camera frame; the dataset's
cloud/NN.npz). As in PartNet's instance segmentation network (Mo et al. 2019), a PointNet++
segmentation backbone gives per-point features, from which the network proposes a fixed number
K of instance masks, each with a part class and a confidence:

- mask head: per point, K mask logits (a shared two-layer MLP; sigmoid gives each point's
  membership of each of the K masks, independently);
- instance features: for each of the K masks, the average of the per-point features weighted by
  the mask's sigmoid (the weights are detached, so the classification and confidence losses do
  not move the masks, only the features they pool);
- class head: from each instance feature, logits over the C part categories plus "no part"
  (class 0); score head: from each instance feature, the confidence logit.

K must be at least the most instances in a view: a view with more leaves the rest unmatched.

Training matches the K predictions to the view's ground-truth instances with the Hungarian
algorithm on a cost of (1 - dice) + (1 - the predicted probability of the instance's class);
the loss is the matched masks' dice loss and per-point binary cross-entropy, the classes'
cross-entropy (unmatched predictions are "no part"), and the confidence's binary cross-entropy
against the matched mask's IoU (0 for unmatched predictions).

Inputs: ``xyz`` (coordinates only) or ``xyzrgb`` (and each point's colour / 255 as three input
features). Coordinates are normalised per view: centred on the mean of all the view's points
and divided by their largest distance from it, so every view lies in the unit ball that
PointNet++'s radii assume.

Points: training samples ``points`` points per view (10,000, as the paper samples): a random
subset without replacement, or every point plus random copies when the view has fewer.
Prediction builds the network's abstraction levels from such a sample and carries the features
to every point of the view in the last propagation level, so every pixel with depth gets its own
mask value (full coverage; pixels without depth are never part of a mask). Each of the K masks
whose most probable class is a part and which holds at least one pixel becomes a COCO result
with score = confidence x class probability.
"""

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

from .base import Baseline
from .pointnet2 import SEGMENTER_PRESETS, PointNet2Segmenter

# the weight of the "no part" class in the classification loss (most of the K predictions are
# unmatched; DETR weighs its "no object" class so too)
NO_PART_WEIGHT = 0.2

# a point belongs to a predicted mask when its sigmoid exceeds this
MASK_THRESHOLD = 0.5


def normalise_cloud(xyz):
    """``xyz`` (n, 3) centred on its mean and scaled into the unit ball (largest distance from
    the centre 1): (n, 3) float32. An empty or single-point cloud is only centred."""
    xyz = np.asarray(xyz, dtype=np.float64)
    if len(xyz) == 0:
        return xyz.astype(np.float32)
    centred = xyz - xyz.mean(axis=0)
    scale = np.sqrt((centred ** 2).sum(axis=1).max())
    return (centred / scale if scale > 0 else centred).astype(np.float32)


def sample_points(n, count, rng):
    """Indices of ``count`` points among ``n`` drawn with ``rng``: a random subset when n >=
    count, else every point once plus count - n random copies, in random order."""
    if n == 0:
        raise ValueError("sample_points: the view has no points")
    if n >= count:
        return rng.choice(n, count, replace=False)
    return rng.permutation(np.concatenate([np.arange(n), rng.choice(n, count - n)]))


def cloud_pixels(dataset, index):
    """The pixels of the points of ``dataset.point_cloud(index)``: flat row-major indices into
    the view's (height, width) picture, those whose depth is positive (the cloud has one point
    per such pixel, in this order), and the picture's (height, width)."""
    depth = np.load(dataset.paths(index)["depth_path"])
    pixels = np.flatnonzero(depth > 0)
    return pixels, depth.shape


def points_to_picture(pixels, values, shape):
    """A (height, width) picture holding ``values`` (n,) at the flat row-major ``pixels`` (n,)
    of :func:`cloud_pixels`, 0 elsewhere, of ``values``' dtype (bool becomes uint8)."""
    values = np.asarray(values)
    if values.dtype == bool:
        values = values.astype(np.uint8)
    picture = np.zeros(int(shape[0]) * int(shape[1]), dtype=values.dtype)
    picture[pixels] = values
    return picture.reshape(shape)


def dice_matrix(pred, gt, smooth=1.0):
    """Soft dice (K, G) between soft masks ``pred`` (K, P) in [0, 1] and binary masks ``gt``
    (G, P) (torch tensors): 2 |p g| / (|p| + |g|), with ``smooth`` added above and below."""
    inter = pred @ gt.t()
    return (2.0 * inter + smooth) / (pred.sum(1, keepdim=True) + gt.sum(1).unsqueeze(0) + smooth)


def match_instances(mask_prob, class_prob, gt_masks, gt_classes):
    """The Hungarian matching of K predictions to G ground-truth instances: (predictions,
    instances), two int64 arrays of min(K, G) indices, pairing prediction predictions[i] with
    instance instances[i] (sorted by prediction). The cost of a pair is (1 - dice of the
    masks) + (1 - the prediction's probability of the instance's class).

    ``mask_prob`` (K, P) in [0, 1], ``class_prob`` (K, C + 1), ``gt_masks`` (G, P) 0/1,
    ``gt_classes`` (G,) int64 class indices (torch tensors)."""
    try:
        from scipy.optimize import linear_sum_assignment
    except ImportError as e:  # pragma: no cover - a Debian package (python3-scipy)
        raise ImportError("insseg: the Hungarian matching needs scipy (Debian: apt-get install "
                          "python3-scipy; pip: scipy)") from e
    cost = (1.0 - dice_matrix(mask_prob, gt_masks)) + (1.0 - class_prob[:, gt_classes])
    rows, cols = linear_sum_assignment(cost.detach().cpu().double().numpy())
    return rows.astype(np.int64), cols.astype(np.int64)


class InsSegNet(nn.Module):
    """The instance segmentation network: PointNet++ per-point features -> ``instances`` (K)
    mask logits per point, and per mask ``classes`` + 1 class logits and a confidence logit
    (see the module's docstring). ``in_features``: 0 (XYZ) or 3 (XYZRGB); ``backbone`` and
    ``width``: the PointNet2Segmenter's preset and channel multiplier."""

    def __init__(self, in_features, instances, classes, backbone="ssg", width=1.0):
        super().__init__()
        self.backbone = PointNet2Segmenter(in_features, preset=backbone, width=width)
        f = self.backbone.out_features
        self.mask_head = nn.Sequential(
            nn.Conv1d(f, f, 1, bias=False), nn.BatchNorm1d(f), nn.ReLU(True),
            nn.Conv1d(f, instances, 1))
        self.class_head = nn.Sequential(nn.Linear(f, f), nn.ReLU(True), nn.Linear(f, classes + 1))
        self.score_head = nn.Sequential(nn.Linear(f, f), nn.ReLU(True), nn.Linear(f, 1))

    def forward(self, xyz, features=None, query_xyz=None, query_features=None):
        """A cloud (B, N, 3) with features (B, N, in_features) or None -> {'mask_logits'
        (B, N, K), 'class_logits' (B, K, C + 1), 'score_logits' (B, K)}. With query points
        (B, Q, 3) (and their features), the masks are the query points' (B, Q, K) and the
        instance features are pooled over them (see PointNet2Segmenter.forward)."""
        f = self.backbone(xyz, features, query_xyz, query_features)
        logits = self.mask_head(f.transpose(1, 2)).transpose(1, 2)
        # per mask, the average of the point features weighted by the mask's sigmoid
        w = torch.sigmoid(logits).detach()
        pooled = (w.transpose(1, 2) @ f) / (w.sum(1).unsqueeze(-1) + 1e-6)
        return {"mask_logits": logits, "class_logits": self.class_head(pooled),
                "score_logits": self.score_head(pooled).squeeze(-1)}


class InsSeg(Baseline):
    """PartNet-InsSeg on the partial point cloud of each view (see the module's docstring).

    Options: ``input`` (``xyz`` or ``xyzrgb``), ``points`` (points sampled per view, default
    10,000), ``instances`` (K, the masks predicted per view; default the larger of 20 and the
    most instances in a training view), ``backbone`` (the PointNet++ preset of
    :data:`partsim.perception.pointnet2.SEGMENTER_PRESETS`: ``ssg``, the default, or
    ``small``) and ``width`` (the backbone's channel multiplier, default 1). The ``size``
    option does not apply (clouds keep the dataset's resolution).

    Category ids of the dataset map to the network's classes 1..C in the dataset's category
    order (0 is "no part"); :meth:`config` records the ids."""

    name = "insseg"
    kind = "detection"
    inputs = ("xyz", "xyzrgb")
    defaults = {"epochs": 40, "batch_size": 8, "lr": 1e-3, "size": None}

    default_points = 10000
    default_instances = 20

    def __init__(self, train, options):
        super().__init__(train, options)
        self.input = self.options.get("input") or self.inputs[0]
        if self.input not in self.inputs:
            raise ValueError("insseg: input must be one of %s, got %r"
                             % (", ".join(self.inputs), self.input))
        self.points = int(self.options.get("points") or self.default_points)
        # the category ids, in the dataset's order: id category_ids[k] is the network's class k+1
        self.category_ids = [int(c["id"]) for c in train.categories]
        # category id -> class index (0 for ids that are not the dataset's)
        self._class_of = np.zeros(max(self.category_ids, default=0) + 1, dtype=np.int64)
        self._class_of[self.category_ids] = np.arange(1, len(self.category_ids) + 1)
        per_image = {}
        for a in train.coco.get("annotations", []):
            per_image[a["image_id"]] = per_image.get(a["image_id"], 0) + 1
        most = max(per_image.values(), default=0)
        self.instances = int(self.options.get("instances")
                             or max(self.default_instances, most))
        self.backbone = self.options.get("backbone") or "ssg"
        if self.backbone not in SEGMENTER_PRESETS:
            raise ValueError("insseg: backbone must be a PointNet++ preset (%s), got %r"
                             % (", ".join(SEGMENTER_PRESETS), self.backbone))
        self.width = float(self.options.get("width") or 1.0)
        if self.points < 1 or self.instances < 1 or self.width <= 0:
            raise ValueError("insseg: points, instances and width must be positive, got %r, "
                             "%r and %r" % (self.points, self.instances, self.width))

    def config(self):
        return {"input": self.input, "points": self.points, "instances": self.instances,
                "backbone": self.backbone, "width": self.width,
                "category_ids": list(self.category_ids)}

    def build_model(self):
        return InsSegNet(3 if self.input == "xyzrgb" else 0, self.instances,
                         len(self.category_ids), self.backbone, self.width)

    # --- data ----------------------------------------------------------------------------------

    def view(self, dataset, index):
        """View ``index`` of ``dataset`` as the network reads it: {'xyz' (n, 3) float32
        normalised, 'features' (n, 3) float32 colour in [0, 1] or None, 'instance' (n,) int64
        (0: no part), 'classes' (max instance + 1,) int64, the class index of each instance
        number (0 where none)}."""
        cloud = dataset.point_cloud(index)
        instance = cloud["instance"].astype(np.int64)
        classes = np.zeros(int(instance.max(initial=0)) + 1, dtype=np.int64)
        # every point of an instance carries the instance's category id
        label = cloud["label"].astype(np.int64)
        known = (instance > 0) & (label > 0) & (label < len(self._class_of))
        classes[instance[known]] = self._class_of[label[known]]
        features = (cloud["rgb"].astype(np.float32) / 255.0 if self.input == "xyzrgb"
                    else None)
        return {"xyz": normalise_cloud(cloud["xyz"]), "features": features,
                "instance": instance, "classes": classes}

    def load_batch(self, dataset, indices, rng, train):
        """{'xyz' (B, P, 3), 'features' (B, P, 3) or None, 'instance' (B, P) int64 (the
        view's instance number per point, 0 none), 'classes' (B, G + 1) int64 (each instance
        number's class, 0 where none)} with P = ``points`` sampled per view."""
        views = [self.view(dataset, i) for i in indices]
        g = max(len(v["classes"]) for v in views)
        xyz, features, instance = [], [], []
        classes = np.zeros((len(views), g), dtype=np.int64)
        for b, v in enumerate(views):
            if len(v["xyz"]) == 0:  # a view that sees nothing: one point at the centre, no part
                v = dict(v, xyz=np.zeros((1, 3), np.float32), instance=np.zeros(1, np.int64),
                         features=None if v["features"] is None else np.zeros((1, 3), np.float32))
            pick = sample_points(len(v["xyz"]), self.points, rng)
            xyz.append(v["xyz"][pick])
            instance.append(v["instance"][pick])
            if v["features"] is not None:
                features.append(v["features"][pick])
            classes[b, :len(v["classes"])] = v["classes"]
        return {"xyz": torch.from_numpy(np.stack(xyz)),
                "features": torch.from_numpy(np.stack(features)) if features else None,
                "instance": torch.from_numpy(np.stack(instance)),
                "classes": torch.from_numpy(classes)}

    # --- training ------------------------------------------------------------------------------

    def loss(self, model, batch):
        """The matched masks' dice and binary cross-entropy, the classes' cross-entropy and the
        confidence's binary cross-entropy against the matched IoU (terms ``mask_dice``,
        ``mask_bce``, ``class``, ``score``; the total is their sum)."""
        out = model(batch["xyz"], batch["features"])
        logits, class_logits = out["mask_logits"], out["class_logits"]
        b, _, k = logits.shape
        class_targets = torch.zeros(b, k, dtype=torch.long, device=logits.device)
        iou_targets = torch.zeros(b, k, device=logits.device)
        dice_terms, bce_terms = [], []
        for i in range(b):
            inst, classes = batch["instance"][i], batch["classes"][i]
            # the instances present among the sampled points
            counts = torch.bincount(inst, minlength=len(classes))[:len(classes)]
            ids = torch.nonzero((classes > 0) & (counts > 0)).flatten()
            if len(ids) == 0:
                continue
            gt = (inst.unsqueeze(0) == ids.unsqueeze(1)).float()  # (G, P)
            prob = torch.sigmoid(logits[i].t())  # (K, P)
            # pair predictions with instances; with more instances than K, the rest go unmatched
            with torch.no_grad():
                rows, cols = match_instances(prob, torch.softmax(class_logits[i], -1), gt,
                                             classes[ids])
            rows = torch.from_numpy(rows).to(logits.device)
            cols = torch.from_numpy(cols).to(logits.device)
            # the matched masks against their instances
            p, t = prob[rows], gt[cols]
            dice_terms.append(1.0 - dice_matrix(p, t).diagonal())
            bce_terms.append(F.binary_cross_entropy_with_logits(
                logits[i].t()[rows], t, reduction="none").mean(1))
            # targets: the instance's class, and the IoU of the thresholded mask with it
            class_targets[i, rows] = classes[ids][cols]
            with torch.no_grad():
                hard = (p > MASK_THRESHOLD).float()
                inter = (hard * t).sum(1)
                iou_targets[i, rows] = inter / (hard.sum(1) + t.sum(1) - inter).clamp_min(1.0)
        # unmatched predictions are "no part" (class 0) with confidence 0
        weight = torch.ones(class_logits.shape[-1], device=logits.device)
        weight[0] = NO_PART_WEIGHT
        class_loss = F.cross_entropy(class_logits.reshape(b * k, -1), class_targets.flatten(),
                                     weight=weight)
        score_loss = F.binary_cross_entropy_with_logits(out["score_logits"], iou_targets)
        zero = logits.sum() * 0.0
        dice = torch.cat(dice_terms).mean() if dice_terms else zero
        bce = torch.cat(bce_terms).mean() if bce_terms else zero
        total = dice + bce + class_loss + score_loss
        return total, {"mask_dice": float(dice), "mask_bce": float(bce),
                       "class": float(class_loss), "score": float(score_loss)}

    # --- prediction ----------------------------------------------------------------------------

    def predict(self, model, dataset, indices, device, rng):
        """COCO results for views ``indices``: one per predicted mask whose most probable class
        is a part and that covers at least one pixel (see the module's docstring)."""
        from .. import vision  # the compiled module: imported when used

        results = []
        with torch.no_grad():
            for index in indices:
                v = self.view(dataset, index)
                n = len(v["xyz"])
                pixels, (h, w) = cloud_pixels(dataset, index)
                if len(pixels) != n:
                    raise ValueError(
                        "insseg: view %d of '%s' has %d points but %d pixels with depth"
                        % (index, dataset.root, n, len(pixels)))
                if n == 0:
                    continue
                # the abstraction levels from a sample, the masks at every point of the view
                pick = torch.from_numpy(sample_points(n, self.points, rng)).to(device)
                xyz = torch.from_numpy(v["xyz"]).unsqueeze(0).to(device)
                feats = (None if v["features"] is None
                         else torch.from_numpy(v["features"]).unsqueeze(0).to(device))
                out = model(xyz[:, pick], None if feats is None else feats[:, pick], xyz, feats)
                masks = (torch.sigmoid(out["mask_logits"][0]) > MASK_THRESHOLD).cpu().numpy()
                prob = torch.softmax(out["class_logits"][0], -1).cpu().numpy()
                confidence = torch.sigmoid(out["score_logits"][0]).cpu().numpy()
                # a result per mask of a part class that holds a pixel
                image_id = int(dataset.images[index]["id"])
                for k in range(masks.shape[1]):
                    c = int(prob[k].argmax())
                    if c == 0 or not masks[:, k].any():
                        continue
                    picture = points_to_picture(pixels, masks[:, k], (h, w))
                    results.append({
                        "image_id": image_id, "category_id": self.category_ids[c - 1],
                        "segmentation": vision.encode_mask(picture),
                        "score": float(confidence[k] * prob[k, c])})
        return results
