#!/usr/bin/env python3
"""Checks partsim's layers: include directions, and that each layer defines its own classes.

    core <- physics <- {assets, render} <- {robot, vision} <- planning <- {tasks, server}
         <- viewer <- {tools, python}

A source or header of a layer (src/<layer>/..., include/partsim/<layer>/...) may include headers
of its own layer and of the layers below it, never of a layer above it or beside it (assets and
render do not know each other, nor do robot and vision, nor tasks and server). A layer's internal
headers (src/<layer>/*.h) are its own: another layer may include them only where EXCEPTIONS says
why; core's internal headers (file reading, JSON parsing, number text, progress lines, the worker
pool) are partsim's private utilities, shared by every layer but not part of the public API.

A class (or struct) declared at namespace scope in a layer's public headers
(include/partsim/<layer>/*.h) has its member functions defined in that layer's sources: a
definition `Type Class::Method(`, `Class::Class(`, `Class<T>::Method(` or an explicit
instantiation `template Type Class<X>::Method(` that starts a line of a source of another layer
(src/<other>/..., comments left out) is an offence, since a user who links only the declaring
layer would see the member and fail to link. A layer that adds to another's class does it with
free functions in its own headers (partsim/render/scene_render.h for the Scene's cameras).

Prints each offending include or definition (file:line) and exits 1; prints the layer graph found
and exits 0 otherwise. Usage: /usr/bin/python3 scripts/check_layering.py [--graph]
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

# Internal headers of a lower layer used by a higher one, and why. None today: the viewer, which
# once shared the server's JSON codecs and web checks, now serves through the server's public
# RosbridgeServer (its extension members).
EXCEPTIONS = set()

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
# a class or struct defined at namespace scope (Google style does not indent namespaces)
CLASS = re.compile(
    r"^(?:class|struct)\s+(?:\[\[\w+\]\]\s+)?([A-Za-z_]\w*)\b(?:\s+final)?\s*(?:[:{]|$)")
# a member definition starting a line: an optional return type (or `template`), then
# Class[<...>]::[Nested::]Method( with Method possibly ~Class or operator...
MEMBER = re.compile(
    r"^(?P<prefix>(?:[\w:<>,*&\s]*?[\s*&])?)(?P<name>(?P<cls>[A-Za-z_]\w*)(?:<[^;()]*>)?"
    r"(?:::[A-Za-z_]\w*)*::(?:~?[A-Za-z_]\w*|operator\s*[^\s(]+))\s*\(")
STATEMENT = {"return", "else", "case", "throw", "new", "delete", "co_return", "goto", "using",
             "typedef", "friend"}


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


def strip_comments(text):
    """The text with // and /* */ comments (and string literals) blanked, lines kept."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        elif c == '"' or c == "'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (min(j, n) - i - 1) + (c if j < n else ""))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def public_classes():
    """{class name: set of layers whose public headers define it at namespace scope}."""
    classes = {}
    for layer in RANK:
        folder = os.path.join("include", "partsim", layer)
        if not os.path.isdir(folder):
            continue
        for name in sorted(os.listdir(folder)):
            if not name.endswith(".h"):
                continue
            with open(os.path.join(folder, name), encoding="utf-8", errors="replace") as f:
                for line in strip_comments(f.read()).splitlines():
                    m = CLASS.match(line)
                    if m:
                        classes.setdefault(m.group(1), set()).add(layer)
    return classes


def foreign_members(path, layer, classes):
    """Definitions in `path` (of `layer`) of members of classes other layers declare."""
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = strip_comments(f.read()).splitlines()
    found = []
    for number, line in enumerate(lines, 1):
        m = MEMBER.match(line)
        if not m or m.group("cls") not in classes or layer in classes[m.group("cls")]:
            continue
        words = m.group("prefix").split()
        if words and words[0] in STATEMENT:
            continue
        owners = ", ".join(sorted(classes[m.group("cls")], key=lambda k: (RANK[k], k)))
        found.append(f"{path}:{number}: defines {m.group('name')}, a member "
                     f"of a class that {owners} declares (include/partsim/{owners}/); define it "
                     f"there, or make it a free function of {layer}")
    return found


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    os.chdir(root)
    problems, graph = [], {}
    classes = public_classes()
    members = []
    for top in ("src", "include/partsim"):
        for dirpath, _, files in os.walk(top):
            for name in sorted(files):
                if not name.endswith((".cc", ".h")):
                    continue
                path = os.path.join(dirpath, name)
                layer = layer_of_file(path)
                if layer not in RANK:
                    continue
                if path.startswith("src/"):
                    members += foreign_members(path, layer, classes)
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
    if problems or members:
        if problems:
            print("layering: %d include(s) against the direction of the layers" % len(problems))
            for p in problems:
                print("  " + p)
        if members:
            print("layering: %d member(s) defined outside the layer of their class" % len(members))
            for p in members:
                print("  " + p)
        return 1
    print("layering: every include goes down the layers, and every layer defines its own "
          "classes' members")
    for layer in sorted(graph, key=lambda k: (RANK[k], k)):
        print("  %-8s -> %s" % (layer, ", ".join(sorted(graph[layer], key=lambda k: (RANK[k], k)))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
