"""Option objects shared by the case files and the layers that use them.

:class:`ContactOptions` is the tuning of the loaded contact models: the ``[contact]`` section of
a gear case produces it (:mod:`fegear.io.gear_case`, whose key declarations take their defaults
from here) and :class:`fegear.ltca.LTCAOptions` carries it to the contact grids. It lives at the
bottom of the package (it imports only :mod:`fegear.errors`) so that the case-file layer and
the model layers share one declaration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

from fegear.errors import InputError

__all__ = ["ContactOptions"]


def _positive_int(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 1


def _positive(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and value > 0


@dataclass(frozen=True)
class ContactOptions:
    """Tuning of the loaded contact models (defaults: the measured choices of ``docs/fidelity.md``).

    Attributes
    ----------
    g_max_mm
        Contact cells are laid where the unloaded separation is below ``g_max`` (mm); it is
        doubled while a left-out cell could close under the solved lag, so it only sets where
        the search starts.
    cell_mm
        Contact-cell size (mm); None: the fine element size of the sector meshes.
    n_across, n_along
        ``hybrid``: cells across the minor and along the major axis of every loaded patch
        after refinement.
    max_cells
        ``hybrid``: cap on the cells of one pair.
    trim
        ``hybrid``: cells whose loaded gap, predicted from the neighbouring position, exceeds
        ``trim θ h_max`` are left out of the solve (0: keep every cell); a trimmed solve is
        accepted only if the ring of left-out cells stays open.
    depth_elements, depth_max_modules
        ``hybrid``: depth of the matching layer, ``min(depth_elements · h, depth_max_modules ·
        m)`` (``h`` the fine element size, ``m`` the module).
    tca_grid
        ``(nu, nv)`` cells of the TCA separation field the contact zone is found on.
    chunk_positions
        Positions solved in sequence by one worker (each from its predecessor).
    """

    g_max_mm: float = 0.02
    cell_mm: float | None = None
    n_across: int = 8
    n_along: int = 16
    max_cells: int = 600
    trim: float = 0.3
    depth_elements: float = 2.0
    depth_max_modules: float = 0.35
    tca_grid: tuple[int, int] = (24, 12)
    chunk_positions: int = 7

    def __post_init__(self) -> None:
        for name in ("n_across", "n_along", "max_cells", "chunk_positions"):
            if not _positive_int(getattr(self, name)):
                raise InputError(name, getattr(self, name), "an integer >= 1")
        for name in ("g_max_mm", "depth_elements", "depth_max_modules"):
            if not _positive(getattr(self, name)) or not math.isfinite(getattr(self, name)):
                raise InputError(name, getattr(self, name), "a finite number > 0")
        if self.cell_mm is not None and not (
            _positive(self.cell_mm) and math.isfinite(self.cell_mm)
        ):
            raise InputError("cell_mm", self.cell_mm, "a finite number > 0, or None (automatic)")
        if not (isinstance(self.trim, int | float) and math.isfinite(self.trim) and self.trim >= 0):
            raise InputError("trim", self.trim, "a finite number >= 0 (0: keep every cell)")
        g = self.tca_grid
        if not (len(g) == 2 and all(isinstance(n, int) and n >= 2 for n in g)):
            raise InputError("tca_grid", g, "two integers >= 2 (nu, nv)")

    @classmethod
    def names(cls) -> tuple[str, ...]:
        """The option names, in declaration order."""
        return tuple(f.name for f in fields(cls))

    @classmethod
    def default(cls, name: str) -> Any:
        """The default of option ``name``."""
        return next(f.default for f in fields(cls) if f.name == name)

    def as_dict(self) -> dict[str, Any]:
        """Every option by name (the pair ``tca_grid`` as a tuple)."""
        return {n: getattr(self, n) for n in self.names()}

    def given(self) -> dict[str, Any]:
        """The options that differ from their defaults, as case-file values (lists for pairs)."""
        return {
            n: list(v) if isinstance(v, tuple) else v
            for n, v in self.as_dict().items()
            if v != self.default(n)
        }
