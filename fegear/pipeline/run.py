"""Run a gear-pair case: geometry → assembly → (TCA | loaded TCA) → displacement fields.

:func:`run_gear_case` is what ``fegear run`` calls for a gear case; it returns a
:class:`GearRun` that :func:`fegear.output.gear_output.write_gear_outputs` turns into files.
The library logs; the caller gets progress through an optional callback
``progress(stage, i, n)`` (``i``/``n`` are the position counters of the position stage and
``None`` otherwise).

Fidelities (DESIGN §9) available for gear pairs:

- ``"fe"``: :func:`fegear.ltca.run_ltca` (FE sector compliance, torque-balanced contact);
  then, per member, the displacement ``u = K⁻¹ P F`` of every position in ONE factorisation
  (all positions are the columns of one right-hand side; one sparse Cholesky,
  :func:`fegear.linalg.solve.factorize_spd`, with the case's ``backend``).
- ``"tca"``: the rigid, unloaded TCA (:func:`fegear.tca.run_tca`): unloaded TE, contact path,
  unloaded bearing pattern. No FE, no loaded results.

- ``"hybrid"`` (the default of every gear case) and ``"hertz"``: as ``"fe"`` with the compliance
  of :mod:`fegear.ltca.hybrid` or the per-pair Hertz laws of :mod:`fegear.ltca.hertz_model`.

Before any FE work, :func:`check_engagement` decides every way the contact can fail (issue 21):
a tip running into the mate's root and no contact at any position are refused
(:class:`~fegear.errors.InputError` naming the installation-error fields), contact lost at some
positions and a contact ratio below 1 become warnings. :func:`report` gives the headline numbers
as they are reported: over the usable positions only, p_max away from the edges, None with a
reason where nothing physical can be reported.
"""

from __future__ import annotations

import logging
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from fegear.errors import DesignError, InputError
from fegear.io.gear_case import FIDELITIES, N_LEVELS, UNLOADED, GearCase, error_fields
from fegear.linalg.solve import SparseFactor, factorize_spd
from fegear.ltca.fidelity import Fidelity, fidelity_of
from fegear.ltca.validity import ValidityCheck, validity_checks
from fegear.pipeline.pair import GearPair, assemble, build_pair

__all__ = [
    "Engagement",
    "GearRun",
    "MemberField",
    "Report",
    "check_engagement",
    "displacements",
    "report",
    "run_gear_case",
]

log = logging.getLogger(__name__)

Array = NDArray[np.float64]
Progress = Callable[[str, "int | None", "int | None"], None]


@dataclass(frozen=True)
class MemberField:
    """One member's stress sector, its displacement and stress at every position (VTK files,
    root stress).

    The sector is the contact sector remeshed with the fillets of the zone teeth refined to
    ``fillet_mm`` (:func:`stress_sector`), loaded by the converged cell forces of the contact
    solve (:func:`displacements`).

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
        Sparse backend of the displacement solve (``"pardiso"`` or ``"superlu"``).
    max_principal, min_principal, von_mises
        ``(n_positions, n)`` MPa, recovered vertex stresses (:mod:`fegear.fem.stress`: element
        values at the vertices, averaged); zeros at positions without contact.
    root
        Per position, the :class:`~fegear.fem.stress.ToothRootStress` of every tooth that can
        touch (``loaded`` says whether it carries force there); empty without contact.
    equilibrium
        Per position, the :class:`~fegear.fem.stress.Equilibrium` of the solve (None without
        contact).
    fillet_mm
        Element size on the fillets of the stress sector (mm).
    fillet_note
        Why ``fillet_mm`` is coarser than asked (:data:`fegear.mesh.sector.FILLET_TRIANGLES`),
        else "".
    dofs, body
        ``(n_dofs, n_positions)`` mm, the P2 displacement in the full DOF numbering, and the
        :class:`~fegear.fem.elasticity.ElasticBody` of the stress sector (only when
        :func:`displacements` is asked to keep them: studies of the recovery).
    """

    name: str
    points: Array
    tets: NDArray[np.int_]
    flank_nodes: NDArray[np.int_]
    displacement: Array
    placements: Array
    solver: str
    max_principal: Array | None = None
    min_principal: Array | None = None
    von_mises: Array | None = None
    root: tuple[tuple[Any, ...], ...] = ()
    equilibrium: tuple[Any, ...] = ()
    fillet_mm: float | None = None
    dofs: Array | None = None
    body: Any = None
    fillet_note: str = ""

    @property
    def root_teeth(self) -> tuple[int, ...]:
        """Member teeth with a root-stress entry (the teeth that can touch)."""
        return tuple(sorted({r.tooth for row in self.root for r in row}))

    def root_series(self, tooth: int, what: str = "tension_MPa") -> Array:
        """``(n_positions,)`` MPa: ``what`` (a :class:`~fegear.fem.stress.ToothRootStress`
        field) of member tooth ``tooth`` at every position (NaN without contact)."""
        out = np.full(len(self.root), np.nan)
        for i, row in enumerate(self.root):
            for r in row:
                if r.tooth == tooth:
                    out[i] = getattr(r, what)
        return out


