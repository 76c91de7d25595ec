"""The paper's Tables 1 and 2 beside the scores of partsim's runs.

Table 1 (movable-part detection, AP % at mask IoU 0.5) has a column per part of four object
categories; partsim's datasets name categories ``<object category>/<part label>``, and
:data:`TABLE1_COLUMNS` says which names fill which column (the paper's "Cabinet" is
PartNet-Mobility's StorageFurniture). Its last column is the mAP over every category of the
run's test split, as the paper's "All" is over all of its categories. Table 2 (motion
attributes) has one row per run.
"""

from __future__ import annotations

import json
import math
import os

# (object category in the paper, in partsim's datasets, part in the paper, labels in partsim's)
TABLE1_COLUMNS = (
    ("Cabinet", "StorageFurniture", "rot. door", ("rotation_door",)),
    ("Cabinet", "StorageFurniture", "body", ("furniture_body",)),
    ("Cabinet", "StorageFurniture", "drawer", ("drawer",)),
    ("Cabinet", "StorageFurniture", "trans. door", ("translation_door",)),
    ("Table", "Table", "drawer", ("drawer",)),
    ("Table", "Table", "body", ("furniture_body", "table_body", "board")),
    ("Table", "Table", "wheel", ("wheel",)),
    ("Table", "Table", "door", ("rotation_door", "door")),
    ("Table", "Table", "caster", ("caster",)),
    ("Faucet", "Faucet", "switch", ("switch",)),
    ("Faucet", "Faucet", "base", ("faucet_base", "base")),
    ("Faucet", "Faucet", "spout", ("spout",)),
    ("Fan", "Fan", "rotor", ("rotor",)),
    ("Fan", "Fan", "frame", ("fan_frame", "frame")),
)

# the paper's Table 1: (algorithm, inputs) -> 14 APs in TABLE1_COLUMNS' order, then the mAP
PAPER_TABLE1 = {
    ("Mask R-CNN", "RGB"): (62.0, 94.2, 66.4, 27.7, 54.3, 88.0, 3.4, 6.3, 0.0, 52.5, 47.9, 99.7,
                            54.4, 67.5, 53.0),
    ("Mask R-CNN", "RGB-D"): (61.7, 93.0, 63.0, 26.3, 58.6, 89.9, 1.4, 13.2, 0.0, 52.1, 55.8,
                              98.9, 39.4, 67.4, 52.8),
    ("PartNet-InsSeg", "XYZ"): (20.6, 65.9, 35.1, 9.8, 15.7, 71.3, 1.7, 1.0, 0.0, 34.4, 55.9,
                                64.2, 50.9, 74.8, 36.1),
    ("PartNet-InsSeg", "XYZRGB"): (17.4, 64.3, 23.6, 5.0, 16.4, 81.8, 1.3, 2.0, 1.0, 29.9, 64.1,
                                   78.0, 42.0, 63.5, 37.1),
}

# Table 2's columns: (header, metrics.json key, scale, digits)
TABLE2_COLUMNS = (
    ("H acc.", "hinge_accuracy", 100.0, "{:.1f}%"),
    ("S acc.", "slider_accuracy", 100.0, "{:.1f}%"),
    ("H_o err (m)", "hinge_origin_error_m", 1.0, "{:.3f}"),
    ("H_a err (°)", "hinge_axis_error_deg", 1.0, "{:.1f}"),
    ("S_a err (°)", "slider_axis_error_deg", 1.0, "{:.2f}"),
    ("door err (°)", "door_error_deg", 1.0, "{:.1f}"),
    ("drawer err (m)", "drawer_error_m", 1.0, "{:.4f}"),
)

PAPER_TABLE2 = {
    ("ResNet50", "RGB-D"): (95.5, 95.5, 0.168, 18.9, 6.35, 14.4, 0.0645),
    ("PointNet++", "RGB-pc"): (95.4, 95.5, 0.195, 18.5, 7.75, 20.8, 0.0918),
}

ALGORITHM = {"maskrcnn": "Mask R-CNN", "insseg": "PartNet-InsSeg", "motion-resnet": "ResNet50",
             "motion-pointnet": "PointNet++"}
INPUTS = {"rgb": "RGB", "rgbd": "RGB-D", "xyz": "XYZ", "xyzrgb": "XYZRGB"}


