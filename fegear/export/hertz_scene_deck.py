"""The Hertz scene (:mod:`fegear.scenes.hertz_scene`) as a CalculiX/Abaqus deck.

The same bodies as fegear's scene (:mod:`fegear.mesh.hertz_scene_bodies`: the block and the lower
half of the crowned roller, a quarter of each with ``symmetry = "quarter"``), meshed with the
same size field around the Hertz ellipse at the element size ``element_mm``, as C3D10 elements
whose mid-edge nodes on the roller's barrel lie on the exact barrel. Conditions, as fegear's:

- block bottom ``z = −H`` clamped (the rigid table);
- symmetry planes ``x = 0`` (``u_x = 0``) and ``y = 0`` (``u_y = 0``) of both bodies;
- the roller's axle plane ``z = Rx`` held in ``x`` and ``y`` and moving rigidly in ``z`` with the
  reference node ``RP_AXLE`` (kinematic coupling of ``u_z``), which carries the force (a quarter
  of it with symmetry, along ``−z``); its ``u_z`` is the approach of the axle to the table.

Contact: block top face (slave) against the barrel (master), :mod:`fegear.export.deck`.
"""

from __future__ import annotations

import io
import math
from dataclasses import asdict

import numpy as np

from fegear.errors import InputError
from fegear.export.deck import (
    DEFAULT_PENALTY_E,
    IP_PRINT,
    Deck,
    boundary_lines,
    contact_cards,
    element_sides,
    material_cards,
    nset_lines,
)
from fegear.export.inp import Tet10Body, tet10_body, write_body
from fegear.mesh.hertz_scene_bodies import BodyMeshSpec, cached_body_mesh, read_tet_mesh
from fegear.scenes.hertz_scene import HertzScene, hertz_reference

__all__ = ["hertz_deck", "barrel_projection", "PRELOAD_APPROACH"]

#: The first step's prescribed approach of the axle, in Hertz approaches (the answer does not
#: depend on it; near the final one, the second step needs fewer Newton iterations).
PRELOAD_APPROACH = 0.7


def barrel_projection(Rx: float, Ry: float):
    """Closest points on the roller's barrel (``fegear.mesh.hertz_scene_bodies.roller_height``):
    the meridian circle of radius ``Ry`` about ``(0, 0, Ry)`` in the plane ``x = 0``, revolved
    about the axle ``(0, y, Rx)``. A point ``x`` is moved radially in its section ``y = const``
    to the section radius ``r(y) = Rx − z_m(y)``, ``z_m = Ry − sqrt(Ry² − y²)`` (exact for the
    normal projection up to the meridian's slope ``y / Ry``: the mid-edge nodes are within
    ``h²/(8R)`` of the surface, so the remaining error is of order ``h² · (y/Ry)²``, below a
    nanometre here)."""

    def project(p: np.ndarray) -> np.ndarray:
        x, y, z = p[:, 0], p[:, 1], p[:, 2]
        r = Rx - (Ry - np.sqrt(Ry * Ry - y * y))
        dx, dz = x, z - Rx
        s = r / np.hypot(dx, dz)
        return np.column_stack([s * dx, y, Rx + s * dz])

    return project


def _body(kind: str, scene: HertzScene, spec: BodyMeshSpec) -> tuple[Tet10Body, bool]:
    """One body of the scene as C3D10 (its linear mesh from fegear's mesh cache)."""
    Rx, Ry = scene.roller_radii_mm
    geo = (
        {"half_size": scene.block_half_size_mm, "height": scene.block_height_mm}
        if kind == "block"
        else {"radii": [Rx, Ry], "half_length": scene.roller_half_length_mm}
    )
    path, hit = cached_body_mesh(kind, geo, spec)
    mesh = read_tet_mesh(path)
    bnd = {name: mesh.facets[:, f].T for name, f in mesh.boundaries.items()}
    project = {"contact": barrel_projection(Rx, Ry)} if kind == "roller" else None
    return tet10_body(kind, mesh.p.T, mesh.t.T, bnd, project), hit


