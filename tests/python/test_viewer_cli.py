"""The viewer's command-line entry points as subprocesses on loopback: `partsim view --dataset
ROOT` (the gallery: gallery.json, thumbnails, /partsim/open and /partsim/gallery, the opened
object's joints moving, a bad ROOT refused by name, an unreadable folder listed), `partsim view
FILE` and `partsim serve --viewer` (the URL printed, scene.json with the file's links, /partsim/step
while running pauses, SIGTERM ends them with exit 0)."""

import io
import json
import os
import re
import signal
import subprocess
import threading
import time
import urllib.error
import urllib.request

import numpy as np
import pytest
from PIL import Image

from conftest import CABINET_URDF, PYTHON_DIR, REPO, require

websocket = require("websocket", "websocket-client (requirements.lock)")

CLI = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                                 "partsim"))
URL = re.compile(r"http://127\.0\.0\.1:(\d+)/\?token=(\S+)")


class Server:
    """A partsim command serving the viewer: its port and token from the URL it prints."""

    def __init__(self, args, timeout=60):
        self.proc = subprocess.Popen([CLI] + [str(a) for a in args], stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True)
        self.lines = []
        found = threading.Event()

        def read():
            for line in self.proc.stdout:
                self.lines.append(line)
                if URL.search(line):
                    found.set()
            found.set()

        self.reader = threading.Thread(target=read, daemon=True)
        self.reader.start()
        found.wait(timeout)
        m = URL.search("".join(self.lines))
        if not m:
            self.stop()
            pytest.fail("no viewer URL printed by %s:\n%s" % (args, "".join(self.lines)))
        self.port, self.token = int(m.group(1)), m.group(2)

    def get(self, path):
        url = "http://127.0.0.1:%d%s?token=%s" % (self.port, path, self.token)
        with urllib.request.urlopen(url, timeout=40) as r:
            return r.read()

    def json(self, path):
        return json.loads(self.get(path))

    def connect(self):
        ws = websocket.create_connection("ws://127.0.0.1:%d/" % self.port, timeout=30)
        ws.send(json.dumps({"op": "auth", "mac": self.token}))
        assert json.loads(ws.recv())["msg"] == "authenticated"
        return ws

    def sigterm(self, within=5.0):
        """SIGTERM; the exit code, which must come within `within` s."""
        self.proc.send_signal(signal.SIGTERM)
        try:
            return self.proc.wait(timeout=within)
        finally:
            self.stop()

    def stop(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=10)
        self.reader.join(timeout=5)


@pytest.fixture
def serve():
    servers = []

    def start(args):
        s = Server(args)
        servers.append(s)
        return s

    yield start
    for s in servers:
        s.stop()


def call(ws, service, args=None, call_id="x"):
    ws.send(json.dumps({"op": "call_service", "service": service, "args": args or {},
                        "id": call_id}))
    deadline = time.time() + 60
    while time.time() < deadline:
        m = json.loads(ws.recv())
        if m.get("op") == "service_response" and m.get("id") == call_id:
            return m
    pytest.fail("no answer to %s" % service)


def next_message(ws, topic):
    while True:
        m = json.loads(ws.recv())
        if m.get("topic") == topic:
            return m["msg"]


def last_message(ws, topic, seconds):
    """The last message of `topic` received over the next `seconds`."""
    last, deadline = None, time.time() + seconds
    while time.time() < deadline:
        ws.settimeout(max(0.01, deadline - time.time()))
        try:
            m = json.loads(ws.recv())
        except websocket.WebSocketTimeoutException:
            break
        if m.get("topic") == topic:
            last = m["msg"]
    ws.settimeout(30)
    assert last is not None, "no message of %s in %g s" % (topic, seconds)
    return last


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    root = tmp_path_factory.mktemp("gallery_%d" % os.getpid())
    subprocess.run([CLI, "assets", "generate", "--out", root, "--categories",
                    "StorageFurniture,Faucet,Door", "--per-category", "2", "--seed", "1"],
                   check=True, capture_output=True, timeout=120)
    # a folder that cannot be read: its mobility.urdf is not XML
    broken = root / "zz_broken"
    broken.mkdir()
    (broken / "mobility.urdf").write_text("this is not a URDF")
    return root


