"""The CalculiX cross-check (docs/calculix.md): decks fegear exports, run by ``ccx``, read back.

The deck tests run everywhere; the tests that run ``ccx`` are skipped when it is not installed
(Debian/Ubuntu: ``apt-get install calculix-ccx``; or ``$FEGEAR_CCX``). The spiral bevel's deck is
checked in ``tests/test_reliability.py``, beside the nominal case's run whose contact zone it
reads.
"""

from __future__ import annotations

import json
import math
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from fegear.api import load_case
from fegear.errors import InputError
from fegear.export import DEFAULT_HERTZ_LEVEL, export_ccx, read_results, run_ccx
from fegear.export.ccx_results import read_dat
from fegear.export.hertz_scene_deck import barrel_projection, hertz_deck
from fegear.scenes.hertz_scene import (
    CELLS_ACROSS_MINOR,
    ELEMENT_TO_CELL,
    HertzScene,
    hertz_reference,
)

CASES = Path(__file__).resolve().parent.parent / "cases"
CCX = os.environ.get("FEGEAR_CCX") or shutil.which("ccx")
needs_ccx = pytest.mark.skipif(
    CCX is None, reason="CalculiX (ccx) not installed: apt-get install calculix-ccx"
)
#: The coarsest Hertz deck: contact elements of 0.45 mm, about one per semi-minor axis
#: (b = 0.478 mm): ~35 s of ccx on 2 shared cores.
COARSE_MM = 0.45


def _volumes(nodes: np.ndarray, elements: np.ndarray) -> np.ndarray:
    p = nodes[elements[:, :4]]
    return np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0])


#: The six edges of a C3D10 in the order of its mid-edge nodes 5..10 (CalculiX manual §6.2.7).
EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]


