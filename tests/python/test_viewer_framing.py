"""What `partsim view FOLDER` shows first, in a real browser: headless Chromium (Debian's) driven
by puppeteer-core (tests/web/framing_check.mjs) on a generated PartNet-Mobility cabinet
(`partsim assets generate`) and on the real object in ../shared/realdata/partnet-mobility-3763
(skipped when that folder is absent).

- The page's first camera (scene.json has no initial_camera) looks at the object from its front:
  PartNet-Mobility objects face -x of their root (the gallery's thumbnails and its "front"
  camera look from there), so the eye lies on that side of the orbit target, above it, and every
  part projects inside the window. The page's earlier camera, from +x, fails these.
- Real clicks on the drawers at their projected centres select the drawers; from the back the
  cabinet's back panel takes the click.
- A scene with one articulated object shows its joint sliders on load, without a click.

They skip only when Chromium cannot start; a missing page (build/web) fails.
"""

import json
import math
import os
import queue
import re
import subprocess
import sys
import time
import urllib.request

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "tests", "web"))

from browser_session import WEB_ROOT, Lines, require_page, run_page_check, stop  # noqa: E402

PARTSIM = os.environ.get("PARTSIM_BIN", os.path.join(REPO, "build", "partsim"))
CHECK = os.path.join(REPO, "tests", "web", "framing_check.mjs")
REAL_OBJECT = os.path.join(os.path.dirname(REPO), "shared", "realdata", "partnet-mobility-3763")
URL = re.compile(r"http://127\.0\.0\.1:\d+/\?token=[0-9A-Za-z_-]+")


def _serve_and_check(folder, out, name, labels):
    """Runs `partsim view FOLDER` and the page check on it; returns (scene.json, the page's
    result)."""
    env = dict(os.environ, PARTSIM_WEB_DIR=WEB_ROOT)
    server = subprocess.Popen([PARTSIM, "view", folder, "--port", "0"], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, env=env, cwd=out)
    try:
        lines = Lines(server)
        url = None
        deadline = time.time() + 90
        while url is None and time.time() < deadline:
            try:
                line = lines.next(timeout=max(deadline - time.time(), 0.1))
            except queue.Empty:
                break
            if line is None:
                break
            m = URL.search(line.get("text", ""))
            url = m.group(0) if m else None
        if url is None:
            stop(server)
            text = "\n".join(ln.get("text", json.dumps(ln)) for ln in lines.all)
            pytest.fail(f"partsim view {folder} printed no URL in 90 s: {text[-3000:]}")
        token = url.split("token=")[1]
        with urllib.request.urlopen(url.split("?")[0] + f"api/scene.json?token={token}",
                                    timeout=60) as r:
            scene = json.loads(r.read())
        config = {"url": url, "out": out, "name": name, "labels": labels, "timeout_ms": 180000}
        returncode, page = run_page_check(CHECK, config, timeout=240)
        if returncode != 0:
            pytest.fail(f"the framing check failed: {page.get('error')} (steps "
                        f"{page.get('steps')}; page errors {page.get('errors')})")
        return scene, page
    finally:
        stop(server)


@pytest.fixture(scope="module", params=["generated", "partnet-mobility-3763"])
def view(request, tmp_path_factory):
    require_page()
    if not os.access(PARTSIM, os.X_OK):
        pytest.fail(f"{PARTSIM} is missing: build partsim first")
    out = str(tmp_path_factory.mktemp("viewer_framing"))
    if request.param == "generated":
        root = os.path.join(out, "tree")
        gen = subprocess.run([PARTSIM, "assets", "generate", "--out", root, "--categories",
                              "StorageFurniture", "--per-category", "1", "--seed", "1"],
                             capture_output=True, text=True, timeout=120)
        assert gen.returncode == 0, gen.stderr[-2000:]
        folder = os.path.join(root, os.listdir(root)[0])
        labels = ["drawer"]
    else:
        if not os.path.isdir(REAL_OBJECT):
            pytest.skip(f"{REAL_OBJECT} is absent")
        folder = REAL_OBJECT
        labels = ["rotation_lid"]
    scene, page = _serve_and_check(folder, out, request.param, labels)
    return {"name": request.param, "scene": scene, "page": page, "labels": labels}


def _rotate(q, v):
    """v (3,) rotated by the unit quaternion q = (w, x, y, z)."""
    w, x, y, z = q
    u = (x, y, z)
    uv = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    uuv = (u[1] * uv[2] - u[2] * uv[1], u[2] * uv[0] - u[0] * uv[2], u[0] * uv[1] - u[1] * uv[0])
    return [v[i] + 2 * (w * uv[i] + uuv[i]) for i in range(3)]


def _expected_front(scene):
    """-x of the object's root in the world, horizontal, from scene.json's poses."""
    art = scene["articulations"][0]["id"]
    root = next(b for b in scene["bodies"]
                if b.get("articulation") == art and b.get("link_index") == 0)
    q = scene["poses"][7 * root["id"] + 3:7 * root["id"] + 7]
    f = _rotate(q, (-1.0, 0.0, 0.0))
    n = math.hypot(f[0], f[1])
    assert n > 0.1, f"the root's x axis is vertical: {f}"
    return [f[0] / n, f[1] / n, 0.0]


def test_first_camera_looks_at_the_front_from_above(view):
    page, front = view["page"], _expected_front(view["scene"])
    assert view["scene"].get("initial_camera") in (None, {}) or \
        view["scene"]["initial_camera"].get("position") is None
    # the direction the page takes as the front is the root's -x
    assert sum(a * b for a, b in zip(page["front"], front)) > 0.99, (page["front"], front)
    eye, target = page["camera"]["position"], page["camera"]["target"]
    d = [e - t for e, t in zip(eye, target)]
    dist = math.sqrt(sum(x * x for x in d))
    # on the front side, turned at most ~30 degrees (cos 0.5 rad x cos 0.45 rad = 0.79), above
    along = sum(a * b for a, b in zip(d, front)) / dist
    assert along > 0.6, f"{view['name']}: eye {eye} is not in front of {target} (front {front})"
    assert d[2] > 0.2 * dist, f"{view['name']}: eye {eye} is not above {target}"


def test_first_camera_frames_every_part(view):
    page = view["page"]
    w, h = page["viewport"]["width"], page["viewport"]["height"]
    links = {b["id"] for b in page["bodies"] if b["kind"] == "link" and b["visuals"] > 0}
    assert links
    for p in page["projected"]:
        if p["id"] in links:
            assert p["at"] is not None, f"body {p['id']} is behind the camera"
            assert 0 <= p["at"]["x"] < w and 0 <= p["at"]["y"] < h, p


def test_clicks_on_the_front_parts_select_them(view):
    clicks = [c for c in view["page"]["clicks"] if c["at"] is not None]
    assert clicks, view["page"]["clicks"]
    for c in clicks:
        assert c["selected"] == c["id"], \
            f"{view['name']}: a click on {c['name']} ({c['label']}) selected {c['selected']}"


def test_single_object_shows_its_joint_sliders_on_load(view):
    scene, panels = view["scene"], view["page"]["panels"]
    assert len(scene["articulations"]) == 1
    movable = [j["name"] for j in scene["articulations"][0]["joints"] if j["type"] != "fixed"]
    assert movable
    assert not panels["joints_hidden"]
    assert sorted(panels["sliders"]) == sorted(movable)
    # nothing selected yet; the sliders fill the side panel, so the hint stays hidden
    assert panels["info_hidden"] and panels["hint_hidden"]
    assert "Click a part" in panels["hint"]
