"""JSON records shared by the writers: software versions and the contact solver's residuals."""

from __future__ import annotations

import importlib.metadata
import platform

from fegear.mechanics.contact import ContactSolution

__all__ = ["solver_record", "versions"]

#: Recorded in every summary; ``pyvista`` (extra ``view``) and ``mkl`` (x86-64 only) may be
#: absent: ``"not installed"``.
_PACKAGES = ("fegear", "numpy", "scipy", "scikit-fem", "gmsh", "meshio", "pyvista", "matplotlib",
             "mkl")  # fmt: skip


def versions() -> dict[str, str]:
    """Python and package versions of this run (``"not installed"`` where absent: the optional
    extras)."""
    out = {"python": platform.python_version()}
    for pkg in _PACKAGES:
        try:
            out[pkg] = importlib.metadata.version(pkg)
        except importlib.metadata.PackageNotFoundError:
            out[pkg] = "not installed"
    return out


def solver_record(s: ContactSolution) -> dict[str, float | int]:
    """Iterations and residuals of one contact solution (mm, N)."""
    return {
        "iterations": s.iterations,
        "equilibrium_residual": s.equilibrium_residual,
        "complementarity_residual": s.complementarity_residual,
        "max_penetration_mm": s.max_penetration,
        "min_active_force_N": s.min_active_force,
    }
