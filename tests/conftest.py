"""Shared test set-up: a private, cold artefact cache and a fixed number of BLAS threads."""

from __future__ import annotations

import os

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


@pytest.fixture(scope="session", autouse=True)
def fegear_cache(tmp_path_factory: pytest.TempPathFactory):
    """Point ``$FEGEAR_CACHE`` at a fresh folder: tests start cold and never touch the repo's
    ``meshes/cache``. Restored at the end of the session."""
    root = tmp_path_factory.mktemp("fegear_cache")
    old = os.environ.get("FEGEAR_CACHE")
    os.environ["FEGEAR_CACHE"] = str(root)
    yield root
    if old is None:
        os.environ.pop("FEGEAR_CACHE", None)
    else:
        os.environ["FEGEAR_CACHE"] = old
