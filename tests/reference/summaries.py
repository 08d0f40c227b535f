"""Reference ``summary.json`` numbers of every case in ``cases/``, and their comparison.

The references guard refactoring: a change that is meant to leave the results alone must give
the same numbers to 1e-9 relative (the runs are deterministic on one machine: the same meshes,
the same operators from the content-hashed cache, ``--workers 1`` and ``2`` bitwise equal).
Meshes differ between hosts (gmsh), so the stored references are those of the machine that
runs CI; regenerate them there after a change that is meant to move the numbers::

    python tests/reference/summaries.py            # every case, tca and the case's fidelity
    python tests/reference/summaries.py tca        # the unloaded TCA only (fast)

What is compared: every number and string of ``summary.json`` except what describes the run
rather than its result (timings, cache use, software versions, file lists, paths) and the
solver's residuals (round-off measures).

The runs take the test session's environment (``tests/conftest.py``): dense BLAS on one thread
and the positions in this process. The thread count is part of the arithmetic: the loaded
results of one machine differ by up to a few 1e-6 relative between one and two OpenBLAS threads
in the operators' dense algebra (FZG p_max 1264.18594 against 1264.18648 MPa: the contact
problem of fine cells amplifies the round-off of another summation order), so references made
with other settings than the tests' cannot be met at 1e-9.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as tests/conftest.py, before numpy loads
os.environ.setdefault("FEGEAR_WORKERS", "1")

import dataclasses  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
from collections.abc import Iterator
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "cases"
STORE = Path(__file__).resolve().parent / "summaries"
#: keys of summary.json that describe the run, not its result
IGNORED = {"timings_s", "cache", "versions", "files", "source", "seconds"}
#: suffix of the solver's residuals: round-off measures (1e-16 against 1e-13 is no change)
ROUND_OFF = "_residual"
#: relative tolerance of the comparison (what "unchanged" means: round-off of a reordered sum)
RTOL = 1e-9
#: absolute floor, in the summary's units (mm, arcsec, MPa, N): values that are zero up to
#: round-off (a TE difference of two equal positions) are compared absolutely
ATOL = 1e-12


def case_files() -> list[Path]:
    """Every TOML case of ``cases/``."""
    return sorted(CASES.glob("*.toml"))


def reference_path(case: Path, fidelity: str) -> Path:
    """Where the reference of ``case`` run at ``fidelity`` (``"tca"`` or ``"own"``) lives."""
    return STORE / f"{case.stem}.{fidelity}.json"


def run_summary(case: Path, fidelity: str) -> dict[str, Any]:
    """``summary.json`` of ``case`` at level 0, at ``fidelity`` (``"own"``: the case's)."""
    import fegear

    c = fegear.load_case(case)
    if c.__class__.__name__ == "HertzCase":
        res = fegear.run(c.replace(level=0, study_levels=()))
        keep = (int, float, str, dict)
        doc = {f.name: getattr(res, f.name) for f in dataclasses.fields(res)}
        doc = {k: v for k, v in doc.items() if isinstance(v, keep) and k != "case"}
        return json.loads(json.dumps(doc, default=float))
    if fidelity == "tca":
        res = fegear.run(c, fidelity="tca")
    else:
        res = fegear.run(c, level=0)
    return json.loads(json.dumps(res.summary, default=float))


def leaves(doc: Any, path: str = "") -> Iterator[tuple[str, Any]]:
    """``(path, value)`` of every compared leaf of a summary."""
    if isinstance(doc, dict):
        for k, v in doc.items():
            if k not in IGNORED and not k.endswith(ROUND_OFF):
                yield from leaves(v, f"{path}.{k}")
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from leaves(v, f"{path}[{i}]")
    else:
        yield path, doc


def differences(new: dict[str, Any], ref: dict[str, Any]) -> list[str]:
    """The leaves of ``new`` that differ from ``ref`` (and those only one of them has)."""
    a, b = dict(leaves(new)), dict(leaves(ref))
    out = [f"{k}: only in the new run" for k in a.keys() - b.keys()]
    out += [f"{k}: missing in the new run" for k in b.keys() - a.keys()]
    for k in sorted(a.keys() & b.keys()):
        x, y = a[k], b[k]
        if isinstance(x, float | int) and isinstance(y, float | int) and not isinstance(x, bool):
            if math.isnan(x) and math.isnan(y):
                continue
            if not math.isclose(x, y, rel_tol=RTOL, abs_tol=ATOL):
                out.append(f"{k}: {x!r} != {y!r} (reference)")
        elif x != y:
            out.append(f"{k}: {x!r} != {y!r} (reference)")
    return out


def main(argv: list[str]) -> None:
    fidelities = argv or ["tca", "own"]
    STORE.mkdir(exist_ok=True)
    for case in case_files():
        for fid in fidelities:
            if fid == "tca" and case.stem == "hertz_scene":
                continue
            doc = run_summary(case, fid)
            path = reference_path(case, fid)
            path.write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n", encoding="utf-8")
            print(path, flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