def hertz_deck(
    scene: HertzScene,
    element_mm: float,
    name: str = "hertz_scene",
    penalty_E: float = DEFAULT_PENALTY_E,
) -> Deck:
    """The deck of the Hertz scene with contact elements of ``element_mm``.

    Parameters
    ----------
    scene
        The scene (a quarter model with ``symmetry = "quarter"``).
    element_mm
        Element size in the refined zone around the Hertz ellipse (mm): fegear's scene uses
        twice its cell size (its level ``L`` has cells of ``2 b / n_L``).
    name
        Job name.
    penalty_E
        Penalty slope in Young's moduli per mm.
    """
    if not (isinstance(element_mm, (int, float)) and math.isfinite(element_mm)):
        raise InputError("element_mm", element_mm, "a finite size > 0 (mm)")
    ref = hertz_reference(scene)
    Rx, Ry = scene.roller_radii_mm
    if not 0.0 < element_mm <= ref.b_mm:
        raise InputError("element_mm", element_mm, f"in (0, b = {ref.b_mm:.3g}] mm")
    # fegear's own refinement (fegear.scenes.hertz_scene): fine within the grid's margin around
    # the ellipse (major axis along y), growing to a quarter of the smaller body dimension
    coarse = min(scene.block_height_mm, Rx) / 4.0
    spec = BodyMeshSpec(
        h_fine=float(element_mm),
        h_coarse=max(coarse, 2 * element_mm),
        r_fine=scene.grid_margin * ref.b_mm + element_mm,
        segment_length=scene.grid_margin * ref.a_mm,
        symmetry=scene.symmetry,
    )
    block, hit_b = _body("block", scene, spec)
    roller, hit_r = _body("roller", scene, spec)
    # the contact surfaces: the faces near the ellipse only (a contact search over the whole
    # barrel and block top costs most of CalculiX's time); their extent is checked afterwards
    # (the loaded patch must end inside them: fegear.export.ccx_results)
    reach_x = 2.0 * (scene.grid_margin * ref.b_mm + element_mm)
    reach_y = 2.0 * scene.grid_margin * ref.a_mm + 2.0 * element_mm
    near = {}
    for body in (block, roller):
        c = body.nodes[body.face_triangles("contact")[:, :3]].mean(axis=1)
        near[body.name] = (np.abs(c[:, 0]) <= reach_x) & (np.abs(c[:, 1]) <= reach_y)
    block = block.with_surface("zone", "contact", near["block"])
    roller = roller.with_surface("zone", "contact", near["roller"])
    quarter = scene.symmetry == "quarter"
    fraction = 0.25 if quarter else 1.0
    out = io.StringIO()
    out.write("*HEADING\n")
    out.write(
        f"fegear Hertz scene: crowned roller Rx {Rx:g} / Ry {Ry:g} mm on a block, "
        f"{scene.force_N:g} N ({'quarter model' if quarter else 'full model'}), "
        f"contact elements {element_mm:g} mm\n"
    )
    out.write("** units: mm, N, MPa. Written by fegear (fegear.export.hertz_scene_deck).\n")
    nb = len(block.nodes)
    write_body(out, block, 0, 0)
    write_body(out, roller, nb, len(block.elements))
    n_nodes = nb + len(roller.nodes)
    rp = n_nodes + 1
    out.write(f"*NODE, NSET=RP_AXLE\n{rp}, 0, 0, {Rx:.12g}\n")

    def ids(body: Tet10Body, face: str, offset: int) -> np.ndarray:
        return body.face_nodes(face) + 1 + offset

    out.write(nset_lines("FIX_TABLE", ids(block, "bottom", 0)))
    out.write(nset_lines("AXLE", ids(roller, "axle", nb)))
    fixed = [("FIX_TABLE", 1, 3, None), ("AXLE", 1, 2, None), ("RP_AXLE", 1, 2, None),
             ("RP_AXLE", 4, 6, None)]  # fmt: skip
    if quarter:
        sx = np.union1d(ids(block, "sym_x", 0), ids(roller, "sym_x", nb))
        sy = np.union1d(ids(block, "sym_y", 0), ids(roller, "sym_y", nb))
        out.write(nset_lines("SYM_X", sx) + nset_lines("SYM_Y", sy))
        fixed += [("SYM_X", 1, 1, None), ("SYM_Y", 2, 2, None)]
    out.write(material_cards("STEEL_BLOCK", scene.E_block_MPa, scene.nu_block, ["E_block"]))
    out.write(material_cards("STEEL_ROLLER", scene.E_roller_MPa, scene.nu_roller, ["E_roller"]))
    out.write(f"*COUPLING, REF NODE={rp}, SURFACE=S_roller_axle, CONSTRAINT NAME=AXLE\n")
    out.write("*KINEMATIC\n3, 3\n")
    E = min(scene.E_block_MPa, scene.E_roller_MPa)
    K = penalty_E * E
    slave, master = "S_block_zone", "S_roller_zone"
    out.write(contact_cards([(slave, master)], K))
    # step 1: the axle pushed down by part of Hertz's approach (contact established near the
    # final patch: fewer Newton iterations in step 2)
    pre = PRELOAD_APPROACH * ref.approach_mm
    out.write("*STEP\n*STATIC\n")
    out.write(boundary_lines(fixed + [("RP_AXLE", 3, 3, -pre)], op_new=False))
    out.write(IP_PRINT)  # CalculiX: energy output (CELS) must start in the first step
    out.write("*END STEP\n")
    force = scene.force_N * fraction
    out.write("*STEP, INC=200\n*STATIC\n1.0, 1.0, 1e-05, 1.0\n")
    out.write(boundary_lines(fixed, op_new=True))
    out.write(f"*CLOAD\nRP_AXLE, 3, {-force:.12g}\n")
    out.write("*NODE PRINT, NSET=RP_AXLE\nU\n")
    out.write(f"*CONTACT PRINT, SLAVE={slave}, MASTER={master}\nCF\n")
    out.write(IP_PRINT)
    out.write("*CONTACT FILE, FREQUENCY=1000\nCDIS, CSTR\n")
    out.write("*END STEP\n")
    record = {
        "kind": "hertz_scene",
        "scene": asdict(scene),
        "element_mm": float(element_mm),
        "penalty_MPa_per_mm": K,
        "modelled_fraction": fraction,
        "force_N": float(scene.force_N),
        "force_modelled_N": force,
        "preload_mm": pre,
        "pairs": [{"slave": slave, "master": master, "name": "roller-block"}],
        "slave_faces": {slave: (block.face_triangles("zone") + 1).tolist()},
        "slave_sides": {slave: element_sides(block, "zone", 0)},
        "ref_nodes": {"RP_AXLE": rp},
        "zone": {"x_mm": reach_x, "y_mm": reach_y},
        "n_nodes": n_nodes,
        "n_elements": len(block.elements) + len(roller.elements),
        "dofs": 3 * n_nodes,
        "mesh_cache_hit": bool(hit_b and hit_r),
        "projected_mm": dict(roller.projected_mm),
        "hertz": {
            "p0_MPa": ref.p0_MPa,
            "a_mm": ref.a_mm,
            "b_mm": ref.b_mm,
            "approach_mm": ref.approach_mm,
        },  # fmt: skip
    }
    return Deck(name=name, text=out.getvalue(), record=record)
