"""partsim's list-shaped commands as units: how each is cut into ``--shard i/N`` runs, what
comes back from a unit, and how the parts become one run's outputs."""

from __future__ import annotations

import hashlib
import io
import json
import os
import shutil
import subprocess
import sys
import tarfile

from .._files import atomic_write
from . import _runner
from ._unit import UNIT_TMP

__all__ = ["COMMANDS", "run", "split_options"]

# the options of this layer (taken out of the command's own arguments): value, or a switch
OPTIONS = {"--ray": True, "--units": True, "--shared": False, "--retries": True,
           "--state": True}

USAGE = """\
partsim COMMAND ... --ray auto|ADDRESS [--units N] [--shared] [--retries R] [--state DIR]

runs a list-shaped command's parts (--shard i/N, i = 0..N-1) as tasks on a Ray cluster and
makes their outputs one run's, byte for byte: COMMAND is one of
  assets generate, assets check, vision detection-dataset, vision motion-dataset,
  tasks evaluate, learn evaluate, vision predict (and learn sweep, whose units are
  training runs).

  --ray auto|ADDRESS  auto: the cluster this machine is in (RAY_ADDRESS, or the one `ray
                      start` started here), else a local cluster started for the run;
                      ADDRESS: a running cluster's head (host:port or ray://host:port)
  --units N           parts to cut the list into (default twice the cluster's CPUs); each is
                      one task, which runs this program with --shard i/N
  --shared            --out is on a path every node sees (NFS, a mounted bucket): workers
                      write there; without it a unit's files come back to this program, which
                      writes them (assets generate and the vision datasets; the others always
                      send their results back)
  --retries R         times a unit is submitted again when its worker or node is lost
                      (default 3)
  --state DIR         where the finished units are recorded (default ~/.cache/partsim/ray/
                      <hash of the command>), removed when the run completes: the same
                      command started again after a crash skips them
Units run in this program's working folder, so relative paths work as they do here: inputs
(--dataset ROOT, assets check's DIR, learn evaluate's and vision predict's RUN, --data) and
that folder must be at the same path on every node (a shared file system), or give absolute
paths. docs/distributed.md has the
local, Ray-cluster and Slurm recipes.
"""


class Spec:
    """One command: ``switches``, its options without a value; ``positional_path``, whether it
    takes one positional argument, a folder; ``out``, the folder option a unit's tree
    lands in (tree commands), or ``result``, the option a unit writes its results file with;
    ``drop``, options of the whole run the units leave out (the merge gets them); ``ok``, a
    unit's exit codes that are results; ``merge``, how the parts become one run."""

    def __init__(self, switches=(), positional_path=False, out=None, result=None,
                 drop=(), ok=(0,), merge=None, quiet=False):
        self.quiet = quiet  # the command has a --quiet switch, which units get
        self.switches = set(switches) | {"--quiet"}
        self.positional_path = positional_path
        self.out = out
        self.result = result
        self.drop = set(drop)
        self.ok = ok
        self.merge = merge


def _dataset_merge(cmd, args, files, cli):
    return [cli] + cmd + [a for a in args if a != "--quiet"] + ["--merge-only"]


def _check_merge(cmd, args, files, cli):
    keep = _keep(args, ("--report", "--results"), COMMANDS[tuple(cmd)])
    return [cli, "assets", "check", "--merge"] + files + keep


def _tasks_merge(cmd, args, files, cli):
    keep = _keep(args, ("--csv",), COMMANDS[tuple(cmd)])
    return [cli, "tasks", "evaluate", "--merge"] + files + keep


def _learn_merge(cmd, args, files, cli):
    return [cli, "learn", "evaluate", _positional(args, COMMANDS[("learn", "evaluate")]),
            "--merge"] + files


def _predict_merge(cmd, args, files, cli):
    return [cli, "vision", "predict", _positional(args, COMMANDS[("vision", "predict")]),
            "--merge"] + files


