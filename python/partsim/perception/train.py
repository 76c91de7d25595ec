"""Training, prediction and scoring of a perception baseline, the same for every model.

A run is a folder:

- ``run.json``: the baseline, the dataset, the options and the network's configuration
  (:meth:`Baseline.config`); a later ``train`` into the folder must agree with it, except for
  ``epochs``, which may grow (the run continues) and ``device``;
- ``checkpoint.pt``: the network, the optimiser, the position (epoch, batch) and torch's random
  state, written whole (a temporary file renamed into place) at the end of every epoch and
  every ``checkpoint_minutes`` within one, so that a killed run continues where its last
  checkpoint was;
- ``progress.csv``: a row per ``log_every`` batches and at the end of each epoch: the loss and
  its terms averaged over those batches, items per second and the wall clock; ``curves.png``
  draws it;
- ``model.pt``: the trained network's weights (a state dict), written when the last epoch ends;
- ``eval-<split>/``: what ``predict`` wrote: ``results.json`` (COCO results) or
  ``predictions.json`` (motion), and the evaluator's ``table.md``, ``table.csv`` and
  ``metrics.json``.

Determinism: the order of an epoch's items is a permutation drawn from (seed, epoch), and each
batch's random draws (point sampling, flips) from (seed, epoch, batch), so a run resumed from a
checkpoint sees the same batches as an uninterrupted one; torch's own random state is saved
with the checkpoint.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import sys
import time

import numpy as np

from .._device import resolve_device
from .._files import atomic_write
from .._text import duration as _duration
from . import BASELINES, baseline_class

RUN_FILE = "run.json"
CHECKPOINT = "checkpoint.pt"
MODEL = "model.pt"
PROGRESS = "progress.csv"
# the "format" of a shard's results file (predict --shard i/N --results FILE)
SHARD_FORMAT = "partsim-vision-predict-shard-1"
FIXED_COLUMNS = ("epoch", "batch", "items", "loss")
TIMING_COLUMNS = ("items_per_s", "wall_s")


class RunError(ValueError):
    """A run folder or its options that cannot be used (the message names the file and key)."""


def _datasets():
    from .. import vision
    return {"detection": vision.DetectionDataset, "motion": vision.MotionDataset}


def open_split(kind, data, split):
    """The dataset of ``kind`` ('detection' or 'motion') in folder ``data``, split ``split``."""
    return _datasets()[kind](data, split)


def _read_json(path, what):
    try:
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
    except (OSError, UnicodeDecodeError, ValueError, RecursionError) as e:
        raise RunError(f"{what} '{path}' cannot be read: {type(e).__name__}: {e}") from None
    if not isinstance(doc, dict):
        raise RunError(f"{what} '{path}' is not a JSON object")
    return doc


# the options every run has that must be positive numbers (the rest are checked by the baseline)
_POSITIVE_INTS = ("epochs", "batch_size", "log_every")
_POSITIVE_FLOATS = ("lr", "checkpoint_minutes")


def _check_options(options, where):
    """Raises RunError naming ``where`` unless the shared numeric options are usable: positive
    integers, positive finite numbers and an integer seed (a run.json written by hand or
    damaged, or options given from Python, never reach the trainer as 1e999 or "ten")."""
    for k in _POSITIVE_INTS:
        v = options.get(k)
        if not (isinstance(v, int) and not isinstance(v, bool) and v >= 1):
            raise RunError(f"{where}: '{k}' must be a positive integer, got {v!r}")
    for k in _POSITIVE_FLOATS:
        v = options.get(k)
        if not (isinstance(v, (int, float)) and not isinstance(v, bool) and 0 < v < math.inf):
            raise RunError(f"{where}: '{k}' must be a positive number, got {v!r}")
    if not (isinstance(options.get("seed"), int) and not isinstance(options["seed"], bool)):
        raise RunError(f"{where}: 'seed' must be an integer, got {options.get('seed')!r}")


def _write_json(path, doc):
    text = json.dumps(doc, indent=1, sort_keys=True) + "\n"
    atomic_write(path, lambda f: f.write(text.encode("utf-8")))


def batch_seed(seed, epoch, batch):
    """The seed of batch ``batch`` of epoch ``epoch``'s random draws."""
    return [int(seed), int(epoch), int(batch)]


