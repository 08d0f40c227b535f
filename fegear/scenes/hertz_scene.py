"""The Hertz scene: a crowned roller pressed on a block, solved with the FE contact engine.

This is the scene whose answer is known. The same pieces the gear analysis uses run here
unchanged: gmsh meshes (:mod:`fegear.mesh.hertz_scene_bodies`), scikit-fem stiffness
(:mod:`fegear.fem`), the Schur-complement compliance on a contact grid
(:mod:`fegear.mechanics.compliance`) and the active-set solver
(:mod:`fegear.mechanics.contact`); the closed-form Hertz solution
(:mod:`fegear.mechanics.hertz_closed_form`) is the reference.

Contact grid: square cells of side ``s`` in the common tangent plane ``z = 0`` covering the
rectangle ``|x| <= X, |y| <= Y`` (its quarter with symmetry), ``X, Y`` = ``margin`` × the Hertz
semi-axes (the grid only has to contain the patch; a patch touching the grid edge is an error).
Each cell has a 3 × 3 Gauss quadrature; its points lie on the block's face ``z = 0`` and, at the
same ``(x, y)``, on the roller's exact barrel surface. The initial gap of a cell is the cell average
of the exact roller height. The force of a cell acts along ``-z`` on the block and ``+z`` on the
roller; ``C = C_block + C_roller``; the rigid unknown is the approach of the roller's axle towards
the block's table, and the constraint is force balance.

Levels: level ``L`` has ``n`` cells across the Hertz minor axis ``2b`` (``CELLS_ACROSS_MINOR``)
and FE elements of side ``h = ELEMENT_TO_CELL × s`` in the refined zone.

Patch size from the computed field: the second moments of the pressure, ``<x²> = Σ F x² / Σ F``;
for a Hertz distribution ``<x²> = b²/5`` along the minor axis and ``<y²> = a²/5`` along the major
one, so the reported semi-axes are ``sqrt(5 <·>)`` of the principal second moments. This measure
converges with the grid (no quantisation by the cell size), unlike the extent of the active cells,
which is reported too.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np

from fegear.errors import InputError
from fegear.fem.elasticity import ElasticBody, assemble_body
from fegear.linalg.solve import factorize_spd
from fegear.mechanics.compliance import (
    body_compliance,
    candidate_operator,
    cross_compliance,
    load_operator,
    probe_operator,
)
from fegear.mechanics.contact import ContactSolution, solve_contact
from fegear.mechanics.halfspace import subsurface_influence
from fegear.mechanics.hertz_closed_form import HertzPoint, hertz_point_radii
from fegear.mechanics.patch import measure_patch
from fegear.mesh.hertz_scene_bodies import (
    BodyMeshSpec,
    cached_body_mesh,
    read_tet_mesh,
    roller_height,
)

__all__ = [
    "CELLS_ACROSS_MINOR",
    "ELEMENT_TO_CELL",
    "HertzScene",
    "HertzLevelResult",
    "BodyField",
    "hertz_reference",
    "run_level",
]

log = logging.getLogger(__name__)

#: Cells across the Hertz minor axis 2b at each level (level 0 = coarsest).
CELLS_ACROSS_MINOR = (6, 8, 12, 16, 24, 32)
#: FE element size in the refined zone, in cell sizes.
ELEMENT_TO_CELL = 2.0
#: Depth of the FE matching points of the hybrid fidelity, in FE element sizes.
HYBRID_DEPTH_ELEMENTS = 2.0
#: Fewer cells than this across the computed minor axis triggers a warning (``docs/fidelity.md``:
#: resolution).
MIN_CELLS_ACROSS_MINOR = 8.0


@dataclass(frozen=True)
class HertzScene:
    """Inputs of the Hertz scene (mm, N, MPa).

    ``roller_radii_mm = (Rx, Ry)``: the roller's principal radii at the contact point, ``Rx``
    about the roller axis ``y`` (curvature in the x-z plane), ``Ry`` the crown radius (curvature in
    the y-z plane). The block is flat.
    """

    force_N: float = 2000.0
    roller_radii_mm: tuple[float, float] = (20.0, 100.0)
    roller_half_length_mm: float = 15.0
    block_half_size_mm: float = 20.0
    block_height_mm: float = 20.0
    E_roller_MPa: float = 206000.0
    nu_roller: float = 0.3
    E_block_MPa: float = 206000.0
    nu_block: float = 0.3
    symmetry: str = "quarter"
    grid_margin: float = 1.35

    def __post_init__(self) -> None:
        f = self.force_N
        if not (isinstance(f, (int, float)) and math.isfinite(f) and f > 0):
            raise InputError("force_N", f, "a finite number > 0")
        if len(self.roller_radii_mm) != 2:
            raise InputError("roller.radii_mm", self.roller_radii_mm, "[Rx, Ry]")
        for i, r in enumerate(self.roller_radii_mm):
            if r is None or not math.isfinite(r) or r <= 0:
                raise InputError(f"roller.radii_mm[{i}]", r, "a finite radius > 0 mm")
        if self.roller_radii_mm[0] > self.roller_radii_mm[1]:
            raise InputError(
                "roller.radii_mm", self.roller_radii_mm, "Rx <= Ry (major axis along y)"
            )
        for name in ("roller_half_length_mm", "block_half_size_mm", "block_height_mm"):
            v = getattr(self, name)
            if not math.isfinite(v) or v <= 0:
                raise InputError(name, v, "> 0")
        for name in ("E_roller_MPa", "E_block_MPa"):
            v = getattr(self, name)
            if not math.isfinite(v) or v <= 0:
                raise InputError(name, v, "> 0 MPa")
        for name in ("nu_roller", "nu_block"):
            v = getattr(self, name)
            if not (math.isfinite(v) and -1.0 < v < 0.5):
                raise InputError(name, v, "in (-1, 0.5)")
        if self.symmetry not in ("quarter", "none"):
            raise InputError("mesh.symmetry", self.symmetry, "'quarter' or 'none'")
        if not self.grid_margin > 1.0:
            raise InputError("mesh.grid_margin", self.grid_margin, "> 1")


@dataclass(frozen=True)
class BodyField:
    """What a VTK writer needs of one body: mesh, displacement, contact pressure on its nodes."""

    name: str
    points: np.ndarray  # (n, 3) mm
    tets: np.ndarray  # (m, 4)
    displacement: np.ndarray  # (n, 3) mm at the vertices
    dofs: int


@dataclass(frozen=True)
class HertzLevelResult:
    """Result of the Hertz scene at one level.

    Arrays: ``centers`` (n, 2) mm cell centres (the modelled part: a quarter with symmetry),
    ``half_width`` mm, ``pressure`` (n,) MPa, ``force`` (n,) N.
    """

    level: int
    cells_across_minor: int
    cell_size_mm: float
    h_fine_mm: float
    p0_MPa: float
    p_max_cell_MPa: float
    a_mm: float
    b_mm: float
    a_extent_mm: float
    b_extent_mm: float
    approach_mm: float
    n_cells: int
    n_active: int
    dofs: dict[str, int]
    seconds: dict[str, float]
    cache_hit: bool
    backend: str
    solution: ContactSolution
    centers: np.ndarray
    half_width: float
    pressure: np.ndarray
    force: np.ndarray
    symmetry: str
    fidelity: str
    modelled_fraction: float
    hertz: HertzPoint
    warnings: tuple[str, ...] = field(default=())
    bodies: tuple[BodyField, ...] = field(default=())

    def error(self, name: str) -> float:
        """Relative error of ``p0``, ``a``, ``b`` or ``approach`` against Hertz."""
        ref = {
            "p0": self.hertz.p0_MPa,
            "a": self.hertz.a_mm,
            "b": self.hertz.b_mm,
            "approach": self.hertz.approach_mm,
        }[name]
        val = {"p0": self.p0_MPa, "a": self.a_mm, "b": self.b_mm, "approach": self.approach_mm}[
            name
        ]
        return (val - ref) / ref


def hertz_reference(scene: HertzScene) -> HertzPoint:
    """Closed-form Hertz solution of the scene (roller on a flat block)."""
    return hertz_point_radii(
        scene.force_N,
        scene.roller_radii_mm,
        None,
        scene.E_roller_MPa,
        scene.nu_roller,
        scene.E_block_MPa,
        scene.nu_block,
    )


def _gauss3() -> tuple[np.ndarray, np.ndarray]:
    """3-point Gauss-Legendre on [-1, 1]: nodes and weights / 2 (weights sum to one)."""
    x, w = np.polynomial.legendre.leggauss(3)
    return x, w / 2.0


def _grid(
    scene: HertzScene, ref: HertzPoint, s: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cell centres (n, 2), quadrature points (n, 9, 2) and weights (n, 9)."""
    # The major axis (a) is along the direction of the larger radius.
    Rx, Ry = scene.roller_radii_mm
    ax, ay = (ref.b_mm, ref.a_mm) if Rx <= Ry else (ref.a_mm, ref.b_mm)
    nx = int(math.ceil(scene.grid_margin * ax / s))
    ny = int(math.ceil(scene.grid_margin * ay / s))
    if scene.symmetry == "quarter":
        xc = (np.arange(nx) + 0.5) * s
        yc = (np.arange(ny) + 0.5) * s
    else:
        xc = (np.arange(-nx, nx) + 0.5) * s
        yc = (np.arange(-ny, ny) + 0.5) * s
    X, Y = np.meshgrid(xc, yc, indexing="ij")
    centers = np.column_stack([X.ravel(), Y.ravel()])
    g, w = _gauss3()
    gx, gy = np.meshgrid(g, g, indexing="ij")
    offs = 0.5 * s * np.column_stack([gx.ravel(), gy.ravel()])
    ww = np.outer(w, w).ravel()
    qp = centers[:, None, :] + offs[None, :, :]
    return centers, qp, np.broadcast_to(ww, qp.shape[:2]).copy()


