"""Mask R-CNN, the SAPIEN paper's movable-part detection baseline on RGB and RGB-D pictures
(Table 1).

torchvision's Mask R-CNN on a ResNet-FPN backbone, trained from scratch on a detection dataset
of `partsim vision detection-dataset` (no weights are downloaded; :func:`load_backbone_weights`
loads a ResNet state dict saved earlier). With ``input="rgbd"`` the backbone's first convolution
takes depth in metres as a fourth channel. Predictions are COCO results (compressed RLE masks at
the picture's size) for ``partsim vision evaluate-detection``.
"""

import numpy as np

from .base import Baseline

# The normalisation of the model's transform, per input channel: ImageNet's RGB statistics
# (those of any pretrained ResNet one loads), and for depth in metres a centre and spread that
# put the background (0, nothing seen) near -1 and the objects of the generated datasets
# (about 2.5 to 4 m from the camera) between 0.7 and 1.7.
RGB_MEAN = (0.485, 0.456, 0.406)
RGB_STD = (0.229, 0.224, 0.225)
DEPTH_MEAN = 1.5
DEPTH_STD = 1.5

# the backbones and the channels of their four stages, which feed the FPN
BACKBONES = {"resnet50": (256, 512, 1024, 2048), "resnet18": (64, 128, 256, 512)}