def epoch_order(seed, epoch, n):
    """The order in which epoch ``epoch`` visits the ``n`` training items."""
    return np.random.default_rng([int(seed), int(epoch), 1 << 30]).permutation(n)


class Run:
    """A training run of one baseline (see the module's docstring for the folder).

    ``Run(out, baseline=None, data=None, **options)`` opens ``out``: a new run needs
    ``baseline`` (a name of :data:`partsim.perception.BASELINES`) and ``data`` (the dataset
    folder); an existing one is read from ``run.json``, and the options given must agree with it
    (``epochs`` may differ: training runs to the new count)."""

    # options every run has, with their defaults (None: the baseline's default)
    COMMON = {"input": None, "size": None, "epochs": None, "batch_size": None, "lr": None,
              "seed": 0, "log_every": 10, "checkpoint_minutes": 10.0}

    def __init__(self, out, baseline=None, data=None, device="auto", quiet=False, **options):
        self.out = os.fspath(out)
        self.quiet = quiet
        try:
            self.device = resolve_device(device)
        except ValueError as e:
            raise RunError(str(e)) from None
        path = os.path.join(self.out, RUN_FILE)
        if os.path.exists(path):
            doc = _read_json(path, "run file")
            for key in ("baseline", "data", "options", "model"):
                if key not in doc:
                    raise RunError(f"run file '{path}': missing key '{key}'")
            if baseline is not None and baseline != doc["baseline"]:
                raise RunError(f"run '{self.out}' trains {doc['baseline']}, not {baseline}")
            if data is not None and os.path.abspath(data) != doc["data"]:
                raise RunError(f"run '{self.out}' trains on '{doc['data']}', not "
                               f"'{os.path.abspath(data)}'")
            if doc["baseline"] not in BASELINES or not isinstance(doc["options"], dict):
                raise RunError(f"run file '{path}': 'baseline' must be one of "
                               f"{', '.join(BASELINES)} and 'options' an object")
            self.name, self.data = doc["baseline"], str(doc["data"])
            self.options = dict(doc["options"])
            _check_options(self.options, f"run file '{path}'")
            for k, v in options.items():
                if v is None or k == "epochs":
                    continue
                if self.options.get(k) != v:
                    raise RunError(f"run '{self.out}' was started with {k}={self.options.get(k)!r}; "
                                   f"this command gives {v!r} (use another --out)")
            if options.get("epochs") is not None:
                self.options["epochs"] = int(options["epochs"])
            self._make_baseline()
            if self.baseline.config() != doc["model"]:
                raise RunError(f"run file '{path}': its network {doc['model']} differs from "
                               f"what these options build, {self.baseline.config()}")
        else:
            if baseline is None or data is None:
                raise RunError(f"'{self.out}' holds no run ({RUN_FILE}): a new run needs the "
                               "baseline and --data")
            self.name, self.data = baseline, os.path.abspath(data)
            cls = baseline_class(baseline)
            self.options = {}
            for k, default in self.COMMON.items():
                v = options.pop(k, None)
                self.options[k] = default if v is None else v
            for k, v in cls.defaults.items():
                if self.options.get(k) is None:
                    self.options[k] = v
            if self.options["input"] is None:
                self.options["input"] = cls.inputs[0]
            if self.options["input"] not in cls.inputs:
                raise RunError(f"{baseline} takes --input {' or '.join(cls.inputs)}, not "
                               f"'{self.options['input']}'")
            self.options.update({k: v for k, v in options.items() if v is not None})
            _check_options(self.options, "options")
            self._make_baseline()

    def _make_baseline(self):
        cls = baseline_class(self.name)
        self.kind = cls.kind
        self.train_set = open_split(self.kind, self.data, "train")
        if len(self.train_set) == 0:
            raise RunError(f"dataset '{self.data}': the train split is empty")
        try:
            self.baseline = cls(self.train_set, self.options)
        except ValueError as e:  # an option the baseline refuses (a backbone it does not know)
            raise RunError(str(e)) from None

    # --- files ---------------------------------------------------------------------------------

    def path(self, name):
        return os.path.join(self.out, name)

    def _save_run_file(self):
        _write_json(self.path(RUN_FILE), {
            "baseline": self.name, "data": self.data, "options": self.options,
            "model": self.baseline.config(), "train_items": len(self.train_set)})

    def _log(self, message):
        if not self.quiet:
            print(f"[partsim.perception] {message}", file=sys.stderr, flush=True)

    # --- training ------------------------------------------------------------------------------

    def train(self, init=None):
        """Trains to ``options['epochs']``, from the last checkpoint when there is one; loads
        the weights file ``init`` (see :func:`load_matching`) into a new run's network first.
        Returns the trained network (on the run's device)."""
        import torch

        os.makedirs(self.out, exist_ok=True)
        o = self.options
        seed, epochs, batch_size = int(o["seed"]), int(o["epochs"]), int(o["batch_size"])
        torch.manual_seed(seed)
        model = self.baseline.build_model().to(self.device)
        optimizer = self.baseline.make_optimizer(model, float(o["lr"]))
        epoch, batch, rows = 0, 0, 0
        checkpoint = self.path(CHECKPOINT)
        if os.path.exists(checkpoint):
            state = torch.load(checkpoint, map_location=self.device)
            model.load_state_dict(state["model"])
            optimizer.load_state_dict(state["optimizer"])
            epoch, batch, rows = state["epoch"], state["batch"], state["rows"]
            torch.set_rng_state(state["torch_rng"])
            self._log(f"continuing from epoch {epoch + 1}, batch {batch} ({checkpoint})")
            if epoch < epochs and os.path.exists(self.path(MODEL)):
                # the network of an earlier end: no longer the run's, and predict would take it
                # over the checkpoints this training writes
                os.remove(self.path(MODEL))
        elif init is not None:
            loaded, skipped = self.baseline.load_weights(model, init)
            self._log(f"initialised {len(loaded)} tensors from '{init}' ({len(skipped)} skipped)")
        self._save_run_file()
        self._truncate_progress(rows)

        n = len(self.train_set)
        per_epoch = (n + batch_size - 1) // batch_size
        total = per_epoch * epochs
        done_at_start = epoch * per_epoch + batch
        t0 = time.monotonic()
        last_save = t0
        sums, count, items = {}, 0, 0
        interval_start = time.monotonic()
        model.train()
        while epoch < epochs:
            order = epoch_order(seed, epoch, n)
            while batch < per_epoch:
                idx = order[batch * batch_size:(batch + 1) * batch_size]
                rng = np.random.default_rng(batch_seed(seed, epoch, batch))
                data = self.baseline.to_device(
                    self.baseline.load_batch(self.train_set, [int(i) for i in idx], rng, True),
                    self.device)
                loss, terms = self.baseline.loss(model, data)
                if not torch.isfinite(loss):
                    raise RunError(f"run '{self.out}': the loss became {float(loss)} at epoch "
                                   f"{epoch + 1}, batch {batch} (terms {terms}); lower --lr")
                optimizer.zero_grad(set_to_none=True)
                loss.backward()
                optimizer.step()
                batch += 1
                count += 1
                items += len(idx)
                sums["loss"] = sums.get("loss", 0.0) + float(loss)
                for k, v in terms.items():
                    sums[k] = sums.get(k, 0.0) + float(v)
                end_of_epoch = batch == per_epoch
                if count >= int(o["log_every"]) or end_of_epoch:
                    now = time.monotonic()
                    rate = items / max(now - interval_start, 1e-9)
                    row = {"epoch": epoch + 1, "batch": batch, "items": items}
                    row.update({k: v / count for k, v in sums.items()})
                    row.update({"items_per_s": rate, "wall_s": now - t0})
                    self._append_progress(row)
                    rows += 1
                    done = epoch * per_epoch + batch
                    eta = (now - t0) / max(done - done_at_start, 1) * (total - done)
                    self._log(f"epoch {epoch + 1}/{epochs} | batch {batch}/{per_epoch} | "
                              f"loss {row['loss']:.4g} | {rate:.1f} items/s | "
                              f"ETA {_duration(eta)}")
                    sums, count, items = {}, 0, 0
                    interval_start = now
                # within an epoch, right after a log row (so that nothing logged is lost)
                if end_of_epoch or (count == 0 and time.monotonic() - last_save
                                    >= 60.0 * float(o["checkpoint_minutes"])):
                    e, b = (epoch + 1, 0) if end_of_epoch else (epoch, batch)
                    self._save_checkpoint(model, optimizer, e, b, rows)
                    last_save = time.monotonic()
            epoch += 1
            batch = 0
        state = model.state_dict()
        atomic_write(self.path(MODEL), lambda f: torch.save(state, f))
        self._plot()
        self._log(f"trained {epochs} epochs of {n} items: {self.path(MODEL)}")
        return model

    def _save_checkpoint(self, model, optimizer, epoch, batch, rows):
        import torch

        state = {"model": model.state_dict(), "optimizer": optimizer.state_dict(),
                 "epoch": epoch, "batch": batch, "rows": rows,
                 "torch_rng": torch.get_rng_state()}
        atomic_write(self.path(CHECKPOINT), lambda f: torch.save(state, f))

    def _columns(self, row):
        terms = [k for k in row if k not in FIXED_COLUMNS and k not in TIMING_COLUMNS]
        return list(FIXED_COLUMNS) + terms + list(TIMING_COLUMNS)

    def _append_progress(self, row):
        path = self.path(PROGRESS)
        new = not os.path.exists(path) or os.path.getsize(path) == 0
        with open(path, "a", newline="", encoding="utf-8") as f:
            w = csv.DictWriter(f, fieldnames=self._columns(row))
            if new:
                w.writeheader()
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})

    def _truncate_progress(self, rows):
        """Keeps the header and the first ``rows`` rows of progress.csv: the rows a resumed run
        writes again after its checkpoint are dropped."""
        path = self.path(PROGRESS)
        if not os.path.exists(path):
            return
        with open(path, encoding="utf-8") as f:
            lines = f.readlines()
        keep = lines[:1 + rows] if rows else []
        if len(keep) != len(lines):
            text = "".join(keep)
            atomic_write(path, lambda f: f.write(text.encode("utf-8")))

    def _plot(self):
        try:
            plot_progress(self.out)
        except ImportError:  # matplotlib is optional: the CSV has the numbers
            pass

    # --- prediction ----------------------------------------------------------------------------

    def load_model(self):
        """The trained network (model.pt, else the last checkpoint's), in evaluation mode."""
        import torch

        torch.manual_seed(int(self.options["seed"]))
        model = self.baseline.build_model()
        if os.path.exists(self.path(MODEL)):
            state = torch.load(self.path(MODEL), map_location="cpu")
        elif os.path.exists(self.path(CHECKPOINT)):
            state = torch.load(self.path(CHECKPOINT), map_location="cpu")["model"]
            self._log(f"no {MODEL} yet: predicting with the last checkpoint")
        else:
            raise RunError(f"run '{self.out}' has no trained network ({MODEL} or {CHECKPOINT})")
        model.load_state_dict(state)
        return model.to(self.device).eval()

    def predict(self, split="test", data=None, shard=None, batch_size=None, results=None):
        """Predicts split ``split`` of ``data`` (default: the run's dataset) and scores it.
        ``shard`` (i, n) predicts only the items whose index modulo n is i. With ``results``
        (a file name) the shard's predictions go to that file and nothing is written into the
        run (a Ray unit's way: :meth:`merge` scores the files); without it they go to
        ``eval-<split>/results.shard-i-of-n.json``, and once every shard's file is there, any
        call (or ``shard=None``) merges them. Returns the evaluation's metrics dict (None for a
        shard whose siblings are not all done, or one written to ``results``)."""
        import torch

        if results is not None and shard is None:
            raise RunError("--results is a shard's file: give --shard i/N with it")
        data = os.path.abspath(data or self.data)
        dataset = open_split(self.kind, data, split)
        folder = self.path(f"eval-{split}")
        stem = "results" if self.kind == "detection" else "predictions"
        indices = list(range(len(dataset)))
        n_shards = 1
        if shard is not None:
            i, n_shards = shard
            indices = indices[i::n_shards]
        model = self.load_model()
        bs = int(batch_size or self.options["batch_size"])
        entries = []
        t0 = time.monotonic()
        with torch.no_grad():
            for start in range(0, len(indices), bs):
                chunk = indices[start:start + bs]
                rng = np.random.default_rng([int(self.options["seed"]), 1 << 31, chunk[0]])
                entries.extend(self.baseline.predict(model, dataset, chunk, self.device, rng))
        self._log(f"predicted {len(indices)} items of {split} in {time.monotonic() - t0:.1f} s")
        if results is not None:
            _write_json(results, {"format": SHARD_FORMAT, "baseline": self.name, "data": data,
                                  "split": split, "shard": [shard[0], n_shards],
                                  "entries": entries})
            return None
        os.makedirs(folder, exist_ok=True)
        if shard is not None:
            part = os.path.join(folder, f"{stem}.shard-{shard[0]}-of-{n_shards}.json")
            _write_json_list(part, entries)
            parts = [os.path.join(folder, f"{stem}.shard-{k}-of-{n_shards}.json")
                     for k in range(n_shards)]
            if not all(os.path.exists(p) for p in parts):
                return None
            entries = []
            for p in parts:
                with open(p, encoding="utf-8") as f:
                    entries.extend(json.load(f))
        return self._score(dataset, folder, stem, entries)

    def merge(self, files):
        """Scores the shards' files written by ``predict(shard=(i, n), results=FILE)``, one
        file per shard 0..n-1 of one split and dataset, as one unsharded ``predict`` of that
        split would (the same ``eval-<split>/`` files). Returns the metrics dict."""
        if not files:
            raise RunError("--merge needs the shards' results files")
        seen, entries, first = {}, [], None
        for path in files:
            doc = _read_json(path, "shard results")
            shard = doc.get("shard")
            if (doc.get("format") != SHARD_FORMAT or not isinstance(doc.get("entries"), list)
                    or not (isinstance(shard, list) and len(shard) == 2
                            and all(isinstance(x, int) and not isinstance(x, bool)
                                    for x in shard) and 0 <= shard[0] < shard[1])):
                raise RunError(f"shard results '{path}': not a file of 'partsim vision predict "
                               "--shard i/N --results FILE'")
            key = (doc.get("baseline"), doc.get("data"), doc.get("split"), shard[1])
            if doc.get("baseline") != self.name:
                raise RunError(f"shard results '{path}': predicted by {doc.get('baseline')}, "
                               f"this run trains {self.name}")
            if first is None:
                first = (path, key)
            elif key != first[1]:
                raise RunError(f"shard results '{path}': its data, split or shard count "
                               f"{key[1:]} differ from '{first[0]}' {first[1][1:]}")
            if shard[0] in seen:
                raise RunError(f"shard results '{path}': shard {shard[0]}/{shard[1]} is also "
                               f"in '{seen[shard[0]]}'")
            seen[shard[0]] = path
            entries.extend(doc["entries"])
        _, data, split, n = first[1]
        if len(seen) < n:
            # the first few missing shards: N comes from a file and may be huge
            missing, k = [], 0
            while len(missing) < min(5, n - len(seen)):
                if k not in seen:
                    missing.append(k)
                k += 1
            more = " and more" if n - len(seen) > len(missing) else ""
            raise RunError(f"--merge: shards {', '.join(f'{k}/{n}' for k in missing)}{more} "
                           "are missing")
        if split not in ("test", "train") or not isinstance(data, str):
            raise RunError(f"shard results '{first[0]}': bad 'split' or 'data'")
        dataset = open_split(self.kind, data, split)
        folder = self.path(f"eval-{split}")
        os.makedirs(folder, exist_ok=True)
        stem = "results" if self.kind == "detection" else "predictions"
        return self._score(dataset, folder, stem, entries)

    def _score(self, dataset, folder, stem, entries):
        from .. import vision

        if self.kind == "detection":
            entries.sort(key=lambda e: (e["image_id"], -e["score"]))
            _write_json_list(os.path.join(folder, f"{stem}.json"), entries)
            evaluation = vision.evaluate_detection(dataset.annotation_file, entries)
        else:
            entries.sort(key=lambda e: str(e["sample_id"]))
            doc = {"samples": entries}
            _write_json(os.path.join(folder, f"{stem}.json"), doc)
            evaluation = vision.evaluate_motion(dataset.annotation_file, doc)
        for name, text in (("table.md", evaluation.to_markdown()),
                           ("table.csv", evaluation.to_csv()),
                           ("metrics.json", evaluation.to_json())):
            atomic_write(os.path.join(folder, name), lambda f, t=text: f.write(t.encode("utf-8")))
        metrics = json.loads(evaluation.to_json())
        metrics["run"] = {"baseline": self.name, "input": self.options["input"],
                          "dataset": dataset.root, "split": dataset.split}
        return metrics


