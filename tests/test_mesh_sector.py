"""Tooth-sector meshes (docs/mesh/README.md): named groups, flank accuracy, volume, static
convergence.

Meshes are cached (``meshes/cache`` or ``$FEGEAR_CACHE``); a cold run meshes the coarsest levels
only. The default suite checks the FZG pinion and the face gear; the face-gear pinion and the
spiral bevel pinion and gear (with their generated fillets: the envelopes of the blades' edge
radii) run under ``-m slow`` (the bevel pair design alone takes ~15 s).
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path

import numpy as np
import pytest

from fegear.errors import InputError
from fegear.geometry import FaceGearDesign, FaceGearMember, InvoluteDesign, InvoluteMember
from fegear.mesh.sector import FlankZone, SectorMesh, mesh_sizes, sector_mesh
from fegear.mesh.sector_check import tooth_compliance
from fegear.mesh.sector_geometry import (
    fillet_distance,
    flank_distance,
    section_integral_volume,
    sector_frame,
)

log = logging.getLogger(__name__)


def fzg_pinion() -> InvoluteMember:
    return InvoluteMember(
        InvoluteDesign(16, 4.5, 20.0, profile_shift=0.1817, face_width_mm=14.0), "pinion"
    )


def face_gear_pinion() -> InvoluteMember:
    # FaceGearMember.pinion() keeps the 0.38 rack tip radius, which the validation refuses for
    # α = 25° with h_f* = 1.25 (tip arcs overlap); 0.3 is the largest round value allowed.
    d = FaceGearDesign()
    return InvoluteMember(
        InvoluteDesign(
            d.n_pinion, d.module_mm, d.pressure_angle_deg, rack_tip_radius_coeff=0.3,
            face_width_mm=d.pinion_face_width_mm,
        ),
        "pinion",
    )  # fmt: skip


@pytest.fixture(scope="session")
def bevel_pair(spiral_bevel_pair):
    return spiral_bevel_pair  # the session's (tests/conftest.py)


# every family at least in the slow suite; FZG pinion + face gear in the default one
MEMBERS = [
    "fzg_pinion",
    "face_gear",
    pytest.param("face_gear_pinion", marks=pytest.mark.slow),
    pytest.param("bevel_pinion", marks=pytest.mark.slow),
    pytest.param("bevel_gear", marks=pytest.mark.slow),
]


@pytest.fixture(scope="session", params=MEMBERS)
def member(request):
    name = request.param
    if name == "fzg_pinion":
        return fzg_pinion()
    if name == "face_gear":
        return FaceGearMember(FaceGearDesign())
    if name == "face_gear_pinion":
        return face_gear_pinion()
    pair = request.getfixturevalue("bevel_pair")  # designed only when a bevel member runs
    return pair.pinion if name == "bevel_pinion" else pair.gear


@pytest.fixture(scope="session")
def sector(member) -> SectorMesh:
    return sector_mesh(member, n_teeth=3, level=0)


def test_named_groups(sector: SectorMesh):
    fixed = "base" if sector.family == "face_gear" else "bore"
    expected = {"cut_left", "cut_right", fixed, "face_start", "face_end"}
    for j in range(3):
        expected |= {f"flank_drive_{j}", f"flank_coast_{j}", f"fillet_{j}", f"top_{j}"}
    assert set(sector.boundaries) == expected
    assert all(len(t) > 0 for t in sector.boundaries.values())
    m = sector.to_skfem()
    assert m.t.shape[1] == len(sector.tets)
    # every named triangle is a boundary facet of the tet mesh (exact: same node indices)
    for name, tri in sector.boundaries.items():
        assert len(m.boundaries[name]) == len(tri), name
    # quality gate held (the mesher raises below it)
    assert sector.diagnostics["min_sicn"] >= 0.03
    # issue 20: the sectors with their generated fillets (face gear, bevel) mesh at the first
    # attempt, HXT (measured min SICN: face gear 0.052, bevel pinion 0.14, gear 0.19)
    assert sector.diagnostics["attempts"] == 1 and sector.diagnostics["algorithm3d"] == 10


def _local_size(mesh: SectorMesh, name: str) -> tuple[np.ndarray, np.ndarray]:
    tri = mesh.boundaries[name]
    p = mesh.points
    e = np.linalg.norm(p[tri] - p[np.roll(tri, 1, axis=1)], axis=-1)  # (k, 3) edge lengths
    nodes = np.unique(tri)
    acc = np.zeros(len(p))
    cnt = np.zeros(len(p))
    for c in range(3):
        np.add.at(acc, tri[:, c], e.mean(axis=1))
        np.add.at(cnt, tri[:, c], 1)
    return nodes, acc[nodes] / cnt[nodes]


def test_flank_nodes_on_analytic_surface(member, sector: SectorMesh):
    fr = sector_frame(member)
    j = sector.centre_tooth
    worst = 0.0
    for side in ("drive", "coast"):
        nodes, h = _local_size(sector, f"flank_{side}_{j}")
        d, _ = flank_distance(fr, side, 0, sector.points[nodes])
        worst = max(worst, float(np.max(d / h)))
        # tolerance: 1 % of the local element size (issue requirement); the CAD flank is a
        # spline loft through exact sections and gmsh puts boundary nodes on the CAD surface
        assert np.all(d < 0.01 * h), f"{side}: max distance / local size = {np.max(d / h):.2e}"
    log.info("%s: max flank-node distance / local size = %.2e", member.name, worst)


def test_fillet_nodes_on_the_generated_fillet(member, sector: SectorMesh):
    fr = sector_frame(member)
    if not fr.has_fillet:
        pytest.skip(f"{fr.family}: the root is a blend, not a generated fillet")
    worst = 0.0
    for j in range(sector.n_teeth):
        nodes, h = _local_size(sector, f"fillet_{j}")
        d = fillet_distance(fr, j - sector.centre_tooth, sector.points[nodes])
        worst = max(worst, float(np.max(d / h)))
        # tolerance: 1 % of the local element size, as for the flanks (the loft between the
        # exact sections sags most where the face-gear fillet shrinks to a point near 555 mm:
        # 0.011 mm there on 3.6 mm elements, measured)
        assert np.all(d < 0.01 * h), f"fillet_{j}: max distance / local size {np.max(d / h):.2e}"
    log.info("%s: max fillet-node distance / local size = %.2e", member.name, worst)


def test_volume_against_section_integral(member, sector: SectorMesh):
    fr = sector_frame(member)
    ref = section_integral_volume(fr, 3)
    err = sector.volume() / ref - 1
    # the estimate integrates the (φ, h) section of the same solid (exact flank points, the same
    # cubic root blends for face gear / bevel) along the face, independently of CAD and mesh.
    # Tolerance 1.2 %: what remains is linear tets chording curved faces, O(h²/R): the concave
    # bore/base side gains volume, convex faces lose it; +0.3 … +0.9 % at level 0 (measured, all
    # families), shrinking with refinement (see test_spur_volume_converges).
    assert abs(err) < 0.012, f"mesh volume {sector.volume():.1f} vs {ref:.1f}: {err:+.3%}"
    log.info("%s: volume error %+.3f %%", member.name, 100 * err)


def test_spur_static_convergence():
    """Deflection under a unit normal load at the pitch point, levels 0-1-2, bore+cuts fixed."""
    m = fzg_pinion()
    fr = sector_frame(m)
    d = np.array([tooth_compliance(sector_mesh(m, level=lv), fr) for lv in (0, 1, 2)])
    h = np.array([mesh_sizes(fr.module, lv)[0] for lv in (0, 1, 2)])
    e01, e12 = abs(d[1] - d[0]), abs(d[2] - d[1])
    rate = np.log(e01 / e12) / np.log(h[0] / h[1])
    msg = f"deflections {d} mm/N, observed rate {rate:.2f}"
    print(msg)
    # tolerance: the change from level 1 to 2 is below 3 % of the deflection (coarse levels;
    # the benchmark goes finer), and it shrinks (rate > 0.5: unstructured, non-nested meshes
    # with linear geometry give a noisy rate near 2)
    assert e12 < 0.03 * d[2], msg
    assert rate > 0.5, msg


def test_spur_volume_converges():
    """Mesh volume vs the section integral over levels 0-1-2 (meshes shared with the static
    check): the chording error shrinks towards 0."""
    m = fzg_pinion()
    ref = section_integral_volume(sector_frame(m), 3)
    err = np.array([sector_mesh(m, level=lv).volume() / ref - 1 for lv in (0, 1, 2)])
    msg = f"volume errors {np.round(100 * err, 3)} %"
    # tolerance: O(h²) chording, 0.9 % at level 0; level 2 (h/2) well below a third of it
    assert abs(err[2]) < 0.3 * abs(err[0]) and abs(err[2]) < 0.003, msg


def test_zone_and_inputs():
    m = fzg_pinion()
    with pytest.raises(InputError):
        sector_mesh(m, level=7)
    with pytest.raises(InputError):
        sector_mesh(m, zone=[FlankZone(5, "drive", (3.0, 6.0), (-2.0, 2.0))])


_SIGPIPE_CHECK = """
import sys
from pathlib import Path
import gmsh
from fegear.mesh.gmsh_session import initialize
def ignored():
    status = Path("/proc/self/status").read_text().splitlines()
    line = next(x for x in status if x.startswith("SigIgn"))
    return bool(int(line.split()[1], 16) & (1 << 12))  # bit 13 - 1: SIGPIPE
