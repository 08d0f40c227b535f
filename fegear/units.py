"""Units in one place: the torque's, and the transmission error's angle.

fegear computes in mm, N, MPa and rad; torques in N·mm (the product of the mm and the N the
solver works in). Users give and read torques in N·m, and a case file may give the pinion's
torque instead of the gear's (``T2 = T1 · N2/N1``, no friction: ``docs/conventions.md``). Every
conversion of a torque between those goes through this module; the TE is reported in arcsec.
"""

from __future__ import annotations

import math

__all__ = [
    "ARCSEC_PER_RAD",
    "NMM_PER_NM",
    "TORQUE_KEYS",
    "nm_from_nmm",
    "pinion_torque_Nm",
    "torque2_Nmm_from",
]

#: N·mm in one N·m.
NMM_PER_NM = 1000.0
#: Arcseconds in one radian.
ARCSEC_PER_RAD = 180.0 * 3600.0 / math.pi
#: The case-file keys of the load (``[load]``, exactly one of them): the gear's torque in N·m or
#: N·mm, or the pinion's in N·m.
TORQUE_KEYS = ("torque2_Nm", "torque2_Nmm", "pinion_torque_Nm")


def nm_from_nmm(torque_Nmm: float) -> float:
    """A torque in N·m from N·mm."""
    return torque_Nmm / NMM_PER_NM


def pinion_torque_Nm(torque2_Nmm: float, ratio: float) -> float:
    """The pinion's torque (N·m) that balances ``torque2_Nmm`` on the gear, ``ratio = N2/N1``
    (no friction)."""
    return torque2_Nmm / ratio / NMM_PER_NM


def torque2_Nmm_from(key: str, value: float, n1: int, n2: int) -> float:
    """The gear's torque (N·mm) of a case file's load ``key`` (:data:`TORQUE_KEYS`) and value,
    for a pair of ``n1`` pinion and ``n2`` gear teeth.

    Raises
    ------
    KeyError
        ``key`` is not one of :data:`TORQUE_KEYS`.
    """
    return {
        "torque2_Nm": value * NMM_PER_NM,
        "torque2_Nmm": value,
        "pinion_torque_Nm": value * NMM_PER_NM * n2 / n1,
    }[key]