def _mid_edge_offsets(xyz: np.ndarray, el: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(dev, length)``, ``(m, 6)`` mm each: how far each mid-edge node lies from its edge's
    midpoint, and the edge's length."""
    mid = np.stack([0.5 * (xyz[el[:, a]] + xyz[el[:, b]]) for a, b in EDGES], axis=1)
    dev = np.linalg.norm(xyz[el[:, 4:]] - mid, axis=-1)
    length = np.stack([np.linalg.norm(xyz[el[:, a]] - xyz[el[:, b]], axis=-1) for a, b in EDGES], 1)
    return dev, length


def _deck_elements(text: str) -> tuple[np.ndarray, np.ndarray]:
    """Nodes (by id) and C3D10 connectivity parsed back from a deck's text."""
    nodes: dict[int, list[float]] = {}
    elems = []
    mode = None
    for line in text.splitlines():
        if line.startswith("*"):
            head = line.split(",")[0]
            mode = {"*NODE": "n", "*ELEMENT": "e"}.get(head)
            continue
        if mode == "n":
            f = line.split(",")
            nodes[int(f[0])] = [float(x) for x in f[1:4]]
        elif mode == "e":
            elems.append([int(x) for x in line.split(",")[1:]])
    ids = np.array(sorted(nodes))
    xyz = np.zeros((ids.max() + 1, 3))
    xyz[ids] = [nodes[i] for i in ids]
    return xyz, np.array(elems)


def test_hertz_deck_is_a_valid_c3d10_model():
    """The exported deck: positive C3D10 volumes in CalculiX's node order, mid-edge nodes at
    the edge midpoints except on the barrel, where they lie on the exact barrel."""
    scene = HertzScene()
    deck = hertz_deck(scene, COARSE_MM)
    xyz, el = _deck_elements(deck.text)
    assert el.shape[1] == 10
    # orientation: every element positive (CalculiX rejects negative Jacobians)
    assert np.all(_volumes(xyz, el) > 0.0)
    dev, length = _mid_edge_offsets(xyz, el)  # mid-edge nodes against their edges' midpoints
    Rx, Ry = scene.roller_radii_mm
    # a move onto the barrel is the chord's sag, at most L² / (8 r) for an edge of length L on a
    # section of radius r >= 0.9 Rx (the crown lowers the section radius by < 10 % here)
    assert np.all(dev <= length**2 / (8 * 0.9 * Rx) + 1e-9)
    moved = xyz[el[:, 4:]][dev > 1e-9]
    on_barrel = barrel_projection(Rx, Ry)(moved)
    # moved nodes lie on the barrel (the projection is a fixed point there, to rounding)
    assert np.max(np.linalg.norm(on_barrel - moved, axis=1)) < 1e-9
    rec = deck.record
    assert rec["force_modelled_N"] == pytest.approx(scene.force_N / 4)  # quarter model


def test_export_refuses_bad_sizes_and_positions(tmp_path):
    case = load_case(CASES / "hertz_scene.toml")
    b = hertz_reference(case.scene).b_mm
    with pytest.raises(InputError, match="element_mm"):
        export_ccx(case, tmp_path, element_mm=2 * b)  # coarser than the contact itself
    with pytest.raises(InputError, match="positions"):
        export_ccx(case, tmp_path, phi1=[0.0])  # the Hertz scene has no positions


def test_hertz_export_defaults_to_level_1(tmp_path):
    """Without a size, the Hertz deck gets the element size of the scene's level 1 (twice its
    cell size: 4 b / 8), not the case's level 3 (a 12-minute CalculiX run, docs/calculix.md);
    ``level`` picks another level's size."""
    case = load_case(CASES / "hertz_scene.toml")
    b = hertz_reference(case.scene).b_mm
    (inp,) = export_ccx(case, tmp_path)
    rec = json.loads(inp.with_suffix(".json").read_text())
    assert case.level == 3 and DEFAULT_HERTZ_LEVEL == 1
    assert rec["element_mm"] == pytest.approx(ELEMENT_TO_CELL * 2 * b / CELLS_ACROSS_MINOR[1])
    with pytest.raises(InputError, match="level"):
        export_ccx(case, tmp_path, level=len(CELLS_ACROSS_MINOR))


def test_dat_reader_reads_the_last_contact_statistics(tmp_path):
    """The ``.dat`` blocks as CalculiX 2.20 writes them; the last time wins."""
    block = (
        "\n statistics for slave set S_A, master set S_B and time  {t}\n\n"
        "   total surface force (fx,fy,fz) and moment about the origin (mx,my,mz)\n\n"
        "    1.0E+00  2.0E+00 -{f}E+02 -2.5E+02  8.9E+01 -1.5E+00\n\n"
        "   center of gravity and mean normal\n\n"
        "    1.9E-01  5.7E-01 -5.5E-03 -8.4E-03 -4.9E-03  9.9E-01\n\n"
        "   moment about the center of gravity(mx,my,mz)\n\n"
        "    2.9E+01 -7.6E+00  2.1E-01\n\n"
        "   area,  normal force (+ = tension) and shear force (size)\n\n"
        "    4.9E-01 -{f}E+02  5.8E-01\n"
    )
    disp = (
        "\n displacements (vx,vy,vz) for set RP and time  {t}\n\n"
        "      6508  0.000000E+00  0.000000E+00 -1.4{k}E-02\n"
    )
    text = "".join(block.format(t=t, f=f) + disp.format(t=t, k=k)
                   for t, f, k in (("0.1E+01", 3, 1), ("0.2E+01", 5, 9)))  # fmt: skip
    (tmp_path / "j.dat").write_text(text)
    stats, d = read_dat(tmp_path / "j.dat")
    assert stats[("S_A", "S_B")]["time"] == 2.0
    assert stats[("S_A", "S_B")]["normal"] == -500.0
    assert d["RP"][6508][2] == pytest.approx(-0.0149)


def test_dat_reader_reads_a_pair_out_of_contact(tmp_path):
    """A pair out of contact: CalculiX 2.20 writes zero force and area and NaN for its centre,
    normal and normal force; it reads as a normal force of 0, and the next pair's block stays
    its own."""
    nan = "             NaN           NaN           NaN"
    empty = (
        "\n statistics for slave set S_A, master set S_B and time  0.2E+01\n\n"
        "   total surface force (fx,fy,fz) and moment about the origin (mx,my,mz)\n\n"
        "    0.000000E+00  0.000000E+00  0.000000E+00  0.000000E+00  0.000000E+00  0.000000E+00"
        f"\n\n   center of gravity and mean normal\n\n{nan}{nan}\n\n"
        f"   moment about the center of gravity(mx,my,mz)\n\n{nan}\n\n"
        "   area,  normal force (+ = tension) and shear force (size)\n\n"
        "    0.000000E+00           NaN           NaN\n"
    )
    loaded = (
        "\n statistics for slave set S_C, master set S_D and time  0.2E+01\n\n"
        "   total surface force (fx,fy,fz) and moment about the origin (mx,my,mz)\n\n"
        "   -4.0E+01 -4.2E+03  2.0E+03 -1.0E+04 -1.0E+06 -2.1E+06\n\n"
        "   center of gravity and mean normal\n\n"
        "    5.0E+02 -5.0E+00 -1.3E-01  8.4E-03  9.0E-01 -4.2E-01\n\n"
        "   moment about the center of gravity(mx,my,mz)\n\n"
        "    6.8E+02  1.1E+03  4.7E+03\n\n"
        "   area,  normal force (+ = tension) and shear force (size)\n\n"
        "    5.5E+00 -4.7E+03  1.9E+01\n"
    )
    (tmp_path / "j.dat").write_text(empty + loaded)
    stats, _ = read_dat(tmp_path / "j.dat")
    assert stats[("S_A", "S_B")]["normal"] == 0.0 and stats[("S_A", "S_B")]["area"] == 0.0
    assert stats[("S_C", "S_D")]["normal"] == -4700.0
    assert stats[("S_C", "S_D")]["moment"][2] == -2.1e6


@needs_ccx
def test_hertz_scene_calculix_against_hertz(tmp_path):
    """The coarsest Hertz deck run by CalculiX: the contact force balances the load, and the
    peak pressure is Hertz's within the scatter of meshes this coarse."""
    case = load_case(CASES / "hertz_scene.toml")
    inp = export_ccx(case, tmp_path, element_mm=COARSE_MM)[0]
    run = run_ccx(inp, threads=1, timeout_s=600)
    assert run.returncode == 0, (tmp_path / (inp.stem + ".log")).read_text()[-2000:]
    res = read_results(inp)
    ref = hertz_reference(case.scene)
    (pair,) = res.pairs
    # the pressure at CalculiX's integration points times their areas is the contact force:
    # 2 %, the cross-check's bound (the print's 7 digits give 2e-5: measured 1.9e-5)
    assert pair.ip_force_N == pytest.approx(pair.normal_force_N, rel=0.02)
    stats, _ = read_dat(inp.with_suffix(".dat"))
    assert pair.contact_area_mm2 == pytest.approx(stats[("S_BLOCK_ZONE", "S_ROLLER_ZONE")]["area"],
                                                  rel=1e-4)  # fmt: skip
    # CalculiX's nodal pressures (a fit per face to its active points) integrate to more
    assert pair.nodal_force_N > 1.1 * pair.normal_force_N
    # equilibrium of the converged increment: CalculiX's force-residual criterion is 0.5 % of
    # the mean nodal force (its default), far tighter on the total
    assert res.balance == pytest.approx(1.0, abs=5e-3)
    assert pair.normal_force_N == pytest.approx(case.scene.force_N / 4, rel=5e-3)
    # the largest nodal pressure against p0: one element per semi-minor axis; the measured
    # ladder (docs/calculix.md) scatters by a few % at these sizes, 8 % bounds it
    assert pair.p_max_MPa == pytest.approx(ref.p0_MPa, rel=0.08)
    # the axle's approach includes the bodies' bulk compliance besides Hertz's local approach
    # (measured 14.9 µm against Hertz's 15.2 µm): same order, within 15 %
    assert res.approach_mm == pytest.approx(ref.approach_mm, rel=0.15)
    assert not res.warnings


@needs_ccx
@pytest.mark.slow
def test_fzg_two_pair_load_shares_against_fegear(tmp_path):
    """FZG at a two-pair position (φ1 = 5°): CalculiX's load shares and lag against fegear
    ``hybrid`` level 0 (several minutes of ccx: slow)."""
    from fegear.ltca import LTCAOptions, run_ltca
    from fegear.pipeline.pair import build_pair

    case = load_case(CASES / "fzg_spur.toml")
    phi1 = math.radians(5.0)
    inp = export_ccx(case, tmp_path, element_mm=0.5, phi1=[phi1])[0]
    run = run_ccx(inp, threads=2, timeout_s=3600)
    assert run.returncode == 0
    res = read_results(inp)
    # torque balance of the converged increment (CalculiX's residual criterion, 0.5 %)
    assert res.balance == pytest.approx(1.0, abs=5e-3)
    pair = build_pair(case)
    opt = LTCAOptions(n_positions=case.n_positions, level=0, fidelity="hybrid", workers=1)
    cyc = run_ltca(pair.pinion, pair.gear, pair.assembly, case.torque2_Nmm, opt,
                   phi1=np.array([phi1]))  # fmt: skip
    fe = {(q.k, q.j): q.load_share for q in cyc.positions[0].pairs if q.force_N > 0}
    ccx = {(q.k, q.j): q.load_share for q in res.pairs if q.normal_force_N > 0}
    assert set(fe) == set(ccx) and len(fe) == 2
    # the acceptance bound for load shares at two-pair positions
    for kj, share in fe.items():
        assert ccx[kj] == pytest.approx(share, abs=0.03)
    # the lag (loaded TE − unloaded TE): 5 %, the bound on the loaded TE
    assert res.theta_rad == pytest.approx(cyc.positions[0].theta, rel=0.05)
    json.dumps(res.to_dict())  # the result is JSON-able


def _tri6_grid(nx: int, ny: int, lx: float, ly: float, lift=None):
    """Six-node triangles over ``[0, lx] × [0, ly]`` (``2 nx ny`` faces: corners, then the
    mid-edge nodes 1-2, 2-3, 3-1), the nodes at ``z = lift(x, y)`` (flat without it)."""
    xs, ys = np.linspace(0.0, lx, 2 * nx + 1), np.linspace(0.0, ly, 2 * ny + 1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    Z = np.zeros_like(X) if lift is None else lift(X, Y)
    xyz = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])

    def n(i, j):
        return i * (2 * ny + 1) + j

    faces = []
    for i in range(0, 2 * nx, 2):
        for j in range(0, 2 * ny, 2):
            faces.append([n(i, j), n(i + 2, j), n(i + 2, j + 2),
                          n(i + 1, j), n(i + 2, j + 1), n(i + 1, j + 1)])  # fmt: skip
            faces.append([n(i, j), n(i + 2, j + 2), n(i, j + 2),
                          n(i + 1, j + 1), n(i + 1, j + 2), n(i, j + 1)])  # fmt: skip
    return np.array(faces), xyz


