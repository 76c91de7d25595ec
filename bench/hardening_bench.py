"""What one client (or one file) can still cost ``partsim serve`` and its viewer: the attacks
of the second hardening round, run against two partsim command lines side by side.

Every scenario starts a fresh ``partsim serve --viewer --token T --port 0 --viewer-port 0
--address 127.0.0.1`` (the default Panda before the built-in cabinet, real time), runs one
attack from this process over loopback, measures what the issue measured, and stops the
server. Each measurement has a ceiling (``--cap`` s of waiting, ``--rss-cap`` MB of memory),
past which the attack is stopped and the row says "> cap". Scenarios:

* ``json``: an unauthenticated viewer client sends ``{"op":"x","a":[{},{},...]}`` of 300,000
  objects (900 KB); 1 s later (the server reads connections in turn: a short message sent
  meanwhile would pass the long one) an authenticated client calls ``/partsim/pause``, and the
  row gives the seconds until its answer.
* ``trajectory``: a rosbridge client publishes a JointTrajectory of 200,000 points (12 MB),
  then, 1 s later, a second client calls ``/rosapi/topics``: seconds until the answer.
* ``plans``: a client asks ``/panda/plan`` four times (RRTstar, 30 s, execute false) and
  disconnects; a second client then asks for a 1 s plan: seconds until its answer.
* ``camera``: a viewer client sends 3,000 ``/partsim/camera`` calls without waiting; a second
  sends one ``/partsim/set_joint_target``: seconds until its answer.
* ``pause``: for 10 s a client alternates ``/partsim/pause`` and ``/partsim/resume`` as fast as
  the server answers; the row gives simulated seconds per wall second (real time: 1).
* ``fragments``: a client subscribes to ``/front_camera/points`` with ``fragment_size`` 1 and
  never reads, for 10 s; the row gives the server's peak resident memory over the first
  measurement (MB) and the /clock messages another client got.
* ``names``: 20 subscribes with topic names of 8 MB, then ``/rosapi/topics``: the peak resident
  memory (MB) over the server's at the start.
* ``slots``: ``--max-clients 32``; 400 handshakes at once on each port: how many got in.
* ``unauth``: ``--max-clients 4``; four sockets connect and never authenticate; 8 s later,
  whether the token holder gets in.
* ``accept``: the server with 64 file descriptors (``prlimit``) and 100 sockets connected to
  the viewer's port: CPU seconds the server used in the next 5 s.

Usage: .venv/bin/python bench/hardening_bench.py --cli OLD_PARTSIM --cli NEW_PARTSIM
       [--only json,plans] [--cap 30] [--rss-cap 3000]
"""

import argparse
import json
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time

import websocket

HOST = "127.0.0.1"
TOKEN = "hardeningbench"
ROSBRIDGE_LINE = re.compile(r"rosbridge on ws://127\.0\.0\.1:(\d+)")
VIEWER_LINE = re.compile(r"viewer: open http://127\.0\.0\.1:(\d+)/")


