"""partsim.vision: the perception benchmark of the SAPIEN paper (movable-part detection and
motion-attribute estimation).

COCO masks and run-length encoding (encode_mask, decode_rle, rle_area, rle_bbox, rle_iou,
compress_rle_counts, decompress_rle_counts) and the evaluators: evaluate_detection (AP at mask
IoU 0.5 per part category and the mAP, COCO's protocol) and evaluate_motion (the columns of the
paper's Table 2). They are the C++ vision layer's, bound in the extension; files and formats are
described in docs/vision.md. Example::

    import partsim.vision as vision
    e = vision.evaluate_detection("instances_test.json", "results.json")
    print(e.to_markdown(), e.map)

The datasets written by `partsim vision detection-dataset` and `motion-dataset` load as numpy
arrays with DetectionDataset and MotionDataset (pure Python; PNG files are read with PIL, and
their .torch() gives a torch.utils.data.Dataset when torch is installed); load_coco reads a COCO
JSON file::

    train = vision.DetectionDataset("out", "train")
    item = train[0]          # rgb, depth, instance, masks, labels, boxes, K, extrinsic, ...
    cloud = train.point_cloud(0)
    motion = vision.MotionDataset("motion_out", "test").torch()  # (5 x H x W, m) pairs

show draws one picture of such a dataset with its annotations, as `partsim vision show` does::

    picture = vision.show("out", 3, "check.png")  # (H, W, 3) uint8, also written to check.png
"""

import json as _json
import os as _os

import numpy as _np

from ._partsim import _vision as _ext

# the C++ layer's names (their __module__ says partsim.vision)
CategoryAp = _ext.CategoryAp
DetectionEvaluation = _ext.DetectionEvaluation
MotionEvaluation = _ext.MotionEvaluation
compress_rle_counts = _ext.compress_rle_counts
decode_rle = _ext.decode_rle
decompress_rle_counts = _ext.decompress_rle_counts
encode_mask = _ext.encode_mask
evaluate_detection = _ext.evaluate_detection
evaluate_motion = _ext.evaluate_motion
rle_area = _ext.rle_area
rle_bbox = _ext.rle_bbox
rle_iou = _ext.rle_iou
show = _ext.show

__all__ = [
    "CategoryAp", "DetectionDataset", "DetectionEvaluation", "MotionDataset", "MotionEvaluation",
    "compress_rle_counts", "decode_rle", "decompress_rle_counts", "encode_mask",
    "evaluate_detection", "evaluate_motion", "load_coco", "rle_area", "rle_bbox", "rle_iou",
    "show",
]


# --- the datasets of `partsim vision detection-dataset` and `motion-dataset` -------------------
# Pure Python on numpy; PIL reads the PNG files and torch backs .torch(), both imported only when
# used, so that `import partsim` works without them.

def _pil_image():
    try:
        from PIL import Image
    except ImportError as e:  # pragma: no cover - PIL is a Debian package (python3-pil)
        raise ImportError("partsim.vision: reading the datasets' PNG files needs PIL "
                          "(Debian: apt-get install python3-pil; pip: pillow)") from e
    return Image


def _read_png(path):
    """A PNG file as a numpy array: (h, w, 3) uint8 for RGB, (h, w) uint8 for 8-bit grey,
    (h, w) uint16 for 16-bit grey (PIL gives those as int32)."""
    with _pil_image().open(path) as im:
        mode = im.mode
        a = _np.array(im)  # a writable copy
    if mode in ("I", "I;16", "I;16B"):
        return a.astype(_np.uint16)
    return a


def _torch():
    try:
        import torch
        import torch.utils.data  # noqa: F401
    except ImportError as e:
        raise ImportError("partsim.vision: .torch() needs PyTorch, which cannot be imported "
                          "here (Debian: apt-get install python3-torch; pip: torch); the numpy "
                          "loaders work without it") from e
    return torch


def load_coco(path):
    """The dict of a COCO JSON file (instances_train.json, instances_test.json, a results list
    gives a list), as json.load reads it."""
    with open(path, "rb") as f:
        return _json.load(f)


def _load_json(path):
    with open(path, "rb") as f:
        return _json.load(f)


def _split_file(root, split, stem):
    if split not in ("train", "test"):
        raise ValueError("partsim.vision: split must be 'train' or 'test', got %r" % (split,))
    path = _os.path.join(root, "%s_%s.json" % (stem, split))
    if not _os.path.isfile(path):
        raise FileNotFoundError(
            "partsim.vision: no %s in '%s' (not a %s dataset of `partsim vision`?)"
            % (_os.path.basename(path), root, "detection" if stem == "instances" else "motion"))
    return path