def _write_json_list(path, entries):
    text = "[\n" + ",\n".join(json.dumps(e, sort_keys=True) for e in entries) + "\n]\n"
    atomic_write(path, lambda f: f.write(text.encode("utf-8")))


def load_matching(model, path, state=None):
    """Loads the tensors of the state dict in file ``path`` whose names and shapes match
    ``model``'s (pretrained weights saved by torch.save, e.g. another run's model.pt); returns
    (loaded names, skipped names). Raises RunError when the file cannot be read or nothing
    matches. ``state``: the file's contents when the caller has read them already."""
    import torch

    if state is None:
        try:
            state = torch.load(path, map_location="cpu")
        except Exception as e:  # torch raises many kinds for a bad file
            raise RunError(f"weights '{path}' cannot be read: {type(e).__name__}: {e}") from None
    if isinstance(state, dict) and "model" in state and isinstance(state["model"], dict):
        state = state["model"]  # a checkpoint
    if not isinstance(state, dict):
        raise RunError(f"weights '{path}' hold no state dict")
    own = model.state_dict()
    loaded = [k for k, v in state.items()
              if k in own and hasattr(v, "shape") and tuple(v.shape) == tuple(own[k].shape)]
    skipped = [k for k in state if k not in loaded]
    if not loaded:
        raise RunError(f"weights '{path}': none of its {len(state)} tensors fits this network")
    own.update({k: state[k] for k in loaded})
    model.load_state_dict(own)
    return loaded, skipped