COMMANDS = {
    ("assets", "generate"): Spec(switches={"--by-category", "--overwrite"}, out="--out"),
    ("assets", "check"): Spec(switches={"--no-visibility"}, positional_path=True,
                              result="--results", drop={"--report", "--results"}, ok=(0, 1),
                              merge=_check_merge),
    ("vision", "detection-dataset"): Spec(switches={"--no-point-clouds", "--merge-only"},
                                          out="--out", merge=_dataset_merge, quiet=True),
    ("vision", "motion-dataset"): Spec(switches={"--no-point-clouds", "--merge-only"},
                                       out="--out", merge=_dataset_merge, quiet=True),
    ("tasks", "evaluate"): Spec(switches={"--no-cameras"}, result="--csv", drop={"--csv"},
                                merge=_tasks_merge),
    ("learn", "evaluate"): Spec(switches={"--random"}, positional_path=True,
                                result="--results", merge=_learn_merge, quiet=True),
    ("vision", "predict"): Spec(positional_path=True, result="--results",
                                merge=_predict_merge, quiet=True),
}


def _items(args, spec):
    """The arguments as (option, value) pairs, value None for switches and positionals'
    option None; "--x=v" is split."""
    out, i = [], 0
    while i < len(args):
        a = args[i]
        if a.startswith("--") and "=" in a:
            name, value = a.split("=", 1)
            out.append((name, value))
        elif a.startswith("--") and a not in spec.switches:
            if i + 1 >= len(args):
                raise ValueError(f"option {a} needs a value")
            out.append((a, args[i + 1]))
            i += 1
        elif a.startswith("--"):
            out.append((a, None))
        else:
            out.append((None, a))
        i += 1
    return out


def _join(items):
    args = []
    for name, value in items:
        args += [value] if name is None else [name] if value is None else [name, value]
    return args


def _keep(args, names, spec):
    return [x for name, value in _items(args, spec) if name in names for x in (name, value)]


def _positional(args, spec):
    pos = [value for name, value in _items(args, spec) if name is None]
    return pos[0] if pos else None


def split_options(argv):
    """(the command's own arguments, this layer's options as a dict)."""
    rest, opts, i = [], {}, 0
    while i < len(argv):
        a = argv[i]
        name, eq, value = a.partition("=")
        if name in OPTIONS:
            if not OPTIONS[name]:
                opts[name] = True
            elif eq:
                opts[name] = value
            else:
                if i + 1 >= len(argv) or argv[i + 1].startswith("--"):
                    raise ValueError(f"option {name} needs a value")
                opts[name] = argv[i + 1]
                i += 1
        else:
            rest.append(a)
        i += 1
    return rest, opts


def _extract(payload: bytes, out: str) -> int:
    """Writes a unit's tar into ``out``, each file to a temporary name beside it and renamed
    (a reader, or a driver killed half-way, never sees half a file); returns the file count."""
    n = 0
    if not payload:  # a unit with nothing to do (more units than objects) made no folder
        return n
    with tarfile.open(fileobj=io.BytesIO(payload), mode="r") as tar:
        for m in tar:
            if not m.isfile():
                continue
            rel = os.path.normpath(m.name)
            if os.path.isabs(rel) or rel.split(os.sep)[0] == "..":
                raise RuntimeError(f"a unit sent a file outside its folder: {m.name!r}")
            dest = os.path.join(out, rel)
            os.makedirs(os.path.dirname(dest), exist_ok=True)
            with tar.extractfile(m) as src:
                def write(f, src=src, mode=m.mode & 0o777):
                    shutil.copyfileobj(src, f)
                    os.fchmod(f.fileno(), mode)
                atomic_write(dest, write, sync=False)
            n += 1
    return n


def _executor(address):
    if address is None:
        return _runner.LocalExecutor()
    return _runner.RayExecutor(address)


