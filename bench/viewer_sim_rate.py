"""How much the browser viewer slows the simulation of ``partsim serve`` (issue 17: a drop
under 5%).

Runs ``partsim serve --fast --duration S --address 127.0.0.1 --port 0`` as a subprocess, once
without the viewer and once with ``--viewer --viewer-port 0`` and one WebSocket client that
talks to the viewer as the page does (docs/viewer.md, "The page"): it reads the token from the
URL the server prints, sends ``{"op": "auth", "mac": T}`` first, loads ``/api/scene.json``, then
subscribes to ``/partsim/poses``, ``/partsim/joint_states`` and ``/partsim/status`` and reads
(and parses) every message until the server stops. The steps come from the server's final line
("partsim serve: stopped after N steps ..."); steps/s = N / S (the server steps from just
before it prints its URL until S s later, polled every 20 ms).

Scenes: the built-in cabinet of ``partsim serve`` with each robot of ``--robots`` (``panda``,
the default robot, and ``gripper``, the flying gripper), each ``--motion``:

* ``still``: nothing commanded. The robot holds its home pose and the cabinet stays shut, so
  the viewer finds nothing that moved and sends one pose message (all bodies) per run: this
  measures the pose snapshots alone (60 a second of wall time).
* ``moving``: in both configurations (with and without the viewer) a second client, on the
  rosbridge port, sends once one ``JointTrajectory`` that swings one robot joint (the Panda's
  ``panda_joint1``, the gripper's ``yaw``) by +-0.5 rad around where it is, a sine of 2.9 s
  of simulated time, long enough for the whole run (points with velocities: the server then
  interpolates one segment per step). The robot's links move between any two snapshots, so
  the client gets pose and joint-state messages at up to the viewer's 60 Hz (about 50 a
  second on the 2-core VM).

The two configurations run back to back per scene, without first in odd rounds and with first
in even ones (a first run of a pair measured faster or slower would otherwise bias the
ratio), scene after scene, for ``--repeats`` rounds. The table shows, per scene, the median
steps/s without and with the viewer (and their minimum-maximum), the median of the per-round ratios with /
without, and the pose messages the client received per second (from subscribing to the
connection's close). The client runs in this process, on the same cores as the server, as a
page would (a browser costs far more). On a shared machine the load average (printed at the
start and the end) says how much other work competed.

Usage: PARTSIM_PYTHON_DIR=build/python /usr/bin/python3 bench/viewer_sim_rate.py
       [--repeats R] [--seconds S] [--robots panda,gripper] [--motion still,moving]
The partsim executable: $PARTSIM_CLI, else ``partsim`` beside PARTSIM_PYTHON_DIR (default
build/python, so build/partsim). Needs Debian's python3-websocket (``import websocket``).
"""

import argparse
import json
import math
import os
import platform
import queue
import re
import statistics
import subprocess
import sys
import threading
import time
import urllib.request

try:
    import websocket  # Debian's python3-websocket (scripts/setup.sh)
except ImportError:
    sys.exit("viewer_sim_rate.py: needs the websocket module (Debian's python3-websocket); "
             "run it with /usr/bin/python3")

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PYTHON_DIR = os.path.abspath(os.environ.get("PARTSIM_PYTHON_DIR",
                                            os.path.join(REPO, "build", "python")))
CLI = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(PYTHON_DIR), "partsim"))

HOST = "127.0.0.1"  # the server binds it and every client talks to it only
STARTUP_TIMEOUT = 60.0  # s until the server prints its URLs
STOP_MARGIN = 60.0  # s the server may take past --duration to stop
IO_TIMEOUT = 10.0  # s for a WebSocket connect or an HTTP request

# the joint each robot swings in "moving" (by the name the robot's joint_states give it)
MOTION_JOINT = {"panda": "panda_joint1", "flying_gripper": "yaw"}
MOTION_AMPLITUDE = 0.5  # rad
MOTION_PERIOD = 2.9  # s of simulated time
MOTION_POINT_DT = 0.25  # s of simulated time between trajectory points

ROSBRIDGE_LINE = re.compile(r"rosbridge on ws://127\.0\.0\.1:(\d+), robot /(\S+) ")
VIEWER_LINE = re.compile(r"viewer: open http://127\.0\.0\.1:(\d+)/\?token=(\w+)")
FINAL_LINE = re.compile(r"partsim serve: stopped after (\d+) steps \(([\d.]+) s simulated\); "
                        r"(\d+) messages sent, (\d+) dropped; (\d+) commands")


