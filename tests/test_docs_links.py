"""The documentation the code relies on is in the repository: every ``docs/…`` page the source
cites exists, and no citation points outside the repository."""

from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
#: The text files of the repository that cite documentation.
TEXTS = [
    p
    for folder in ("fegear", "tests", "docs", "benchmarks", "cases")
    for p in sorted((REPO / folder).rglob("*"))
    if p.suffix in (".py", ".md", ".toml") and p.is_file()
]


def test_the_cited_docs_pages_exist():
    cited = {
        m
        for p in (REPO / "fegear").rglob("*.py")
        for m in re.findall(r"docs/[A-Za-z0-9_/.-]+\.(?:md|png)", p.read_text(encoding="utf-8"))
    }
    assert len(cited) >= 5  # the reader finds the citations (conventions, fidelity, ...)
    missing = sorted(c for c in cited if not (REPO / c).exists())
    assert not missing, missing


def test_no_citation_of_notes_outside_the_repository():
    outside = ("DESIGN" + " §", "../" + "shared")  # split: this file holds no such citation
    found = [
        f"{p.relative_to(REPO)}: {w}"
        for p in TEXTS + [REPO / "README.md"]
        for w in outside
        if w in p.read_text(encoding="utf-8")
    ]
    assert not found, found
