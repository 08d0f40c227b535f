"""Shared test set-up: a private, cold artefact cache and a fixed number of BLAS threads."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

# Dense BLAS/LAPACK (OpenBLAS under numpy) on one thread: the contact grids of the tests are small
# (a few hundred cells), so threads buy nothing, and a fixed thread count keeps the floating-point
# summation order, hence the results, the same from run to run. Set before numpy is imported by
# any test module; an explicit setting in the environment wins. MKL (PARDISO) is left alone: it
# takes its own thread count (fegear.linalg.schur: MKL_NUM_THREADS, else 2).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# Mesh positions in this process unless a test asks for worker processes (tests/test_ltca_cycle.py
# checks that the worker count does not change the result): fewer forks of the test session.
os.environ.setdefault("FEGEAR_WORKERS", "1")

import pytest  # noqa: E402


def pytest_configure(config: pytest.Config) -> None:
    """Point ``$FEGEAR_CACHE`` at a fresh folder before any test module is imported: the tests
    start cold and never read or write the user's cache (the per-user cache folder, or a
    ``$FEGEAR_CACHE`` of the shell, which this overrides); subprocesses inherit it. Removed,
    and the old value restored, at the end of the session (a face-gear cache is ~100 MB). Under
    pytest-xdist every worker process runs this too and has a folder of its own: the tests that
    count the cache's hits and builds, or clear it, never see another process's entries."""
    root = tempfile.mkdtemp(prefix="fegear_test_cache_")
    config._fegear_cache = (root, os.environ.get("FEGEAR_CACHE"))  # type: ignore[attr-defined]
    os.environ["FEGEAR_CACHE"] = root


def pytest_unconfigure(config: pytest.Config) -> None:
    root, old = getattr(config, "_fegear_cache", (None, None))
    if root is None:
        return
    shutil.rmtree(root, ignore_errors=True)
    if old is None:
        os.environ.pop("FEGEAR_CACHE", None)
    else:
        os.environ["FEGEAR_CACHE"] = old


@pytest.fixture(scope="session")
def fegear_cache() -> Path:
    """The session's private artefact cache folder."""
    return Path(os.environ["FEGEAR_CACHE"])


@pytest.fixture(scope="session")
def spiral_bevel_pair():
    """The reference spiral bevel pair, shared by the test modules that use it as it is (a
    frozen dataclass; its members' caches only memoize): the pair of
    ``cases/spiral_bevel_nominal.toml`` as ``build_pair`` makes it, the blank data of
    ``SpiralBevelPair.design()`` but the module as the case file writes it (4.941634 mm for
    25.4/5.14, 5e-8 relative). The synthesis (10-25 s: the third-order roll is tuned on the
    unloaded TE) is made once per process and shared with every spiral bevel case run in it
    (the artefact cache and ``build_pair``'s memo), not made a second time for the exact
    module."""
    from fegear.case_files import load_case
    from fegear.pipeline.pair import build_pair

    case = load_case(Path(__file__).resolve().parents[1] / "cases" / "spiral_bevel_nominal.toml")
    return build_pair(case).spiral_bevel


@pytest.fixture(scope="session")
def hypoid_pair():
    """The hypoid pair of ``cases/hypoid_nominal.toml`` as ``build_pair`` makes it (10/41,
    offset 25 mm): one synthesis per process, shared with every hypoid case run in it."""
    from fegear.case_files import load_case
    from fegear.pipeline.pair import build_pair

    case = load_case(Path(__file__).resolve().parents[1] / "cases" / "hypoid_nominal.toml")
    return build_pair(case).spiral_bevel
