"""The vision evaluators against independent computations written here in numpy: COCO's mask AP
(COCOeval's steps as pycocotools writes them, with its 2.2e-16 in the precision's denominator and
the detections on crowd regions kept in the lists) on random synthetic ground truth and results,
through the command line and through partsim.vision; the RLE helpers against pixel masks; the
motion metrics against their definitions."""

import json
import math
import os
import subprocess

import numpy as np
import pytest

import partsim
import partsim.vision as vision
from conftest import PYTHON_DIR

CLI = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                                 "partsim"))
CATEGORIES = {3: "Cabinet/rotation_door", 7: "Cabinet/drawer", 11: "Table/drawer",
              12: "Table/wheel", 20: "Faucet/spout", 21: "Fan/rotor"}
NO_TRUTH = 12     # detections only: absent
ONLY_CROWD = 21   # crowd regions only: absent


# --- RLE, written from COCO's format description -------------------------------------------

def rle_counts(mask):
    """Run lengths of a (h, w) mask in column-major order, background first."""
    flat = np.asarray(mask, dtype=bool).flatten(order="F")
    if flat.size == 0:
        return [0]
    edges = np.flatnonzero(flat[1:] != flat[:-1]) + 1
    runs = np.diff(np.concatenate([[0], edges, [flat.size]])).tolist()
    return ([0] + runs) if flat[0] else runs


def compress(counts):
    """COCO's compressed text: from the fourth count on, the difference to the count two before;
    5 bits a character from '0', bit 5 a continuation, bit 4 of the last the sign."""
    out = []
    for i, c in enumerate(counts):
        x = c - counts[i - 2] if i > 2 else c
        more = True
        while more:
            ch = x & 0x1F
            x >>= 5
            more = (x != -1) if ch & 0x10 else (x != 0)
            out.append(chr((ch | 0x20 if more else ch) + 48))
    return "".join(out)


def rle(mask, compressed):
    counts = rle_counts(mask)
    return {"size": list(mask.shape), "counts": compress(counts) if compressed else counts}


def mask_iou(det, gt, crowd):
    inter = np.logical_and(det, gt).sum()
    union = det.sum() if crowd else np.logical_or(det, gt).sum()
    return inter / union if union else 0.0


# --- COCOeval at one IoU threshold, all areas --------------------------------------------------

def coco_mask_ap(images, truths, detections, iou_threshold=0.5, max_dets=100):
    """{category id: AP or None (no ground truth)} and the mAP. truths: (image, category, mask,
    crowd); detections: (image, category, mask, score), in file order."""
    recall_thresholds = np.linspace(0.0, 1.0, int(np.round((1.0 - 0.0) / 0.01)) + 1)
    aps = {}
    for cat in CATEGORIES:
        scores, matched, ignored, npig = [], [], [], 0
        for img in sorted(images):
            g = [t for t in truths if t[0] == img and t[1] == cat]
            g = sorted(g, key=lambda t: t[3])  # crowd last, stable
            d = [x for x in detections if x[0] == img and x[1] == cat]
            d = sorted(d, key=lambda x: -x[3])[:max_dets]  # stable
            npig += sum(1 for t in g if not t[3])
            gtm = [False] * len(g)
            for det in d:
                iou, m = min(iou_threshold, 1 - 1e-10), -1
                for j, t in enumerate(g):
                    if gtm[j] and not t[3]:
                        continue
                    if m > -1 and not g[m][3] and t[3]:
                        break
                    o = mask_iou(det[2], t[2], t[3])
                    if o < iou:
                        continue
                    iou, m = o, j
                if m > -1:
                    gtm[m] = True
                scores.append(det[3])
                matched.append(m > -1)
                ignored.append(m > -1 and g[m][3])
        if npig == 0:
            aps[cat] = None
            continue
        order = np.argsort(-np.array(scores, dtype=float), kind="mergesort")
        dtm = np.array(matched, dtype=bool)[order]
        dtig = np.array(ignored, dtype=bool)[order]
        tp = np.cumsum(dtm & ~dtig).astype(float)
        fp = np.cumsum(~dtm & ~dtig).astype(float)
        rc = tp / npig
        pr = (tp / (fp + tp + np.spacing(1))).tolist()
        for i in range(len(pr) - 1, 0, -1):
            if pr[i] > pr[i - 1]:
                pr[i - 1] = pr[i]
        q = np.zeros(len(recall_thresholds))
        for ri, pi in enumerate(np.searchsorted(rc, recall_thresholds, side="left")):
            if pi < len(pr):
                q[ri] = pr[pi]
        aps[cat] = float(np.mean(q))
    present = [a for a in aps.values() if a is not None]
    return aps, (float(np.mean(present)) if present else None)