def expected_objects(root):
    out = []
    for name in sorted(os.listdir(root)):
        if name == "zz_broken":
            continue
        meta = json.loads((root / name / "meta.json").read_text())
        labels = []
        for line in (root / name / "semantics.txt").read_text().split("\n"):
            parts = line.split()
            if len(parts) == 3 and parts[1] in ("hinge", "slider") and parts[2] not in labels:
                labels.append(parts[2])
        out.append((name, meta["model_cat"], labels))
    return out


def test_gallery_lists_thumbnails_opens_animates_and_closes(tree, serve):
    s = serve(["view", "--dataset", tree, "--port", "0"])
    g = s.json("/api/gallery.json")
    assert g["root"] == str(tree) and g["open"] is None
    assert [(o["name"], o["category"], o["labels"]) for o in g["objects"]] == \
        expected_objects(tree)
    assert [o["index"] for o in g["objects"]] == list(range(6))
    assert g["categories"] == {"StorageFurniture": 2, "Faucet": 2, "Door": 2}
    assert all(o["parts"] >= 1 for o in g["objects"])
    assert [e["name"] for e in g["errors"]] == ["zz_broken"] and g["errors"][0]["error"]

    # thumbnails: 160 x 120, the object in the middle on a plain background
    for o in g["objects"]:
        data = s.get(o["thumbnail"])
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        picture = np.asarray(Image.open(io.BytesIO(data)))
        h, w = picture.shape[:2]
        assert (w, h) == (160, 120)
        ys, xs = np.nonzero(np.any(picture != picture[0, 0], axis=-1))
        assert 0.03 * w * h < len(xs) < 0.8 * w * h, o["name"]
        assert xs.min() > 0 and xs.max() < w - 1 and ys.min() > 0 and ys.max() < h - 1, o["name"]
    with pytest.raises(urllib.error.HTTPError, match="404"):
        s.get("/api/thumbnail/6.png")

    empty = s.json("/api/scene.json")
    assert empty["bodies"] == []
    ws = s.connect()
    r = call(ws, "/partsim/open", {"index": 6}, "bad")
    assert r["result"] is False and "0 to 5" in r["values"]

    # open a cabinet: the scene is its links, and its joints sweep
    r = call(ws, "/partsim/open", {"index": 0}, "open")
    assert r["result"] is True and r["values"]["message"] == g["objects"][0]["name"]
    scene = s.json("/api/scene.json")
    assert scene["scene_version"] > empty["scene_version"]
    links = [b["name"] for b in scene["bodies"] if b["kind"] == "link"]
    urdf = (tree / g["objects"][0]["name"] / "mobility.urdf").read_text()
    assert sorted(links) == sorted(re.findall(r'<link name="([^"]+)"', urdf))
    assert s.json("/api/gallery.json")["open"] == 0
    ws.send(json.dumps({"op": "subscribe", "topic": "/partsim/joint_states"}))
    first = next_message(ws, "/partsim/joint_states")["position"]
    later = last_message(ws, "/partsim/joint_states", 1.5)["position"]
    assert max(abs(a - b) for a, b in zip(first, later)) > 0.05

    # step while running pauses, then steps
    ws.send(json.dumps({"op": "subscribe", "topic": "/partsim/status"}))
    call(ws, "/partsim/step", {"n": 3}, "step")
    status = next_message(ws, "/partsim/status")
    while not status["paused"]:
        status = next_message(ws, "/partsim/status")
    call(ws, "/partsim/resume", {}, "resume")

    r = call(ws, "/partsim/gallery", {}, "back")
    assert r["result"] is True
    assert s.json("/api/scene.json")["bodies"] == []
    assert s.json("/api/gallery.json")["open"] is None
    ws.close()
    assert s.sigterm() == 0


