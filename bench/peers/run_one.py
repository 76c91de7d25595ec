"""One measurement in its own process: builds one scene in one engine, steps it once untimed,
then times `steps` single steps (one call per step from Python, as a control loop does) and
prints a JSON line: steps/s of the wall clock, process CPU ms per step, and what the engine
reports at the end (joint positions, the robot's joint error, the boxes' mean height).

Usage (peers_bench.py runs it): python run_one.py ENGINE SCENE STEPS ASSET_DIR DT SLEEP(0|1)
"""

import importlib
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def main():
    engine, scene, steps, assets, dt, sleep = sys.argv[1:7]
    steps, dt = int(steps), float(dt)
    mod = importlib.import_module("engine_" + engine)
    t0 = time.perf_counter()
    step, finish = mod.build(scene, assets, dt, sleep == "1")
    build_s = time.perf_counter() - t0
    step()  # untimed: the first step's one-off work
    t, c = time.perf_counter(), time.process_time()
    for _ in range(steps):
        step()
    wall, cpu = time.perf_counter() - t, time.process_time() - c
    out = {"engine": engine, "scene": scene, "steps": steps, "rate": steps / wall,
           "wall_s": wall, "cpu_ms": 1000.0 * cpu / steps, "build_s": build_s,
           "version": mod.version()}
    out.update(finish())
    # a marked line: some engines print notes of their own on stdout
    print("\nPEERS_RESULT " + json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
