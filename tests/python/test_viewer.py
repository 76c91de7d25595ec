"""partsim.Viewer and scene.create_viewer from Python: the binding surface (properties, the
SAPIEN calls), HTTP and the WebSocket against the running server on loopback, render()
blocking while the page pauses, and Ctrl-C while it blocks. The protocol itself is tested in C++
(tests/viewer/viewer_test.cc)."""

import json
import os
import signal
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request

import pytest

import partsim
from conftest import require

websocket = require("websocket", "websocket-client (requirements.lock)")


@pytest.fixture
def scene():
    s = partsim.Scene()
    s.add_ground(0.0)
    b = s.create_actor_builder()
    b.add_box_collision(half_size=[0.1, 0.1, 0.1])
    b.add_box_visual(half_size=[0.1, 0.1, 0.1])
    box = b.build()
    box.set_name("box")
    box.set_pose(partsim.Pose([0, 0, 1]))
    return s


def get(viewer, path, token=True):
    url = f"http://127.0.0.1:{viewer.port}{path}"
    if token:
        url += "?token=" + viewer.token
    with urllib.request.urlopen(url, timeout=10) as r:
        return r.read()


def connect(viewer):
    ws = websocket.create_connection(f"ws://127.0.0.1:{viewer.port}/", timeout=10)
    ws.send(json.dumps({"op": "auth", "mac": viewer.token}))
    assert json.loads(ws.recv())["msg"] == "authenticated"
    return ws


