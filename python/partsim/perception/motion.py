"""The paper's two motion-attribute baselines (SAPIEN, appendix "Motion Recognition").

Both read a :class:`partsim.vision.MotionDataset` and regress the paper's 13-vector
m = (T_r, T_t, p^r (3), d^r (3), d^t (3), x_door, x_drawer) in the OpenCV camera frame
(docs/vision.md, "Motion attributes: files and metrics"):

- ``motion-resnet`` (:class:`MotionResNet`): a torchvision ResNet (ResNet-50 as in the paper)
  whose first convolution takes 5 channels, R, G, B, depth and the target part's mask, and whose
  last layer gives the 13 numbers;
- ``motion-pointnet`` (:class:`MotionPointNet`): PointNet++ on the partial point cloud lifted
  from the same depth picture, RGB and the target's mask as per-point features.

Both networks return the 13 *raw* outputs: T_r and T_t as logits, the pivot in metres, the
axes and states before their squashing. :func:`motion_outputs` turns them into the prediction
vector and :func:`motion_loss` is the paper's seven-term loss on them.
"""

import numpy as np
import torch
import torch.nn.functional as F

from .base import Baseline
from .insseg import sample_points
from .pointnet2 import ENCODER_PRESETS, PointNet2Encoder

# the slices of the 13-vector m
T_R, T_T = 0, 1
PIVOT = slice(2, 5)
AXIS_R = slice(5, 8)
AXIS_T = slice(8, 11)
X_DOOR, X_DRAWER = 11, 12

# below this a vector length counts as zero (cosines and axis normalisation)
_EPS = 1e-8


def axis_output(raw_axis):
    """An axis prediction from its three raw outputs (B, 3): tanh of the raw vector scaled to
    unit length, so each component is in [-1, 1] as the paper's tanh gives, and tanh never
    saturates. The loss on an axis is a cosine, blind to the raw vector's length; with tanh on
    the raw values that length drifts, and once every component is far from 0 tanh is flat and
    the axis stops learning (seen in training: the slider axis' raw outputs grew to 10-50, all
    of one sign, and its loss term stayed at 0.6 for 15 epochs)."""
    return torch.tanh(raw_axis / raw_axis.norm(dim=1, keepdim=True).clamp_min(_EPS))


def motion_outputs(raw):
    """The prediction vector m from the networks' raw outputs ``raw`` (B, 13) (a torch tensor):
    T_r and T_t as probabilities (sigmoid of the logits), the pivot as is (metres), the hinge
    and slider axes through :func:`axis_output` (each component in [-1, 1]) and sigmoid on
    x_door and x_drawer (in [0, 1]). The evaluator takes the larger of T_r and T_t as the
    predicted type."""
    return torch.cat([torch.sigmoid(raw[:, T_R:T_T + 1]),
                      raw[:, PIVOT],
                      axis_output(raw[:, AXIS_R]),
                      axis_output(raw[:, AXIS_T]),
                      torch.sigmoid(raw[:, X_DOOR:X_DRAWER + 1])], dim=1)


