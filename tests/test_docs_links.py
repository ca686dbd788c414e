"""Every file the repository's text points at is in the repository.

Scans the tracked text files (``git ls-files``) for references to repository
files: relative Markdown links, bare mentions of Markdown files by name, and
paths under the project's folders (docs, robots, worlds, missions, behaviors,
scripts). URLs, globs and placeholders (an upper-case NAME, ``<name>``,
``{name}``) are not references.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCANNED = {".py", ".md", ".toml", ".xml", ".yaml", ".yml", ".sh"}
FOLDERS = ("docs", "robots", "worlds", "missions", "behaviors", "scripts")

MARKDOWN_LINK = re.compile(r"\[[^\]\n]*\]\(([^)\s]+)\)")
# a path starts after a space, a quote, a bracket or the start of a line, not inside a word, a path or a URL
_START = r"(?<![\w./:@$<{-])"
_TAIL = r"[^\s`'\"()\[\],;|>#]*"
MARKDOWN_FILE = re.compile(_START + r"((?:[\w.-]+/)*[\w-]+\.md)\b")
FOLDER_PATH = re.compile(_START + r"((?:" + "|".join(FOLDERS) + r")/" + _TAIL + ")")
LINE_NUMBER = re.compile(r"(?::\d+)+$")  # file:line
PLACEHOLDER = re.compile(r"[*?{}<>$…]|\.\.\.|(?:^|/)[A-Z][A-Z0-9_]*(?:/|$)")


def tracked_text_files() -> list[Path]:
    listed = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    files = [ROOT / name for name in listed.split("\0") if name and Path(name).suffix in SCANNED]
    return [path for path in files if path != Path(__file__).resolve()]  # this file's examples are not references


def references(text: str, markdown: bool = True) -> set[str]:
    """The repository paths a text mentions (placeholders and URLs left out); links only in Markdown."""
    found = set()
    for link in MARKDOWN_LINK.findall(text) if markdown else []:
        if re.match(r"[a-z][a-z0-9+.-]*:", link) or link.startswith("#"):
            continue  # a URL, mailto: or an anchor in the same page
        found.add(link.split("#", 1)[0])
    found.update(MARKDOWN_FILE.findall(text))
    found.update(LINE_NUMBER.sub("", path.rstrip(".:")).rstrip(".") for path in FOLDER_PATH.findall(text))
    return {ref for ref in found if ref and not PLACEHOLDER.search(ref)}


def exists(ref: str, source: Path, names: set[str]) -> bool:
    if "/" not in ref.rstrip("/") and ref in names:
        return True  # a file mentioned by name alone: README.md
    return any((base / ref).exists() for base in (source.parent, ROOT))


def dangling() -> list[str]:
    files = tracked_text_files()
    names = {path.name for path in files}
    return [
        f"{path.relative_to(ROOT)}: {ref}"
        for path in files
        for ref in sorted(references(path.read_text(encoding="utf-8", errors="replace"), path.suffix == ".md"))
        if not exists(ref, path, names)
    ]


def test_no_file_reference_dangles():
    missing = dangling()
    assert not missing, "references to files that are not in the repository:\n" + "\n".join(missing)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("see [results](docs/results.md#fetch) and [MuJoCo](https://mujoco.org)", {"docs/results.md"}),
        ("(see NOTE5.md)", {"NOTE5.md"}),
        ("bt-run missions/demo.yaml.", {"missions/demo.yaml"}),
        ("every robots/*/scene.xml, robots/NAME/README.md, robots/<name>/robot.yaml", set()),
        ('f"robots/{name}/robot.yaml" and https://github.com/x/y/docs/a.md', set()),
        ("error: missions/typo.yaml:12: unknown skill", {"missions/typo.yaml"}),
    ],
)
def test_what_counts_as_a_reference(text, expected):
    assert references(text) == expected