#: A tip closer than this to the mate's root (mm) is an interference (the clearance is computed
#: to well below a micrometre, :func:`fegear.tca.engagement.tip_root_clearance`).
INTERFERENCE_TOL_MM = 1e-4


@dataclass(frozen=True)
class Engagement:
    """How the flanks engage, checked before the loaded analysis (:func:`check_engagement`).

    Attributes
    ----------
    clearance
        Tip-to-root clearances (:class:`fegear.tca.engagement.Clearance`).
    handover
        Interior contact over the cycle (:class:`fegear.tca.engagement.Handover`).
    path
        One pair's unloaded contact over its whole contact interval
        (:class:`fegear.tca.path.ContactPath`: contact ratio, path length, what ends it), or
        None where no pair has interior contact.
    phi1
        ``(n,)`` rad, the positions of the run.
    has_contact
        ``(n,)`` bool, the unloaded TCA found contact there.
    missed_handover
        The interior contact covers less than the whole cycle (contact ratio below 1) and no
        position of the run falls where it does not: the run's TE peak-to-peak and contact
        ratio do not see the handover.
    errors
        ``[(case-file key, value)]`` of the non-zero installation errors.
    warnings
        Terminal warnings (they change the meaning of a headline).
    """

    clearance: Any
    handover: Any
    phi1: Array
    has_contact: NDArray[np.bool_]
    missed_handover: bool
    errors: tuple[tuple[str, float], ...]
    warnings: tuple[str, ...]
    path: Any = None

    @property
    def contact_ratio_below_one(self) -> float | None:
        """The unloaded contact ratio when it is below 1 (the interior fraction), else None."""
        f = float(self.handover.interior_fraction)
        return f if f < 1.0 else None

    @property
    def lost(self) -> tuple[int, ...]:
        """Positions of the run without unloaded contact."""
        return tuple(int(i) for i in np.flatnonzero(~self.has_contact))


def _fields_text(errors) -> str:
    return ", ".join(f"{k} = {v:g}" for k, v in errors) or "no installation errors"


def _check_clearance(case: GearCase, pair: GearPair):
    """Refuse a tip running into the mate's root (:class:`~fegear.errors.InputError` naming the
    installation-error field that causes it and the depth; a :class:`~fegear.errors.DesignError`
    if the error-free pair already interferes)."""
    from dataclasses import replace

    from fegear.assembly import InstallationErrors
    from fegear.tca.engagement import tip_root_clearance

    c = tip_root_clearance(pair.pinion, pair.gear, pair.assembly)
    if c.interference_mm <= INTERFERENCE_TOL_MM:
        return c
    who = c.worse
    mate = "gear" if who == "pinion" else "pinion"
    errs = error_fields(case)
    nominal = tip_root_clearance(pair.pinion, pair.gear, assemble(case, pair, InstallationErrors()))
    what = (
        f"tip/root interference: the {who} tip runs {c.interference_mm:.3f} mm into the {mate} "
        f"root; the tip clearance without errors is "
        f"{min(nominal.pinion_tip_mm, nominal.gear_tip_mm):.3f} mm"
    )
    if not errs or nominal.interference_mm > INTERFERENCE_TOL_MM:
        raise DesignError(
            "pair", "tip/root interference", "a pair whose tips clear the roots", what
        )
    culprits = []
    for key, value in errs:
        one = replace(InstallationErrors(), **{key.split(".", 1)[1]: value})
        alone = tip_root_clearance(pair.pinion, pair.gear, assemble(case, pair, one))
        if alone.interference_mm > INTERFERENCE_TOL_MM:
            culprits.append((key, value))
    named = culprits or errs
    field = ", ".join(k for k, _ in named)
    value = named[0][1] if len(named) == 1 else [v for _, v in named]
    raise InputError(
        field, value, "an installation error that keeps the tips out of the roots", what
    )


def _jamming(pair: GearPair, case: GearCase) -> str:
    """The warning of a parallel-axes pair that jams (:func:`fegear.tca.engagement.jamming`),
    else ""."""
    from fegear.tca.engagement import jamming

    if pair.assembly.kind != "parallel":
        return ""
    j = jamming(pair.pinion, pair.gear, case.errors)
    if j is None:
        return ""
    named = ", ".join(f"{k} = {v:g}" for k, v in j.fields)
    return (
        f"the pair jams ({named}): its teeth are cut without backlash for the centre distance "
        f"{j.working_mm:.4f} mm; at {j.centre_distance_mm:.4f} mm their other flanks would "
        f"overlap by {j.depth_mm:.4f} mm along the line of action; the analysis loads the "
        "working flanks only"
    )


