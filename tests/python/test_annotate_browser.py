"""The annotation page of `partsim annotate` (docs/annotation.md) in a real browser: headless
Chromium (Debian's) driven by puppeteer-core (web/node_modules) answers every question of
generated objects whose answer is known.

The module fixture generates objects of four categories twice with the same seed, as
PartNet-Mobility objects (the truth: mobility_v2.json) and as annotation tasks
(`--unannotated`: the part tree and its meshes, no mobility files). For each task it starts
`partsim annotate` on a free loopback port and runs tests/web/annotate_check.mjs, which answers
the questions through the page as a user would (buttons, checkboxes, selects, typed numbers, and
the axis picked in 3D: two points on the meshes, a face normal or a bounding-box edge) from the
truth, then exports. On the way it sends a fixed group that partsim must refuse, undoes an
answer, and stops the server (SIGKILL) mid-session, starts it again on the same session folder
and goes on from there; the finished dispenser is then reviewed (`--review`), each joint shown
moving. The tests assert on what the script printed and on the export, and compute the number
of questions the procedure needs from result.json and the truth, independently of partsim and of
the script. They skip only when Chromium cannot start.

PARTSIM_UPDATE_SCREENSHOT=1 copies the screenshot of a hinge question (its preview moving) to
docs/images/annotate.png.
"""

import json
import math
import os
import re
import shutil
import subprocess
import sys

import pytest

import partsim

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "tests", "web"))

from browser_session import WEB_ROOT, Lines, require_page, run_page_check, stop  # noqa: E402

PARTSIM = os.environ.get("PARTSIM_BIN", os.path.join(REPO, "build", "partsim"))
CHECK = os.path.join(REPO, "tests", "web", "annotate_check.mjs")
# drawers (sliders), a door and knobs (hinges) and a button, a faucet's hinges, a dispenser's
# screw (a slider that turns without limit)
CATEGORIES = ["StorageFurniture", "Faucet", "Oven", "Dispenser"]
URL = re.compile(
    r"partsim annotate: open (http://127\.0\.0\.1:\d+/annotate\.html\?token=[0-9A-Za-z_-]+)")
# answers given before the server is stopped (StorageFurniture): past the refused fixed group
STOP_AFTER = 8


def _generate(out, unannotated):
    args = [PARTSIM, "assets", "generate", "--categories", ",".join(CATEGORIES),
            "--per-category", "1", "--seed", "3", "--out", out]
    gen = subprocess.run(args + (["--unannotated"] if unannotated else []),
                         capture_output=True, text=True, timeout=120)
    assert gen.returncode == 0, gen.stderr[-2000:]


def _start(task, session, review=False):
    """Starts `partsim annotate` on a task; returns (process, output lines, page URL)."""
    env = dict(os.environ, PARTSIM_WEB_DIR=WEB_ROOT)
    args = [PARTSIM, "annotate", task, "--out", session, "--port", "0"]
    args += ["--review"] if review else []
    server = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              env=env, cwd=os.path.dirname(session))
    lines = Lines(server)
    m = lines.wait_for(URL, 60)
    if m is None:
        stop(server)
        lines.thread.join(timeout=10)
        text = "\n".join(ln.get("text", json.dumps(ln)) for ln in lines.all)
        pytest.fail(f"partsim annotate printed no URL in 60 s (rc {server.returncode}): "
                    f"{text[-3000:]}")
    return server, lines, m.group(1)