@pytest.mark.parametrize(
    ("field", "exact"),
    [
        (lambda x, y: np.full_like(x, 3.0), 3.0 * 2.0 * 1.5),
        (lambda x, y: 1.0 + 2.0 * x - y, 2.0 * 1.5 * (1.0 + 2.0 - 0.75)),
        # ∫∫ x² + x y + y² over [0, 2] × [0, 1.5] = (8/3) 1.5 + (2)(1.125) + 2 (1.125)
        (lambda x, y: x * x + x * y + y * y, 8.0 / 3.0 * 1.5 + 2.0 * 1.125 + 2.0 * 1.125),
    ],
)
def test_face_integral_is_exact_for_quadratic_fields_on_flat_faces(field, exact):
    """The six-node face integral (``face_integral``): a constant, linear and quadratic
    pressure over flat faces integrate exactly (the 7-point rule is of degree 5), and the
    corner nodes carry no weight (``∫ N_corner dA = 0``)."""
    from fegear.export.ccx_results import face_integral

    faces, xyz = _tri6_grid(3, 2, 2.0, 1.5)
    v = field(xyz[:, 0], xyz[:, 1])
    assert face_integral(faces, xyz, v).sum() == pytest.approx(exact, rel=1e-12)
    corners = np.zeros(len(xyz))
    corners[np.unique(faces[:, :3])] = 1.0
    assert face_integral(faces, xyz, corners).sum() == pytest.approx(0.0, abs=1e-12)


