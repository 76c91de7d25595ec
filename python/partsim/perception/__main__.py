"""`partsim vision train|predict|table`: the perception baselines from the command line
(run through `python -m partsim.perception` by the `partsim` program).

    partsim vision train maskrcnn|insseg|motion-resnet|motion-pointnet --data DIR --out RUN
        [--input I] [--epochs N] [--size S] [--batch-size B] [--lr LR] [--seed S]
        [--backbone NAME] [--points N] [--instances K] [--channels C] [--rois R] [--width W]
        [--init WEIGHTS] [--device auto|cpu|cuda] [--log-every N] [--checkpoint-minutes M]
        [--no-eval] [--quiet]
    partsim vision predict RUN [--split test|train] [--data DIR] [--shard i/N [--results FILE]]
        [--batch-size B] [--device auto|cpu|cuda] [--quiet]
    partsim vision predict RUN --merge FILE...
    partsim vision predict RUN ... --ray auto|ADDRESS [--units N]   (shards as Ray tasks)
    partsim vision table RUN... [--split test|train] [--out FILE]

Exit codes: 0 done, 1 a failure while running (a file that cannot be read, PyTorch missing),
2 a bad command line or a run folder that does not fit the command.
"""

from __future__ import annotations

import argparse
import json
import sys

from . import BASELINES


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.print_usage(sys.stderr)
        print(f"partsim vision: {message}", file=sys.stderr)
        sys.exit(2)


def _shard(text):
    try:
        i, n = (int(x) for x in text.split("/"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"--shard wants i/N, got '{text}'") from None
    if not (n >= 1 and 0 <= i < n):
        raise argparse.ArgumentTypeError(f"--shard {text}: i must be in [0, N)")
    return i, n


def _positive_int(text):
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got '{text}'") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {v}")
    return v


def _positive_float(text):
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive number, got '{text}'") from None
    if not v > 0 or v != v or v == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text}")
    return v


def parser():
    p = _Parser(prog="partsim vision", description="the paper's perception baselines")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    t = sub.add_parser("train", help="train a baseline on a dataset's train split")
    t.add_argument("baseline", choices=list(BASELINES))
    t.add_argument("--data", required=True, help="a folder of partsim vision *-dataset")
    t.add_argument("--out", required=True, help="the run folder (continued when it exists)")
    t.add_argument("--input", help="rgb|rgbd (maskrcnn), xyz|xyzrgb (insseg)")
    t.add_argument("--epochs", type=_positive_int)
    t.add_argument("--size", type=_positive_int, help="square side the pictures are resized to")
    t.add_argument("--batch-size", type=_positive_int)
    t.add_argument("--lr", type=_positive_float)
    t.add_argument("--seed", type=int)
    t.add_argument("--backbone", help="resnet50 (default) or resnet18 (maskrcnn, motion-resnet); "
                   "ssg (default) or small (insseg, motion-pointnet)")
    t.add_argument("--points", type=_positive_int, help="points per view (insseg, "
                   "motion-pointnet)")
    t.add_argument("--instances", type=_positive_int, help="instance masks per view (insseg)")
    t.add_argument("--channels", type=_positive_int,
                   help="width of the FPN and the mask head (maskrcnn; 256)")
    t.add_argument("--rois", type=_positive_int,
                   help="regions sampled per picture for the box and mask heads (maskrcnn; 512)")
    t.add_argument("--width", type=_positive_float,
                   help="channel multiplier of the PointNet++ (insseg, motion-pointnet; 1)")
    t.add_argument("--init", help="weights to start from: a state dict (another run's "
                   "model.pt or checkpoint.pt; for maskrcnn also a torchvision ResNet's, "
                   "loaded into the backbone)")
    t.add_argument("--device", default="auto")
    t.add_argument("--log-every", type=_positive_int, help="batches per progress row (10)")
    t.add_argument("--checkpoint-minutes", type=_positive_float,
                   help="checkpoint within an epoch this often (10)")
    t.add_argument("--no-eval", action="store_true", help="do not predict the test split after")
    t.add_argument("--quiet", action="store_true")

    r = sub.add_parser("predict", help="predict a split with a trained run and score it")
    r.add_argument("run")
    r.add_argument("--split", default="test", choices=["test", "train"])
    r.add_argument("--data", help="another dataset folder (default: the run's)")
    r.add_argument("--shard", type=_shard, help="predict items i, i+N, ... (then merge)")
    r.add_argument("--results", help="with --shard: write the shard's predictions to this file "
                   "instead of the run (then --merge)")
    r.add_argument("--merge", nargs="+", metavar="FILE",
                   help="score the shards' --results files as one prediction of the split")
    r.add_argument("--batch-size", type=_positive_int)
    r.add_argument("--device", default="auto")
    r.add_argument("--quiet", action="store_true")

    b = sub.add_parser("table", help="the paper's Tables 1 and 2 beside the runs' scores")
    b.add_argument("runs", nargs="+")
    b.add_argument("--split", default="test", choices=["test", "train"])
    b.add_argument("--out", help="also write the Markdown to this file")
    return p


def _print_scores(metrics):
    if metrics is None:
        print("shard written; the other shards are not all done yet")
        return
    if "map" in metrics:
        m = metrics["map"]
        print("mAP (IoU 0.5): " + ("n/a" if m is None else f"{100 * m:.1f}"))
    else:
        keys = ("hinge_accuracy", "slider_accuracy", "hinge_origin_error_m",
                "hinge_axis_error_deg", "slider_axis_error_deg", "door_error_deg",
                "drawer_error_m")
        print(", ".join(f"{k} {metrics.get(k)}" for k in keys))


def main(argv=None):
    args = parser().parse_args(argv)
    try:
        from . import table as table_module
        from .train import Run, RunError
        from .._partsim import PartsimError
    except ImportError as e:
        print(f"partsim vision {args.command}: needs PyTorch ({e})", file=sys.stderr)
        return 1
    try:
        if args.command == "train":
            options = {k: getattr(args, k) for k in (
                "input", "epochs", "size", "batch_size", "lr", "seed", "backbone", "points",
                "instances", "channels", "rois", "width", "log_every", "checkpoint_minutes")}
            run = Run(args.out, baseline=args.baseline, data=args.data, device=args.device,
                      quiet=args.quiet, **options)
            run.train(init=args.init)
            if not args.no_eval:
                _print_scores(run.predict("test"))
        elif args.command == "predict":
            run = Run(args.run, device=args.device, quiet=args.quiet)
            if args.merge:
                if args.shard or args.results or args.data:
                    raise RunError("--merge takes the run and the shards' files only (their "
                                   "split and data are in the files)")
                _print_scores(run.merge(args.merge))
            elif args.results:
                run.predict(args.split, data=args.data, shard=args.shard,
                            batch_size=args.batch_size, results=args.results)
                if not args.quiet:
                    print(f"shard {args.shard[0]}/{args.shard[1]} written to {args.results}")
            else:
                _print_scores(run.predict(args.split, data=args.data, shard=args.shard,
                                          batch_size=args.batch_size))
        else:
            text = table_module.render(args.runs, args.split)
            print(text)
            if args.out:
                with open(args.out, "w", encoding="utf-8") as f:
                    f.write(text + "\n")
    except RunError as e:
        print(f"partsim vision {args.command}: {e}", file=sys.stderr)
        return 2
    except (OSError, json.JSONDecodeError, PartsimError) as e:
        print(f"partsim vision {args.command}: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
