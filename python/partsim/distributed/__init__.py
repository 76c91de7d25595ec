"""partsim.distributed: partsim's list-shaped jobs on a Ray cluster.

A list-shaped command (``assets generate``, ``assets check``, the vision datasets, ``tasks
evaluate``, ``learn evaluate``) is cut into N shards (``--shard i/N`` of the command line);
each shard is a unit, run as a Ray task (the partsim command line on a worker node), and the
units' outputs are merged into what one run writes, byte for byte. A unit whose worker dies is
submitted again; outputs are written atomically and finished units are recorded, so nothing
is lost and a run started again skips what is done. ``partsim learn sweep`` runs the paper's
Table 3 grid with one training run per unit.

From the command line, add ``--ray auto`` (or a head's address) to the command; from Python::

    import partsim.distributed as dist
    dist.run(["assets", "generate", "--out", "ds", "--per-category", "paper"], ray="auto")
    print(dist.sweep("sweep", steps=100_000, tasks=["drawer"], obs=["mobility"],
                     train_objects=[4], seeds=[0, 1, 2], ray="auto"))

docs/distributed.md has the recipes (one machine, a Ray cluster, Slurm arrays).
"""

from ._commands import COMMANDS, USAGE, run, split_options
from ._runner import LocalExecutor, RayExecutor, UnitFailed, run_units
from ._sweep import grid, sweep

__all__ = ["COMMANDS", "LocalExecutor", "RayExecutor", "UnitFailed", "grid", "main", "run",
           "run_units", "sweep"]


def main(argv=None) -> int:
    """``partsim COMMAND ... --ray ...`` (``python3 -m partsim.distributed COMMAND ...``):
    returns the exit code (0 done, 1 a failure, 2 a usage error)."""
    import sys

    argv = list(sys.argv[1:] if argv is None else argv)
    name = " ".join(a for a in argv[:2] if not a.startswith("-"))
    if not argv or "--help" in argv or "-h" in argv:
        print(USAGE, end="")
        return 0 if argv else 2
    try:
        rest, opts = split_options(argv)
        if rest[:2] == ["learn", "sweep"]:
            from ._sweep import sweep_main

            extra = sorted(set(opts) - {"--ray", "--retries"})
            if extra:
                raise ValueError(f"learn sweep runs one training run per unit on a path every "
                                 f"node sees: {', '.join(extra)} does not apply")
            args = rest[2:] + [x for k, v in opts.items() for x in (k, v)]
            return sweep_main(args)
        if "--ray" not in opts:
            raise ValueError("--ray auto|ADDRESS is missing")
        units = opts.get("--units")
        retries = opts.get("--retries", "3")
        if units is not None and (not units.isdigit() or int(units) < 1):
            raise ValueError(f"--units wants an integer >= 1, got {units!r}")
        if not retries.isdigit():
            raise ValueError(f"--retries wants an integer >= 0, got {retries!r}")
        return run(rest, ray=opts["--ray"], units=int(units) if units else None,
                   shared=bool(opts.get("--shared")), retries=int(retries),
                   state=opts.get("--state"), quiet="--quiet" in rest)
    except ValueError as e:
        print(f"partsim {name}: {e}", file=sys.stderr)
        return 2
    except (RuntimeError, OSError) as e:
        print(f"partsim {name}: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"partsim {name}: interrupted (the same command continues where "
              "it stopped)", file=sys.stderr)
        return 130
