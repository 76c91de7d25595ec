"""What `partsim view` shows first, in a real browser: headless Chromium (Debian's) driven by
puppeteer-core (tests/web/framing_check.mjs) on a generated PartNet-Mobility cabinet (`partsim
assets generate`): as a folder, turned 1.2 rad about z by a scene file, and twice side by side;
on the real object in ../shared/realdata/partnet-mobility-3763 (skipped when that folder is
absent); and on the built-in cabinet (`partsim view` with no file).

- The page's first camera (scene.json has no initial_camera) looks at the object from its front:
  PartNet-Mobility objects face -x of their root (the gallery's thumbnails and its "front"
  camera look from there); the built-in cabinet faces +x, where its drawer opens. The eye lies
  on that side of the orbit target, above it, and every part projects inside the window. The
  page's earlier camera, from +x of the world, fails these for PartNet-Mobility objects.
- The drawers (and the built-in cabinet's door, the real bottle's lid) are visible: the page
  draws them over a good share of their screen box (from the back, the cabinet's back panel hides
  the drawers), and a real click there selects them.
- A scene with one articulated object shows its joint sliders on load, without a click; with two
  objects none show, and the side panel says that a click on a part shows its joints.

They skip only when Chromium cannot start; a missing page (build/web) fails.
"""

import json
import math
import os
import re
import subprocess
import sys
import urllib.request

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "tests", "web"))

from browser_session import WEB_ROOT, Lines, require_page, run_page_check, stop  # noqa: E402

PARTSIM = os.environ.get("PARTSIM_BIN", os.path.join(REPO, "build", "partsim"))
CHECK = os.path.join(REPO, "tests", "web", "framing_check.mjs")
REAL_OBJECT = os.path.join(os.path.dirname(REPO), "shared", "realdata", "partnet-mobility-3763")
URL = re.compile(r"http://127\.0\.0\.1:\d+/\?token=[0-9A-Za-z_-]+")


def _serve_and_check(args, out, name, parts):
    """Runs `partsim view ARGS` and the page check on it; returns (scene.json, the page's
    result)."""
    env = dict(os.environ, PARTSIM_WEB_DIR=WEB_ROOT)
    server = subprocess.Popen([PARTSIM, "view", *args, "--port", "0"], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, env=env, cwd=out)
    try:
        lines = Lines(server)
        m = lines.wait_for(URL, 90)
        url = m.group(0) if m else None
        if url is None:
            stop(server)
            text = "\n".join(ln.get("text", json.dumps(ln)) for ln in lines.all)
            pytest.fail(f"partsim view {args} printed no URL in 90 s: {text[-3000:]}")
        token = url.split("token=")[1]
        with urllib.request.urlopen(url.split("?")[0] + f"api/scene.json?token={token}",
                                    timeout=60) as r:
            scene = json.loads(r.read())
        config = {"url": url, "out": out, "name": name, "parts": parts, "timeout_ms": 180000}
        returncode, page = run_page_check(CHECK, config, timeout=240)
        if returncode != 0:
            pytest.fail(f"the framing check failed: {page.get('error')} (steps "
                        f"{page.get('steps')}; page errors {page.get('errors')})")
        return scene, page
    finally:
        stop(server)


# per case: what `partsim view` is given, which way the object faces in its root's frame (-1:
# -x, PartNet-Mobility's; +1: +x) and the parts clicked (labels or body names)
CASES = {
    "generated": {"facing": -1, "parts": ["drawer"]},
    "rotated": {"facing": -1, "parts": ["drawer"]},
    "two-objects": {"facing": -1, "parts": []},
    "partnet-mobility-3763": {"facing": -1, "parts": ["rotation_lid"]},
    "built-in": {"facing": 1, "parts": ["drawer_0", "door_0"]},
}


def _generated_cabinet(out):
    root = os.path.join(out, "tree")
    gen = subprocess.run([PARTSIM, "assets", "generate", "--out", root, "--categories",
                          "StorageFurniture", "--per-category", "1", "--seed", "1"],
                         capture_output=True, text=True, timeout=120)
    assert gen.returncode == 0, gen.stderr[-2000:]
    return os.path.join(root, os.listdir(root)[0])


