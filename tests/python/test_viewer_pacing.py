"""The Python viewer's loop timing: render() paces SAPIEN's loop to real time by default (the
scene's time does not run ahead of the wall clock), runs as fast as it can with
realtime=False / set_realtime(False), and wait_for_client(timeout) tells whether a page (a
WebSocket client) came. Wall-clock bounds here are lower bounds, except one: the unpaced loop
stays far below real time (1 s for 10 s simulated; the loop takes about 10 ms)."""

import json
import threading
import time

import pytest

import partsim
from conftest import require

websocket = require("websocket", "websocket-client (requirements.lock)")


def _scene(timestep):
    s = partsim.Scene(timestep=timestep)
    s.add_ground(0.0)
    b = s.create_actor_builder()
    b.add_box_collision(half_size=[0.1, 0.1, 0.1])
    b.add_box_visual(half_size=[0.1, 0.1, 0.1])
    box = b.build()
    box.set_pose(partsim.Pose([0, 0, 0.5]))
    return s


def _loop(scene, viewer, n):
    """SAPIEN's viewer loop for n steps; the wall-clock seconds it took."""
    start = time.monotonic()
    for _ in range(n):
        scene.step()
        scene.update_render()
        viewer.render()
    return time.monotonic() - start


def test_render_paces_the_loop_to_real_time_by_default():
    dt, n = 0.02, 40
    scene = _scene(dt)
    viewer = scene.create_viewer()
    try:
        assert viewer.realtime
        t0 = scene.get_time()
        wall = _loop(scene, viewer, n)
        # pacing starts at the first render(): the n - 1 steps after it take at least their
        # simulated time
        simulated = scene.get_time() - t0
        assert simulated == pytest.approx(n * dt)
        assert wall >= 0.999 * (n - 1) * dt, f"{n} steps of {dt} s took {wall:.3f} s"
    finally:
        viewer.stop()


def test_partsim_viewer_class_paces_too():
    dt, n = 0.02, 30
    scene = _scene(dt)
    viewer = partsim.Viewer(scene)
    try:
        assert viewer.realtime
        wall = _loop(scene, viewer, n)
        assert wall >= 0.999 * (n - 1) * dt
    finally:
        viewer.stop()


@pytest.mark.parametrize("how", ["create_viewer", "set_realtime"])
def test_unpaced_loop_runs_far_faster_than_real_time(how):
    dt, n = 0.1, 100  # 10 s of simulated time
    scene = _scene(dt)
    if how == "create_viewer":
        viewer = scene.create_viewer(realtime=False)
    else:
        viewer = partsim.Viewer(scene)
        viewer.set_realtime(False)
    try:
        assert not viewer.realtime
        wall = _loop(scene, viewer, n)
        assert scene.get_time() == pytest.approx(n * dt)
        # unpaced, 100 steps and renders of a box take milliseconds: far below the 10 s that a
        # paced loop takes at least
        assert wall < 0.1 * n * dt, f"{n} unpaced steps took {wall:.3f} s"
    finally:
        viewer.stop()


def test_pacing_can_be_switched_back_on():
    dt, n = 0.02, 30
    scene = _scene(dt)
    viewer = scene.create_viewer(realtime=False)
    try:
        _loop(scene, viewer, 10)
        viewer.set_realtime(True)
        assert viewer.realtime
        # paced from the first render() after the switch, not from the start of the loop
        wall = _loop(scene, viewer, n)
        assert wall >= 0.999 * (n - 1) * dt
    finally:
        viewer.stop()


def test_sapien_adapter_viewer_paces_by_default():
    sapien = pytest.importorskip("partsim.sapien")
    dt, n = 0.02, 30
    scene = sapien.Scene()
    scene.set_timestep(dt)
    viewer = scene.create_viewer()
    try:
        assert viewer.realtime
        start = time.monotonic()
        for _ in range(n):
            scene.step()
            scene.update_render()
            viewer.render()
        assert time.monotonic() - start >= 0.999 * (n - 1) * dt
        viewer.set_realtime(False)
        assert not viewer.realtime
    finally:
        viewer.stop()


def _connect(viewer):
    """A WebSocket client that authenticates as the page does; returns it once answered."""
    ws = websocket.create_connection(f"ws://127.0.0.1:{viewer.port}/", timeout=30)
    ws.send(json.dumps({"op": "auth", "mac": viewer.token}))
    assert json.loads(ws.recv())["msg"] == "authenticated"
    return ws


def test_wait_for_client_times_out_without_a_page():
    viewer = partsim.Viewer(_scene(0.01))
    try:
        assert viewer.clients == 0
        start = time.monotonic()
        assert viewer.wait_for_client(timeout=0.3) is False
        assert time.monotonic() - start >= 0.3
        assert viewer.wait_for_client(timeout=0) is False
    finally:
        viewer.stop()


def test_wait_for_client_returns_true_once_a_client_authenticates():
    scene = _scene(0.01)
    viewer = scene.create_viewer()
    clients = []
    errors = []

    def connect():
        try:
            time.sleep(0.2)  # the viewer is waiting by then, typically
            clients.append(_connect(viewer))
        except Exception as e:  # noqa: BLE001  (reported by the assertion below)
            errors.append(e)

    thread = threading.Thread(target=connect, daemon=True)
    thread.start()
    try:
        assert viewer.wait_for_client(timeout=120) is True, errors
        assert viewer.clients >= 1
        thread.join(timeout=60)
        assert clients and not errors, errors
        # connected already: no wait
        assert viewer.wait_for_client(timeout=0) is True
        # the client goes: the count follows (the server notices the close on its thread)
        clients[0].close()
        deadline = time.monotonic() + 60
        while viewer.clients and time.monotonic() < deadline:
            time.sleep(0.05)
        assert viewer.clients == 0
        assert viewer.wait_for_client(timeout=0.1) is False
    finally:
        for ws in clients:
            ws.close()
        viewer.stop()


def test_wait_for_client_returns_false_once_closed():
    viewer = partsim.Viewer(_scene(0.01))
    try:
        viewer.close()
        # no timeout: it would wait for ever, but the viewer is closed
        assert viewer.wait_for_client() is False
    finally:
        viewer.stop()
