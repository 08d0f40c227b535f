"""The unloaded contact path of one tooth pair over its whole contact interval.

All teeth of a member are alike, so pair ``m`` at pinion angle ``φ1`` is pair 0 at
``ψ = φ1 − m τ1`` (``τ1 = 2π/N1``; pinion tooth ``k = −s1 m`` sits at ``s1(φ1 − m τ1)`` and gear
tooth ``j = −s2 m`` at ``s2(φ2 − m τ2)``, ``φ2 = (N1/N2) φ1``): the positions of one cycle with
pairs ``m ∈ {−1, 0, 1}`` sample pair 0 over three cycles. Pair 0 is *in contact* at ``ψ`` when its
closing rotation is the smallest of all pairs (within ``tol_rad``: conjugate pairs tie) and its
contact point is on neither the tip nor the root (fillet-limit) boundary of either working
surface: a pair that touches only with a tip edge is bridging a gap in the meshing, not carrying
it with its flanks. A face end does not end the interval (a line contact always reaches it, a
localized one runs along it under misalignment; it stays flagged as an edge contact), as in
:func:`fegear.tca.engagement.handover`. The contact interval
``[ψ_in, ψ_out]`` is the run of such samples, its ends refined by bisection on the same predicate
(batches of 8 positions per round, 4 rounds: a resolution of ``τ1/n_positions/9⁴``). Then

- the unloaded contact ratio ``ε = (ψ_out − ψ_in)/τ1``: below 1 the pairs cannot hand the load
  over with their working surfaces,
- the path: pair 0's contact points on the gear (member 2) flank, in the gear frame, over the
  interval; its length is the polyline length through the samples and the two ends (a line
  contact's path is its mid-face section's, whose length is an arc length independent of the
  samples: :mod:`fegear.tca.line_path`),
- what ends the interval at each end: the edge the pair runs onto (``"gear:tip"``,
  ``"pinion:tip"``, ...) or ``"transfer"`` when another pair takes the contact over first.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fegear.store.cache import cached_file

from ..geometry.transforms import apply_points
from .cached import pair_key
from .core import TCA
from .line_path import line_contact_states, mid_face_path
from .parallel import positions as parallel_positions
from .results import PositionResult

__all__ = ["ContactPath", "cached_contact_path", "contact_path"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ContactPath:
    """Pair 0's unloaded contact over its contact interval.

    Attributes
    ----------
    phi_start, phi_end
        rad, pinion angles bounding the interval (pair 0's own angle ``ψ``).
    contact_ratio
        ``(phi_end − phi_start) N1 / 2π``.
    length_mm
        Length of the path on the gear flank (mm).
    phi
        ``(n,)`` rad, the samples of the path (ends included), ascending.
    gear_points, pinion_points
        ``(n, 3)`` mm, the contact points on gear tooth 0 (gear member frame) and pinion tooth
        0 (pinion member frame).
    fixed_points
        ``(n, 3)`` mm, the contact points in the fixed frame (the path of contact in space;
        for a spur involute pinion it lies in the plane of action and its transverse extent is
        ``r_b1 (phi_end − phi_start)``).
    gear_uv, pinion_uv
        ``(n, 2)`` the same in flank coordinates.
    start_limit, end_limit
        What ends the interval: the edge tags of the pair just outside it (``"gear:tip"``,
        ``"pinion:tip,pinion:v_start"``, ...) or ``"transfer"``.
    """

    phi_start: float
    phi_end: float
    contact_ratio: float
    length_mm: float
    phi: Array
    gear_points: Array
    pinion_points: Array
    fixed_points: Array
    gear_uv: Array
    pinion_uv: Array
    start_limit: str
    end_limit: str


@dataclass(frozen=True)
class _Sample:
    psi: float
    inside: bool
    edge: str
    uv1: Array
    uv2: Array


def _samples(tca: TCA, pos: PositionResult, tol_rad: float) -> list[_Sample]:
    """Pair 0 at ``ψ = φ1 − m τ1`` for every pair ``m`` of a position."""
    tau = 2 * np.pi / tca.asm.n1
    m = -tca.asm.sense1 * tca.pairs[:, 0]
    out = []
    for i in range(len(m)):
        ok = bool(pos.has_contact and pos.pair_valid[i])
        tags = [t for t in pos.edge[i].split(",") if t] if ok else []
        profile = any(t.endswith(":tip") or t.endswith(":root") for t in tags)
        inside = ok and pos.backlash_rad[i] <= tol_rad and not profile
        out.append(
            _Sample(
                psi=float(pos.phi1 - m[i] * tau),
                inside=inside,
                edge=pos.edge[i] if ok and pos.backlash_rad[i] <= tol_rad else "transfer",
                uv1=np.asarray(pos.pinion_uv[i], float),
                uv2=np.asarray(pos.gear_uv[i], float),
            )
        )
    return out


def _as_line(tca: TCA, samples: list[_Sample], tol_rad: float) -> list[_Sample]:
    """The samples of a line contact, in contact by the line's sections and not by the TCA's
    point (:func:`fegear.tca.line_path.line_contact_states`)."""
    if not samples:
        return samples
    psi = np.array([x.psi for x in samples])
    uv1 = np.array([x.uv1 for x in samples])
    inside, edge = line_contact_states(tca, psi, uv1, tol_rad)
    out = []
    for x, ok, e in zip(samples, inside, edge, strict=True):
        tied = x.edge != "transfer"  # pair 0 closes first (another pair has not taken over)
        out.append(_Sample(x.psi, tied and bool(ok), e if tied else "transfer", x.uv1, x.uv2))
    return out


def _evaluate(
    tca: TCA, psi: Array, tol_rad: float, workers: int | None, line: bool = False
) -> list[_Sample]:
    """Pair-0 samples at angles ``psi`` (each solved at ``φ1`` in the central cycle, all pairs;
    in up to ``workers`` processes: :func:`fegear.tca.parallel.positions`); ``line``: of a line
    contact (:func:`_as_line`)."""
    tau = 2 * np.pi / tca.asm.n1
    m_of = -tca.asm.sense1 * tca.pairs[:, 0]
    shift = np.round(np.asarray(psi) / tau)
    shift = np.clip(-shift, m_of.min(), m_of.max())
    phi1 = np.asarray(psi) + shift * tau
    out = []
    done = parallel_positions(tca, phi1, with_grids=False, ellipses=False, workers=workers)
    for p, s in zip(done, shift, strict=True):
        i = int(np.flatnonzero(m_of == s)[0])
        out.append(_samples(tca, p, tol_rad)[i])
    return _as_line(tca, out, tol_rad) if line else out


def _refine(
    tca: TCA,
    brackets: list[tuple[_Sample, _Sample]],
    tol_rad: float,
    rounds: int,
    workers: int | None,
    line: bool = False,
) -> list[tuple[_Sample, _Sample]]:
    """Brackets ``(a, b)`` (``a`` inside, ``b`` outside) shrunk by batched bisection, 8 inner
    points per bracket and round, the points of all brackets in one batch of positions (each
    position is independent of its batch: the brackets come out as refined one by one)."""
    brackets = list(brackets)
    for _ in range(rounds):
        psi = [np.linspace(a.psi, b.psi, 10)[1:-1] for a, b in brackets]
        flat = _evaluate(tca, np.concatenate(psi), tol_rad, workers, line) if psi else []
        for j, (a, b) in enumerate(brackets):
            s = flat[8 * j : 8 * j + 8]
            ins = [x.inside for x in s]
            k = ins.index(False) if False in ins else len(s)
            brackets[j] = (s[k - 1] if k > 0 else a, s[k] if k < len(s) else b)
    return brackets


def contact_path(
    tca: TCA, positions: list[PositionResult] | tuple[PositionResult, ...],
    tol_rad: float = 1e-9, rounds: int = 4, workers: int | None = None,
) -> ContactPath | None:  # fmt: skip
    """Pair 0's contact interval and path from the positions of one cycle (see module docstring).

    Parameters
    ----------
    tca
        The TCA that produced ``positions`` (its flank maps refine the ends).
    positions
        TCA positions over one mesh cycle (pairs ``m = −1, 0, 1`` at least).
    tol_rad
        A pair within ``tol_rad`` of the smallest closing rotation is in contact (1e-9 rad:
        0.5 nm at a 500 mm radius; conjugate pairs tie to ~1e-12 rad).
    rounds
        Bisection rounds per end (8 positions each; both ends in one batch).
    workers
        Processes for the positions of the ends (:func:`fegear.tca.parallel.positions`).

    Returns
    -------
    ContactPath, or None if pair 0 is never in interior contact.
    """
    s = sorted((x for p in positions for x in _samples(tca, p, tol_rad)), key=lambda x: x.psi)
    line = any(p.ellipse is not None and p.ellipse.line_contact for p in positions)
    if line:
        s = _as_line(tca, s, tol_rad)
    inside = np.array([x.inside for x in s])
    if not inside.any():
        return None
    # the run of inside samples around the one nearest ψ = 0
    idx = np.flatnonzero(inside)
    k0 = int(idx[np.argmin(np.abs([s[i].psi for i in idx]))])
    lo = k0
    while lo > 0 and inside[lo - 1]:
        lo -= 1
    hi = k0
    while hi < len(s) - 1 and inside[hi + 1]:
        hi += 1
    run = s[lo : hi + 1]
    ends = ([(s[lo], s[lo - 1])] if lo > 0 else []) + (
        [(s[hi], s[hi + 1])] if hi < len(s) - 1 else []
    )
    refined = _refine(tca, ends, tol_rad, rounds, workers, line)
    start_limit = end_limit = "unresolved (the interval reaches past the cycle's pairs)"
    if lo > 0:
        start, before = refined.pop(0)
        run = [start] + run
        start_limit = before.edge or "transfer"
    if hi < len(s) - 1:
        end, after = refined.pop(0)
        run = run + [end]
        end_limit = after.edge or "transfer"
    phi = np.array([x.psi for x in run])
    uv1 = np.array([x.uv1 for x in run])
    uv2 = np.array([x.uv2 for x in run])
    phi_start, phi_end = float(phi[0]), float(phi[-1])
    mid = None
    if line:
        # a line contact touches along a line across the face: the TCA's point is anywhere on
        # it; the path is the mid-face section's (fegear.tca.line_path)
        mid = mid_face_path(tca, phi, uv1, tol_rad)
        if mid is not None:
            phi, uv1, uv2 = mid.phi, mid.pinion_uv, mid.gear_uv
    g = tca.fm2.evaluate(*tca.fm2.native(uv2[:, 0], uv2[:, 1]))[0]
    p = tca.fm1.evaluate(*tca.fm1.native(uv1[:, 0], uv1[:, 1]))[0]
    length = (
        mid.length_mm
        if mid is not None
        else float(np.linalg.norm(np.diff(g, axis=0), axis=1).sum())
    )
    fixed = apply_points(tca.asm.placement1(phi), p)
    tau = 2 * np.pi / tca.asm.n1
    return ContactPath(
        phi_start=phi_start,
        phi_end=phi_end,
        contact_ratio=float((phi_end - phi_start) / tau),
        length_mm=length,
        phi=phi,
        gear_points=g,
        pinion_points=p,
        fixed_points=fixed,
        gear_uv=uv2,
        pinion_uv=uv1,
        start_limit=start_limit,
        end_limit=end_limit,
    )


def cached_contact_path(
    pinion, gear, assembly, options, tca: TCA, positions, workers: int | None = None
) -> ContactPath | None:
    """:func:`contact_path` of the pair, read from the artefact cache when the same pair
    (members, assembly with its errors, TCA options, the positions' angles) was traced before
    (seed face gear ~1.8 s otherwise). ``workers``: as :func:`contact_path`."""
    phi1 = np.array([p.phi1 for p in positions], dtype=float)
    params = {**pair_key(pinion, gear, assembly, options), "phi1": phi1}
    box: dict[str, ContactPath | None] = {}
    arrays = ("phi", "gear_points", "pinion_points", "fixed_points", "gear_uv", "pinion_uv")

    def build(path) -> None:
        cp = box["cp"] = contact_path(tca, positions, workers=workers)
        with open(path, "wb") as fh:
            if cp is None:
                np.savez(fh, none=np.array(True))
            else:
                np.savez(
                    fh,
                    none=np.array(False),
                    scalars=np.array([cp.phi_start, cp.phi_end, cp.contact_ratio, cp.length_mm]),
                    limits=np.array([cp.start_limit, cp.end_limit]),
                    **{k: getattr(cp, k) for k in arrays},
                )

    path, hit = cached_file("contact_path", params, ".npz", build)
    if not hit:
        return box["cp"]
    with np.load(path, allow_pickle=False) as z:
        if bool(z["none"]):
            return None
        s, lim = z["scalars"], z["limits"]
        return ContactPath(
            phi_start=float(s[0]),
            phi_end=float(s[1]),
            contact_ratio=float(s[2]),
            length_mm=float(s[3]),
            start_limit=str(lim[0]),
            end_limit=str(lim[1]),
            **{k: z[k] for k in arrays},
        )
