"""The learning protocol (partsim.learn.protocol and `partsim learn`) on tiny configurations:
the object split, train -> evaluate -> table through the real command line, resuming a run,
refusing a folder of another run, the bad arguments, and the environments' `opened` info that
the door metric reads."""

import csv
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import PYTHON_DIR, require

torch = require("torch", "python3-torch (scripts/setup.sh)")

import partsim.envs as envs  # noqa: E402
from partsim.learn import protocol  # noqa: E402

CLI = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                                 "partsim"))

# a run small enough for the suite: 2 environments, 400 steps in two segments, 2 test objects
TINY = ["--train-objects", "2", "--steps", "400", "--warmup-steps", "100", "--num-envs", "2",
        "--test-objects", "2", "--checkpoint-interval", "200", "--log-interval", "100",
        "--batch-size", "32", "--hidden", "32,32", "--max-episode-steps", "60",
        "--buffer-size", "5000", "--quiet"]


def learn(*args, check=True):
    """Runs `partsim learn ARGS`; returns the CompletedProcess."""
    result = subprocess.run([CLI, "learn"] + [str(a) for a in args], capture_output=True,
                            text=True, timeout=600)
    if check:
        assert result.returncode == 0, result.stderr
    return result


def test_split_nests_training_sets_and_keeps_one_test_set():
    splits = {}
    for n in protocol.TRAIN_SIZES:
        config = protocol.RunConfig(task="drawer", train_objects=n, test_objects=4)
        splits[n] = protocol.task_objects(config)
    tests = {tuple(test) for _, test in splits.values()}
    assert len(tests) == 1, "every training size must be tested on the same objects"
    test = set(next(iter(tests)))
    assert len(test) == 4
    for n, (train, _) in splits.items():
        assert len(train) == n and len(set(train)) == n
        assert not set(train) & test, f"{n} training objects overlap the test set"
    for small, large in zip(protocol.TRAIN_SIZES, protocol.TRAIN_SIZES[1:]):
        assert splits[small][0] == splits[large][0][:small]
    # the training seed does not move the split; the split seed does
    seeded = protocol.task_objects(protocol.RunConfig(task="drawer", train_objects=4,
                                                      test_objects=4, seed=9))
    assert seeded == splits[4]
    other = protocol.task_objects(protocol.RunConfig(task="drawer", train_objects=4,
                                                     test_objects=4, split_seed=1))
    assert other != splits[4]
    # the objects have the task's target
    ps = sys.modules["partsim"]._partsim
    assert set(splits[16][0]) <= set(ps.find_task_objects(ps.parse_task_type("drawer"), 20, 0))


def test_split_of_a_dataset_tree_leaves_unseen_objects(tmp_path):
    root = tmp_path / "tree"
    subprocess.run([CLI, "assets", "generate", "--out", root, "--categories",
                    "StorageFurniture", "--per-category", "5", "--seed", "2"], check=True,
                   capture_output=True, timeout=300)
    pool = protocol._dataset_pool("drawer", str(root))
    assert pool and all(os.path.isfile(os.path.join(p, "mobility.urdf")) for p in pool)
    train, test = protocol.task_objects(protocol.RunConfig(
        task="drawer", train_objects=len(pool) - 1, dataset=str(root), test_objects=0))
    assert len(test) == 1 and not set(train) & set(test)
    assert sorted(train + test) == sorted(pool)
    with pytest.raises(ValueError, match="at least one must stay unseen"):
        protocol.task_objects(protocol.RunConfig(task="drawer", train_objects=len(pool),
                                                 dataset=str(root)))
    with pytest.raises(ValueError, match="not a folder"):
        protocol.task_objects(protocol.RunConfig(dataset=str(tmp_path / "missing")))


def test_opened_is_the_targets_displacement():
    env = envs.OpenCabinetEnv(task="door", obs_mode="mobility", max_episode_steps=5)
    try:
        env.reset(seed=3)
        _, _, _, _, info = env.step(np.zeros(7))
        joint = env.task.target_joint
        lo, hi = np.asarray(joint.get_limits()).reshape(-1)[:2]
        assert info["opened"] == pytest.approx(info["progress"] * (hi - lo), abs=1e-12)
        assert info["opened"] == pytest.approx(
            min(abs(joint.get_qpos() - lo), abs(hi - joint.get_qpos())), abs=1e-9)
    finally:
        env.close()


