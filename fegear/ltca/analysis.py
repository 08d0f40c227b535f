"""The contact models of a loaded mesh cycle: the options (:class:`LTCAOptions`), the contact
zone of the sectors (:func:`cycle_zone`) and the member models every position is solved on
(:func:`build_models`).

One position's loaded contact is :func:`fegear.ltca.position.solve_position` (the formulation:
``docs/ltca/contact_formulation.md``); :func:`fegear.ltca.cycle.run_ltca` runs the positions of
a cycle.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from fegear.errors import InputError
from fegear.forked import apart, process_count
from fegear.linalg.schur import resolve_backend
from fegear.ltca.fidelity import Fidelity, fidelity_of
from fegear.ltca.model import (
    MemberModel,
    build_member_model,
)
from fegear.ltca.position import solve_position
from fegear.ltca.zone import ContactZone, contact_zone
from fegear.mesh import gmsh_session
from fegear.mesh.sector import FINE, mesh_sizes, sector_mesh
from fegear.mesh.sector_geometry import sector_frame
from fegear.options import ContactOptions
from fegear.store.cache import count_lookups, recorded
from fegear.store.memo import Memo
from fegear.tca import TCAOptions
from fegear.tca.cached import cached_tca

__all__ = ["LTCAOptions", "MemberModels", "build_models", "cycle_zone", "solve_position"]

log = logging.getLogger(__name__)

# The cycle whose TCA gives the contact zone of the sector meshes (cycle_zone).
_ZONE_POSITIONS = 25

#: The member models last built in this process (one pair: two), given again to the next run
#: of the same members while their cache entries are unchanged (:mod:`fegear.store.memo`):
#: a sweep worker, a script over installation errors or a loop over fegear.run builds each
#: model once.
_MODELS: Memo[MemberModel] = Memo("member model", 2)


@dataclass(frozen=True)
class LTCAOptions:
    """Options of the loaded analysis.

    Attributes
    ----------
    n_positions
        Positions per mesh cycle.
    level
        Sector mesh level (0 coarse … 4 fine).
    n_teeth
        Teeth per sector; None: every tooth that can touch in the cycle plus one unloaded
        neighbour on each side (:func:`fegear.ltca.zone.contact_zone`; 5 on the seed face gear
        and the spiral bevel).
    E_MPa, nu
        Material of both members.
    backend
        Sparse direct backend.
    fidelity
        Name of the loaded :class:`~fegear.ltca.fidelity.Fidelity` (``"fe"``, ``"hertz"``,
        ``"hybrid"``).
    g_max_mm, cell_mm, tca_grid, n_across, n_along, max_cells, depth_elements, \
    depth_max_modules, trim, chunk_positions
        Tuning of the contact models: :class:`fegear.options.ContactOptions` (the ``[contact]``
        section of a case), whose defaults and checks these are. Cells much smaller than the P2
        elements make the FE compliance ``PᵀK⁻¹P`` rank-deficient (more cells than surface DOFs
        under them), so ``fe`` keeps element-sized cells and only ``hybrid`` refines them to
        ``n_across`` × ``n_along`` per patch. ``chunk_positions`` is part of the method (each
        position of a chunk starts from its predecessor: the result depends on it within the
        grid-refinement tolerance), ``workers`` is not. The measurements behind the defaults:
        ``benchmarks/results/contact_options.md``.
    workers
        Processes solving the chunks in parallel; None: one per core (at most one per chunk).
    """

    n_positions: int = 25
    level: int = 0
    n_teeth: int | None = None
    cell_mm: float | None = ContactOptions.default("cell_mm")
    g_max_mm: float = ContactOptions.default("g_max_mm")
    tca_grid: tuple[int, int] = ContactOptions.default("tca_grid")
    E_MPa: float = 206000.0
    nu: float = 0.3
    backend: str = "auto"
    fidelity: str = "fe"
    n_across: int = ContactOptions.default("n_across")
    n_along: int = ContactOptions.default("n_along")
    max_cells: int = ContactOptions.default("max_cells")
    depth_elements: float = ContactOptions.default("depth_elements")
    depth_max_modules: float = ContactOptions.default("depth_max_modules")
    trim: float = ContactOptions.default("trim")
    chunk_positions: int = ContactOptions.default("chunk_positions")
    workers: int | None = None

    def __post_init__(self) -> None:
        fidelity_of(self.fidelity)  # InputError naming the registered fidelities
        self.contact  # noqa: B018  (InputError naming a bad tuning option)
        if self.workers is not None and not (isinstance(self.workers, int) and self.workers >= 1):
            raise InputError("workers", self.workers, "an integer >= 1, or None for all cores")
        if self.n_teeth is not None and not (isinstance(self.n_teeth, int) and self.n_teeth >= 1):
            raise InputError("n_teeth", self.n_teeth, "an integer >= 1, or None (automatic)")

    @property
    def contact(self) -> ContactOptions:
        """The tuning of the contact models as a :class:`~fegear.options.ContactOptions`."""
        return ContactOptions(**{n: getattr(self, n) for n in ContactOptions.names()})


@dataclass(frozen=True)
class MemberModels:
    """FE models of both members and the cell size that goes with them."""

    pinion: MemberModel
    gear: MemberModel
    cell_mm: float
    seconds: float
    fidelity: str = "fe"
    depth_mm: float = 0.0
    E: float = 206000.0
    nu: float = 0.3
    n_across: int = 8
    n_along: int = 16
    max_cells: int = 600
    zone: ContactZone | None = None
    trim: float = 0.3

    @property
    def kind(self) -> Fidelity:
        """The :class:`~fegear.ltca.fidelity.Fidelity` the models were built for."""
        return fidelity_of(self.fidelity)


def cycle_zone(
    pinion,
    gear,
    assembly,
    options: LTCAOptions,
    gap_mm: float | None = None,
    exact: bool = False,
) -> ContactZone:
    """The contact zone (:func:`fegear.ltca.zone.contact_zone`) of the default cycle of
    ``_ZONE_POSITIONS`` positions (the TCA comes from its cache), with the separation bound
    ``gap_mm`` (default ``g_max``, where the contact grids start). The first zone is the sampled
    one (``exact=False``); when a pair outside it can close under the solved lag,
    :func:`fegear.ltca.run_ltca` rebuilds the sectors on the exact zone of the grown bound
    (:func:`fegear.ltca.cycle.grown_zone`). The zone does not depend on the positions asked
    for, so every run on the pair shares the meshes."""
    n = _ZONE_POSITIONS
    tca_opt = TCAOptions(
        n_positions=n, separation_grid=options.tca_grid, E_MPa=options.E_MPa, nu=options.nu
    )
    phi1 = -np.pi / assembly.n1 + 2 * np.pi / assembly.n1 * np.arange(n) / n
    tca, positions, _ = cached_tca(pinion, gear, assembly, tca_opt, phi1)
    return contact_zone(
        positions,
        tca.fm1.bounds,
        tca.fm2.bounds,
        assembly.side1,
        assembly.side2,
        options.g_max_mm if gap_mm is None else gap_mm,
        n_teeth=options.n_teeth,
        exact=exact,
    )


def _sector_meshes_apart(members, sides, n_teeth: int, level: int, workers: int | None) -> list:
    """Both members' sector meshes (:func:`fegear.mesh.sector.sector_mesh`) as two functions
    that return them: the gear's is started now in a forked process when two processes are
    allowed (``workers``; :func:`fegear.forked.apart`), the pinion's is made here when asked
    for, so that what is done with it (its operator) runs while the gear is meshed. gmsh meshes
    on one thread (deterministic meshes). The mesh made in the other process is the one made
    here (same code and inputs, the cache entry it writes is read back the same); its cache
    lookups are counted as this run's (:func:`fegear.store.cache.recorded`). A process that
    has run gmsh before meshes both here (:func:`fegear.mesh.gmsh_session.started_here`); one
    told to keep gmsh out (:func:`fegear.mesh.gmsh_session.mesh_elsewhere`) meshes both in
    forked processes."""

    def one(i: int):
        return recorded(lambda: sector_mesh(members[i], n_teeth, level, side=sides[i]))

    # a process that has run gmsh cannot mesh in a fork of itself (gmsh_session.started_here);
    # one that is to fork meshing processes later meshes in forks too (meshes_elsewhere)
    both = gmsh_session.meshes_elsewhere()
    fork = both or (process_count(workers, 2) > 1 and not gmsh_session.started_here())
    first = apart(lambda: one(0), True) if both else None
    later = apart(lambda: one(1), fork)

    def get(i: int):
        sm, lookups = (first() if first else one(0)) if i == 0 else later()
        count_lookups(lookups)
        return sm

    return [lambda: get(0), lambda: get(1)]


def build_models(
    pinion, gear, assembly, options: LTCAOptions, zone: ContactZone | None = None
) -> MemberModels:
    """Mesh both sectors of ``zone.n_teeth`` teeth (default :func:`cycle_zone`), fine on the
    whole working flank of every tooth that can carry load (all but the outer tooth at each
    end), and compute their compliance operators (cached).

    What the models depend on is the member's design, the tooth count, the mesh level, the
    working side and the material: not the installation errors, the torque, the positions or
    the fidelity (the TCA's zone only sets the tooth count), so a study over any of those reads
    them from the cache (``docs/ltca/studies.md``). The operator of each member is the flank
    block ``(K⁻¹)_ff`` of those teeth, shared by every fidelity, plus, for ``hybrid``, one
    block per tooth for the layer below its flank (:func:`~fegear.ltca.model.build_member_model`),
    each a cache entry of its own."""
    t0 = time.perf_counter()
    if zone is None:
        zone = cycle_zone(pinion, gear, assembly, options)
    n = zone.n_teeth
    sides = (assembly.side1, assembly.side2)
    # the fine element size of each sector, as its mesh records it (mesh_sizes of its frame's
    # module), known before the meshes: the pinion's operator is built while the gear is meshed
    fine = [mesh_sizes(sector_frame(m).module, options.level)[0] for m in (pinion, gear)]
    h = max(fine)
    module = min(f / FINE[options.level] for f in fine)
    depth = layer = fidelity_of(options.fidelity).layer_depth(h, module, options)
    loaded = tuple(range(1, n - 1)) if n >= 3 else tuple(range(n))

    def model(i: int, sm) -> MemberModel:
        assert float(sm.parameters["h_fine_mm"]) == fine[i], "the size the layer was made for"
        return build_member_model(
            (pinion, gear)[i].name,
            sm,
            sides[i],
            options.E_MPa,
            options.nu,
            options.backend,
            layer_mm=layer,
            teeth=loaded,
        )

    # what a member's model is made from (its mesh and operator entries' keys hold the same)
    made_of = [
        {"member": repr(m), "side": sides[i], "n_teeth": n, "level": options.level,
         "E": options.E_MPa, "nu": options.nu, "backend": resolve_backend(options.backend),
         "layer_mm": layer, "teeth": loaded}
        for i, m in enumerate((pinion, gear))
    ]  # fmt: skip
    kept = [_MODELS.holds(p) for p in made_of]
    # the gear's sector meshed in a second process while this one meshes the pinion's and
    # builds its operator; one process: one after the other (the same meshes and operators)
    workers = options.workers if not kept[1] else 1  # a kept gear model needs no mesh
    meshes = (
        [] if all(kept) else _sector_meshes_apart((pinion, gear), sides, n, options.level, workers)
    )
    models = [_MODELS.get(made_of[i], lambda i=i: model(i, meshes[i]()))[0] for i in range(2)]
    cell = options.cell_mm if options.cell_mm is not None else h
    return MemberModels(
        models[0],
        models[1],
        cell,
        time.perf_counter() - t0,
        fidelity=options.fidelity,
        depth_mm=depth,
        E=options.E_MPa,
        nu=options.nu,
        n_across=options.n_across,
        n_along=options.n_along,
        max_cells=options.max_cells,
        zone=zone,
        trim=options.trim,
    )