def test_face_integral_follows_curved_faces():
    """On a cylinder of radius 5 mm (the nodes on it, the faces quadratic), a unit pressure
    integrates to the cylinder's area within the quadratic geometry's O(h⁴) error."""
    from fegear.export.ccx_results import face_integral

    R, phi, L = 5.0, 0.8, 2.0
    faces, xyz = _tri6_grid(4, 2, phi, L)
    pts = np.column_stack([R * np.sin(xyz[:, 0]), xyz[:, 1], R * np.cos(xyz[:, 0])])
    total = face_integral(faces, pts, np.ones(len(pts))).sum()
    assert total == pytest.approx(R * phi * L, rel=1e-5)


#: ``*CONTACT PRINT`` blocks of face-to-face contact as CalculiX 2.20 writes them (its energy
#: header reads "contact print energy (...)for all"); the load step's at time 2.
_POINTS_DAT = """
 contact stress (slave element+face,press,tang1,tang2) for all contact elements and time \
0.2000000E+01

         7          1  1.000000E+03  0.000000E+00  0.000000E+00
         7          1  5.000000E+02  0.000000E+00  0.000000E+00
         9          3  2.000000E+03  0.000000E+00  0.000000E+00

 relative contact displacement (slave element+face,normal,tang1,tang2) for all contact \
elements and time 0.2000000E+01

         7          1 -1.000000E-04  0.000000E+00  0.000000E+00
         7          1 -5.000000E-05  0.000000E+00  0.000000E+00
         9          3 -2.000000E-04  0.000000E+00  0.000000E+00

 contact print energy (slave element+face,energy)for all contact elements and time 0.2000000E+01

         7          1  5.000000E-04
         7          1  2.500000E-04
         9          3  4.000000E-03
"""