class DetectionDataset:
    """The movable-part detection dataset written by `partsim vision detection-dataset`, one
    split, as numpy arrays.

    `DetectionDataset(root, split="train")` reads `root/instances_<split>.json` (COCO) and, per
    object, `root/objects/<name>/views.json` (cameras, joint positions). Item `i` is the split's
    i-th image (the COCO file's order), a dict of:

    - `rgb` (h, w, 3) uint8; `depth` (h, w) float32, metres along the camera's z (0 where nothing
      is seen), from depth/NN.npy; `instance` (h, w) uint16, the part-instance picture (0 =
      none, k = the view's k-th annotated part);
    - `masks` (n, h, w) bool, decoded from the annotations' RLE; `labels` (n,) int64 category
      ids; `boxes` (n, 4) float64 COCO [x, y, width, height]; `areas` (n,) int64 pixel counts;
      `annotation_ids` (n,) int64; `iscrowd` (n,) int64;
    - `K` (3, 3) intrinsics and `extrinsic` (3, 4) world -> OpenCV camera [R | t] (x right, y
      down, z forward), float64; `camera` the views.json entry (also `pose`, `width`,
      `height`); `qpos` (dof,) float64, the object's joint positions in the view;
    - `image_id`, `object` (its folder name under objects/), `view`, `category` (the object's
      category, meta.json's model_cat) and the file paths `rgb_path`, `depth_path` (.npy),
      `depth_png_path` (16-bit millimetres), `instance_path`, `cloud_path` ('' when the dataset
      has no point clouds).

    `categories` lists the COCO categories ({'id', 'name', 'supercategory'}, names
    '<object category>/<part label>'); `coco` is the whole COCO dict; `point_cloud(i)` loads
    the view's partial point cloud; `torch()` wraps the split as a torch Dataset with
    torchvision-style targets.
    """

    def __init__(self, root, split="train"):
        self.root = _os.fspath(root)
        self.split = split
        self.annotation_file = _split_file(self.root, split, "instances")
        self.coco = load_coco(self.annotation_file)
        self.images = list(self.coco["images"])
        self.categories = list(self.coco["categories"])
        self._annotations = {im["id"]: [] for im in self.images}
        for a in self.coco["annotations"]:
            self._annotations.setdefault(a["image_id"], []).append(a)
        self._views = {}  # object folder -> {view number: views.json entry}

    @property
    def category_names(self):
        """{category id: name} of the split's categories."""
        return {c["id"]: c["name"] for c in self.categories}

    def __len__(self):
        """The number of images in the split."""
        return len(self.images)

    def _object_dir(self, image):
        # file_name is objects/<name>/rgb/NN.png
        rel = _os.path.dirname(_os.path.dirname(image["file_name"]))
        return _os.path.join(self.root, rel)

    def _view(self, image):
        folder = self._object_dir(image)
        views = self._views.get(folder)
        if views is None:
            doc = _load_json(_os.path.join(folder, "views.json"))
            views = {v["view"]: v for v in doc["views"]}
            views["_category"] = doc.get("category", "")
            self._views[folder] = views
        view = image.get("view")
        if view is None:  # rgb/NN.png
            view = int(_os.path.splitext(_os.path.basename(image["file_name"]))[0])
        return folder, views[view], views["_category"]

    def _image(self, index):
        if not -len(self.images) <= index < len(self.images):
            raise IndexError("DetectionDataset: index %d out of range (%d images)"
                             % (index, len(self.images)))
        return self.images[index]

    def paths(self, index):
        """The files of image `index`: {'rgb_path', 'depth_path' (.npy), 'depth_png_path',
        'instance_path', 'cloud_path' ('' when the dataset has no point clouds)}."""
        image = self._image(index)
        folder, view, _ = self._view(image)
        return {
            "rgb_path": _os.path.join(self.root, image["file_name"]),
            "depth_path": _os.path.join(folder, view["depth_npy"]),
            "depth_png_path": _os.path.join(folder, view["depth"]),
            "instance_path": _os.path.join(folder, view["instances_png"]),
            "cloud_path": _os.path.join(folder, view["cloud"]) if view.get("cloud") else "",
        }

    def annotations(self, index):
        """The COCO annotation dicts of image `index`, in the file's order."""
        return list(self._annotations.get(self._image(index)["id"], []))

    def __getitem__(self, index):
        """Image `index` as a dict of numpy arrays (see the class)."""
        image = self._image(index)
        folder, view, category = self._view(image)
        item = {"image_id": image["id"], "object": _os.path.basename(folder),
                "view": view["view"], "category": category}
        item.update(self.paths(index))
        item["rgb"] = _read_png(item["rgb_path"])
        item["depth"] = _np.load(item["depth_path"]).astype(_np.float32, copy=False)
        item["instance"] = _read_png(item["instance_path"])
        h, w = int(image["height"]), int(image["width"])
        anns = self._annotations.get(image["id"], [])
        masks = _np.zeros((len(anns), h, w), dtype=bool)
        for k, a in enumerate(anns):
            masks[k] = _ext.decode_rle(a["segmentation"]).astype(bool)
        item["masks"] = masks
        item["labels"] = _np.array([a["category_id"] for a in anns], dtype=_np.int64)
        item["boxes"] = _np.array([a["bbox"] for a in anns], dtype=_np.float64).reshape(-1, 4)
        item["areas"] = _np.array([a["area"] for a in anns], dtype=_np.int64)
        item["annotation_ids"] = _np.array([a["id"] for a in anns], dtype=_np.int64)
        item["iscrowd"] = _np.array([a.get("iscrowd", 0) for a in anns], dtype=_np.int64)
        camera = view["camera"]
        item["camera"] = camera
        item["K"] = _np.array(camera["K"], dtype=_np.float64)
        item["extrinsic"] = _np.array(camera["extrinsic"], dtype=_np.float64)
        item["qpos"] = _np.array(view["qpos"], dtype=_np.float64)
        return item

    def point_cloud(self, index):
        """The partial point cloud of image `index` (cloud/NN.npz): {'xyz' (m, 3) float32 in
        the OpenCV camera frame, metres; 'rgb' (m, 3) uint8; 'instance' (m,) int32, the
        instance picture's value at the point's pixel; 'label' (m,) int32, the part's category
        id, 0 for none}, one point per pixel that sees a surface, in row-major pixel order.
        Raises FileNotFoundError when the dataset was made without point clouds."""
        path = self.paths(index)["cloud_path"]
        if not path:
            raise FileNotFoundError("DetectionDataset: the dataset in '%s' has no point clouds"
                                    % self.root)
        with _np.load(path) as z:
            return {k: z[k] for k in ("xyz", "rgb", "instance", "label")}

    def torch(self, transform=None):
        """The split as a torch.utils.data.Dataset of (image, target) pairs as torchvision's
        detection models take them: image a float32 tensor (3, h, w) in [0, 1]; target a dict
        of 'boxes' (n, 4) float32 [x1, y1, x2, y2], 'labels' (n,) int64, 'masks' (n, h, w)
        uint8, 'image_id' (1,) int64, 'area' (n,) float32 and 'iscrowd' (n,) int64.
        `transform(image, target)`, when given, returns the pair to yield. Raises ImportError
        when torch cannot be imported."""
        torch = _torch()
        return _make_torch_dataset(torch, self, transform, _detection_tensors)

    def __repr__(self):
        return "DetectionDataset(%r, %r): %d images, %d categories" % (
            self.root, self.split, len(self.images), len(self.categories))