def motion_loss(raw, m):
    """The paper's loss L = L_dr + L_dt + L_p + L_Tr + L_Tt + L_door + L_drawer of the raw
    outputs ``raw`` (B, 13) against the labels ``m`` (B, 13).

    - L_dr, L_dt: 1 - |cos| between the axis output (:func:`axis_output`) and the true axis
      (sign-free cosine distance);
    - L_p: the squared distance (m^2) from the predicted pivot to the true hinge axis line;
    - L_Tr, L_Tt: binary cross-entropies of T_r and T_t, computed from the logits;
    - L_door, L_drawer: squared errors of sigmoid(raw) against x_door and x_drawer.

    Masked by type: L_dr, L_p and L_door are taken over the hinges of the batch (T_r = 1),
    L_dt and L_drawer over its sliders (T_t = 1), so the entries of the other type, zeros in the
    labels, never count; L_Tr and L_Tt over every sample. Each term is a *mean* over its samples
    (where the paper writes sums), so that the learning rate does not depend on the batch size
    or on its mix of types; a term with no sample of its type in the batch is 0.

    Returns ``(total, terms)``: the scalar tensor L and the seven terms as floats, keyed
    ``dr``, ``dt``, ``p``, ``Tr``, ``Tt``, ``door``, ``drawer``."""
    m = m.to(raw.dtype)
    hinge = m[:, T_R] > 0.5
    slider = m[:, T_T] > 0.5

    def mean_over(values, mask):
        # the mean over the samples of one type; 0 when the batch has none
        return values[mask].mean() if bool(mask.any()) else raw.new_zeros(())

    def axis_distance(pred, true):
        # 1 - |cos| between each row of pred and of true
        dot = (pred * true).sum(dim=1)
        norms = (pred.norm(dim=1) * true.norm(dim=1)).clamp_min(_EPS)
        return 1.0 - (dot / norms).abs()

    # the pivot's offset from the true axis line: v minus its component along the unit axis
    axis_r = m[:, AXIS_R] / m[:, AXIS_R].norm(dim=1, keepdim=True).clamp_min(_EPS)
    v = raw[:, PIVOT] - m[:, PIVOT]
    off_axis = v - (v * axis_r).sum(dim=1, keepdim=True) * axis_r

    terms = {
        "dr": mean_over(axis_distance(axis_output(raw[:, AXIS_R]), m[:, AXIS_R]), hinge),
        "dt": mean_over(axis_distance(axis_output(raw[:, AXIS_T]), m[:, AXIS_T]), slider),
        "p": mean_over((off_axis ** 2).sum(dim=1), hinge),
        "Tr": F.binary_cross_entropy_with_logits(raw[:, T_R], m[:, T_R]),
        "Tt": F.binary_cross_entropy_with_logits(raw[:, T_T], m[:, T_T]),
        "door": mean_over((torch.sigmoid(raw[:, X_DOOR]) - m[:, X_DOOR]) ** 2, hinge),
        "drawer": mean_over((torch.sigmoid(raw[:, X_DRAWER]) - m[:, X_DRAWER]) ** 2, slider),
    }
    total = sum(terms.values())
    return total, {k: float(v.detach()) for k, v in terms.items()}


class _MotionBaseline(Baseline):
    """What the two motion baselines share: the option checks, the loss, prediction."""

    kind = "motion"
    defaults = {"epochs": 30, "batch_size": 16, "lr": 1e-3, "size": None}

    def __init__(self, train, options):
        super().__init__(train, options)
        self.options.setdefault("input", self.inputs[0])
        if self.options["input"] not in self.inputs:
            raise ValueError("%s: input '%s' is not accepted (accepted: %s)" % (
                self.name, self.options["input"], ", ".join(self.inputs)))
        self.train = train

    def _forward(self, model, batch):
        """The raw outputs (B, 13) of ``model`` on ``batch``."""
        raise NotImplementedError

    def loss(self, model, batch):
        """The paper's seven-term loss (:func:`motion_loss`) of the batch."""
        return motion_loss(self._forward(model, batch), batch["m"])

    def predict(self, model, dataset, indices, device, rng):
        """``{"sample_id", "m"}`` for each item of ``indices``, m the 13 numbers of
        :func:`motion_outputs` (T_r and T_t as probabilities), in batches of the run's
        ``batch_size``."""
        indices = list(indices)
        step = int(self.options.get("batch_size") or self.defaults["batch_size"])
        entries = []
        with torch.no_grad():
            for start in range(0, len(indices), step):
                chunk = indices[start:start + step]
                batch = self.to_device(self.load_batch(dataset, chunk, rng, False), device)
                m = motion_outputs(self._forward(model, batch)).cpu().double().numpy()
                for i, row in zip(chunk, m):
                    entries.append({"sample_id": dataset.samples[i]["sample_id"],
                                    "m": [float(x) for x in row]})
        return entries


def _hinge_pivot_stats(dataset):
    """Mean and standard deviation (3,) of the training hinges' pivots (metres), read from the
    labels; (0, 1) when the split has no hinge."""
    pivots = np.array([s["m"][PIVOT] for s in dataset.samples if s["m"][T_R] > 0.5])
    if len(pivots) == 0:
        return np.zeros(3), np.ones(3)
    # at least 5 cm, so that a split of one hinge (or of pivots in a plane) still scales
    return pivots.mean(axis=0), np.maximum(pivots.std(axis=0), 0.05)


