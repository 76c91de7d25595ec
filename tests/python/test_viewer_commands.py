"""Where a joint moved in the viewer's page goes, through `partsim serve --viewer` on loopback:
a joint of the served robot through the robot's own controllers (the path of a ROS client's
position command: counted in /partsim/stats' commands on the rosbridge port), a joint of any
other articulation through a position controller of that joint; both joints then reach their
targets."""

import json
import os
import re
import time

import pytest

from conftest import CABINET_URDF, require
from test_viewer_cli import call, serve  # noqa: F401 (serve: the fixture)

websocket = require("websocket", "websocket-client (requirements.lock)")

ROSBRIDGE = re.compile(r"rosbridge on ws://127\.0\.0\.1:(\d+), robot /(\S+) ")


def joint_position(ws, articulation, joint, deadline):
    """The next /partsim/joint_states position of `joint` (None if none before `deadline`)."""
    while time.time() < deadline:
        ws.settimeout(max(0.01, deadline - time.time()))
        try:
            m = json.loads(ws.recv())
        except websocket.WebSocketTimeoutException:
            return None
        msg = m.get("msg", {})
        if (m.get("topic") == "/partsim/joint_states" and msg.get("articulation") == articulation
                and joint in msg.get("name", [])):
            return msg["position"][msg["name"].index(joint)]
    return None


def wait_near(ws, articulation, joint, target, tolerance, seconds=60):
    """Waits (up to `seconds`) for the joint to come within `tolerance` of `target`; the last
    position heard."""
    deadline, q = time.time() + seconds, None
    while time.time() < deadline:
        got = joint_position(ws, articulation, joint, deadline)
        if got is None:
            break
        q = got
        if abs(q - target) <= tolerance:
            break
    return q


def commands(port):
    ws = websocket.create_connection("ws://127.0.0.1:%d/" % port, timeout=30)
    try:
        return call(ws, "/partsim/stats")["values"]["commands"]
    finally:
        ws.close()


def test_page_joints_go_through_the_controllers(tmp_path, serve):
    urdf = tmp_path / ("cabinet_%d.urdf" % os.getpid())
    urdf.write_text(CABINET_URDF)
    s = serve(["serve", urdf, "--port", "0", "--viewer", "--viewer-port", "0", "--robot",
               "gripper"])
    m = ROSBRIDGE.search("".join(s.lines))
    assert m, "".join(s.lines)
    bridge, robot_name = int(m.group(1)), m.group(2)
    arts = s.json("/api/scene.json")["articulations"]
    robot = next(a["id"] for a in arts if a["name"] == robot_name)
    cabinet = next(a["id"] for a in arts if a["name"] == "cabinet")

    def prismatic(a):
        return next(j for j in arts[a]["joints"] if j["type"] == "prismatic")

    ws = s.connect()
    ws.send(json.dumps({"op": "subscribe", "topic": "/partsim/joint_states"}))
    before = commands(bridge)

    # the robot's joint: through the served robot's controllers, as a ROS client's command
    j = prismatic(robot)
    target = 0.2
    assert j["lower"] < target < j["upper"]
    r = call(ws, "/partsim/set_joint_target",
             {"articulation": robot, "joint": j["name"], "position": target}, "robot")
    assert r["result"] and r["values"]["success"], r
    assert "served robot" in r["values"]["message"], r
    assert commands(bridge) == before + 1, "the command went through the served robot"
    q = wait_near(ws, robot, j["name"], target, 0.02)
    assert q is not None and abs(q - target) <= 0.02, (q, target)

    # the cabinet's joint: a position controller of that joint, not the robot's
    c = prismatic(cabinet)
    lo, hi = c["lower"], c["upper"]
    target = lo + 0.5 * (hi - lo)
    r = call(ws, "/partsim/set_joint_target",
             {"articulation": cabinet, "joint": c["name"], "position": target}, "cabinet")
    assert r["result"] and r["values"]["success"], r
    assert commands(bridge) == before + 1, "the cabinet is not the served robot"
    q = wait_near(ws, cabinet, c["name"], target, 0.05 * (hi - lo))
    assert q is not None and abs(q - target) <= 0.05 * (hi - lo), (q, target)

    # out of the limits: clamped, and the answer says so
    r = call(ws, "/partsim/set_joint_target",
             {"articulation": cabinet, "joint": c["name"], "position": hi + 1.0}, "far")
    assert r["result"] and "clamped" in r["values"]["message"], r
    ws.close()
    assert s.sigterm() == 0
