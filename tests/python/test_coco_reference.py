"""partsim's detection evaluation held against pycocotools' COCOeval, the reference
implementation of COCO's metrics, on the same files.

The ground truth is a detection dataset made by partsim itself (`partsim assets generate` and
`partsim vision detection-dataset`: rendered cabinets, refrigerators and faucets with RLE masks of
their parts), made harder here: two parts turned into crowd regions (one written with
uncompressed counts, as COCO's own crowd annotations are), a category with detections but no
ground truth and one with crowd regions only. The results are made from the ground-truth masks,
decoded with pycocotools: shifted, grown or shrunk masks (IoUs across the thresholds), missed
parts, duplicates, detections on crowd regions, false positives in other places and categories,
an empty mask, scores with ties within and across images, and more than 100 detections in one
image and category.

partsim evaluates masks only (polygons and box results are refused, see docs/vision.md), so
the comparison is COCOeval with iouType "segm", area range "all":
- `partsim vision evaluate-detection` (the CLI's metrics.json): AP at IoU 0.5 per category and
  the mAP, against COCOeval's precision at IoU 0.5 and its AP50;
- partsim.vision.evaluate_detection at each of COCOeval's ten IoU thresholds and its three
  maxDets: per-category AP and recall (true positives over ground truths) against COCOeval's
  precision and recall arrays, and their means against COCOeval's summary (AP, AP50, AP75,
  AR1, AR10, AR100); which categories are absent (no ground truth) agrees too.
"""

import contextlib
import copy
import io
import json
import os
import subprocess

import numpy as np
import pytest

import partsim.vision as vision
from conftest import PYTHON_DIR

# pycocotools is in requirements.lock: the comparison runs wherever the suite does (no skip)
import pycocotools.mask as mask_utils  # noqa: E402
from pycocotools.coco import COCO  # noqa: E402
from pycocotools.cocoeval import COCOeval  # noqa: E402

CLI = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                                 "partsim"))
TOL = 1e-9          # COCOeval adds 2.2e-16 to the precision's denominator; nothing else differs
NO_TRUTH = 901      # a category with detections and no ground truth: absent
ONLY_CROWD = 902    # a category whose ground truth is crowd regions only: absent
MAX_DETS = (1, 10, 100)