def _check(url, truth, lines, **options):
    config = {"url": url, "truth": truth, "timeout_ms": 150000, **options}
    returncode, page = run_page_check(CHECK, config, timeout=200)
    if returncode != 0:
        text = "\n".join(ln.get("text", json.dumps(ln)) for ln in lines.all)
        pytest.fail(f"the annotation check failed: {page.get('error')} (steps {page.get('steps')}; "
                    f"page errors {page.get('errors')}); server output: {text[-3000:]}")
    return page


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    require_page()
    if not os.path.isfile(os.path.join(WEB_ROOT, "annotate.html")):
        pytest.fail("build/web has no annotate.html: run bash scripts/build_web.sh")
    if not os.access(PARTSIM, os.X_OK):
        pytest.fail(f"{PARTSIM} is missing: build partsim first")
    out = str(tmp_path_factory.mktemp("annotate"))
    truth_root = os.path.join(out, "truth")
    tasks_root = os.path.join(out, "tasks")
    _generate(truth_root, False)
    _generate(tasks_root, True)
    names = sorted(os.listdir(truth_root))
    assert names == sorted(os.listdir(tasks_root)) and len(names) == len(CATEGORIES), names

    runs = {}
    for name in names:
        task = os.path.join(tasks_root, name)
        # a task: the part tree and its meshes, none of the answer
        files = set(os.listdir(task))
        assert {"result.json", "meta.json", "textured_objs"} <= files, files
        assert not files & {"mobility.urdf", "mobility_v2.json", "semantics.txt"}, files
        with open(os.path.join(task, "meta.json")) as f:
            category = json.load(f)["model_cat"]
        with open(os.path.join(truth_root, name, "mobility_v2.json")) as f:
            truth = json.load(f)
        session = os.path.join(out, "sessions", name)
        os.makedirs(os.path.dirname(session), exist_ok=True)
        run = {"name": name, "category": category, "task": task, "truth": truth,
               "truth_folder": os.path.join(truth_root, name), "session": session, "pages": []}
        server, lines, url = _start(task, session)
        try:
            if category == "StorageFurniture":
                # a refused group and an Undo, then the server killed mid-session and started
                # again on the same folder: the page goes on where it was
                run["pages"].append(_check(url, truth, lines, refuse_fixed=True, undo_after=2,
                                           stop_after=STOP_AFTER))
                server.kill()
                server.wait(timeout=10)
                with open(os.path.join(session, "session.json")) as f:
                    run["session_json_at_kill"] = json.load(f)
                server, lines, url = _start(task, session)
                run["pages"].append(_check(url, truth, lines))
            else:
                shot = os.path.join(out, "annotate.png") if category == "Oven" else None
                run["pages"].append(_check(url, truth, lines, screenshot=shot))
        finally:
            stop(server)
        if category == "Dispenser":
            # the review of the finished session: every joint shown moving, one rejected
            server, lines, url = _start(task, session, review=True)
            try:
                run["review"] = _check(url, truth, lines, review=True)
            finally:
                stop(server)
        run["time_s"] = sum(p["time_s"] for p in run["pages"])
        run["page"] = run["pages"][-1]
        runs[category] = run
    # per object: the scripted session's time, its answers, and how each joint's axis came
    # (origin/direction: a tool of the page or typed)
    summary = {c: {"name": r["name"], "time_s": round(r["time_s"], 2),
                   "answers": r["page"]["final"]["answers"],
                   "axes": [f"{q['joint']['how']['origin']}/{q['joint']['how']['direction']}"
                            for p in r["pages"] for q in p["questions"] if "joint" in q]}
               for c, r in runs.items()}
    with open(os.path.join(out, "annotate_times.json"), "w") as f:
        json.dump(summary, f, indent=1)
    print("annotation sessions (s):", json.dumps(summary))
    return runs


# ---- the truth, independently of partsim and of the check script

def _tree(task):
    """result.json's nodes: {id: children ids}, and the roots."""
    with open(os.path.join(task, "result.json")) as f:
        roots = json.load(f)
    children = {}

    def walk(n):
        children[n["id"]] = [c["id"] for c in n.get("children", [])]
        for c in n.get("children", []):
            walk(c)
    for r in roots:
        walk(r)
    return children, [r["id"] for r in roots]


def _top(truth, i):
    """The rigid link a truth link belongs to: a static link is one with its parent."""
    by_id = {link["id"]: link for link in truth}
    while by_id[i]["joint"] == "static" and by_id[i]["parent"] in by_id:
        i = by_id[i]["parent"]
    return i


def _rigid(truth):
    """The truth's rigid links: {top link id: set of part ids}, and part id -> top link id."""
    groups = {}
    for link in truth:
        parts = {p["id"] for p in link["parts"] if p}
        groups.setdefault(_top(truth, link["id"]), set()).update(parts)
    of_part = {p: g for g, parts in groups.items() for p in parts}
    return groups, of_part


def minimum_questions(task, truth):
    """The questions the procedure of docs/annotation.md asks for this object when every answer
    is right: motion questions (nodes of two or more children whose parts are not one rigid
    link), one fixed-group question per rigid link split over several units plus the closing
    "none" while a merge is still possible, the joints with their closing "none"s until the links
    form one tree, one root question per tree."""
    children, roots = _tree(task)
    groups, of_part = _rigid(truth)

    def leaves(n):
        return [n] if not children[n] else [x for c in children[n] for x in leaves(c)]

    motion, moves, units = 0, [], []

    def visit(n):
        nonlocal motion
        while len(children[n]) == 1:
            n = children[n][0]
        if not children[n]:
            units.append({n})
            return
        motion += 1
        if len({of_part[x] for x in leaves(n)}) > 1:
            moves.append(set(leaves(n)))
            for c in children[n]:
                visit(c)
        else:
            units.append(set(leaves(n)))
    for r in roots:
        visit(r)

    links = [set(u) for u in units]
    fixed = 0
    for parts in groups.values():
        spanned = [link for link in links if link & parts]
        if len(spanned) > 1:
            fixed += 1
            links = [link for link in links if not link & parts] + [set().union(*spanned)]
    if any(not any(m <= a | b for m in moves) for i, a in enumerate(links) for b in links[i + 1:]):
        fixed += 1  # "none"

    joints = {k: sum(1 for link in truth if link["joint"] == k) for k in ("hinge", "slider")}
    trees = len(links)
    questions = 0
    if trees > 1:
        questions += joints["hinge"]
        trees -= joints["hinge"]
        if trees > 1:
            questions += 1 + joints["slider"]  # the hinges' "none", then the sliders
            trees -= joints["slider"]
            if trees > 1:
                questions += 1
    return motion + fixed + questions + trees


