"""The user documentation speaks to users, not of the developers' situation: README.md,
docs/*.md (not the generated docs/cli.md and docs/api/) and bench/README.md name no developer
machine ("this project's 2-core machine", "measured here", "on this machine"), no issue or
work session ("issue 17", "issue 'The engine'"), and no other agents' builds. Measurements
name the machine they were taken on instead (e.g. "a 2-core Debian 12 machine without a GPU")."""

import glob
import os
import re

import pytest

from conftest import REPO

DOCS = [os.path.join(REPO, "README.md"), os.path.join(REPO, "bench", "README.md")] + sorted(
    p for p in glob.glob(os.path.join(REPO, "docs", "*.md")) if os.path.basename(p) != "cli.md")

# Developer-facing phrases, each with why it is wrong for a user.
PHRASES = [
    (r"\b(?:this|the) project's (?:\d-core|build) (?:machine|VM)\b", "the developers' machine"),
    (r"\bissue (?:\d+|['\"])", "a reference to an issue"),
    (r"\bissue-\d+\b", "a link to an issue-named heading"),
    (r"\bthe issue's\b", "a reference to an issue"),
    (r"\b(?:later|earlier) issues\b", "a reference to issues"),
    (r"\b(?:measured|takes? [^.\n]{0,20}|minutes|seconds|hours|tuned) here\b",
     "'here' meaning the developers' machine"),
    (r"\bon this (?:machine|VM|CPU)\b", "the developers' machine"),
    (r"\bthis (?:shared |loaded )?VM\b", "the developers' machine"),
    (r"\bthis machine's\b", "the developers' machine"),
    (r"\b(?:in|within|fit in) (?:a|this) session\b", "the developers' work session"),
    (r"\bother agents?'|\banother agent's\b", "the developers' build machine"),
    (r"\bwas lent\b|\ba lent machine\b|\bthe lent machine\b", "the developers' machine loans"),
    (r"\bthe team\b", "the developers' workflow"),
]


def wording_problems(path):
    """`file:line: phrase (why)` for each developer-facing phrase in the file at `path`."""
    problems = []
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            for pattern, why in PHRASES:
                for match in re.finditer(pattern, line, flags=re.I):
                    problems.append(f"{os.path.relpath(path, REPO)}:{number}: "
                                    f"'{match.group(0)}' ({why})")
    return problems


@pytest.mark.parametrize("path", DOCS, ids=lambda p: os.path.relpath(p, REPO))
def test_docs_speak_to_users(path):
    problems = wording_problems(path)
    assert not problems, "developer-facing wording:\n" + "\n".join(problems)


def test_the_wording_check_sees_the_phrases(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("One run, on this project's 2-core machine.\n"
                    "Done: the engine (issue \"The engine\").\n"
                    "See the viewer (issue 17) and [bench](x.md#speed-issue-18).\n"
                    "About 6 minutes here; measured here.\n"
                    "It is met on this machine with generated objects.\n"
                    "Other agents' builds were running.\n"
                    "Click here to open the steps here. The Panda is on the machine that simulates.\n")
    lines = [int(p.split(":")[1]) for p in wording_problems(str(page))]
    assert sorted(set(lines)) == [1, 2, 3, 4, 5, 6]
    assert lines.count(4) == 2
