"""docs/cli.md is what scripts/gen_cli_docs.py makes of the built program's --help texts, so it
lists every command and option; the script finds the commands and subcommands from the help
texts themselves (checked against a stand-in program)."""

import os
import stat
import subprocess
import sys

import pytest

from conftest import PYTHON_DIR, REPO

CLI = os.environ.get("PARTSIM_CLI", os.path.join(os.path.dirname(os.path.abspath(PYTHON_DIR)),
                                                 "partsim"))
SCRIPT = os.path.join(REPO, "scripts", "gen_cli_docs.py")
sys.path.insert(0, os.path.join(REPO, "scripts"))
import gen_cli_docs  # noqa: E402


def test_docs_cli_md_is_the_current_help_of_every_command(tmp_path):
    out = tmp_path / "cli.md"
    subprocess.run([sys.executable, SCRIPT, "--partsim", CLI, "--out", str(out)], check=True,
                   timeout=300)
    with open(os.path.join(REPO, "docs", "cli.md"), encoding="utf-8") as f:
        committed = f.read()
    assert out.read_text(encoding="utf-8") == committed, (
        "docs/cli.md is not the program's current --help: run "
        "`python3 scripts/gen_cli_docs.py --partsim build/partsim` and commit docs/cli.md")
    # the commands and options the page once lacked
    for text in ("## partsim vision", "detection-dataset", "motion-dataset", "--no-cameras",
                 "--targets", "--ids", "### partsim assets check", "--limit N",
                 "--max-clients", "--viewer-port", "--camera-rate"):
        assert text in committed, text


FAKE = r"""#!/bin/sh
case "$*" in
  "--help"|"info --help") printf '%s\n' 'usage:' '  partsim info [OBJECT]' \
      '  partsim tool a|b [options]' '  partsim box open DIR' '  partsim --help' ;;
  "tool --help"|"tool a --help") printf 'usage:\n  partsim tool a X\n  partsim tool b Y\n' ;;
  "tool b --help") printf 'usage: partsim tool b Y [--deep]\n  --deep  goes deep\n' ;;
  "box --help") printf 'usage:\n  partsim box open DIR   (see partsim box open --help)\n' ;;
  "box open --help") printf 'usage: partsim box open DIR [--lid]\n' ;;
  *) echo "unknown: $*" >&2; exit 2 ;;
esac
"""


def test_commands_and_subcommands_are_found_from_the_help_texts(tmp_path):
    fake = tmp_path / "partsim"
    fake.write_text(FAKE)
    fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
    found = [(words, text.splitlines()[0]) for words, text in gen_cli_docs.sections(str(fake))]
    # info's help is the program's: no section of its own; "tool a|b" names both subcommands,
    # and only b's help says more than tool's
    assert found == [((), "usage:"), (("tool",), "usage:"),
                     (("tool", "b"), "usage: partsim tool b Y [--deep]"),
                     (("box",), "usage:"), (("box", "open"), "usage: partsim box open DIR [--lid]")]
    page = gen_cli_docs.render(str(fake))
    assert "### partsim tool b\n" in page and "  --deep  goes deep\n" in page
    assert "### partsim tool a" not in page


def test_a_help_that_fails_is_an_error(tmp_path):
    fake = tmp_path / "partsim"
    fake.write_text(FAKE.replace('"box open --help")', '"box open --never")'))
    fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
    with pytest.raises(RuntimeError, match="box open --help' exited with 2"):
        gen_cli_docs.sections(str(fake))
