"""`partsim serve --viewer` ends on SIGTERM, with exit status 0, whatever its clients are doing:
a viewer client flooding camera calls and sending messages near the size bound, and a rosbridge
client asking for motion plans, all the while the signal comes. The bound asserted is generous
(10 s, for a loaded machine); the time measured is printed."""

import json
import os
import re
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
VIEWER_URL = re.compile(r"http://127\.0\.0\.1:(\d+)/\?token=(\S+)")
ROSBRIDGE = re.compile(r"rosbridge on ws://127\.0\.0\.1:(\d+)")


def start_serve():
    proc = subprocess.Popen([CLI, "serve", "--port", "0", "--viewer", "--viewer-port", "0",
                             "--robot", "panda"], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    lines, found = [], threading.Event()

    def read():
        for line in proc.stdout:
            lines.append(line)
            if VIEWER_URL.search(line):
                found.set()
        found.set()

    threading.Thread(target=read, daemon=True).start()
    found.wait(60)
    text = "".join(lines)
    viewer, bridge = VIEWER_URL.search(text), ROSBRIDGE.search(text)
    if not viewer or not bridge:
        proc.kill()
        proc.wait(10)
        pytest.fail("partsim serve printed no addresses:\n" + text)
    return proc, lines, int(viewer.group(1)), viewer.group(2), int(bridge.group(1))


def busy(stop, errors, work):
    """Runs work() until `stop` is set or the server goes (the socket then fails)."""
    try:
        while not stop.is_set():
            work()
    except Exception as e:  # the server closing the socket under us is expected
        errors.append(repr(e))


def test_sigterm_ends_serve_within_bounds_while_clients_are_busy():
    proc, lines, viewer_port, token, bridge_port = start_serve()
    stop, errors, threads = threading.Event(), [], []
    try:
        # the viewer: camera pictures of the scene's cameras and messages near 1 MB
        page = websocket.create_connection("ws://127.0.0.1:%d/" % viewer_port, timeout=30)
        page.send(json.dumps({"op": "auth", "mac": token}))
        assert json.loads(page.recv())["msg"] == "authenticated"
        scene_url = "http://127.0.0.1:%d/api/scene.json?token=%s" % (viewer_port, token)
        with urllib.request.urlopen(scene_url, timeout=30) as r:
            cameras = json.loads(r.read()).get("cameras", [])
        camera = cameras[0]["name"] if cameras and "name" in cameras[0] else "front_camera"
        big = json.dumps({"op": "subscribe", "topic": "/x" * 300000})  # about 600 kB

        def flood_viewer():
            for _ in range(20):
                page.send(json.dumps({"op": "call_service", "service": "/partsim/camera",
                                      "args": {"name": camera}}))
            page.send(big)

        def drain(ws):
            def read():
                ws.settimeout(1)
                try:
                    ws.recv()
                except websocket.WebSocketTimeoutException:
                    pass
            return read

        # rosbridge: motion plans, over and over
        ros = websocket.create_connection("ws://127.0.0.1:%d/" % bridge_port, timeout=30)

        def plan():
            ros.send(json.dumps({"op": "call_service", "service": "/panda/plan",
                                 "args": {"joint_goal": [0.3, -0.5, 0.2, -2.0, 0.1, 1.8, 0.6],
                                          "time_limit": 5.0}}))
            time.sleep(0.05)

        for work in (flood_viewer, drain(page), plan, drain(ros)):
            t = threading.Thread(target=busy, args=(stop, errors, work), daemon=True)
            t.start()
            threads.append(t)
        time.sleep(3)  # the clients at work
        assert proc.poll() is None, "".join(lines)
        t0 = time.monotonic()
        proc.send_signal(signal.SIGTERM)
        try:
            code = proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            pytest.fail("partsim serve still ran 10 s after SIGTERM:\n" + "".join(lines[-20:]))
        took = time.monotonic() - t0
        print("partsim serve exited %.2f s after SIGTERM (status %d)" % (took, code))
        assert code == 0, "exit status %d:\n%s" % (code, "".join(lines[-20:]))
    finally:
        stop.set()
        if proc.poll() is None:
            proc.kill()
            proc.wait(10)
        for t in threads:
            t.join(5)
