r"""Line loads, the face load factor KHβ and the mesh stiffness of a loaded cylindrical pair.

What ISO 6336 users read first, from the converged contact forces of a loaded cycle
(:class:`~fegear.ltca.results.LoadedCycle` of a fidelity with contact cells: ``fe``,
``hybrid``). Units: N, mm; stiffness in N/(mm·µm) as ISO writes it.

*Face-width distribution.* Each contact cell is a parallelogram on the pinion flank (centre,
edge vectors); its normal force is spread uniformly over it and collected in ``n`` bins of the
common face width ``b`` by the axial position ``z``: the load per unit face width ``q(z)``
(N/mm) of a position, all pairs together, and ``q_j(z)`` of each pair. A bin takes the part of
each cell's force whose ``z`` falls in it, integrated exactly (:func:`cell_bin_fractions`: the
``z`` of a uniform parallelogram is the sum of two uniform variables, a trapezoid); the part of
a cell overhanging a face end is given to its part on the face (the force acts on the flank).
So ``Σ q Δz`` is the position's total normal force ``F_n``, and a distribution does not depend
on where the cell edges fall in the bins (a 5 × 5 sample of each cell, cells of 0.7 mm and bins
of 0.875 mm on FZG, gave a bin 6 or 7 samples of a cell: ±8 % of a cell's share, depending on
the phase of the grid). For an unmodified pair every normal is tangent to the base
cylinder at the base helix angle, so ``F_n = T_2 / (r_{b2} \cos β_b)`` (the solver balances the
torque with the moment arms of the cells).

*Line load along a contact line.* A contact line crosses the face at the base helix angle
``β_b``: the load per unit length of the line of pair ``j`` is ``w_j = q_j \cos β_b`` at the
distance ``s = (z − z_start)/\cos β_b`` along it.

*Face load factor* (ISO 6336-1:2019 §7.1, method A: from the load distribution across the face
width, ``K_{Hβ} = w_{max}/w_m``): per position ``K_{Hβ}(φ) = \max_z q(z) / (F_n/b)``; the
cycle's ``K_{Hβ}`` is that of the mean distribution over the usable positions,
``\bar q(z) = \mathrm{mean}_φ\, q(z)``, ``\max \bar q / \mathrm{mean}\, \bar q``. Its value
depends on the bin width where the distribution has a peak narrower than a bin (an edge): the
bins are given beside it.

*Mesh stiffness* (ISO 6336-1 §9: the load per unit face width along the transverse line of
action over the deflection it causes). The elastic lag ``θ`` of member 2 (rad; the approach
beyond the unloaded closure of the position) is the transverse deflection ``δ = θ r_{b2}``
along the line of action under the transverse force ``F_{bt} = T_2/r_{b2}``:

.. math:: c_γ(φ) = \frac{F_{bt}}{b\,δ} = \frac{T_2}{r_{b2}^2\, b\, θ}, \qquad
          c_γ = \mathrm{mean}_φ\, c_γ(φ), \qquad
          c'_j(φ) = \frac{T_{2,j}/r_{b2}}{b_j\, δ},

the secant stiffness at the run's load (contact flattening is slightly non-linear); ``c'_j`` the
single stiffness of pair ``j`` per unit of the face width ``b_j`` its contact line spans (the
torque ``T_{2,j}`` it carries), ``c'`` the largest over the pairs whose line spans the whole face
(ISO: "the maximum stiffness of one pair of teeth"). With flank modifications the lag includes
closing them, and the secant stiffness is then that of the modified mesh at that load, below
the flanks' own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fegear.tca.contact_lines import contact_line, plane_of_action

__all__ = ["LoadDistribution", "PairLineLoad", "PositionLoad", "load_distribution"]

Array = NDArray[np.float64]
#: Bins of the face width (a 14 mm FZG face: 0.875 mm, about one ``hybrid`` cell along a line).
N_BINS = 16


@dataclass(frozen=True)
class PairLineLoad:
    """One pair's load along its contact line at one position.

    Attributes
    ----------
    k, j
        Pinion and gear tooth.
    force_N, torque_Nmm
        Its normal force and its torque on member 2.
    q_N_per_mm
        ``(n_bins,)`` its load per unit face width in the bins.
    s_mm, w_N_per_mm
        ``(n_bins,)`` the same along the contact line: distance from the line's start at the
        first face end, and the load per unit length of the line.
    span_mm
        Axial extent ``b_j`` of its (unloaded, nominal) contact line.
    c_prime
        Its single stiffness ``c'_j`` (N/(mm·µm)), None where the pair carries nothing.
    """

    k: int
    j: int
    force_N: float
    torque_Nmm: float
    q_N_per_mm: Array
    s_mm: Array
    w_N_per_mm: Array
    span_mm: float
    c_prime: float | None


@dataclass(frozen=True)
class PositionLoad:
    """The face-width load of one position.

    Attributes
    ----------
    q_N_per_mm
        ``(n_bins,)`` load per unit face width, all pairs.
    force_N
        Total normal force ``Σ q Δz``.
    k_h_beta
        ``max q / (F_n / b)``.
    mesh_stiffness
        ``c_γ(φ)`` (N/(mm·µm)), None without an elastic lag.
    pairs
        The :class:`PairLineLoad` of each loaded pair.
    usable
        The position is ``ok`` (not lost or degenerate).
    """

    q_N_per_mm: Array
    force_N: float
    k_h_beta: float | None
    mesh_stiffness: float | None
    pairs: tuple[PairLineLoad, ...]
    usable: bool


@dataclass(frozen=True)
class LoadDistribution:
    """Line loads, KHβ and mesh stiffness over a loaded cycle (module docstring).

    Attributes
    ----------
    z_mm
        ``(n_bins,)`` bin centres over the common face (fixed frame ``z``), ``dz_mm`` their width.
    face_mm
        Common face width ``b``.
    beta_b_deg
        Base helix angle.
    positions
        :class:`PositionLoad` per position.
    q_mean_N_per_mm
        ``(n_bins,)`` mean distribution over the usable positions (NaN without one;
        ``summary.json``: null, with the reason).
    k_h_beta
        Cycle KHβ (of the mean distribution), None without usable positions.
    k_h_beta_max
        The largest per-position KHβ and the position index where it is.
    c_gamma, c_prime
        Mean mesh stiffness and the largest full-face single stiffness (N/(mm·µm)).
    normal_force_N
        ``T_2/(r_b2 cos β_b)``: the normal force of unmodified flanks.
    reason
        Why values are None ("" when given).
    """

    z_mm: Array
    dz_mm: float
    face_mm: float
    beta_b_deg: float
    positions: tuple[PositionLoad, ...]
    q_mean_N_per_mm: Array
    k_h_beta: float | None
    k_h_beta_max: tuple[float, int] | None
    c_gamma: float | None
    c_prime: float | None
    normal_force_N: float
    reason: str = ""

    def as_dict(self) -> dict[str, object]:
        """JSON-ready (summary.json ``cylindrical.load``)."""

        def f(x):
            return None if x is None else float(x)

        return {
            "face_width_mm": self.face_mm,
            "bins_z_mm": self.z_mm.tolist(),
            "bin_width_mm": self.dz_mm,
            "base_helix_angle_deg": self.beta_b_deg,
            "k_h_beta": f(self.k_h_beta),
            "k_h_beta_definition": "max/mean of the face-width load distribution averaged "
            "over the usable positions (ISO 6336-1 method A); per position in positions[]",
            "k_h_beta_max_position": None
            if self.k_h_beta_max is None
            else {"value": self.k_h_beta_max[0], "position": self.k_h_beta_max[1]},
            "q_mean_N_per_mm": None if self.k_h_beta is None else self.q_mean_N_per_mm.tolist(),
            "c_gamma_N_per_mm_um": f(self.c_gamma),
            "c_gamma_definition": "mean mesh stiffness (ISO 6336-1 §9): the mean over the "
            "usable positions of the secant c_γ(φ) = T2/(r_b2² b θ), θ the elastic lag of the "
            "gear beyond the unloaded closure (transverse force over face width over the "
            "deflection along the line of action); per position in positions[]",
            "c_prime_N_per_mm_um": f(self.c_prime),
            "c_prime_definition": "single stiffness (ISO 6336-1 §9): the largest, over the "
            "usable positions, of one pair's T2_j/(r_b2² b_j θ), b_j the axial span of its "
            "contact line, among the pairs whose line spans the whole face width",
            "normal_force_unmodified_N": self.normal_force_N,
            "reason": self.reason,
            "positions": [
                {
                    "force_N": p.force_N,
                    "k_h_beta": f(p.k_h_beta),
                    "mesh_stiffness_N_per_mm_um": f(p.mesh_stiffness),
                    "usable": p.usable,
                    "q_N_per_mm": p.q_N_per_mm.tolist(),
                    "pairs": [
                        {
                            "pinion_tooth": q.k,
                            "gear_tooth": q.j,
                            "force_N": q.force_N,
                            "span_mm": q.span_mm,
                            "c_prime_N_per_mm_um": f(q.c_prime),
                            "s_mm": q.s_mm.tolist(),
                            "w_N_per_mm": q.w_N_per_mm.tolist(),
                        }
                        for q in p.pairs
                    ],
                }
                for p in self.positions
            ],
        }


def _uniform_sum_cdf(x: Array, alpha: Array, beta: Array) -> Array:
    """CDF at ``x`` of ``A + B``, ``A ~ U[−α, α]``, ``B ~ U[−β, β]`` independent (broadcast):

        F(x) = [G(x+α+β) − G(x+α−β) − G(x−α+β) + G(x−α−β)] / (4αβ),  G(t) = max(t, 0)²/2

    (the double integral of the joint density over ``a + b ≤ x``). Where one half-width is
    below 1e-6 of the other, the uniform of the larger: the closed form loses its digits to
    cancellation there (relative error ~ 1e-16 x²/(α x))."""
    lo, hi = np.minimum(alpha, beta), np.maximum(alpha, beta)
    hi = np.maximum(hi, 1e-300)
    thin = lo < 1e-6 * hi
    a = np.where(thin, hi, alpha)
    b = np.where(thin, hi, beta)

    def g(t):
        return 0.5 * np.maximum(t, 0.0) ** 2

    two = (g(x + a + b) - g(x + a - b) - g(x - a + b) + g(x - a - b)) / (4.0 * a * b)
    one = np.clip((x + hi) / (2.0 * hi), 0.0, 1.0)
    return np.clip(np.where(thin, one, two), 0.0, 1.0)


def cell_bin_fractions(center_z: Array, edge_z: Array, edges: Array) -> Array:
    """``(n, n_bins)``: the fraction of each cell's force in each bin ``[edges[k], edges[k+1])``.

    A cell is the parallelogram ``center + s e_1 + t e_2``, ``s, t ∈ [−½, ½]``, its force
    uniform over it, so its ``z`` is the sum of two uniform variables of half-widths
    ``|e_1z|/2`` and ``|e_2z|/2`` (:func:`_uniform_sum_cdf`); a bin takes ``F(z_{k+1}) −
    F(z_k)``. The part outside ``[edges[0], edges[-1]]`` (a cell overhanging a face end) is
    given to the part inside, so each row sums to 1 (a cell wholly outside, which the grid does
    not make, goes to the nearer end bin).

    ``center_z``: ``(n,)``, ``edge_z``: ``(n, 2)`` the ``z`` of the cells' edge vectors,
    ``edges``: ``(n_bins + 1,)`` increasing bin edges (mm).
    """
    x = edges[None, :] - center_z[:, None]
    F = _uniform_sum_cdf(x, 0.5 * np.abs(edge_z[:, :1]), 0.5 * np.abs(edge_z[:, 1:]))
    frac = np.diff(F, axis=1)
    inside = F[:, -1] - F[:, 0]
    out = np.zeros_like(frac)
    ok = inside > 1e-12
    out[ok] = frac[ok] / inside[ok, None]
    end = np.where(center_z[~ok] < 0.5 * (edges[0] + edges[-1]), 0, frac.shape[1] - 1)
    out[np.flatnonzero(~ok), end] = 1.0
    return out


def load_distribution(pinion, gear, assembly, cycle, n_bins: int = N_BINS) -> LoadDistribution:
    """The :class:`LoadDistribution` of a loaded cycle of a cylindrical pair (``assembly``: the
    pair's, for its plane of action and contact lines)."""
    pa = plane_of_action(pinion, gear, assembly)
    z0, z1 = pa.face
    b = z1 - z0
    edges = np.linspace(z0, z1, n_bins + 1)
    dz = b / n_bins
    zc = 0.5 * (edges[1:] + edges[:-1])
    cb = math.cos(pinion.beta_b)
    rb2 = gear.r_b
    tau1 = 2 * math.pi / pinion.n_teeth
    T2 = cycle.torque2_Nmm
    out = []
    reason = ""
    for pos in cycle.positions:
        usable = pos.status == "ok"
        theta = abs(float(pos.theta))
        delta = theta * rb2  # mm
        c_mesh = T2 / rb2 / (b * delta) * 1e-3 if delta > 0 else None
        if not pos.cells:
            out.append(PositionLoad(np.zeros(n_bins), 0.0, None, c_mesh, (), usable))
            continue
        force = pos.solution.force
        start = 0
        pairs = []
        total = np.zeros(n_bins)
        for c, q in zip(pos.cells, pos.pairs, strict=True):
            f = force[start : start + c.n]
            start += c.n
            frac = cell_bin_fractions(c.centers[:, 2], c.edges[:, :, 2], edges)
            qj = (f @ frac) / dz
            total += qj
            if q.force_N <= 0.0:
                continue
            line = contact_line(pinion, gear, assembly.without_errors(), pos.phi1 + c.k * tau1)
            span = max(0.0, line.z_end - line.z_start)
            cj = q.torque_Nmm / rb2 / (span * delta) * 1e-3 if delta > 0 and span > 0 else None
            pairs.append(
                PairLineLoad(
                    k=int(c.k), j=int(c.j), force_N=float(q.force_N),
                    torque_Nmm=float(q.torque_Nmm), q_N_per_mm=qj, s_mm=(zc - z0) / cb,
                    w_N_per_mm=qj * cb, span_mm=span, c_prime=cj,
                )
            )  # fmt: skip
        F = float(np.sum(total) * dz)
        khb = float(total.max() / (F / b)) if F > 0 else None
        out.append(PositionLoad(total, F, khb, c_mesh, tuple(pairs), usable))
    used = [p for p in out if p.usable and p.force_N > 0]
    if not used:
        reason = (
            "no usable position with contact cells (fidelity hertz has none, or every "
            "position is lost or degenerate)"
        )
        q_mean = np.full(n_bins, np.nan)  # no distribution (summary.json: null, reason)
        khb = khb_max = c_g = c_p = None
    else:
        q_mean = np.mean([p.q_N_per_mm for p in used], axis=0)
        khb = float(q_mean.max() / q_mean.mean())
        i_max = max(
            (i for i, p in enumerate(out) if p.usable and p.k_h_beta is not None),
            key=lambda i: out[i].k_h_beta,
        )
        khb_max = (float(out[i_max].k_h_beta), int(i_max))
        cs = [p.mesh_stiffness for p in used if p.mesh_stiffness is not None]
        c_g = float(np.mean(cs)) if cs else None
        full = [q.c_prime for p in used for q in p.pairs
                if q.c_prime is not None and q.span_mm >= b * (1 - 1e-9)]  # fmt: skip
        c_p = max(full) if full else None
    return LoadDistribution(
        z_mm=zc, dz_mm=dz, face_mm=b, beta_b_deg=math.degrees(pinion.beta_b),
        positions=tuple(out), q_mean_N_per_mm=q_mean, k_h_beta=khb, k_h_beta_max=khb_max,
        c_gamma=c_g, c_prime=c_p, normal_force_N=T2 / (rb2 * cb), reason=reason,
    )  # fmt: skip
