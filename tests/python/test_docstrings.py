"""Every public member of the partsim package has a docstring of its own, beyond the signature
pybind11 writes; the Markdown API reference made from them (docs/api, scripts/gen_api_docs.py) is
up to date.

What is walked: the public names of `partsim`, `partsim.envs` and `partsim.vision`, and for each
class its own public members (methods, static methods, properties, nested classes), recursively.
A pybind11 overloaded function needs text under every overload.

What is not required, and why:
- dunder and other `_`-prefixed names (pybind11 writes `__init__`, `__repr__`, ... itself);
- enum values and pybind11's enum helpers `name` and `value` (the enum class documents them);
- plain data attributes (class constants such as `metadata`, which cannot carry a docstring);
- the SAPIEN adapter (partsim.sapien, partsim.core): SAPIEN's names, documented by SAPIEN and by
  docs/sapien_compatibility.md;
- names re-exported from other packages (e.g. gymnasium's spaces in partsim.envs).
"""

import inspect
import os
import re
import subprocess
import sys

import partsim
import partsim._partsim as ext
import partsim.envs as envs
import partsim.vision as vision
from conftest import PYTHON_DIR, REPO

OWN_MODULES = ("partsim._partsim", "partsim.envs", "partsim.vision", "partsim")
ENUM_HELPERS = ("name", "value")

# one pybind11 signature line: "name(arg: type = default) -> type"
SIGNATURE = re.compile(r"^\s*\w+\(.*\)(\s*->\s*.+)?\s*$")
# the headers of an overloaded pybind11 function's docstring
OVERLOAD_HEADER = re.compile(r"^\s*\w+\(\*args, \*\*kwargs\)\s*$|^\s*Overloaded function\.\s*$")
OVERLOAD_ITEM = re.compile(r"^(\d+)\. (\w+\(.*)$")


def own_texts(doc):
    """The texts a docstring holds besides pybind11's signatures: one per overload (a text may be
    empty), or one for a plain function, class or property."""
    if not doc:
        return [""]
    lines = doc.splitlines()
    # enums: pybind11 appends "Members:" and the value names to the class docstring
    if "Members:" in (l.strip() for l in lines):
        lines = lines[:[l.strip() for l in lines].index("Members:")]
    if len(lines) > 1 and OVERLOAD_HEADER.match(lines[0]) and OVERLOAD_HEADER.match(lines[1]):
        texts, cur = [], None
        for line in lines[2:]:
            if OVERLOAD_ITEM.match(line):
                if cur is not None:
                    texts.append("\n".join(cur).strip())
                cur = []
            elif cur is not None:
                cur.append(line)
        if cur is not None:
            texts.append("\n".join(cur).strip())
        return texts or [""]
    return ["\n".join(l for l in lines if not SIGNATURE.match(l)).strip()]


def is_documented(doc):
    """True when every overload has text of its own that reads as words."""
    return all(re.search(r"[A-Za-z]{3,}", t) for t in own_texts(doc))


def walk_class(cls, qualname, out):
    out.append((qualname, cls.__doc__))
    is_enum = hasattr(cls, "__members__")
    for name, attr in cls.__dict__.items():
        if name.startswith("_") or (is_enum and (name in ENUM_HELPERS or
                                                  name in cls.__members__)):
            continue
        if isinstance(attr, (staticmethod, classmethod)):
            attr = attr.__func__
        if inspect.isclass(attr):
            walk_class(attr, qualname + "." + name, out)
        elif isinstance(attr, property) or callable(attr):
            out.append((qualname + "." + name, attr.__doc__))
        # anything else is data (a class constant): no docstring of its own to check


def public_members():
    """[(qualified name, docstring)] of the package's public API."""
    out = []
    for module, prefix in ((partsim, "partsim."), (envs, "partsim.envs."),
                           (vision, "partsim.vision.")):
        out.append((module.__name__, module.__doc__))
        for name in sorted(dir(module)):
            if name.startswith("_"):
                continue
            obj = getattr(module, name)
            if inspect.ismodule(obj):
                continue  # a submodule: walked on its own
            if getattr(obj, "__module__", None) not in OWN_MODULES and not (
                    inspect.isbuiltin(obj) and module is partsim):
                continue  # imported from elsewhere (numpy, gymnasium)
            if inspect.isclass(obj):
                walk_class(obj, prefix + name, out)
            elif callable(obj):
                out.append((prefix + name, obj.__doc__))
    return out


def test_walk_finds_the_api():
    names = {n for n, _ in public_members()}
    # the walk reaches into classes, properties, static methods, enums and envs
    for expected in ("partsim.Scene", "partsim.Scene.step", "partsim.Camera.get_picture",
                     "partsim.UrdfLoader.fix_root_link", "partsim.Pose.from_transformation_matrix",
                     "partsim.ActorType", "partsim.set_log_level", "partsim.envs.OpenCabinetEnv",
                     "partsim.envs.OpenCabinetEnv.step", "partsim.vision.evaluate_detection",
                     "partsim.vision.DetectionEvaluation.map"):
        assert expected in names, expected
    assert not any(n.startswith(("partsim.core", "partsim.sapien", "partsim.Engine"))
                   for n in names)
    assert len(names) > 600


def test_every_public_member_has_a_docstring():
    missing = [name for name, doc in public_members() if not is_documented(doc)]
    assert not missing, "%d public members have no docstring beyond the signature:\n  %s" % (
        len(missing), "\n  ".join(missing))


def test_signature_only_docstrings_are_caught():
    assert not is_documented(None)
    assert not is_documented("get_id(self: partsim._partsim.Camera) -> int\n")
    assert not is_documented(
        "f(*args, **kwargs)\nOverloaded function.\n\n1. f(self: A, x: int) -> None\n\nInts.\n\n"
        "2. f(self: A, x: str) -> None\n")
    assert not is_documented("Members:\n\n  STATIC\n\n  DYNAMIC")
    assert is_documented("get_id(self: partsim._partsim.Camera) -> int\n\nThe camera's id.\n")
    assert is_documented("How an actor moves.\n\nMembers:\n\n  STATIC")


def test_api_reference_is_up_to_date():
    script = os.path.join(REPO, "scripts", "gen_api_docs.py")
    result = subprocess.run([sys.executable, script, "--python-dir", PYTHON_DIR, "--check"],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
