r"""Amplitudes of the mesh orders of a transmission-error series over one mesh cycle.

The positions of a cycle are uniformly spaced over one mesh period, ``φ1_i = φ1_0 + i·2π/(N1 n)``
(``i = 0 … n−1``, the end excluded), so the TE is sampled over exactly one period of the mesh
frequency and its discrete Fourier coefficients are the mesh orders (Smith, *Gear Noise and
Vibration*, 2003, ch. 2; the mesh order ``k`` is ``k N1`` orders of the pinion):

.. math:: A_k = \frac{2}{n}\left|\sum_{i=0}^{n-1} TE_i\, e^{-2\pi \mathrm{i}\, k i/n}\right|,
          \qquad k = 1, 2, 3,

the amplitude (half the peak-to-peak) of the ``k``-th mesh harmonic. A harmonic ``k`` needs
``n > 2k`` positions (Nyquist); the amplitudes of higher mesh orders present in the TE alias
onto the lower ones when ``n`` is small (the coarse cycles of the tests: 9 positions resolve
orders 1-4, and a TE with sharp handovers has content above), so a study of the harmonics takes
``n_positions`` of 25 or more. A series with a position left out (lost contact, degenerate) has
no uniform sampling: its amplitudes are None with the reason.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["MeshOrders", "mesh_orders"]


@dataclass(frozen=True)
class MeshOrders:
    """Amplitudes of the first mesh orders of a TE series.

    Attributes
    ----------
    orders
        The mesh orders ``(1, 2, 3)``.
    amplitude_arcsec
        Per order, ``A_k`` (arcsec), or None where it cannot be read (``reason``).
    reason
        Why an amplitude is None ("" when all are given).
    """

    orders: tuple[int, ...]
    amplitude_arcsec: tuple[float | None, ...]
    reason: str = ""

    def as_dict(self) -> dict[str, object]:
        return {
            "orders": list(self.orders),
            "amplitude_arcsec": list(self.amplitude_arcsec),
            "reason": self.reason,
        }


def mesh_orders(
    te_arcsec: ArrayLike, usable: ArrayLike | None = None, n_orders: int = 3
) -> MeshOrders:
    """The :class:`MeshOrders` of ``te_arcsec`` ``(n,)``, sampled uniformly over one mesh cycle.

    Parameters
    ----------
    te_arcsec
        The TE at the ``n`` positions of the cycle (arcsec).
    usable
        ``(n,)`` bool, the positions whose TE is a TE (default: all); with any False every
        amplitude is None.
    n_orders
        How many mesh orders (1 … n_orders).
    """
    te = np.asarray(te_arcsec, dtype=float)
    orders = tuple(range(1, n_orders + 1))
    n = te.size
    if usable is not None and not np.all(usable):
        bad = int(np.sum(~np.asarray(usable, dtype=bool)))
        why = f"{bad} of {n} positions left out (lost or degenerate): no uniform sampling"
        return MeshOrders(orders, (None,) * n_orders, why)
    if n == 0 or not np.all(np.isfinite(te)):
        return MeshOrders(orders, (None,) * n_orders, "no finite TE series")
    spec = np.fft.rfft(te)
    amps: list[float | None] = []
    for k in orders:
        amps.append(float(2.0 * abs(spec[k]) / n) if n > 2 * k else None)
    why = "" if all(a is not None for a in amps) else (
        f"{n} positions resolve mesh orders below {n / 2:g} only (n > 2k)"
    )  # fmt: skip
    return MeshOrders(orders, tuple(amps), why)
