"""The perception datasets of `partsim vision detection-dataset` and `motion-dataset` (issue 16),
checked from their files with numpy and against partsim's own model of the objects, and the
loaders of partsim.vision (DetectionDataset, MotionDataset, load_coco, .torch()).

One small tree (generated cabinets, refrigerators and faucets) and both datasets are made once
for the module; the real PartNet-Mobility bottle of ../shared/realdata is used when present.
What is checked, as the issue's "Done means" asks:
- every annotation's RLE mask is the instance picture's pixels of that instance, its box is the
  mask's tightest box, its area the mask's pixel count, none is below the stated threshold;
- the COCO files' schema (keys and types, unique ids, references that exist, iscrowd 0);
- part categories are "<meta.json model_cat>/<semantics.txt label>" of the annotated link;
- the depth PNG is the float depth in millimetres, rounded; the point clouds project with K to
  the pixels whose depth, colour and instance they carry;
- motion labels: the joint's axis of the object loaded in partsim at the sample's joint
  positions, mapped with the sample's extrinsic, is m's axis (sign included), the pivot lies on
  it, the states are (q - lower) / 2 pi and (q - lower) / slider_range;
- the loaders give what the files hold (PNG decoded here without PIL), with torch when present;
- the evaluators score the ground truth against itself perfectly.
"""

import json
import math
import os
import struct
import subprocess
import sys
import zlib

import numpy as np
import pytest

import partsim
import partsim.vision as vision
from conftest import PYTHON_DIR, REPO, require

CLI = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                                 "partsim"))
REAL_BOTTLE = os.path.join(REPO, "..", "shared", "realdata", "partnet-mobility-3763")
VIEWS = 2
SIZE = 96
CATEGORIES = "StorageFurniture,Refrigerator,Faucet"


def run_cli(*args, ok=True):
    result = subprocess.run([CLI] + [str(a) for a in args], capture_output=True, text=True,
                            timeout=300)
    if ok:
        assert result.returncode == 0, "partsim %s: %s%s" % (
            " ".join(map(str, args)), result.stdout, result.stderr)
    return result


class Data:
    """The files the module's tests read."""


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    base = tmp_path_factory.mktemp("vision_datasets")
    d = Data()
    d.tree, d.det, d.mot = str(base / "tree"), str(base / "det"), str(base / "mot")
    run_cli("assets", "generate", "--out", d.tree, "--categories", CATEGORIES,
            "--per-category", 2, "--seed", 1)
    common = ["--views", VIEWS, "--size", SIZE, "--seed", 5, "--quiet"]
    run_cli("vision", "detection-dataset", "--dataset", d.tree, "--out", d.det, *common)
    run_cli("vision", "motion-dataset", "--dataset", d.tree, "--out", d.mot, *common)
    return d


@pytest.fixture(scope="module")
def bottle(tmp_path_factory):
    if not os.path.isdir(REAL_BOTTLE):
        pytest.skip("no ../shared/realdata")
    out = str(tmp_path_factory.mktemp("vision_bottle") / "det")
    run_cli("vision", "detection-dataset", "--dataset", REAL_BOTTLE, "--out", out, "--views", 3,
            "--size", SIZE, "--quiet")
    return out


# --- reading the files without the loaders -----------------------------------------------------

def read_json(path):
    with open(path) as f:
        return json.load(f)