def _scene_file(out, objects):
    path = os.path.join(out, "scene.json")
    with open(path, "w") as f:
        json.dump({"objects": objects}, f)
    return path


@pytest.fixture(scope="module", params=list(CASES))
def view(request, tmp_path_factory):
    require_page()
    if not os.access(PARTSIM, os.X_OK):
        pytest.fail(f"{PARTSIM} is missing: build partsim first")
    name = request.param
    out = str(tmp_path_factory.mktemp("viewer_framing"))
    if name == "generated":
        args = [_generated_cabinet(out)]
    elif name == "rotated":
        args = [_scene_file(out, [{"path": _generated_cabinet(out),
                                   "pose": {"position": [0, 0, 0], "rpy": [0, 0, 1.2]}}])]
    elif name == "two-objects":
        folder = _generated_cabinet(out)
        args = [_scene_file(out, [
            {"path": folder, "name": "left", "pose": {"position": [0, 0.8, 0]}},
            {"path": folder, "name": "right", "pose": {"position": [0, -0.8, 0]}}])]
    elif name == "partnet-mobility-3763":
        if not os.path.isdir(REAL_OBJECT):
            pytest.skip(f"{REAL_OBJECT} is absent")
        args = [REAL_OBJECT]
    else:
        args = []
    scene, page = _serve_and_check(args, out, name, CASES[name]["parts"])
    return {"name": name, "scene": scene, "page": page, **CASES[name]}


def _rotate(q, v):
    """v (3,) rotated by the unit quaternion q = (w, x, y, z)."""
    w, x, y, z = q
    u = (x, y, z)
    uv = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    uuv = (u[1] * uv[2] - u[2] * uv[1], u[2] * uv[0] - u[0] * uv[2], u[0] * uv[1] - u[1] * uv[0])
    return [v[i] + 2 * (w * uv[i] + uuv[i]) for i in range(3)]


def _expected_front(scene, facing):
    """`facing` times x of the first object's root in the world, horizontal, from scene.json's
    poses."""
    art = scene["articulations"][0]["id"]
    root = next(b for b in scene["bodies"]
                if b.get("articulation") == art and b.get("link_index") == 0)
    q = scene["poses"][7 * root["id"] + 3:7 * root["id"] + 7]
    f = _rotate(q, (float(facing), 0.0, 0.0))
    n = math.hypot(f[0], f[1])
    assert n > 0.1, f"the root's x axis is vertical: {f}"
    return [f[0] / n, f[1] / n, 0.0]


def test_first_camera_looks_at_the_front_from_above(view):
    page, front = view["page"], _expected_front(view["scene"], view["facing"])
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


def test_front_parts_are_visible_and_clicks_select_them(view):
    if not view["parts"]:
        # a case with no part named to click (two objects; the real bottle): the page was
        # asked for no clicks and made none
        assert not view["page"].get("clicks"), view["page"]["clicks"]
        return
    clicks = view["page"]["clicks"]
    assert clicks, view["page"]["bodies"]
    for c in clicks:
        # a visible part: at least a tenth of its screen box shows it (drawers and doors on the
        # front: a third or more; seen from the back, none)
        assert c["visible"] >= 0.1 * c["samples"], \
            f"{view['name']}: {c['name']} ({c['label']}) shows at {c['visible']} of " \
            f"{c['samples']} points"
        assert c["selected"] == c["id"], \
            f"{view['name']}: a click on {c['name']} at {c['at']} selected {c['selected']}"


def test_single_object_shows_its_joint_sliders_on_load(view):
    scene, panels = view["scene"], view["page"]["panels"]
    movable = [[j["name"] for j in a["joints"] if j["type"] != "fixed"]
               for a in scene["articulations"]]
    assert all(movable)
    # nothing selected yet
    assert panels["info_hidden"]
    assert "Click a part" in panels["hint"] and "joint" in panels["hint"]
    if len(movable) == 1:
        assert not panels["joints_hidden"]
        assert sorted(panels["sliders"]) == sorted(movable[0])
        assert panels["hint_hidden"]  # the sliders fill the side panel
    else:
        # which object's joints? a click on one of its parts says
        assert panels["joints_hidden"] and panels["sliders"] == []
        assert not panels["hint_hidden"]
