"""bench/perception_gpu_check.py, the perception baselines' GPU check, on the CPU: `pack` bundles
the tiny benchmark's training items (with the real package), and `run` trains and times two of
the networks on the bundle in a Python that cannot import partsim's compiled module, as on a
GPU machine whose Python differs from the build's. A baseline whose batches or loss change
without the bundle following fails here, not on a lent GPU."""

import json
import os
import subprocess
import sys

from conftest import PYTHON_DIR, require

require("torch", "Debian's python3-torch")
require("torchvision", "Debian's python3-torchvision")

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(REPO, "bench", "perception_gpu_check.py")

# runs the check with partsim's compiled module and partsim.vision made unimportable
BLOCKED = """
import runpy, sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name in ("partsim._partsim", "partsim.vision"):
            raise ImportError("blocked by the test: " + name)
sys.meta_path.insert(0, Block())
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
"""


def test_pack_then_run_without_the_compiled_module(perception_data, tmp_path):
    bundle = str(tmp_path / "bundle")
    env = dict(os.environ, PARTSIM_PYTHON_DIR=PYTHON_DIR)
    r = subprocess.run([sys.executable, SCRIPT, "pack", "--detection", perception_data.det,
                        "--motion", perception_data.mot, "--out", bundle],
                       capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert os.path.exists(os.path.join(bundle, "bundle.json"))

    env = {k: v for k, v in os.environ.items() if k not in ("PARTSIM_PYTHON_DIR", "PYTHONPATH")}
    out = str(tmp_path / "result.json")
    r = subprocess.run([sys.executable, "-c", BLOCKED, SCRIPT, "run", "--bundle", bundle,
                        "--device", "cpu", "--baselines", "insseg,motion-resnet", "--size",
                        "32", "--batch-size", "2", "--batches", "1", "--train-steps", "12",
                        "--backbone", "resnet18", "--point-backbone", "small", "--points",
                        "256", "--out", out],
                       capture_output=True, text=True, env=env, timeout=600, cwd=str(tmp_path))
    assert r.returncode == 0, r.stdout + r.stderr
    assert "compiled module imported: no" in r.stdout
    with open(out) as f:
        doc = json.load(f)
    rows = {b["baseline"]: b for b in doc["baselines"]}
    assert sorted(rows) == ["insseg", "motion-resnet"]
    for row in rows.values():
        assert row["finite"] and row["train"]["items_per_s"] > 0, row
        assert row["forward"]["items_per_s"] > 0, row
        losses = row["training_run"]["losses"]
        assert len(losses) == 12 and all(abs(x) < 1e6 for x in losses), row
    assert doc["compiled_module_imported"] == [] and doc["all_finite"] is True
