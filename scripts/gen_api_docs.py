#!/usr/bin/python3
"""Writes the Markdown API reference of the partsim Python package (docs/api) from the built
extension's docstrings and signatures and from python/partsim/envs.py and vision.py.

One page per subsystem: a class, enum, exception or function goes on the page of the binding
file that registers it (src/python/<file>_py.cc, see PAGES), so new bindings land on the right
page without editing this script; the Python modules partsim.envs and partsim.vision (whose
names may be bindings of an extension submodule) have a page each (MODULE_PAGES). The SAPIEN
adapter (python/partsim/sapien/) is not documented here: see docs/sapien_compatibility.md.

Usage:
    /usr/bin/python3 scripts/gen_api_docs.py [--python-dir build/python] [--out docs/api] [--check]

--check compares with the files in --out instead of writing them (exit 1 when they differ).
"""

import argparse
import importlib
import inspect
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gen_stubs  # noqa: E402  (the overload parsing the stubs use)

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODULE = "partsim._partsim"
BINDINGS = os.path.join(REPO, "src", "python")

# page -> (title, what it holds, binding files whose registrations it lists)
PAGES = [
    ("core", "Core", "Poses, partsim's exceptions and the log level.", ["core_py.cc"]),
    ("physics", "Physics",
     "Scene descriptions, the Scene, builders, the Actor / Articulation / Link / Joint handles, "
     "contacts and warnings.", ["physics_py.cc"]),
    ("assets", "Assets",
     "The URDF loader, mesh files, PartNet-Mobility objects and their quality checks.",
     ["assets_py.cc"]),
    ("render", "Render",
     "Cameras, lights, render backends, point clouds and image writers.", ["render_py.cc"]),
    ("robot", "Robot",
     "Robot models, URDF writing, kinematics and inverse kinematics, trajectories, controllers "
     "and the IMU.", ["robot_py.cc", "control_py.cc"]),
    ("planning", "Planning", "Collision-free motion planning (OMPL).", ["planning_py.cc"]),
    ("tasks", "Tasks",
     "The drawer-pulling and door-opening tasks and their heuristic solvers.", ["tasks_py.cc"]),
    ("viewer", "Viewer",
     "The viewer in a web browser (docs/viewer.md): partsim.Viewer and Scene.create_viewer.",
     ["viewer_py.cc"]),
]
# the package's Python modules, one page each: module, page slug, title, summary
MODULE_PAGES = [
    ("partsim.envs", "envs", "Environments (partsim.envs)",
     "The tasks as Gymnasium environments (gymnasium.Env, gymnasium.vector.VectorEnv), registered for gymnasium.make."),
    ("partsim.vision", "vision", "Vision (partsim.vision)",
     "COCO masks and RLE, and the evaluators of movable-part detection and motion attributes."),
]

# a registration in a binding file: py::class_<...>(m, "Name" / py::enum_ / py::exception /
# m.def("name"
REGISTRATION = re.compile(
    r'(?:py::(?:class_|enum_|exception)<[^;{]*?>\s*(?:\w+\s*)?\(\s*m\s*,\s*|\bm\.def\(\s*)'
    r'"(\w+)"', re.S)
OBJECT_REPR = re.compile(r"<%s\.(\w+) object at 0x[0-9a-f]+>" % re.escape(MODULE))
ENUM_REPR = re.compile(r"<(\w+\.\w+): -?\d+>")
SIGNATURE = re.compile(r"^(\w+)\((.*)\)(?: -> (.+))?$")


def registrations():
    """{name: (file, position)} of the module-level names each binding file registers."""
    out = {}
    for name in sorted(os.listdir(BINDINGS)):
        if not name.endswith(".cc"):
            continue
        with open(os.path.join(BINDINGS, name)) as f:
            text = f.read()
        for m in REGISTRATION.finditer(text):
            out.setdefault(m.group(1), (name, m.start()))
    return out


