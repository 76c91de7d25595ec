"""partsim.distributed on a real Ray cluster: a head and one more worker node started by the test
on 127.0.0.1, a small pipeline run through `partsim ... --ray ADDRESS` (generate 6 objects, check
them, a detection dataset of 2 views each, tasks evaluate on them, learn evaluate, a 2-run sweep
of a few hundred steps) whose outputs equal the single-process run byte for byte (timings aside),
and a worker killed with SIGKILL mid-run without a change in the outputs. The cluster is shut
down at the end of the module whatever the tests did."""

import csv
import io
import os
import signal
import subprocess
import time

import pytest

from conftest import PYTHON_DIR, require

ray = require("ray", "ray (requirements.lock)")
require("torch", "python3-torch (scripts/setup.sh)")

CLI = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                                 "partsim"))
# every address of the cluster on the loopback interface: Ray takes the machine's own address
# unless it believes it runs on one node; the second node is added by the test's process
LOOPBACK = {"RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0", "RAY_USAGE_STATS_ENABLED": "0"}
OBJECTS = ["--categories", "StorageFurniture,Table", "--per-category", "3", "--seed", "3"]
# a learning run small enough for the suite (as test_learn_protocol's)
TINY = ["--steps", "400", "--warmup-steps", "100", "--num-envs", "2", "--test-objects", "2",
        "--checkpoint-interval", "200", "--log-interval", "100", "--batch-size", "32",
        "--hidden", "32,32", "--max-episode-steps", "60", "--buffer-size", "5000"]
SWEEP = ["--tasks", "drawer", "--obs", "mobility", "--train-objects", "2", "--seeds", "0,1",
         "--episodes", "2"] + TINY


def partsim(*args, timeout=600, check=True):
    env = dict(os.environ, **LOOPBACK, PYTHONPATH=os.path.abspath(PYTHON_DIR))
    r = subprocess.run([CLI] + [str(a) for a in args], capture_output=True, text=True, env=env,
                       timeout=timeout)
    if check:
        assert r.returncode == 0, f"partsim {' '.join(map(str, args))}:\n{r.stdout}\n{r.stderr}"
    return r


def tree(root):
    """Every file under root: relative path -> bytes."""
    out = {}
    for folder, _, files in os.walk(root):
        for name in files:
            path = os.path.join(folder, name)
            with open(path, "rb") as f:
                out[os.path.relpath(path, root)] = f.read()
    return out


def assert_same_tree(a, b):
    ta, tb = tree(a), tree(b)
    assert sorted(ta) == sorted(tb), set(ta) ^ set(tb)
    differ = [k for k in ta if ta[k] != tb[k]]
    assert not differ, f"files differ: {differ[:5]}"


def episodes(path):
    """A tasks evaluate CSV without its timing column."""
    rows = list(csv.reader(io.StringIO(open(path, encoding="utf-8").read())))
    drop = rows[0].index("seconds")
    return [r[:drop] + r[drop + 1:] for r in rows]


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """A Ray head (1 CPU) and one more worker node (1 CPU) on 127.0.0.1; its address."""
    from ray.cluster_utils import Cluster

    saved = {k: os.environ.get(k) for k in LOOPBACK}
    os.environ.update(LOOPBACK)
    os.environ["PYTHONPATH"] = os.path.abspath(PYTHON_DIR)
    c = None
    try:
        # a small object store each: Ray's default is 30% of the memory, in /dev/shm
        store = 200 * 1024 * 1024
        c = Cluster(initialize_head=True, head_node_args={
            "num_cpus": 1, "include_dashboard": False, "node_ip_address": "127.0.0.1",
            "object_store_memory": store})
        c.add_node(num_cpus=1, node_ip_address="127.0.0.1", object_store_memory=store)
        c.wait_for_nodes()
        assert c.address.startswith("127.0.0.1:")
        yield c.address
    finally:
        if c is not None:
            c.shutdown()
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


@pytest.fixture(scope="module")
def single(tmp_path_factory):
    """The pipeline's generated objects, written by one process."""
    root = tmp_path_factory.mktemp("single")
    partsim("assets", "generate", "--out", root / "objects", *OBJECTS)
    return root