def wait_until(predicate, what, seen, timeout=60):
    """Polls predicate() until it holds; after `timeout` seconds (a loaded 2-core machine takes
    far less) fails, naming what was awaited and what seen() shows then."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            pytest.fail(f"waited {timeout} s for {what}; saw {seen()}")
        time.sleep(0.01)


def wait_until_blocked(returned, timeout=60, still=1.0):
    """Waits until the render loop has stopped returning: len(returned) unchanged for `still`
    seconds (a running loop returns thousands of times a second). Returns that length."""
    deadline = time.monotonic() + timeout
    count, since = len(returned), time.monotonic()
    while time.monotonic() - since < still:
        if time.monotonic() > deadline:
            pytest.fail(f"waited {timeout} s for render() to block; it still returns "
                        f"({len(returned)} times so far)")
        time.sleep(0.05)
        if len(returned) != count:
            count, since = len(returned), time.monotonic()
    return count


def reply(ws, call_id):
    while True:
        m = json.loads(ws.recv())
        if m.get("id") == call_id:
            return m


def test_viewer_serves_the_scene_and_streams_poses(scene, capfd):
    viewer = partsim.Viewer(scene, token="tok")
    assert "open http://127.0.0.1:%d/?token=tok" % viewer.port in capfd.readouterr().err
    assert viewer.url == "http://127.0.0.1:%d/?token=tok" % viewer.port
    assert viewer.token == "tok" and not viewer.closed and not viewer.paused
    content = json.loads(get(viewer, "/api/scene.json"))
    assert [b["name"] for b in content["bodies"]] == ["ground", "box"]
    assert content["poses"][7 + 2] == pytest.approx(1.0)
    with pytest.raises(urllib.error.HTTPError, match="403"):
        get(viewer, "/api/scene.json", token=False)
    mesh = get(viewer, "/api/mesh/%d.bin" % content["bodies"][1]["visuals"][0]["mesh"])
    assert mesh[:4] == b"PSMH"

    ws = connect(viewer)
    ws.send(json.dumps({"op": "subscribe", "topic": "/partsim/poses"}))
    first = json.loads(ws.recv())
    assert first["msg"]["ids"] == [0, 1]
    # SAPIEN's loop: the box falls, and only the box is sent
    for _ in range(30):
        scene.step()
        scene.update_render()
        viewer.render()
        time.sleep(0.02)
    moved = json.loads(ws.recv())
    assert moved["msg"]["ids"] == [1] and moved["msg"]["poses"][2] < 1.0
    ws.send(json.dumps({"op": "call_service", "service": "/partsim/close", "id": "c"}))
    assert reply(ws, "c")["result"] is True
    assert viewer.closed
    ws.close()
    viewer.stop()


def test_render_blocks_while_the_page_pauses(scene):
    viewer = scene.create_viewer()
    assert isinstance(viewer, partsim.Viewer)
    ws = connect(viewer)
    ws.send(json.dumps({"op": "call_service", "service": "/partsim/pause", "id": "p"}))
    assert reply(ws, "p")["result"] is True
    assert viewer.paused
    returned = []

    def loop():
        while not viewer.closed and len(returned) < 100:
            viewer.render()
            returned.append(1)
            scene.step()

    t = threading.Thread(target=loop)
    t.start()
    time.sleep(0.3)  # a loop that did not block would have returned by now
    assert not returned  # blocked
    ws.send(json.dumps({"op": "call_service", "service": "/partsim/step", "args": {"n": 2},
                        "id": "s"}))
    reply(ws, "s")
    wait_until(lambda: len(returned) >= 2, "render() to return twice after /partsim/step n=2",
               lambda: f"{len(returned)} returns")
    assert wait_until_blocked(returned) == 2  # and no more: blocked again
    ws.send(json.dumps({"op": "call_service", "service": "/partsim/close", "id": "c"}))
    reply(ws, "c")
    t.join(timeout=10)
    assert not t.is_alive() and viewer.closed
    ws.close()
    viewer.stop()


def test_step_while_running_pauses_then_steps(scene):
    viewer = scene.create_viewer()
    ws = connect(viewer)
    returned = []

    def loop():
        while not viewer.closed and len(returned) < 100000:
            viewer.render()
            returned.append(1)
            scene.step()

    t = threading.Thread(target=loop)
    t.start()
    wait_until(lambda: len(returned) >= 10, "the render loop to run (10 returns)",
               lambda: f"{len(returned)} returns, paused = {viewer.paused}")
    assert not viewer.paused  # running
    ws.send(json.dumps({"op": "call_service", "service": "/partsim/step", "args": {"n": 3},
                        "id": "s"}))
    assert reply(ws, "s")["result"] is True
    assert viewer.paused
    count = wait_until_blocked(returned)  # blocked again after the 3 steps
    assert t.is_alive(), f"the loop ended ({len(returned)} returns) instead of blocking"
    ws.send(json.dumps({"op": "call_service", "service": "/partsim/step", "args": {"n": 2},
                        "id": "s2"}))
    reply(ws, "s2")
    wait_until(lambda: len(returned) >= count + 2,
               "render() to return twice more after /partsim/step n=2",
               lambda: f"{len(returned) - count} more returns")
    assert wait_until_blocked(returned) == count + 2  # exactly 2, then blocked
    ws.send(json.dumps({"op": "call_service", "service": "/partsim/close", "id": "c"}))
    reply(ws, "c")
    t.join(timeout=10)
    assert not t.is_alive()
    ws.close()
    viewer.stop()


def test_sapien_viewer_calls(scene):
    viewer = partsim.Viewer()  # SAPIEN 2: the scene comes later
    with pytest.raises(urllib.error.HTTPError, match="503"):
        get(viewer, "/api/scene.json")  # no scene yet
    viewer.set_scene(scene)
    viewer.set_camera_xyz(x=-2, y=0, z=1)
    viewer.set_camera_rpy(r=0, p=-0.3, y=0)
    content = json.loads(get(viewer, "/api/scene.json"))
    assert content["initial_camera"] == {"position": [-2, 0, 1], "rpy": [0, -0.3, 0],
                                         "fovy": None}
    viewer.set_fovy(0.9)
    assert json.loads(get(viewer, "/api/scene.json"))["initial_camera"]["fovy"] == 0.9
    with pytest.raises(partsim.PartsimError, match="field of view"):
        viewer.set_fovy(0.0)
    assert len(content["bodies"]) == 2
    viewer.render()
    viewer.close()
    assert viewer.closed
    with pytest.raises(partsim.PartsimError, match="finite"):
        viewer.set_camera_xyz(float("nan"), 0, 0)
    viewer.stop()


def test_ctrl_c_while_paused_raises_keyboard_interrupt(tmp_path):
    # a child process: a SAPIEN loop that the page has paused, then SIGINT
    script = tmp_path / "loop.py"
    script.write_text(
        "import faulthandler, json, signal, sys, websocket, partsim\n"
        "faulthandler.register(signal.SIGUSR1)  # the test asks for the stacks if it hangs\n"
        "# Python turns SIGINT into KeyboardInterrupt only where it was not ignored at start: a\n"
        "# suite run from a background job (nohup ... &) passes SIGINT ignored to its children\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "scene = partsim.Scene()\n"
        "viewer = scene.create_viewer()\n"
        "ws = websocket.create_connection('ws://127.0.0.1:%d/' % viewer.port, timeout=10)\n"
        "ws.send(json.dumps({'op': 'auth', 'mac': viewer.token}))\n"
        "ws.send(json.dumps({'op': 'call_service', 'service': '/partsim/pause'}))\n"
        "while not viewer.paused: pass\n"
        "print('paused', flush=True)\n"
        "try:\n"
        "    while not viewer.closed:\n"
        "        scene.step(); viewer.render()\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted, closed =', viewer.closed, flush=True)\n")
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(partsim.__file__)))
    p = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert p.stdout.readline().strip() == "paused"
        time.sleep(0.3)
        p.send_signal(signal.SIGINT)
        # it exits within 0.3 s (measured on the loaded build VM); 30 s allows for any load, and
        # a child still running then shows where each of its threads stands (that is how a
        # SIGINT ignored from the start showed)
        try:
            out, _ = p.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            p.send_signal(signal.SIGUSR1)
            time.sleep(1)
            p.kill()
            out, err = p.communicate()
            pytest.fail(f"still running 30 s after SIGINT; printed {out!r}; stacks:\n{err}")
    finally:
        p.kill()
    assert "interrupted, closed = True" in out


def test_make_cabinet_urdf_is_the_built_in_cabinet():
    urdf = partsim.make_cabinet_urdf()
    scene = partsim.Scene()
    loader = scene.create_urdf_loader()
    loader.fix_root_link = True
    cabinet = loader.load_from_string(urdf, ".")
    assert [link.get_name() for link in cabinet.get_links()] == ["body", "drawer_0", "door_0"]
    assert [j.get_name() for j in cabinet.get_active_joints()] == ["drawer_0_joint",
                                                                  "door_0_joint"]
    assert partsim.make_cabinet_urdf(seed=3) != urdf
    with pytest.raises(partsim.PartsimError, match="height"):
        partsim.make_cabinet_urdf(height=-1)


def http_code(viewer, path, token=True):
    """The status of a GET (200 or the error's code)."""
    try:
        get(viewer, path, token)
        return 200
    except urllib.error.HTTPError as e:
        return e.code


def test_bundle_serves_only_regular_files_inside_its_folder(scene, tmp_path):
    root = tmp_path / "web"
    root.mkdir()
    (root / "index.html").write_text("<html>the page</html>")
    (root / "viewer.js").write_text("let x = 1;")
    (root / "sub").mkdir()
    os.symlink("viewer.js", root / "alias.js")  # a link that stays inside is followed
    os.symlink("/", root / "all")
    os.symlink("/etc/passwd", root / "passwd.txt")
    os.symlink(tmp_path, root / "up")
    (tmp_path / "secret.txt").write_text("not in the bundle")
    os.mkfifo(root / "fifo.js")
    viewer = partsim.Viewer(scene, token="tok", web_root=str(root))
    try:
        assert get(viewer, "/", token=False) == b"<html>the page</html>"
        assert get(viewer, "/viewer.js", token=False) == b"let x = 1;"
        assert get(viewer, "/alias.js", token=False) == b"let x = 1;"
        # links out of the folder, folders and FIFOs (never opened: the request would hang)
        for path in ["/all/etc/passwd", "/passwd.txt", "/up/secret.txt", "/all", "/sub",
                     "/fifo.js"]:
            assert http_code(viewer, path, token=False) in (403, 404), path
    finally:
        viewer.close()


def png_bytes(width, height):
    """A grey 8-bit PNG of width x height pixels."""
    import struct
    import zlib

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff))

    rows = b"".join(b"\0" + b"\x80" * width for _ in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0,
                                                              0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def test_texture_endpoint_serves_only_images_beside_their_mesh(tmp_path, capfd):
    obj = tmp_path / "object"
    (obj / "textured_objs").mkdir(parents=True)
    (obj / "images").mkdir()
    (obj / "images" / "wood.png").write_bytes(png_bytes(3, 2))
    (obj / "textured_objs" / "text.png").write_text("root:x:0:0:not an image\n")
    os.symlink("/etc/passwd", obj / "textured_objs" / "link.png")
    # PartNet-Mobility's layout: textured_objs/*.mtl name ../images/*
    maps = {"good": "../images/wood.png", "absolute": "/etc/passwd",
            "escape": "../../../../../../../../etc/shadow", "link": "link.png",
            "text": "text.png"}
    scene = partsim.Scene()
    for name, map_kd in maps.items():
        (obj / "textured_objs" / f"{name}.mtl").write_text(f"newmtl m\nKd 1 1 1\nmap_Kd {map_kd}\n")
        (obj / "textured_objs" / f"{name}.obj").write_text(
            f"mtllib {name}.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
            "usemtl m\nf 1/1 2/2 3/3\n")
        b = scene.create_actor_builder()
        b.add_visual_from_file(str(obj / "textured_objs" / f"{name}.obj"))
        b.build_kinematic().set_name(name)
    viewer = partsim.Viewer(scene, token="tok")
    try:
        content = json.loads(get(viewer, "/api/scene.json"))  # the scene loads
        texture = {b["name"]: b["visuals"][0]["texture"] for b in content["bodies"]}
        # the image beside its mesh, decoded and sent as PNG
        png = get(viewer, "/api/texture/%d.png" % texture["good"])
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and png[16:24] == bytes([0, 0, 0, 3, 0, 0, 0, 2])
        # files out of the object's folder are dropped from the scene with a warning
        for name in ["absolute", "escape", "link"]:
            assert texture[name] == -1, name
        err = capfd.readouterr().err
        assert "/etc/passwd" in err and "shadow" in err
        # a file that is not an image is not sent
        assert texture["text"] >= 0
        assert http_code(viewer, "/api/texture/%d.png" % texture["text"]) == 404
        for k in range(len(maps) + 1):
            try:
                assert b"root:" not in get(viewer, "/api/texture/%d.png" % k)
            except urllib.error.HTTPError:
                pass
    finally:
        viewer.close()
