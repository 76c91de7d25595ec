"""`--shard i/N` of the list-shaped commands, and their merges: the shards of a run, put together,
are byte for byte the run done at once (assets generate's tree; assets check's printout, report
and results; tasks evaluate's printout and CSV, the simulated seconds aside), and the merges
refuse what is not the shards of one run, naming the files."""

import csv
import filecmp
import io
import os
import subprocess

import pytest

from conftest import PYTHON_DIR

CLI = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                                 "partsim"))
GENERATE = ["--categories", "StorageFurniture,Door,Laptop", "--per-category", "2", "--seed", "7"]


def partsim(*args, cwd=None):
    return subprocess.run([CLI, *args], capture_output=True, text=True, timeout=120, cwd=cwd)


def tree(root):
    """Every file under `root`, relative path -> bytes, and every folder."""
    files, folders = {}, set()
    for d, dirs, names in os.walk(root):
        folders.update(os.path.relpath(os.path.join(d, x), root) for x in dirs)
        for n in names:
            with open(os.path.join(d, n), "rb") as f:
                files[os.path.relpath(os.path.join(d, n), root)] = f.read()
    return files, folders


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    """A single run's tree of 6 objects, with a folder that fails the check beside them."""
    out = tmp_path_factory.mktemp("single") / "ds"
    r = partsim("assets", "generate", "--out", str(out), *GENERATE)
    assert r.returncode == 0, r.stderr
    return out


def test_generate_shards_into_one_folder_make_the_single_run_s_tree(dataset, tmp_path):
    out = tmp_path / "ds"
    for i in (2, 0, 1):
        r = partsim("assets", "generate", "--out", str(out), *GENERATE, "--shard", f"{i}/3")
        assert r.returncode == 0, r.stderr
        assert f"wrote 2 objects to {out} (shard {i}/3)" in r.stderr, r.stderr
    assert tree(out) == tree(dataset)
    # a shard run again skips its objects, whole already, and rewrites nothing
    stamp = os.stat(out / "1030000" / "mobility.urdf").st_mtime_ns
    r = partsim("assets", "generate", "--out", str(out), *GENERATE, "--shard", "0/3")
    assert r.returncode == 0, r.stderr
    assert "wrote 0 objects" in r.stderr and "skipped 2 already there" in r.stderr, r.stderr
    assert os.stat(out / "1030000" / "mobility.urdf").st_mtime_ns == stamp
    # ... or rewrites them with --overwrite, leaving the other shards' objects
    (out / "1030000" / "stale.txt").write_text("old")
    (out / "1030001" / "stale.txt").write_text("not shard 0's")
    r = partsim("assets", "generate", "--out", str(out), *GENERATE, "--shard", "0/3",
                "--overwrite")
    assert r.returncode == 0, r.stderr
    assert not (out / "1030000" / "stale.txt").exists()
    assert (out / "1030001" / "stale.txt").exists()
    # another seed's object under this shard's name is not taken for this run's
    r = partsim("assets", "generate", "--out", str(out), *GENERATE[:-1], "8", "--shard", "0/3")
    assert r.returncode == 1
    assert "1030000" in r.stderr and "another seed" in r.stderr, r.stderr


