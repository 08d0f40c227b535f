"""What the README shows runs (issue 22, "Must show").

- The Python example: the first ```python block under the heading "Python API" of README.md,
  run verbatim (in a fresh folder holding the shipped case files, as the README's readers have
  them); until README.md has that section, ``docs/api_example.py``, which is what it will show
  (when both exist they must be identical).
- Every ``fegear ...`` command line in the ```bash blocks of README.md and docs/cli/README.md
  parses with the command's own argument parser (not run).
"""

from __future__ import annotations

import re
import runpy
import shlex
import shutil
from pathlib import Path

import pytest

from fegear.cli import parser

REPO = Path(__file__).resolve().parents[1]
README = REPO / "README.md"
EXAMPLE = REPO / "docs" / "api_example.py"
DOCS_WITH_COMMANDS = [README, REPO / "docs" / "cli" / "README.md"]


def _blocks(text: str, lang: str) -> list[tuple[str, str]]:
    """``[(heading above, body)]`` of the fenced blocks of ``lang`` in a Markdown text."""
    out, heading, lines = [], "", text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("#"):
            heading = line.lstrip("#").strip()
        if line.strip() == f"```{lang}":
            j = i + 1
            while j < len(lines) and lines[j].strip() != "```":
                j += 1
            out.append((heading, "\n".join(lines[i + 1 : j]) + "\n"))
            i = j
        i += 1
    return out


def readme_example() -> str | None:
    """The first python block under a heading containing "Python API", or None."""
    if not README.is_file():
        return None
    for heading, body in _blocks(README.read_text(encoding="utf-8"), "python"):
        if "python api" in heading.lower():
            return body
    return None


def test_readme_example_is_the_docs_example():
    """The README's "Python API" section shows docs/api_example.py verbatim (a renamed heading or
    a missing code block fails here instead of silently running the docs copy)."""
    text = readme_example()
    assert text is not None, "README.md has no python block under a 'Python API' heading"
    assert text.strip() == EXAMPLE.read_text(encoding="utf-8").strip()


def test_python_example_runs_verbatim(tmp_path, monkeypatch, capsys):
    """The example as the README shows it, from a folder with the shipped ``cases/*.toml``:
    it prints its table and writes the files and the picture it names."""
    text = readme_example()
    assert text is not None, "README.md has no python block under a 'Python API' heading"
    (tmp_path / "cases").mkdir()
    for f in (REPO / "cases").glob("*.toml"):
        shutil.copy(f, tmp_path / "cases" / f.name)
    script = tmp_path / "example.py"
    script.write_text(text, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(script), run_name="__main__")
    out = capsys.readouterr().out
    assert "as designed: TE p-p" in out and "tilted: TE p-p" in out
    assert "pattern centre" in out
    for name in re.findall(r'"(out/[^"]+)"', text):  # every path the example writes
        assert (tmp_path / name).exists(), name


def _command_lines(path: Path) -> list[str]:
    """The ``fegear ...`` lines of the ```bash blocks (continuation lines joined, comments
    dropped)."""
    lines = []
    for _, body in _blocks(path.read_text(encoding="utf-8"), "bash"):
        joined = body.replace("\\\n", " ")
        for line in joined.splitlines():
            line = line.strip()
            if line.startswith("fegear "):
                lines.append(line)
    return lines


COMMANDS = [(p, line) for p in DOCS_WITH_COMMANDS if p.is_file() for line in _command_lines(p)]


def test_the_docs_have_command_lines():
    assert any(p == REPO / "docs" / "cli" / "README.md" for p, _ in COMMANDS)


@pytest.mark.parametrize(
    ("path", "line"),
    COMMANDS,
    ids=[f"{p.parent.name}/{p.name}:{i}" for i, (p, _) in enumerate(COMMANDS)],  # fmt: skip
)
def test_command_line_parses(path, line):
    argv = shlex.split(line, comments=True)
    assert argv[0] == "fegear"
    try:
        parser().parse_args(argv[1:])
    except SystemExit as exc:  # argparse's refusal (exit 2); --help and --version exit 0
        if exc.code not in (0, None):
            pytest.fail(f"{path.name}: {line!r} does not parse (argparse exit {exc.code})")


@pytest.mark.parametrize("command", ["run", "sweep"])
def test_help_names_every_gear_fidelity(command, capsys):
    """``fegear run --help`` and ``fegear sweep --help`` list every fidelity of the gear
    pairs (the sweep's once lacked ``hybrid``, the default)."""
    from fegear.io.gear_case import FIDELITIES

    with pytest.raises(SystemExit):
        parser().parse_args([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    start = text.rindex("--fidelity FIDELITY") + len("--fidelity FIDELITY")  # options, not usage
    help_text = text[start : start + 400]
    for fid in FIDELITIES:
        assert re.search(rf"\b{fid}\b", help_text), (command, fid, help_text)


def test_readme_is_for_users():
    """README.md speaks to users about the project as it is (issue 22): at most ~300 lines, no
    development history, no pointers outside the repository."""
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 300
    for word in ("session", "DESIGN" + " §", "../" + "shared", "before/after"):
        assert word.lower() not in text.lower(), word


def _case_table() -> dict[str, set[str]]:
    """``{section row label: keys}`` of the README's case-file reference table (the backticked
    words of its second column)."""
    text = README.read_text(encoding="utf-8")
    start = text.index("## Case files")
    rows = {}
    for line in text[start:].splitlines()[1:]:
        if line.startswith("## "):
            break
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 2 and cells[0].startswith("`["):
            rows[cells[0]] = set(re.findall(r"`([A-Za-z0-9_]+)`", cells[1]))
    return rows


def test_case_file_reference_is_the_schema():
    """Every key of the gear-case schema is in the README's case-file table under its section,
    and the table names no key the schema does not know."""
    from fegear.io import gear_case as gc

    rows = _case_table()
    expected = {
        f"`[{sec.name}]`": set(sec.names)
        for sec in (gc.CASE, gc.LOAD, gc.ANALYSIS, gc.MATERIAL, gc.TOPOGRAPHY)
    }
    for kind, sec in gc.PAIR_SECTIONS.items():
        expected[f"`[pair]`, kind `{kind}`"] = set(sec.names)
    expected["`[errors]`"] = set(gc.PAIR_ERRORS_INTERSECTING) | set(gc.PAIR_ERRORS_PARALLEL)
    assert rows == expected


def test_the_case_file_reference_page_is_generated_from_the_schema():
    """docs/case_files.md is what ``python -m fegear.case_files`` writes from the declarations (the
    validator reads the same declarations, so the page cannot drift from what is accepted)."""
    from fegear.case_files import reference

    page = (REPO / "docs" / "case_files.md").read_text(encoding="utf-8")
    assert page == reference(), "regenerate: python -m fegear.case_files > docs/case_files.md"