# --- synthetic data ----------------------------------------------------------------------------

def random_mask(rng, h, w):
    """A rectangle, sometimes with pixels flipped."""
    m = np.zeros((h, w), dtype=bool)
    x0, x1 = sorted(rng.integers(0, w + 1, 2))
    y0, y1 = sorted(rng.integers(0, h + 1, 2))
    m[y0:y1 + 1, x0:x1 + 1] = True
    if rng.random() < 0.3:
        m ^= rng.random((h, w)) < 0.05
    return m


def perturbed(rng, mask):
    """The mask shifted by up to `shift` pixels each way, some pixels flipped: IoUs from 0 to 1,
    many near 0.5 for small masks."""
    shift = int(rng.integers(0, 3))
    m = np.roll(mask, (int(rng.integers(-shift, shift + 1)), int(rng.integers(-shift, shift + 1))),
                axis=(0, 1))
    if rng.random() < 0.5:
        m = m ^ (rng.random(m.shape) < 0.03)
    return m


def synthetic(seed):
    """(ground-truth dict, results list, images, truths, detections) for coco_mask_ap."""
    rng = np.random.default_rng(seed)
    image_ids = [int(i) for i in rng.permutation(40)[:12] + 1]
    images = {i: (int(rng.integers(8, 40)), int(rng.integers(8, 40))) for i in image_ids}
    truths, detections = [], []
    score = lambda: float(np.round(rng.random(), 1))  # noqa: E731  (ties on purpose)
    for img, (h, w) in images.items():
        for cat in CATEGORIES:
            if cat == NO_TRUTH:
                count = 0
            else:
                count = int(rng.integers(0, 4))
            for _ in range(count):
                crowd = cat == ONLY_CROWD or rng.random() < 0.1
                m = random_mask(rng, h, w)
                truths.append((img, cat, m, crowd))
                if rng.random() < 0.8:
                    detections.append((img, cat, perturbed(rng, m), score()))
                if rng.random() < 0.2:  # a duplicate
                    detections.append((img, cat, perturbed(rng, m), score()))
            for _ in range(int(rng.integers(0, 2))):  # false positives, empty masks among them
                m = random_mask(rng, h, w) if rng.random() < 0.9 else np.zeros((h, w), bool)
                detections.append((img, cat, m, score()))
    # one image and category with more than 100 detections: the lowest scores are cut
    img = image_ids[0]
    h, w = images[img]
    for k in range(110):
        detections.append((img, 3, random_mask(rng, h, w), float(rng.random())))
    order = rng.permutation(len(detections))
    detections = [detections[i] for i in order]

    gt = {"images": [{"id": i, "width": w, "height": h} for i, (h, w) in images.items()],
          "categories": [{"id": c, "name": n} for c, n in CATEGORIES.items()],
          "annotations": [{"id": k + 1, "image_id": t[0], "category_id": t[1],
                           "segmentation": rle(t[2], compressed=k % 2 == 0),
                           "iscrowd": int(t[3])} for k, t in enumerate(truths)]}
    results = [{"image_id": d[0], "category_id": d[1], "segmentation": rle(d[2], True),
                "score": d[3]} for d in detections]
    return gt, results, images, truths, detections


# --- tests -------------------------------------------------------------------------------------

