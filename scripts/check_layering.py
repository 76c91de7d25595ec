#!/usr/bin/env python3
"""Checks the include direction of partsim's layers.

    core <- physics <- {assets, render} <- {robot, vision} <- planning <- {tasks, server}
         <- viewer <- {tools, python}

A source or header of a layer (src/<layer>/..., include/partsim/<layer>/...) may include headers
of its own layer and of the layers below it, never of a layer above it or beside it (assets and
render do not know each other, nor do robot and vision, nor tasks and server). A layer's internal
headers (src/<layer>/*.h) are its own: another layer may include them only where EXCEPTIONS says
why; core's internal headers (file reading, JSON parsing, number text, progress lines, the worker
pool) are partsim's private utilities, shared by every layer but not part of the public API.
Prints each offending include (file:line) and exits 1; prints the layer graph found and exits 0
otherwise. Usage: /usr/bin/python3 scripts/check_layering.py [--graph]
"""

import os
import re
import sys

RANK = {
    "core": 0,
    "physics": 1,
    "assets": 2,
    "render": 2,
    "robot": 3,
    "vision": 3,
    "planning": 4,
    "tasks": 5,
    "server": 5,
    "viewer": 6,
    "tools": 7,
    "python": 7,
}

# Internal headers of a lower layer used by a higher one, and why. The viewer speaks the
# rosbridge protocol of the server layer: it shares its JSON codecs (status and service
# responses, base64, step counts) and the checks of every network service (Origin, token).
EXCEPTIONS = {
    ("src/viewer/viewer.cc", "server/ros_json.h"),
    ("src/viewer/viewer.cc", "server/web_security.h"),
}

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def layer_of_file(path):
    parts = path.split("/")
    if parts[0] == "src" and len(parts) > 2:
        return parts[1]
    if parts[:2] == ["include", "partsim"] and len(parts) > 3:
        return parts[2]
    return None


def layer_of_include(inc):
    parts = inc.split("/")
    if parts[0] == "partsim" and len(parts) > 2:
        return parts[1], False  # a public header
    if parts[0] in RANK and len(parts) > 1:
        return parts[0], True  # an internal header: src/<layer>/...
    return None, False


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    os.chdir(root)
    problems, graph = [], {}
    for top in ("src", "include/partsim"):
        for dirpath, _, files in os.walk(top):
            for name in sorted(files):
                if not name.endswith((".cc", ".h")):
                    continue
                path = os.path.join(dirpath, name)
                layer = layer_of_file(path)
                if layer not in RANK:
                    continue
                with open(path, encoding="utf-8", errors="replace") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        target, internal = layer_of_include(m.group(1))
                        if target is None or target == layer or target not in RANK:
                            continue
                        graph.setdefault(layer, set()).add(target)
                        where = f"{path}:{number}: includes \"{m.group(1)}\""
                        if RANK[target] >= RANK[layer]:
                            side = "above" if RANK[target] > RANK[layer] else "beside"
                            problems.append(f"{where}, a header of {target}, {side} {layer}")
                        elif internal and target != "core" and (path, m.group(1)) not in EXCEPTIONS:
                            problems.append(
                                f"{where}, an internal header of {target} (use its public "
                                f"headers in include/partsim/{target}/)")
    if problems:
        print("layering: %d include(s) against the direction of the layers" % len(problems))
        for p in problems:
            print("  " + p)
        return 1
    print("layering: every include goes down the layers")
    for layer in sorted(graph, key=lambda k: (RANK[k], k)):
        print("  %-8s -> %s" % (layer, ", ".join(sorted(graph[layer], key=lambda k: (RANK[k], k)))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