def _mesh_spec(scene: HertzScene, ref: HertzPoint, s: float) -> BodyMeshSpec:
    Rx, Ry = scene.roller_radii_mm
    ax, ay = (ref.b_mm, ref.a_mm) if Rx <= Ry else (ref.a_mm, ref.b_mm)
    if ax > ay:
        raise InputError("roller.radii_mm", scene.roller_radii_mm, "Rx <= Ry (major axis along y)")
    h = ELEMENT_TO_CELL * s
    coarse = min(scene.block_height_mm, scene.roller_radii_mm[0]) / 4.0
    return BodyMeshSpec(
        h_fine=h,
        h_coarse=max(coarse, 2 * h),
        r_fine=scene.grid_margin * ax + h,
        segment_length=scene.grid_margin * ay,
        symmetry=scene.symmetry,
    )


def _clamps(body: str, symmetry: str) -> list[tuple[str, str]]:
    fixed = [("bottom", "xyz")] if body == "block" else [("axle", "xyz")]
    if symmetry == "quarter":
        fixed += [("sym_x", "x"), ("sym_y", "y")]
    return fixed


def hybrid_compliance(
    op,
    P,
    Q,
    centers: np.ndarray,
    half_width: float,
    depth: float,
    E: float,
    nu: float,
    quarter: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """Hybrid compliance of one body: coarse FE below a matching depth, half-space above it.

    Following Vijayakar (1991, IJNME 31, 525: a combined surface integral and finite element
    solution of 3-D contact), the approach of cell ``i`` under the cell forces is split at a
    matching point ``y_i = x_i + d e_i`` at depth ``d`` below the cell centre ``x_i``:

    .. math::

        w_i = \\underbrace{Q_i^T K^{-1} P F}_{\\text{FE at depth } d}
            + \\underbrace{\\sum_j \\big[u^{hs}(x_i; j) - u^{hs}(y_i; j)\\big] F_j}
              _{\\text{half-space compression of the top layer}} .

    The FE is accurate at ``y_i`` when ``d`` is a few element sizes (there the coarse mesh no
    longer has to resolve the pressure's near field), and the half-space is accurate for the
    layer ``[0, d]`` when ``d`` is small against the body's radii; the FE's own (wrong) near field
    is what the matching removes: the part the coarse FE carries above ``y_i`` is never used.
    With ``d`` tied to the element size (``HYBRID_DEPTH_ELEMENTS``) the correction layer shrinks
    as the FE is refined, so the hybrid tends to the pure FE answer. The FE part is not exactly
    symmetric; the symmetric part is used. With quarter symmetry the half-space terms include the
    three mirror images of every cell (the FE carries them through its symmetry conditions).

    Returns the (n, n) compliance and its half-space part.
    """
    C_fe = cross_compliance(op, Q, P)
    hw = np.full((centers.shape[0], 2), half_width)
    images = [(1, 1), (1, -1), (-1, 1), (-1, -1)] if quarter else [(1, 1)]
    near = np.zeros_like(C_fe)
    for sx, sy in images:
        c_img = centers * [sx, sy]
        near += subsurface_influence(centers, 0.0, c_img, hw, E, nu)
        near -= subsurface_influence(centers, depth, c_img, hw, E, nu)
    C = 0.5 * (C_fe + C_fe.T) + 0.5 * (near + near.T)
    return C, near


def run_level(
    scene: HertzScene,
    level: int,
    backend: str = "auto",
    with_fields: bool = False,
    fidelity: str = "fe",
    fe_level: int = 0,
) -> HertzLevelResult:
    """Solve the scene at one level (0 = coarsest) and compare with Hertz.

    Parameters
    ----------
    scene
        The inputs.
    level
        Index into :data:`CELLS_ACROSS_MINOR`.
    backend
        Sparse direct backend for the compliance ("auto", "pardiso", "superlu").
    with_fields
        Also compute the displacement fields of both bodies (one extra sparse solve each), for
        the VTK output.
    fidelity
        ``"fe"``: the compliance of each body is pure FE on the level's grid and a mesh refined
        to match it. ``"hybrid"``: the grid of the level, but the FE mesh of ``fe_level``, with
        the near field of every body replaced by the half-space (:func:`hybrid_compliance`).
    fe_level
        The level whose FE mesh is used: with ``hybrid`` always (a coarse mesh under a fine
        grid); with ``fe`` only when finer than ``level`` (elements smaller than the cells).
    """
    if fidelity not in ("fe", "hybrid"):
        raise InputError("fidelity", fidelity, "'fe' or 'hybrid'")
    if not (isinstance(level, int) and 0 <= level < len(CELLS_ACROSS_MINOR)):
        raise InputError("level", level, f"an integer in [0, {len(CELLS_ACROSS_MINOR) - 1}]")
    t_start = time.perf_counter()
    ref = hertz_reference(scene)
    n_minor = CELLS_ACROSS_MINOR[level]
    s = 2.0 * ref.b_mm / n_minor
    centers, qp, qw = _grid(scene, ref, s)
    n = centers.shape[0]
    # The FE mesh: ``fe`` refines it with the grid (or further, with fe_level > level);
    # ``hybrid`` keeps the mesh of fe_level whatever the grid.
    mesh_level = max(level, fe_level) if fidelity == "fe" else fe_level
    s_fe = 2.0 * ref.b_mm / CELLS_ACROSS_MINOR[mesh_level]
    spec = _mesh_spec(scene, ref, s_fe)
    Rx, Ry = scene.roller_radii_mm
    seconds: dict[str, float] = {}
    warnings: list[str] = []

    # Meshes (cached by content hash).
    t0 = time.perf_counter()
    block_geo = {"half_size": scene.block_half_size_mm, "height": scene.block_height_mm}
    roller_geo = {"radii": [Rx, Ry], "half_length": scene.roller_half_length_mm}
    path_b, hit_b = cached_body_mesh("block", block_geo, spec)
    path_r, hit_r = cached_body_mesh("roller", roller_geo, spec)
    seconds["mesh"] = time.perf_counter() - t0

    # Stiffness and compliance of each body.
    C = np.zeros((n, n))
    dofs: dict[str, int] = {}
    seconds["assembly"] = 0.0
    seconds["operator"] = 0.0
    hits = [hit_b, hit_r]
    used_backend = ""
    bodies: dict[str, tuple[ElasticBody, object]] = {}
    for name, path, _geo in (("block", path_b, block_geo), ("roller", path_r, roller_geo)):
        mesh = read_tet_mesh(path)
        clamped = _clamps(name, scene.symmetry)
        E, nu = (
            (scene.E_block_MPa, scene.nu_block)
            if name == "block"
            else (scene.E_roller_MPa, scene.nu_roller)
        )
        body = assemble_body(mesh, E, nu, clamped)
        z = (
            np.zeros(qp.shape[:2])
            if name == "block"
            else roller_height(qp[..., 0], qp[..., 1], Rx, Ry)
        )
        pts = np.concatenate([qp, z[..., None]], axis=-1)
        direction = np.tile([0.0, 0.0, -1.0 if name == "block" else 1.0], (n, 1))
        P = load_operator(body, "contact", pts, qw, direction)
        key = {"mesh": path.name, "clamped": clamped}
        if fidelity == "fe":
            op = candidate_operator(body, np.unique(P.nonzero()[0]), backend=backend, cache_key=key)
            C += body_compliance(op, P)
        else:
            depth = HYBRID_DEPTH_ELEMENTS * spec.h_fine
            surf = np.column_stack(
                [
                    centers,
                    roller_height(centers[:, 0], centers[:, 1], Rx, Ry)
                    if name == "roller"
                    else np.zeros(n),
                ]
            )
            Q = probe_operator(body, surf + depth * direction, direction)
            loaded = np.unique(P.nonzero()[0])
            cand = np.union1d(loaded, np.unique(Q.nonzero()[0]))
            op = candidate_operator(body, cand, backend=backend, cache_key=key, load_dofs=loaded)
            Cb, near = hybrid_compliance(
                op, P, Q, centers, 0.5 * s, depth, E, nu, quarter=scene.symmetry == "quarter"
            )
            C += Cb
        seconds["operator"] += op.seconds - body.assembly_seconds
        seconds["assembly"] += body.assembly_seconds
        hits.append(op.cache_hit)
        used_backend = op.backend if op.backend != "cache" else used_backend or "cache"
        dofs[name] = body.n_dofs
        bodies[name] = (body, P)

    # Contact solve: the cell gaps are cell averages of the exact roller height.
    gap = np.sum(qw * roller_height(qp[..., 0], qp[..., 1], Rx, Ry), axis=1)
    fraction = 0.25 if scene.symmetry == "quarter" else 1.0
    t0 = time.perf_counter()
    sol = solve_contact(C, gap, scene.force_N * fraction)
    seconds["solve"] = time.perf_counter() - t0

    area = s * s
    pressure = sol.force / area
    if scene.symmetry == "quarter":
        full_c = np.concatenate([centers * [sx, sy] for sx in (1, -1) for sy in (1, -1)])
        full_f = np.tile(sol.force, 4)
    else:
        full_c, full_f = centers, sol.force
    patch = measure_patch(full_c, full_f, area)
    a_mm, b_mm = patch.semi_major, patch.semi_minor
    act = centers[sol.active]
    ext = np.abs(act).max(axis=0) + 0.5 * s
    a_ext, b_ext = (ext[1], ext[0]) if Rx <= Ry else (ext[0], ext[1])
    # The patch must not reach the grid edge: then the grid truncated it.
    edge = np.abs(centers).max(axis=0)
    if np.any(np.abs(act).max(axis=0) >= edge - 1e-12):
        warnings.append(
            "the contact patch reaches the edge of the contact grid: enlarge grid_margin"
        )
        log.warning(warnings[-1])
    ratio = 2.0 * b_mm / s
    if ratio < MIN_CELLS_ACROSS_MINOR:
        warnings.append(
            f"contact grid too coarse for the ellipse: {ratio:.1f} cells across the minor axis "
            f"(2b = {2 * b_mm:.3g} mm, cell {s:.3g} mm); at least {MIN_CELLS_ACROSS_MINOR:g} "
            "are needed for percent accuracy"
        )
        log.warning(warnings[-1])

    fields: list[BodyField] = []
    if with_fields:
        t0 = time.perf_counter()
        for name, (body, P) in bodies.items():
            fields.append(_body_field(name, body, P @ sol.force, backend))
        seconds["fields"] = time.perf_counter() - t0
    seconds["total"] = time.perf_counter() - t_start
    return HertzLevelResult(
        level=level,
        cells_across_minor=n_minor,
        cell_size_mm=s,
        h_fine_mm=spec.h_fine,
        p0_MPa=patch.p_peak,
        p_max_cell_MPa=patch.p_max_cell,
        a_mm=a_mm,
        b_mm=b_mm,
        a_extent_mm=float(a_ext),
        b_extent_mm=float(b_ext),
        approach_mm=sol.theta,
        n_cells=n,
        n_active=sol.n_active,
        dofs=dofs,
        seconds=seconds,
        cache_hit=all(hits),
        backend=used_backend,
        solution=sol,
        centers=centers,
        half_width=0.5 * s,
        pressure=pressure,
        force=sol.force,
        symmetry=scene.symmetry,
        fidelity=fidelity,
        modelled_fraction=fraction,
        hertz=ref,
        warnings=tuple(warnings),
        bodies=tuple(fields),
    )


def _body_field(name: str, body: ElasticBody, f: np.ndarray, backend: str) -> BodyField:
    """Displacement of a body under the contact forces (one sparse SPD solve on the free DOFs,
    :func:`fegear.linalg.solve.factorize_spd` with the scene's backend)."""
    u = np.zeros(body.n_dofs)
    u[body.free] = factorize_spd(body.K, backend).solve(f[body.free])
    nv = body.mesh.p.shape[1]
    disp = u[: 3 * nv].reshape(nv, 3)
    return BodyField(
        name=name,
        points=body.mesh.p.T.copy(),
        tets=body.mesh.t.T.copy(),
        displacement=disp,
        dofs=body.n_dofs,
    )