class MaskRCNN(Baseline):
    """Mask R-CNN with a ResNet-FPN backbone (``backbone``: ``resnet50``, the paper's, or
    ``resnet18``), all layers trainable, on ``rgb`` (3 channels in [0, 1]) or ``rgbd`` (and
    depth in metres). The network's transform resizes pictures so that their sides are
    ``size`` (``None``: the training pictures' largest side, so square pictures keep their size)
    and gives predictions back at the picture's own size.

    ``channels`` is the width of the FPN and the mask head and ``rois`` the regions sampled per
    picture to train the box and mask heads (torchvision's 256 and 512; the tests' quick runs
    take 64 and 64). Category ids of the dataset map to the network's labels 1..K in the
    dataset's category order (0 is the background); :meth:`config` records the ids.

    :meth:`loss` wants the model in training mode (torchvision's model returns its losses only
    then), :meth:`predict` in evaluation mode. A batch is a pair of lists, pictures of any size.
    """

    name = "maskrcnn"
    kind = "detection"
    inputs = ("rgb", "rgbd")
    # From scratch on a few thousand pictures, with Adam (see make_optimizer); the pictures of
    # `partsim vision detection-dataset` are 512 x 512 by default and keep their size.
    defaults = {"epochs": 24, "batch_size": 4, "lr": 1e-4, "size": None}

    # predictions below this score are not written; at most this many per picture
    score_threshold = 0.05
    max_detections = 100

    def __init__(self, train, options):
        super().__init__(train, options)
        self.input = self.options.get("input") or self.inputs[0]
        if self.input not in self.inputs:
            raise ValueError("maskrcnn: input must be one of %s, got %r"
                             % (", ".join(self.inputs), self.input))
        self.backbone = self.options.get("backbone") or "resnet50"
        if self.backbone not in BACKBONES:
            raise ValueError("maskrcnn: backbone must be one of %s, got %r"
                             % (", ".join(BACKBONES), self.backbone))
        # the width of the FPN and the mask head, and the regions sampled per picture
        self.channels = int(self.options.get("channels") or 256)
        self.rois = int(self.options.get("rois") or 512)
        if self.channels <= 0:
            raise ValueError("maskrcnn: channels must be positive, got %r" % (self.channels,))
        if self.rois <= 0:
            raise ValueError("maskrcnn: rois must be positive, got %r" % (self.rois,))
        # the category ids, in the dataset's order: id categories[k] is the network's label k+1
        self.categories = [int(c["id"]) for c in train.categories]
        if not self.categories:
            raise ValueError("maskrcnn: the training split has no categories")
        self.label_of = {c: k + 1 for k, c in enumerate(self.categories)}
        # the side pictures are resized to: the option, else the training pictures' largest
        size = self.options.get("size")
        if size is None:
            size = max([max(int(im["width"]), int(im["height"])) for im in train.images] or [0])
        if not size or int(size) <= 0:
            raise ValueError("maskrcnn: size must be a positive number of pixels, got %r" % (size,))
        self.size = int(size)
        self.batch_size = int(self.options.get("batch_size") or self.defaults["batch_size"])

    def config(self):
        return {"input": self.input, "backbone": self.backbone, "channels": self.channels,
                "rois": self.rois, "size": self.size, "categories": list(self.categories)}

    def load_weights(self, model, path):
        """``--init``: a Mask R-CNN's state dict (another run's) loads tensor by tensor as for
        every baseline; a bare ResNet's (keys ``conv1.weight``, ``layer1...``, as torchvision's
        classification networks save them: pretrained weights) loads into the backbone by
        :func:`load_backbone_weights`."""
        import torch
        from .train import RunError, load_matching

        try:
            saved = torch.load(path, map_location="cpu")
        except Exception as e:  # torch raises many kinds for a bad file
            raise RunError(f"weights '{path}' cannot be read: {type(e).__name__}: {e}") from None
        if isinstance(saved, dict) and "conv1.weight" in saved and not any(
                str(k).startswith("backbone.") for k in saved):
            loaded, skipped = load_backbone_weights(model, path, saved)
            if not loaded:
                raise RunError(f"weights '{path}': none of its {len(saved)} tensors fits "
                               f"the {self.backbone} backbone")
            return loaded, skipped
        return load_matching(model, path, saved)

    def build_model(self):
        import torch
        import torchvision
        from torchvision.models.detection import MaskRCNN as TorchMaskRCNN
        from torchvision.models.detection.backbone_utils import BackboneWithFPN
        from torchvision.models.detection.faster_rcnn import FastRCNNPredictor
        from torchvision.models.detection.mask_rcnn import MaskRCNNHeads, MaskRCNNPredictor
        from torchvision.ops.feature_pyramid_network import LastLevelMaxPool

        # Normalisation: GroupNorm (32 groups). Trained from scratch with a few pictures per
        # batch, BatchNorm's batch statistics are noisy and its running averages, used in
        # evaluation, lag the weights; torchvision's FrozenBatchNorm2d is an identity at
        # initialisation, which leaves a from-scratch ResNet without any normalisation. GroupNorm
        # normalises each picture alone, the same in training and evaluation (Wu & He 2018, and
        # He et al. 2019 train Mask R-CNN from scratch with it).
        def norm_layer(channels):
            return torch.nn.GroupNorm(32, channels)

        # the ResNet's four stages feed the FPN, every layer trainable (torchvision's
        # resnet_fpn_backbone with trainable_layers=5, the FPN's width an option)
        resnet = getattr(torchvision.models, self.backbone)(weights=None, norm_layer=norm_layer)
        backbone = BackboneWithFPN(resnet, {"layer%d" % (k + 1): str(k) for k in range(4)},
                                   list(BACKBONES[self.backbone]), self.channels,
                                   extra_blocks=LastLevelMaxPool())
        mean, std = list(RGB_MEAN), list(RGB_STD)
        if self.input == "rgbd":
            # the first convolution takes R, G, B and depth, initialised as torchvision
            # initialises the ResNet's convolutions (Kaiming normal)
            old = backbone.body.conv1
            conv = torch.nn.Conv2d(4, old.out_channels, kernel_size=old.kernel_size,
                                   stride=old.stride, padding=old.padding, bias=False)
            torch.nn.init.kaiming_normal_(conv.weight, mode="fan_out", nonlinearity="relu")
            backbone.body.conv1 = conv
            mean.append(DEPTH_MEAN)
            std.append(DEPTH_STD)
        # the heads as torchvision's (box: two 1024-wide layers; mask: four 3 x 3 convolutions
        # and a deconvolution), the mask head as wide as the FPN; K categories and background
        k, classes = self.channels, len(self.categories) + 1
        return TorchMaskRCNN(backbone, min_size=self.size, max_size=self.size,
                             image_mean=mean, image_std=std,
                             box_predictor=FastRCNNPredictor(1024, classes),
                             mask_head=MaskRCNNHeads(k, (k, k, k, k), 1),
                             mask_predictor=MaskRCNNPredictor(k, k, classes),
                             box_batch_size_per_image=self.rois,
                             box_score_thresh=self.score_threshold,
                             box_detections_per_img=self.max_detections)

    def make_optimizer(self, model, lr):
        import torch
        # Adam, which overfits faster from scratch. Measured on the tests' four 64 x 64 pictures
        # (ResNet-18, 100 steps of the whole split, mAP on the same pictures): SGD with momentum
        # 0.9 and weight decay 1e-4, Mask R-CNN's usual recipe, turns to NaN at 0.02 without
        # warm-up and reaches 0.68-0.85 at 0.005-0.01 (three seeds); Adam at 3e-4 reaches
        # 0.77-0.87 (four seeds).
        params = [p for p in model.parameters() if p.requires_grad]
        return torch.optim.Adam(params, lr=lr)

    def load_batch(self, dataset, indices, rng, train):
        """``(images, targets)``: lists, one entry per item. An image is a float32 tensor
        (C, h, w): R, G, B in [0, 1], and depth in metres for ``rgbd``; a target a dict of
        ``boxes`` (n, 4) float32 [x1, y1, x2, y2] pixels, ``labels`` (n,) int64 (the network's,
        1..K), ``masks`` (n, h, w) uint8 and ``image_id`` (1,) int64. Crowd annotations and
        empty parts are left out. In training, each picture is flipped left-right with
        probability 1/2 (``rng``), its masks and boxes with it."""
        import torch
        images, targets = [], []
        for i in indices:
            item = dataset[int(i)]
            channels = [item["rgb"].astype(np.float32) / 255.0]
            if self.input == "rgbd":
                channels.append(item["depth"].astype(np.float32)[..., None])
            image = np.concatenate(channels, axis=2).transpose(2, 0, 1)  # (C, h, w)
            width = image.shape[2]

            # the parts to learn: not crowd, not empty, of a known category
            boxes = np.asarray(item["boxes"], dtype=np.float64).reshape(-1, 4)
            keep = [k for k in range(len(item["labels"]))
                    if not item["iscrowd"][k] and boxes[k, 2] > 0 and boxes[k, 3] > 0
                    and int(item["labels"][k]) in self.label_of]
            masks = item["masks"][keep].astype(np.uint8)
            labels = np.array([self.label_of[int(item["labels"][k])] for k in keep],
                              dtype=np.int64)
            xyxy = np.concatenate([boxes[keep, :2], boxes[keep, :2] + boxes[keep, 2:]], axis=1)

            # random left-right flip: x becomes width - x, so a box's x1 and x2 swap roles
            if train and rng.random() < 0.5:
                image = image[:, :, ::-1]
                masks = masks[:, :, ::-1]
                xyxy = np.stack([width - xyxy[:, 2], xyxy[:, 1], width - xyxy[:, 0], xyxy[:, 3]],
                                axis=1)

            images.append(torch.from_numpy(np.ascontiguousarray(image)))
            targets.append({
                "boxes": torch.as_tensor(xyxy, dtype=torch.float32).reshape(-1, 4),
                "labels": torch.from_numpy(labels),
                "masks": torch.from_numpy(np.ascontiguousarray(masks)),
                "image_id": torch.tensor([int(item["image_id"])], dtype=torch.int64),
            })
        return images, targets

    def loss(self, model, batch):
        images, targets = batch
        losses = model(images, targets)  # in training mode the model returns its loss terms
        total = sum(losses.values())
        return total, {k: float(v.detach()) for k, v in losses.items()}

    def predict(self, model, dataset, indices, device, rng):
        import torch

        from .. import vision  # the compiled module: imported when used (see __init__)
        indices = list(indices)
        results = []
        # a few pictures at a time, so that a whole test split never sits in memory
        for start in range(0, len(indices), self.batch_size):
            images, targets = self.load_batch(dataset, indices[start:start + self.batch_size],
                                              rng, train=False)
            outputs = model([image.to(device) for image in images])
            for target, out in zip(targets, outputs):
                image_id = int(target["image_id"][0])
                order = torch.argsort(out["scores"], descending=True)[:self.max_detections]
                for k in order.tolist():
                    score = float(out["scores"][k])
                    if score < self.score_threshold:
                        continue
                    # masks come as (1, h, w) probabilities pasted at the picture's size
                    mask = (out["masks"][k, 0] >= 0.5).cpu().numpy().astype(np.uint8)
                    if not mask.any():
                        continue
                    results.append({
                        "image_id": image_id,
                        "category_id": self.categories[int(out["labels"][k]) - 1],
                        "segmentation": vision.encode_mask(mask, compressed=True),
                        "score": score,
                    })
        return results


