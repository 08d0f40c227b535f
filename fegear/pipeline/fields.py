"""The displacement and stress fields of a loaded gear run: the stress sectors (the contact
sectors remeshed with refined fillets) under the converged cell forces of the contact solve,
``u = K⁻¹ P F`` for all positions in one factorisation per member, the recovered stresses and
the tooth root stress (:func:`displacements`)."""

from __future__ import annotations

import contextvars
import logging
import threading
import time
from collections import OrderedDict
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from fegear.fem.assembly import elasticity_stiffness
from fegear.fem.elasticity import assemble_body
from fegear.fem.stress import (
    CONTACT_CLEARANCE_MODULES,
    FILLET_MODULES,
    Equilibrium,
    ToothRootStress,
    VertexStress,
    fillet_regions,
    principal_stresses,
    reactions,
    tooth_root_stress,
    von_mises,
)
from fegear.geometry.transforms import apply_points, inverse
from fegear.linalg.solve import SparseFactor, factorize_spd
from fegear.ltca.model import member_load_operator
from fegear.mesh.sector import FILLET_TRIANGLES, FINE, default_zone, sector_mesh
from fegear.mesh.sector_geometry import sector_frame
from fegear.pipeline.pair import GearPair
from fegear.store.cache import cached_record
from fegear.store.records import registry

__all__ = ["FIELD_CLASSES", "MemberField", "displacements", "stress_sector"]

log = logging.getLogger(__name__)

Array = NDArray[np.float64]


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


#: The classes of a cached tuple of :class:`MemberField` (:mod:`fegear.store.records`; kept
#: without ``dofs`` and ``body``).
FIELD_CLASSES = registry(MemberField, ToothRootStress, Equilibrium)

#: Factorised contact sectors kept in the process (the last pair): runs of the same pair in one
#: process (sweeps, scripts, the test session) solve their fields by back-substitution only.
#: The stress sectors' factors are never kept (:func:`_stress_solve`: 2.2-2.4 GB each on the
#: seed face gear).
_FACTORS: OrderedDict[tuple, tuple[sp.csr_matrix, SparseFactor]] = OrderedDict()
_MAX_FACTORS = 2
_FACTORS_LOCK = threading.Lock()  # the members' solves look their factors up in threads


def _factorised(sector, body, backend: str = "auto") -> tuple[sp.csr_matrix, SparseFactor]:
    """``(K_full, factor)`` of a stress sector: the full stiffness (reactions) and the
    solver on its free DOFs, from :data:`_FACTORS` when the same mesh (file), material and
    clamping were factorised before in this process."""
    key = (str(sector.path), body.E, body.nu, body.free.size, body.n_dofs, backend)
    with _FACTORS_LOCK:
        if key in _FACTORS:
            _FACTORS.move_to_end(key)
            return _FACTORS[key]
        K = elasticity_stiffness(body.mesh, body.E, body.nu).tocsr()
        factor = factorize_spd(K[body.free][:, body.free].tocsr(), backend)
        _FACTORS[key] = (K, factor)
        while len(_FACTORS) > _MAX_FACTORS:
            _FACTORS.popitem(last=False)
        return K, factor