class BenchError(Exception):
    pass


def fail(what, proc=None, out=None, err=None):
    """A BenchError naming what went wrong, with the end of the server's output."""
    tail = ""
    if out is not None:
        tail += "\n--- stdout ---\n" + "".join(out[-20:])
    if err is not None:
        tail += "\n--- stderr ---\n" + "".join(err[-20:])
    rc = "" if proc is None or proc.poll() is None else f" (exit code {proc.returncode})"
    return BenchError(what + rc + tail)


class ViewerClient(threading.Thread):
    """One page's worth of WebSocket traffic: auth, scene.json, the page's three
    subscriptions, then every message read and parsed until the server closes."""

    def __init__(self, port, token, seconds):
        super().__init__(daemon=True)
        self.port, self.token = port, token
        self.deadline = time.monotonic() + seconds + STOP_MARGIN
        self.counts = {"/partsim/poses": 0, "/partsim/joint_states": 0, "/partsim/status": 0}
        self.pose_ids = 0  # bodies summed over the pose messages
        self.first_pose_ids = 0
        self.bodies = None
        self.subscribed_at = self.first_pose_at = self.closed_at = None
        self.error = None
        self.started = threading.Event()  # subscribed (or failed)

    def run(self):
        ws = None
        try:
            ws = websocket.create_connection(f"ws://{HOST}:{self.port}/", timeout=IO_TIMEOUT)
            ws.send(json.dumps({"op": "auth", "mac": self.token}))
            reply = json.loads(ws.recv())
            if reply.get("op") != "status" or reply.get("level") == "error":
                raise BenchError(f"viewer refused the token: {reply}")
            url = f"http://{HOST}:{self.port}/api/scene.json?token={self.token}"
            with urllib.request.urlopen(url, timeout=IO_TIMEOUT) as r:
                self.bodies = len(json.load(r)["bodies"])
            for topic in self.counts:
                ws.send(json.dumps({"op": "subscribe", "topic": topic}))
            self.subscribed_at = time.monotonic()
            self.started.set()
            while True:
                ws.settimeout(max(0.1, min(IO_TIMEOUT, self.deadline - time.monotonic())))
                try:
                    text = ws.recv()
                except websocket.WebSocketConnectionClosedException:
                    break
                if not text:  # a close frame
                    break
                m = json.loads(text)
                if m.get("op") == "status" and m.get("level") in ("error", "warning"):
                    raise BenchError(f"viewer answered an error: {m}")
                topic = m.get("topic")
                if topic in self.counts:
                    self.counts[topic] += 1
                if topic == "/partsim/poses":
                    ids = len(m["msg"]["ids"])
                    self.pose_ids += ids
                    if self.first_pose_at is None:
                        self.first_pose_at, self.first_pose_ids = time.monotonic(), ids
                if time.monotonic() > self.deadline:
                    raise BenchError("the viewer's connection stayed open past the run")
        except Exception as e:  # reported by the run, which fails
            self.error = e
        finally:
            self.closed_at = time.monotonic()
            self.started.set()
            if ws is not None:
                try:
                    ws.close(timeout=1)
                except Exception:
                    pass


def drive_robot(port, robot, seconds):
    """Connects to the rosbridge port and sends one JointTrajectory that swings the robot's
    MOTION_JOINT for the whole run; returns the open connection (closed by the caller)."""
    ws = websocket.create_connection(f"ws://{HOST}:{port}/", timeout=IO_TIMEOUT)
    # the joint's current position: one /joint_states message (throttled: the server
    # publishes it every step)
    ws.send(json.dumps({"op": "subscribe", "id": "js", "topic": "/joint_states",
                        "throttle_rate": 1000, "queue_length": 1}))
    while True:
        m = json.loads(ws.recv())
        if m.get("op") == "status" and m.get("level") == "error":
            raise BenchError(f"rosbridge refused the /joint_states subscription: {m}")
        if m.get("topic") == "/joint_states":
            break
    ws.send(json.dumps({"op": "unsubscribe", "id": "js", "topic": "/joint_states"}))
    names = m["msg"]["name"]
    joint = MOTION_JOINT.get(robot)
    if joint not in names:
        raise BenchError(f"robot /{robot}: no joint {joint!r} to move among {names}")
    q0 = m["msg"]["position"][names.index(joint)]
    # simulated seconds the run may reach: 500 Hz physics at up to 500,000 steps/s
    horizon = min(86400.0, seconds * 1000.0 + 10.0)
    n = int(horizon / MOTION_POINT_DT)
    w = 2 * math.pi / MOTION_PERIOD
    # with velocities: the server interpolates each segment on its own (cubic Hermite);
    # positions alone make it fit a spline through every point at every step, whose cost would
    # swamp the viewer's
    points = [{"positions": [q0 + MOTION_AMPLITUDE * math.sin(w * k * MOTION_POINT_DT)],
               "velocities": [MOTION_AMPLITUDE * w * math.cos(w * k * MOTION_POINT_DT)],
               "time_from_start": round(k * MOTION_POINT_DT, 6)} for k in range(1, n + 1)]
    ws.send(json.dumps({"op": "publish", "topic": f"/{robot}/joint_trajectory_controller/command",
                        "msg": {"joint_names": [joint], "points": points}}))
    return ws


