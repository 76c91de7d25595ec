"""What a worker runs for one unit: the partsim command line with the unit's arguments.

This module needs the standard library only and is sent to the workers by value (the driver
registers it with Ray's pickler), so a worker node needs the partsim command line but not this
Python package on its path.
"""

import ctypes
import io
import os
import shutil
import signal
import socket
import subprocess
import tarfile
import tempfile
import time

# the placeholder in a unit's arguments that becomes the worker's temporary folder
UNIT_TMP = "{unit_tmp}"


def _die_with_parent() -> None:
    """In the child, before exec: the kernel kills it when the worker that started it dies (a
    worker killed by Ray or by SIGKILL leaves no orphan writing into the outputs)."""
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except OSError:
        pass


def _tar_tree(folder: str) -> bytes:
    """The files under ``folder`` as an uncompressed tar, in sorted order, with neutral owners
    and times (what comes back is the files' bytes and modes, nothing of the worker)."""
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w") as tar:
        for root, dirs, files in os.walk(folder):
            dirs.sort()
            for name in sorted(files):
                path = os.path.join(root, name)
                info = tar.gettarinfo(path, arcname=os.path.relpath(path, folder))
                info.uid = info.gid = 0
                info.uname = info.gname = ""
                info.mtime = 0
                with open(path, "rb") as f:
                    tar.addfile(info, f)
    return buf.getvalue()


def find_cli(preferred: str) -> str:
    """The driver's command line when this node has it at the same path, else ``$PARTSIM_CLI``,
    else ``partsim`` on PATH; RuntimeError when none is there."""
    for c in (preferred, os.environ.get("PARTSIM_CLI", ""), shutil.which("partsim") or ""):
        if c and os.path.isfile(c) and os.access(c, os.X_OK):
            return c
    raise RuntimeError(f"no partsim command line on {socket.gethostname()} (not at {preferred}, "
                       "no PARTSIM_CLI, none on PATH): install partsim on every node")


def run_unit(spec: dict) -> dict:
    """Runs one unit: ``spec["cli"]`` with ``spec["args"]`` (``{unit_tmp}`` replaced by a fresh
    temporary folder) and returns its exit code, the ends of its output, where it ran, and the
    file (``collect`` "file:REL") or folder (``collect`` "tree:REL", as a tar) the driver takes
    back from the temporary folder."""
    start = time.monotonic()
    cli = find_cli(spec["cli"])
    with tempfile.TemporaryDirectory(prefix="partsim-unit-") as tmp:
        args = [a.replace(UNIT_TMP, tmp) for a in spec["args"]]
        env = dict(os.environ, **spec.get("env", {}))
        # the driver's working folder when this node has it (a shared file system), so that
        # relative paths mean what they mean there
        cwd = spec.get("cwd") if os.path.isdir(spec.get("cwd") or "") else tmp
        p = subprocess.run([cli] + args, capture_output=True, text=True, env=env, cwd=cwd,
                           preexec_fn=_die_with_parent, check=False)
        result = {"key": spec["key"], "rc": p.returncode, "stdout": p.stdout[-20000:],
                  "stderr": p.stderr[-4000:], "host": socket.gethostname(), "pid": os.getpid(),
                  "payload": None}
        collect = spec.get("collect")
        if collect and p.returncode in spec.get("ok", (0,)):
            kind, rel = collect.split(":", 1)
            path = os.path.join(tmp, rel)
            if kind == "tree":
                result["payload"] = _tar_tree(path) if os.path.isdir(path) else b""
            elif os.path.isfile(path):
                with open(path, "rb") as f:
                    result["payload"] = f.read()
            else:
                result["rc"] = -1
                result["stderr"] += f"\nthe unit wrote no {rel}"
    result["seconds"] = time.monotonic() - start
    return result
