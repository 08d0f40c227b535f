"""Run a gear-pair case: geometry → assembly → (TCA | loaded TCA) → displacement fields.

:func:`run_gear_case` is what ``fegear run`` calls for a gear case; it returns a
:class:`GearRun` that :func:`fegear.io.gear_output.write_gear_outputs` turns into files.
The library logs; the caller gets progress through an optional callback
``progress(stage, i, n)`` (``i``/``n`` are the position counters of the position stage and
``None`` otherwise).

Fidelities (DESIGN §9) available for gear pairs:

- ``"fe"``: :func:`fegear.ltca.run_ltca` (FE sector compliance, torque-balanced contact);
  then, per member, the displacement ``u = K⁻¹ P F`` of every position in ONE factorisation
  (all positions are the columns of one right-hand side; MKL PARDISO through ``pypardiso``
  where installed, else SciPy SuperLU).
- ``"tca"``: the rigid, unloaded TCA (:func:`fegear.tca.run_tca`): unloaded TE, contact path,
  unloaded bearing pattern. No FE, no loaded results.

The spiral bevel case files ask for ``"tca"`` (fast); ``fe`` and ``hertz`` run on them too.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from fegear.errors import InputError
from fegear.io.gear_case import FIDELITIES, N_LEVELS, GearCase, GearPair, build_pair

__all__ = ["GearRun", "MemberField", "run_gear_case", "displacements"]

log = logging.getLogger(__name__)

Array = NDArray[np.float64]
Progress = Callable[[str, "int | None", "int | None"], None]


@dataclass(frozen=True)
class MemberField:
    """One member's sector and its displacement at every position (for the VTK files).

    Attributes
    ----------
    name
        ``"pinion"`` or ``"gear"``.
    points
        ``(n, 3)`` mm, sector vertices in the MEMBER frame.
    tets
        ``(m, 4)`` vertex indices.
    flank_nodes
        ``(k,)`` indices of the vertices on the working flanks.
    displacement
        ``(n_positions, n, 3)`` mm, vertex displacement in the MEMBER frame (zeros at positions
        without contact).
    placements
        ``(n_positions, 4, 4)`` member frame → fixed frame at each position.
    solver
        Sparse backend of the displacement solve (``"pypardiso"`` or ``"superlu"``).
    """

    name: str
    points: Array
    tets: NDArray[np.int_]
    flank_nodes: NDArray[np.int_]
    displacement: Array
    placements: Array
    solver: str


@dataclass(frozen=True)
class GearRun:
    """Everything a gear-case run produced (input of the writers).

    Attributes
    ----------
    case
        The case as run (fidelity and level overrides applied).
    pair
        Members and the assembly with the installation errors.
    assembly
        The assembly with the reference gear phase (the one the analysis used).
    cycle
        :class:`~fegear.ltca.LoadedCycle` (fidelity ``"fe"``), else None.
    tca
        :class:`~fegear.tca.CycleResult` (fidelity ``"tca"``), else None.
    members
        The two :class:`MemberField` (fidelity ``"fe"``), else empty.
    seconds
        Wall time per stage.
    """

    case: GearCase
    pair: GearPair
    assembly: Any
    cycle: Any = None
    tca: Any = None
    members: tuple[MemberField, ...] = ()
    seconds: dict[str, float] = field(default_factory=dict)

    @property
    def fidelity(self) -> str:
        return self.case.fidelity

    @property
    def phi2(self) -> Array:
        """``(n,)`` rad, gear angle of the TCA-closed position (``ratio φ1 + TE_unloaded``)."""
        from fegear.tca.results import ARCSEC

        c = self.cycle if self.cycle is not None else self.tca
        te = c.te_unloaded_arcsec if self.cycle is not None else c.te_arcsec
        return self.assembly.ratio * np.asarray(c.phi1) + np.asarray(te) * ARCSEC


def _override(case: GearCase, fidelity: str | None, level: int | None) -> GearCase:
    from dataclasses import replace

    if fidelity is not None and fidelity not in FIDELITIES:
        raise InputError("--fidelity", fidelity, f"one of {FIDELITIES} for gear pairs")
    if level is not None and not 0 <= level < N_LEVELS:
        raise InputError("--level", level, f"an integer in [0, {N_LEVELS - 1}]")
    return replace(
        case,
        fidelity=fidelity if fidelity is not None else case.fidelity,
        level=level if level is not None else case.level,
    )


def _linear_solver(K: sp.csr_matrix) -> tuple[Callable[[Array], Array], str]:
    """A solver of ``K X = B`` for several right-hand sides (one factorisation)."""
    try:
        import pypardiso

        solver = pypardiso.PyPardisoSolver()

        def solve(B: Array) -> Array:
            return np.asarray(solver.solve(K, np.ascontiguousarray(B))).reshape(B.shape)

        return solve, "pypardiso"
    except Exception:  # noqa: BLE001  (pypardiso or MKL missing: the portable fallback)
        import scipy.sparse.linalg as sla

        lu = sla.splu(K.tocsc())
        return lu.solve, "superlu"


def displacements(run_pair: GearPair, asm, models, cycle, phi2: Array) -> tuple[MemberField, ...]:
    """Vertex displacements of both sectors at every position: ``u = K⁻¹ P F``.

    ``P`` is rebuilt exactly as in the contact solve (:func:`fegear.ltca.model.
    member_load_operator`: pinion cells along ``−n1`` at the pinion flank points, gear cells
    along ``+n1`` at the points displaced by the cell gap), so the forces are the solver's.
    The rigid lag ``θ`` of member 2 is not part of ``u`` (the sectors are clamped at the bore
    and the cuts); the VTK places the gear at its unloaded (TCA-closed) angle.
    """
    from fegear.ltca.model import member_load_operator

    out = []
    n_pos = len(cycle.positions)
    for name, model in (("pinion", models.pinion), ("gear", models.gear)):
        body = model.body
        nodal = body.scalar_basis.nodal_dofs[0]  # scalar DOF of each vertex
        vdofs = 3 * nodal[:, None] + np.arange(3)[None, :]
        n_v = body.mesh.p.shape[1]
        place = np.stack(
            [
                asm.placement1(p.phi1) if name == "pinion" else asm.placement2(phi2[i])
                for i, p in enumerate(cycle.positions)
            ]
        )
        B = np.zeros((body.free.size, n_pos))
        for i, pos in enumerate(cycle.positions):
            if not pos.cells:
                continue
            cols = []
            for c in pos.cells:
                if name == "pinion":
                    cols.append(member_load_operator(model, place[i], c.k, c.quad_points,
                                                     -c.normals))  # fmt: skip
                else:
                    q = c.quad_points + c.gap[:, None, None] * c.normals[:, None]
                    cols.append(member_load_operator(model, place[i], c.j, q, c.normals))
            f = sp.hstack(cols).tocsr() @ pos.solution.force
            B[:, i] = f[body.free]
        U = np.zeros((n_pos, n_v, 3))
        used = "none"
        if np.any(B):
            t0 = time.perf_counter()
            solve, used = _linear_solver(body.K)
            X = solve(B)
            full = np.zeros((body.n_dofs, n_pos))
            full[body.free] = X
            U = np.transpose(full[vdofs], (2, 0, 1))
            log.info("%s: displacements of %d positions in %.2f s (%s)", name, n_pos,
                     time.perf_counter() - t0, used)  # fmt: skip
        bnames = [b for b in body.mesh.boundaries if b.startswith(f"flank_{model.side}_")]
        facets = np.concatenate([body.mesh.boundaries[b] for b in bnames])
        flank_nodes = np.unique(body.mesh.facets[:, facets])
        out.append(
            MemberField(
                name=name,
                points=body.mesh.p.T.copy(),
                tets=body.mesh.t.T.copy(),
                flank_nodes=flank_nodes,
                displacement=U,
                placements=place,
                solver=used,
            )
        )
    return tuple(out)


def run_gear_case(
    case: GearCase,
    fidelity: str | None = None,
    level: int | None = None,
    progress: Progress | None = None,
    pair: GearPair | None = None,
    workers: int | None = None,
) -> GearRun:
    """Run a gear case at its (or the given) fidelity and level.

    Parameters
    ----------
    case
        A validated :class:`~fegear.io.gear_case.GearCase`.
    fidelity, level
        Overrides of ``[analysis] fidelity`` and ``level``.
    progress
        ``progress(stage, i, n)``: called at the start of each stage (``i = n = None``) and after
        each mesh position (``stage = "positions"``).
    pair
        The pair of the case if already built (:func:`~fegear.io.gear_case.build_pair`, which
        is where bad design data is refused).
    workers
        Processes for the mesh positions (:mod:`fegear.ltca.cycle`); None: one per core. A
        sweep, which runs its items in parallel already, passes 1.

    Raises
    ------
    InputError
        Bad overrides or design data.
    """
    from fegear.ltca import LTCAOptions, build_models, run_ltca
    from fegear.tca import TCAOptions, reference_phase, run_tca

    case = _override(case, fidelity, level)
    say = progress or (lambda stage, i, n: None)
    seconds: dict[str, float] = {}
    t0 = time.perf_counter()
    say("geometry", None, None)
    pair = pair if pair is not None else build_pair(case)
    seconds["geometry"] = time.perf_counter() - t0

    if case.fidelity == "tca":
        t0 = time.perf_counter()
        say("tca", None, None)
        opt = TCAOptions(n_positions=case.n_positions, E_MPa=case.E_MPa, nu=case.nu,
                         pinion_torque_Nm=case.torque2_Nmm / case.ratio / 1000.0)  # fmt: skip
        asm = pair.assembly.with_phase2(reference_phase(pair.pinion, pair.gear, pair.assembly, opt))
        r = run_tca(pair.pinion, pair.gear, asm, opt, calibrate=False)
        seconds["tca"] = time.perf_counter() - t0
        return GearRun(case=case, pair=pair, assembly=asm, tca=r, seconds=seconds)

    opt = LTCAOptions(
        n_positions=case.n_positions,
        level=case.level,
        n_teeth=case.n_teeth,
        E_MPa=case.E_MPa,
        nu=case.nu,
        backend=case.backend,
        fidelity=case.fidelity,
        workers=workers,
    )
    t0 = time.perf_counter()
    say("models", None, None)
    models = build_models(pair.pinion, pair.gear, pair.assembly, opt)
    seconds["models"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    say("positions", 0, case.n_positions)
    cycle = run_ltca(
        pair.pinion,
        pair.gear,
        pair.assembly,
        case.torque2_Nmm,
        opt,
        models=models,
        progress=lambda i, n: say("positions", i, n),
    )
    seconds["positions"] = time.perf_counter() - t0
    if cycle.zone is not None and cycle.zone is not models.zone:
        # the load grew the contact zone: the cycle ran on other sectors (cached, read back)
        models = build_models(pair.pinion, pair.gear, pair.assembly, opt, zone=cycle.zone)
    asm = pair.assembly.with_phase2(cycle.phase2)  # the phase run_ltca closed the pair with
    run = GearRun(case=case, pair=pair, assembly=asm, cycle=cycle, seconds=seconds)
    if case.fidelity == "hertz":  # no contact grid: no cell loads, no displacement fields
        return run
    t0 = time.perf_counter()
    say("displacements", None, None)
    members = displacements(pair, asm, models, cycle, run.phi2)
    seconds["displacements"] = time.perf_counter() - t0
    return GearRun(
        case=case, pair=pair, assembly=asm, cycle=cycle, members=members, seconds=seconds
    )