def mention(name):
    """(file, position) of the first string literal "name" in a binding file, for names
    registered through a helper (e.g. the solvers in tasks_py.cc)."""
    for file in sorted(os.listdir(BINDINGS)):
        if file.endswith(".cc"):
            with open(os.path.join(BINDINGS, file)) as f:
                pos = f.read().find('"%s"' % name)
            if pos >= 0:
                return file, pos
    return None, 0


def clean(text):
    """Signature text without the module prefix and memory addresses."""
    text = OBJECT_REPR.sub(r"\1()", text)
    text = ENUM_REPR.sub(r"\1", text)
    return text.replace(MODULE + ".", "")


def split_doc(doc):
    """[(signature or None, text)] of a pybind11 docstring, one per overload."""
    lines = (doc or "").splitlines()
    if len(lines) > 1 and lines[1].strip() == "Overloaded function.":
        return gen_stubs.split_overloads(lines[2:])
    if lines and SIGNATURE.match(lines[0].strip()):
        return [(lines[0].strip(), "\n".join(lines[1:]).strip())]
    return [(None, inspect.cleandoc(doc or ""))]


def strip_self(sig):
    """'f(self: X, a: int) -> T' -> ('a: int', 'T')."""
    m = SIGNATURE.match(sig)
    args, ret = m.group(2), m.group(3)
    args = re.sub(r"^self(: [\w.]+)?(, )?", "", args)
    return clean(args), clean(ret) if ret else None


def md_text(text):
    """Docstring text as Markdown: reST literal blocks become fenced code."""
    out, lines, i = [], text.splitlines(), 0
    while i < len(lines):
        line = lines[i]
        if line.rstrip().endswith("::") and i + 1 < len(lines) and not lines[i + 1].strip():
            out.append(line.rstrip()[:-1])
            j = i + 2
            block = []
            while j < len(lines) and (not lines[j].strip() or lines[j].startswith(" ")):
                block.append(lines[j])
                j += 1
            while block and not block[-1].strip():
                block.pop()
            out += ["", "```python"] + [inspect.cleandoc("\n".join(block))] + ["```", ""]
            i = j
            continue
        out.append(line)
        i += 1
    return "\n".join(out).strip()


class Page:
    def __init__(self, slug, title, summary):
        self.slug, self.title, self.summary = slug, title, summary
        self.lines = []
        self.names = []  # (qualified name, anchor) for the index

    def anchor(self, qualname):
        self.names.append(qualname)
        return '<a id="%s"></a>' % qualname

    def add(self, *lines):
        self.lines.extend(lines)

    def doc(self, text):
        if text:
            self.add(md_text(text), "")

    def text(self):
        head = ["# %s" % self.title, "", self.summary, "",
                "Generated by `scripts/gen_api_docs.py` from the docstrings; do not edit by "
                "hand. Index: [README.md](README.md).", ""]
        return "\n".join(head + self.lines).rstrip() + "\n"


def is_enum(cls):
    return hasattr(cls, "__members__") and hasattr(cls, "__entries")


def own_members(cls, sapien):
    """[(name, attribute)] of a class's own public members, in name order."""
    out = []
    for name, attr in sorted(cls.__dict__.items()):
        if name.startswith("_") and name != "__init__":
            continue
        if is_enum(cls) and (name in cls.__members__ or name in ("name", "value", "__init__")):
            continue
        out.append((name, attr))
    return out


def property_type(prop):
    """The getter's return type from its pybind11 signature '(self: X) -> T'."""
    first = (getattr(prop.fget, "__doc__", None) or "").strip().split("\n")[0]
    m = re.match(r"^\w*\(.*\) -> (.+)$", first)
    return clean(m.group(1)) if m else None


def write_function(page, qualname, func, level="###", display=None):
    """A pybind11 function or method: one heading per overload."""
    display = display or qualname.rsplit(".", 1)[-1]
    page.add(page.anchor(qualname))
    for sig, text in split_doc(func.__doc__):
        if sig:
            args, ret = strip_self(sig)
            page.add("%s `%s(%s)%s`" % (level, display, args, " -> " + ret if ret and
                                       ret != "None" else ""), "")
        else:
            page.add("%s `%s`" % (level, display), "")
        page.doc(text)


