"""`partsim annotate` served (docs/annotation.md), driven over its HTTP routes and rosbridge
services by a real WebSocket client: objects written by `partsim assets generate --unannotated`
are annotated by answering each question from the generator's ground truth (the same command
without --unannotated); the server is killed (SIGKILL) in the middle and started again on the
same session, which resumes at the same question; the export loads with the strict
PartNet-Mobility loader and matches the truth; review mode records a decision per joint; bad
inputs end the command with an error naming what is wrong, and leave a saved session as it was.
"""

import json
import os
import re
import shutil
import signal
import subprocess
import threading
import time
import urllib.request

import pytest

from conftest import PYTHON_DIR, require

websocket = require("websocket", "websocket-client (requirements.lock)")

CLI = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                                 "partsim"))
URL = re.compile(r"http://127\.0\.0\.1:(\d+)/annotate\.html\?token=([0-9A-Za-z_-]+)")
CATEGORIES = ["StorageFurniture", "Bottle", "Faucet"]


class Annotate:
    """`partsim annotate INPUT --out DIR`: its port and token from the URL it prints."""

    def __init__(self, task, session, extra=()):
        self.proc = subprocess.Popen([CLI, "annotate", str(task), "--out", str(session),
                                      "--port", "0", *extra], stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True)
        self.lines = []
        found = threading.Event()

        def read():
            for line in self.proc.stdout:
                self.lines.append(line)
                if URL.search(line):
                    found.set()
            found.set()

        threading.Thread(target=read, daemon=True).start()
        found.wait(60)
        m = URL.search("".join(self.lines))
        if not m:
            self.kill()
            pytest.fail("no URL printed:\n" + "".join(self.lines))
        self.port, self.token = int(m.group(1)), m.group(2)
        try:
            self.ws = websocket.create_connection("ws://127.0.0.1:%d/" % self.port, timeout=30)
            self.ws.send(json.dumps({"op": "auth", "mac": self.token}))
            assert json.loads(self.ws.recv())["msg"] == "authenticated"
        except BaseException:
            self.kill()  # no server left behind by a failed start
            raise
        self.calls = 0

    def json(self, path):
        url = "http://127.0.0.1:%d%s?token=%s" % (self.port, path, self.token)
        with urllib.request.urlopen(url, timeout=30) as r:
            return json.loads(r.read())

    def call(self, service, args=None):
        self.calls += 1
        call_id = "c%d" % self.calls
        self.ws.send(json.dumps({"op": "call_service", "service": service, "args": args or {},
                                 "id": call_id}))
        deadline = time.time() + 60
        while time.time() < deadline:
            m = json.loads(self.ws.recv())
            if m.get("op") == "service_response" and m.get("id") == call_id:
                assert m["result"], m
                return m["values"]
        pytest.fail("no answer to " + service)

    def kill(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGKILL)
            self.proc.wait(timeout=10)


class Truth:
    """The generator's answer: each part's rigid link (a static link is fixed to its parent)."""

    def __init__(self, folder):
        with open(os.path.join(folder, "mobility_v2.json")) as f:
            self.links = {e["id"]: e for e in json.load(f)}
        self.rigid_of_link = {}
        for i, e in self.links.items():
            top = i
            while self.links[top]["joint"] == "static" and self.links[top]["parent"] >= 0:
                top = self.links[top]["parent"]
            self.rigid_of_link[i] = top
        self.rigid_of_part = {p["id"]: self.rigid_of_link[i]
                              for i, e in self.links.items() for p in e["parts"]}


def leaves(nodes, node_id):
    out, stack = [], [node_id]
    while stack:
        n = nodes[stack.pop()]
        if not n["children"]:
            out.append(n["id"])
        stack.extend(n["children"])
    return out


