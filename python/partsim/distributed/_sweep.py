"""``partsim learn sweep``: the SAPIEN paper's Table 3 grid as training runs, then their
evaluations and the table, on a Ray cluster or one run after another here."""

from __future__ import annotations

import hashlib
import json
import os
import sys

from . import _runner

__all__ = ["grid", "sweep", "sweep_main"]

# the sweep's own options (value options; --quiet is a switch); `learn train`'s go to every run
GRID = {"--tasks": "door,drawer", "--obs": "raw,mobility,visual",
        "--train-objects": "2,4,8,16", "--seeds": "0,1,2"}
OWN = {"--out", "--episodes", "--eval-seed", "--ray", "--retries"} | set(GRID)


def grid(tasks, obs, train_objects, seeds) -> list:
    """The runs of the grid, in a fixed order: (name, task, obs, N, seed); the name is the run's
    folder, ``<task>-<obs>-n<N>-s<seed>``."""
    return [(f"{t}-{o}-n{n}-s{s}", t, o, int(n), int(s))
            for t in tasks for o in obs for n in train_objects for s in seeds]


def sweep(out: str, steps: int, tasks=("door", "drawer"), obs=("raw", "mobility", "visual"),
          train_objects=(2, 4, 8, 16), seeds=(0, 1, 2), train_args=(), episodes: int = 20,
          eval_seed: int = 1000, ray: str | None = None, retries: int = 3,
          quiet: bool = False, executor=None, cli: str | None = None) -> str:
    """Trains every run of the grid into ``out/<name>`` (``partsim learn train`` with
    ``train_args`` added), evaluates each (``partsim learn evaluate``, ``episodes`` per object)
    and returns Table 3's layout, also written to ``out/table.md`` and ``out/table.csv``.

    Each run is one unit: a Ray task on the cluster ``ray`` ("auto" or an address; ``out``
    must then be on a path every node sees) or, with None, one after another here. A run
    continues from its last checkpoint when started again, so a preempted task, or the whole
    sweep run again, goes on where it stopped; finished runs and evaluations are skipped."""
    from .. import _cli
    from ..learn import protocol

    cli = cli or _cli.find_cli()
    if not cli:
        raise RuntimeError("cannot find the partsim command line (set PARTSIM_CLI)")
    if steps < 1:
        raise ValueError(f"--steps must be at least 1, got {steps}")
    for t in tasks:
        if t not in ("door", "drawer"):
            raise ValueError(f"--tasks: unknown task {t!r} (door, drawer)")
    for o in obs:
        if o not in ("raw", "mobility", "visual"):
            raise ValueError(f"--obs: unknown state {o!r} (raw, mobility, visual)")
    out = os.path.abspath(out)
    runs = grid(tasks, obs, train_objects, seeds)
    if not runs:
        raise ValueError("the grid is empty")
    os.makedirs(out, exist_ok=True)
    state = os.path.join(out, ".sweep")
    own = executor is None
    executor = executor or (_runner.LocalExecutor() if ray is None
                            else _runner.RayExecutor(ray))
    try:
        train = [{"key": f"train-{name}-{_digest(steps, train_args)}", "cli": cli, "cpus": 1,
                  "collect": None,
                  "args": ["learn", "train", "--task", t, "--obs", o, "--train-objects",
                           str(n), "--seed", str(s), "--steps", str(steps)] + list(train_args)
                  + ["--out", os.path.join(out, name), "--quiet"]}
                 for name, t, o, n, s in runs]
        _runner.run_units(train, executor, state, lambda unit, result: None, retries=retries,
                          quiet=quiet, label="partsim learn sweep (training)")
        evaluate = [{"key": f"eval-{name}-{_digest(steps, train_args, episodes, eval_seed)}",
                     "cli": cli,
                     "cpus": 1, "collect": None,
                     "args": ["learn", "evaluate", os.path.join(out, name), "--episodes",
                              str(episodes), "--seed", str(eval_seed), "--quiet"]}
                    for name, *_ in runs]
        _runner.run_units(evaluate, executor, state, lambda unit, result: None,
                          retries=retries, quiet=quiet,
                          label="partsim learn sweep (evaluation)")
    finally:
        if own:
            executor.shutdown()
    folders = [os.path.join(out, name) for name, *_ in runs]
    text = protocol.table(folders)
    protocol._write_atomic(os.path.join(out, "table.md"), text)
    protocol._write_atomic(os.path.join(out, "table.csv"), protocol.table(folders, "csv"))
    return text


def _digest(*what) -> str:
    """A short hash of a unit's options: its record of being done names them, so a sweep run
    again with other options does not take an earlier one's runs as done."""
    return hashlib.sha256(json.dumps(what, default=list).encode()).hexdigest()[:12]


def _ints(text, what):
    try:
        values = [int(x) for x in text.split(",")]
    except ValueError:
        raise ValueError(f"{what} wants integers separated by commas, got {text!r}") from None
    if not values or min(values) < 0:
        raise ValueError(f"{what} wants integers >= 0, got {text!r}")
    return values


def sweep_main(args) -> int:
    """``partsim learn sweep ...``: prints the table; returns the exit code. The options are
    the sweep's own (OWN, --steps, --quiet) and `learn train`'s, which go to every run; those
    that name one run (--task, --seed) are refused."""
    from ..learn import protocol

    for a in args:
        if a in ("--task", "--seed"):
            raise ValueError(f"sweep takes the grid as --tasks, --obs, --train-objects, "
                             f"--seeds, not {a}")
    per_run = {"task", "obs", "train-objects", "seed", "out", "steps", "quiet"}
    spec = {k: str for k in protocol.TRAIN_SPEC if k not in per_run}
    spec.update({k[2:]: str for k in OWN | {"--steps"}})
    spec["quiet"] = bool
    parsed, positional = protocol._parse_options(args, spec)
    if positional:
        raise ValueError(f"sweep takes no positional arguments ({positional[0]!r})")
    opts = dict(GRID)
    opts.update({f"--{k}": v for k, v in parsed.items() if f"--{k}" in OWN | {"--steps"}})
    train_args = [x for k, v in parsed.items() if f"--{k}" not in OWN | {"--steps"}
                  and k != "quiet" for x in (f"--{k}", v)]
    if "--out" not in opts:
        raise ValueError("sweep needs --out SWEEP")
    if "--steps" not in opts:
        raise ValueError("sweep needs --steps S (the paper: 1000000)")
    text = sweep(opts["--out"], steps=_ints(opts["--steps"], "--steps")[0],
                 tasks=opts["--tasks"].split(","), obs=opts["--obs"].split(","),
                 train_objects=_ints(opts["--train-objects"], "--train-objects"),
                 seeds=_ints(opts["--seeds"], "--seeds"), train_args=train_args,
                 episodes=_ints(opts.get("--episodes", "20"), "--episodes")[0],
                 eval_seed=_ints(opts.get("--eval-seed", "1000"), "--eval-seed")[0],
                 ray=opts.get("--ray"), retries=_ints(opts.get("--retries", "3"),
                                                      "--retries")[0],
                 quiet=parsed.get("quiet", False))
    sys.stdout.write(text)
    return 0
