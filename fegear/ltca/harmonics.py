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
``n_positions`` of 25 or more.

A series with positions left out (lost contact, degenerate) is no longer uniformly sampled. Its
harmonics are fitted by least squares on the ``m`` usable positions: the truncated Fourier
series ``c_0 + Σ_{k=1}^{K} (a_k cos kω_i + b_k sin kω_i)``, ``A_k = √(a_k² + b_k²)``. On a
full uniform cycle the Fourier columns are orthogonal and the fit returns the DFT's amplitudes
exactly (any ``K < n/2``), so both paths agree where both apply. With gaps, the fit takes the
largest ``K ≤ (n − 1)/2`` whose design matrix ``X`` keeps ``cond(X) ≤`` :data:`MAX_COND`
(the orders above ``K`` leak into the fitted ones by at most about that factor times their own
amplitude), and needs at least :data:`MIN_USABLE` of the cycle usable ("enough of the cycle"):
one degenerate hand-over position out of 25 leaves 24, and the amplitudes are read from them,
with ``positions_used`` saying so, instead of being dropped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["MAX_COND", "MIN_USABLE", "MeshOrders", "mesh_orders"]

#: The least share of a cycle's positions that must be usable for its harmonics (module
#: docstring); below it a gap spans more than a quarter of the mesh period and the higher
#: orders are not determined by the positions left.
MIN_USABLE = 0.75
#: The largest condition number of the least-squares Fourier fit of a gappy series.
MAX_COND = 10.0


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
    positions_used: int = 0
    positions: int = 0

    def as_dict(self) -> dict[str, object]:
        return {
            "orders": list(self.orders),
            "amplitude_arcsec": list(self.amplitude_arcsec),
            "reason": self.reason,
            "positions_used": self.positions_used,
            "positions": self.positions,
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
        ``(n,)`` bool, the positions whose TE is a TE (default: all); the others are left out
        and the amplitudes fitted on the rest (module docstring).
    n_orders
        How many mesh orders (1 … n_orders).
    """
    te = np.asarray(te_arcsec, dtype=float)
    orders = tuple(range(1, n_orders + 1))
    n = te.size
    ok = np.ones(n, bool) if usable is None else np.asarray(usable, dtype=bool).copy()
    ok &= np.isfinite(te)
    m = int(ok.sum())
    if m == 0:
        return MeshOrders(orders, (None,) * n_orders, "no finite TE series", 0, n)
    if m == n:
        spec = np.fft.rfft(te)
        amps: list[float | None] = []
        for k in orders:
            amps.append(float(2.0 * abs(spec[k]) / n) if n > 2 * k else None)
        why = "" if all(a is not None for a in amps) else (
            f"{n} positions resolve mesh orders below {n / 2:g} only (n > 2k)"
        )  # fmt: skip
        return MeshOrders(orders, tuple(amps), why, n, n)
    left = f"{n - m} of {n} positions left out (lost or degenerate)"
    if m < MIN_USABLE * n:
        why = f"{left}: fewer than {100 * MIN_USABLE:g} % of the cycle usable"
        return MeshOrders(orders, (None,) * n_orders, why, m, n)
    w = 2.0 * np.pi * np.flatnonzero(ok) / n
    fit = None
    for K in range((n - 1) // 2, 0, -1):
        if 2 * K + 1 > m:
            continue
        k = np.arange(1, K + 1)
        X = np.hstack([np.ones((m, 1)), np.cos(np.outer(w, k)), np.sin(np.outer(w, k))])
        if np.linalg.cond(X) <= MAX_COND:
            coef = np.linalg.lstsq(X, te[ok], rcond=None)[0]
            fit = (K, np.hypot(coef[1 : K + 1], coef[K + 1 :]))
            break
    if fit is None:
        why = f"{left}: no well-conditioned Fourier fit (cond > {MAX_COND:g})"
        return MeshOrders(orders, (None,) * n_orders, why, m, n)
    K, amp = fit
    amps = [float(amp[k - 1]) if k <= K else None for k in orders]
    why = "" if all(a is not None for a in amps) else (
        f"{left}: the positions left determine mesh orders up to {K} only (cond ≤ {MAX_COND:g})"
    )  # fmt: skip
    return MeshOrders(orders, tuple(amps), why, m, n)
