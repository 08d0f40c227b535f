"""An output folder holds one run: the files fegear wrote there are listed, and replaced as a whole.

Writing a run's files into a folder (:func:`output_run`, what ``result.write(folder)`` and
``fegear run --out`` use) goes in three steps:

1. :func:`inspect_output_folder`, before any work: the folder is new or empty, or holds the
   outputs of an earlier fegear run (its manifest :data:`MANIFEST`, or for folders written
   before manifests existed, the ``files`` list of its ``summary.json``), or holds other files;
   the last is refused (:class:`~fegear.errors.InputError` naming the option) unless
   ``overwrite`` is given, so a run never mixes its files with another case's (``fegear plot``
   drew a stale face gear from an FZG run's folder).
2. Before the first file is written: the earlier run's files are removed (only those its
   manifest lists: a file fegear did not write is never removed), and the temporary files of
   interrupted atomic writes (:func:`fegear.store.files.clean_stale_temps`).
3. While writing, every file is added to the manifest before it is created (the atomic writes
   of :mod:`fegear.store.files` report to it), so a run killed half-way leaves a manifest that
   still names every file it made; the next run removes them.

:meth:`OutputFolder.describe` is the line the command prints about what it did.
"""

from __future__ import annotations

import json
import logging
import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from fegear.errors import InputError
from fegear.store.files import check_writable_folder, clean_stale_temps, is_stale_temp, journal

__all__ = ["MANIFEST", "OutputFolder", "inspect_output_folder", "output_run", "run_files"]

log = logging.getLogger(__name__)

#: The manifest: the files of the last run written into the folder, one relative path a line.
MANIFEST = ".fegear-outputs"
_HEADER = "# fegear outputs: the files of the run written into this folder (removed by the next)"
#: Stems of fegear's output files (gear and Hertz-scene runs): a temporary file of an earlier
#: fegear (no process id in its name) with one of them is a leftover of an interrupted write.
_OUTPUT_STEMS = re.compile(
    r"^(summary|cycle|te|load_share|p_max|root_stress|bearing_pattern\w*|block|roller|"
    r"contact_cells|pressure_map|convergence|(pinion|gear|contact_cells|flank_pinion|flank_gear)"
    r"_[0-9]{3})$"
)


@dataclass(frozen=True)
class OutputFolder:
    """What an output folder holds before a run writes into it.

    Attributes
    ----------
    path
        The folder.
    state
        ``"new"`` (absent), ``"empty"``, ``"previous"`` (the outputs of an earlier fegear run
        and nothing else), ``"foreign"`` (files fegear did not write; allowed with
        ``overwrite``).
    previous
        Relative paths of the earlier run's files that exist (removed before writing).
    others
        Relative paths of the files fegear did not write (kept; files of the same name as an
        output are replaced).
    stale
        Relative paths of temporary files of interrupted writes (removed before writing).
    overwrite
        The folder was accepted with other files in it.
    """

    path: Path
    state: str
    previous: tuple[str, ...] = ()
    others: tuple[str, ...] = ()
    stale: tuple[str, ...] = ()
    overwrite: bool = False

    def describe(self) -> str:
        """One line: what writing the run there does (removes, keeps)."""
        where = f"{self.path}/"
        tmp = f"; {len(self.stale)} temporary files of an interrupted run removed" * bool(
            self.stale
        )
        if self.state == "new":
            return f"{where}: a new folder{tmp}"
        if self.state == "empty":
            return f"{where}: an empty folder{tmp}"
        if self.state == "previous":
            return f"{where}: the {len(self.previous)} files of the previous run removed{tmp}"
        return (
            f"{where}: --overwrite: {len(self.others)} files fegear did not write are kept "
            f"(those named as outputs are replaced), {len(self.previous)} files of the previous "
            f"run removed{tmp}"
        )