def test_train_evaluate_table_through_the_command_line(tmp_path):
    run = tmp_path / "run"
    learn("train", "--task", "drawer", "--obs", "mobility", "--seed", "0", "--out", run, *TINY)
    doc = json.loads((run / "run.json").read_text())
    assert doc["config"]["train_objects"] == 2 and len(doc["train"]) == 2
    assert len(doc["test"]) == 2 and not set(doc["train"]) & set(doc["test"])
    with open(run / "progress.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["env_steps"]) for r in rows] == [100, 200, 300, 400]
    assert int(rows[-1]["updates"]) > 0 and float(rows[-1]["updates_per_s"]) > 0
    assert (run / "curves.png").stat().st_size > 1000
    with open(run / "curves.png", "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"

    # a second start of the finished run changes nothing
    before = (run / "progress.csv").read_bytes()
    learn("train", "--task", "drawer", "--obs", "mobility", "--seed", "0", "--out", run, *TINY)
    assert (run / "progress.csv").read_bytes() == before
    # a folder of another run is refused, naming what differs
    bad = learn("train", "--task", "drawer", "--obs", "mobility", "--seed", "1", "--out", run,
                *TINY, check=False)
    assert bad.returncode == 2 and "seed" in bad.stderr

    out = learn("evaluate", run, "--episodes", "2", "--quiet").stdout
    assert "train: success rate at 80% of the range" in out and "test:" in out
    ev = json.loads((run / "eval.json").read_text())
    assert ev["policy"] == "agent" and ev["episodes"] == 2
    # the steps of the checkpoint played (the table marks cells by them), and the run's target
    assert ev["steps"] == ev["run_steps"] == 400
    for part in ("train", "test"):
        assert [o["object"] for o in ev[part]["objects"]] == doc[part]
        assert 0.0 <= ev[part]["metric"] <= 1.0
    with open(run / "eval.csv", newline="") as f:
        episodes = list(csv.DictReader(f))
    assert len(episodes) == 2 * 2 * 2
    # the drawer metric is the share of episodes ending at >= 80% of the range
    test_rows = [r for r in episodes if r["set"] == "test"]
    assert ev["test"]["metric"] == pytest.approx(
        np.mean([float(r["progress"]) >= 0.8 for r in test_rows]))
    # evaluation is deterministic
    learn("evaluate", run, "--episodes", "2", "--quiet")
    assert json.loads((run / "eval.json").read_text()) == ev
    # a random baseline goes to its own file
    learn("evaluate", run, "--episodes", "1", "--random", "--quiet")
    assert json.loads((run / "eval_random.json").read_text())["policy"] == "random"
    assert json.loads((run / "eval.json").read_text()) == ev

    table = learn("table", run).stdout
    # a run of 400 steps: its cells are marked reduced
    cell = f"{ev['train']['metric']:.2f}† (0.83)"
    assert "| mobility-exp | train |" in table and cell in table
    assert "- (85.4)" in table  # raw door: no run, the paper's number
    assert "training steps per run: 400 (the paper: 1,000,000); †: reduced" in table
    rows = learn("table", run, "--csv").stdout.splitlines()
    assert rows[0] == "obs,task,set,train_objects,ours,runs,paper,steps"
    assert any(r.startswith("mobility,drawer,test,2,") and r.endswith(",400") for r in rows)

    # hostile shard files for --merge: refused, naming the file; the run's eval files stay
    saved = (run / "eval.json").read_bytes()
    shard = json.loads(learn("evaluate", run, "--episodes", "2", "--shard", "0/2", "--results",
                             tmp_path / "s0.json", "--quiet").stdout and
                       (tmp_path / "s0.json").read_text())
    huge = dict(shard, objects=[dict(shard["objects"][0], index=10**30)])
    hostile = {"garbage.json": "\u00e9\u6f22\x00\ufffd{[".encode("utf-8", "surrogatepass"),
               "deep.json": b"[" * 100_000 + b"]" * 100_000,
               "huge.json": json.dumps(huge).encode()}
    for name, data in hostile.items():
        (tmp_path / name).write_bytes(data)
        bad = learn("evaluate", run, "--merge", tmp_path / name, tmp_path / "s0.json",
                    check=False)
        assert bad.returncode == 2 and name in bad.stderr, (name, bad.stderr)
        assert "Traceback" not in bad.stderr
        assert (run / "eval.json").read_bytes() == saved


def test_resume_after_an_interruption_continues_the_same_run(tmp_path):
    straight, cut = tmp_path / "straight", tmp_path / "cut"
    args = ["--task", "door", "--obs", "raw", "--seed", "3"]
    learn("train", *args, "--out", straight, *TINY)
    # the same run stopped at its first checkpoint (the first of two segments), then started
    # again for all its steps: what a crash's continuation does
    short = [a if a != "400" else "200" for a in TINY]
    learn("train", *args, "--out", cut, *short)
    learn("train", *args, "--out", cut, *TINY)
    assert json.loads((cut / "run.json").read_text())["config"]["steps"] == 400
    fewer = learn("train", *args, "--out", cut, *short, check=False)
    assert fewer.returncode == 2 and "has trained 400 steps already" in fewer.stderr
    a = (straight / "progress.csv").read_text().splitlines()
    b = (cut / "progress.csv").read_text().splitlines()
    timing = {"wall_s", "env_steps_per_s", "updates_per_s"}
    header = a[0].split(",")
    keep = [i for i, h in enumerate(header) if h not in timing]
    assert len(a) == len(b) == 5
    for ra, rb in zip(a[1:], b[1:]):
        assert [ra.split(",")[i] for i in keep] == [rb.split(",")[i] for i in keep]
    sa = torch.load(next(straight.glob("ckpt_*")) / "agent.pt")
    sb = torch.load(next(cut.glob("ckpt_*")) / "agent.pt")
    for name in ("actor", "critic"):
        for k, v in sa[name].items():
            assert torch.equal(v, sb[name][k]), f"{name}.{k} differs after the resume"


# a run shorter than its first log row and first checkpoint: 4 environments step together, so
# 10 steps end at 12
SHORT = ["--task", "drawer", "--obs", "mobility", "--seed", "0", "--train-objects", "2",
         "--test-objects", "2", "--num-envs", "4", "--hidden", "16,16", "--quiet"]


def progress_rows(run):
    with open(run / "progress.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_a_run_shorter_than_a_log_interval_finishes_and_a_rerun_exits_0(tmp_path):
    run = tmp_path / "run"
    first = learn("train", "--steps", "10", "--out", run, *SHORT)
    assert json.loads(first.stdout.splitlines()[-1])["env_steps"] == 12
    rows = progress_rows(run)
    assert [int(r["env_steps"]) for r in rows] == [12]  # the run's last step, logged
    assert int(rows[0]["updates"]) == 0 and rows[0]["q1_loss"] == ""  # all warm-up
    assert json.loads((run / "checkpoint.json").read_text())["env_steps"] == 12
    assert (run / "curves.png").stat().st_size > 1000

    # the same command again: finished, nothing changes
    files = {name: (run / name).read_bytes()
             for name in ("run.json", "progress.csv", "checkpoint.json", "curves.png")}
    again = learn("train", "--steps", "10", "--out", run, *SHORT)
    assert "already finished" in again.stderr and "12 environment steps" in again.stderr
    assert json.loads(again.stdout.splitlines()[-1]) == {"env_steps": 12,
                                                         "already_finished": True}
    for name, data in files.items():
        assert (run / name).read_bytes() == data, name
    # asking fewer steps than the run's own is still refused
    fewer = learn("train", "--steps", "8", "--out", run, *SHORT, check=False)
    assert fewer.returncode == 2 and "has trained 12 steps already" in fewer.stderr


def test_the_last_row_of_a_short_run_gives_way_when_it_is_continued(tmp_path):
    run = tmp_path / "run"
    learn("train", "--steps", "10", "--log-interval", "8", "--out", run, *SHORT)
    assert [int(r["env_steps"]) for r in progress_rows(run)] == [8, 12]
    # trained further: the row at 12 was the end of the shorter run, not an interval's
    learn("train", "--steps", "20", "--log-interval", "8", "--out", run, *SHORT)
    assert [int(r["env_steps"]) for r in progress_rows(run)] == [8, 16, 20]
    assert json.loads((run / "run.json").read_text())["config"]["steps"] == 20


def test_runs_hold_the_handle_unless_told_and_older_runs_keep_their_free_fingers():
    assert protocol.RunConfig().gripper == "closed"
    old = protocol.RunConfig(gripper="free").to_json()
    del old["gripper"]  # a run.json written before the option
    assert protocol.RunConfig.from_json(old).gripper == "free"
    env = protocol._make_env(protocol.RunConfig(), [protocol.task_objects(
        protocol.RunConfig())[0][0]], 1)
    assert env.single_action_space.shape == (6,)
    env.close()


def test_a_run_from_before_the_gripper_option_continues_with_free_fingers(tmp_path):
    run = tmp_path / "run"
    learn("train", "--steps", "10", "--gripper", "free", "--out", run, *SHORT)
    doc = json.loads((run / "run.json").read_text())
    del doc["config"]["gripper"]  # as such runs were written
    (run / "run.json").write_text(json.dumps(doc))
    bad = learn("train", "--steps", "20", "--out", run, *SHORT, check=False)
    assert bad.returncode == 2 and "other options (gripper)" in bad.stderr
    learn("train", "--steps", "20", "--gripper", "free", "--out", run, *SHORT)
    assert json.loads((run / "checkpoint.json").read_text())["env_steps"] >= 20


@pytest.mark.parametrize("hostile, train_says, evaluate_says", [
    (b"\xff\xfe garbage \xe9\x00", "run.json: cannot be read", "run.json: cannot be read"),
    (b"[" * 100_000 + b"]" * 100_000, "run.json: cannot be read", "run.json: cannot be read"),
    # hidden sizes of 1e999, which JSON reads as infinity
    (None, "other options (hidden_sizes)", "hidden_sizes must be a list of integers"),
])
def test_a_hostile_run_json_is_refused_by_name(tmp_path, hostile, train_says, evaluate_says):
    run = tmp_path / "run"
    learn("train", "--steps", "10", "--out", run, *SHORT)
    if hostile is None:
        doc = json.loads((run / "run.json").read_text())
        doc["config"]["hidden_sizes"] = [1e999]
        hostile = json.dumps(doc).encode()
    (run / "run.json").write_bytes(hostile)
    for args, says in ((["train", "--steps", "20", "--out", run, *SHORT], train_says),
                       (["evaluate", run], evaluate_says)):
        bad = learn(*args, check=False)
        assert bad.returncode == 2 and says in bad.stderr, (args[0], bad.stderr)
        assert "Traceback" not in bad.stderr
    assert (run / "run.json").read_bytes() == hostile  # nothing was written over it


def test_curves_of_several_runs_are_drawn_over_each_other(tmp_path):
    runs = [tmp_path / f"s{seed}" for seed in (0, 1)]
    for seed, run in enumerate(runs):
        learn("train", "--steps", "20", "--log-interval", "8", "--seed", str(seed), "--out", run,
              *SHORT)
    out = tmp_path / "both.png"
    done = learn("curves", *runs, "--out", out, "--labels", "seed 0,seed 1")
    assert done.stdout.strip() == str(out)
    with open(out, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    assert out.read_bytes() != (runs[0] / "curves.png").read_bytes()
    # several runs need a file to go to, and as many labels as runs
    bad = learn("curves", *runs, check=False)
    assert bad.returncode == 2 and "need --out" in bad.stderr
    bad = learn("curves", *runs, "--out", out, "--labels", "one", check=False)
    assert bad.returncode == 2 and "1 labels for 2 runs" in bad.stderr


@pytest.mark.parametrize("args, message", [
    (["train", "--task", "window", "--out", "X"], "task must be 'door' or 'drawer'"),
    (["train", "--obs", "depth", "--out", "X"], "obs must be"),
    (["train", "--train-objects", "0", "--out", "X"], "train_objects must be at least 1"),
    (["train", "--steps", "many", "--out", "X"], "--steps: 'many' is not a valid value"),
    (["train", "--task", "drawer"], "needs --out"),
    (["train", "--frobnicate", "1"], "unknown option --frobnicate"),
    (["train", "--steps"], "needs a value"),
    (["train", "--hidden", "0,4", "--out", "X"], "--hidden"),
    (["train", "--init-alpha", "0", "--out", "X"], "init_alpha must be > 0"),
    (["train", "--updates-per-step", "nan", "--out", "X"], "updates_per_step must be >= 0"),
    (["evaluate", "NOWHERE"], "not a run folder"),
    (["evaluate", "NOWHERE", "--episodes", "0"], "episodes must be at least 1"),
    (["table"], "at least one RUN"),
    (["frob"], "unknown command 'frob'"),
    (["train", "--device", "tpu", "--out", "X"], "--device wants auto, cpu or cuda"),
    (["train", "--gripper", "loose", "--out", "X"], "gripper must be 'closed' or 'free'"),
    (["evaluate", "NOWHERE", "--shard", "2/2", "--results", "F"], "--shard wants i/N"),
    (["evaluate", "NOWHERE", "--merge"], "needs the shards' results files"),
    (["sweep", "--out", "X", "--tasks", "lid", "--steps", "10"], "unknown task 'lid'"),
    (["sweep", "--out", "X"], "sweep needs --steps"),
    (["sweep", "--out", "X", "--steps", "10", "--frob", "1"], "unknown option --frob"),
    (["sweep", "--out", "X", "--task", "door", "--steps", "10"], "takes the grid as --tasks"),
])
def test_bad_command_lines_are_refused_by_name(tmp_path, args, message):
    args = [str(tmp_path / a) if a in ("X", "NOWHERE") else a for a in args]
    result = learn(*args, check=False)
    assert result.returncode == 2, result.stdout + result.stderr
    assert message in result.stderr
    assert not (tmp_path / "X").exists()


def test_device_cuda_without_a_gpu_is_refused_before_training(tmp_path):
    if torch.cuda.is_available():
        pytest.skip("this torch sees a GPU: --device cuda is valid here")
    result = learn("train", "--device", "cuda", "--out", tmp_path / "run", *SHORT, check=False)
    assert result.returncode == 2 and "PyTorch sees no GPU" in result.stderr
    assert not (tmp_path / "run" / "progress.csv").exists()


def test_table_refuses_an_unevaluated_or_broken_run(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    (run / "run.json").write_text(json.dumps({"config": {}}))
    result = learn("table", run, check=False)
    assert result.returncode == 2 and "has not been evaluated" in result.stderr
    (run / "eval.json").write_text("{not json")
    result = learn("table", run, check=False)
    assert result.returncode == 2 and "eval.json: cannot be read" in result.stderr
    (run / "run.json").write_text("[1, 2]")
    result = learn("evaluate", run, check=False)
    assert result.returncode == 2 and "has no 'config' object" in result.stderr


def test_the_module_entry_point_is_the_same_command(tmp_path):
    env = dict(os.environ, PYTHONPATH=os.path.abspath(PYTHON_DIR))
    result = subprocess.run([sys.executable, "-m", "partsim.learn", "--help"],
                            capture_output=True, text=True, env=env, timeout=120)
    assert result.returncode == 0 and "partsim learn train" in result.stdout
    assert learn("--help").stdout == result.stdout


def test_without_torch_the_commands_say_what_to_install(tmp_path):
    code = (
        "import sys; sys.modules['torch'] = None\n"  # an interpreter without PyTorch
        "from partsim.learn.protocol import main\n"
        "import partsim.learn as learn\n"
        "try:\n"
        "    learn.SAC\n"
        "except ImportError as e:\n"
        "    print('import:', e)\n"
        f"sys.exit(main(['train', '--out', {str(tmp_path / 'run')!r}]))\n"
    )
    env = dict(os.environ, PYTHONPATH=os.path.abspath(PYTHON_DIR))
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            env=env, timeout=120)
    assert result.returncode == 1, result.stderr
    assert "import: partsim.learn needs PyTorch" in result.stdout
    assert "needs torch: install Debian's python3-torch" in result.stderr
    assert not (tmp_path / "run").exists()


def test_an_evaluation_records_the_steps_its_checkpoint_trained(tmp_path):
    """A run evaluated before its end is recorded (and marked in the table) by the steps of
    the checkpoint played, not by its --steps; without a readable checkpoint.json, --steps."""
    from partsim.learn.protocol import RunConfig, _trained_steps

    config = RunConfig(task="drawer", obs="mobility", train_objects=2, steps=1_000_000)
    assert _trained_steps(str(tmp_path), config) == 1_000_000
    pointer = tmp_path / "checkpoint.json"
    pointer.write_text(json.dumps({"dir": "ckpt_000000280000", "env_steps": 280000}))
    assert _trained_steps(str(tmp_path), config) == 280000
    for bad in ('{"env_steps": 1e999}', '{"env_steps": true}', '{"env_steps": -5}', "[",
                '{"dir": "x"}'):
        pointer.write_text(bad)
        assert _trained_steps(str(tmp_path), config) == 1_000_000, bad