def test_gallery_category_filter(tree, serve):
    s = serve(["view", "--dataset", tree, "--port", "0", "--category", "Faucet"])
    g = s.json("/api/gallery.json")
    assert [o["category"] for o in g["objects"]] == ["Faucet", "Faucet"]
    assert g["categories"] == {"Faucet": 2}
    assert s.sigterm() == 0


def test_gallery_refuses_a_bad_root(tmp_path):
    missing = tmp_path / "nowhere"
    r = subprocess.run([CLI, "view", "--dataset", missing, "--port", "0"], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and str(missing) in r.stderr and "does not exist" in r.stderr
    empty = tmp_path / "empty"
    empty.mkdir()
    r = subprocess.run([CLI, "view", "--dataset", empty, "--port", "0"], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and str(empty) in r.stderr and "no PartNet-Mobility object" in r.stderr


def test_gallery_refuses_a_category_it_lacks(tree):
    r = subprocess.run([CLI, "view", "--dataset", tree, "--port", "0", "--category", "Oven"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "'Oven'" in r.stderr and "StorageFurniture" in r.stderr


def test_view_file_serves_its_links_and_stops_on_sigterm(tmp_path, serve):
    urdf = tmp_path / ("cabinet_%d.urdf" % os.getpid())
    urdf.write_text(CABINET_URDF)
    s = serve(["view", urdf, "--port", "0"])
    scene = s.json("/api/scene.json")
    assert {"base", "door", "drawer"} <= {b["name"] for b in scene["bodies"]}
    # served mode: a step while running pauses, then the SimServer takes the n steps
    ws = s.connect()
    ws.send(json.dumps({"op": "subscribe", "topic": "/partsim/status"}))
    running = next_message(ws, "/partsim/status")
    assert running["paused"] is False
    assert call(ws, "/partsim/step", {"n": 5}, "step")["result"] is True
    # the call queues the steps; the simulation thread takes them when it gets the CPU. Wait
    # until the step count holds over half a second (it never does while running)
    status, deadline = last_message(ws, "/partsim/status", 0.5), time.time() + 30
    while True:
        later = last_message(ws, "/partsim/status", 0.5)
        if later["step"] == status["step"] or time.time() > deadline:
            break
        status = later
    assert later["paused"] is True and later["step"] == status["step"], (status, later)
    assert later["step"] >= running["step"] + 5, (running, later)
    ws.close()
    t0 = time.time()
    assert s.sigterm() == 0 and time.time() - t0 < 5


def test_view_serves_an_mjcf_model(serve):
    car = os.path.join(REPO, "..", "shared", "realdata", "mjcf", "car", "car.xml")
    if not os.path.exists(car):
        pytest.skip(f"{car} is absent (../shared)")
    s = serve(["view", car, "--port", "0"])
    bodies = {b["name"] for b in s.json("/api/scene.json")["bodies"]}
    # the car's chassis and wheels (one articulation) and its floor (the worldbody's geoms)
    assert {"car", "left wheel", "right wheel", "car/world"} <= bodies, bodies
    assert s.sigterm() == 0


def test_serve_viewer_prints_the_url_and_stops_on_sigterm(tmp_path, serve):
    urdf = tmp_path / ("cabinet_%d.urdf" % os.getpid())
    urdf.write_text(CABINET_URDF)
    s = serve(["serve", urdf, "--port", "0", "--viewer", "--viewer-port", "0", "--robot",
               "gripper"])
    names = {b["name"] for b in s.json("/api/scene.json")["bodies"]}
    assert {"base", "door", "drawer"} <= names
    t0 = time.time()
    assert s.sigterm() == 0 and time.time() - t0 < 5