class MotionDataset:
    """The motion-attribute dataset written by `partsim vision motion-dataset`, one split, as
    numpy arrays.

    `MotionDataset(root, split="train")` reads `root/motion_<split>.json`. Item `i` is the
    split's i-th sample (the file's order), a dict of:

    - `rgb` (h, w, 3) uint8; `depth` (h, w) float32 metres (depth/*.npy); `mask` (h, w) bool,
      the target door or drawer;
    - `m` (13,) float64, the paper's label vector in the OpenCV camera frame (T_r, T_t, pivot
      p^r (3), hinge axis d^r (3), slider axis d^t (3), x_door = (q - lower) / 2 pi, x_drawer =
      (q - lower) / slider_range; see docs/vision.md);
    - `K` (3, 3), `extrinsic` (3, 4) world -> OpenCV camera, `camera` (the file's entry, with
      `pose`, `width`, `height`), `qpos` (dof,) the object's joint positions;
    - `sample_id`, `object`, `category`, `link` (the target link's name), `label` (its part
      label), `type` ('hinge' or 'slider'), `state` (q - lower: rad or m), `pivot` and `axis`
      (3,) float64, and the paths `rgb_path`, `depth_path` (.npy), `depth_png_path`,
      `mask_path`.

    `slider_range` is the dataset's slider normalisation (metres: the largest range of its
    drawers); `samples` the file's sample dicts; `torch()` wraps the split as a torch Dataset of
    (5-channel input, m) pairs.
    """

    def __init__(self, root, split="train"):
        self.root = _os.fspath(root)
        self.split = split
        self.annotation_file = _split_file(self.root, split, "motion")
        self.ground_truth = _load_json(self.annotation_file)
        self.slider_range = float(self.ground_truth["slider_range"])
        self.samples = list(self.ground_truth["samples"])

    def __len__(self):
        """The number of samples in the split."""
        return len(self.samples)

    def __getitem__(self, index):
        """Sample `index` as a dict of numpy arrays (see the class)."""
        if not -len(self.samples) <= index < len(self.samples):
            raise IndexError("MotionDataset: index %d out of range (%d samples)"
                             % (index, len(self.samples)))
        s = self.samples[index]
        item = {k: s[k] for k in ("sample_id", "object", "category", "link", "label", "type",
                                  "state") if k in s}
        item["rgb_path"] = _os.path.join(self.root, s["rgb"])
        item["depth_path"] = _os.path.join(self.root, s["depth_npy"])
        item["depth_png_path"] = _os.path.join(self.root, s["depth"])
        item["mask_path"] = _os.path.join(self.root, s["mask"])
        item["rgb"] = _read_png(item["rgb_path"])
        item["depth"] = _np.load(item["depth_path"]).astype(_np.float32, copy=False)
        item["mask"] = _read_png(item["mask_path"]) > 0
        item["m"] = _np.array(s["m"], dtype=_np.float64)
        camera = s["camera"]
        item["camera"] = camera
        item["K"] = _np.array(camera["K"], dtype=_np.float64)
        item["extrinsic"] = _np.array(camera["extrinsic"], dtype=_np.float64)
        item["qpos"] = _np.array(s["qpos"], dtype=_np.float64)
        item["pivot"] = _np.array(s["pivot"], dtype=_np.float64)
        item["axis"] = _np.array(s["axis"], dtype=_np.float64)
        return item

    def torch(self, transform=None):
        """The split as a torch.utils.data.Dataset of (x, m) pairs, the paper's network input
        and label: x a float32 tensor (5, h, w) of R, G, B in [0, 1], depth in metres and the
        target's mask (0 or 1); m a float32 tensor (13,). `transform(x, m)`, when given,
        returns the pair to yield. Raises ImportError when torch cannot be imported."""
        torch = _torch()
        return _make_torch_dataset(torch, self, transform, _motion_tensors)

    def __repr__(self):
        return "MotionDataset(%r, %r): %d samples, slider_range %g m" % (
            self.root, self.split, len(self.samples), self.slider_range)