def load_backbone_weights(model, path, saved=None):
    """Loads the ResNet weights saved at ``path`` (a state dict written by ``torch.save``: a
    torchvision ResNet's ``state_dict()``, or keys under ``backbone.body.``, a Mask R-CNN's)
    into ``model``'s backbone (``model.backbone.body``). Keys the backbone does not have (the
    ResNet's ``fc``, BatchNorm's running statistics when the backbone uses GroupNorm) and
    tensors of another shape are skipped, except the first convolution of an RGB-D model,
    which gets the saved RGB weights in its first three input channels and their mean in the
    fourth. Returns ``(loaded, skipped)``, the lists of the file's keys (without prefix).
    ``saved``: the file's contents when the caller has read them already."""
    import torch
    if saved is None:
        saved = torch.load(path, map_location="cpu")
    if not isinstance(saved, dict):
        raise ValueError("load_backbone_weights: %s does not hold a state dict (got %s)"
                         % (path, type(saved).__name__))
    prefix = "backbone.body."
    if any(k.startswith(prefix) for k in saved):
        saved = {k[len(prefix):]: v for k, v in saved.items() if k.startswith(prefix)}

    body = model.backbone.body
    own = body.state_dict()
    update, loaded, skipped = {}, [], []
    for key, value in saved.items():
        target = own.get(key)
        if target is None:
            skipped.append(key)
        elif target.shape == value.shape:
            update[key] = value.to(target.dtype)
            loaded.append(key)
        elif (key == "conv1.weight" and value.dim() == 4 and value.shape[1] == 3
              and target.shape[1] == 4 and target.shape[0] == value.shape[0]
              and target.shape[2:] == value.shape[2:]):
            # RGB-D: the RGB filters, and their mean over colours for the depth channel
            update[key] = torch.cat([value, value.mean(dim=1, keepdim=True)], dim=1)
            update[key] = update[key].to(target.dtype)
            loaded.append(key)
        else:
            skipped.append(key)
    body.load_state_dict(update, strict=False)
    return loaded, skipped
