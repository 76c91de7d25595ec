"""PointNet++ (Qi et al. 2017) in plain PyTorch: the point-cloud backbone of the ``insseg`` and
``motion-pointnet`` baselines.

No compiled operators: farthest point sampling, ball query and three-nearest-neighbour
interpolation are written with tensor operations, batched over (B, N, ...) clouds, so the
same code runs on the CPU and on a GPU. Points are (B, N, 3) float tensors; per-point features
are (B, N, C) (channels last, like the points) or ``None``.

- :func:`farthest_point_sample`, :func:`ball_query`, :func:`gather_points`: the sampling and
  grouping operators.
- :class:`SetAbstraction` (single-scale grouping, or global with ``npoint=None``) and
  :class:`FeaturePropagation` (inverse squared distance interpolation from the 3 nearest
  points, plus skip features): the layers.
- :class:`PointNet2Encoder`: a cloud to one global feature (B, F), PointNet++'s SSG
  classification network by default.
- :class:`PointNet2Segmenter`: a cloud to per-point features (B, N, F), PointNet++'s SSG
  segmentation network by default (its four-level ScanNet configuration).

The radii of the presets are those of PointNet++, chosen for clouds normalised into the unit
ball (centred, largest distance from the centre 1): callers normalise their points so.
"""

import torch
import torch.nn as nn

# A set abstraction level is (npoint, radius, nsample, mlp): npoint centres drawn by farthest
# point sampling, each grouping up to nsample points within radius, passed through a shared MLP
# of the given output channels and max-pooled. npoint=None is the global level (one centre at
# the origin grouping every point). A propagation level is the output channels of its MLP.
SEGMENTER_PRESETS = {
    # PointNet++ SSG semantic segmentation (four levels, 1024 to 16 centres)
    "ssg": {
        "sa": ((1024, 0.1, 32, (32, 32, 64)), (256, 0.2, 32, (64, 64, 128)),
               (64, 0.4, 32, (128, 128, 256)), (16, 0.8, 32, (256, 256, 512))),
        "fp": ((256, 256), (256, 256), (256, 128), (128, 128, 128)),
    },
    # a small network for tests and quick runs on a CPU (a few hundred to a few thousand points)
    "small": {
        "sa": ((128, 0.2, 16, (32, 32, 64)), (32, 0.4, 16, (64, 64, 128)),
               (8, 0.8, 16, (128, 128, 256))),
        "fp": ((128, 128), (128, 64), (64, 64, 64)),
    },
}
ENCODER_PRESETS = {
    # PointNet++ SSG classification (512 and 128 centres, then the global level): 1024 features
    "ssg": {"sa": ((512, 0.2, 32, (64, 64, 128)), (128, 0.4, 64, (128, 128, 256)),
                   (None, None, None, (256, 512, 1024)))},
    "small": {"sa": ((128, 0.2, 16, (32, 32, 64)), (32, 0.4, 16, (64, 64, 128)),
                     (None, None, None, (128, 256)))},
}

# queries x points of one block of the distance matrices below (bounds their memory)
_BLOCK_ELEMENTS = 1 << 24


def square_distance(a, b):
    """Squared Euclidean distances (B, M, N) between points a (B, M, 3) and b (B, N, 3)."""
    # |a|^2 + |b|^2 - 2 a.b, clamped at 0 where rounding makes it slightly negative
    d = (a * a).sum(-1, keepdim=True) + (b * b).sum(-1).unsqueeze(1) - 2.0 * a @ b.transpose(1, 2)
    return d.clamp_min_(0.0)


def gather_points(values, idx):
    """``values`` (B, N, C) picked at indices ``idx`` (B, ...) into the points: (B, ..., C)."""
    b, _, c = values.shape
    flat = idx.reshape(b, -1)
    out = torch.gather(values, 1, flat.unsqueeze(-1).expand(-1, -1, c))
    return out.reshape(*idx.shape, c)