def run_serve(robot_args, viewer, moving, seconds):
    """One `partsim serve --fast` run; returns its figures (raises BenchError)."""
    cmd = [CLI, "serve", "--fast", "--duration", f"{seconds:g}", "--address", HOST,
           "--port", "0"] + robot_args
    if viewer:
        cmd += ["--viewer", "--viewer-port", "0"]
    out, err, lines = [], [], queue.Queue()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            stdin=subprocess.DEVNULL)

    def read(stream, keep, q=None):
        for line in stream:
            keep.append(line)
            if q is not None:
                q.put(line)
        if q is not None:
            q.put(None)

    readers = [threading.Thread(target=read, args=(proc.stdout, out, lines), daemon=True),
               threading.Thread(target=read, args=(proc.stderr, err), daemon=True)]
    for t in readers:
        t.start()
    client = driver = None
    try:
        # the URLs: the rosbridge line, and the viewer's with --viewer
        bridge_port = robot = viewer_port = token = None
        deadline = time.monotonic() + STARTUP_TIMEOUT
        while bridge_port is None or (viewer and viewer_port is None):
            try:
                line = lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                raise fail(f"{' '.join(cmd)}: no URL printed within {STARTUP_TIMEOUT:.0f} s",
                           proc, out, err)
            if line is None:
                proc.wait(timeout=IO_TIMEOUT)
                readers[1].join(IO_TIMEOUT)
                raise fail(f"{' '.join(cmd)}: the server did not start", proc, out, err)
            m = ROSBRIDGE_LINE.search(line)
            if m:
                bridge_port, robot = int(m.group(1)), m.group(2)
            m = VIEWER_LINE.search(line)
            if m:
                viewer_port, token = int(m.group(1)), m.group(2)
        if viewer:
            client = ViewerClient(viewer_port, token, seconds)
            client.start()
            client.started.wait(STARTUP_TIMEOUT)
            if client.error is not None:
                raise fail(f"viewer client: {client.error}", proc, out, err)
        if moving:
            driver = drive_robot(bridge_port, robot, seconds)
        try:
            proc.wait(timeout=seconds + STOP_MARGIN)
        except subprocess.TimeoutExpired:
            raise fail(f"{' '.join(cmd)}: still running {STOP_MARGIN:.0f} s after --duration",
                       proc, out, err)
        for t in readers:
            t.join(IO_TIMEOUT)
        final = [FINAL_LINE.search(line) for line in out]
        final = [m for m in final if m]
        if proc.returncode != 0 or not final:
            raise fail(f"{' '.join(cmd)}: no final line 'partsim serve: stopped after N steps'",
                       proc, out, err)
        steps, commands = int(final[-1].group(1)), int(final[-1].group(5))
        if moving and commands < 1:
            raise fail(f"{' '.join(cmd)}: the robot's trajectory command did not arrive",
                       proc, out, err)
        r = {"steps": steps, "rate": steps / seconds, "robot": robot}
        if client is not None:
            client.join(STOP_MARGIN)
            if client.is_alive():
                raise fail("viewer client: still reading after the server stopped", proc, out,
                           err)
            if client.error is not None:
                raise fail(f"viewer client: {client.error}", proc, out, err)
            subscribed = max(1e-9, client.closed_at - client.subscribed_at)
            poses = client.counts["/partsim/poses"]
            r.update(poses=poses, pose_rate=poses / subscribed, bodies=client.bodies,
                     joint_states=client.counts["/partsim/joint_states"],
                     status=client.counts["/partsim/status"],
                     ids_per_pose=client.pose_ids / poses if poses else 0.0,
                     first_pose_ids=client.first_pose_ids,
                     first_pose_ms=(None if client.first_pose_at is None else
                                    1000 * (client.first_pose_at - client.subscribed_at)),
                     subscribed=subscribed)
        return r
    finally:
        if driver is not None:
            try:
                driver.close(timeout=1)
            except Exception:
                pass
        if proc.poll() is None:
            proc.kill()
            proc.wait(timeout=IO_TIMEOUT)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=5, help="rounds (default 5)")
    ap.add_argument("--seconds", type=float, default=5.0, help="--duration of each run (default 5)")
    ap.add_argument("--robots", default="panda,gripper",
                    help="robots beside the built-in cabinet (default panda,gripper)")
    ap.add_argument("--motion", default="still,moving",
                    help="still, moving or both (default still,moving)")
    args = ap.parse_args()
    robots = [r for r in args.robots.split(",") if r]
    motions = [m for m in args.motion.split(",") if m]
    if args.repeats < 1 or args.seconds <= 0 or not robots or not motions:
        ap.error("--repeats, --seconds, --robots and --motion need positive values")
    for r in robots:
        if r not in ("panda", "gripper"):
            ap.error(f"--robots: {r!r} is not panda or gripper")
    for m in motions:
        if m not in ("still", "moving"):
            ap.error(f"--motion: {m!r} is not still or moving")
    if not os.access(CLI, os.X_OK):
        sys.exit(f"viewer_sim_rate.py: no partsim executable at {CLI} (build first, or set "
                 "PARTSIM_CLI or PARTSIM_PYTHON_DIR)")
    scenes = [(f"cabinet + {r}, {m}", ["--robot", r], m == "moving")
              for r in robots for m in motions]

    load0 = os.getloadavg()
    print(f"partsim serve at {CLI}; python {platform.python_version()}, websocket-client "
          f"{websocket.__version__}, {os.cpu_count()} cores; load average at the start "
          f"{load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}", flush=True)
    t0 = time.monotonic()
    results = {name: {"without": [], "with": []} for name, _, _ in scenes}
    try:
        for rnd in range(args.repeats):
            for name, robot_args, moving in scenes:
                # the order turns every round (without first, then with first, ...), so that
                # whatever favours the first or the second run of a pair cancels out
                for viewer in ((False, True) if rnd % 2 == 0 else (True, False)):
                    r = run_serve(robot_args, viewer, moving, args.seconds)
                    results[name]["with" if viewer else "without"].append(r)
                    line = (f"  round {rnd + 1}/{args.repeats}, {name}, "
                            f"{'with' if viewer else 'without'} viewer: {r['steps']} steps, "
                            f"{r['rate']:.0f} steps/s")
                    if viewer:
                        first = ("none" if r["first_pose_ms"] is None else
                                 f"{r['first_pose_ms']:.0f} ms")
                        line += (f"; client: {r['poses']} pose messages ({r['pose_rate']:.1f}/s, "
                                 f"{r['ids_per_pose']:.1f} of {r['bodies']} bodies each, first "
                                 f"after {first} with {r['first_pose_ids']}), "
                                 f"{r['joint_states']} joint_states, {r['status']} status "
                                 f"in {r['subscribed']:.2f} s")
                    print(line, flush=True)
    except BenchError as e:
        sys.exit(f"viewer_sim_rate.py: {e}")
    load1 = os.getloadavg()
    print(f"\nload average at the end {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f}; "
          f"{time.monotonic() - t0:.0f} s in all; {args.repeats} rounds of {args.seconds:g} s "
          f"runs (`partsim serve --fast`, 500 Hz physics)\n")
    print("| scene | steps/s without viewer, median (min-max) | steps/s with viewer + client, "
          "median (min-max) | with / without, median of rounds (min-max) | pose messages/s "
          "to the client (median) | bodies per pose message |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, _, _ in scenes:
        wo = [r["rate"] for r in results[name]["without"]]
        wi = [r["rate"] for r in results[name]["with"]]
        ratios = [b / a for a, b in zip(wo, wi)]
        pose_rate = statistics.median(r["pose_rate"] for r in results[name]["with"])
        ids = statistics.median(r["ids_per_pose"] for r in results[name]["with"])
        print(f"| {name} | {statistics.median(wo):,.0f} ({min(wo):,.0f}-{max(wo):,.0f}) "
              f"| {statistics.median(wi):,.0f} ({min(wi):,.0f}-{max(wi):,.0f}) "
              f"| {statistics.median(ratios):.3f} ({min(ratios):.3f}-{max(ratios):.3f}) "
              f"| {pose_rate:.1f} | {ids:.1f} |")


if __name__ == "__main__":
    main()