# --------------------------------------------------------------------------------------------
# ResNet on the 5-channel picture


def _motion_picture(item, size):
    """A MotionDataset item as the 5-channel picture (5, S, S) float32: R, G, B in [0, 1],
    depth in metres (0 where nothing was hit), the target's mask (0 or 1). With ``size`` the
    picture is resized to size x size: bilinear (antialiased when shrinking) for RGB and depth,
    nearest for the mask, so the mask stays binary."""
    rgb = torch.from_numpy(item["rgb"]).permute(2, 0, 1).float().div_(255.0)
    depth = torch.from_numpy(np.ascontiguousarray(item["depth"], dtype=np.float32))[None]
    mask = torch.from_numpy(item["mask"].astype(np.float32))[None]
    x = torch.cat([rgb, depth, mask])
    if size is not None and tuple(x.shape[1:]) != (size, size):
        shrink = size < max(x.shape[1:])
        smooth = F.interpolate(x[None, :4], size=(size, size), mode="bilinear",
                               align_corners=False, antialias=shrink)[0]
        mask = F.interpolate(x[None, 4:], size=(size, size), mode="nearest")[0]
        x = torch.cat([smooth, mask])
    return x


class _MotionResNetModule(torch.nn.Module):
    """A torchvision ResNet ``net`` on the 5-channel picture, 13 raw outputs. The input is
    standardised per channel (buffers ``input_mean``, ``input_std``) and the pivot outputs are
    scaled around the training hinges' pivots (``pivot_mean + pivot_std * output``); buffers,
    so that a checkpoint carries them."""

    def __init__(self, net):
        super().__init__()
        self.net = net
        self.register_buffer("input_mean", torch.zeros(5))
        self.register_buffer("input_std", torch.ones(5))
        self.register_buffer("pivot_mean", torch.zeros(3))
        self.register_buffer("pivot_std", torch.ones(3))

    def forward(self, x):
        x = (x - self.input_mean[:, None, None]) / self.input_std[:, None, None]
        raw = self.net(x)
        pivot = self.pivot_mean + self.pivot_std * raw[:, PIVOT]
        return torch.cat([raw[:, :PIVOT.start], pivot, raw[:, PIVOT.stop:]], dim=1)


