"""The Python packaging: the system libraries the wheel needs are named, the command line that
goes with the package is found, and the project's files that describe the wheel agree.

(The wheel itself is built and installed into a new venv by scripts/test.sh through
scripts/build_wheel.sh and scripts/wheel_smoke.sh.)
"""

import os
import re
import shutil
import subprocess
import sys
import tomllib

from conftest import PYTHON_DIR, REPO, partsim

# libraries every Linux system has, the C++ runtime, MuJoCo (the wheel carries it) and Debian's
# ROS 1 libraries (only a command line built with the ROS 1 node links them)
_BASE = re.compile(r"^(ld-linux.*|libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s|libz|"
                   r"libmujoco|libros.*|libactionlib.*|libxmlrpcpp.*|libcpp_common.*)\.so")


def _needed(path):
    out = subprocess.run(["readelf", "-d", path], capture_output=True, text=True, check=True)
    return re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out.stdout)


def test_every_system_library_the_binaries_link_has_its_debian_package_named():
    module = partsim._partsim.__file__
    cli = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(PYTHON_DIR))), "partsim")
    binaries = [module] + ([cli] if os.path.isfile(cli) else [])
    unnamed = sorted({lib for b in binaries for lib in _needed(b)
                      if not _BASE.match(lib) and lib not in partsim.SYSTEM_PACKAGES})
    assert not unnamed, (f"libraries linked but missing from partsim.SYSTEM_PACKAGES "
                         f"(python/partsim/__init__.py) and docs/install.md: {unnamed}")


def test_the_install_docs_list_every_system_package():
    with open(os.path.join(REPO, "docs", "install.md"), encoding="utf-8") as f:
        text = f.read()
    missing = [p for p in set(partsim.SYSTEM_PACKAGES.values()) if p not in text]
    assert not missing, f"docs/install.md does not list {missing}"


def test_a_missing_system_library_is_named_with_its_package():
    e = ImportError("libembree3.so.3: cannot open shared object file: No such file or directory")
    text = partsim._missing_library_message(e)
    assert "libembree3.so.3" in text and "libembree3-3" in text and "apt-get install" in text
    # other import errors pass through unchanged
    assert partsim._missing_library_message(ImportError("no module x")) == "no module x"


def test_a_real_failed_load_names_the_missing_library(tmp_path):
    """A copy of the package whose compiled module links a library that is not there: `import
    partsim` fails with partsim's message, which names the library and the apt-get line."""
    shutil.copytree(os.path.join(PYTHON_DIR, "partsim"), tmp_path / "partsim",
                    ignore=shutil.ignore_patterns("_partsim*.so", "__pycache__"))
    (tmp_path / "stub.c").write_text("int partsim_stub(void) { return 0; }\n")
    lib = tmp_path / "libs"
    lib.mkdir()
    subprocess.run(["gcc", "-shared", "-fPIC", "-Wl,-soname,libpartsim_absent.so.1", "-o",
                    str(lib / "libpartsim_absent.so.1"), str(tmp_path / "stub.c")], check=True)
    module = tmp_path / "partsim" / os.path.basename(partsim._partsim.__file__)
    subprocess.run(["gcc", "-shared", "-fPIC", "-o", str(module), str(tmp_path / "stub.c"),
                    "-Wl,--no-as-needed", str(lib / "libpartsim_absent.so.1")], check=True)
    shutil.rmtree(lib)  # the library the module needs is gone
    p = subprocess.run([sys.executable, "-c", "import partsim"], capture_output=True, text=True,
                       cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(tmp_path)})
    assert p.returncode != 0
    assert "partsim's compiled module cannot load" in p.stderr, p.stderr
    assert "libpartsim_absent.so.1" in p.stderr and "apt-get install" in p.stderr, p.stderr


def test_numpy_2_is_refused_by_name_instead_of_crashing(tmp_path):
    """With numpy 2 the module's arrays would crash the process (pybind11 2.10): import partsim
    refuses with a message that names the version and the fix."""
    fake = tmp_path / "numpy"
    fake.mkdir()
    (fake / "__init__.py").write_text("__version__ = '2.4.6'\n")
    p = subprocess.run([sys.executable, "-c", "import partsim"], capture_output=True, text=True,
                       cwd=tmp_path, env={**os.environ, "PYTHONPATH": f"{tmp_path}:{PYTHON_DIR}"})
    assert p.returncode != 0
    assert "numpy 2.4.6" in p.stderr and "numpy<2" in p.stderr, p.stderr


def test_find_cli_finds_the_build_trees_command_line(monkeypatch):
    monkeypatch.delenv("PARTSIM_CLI", raising=False)
    build = os.path.dirname(os.path.abspath(PYTHON_DIR))
    assert partsim.find_cli() == os.path.join(build, "partsim")
    monkeypatch.setenv("PARTSIM_CLI", "/some/partsim")
    assert partsim.find_cli() == "/some/partsim"


def test_find_cli_finds_an_install_prefixs_and_a_wheels(tmp_path, monkeypatch):
    """The package's own layouts: PREFIX/lib/python3/dist-packages/partsim beside
    PREFIX/bin/partsim, and a wheel's partsim/bin/partsim."""
    import importlib.util

    monkeypatch.delenv("PARTSIM_CLI", raising=False)
    source = os.path.join(REPO, "python", "partsim", "_cli.py")
    for package, cli in (
        (tmp_path / "prefix/lib/python3/dist-packages/partsim", tmp_path / "prefix/bin/partsim"),
        (tmp_path / "site-packages/partsim", tmp_path / "site-packages/partsim/bin/partsim"),
    ):
        package.mkdir(parents=True)
        cli.parent.mkdir(parents=True, exist_ok=True)
        cli.write_text("#!/bin/sh\n")
        cli.chmod(0o755)
        (package / "_cli.py").write_text(open(source, encoding="utf-8").read())
        spec = importlib.util.spec_from_file_location("_cli_copy", package / "_cli.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        assert module.find_cli() == str(cli)


def test_pyproject_and_the_lock_agree():
    """The wheel's version is CMake's, its build requirements are the lock's pins, and its
    runtime dependencies are in the lock."""
    with open(os.path.join(REPO, "pyproject.toml"), "rb") as f:
        project = tomllib.load(f)
    with open(os.path.join(REPO, "requirements.lock"), encoding="utf-8") as f:
        pins = dict(re.findall(r"^([a-z0-9-]+)==([^ \\\n]+)", f.read(), re.M))
    for req in project["build-system"]["requires"]:
        name, version = req.split("==")
        assert pins.get(name) == version, f"pyproject.toml requires {req}, the lock pins {pins.get(name)}"
    for req in project["project"]["dependencies"]:
        name = re.match(r"[a-z0-9-]+", req).group(0)
        assert name in pins, f"the wheel depends on {name}, which the lock does not pin"
    with open(os.path.join(REPO, "CMakeLists.txt"), encoding="utf-8") as f:
        cmake_version = re.search(r"project\(partsim VERSION ([0-9.]+)", f.read()).group(1)
    assert partsim.__version__.startswith(cmake_version)
    assert project["project"]["scripts"]["partsim"] == "partsim._cli:main"