def _angle_deg(a, b):
    na = math.sqrt(sum(x * x for x in a))
    nb = math.sqrt(sum(x * x for x in b))
    c = sum(x * y for x, y in zip(a, b)) / (na * nb)
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def _line_distance(p, o, d):
    n = math.sqrt(sum(x * x for x in d))
    v = [p[k] - o[k] for k in range(3)]
    c = [v[1] * d[2] - v[2] * d[1], v[2] * d[0] - v[0] * d[2], v[0] * d[1] - v[1] * d[0]]
    return math.sqrt(sum(x * x for x in c)) / n


def _export(run):
    with open(os.path.join(run["session"], "object", "mobility_v2.json")) as f:
        return json.load(f)


def _bbox_diagonal(run):
    with open(os.path.join(run["truth_folder"], "bounding_box.json")) as f:
        box = json.load(f)
    return math.dist(box["min"], box["max"])


# ---- the tests

def test_every_object_is_annotated_through_the_page(runs):
    assert sorted(runs) == sorted(CATEGORIES)
    for category, run in runs.items():
        page = run["page"]
        assert page["ok"]
        assert page["final"]["phase"] == "done" and page["final"]["done"], (category, page["final"])
        exported = page["final"]["exported"]
        assert exported, category
        assert os.path.samefile(exported, os.path.join(run["session"], "object")), exported
        assert exported in page["export_text"]
        for p in run["pages"]:
            assert p["errors_at_end"] == [], (category, p["errors_at_end"])
        assert run["time_s"] > 0


def test_export_matches_the_truth(runs):
    for category, run in runs.items():
        groups, _ = _rigid(run["truth"])
        by_id = {link["id"]: link for link in run["truth"]}
        exported = _export(run)
        key = {link["id"]: frozenset(p["id"] for p in link["parts"] if p) for link in exported}
        assert sorted(map(sorted, key.values())) == sorted(map(sorted, groups.values())), category
        truth_of = {frozenset(parts): by_id[top] for top, parts in groups.items()}
        group_of = {top: frozenset(parts) for top, parts in groups.items()}
        size = _bbox_diagonal(run)
        for link in exported:
            t = truth_of[key[link["id"]]]
            where = f"{category} {run['name']} link {link['id']} ({t['name']})"
            expected = t["joint"] if t["joint"] in ("hinge", "slider", "free") else "heavy"
            assert link["joint"] == expected, where
            if t["parent"] < 0:
                assert link["parent"] == -1, where
            else:
                assert key[link["parent"]] == group_of[_top(run["truth"], t["parent"])], where
            if expected not in ("hinge", "slider"):
                continue
            axis, truth_axis = link["jointData"]["axis"], t["jointData"]["axis"]
            assert _angle_deg(axis["direction"], truth_axis["direction"]) < 1.0, \
                (where, axis, truth_axis)
            if expected == "hinge":
                # picked in 3D: on the truth's axis within a click's precision
                off = _line_distance(axis["origin"], truth_axis["origin"], truth_axis["direction"])
                assert off < 0.005 * size, (where, axis, truth_axis)
            limit, truth_limit = link["jointData"]["limit"], t["jointData"]["limit"]
            assert bool(limit["noLimit"]) == bool(truth_limit["noLimit"]), where
            if not truth_limit["noLimit"]:
                assert limit["a"] == pytest.approx(truth_limit["a"], abs=1e-6), where
                assert limit["b"] == pytest.approx(truth_limit["b"], abs=1e-6), where
            if expected == "slider":
                assert bool(limit.get("rotates")) == bool(truth_limit.get("rotates")), where
                if truth_limit.get("rotates"):
                    free = bool(truth_limit["noRotationLimit"])
                    assert bool(limit["noRotationLimit"]) == free, where
                    if not free:
                        assert limit["rotationLimit"] == \
                            pytest.approx(truth_limit["rotationLimit"], abs=1e-6), where