def _stress_solve(body, F: Array, backend: str = "auto") -> tuple[Array, sp.csr_matrix, str]:
    """``(u_free, K_rows, solver)``: the displacement on the free DOFs of a stress sector under
    the loads ``F`` (``(n_dofs, n_positions)`` N, all positions in one solve), the rows of the
    full stiffness on the clamped DOFs (the rest zero: all :func:`fegear.fem.stress.reactions`
    reads of it, the same products) and the backend that solved.

    One factorisation, released on return, and never kept in :data:`_FACTORS`: a stress
    sector's factor is most of the memory of a root-stress run (seed face gear: 269 and 304
    million entries in ``L``, 2.2 and 2.4 GB; keeping both, as the contact sectors' are kept,
    took the run to 8.7 GB), so the members are factorised one after the other and the full
    stiffness is dropped before the factorisation (``benchmarks/results/root_stress_cost.md``).
    A repeated run reads its fields from the cache (``member_fields``) instead."""
    K = elasticity_stiffness(body.mesh, body.E, body.nu).tocsr()
    fixed = np.setdiff1d(np.arange(body.n_dofs), body.free)
    R = K[fixed]  # the clamped rows, placed back at their rows of K (the others empty)
    count = np.zeros(body.n_dofs + 1, dtype=np.int64)
    count[fixed + 1] = np.diff(R.indptr)
    rows = sp.csr_matrix((R.data, R.indices, np.cumsum(count)), shape=K.shape)
    Kf = K[body.free][:, body.free].tocsr()
    del K
    factor = factorize_spd(Kf, backend)
    del Kf
    u = factor.solve(np.ascontiguousarray(F[body.free]))
    used = factor.backend
    del factor  # the last reference: PARDISO's memory is released now (phase -1)
    return u, rows, used


def _vertex_displacements(
    model, body, F: Array, vdofs, backend: str, n_threads: int | None = None
) -> tuple[Array, str]:
    """``(U, solver)``: the vertex displacements ``(n_positions, n_vertices, 3)`` mm of a
    contact sector under the consistent loads ``F`` ``(n_dofs, n_positions)`` N, and the sparse
    backend that solved them, from the cache when the same sector was solved under the same
    loads before (a run repeated: no factorisation), else one factorisation for all positions
    (kept in the process, :func:`_factorised`, for the next loads on the same sector: the
    variants of a study) and one solve with ``n_threads`` MKL threads (None: as factorised)."""
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
        full[body.free] = factor.solve(np.ascontiguousarray(F[body.free]), n_threads)
        U = np.transpose(full[vdofs], (2, 0, 1))
        entry.write(".npy", lambda p: np.save(p, U))
        return {"solver": factor.backend}

    entry, record, _ = cached_record("fields", params, build)
    return np.load(entry.path(".npy")), str(record["solver"])


def _member_loads(name: str, smodel, place: Array, cycle, n_dofs: int) -> Array:
    """``F`` ``(n_dofs, n_positions)`` N: the consistent loads ``P f`` of the converged cell
    forces on member ``name`` at every position (``P`` as in the contact solve,
    :func:`fegear.ltca.model.member_load_operator`: pinion cells along ``−n1`` at the pinion
    flank points, gear cells along ``+n1`` at the points moved across the gap). Only the loaded
    cells (``f ≠ 0``) are located on the flank: a cell without force adds nothing to ``P f``
    (its products are zeros, and a zero added leaves a sum as it was), and locating the points
    was most of the time of the loads, on cell grids that are mostly open."""
    F = np.zeros((n_dofs, len(cycle.positions)))
    for i, pos in enumerate(cycle.positions):
        cols, forces, start = [], [], 0
        for c in pos.cells or ():
            f = pos.solution.force[start : start + c.n]
            start += c.n
            on = f != 0.0
            if not on.any():
                continue
            x, nrm = c.quad_points[on], c.normals[on]
            if name == "pinion":
                cols.append(member_load_operator(smodel, place[i], c.k, x, -nrm))
            else:
                x = x + c.gap[on, None, None] * nrm[:, None]
                cols.append(member_load_operator(smodel, place[i], c.j, x, nrm))
            forces.append(f[on])
        if cols:
            F[:, i] = sp.hstack(cols).tocsr() @ np.concatenate(forces)
    return F