def run_cli(*args):
    result = subprocess.run([CLI] + [str(a) for a in args], capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0, "partsim %s: %s%s" % (
        " ".join(map(str, args)), result.stdout, result.stderr)
    return result


# --- masks, with numpy and pycocotools only ----------------------------------------------------

def decode(segmentation, h, w):
    rle = segmentation
    if isinstance(rle["counts"], list):
        rle = mask_utils.frPyObjects(rle, h, w)
    return mask_utils.decode(rle).astype(bool)


def encode(mask):
    rle = mask_utils.encode(np.asfortranarray(mask.astype(np.uint8)))
    return {"size": [int(s) for s in rle["size"]], "counts": rle["counts"].decode("ascii")}


def uncompressed(mask):
    """COCO's uncompressed RLE: run lengths down the columns, background first."""
    flat = mask.flatten(order="F")
    edges = np.flatnonzero(flat[1:] != flat[:-1]) + 1
    runs = np.diff(np.concatenate([[0], edges, [flat.size]])).tolist()
    return {"size": list(mask.shape), "counts": ([0] + runs) if flat[0] else runs}


def shifted(mask, dy, dx):
    out = np.zeros_like(mask)
    h, w = mask.shape
    out[max(dy, 0):h + min(dy, 0), max(dx, 0):w + min(dx, 0)] = \
        mask[max(-dy, 0):h + min(-dy, 0), max(-dx, 0):w + min(-dx, 0)]
    return out


def grown(mask, k):
    """Dilated (k > 0) or eroded (k < 0) by |k| pixels with a 3x3 cross."""
    for _ in range(abs(k)):
        moved = [shifted(mask, dy, dx) for dy, dx in ((1, 0), (-1, 0), (0, 1), (0, -1))]
        mask = np.logical_or.reduce([mask] + moved) if k > 0 else \
            np.logical_and.reduce([mask] + moved)
    return mask


def jittered(rng, mask):
    """The mask moved by up to 2 pixels each way and grown or shrunk by up to 1: IoUs from
    about 0.3 to 1 on these small parts."""
    m = shifted(mask, int(rng.integers(-2, 3)), int(rng.integers(-2, 3)))
    return grown(m, int(rng.integers(-1, 2)))


def box_mask(rng, h, w):
    m = np.zeros((h, w), bool)
    y0, x0 = rng.integers(0, h - 4), rng.integers(0, w - 4)
    m[y0:y0 + rng.integers(2, h // 3), x0:x0 + rng.integers(2, w // 3)] = True
    return m


# --- the files ---------------------------------------------------------------------------------

def make_files(gt_path, out):
    """Writes out/gt.json (the dataset's ground truth, with crowd regions and two extra
    categories) and out/results.json (imperfect detections); returns their paths."""
    rng = np.random.default_rng(7)
    gt = json.loads(open(gt_path).read())
    images = {im["id"]: im for im in gt["images"]}
    anns = gt["annotations"]
    assert len(images) >= 4 and len(anns) >= 15 and len(gt["categories"]) >= 4
    masks = {a["id"]: decode(a["segmentation"], images[a["image_id"]]["height"],
                             images[a["image_id"]]["width"]) for a in anns}

    # two parts become crowd regions, one with uncompressed counts
    ordinary = [a for a in anns if a["area"] >= 40]
    crowd = [ordinary[3], ordinary[len(ordinary) // 2]]
    for a in crowd:
        a["iscrowd"] = 1
    crowd[0]["segmentation"] = uncompressed(masks[crowd[0]["id"]])
    # a category with detections only, and one with a crowd region only
    gt["categories"] += [{"id": NO_TRUTH, "name": "Ghost/handle", "supercategory": "Ghost"},
                         {"id": ONLY_CROWD, "name": "Ghost/lid", "supercategory": "Ghost"}]
    next_id = max(a["id"] for a in anns) + 1
    crowd_only = copy.deepcopy(ordinary[1])
    crowd_only.update(id=next_id, category_id=ONLY_CROWD, iscrowd=1)
    anns.append(crowd_only)
    masks[next_id] = masks[ordinary[1]["id"]]

    def score():
        return round(float(rng.uniform(0.05, 1.0)), 2)  # two decimals: ties

    results = []

    def detect(image_id, category_id, mask, s=None):
        results.append({"image_id": image_id, "category_id": category_id,
                        "segmentation": encode(mask), "score": score() if s is None else s})

    for a in anns:
        m, im, cat = masks[a["id"]], a["image_id"], a["category_id"]
        if a["iscrowd"]:
            # detections inside a crowd region: ignored, not false positives
            for _ in range(int(rng.integers(1, 4))):
                detect(im, cat, grown(m, -1) & box_mask(rng, *m.shape) | grown(m, -2))
            continue
        if rng.random() < 0.15:
            continue  # missed
        detect(im, cat, m if rng.random() < 0.2 else jittered(rng, m))
        if rng.random() < 0.3:  # a duplicate, further off
            detect(im, cat, jittered(rng, jittered(rng, m)))
        if rng.random() < 0.15:  # the part taken for another category
            other = gt["categories"][int(rng.integers(len(gt["categories"])))]["id"]
            detect(im, other, jittered(rng, m))
    image_ids = sorted(images)
    for _ in range(25):  # false positives anywhere
        im = images[image_ids[int(rng.integers(len(image_ids)))]]
        cat = gt["categories"][int(rng.integers(len(gt["categories"])))]["id"]
        detect(im["id"], cat, box_mask(rng, im["height"], im["width"]))
    first = anns[0]
    h, w = images[first["image_id"]]["height"], images[first["image_id"]]["width"]
    # an empty mask, and more than 100 detections of one image and category, the true one
    # among the low scores
    detect(first["image_id"], first["category_id"], np.zeros((h, w), bool))
    for k in range(110):
        detect(first["image_id"], first["category_id"], box_mask(rng, h, w), 0.5 + k / 1000)
    detect(first["image_id"], first["category_id"], masks[first["id"]], 0.3)
    # equal scores across images, in an order that is not the images'
    for a in reversed(anns[-6:]):
        if not a["iscrowd"]:
            detect(a["image_id"], a["category_id"], jittered(rng, masks[a["id"]]), 0.77)

    rng.shuffle(results)
    out.mkdir(exist_ok=True)
    (out / "gt.json").write_text(json.dumps(gt))
    (out / "results.json").write_text(json.dumps(results))
    return str(out / "gt.json"), str(out / "results.json")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    base = tmp_path_factory.mktemp("coco_reference")
    tree, det = base / "tree", base / "det"
    run_cli("assets", "generate", "--out", tree, "--categories",
            "StorageFurniture,Refrigerator,Faucet", "--per-category", 2, "--seed", 3)
    run_cli("vision", "detection-dataset", "--dataset", tree, "--out", det, "--views", 3,
            "--size", 96, "--seed", 4, "--no-point-clouds", "--quiet")
    return make_files(det / "instances_test.json", base)


# --- COCOeval ----------------------------------------------------------------------------------

class Reference:
    """COCOeval's segm evaluation of the files, default parameters."""

    def __init__(self, gt_path, results_path):
        with contextlib.redirect_stdout(io.StringIO()):
            coco_gt = COCO(gt_path)
            coco_dt = coco_gt.loadRes(results_path)
            e = COCOeval(coco_gt, coco_dt, "segm")
            e.evaluate()
            e.accumulate()
            e.summarize()
        p = e.params
        assert p.areaRngLbl[0] == "all" and list(p.maxDets) == list(MAX_DETS)
        self.iou_thresholds = [float(t) for t in p.iouThrs]
        self.cat_ids = list(p.catIds)
        self.precision = e.eval["precision"][:, :, :, 0, :]  # (T, R, K, M), all areas
        self.recall = e.eval["recall"][:, :, 0, :]           # (T, K, M)
        self.stats = e.stats

    def ap(self, t, category_id, m=2):
        """AP of one category at threshold index t and maxDets index m; None when COCOeval has
        no ground truth for it (-1 in its arrays)."""
        p = self.precision[t, :, self.cat_ids.index(category_id), m]
        return None if np.all(p == -1) else float(np.mean(p))

    def recall_of(self, t, category_id, m=2):
        r = self.recall[t, self.cat_ids.index(category_id), m]
        return None if r == -1 else float(r)


@pytest.fixture(scope="module")
def reference(files):
    return Reference(*files)


def partsim_scores(evaluation):
    """{category id: (ap, recall) or None when absent} of a partsim DetectionEvaluation."""
    return {c.category_id: (c.ap, c.true_positives / c.ground_truths) if c.present else None
            for c in evaluation.categories}


# --- the comparisons ---------------------------------------------------------------------------

def test_the_data_exercises_the_protocol(files, reference):
    """The comparison means something only if the data reaches every branch."""
    e = vision.evaluate_detection(*files)
    cats = {c.category_id: c for c in e.categories}
    assert cats[NO_TRUTH].detections > 0 and not cats[NO_TRUTH].present
    assert cats[ONLY_CROWD].crowd == 1 and not cats[ONLY_CROWD].present
    assert sum(c.crowd for c in e.categories) == 3 and sum(c.ignored for c in e.categories) >= 3
    assert sum(c.false_positives for c in e.categories) >= 30
    assert sum(c.true_positives for c in e.categories) < sum(c.ground_truths
                                                             for c in e.categories)
    assert e.present >= 4
    # APs spread out at IoU 0.5 and 0.75, neither perfect nor zero, and falling with the IoU
    aps = reference.precision[:, :, :, 2]
    for t in (0, 5):
        per_cat = [np.mean(aps[t, :, k]) for k in range(aps.shape[2]) if aps[t, 0, k] != -1]
        assert len(set(per_cat)) >= 4 and 0.3 < max(per_cat) < 1, (t, per_cat)
    assert reference.stats[1] > reference.stats[2] > reference.stats[0] * 0.5 > 0


def test_command_line_ap50_equals_cocoeval(files, reference, tmp_path):
    gt, results = files
    run_cli("vision", "evaluate-detection", "--gt", gt, "--results", results,
            "--out", tmp_path)
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["iou_threshold"] == 0.5 and metrics["max_detections"] == 100
    t50 = reference.iou_thresholds.index(0.5)
    for c in metrics["categories"]:
        want = reference.ap(t50, c["id"])
        if want is None:
            assert not c["present"] and c["ap"] is None, c["name"]
        else:
            assert c["present"] and c["ap"] == pytest.approx(want, abs=TOL), c["name"]
    # COCOeval's AP50 is the mean over the categories with ground truth
    assert metrics["map"] == pytest.approx(reference.stats[1], abs=TOL)
    assert metrics["present"] == sum(reference.ap(t50, k) is not None
                                     for k in reference.cat_ids)


def test_every_threshold_and_max_detections_equal_cocoeval(files, reference):
    gt, results = files
    gt_doc, results_doc = json.load(open(gt)), json.load(open(results))
    means = {}  # (t, m) -> (mean AP, mean recall) over the present categories
    for t, threshold in enumerate(reference.iou_thresholds):
        for m, max_dets in enumerate(MAX_DETS):
            # paths and dicts alike
            source = (gt, results) if (t + m) % 2 else (gt_doc, results_doc)
            e = vision.evaluate_detection(*source, iou_threshold=threshold,
                                          max_detections=max_dets)
            scores = partsim_scores(e)
            assert set(scores) == set(reference.cat_ids)
            for k, got in scores.items():
                want_ap, want_recall = reference.ap(t, k, m), reference.recall_of(t, k, m)
                where = "IoU %.2f, maxDets %d, category %d" % (threshold, max_dets, k)
                if want_ap is None:
                    assert got is None and want_recall is None, where
                    continue
                assert got is not None, where
                assert got[0] == pytest.approx(want_ap, abs=TOL), where
                assert got[1] == pytest.approx(want_recall, abs=TOL), where
            present = [v for v in scores.values() if v is not None]
            assert e.map == pytest.approx(np.mean([v[0] for v in present]), abs=1e-12)
            means[t, m] = (e.map, np.mean([v[1] for v in present]))
    # COCOeval's summary: AP, AP50, AP75 at maxDets 100; AR at maxDets 1, 10, 100
    thresholds = range(len(reference.iou_thresholds))
    t50, t75 = reference.iou_thresholds.index(0.5), reference.iou_thresholds.index(0.75)
    s = reference.stats
    assert np.mean([means[t, 2][0] for t in thresholds]) == pytest.approx(s[0], abs=TOL)
    assert means[t50, 2][0] == pytest.approx(s[1], abs=TOL)
    assert means[t75, 2][0] == pytest.approx(s[2], abs=TOL)
    for m in range(3):
        assert np.mean([means[t, m][1] for t in thresholds]) == pytest.approx(s[6 + m],
                                                                            abs=TOL), m