def oracle(state, nodes, truth):
    """The answer the truth gives to the state's question."""
    q = state["question"]
    phase = q["phase"]
    a = {"index": q["index"]}
    if phase == "motion":
        a["moves"] = len({truth.rigid_of_part[p] for p in leaves(nodes, q["node"])}) > 1
        return a
    rigid_of = {l["id"]: truth.rigid_of_part[l["leaves"][0]] for l in state["links"]}
    link_of_rigid = {r: l for l, r in rigid_of.items()}
    if phase == "fixed":
        groups = {}
        for link, r in rigid_of.items():
            groups.setdefault(r, []).append(link)
        for links in groups.values():
            if len(links) > 1:
                return dict(a, links=links)
        return dict(a, none=True)
    if phase in ("hinge", "slider"):
        parent_of = {l["id"]: l["parent"] for l in state["links"]}
        for i, e in truth.links.items():
            child = link_of_rigid[truth.rigid_of_link[i]]
            if e["joint"] != phase or parent_of[child] >= 0:
                continue
            d, lim = e["jointData"]["axis"], e["jointData"]["limit"]
            return dict(a, parent=link_of_rigid[truth.rigid_of_link[e["parent"]]], child=child,
                        origin=d["origin"], direction=d["direction"], lower=lim["a"],
                        upper=lim["b"], no_limit=lim["noLimit"],
                        rotates=lim.get("rotates", False),
                        rotation_limit=lim.get("rotationLimit", 0),
                        no_rotation_limit=lim.get("noRotationLimit", False))
        return dict(a, none=True)
    assert phase == "root", state
    r = rigid_of[q["link"]]
    return dict(a, kind="free" if truth.links[r]["joint"] == "free" else "fixed")


@pytest.fixture(scope="module")
def objects(tmp_path_factory):
    root = tmp_path_factory.mktemp("annotate")
    for form, extra in (("truth", []), ("tasks", ["--unannotated"])):
        subprocess.run([CLI, "assets", "generate", "--out", root / form, "--categories",
                        ",".join(CATEGORIES), "--seed", "5", *extra],
                       check=True, capture_output=True, timeout=120)
    names = sorted(os.listdir(root / "tasks"))
    assert len(names) == len(CATEGORIES)
    return root, names