def test_contact_points_reader_recovers_each_points_area(tmp_path):
    """The integration points' print: the pressure, overclosure and spring energy of each
    contact element; the area each point stands for, ``2 K E / p²``, makes the force
    ``Σ p A``; a face's force goes to its nodes whole (``_spread``)."""
    from fegear.export.ccx_results import _face_points, _lumped, _spread, read_dat_points

    (tmp_path / "j.dat").write_text(_POINTS_DAT)
    pts = read_dat_points(tmp_path / "j.dat")
    assert pts is not None and pts.time == 2.0
    assert pts.element.tolist() == [7, 7, 9] and pts.face.tolist() == [1, 1, 3]
    K = 1.0e7  # MPa/mm: p = K × overclosure in the rows above
    np.testing.assert_allclose(pts.pressure, -K * pts.overclosure)
    a = pts.areas(K)  # E = A p² / (2 K)
    np.testing.assert_allclose(a, [0.01, 0.02, 0.02])
    force, area, pmax, n = _face_points(pts, [[9, 3], [7, 1], [8, 2]], K)
    np.testing.assert_allclose(force, [40.0, 20.0, 0.0])
    np.testing.assert_allclose(area, [0.02, 0.03, 0.0])
    assert pmax.tolist() == [2000.0, 1000.0, 0.0] and n == 3
    # spreading: the nodal forces sum to each face's force, also where the nodal field is 0
    faces, xyz = _tri6_grid(1, 1, 1.0, 1.0)
    p_nodes = np.where(xyz[:, 0] > 0.5, 1.0, 0.0)
    f = _spread(faces, xyz, p_nodes, np.array([40.0, 20.0]))
    assert f.sum() == pytest.approx(60.0)
    assert np.all(f[p_nodes == 0.0] == 0.0)  # the force goes where CalculiX's pressure is
    assert _lumped(faces, xyz).sum() == pytest.approx(1.0)
    f = _spread(faces, xyz, np.zeros(len(xyz)), np.array([40.0, 20.0]))
    assert f.sum() == pytest.approx(60.0) and np.all(f > 0.0)  # by area without a nodal field
    (tmp_path / "none.dat").write_text("")
    assert read_dat_points(tmp_path / "none.dat") is None