class MotionResNet(_MotionBaseline):
    """The paper's ResNet baseline: R, G, B, depth and the target part's mask in, m out.

    Options: ``backbone`` (``resnet50``, the paper's, by default; ``resnet18``, ``resnet34``,
    ``resnet101`` also work), ``size`` (``None`` keeps the dataset's pictures; otherwise they
    are resized to size x size, bilinear for RGB and depth and nearest for the mask; the
    labels, in the camera frame, are unchanged by this; at 32 pixels or fewer the last stage
    is 1 x 1, where batch norm cannot train on a batch of one sample). Untrained weights
    (``weights=None``); the first convolution takes 5 channels and the last layer gives 13
    numbers.

    Inputs are standardised per channel with the mean and standard deviation of the training
    split (R, G, B, depth with its zeros where nothing was hit, mask), measured on up to 32 of
    its pictures when the network is built and kept in the network's buffers. The pivot
    outputs are the training hinges' mean pivot plus their standard deviation times the
    network's output, so the last layer works on numbers of order 1 although pivots lie metres
    away. No augmentation."""

    name = "motion-resnet"
    inputs = ("rgbd",)
    BACKBONES = ("resnet18", "resnet34", "resnet50", "resnet101")

    def __init__(self, train, options):
        super().__init__(train, options)
        self.options.setdefault("backbone", "resnet50")
        if self.options["backbone"] not in self.BACKBONES:
            raise ValueError("motion-resnet: backbone '%s' is not one of %s" % (
                self.options["backbone"], ", ".join(self.BACKBONES)))

    def config(self):
        """The backbone, the input and the picture size."""
        return {"backbone": self.options["backbone"], "input": self.options["input"],
                "size": self.options.get("size")}

    def build_model(self):
        """The ResNet with 5 input channels and 13 outputs, its normalisation buffers set from
        the training split."""
        import torchvision
        net = getattr(torchvision.models, self.options["backbone"])(weights=None)
        net.conv1 = torch.nn.Conv2d(5, 64, kernel_size=7, stride=2, padding=3, bias=False)
        net.fc = torch.nn.Linear(net.fc.in_features, 13)
        model = _MotionResNetModule(net)
        mean, std = self._input_stats()
        pivot_mean, pivot_std = _hinge_pivot_stats(self.train)
        model.input_mean.copy_(mean)
        model.input_std.copy_(std)
        model.pivot_mean.copy_(torch.as_tensor(pivot_mean))
        model.pivot_std.copy_(torch.as_tensor(pivot_std))
        return model

    def _input_stats(self, count=32):
        """Per-channel mean and standard deviation (5,) over up to ``count`` evenly spaced
        pictures of the training split (at the run's size)."""
        n = len(self.train)
        if n == 0:
            return torch.zeros(5), torch.ones(5)
        picks = np.unique(np.linspace(0, n - 1, min(n, count)).round().astype(int))
        x = torch.stack([_motion_picture(self.train[int(i)], self.options.get("size"))
                         for i in picks])
        return x.mean(dim=(0, 2, 3)), x.std(dim=(0, 2, 3)).clamp_min(1e-3)

    def load_batch(self, dataset, indices, rng, train):
        """``{"x": (B, 5, S, S), "m": (B, 13)}`` float32 (``rng`` unused: no augmentation)."""
        items = [dataset[int(i)] for i in indices]
        x = torch.stack([_motion_picture(it, self.options.get("size")) for it in items])
        m = torch.as_tensor(np.stack([it["m"] for it in items]), dtype=torch.float32)
        return {"x": x, "m": m}

    def _forward(self, model, batch):
        return model(batch["x"])


# --------------------------------------------------------------------------------------------
# PointNet++ on the camera-frame point cloud


def lift_depth(depth, K):
    """The pixels of ``depth`` (h, w) metres that see a surface (depth > 0), lifted into the
    OpenCV camera frame with the intrinsics ``K`` (3, 3): x = (u - cx) z / fx, y = (v - cy) z /
    fy, z = depth, u the column and v the row of the pixel's centre. Returns the points (n, 3)
    float32, metres, and their flat row-major pixel indices (n,), in row-major order."""
    depth = np.asarray(depth, dtype=np.float64)
    pixels = np.flatnonzero(depth > 0)
    v, u = np.divmod(pixels, depth.shape[1])
    z = depth.reshape(-1)[pixels]
    x = (u - K[0, 2]) * z / K[0, 0]
    y = (v - K[1, 2]) * z / K[1, 1]
    return np.stack([x, y, z], axis=1).astype(np.float32), pixels


class _MotionPointNetModule(torch.nn.Module):
    """PointNet++ on a camera-frame cloud, 13 raw outputs with the pivot in the camera frame.

    The cloud (B, N, 3), metres, is normalised per view into the unit ball that PointNet++'s
    radii assume (centred on the mean of its points, divided by their largest distance from
    it). The encoder's global feature goes through an MLP to 13 numbers: two hidden layers
    with layer norm and ReLU (layer norm rather than batch norm, so that a batch of one sample
    trains). The pivot, which the network predicts in the normalised frame, is mapped back:
    centre + scale * output."""

    def __init__(self, in_features, preset, width):
        super().__init__()
        self.encoder = PointNet2Encoder(in_features, preset=preset, width=width)
        layers, c = [], self.encoder.out_features
        for out in (max(16, int(round(512 * width))), max(16, int(round(256 * width)))):
            layers += [torch.nn.Linear(c, out, bias=False), torch.nn.LayerNorm(out),
                       torch.nn.ReLU(True)]
            c = out
        layers.append(torch.nn.Linear(c, 13))
        self.head = torch.nn.Sequential(*layers)

    def forward(self, xyz, features):
        # each view into the unit ball: centre (B, 1, 3), scale (B, 1, 1) metres
        centre = xyz.mean(dim=1, keepdim=True)
        scale = (xyz - centre).norm(dim=2).amax(dim=1).clamp_min(_EPS)[:, None, None]
        raw = self.head(self.encoder((xyz - centre) / scale, features))
        # the pivot back into the camera frame
        pivot = centre[:, 0] + scale[:, 0] * raw[:, PIVOT]
        return torch.cat([raw[:, :PIVOT.start], pivot, raw[:, PIVOT.stop:]], dim=1)


