#!/usr/bin/env python3
"""partsim.distributed's cost: the same list of units in one process, and as Ray tasks with 1
and 2 workers on this machine, side by side in one run.

Workloads (each a list cut into --units shards):
  generate   `partsim assets generate` of --objects objects (short units: the per-task
             overhead dominates)
  dataset    `partsim vision detection-dataset` over those objects, --views views each at
             --size pixels (rendering: the work dominates)
For each workload and repetition: (a) the command as one process (`--shard 0/1`, the plain
run), (b) the same units one after another in this process (partsim.distributed's local
executor: the cost of cutting and merging), (c) Ray with one worker (a head with 1 CPU) and
(d) with two (2 CPUs), the cluster started on 127.0.0.1 by this program before the clock
starts. Prints the medians, the speed-ups over (a), the per-unit overhead (c - a) / units, and
the measured cost per unit of work (s per object, s per view) that the estimates in
bench/README.md scale up.

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
    per = max(1, objects // 4)
    gen = ["assets", "generate", "--categories",
           "StorageFurniture,Table,Microwave,Refrigerator", "--per-category", str(per),
           "--seed", "5"]
    data = ["vision", "detection-dataset", "--dataset", os.path.join(root, "objects"),
            "--views", str(views), "--size", str(size), "--quiet"]
    return {"generate": (gen, 4 * per, "object"), "dataset": (data, 4 * per * views, "view")}


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
                for name, (argv, _, _) in work.items():
                    for rep in range(a.reps):
                        out = os.path.join(root, f"out-{rep}")

                        def plain():
                            subprocess.run([cli] + argv + ["--out", out], check=True,
                                           capture_output=True)

                        def units(ex):
                            return lambda: dist.run(argv + ["--out", out], units=a.units,
                                                    executor=ex, quiet=True, cli=cli)

                        runs = {label: units(executor)} if label else {
                            "one process": plain,
                            "units, one after another": units(dist.LocalExecutor())}
                        for what, fn in runs.items():
                            shutil.rmtree(out, ignore_errors=True)
                            times.setdefault((name, what), []).append(timed(fn))
            finally:
                if executor:
                    executor.shutdown()
                if cluster:
                    cluster.shutdown()
    finally:
        shutil.rmtree(root, ignore_errors=True)
    order = ("one process", "units, one after another", "ray, 1 worker", "ray, 2 workers")
    print(f"{a.units} units, median of {a.reps}; speed-up = one process / this")
    print("| workload | run | seconds | speed-up |\n|---|---|---:|---:|")
    for name, (argv, count, unit) in work.items():
        base = statistics.median(times[(name, "one process")])
        for what in order:
            t = statistics.median(times[(name, what)])
            print(f"| {name} ({count} {unit}s) | {what} | {t:.2f} | {base / t:.2f} |")
    for name, (argv, count, unit) in work.items():
        base = statistics.median(times[(name, "one process")])
        one = statistics.median(times[(name, "ray, 1 worker")])
        print(f"{name}: {base / count:.3f} s per {unit} in one process; Ray's overhead "
              f"{(one - base) / a.units:.2f} s per unit (1 worker)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