@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_command_line_ap_equals_numpy_cocoeval(tmp_path, seed):
    gt, results, images, truths, detections = synthetic(seed)
    (tmp_path / "gt.json").write_text(json.dumps(gt))
    (tmp_path / "results.json").write_text(json.dumps(results))
    out = subprocess.run([CLI, "vision", "evaluate-detection", "--gt", str(tmp_path / "gt.json"),
                          "--results", str(tmp_path / "results.json"), "--out",
                          str(tmp_path / "report")], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    metrics = json.loads((tmp_path / "report" / "metrics.json").read_text())

    expected, expected_map = coco_mask_ap(images, truths, detections)
    got = {c["id"]: c for c in metrics["categories"]}
    assert set(got) == set(CATEGORIES)
    for cat, ap in expected.items():
        if ap is None:
            assert got[cat]["ap"] is None and not got[cat]["present"], CATEGORIES[cat]
        else:
            assert abs(got[cat]["ap"] - ap) < 1e-9, (CATEGORIES[cat], got[cat]["ap"], ap)
    assert abs(metrics["map"] - expected_map) < 1e-9
    assert sorted(metrics["absent"]) == sorted([CATEGORIES[NO_TRUTH], CATEGORIES[ONLY_CROWD]])
    # the cases are not trivial: APs strictly between 0 and 1, and the cut at 100 bites
    assert any(0.05 < ap < 0.95 for ap in expected.values() if ap is not None)
    assert got[3]["detections"] > got[3]["true_positives"] + got[3]["false_positives"] + \
        got[3]["ignored"]
    # the printed table and the CSV carry the same mAP
    assert ("**%.1f**" % (100 * expected_map)) in out.stdout
    csv_all = (tmp_path / "report" / "table.csv").read_text().splitlines()[-1]
    assert csv_all.startswith("All,") and abs(float(csv_all.split(",")[-1]) -
                                              100 * expected_map) < 1e-3


def test_binding_accepts_dicts_and_paths(tmp_path):
    gt, results, images, truths, detections = synthetic(5)
    expected, expected_map = coco_mask_ap(images, truths, detections)
    from_dicts = vision.evaluate_detection(gt, results)
    (tmp_path / "gt.json").write_text(json.dumps(gt))
    (tmp_path / "results.json").write_text(json.dumps(results))
    from_paths = vision.evaluate_detection(str(tmp_path / "gt.json"), tmp_path / "results.json")
    for e in (from_dicts, from_paths):
        assert abs(e.map - expected_map) < 1e-9
        for c in e.categories:
            if expected[c.category_id] is None:
                assert not c.present and math.isnan(c.ap)
            else:
                assert abs(c.ap - expected[c.category_id]) < 1e-9
    assert json.loads(from_dicts.to_json()) == json.loads(from_paths.to_json())
    assert from_dicts.to_markdown().startswith("| object category |")
    # a stricter threshold: numpy agrees there too
    strict = vision.evaluate_detection(gt, results, iou_threshold=0.75, max_detections=5)
    expected_strict, map_strict = coco_mask_ap(images, truths, detections, 0.75, 5)
    assert abs(strict.map - map_strict) < 1e-9
    assert strict.iou_threshold == 0.75 and strict.max_detections == 5
    # numpy numbers in the dicts are fine; bad entries name themselves
    results[0]["score"] = np.float32(0.5)
    vision.evaluate_detection(gt, results)
    results[0]["image_id"] = 1000
    with pytest.raises(partsim.PartsimError, match=r"\[0\]: image_id 1000 is not an image"):
        vision.evaluate_detection(gt, results)


def test_rle_helpers_agree_with_pixels():
    rng = np.random.default_rng(9)
    for h, w in [(1, 1), (5, 7), (13, 4), (0, 3), (32, 32)]:
        for density in (0.0, 0.3, 1.0):
            m = rng.random((h, w)) < density
            r = vision.encode_mask(m)
            assert r == {"size": [h, w], "counts": compress(rle_counts(m))}
            assert vision.encode_mask(m, compressed=False)["counts"] == rle_counts(m)
            back = vision.decode_rle(r)
            assert back.dtype == np.uint8 and back.shape == (h, w)
            assert np.array_equal(back.astype(bool), m)
            assert vision.rle_area(r) == m.sum()
            assert vision.decompress_rle_counts(r["counts"]) == rle_counts(m)
            if m.any():
                ys, xs = np.nonzero(m)
                assert vision.rle_bbox(r) == [xs.min(), ys.min(), xs.max() - xs.min() + 1,
                                              ys.max() - ys.min() + 1]
            other = rng.random((h, w)) < 0.5
            o = vision.encode_mask(other, compressed=False)
            assert vision.rle_iou(r, o) == pytest.approx(mask_iou(m, other, False), abs=1e-15)
            assert vision.rle_iou(r, o, crowd=True) == pytest.approx(mask_iou(m, other, True),
                                                                     abs=1e-15)
    # bytes counts, as pycocotools gives them
    assert vision.rle_area({"size": [2, 2], "counts": b"13"}) == 3
    with pytest.raises(partsim.PartsimError, match="add up to 3 pixels"):
        vision.decode_rle({"size": [2, 2], "counts": [1, 2]})
    with pytest.raises(partsim.PartsimError, match="missing key 'counts'"):
        vision.rle_area({"size": [2, 2]})


def random_unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def test_motion_metrics_equal_their_definitions(tmp_path):
    rng = np.random.default_rng(4)
    slider_range = 0.7
    gt, pred = [], []
    for k in range(40):
        hinge = k % 3 != 0
        m = np.zeros(13)
        m[0:2] = (1, 0) if hinge else (0, 1)
        m[2:5] = rng.normal(size=3)
        m[5:8] = random_unit(rng) * rng.uniform(0.5, 2)
        m[8:11] = random_unit(rng)
        m[11:13] = rng.random(2)
        p = m + rng.normal(scale=0.2, size=13)
        p[0:2] = rng.random(2)
        gt.append({"sample_id": "s%d" % k if k % 2 else k, "m": m.tolist()})
        pred.append({"sample_id": "s%d" % k if k % 2 else k, "m": p.tolist()})
    pred.reverse()

    def angle(a, b):
        c = abs(np.dot(a, b)) / np.linalg.norm(a) / np.linalg.norm(b)
        return math.degrees(math.acos(min(1.0, c)))

    by_id = {str(p["sample_id"]): np.array(p["m"]) for p in pred}
    rows = [(np.array(g["m"]), by_id[str(g["sample_id"])]) for g in gt]
    hinges = [(g, p) for g, p in rows if g[0] == 1]
    sliders = [(g, p) for g, p in rows if g[1] == 1]
    d_true = [g[5:8] / np.linalg.norm(g[5:8]) for g, _ in hinges]
    expected = {
        "hinge_accuracy": np.mean([p[0] >= p[1] for _, p in hinges]),
        "slider_accuracy": np.mean([p[0] < p[1] for _, p in sliders]),
        "hinge_origin_error": np.mean([np.linalg.norm(np.cross(p[2:5] - g[2:5], d))
                                       for (g, p), d in zip(hinges, d_true)]),
        "hinge_axis_error": np.mean([angle(p[5:8], g[5:8]) for g, p in hinges]),
        "slider_axis_error": np.mean([angle(p[8:11], g[8:11]) for g, p in sliders]),
        "door_error": np.mean([abs(p[11] - g[11]) * 360 for g, p in hinges]),
        "drawer_error": np.mean([abs(p[12] - g[12]) * slider_range for g, p in sliders]),
    }
    e = vision.evaluate_motion({"slider_range": slider_range, "samples": gt}, {"samples": pred})
    assert (e.hinges, e.sliders) == (len(hinges), len(sliders))
    for name, value in expected.items():
        assert getattr(e, name) == pytest.approx(value, abs=1e-9), name
    assert 0 < e.hinge_accuracy < 1  # the random types are sometimes wrong

    # the command line reads the same from files
    (tmp_path / "gt.json").write_text(json.dumps({"slider_range": slider_range, "samples": gt}))
    (tmp_path / "pred.json").write_text(json.dumps({"samples": pred}))
    out = subprocess.run([CLI, "vision", "evaluate-motion", "--gt", str(tmp_path / "gt.json"),
                          "--predictions", str(tmp_path / "pred.json"), "--out",
                          str(tmp_path / "m")], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    metrics = json.loads((tmp_path / "m" / "metrics.json").read_text())
    assert metrics["hinge_axis_error_deg"] == pytest.approx(expected["hinge_axis_error"], abs=1e-9)
    assert metrics["drawer_error_m"] == pytest.approx(expected["drawer_error"], abs=1e-9)
    with pytest.raises(partsim.PartsimError, match="no prediction for sample_id 0"):
        vision.evaluate_motion({"slider_range": 1, "samples": gt}, {"samples": pred[:-2]})


def test_package_exports_the_vision_module():
    assert partsim.vision is vision
    assert vision.evaluate_detection.__module__ == "partsim.vision"
    assert vision.DetectionEvaluation.__module__ == "partsim.vision"
    assert set(vision.__all__) == {n for n in dir(vision) if not n.startswith("_")}