def _make_torch_dataset(torch, dataset, transform, convert):
    """`dataset` as a torch Dataset of the pairs `convert(torch, item)` makes, passed through
    `transform(a, b)` when one is given."""

    class _TorchDataset(torch.utils.data.Dataset):
        def __len__(self):
            return len(dataset)

        def __getitem__(self, index):
            a, b = convert(torch, dataset[index])
            return transform(a, b) if transform is not None else (a, b)

    return _TorchDataset()


def _detection_tensors(torch, item):
    """A DetectionDataset item as (image, target): torchvision's detection convention."""
    image = torch.from_numpy(item["rgb"]).permute(2, 0, 1).float().div_(255.0)
    xywh = item["boxes"]
    xyxy = _np.concatenate([xywh[:, :2], xywh[:, :2] + xywh[:, 2:]], axis=1)
    target = {
        "boxes": torch.as_tensor(xyxy, dtype=torch.float32).reshape(-1, 4),
        "labels": torch.as_tensor(item["labels"], dtype=torch.int64),
        "masks": torch.from_numpy(item["masks"].astype(_np.uint8)),
        "image_id": torch.tensor([item["image_id"]], dtype=torch.int64),
        "area": torch.as_tensor(item["areas"], dtype=torch.float32),
        "iscrowd": torch.as_tensor(item["iscrowd"], dtype=torch.int64),
    }
    return image, target


def _motion_tensors(torch, item):
    """A MotionDataset item as (5-channel input, m): RGB in [0, 1], depth in metres, mask."""
    rgb = item["rgb"].astype(_np.float32) / 255.0
    x = _np.concatenate([rgb, item["depth"][..., None].astype(_np.float32),
                         item["mask"][..., None].astype(_np.float32)], axis=2)
    x = torch.from_numpy(_np.ascontiguousarray(x.transpose(2, 0, 1)))
    return x, torch.as_tensor(item["m"], dtype=torch.float32)