def check_engagement(case: GearCase, pair: GearPair, tca, positions, clearance) -> Engagement:
    """Every way the contact can fail, decided before the loaded analysis.

    ``tca``, ``positions``: the TCA of the run's positions (:func:`fegear.tca.cached.cached_tca`,
    the one the loaded analysis reads back); ``clearance``: the pair's tip/root clearances
    (checked first: an interference is refused before any TCA).

    Raises
    ------
    InputError
        No position of the cycle has contact: the flanks do not meet (naming the installation
        errors that separate them).
    """
    from fegear.tca.engagement import cached_handover
    from fegear.tca.path import cached_contact_path

    errs = tuple(error_fields(case))
    has = np.array([p.has_contact for p in positions], dtype=bool)
    phi1 = np.array([p.phi1 for p in positions], dtype=float)
    n = len(positions)
    if not has.any():
        field = ", ".join(k for k, _ in errs) or "pair"
        value = errs[0][1] if len(errs) == 1 else [v for _, v in errs] if errs else "as designed"
        raise InputError(
            field,
            value,
            "installation errors under which the flanks meet",
            f"no contact anywhere: the flanks do not meet at any of the {n} positions of the "
            f"cycle; the teeth are separated by {_fields_text(errs)}",
        )
    h = cached_handover(pair.pinion, pair.gear, pair.assembly, tca.opt, tca)
    path = cached_contact_path(pair.pinion, pair.gear, pair.assembly, tca.opt, tca, positions)
    warnings = []
    jam = _jamming(pair, case)
    if jam:
        warnings.append(jam)
    lost = np.flatnonzero(~has)
    if lost.size:
        where = ", ".join(f"{i} (φ1 = {np.degrees(phi1[i]):.3f}°)" for i in lost)
        warnings.append(
            f"contact lost at {lost.size} of {n} positions: {where}; the flanks do not meet "
            f"there ({_fields_text(errs)}); the TE peak-to-peak leaves them out"
        )
    missed = False
    if h.interior_fraction < 1.0:
        pct = 100.0 * (1.0 - h.interior_fraction)
        spans = ", ".join(f"{np.degrees(a):.2f}° to {np.degrees(b):.2f}°" for a, b in h.intervals)
        text = (
            f"unloaded contact ratio {h.interior_fraction:.3f} < 1 ({_fields_text(errs)}): over "
            f"{pct:.1f} % of each mesh cycle (φ1 {spans}) the contact is at a tip or root edge "
            "or lost"
        )
        inside = h.covers(phi1)
        if not inside.any():
            missed = True
            need = int(np.ceil(1.0 / max(1.0 - h.interior_fraction, 1e-9))) + 1
            text += (
                f"; none of the {n} positions falls there, so their TE peak-to-peak and contact "
                f"ratio would not see it: not reported (run with n_positions >= {need})"
            )
        warnings.append(text)
    return Engagement(
        clearance=clearance,
        handover=h,
        phi1=phi1,
        has_contact=has,
        missed_handover=missed,
        errors=errs,
        warnings=tuple(warnings),
        path=path,
    )


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
        :class:`~fegear.ltca.LoadedCycle` (loaded fidelities), else None.
    tca
        :class:`~fegear.tca.CycleResult` (fidelity ``"tca"``), else None.
    members
        The two :class:`MemberField` (fidelities ``"fe"`` and ``"hybrid"``), else empty.
    seconds
        Wall time per stage.
    engagement
        What :func:`check_engagement` found before the analysis.
    cache
        The artefact-cache lookups of the run (:class:`fegear.store.cache.CacheUse`: what was
        read, what was built), or None.
    ellipses
        Per position the contact ellipses of the unloaded TCA
        (:class:`fegear.tca.ellipse.EllipseAt`, None without contact; Hertz at the case's load
        on one pair).
    """

    case: GearCase
    pair: GearPair
    assembly: Any
    cycle: Any = None
    tca: Any = None
    members: tuple[MemberField, ...] = ()
    seconds: dict[str, float] = field(default_factory=dict)
    engagement: Engagement | None = None
    cache: Any = None
    ellipses: tuple = ()

    @property
    def fidelity(self) -> str:
        return self.case.fidelity

    @property
    def kind(self) -> Fidelity | None:
        """The loaded :class:`~fegear.ltca.fidelity.Fidelity` of the run (None: unloaded TCA)."""
        return None if self.fidelity == UNLOADED else fidelity_of(self.fidelity)

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


#: Factorised stress sectors kept in the process (the last pair): runs of the same pair in one
#: process (sweeps, scripts, the test session) solve by back-substitution only. A 190k-DOF FZG
#: stress sector's Cholesky is some hundred MB, hence two.
_FACTORS: OrderedDict[tuple, tuple[sp.csr_matrix, SparseFactor]] = OrderedDict()
_MAX_FACTORS = 2


def _factorised(sector, body, backend: str = "auto") -> tuple[sp.csr_matrix, SparseFactor]:
    """``(K_full, factor)`` of a stress sector: the full stiffness (reactions) and the
    solver on its free DOFs, from :data:`_FACTORS` when the same mesh (file), material and
    clamping were factorised before in this process."""
    from fegear.fem.assembly import elasticity_stiffness

    key = (str(sector.path), body.E, body.nu, body.free.size, body.n_dofs, backend)
    if key in _FACTORS:
        _FACTORS.move_to_end(key)
        return _FACTORS[key]
    K = elasticity_stiffness(body.mesh, body.E, body.nu).tocsr()
    factor = factorize_spd(K[body.free][:, body.free].tocsr(), backend)
    _FACTORS[key] = (K, factor)
    while len(_FACTORS) > _MAX_FACTORS:
        _FACTORS.popitem(last=False)
    return K, factor


def _vertex_displacements(model, body, F: Array, vdofs, backend: str) -> tuple[Array, str]:
    """``(U, solver)``: the vertex displacements ``(n_positions, n_vertices, 3)`` mm of a
    contact sector under the consistent loads ``F`` ``(n_dofs, n_positions)`` N, and the sparse
    backend that solved them, from the cache when the same sector was solved under the same
    loads before (a run repeated: no factorisation), else one factorisation for all positions
    (kept in the process, :func:`_factorised`, for the next loads on the same sector: the
    variants of a study)."""
    from fegear.store.cache import cached_record

    params = {
        "mesh": model.sector.path.name if model.sector.path else repr(model.sector.parameters),
        "E": body.E,
        "nu": body.nu,
        "free": body.free,
        "loads": F,
    }

    def build(entry) -> dict[str, object]:
        _, factor = _factorised(model.sector, body, backend)
        full = np.zeros_like(F)
        full[body.free] = factor.solve(np.ascontiguousarray(F[body.free]))
        U = np.transpose(full[vdofs], (2, 0, 1))
        entry.write(".npy", lambda p: np.save(p, U))
        return {"solver": factor.backend}

    entry, record, _ = cached_record("fields", params, build)
    return np.load(entry.path(".npy")), str(record["solver"])


def _loaded_points(pos, member: str, placement: Array) -> dict[int, Array]:
    """``{member tooth: (q, 3) mm}``: the centres of the loaded contact cells of a position on
    each tooth of ``member`` (its frame; gear cells moved across their gap onto its flank)."""
    from fegear.geometry.transforms import apply_points, inverse

    out: dict[int, list[Array]] = {}
    if not pos.cells:
        return {}
    force = pos.solution.force
    start = 0
    Minv = inverse(placement)
    for c in pos.cells:
        f = force[start : start + c.n]
        start += c.n
        if not np.any(f > 0.0):
            continue
        x = c.centers[f > 0.0]
        if member == "gear":
            x = x + c.gap[f > 0.0, None] * c.normals[f > 0.0]
        out.setdefault(int(c.k if member == "pinion" else c.j), []).append(apply_points(Minv, x))
    return {k: np.vstack(v) for k, v in out.items()}


def stress_sector(member, model, teeth: tuple[int, ...] | None, fillet_mm: float):
    """The contact sector of ``model`` remeshed with the fillets of its sector teeth ``teeth``
    (None: every tooth whose flank the contact sector refines) at ``fillet_mm``
    (:func:`fegear.mesh.sector.sector_mesh`, cached), as a
    :class:`~fegear.ltca.model.MemberModel` without compliance operator (``op`` None): what
    :func:`fegear.ltca.model.member_load_operator` needs to load it."""
    from dataclasses import replace

    from fegear.fem.elasticity import assemble_body
    from fegear.mesh.sector import default_zone, sector_mesh
    from fegear.mesh.sector_geometry import sector_frame

    p = model.sector.parameters
    n, rim = int(p["n_teeth"]), float(p.get("rim_modules", 3.0))
    zone = None
    if teeth is not None:
        whole = default_zone(sector_frame(member, rim), n, model.side)
        zone = tuple(z for z in whole if z.tooth in teeth) or None
    sector = sector_mesh(
        member,
        n,
        int(p["level"]),
        zone=zone,
        rim_modules=rim,
        fillet_mm=fillet_mm,
        side=model.side,
    )
    mesh = sector.to_skfem()
    support = "base" if "base" in mesh.boundaries else "bore"
    clamped = [(support, "xyz"), ("cut_left", "xyz"), ("cut_right", "xyz")]
    body = assemble_body(mesh, model.body.E, model.body.nu, clamped)
    return replace(model, sector=sector, body=body, op=None, layer_mm=0.0, layer_tets=None)


def displacements(
    run_pair: GearPair,
    asm,
    models,
    cycle,
    phi2: Array,
    fillet_modules: float | None = None,
    refine_teeth: dict[str, tuple[int, ...]] | None = None,
    keep_dofs: bool = False,
    root_stress: bool = True,
    backend: str = "auto",
) -> tuple[MemberField, ...]:
    """Displacement and stress of both stress sectors at every position: ``u = K⁻¹ P F``.

    The sectors are those of the contact solve remeshed with the fillets of the loaded teeth at
    ``fillet_modules`` modules (default :data:`fegear.fem.stress.FILLET_MODULES`,
    :func:`stress_sector`). ``P`` is built exactly as in the contact solve
    (:func:`fegear.ltca.model.member_load_operator`: pinion cells along ``−n1`` at the pinion
    flank points, gear cells along ``+n1`` at the points displaced by the cell gap), so the
    forces are the solver's. All positions are the columns of one right-hand side (one
    factorisation per member). The rigid lag ``θ`` of member 2 is not part of ``u`` (the
    sectors are clamped at the bore and the cuts); the VTK places the gear at its unloaded
    (TCA-closed) angle. Then, per position, the recovered vertex stresses, the root stress of
    every tooth that can touch (:func:`fegear.fem.stress.tooth_root_stress`) and the
    equilibrium of the solve (:func:`fegear.fem.stress.reactions`).

    ``refine_teeth``: ``{member: sector teeth}`` whose flank (and fillets) the stress sector
    refines (default: every tooth that can carry load; a refinement study refines the tooth it
    reads only);
    ``keep_dofs``: keep the P2 displacement and the body in the :class:`MemberField`.
    ``root_stress`` False: the displacement on the contact sectors themselves (no remeshing, the
    factorisation of a sector of the contact model's size), without stresses (the contact
    sectors' fillets are as coarse as their level: their stresses are not the root stress).
    ``backend``: of the sparse Cholesky (:func:`fegear.linalg.solve.factorize_spd`).
    """
    from fegear.fem.stress import (
        CONTACT_CLEARANCE_MODULES,
        FILLET_MODULES,
        VertexStress,
        fillet_regions,
        principal_stresses,
        reactions,
        tooth_root_stress,
        von_mises,
    )
    from fegear.ltca.model import member_load_operator
    from fegear.mesh.sector import FILLET_TRIANGLES, FINE

    out = []
    n_pos = len(cycle.positions)
    fm = FILLET_MODULES if fillet_modules is None else float(fillet_modules)
    for name, model, member in (
        ("pinion", models.pinion, run_pair.pinion),
        ("gear", models.gear, run_pair.gear),
    ):
        p = model.sector.parameters
        module = float(p["h_fine_mm"]) / FINE[int(p["level"])]
        teeth = refine_teeth.get(name) if refine_teeth is not None else None
        t0 = time.perf_counter()
        smodel = stress_sector(member, model, teeth, fm * module) if root_stress else model
        body = smodel.body
        nodal = body.scalar_basis.nodal_dofs[0]  # scalar DOF of each vertex
        vdofs = 3 * nodal[:, None] + np.arange(3)[None, :]
        n_v = body.mesh.p.shape[1]
        place = np.stack(
            [
                asm.placement1(pp.phi1) if name == "pinion" else asm.placement2(phi2[i])
                for i, pp in enumerate(cycle.positions)
            ]
        )
        F = np.zeros((body.n_dofs, n_pos))
        for i, pos in enumerate(cycle.positions):
            if not pos.cells:
                continue
            cols = []
            for c in pos.cells:
                if name == "pinion":
                    cols.append(member_load_operator(smodel, place[i], c.k, c.quad_points,
                                                     -c.normals))  # fmt: skip
                else:
                    q = c.quad_points + c.gap[:, None, None] * c.normals[:, None]
                    cols.append(member_load_operator(smodel, place[i], c.j, q, c.normals))
            F[:, i] = sp.hstack(cols).tocsr() @ pos.solution.force
        U = np.zeros((n_pos, n_v, 3))
        full = np.zeros((body.n_dofs, n_pos))
        used = "none"
        loaded = np.flatnonzero(np.any(F != 0.0, axis=0))
        K = None
        if loaded.size and not (root_stress or keep_dofs):
            U, used = _vertex_displacements(smodel, body, F, vdofs, backend)
        elif loaded.size:
            K, factor = _factorised(smodel.sector, body, backend)
            used = factor.backend
            full[body.free] = factor.solve(np.ascontiguousarray(F[body.free]))
            U = np.transpose(full[vdofs], (2, 0, 1))
        teeth = model.teeth if model.teeth is not None else None
        regions = fillet_regions(smodel.sector, model.side, teeth) if root_stress else ()
        rec = None
        if root_stress:
            rec = VertexStress(body.mesh.p.T, body.mesh.t.T, body.scalar_basis.element_dofs,
                               body.E, body.nu)  # fmt: skip
        s_max, s_min, s_vm = (np.zeros((n_pos, n_v)) for _ in range(3))
        root: list[tuple[Any, ...]] = [() for _ in range(n_pos)]
        equil: list[Any] = [None] * n_pos
        fixed = np.setdiff1d(np.arange(body.n_dofs), body.free)
        pts = body.mesh.p.T
        for i in loaded if root_stress else ():
            sig = rec(full[:, i])
            ps = principal_stresses(sig)
            s_max[i], s_min[i], s_vm[i] = ps[:, 2], ps[:, 0], von_mises(sig)
            touch = _loaded_points(cycle.positions[i], name, place[i])
            root[i] = tuple(
                tooth_root_stress(pts, r, sig, r.tooth in touch, touch.get(r.tooth),
                                  CONTACT_CLEARANCE_MODULES * module)
                for r in regions
            )  # fmt: skip
            equil[i] = reactions(K, body.basis.doflocs, fixed, full[:, i], F[:, i])
        diag = smodel.sector.diagnostics
        h_fil = float(diag.get("fillet_mm", fm * module)) if root_stress else None
        note = ""
        if h_fil is not None and h_fil > fm * module * (1.0 + 1e-9):
            note = (
                f"{name}: fillet elements {h_fil:.3g} mm instead of {fm * module:.3g} mm "
                f"({fm:g} m): {float(diag.get('fillet_area_mm2', 0.0)):.0f} mm² of refined "
                f"fillets would take more than {FILLET_TRIANGLES} triangles; on the FZG pair "
                f"{h_fil / module:.2g} m reads the root stress within the errors of "
                "benchmarks/results/root_stress_refinement.md at that size"
            )
            log.warning(note)
        log.info("%s: %s sector (fillets %s mm, %d tets), %d positions in %.2f s (%s)",
                 name, "stress" if root_stress else "contact", h_fil, body.mesh.t.shape[1],
                 n_pos, time.perf_counter() - t0, used)  # fmt: skip
        bnames = [b for b in body.mesh.boundaries if b.startswith(f"flank_{model.side}_")]
        facets = np.concatenate([body.mesh.boundaries[b] for b in bnames])
        flank_nodes = np.unique(body.mesh.facets[:, facets])
        out.append(
            MemberField(
                name=name,
                points=pts.copy(),
                tets=body.mesh.t.T.copy(),
                flank_nodes=flank_nodes,
                displacement=U,
                placements=place,
                solver=used,
                max_principal=s_max if root_stress else None,
                min_principal=s_min if root_stress else None,
                von_mises=s_vm if root_stress else None,
                root=tuple(root) if root_stress else (),
                equilibrium=tuple(equil),
                fillet_mm=h_fil,
                fillet_note=note,
                dofs=full if keep_dofs else None,
                body=body if keep_dofs else None,
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
    notify: Callable[[str], None] | None = None,
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
        The pair of the case if already built (:func:`~fegear.pipeline.pair.build_pair`, which
        is where bad design data is refused).
    workers
        Processes for the mesh positions (:mod:`fegear.ltca.cycle`); None: one per core. A
        sweep, which runs its items in parallel already, passes 1.
    notify
        ``notify(text)``: called with each warning of the engagement checks as soon as they
        are made, before the loaded analysis (they are in ``GearRun.engagement`` too).

    Raises
    ------
    InputError
        Bad overrides or design data; an installation under which the flanks cannot mesh: no
        contact at any position (naming the installation errors), or a tip running into the
        mate's root (naming the error and the depth). Both are decided before any FE work.
    """
    from dataclasses import replace

    from fegear.store.cache import record_cache_use

    with record_cache_use() as used:
        run = _run_gear_case(case, fidelity, level, progress, pair, workers, notify)
    return replace(run, cache=used())


def _ellipses(case: GearCase, tca, positions) -> tuple:
    """The contact ellipses of the TCA positions at the case's load (:mod:`fegear.tca.ellipse`)."""
    from fegear.tca.ellipse import ellipses

    T1 = case.torque2_Nmm / case.ratio / 1000.0
    return ellipses(positions, tca.asm.axis1(), T1, tca.opt.paint_mm, case.E_MPa, case.nu)


def _run_gear_case(case, fidelity, level, progress, pair, workers, notify) -> GearRun:
    from fegear.ltca import LTCAOptions, build_models, run_ltca
    from fegear.ltca.cycle import cycle_tca
    from fegear.tca import TCAOptions
    from fegear.tca.cached import cached_tca
    from fegear.tca.cycle import cycle_result

    case = _override(case, fidelity, level)
    say = progress or (lambda stage, i, n: None)
    seconds: dict[str, float] = {}
    t0 = time.perf_counter()
    say("geometry", None, None)
    pair = pair if pair is not None else build_pair(case)
    clearance = _check_clearance(case, pair)  # interference: refused before any TCA
    seconds["geometry"] = time.perf_counter() - t0

    if case.fidelity == UNLOADED:
        t0 = time.perf_counter()
        say("tca", None, None)
        opt = TCAOptions(n_positions=case.n_positions, E_MPa=case.E_MPa, nu=case.nu,
                         pinion_torque_Nm=case.torque2_Nmm / case.ratio / 1000.0)  # fmt: skip
        n = case.n_positions
        phi1 = -np.pi / pair.assembly.n1 + 2 * np.pi / pair.assembly.n1 * np.arange(n) / n
        tca, positions, _ = cached_tca(pair.pinion, pair.gear, pair.assembly, opt, phi1)
        eng = check_engagement(case, pair, tca, positions, clearance)
        for w in eng.warnings:
            (notify or log.warning)(w)
        r = cycle_result(list(positions), opt.paint_mm, tca)
        ell = _ellipses(case, tca, positions)
        seconds["tca"] = time.perf_counter() - t0
        return GearRun(
            case=case, pair=pair, assembly=tca.asm, tca=r, seconds=seconds, engagement=eng,
            ellipses=ell,
        )  # fmt: skip

    opt = LTCAOptions(
        n_positions=case.n_positions,
        level=case.level,
        n_teeth=case.n_teeth,
        E_MPa=case.E_MPa,
        nu=case.nu,
        backend=case.backend,
        fidelity=case.fidelity,
        workers=workers,
        **case.contact.as_dict(),
    )
    t0 = time.perf_counter()
    tca, positions, _ = cycle_tca(pair.pinion, pair.gear, pair.assembly, opt)
    eng = check_engagement(case, pair, tca, positions, clearance)  # before the FE work
    ell = _ellipses(case, tca, positions)
    for w in eng.warnings:
        (notify or log.warning)(w)
    seconds["checks"] = time.perf_counter() - t0
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
    models = cycle.models  # those of the grown zone if the load made it grow
    asm = pair.assembly.with_phase2(cycle.phase2)  # the phase run_ltca closed the pair with
    run = GearRun(case=case, pair=pair, assembly=asm, cycle=cycle, seconds=seconds, engagement=eng,
                  ellipses=ell)  # fmt: skip
    if not fidelity_of(case.fidelity).cells:  # no cell loads: no displacement fields
        return run
    t0 = time.perf_counter()
    say("displacements", None, None)
    members = displacements(
        pair, asm, models, cycle, run.phi2, root_stress=case.root_stress, backend=case.backend
    )
    seconds["displacements"] = time.perf_counter() - t0
    return GearRun(
        case=case,
        pair=pair,
        assembly=asm,
        cycle=cycle,
        members=members,
        seconds=seconds,
        engagement=eng,
        ellipses=ell,
    )


@dataclass(frozen=True)
class Report:
    """The headline numbers of a run as ``summary.json`` and the terminal report them: each
    means what it says, None with the reason beside it where nothing physical can be reported
    (DESIGN §10), and the warnings that change the meaning of a headline.

    Attributes
    ----------
    n_positions
        Positions of the run.
    te_pp_unloaded_arcsec, te_pp_unloaded_reason
        Unloaded TE peak-to-peak over the positions with unloaded contact.
    te_pp_loaded_arcsec, te_pp_loaded_reason, positions_used, excluded
        Loaded TE peak-to-peak over the usable positions (``positions_used`` of them;
        ``excluded``: :class:`fegear.ltca.results.Excluded`, lost or degenerate).
    contact_ratio_loaded, contact_ratio_reason
        Mean number of loaded pairs.
    p_max_MPa, p_max_reason, p_max_position, p_max_pair
        Largest pressure away from the flank edges, where.
    p_max_edge_MPa, p_max_edge_position, p_max_edge_pair, p_max_edge_edges, edge_positions
        Largest pressure at a flank edge (singular), where, which edges; the usable positions
        with an edge contact.
    interior_fraction
        Part of the cycle with interior unloaded contact (the contact ratio when below 1).
    validity
        The checks of the model's validity range (:mod:`fegear.ltca.validity`; loaded runs).
    warnings
        Warnings for the terminal (and ``summary.json``), in order.
    """

    n_positions: int
    te_pp_unloaded_arcsec: float | None
    te_pp_unloaded_reason: str
    te_pp_loaded_arcsec: float | None = None
    te_pp_loaded_reason: str = ""
    positions_used: int = 0
    excluded: tuple = ()
    contact_ratio_loaded: float | None = None
    contact_ratio_reason: str = ""
    p_max_MPa: float | None = None
    p_max_reason: str = ""
    p_max_position: int | None = None
    p_max_pair: tuple[int, int] | None = None
    p_max_edge_MPa: float | None = None
    p_max_edge_position: int | None = None
    p_max_edge_pair: tuple[int, int] | None = None
    p_max_edge_edges: tuple[str, ...] = ()
    edge_positions: tuple[int, ...] = ()
    interior_fraction: float | None = None
    warnings: tuple[str, ...] = ()
    validity: tuple[ValidityCheck, ...] = ()


def _angles(phi1, idx) -> str:
    return ", ".join(f"{i} (φ1 = {np.degrees(phi1[i]):.3f}°)" for i in idx)


def report(run: GearRun) -> Report:
    """The :class:`Report` of a run."""
    eng = run.engagement
    warnings = list(eng.warnings) if eng is not None else []
    missed = eng is not None and eng.missed_handover
    miss_reason = (
        "the positions miss the handover of a contact ratio below 1 (see the warnings)"
        if missed
        else ""
    )
    frac = float(eng.handover.interior_fraction) if eng is not None else None
    if run.cycle is None:  # unloaded TCA
        r = run.tca
        seen = r.te_arcsec[r.has_contact]
        te_u = float(np.ptp(seen)) if seen.size >= 2 and not missed else None
        why = miss_reason or ("" if te_u is not None else "fewer than two positions in contact")
        loaded = "unloaded TCA only (fidelity tca)"
        return Report(
            n_positions=int(r.phi1.size),
            te_pp_unloaded_arcsec=te_u,
            te_pp_unloaded_reason=why,
            te_pp_loaded_reason=loaded,
            contact_ratio_reason=loaded,
            p_max_reason=loaded,
            interior_fraction=frac,
            warnings=tuple(warnings),
        )
    c = run.cycle
    h = c.headline()
    n = h.n_positions
    te_u, te_u_why = (
        h.te_pp_unloaded_arcsec,
        "" if h.te_pp_unloaded_arcsec is not None else ("fewer than two positions in contact"),
    )
    te_l, te_l_why = h.te_pp_loaded_arcsec, h.te_pp_reason
    cr, cr_why = h.contact_ratio_loaded, ""
    if missed:
        te_u, te_u_why = None, miss_reason
        te_l, te_l_why = None, miss_reason
        cr, cr_why = None, miss_reason
    lost_before = set(eng.lost) if eng is not None else set()
    lost = [e for e in h.excluded if e.status == "lost" and e.index not in lost_before]
    if lost:
        where = _angles(c.phi1, [e.index for e in lost])
        warnings.append(
            f"no load carried at {len(lost)} of {n} positions: {where} ({lost[0].reason}); "
            "left out of the TE peak-to-peak"
        )
    degen = [e for e in h.excluded if e.status == "degenerate"]
    if run.kind is not None and run.kind.cells and not run.kind.resolves_patch:
        bad = [(q, i) for i, p in enumerate(c.positions) for q in p.pairs if q.in_contact]
        bad = [(q, i) for q, i in bad if not q.resolved]
        if bad:
            cells = sorted({float(np.min(cc.cell_mm)) for p in c.positions for cc in p.cells})
            size = f"{cells[0]:.3g}" + (f"-{cells[-1]:.3g}" if cells[-1] > cells[0] else "")
            widths = [2.0 * q.semi_minor_mm for q, _ in bad if q.semi_minor_mm > 0]
            patch = (
                f"the loaded patch (2b = {min(widths):.3g}-{max(widths):.3g} mm"
                if widths
                else "the loaded patch (narrower than one cell"
            )
            at = len({i for _, i in bad})
            warnings.append(
                f"{run.fidelity}: the contact cells ({size} mm) are wider than {patch}) at {at} "
                f"of {n} positions: the pressures and the TE there are cell averages, not the "
                "contact's; run --fidelity hybrid (it resolves the patch at every level)"
            )
    if degen:
        where = (
            f"all {n} positions"
            if len(degen) == n
            else f"{len(degen)} of {n} positions: {_angles(c.phi1, [e.index for e in degen])}"
        )
        warnings.append(
            f"degenerate (a loaded patch the cells do not resolve) at {where}; left out of the "
            "TE peak-to-peak and p_max (reasons in summary.json: cycle.excluded_positions)"
        )
    if h.excluded and te_l is not None:
        warnings.append(
            f"loaded TE peak-to-peak over {h.te_pp_positions_used} of {n} positions (the others "
            "are left out, above)"
        )
    if te_l is None and not missed:
        warnings.append(f"loaded TE peak-to-peak not reported: {te_l_why}")
    if h.p_max_MPa is None:
        warnings.append(f"p_max not reported: {h.p_max_reason}")
    checks = validity_checks(
        c, float(run.case.pair["module_mm"]), run.case.kind, h.p_max_MPa, h.p_max_position
    )
    warnings += [v.text for v in checks if v.exceeded]
    return Report(
        n_positions=n,
        te_pp_unloaded_arcsec=te_u,
        te_pp_unloaded_reason=te_u_why,
        te_pp_loaded_arcsec=te_l,
        te_pp_loaded_reason=te_l_why,
        positions_used=h.te_pp_positions_used,
        excluded=h.excluded,
        contact_ratio_loaded=cr,
        contact_ratio_reason=cr_why,
        p_max_MPa=h.p_max_MPa,
        p_max_reason=h.p_max_reason,
        p_max_position=h.p_max_position,
        p_max_pair=h.p_max_pair,
        p_max_edge_MPa=h.p_max_edge_MPa,
        p_max_edge_position=h.p_max_edge_position,
        p_max_edge_pair=h.p_max_edge_pair,
        p_max_edge_edges=h.p_max_edge_edges,
        edge_positions=h.edge_positions,
        interior_fraction=frac,
        warnings=tuple(warnings),
        validity=checks,
    )