def write_python_function(page, qualname, func, level="###", display=None):
    display = display or qualname.rsplit(".", 1)[-1]
    try:
        sig = str(inspect.signature(func))
    except (TypeError, ValueError):
        sig = "(...)"
    sig = re.sub(r"^\(self(, )?", "(", sig)
    sig = re.sub(r"([:>] )'([^']*)'", r"\1\2", sig)  # postponed annotations are strings
    sig = re.sub(r"<class '([\w.]+)'>", r"\1", sig)
    page.add(page.anchor(qualname), "%s `%s%s`" % (level, display, sig), "")
    page.doc(inspect.cleandoc(func.__doc__ or ""))  # its own: no docstring inherited


def write_class(page, cls, qualname, sapien, python=False):
    kind = "exception" if issubclass(cls, BaseException) else "enum" if is_enum(cls) else "class"
    bases = [b.__name__ for b in cls.__bases__
             if b.__module__ in (MODULE, "builtins") and b is not object and
             b.__name__ != "pybind11_object"]
    page.add(page.anchor(qualname), "## %s `%s`%s" % (
        kind, qualname, " (%s)" % ", ".join(bases) if bases else ""), "")
    doc = cls.__doc__ or ""
    if is_enum(cls):
        doc = doc.split("\n\nMembers:")[0]
    page.doc(inspect.cleandoc(doc) if python else doc)
    if kind == "exception":
        return
    if is_enum(cls):
        entries = cls.__entries.items()
        if any(value_doc for _, (_, value_doc) in entries):
            page.add("| Value | Meaning |", "|---|---|")
            for name, (value, value_doc) in entries:
                page.add("| `%s.%s` (%d) | %s |" % (cls.__name__, name, int(value),
                                                   (value_doc or "").replace("|", "\\|")))
        else:
            page.add("Values: " + ", ".join("`%s.%s` (%d)" % (cls.__name__, name, int(value))
                                            for name, (value, _) in entries) + ".")
        page.add("")
    for name, attr in own_members(cls, sapien):
        member = qualname + "." + name
        if inspect.isclass(attr):
            write_class(page, attr, member, sapien, python)
        elif isinstance(attr, property):
            access = "read/write" if attr.fset is not None else "read-only"
            typ = None if python else property_type(attr)
            page.add(page.anchor(member), "### property `%s`%s (%s)" % (
                name, ": `%s`" % typ if typ else "", access), "")
            page.doc(inspect.cleandoc(attr.__doc__ or "") if python else attr.__doc__)
        elif name == "__init__":
            if python:
                write_python_function(page, member, attr, display=cls.__name__)
            elif "__init__(self: " in (attr.__doc__ or ""):
                write_function(page, member, attr, display=cls.__name__)
        elif isinstance(attr, (staticmethod, classmethod)):
            func = attr.__func__
            if python:
                write_python_function(page, member, func, display="static " + name)
            else:
                write_function(page, member, func, display="static " + name)
        elif callable(attr):
            (write_python_function if python else write_function)(page, member, attr)