@torch.no_grad()
def farthest_point_sample(xyz, m, start=None):
    """Indices (B, m) int64 of ``m`` points of ``xyz`` (B, N, 3) chosen by farthest point
    sampling: the first is ``start`` ((B,) indices; default point 0 of every cloud, so the
    result is deterministic), each next one the point farthest from those chosen so far (ties:
    the lowest index). Once every distinct point is chosen (m > N, or copies in the cloud), the
    rest of the indices are 0."""
    b, n, _ = xyz.shape
    batch = torch.arange(b, device=xyz.device)
    idx = torch.zeros(b, m, dtype=torch.long, device=xyz.device)
    # squared distance of every point to the nearest chosen point
    nearest = torch.full((b, n), float("inf"), dtype=xyz.dtype, device=xyz.device)
    far = (torch.zeros(b, dtype=torch.long, device=xyz.device) if start is None
           else torch.as_tensor(start, dtype=torch.long, device=xyz.device).expand(b).clone())
    for i in range(m):
        idx[:, i] = far
        centre = xyz[batch, far].unsqueeze(1)
        nearest = torch.minimum(nearest, ((xyz - centre) ** 2).sum(-1))
        far = nearest.argmax(-1)
    return idx


@torch.no_grad()
def ball_query(radius, k, xyz, centers):
    """Indices (B, M, k) int64 into ``xyz`` (B, N, 3) of up to ``k`` points within ``radius``
    of each of ``centers`` (B, M, 3), as PointNet++'s CUDA operator gives them: the first k
    such points in index order, the remaining slots padded with the first one found. A centre
    with no point within the radius gets its nearest point in every slot."""
    b, n, _ = xyz.shape
    m = centers.shape[1]
    order = torch.arange(n, device=xyz.device)
    out = []
    block = max(1, _BLOCK_ELEMENTS // max(1, b * n))
    for s in range(0, m, block):
        d2 = square_distance(centers[:, s:s + block], xyz)
        # the indices of the points within the radius, n elsewhere; the k smallest are the
        # first k points found in index order
        idx = torch.where(d2 <= radius * radius, order, n)
        idx = idx.topk(min(k, n), dim=-1, largest=False, sorted=True).values
        first = idx[..., :1]
        first = torch.where(first == n, d2.argmin(-1, keepdim=True), first)
        idx = torch.where(idx == n, first, idx)
        if k > n:
            idx = torch.cat([idx, first.expand(-1, -1, k - n)], dim=-1)
        out.append(idx)
    return torch.cat(out, dim=1)


def three_interpolate(xyz, known_xyz, known_features):
    """The features ``known_features`` (B, S, C) of points ``known_xyz`` (B, S, 3) carried to
    the points ``xyz`` (B, Q, 3): (B, Q, C), PointNet++'s interpolation, the average of the 3
    nearest known points weighted by their inverse squared distance (fewer when S < 3; S = 1
    copies the single feature). A point that coincides with a known point takes its feature."""
    b, q, _ = xyz.shape
    s = known_xyz.shape[1]
    if s == 1:
        return known_features.expand(b, q, known_features.shape[-1])
    k = min(3, s)
    out = []
    block = max(1, _BLOCK_ELEMENTS // max(1, b * s))
    for start in range(0, q, block):
        d2, idx = square_distance(xyz[:, start:start + block], known_xyz).topk(
            k, dim=-1, largest=False, sorted=True)
        weight = 1.0 / (d2 + 1e-8)
        weight = weight / weight.sum(-1, keepdim=True)
        out.append((gather_points(known_features, idx) * weight.unsqueeze(-1)).sum(-2))
    return torch.cat(out, dim=1)


def _scaled(channels, width):
    """MLP channels multiplied by ``width`` (at least 8 each)."""
    return tuple(max(8, int(round(c * width))) for c in channels)


class SetAbstraction(nn.Module):
    """A set abstraction level with single-scale grouping: ``npoint`` centres by farthest point
    sampling, each grouping up to ``nsample`` points within ``radius`` (ball query), their
    coordinates relative to the centre concatenated with their ``in_channels`` features, a
    shared MLP (1x1 convolutions, batch norm, ReLU) of output channels ``mlp`` and a max over
    the group. ``npoint=None`` is the global level: one centre at the origin grouping all the
    points (radius and nsample unused)."""

    def __init__(self, npoint, radius, nsample, in_channels, mlp):
        super().__init__()
        self.npoint, self.radius, self.nsample = npoint, radius, nsample
        layers, c = [], in_channels + 3
        for out in mlp:
            layers += [nn.Conv2d(c, out, 1, bias=False), nn.BatchNorm2d(out), nn.ReLU(True)]
            c = out
        self.mlp = nn.Sequential(*layers)
        self.out_channels = c

    def forward(self, xyz, features=None):
        """``xyz`` (B, N, 3), ``features`` (B, N, in_channels) or None -> the centres
        (B, npoint, 3) (global: (B, 1, 3) zeros) and their features (B, npoint, mlp[-1])."""
        if self.npoint is None:
            centres = xyz.new_zeros(xyz.shape[0], 1, 3)
            grouped = xyz.unsqueeze(1)  # relative to the origin
            if features is not None:
                grouped = torch.cat([grouped, features.unsqueeze(1)], dim=-1)
        else:
            centres = gather_points(xyz, farthest_point_sample(xyz, self.npoint))
            idx = ball_query(self.radius, self.nsample, xyz, centres)
            grouped = gather_points(xyz, idx) - centres.unsqueeze(2)
            if features is not None:
                grouped = torch.cat([grouped, gather_points(features, idx)], dim=-1)
        # (B, centres, group, 3 + C) -> (B, 3 + C, centres, group) -> MLP -> max over the group
        x = self.mlp(grouped.permute(0, 3, 1, 2))
        return centres, x.max(dim=-1).values.transpose(1, 2)


class FeaturePropagation(nn.Module):
    """A feature propagation level: the features of a coarser level interpolated to the points
    of a finer one (:func:`three_interpolate`), concatenated with the finer points' own (skip)
    features and passed through a shared MLP (1x1 convolutions, batch norm, ReLU) of output
    channels ``mlp``. ``in_channels`` is the coarse channels plus the skip channels."""

    def __init__(self, in_channels, mlp):
        super().__init__()
        layers, c = [], in_channels
        for out in mlp:
            layers += [nn.Conv1d(c, out, 1, bias=False), nn.BatchNorm1d(out), nn.ReLU(True)]
            c = out
        self.mlp = nn.Sequential(*layers)
        self.out_channels = c

    def forward(self, xyz, known_xyz, skip, known_features):
        """Points ``xyz`` (B, Q, 3) with skip features (B, Q, C1) or None, from ``known_xyz``
        (B, S, 3) with ``known_features`` (B, S, C2) -> (B, Q, mlp[-1])."""
        x = three_interpolate(xyz, known_xyz, known_features)
        if skip is not None:
            x = torch.cat([x, skip], dim=-1)
        return self.mlp(x.transpose(1, 2)).transpose(1, 2)


def _abstraction_levels(sa, in_features, width):
    levels, c = nn.ModuleList(), in_features
    for npoint, radius, nsample, mlp in sa:
        level = SetAbstraction(npoint, radius, nsample, c, _scaled(mlp, width))
        levels.append(level)
        c = level.out_channels
    return levels


def _level_features(xyz, features):
    """The features a level-0 point carries: its coordinates, then its input features."""
    return xyz if features is None else torch.cat([xyz, features], dim=-1)


class PointNet2Encoder(nn.Module):
    """PointNet++ as a global encoder: a cloud (B, N, 3) with ``in_features`` channels per point
    (0: coordinates only) to one feature vector (B, out_features).

    ``preset`` names the levels of :data:`ENCODER_PRESETS` (``"ssg"``: PointNet++'s SSG
    classification network, 1024 features; ``"small"``), ``width`` multiplies every MLP's
    channels, and ``sa`` (a sequence of (npoint, radius, nsample, mlp)) replaces the preset's
    levels. The last level is max-pooled over its centres (one centre for a global level).
    Radii suit clouds normalised into the unit ball."""

    def __init__(self, in_features=0, preset="ssg", width=1.0, sa=None):
        super().__init__()
        if sa is None:
            if preset not in ENCODER_PRESETS:
                raise ValueError("PointNet2Encoder: preset must be one of %s, got %r"
                                 % (", ".join(ENCODER_PRESETS), preset))
            sa = ENCODER_PRESETS[preset]["sa"]
        self.in_features = int(in_features)
        self.levels = _abstraction_levels(sa, self.in_features, width)
        self.out_features = self.levels[-1].out_channels

    def forward(self, xyz, features=None):
        """``xyz`` (B, N, 3), ``features`` (B, N, in_features) or None -> (B, out_features)."""
        _check_inputs("PointNet2Encoder", xyz, features, self.in_features)
        for level in self.levels:
            xyz, features = level(xyz, features)
        return features.max(dim=1).values


class PointNet2Segmenter(nn.Module):
    """PointNet++ as a per-point feature network: a cloud (B, N, 3) with ``in_features``
    channels per point (0: coordinates only) to features (B, N, out_features).

    Set abstraction levels go down to a few centres, then feature propagation levels come back
    up, each with the skip features of its level; at the input level the skip features are the
    points' coordinates and input features. ``preset`` names the levels of
    :data:`SEGMENTER_PRESETS` (``"ssg"``: PointNet++'s SSG segmentation network, 128 features;
    ``"small"``: 64), ``width`` multiplies every MLP's channels, and ``sa`` and ``fp`` (as many
    propagation MLPs as abstraction levels, coarsest first) replace the preset's levels. Radii
    suit clouds normalised into the unit ball."""

    def __init__(self, in_features=0, preset="ssg", width=1.0, sa=None, fp=None):
        super().__init__()
        if sa is None or fp is None:
            if preset not in SEGMENTER_PRESETS:
                raise ValueError("PointNet2Segmenter: preset must be one of %s, got %r"
                                 % (", ".join(SEGMENTER_PRESETS), preset))
            sa = SEGMENTER_PRESETS[preset]["sa"] if sa is None else sa
            fp = SEGMENTER_PRESETS[preset]["fp"] if fp is None else fp
        if len(fp) != len(sa):
            raise ValueError("PointNet2Segmenter: %d propagation levels for %d abstraction "
                             "levels (they must be as many)" % (len(fp), len(sa)))
        self.in_features = int(in_features)
        self.down = _abstraction_levels(sa, self.in_features, width)
        # channels of each level's points, the input level's being coordinates + features
        channels = [3 + self.in_features] + [level.out_channels for level in self.down]
        self.up = nn.ModuleList()
        c = channels[-1]
        for j, mlp in enumerate(fp):
            level = FeaturePropagation(c + channels[-2 - j], _scaled(mlp, width))
            self.up.append(level)
            c = level.out_channels
        self.out_features = c

    def forward(self, xyz, features=None, query_xyz=None, query_features=None):
        """``xyz`` (B, N, 3), ``features`` (B, N, in_features) or None -> per-point features
        (B, N, out_features).

        With ``query_xyz`` (B, Q, 3) (and ``query_features`` (B, Q, in_features) when the
        network has input features), the abstraction levels are built from the given cloud and
        the last propagation level carries their features to the query points instead:
        (B, Q, out_features). That level works point by point (in evaluation mode), so a query
        point that is also a cloud point gets exactly the features it gets in the cloud; this
        predicts for every point of a dense scan from a sample of it."""
        _check_inputs("PointNet2Segmenter", xyz, features, self.in_features)
        if query_xyz is None:
            query_xyz, query_features = xyz, features
        else:
            _check_inputs("PointNet2Segmenter (query)", query_xyz, query_features,
                          self.in_features)
        xyzs, feats = [xyz], [_level_features(xyz, features)]
        for level in self.down:
            xyz, features = level(xyz, features)
            xyzs.append(xyz)
            feats.append(features)
        x = feats[-1]
        for j, level in enumerate(self.up):
            fine = len(self.down) - 1 - j
            if fine == 0:
                x = level(query_xyz, xyzs[1], _level_features(query_xyz, query_features), x)
            else:
                x = level(xyzs[fine], xyzs[fine + 1], feats[fine], x)
        return x


def _check_inputs(who, xyz, features, in_features):
    if xyz.dim() != 3 or xyz.shape[-1] != 3:
        raise ValueError("%s: xyz must be (B, N, 3), got %s" % (who, tuple(xyz.shape)))
    got = 0 if features is None else features.shape[-1]
    if got != in_features:
        raise ValueError("%s: the network takes %d feature channels per point, got %d"
                         % (who, in_features, got))
    if features is not None and tuple(features.shape[:2]) != tuple(xyz.shape[:2]):
        raise ValueError("%s: features %s do not match xyz %s"
                         % (who, tuple(features.shape), tuple(xyz.shape)))