before = ignored()
gmsh.initialize(interruptible=False) if sys.argv[1] == "bare" else initialize()
print(before, ignored())
gmsh.finalize()
"""


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads /proc (Linux)")
@pytest.mark.parametrize(("start", "kept"), [("bare", False), ("fegear", True)])
def test_gmsh_leaves_sigpipe_ignored(start: str, kept: bool):
    """gmsh's first initialize() in a process resets SIGPIPE to 'terminate'; after it a write to
    a closed pipe (a worker process that died) killed the whole process silently (exit 141, seen
    as CI runs that stopped after 529 tests). fegear's gmsh start puts Python's 'ignore' back.
    Each case in a fresh interpreter: only the first initialize() does it."""
    import subprocess
    import sys

    out = subprocess.run(
        [sys.executable, "-c", _SIGPIPE_CHECK, start], capture_output=True, text=True, check=True
    ).stdout.split()
    assert out == ["True", str(kept)], out


_NATIVE_PRINT = """
import ctypes, logging, os, sys
from fegear.mesh.gmsh_session import native_output_to_log
logging.basicConfig(level=logging.DEBUG, stream=sys.stdout, format="LOG %(message)s")
log = logging.getLogger("t")
libc = ctypes.CDLL(None)
print("before", flush=True)
with native_output_to_log(log):
    libc.printf(b"from C stdout\\n")  # block-buffered while redirected: flushed by the helper
    os.write(2, b"from fd 2\\n")