def run(argv, ray: str | None = "auto", units: int | None = None, shared: bool = False,
        retries: int = 3, state: str | None = None, quiet: bool = False, executor=None,
        cli: str | None = None) -> int:
    """Runs ``partsim ARGV`` (e.g. ``["assets", "generate", "--out", "d"]``) cut into
    ``units`` shards, as Ray tasks on the cluster ``ray`` ("auto" or an address; None: one
    after another in this process), and merges the parts into the outputs of one run. Returns
    the exit code the command itself would have. See the module's help for the options."""
    from .. import _cli

    argv = list(argv)
    cmd = tuple(argv[:2])
    spec = COMMANDS.get(cmd)
    if spec is None:
        raise ValueError(f"--ray runs {', '.join(' '.join(c) for c in COMMANDS)} and learn "
                         f"sweep; not {' '.join(argv[:2]) or 'nothing'!r}")
    items = _items(argv[2:], spec)
    names = [n for n, _ in items]
    if "--shard" in names:
        raise ValueError("--ray cuts the list into shards itself: leave --shard out")
    if "--merge" in names or "--merge-only" in names:
        raise ValueError("--ray merges the shards itself: leave --merge/--merge-only out")
    if spec.positional_path and _positional(argv[2:], spec) is None:
        raise ValueError(f"{' '.join(cmd)} needs its folder argument")
    cli = cli or _cli.find_cli()
    if not cli:
        raise RuntimeError("cannot find the partsim command line (set PARTSIM_CLI)")
    jobs = next((int(v) for n, v in items if n == "--jobs" and v and v.isdigit()), 1)
    out = next((v for n, v in items if n == spec.out), None) if spec.out else None
    if spec.out and not out:
        raise ValueError(f"{' '.join(cmd)} needs {spec.out} DIR")

    own = executor is None
    executor = executor or _executor(ray)
    try:
        n = units or 2 * executor.cpus()
        if n < 1:
            raise ValueError(f"--units must be at least 1, got {n}")
        key = hashlib.sha256(json.dumps([os.getcwd(), list(cmd), _join(items), n,
                                         shared]).encode())
        state = state or os.path.join(os.environ.get("XDG_CACHE_HOME") or
                                      os.path.expanduser("~/.cache"), "partsim", "ray",
                                      key.hexdigest()[:16])
        base = [(k, v) for k, v in items if k not in spec.drop]
        specs = []
        for i in range(n):
            unit = [(k, v) for k, v in base if k != "--quiet"] + [("--shard", f"{i}/{n}")]
            if spec.quiet:
                unit.append(("--quiet", None))
            if spec.out and not shared:
                unit = [(k, f"{UNIT_TMP}/out" if k == spec.out else v) for k, v in unit]
            if spec.result:
                unit = [(k, v) for k, v in unit if k != spec.result] + \
                    [(spec.result, f"{UNIT_TMP}/result")]
            collect = "file:result" if spec.result else None if shared else "tree:out"
            specs.append({"key": f"{i}-of-{n}", "cli": cli, "args": list(cmd) + _join(unit),
                          "collect": collect, "ok": spec.ok, "cpus": jobs, "cwd": os.getcwd()})

        def take(unit, result):
            if unit["collect"] == "tree:out":
                _extract(result["payload"], out)
            elif unit["collect"]:
                atomic_write(os.path.join(state, unit["key"] + ".result"),
                             lambda f: f.write(result["payload"]), sync=False)

        summary = _runner.run_units(specs, executor, state, take, retries=retries,
                                    quiet=quiet, label="partsim " + " ".join(cmd))
    finally:
        if own:
            executor.shutdown()
    rc = 0
    if spec.merge is not None:
        files = [os.path.join(state, s["key"] + ".result") for s in specs] if spec.result \
            else []
        sys.stdout.flush()
        rc = subprocess.run(spec.merge(list(cmd), _join(items), files, cli), check=False)\
            .returncode
    elif not quiet:
        print(f"{' '.join(cmd)}: {summary['units']} units into {out} ({summary['ran']} ran, "
              f"{summary['skipped']} skipped)")
    if rc in spec.ok and rc <= 1:
        shutil.rmtree(state, ignore_errors=True)
    if not quiet:
        print(f"partsim {' '.join(cmd)}: {summary['ran']} units in "
              f"{summary['seconds']:.1f} s ({summary['unit_seconds']:.1f} s in units"
              + (f", {summary['lost_workers']} lost workers" if summary["lost_workers"] else "")
              + ")", file=sys.stderr)
    return rc