def test_patch_boxes_hold_the_tca_contact_line_narrowly():
    """FZG at the pitch point: the patch strips of a locally refined deck
    (:func:`fegear.export.gear_deck.patch_boxes`) hold the pinion cells of the TCA's smallest
    separation of each face-width column, end where the separation reaches the gap, and are
    narrower than the reach's boxes; the gear gets one box per pinion strip."""
    from fegear.export.gear_deck import DEFAULT_REACH_MM, patch_boxes
    from fegear.ltca import LTCAOptions
    from fegear.ltca.analysis import cycle_zone
    from fegear.ltca.cycle import cycle_tca
    from fegear.ltca.zone import contact_zone
    from fegear.pipeline.pair import build_pair
    from fegear.validation.rows import pitch_point_phi1

    case = load_case(CASES / "fzg_spur.toml")
    pair = build_pair(case)
    opt = LTCAOptions(n_positions=case.n_positions, level=case.level, n_teeth=case.n_teeth,
                      E_MPa=case.E_MPa, nu=case.nu, fidelity="fe",
                      **case.contact.as_dict())  # fmt: skip
    phi1 = pitch_point_phi1(pair)
    tca, (pos,), _ = cycle_tca(pair.pinion, pair.gear, pair.assembly, opt, np.array([phi1]))
    n = cycle_zone(pair.pinion, pair.gear, pair.assembly, opt).n_teeth
    asm, b1, b2 = tca.asm, tca.fm1.bounds, tca.fm2.bounds
    reach = contact_zone([pos], b1, b2, asm.side1, asm.side2, DEFAULT_REACH_MM, n_teeth=n)
    gap = 0.01
    z1, z2 = patch_boxes(pos, reach.pairs, b1, b2, asm.side1, asm.side2, n // 2, gap, 0.0)
    (g,) = [g for g in pos.grids if (g.k, g.j) == (0, 0)]
    assert len(z1) == len(z2) == len(g.v)  # a strip per face-width column
    width = max(z.u[1] - z.u[0] for z in reach.pinion) * len(reach.pinion)
    for z in z1:
        col = int(np.argmin(np.abs(g.v - 0.5 * (z.v[0] + z.v[1]))))
        ok = g.valid[:, col]
        s = np.interp(z.u, g.u[ok], g.separation[ok, col])
        assert z.u[0] <= g.u[ok][np.argmin(g.separation[ok, col])] <= z.u[1]
        # the parabola through three samples 0.34 mm apart: its ends within 1 µm of the gap
        np.testing.assert_allclose(s, gap, atol=1e-3)
        assert 0.3 < z.u[1] - z.u[0] < 0.5 * width  # ±0.36 mm; the reach's boxes ±1.0 mm
