"""The gallery page of `partsim view --dataset ROOT` in a real browser (issue 17): headless
Chromium (Debian's) driven by puppeteer-core (web/node_modules) on a generated PartNet-Mobility
tree.

One session (module fixture) generates six objects (`partsim assets generate --categories
StorageFurniture,Faucet,Door --per-category 2 --seed 1`), starts `partsim view --dataset` on a
free loopback port and runs tests/web/gallery_check.mjs, which looks at the grid, filters it,
opens two objects one after the other with clicks on their cards and goes back with the Gallery
button; the tests below assert on what it printed and on the server's /api/gallery.json. They
skip only when Chromium cannot start; a missing page (build/web) or a failure of the page is a
failure.

PARTSIM_UPDATE_SCREENSHOT=1 copies the gallery's screenshot to docs/images/viewer_gallery.png.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import urllib.request
import xml.etree.ElementTree as ET

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "tests", "web"))

from browser_session import WEB_ROOT, Lines, require_page, run_page_check, stop  # noqa: E402

PARTSIM = os.environ.get("PARTSIM_BIN", os.path.join(REPO, "build", "partsim"))
CHECK = os.path.join(REPO, "tests", "web", "gallery_check.mjs")
CATEGORIES = ["StorageFurniture", "Faucet", "Door"]
URL = re.compile(r"http://127\.0\.0\.1:\d+/\?token=[0-9A-Za-z_-]+")


def _objects(root):
    """The generated tree as the gallery should list it: folder name, category, link names."""
    objects = []
    for name in sorted(os.listdir(root)):
        folder = os.path.join(root, name)
        if not os.path.isfile(os.path.join(folder, "mobility.urdf")):
            continue
        with open(os.path.join(folder, "meta.json")) as f:
            category = json.load(f)["model_cat"]
        robot = ET.parse(os.path.join(folder, "mobility.urdf")).getroot()
        links = [link.get("name") for link in robot.findall("link")]
        movable = [j.get("name") for j in robot.findall("joint") if j.get("type") != "fixed"]
        objects.append({"name": name, "category": category, "links": links, "movable": movable})
    return objects


def _get_json(url, path):
    base, token = url.split("/?token=")
    with urllib.request.urlopen(f"{base}{path}?token={token}", timeout=30) as r:
        return json.loads(r.read())


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    require_page()
    if not os.access(PARTSIM, os.X_OK):
        pytest.fail(f"{PARTSIM} is missing: build partsim first")
    out = str(tmp_path_factory.mktemp("viewer_gallery"))
    root = os.path.join(out, "tree")
    gen = subprocess.run([PARTSIM, "assets", "generate", "--out", root, "--categories",
                          ",".join(CATEGORIES), "--per-category", "2", "--seed", "1"],
                         capture_output=True, text=True, timeout=120)
    assert gen.returncode == 0, gen.stderr[-2000:]
    objects = _objects(root)
    assert len(objects) == 6, objects

    env = dict(os.environ, PARTSIM_WEB_DIR=WEB_ROOT)
    server = subprocess.Popen([PARTSIM, "view", "--dataset", root, "--port", "0"],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              env=env, cwd=out)
    try:
        lines = Lines(server)
        m = lines.wait_for(URL, 90)
        url = m.group(0) if m else None
        text = "\n".join(ln.get("text", json.dumps(ln)) for ln in lines.all)
        if url is None:
            stop(server)
            lines.thread.join(timeout=10)
            text = "\n".join(ln.get("text", json.dumps(ln)) for ln in lines.all)
            pytest.fail(f"partsim view --dataset printed no URL in 90 s (rc {server.returncode}): "
                        f"{text[-3000:]}")

        storage = max((o for o in objects if o["category"] == "StorageFurniture"),
                      key=lambda o: len(o["movable"]))
        door = next(o for o in objects if o["category"] == "Door")
        config = {"url": url, "out": out, "category": "Faucet", "label": "door",
                  "open": [storage["name"], door["name"]], "mesh_delay_ms": 600,
                  "timeout_ms": 240000}
        returncode, page = run_page_check(CHECK, config, timeout=300)
        if returncode != 0:
            pytest.fail(f"the gallery check failed: {page.get('error')} (steps {page.get('steps')}; "
                        f"page errors {page.get('errors')}); server output: {text[-3000:]}")
        served = _get_json(url, "/api/gallery.json")
        return {"page": page, "objects": objects, "served": served, "config": config,
                "by_name": {o["name"]: o for o in objects}}
    finally:
        stop(server)


def test_gallery_lists_the_generated_tree(session):
    page, objects = session["page"], session["objects"]
    assert page["ok"]
    assert page["gallery_ready"]["gallery"] is True
    assert page["state_at_load"] == {"enabled": True, "mode": "grid", "open": None, "name": ""}
    assert page["grid_visible"]
    items = page["items"]
    assert [i["name"] for i in items] == [o["name"] for o in objects]
    for item, o in zip(items, objects):
        assert item["category"] == o["category"]
        assert item["shown"]
        # what the card shows: name, category, labels
        assert o["name"] in item["text"] and o["category"] in item["text"], item["text"]
        for label in set(item["labels"]):
            assert label in item["text"], (label, item["text"])
    # the category select: every category with its count
    options = {opt["value"]: opt["text"] for opt in page["category_options"]}
    assert options[""].endswith("(6)")
    for c in CATEGORIES:
        assert options[c] == f"{c} (2)"
    assert page["errors_listed"] == []
    assert session["served"]["errors"] == []


def test_thumbnails_load(session):
    page = session["page"]
    for item in page["items"]:
        assert item["thumbnail"] == "loaded", item
        assert item["naturalWidth"] == 160 and item["naturalHeight"] == 120, item
    # a placeholder stood in for each picture until it came (the check held the pictures back
    # until it had counted them)
    assert page["placeholders_at_load"] == len(page["items"])
    # loaded as they scroll into view: a 440 x 200 window asks for the first rows only
    lazy = page["lazy"]
    names = [i["name"] for i in page["items"]]
    assert 0 < len(lazy["before_scroll"]) < len(names), lazy
    assert lazy["before_scroll"] == names[:len(lazy["before_scroll"])], lazy
    assert sorted(lazy["after_scroll"]) == sorted(names)
    assert lazy["errors"] == []
    if os.environ.get("PARTSIM_UPDATE_SCREENSHOT") == "1":
        shutil.copyfile(page["screenshot"], os.path.join(REPO, "docs", "images", "viewer_gallery.png"))


def test_filters_narrow_the_grid(session):
    page, objects = session["page"], session["objects"]
    faucets = [o["name"] for o in objects if o["category"] == "Faucet"]
    assert len(faucets) == 2
    assert page["category_filter"] == faucets
    assert page["count_text"].startswith("2 of 6")
    assert page["name_filter"] == [session["config"]["open"][0]]
    label = session["config"]["label"]
    with_label = [i["name"] for i in page["items"]
                  if any(label in lab for lab in i["labels"]) or label in i["name"]]
    assert with_label, f"no object has a label with '{label}'"
    assert page["label_filter"] == with_label
    assert page["after_filters"] == [o["name"] for o in objects]


def _moved(o):
    """Largest change of a link's drawn pose from the first sample to either later one (0.75 s
    and 1.5 s later: one of the two differs whatever the phase of the sweep)."""
    before = {b["name"]: b["pose"] for b in o["poses0"]}
    return max(max(abs(x - y) for x, y in zip(before[b["name"]], b["pose"]))
               for later in (o["poses_mid"], o["poses1"]) for b in later if b["name"] in before)


def test_click_opens_the_object_and_its_joints_animate(session):
    page = session["page"]
    for o in page["opened"]:
        expected = session["by_name"][o["name"]]
        assert o["state"]["mode"] == "viewer" and o["state"]["open"] == o["index"]
        assert o["toolbar_name"] == o["name"]
        assert o["canvas_visible"]
        links = sorted(b["name"] for b in o["bodies"] if b["kind"] == "link")
        assert links == sorted(expected["links"]), (links, expected["links"])
        # sampled once every mesh had come (they were held back 600 ms): each visual built
        for b in o["bodies"]:
            assert b["visuals"] == b["visuals_listed"], b
        assert sum(b["visuals"] for b in o["bodies"]) > 0
        # no meshes left over from the previous object: one per visual of this scene
        assert o["mesh_count"] == sum(b["visuals"] for b in o["bodies"]), o["mesh_count"]
        # the panels start afresh for each object
        assert o["info_hidden"] and o["joints_hidden"]
        assert expected["movable"], f"{o['name']} has no movable joint"
        assert _moved(o) > 1e-3, f"{o['name']}: no link moved in {o['sampled_s']:.1f} s"
        assert o["status1"]["time"] > o["status0"]["time"]
    first = page["opened"][0]
    assert first["selected"]["id"] is not None and first["info_shown_after_select"]


def test_step_while_running_pauses_and_the_page_says_so(session):
    step = session["page"]["step"]
    assert step["before"]["paused"] is False
    assert step["paused"]["paused"] is True and step["badge_paused"] == "paused"
    # paused stays paused: the simulation stands still
    assert step["later"]["step"] == step["paused"]["step"]
    assert step["badge_resumed"] == "running"


def test_gallery_button_returns_to_the_grid(session):
    page = session["page"]
    for o in page["opened"]:
        back = o["back"]
        assert back["state"] == {"enabled": True, "mode": "grid", "open": None, "name": ""}
        assert back["shown"] == [x["name"] for x in session["objects"]]
        assert not any(b["kind"] == "link" for b in back["bodies"])
        assert back["mesh_count"] == sum(b["visuals"] for b in back["bodies"])
        assert not back["canvas_visible"]
    assert session["served"]["open"] is None


def test_no_console_errors(session):
    page = session["page"]
    assert page["errors_at_end"] == [], page["errors_at_end"]
    # gallery mode answers /api/gallery.json: no 404 probe either
    assert page["probes"] == []