def test_generate_on_ray_equals_one_run(cluster, single, tmp_path):
    r = partsim("assets", "generate", "--out", tmp_path / "objects", *OBJECTS,
                "--ray", cluster, "--units", "4", "--state", tmp_path / "state")
    assert "4/4 units done" in r.stderr
    assert len(os.listdir(tmp_path / "objects")) == 6
    assert_same_tree(single / "objects", tmp_path / "objects")
    assert not os.path.exists(tmp_path / "state"), "the record of finished units stays"


def test_check_on_ray_equals_one_run(cluster, single, tmp_path):
    one = partsim("assets", "check", single / "objects", "--no-visibility", "--report",
                  tmp_path / "one.txt", "--results", tmp_path / "one.json", check=False)
    many = partsim("assets", "check", single / "objects", "--no-visibility", "--report",
                   tmp_path / "ray.txt", "--results", tmp_path / "ray.json", "--ray", cluster,
                   "--units", "3", check=False)
    assert one.returncode == many.returncode, many.stderr
    assert one.stdout == many.stdout
    assert "3/3 units done" in many.stderr
    for name in ("txt", "json"):
        assert (tmp_path / f"one.{name}").read_bytes() == (tmp_path / f"ray.{name}").read_bytes()


@pytest.mark.parametrize("shared", [False, True], ids=["sent-back", "shared"])
def test_detection_dataset_on_ray_equals_one_run(cluster, single, tmp_path, shared):
    args = ["vision", "detection-dataset", "--dataset", single / "objects", "--views", "2",
            "--size", "64"]
    partsim(*args, "--out", tmp_path / "one", "--quiet")
    # --shared: the workers write into the folder themselves; else the driver writes what
    # they send back; 8 units for 6 objects: some have nothing to do
    r = partsim(*args, "--out", tmp_path / "ray", "--ray", cluster, "--units", "8",
                *(["--shared"] if shared else []))
    assert "8/8 units done" in r.stderr
    assert_same_tree(tmp_path / "one", tmp_path / "ray")


def test_tasks_evaluate_on_ray_equals_one_run(cluster, single, tmp_path):
    args = ["tasks", "evaluate", "--dataset", single / "objects", "--count", "6",
            "--no-cameras"]
    one = partsim(*args, "--csv", tmp_path / "one.csv")
    many = partsim(*args, "--csv", tmp_path / "ray.csv", "--ray", cluster, "--units", "3")
    assert "3/3 units done" in many.stderr
    assert episodes(tmp_path / "one.csv") == episodes(tmp_path / "ray.csv")
    assert len(episodes(tmp_path / "one.csv")) > 1
    assert "succeeded" in one.stdout and one.stdout == many.stdout


def test_sweep_and_learn_evaluate_on_ray_equal_one_process(cluster, tmp_path):
    local = partsim("learn", "sweep", "--out", tmp_path / "local", *SWEEP)
    many = partsim("learn", "sweep", "--out", tmp_path / "ray", *SWEEP, "--ray", cluster)
    assert "2/2 units done" in many.stderr
    assert local.stdout == many.stdout and "| mobility-exp | train |" in many.stdout
    for run in ("drawer-mobility-n2-s0", "drawer-mobility-n2-s1"):
        for name in ("eval.json", "eval.csv"):
            assert (tmp_path / "local" / run / name).read_bytes() == \
                (tmp_path / "ray" / run / name).read_bytes(), (run, name)
    assert (tmp_path / "local" / "table.md").read_bytes() == \
        (tmp_path / "ray" / "table.md").read_bytes()
    # learn evaluate of one run in 3 units: the run's own eval files again
    run = tmp_path / "ray" / "drawer-mobility-n2-s1"
    before = {n: (run / n).read_bytes() for n in ("eval.json", "eval.csv")}
    for n in before:
        os.remove(run / n)
    r = partsim("learn", "evaluate", run, "--episodes", "2", "--ray", cluster, "--units", "3")
    assert "3/3 units done" in r.stderr
    assert {n: (run / n).read_bytes() for n in before} == before
    # run again: every training run and evaluation is found done
    again = partsim("learn", "sweep", "--out", tmp_path / "ray", *SWEEP, "--ray", cluster)
    assert "(2 done before, skipped)" in again.stderr and again.stdout == many.stdout