class MotionPointNet(_MotionBaseline):
    """The paper's PointNet++ baseline: the partial RGB point cloud of the view in, m out.

    Each picture's pixels with depth are lifted into the OpenCV camera frame with the sample's
    ``K`` (:func:`lift_depth`); every point carries its colour / 255 and the target part's mask
    (0 or 1) as four input features. The paper replaces the 5-channel picture by the RGB point
    cloud and does not mention the mask, but without it the network cannot know which of the
    object's parts it is asked about, so it comes along as in the picture. ``points`` points are
    sampled per view (10,000 by default, as in the paper): a random subset, or every point plus
    random copies when the view has fewer. The cloud is normalised per view inside the network
    and the pivot mapped back to the camera frame (:class:`_MotionPointNetModule`), so the
    labels and the loss stay in metres in the camera frame.

    Options: ``points``, ``backbone`` (the PointNet2Encoder preset: ``ssg``, PointNet++'s SSG
    classification network, by default; ``small`` for quick runs), ``width`` (the channel
    multiplier of the encoder and of the head, default 1). ``size`` is not used: the cloud has
    one point per pixel of the dataset's pictures. No augmentation besides the random sample
    of points."""

    name = "motion-pointnet"
    inputs = ("xyzrgb",)
    default_points = 10000

    def __init__(self, train, options):
        super().__init__(train, options)
        self.points = int(self.options.get("points") or self.default_points)
        self.backbone = self.options.get("backbone") or "ssg"
        self.width = float(self.options.get("width") or 1.0)
        if self.backbone not in ENCODER_PRESETS:
            raise ValueError("motion-pointnet: backbone must be a PointNet++ preset (%s), got %r"
                             % (", ".join(ENCODER_PRESETS), self.backbone))
        if self.points < 1 or self.width <= 0:
            raise ValueError("motion-pointnet: points and width must be positive, got %r and %r"
                             % (self.points, self.width))

    def config(self):
        """The input, the points per view, the preset and the width."""
        return {"input": self.options["input"], "points": self.points,
                "backbone": self.backbone, "width": self.width}

    def build_model(self):
        """PointNet2Encoder with 4 input features (R, G, B, mask), then an MLP to 13 numbers."""
        return _MotionPointNetModule(4, self.backbone, self.width)

    def load_batch(self, dataset, indices, rng, train):
        """``{"xyz": (B, P, 3) camera frame, metres, "features": (B, P, 4) colour / 255 and
        mask, "m": (B, 13)}`` float32, P = ``points`` drawn with ``rng``."""
        xyz, features, m = [], [], []
        for i in indices:
            item = dataset[int(i)]
            points, pixels = lift_depth(item["depth"], item["K"])
            if len(points) == 0:
                raise ValueError("motion-pointnet: sample '%s' has no pixel with depth"
                                 % item["sample_id"])
            colour = item["rgb"].reshape(-1, 3)[pixels].astype(np.float32) / 255.0
            mask = item["mask"].reshape(-1)[pixels].astype(np.float32)[:, None]
            pick = sample_points(len(points), self.points, rng)
            xyz.append(points[pick])
            features.append(np.concatenate([colour, mask], axis=1)[pick])
            m.append(item["m"])
        return {"xyz": torch.from_numpy(np.stack(xyz)),
                "features": torch.from_numpy(np.stack(features)),
                "m": torch.as_tensor(np.stack(m), dtype=torch.float32)}

    def _forward(self, model, batch):
        return model(batch["xyz"], batch["features"])