def _loaded_points(pos, member: str, placement: Array) -> dict[int, Array]:
    """``{member tooth: (q, 3) mm}``: the centres of the loaded contact cells of a position on
    each tooth of ``member`` (its frame; gear cells moved across their gap onto its flank)."""
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
    factorisation per member; with ``root_stress`` the members one after the other, each
    factor released before the next sector is meshed: :func:`_stress_solve`). The rigid lag
    ``θ`` of member 2 is not part of ``u`` (the sectors are clamped at the bore and the cuts);
    the VTK places the gear at its unloaded (TCA-closed) angle. Then, per position, the
    recovered vertex stresses, the root stress of every tooth that can touch
    (:func:`fegear.fem.stress.tooth_root_stress`) and the equilibrium of the solve
    (:func:`fegear.fem.stress.reactions`).

    ``refine_teeth``: ``{member: sector teeth}`` whose flank (and fillets) the stress sector
    refines (default: every tooth that can carry load; a refinement study refines the tooth it
    reads only);
    ``keep_dofs``: keep the P2 displacement and the body in the :class:`MemberField`.
    ``root_stress`` False: the displacement on the contact sectors themselves (no remeshing, the
    factorisation of a sector of the contact model's size), without stresses (the contact
    sectors' fillets are as coarse as their level: their stresses are not the root stress).
    ``backend``: of the sparse Cholesky (:func:`fegear.linalg.solve.factorize_spd`).

    Without root stress and kept DOFs (the vertex displacements only, a sweep's fields), the
    two members' solves run in threads, one MKL thread each (:func:`_vertex_displacements`):
    the pinion's solve while the gear's loads are built, then the two solves side by side
    (on the seed face gear a second MKL thread shortens a solve by 10 % for twice its CPU: two
    one-thread solves side by side take 0.36 s where the two two-thread solves took 0.58 s, and
    0.66 s of CPU instead of 1.15 s). The displacements are those of the two-thread solves
    (bit for bit in the runs compared; PARDISO promises round-off); the root-stress path keeps
    its solve as it was.
    """
    with ThreadPoolExecutor(max_workers=2, thread_name_prefix="fegear-fields") as pool:
        out, solves, notes = _members(
            pool, run_pair, asm, models, cycle, phi2, fillet_modules, refine_teeth, keep_dofs,
            root_stress, backend,
        )  # fmt: skip
        for k, job in solves.items():
            U, used = job.result()
            out[k] = replace(out[k], displacement=U, solver=used)
    for k, (fmt, args, t0) in enumerate(notes):
        log.info(fmt, *args, time.perf_counter() - t0 if k in solves else t0, out[k].solver)
    return tuple(out)


def _members(
    pool, run_pair, asm, models, cycle, phi2, fillet_modules, refine_teeth, keep_dofs,
    root_stress, backend,
) -> tuple[list[MemberField], dict[int, Future], list[tuple[str, tuple, float]]]:  # fmt: skip
    """The body of :func:`displacements`: ``(fields, solves, notes)``, the fields of the two
    members (the displacement of those in ``solves`` still zero: ``{index: its solve running in
    pool}``) and per member its log line (format, arguments, then the start time of a pending
    solve, else the seconds it took)."""
    out: list[MemberField] = []
    solves: dict[int, Future] = {}
    notes: list[tuple[str, tuple, float]] = []
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
        F = _member_loads(name, smodel, place, cycle, body.n_dofs)
        U = np.zeros((n_pos, n_v, 3))
        full = np.zeros((body.n_dofs, n_pos))
        used = "none"
        loaded = np.flatnonzero(np.any(F != 0.0, axis=0))
        K = None
        if loaded.size and not (root_stress or keep_dofs):
            ctx = contextvars.copy_context()  # the cache's and the journal's context
            solves[len(out)] = pool.submit(ctx.run, _vertex_displacements, smodel, body, F,
                                           vdofs, backend, 1)  # fmt: skip
        elif loaded.size and root_stress:
            full[body.free], K, used = _stress_solve(body, F, backend)
            U = np.transpose(full[vdofs], (2, 0, 1))
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
        fixed = np.setdiff1d(np.arange(body.n_dofs), body.free) if root_stress else None
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
        notes.append((
            "%s: %s sector (fillets %s mm, %d tets), %d positions in %.2f s (%s)",
            (name, "stress" if root_stress else "contact", h_fil, body.mesh.t.shape[1], n_pos),
            t0 if len(out) in solves else time.perf_counter() - t0,
        ))  # fmt: skip
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
    return out, solves, notes