def assert_close(a, b, where="metrics"):
    """Equal JSON documents, numbers to 1e-5 (the units' batches differ from one pass's)."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and sorted(a) == sorted(b), where
        for k in a:
            assert_close(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            assert_close(x, y, f"{where}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert a == pytest.approx(b, rel=1e-5, abs=1e-6), where
    else:
        assert a == b, where


def test_vision_predict_on_ray_equals_one_pass(cluster, perception_data, tmp_path):
    """A perception run's prediction in 3 units (each `vision predict --shard i/3 --results`),
    merged and scored by the driver: the run's own predictions and scores."""
    import json

    import numpy as np

    run = tmp_path / "run"
    partsim("vision", "train", "motion-resnet", "--data", perception_data.mot, "--out", run,
            "--backbone", "resnet18", "--size", "32", "--epochs", "1", "--seed", "3", "--quiet")
    folder = run / "eval-test"
    whole = json.loads((folder / "predictions.json").read_text())
    metrics = json.loads((folder / "metrics.json").read_text())
    for name in ("predictions.json", "metrics.json", "table.md"):
        os.remove(folder / name)
    r = partsim("vision", "predict", run, "--ray", cluster, "--units", "3", "--state",
                tmp_path / "state")
    assert "3/3 units done" in r.stderr and "hinge_accuracy" in r.stdout
    merged = json.loads((folder / "predictions.json").read_text())
    assert [s["sample_id"] for s in merged["samples"]] == \
        [s["sample_id"] for s in whole["samples"]]
    for a, b in zip(merged["samples"], whole["samples"]):
        np.testing.assert_allclose(a["m"], b["m"], rtol=1e-5, atol=1e-6)
    assert_close(json.loads((folder / "metrics.json").read_text()), metrics)
    assert (folder / "table.md").exists() and not (tmp_path / "state").exists()


def test_a_worker_killed_mid_run_loses_nothing(cluster, single, tmp_path):
    args = ["tasks", "evaluate", "--dataset", single / "objects", "--count", "6",
            "--no-cameras"]
    partsim(*args, "--csv", tmp_path / "one.csv")
    env = dict(os.environ, **LOOPBACK, PYTHONPATH=os.path.abspath(PYTHON_DIR))
    driver = subprocess.Popen([CLI] + [str(a) for a in args] +
                              ["--csv", tmp_path / "ray.csv", "--ray", cluster, "--units", "6"],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    killed = None
    try:
        deadline = time.monotonic() + 120
        while killed is None and driver.poll() is None and time.monotonic() < deadline:
            for pid in os.listdir("/proc"):
                if not pid.isdigit():
                    continue
                try:
                    with open(f"/proc/{pid}/cmdline", "rb") as f:
                        title = f.read().decode(errors="replace")
                except OSError:
                    continue
                # a Ray worker while it runs a unit (its process title)
                if title.startswith("ray::partsim_unit_"):
                    os.kill(int(pid), signal.SIGKILL)
                    killed = title.strip("\0")
                    break
            time.sleep(0.05)
        out, err = driver.communicate(timeout=300)
    finally:
        if driver.poll() is None:
            driver.kill()
    assert killed, "no unit was seen running"
    assert driver.returncode == 0, err
    assert "worker lost" in err and "submitted again" in err, err
    assert "6/6 units done" in err
    assert episodes(tmp_path / "one.csv") == episodes(tmp_path / "ray.csv")


def test_bad_ray_command_lines_are_refused_by_name(tmp_path):
    r = partsim("assets", "generate", "--out", tmp_path / "d", "--shard", "0/2", "--ray",
                "auto", check=False)
    assert r.returncode == 2 and "leave --shard out" in r.stderr
    r = partsim("info", "--ray", "auto", check=False)
    assert r.returncode == 2 and "--ray runs assets generate" in r.stderr
    r = partsim("assets", "generate", "--out", tmp_path / "d", "--ray", "auto", "--units", "0",
                check=False)
    assert r.returncode == 2 and "--units wants an integer >= 1" in r.stderr
    r = partsim("assets", "generate", "--ray", "auto", check=False)
    assert r.returncode == 2 and "needs --out DIR" in r.stderr
    r = partsim("learn", "sweep", "--out", tmp_path / "s", "--tasks", "lid", "--steps", "10",
                check=False)
    assert r.returncode == 2 and "unknown task 'lid'" in r.stderr
