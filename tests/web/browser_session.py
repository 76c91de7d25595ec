"""Shared by the Python side of the browser tests (tests/python/test_viewer_browser.py,
tests/python/test_viewer_gallery_browser.py): a process's output lines read on a thread, stopping
a process, and running one of the Node scripts of tests/web that drive headless Chromium (they
print one JSON line last; exit code 2 with {"skip": reason} when Chromium cannot start).
"""

import json
import os
import queue
import shutil
import subprocess
import threading
import time

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
WEB_ROOT = os.path.join(REPO, "build", "web")


class Lines:
    """Reads a process's standard output lines on a thread, JSON-decoded where possible."""

    def __init__(self, proc):
        self.q = queue.Queue()
        self.all = []
        self.thread = threading.Thread(target=self._read, args=(proc,), daemon=True)
        self.thread.start()

    def _read(self, proc):
        for line in proc.stdout:
            try:
                obj = json.loads(line)
            except ValueError:
                obj = {"text": line.rstrip("\n")}
            if not isinstance(obj, dict):
                obj = {"text": line.rstrip("\n")}
            self.all.append(obj)
            self.q.put(obj)
        self.q.put(None)

    def next(self, timeout):
        """The next line (None at the end of the output); raises queue.Empty after `timeout` s."""
        return self.q.get(timeout=timeout)

    def wait_for(self, pattern, seconds):
        """The first match of the compiled regex `pattern` in a text line of the next `seconds`;
        None when the output ends or the time runs out first."""
        deadline = time.time() + seconds
        while time.time() < deadline:
            try:
                line = self.next(timeout=max(deadline - time.time(), 0.1))
            except queue.Empty:
                return None
            if line is None:
                return None
            m = pattern.search(line.get("text", ""))
            if m:
                return m
        return None


def stop(proc):
    """Terminates a process started by a test (SIGTERM, then SIGKILL after 10 s) and waits."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=10)


def require_page():
    """Fails (not skips) when Node or the built page is missing: an incomplete set-up."""
    if not shutil.which("node"):
        pytest.fail("node is not installed (scripts/setup.sh installs it)")
    if not os.path.isfile(os.path.join(WEB_ROOT, "index.html")):
        pytest.fail("build/web is missing: run bash scripts/build_web.sh")


def run_page_check(script, config, timeout):
    """Runs `node script CONFIG_JSON`; returns (exit code, the JSON of its last line). Skips the
    test when the script says Chromium cannot start; fails when it printed no JSON."""
    check = subprocess.run(["node", script, json.dumps(config)], capture_output=True, text=True,
                           timeout=timeout, cwd=REPO)
    try:
        page = json.loads(check.stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        pytest.fail(f"{os.path.basename(script)} printed no JSON (rc {check.returncode}): "
                    f"{check.stdout[-2000:]} {check.stderr[-3000:]}")
    if check.returncode == 2 and page.get("skip"):
        pytest.skip(f"Chromium cannot start: {page['skip']}")
    return check.returncode, page