def test_check_merge_prints_reports_and_writes_what_one_run_does(dataset, tmp_path):
    root = tmp_path / "ds"
    root.mkdir()
    for name in os.listdir(dataset):
        os.symlink(dataset / name, root / name, target_is_directory=True)
    # a folder holding only a mesh fails to load: the merge has failures to print
    (root / "999" / "textured_objs").mkdir(parents=True)
    (root / "999" / "textured_objs" / "original-0.obj").write_text("v 0 0 0\n")
    common = ["--no-visibility", "--jobs", "1"]
    single = partsim("assets", "check", "ds", *common, "--report", "single.txt", "--results",
                     "single.json", cwd=tmp_path)
    assert single.returncode == 1, single.stderr
    assert "checked 7 objects: 6 passed, 1 failed" in single.stdout
    assert "999" in single.stderr
    shards = []
    for i in range(3):
        r = partsim("assets", "check", "ds", *common, "--shard", f"{i}/3", "--results",
                    f"s{i}.json", cwd=tmp_path)
        assert r.returncode in (0, 1), r.stderr
        shards.append(f"s{i}.json")
    merged = partsim("assets", "check", "--merge", *reversed(shards), "--report", "merged.txt",
                     "--results", "merged.json", cwd=tmp_path)
    assert merged.returncode == single.returncode, merged.stderr
    assert merged.stdout == single.stdout
    assert "999" in merged.stderr
    assert filecmp.cmp(tmp_path / "single.txt", tmp_path / "merged.txt", shallow=False)
    assert filecmp.cmp(tmp_path / "single.json", tmp_path / "merged.json", shallow=False)
    # what is not the shards of one check
    r = partsim("assets", "check", "--merge", "s0.json", "s1.json", "s0.json", cwd=tmp_path)
    assert r.returncode == 1 and "'s0.json' and 's0.json'" in r.stderr, r.stderr
    assert "overlap" in r.stderr
    r = partsim("assets", "check", "--merge", "s0.json", "s1.json", cwd=tmp_path)
    assert r.returncode == 1 and "cover" in r.stderr and "missing" in r.stderr, r.stderr
    r = partsim("assets", "check", "--merge", "s0.json", "nope.json", cwd=tmp_path)
    assert r.returncode == 1 and "nope.json" in r.stderr, r.stderr
    # a check of another folder
    r = partsim("assets", "check", str(dataset), "--no-visibility", "--shard", "1/3",
                "--results", "other.json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    r = partsim("assets", "check", "--merge", "s0.json", "other.json", "s2.json", cwd=tmp_path)
    assert r.returncode == 1 and "'s0.json' and 'other.json'" in r.stderr, r.stderr
    assert "different checks" in r.stderr


def without_seconds(text):
    rows = list(csv.reader(io.StringIO(text)))
    assert rows[0][4] == "seconds"
    return [row[:4] + row[5:] for row in rows]


def test_tasks_evaluate_merge_is_the_single_run(tmp_path):
    run = ["tasks", "evaluate", "--count", "3", "--no-cameras"]
    single = partsim(*run, "--csv", "single.csv", cwd=tmp_path)
    assert single.returncode == 0, single.stderr
    assert " / 3 succeeded" in single.stdout
    single_csv = (tmp_path / "single.csv").read_text()
    for i in range(2):
        r = partsim(*run, "--shard", f"{i}/2", "--csv", f"s{i}.csv", cwd=tmp_path)
        assert r.returncode == 0, r.stderr
    # a shard's CSV: its line, then the whole run's header and its episodes' rows
    shard0 = (tmp_path / "s0.csv").read_text().splitlines()
    assert shard0[0].startswith("# partsim tasks evaluate shard: ")
    assert len(shard0) == 2 + 2
    single_rows = single_csv.splitlines()
    assert without_seconds("\n".join(shard0[1:])) == without_seconds(
        "\n".join([single_rows[0], single_rows[1], single_rows[3]]))
    merged = partsim("tasks", "evaluate", "--merge", "s1.csv", "s0.csv", "--csv", "merged.csv",
                     cwd=tmp_path)
    assert merged.returncode == 0, merged.stderr
    assert merged.stdout == single.stdout
    assert without_seconds((tmp_path / "merged.csv").read_text()) == without_seconds(single_csv)
    # what is not the shards of one run
    r = partsim("tasks", "evaluate", "--merge", "s0.csv", "s0.csv", "s1.csv", cwd=tmp_path)
    assert r.returncode == 1 and "'s0.csv' and 's0.csv'" in r.stderr, r.stderr
    assert "overlap" in r.stderr
    r = partsim("tasks", "evaluate", "--merge", "s0.csv", cwd=tmp_path)
    assert r.returncode == 1 and "missing" in r.stderr, r.stderr
    r = partsim("tasks", "evaluate", "--merge", "s0.csv", "nope.csv", cwd=tmp_path)
    assert r.returncode == 1 and "nope.csv" in r.stderr, r.stderr
    r = partsim("tasks", "evaluate", "--merge", "single.csv", cwd=tmp_path)
    assert r.returncode == 1 and "single.csv" in r.stderr, r.stderr
    r = partsim("tasks", "evaluate", "--task", "door", "--count", "3", "--no-cameras",
                "--shard", "1/2", "--csv", "door.csv", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    r = partsim("tasks", "evaluate", "--merge", "s0.csv", "door.csv", cwd=tmp_path)
    assert r.returncode == 1 and "'s0.csv' and 'door.csv'" in r.stderr, r.stderr
    assert "different runs" in r.stderr


@pytest.mark.parametrize("command", [
    ["assets", "generate", "--out", "x"],
    ["assets", "check", "x"],
    ["tasks", "evaluate"],
    ["vision", "detection-dataset", "--dataset", "x", "--out", "y"],
])
@pytest.mark.parametrize("shard", ["3/3", "x", "1/0", "-1/2", "1/", "0/2x"])
def test_a_bad_shard_is_a_command_line_error(command, shard, tmp_path):
    r = partsim(*command, "--shard", shard, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert f"--shard wants i/N with 0 <= i < N (e.g. 0/4), got '{shard}'" in r.stderr
    assert not os.listdir(tmp_path)


def test_merges_take_only_their_own_flags(tmp_path):
    r = partsim("tasks", "evaluate", "--merge", "a.csv", "--count", "3", cwd=tmp_path)
    assert r.returncode == 2 and "--count" in r.stderr, r.stderr
    r = partsim("assets", "check", "--merge", "a.json", "--jobs", "2", cwd=tmp_path)
    assert r.returncode == 2 and "--jobs" in r.stderr, r.stderr
