"""Every relative link in README.md and docs/*.md points to a file or folder that exists in the
checkout, and a link to a heading (`file.md#heading`, `#heading`) to a heading that exists,
with GitHub's heading anchors. Links to web sites are not followed. The README opens with the
two set-up commands."""

import glob
import os
import re

import pytest

from conftest import REPO

DOCS = [os.path.join(REPO, "README.md")] + sorted(glob.glob(os.path.join(REPO, "docs", "*.md")))
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")


def prose(text):
    """`text` without fenced code blocks and inline code, which hold no links."""
    text = re.sub(r"^```.*?^```", "", text, flags=re.M | re.S)
    return re.sub(r"`[^`\n]*`", "", text)


def anchors(path):
    """GitHub's anchors of the headings of a Markdown file."""
    with open(path, encoding="utf-8") as f:
        text = re.sub(r"^```.*?^```", "", f.read(), flags=re.M | re.S)
    seen, out = {}, set()
    for heading in re.findall(r"^#{1,6}\s+(.*?)\s*#*\s*$", text, flags=re.M):
        slug = re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        out.add(slug if n == 0 else f"{slug}-{n}")
    return out


def broken_links(path):
    with open(path, encoding="utf-8") as f:
        text = prose(f.read())
    broken = []
    for target in LINK.findall(text):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
            continue
        file_part, _, anchor = target.partition("#")
        resolved = os.path.normpath(os.path.join(os.path.dirname(path), file_part)) \
            if file_part else path
        if not os.path.exists(resolved):
            broken.append(f"{target}: {os.path.relpath(resolved, REPO)} does not exist")
        elif anchor and resolved.endswith(".md") and anchor not in anchors(resolved):
            broken.append(f"{target}: no heading '#{anchor}' in {os.path.relpath(resolved, REPO)}")
    return broken


@pytest.mark.parametrize("path", DOCS, ids=lambda p: os.path.relpath(p, REPO))
def test_relative_links_point_to_existing_files(path):
    broken = broken_links(path)
    assert not broken, "broken links in " + os.path.relpath(path, REPO) + ":\n" + "\n".join(broken)


def test_the_link_checker_sees_links(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("# Title\n\n## A first C++ program\n\n[ok](page.md#a-first-c-program) "
                    "[bad](missing.md) [anchor](#nope) ![image](img.png) `[code](x.md)`\n"
                    "```\n[fenced](y.md)\n```\n[web](https://example.org/x)\n")
    broken = broken_links(str(page))
    assert [b.split(":")[0] for b in broken] == ["missing.md", "#nope", "img.png"]


def test_readme_opens_with_the_set_up_commands():
    with open(os.path.join(REPO, "README.md"), encoding="utf-8") as f:
        lines = [line for line in f.read().splitlines() if line.strip()]
    assert lines[0] == "# partsim"
    bullets = [line for line in lines[1:10] if line.startswith("- ")]
    assert bullets[0].startswith("- `bash scripts/run.sh`")
    assert bullets[1].startswith("- `bash scripts/test.sh`")
