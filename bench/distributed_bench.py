#!/usr/bin/env python3
"""partsim.distributed's cost: the same list of units in one process, and as Ray tasks with 1
and 2 workers on this machine, side by side in one run.

Workloads (each a list cut into --units shards):
  generate   `partsim assets generate` of --objects objects (short units: the per-task
             overhead dominates)
  dataset    `partsim vision detection-dataset` over those objects, --views views each at
             --size pixels (rendering: the work dominates; llvmpipe renders on every core)
  evaluate   `partsim tasks evaluate --no-cameras` on those objects (physics on one thread)
For each workload and repetition: (a) the command as one process (the plain run), (b) the
same units one after another from this process (partsim.distributed's local executor: a
process per unit, and the merge), (c) Ray with one worker (a head with 1 CPU) and (d) with two
(2 CPUs), the units writing into --out themselves (--shared), and (e) with two, their outputs
sent back to the driver, which writes them; the cluster is started on 127.0.0.1 by this
program before the clock starts. Prints the medians, the speed-ups over (a), the overheads per unit ((b - a) / units: a process
of its own and the merge; (c - b) / units: Ray's task), and the cost per item of work (s per
object, s per view) that the estimates in bench/README.md scale up.

Usage: PYTHONPATH=build/python .venv/bin/python bench/distributed_bench.py [--reps 3]
       [--objects 16] [--units 8] [--views 4] [--size 128]
"""

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")  # loopback addresses only
os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")

import partsim.distributed as dist  # noqa: E402
from partsim import _cli  # noqa: E402


def workloads(root, objects, views, size):
    """name -> (the command, the option its output goes to, items, the item's name)."""
    per = max(1, objects // 4)
    gen = ["assets", "generate", "--categories",
           "StorageFurniture,Table,Microwave,Refrigerator", "--per-category", str(per),
           "--seed", "5"]
    data = ["vision", "detection-dataset", "--dataset", os.path.join(root, "objects"),
            "--views", str(views), "--size", str(size), "--quiet"]
    tasks = ["tasks", "evaluate", "--dataset", os.path.join(root, "objects"), "--count",
             str(4 * per), "--no-cameras"]
    return {"generate": (gen, "--out", 4 * per, "object"),
            "dataset": (data, "--out", 4 * per * views, "view"),
            "evaluate": (tasks, "--csv", None, "episode")}


def timed(fn):
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--objects", type=int, default=16)
    ap.add_argument("--units", type=int, default=8)
    ap.add_argument("--views", type=int, default=4)
    ap.add_argument("--size", type=int, default=128)
    a = ap.parse_args()
    from ray.cluster_utils import Cluster

    cli = _cli.find_cli()
    root = tempfile.mkdtemp(prefix="partsim-dist-bench-")
    work = workloads(root, a.objects, a.views, a.size)
    subprocess.run([cli] + work["generate"][0] + ["--out", os.path.join(root, "objects")],
                   check=True, capture_output=True)
    # the episodes: the objects with a drawer, as tasks evaluate finds them
    subprocess.run([cli] + work["evaluate"][0] + ["--csv", os.path.join(root, "e.csv")],
                   check=True, capture_output=True)
    with open(os.path.join(root, "e.csv"), encoding="utf-8") as f:
        episodes = sum(1 for line in f if line.strip() and not line.startswith("#")) - 1
    work["evaluate"] = work["evaluate"][:2] + (episodes, "episode")
    times = {}
    try:
        for label, cpus in (("ray, 1 worker", 1), ("ray, 2 workers", 2), (None, 0)):
            cluster = executor = None
            if label:
                cluster = Cluster(initialize_head=True, head_node_args={
                    "num_cpus": cpus, "include_dashboard": False,
                    "node_ip_address": "127.0.0.1"})
                executor = dist.RayExecutor(cluster.address)
            try:
                for name, (argv, flag, _, _) in work.items():
                    for rep in range(a.reps):
                        out = os.path.join(root, f"out-{rep}")

                        def plain():
                            subprocess.run([cli] + argv + [flag, out], check=True,
                                           capture_output=True)

                        def units(ex, shared=True):
                            return lambda: dist.run(argv + [flag, out], units=a.units,
                                                    executor=ex, quiet=True, cli=cli,
                                                    shared=shared)

                        if label is None:
                            runs = {"one process": plain,
                                    "units, one after another": units(dist.LocalExecutor())}
                        else:
                            runs = {label: units(executor)}
                            if cpus == 2 and flag == "--out":
                                runs[label + ", outputs sent back"] = units(executor, False)
                        for what, fn in runs.items():
                            shutil.rmtree(out, ignore_errors=True)
                            if os.path.isfile(out):
                                os.remove(out)
                            times.setdefault((name, what), []).append(timed(fn))
            finally:
                if executor:
                    executor.shutdown()
                if cluster:
                    cluster.shutdown()
    finally:
        shutil.rmtree(root, ignore_errors=True)
    order = ("one process", "units, one after another", "ray, 1 worker", "ray, 2 workers",
             "ray, 2 workers, outputs sent back")
    print(f"{a.units} units, median of {a.reps}; speed-up = one process / this; the units "
          "write into --out (--shared) but where it says sent back")
    print("| workload | run | seconds | speed-up |\n|---|---|---:|---:|")
    for name, (argv, flag, count, unit) in work.items():
        base = statistics.median(times[(name, "one process")])
        for what in order:
            if (name, what) not in times:
                continue
            t = statistics.median(times[(name, what)])
            print(f"| {name} ({count} {unit}s) | {what} | {t:.2f} | {base / t:.2f} |")
    for name, (argv, flag, count, unit) in work.items():
        base = statistics.median(times[(name, "one process")])
        local = statistics.median(times[(name, "units, one after another")])
        one = statistics.median(times[(name, "ray, 1 worker")])
        print(f"{name}: {base / count:.4f} s per {unit} in one process; per unit, "
              f"{(local - base) / a.units:.2f} s for a process of its own and the merge, "
              f"{(one - local) / a.units:.2f} s more as a Ray task")
    return 0


if __name__ == "__main__":
    sys.exit(main())