def _load(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def run_scores(run, split="test"):
    """(run.json, eval-<split>/metrics.json) of run folder ``run``; raises FileNotFoundError
    naming the missing file (a run not yet predicted)."""
    run = os.fspath(run)
    doc = _load(os.path.join(run, "run.json"))
    metrics_path = os.path.join(run, f"eval-{split}", "metrics.json")
    if not os.path.exists(metrics_path):
        raise FileNotFoundError(f"'{metrics_path}' is missing: run `partsim vision predict "
                                f"{run} --split {split}` first")
    return doc, _load(metrics_path)


def table1_row(metrics):
    """The 14 APs (percent, None where the run's test split has no such part) and the mAP of
    a detection run's metrics.json."""
    ap = {}
    for c in metrics.get("categories", []):
        if c.get("present") and c.get("ap") is not None:
            ap[c["name"]] = 100.0 * c["ap"]
    row = []
    for _, category, _, labels in TABLE1_COLUMNS:
        row.append(next((ap[f"{category}/{label}"] for label in labels
                         if f"{category}/{label}" in ap), None))
    m = metrics.get("map")
    row.append(None if m is None else 100.0 * m)
    return row


def table2_row(metrics):
    """Table 2's seven numbers of a motion run's metrics.json (None where absent)."""
    row = []
    for _, key, scale, _ in TABLE2_COLUMNS:
        v = metrics.get(key)
        row.append(None if v is None or (isinstance(v, float) and math.isnan(v)) else v * scale)
    return row


def _cell(v, fmt="{:.1f}"):
    return "–" if v is None else fmt.format(v)


def _label(doc, run):
    o = doc.get("options", {})
    return (f"{ALGORITHM.get(doc.get('baseline'), doc.get('baseline'))}",
            f"{INPUTS.get(o.get('input'), o.get('input'))}",
            os.path.basename(os.path.abspath(os.fspath(run))))


def render(runs, split="test"):
    """Markdown: Table 1 for the detection runs and Table 2 for the motion runs among
    ``runs`` (folders), each with the paper's rows first."""
    detection, motion = [], []
    for run in runs:
        doc, metrics = run_scores(run, split)
        kind = "motion" if doc.get("baseline", "").startswith("motion-") else "detection"
        (motion if kind == "motion" else detection).append((run, doc, metrics))
    out = []
    if detection:
        head = ["algorithm", "inputs", "source"] + [
            f"{paper} {part}" for paper, _, part, _ in TABLE1_COLUMNS] + ["mAP"]
        out.append("Table 1: movable-part detection, AP (%) at mask IoU 0.5 "
                   f"(partsim's runs on their {split} split)\n")
        out.append("| " + " | ".join(head) + " |")
        out.append("|" + "---|" * 3 + "---:|" * (len(TABLE1_COLUMNS) + 1))
        for (alg, inputs), values in PAPER_TABLE1.items():
            out.append("| " + " | ".join([alg, inputs, "paper"] + [_cell(v) for v in values])
                       + " |")
        for run, doc, metrics in detection:
            alg, inputs, name = _label(doc, run)
            out.append("| " + " | ".join([alg, inputs, f"partsim `{name}`"]
                                         + [_cell(v) for v in table1_row(metrics)]) + " |")
        out.append("")
    if motion:
        head = ["algorithm", "setting", "source"] + [h for h, _, _, _ in TABLE2_COLUMNS]
        out.append(f"Table 2: motion attributes (partsim's runs on their {split} split)\n")
        out.append("| " + " | ".join(head) + " |")
        out.append("|" + "---|" * 3 + "---:|" * len(TABLE2_COLUMNS))
        for (alg, setting), values in PAPER_TABLE2.items():
            cells = [_cell(v, fmt if "%" not in fmt else "{:.1f}%")
                     for v, (_, _, _, fmt) in zip(values, TABLE2_COLUMNS)]
            out.append("| " + " | ".join([alg, setting, "paper"] + cells) + " |")
        for run, doc, metrics in motion:
            alg, inputs, name = _label(doc, run)
            setting = "RGB-D" if doc.get("baseline") == "motion-resnet" else "RGB-pc"
            cells = [_cell(v, fmt) for v, (_, _, _, fmt) in zip(table2_row(metrics),
                                                                 TABLE2_COLUMNS)]
            out.append("| " + " | ".join([alg, setting, f"partsim `{name}`"] + cells) + " |")
        out.append("")
    return "\n".join(out)
