"""What the two paper pages share: measured *parts* kept in a JSON file, run in child processes,
and the Markdown helpers of the pages.

A page generator (``make_face_gear_2013.py``, ``make_spiral_bevel_multipair.py``) names its
parts, each a function returning JSON-able data. ``python make_X.py`` runs the parts its JSON file
does not hold yet (each in a child process: the FE operators of the loaded runs go with it),
stores each with its wall time, and renders the page from the JSON; ``python make_X.py PART ...``
reruns the named parts; ``python make_X.py render`` only renders. The fegear artefact cache
(meshes, operators, TCA) makes a rerun of a part cheaper, not free.
"""

from __future__ import annotations

import json
import logging
import math
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

log = logging.getLogger("papers")

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
CASES = ROOT / "cases"


def run_part_child(script: Path, name: str) -> tuple[object, float]:
    """Run part ``name`` of ``script`` in a child process; its data and wall seconds."""
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "part.json"
        subprocess.run([sys.executable, str(script), "--part", name, str(out)], check=True)
        data = json.loads(out.read_text(encoding="utf-8"))
    return data, time.perf_counter() - t0


def main(
    argv: list[str],
    script: Path,
    data_path: Path,
    parts: dict[str, Callable[[], object]],
    render: Callable[[dict], str],
    page: Path,
    figures: Callable[[dict], None] | None = None,
) -> None:
    """The command line of a page generator (module docstring): ``render(doc)`` is the page's
    text (pure: the tests compare it with the page), ``figures(doc)`` writes its PNGs."""
    logging.basicConfig(level=logging.WARNING, format="%(message)s")
    if argv[:1] == ["--part"]:  # a child of run_part_child
        Path(argv[2]).write_text(json.dumps(parts[argv[1]]()), encoding="utf-8")
        return
    doc = json.loads(data_path.read_text(encoding="utf-8")) if data_path.exists() else {}
    doc.setdefault("parts", {})
    if argv != ["render"]:
        unknown = [a for a in argv if a not in parts]
        if unknown:
            raise SystemExit(f"unknown part(s) {unknown}: one of {', '.join(parts)} or render")
        todo = argv or [p for p in parts if p not in doc["parts"]]
        for name in todo:
            log.warning("part %s ...", name)
            data, seconds = run_part_child(script, name)
            doc["parts"][name] = {"data": data, "seconds": seconds}
            log.warning("part %s: %.0f s", name, seconds)
            data_path.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    if figures is not None:
        figures(doc)
    page.write_text(render(doc), encoding="utf-8")
    print(page)


def seconds_text(doc: dict, order: Sequence[str]) -> str:
    """``"12.3 min on 2 cores: path 40 s, ..."`` from the parts' wall times."""
    parts = doc["parts"]
    total = sum(parts[p]["seconds"] for p in order if p in parts)
    each = ", ".join(f"`{p}` {parts[p]['seconds']:.0f} s" for p in order if p in parts)
    return f"{total / 60:.1f} min ({each})"


def num(x: float | None, digits: int = 4) -> str:
    """A number with ``digits`` significant digits (``—`` for None or not finite)."""
    if x is None or not math.isfinite(x):
        return "—"
    if x == 0:
        return "0"
    if abs(x) < 1e-3:
        return f"{x:.{max(digits - 2, 0)}e}"
    mag = math.floor(math.log10(abs(x)))
    dec = max(0, digits - 1 - mag)
    return f"{x:.{dec}f}"


def reflow(text: str, width: int = 100) -> str:
    """Markdown with its paragraphs and list items re-wrapped to ``width`` columns (tables,
    indented code, headings and images kept as they are)."""
    import re
    import textwrap

    item = re.compile(r"^(- |\d+\. )")
    out = []
    for block in text.split("\n\n"):
        lines = block.split("\n")
        first = lines[0]
        if first.startswith(("|", "    ", "#", "![")) or not first.strip():
            out.append(block)
            continue
        if item.match(first):
            items, cur = [], []
            for ln in lines:
                if item.match(ln) and cur:
                    items.append(" ".join(cur))
                    cur = []
                cur.append(ln.strip())
            items.append(" ".join(cur))
            wrapped = [
                textwrap.fill(it, width, subsequent_indent=" " * len(item.match(it).group(1)),
                              break_long_words=False, break_on_hyphens=False)
                for it in items
            ]  # fmt: skip
            out.append("\n".join(wrapped))
            continue
        out.append(textwrap.fill(" ".join(ln.strip() for ln in lines), width,
                                 break_long_words=False, break_on_hyphens=False))  # fmt: skip
    return "\n\n".join(out)


def table(head: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """A Markdown table (cells: strings or numbers, formatted by :func:`num`)."""

    def cell(v: object) -> str:
        if isinstance(v, float) or v is None:
            return num(v)
        return str(v).replace("|", "\\|")

    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    out += ["| " + " | ".join(cell(v) for v in r) + " |" for r in rows]
    return "\n".join(out)


def plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot

    return pyplot


def save(fig, path: Path) -> str:
    """Save a figure (PNG, 110 dpi) and return its path relative to the pages' folder."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt().close(fig)
    return str(path.relative_to(HERE))
