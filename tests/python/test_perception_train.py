"""The shared machinery of the perception baselines (partsim.perception.train and the
`partsim vision train|predict|table` commands): runs that continue exactly after a kill or a
longer --epochs, sharded prediction equal to one pass, the tables, weights loaded from a file,
and bad command lines and run folders refused with a message and exit code 2.

The network is the motion-attribute ResNet with the small resnet18 backbone on 32-pixel
pictures of the session's tiny dataset: the machinery does not depend on the model."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from conftest import PYTHON_DIR, require

torch = require("torch", "Debian's python3-torch")
require("torchvision", "Debian's python3-torchvision")

SMALL = ["--backbone", "resnet18", "--size", "32", "--batch-size", "4", "--seed", "3",
         "--quiet"]


def vision(cli, *args, ok=True, timeout=600):
    r = subprocess.run([cli, "vision"] + [str(a) for a in args], capture_output=True,
                       text=True, timeout=timeout)
    if ok:
        assert r.returncode == 0, "partsim vision %s: %s%s" % (" ".join(map(str, args)),
                                                               r.stdout, r.stderr)
    return r


def weights(run):
    return torch.load(os.path.join(run, "model.pt"), map_location="cpu")


def assert_same_weights(a, b):
    assert a.keys() == b.keys()
    for k in a:
        assert torch.equal(a[k], b[k]), k


@pytest.fixture(scope="module")
def straight(perception_data, tmp_path_factory):
    """A run of 2 epochs in one go (4 batches per epoch), predicted on the test split."""
    run = str(tmp_path_factory.mktemp("perception_train") / "straight")
    vision(perception_data.cli, "train", "motion-resnet", "--data", perception_data.mot,
           "--out", run, "--epochs", 2, "--log-every", 1, *SMALL)
    return run


def test_a_run_continued_to_more_epochs_equals_one_run(perception_data, straight, tmp_path):
    run = str(tmp_path / "continued")
    vision(perception_data.cli, "train", "motion-resnet", "--data", perception_data.mot,
           "--out", run, "--epochs", 1, "--log-every", 1, "--no-eval", *SMALL)
    one = weights(run)
    vision(perception_data.cli, "train", "motion-resnet", "--data", perception_data.mot,
           "--out", run, "--epochs", 2, "--log-every", 1, "--no-eval", *SMALL)
    assert_same_weights(weights(run), weights(straight))
    assert any(not torch.equal(one[k], weights(run)[k]) for k in one)  # it did train on
    # the log is the straight run's, but for the timing columns
    def rows(r):
        with open(os.path.join(r, "progress.csv")) as f:
            lines = f.read().splitlines()
        head = lines[0].split(",")
        keep = [i for i, h in enumerate(head) if h not in ("items_per_s", "wall_s")]
        return [[line.split(",")[i] for i in keep] for line in lines]
    assert rows(run) == rows(straight)
    assert len(rows(run)) == 1 + 2 * 4
    assert os.path.getsize(os.path.join(run, "curves.png")) > 1000


def test_a_run_trained_further_drops_its_earlier_model(perception_data, tmp_path):
    """model.pt is the network of the run's last epoch: a run continued to more epochs removes
    the earlier one, so that predict, meanwhile, takes the newer checkpoint."""
    run = str(tmp_path / "further")
    args = ["train", "motion-resnet", "--data", perception_data.mot, "--out", run,
            "--log-every", "1", "--checkpoint-minutes", "1e-9", "--no-eval", *SMALL]
    vision(perception_data.cli, *args, "--epochs", 1)
    first = weights(run)
    p = subprocess.Popen([perception_data.cli, "vision"] + args + ["--epochs", "3"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    checkpoint = os.path.join(run, "checkpoint.pt")
    start = os.path.getmtime(checkpoint)
    deadline = time.monotonic() + 300
    while (os.path.getmtime(checkpoint) == start and p.poll() is None
           and time.monotonic() < deadline):
        time.sleep(0.05)
    p.send_signal(signal.SIGKILL)
    p.wait()
    assert not os.path.exists(os.path.join(run, "model.pt"))
    r = vision(perception_data.cli, "predict", run)
    assert "predicting with the last checkpoint" in r.stderr
    newer = torch.load(checkpoint, map_location="cpu")["model"]
    assert any(not torch.equal(first[k], newer[k]) for k in first)


def test_a_killed_run_continues_where_its_checkpoint_was(perception_data, straight, tmp_path):
    """Checkpoints after every logged batch (--checkpoint-minutes tiny); the process is killed
    with SIGKILL once one exists, then started again with the same command."""
    run = str(tmp_path / "killed")
    args = [perception_data.cli, "vision", "train", "motion-resnet", "--data",
            perception_data.mot, "--out", run, "--epochs", "2", "--log-every", "1",
            "--checkpoint-minutes", "1e-9", "--no-eval"] + SMALL
    p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    checkpoint = os.path.join(run, "checkpoint.pt")
    deadline = time.monotonic() + 300
    while not os.path.exists(checkpoint) and p.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    p.send_signal(signal.SIGKILL)
    p.wait()
    assert os.path.exists(checkpoint)
    assert not os.path.exists(os.path.join(run, "model.pt"))
    vision(perception_data.cli, *args[2:])
    assert_same_weights(weights(run), weights(straight))


def test_sharded_prediction_equals_one_pass(perception_data, straight, tmp_path):
    with open(os.path.join(straight, "eval-test", "predictions.json")) as f:
        whole = json.load(f)
    first = vision(perception_data.cli, "predict", straight, "--shard", "0/2", "--quiet")
    assert "not all done" in first.stdout
    os.remove(os.path.join(straight, "eval-test", "predictions.json"))
    vision(perception_data.cli, "predict", straight, "--shard", "1/2", "--quiet")
    with open(os.path.join(straight, "eval-test", "predictions.json")) as f:
        merged = json.load(f)
    assert len(merged["samples"]) == len(whole["samples"]) > 0
    for a, b in zip(merged["samples"], whole["samples"]):
        assert a["sample_id"] == b["sample_id"]
        np.testing.assert_allclose(a["m"], b["m"], rtol=1e-5, atol=1e-6)


def test_shards_written_to_files_merge_to_one_pass(perception_data, straight, tmp_path):
    """--shard i/N --results FILE (a Ray unit's way) writes nothing into the run; --merge
    scores the files as one pass would."""
    cli, folder = perception_data.cli, os.path.join(straight, "eval-test")
    with open(os.path.join(folder, "predictions.json")) as f:
        whole = json.load(f)
    with open(os.path.join(folder, "metrics.json")) as f:
        whole_metrics = json.load(f)
    before = sorted(os.listdir(folder))
    files = [str(tmp_path / f"shard{i}.json") for i in range(3)]
    for i, path in enumerate(files):
        r = vision(cli, "predict", straight, "--shard", f"{i}/3", "--results", path)
        assert f"shard {i}/3 written to {path}" in r.stdout
    assert sorted(os.listdir(folder)) == before
    # bad merges: named, exit 2, the run's evaluation left as it was
    other = str(tmp_path / "other.json")
    with open(other, "w") as f:
        json.dump({"episodes": []}, f)
    # a shard count of 10^18 in a file: named at once, not counted out
    huge = str(tmp_path / "huge.json")
    with open(files[0]) as f:
        doc = json.load(f)
    with open(huge, "w") as f:
        json.dump(dict(doc, shard=[0, 10**18]), f)
    for args, message in (
            ([huge], "shards 1/1000000000000000000, 2/1000000000000000000, "
                     "3/1000000000000000000, 4/1000000000000000000, "
                     "5/1000000000000000000 and more are missing"),
            (files[:2], "shards 2/3 are missing"),
            (files + [files[1]], "shard 1/3 is also in"),
            (files[:2] + [other], "not a file of 'partsim vision predict"),
            ([str(tmp_path / "none.json")], "none.json' cannot be read")):
        r = vision(cli, "predict", straight, "--merge", *args, ok=False)
        assert r.returncode == 2 and message in r.stderr, (args, r.stderr)
    r = vision(cli, "predict", straight, "--results", files[0], ok=False)
    assert r.returncode == 2 and "give --shard i/N with it" in r.stderr
    os.remove(os.path.join(folder, "predictions.json"))
    os.remove(os.path.join(folder, "metrics.json"))
    r = vision(cli, "predict", straight, "--merge", files[2], files[0], files[1])
    assert "hinge_accuracy" in r.stdout
    with open(os.path.join(folder, "predictions.json")) as f:
        merged = json.load(f)
    with open(os.path.join(folder, "metrics.json")) as f:
        assert json.load(f) == whole_metrics
    assert [a["sample_id"] for a in merged["samples"]] == \
        [b["sample_id"] for b in whole["samples"]]
    for a, b in zip(merged["samples"], whole["samples"]):
        np.testing.assert_allclose(a["m"], b["m"], rtol=1e-5, atol=1e-6)


def test_network_options_from_the_command_line(perception_data, tmp_path):
    """--width of the PointNet++ baselines reaches the network and run.json; a run continued
    with another width is refused."""
    run = str(tmp_path / "narrow")
    args = ["train", "motion-pointnet", "--data", perception_data.mot, "--out", run,
            "--backbone", "small", "--points", "256", "--epochs", "1", "--no-eval", "--quiet"]
    vision(perception_data.cli, *args, "--width", "0.5")
    with open(os.path.join(run, "run.json")) as f:
        doc = json.load(f)
    assert doc["model"]["width"] == 0.5 and doc["options"]["width"] == 0.5
    narrow = sum(v.numel() for v in weights(run).values())
    wide = str(tmp_path / "wide")
    vision(perception_data.cli, *[wide if a == run else a for a in args], "--width", "1")
    assert sum(v.numel() for v in weights(wide).values()) > 2 * narrow
    r = vision(perception_data.cli, *args, "--width", "2", ok=False)
    assert r.returncode == 2 and "was started with width=0.5" in r.stderr


def test_the_table_puts_the_run_beside_the_paper(perception_data, straight, tmp_path):
    out = str(tmp_path / "table.md")
    r = vision(perception_data.cli, "table", straight, "--out", out)
    assert "Table 2" in r.stdout and "Table 1" not in r.stdout
    lines = r.stdout.splitlines()
    paper = [line for line in lines if "| paper |" in line]
    assert len(paper) == 2 and "| 95.5% | 95.5% | 0.168 |" in paper[0]
    ours = [line for line in lines if "partsim `straight`" in line]
    assert len(ours) == 1
    with open(os.path.join(straight, "eval-test", "metrics.json")) as f:
        metrics = json.load(f)
    assert ("%.1f%%" % (100 * metrics["hinge_accuracy"])) in ours[0]
    with open(out) as f:
        assert f.read().strip() == r.stdout.strip()
    # a run never predicted is named
    bare = str(tmp_path / "bare")
    vision(perception_data.cli, "train", "motion-resnet", "--data", perception_data.mot,
           "--out", bare, "--epochs", 1, "--no-eval", *SMALL)
    r = vision(perception_data.cli, "table", bare, ok=False)
    assert r.returncode == 1 and "eval-test/metrics.json" in r.stderr and "predict" in r.stderr


def test_init_loads_the_tensors_that_fit(perception_data, straight, tmp_path):
    sys.path.insert(0, PYTHON_DIR)
    from partsim.perception.train import Run, load_matching, RunError

    run = Run(str(tmp_path / "init"), baseline="motion-resnet", data=perception_data.mot,
              device="cpu", quiet=True, backbone="resnet18", size=32, epochs=1)
    model = run.baseline.build_model()
    saved = weights(straight)
    loaded, skipped = load_matching(model, os.path.join(straight, "model.pt"))
    assert set(loaded) == set(saved) and skipped == []
    for k, v in model.state_dict().items():
        assert torch.equal(v, saved[k]), k
    # a file of another network's tensors: nothing fits
    other = str(tmp_path / "other.pt")
    torch.save({"fc.weight": torch.zeros(3, 3)}, other)
    with pytest.raises(RunError, match="none of its 1 tensors fits"):
        load_matching(model, other)
    with open(str(tmp_path / "garbage.pt"), "wb") as f:
        f.write(b"\x00not a torch file")
    with pytest.raises(RunError, match="garbage.pt' cannot be read"):
        load_matching(model, str(tmp_path / "garbage.pt"))


def test_bad_command_lines_and_run_folders(perception_data, straight, tmp_path):
    cli, mot = perception_data.cli, perception_data.mot
    cases = [
        (["train", "yolo", "--data", mot, "--out", str(tmp_path / "a")], "invalid choice"),
        (["train", "maskrcnn", "--data", mot, "--out", str(tmp_path / "a"), "--input",
          "xyz"], "takes --input rgb or rgbd"),
        (["train", "motion-resnet", "--data", mot, "--out", str(tmp_path / "a"), "--epochs",
          "0"], "positive integer"),
        (["train", "motion-resnet", "--data", mot, "--out", str(tmp_path / "a"), "--lr",
          "nan"], "positive number"),
        (["train", "motion-resnet", "--data", mot, "--out", str(tmp_path / "a"), "--device",
          "tpu"], "auto, cpu or cuda"),
        (["train", "motion-resnet", "--data", mot, "--out", straight, "--lr", "0.5"],
         "was started with lr="),
        (["train", "insseg", "--data", mot, "--out", straight], "trains motion-resnet"),
        (["train", "motion-resnet", "--data", mot, "--out", str(tmp_path / "a"), "--backbone",
          "vgg"], "vgg"),
        (["predict", str(tmp_path / "nothing")], "holds no run"),
        (["predict", straight, "--shard", "2/2"], "i must be in [0, N)"),
        (["predict", straight, "--merge", "a.json", "--shard", "0/2"],
         "--merge takes the run and the shards' files only"),
        (["train", "insseg", "--data", mot, "--out", str(tmp_path / "a"), "--width", "0"],
         "positive number"),
    ]
    if not torch.cuda.is_available():
        cases.append((["train", "motion-resnet", "--data", mot, "--out", str(tmp_path / "a"),
                       "--device", "cuda"], "PyTorch sees no GPU"))
    for args, message in cases:
        r = vision(cli, *args, ok=False)
        assert r.returncode == 2, (args, r.stdout, r.stderr)
        assert message in r.stderr, (args, r.stderr)
    # a damaged run.json is named, and the run's files stay as they were
    broken = tmp_path / "broken"
    broken.mkdir()
    (broken / "run.json").write_text("[" * 100000)
    r = vision(cli, "predict", str(broken), ok=False)
    assert r.returncode == 2 and "run.json' cannot be read" in r.stderr
    assert (broken / "run.json").read_text() == "[" * 100000
    # a run.json with a huge number or garbage where a name goes: refused, named, left alone
    with open(os.path.join(straight, "run.json")) as f:
        good = json.load(f)
    for key, value, message in (("epochs", "1e999", "'epochs' must be a positive integer"),
                                ("lr", "-1", "'lr' must be a positive number"),
                                ("baseline", r'"\u00e9\u2603\ud83d\ude00"',
                                 "'baseline' must be one of")):
        # the value written into the JSON text as it is (1e999 reads back as infinity)
        if key == "baseline":
            text = json.dumps(dict(good, baseline="@")).replace('"@"', value)
        else:
            text = json.dumps(dict(good, options=dict(good["options"], **{key: "@"})))
            text = text.replace('"@"', value)
        (broken / "run.json").write_text(text)
        r = vision(cli, "predict", str(broken), ok=False)
        assert r.returncode == 2 and message in r.stderr, (key, r.stderr)
        assert (broken / "run.json").read_text() == text
    r = vision(cli, "train", "motion-resnet", "--data", str(tmp_path / "no-data"), "--out",
               str(tmp_path / "b"), ok=False)
    assert r.returncode == 1 and "no-data" in r.stderr
