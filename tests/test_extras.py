"""What is optional: fegear imports and runs without it.

``pyvista`` (extra ``view``), MKL (a dependency on x86-64 only: elsewhere there is none) and the
former ``pypardiso`` dependency are blocked in a subprocess (``sys.modules[name] = None`` makes
their import fail; the MKL loader of :mod:`fegear.linalg._mkl_pardiso` is replaced by one that
finds no ``mkl_rt``), which then imports the command line and runs a cheap case. The full main
job of a fresh install without extras, and without MKL, is measured in
``benchmarks/results/install_without_extras.md``.
"""

from __future__ import annotations

import ast
import importlib.metadata
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "fegear"

#: Modules of the optional extras (and their heavy dependencies) that fegear may only import
#: inside the functions that need them.
OPTIONAL = ("pyvista", "vtk", "pypardiso", "mkl")

#: Run as ``python -c BLOCKED ARGS...``: fegear's command line with the optional packages blocked.
BLOCKED = f"""
import sys
for name in {OPTIONAL!r}:
    sys.modules[name] = None
import fegear.linalg._mkl_pardiso as _mkl
from fegear.errors import BackendUnavailable

def _no_mkl():
    raise BackendUnavailable("mkl_rt blocked by tests/test_extras.py")

_mkl.load_library = _no_mkl
from fegear.cli import main
sys.exit(main(sys.argv[1:]))
"""


def _env(**extra: str) -> dict[str, str]:
    """The test's environment without ``FEGEAR_SOLVER`` (``auto`` decides), plus ``extra``."""
    return {**{k: v for k, v in os.environ.items() if k != "FEGEAR_SOLVER"}, **extra}


def _run_blocked(args: list[str], tmp_path: Path) -> subprocess.CompletedProcess:
    """``fegear ARGS`` with the optional packages blocked, in ``tmp_path`` with its own cache."""
    environ = _env(FEGEAR_CACHE=str(tmp_path / "cache"))
    return subprocess.run(
        [sys.executable, "-c", BLOCKED, *args],
        cwd=tmp_path,
        env=environ,
        capture_output=True,
        text=True,
        timeout=120,
    )


def _import_time_imports(tree: ast.Module):
    """``(line, module)`` of the imports that run when the module is imported: everything but
    the bodies of functions (top-level ``if`` / ``try`` / class bodies included)."""
    stack: list[ast.AST] = list(tree.body)
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            continue
        if isinstance(node, ast.Import):
            yield from ((node.lineno, a.name) for a in node.names)
        elif isinstance(node, ast.ImportFrom) and not node.level:
            yield node.lineno, node.module or ""
        stack.extend(ast.iter_child_nodes(node))


def test_no_module_level_import_of_an_optional_package() -> None:
    """``import pyvista`` etc. only inside functions: importing fegear never needs the extras."""
    found = [
        f"{path.relative_to(REPO)}:{line} {name}"
        for path in sorted(PACKAGE.rglob("*.py"))
        for line, name in _import_time_imports(ast.parse(path.read_text(encoding="utf-8")))
        if name.split(".")[0] in OPTIONAL
    ]
    assert not found, "module-level imports of optional packages:\n" + "\n".join(found)


def test_cli_and_a_cheap_run_without_the_extras(tmp_path) -> None:
    """The command line imports, and the unloaded TCA of the seed face gear runs (6 s; it
    writes no VTK: the main job of a fresh install without extras is measured, see the module
    docstring)."""
    out = tmp_path / "out"
    case = REPO / "cases" / "face_gear_nominal.toml"
    proc = _run_blocked(["run", str(case), "--fidelity", "tca", "--out", str(out), "-q"], tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    doc = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert doc["versions"]["fegear"]


def test_sparse_solver_without_mkl_is_superlu(tmp_path) -> None:
    """``auto`` falls back to SuperLU when no MKL loads, and says so; ``pardiso`` is refused."""
    code = BLOCKED.replace(
        "from fegear.cli import main\nsys.exit(main(sys.argv[1:]))",
        """import numpy as np, scipy.sparse as sp
from fegear.linalg.solve import factorize_spd
K = sp.diags([-np.ones(4), 4.0 * np.ones(5), -np.ones(4)], [-1, 0, 1], format="csr")
f = factorize_spd(K)
assert f.backend == "superlu", f.backend
assert np.allclose(K @ f.solve(np.ones(5)), 1.0)
try:
    factorize_spd(K, "pardiso")
except BackendUnavailable as exc:
    print("refused:", exc)
else:
    raise SystemExit("pardiso was not refused")
""",
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], env=_env(), capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "refused: PARDISO was requested but is not available (mkl_rt blocked" in proc.stdout


def test_versions_record_absent_packages(monkeypatch) -> None:
    from fegear.results import records

    real = importlib.metadata.version

    def version(name: str) -> str:
        if name in OPTIONAL:
            raise importlib.metadata.PackageNotFoundError(name)
        return real(name)

    monkeypatch.setattr(importlib.metadata, "version", version)
    v = records.versions()
    assert v["pyvista"] == "not installed" and v["mkl"] == "not installed"
    assert v["numpy"] == real("numpy")


def test_the_extras_are_declared() -> None:
    """``view`` is pyvista; ``test`` has it too (the tests read the VTK output back with it)."""
    import tomllib

    extras = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"][
        "optional-dependencies"
    ]
    assert any(d.startswith("pyvista") for d in extras["view"])
    assert any(d.startswith("pyvista") for d in extras["test"])


def test_flank_views_written_and_read_without_pyvista(tmp_path) -> None:
    """The main job's only VTK file that needed pyvista, the flank view ``.vtp``: written and
    read back without it (the round trip is exact), and pyvista, where installed, reads it as
    the same cells and fields."""
    path = tmp_path / "flank_gear_000.vtp"
    code = BLOCKED.replace(
        "from fegear.cli import main\nsys.exit(main(sys.argv[1:]))",
        f"""import numpy as np
from pathlib import Path

import numpy as np
from fegear.output.flank_view import FlankFrame, FlankPatch
from fegear.output.flank_vtp import read_flank_vtp, write_flank_vtp
rng = np.random.default_rng(0)
outline = rng.standard_normal((11, 2))
quads = rng.standard_normal((7, 4, 2))
frame = FlankFrame("gear", "v (mm)", "h (mm)", outline, ("toe", "heel"))
patch = FlankPatch("gear", quads, quads.mean(1), rng.random(7), rng.random(7),
                   rng.integers(0, 3, 7), rng.integers(0, 2, 7), rng.random(7) > 0.5)
write_flank_vtp(Path({str(path)!r}), frame, patch, 1.2345678901234567)
fr, pa, t = read_flank_vtp(Path({str(path)!r}))
assert t == 1.2345678901234567 and fr.face_ends == ("toe", "heel") and fr.member == "gear"
assert (fr.face_name, fr.profile_name) == ("v (mm)", "h (mm)")
assert np.array_equal(fr.outline, outline)
for name in ("quads", "pressure_MPa", "force_N", "tooth", "pair", "edge"):
    assert np.array_equal(getattr(pa, name), getattr(patch, name)), name
""",
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], env=_env(), capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    try:
        import pyvista as pv
    except ImportError:
        return
    mesh = pv.read(str(path))
    assert mesh.n_cells == 8 and mesh.n_lines == 1  # the outline, then the 7 quads
    assert list(mesh.field_data["face_ends"]) == ["toe", "heel"]
    assert mesh.cell_data["tooth"].dtype == np.int32
