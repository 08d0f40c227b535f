"""fegear: finite-element loaded tooth contact analysis.

The Python API (:mod:`fegear.api`)::

    import fegear

    case = fegear.load_case("cases/face_gear_nominal.toml")
    result = fegear.run(case.with_errors(dgamma_deg=0.02), fidelity="tca")
    result.write("out/dgamma")

The names below are imported on first use, so ``import fegear`` stays light.
"""

from __future__ import annotations

import importlib
import logging
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"
__all__ = [
    "__version__",
    "load_case",
    "run",
    "table",
    "plot_te",
    "plot_patterns",
    "GearCase",
    "HertzCase",
    "GearResult",
    "HertzResult",
    "FegearError",
    "InputError",
]

# name -> module that defines it
_LAZY = {
    "load_case": "fegear.api",
    "run": "fegear.api",
    "table": "fegear.api",
    "plot_te": "fegear.api",
    "plot_patterns": "fegear.api",
    "GearResult": "fegear.api",
    "HertzResult": "fegear.api",
    "GearCase": "fegear.io.gear_case",
    "HertzCase": "fegear.scenes.hertz_case",
    "FegearError": "fegear.errors",
    "InputError": "fegear.errors",
}

if TYPE_CHECKING:  # pragma: no cover
    from fegear.api import (
        GearResult,
        HertzResult,
        load_case,
        plot_patterns,
        plot_te,
        run,
        table,
    )
    from fegear.errors import FegearError, InputError
    from fegear.io.gear_case import GearCase
    from fegear.scenes.hertz_case import HertzCase


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'fegear' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


logging.getLogger(__name__).addHandler(logging.NullHandler())