print("after", flush=True)
"""


@pytest.mark.skipif(sys.platform == "win32", reason="C runtime lookup by ctypes.CDLL(None)")
def test_native_output_goes_to_the_log_not_the_terminal():
    """What gmsh's C++ meshers print past General.Terminal = 0 (seen: "Found two exactly
    self-intersecting facets") must not reach the terminal: a library logs, only the CLI prints.
    Native writes to fds 1 and 2 inside the block come out as log records, and the
    process's own output before and after is untouched. In a fresh interpreter: pytest's own
    capture sits on the same file descriptors."""
    import subprocess

    res = subprocess.run(
        [sys.executable, "-c", _NATIVE_PRINT], capture_output=True, text=True, check=True
    )
    lines = res.stdout.splitlines()
    assert lines[0] == "before" and lines[-1] == "after"
    # (the C stream is flushed when the block ends, so it may come after the direct write)
    assert sorted(lines[1:-1]) == ["LOG gmsh: from C stdout", "LOG gmsh: from fd 2"]
    assert res.stderr == ""


def test_the_dgamma_face_gear_sector_meshes_with_hxt_first_time():
    """The face gear of the Δγ = −0.02° case (fe level 0, its contact zone): on the session-7
    host gmsh's surface mesher closed the outer face end at the 0.8 mm wide top land with a
    triangle on the three collinear nodes of that edge; HXT then stopped ("two exactly
    self-intersecting facets") and the sector needed a second, slower attempt with another
    surface algorithm. Such a flat triangle is now found after the surface mesh and re-meshed
    with one segment on those short edges (``diagnostics["flat_triangles_fixed"]``: 1 there).
    Whether the surface mesher makes that triangle depends on the host's floating point (the
    AVX-512 host of session 10 made none: 0 fixed), so the test asks for what must hold on
    every host: one attempt, HXT, and a valid mesh."""
    from fegear.case_files import load_case
    from fegear.ltca import LTCAOptions
    from fegear.ltca.analysis import cycle_zone
    from fegear.pipeline.pair import build_pair

    repo = Path(__file__).resolve().parents[1]
    case = load_case(repo / "cases" / "face_gear_dgamma_minus.toml")
    pair = build_pair(case)
    opt = LTCAOptions(level=0, n_teeth=case.n_teeth, E_MPa=case.E_MPa, nu=case.nu)
    zone = cycle_zone(pair.pinion, pair.gear, pair.assembly, opt)
    sm = sector_mesh(pair.gear, zone.n_teeth, 0, zone=zone.gear)
    d = sm.diagnostics  # how the mesh was made (kept beside it in the cache)
    assert d["attempts"] == 1 and d["algorithm3d"] == 10  # HXT, first time
    assert d["min_sicn"] >= 0.03  # the quality every sector must have


def test_a_flat_surface_triangle_puts_one_segment_on_the_short_top_land_edges(monkeypatch):
    """The repair of :func:`fegear.mesh.sector._fix_flat_triangles`, on a block whose 0.8 mm wide
    top meets its end face (the face gear's outer top land): gmsh puts two segments on that edge
    (``Mesh.MinimumCurveNodes`` = 3). Whether the surface mesher then closes a triangle on those
    three collinear nodes depends on the host, so the flat triangle is reported by a stub of the
    quality query; the repair must give the short top ∩ end edges (and only those) one segment
    and re-mesh the surfaces."""
    import gmsh

    from fegear.mesh import sector
    from fegear.mesh.gmsh_session import initialize

    initialize()
    try:
        gmsh.model.add("block")
        gmsh.model.occ.addBox(0, 0, 0, 10, 0.8, 5)
        gmsh.model.occ.synchronize()
        faces = {
            name: [
                t
                for _, t in gmsh.model.getEntitiesInBoundingBox(*box, dim=2)
                if gmsh.model.occ.getMass(2, t) > 0
            ]
            for name, box in {
                "top_0": (-1, -1, 4.9, 11, 2, 5.1),
                "face_end": (9.9, -1, -1, 10.1, 2, 6),
                "face_start": (-0.1, -1, -1, 0.1, 2, 6),
            }.items()
        }
        gmsh.option.setNumber("Mesh.MeshSizeMax", 2.0)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 2.0)
        # Two segments on every edge, as on the sector's curved edges (MinimumCurveNodes = 3).
        gmsh.option.setNumber("Mesh.MinimumLineNodes", 3)
        gmsh.model.mesh.generate(2)
        for _, c in gmsh.model.getEntities(1):
            assert len(gmsh.model.mesh.getNodes(1, c, includeBoundary=True)[0]) >= 3
        assert sector._fix_flat_triangles(gmsh, faces, 2.0) == 0  # a good mesh is left alone
        qualities = gmsh.model.mesh.getElementQualities

        def one_flat(tags, name):
            q = np.array(qualities(tags, name))
            q[0] = 0.0
            return q

        monkeypatch.setattr(gmsh.model.mesh, "getElementQualities", one_flat)
        assert sector._fix_flat_triangles(gmsh, faces, 2.0) == 1
        monkeypatch.undo()
        top = {c for _, c in gmsh.model.getBoundary([(2, t) for t in faces["top_0"]], False, False)}
        ends = {
            c
            for name in ("face_end", "face_start")
            for _, c in gmsh.model.getBoundary([(2, t) for t in faces[name]], False, False)
        }
        for c in {c for _, c in gmsh.model.getEntities(1)}:
            nodes, _, _ = gmsh.model.mesh.getNodes(1, c, includeBoundary=True)
            short_edge = c in top & ends  # the top's 0.8 mm edges; not the bottom's, 10 or 5 mm
            assert (len(nodes) == 2) == short_edge, (c, len(nodes), gmsh.model.occ.getMass(1, c))
        tags, _ = gmsh.model.mesh.getElementsByType(2)
        assert len(tags) > 0  # the surfaces are meshed again
    finally:
        gmsh.finalize()