def generate(python_dir):
    """{file name: text} of the reference."""
    sys.path.insert(0, python_dir)
    ext = importlib.import_module(MODULE)
    sapien = None  # the SAPIEN adapter (partsim.sapien) is documented in sapien_compatibility.md
    package = importlib.import_module("partsim")
    where = registrations()

    pages = [Page(slug, title, summary) for slug, title, summary, _ in PAGES]
    page_of_file = {f: p for p, (_, _, _, files) in zip(pages, PAGES) for f in files}
    other = Page("other", "Other", "Names of the extension registered outside the binding "
                 "files' usual patterns.")
    entries = []  # (page, file position, name, object)
    for name in dir(ext):
        if name.startswith("_"):
            continue
        obj = getattr(ext, name)
        file, pos = where.get(name) or mention(name)
        entries.append((page_of_file.get(file, other), PAGES_ORDER(file), pos, name, obj))
    entries.sort(key=lambda e: (e[1], e[2], e[3]))
    for page, _, _, name, obj in entries:
        if inspect.isclass(obj):
            write_class(page, obj, name, sapien)
        else:
            write_function(page, name, obj, level="##", display=name)

    module_pages = []
    for module_name, slug, title, summary in MODULE_PAGES:
        module = importlib.import_module(module_name)
        page = Page(slug, title, summary)
        page.doc(inspect.getdoc(module))
        for name in module.__all__:
            obj = getattr(module, name)
            # pure Python, or a binding re-exported from an extension submodule
            python = not isinstance(obj, gen_stubs.PYBIND_FUNC) and not (
                inspect.isclass(obj) and type(obj).__name__ == "pybind11_type")
            if inspect.isclass(obj):
                write_class(page, obj, slug + "." + name, sapien, python=python)
            elif python:
                write_python_function(page, slug + "." + name, obj, level="##", display=name)
            else:
                write_function(page, slug + "." + name, obj, level="##", display=name)
        module_pages.append(page)

    all_pages = pages + ([other] if other.lines else []) + module_pages
    files = {p.slug + ".md": p.text() for p in all_pages}

    index = ["# partsim Python API reference", "",
             inspect.cleandoc(package.__doc__ or ""), "",
             "Generated by `scripts/gen_api_docs.py` from the bindings' docstrings "
             "(src/python/*.cc) and python/partsim/envs.py and vision.py; do not edit by hand. "
             "Regenerate "
             "after changing a docstring:", "",
             "```sh",
             "/usr/bin/python3 scripts/gen_api_docs.py --python-dir build/python --out docs/api",
             "```", "",
             "`tests/python/test_docstrings.py` fails when a public member has no docstring or "
             "when these pages are out of date. Units are SI (m, rad, s, kg, N, N m) unless a "
             "docstring says otherwise; poses are named by frames (X_WB: frame B in the world "
             "W). SAPIEN's names, which partsim also exports, are described in "
             "[../sapien_compatibility.md](../sapien_compatibility.md).", "",
             "| Page | What it holds | Names |", "|---|---|---|"]
    for p in all_pages:
        index.append("| [%s](%s.md) | %s | %d |" % (p.title, p.slug, p.summary, len(p.names)))
    index += ["", "## Index", ""]
    for p in all_pages:
        tops = [n for n in p.names if "." not in n or (
            n.startswith(tuple(slug + "." for _, slug, _, _ in MODULE_PAGES)) and
            n.count(".") == 1)]
        index.append("- **[%s](%s.md)**: %s" % (p.title, p.slug, ", ".join(
            "[`%s`](%s.md#%s)" % (n, p.slug, n) for n in tops)))
    files["README.md"] = "\n".join(index).rstrip() + "\n"
    return files


def PAGES_ORDER(file):
    for i, (_, _, _, files) in enumerate(PAGES):
        if file in files:
            return i * 10 + files.index(file)
    return 1000


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--python-dir", default=os.environ.get(
        "PARTSIM_PYTHON_DIR", os.path.join(REPO, "build", "python")))
    parser.add_argument("--out", default=os.path.join(REPO, "docs", "api"))
    parser.add_argument("--check", action="store_true")
    opts = parser.parse_args()
    files = generate(os.path.abspath(opts.python_dir))
    if opts.check:
        present = set(os.listdir(opts.out)) if os.path.isdir(opts.out) else set()
        stale = sorted(n for n in present | set(files) if n.endswith(".md") and (
            n not in files or n not in present or
            open(os.path.join(opts.out, n)).read() != files[n]))
        if stale:
            print("%s is out of date (%s); run scripts/gen_api_docs.py --python-dir %s --out %s"
                  % (opts.out, ", ".join(stale), opts.python_dir, opts.out))
            return 1
        return 0
    os.makedirs(opts.out, exist_ok=True)
    for name in os.listdir(opts.out):
        if name.endswith(".md") and name not in files:
            os.remove(os.path.join(opts.out, name))
    for name, text in sorted(files.items()):
        with open(os.path.join(opts.out, name), "w") as f:
            f.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