def test_question_count_is_the_minimum(runs):
    for category, run in runs.items():
        expected = minimum_questions(run["task"], run["truth"])
        final = run["page"]["final"]
        assert final["answers"] == expected, (category, final["history"])
        assert len(final["history"]) == expected


def test_export_loads_with_the_strict_loader(runs):
    for category, run in runs.items():
        folder = os.path.join(run["session"], "object")
        scene = partsim.Scene()
        loader = scene.create_partnet_mobility_loader()
        loader.strict = True
        art = loader.load(folder)
        movable = sum(1 for link in run["truth"] if link["joint"] in ("hinge", "slider"))
        screws = sum(1 for link in run["truth"] if link["joint"] == "slider"
                     and link["jointData"]["limit"].get("rotates"))
        assert art.dof == movable + screws, category
        assert not loader.last_report(), (category, str(loader.last_report()))


def test_axes_are_picked_in_3d_and_the_preview_moves(runs):
    tools = {"points", "normal", "edge"}
    used = set()
    for category, run in runs.items():
        joints = [q["joint"] for p in run["pages"] for q in p["questions"] if "joint" in q]
        assert joints, category
        # at least one direction of each object came from a click on the 3D view
        assert any(j["how"]["direction"] in tools for j in joints), \
            (category, [(j["tried"], j["how"]) for j in joints])
        used.update(x for j in joints for x in j["how"].values())
        for j in joints:
            # the child (and what hangs below it) moves while the form is filled (a matrix entry
            # changes by more than float noise: the oven's button travels 2 mm)
            assert sorted(j["preview"]["leaves"]) == sorted(j["moving_expected"]), (category, j)
            assert j["preview"]["moved"] > 1e-5, (category, j)
    assert tools <= used, used


def test_a_restarted_server_resumes_at_the_same_question(runs):
    run = runs["StorageFurniture"]
    first, second = run["pages"]
    stopped = first["stopped"]
    assert stopped["answers"] == STOP_AFTER
    assert len(run["session_json_at_kill"]["answers"]) == STOP_AFTER
    # the page of the new server: the same question, the same history
    assert second["loaded"]["index"] == stopped["index"]
    assert second["loaded"]["phase"] == stopped["phase"]
    assert second["loaded"]["answers"] == STOP_AFTER
    assert second["loaded"]["history"] == len(stopped["history"])


def test_undo_removes_the_last_answer(runs):
    undo = runs["StorageFurniture"]["pages"][0]["undo"]
    assert undo["answers_after"] == undo["answers_before"] - 1
    assert undo["index_after"] == undo["index_before"] - 1
    assert undo["history_after"] == undo["answers_before"] - 1
    # the question answered last is asked again
    assert undo["asked_again"]["text"] == undo["undone"]["text"]
    assert undo["asked_again"]["phase"] == undo["undone"]["phase"]


def test_a_wrong_answer_is_refused_and_changes_nothing(runs):
    refused = runs["StorageFurniture"]["pages"][0]["refused"]
    assert refused["message"], refused
    assert refused["shown"]["visible"] and refused["shown"]["text"] == refused["message"]
    # every link was ticked, some with a click on its mesh
    assert sorted(refused["ticked"]) == sorted(f"fixed-link-{i}" for i in refused["links"])
    assert refused["by3d"], refused
    before, after = refused["before"], refused["after"]
    assert after["index"] == before["index"] and after["answers"] == before["answers"]
    assert after["links"] == before["links"]


def test_review_shows_each_joint_and_records_the_decisions(runs):
    review = runs["Dispenser"]["review"]["review"]
    assert review["phase"] == "review"
    truth = runs["Dispenser"]["truth"]
    joints = sum(1 for link in truth if link["joint"] in ("hinge", "slider"))
    assert len(review["decisions"]) == joints
    for d in review["decisions"]:
        assert d["error"] is None, d
        assert d["preview"]["moved"] > 1e-5, d
    final = review["final"]
    assert final["done"]
    decided = {j["link"]: (j["decision"], j["comment"]) for j in final["joints"]}
    *accepted, rejected = review["decisions"]
    for d in accepted:
        assert decided[d["link"]][0] == "accept"
    assert decided[rejected["link"]] == ("reject", "axis looks off")


def test_screenshot_of_a_hinge_question(runs):
    page = runs["Oven"]["page"]
    shot = page["screenshot"]
    assert shot and os.path.getsize(shot) > 10000
    if os.environ.get("PARTSIM_UPDATE_SCREENSHOT") == "1":
        shutil.copyfile(shot, os.path.join(REPO, "docs", "images", "annotate.png"))
