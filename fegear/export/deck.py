"""The parts of a CalculiX/Abaqus deck shared by the Hertz scene and the gear pairs.

A deck (:class:`Deck`) is the ``.inp`` text plus a JSON record of what the reader
(:mod:`fegear.export.ccx_results`) needs to turn the results back into fegear's quantities: the
contact pairs' surface names, the reference nodes, the frame, the load.

Contact (``docs/calculix.md``): face-to-face penalty contact (``TYPE=SURFACE TO
SURFACE``), frictionless, linear pressure-overclosure of slope ``K`` (MPa/mm). The penalty lets
the surfaces overlap by ``p / K``: with the default ``K = 50 E / mm`` (CalculiX's own default for
node-to-face penalty) that is 0.15 µm at 1500 MPa, against 5-10 µm of elastic approach in the
scenes here (the deck's record keeps ``K`` so a reader can say what it is).

Load in two steps, both static and geometrically linear (fegear's model: small deformations):

1. the loaded member is moved by a small prescribed rigid motion (``preload``) into the mate,
   so that contact is established before any force is applied (a force-driven step that starts
   from one touching point has no stiffness against the free rigid motion);
2. that motion is released (``*BOUNDARY, OP=NEW`` restates the other conditions) and the force or
   torque is applied on the reference node; the answer does not depend on step 1.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fegear.errors import InputError
from fegear.store.files import atomic_write

__all__ = [
    "Deck",
    "DEFAULT_PENALTY_E",
    "IP_PRINT",
    "boundary_lines",
    "nset_lines",
    "contact_cards",
    "element_sides",
]

#: Default penalty slope in Young's moduli per mm (CalculiX's default for node-to-face penalty).
DEFAULT_PENALTY_E = 50.0

#: The contact values at the slave faces' integration points, printed to the ``.dat`` (one row
#: per active integration point of face-to-face penalty contact: slave element, face, values;
#: CalculiX manual, ``*CONTACT PRINT``): the pressure (``CSTR``), the overclosure (``CDIS``) and
#: the spring energy (``CELS``), from which the reader recovers each point's area
#: (:mod:`fegear.export.ccx_results`). Without ``SLAVE``/``MASTER``: all contact elements.
IP_PRINT = "*CONTACT PRINT\nCSTR, CDIS, CELS\n"


def element_sides(body, surface: str, element_offset: int) -> list[list[int]]:
    """``[[element, face], ...]`` of a body's surface as the deck numbers them (1-based elements
    after ``element_offset``; faces 1-4), in the order of its six-node faces
    (:meth:`fegear.export.inp.Tet10Body.face_triangles`)."""
    f = np.asarray(body.faces[surface], dtype=np.int64)
    return np.column_stack([f[:, 0] + 1 + element_offset, f[:, 1]]).tolist()


@dataclass(frozen=True)
class Deck:
    """A ready-to-run deck.

    Attributes
    ----------
    name
        Job name (``<name>.inp``; CalculiX writes ``<name>.frd`` and ``<name>.dat``).
    text
        The deck.
    record
        What the reader needs (JSON-able): ``kind`` (``"hertz_scene"`` or ``"gear_pair"``), the
        contact pairs, reference nodes, frame, load, mesh sizes and counts.
    """

    name: str
    text: str
    record: Mapping[str, object] = field(default_factory=dict)

    def write(self, folder: str | Path) -> Path:
        """Write ``<folder>/<name>.inp`` and ``<folder>/<name>.json``; the ``.inp`` path."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        inp = folder / f"{self.name}.inp"
        atomic_write(inp, lambda p: p.write_text(self.text, encoding="ascii"))
        rec = json.dumps(self.record, indent=1)
        atomic_write(folder / f"{self.name}.json", lambda p: p.write_text(rec, encoding="utf-8"))
        return inp


def nset_lines(name: str, ids: Sequence[int] | np.ndarray) -> str:
    """``*NSET`` card of 1-based node ids, 16 per line (the Abaqus limit)."""
    ids = np.asarray(ids, dtype=np.int64)
    if ids.size == 0:
        raise InputError(f"nset {name}", 0, "at least one node")
    rows = [", ".join(map(str, ids[i : i + 16])) for i in range(0, ids.size, 16)]
    return f"*NSET, NSET={name}\n" + "\n".join(rows) + "\n"


def boundary_lines(items: Sequence[tuple[str | int, int, int, float | None]], op_new: bool) -> str:
    """``*BOUNDARY`` card: ``(node or set, first dof, last dof, value or None)`` per line."""
    out = ["*BOUNDARY, OP=NEW" if op_new else "*BOUNDARY"]
    for target, a, b, v in items:
        out.append(f"{target}, {a}, {b}" + ("" if v is None else f", {v:.12g}"))
    return "\n".join(out) + "\n"


def contact_cards(
    pairs: Sequence[tuple[str, str]], penalty_MPa_per_mm: float, interaction: str = "FLANKS"
) -> str:
    """``*SURFACE INTERACTION`` (linear penalty, frictionless) and one ``*CONTACT PAIR`` card
    of ``(slave, master)`` surface pairs."""
    if not (np.isfinite(penalty_MPa_per_mm) and penalty_MPa_per_mm > 0.0):
        raise InputError("penalty", penalty_MPa_per_mm, "a finite slope > 0 (MPa/mm)")
    lines = [
        f"*SURFACE INTERACTION, NAME={interaction}",
        "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
        f"{penalty_MPa_per_mm:.6g}",
        f"*CONTACT PAIR, INTERACTION={interaction}, TYPE=SURFACE TO SURFACE",
    ]
    lines += [f"{s}, {m}" for s, m in pairs]
    return "\n".join(lines) + "\n"


def material_cards(name: str, E: float, nu: float, elsets: Sequence[str]) -> str:
    """``*MATERIAL`` (linear elastic) and a ``*SOLID SECTION`` per element set."""
    out = [f"*MATERIAL, NAME={name}", "*ELASTIC", f"{E:.12g}, {nu:.12g}"]
    out += [f"*SOLID SECTION, ELSET={e}, MATERIAL={name}" for e in elsets]
    return "\n".join(out) + "\n"
