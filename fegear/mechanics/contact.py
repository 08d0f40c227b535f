"""Active-set solver of the normal contact problem between two elastic bodies.

This module knows nothing about gears. It solves, for the forces ``F`` on ``n`` contact cells and
one rigid-body unknown ``theta`` (a rigid approach in mm for two bodies pressed together, or a
rotation in rad for a gear pair),

.. math::

    d &= g - \\theta\\,h + C F \\ge 0, \\qquad F \\ge 0, \\qquad F_i d_i = 0, \\\\
    h^T F &= T,

where ``g`` (mm) are the initial separations of the cells, ``C`` (mm/N, symmetric positive
definite) the compliance (normal approach of cell ``i`` per unit force on cell ``j``, both bodies
summed), ``h`` the weights of the rigid motion (``h = 1`` for a rigid approach with force balance
``sum F = T``; the moment arms of the cell normals for a rotation with torque balance) and ``T``
the load (N, or N·mm). These are the Karush-Kuhn-Tucker conditions of the strictly convex
quadratic programme

.. math::

    \\min_F \\; \\tfrac12 F^T C F + g^T F \\quad \\text{s.t.} \\quad F \\ge 0,\\; h^T F = T,

whose multiplier of the equality is ``theta`` (Kalker 1990, *Three-dimensional elastic bodies in
rolling contact*, ch. 2; Johnson 1985, *Contact Mechanics*, §5.9).

Algorithm: the primal active-set method of Lawson & Hanson (1974, *Solving Least Squares
Problems*, ch. 23, algorithm NNLS) extended by the one equality. The iterate ``F`` is always
feasible (``F >= 0``, ``h^T F = T``). On the active set ``I`` the equality-constrained problem is
solved exactly (a Cholesky factorisation of ``C_II`` and one scalar for ``theta``); if that solution
has negative forces the iterate moves towards it as far as feasibility allows and the cells that
reach zero leave ``I``; otherwise the cells with negative gap (penetration, i.e. negative gradient
of the objective) join ``I``. Several cells join at once while the objective keeps decreasing; the
first time it does not, the method falls back to adding only the most penetrating cell, which is
Lawson & Hanson's rule: every completed outer step then strictly lowers the objective, no active
set repeats, and the method terminates after finitely many steps. A hard cap on iterations raises
:class:`~fegear.errors.SolverError` (it is a safety net, not part of the algorithm).

Deterministic: no randomness, ties broken by the lowest index, so a repeated run is bit-identical.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from fegear.errors import InputError, SolverError

__all__ = ["ContactSolution", "solve_contact"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ContactSolution:
    """Solution of the contact problem.

    Attributes
    ----------
    force
        (n,) N, force on every cell, ``>= 0``.
    gap
        (n,) mm, gap after loading ``d = g - theta h + C F``; zero (to round-off) on active cells.
    active
        (n,) bool, cells carrying force.
    theta
        The rigid unknown: approach (mm) or rotation (rad).
    iterations
        Outer iterations (solves of the equality-constrained sub-problem).
    equilibrium_residual
        ``|h^T F - T| / |T|``.
    complementarity_residual
        ``max_i |F_i d_i| / (T_scale d_scale)``: relative complementarity.
    max_penetration
        mm, ``max(0, -min d)`` over the inactive cells.
    min_active_force
        N, smallest force on an active cell (no tension means ``>= 0``).
    """

    force: np.ndarray
    gap: np.ndarray
    active: np.ndarray
    theta: float
    iterations: int
    equilibrium_residual: float
    complementarity_residual: float
    max_penetration: float
    min_active_force: float

    @property
    def n_active(self) -> int:
        """Number of cells in contact."""
        return int(np.count_nonzero(self.active))


def _check_inputs(
    compliance: np.ndarray, gap0: np.ndarray, load: float, weights: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    C = np.asarray(compliance, dtype=float)
    g = np.asarray(gap0, dtype=float).ravel()
    h = np.asarray(weights, dtype=float).ravel()
    n = g.size
    if n == 0:
        raise InputError("gap0", "[]", "at least one contact cell")
    if C.shape != (n, n):
        raise InputError("compliance", f"shape {C.shape}", f"shape ({n}, {n}) matching gap0")
    if h.shape != (n,):
        raise InputError("weights", f"shape {h.shape}", f"shape ({n},) matching gap0")
    for name, arr in (("compliance", C), ("gap0", g), ("weights", h)):
        if not np.all(np.isfinite(arr)):
            raise InputError(name, "non-finite entries", "finite numbers")
    if not np.isfinite(load) or load <= 0.0:
        raise InputError("load", load, "a finite number > 0")
    if np.any(h <= 0.0):
        raise InputError("weights", f"min {h.min():.3g}", "> 0 on every cell")
    if np.any(np.diag(C) <= 0.0):
        raise InputError("compliance", "non-positive diagonal", "symmetric positive definite")
    return C, g, h


def _subproblem(
    C: np.ndarray, g: np.ndarray, h: np.ndarray, load: float, idx: np.ndarray
) -> tuple[np.ndarray, float]:
    """Equality-constrained minimiser on the active set ``idx``.

    With ``C_II F_I = theta h_I - g_I`` and ``h_I^T F_I = T``: let ``x = C_II^{-1} h_I`` and
    ``y = -C_II^{-1} g_I``; then ``theta = (T - h_I^T y) / (h_I^T x)`` and ``F_I = theta x + y``.
    """
    Cii = C[np.ix_(idx, idx)]
    try:
        cf = scipy.linalg.cho_factor(Cii, lower=True, check_finite=False)
    except np.linalg.LinAlgError as exc:
        raise SolverError(
            f"compliance block of {idx.size} active cells is not positive definite: {exc}"
        ) from exc
    rhs = np.column_stack([h[idx], -g[idx]])
    sol = scipy.linalg.cho_solve(cf, rhs, check_finite=False)
    x, y = sol[:, 0], sol[:, 1]
    hx = h[idx] @ x
    theta = (load - h[idx] @ y) / hx
    z = theta * x + y
    # theta x + y cancels when |y| >> |z| (gap offsets >> C T, ill-conditioned C_II): one
    # refinement step along x restores h^T z = T and leaves d_I = g_I - theta h_I + C_II z unchanged
    delta = (load - h[idx] @ z) / hx
    return z + delta * x, float(theta + delta)


def _objective(C: np.ndarray, g: np.ndarray, F: np.ndarray) -> float:
    nz = np.flatnonzero(F)
    Fn = F[nz]
    return float(0.5 * Fn @ (C[np.ix_(nz, nz)] @ Fn) + g[nz] @ Fn)


def solve_contact(
    compliance: np.ndarray,
    gap0: np.ndarray,
    load: float,
    weights: np.ndarray | None = None,
    *,
    penetration_tol: float | None = None,
    max_iterations: int | None = None,
    active_guess: np.ndarray | None = None,
) -> ContactSolution:
    """Solve the normal contact problem (see the module docstring).

    Parameters
    ----------
    compliance
        (n, n) mm/N, symmetric positive definite influence matrix of the cells.
    gap0
        (n,) mm, initial separations (may be negative for an initial overlap; only differences
        matter because ``theta`` absorbs a constant when ``weights`` are uniform).
    load
        Total force ``sum h_i F_i`` to transmit (N, or N·mm for a torque), ``> 0``.
    weights
        (n,) ``h``, positive weights of the rigid unknown; ``None`` means all ones (force balance).
    penetration_tol
        mm; inactive cells with gap above ``-penetration_tol`` are accepted. Default: ``1e-12`` of
        the scale of the problem ``max(|theta| max h, max g - min g, mean diag(C) T)``.
    max_iterations
        Safety cap; default ``10 n + 100``.
    active_guess
        (n,) bool, optional guess of the cells in contact (e.g. from a neighbouring solution). The
        iterate still starts feasible from the single closest cell, but the first sub-problem is
        solved on the guess together with it: cells of the guess that get no force leave at once
        (a step of length zero), so a good guess saves most of the outer iterations and a bad one
        costs one factorisation. The solution does not depend on it (the problem is strictly
        convex).

    Returns
    -------
    ContactSolution
    """
    h_in = np.ones(np.asarray(gap0).size) if weights is None else weights
    C, g, h = _check_inputs(compliance, gap0, float(load), h_in)
    n = g.size
    T = float(load)
    max_it = 10 * n + 100 if max_iterations is None else int(max_iterations)
    disp_scale = max(float(np.ptp(g)), float(np.mean(np.diag(C))) * T, 1e-300)

    # Feasible start: the whole load on the cell that is closest in the sense of the rigid motion
    # (smallest gap per unit weight), as in a rigid-body contact.
    start = int(np.argmin(g / h))
    F = np.zeros(n)
    F[start] = T / h[start]
    active = np.zeros(n, dtype=bool)
    active[start] = True
    if active_guess is not None:
        guess = np.asarray(active_guess, dtype=bool).ravel()
        if guess.shape != (n,):
            raise InputError("active_guess", f"shape {guess.shape}", f"shape ({n},)")
        active |= guess
    theta = 0.0
    single_add = False
    f_prev = np.inf  # objective after the previous outer step
    it = 0
    while True:
        # Inner loop: move towards the sub-problem solution on the active set, keeping F >= 0.
        while True:
            it += 1
            if it > max_it:
                raise SolverError(f"contact solver did not terminate in {max_it} iterations")
            idx = np.flatnonzero(active)
            z, theta = _subproblem(C, g, h, T, idx)
            if np.all(z > 0.0):
                F = np.zeros(n)
                F[idx] = z
                break
            # Largest step alpha in [0, 1) from F towards z with F + alpha (z - F) >= 0.
            Fi = F[idx]
            neg = z <= 0.0
            # ratio test; a cell with F = 0 (just added) and z <= 0 blocks at once (alpha = 0),
            # without the 0/0 of F = z = 0
            ratio = np.full(idx.size, np.inf)
            blocking = neg & (Fi - z > 0.0)
            ratio[blocking] = Fi[blocking] / (Fi[blocking] - z[blocking])
            ratio[neg & ~blocking] = 0.0  # F = z = 0: a just-added cell that gets no force
            alpha = float(np.min(ratio))
            Fi_new = Fi + alpha * (z - Fi)
            # Cells that reach zero leave the active set.
            leaving = neg & (Fi_new <= 1e-15 * max(T, 1.0) * np.max(1.0 / h[idx]))
            leaving |= neg & (Fi_new <= 0.0)
            if not np.any(leaving):  # round-off: drop the cell that limited the step
                leaving[int(np.argmin(ratio))] = True
            Fi_new[leaving] = 0.0
            Fi_new = np.maximum(Fi_new, 0.0)
            # Re-impose the equality exactly after the step (round-off only).
            s = h[idx] @ Fi_new
            if s > 0.0:
                Fi_new *= T / s
            F = np.zeros(n)
            F[idx] = Fi_new
            active[idx[leaving]] = False
            if not np.any(active):  # cannot happen in exact arithmetic; restart from one cell
                F[start] = T / h[start]
                active[start] = True

        d = g - theta * h + C[:, active] @ F[active]
        scale = max(abs(theta) * float(h.max()), disp_scale)
        tol = 1e-12 * scale if penetration_tol is None else float(penetration_tol)
        violated = (~active) & (d < -tol)
        if not np.any(violated):
            break
        f_now = _objective(C, g, F)
        if not single_add and f_now >= f_prev:
            log.debug("objective did not decrease at iteration %d: single-add mode", it)
            single_add = True
        f_prev = f_now
        if single_add:
            cand = np.flatnonzero(violated)
            active[cand[int(np.argmin(d[cand]))]] = True
        else:
            active |= violated

    d = g - theta * h + C @ F
    d[active] = np.where(np.abs(d[active]) < 1e-300, 0.0, d[active])
    scale = max(abs(theta) * float(h.max()), disp_scale)
    eq = abs(h @ F - T) / T
    compl = float(np.max(np.abs(F * d))) / (T / float(h.min()) * scale)
    inactive = ~active
    pen = float(max(0.0, -d[inactive].min())) if np.any(inactive) else 0.0
    fmin = float(F[active].min())
    log.debug(
        "contact: %d/%d active, theta=%.6g, %d iterations, eq=%.2e", active.sum(), n, theta, it, eq
    )
    return ContactSolution(
        force=F,
        gap=d,
        active=active.copy(),
        theta=theta,
        iterations=it,
        equilibrium_residual=float(eq),
        complementarity_residual=compl,
        max_penetration=pen,
        min_active_force=fmin,
    )