def png(path):
    """A non-interlaced PNG (8-bit grey or RGB, 16-bit grey) decoded with zlib and numpy: the
    loaders' PIL is not the reference."""
    with open(path, "rb") as f:
        raw = f.read()
    assert raw[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, header = 8, b"", None
    while pos < len(raw):
        length, kind = struct.unpack(">I4s", raw[pos:pos + 8])
        body = raw[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, color, _, _, interlace = header
    assert interlace == 0 and depth in (8, 16) and color in (0, 2), (path, header)
    channels = 3 if color == 2 else 1
    bpp = channels * depth // 8
    stride = width * bpp
    data = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, stride + 1)
    out = np.zeros((height, stride), np.int64)
    prev = np.zeros(stride, np.int64)
    for r in range(height):
        kind, line = data[r, 0], data[r, 1:].astype(np.int64)
        if kind == 0:
            cur = line
        elif kind == 2:
            cur = (line + prev) & 255
        else:
            cur = line.copy()
            for i in range(stride):
                a = cur[i - bpp] if i >= bpp else 0
                c = prev[i - bpp] if i >= bpp else 0
                b = prev[i]
                if kind == 1:
                    pred = a
                elif kind == 3:
                    pred = (a + b) // 2
                else:
                    assert kind == 4, (path, kind)
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[i] = (cur[i] + pred) & 255
        out[r] = prev = cur
    if depth == 16:
        return (out[:, 0::2] * 256 + out[:, 1::2]).astype(np.uint16).reshape(height, width)
    out = out.astype(np.uint8)
    return out.reshape(height, width, 3) if channels == 3 else out.reshape(height, width)


def semantics(folder):
    """{link name: (joint, label)} of an object's semantics.txt."""
    out = {}
    with open(os.path.join(folder, "semantics.txt")) as f:
        for line in f:
            parts = line.split()
            if len(parts) >= 3:
                out[parts[0]] = (parts[1], parts[2])
    return out


def model_cat(folder):
    """meta.json's object category of an object folder."""
    return read_json(os.path.join(folder, "meta.json"))["model_cat"]


def detection_views(root):
    """[(split, image dict, object folder, views.json entry, [annotations])] of a dataset."""
    out = []
    for split in ("train", "test"):
        coco = read_json(os.path.join(root, "instances_%s.json" % split))
        anns = {}
        for a in coco["annotations"]:
            anns.setdefault(a["image_id"], []).append(a)
        for image in coco["images"]:
            folder = os.path.join(root, "objects", image["object"])
            views = read_json(os.path.join(folder, "views.json"))["views"]
            view = [v for v in views if v["view"] == image["view"]]
            assert len(view) == 1
            out.append((split, image, folder, view[0], anns.get(image["id"], [])))
    return out


def category_names(root):
    """{category id: name} of a detection dataset."""
    coco = read_json(os.path.join(root, "instances_train.json"))
    return {c["id"]: c["name"] for c in coco["categories"]}


def motion_samples(root):
    """[(split, sample dict)] of a motion dataset."""
    return [(split, s) for split in ("train", "test")
            for s in read_json(os.path.join(root, "motion_%s.json" % split))["samples"]]


# --- detection ---------------------------------------------------------------------------------

def check_coco_schema(root):
    """Keys, types, unique ids and references of both COCO files; returns dataset.json."""
    manifest = read_json(os.path.join(root, "dataset.json"))
    seen_images, seen_annotations, objects = set(), set(), {}
    categories = None
    for split in ("train", "test"):
        coco = vision.load_coco(os.path.join(root, "instances_%s.json" % split))
        assert set(coco) >= {"images", "annotations", "categories"}
        cats = coco["categories"]
        for c in cats:
            assert isinstance(c["id"], int) and isinstance(c["name"], str)
            assert c["supercategory"] == c["name"].split("/")[0] and "/" in c["name"]
        assert len({c["id"] for c in cats}) == len(cats)
        if categories is None:
            categories = cats
        assert cats == categories  # the same categories in both splits
        assert [c["name"] for c in cats] == manifest["categories"]
        images = {}
        for im in coco["images"]:
            assert isinstance(im["id"], int) and im["id"] not in seen_images
            assert isinstance(im["file_name"], str)
            assert os.path.isfile(os.path.join(root, im["file_name"]))
            assert isinstance(im["width"], int) and isinstance(im["height"], int)
            assert (im["width"], im["height"]) == (manifest["options"]["size"],) * 2
            seen_images.add(im["id"])
            images[im["id"]] = im
            objects.setdefault(im["object"], set()).add(split)
        cat_ids = {c["id"] for c in cats}
        for a in coco["annotations"]:
            assert isinstance(a["id"], int) and a["id"] not in seen_annotations
            seen_annotations.add(a["id"])
            assert a["image_id"] in images and a["category_id"] in cat_ids
            assert a["iscrowd"] == 0
            im = images[a["image_id"]]
            seg = a["segmentation"]
            assert seg["size"] == [im["height"], im["width"]]
            assert isinstance(seg["counts"], str)
            assert isinstance(a["area"], int) and a["area"] > 0
            assert len(a["bbox"]) == 4 and all(isinstance(x, (int, float)) for x in a["bbox"])
    # images of an object are all in its split, the one dataset.json names
    for name, splits in objects.items():
        assert splits == {manifest["split"][name]}
    return manifest


def test_coco_files_follow_the_schema(data):
    manifest = check_coco_schema(data.det)
    assert manifest["options"]["min_area_fraction"] == 1 / 4096
    # 75/25 by object within each category: of two objects, one trains and one tests
    by_cat = {}
    for name, split in manifest["split"].items():
        by_cat.setdefault(model_cat(os.path.join(data.tree, name)), []).append(split)
    assert sorted(by_cat) == sorted(CATEGORIES.split(","))
    assert all(sorted(s) == ["test", "train"] for s in by_cat.values())
    n_images = sum(len(vision.load_coco(os.path.join(data.det, "instances_%s.json" % s))
                       ["images"]) for s in ("train", "test"))
    assert n_images == 6 * VIEWS


def check_masks(root, objects_root):
    """Masks against the instance pictures, boxes, areas, the threshold, the labels (from the
    object folders under objects_root); returns the number of annotations."""
    manifest = read_json(os.path.join(root, "dataset.json"))
    names = category_names(root)
    annotated = 0
    for split, image, folder, view, anns in detection_views(root):
        instance = png(os.path.join(folder, view["instances_png"]))
        assert instance.shape == (image["height"], image["width"])
        min_pixels = manifest["options"]["min_area_fraction"] * instance.size
        # the COCO annotations are the view's instances, in order
        assert len(anns) == len(view["instances"])
        assert set(np.unique(instance)) - {0} == {i["instance"] for i in view["instances"]}
        for a, inst in zip(anns, view["instances"]):
            assert a["segmentation"] == inst["segmentation"]
            assert names[a["category_id"]] == inst["category"]
            mask = vision.decode_rle(a["segmentation"]).astype(bool)
            np.testing.assert_array_equal(mask, instance == inst["instance"])
            rows, cols = np.nonzero(mask)
            x0, y0 = cols.min(), rows.min()
            assert a["bbox"] == [x0, y0, cols.max() - x0 + 1, rows.max() - y0 + 1]
            assert a["area"] == mask.sum() == vision.rle_area(a["segmentation"]) == inst["area"]
            assert a["area"] >= min_pixels
            annotated += 1
        # labels: "<meta.json model_cat>/<semantics.txt label>" of the annotated link
        obj = os.path.join(objects_root, image["object"])
        lines, cat = semantics(obj), model_cat(obj)
        assert read_json(os.path.join(folder, "views.json"))["category"] == cat
        for inst in view["instances"]:
            label = lines[inst["link"]][1]
            assert inst["label"] == label and inst["category"] == cat + "/" + label
    return annotated


def test_masks_match_the_instance_pictures_and_semantics(data):
    assert check_masks(data.det, data.tree) > 6 * VIEWS  # a few parts per view
    # the categories are exactly the labelled links of the tree's objects
    expected = set()
    for name in os.listdir(data.tree):
        obj = os.path.join(data.tree, name)
        expected |= {model_cat(obj) + "/" + label for _, label in semantics(obj).values()}
    assert set(category_names(data.det).values()) == expected


class Rerender:
    """An object loaded in partsim with a camera like the dataset's: renders a view again from
    the joint positions and camera pose its files record."""

    def __init__(self, folder, manifest):
        self.scene = partsim.Scene()
        self.art = self.scene.create_partnet_mobility_loader().load(folder)
        size = manifest["options"]["size"]
        self.camera = self.scene.add_camera(
            "check", size, size, math.radians(manifest["options"]["fovy_degrees"]), 0.01, 100.0)
        self.link_of = {e.id: self.art.get_link(e.link_index).get_name()
                        for e in self.scene.get_render_entities()
                        if e.is_link and e.articulation_id == self.art.get_id()}

    def render(self, qpos, camera):
        """(link name per pixel, '' for none; depth in metres) of a view."""
        self.art.set_qpos(np.array(qpos))
        self.camera.set_pose(partsim.Pose(camera["pose"]["p"], camera["pose"]["q"]))
        self.scene.update_render()
        self.camera.take_picture(["Segmentation", "Position"])
        np.testing.assert_array_equal(self.camera.get_intrinsic_matrix(), camera["K"])
        np.testing.assert_array_equal(self.camera.get_extrinsic_matrix(), camera["extrinsic"])
        ids = np.array(self.camera.get_picture("Segmentation"))[..., 1]
        links = np.array([self.link_of.get(int(i), "") for i in ids.ravel()]).reshape(ids.shape)
        return links, np.array(self.camera.get_depth())


def test_views_render_again_to_the_same_masks_and_depth(data):
    """The files against a new rendering in partsim of the recorded joint positions and camera
    pose: every labelled link seen by at least the threshold's pixels, and only those, is
    annotated, with the pixels where the link projects; the depth is the rendered one; the
    motion mask is the target link's pixels."""
    det_manifest = read_json(os.path.join(data.det, "dataset.json"))
    threshold = det_manifest["options"]["min_area_fraction"] * SIZE * SIZE
    renderers = {}

    def renderer(name, manifest):
        if name not in renderers:
            renderers[name] = Rerender(os.path.join(data.tree, name), manifest)
        return renderers[name]

    for _, image, folder, view, _ in detection_views(data.det):
        labelled = semantics(os.path.join(data.tree, image["object"]))
        links, depth = renderer(image["object"], det_manifest).render(view["qpos"],
                                                                      view["camera"])
        np.testing.assert_array_equal(depth, np.load(os.path.join(folder, view["depth_npy"])))
        instance = png(os.path.join(folder, view["instances_png"]))
        annotated = {i["link"]: i["instance"] for i in view["instances"]}
        for link in set(links.ravel()) - {""}:
            pixels = links == link
            if link in labelled and pixels.sum() >= threshold:
                np.testing.assert_array_equal(instance == annotated[link], pixels)
            else:
                assert link not in annotated
        assert set(annotated) <= set(links.ravel())
    mot_manifest = read_json(os.path.join(data.mot, "dataset.json"))
    for _, s in motion_samples(data.mot):
        links, depth = renderer(s["object"], mot_manifest).render(s["qpos"], s["camera"])
        np.testing.assert_array_equal(depth, np.load(os.path.join(data.mot, s["depth_npy"])))
        np.testing.assert_array_equal(png(os.path.join(data.mot, s["mask"])) > 0,
                                      links == s["link"])


def test_depth_png_is_the_npy_in_rounded_millimetres(data):
    pairs = [(os.path.join(f, v["depth"]), os.path.join(f, v["depth_npy"]))
             for _, _, f, v, _ in detection_views(data.det)]
    for split in ("train", "test"):
        for s in read_json(os.path.join(data.mot, "motion_%s.json" % split))["samples"]:
            pairs.append((os.path.join(data.mot, s["depth"]), os.path.join(data.mot,
                                                                          s["depth_npy"])))
    for png_path, npy_path in pairs:
        depth = np.load(npy_path)
        assert depth.dtype == np.float32 and depth.shape == (SIZE, SIZE)
        mm = np.where(depth > 0, np.minimum(np.floor(depth.astype(np.float64) * 1000 + 0.5),
                                            65535), 0)
        np.testing.assert_array_equal(png(png_path), mm.astype(np.uint16))
        assert (depth > 0).any() and (depth == 0).any()


def test_point_clouds_project_back_to_their_pixels(data):
    names = category_names(data.det)
    cat_id = {n: i for i, n in names.items()}
    for _, image, folder, view, anns in detection_views(data.det):
        with np.load(os.path.join(folder, view["cloud"])) as z:
            xyz, rgb, inst, label = z["xyz"], z["rgb"], z["instance"], z["label"]
        depth = np.load(os.path.join(folder, view["depth_npy"]))
        instance = png(os.path.join(folder, view["instances_png"]))
        colour = png(os.path.join(folder, view["rgb"]))
        rows, cols = np.nonzero(depth > 0)  # row-major, the cloud's order
        assert xyz.shape == (len(rows), 3) and xyz.dtype == np.float32
        K = np.array(view["camera"]["K"])
        p = xyz.astype(np.float64)
        u = K[0, 0] * p[:, 0] / p[:, 2] + K[0, 2]
        v = K[1, 1] * p[:, 1] / p[:, 2] + K[1, 2]
        # OpenCV frame: z forward, the pixel centres at integer coordinates
        assert np.abs(u - cols).max() < 0.02 and np.abs(v - rows).max() < 0.02
        np.testing.assert_allclose(p[:, 2], depth[rows, cols], rtol=1e-5)
        np.testing.assert_array_equal(rgb, colour[rows, cols])
        np.testing.assert_array_equal(inst, instance[rows, cols])
        number_to_cat = {i["instance"]: cat_id[i["category"]] for i in view["instances"]}
        np.testing.assert_array_equal(label, [number_to_cat.get(i, 0) for i in inst])


def test_detection_loader_returns_the_files(data):
    names = category_names(data.det)
    for split in ("train", "test"):
        ds = vision.DetectionDataset(data.det, split)
        coco = read_json(os.path.join(data.det, "instances_%s.json" % split))
        assert len(ds) == len(coco["images"]) and ds.categories == coco["categories"]
        assert ds.category_names == names
        by_id = {im["id"]: im for im in coco["images"]}
        for k in range(len(ds)):
            item = ds[k]
            image = by_id[item["image_id"]]
            assert image == coco["images"][k]
            folder = os.path.join(data.det, "objects", image["object"])
            view = read_json(os.path.join(folder, "views.json"))["views"][image["view"]]
            assert item["object"] == image["object"] and item["view"] == image["view"]
            assert item["rgb_path"] == os.path.join(data.det, image["file_name"])
            assert item["rgb"].dtype == np.uint8 and item["rgb"].shape == (SIZE, SIZE, 3)
            np.testing.assert_array_equal(item["rgb"], png(item["rgb_path"]))
            assert item["depth"].dtype == np.float32
            np.testing.assert_array_equal(item["depth"],
                                          np.load(os.path.join(folder, view["depth_npy"])))
            assert item["instance"].dtype == np.uint16
            np.testing.assert_array_equal(item["instance"],
                                          png(os.path.join(folder, view["instances_png"])))
            np.testing.assert_array_equal(png(item["depth_png_path"]),
                                          png(os.path.join(folder, view["depth"])))
            anns = [a for a in coco["annotations"] if a["image_id"] == image["id"]]
            n = len(anns)
            assert item["masks"].shape == (n, SIZE, SIZE) and item["masks"].dtype == bool
            for j, inst in enumerate(view["instances"]):
                np.testing.assert_array_equal(item["masks"][j],
                                              item["instance"] == inst["instance"])
            assert item["labels"].dtype == np.int64
            assert item["labels"].tolist() == [a["category_id"] for a in anns]
            assert item["boxes"].shape == (n, 4)
            assert item["boxes"].tolist() == [a["bbox"] for a in anns]
            assert item["areas"].tolist() == [a["area"] for a in anns]
            assert item["annotation_ids"].tolist() == [a["id"] for a in anns]
            assert item["K"].shape == (3, 3) and item["extrinsic"].shape == (3, 4)
            assert item["K"].tolist() == view["camera"]["K"]
            assert item["extrinsic"].tolist() == view["camera"]["extrinsic"]
            assert item["qpos"].tolist() == view["qpos"]
            cloud = ds.point_cloud(k)
            with np.load(os.path.join(folder, view["cloud"])) as z:
                for key in ("xyz", "rgb", "instance", "label"):
                    np.testing.assert_array_equal(cloud[key], z[key])
        with pytest.raises(IndexError):
            ds[len(ds)]
    with pytest.raises(ValueError, match="split"):
        vision.DetectionDataset(data.det, "val")
    with pytest.raises(FileNotFoundError, match="instances_train.json"):
        vision.DetectionDataset(data.mot)
    assert vision.load_coco(os.path.join(data.det, "instances_test.json")) == read_json(
        os.path.join(data.det, "instances_test.json"))


def test_evaluate_detection_of_the_ground_truth_is_perfect(data):
    for split in ("train", "test"):
        gt = os.path.join(data.det, "instances_%s.json" % split)
        coco = read_json(gt)
        results = [{"image_id": a["image_id"], "category_id": a["category_id"],
                    "segmentation": a["segmentation"], "score": 1.0}
                   for a in coco["annotations"]]
        e = vision.evaluate_detection(gt, results)
        assert e.map == 1.0
        assert all(c.ap == 1.0 for c in e.categories if c.present)
        assert vision.evaluate_detection(gt, []).map == 0.0


# --- motion ------------------------------------------------------------------------------------

def targets(folder, words=("door", "drawer")):
    """{link name: 'hinge' or 'slider'} of an object's motion targets, from semantics.txt: the
    parts whose label contains one of `words` (by default the paper's doors and drawers) and
    that move on a hinge or a slider (also one that turns as it slides, "slider+")."""
    out = {}
    for link, (joint, label) in semantics(folder).items():
        if not any(w in label for w in words):
            continue
        if joint == "hinge":
            out[link] = "hinge"
        elif joint in ("slider", "slider+"):
            out[link] = "slider"
    return out


def check_motion_sample(root, s, art, joint, slider_range, min_area_fraction):
    """A motion sample of dataset `root` against `joint`, the joint of its part's motion, of
    `art` (moved to the sample's joint positions): the label vector m, the axis in the camera
    frame (sign included), the state and the pivot from the part's visible pixels."""
    art.set_qpos(np.array(s["qpos"]))
    X_WJ = joint.get_global_pose().to_transformation_matrix()
    ext = np.array(s["camera"]["extrinsic"])
    R, t = ext[:, :3], ext[:, 3]
    axis = R @ X_WJ[:3, 0]
    axis /= np.linalg.norm(axis)
    origin = R @ X_WJ[:3, 3] + t
    m = np.array(s["m"])
    assert m.shape == (13,)
    q = s["qpos"][joint.get_dof_index()]
    lower = np.asarray(joint.get_limits()).reshape(2)[0]
    assert s["state"] == pytest.approx(q - lower, abs=1e-12)
    if s["type"] == "hinge":
        assert m[:2].tolist() == [1, 0]
        np.testing.assert_allclose(m[5:8], axis, atol=1e-9)  # sign included
        assert not m[8:11].any() and m[12] == 0
        pivot = m[2:5]
        off = (pivot - origin) - axis * axis.dot(pivot - origin)
        assert np.linalg.norm(off) < 1e-4
        assert m[11] == pytest.approx((q - lower) / (2 * math.pi), abs=1e-12)
    else:
        assert m[:2].tolist() == [0, 1]
        np.testing.assert_allclose(m[8:11], axis, atol=1e-9)
        assert not m[2:8].any() and m[11] == 0
        assert m[12] == pytest.approx((q - lower) / slider_range, abs=1e-12)
        assert 0 <= m[12] <= 1
    np.testing.assert_allclose(s["axis"], axis, atol=1e-9)
    # the pivot: the point of the axis nearest the centroid of the part's visible points
    depth = np.load(os.path.join(root, s["depth_npy"]))
    mask = png(os.path.join(root, s["mask"])) > 0
    rows, cols = np.nonzero(mask & (depth > 0))
    K = np.array(s["camera"]["K"])
    z = depth[rows, cols].astype(np.float64)
    pts = np.stack([(cols - K[0, 2]) * z / K[0, 0], (rows - K[1, 2]) * z / K[1, 1], z], 1)
    c = pts.mean(0)
    np.testing.assert_allclose(s["pivot"], origin + axis * axis.dot(c - origin), atol=1e-4)
    assert mask.sum() >= min_area_fraction * mask.size


def test_motion_labels_agree_with_the_joints(data):
    manifest = read_json(os.path.join(data.mot, "dataset.json"))
    slider_range = manifest["slider_range"]
    objects = {}  # name -> articulation, one scene each
    largest_drawer = 0.0
    for name in sorted(os.listdir(data.tree)):
        folder = os.path.join(data.tree, name)
        scene = partsim.Scene()
        art = scene.create_partnet_mobility_loader().load(folder)
        objects[name] = (scene, art)
        for link, kind in targets(folder).items():
            if kind == "slider":
                joint = art.get_joint(art.find_link_by_name(link).get_index())
                lo, hi = np.asarray(joint.get_limits()).reshape(2)
                largest_drawer = max(largest_drawer, hi - lo)
    # the slider normalisation is the largest drawer range of the dataset
    assert slider_range == pytest.approx(largest_drawer, rel=1e-12) and slider_range > 0
    # objects without doors or drawers (the faucets) are left out
    with_targets = {n for n in objects if targets(os.path.join(data.tree, n))}
    assert set(manifest["split"]) == with_targets
    samples = motion_samples(data.mot)
    counts = {}
    for split, s in samples:
        assert manifest["split"][s["object"]] == split
        assert read_json(os.path.join(data.mot, "motion_%s.json" % split))["slider_range"] == \
            slider_range
        folder = os.path.join(data.tree, s["object"])
        assert targets(folder)[s["link"]] == s["type"]
        assert s["label"] == semantics(folder)[s["link"]][1]
        assert s["category"] == model_cat(folder)
        counts[(s["object"], s["link"])] = counts.get((s["object"], s["link"]), 0) + 1
        _, art = objects[s["object"]]
        joint = art.get_joint(art.find_link_by_name(s["link"]).get_index())
        check_motion_sample(data.mot, s, art, joint, slider_range,
                            manifest["options"]["min_area_fraction"])
    assert {k[0] for k in counts} == with_targets
    assert all(1 <= n <= VIEWS for n in counts.values())
    assert {s["type"] for _, s in samples} == {"hinge", "slider"}


def test_motion_loader_returns_the_files(data):
    for split in ("train", "test"):
        ds = vision.MotionDataset(data.mot, split)
        doc = read_json(os.path.join(data.mot, "motion_%s.json" % split))
        assert len(ds) == len(doc["samples"]) and ds.slider_range == doc["slider_range"]
        for k, s in enumerate(doc["samples"]):
            item = ds[k]
            assert item["sample_id"] == s["sample_id"] and item["type"] == s["type"]
            assert item["m"].dtype == np.float64 and item["m"].tolist() == s["m"]
            np.testing.assert_array_equal(item["rgb"], png(os.path.join(data.mot, s["rgb"])))
            np.testing.assert_array_equal(item["depth"],
                                          np.load(os.path.join(data.mot, s["depth_npy"])))
            assert item["mask"].dtype == bool
            np.testing.assert_array_equal(item["mask"],
                                          png(os.path.join(data.mot, s["mask"])) > 0)
            assert item["K"].tolist() == s["camera"]["K"]
            assert item["extrinsic"].tolist() == s["camera"]["extrinsic"]
            assert item["qpos"].tolist() == s["qpos"]
    with pytest.raises(FileNotFoundError, match="motion_train.json"):
        vision.MotionDataset(data.det)


def test_evaluate_motion_of_the_ground_truth_is_perfect(data):
    for split in ("train", "test"):
        gt = os.path.join(data.mot, "motion_%s.json" % split)
        doc = read_json(gt)
        e = vision.evaluate_motion(gt, {"samples": [{"sample_id": s["sample_id"], "m": s["m"]}
                                                    for s in doc["samples"]]})
        assert e.hinges + e.sliders == len(doc["samples"])
        if e.hinges:
            assert e.hinge_accuracy == 1.0
            assert e.hinge_origin_error == pytest.approx(0, abs=1e-12)
            assert e.hinge_axis_error == pytest.approx(0, abs=1e-5)
            assert e.door_error == 0.0
        if e.sliders:
            assert e.slider_accuracy == 1.0
            assert e.slider_axis_error == pytest.approx(0, abs=1e-5)
            assert e.drawer_error == 0.0


# --- torch and missing packages ----------------------------------------------------------------

def test_torch_datasets(data):
    torch = require("torch", "python3-torch (scripts/setup.sh)")
    det = vision.DetectionDataset(data.det, "train")
    tds = det.torch()
    assert isinstance(tds, torch.utils.data.Dataset) and len(tds) == len(det)
    image, target = tds[0]
    item = det[0]
    assert image.dtype == torch.float32 and tuple(image.shape) == (3, SIZE, SIZE)
    np.testing.assert_allclose(image.numpy(), item["rgb"].transpose(2, 0, 1) / 255.0, atol=1e-6)
    x, y, w, h = item["boxes"].T
    np.testing.assert_array_equal(target["boxes"].numpy(), np.stack([x, y, x + w, y + h], 1))
    assert target["boxes"].dtype == torch.float32 and target["labels"].dtype == torch.int64
    assert target["labels"].tolist() == item["labels"].tolist()
    assert target["masks"].dtype == torch.uint8
    np.testing.assert_array_equal(target["masks"].numpy(), item["masks"].astype(np.uint8))
    assert target["image_id"].tolist() == [item["image_id"]]
    images, targets = next(iter(torch.utils.data.DataLoader(
        tds, batch_size=2, collate_fn=lambda b: tuple(zip(*b)))))
    assert len(images) == len(targets) == 2 and targets[1]["image_id"].item() == det[1]["image_id"]

    mot = vision.MotionDataset(data.mot, "train")
    tm = mot.torch()
    x, m = tm[0]
    item = mot[0]
    assert x.dtype == torch.float32 and tuple(x.shape) == (5, SIZE, SIZE)
    np.testing.assert_allclose(x[:3].numpy(), item["rgb"].transpose(2, 0, 1) / 255.0, atol=1e-6)
    np.testing.assert_array_equal(x[3].numpy(), item["depth"])
    np.testing.assert_array_equal(x[4].numpy(), item["mask"].astype(np.float32))
    np.testing.assert_allclose(m.numpy(), item["m"], rtol=1e-6, atol=1e-7)
    batch_x, batch_m = next(iter(torch.utils.data.DataLoader(tm, batch_size=2)))
    assert tuple(batch_x.shape) == (2, 5, SIZE, SIZE) and tuple(batch_m.shape) == (2, 13)
    # a transform sees and replaces the pair
    tt = mot.torch(transform=lambda x, m: (x[:3], m[:2]))
    assert tuple(tt[0][0].shape) == (3, SIZE, SIZE) and tuple(tt[0][1].shape) == (2,)


def test_without_torch_and_pil(data, monkeypatch):
    monkeypatch.setitem(sys.modules, "torch", None)  # import torch raises ImportError
    with pytest.raises(ImportError, match="needs PyTorch"):
        vision.DetectionDataset(data.det).torch()
    with pytest.raises(ImportError, match="needs PyTorch"):
        vision.MotionDataset(data.mot).torch()
    # a fresh interpreter where neither PIL nor torch imports: partsim imports, the files load
    # up to the pictures, which name PIL
    code = ("import sys; sys.modules['PIL'] = None; sys.modules['torch'] = None\n"
            "sys.path.insert(0, %r)\n"
            "import partsim, partsim.vision as v\n"
            "d = v.DetectionDataset(%r)\n"
            "assert len(d) > 0 and d.categories\n"
            "try:\n    d[0]\nexcept ImportError as e:\n    print('ImportError', e)\n"
            % (os.path.abspath(PYTHON_DIR), data.det))
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert "ImportError" in result.stdout and "PIL" in result.stdout


# --- the real PartNet-Mobility bottle ----------------------------------------------------------

def test_real_bottle_detection_dataset(bottle, tmp_path):
    check_coco_schema(bottle)
    cat = model_cat(REAL_BOTTLE)
    assert cat == "Bottle"
    names = category_names(bottle)
    assert names and all(n.startswith(cat + "/") for n in names.values())
    assert set(names.values()) == {cat + "/" + label
                                   for _, label in semantics(REAL_BOTTLE).values()}
    assert check_masks(bottle, os.path.dirname(REAL_BOTTLE)) > 0
    ds = vision.DetectionDataset(bottle, "train")
    assert len(ds) == 3 and len(vision.DetectionDataset(bottle, "test")) == 0
    item = ds[0]
    assert item["category"] == cat and len(item["labels"]) == len(item["masks"]) > 0
    # no door nor drawer: the motion dataset of the paper's parts is refused, saying why
    refused = run_cli("vision", "motion-dataset", "--dataset", REAL_BOTTLE, "--out",
                      tmp_path / "mot", "--views", 1, "--size", SIZE, "--quiet", ok=False)
    assert refused.returncode == 1
    assert "label contains 'door' or 'drawer'" in refused.stderr and "--parts" in refused.stderr


def test_real_bottle_motion_dataset_of_its_screw_cap(tmp_path):
    """--parts lid: the bottle's cap slides along its axis as it turns (mobility_v2.json's
    "slider" that "rotates"; in mobility.urdf a prismatic joint on link_0_helper and a
    continuous one on link_0). It is a slider sample whose axis, state and range are the
    helper's prismatic joint's."""
    if not os.path.isdir(REAL_BOTTLE):
        pytest.skip("no ../shared/realdata")
    assert targets(REAL_BOTTLE) == {} and targets(REAL_BOTTLE, ["lid"]) == {"link_0": "slider"}
    out = str(tmp_path / "mot")
    run_cli("vision", "motion-dataset", "--dataset", REAL_BOTTLE, "--out", out, "--views", 4,
            "--size", SIZE, "--parts", "lid", "--quiet")
    manifest = read_json(os.path.join(out, "dataset.json"))
    assert manifest["options"]["parts"] == ["lid"]
    scene = partsim.Scene()
    art = scene.create_partnet_mobility_loader().load(REAL_BOTTLE)
    helper = art.get_joint(art.find_link_by_name("link_0_helper").get_index())
    lo, hi = np.asarray(helper.get_limits()).reshape(2)
    assert manifest["slider_range"] == pytest.approx(hi - lo, rel=1e-12) and hi > lo
    samples = motion_samples(out)
    assert 1 <= len(samples) <= 4
    for _, s in samples:
        assert s["link"] == "link_0" and s["type"] == "slider"
        assert s["label"] == semantics(REAL_BOTTLE)["link_0"][1] and s["category"] == "Bottle"
        check_motion_sample(out, s, art, helper, manifest["slider_range"],
                            manifest["options"]["min_area_fraction"])
    # the cap's turn is drawn too: the continuous joint on link_0 varies between samples
    turn = art.get_joint(art.find_link_by_name("link_0").get_index()).get_dof_index()
    assert len({round(s["qpos"][turn], 9) for _, s in samples}) == len(samples)
    # a word no label holds is refused by name; so is a word with a space
    refused = run_cli("vision", "motion-dataset", "--dataset", REAL_BOTTLE, "--out",
                      tmp_path / "none", "--views", 1, "--size", SIZE, "--parts", "knob,button",
                      "--quiet", ok=False)
    assert refused.returncode == 1 and "'knob' or 'button'" in refused.stderr
    refused = run_cli("vision", "motion-dataset", "--dataset", REAL_BOTTLE, "--out",
                      tmp_path / "bad", "--parts", "lid,,door", ok=False)
    assert refused.returncode == 2 and "--parts" in refused.stderr