class Server:
    """One ``partsim serve`` with the viewer, stopped on exit from the ``with``."""

    def __init__(self, cli, extra=(), nofile=None):
        cmd = [cli, "serve", "--viewer", "--token", TOKEN, "--port", "0", "--viewer-port", "0",
               "--address", HOST, *extra]
        if nofile:
            cmd = ["prlimit", f"--nofile={nofile}:{nofile}", *cmd]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                     text=True)
        self.port = self.viewer_port = None
        deadline = time.time() + 60
        while time.time() < deadline and (self.port is None or self.viewer_port is None):
            line = self.proc.stdout.readline()
            if not line:
                break
            if m := ROSBRIDGE_LINE.search(line):
                self.port = int(m.group(1))
            if m := VIEWER_LINE.search(line):
                self.viewer_port = int(m.group(1))
        if self.port is None or self.viewer_port is None:
            self.proc.kill()
            raise RuntimeError(f"{cli} serve did not print its ports")
        threading.Thread(target=self.proc.stdout.read, daemon=True).start()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.proc.send_signal(signal.SIGTERM)
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()

    def status(self, key):
        """A /proc/PID/status value in MB (VmRSS, VmHWM)."""
        with open(f"/proc/{self.proc.pid}/status") as f:
            for line in f:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) / 1024.0
        return 0.0

    def cpu_seconds(self):
        with open(f"/proc/{self.proc.pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def client(self, viewer=False, auth=True, timeout=10):
        port = self.viewer_port if viewer else self.port
        ws = websocket.create_connection(f"ws://{HOST}:{port}/", timeout=timeout,
                                         origin=f"http://{HOST}:{port}")
        if auth:
            ws.send(json.dumps({"op": "auth", "mac": TOKEN}))
            wait_for(ws, lambda m: m.get("op") == "status", 10)
        return ws


def wait_for(ws, match, timeout):
    """The first message that `match`es within `timeout` s; None when none came."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        ws.settimeout(max(0.01, deadline - time.time()))
        try:
            text = ws.recv()
        except (websocket.WebSocketTimeoutException, socket.timeout):
            return None
        except (websocket.WebSocketException, OSError):
            return None
        try:
            m = json.loads(text)
        except (ValueError, TypeError):
            continue
        if match(m):
            return m
    return None


def call(ws, service, args, call_id, timeout):
    """Seconds until `service` answers (None past `timeout`)."""
    t0 = time.time()
    ws.send(json.dumps({"op": "call_service", "service": service, "args": args, "id": call_id}))
    m = wait_for(ws, lambda m: m.get("op") == "service_response" and m.get("id") == call_id,
                 timeout)
    return None if m is None else time.time() - t0


def seconds(v, cap):
    return f"> {cap:g} s" if v is None else f"{v:.2f} s"


# ---- scenarios: each returns the row's text ----

def json_flood(cli, a):
    with Server(cli) as s:
        other = s.client(viewer=True)
        bad = s.client(viewer=True, auth=False)
        bad.send('{"op":"x","a":[' + ",".join(["{}"] * 300000) + "]}")
        time.sleep(1)  # until the server has read it all (it reads connections in turn)
        return seconds(call(other, "/partsim/pause", {}, "p", a.cap), a.cap)


def trajectory(cli, a):
    with Server(cli) as s:
        sender, other = s.client(), s.client()
        points = [{"positions": [0] * 9, "time_from_start": {"secs": k}}
                  for k in range(1, 200001)]
        sender.send(json.dumps({"op": "publish",
                                "topic": "/panda/joint_trajectory_controller/command",
                                "msg": {"joint_names": [], "points": points}},
                               separators=(",", ":")))
        time.sleep(1)
        return seconds(call(other, "/rosapi/topics", {}, "t", a.cap), a.cap)


def plans(cli, a):
    with Server(cli) as s:
        home = [0.0, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8, 0.04, 0.04]
        goal = [0.5, -0.3, 0.2, -1.8, 0.1, 1.7, 0.9, 0.04, 0.04]
        greedy = s.client()
        for k in range(4):
            greedy.send(json.dumps({"op": "call_service", "service": "/panda/plan", "id": f"g{k}",
                                    "args": {"joint_goal": goal, "algorithm": "RRTstar",
                                             "time_limit": 30, "execute": False}}))
        time.sleep(0.5)
        greedy.close()
        other = s.client()
        return seconds(call(other, "/panda/plan", {"joint_goal": home, "time_limit": 1,
                                                   "execute": False}, "o", a.cap), a.cap)


def camera(cli, a):
    with Server(cli) as s:
        flood, other = s.client(viewer=True), s.client(viewer=True)
        for k in range(3000):
            flood.send(json.dumps({"op": "call_service", "service": "/partsim/camera",
                                   "id": f"c{k}", "args": {"name": "front_camera"}}))
        return seconds(call(other, "/partsim/set_joint_target",
                            {"articulation": 0, "joint": "panda_joint1", "position": 0.1}, "j",
                            a.cap), a.cap)


def pause(cli, a):
    with Server(cli) as s:
        ws = s.client()
        t0 = time.time()
        s0 = call_stats(ws)
        k = 0
        while time.time() - t0 < 10:
            service = "/partsim/pause" if k % 2 == 0 else "/partsim/resume"
            call(ws, service, {}, f"x{k}", 10)
            k += 1
        call(ws, "/partsim/resume", {}, "r", 10)
        s1 = call_stats(ws)
        wall = time.time() - t0
        sim = (s1["clock_steps"] - s0["clock_steps"]) * s1["timestep"]
        return f"{sim / wall:.2f} ({k} calls)"


def call_stats(ws):
    ws.send(json.dumps({"op": "call_service", "service": "/partsim/stats", "id": "s"}))
    m = wait_for(ws, lambda m: m.get("op") == "service_response" and m.get("id") == "s", 10)
    return m["values"]


def fragments(cli, a):
    with Server(cli) as s:
        base = s.status("VmRSS")
        other = s.client()
        other.send(json.dumps({"op": "subscribe", "topic": "/clock"}))
        hog = s.client()
        hog.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        hog.send(json.dumps({"op": "subscribe", "topic": "/front_camera/points",
                             "fragment_size": 1}))
        clocks = 0
        t0 = time.time()
        while time.time() - t0 < 10 and s.status("VmRSS") - base < a.rss_cap:
            if wait_for(other, lambda m: m.get("topic") == "/clock", 0.2):
                clocks += 1
        peak = s.status("VmHWM") - base
        over = s.status("VmRSS") - base >= a.rss_cap
        return f"{'> ' if over else ''}{peak:.0f} MB, {clocks} /clock"


def names(cli, a):
    with Server(cli) as s:
        base = s.status("VmRSS")
        ws = s.client()
        for k in range(20):
            ws.send(json.dumps({"op": "subscribe", "topic": "/" + chr(97 + k) * (8 << 20),
                                "type": "std_msgs/String"}))
        call(ws, "/rosapi/topics", {}, "t", a.cap)
        return f"{s.status('VmHWM') - base:.0f} MB"


def slots(cli, a):
    with Server(cli, extra=["--max-clients", "32"]) as s:
        out = []
        for viewer in (False, True):
            got, socks, lock = [], [], threading.Lock()

            def one():
                try:
                    ws = s.client(viewer=viewer, auth=False, timeout=20)
                    with lock:
                        got.append(1)
                        socks.append(ws)
                except Exception:  # refused (503) or timed out
                    pass

            threads = [threading.Thread(target=one) for _ in range(400)]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            out.append(f"{len(got)}/32 {'viewer' if viewer else 'rosbridge'}")
            for ws in socks:
                ws.close()
            time.sleep(1)
        return ", ".join(out)


def unauth(cli, a):
    with Server(cli, extra=["--max-clients", "4"]) as s:
        idle = [s.client(auth=False) for _ in range(4)]
        time.sleep(8)
        try:
            s.client()
            ok = "token holder gets in"
        except Exception:
            ok = "token holder locked out"
        del idle
        return ok


def accept(cli, a):
    with Server(cli, nofile=64) as s:
        socks = []
        for _ in range(100):
            try:
                socks.append(socket.create_connection((HOST, s.viewer_port), timeout=2))
            except OSError:
                break
        time.sleep(1)
        c0 = s.cpu_seconds()
        time.sleep(5)
        used = s.cpu_seconds() - c0
        for k in socks:
            k.close()
        return f"{used:.2f} CPU-s"


SCENARIOS = {"json": json_flood, "trajectory": trajectory, "plans": plans, "camera": camera,
             "pause": pause, "fragments": fragments, "names": names, "slots": slots,
             "unauth": unauth, "accept": accept}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cli", action="append", required=True, help="a partsim command line")
    p.add_argument("--only", default=",".join(SCENARIOS))
    p.add_argument("--cap", type=float, default=30.0, help="seconds waited at most")
    p.add_argument("--rss-cap", type=float, default=3000.0, help="MB a server may grow")
    a = p.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f}; caps {a.cap:g} s, {a.rss_cap:g} MB")
    print("| scenario | " + " | ".join(a.cli) + " |")
    print("|---|" + "---|" * len(a.cli))
    for name in a.only.split(","):
        row = []
        for cli in a.cli:
            try:
                row.append(SCENARIOS[name](cli, a))
            except Exception as e:  # a scenario that fails says why and the others go on
                row.append(f"failed: {e}")
        print(f"| {name} | " + " | ".join(row) + " |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