def _listed(folder: Path) -> tuple[list[str], bool]:
    """The files an earlier run listed (its manifest; else the ``files`` of a fegear
    ``summary.json``), and whether the folder is fegear's."""
    m = folder / MANIFEST
    if m.is_file():
        names = []
        for line in m.read_text(encoding="utf-8", errors="replace").splitlines():
            line = line.strip()
            if line and not line.startswith("#"):
                names.append(line)
        return names, True
    s = folder / "summary.json"
    if s.is_file():
        try:
            doc = json.loads(s.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return [], False
        if isinstance(doc, dict) and "fegear" in doc.get("versions", {}):
            files = doc.get("files")
            if isinstance(files, list) and all(isinstance(f, str) for f in files):
                return list(files) + ["summary.json"], True
    return [], False


def _inside(folder: Path, name: str) -> Path | None:
    """``folder / name`` if it stays inside ``folder`` (a manifest is data, not a command)."""
    p = (folder / name).resolve()
    root = folder.resolve()
    return p if p != root and root in p.parents else None


def inspect_output_folder(
    folder: str | Path, overwrite: bool = False, field: str = "--out"
) -> OutputFolder:
    """What ``folder`` holds (:class:`OutputFolder`), checked before any work.

    Raises
    ------
    InputError
        ``folder`` cannot be written (:func:`fegear.store.files.check_writable_folder`), or
        holds files fegear did not write and ``overwrite`` is False (naming ``field``).
    """
    p = check_writable_folder(folder, field)
    if not p.exists():
        return OutputFolder(p, "new", overwrite=overwrite)
    listed, ours = _listed(p)
    previous = []
    for name in listed:
        q = _inside(p, name)
        if q is not None and q.is_file():
            previous.append(name)
    known = set(previous) | {MANIFEST}
    stale, others = [], []
    for q in sorted(p.rglob("*")):
        if not q.is_file() and not q.is_symlink():
            continue
        rel = q.relative_to(p).as_posix()
        if rel in known:
            continue
        if is_stale_temp(q, _OUTPUT_STEMS):
            stale.append(rel)
        else:
            others.append(rel)
    if others and not overwrite:
        what = f"{len(others)} files " + (
            "that its last fegear run did not write" if ours else "fegear did not write"
        )
        flag = "--overwrite" if field.startswith("--") else "overwrite=True"
        raise InputError(
            field, str(p), "an empty or new folder, or one that holds a fegear run's outputs "
            f"(or give {flag})",
            f"it holds {what}, e.g. {others[0]!r}; fegear writes one run per folder",
        )  # fmt: skip
    state = "foreign" if others else ("previous" if previous or ours else "empty")
    return OutputFolder(p, state, tuple(previous), tuple(others), tuple(stale), overwrite)


@contextmanager
def output_run(folder: OutputFolder) -> Iterator[Path]:
    """Write one run into ``folder``: remove the earlier run's files and stale temporary files,
    start the manifest, and list every file written inside the block in it (yields the folder
    path)."""
    p = folder.path
    for name in folder.previous:
        q = _inside(p, name)
        if q is not None:
            q.unlink(missing_ok=True)
    gone = clean_stale_temps(p, recursive=True, stems=_OUTPUT_STEMS)
    emptied = {(p / n).parent for n in folder.previous} | {q.parent for q in gone}
    for d in sorted(emptied, key=lambda x: -len(x.parts)):
        if d != p and d.is_dir() and not any(d.iterdir()):
            d.rmdir()
    p.mkdir(parents=True, exist_ok=True)
    m = p / MANIFEST
    with open(m, "w", encoding="utf-8") as fh:
        fh.write(_HEADER + "\n")
        fh.flush()
        os.fsync(fh.fileno())
    with journal(p, m):
        yield p


def run_files(folder: str | Path) -> list[str] | None:
    """The files of the run in ``folder`` (relative paths): the ``files`` of its
    ``summary.json`` when its manifest says fegear wrote it, else those of a fegear
    ``summary.json`` of a folder written before manifests; None when the folder holds no
    finished fegear run."""
    p = Path(folder)
    listed, ours = _listed(p)
    if not ours or not (p / "summary.json").is_file():
        return None
    try:
        doc = json.loads((p / "summary.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    files = doc.get("files") if isinstance(doc, dict) else None
    if not isinstance(files, list):
        return [n for n in listed if n != "summary.json"]
    return [f for f in files if isinstance(f, str)]
