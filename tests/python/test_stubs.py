"""The hand-checked type stubs name every public class, function and method of the module, and
nothing that is not there (python/partsim/_partsim.pyi, made by scripts/gen_stubs.py)."""

import ast
import inspect
import os

import partsim._partsim as ext
from conftest import REPO

STUB = os.path.join(REPO, "python", "partsim", "_partsim.pyi")


def stub_names():
    """{qualified name} of classes, functions, methods and attributes in the .pyi."""
    with open(STUB) as f:
        tree = ast.parse(f.read())
    names = set()

    def visit(body, prefix):
        for node in body:
            if isinstance(node, ast.ClassDef):
                names.add(prefix + node.name)
                visit(node.body, prefix + node.name + ".")
            elif isinstance(node, ast.FunctionDef):
                names.add(prefix + node.name)
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                names.add(prefix + node.target.id)

    visit(tree.body, "")
    return names


def module_names():
    """{qualified name} of everything public the module defines (own class members only)."""
    names = set()

    def visit_class(cls, prefix):
        names.add(prefix + cls.__name__)
        if issubclass(cls, BaseException):
            return
        for name, attr in cls.__dict__.items():
            if inspect.isfunction(attr):
                continue
            # dunders count when the bindings define them (pybind11 functions)
            if name.startswith("_") and type(attr).__name__ != "instancemethod":
                continue
            if inspect.isclass(attr):
                visit_class(attr, prefix + cls.__name__ + ".")
            else:
                names.add(prefix + cls.__name__ + "." + name)

    for name in dir(ext):
        if name.startswith("_"):
            continue
        obj = getattr(ext, name)
        if inspect.isclass(obj):
            visit_class(obj, "")
        elif callable(obj):
            names.add(name)
    return names


def test_stub_names_everything_in_the_module():
    missing = module_names() - stub_names()
    assert not missing, "not in %s (run scripts/gen_stubs.py): %s" % (STUB, sorted(missing))


def test_stub_names_nothing_that_is_gone():
    # dunder methods in the stub may come from pybind11 (e.g. __int__ of enums)
    extra = {n for n in stub_names() - module_names() if not n.split(".")[-1].startswith("_")}
    assert not extra, "in %s but not in the module: %s" % (STUB, sorted(extra))


def test_package_exports_the_module():
    import partsim
    for name in dir(ext):
        if not name.startswith("_"):
            assert getattr(partsim, name) is getattr(ext, name)


def test_stubs_are_what_gen_stubs_writes():
    """Signatures and docstrings too, not only names: the committed .pyi is exactly what
    scripts/gen_stubs.py makes from the built module (run it to update the file)."""
    import subprocess
    import sys

    from conftest import PYTHON_DIR

    script = os.path.join(REPO, "scripts", "gen_stubs.py")
    out = subprocess.run([sys.executable, script, "--python-dir", PYTHON_DIR, "--check"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, (
        "python/partsim/_partsim.pyi is stale: run /usr/bin/python3 scripts/gen_stubs.py "
        "--python-dir build/python\n" + out.stdout[-3000:] + out.stderr[-3000:])