def test_annotate_every_object_through_the_services_with_a_kill_in_the_middle(objects,
                                                                              tmp_path):
    root, names = objects
    load = require("partsim", "the partsim module")
    exported = {}
    for name in names:
        truth = Truth(root / "truth" / name)
        session = tmp_path / name
        server = Annotate(root / "tasks" / name, session)
        try:
            obj = server.json("/api/annotate/object.json")
            nodes = {n["id"]: n for n in obj["nodes"]}
            state = server.json("/api/annotate/state.json")
            assert state["question"]["index"] == 0 and state["answers"] == 0
            answered = 0
            while not state["done"]:
                if answered == 3:
                    # killed between two answers: the next server resumes at the same question
                    asked = state["question"]
                    server.kill()
                    server = Annotate(root / "tasks" / name, session)
                    state = server.json("/api/annotate/state.json")
                    assert state["question"] == asked
                    assert state["answers"] == 3
                values = server.call("/partsim/annotate/answer", oracle(state, nodes, truth))
                assert values["success"], values["message"]
                state = values["state"]
                answered += 1
                assert answered < 200
            # an answer to a question already answered is refused and changes nothing
            stale = server.call("/partsim/annotate/answer", {"index": 0, "moves": True})
            assert not stale["success"] and "question" in stale["message"]
            assert stale["state"]["answers"] == answered
            # so are hostile answers: huge numbers, non-ASCII garbage, deep nesting
            for hostile in ({"index": 10 ** 30}, {"index": answered, "links": [2 ** 62, 1]},
                            {"index": answered, "kind": "\u00e9\u6f22\ud83d\ude00\x00"},
                            {"index": answered, "origin": [[[[[[[[1]]]]]]]] * 3},
                            {"index": answered, "lower": "\xff" * 1000}):
                v = server.call("/partsim/annotate/answer", hostile)
                assert not v["success"] and v["message"], (hostile, v)
                assert v["state"]["answers"] == answered
            values = server.call("/partsim/annotate/export")
            assert values["success"], values["message"]
            folder = values["folder"]
            assert values["state"]["exported"] == folder
        finally:
            server.kill()
        # the export: strict loading, and the truth's joints
        with open(os.path.join(folder, "mobility_v2.json")) as f:
            got = json.load(f)
        by_rigid = {}
        for e in got:
            rigid = {truth.rigid_of_part[p["id"]] for p in e["parts"]}
            assert len(rigid) == 1, e
            by_rigid[rigid.pop()] = e
        assert len(by_rigid) == len(set(truth.rigid_of_link.values()))
        for i, e in truth.links.items():
            if truth.rigid_of_link[i] != i:
                continue
            g = by_rigid[i]
            assert g["joint"] == e["joint"], (name, e, g)
            if e["parent"] < 0:
                assert g["parent"] == -1
                continue
            assert g["parent"] == by_rigid[truth.rigid_of_link[e["parent"]]]["id"]
            if e["joint"] in ("hinge", "slider"):
                for key in ("origin", "direction"):
                    assert g["jointData"]["axis"][key] == \
                        pytest.approx(e["jointData"]["axis"][key], abs=1e-6)
                assert g["jointData"]["limit"] == pytest.approx(e["jointData"]["limit"], abs=1e-6)
        scene = load.Scene()
        loader = scene.create_partnet_mobility_loader()
        loader.strict = True
        loader.load(folder)
        exported[name] = folder
    # the annotated cabinet's drawers or doors carry the labels the tasks look for: the
    # heuristic solver pulls or opens one
    cabinet = [n for n in names if '"StorageFurniture"' in (root / "tasks" / n /
                                                            "meta.json").read_text()]
    assert cabinet
    shutil.copytree(exported[cabinet[0]], tmp_path / "dataset" / cabinet[0])
    with open(os.path.join(exported[cabinet[0]], "semantics.txt")) as f:
        task = "drawer" if " drawer\n" in f.read() else "door"
    r = subprocess.run([CLI, "tasks", "evaluate", "--task", task, "--dataset",
                        str(tmp_path / "dataset"), "--no-cameras"], capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0 and "1 / 1 succeeded" in r.stdout, r.stdout + r.stderr


def test_review_mode_records_a_decision_per_joint(objects, tmp_path):
    root, names = objects
    name = names[0]
    truth = Truth(root / "truth" / name)
    session = tmp_path / "review"
    server = Annotate(root / "tasks" / name, session, ["--review"])
    try:
        obj = server.json("/api/annotate/object.json")
        nodes = {n["id"]: n for n in obj["nodes"]}
        state = server.json("/api/annotate/state.json")
        # before every question is answered, a review is refused
        early = server.call("/partsim/annotate/review", {"link": 0, "accept": True})
        assert not early["success"]
        while not state["done"]:
            state = server.call("/partsim/annotate/answer", oracle(state, nodes, truth))["state"]
        assert state["question"]["phase"] == "review"
        joints = state["review"]["joints"]
        assert joints and all(j["decision"] is None for j in joints)
        for k, j in enumerate(joints):
            review = {"link": j["link"], "accept": k > 0, "comment": "axis" if k == 0 else ""}
            v = server.call("/partsim/annotate/review", review)
            assert v["success"], v["message"]
        bad = server.call("/partsim/annotate/review", {"link": 10 ** 6, "accept": True})
        assert not bad["success"] and "no joint" in bad["message"]
        state = server.json("/api/annotate/state.json")
        assert state["review"]["done"]
        assert [j["decision"] for j in state["review"]["joints"]] == \
            ["reject"] + ["accept"] * (len(joints) - 1)
        # the export carries the reviews, by the exported links' names
        folder = server.call("/partsim/annotate/export")["folder"]
        with open(os.path.join(folder, "meta.json")) as f:
            meta = json.load(f)
        assert [r["accept"] for r in meta["reviews"]] == [False] + [True] * (len(joints) - 1)
        assert all(r["link"].startswith("link_") for r in meta["reviews"])
    finally:
        server.kill()
    with open(session / "session.json") as f:
        saved = json.load(f)
    assert len(saved["reviews"]) == len(joints)
    assert saved["reviews"][0] == {"link": joints[0]["link"], "accept": False, "comment": "axis"}


def test_bad_inputs_end_with_an_error_and_keep_the_saved_session(objects, tmp_path):
    root, names = objects
    task = tmp_path / "task"
    shutil.copytree(root / "tasks" / names[0], task)
    session = tmp_path / "s"
    server = Annotate(task, session)
    try:
        state = server.json("/api/annotate/state.json")
        assert server.call("/partsim/annotate/answer",
                           {"index": 0, "moves": True})["success"]
    finally:
        server.kill()
    saved = (session / "session.json").read_bytes()

    def run(*args):
        return subprocess.run([CLI, "annotate", *map(str, args), "--port", "0", "--duration",
                               "1"], capture_output=True, text=True, timeout=60)

    # the input's result.json nested 100,000 deep; then one with 10^5 parts
    with open(task / "result.json", "w") as f:
        f.write("[" + '{"id": 1, "children": [' * 100000 + "]}" * 100000 + "]")
    r = run(task, "--out", session)
    assert r.returncode == 1 and "nested deeper than" in r.stderr, r.stderr
    with open(task / "result.json", "w") as f:
        f.write('[{"id": 0, "children": [' + ",".join(
            '{"id": %d, "objs": ["original-0"]}' % i for i in range(1, 100001)) + "]}]")
    r = run(task, "--out", session)
    assert r.returncode == 1 and "more than 10000 part nodes" in r.stderr, r.stderr
    # the original tree back, less one mesh file: named
    shutil.copy(root / "tasks" / names[0] / "result.json", task / "result.json")
    os.remove(task / "textured_objs" / "original-0.obj")
    r = run(task, "--out", session)
    assert r.returncode == 1 and "original-0.obj" in r.stderr, r.stderr
    # the mesh back, changed: the session is of another input
    with open(root / "tasks" / names[0] / "textured_objs" / "original-0.obj") as f:
        text = f.read()
    with open(task / "textured_objs" / "original-0.obj", "w") as f:
        f.write(text + "v 9 9 9\n")
    r = run(task, "--out", session)
    assert r.returncode == 1 and "another input" in r.stderr, r.stderr
    # a non-manifold mesh: a warning, or with --strict an error
    with open(task / "textured_objs" / "original-0.obj", "w") as f:
        f.write(text + "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\n"
                "f -5 -4 -3\nf -4 -5 -2\nf -5 -4 -1\n")
    r = run(task, "--out", tmp_path / "fresh", "--strict")
    assert r.returncode == 1 and "not manifold" in r.stderr, r.stderr
    r = run(task, "--out", tmp_path / "fresh")
    assert r.returncode == 0 and "warning" in r.stdout and "not manifold" in r.stdout, r.stdout
    # through all of it the saved answer stayed
    assert (session / "session.json").read_bytes() == saved
    # the command line
    r = subprocess.run([CLI, "annotate", str(task)], capture_output=True, text=True, timeout=30)
    assert r.returncode == 2 and "--out" in r.stderr


def test_the_real_bottle_annotated_from_its_own_annotation(tmp_path):
    """PartNet-Mobility's bottle 3763 (../shared/realdata): its result.json and meshes as the
    input, its mobility_v2.json as the truth. Five questions give back the dataset's links: a
    free body of two parts and a screw cap (a slider that also turns)."""
    src = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
        os.path.abspath(__file__)))), "..", "shared", "realdata", "partnet-mobility-3763")
    if not os.path.isdir(src):
        pytest.skip("no " + src)
    truth = Truth(src)
    server = Annotate(src, tmp_path / "s")
    try:
        nodes = {n["id"]: n for n in server.json("/api/annotate/object.json")["nodes"]}
        state = server.json("/api/annotate/state.json")
        # its meshes have edges of three triangles: read, with a warning per part
        assert len(state["warnings"]) == 3 and "not manifold" in state["warnings"][0]
        phases = []
        while not state["done"]:
            phases.append(state["question"]["phase"])
            values = server.call("/partsim/annotate/answer", oracle(state, nodes, truth))
            assert values["success"], values["message"]
            state = values["state"]
        assert phases == ["motion", "fixed", "hinge", "slider", "root"]
        folder = server.call("/partsim/annotate/export")["folder"]
    finally:
        server.kill()
    with open(os.path.join(folder, "mobility_v2.json")) as f:
        got = {tuple(sorted(p["id"] for p in e["parts"])): e for e in json.load(f)}
    for e in truth.links.values():
        g = got[tuple(sorted(p["id"] for p in e["parts"]))]
        assert g["joint"] == e["joint"] and g["name"] == e["name"]
        if e["joint"] == "slider":
            for key in ("origin", "direction"):
                assert g["jointData"]["axis"][key] == \
                    pytest.approx(e["jointData"]["axis"][key], abs=1e-6)
            assert g["jointData"]["limit"] == pytest.approx(e["jointData"]["limit"], abs=1e-6)
    # semantics.txt in the dataset's movable-part vocabulary ("slider+ rotation_lid",
    # "free bottle_body"), the links numbered in another order
    def kinds_and_labels(folder):
        with open(os.path.join(folder, "semantics.txt")) as f:
            return sorted(tuple(line.split()[1:]) for line in f if line.strip())
    assert kinds_and_labels(folder) == kinds_and_labels(src)
    with open(os.path.join(src, "result.json"), "rb") as a, \
            open(os.path.join(folder, "result.json"), "rb") as b:
        assert a.read() == b.read()
    scene = require("partsim", "the partsim module").Scene()
    loader = scene.create_partnet_mobility_loader()
    loader.strict = True
    loader.load(folder)
