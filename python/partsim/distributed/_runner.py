"""Units on an executor: Ray tasks, or one after another in this process; retries when a worker
is lost, skips what an earlier attempt finished, and reports progress with an ETA."""

from __future__ import annotations

import json
import os
import sys
import time

from .._files import atomic_write
from . import _unit

__all__ = ["LocalExecutor", "RayExecutor", "UnitFailed", "run_units"]


class UnitFailed(RuntimeError):
    """A unit's command failed (its own error, not a lost worker): retrying would not help."""

    def __init__(self, key: str, result: dict):
        self.result = result
        tail = (result.get("stderr") or "").strip().splitlines()[-8:]
        super().__init__(f"unit {key} failed with exit code {result['rc']} on "
                         f"{result.get('host')}:\n  " + "\n  ".join(tail))


class LocalExecutor:
    """Runs the units one after another in this process (no Ray): the reference the Ray runs
    are compared with, and what ``learn sweep`` does without ``--ray``."""

    name = "this process"

    def __init__(self):
        self._pending = []

    def cpus(self) -> int:
        return 1

    def submit(self, spec: dict, cpus: float = 1):
        self._pending.append(spec)
        return spec["key"]

    def wait(self):
        """(key, result, error) of one finished unit."""
        spec = self._pending.pop(0)
        return spec["key"], _unit.run_unit(spec), None

    def shutdown(self):
        pass


class RayExecutor:
    """Units as Ray tasks. ``address``: "auto" joins the cluster this machine belongs to
    (``RAY_ADDRESS``, or the one ``ray start`` started here) and starts a local one when there
    is none; otherwise the address of a running cluster's head (host:port or ray://...)."""

    def __init__(self, address: str = "auto", quiet: bool = False):
        try:
            import ray
            from ray import cloudpickle
        except ImportError as e:
            raise RuntimeError("--ray needs the ray package (in requirements.lock; "
                               "pip install 'ray==2.60.0')") from e
        self.ray = ray
        # the worker's function goes by value: a node needs the command line, not this package
        cloudpickle.register_pickle_by_value(_unit)
        kwargs = {"log_to_driver": False, "logging_level": "ERROR", "configure_logging": True}
        started = False
        if address == "auto":
            try:
                ray.init(address="auto", **kwargs)
            except ConnectionError:
                ray.init(include_dashboard=False, **kwargs)
                started = True
        else:
            ray.init(address=address, **kwargs)
        self.started = started
        self.name = ("a local Ray cluster started for this run" if started else
                     f"the Ray cluster at {ray.get_runtime_context().gcs_address}")
        # no retries of Ray's own: the driver submits a lost unit again, and says so
        self._task = ray.remote(max_retries=0)(_unit.run_unit)
        self._refs = {}

    def cpus(self) -> int:
        return max(1, int(self.ray.cluster_resources().get("CPU", 1)))

    def submit(self, spec: dict, cpus: float = 1):
        ref = self._task.options(num_cpus=cpus, name=f"partsim_unit_{spec['key']}").remote(spec)
        self._refs[ref] = spec["key"]
        return spec["key"]

    def wait(self):
        ready, _ = self.ray.wait(list(self._refs), num_returns=1)
        key = self._refs.pop(ready[0])
        try:
            return key, self.ray.get(ready[0]), None
        except self.ray.exceptions.RayTaskError as e:  # the unit's function raised
            return key, {"key": key, "rc": -1, "stdout": "", "stderr": str(e),
                         "host": "?", "seconds": 0.0, "payload": None}, None
        except self.ray.exceptions.RayError as e:  # the worker or its node was lost
            return key, None, e

    def shutdown(self):
        self.ray.shutdown()


def _clock(seconds: float) -> str:
    s = int(round(seconds))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}" if s >= 3600 else \
        f"{s // 60}:{s % 60:02d}"


def run_units(units: list, executor, state_dir: str, on_result, retries: int = 3,
              quiet: bool = False, label: str = "partsim") -> dict:
    """Runs every unit (a spec of :func:`_unit.run_unit`, with "key" and "cpus") on
    ``executor``; ``on_result(spec, result)`` takes each finished unit's outputs in (on the
    driver), after which the unit is recorded as done in ``state_dir``: a run started again
    skips the units done. A unit whose worker or node was lost is submitted again, up to
    ``retries`` times; a unit whose command fails raises :class:`UnitFailed` (after the other
    running units finished and were taken in). Returns counts and times."""
    os.makedirs(state_dir, exist_ok=True)
    pending, skipped = [], 0
    for spec in units:
        if os.path.exists(os.path.join(state_dir, spec["key"] + ".done")):
            skipped += 1
        else:
            pending.append(spec)
    by_key = {spec["key"]: spec for spec in pending}
    attempts = {k: 0 for k in by_key}
    for spec in pending:
        executor.submit(spec, spec.get("cpus", 1))
    running, done, lost, failure = len(pending), 0, 0, None
    start = time.monotonic()
    seconds = []
    if not quiet:
        print(f"{label}: {len(units)} units on {executor.name}"
              + (f" ({skipped} done before, skipped)" if skipped else ""), file=sys.stderr)
    while running:
        key, result, error = executor.wait()
        running -= 1
        spec = by_key[key]
        if error is not None:
            attempts[key] += 1
            lost += 1
            if attempts[key] > retries:
                failure = failure or RuntimeError(f"unit {key}: its worker was lost "
                                                  f"{attempts[key]} times ({error})")
                continue
            if not quiet:
                print(f"{label}: unit {key}: worker lost ({type(error).__name__}); "
                      f"submitted again ({attempts[key]}/{retries})", file=sys.stderr)
            executor.submit(spec, spec.get("cpus", 1))
            running += 1
            continue
        if result["rc"] not in spec.get("ok", (0,)):
            failure = failure or UnitFailed(key, result)
            continue
        on_result(spec, result)
        record = json.dumps({"host": result["host"], "seconds": result["seconds"]})
        atomic_write(os.path.join(state_dir, key + ".done"),
                     lambda f: f.write(record.encode("utf-8")), sync=False)
        done += 1
        seconds.append(result["seconds"])
        if not quiet:
            elapsed = time.monotonic() - start
            eta = elapsed / done * (len(pending) - done)
            print(f"{label}: {done + skipped}/{len(units)} units done, {running} in flight, "
                  f"{_clock(elapsed)} elapsed, ETA {_clock(eta)}", file=sys.stderr)
    if failure is not None:
        raise failure
    return {"units": len(units), "ran": done, "skipped": skipped, "lost_workers": lost,
            "seconds": time.monotonic() - start, "unit_seconds": sum(seconds)}