def read_progress(run):
    """progress.csv of run folder ``run`` as a dict of column -> list of floats."""
    path = os.path.join(os.fspath(run), PROGRESS)
    with open(path, encoding="utf-8") as f:
        rows = list(csv.DictReader(io.StringIO(f.read())))
    if not rows:
        raise RunError(f"'{path}' has no rows yet")
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def plot_progress(run, out=None):
    """Draws the loss and its terms of run folder ``run`` against the items seen (by default
    into ``run/curves.png``); returns the path. Needs matplotlib."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    p = read_progress(run)
    x = np.cumsum(p["items"])
    terms = [k for k in p if k not in FIXED_COLUMNS and k not in TIMING_COLUMNS]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    axes[0].plot(x, p["loss"], color="black")
    axes[0].set_title("loss")
    for k in terms:
        axes[1].plot(x, p[k], label=k)
    axes[1].set_title("loss terms")
    if terms:
        axes[1].legend(fontsize=7)
    for a in axes:
        a.set_xlabel("training items seen")
        a.set_yscale("log")
        a.grid(alpha=0.3)
    run_json = os.path.join(os.fspath(run), RUN_FILE)
    title = os.path.basename(os.path.abspath(os.fspath(run)))
    if os.path.exists(run_json):
        doc = _read_json(run_json, "run file")
        title = f"{doc.get('baseline')} ({doc.get('options', {}).get('input')}): {title}"
    fig.suptitle(title)
    fig.tight_layout()
    out = out or os.path.join(os.fspath(run), "curves.png")
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return out
