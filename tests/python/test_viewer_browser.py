"""The viewer page in a real browser (issue 17): headless Chromium (Debian's) driven by
puppeteer-core (web/node_modules) against a SAPIEN-style viewer loop on the cabinet.

One session (module fixture) runs tests/web/cabinet_viewer.py, which prints the viewer's URL and
a partsim camera's pose and silhouette, and tests/web/viewer_check.mjs, which opens the page,
takes the pictures and clicks, drags, pauses and closes with real mouse events; the tests below
assert on what both printed. They skip only when Chromium (or the page's packages) cannot start;
a missing page (build/web) or a failure of the page is a failure.

Silhouette threshold: the page's non-background pixels (segmentation colours, no grid, panels
hidden) against partsim's depth > 0 at the same camera pose, fovy and size: IoU >= 0.8. The two
renderers draw the same triangles through the same projection, so the silhouettes differ by
edge pixels only (IoU 0.9998 measured on the cabinet); 0.8 still fails a camera off by a few
degrees or centimetres, a wrong axis convention or a missing part.

PARTSIM_UPDATE_SCREENSHOT=1 copies the page's screenshot to docs/images/viewer.png.
"""

import os
import queue
import shutil
import subprocess
import sys
import time

import numpy as np
import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "tests", "web"))

from browser_session import WEB_ROOT, Lines, require_page, run_page_check, stop  # noqa: E402

PYTHON_DIR = os.environ.get("PARTSIM_PYTHON_DIR", os.path.join(REPO, "build", "python"))
SCRIPT = os.path.join(REPO, "tests", "web", "cabinet_viewer.py")
CHECK = os.path.join(REPO, "tests", "web", "viewer_check.mjs")
IOU_THRESHOLD = 0.8


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    require_page()
    out = str(tmp_path_factory.mktemp("viewer_browser"))
    env = dict(os.environ, PARTSIM_PYTHON_DIR=PYTHON_DIR, PARTSIM_WEB_DIR=WEB_ROOT)
    err_path = os.path.join(out, "loop_stderr.txt")
    err = open(err_path, "w")
    loop = subprocess.Popen(
        [sys.executable, SCRIPT, "--out", out, "--max-seconds", "240"],
        stdout=subprocess.PIPE, stderr=err, text=True, env=env, cwd=REPO)

    def loop_stderr():
        err.flush()
        with open(err_path) as f:
            return f.read()[-3000:]

    try:
        lines = Lines(loop)
        try:
            first = lines.next(timeout=90)
        except queue.Empty:
            pytest.fail("the viewer loop printed nothing in 90 s")
        if first is None or "url" not in first:
            stop(loop)
            pytest.fail(f"the viewer loop failed: {first} {loop_stderr()}")
        config = {"url": first["url"], "camera": first["camera"], "out": out, "timeout_ms": 180000}
        returncode, page = run_page_check(CHECK, config, timeout=240)
        # the close button ends the loop; its last line says so
        deadline = time.time() + 30
        while loop.poll() is None and time.time() < deadline:
            time.sleep(0.1)
        stop(loop)
        lines.thread.join(timeout=10)
        if returncode != 0:
            pytest.fail(f"the page check failed: {page.get('error')} (steps {page.get('steps')}; "
                        f"page errors {page.get('errors')}); loop stderr: "
                        f"{loop_stderr()}")
        return {"first": first, "page": page, "lines": lines.all, "out": out}
    finally:
        stop(loop)
        err.close()


def test_page_loads_without_console_errors(session):
    page = session["page"]
    assert page["ok"]
    assert page["errors_before_close"] == [], page["errors_before_close"]
    assert page["stats_at_load"]["connected"]
    assert page["stats_at_load"]["bodies"] == len(page["bodies"]) >= 3
    # poses stream: the page drew pose messages and its last one is recent
    assert page["stats"]["pose_messages"] > 10
    assert page["stats"]["fps"] > 0


def test_screenshot_shows_cabinet_where_partsim_camera_sees_it(session):
    from PIL import Image

    page = session["page"]
    ours = np.asarray(Image.open(session["first"]["mask"]).convert("L")) > 127
    shot = np.asarray(Image.open(page["silhouette"]).convert("RGB")).astype(int)
    background = np.array([int(page["background"][i:i + 2], 16) for i in (0, 2, 4)])
    theirs = np.abs(shot - background).sum(axis=2) > 24
    assert ours.shape == theirs.shape, (ours.shape, theirs.shape)
    assert ours.mean() > 0.05, "the partsim camera does not see the cabinet"
    iou = (ours & theirs).sum() / max((ours | theirs).sum(), 1)
    assert iou >= IOU_THRESHOLD, f"silhouette IoU {iou:.3f} < {IOU_THRESHOLD}"
    if os.environ.get("PARTSIM_UPDATE_SCREENSHOT") == "1":
        shutil.copyfile(page["screenshot"], os.path.join(REPO, "docs", "images", "viewer.png"))


def test_click_on_drawer_shows_its_label(session):
    page = session["page"]
    drawer = next(b for b in page["bodies"] if b["label"] == "drawer")
    assert page["selected"] == drawer["id"]
    assert page["info"]["label"] == "drawer"
    assert page["info"]["name"].startswith(drawer["name"])
    assert page["info"]["type"] == "prismatic"
    assert page["info"]["joint"] == drawer["joint"]


def test_slider_drag_moves_the_joint_on_the_server(session):
    page = session["page"]
    slider = page["slider"]
    lo, hi = slider["range"]
    target = slider["value"]
    assert target > lo + 0.5 * (hi - lo), f"the drag set {target} in [{lo}, {hi}]"
    # qpos printed by the Python loop after the drag (and its last line, at close)
    after = [ln for ln in session["lines"]
             if "qpos" in ln and ln.get("wall", float("inf")) > slider["dragged_at"]]
    assert after, "the loop printed no qpos after the drag"
    q = after[-1]["qpos"][slider["joint"]]
    assert abs(q - target) < 0.15 * (hi - lo), f"server qpos {q}, slider target {target}"
    assert q > lo + 0.4 * (hi - lo)


def test_pause_stops_the_simulation(session):
    page = session["page"]
    pause = page["pause"]
    assert pause["before"]["step"] == pause["after"]["step"]
    assert pause["before"]["time"] == pause["after"]["time"]
    assert pause["after"]["wall"] - pause["before"]["wall"] >= 1.5
    assert pause["resumed"]["step"] > pause["after"]["step"]
    # the Python loop itself stood still: render() blocked while paused
    walls = [ln["wall"] for ln in session["lines"] if "wall" in ln]
    gaps = np.diff(walls)
    assert gaps.size and gaps.max() >= 1.5, f"largest gap between loop lines {gaps.max():.2f} s"


def test_close_button_ends_the_viewer_loop(session):
    last = session["lines"][-1]
    assert last.get("closed") is True, last
    assert last.get("timeout") is False
