"""Gear-pair case files (TOML): schema, validation and the pair they describe.

Units are in the key names (DESIGN §3). Unknown sections and keys are refused with the closest
known key suggested (which catches a wrong unit suffix: ``module_in`` → ``module_mm``), missing
required keys are refused, and every error is an :class:`~fegear.errors.InputError` naming the
case-file field, the value and the allowed range, so that ``fegear run`` prints one line and exits
with code 2 before any work.

Schema (``*`` = required)::

    [case]      kind* = "face_gear" | "spur" | "spiral_bevel", name, description
    [pair]      design data, by kind (below)
    [load]      torque2_Nm | torque2_Nmm | pinion_torque_Nm   (exactly one, > 0)
                speed_rpm (recorded only: the model is quasi-static, speed does not enter)
    [errors]    intersecting axes (face_gear, spiral_bevel): dE_mm, dA1_mm, dA2_mm, dgamma_deg
                parallel axes (spur): da_mm, f_sigma_delta_mm, f_sigma_beta_mm, dA1_mm, dA2_mm
                (all default 0; sign conventions in :mod:`fegear.assembly`)
    [analysis]  fidelity ("hybrid" default | "fe" | "hertz" | "tca"), level (0..4), n_positions,
                n_teeth (3..9; default: the teeth that can touch + one neighbour each side),
                backend ("auto" | "pardiso" | "superlu")
    [material]  E_MPa (> 0), nu (in (-1, 0.5))    — both members

``[pair]`` by kind:

- ``face_gear``: n_face_gear*, n_pinion*, module_mm*, pressure_angle_deg*, inner_radius_mm*,
  outer_radius_mm*, shaft_angle_deg, pinion_face_width_mm, blank_thickness_mm, n_shaper
  (default n_pinion + 2), addendum_coeff, dedendum_coeff.
- ``spur``: teeth* = [z1, z2], module_mm*, pressure_angle_deg*, profile_shift = [x1, x2],
  face_width_mm (a number or [b1, b2]), addendum_coeff, dedendum_coeff, profile_crowning_mm,
  lead_crowning_mm, tip_relief_mm (a number for both members or [pinion, gear]).
- ``spiral_bevel`` (blank data; machine settings are synthesized): n_pinion*, n_gear*,
  module_mm* (outer transverse), spiral_angle_deg*, pressure_angle_deg*, face_width_mm*,
  shaft_angle_deg, cutter_radius_mm, te_amplitude_arcsec (predesigned parabolic TE), side
  ("drive" | "coast").

The load is the resisting torque on member 2 or the torque on member 1, positive in the driving
sense; a pinion torque is converted with the tooth ratio, ``T2 = T1 · N2/N1`` (no friction).
"""

from __future__ import annotations

import copy
import difflib
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fegear.assembly import InstallationErrors
from fegear.errors import InputError

__all__ = [
    "GEAR_KINDS",
    "DEFAULT_FIDELITY",
    "FIDELITIES",
    "N_LEVELS",
    "GearCase",
    "GearPair",
    "parse_gear_case",
    "build_pair",
    "assemble",
    "error_fields",
]

GEAR_KINDS = ("face_gear", "spur", "spiral_bevel")
#: Fidelities of the gear pairs (DESIGN §9).
FIDELITIES = ("fe", "hertz", "hybrid", "tca")
#: The fidelity of a gear case that does not name one: the one that resolves the contact patch
#: at the default (coarsest) level. ``fe`` level 0 does not: its cells are wider than the patch
#: (FZG: p_max 126-160 MPa where ``hybrid``, ``hertz`` and line Hertz give about 1100 MPa; seed
#: face gear: loaded TE p-p 2.39″ against 0.43″ at ``hybrid``).
DEFAULT_FIDELITY = "hybrid"
#: Sector mesh levels 0 … N_LEVELS − 1 (:data:`fegear.mesh.sector.FINE`).
N_LEVELS = 5

_NUM = (int, float)
_PAIR = "number-or-pair"  # a number (both members) or a list [pinion, gear]
_INT2 = "int-pair"  # a list of two integers
_NUM2 = "number-pair"  # a list of two numbers

# schema: key -> (type, required)
_PAIR_SCHEMA: dict[str, dict[str, tuple[Any, bool]]] = {
    "face_gear": {
        "n_face_gear": (int, True),
        "n_pinion": (int, True),
        "module_mm": (_NUM, True),
        "pressure_angle_deg": (_NUM, True),
        "inner_radius_mm": (_NUM, True),
        "outer_radius_mm": (_NUM, True),
        "shaft_angle_deg": (_NUM, False),
        "pinion_face_width_mm": (_NUM, False),
        "blank_thickness_mm": (_NUM, False),
        "n_shaper": (int, False),
        "addendum_coeff": (_NUM, False),
        "dedendum_coeff": (_NUM, False),
    },
    "spur": {
        "teeth": (_INT2, True),
        "module_mm": (_NUM, True),
        "pressure_angle_deg": (_NUM, True),
        "profile_shift": (_NUM2, False),
        "face_width_mm": (_PAIR, False),
        "addendum_coeff": (_PAIR, False),
        "dedendum_coeff": (_PAIR, False),
        "profile_crowning_mm": (_PAIR, False),
        "lead_crowning_mm": (_PAIR, False),
        "tip_relief_mm": (_PAIR, False),
    },
    "spiral_bevel": {
        "n_pinion": (int, True),
        "n_gear": (int, True),
        "module_mm": (_NUM, True),
        "spiral_angle_deg": (_NUM, True),
        "pressure_angle_deg": (_NUM, True),
        "face_width_mm": (_NUM, True),
        "shaft_angle_deg": (_NUM, False),
        "cutter_radius_mm": (_NUM, False),
        "te_amplitude_arcsec": (_NUM, False),
        "side": (str, False),
    },
}
_ERRORS_INTERSECTING = ("dE_mm", "dA1_mm", "dA2_mm", "dgamma_deg")
_ERRORS_PARALLEL = ("da_mm", "f_sigma_delta_mm", "f_sigma_beta_mm", "dA1_mm", "dA2_mm")
_COMMON_SCHEMA: dict[str, dict[str, tuple[Any, bool]]] = {
    "case": {"kind": (str, True), "name": (str, False), "description": (str, False)},
    "load": {
        "torque2_Nm": (_NUM, False),
        "torque2_Nmm": (_NUM, False),
        "pinion_torque_Nm": (_NUM, False),
        "speed_rpm": (_NUM, False),
    },
    "analysis": {
        "fidelity": (str, False),
        "level": (int, False),
        "n_positions": (int, False),
        "n_teeth": (int, False),
        "backend": (str, False),
    },
    "material": {"E_MPa": (_NUM, False), "nu": (_NUM, False)},
}
_REQUIRED_SECTIONS = ("case", "pair", "load")
_TORQUE_KEYS = ("torque2_Nm", "torque2_Nmm", "pinion_torque_Nm")


@dataclass(frozen=True)
class GearCase:
    """A validated gear-pair case.

    Attributes
    ----------
    name
        Case name (``[case] name``, else the file stem).
    kind
        ``"face_gear"``, ``"spur"`` or ``"spiral_bevel"``.
    pair
        The ``[pair]`` table with defaults filled in (case-file keys and units).
    torque2_Nmm
        Resisting torque on member 2 (N·mm, > 0), converted from whichever load key was given.
    load_key
        The load key of the case file (``"torque2_Nm"``, ``"torque2_Nmm"`` or
        ``"pinion_torque_Nm"``) and ``load_value`` its value.
    errors
        Installation errors.
    fidelity, level, n_positions, n_teeth, backend
        Analysis settings (``[analysis]``).
    E_MPa, nu
        Material of both members.
    speed_rpm
        Recorded only (quasi-static model).
    description, source
        Free text and the file the case came from.
    """

    name: str
    kind: str
    pair: dict[str, Any]
    torque2_Nmm: float
    load_key: str
    load_value: float
    errors: InstallationErrors = field(default_factory=InstallationErrors)
    fidelity: str = "hybrid"
    level: int = 0
    n_positions: int = 25
    n_teeth: int | None = None
    backend: str = "auto"
    E_MPa: float = 206000.0
    nu: float = 0.3
    speed_rpm: float | None = None
    description: str = ""
    source: str = "<memory>"

    @property
    def ratio(self) -> float:
        """Tooth ratio ``N2/N1``."""
        n1, n2 = _tooth_numbers(self.kind, self.pair)
        return n2 / n1

    def to_document(self) -> dict[str, Any]:
        """The case as a case-file document (the TOML tables as dicts, units in the keys):
        :func:`parse_gear_case` of it gives this case back (the round trip is exact)."""
        case: dict[str, Any] = {"kind": self.kind, "name": self.name}
        if self.description:
            case["description"] = self.description
        load: dict[str, Any] = {self.load_key: self.load_value}
        if self.speed_rpm is not None:
            load["speed_rpm"] = self.speed_rpm
        analysis: dict[str, Any] = {
            "fidelity": self.fidelity,
            "level": self.level,
            "n_positions": self.n_positions,
            "backend": self.backend,
        }
        if self.n_teeth is not None:
            analysis["n_teeth"] = self.n_teeth
        return {
            "case": case,
            "pair": copy.deepcopy(self.pair),
            "load": load,
            "errors": {k: getattr(self.errors, k) for k in _error_keys(self.kind)},
            "analysis": analysis,
            "material": {"E_MPa": self.E_MPa, "nu": self.nu},
        }

    def replace(self, **changes: Any) -> GearCase:
        """A new, validated case with some fields changed (the case itself is frozen).

        Parameters
        ----------
        **changes
            Fields of the case: ``name``, ``description``, ``fidelity``, ``level``,
            ``n_positions``, ``n_teeth`` (None: automatic), ``backend``, ``E_MPa``, ``nu``,
            ``speed_rpm`` (rpm, recorded only), ``errors`` (an
            :class:`~fegear.assembly.InstallationErrors` or a mapping of the ``[errors]`` keys:
            it replaces all of them, the ones not given are 0), ``pair`` (the whole ``[pair]``
            table: ``case.replace(pair={**case.pair, "module_mm": 5.0})``), a load, which
            replaces the case's torque (``torque2_Nm``, N·m, or ``torque2_Nmm``, N·mm, on
            member 2; ``pinion_torque_Nm``, N·m, on member 1), and ``source``.

        Returns
        -------
        GearCase
            Validated exactly like a case file: the new values go into the case's document
            (:meth:`to_document`) and through :func:`parse_gear_case`.

        Raises
        ------
        InputError
            An unknown or fixed field (``kind``), or a value the case file would refuse, named
            as in the case file (``analysis.level = 7 is not allowed: must be an integer in
            [0, 4]``).
        """
        doc = self.to_document()
        source = self.source
        for key, value in changes.items():
            value = _plain(value)
            if key == "source":
                source = str(value)
            elif key in _REPLACE_KEYS:
                section, name = _REPLACE_KEYS[key]
                if value is None and key in ("n_teeth", "speed_rpm", "description"):
                    doc[section].pop(name, None)
                else:
                    doc[section][name] = value
            elif key in _TORQUE_KEYS:
                for other in _TORQUE_KEYS:
                    doc["load"].pop(other, None)
                doc["load"][key] = value
            elif key == "pair":
                if not isinstance(value, dict):
                    raise InputError("pair", value, "a mapping of the [pair] keys")
                doc["pair"] = value
            elif key == "errors":
                if isinstance(value, InstallationErrors):
                    value = {k: getattr(value, k) for k in _error_keys(self.kind)}
                if not isinstance(value, dict):
                    raise InputError("errors", value, "InstallationErrors or a mapping")
                doc["errors"] = value
            else:
                known = sorted([*_REPLACE_KEYS, *_TORQUE_KEYS, "pair", "errors", "source"])
                close = difflib.get_close_matches(key, known, n=1, cutoff=0.5)
                hint = f"did you mean {close[0]!r}?" if close else ""
                if key in ("kind", "load_key", "load_value"):
                    hint = "fixed for a case: load another case file for another kind"
                    if key != "kind":
                        hint = "give the load as torque2_Nm, torque2_Nmm or pinion_torque_Nm"
                raise InputError(key, value, f"one of the fields {known}", hint)
        return parse_gear_case(doc, source=source)

    def with_errors(self, **errors: float) -> GearCase:
        """A new, validated case with some installation errors changed (the others kept).

        Parameters
        ----------
        **errors
            ``[errors]`` keys of the case's kind: intersecting axes (face gear, spiral bevel)
            ``dE_mm`` (shortest distance between the axes, mm), ``dA1_mm`` (ΔP: pinion axial,
            mm), ``dA2_mm`` (ΔG, Δq: gear axial, mm), ``dgamma_deg`` (shaft angle, deg);
            parallel axes (spur) ``da_mm`` (centre distance, mm), ``f_sigma_delta_mm``,
            ``f_sigma_beta_mm`` (axis-parallelism errors in and out of the plane of the axes
            over the face width, mm), ``dA1_mm``, ``dA2_mm``. Sign conventions:
            :mod:`fegear.assembly`. ``case.replace(errors={})`` sets all of them to 0.

        Raises
        ------
        InputError
            A key of another kind or a misspelt one (``errors.dgamma_rad = 0.1 is not allowed:
            must be one of the keys [...] for kind 'face_gear' (did you mean 'dgamma_deg'?)``),
            or a value out of range, as the case file would.
        """
        doc = self.to_document()
        doc["errors"].update({k: _plain(v) for k, v in errors.items()})
        return parse_gear_case(doc, source=self.source)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready inputs (for ``summary.json``)."""
        return {
            "name": self.name,
            "kind": self.kind,
            "source": self.source,
            "description": self.description,
            "pair": dict(self.pair),
            "load": {
                self.load_key: self.load_value,
                "torque2_Nmm": self.torque2_Nmm,
                "pinion_torque_Nm": self.torque2_Nmm / self.ratio / 1000.0,
                "speed_rpm": self.speed_rpm,
            },
            "errors": {k: getattr(self.errors, k) for k in _error_keys(self.kind)},
            "analysis": {
                "fidelity": self.fidelity,
                "level": self.level,
                "n_positions": self.n_positions,
                "n_teeth": self.n_teeth,
                "backend": self.backend,
            },
            "material": {"E_MPa": self.E_MPa, "nu": self.nu},
        }


#: :meth:`GearCase.replace` field -> (case-file section, key)
_REPLACE_KEYS = {
    "name": ("case", "name"),
    "description": ("case", "description"),
    "fidelity": ("analysis", "fidelity"),
    "level": ("analysis", "level"),
    "n_positions": ("analysis", "n_positions"),
    "n_teeth": ("analysis", "n_teeth"),
    "backend": ("analysis", "backend"),
    "E_MPa": ("material", "E_MPa"),
    "nu": ("material", "nu"),
    "speed_rpm": ("load", "speed_rpm"),
}


def _plain(value: Any) -> Any:
    """Python values of what a case file could hold: numpy scalars and arrays become numbers
    and lists, tuples lists (so that the case-file checks see what they expect)."""
    import numpy as np

    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _tooth_numbers(kind: str, pair: dict[str, Any]) -> tuple[int, int]:
    if kind == "face_gear":
        return pair["n_pinion"], pair["n_face_gear"]
    if kind == "spur":
        return pair["teeth"][0], pair["teeth"][1]
    return pair["n_pinion"], pair["n_gear"]


def _error_keys(kind: str) -> tuple[str, ...]:
    return _ERRORS_PARALLEL if kind == "spur" else _ERRORS_INTERSECTING


def _is_num(v: Any) -> bool:
    return isinstance(v, _NUM) and not isinstance(v, bool)


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _check_value(fld: str, value: Any, typ: Any) -> None:
    if typ is _NUM:
        if not _is_num(value):
            raise InputError(fld, value, "a number")
        if not math.isfinite(value):
            raise InputError(fld, value, "a finite number")
    elif typ is int:
        if not _is_int(value):
            raise InputError(fld, value, "an integer")
    elif typ is str:
        if not isinstance(value, str):
            raise InputError(fld, value, "a string")
    elif typ in (_INT2, _NUM2, _PAIR):
        if typ == _PAIR and _is_num(value):
            _check_value(fld, value, _NUM)
            return
        what = {
            _INT2: "a list of two integers [pinion, gear]",
            _NUM2: "a list of two numbers [pinion, gear]",
            _PAIR: "a number or a list of two numbers [pinion, gear]",
        }[typ]
        if not isinstance(value, list) or len(value) != 2:
            raise InputError(fld, value, what)
        for i, v in enumerate(value):
            _check_value(f"{fld}[{i}]", v, int if typ == _INT2 else _NUM)


def _check_table(
    section: str, table: Any, schema: dict[str, tuple[Any, bool]], what: str = ""
) -> dict[str, Any]:
    if not isinstance(table, dict):
        raise InputError(section, table, f"a TOML table [{section}]")
    for key, value in table.items():
        if key not in schema:
            close = difflib.get_close_matches(key, list(schema), n=1, cutoff=0.5)
            hint = f"did you mean {close[0]!r}?" if close else ""
            raise InputError(
                f"{section}.{key}", value, f"one of the keys {sorted(schema)}{what}", hint
            )
        _check_value(f"{section}.{key}", value, schema[key][0])
    for key, (_, required) in schema.items():
        if required and key not in table:
            raise InputError(f"{section}.{key}", "missing", f"present (required{what})")
    return dict(table)


def _positive(fld: str, v: float) -> None:
    if not v > 0:
        raise InputError(fld, v, "> 0")


def _in_range(fld: str, v: float, lo: float, hi: float, unit: str = "") -> None:
    if not lo <= v <= hi:
        raise InputError(fld, v, f"in [{lo:g}, {hi:g}]{unit}")


def _teeth(fld: str, v: int, minimum: int = 5) -> None:
    if v < minimum:
        raise InputError(fld, v, f"an integer >= {minimum}")


def _check_pair(kind: str, p: dict[str, Any]) -> dict[str, Any]:
    """Plain ranges of the design data (the geometry checks the rest: undercut, pointing)."""
    if kind == "face_gear":
        for k in ("n_face_gear", "n_pinion", "n_shaper"):
            if k in p:
                _teeth(f"pair.{k}", p[k])
        for k in ("module_mm", "inner_radius_mm", "outer_radius_mm", "pinion_face_width_mm",
                  "blank_thickness_mm", "addendum_coeff", "dedendum_coeff"):  # fmt: skip
            if k in p:
                _positive(f"pair.{k}", p[k])
        _in_range("pair.pressure_angle_deg", p["pressure_angle_deg"], 10, 35, " deg")
        if "shaft_angle_deg" in p:
            _in_range("pair.shaft_angle_deg", p["shaft_angle_deg"], 45, 135, " deg")
        if p["outer_radius_mm"] <= p["inner_radius_mm"]:
            raise InputError(
                "pair.outer_radius_mm",
                p["outer_radius_mm"],
                f"> pair.inner_radius_mm = {p['inner_radius_mm']}",
            )
    elif kind == "spur":
        for i, z in enumerate(p["teeth"]):
            _teeth(f"pair.teeth[{i}]", z)
        _positive("pair.module_mm", p["module_mm"])
        _in_range("pair.pressure_angle_deg", p["pressure_angle_deg"], 10, 35, " deg")
        for i, x in enumerate(p.get("profile_shift", [0.0, 0.0])):
            _in_range(f"pair.profile_shift[{i}]", x, -1, 2)
        for k, check in (
            ("face_width_mm", _positive),
            ("addendum_coeff", _positive),
            ("dedendum_coeff", _positive),
        ):
            for fld, v in _members(k, p.get(k)):
                check(fld, v)
        for k in ("profile_crowning_mm", "lead_crowning_mm", "tip_relief_mm"):
            for fld, v in _members(k, p.get(k)):
                if v < 0:
                    raise InputError(fld, v, ">= 0")
    else:
        _teeth("pair.n_pinion", p["n_pinion"])
        _teeth("pair.n_gear", p["n_gear"])
        if p["n_pinion"] > p["n_gear"]:
            raise InputError(
                "pair.n_pinion", p["n_pinion"], f"<= pair.n_gear = {p['n_gear']} (member 1)"
            )
        for k in ("module_mm", "face_width_mm", "cutter_radius_mm", "te_amplitude_arcsec"):
            if k in p:
                _positive(f"pair.{k}", p[k])
        _in_range("pair.spiral_angle_deg", p["spiral_angle_deg"], 0, 50, " deg")
        _in_range("pair.pressure_angle_deg", p["pressure_angle_deg"], 10, 30, " deg")
        if "shaft_angle_deg" in p and not 0 < p["shaft_angle_deg"] < 180:
            raise InputError("pair.shaft_angle_deg", p["shaft_angle_deg"], "in (0, 180) deg")
        if "te_amplitude_arcsec" in p:
            _in_range("pair.te_amplitude_arcsec", p["te_amplitude_arcsec"], 0, 60, " arcsec")
        if p.get("side", "drive") not in ("drive", "coast"):
            raise InputError("pair.side", p["side"], "'drive' or 'coast'")
    return p


def _members(key: str, value: Any) -> list[tuple[str, float]]:
    """``[(field, value)]`` of a number-or-pair key (empty if absent)."""
    if value is None:
        return []
    if isinstance(value, list):
        return [(f"pair.{key}[{i}]", v) for i, v in enumerate(value)]
    return [(f"pair.{key}", value)]


def parse_gear_case(data: dict[str, Any], source: str = "<memory>") -> GearCase:
    """Validate a parsed TOML document of a gear pair and build the case.

    Parameters
    ----------
    data
        The parsed TOML document.
    source
        Where it came from (file path), for messages and the default name.

    Raises
    ------
    InputError
        Naming the case-file field, the value and the allowed range.
    """
    if "case" not in data:
        raise InputError("case", "missing", "a [case] section (required)")
    kind = data["case"].get("kind") if isinstance(data["case"], dict) else None
    if kind not in GEAR_KINDS:
        raise InputError("case.kind", kind, f"one of {GEAR_KINDS}")
    sections = ("case", "pair", "load", "errors", "analysis", "material")
    for key in data:
        if key not in sections:
            close = difflib.get_close_matches(key, list(sections), n=1, cutoff=0.5)
            raise InputError(
                key,
                "[" + key + "]",
                f"one of the sections {sorted(sections)}",
                f"did you mean [{close[0]}]?" if close else "",
            )
    for sec in _REQUIRED_SECTIONS:
        if sec not in data:
            raise InputError(sec, "missing", f"a [{sec}] section (required)")
    for_kind = f" for kind {kind!r}"
    case = _check_table("case", data["case"], _COMMON_SCHEMA["case"])
    pair = _check_pair(kind, _check_table("pair", data["pair"], _PAIR_SCHEMA[kind], for_kind))
    load = _check_table("load", data["load"], _COMMON_SCHEMA["load"])
    err_schema = {k: (_NUM, False) for k in _error_keys(kind)}
    errs = _check_table("errors", data.get("errors", {}), err_schema, for_kind)
    ana = _check_table("analysis", data.get("analysis", {}), _COMMON_SCHEMA["analysis"])
    mat = _check_table("material", data.get("material", {}), _COMMON_SCHEMA["material"])

    given = [k for k in _TORQUE_KEYS if k in load]
    if len(given) != 1:
        raise InputError(
            "load",
            ", ".join(given) if given else "no torque",
            "exactly one of load.torque2_Nm, load.torque2_Nmm, load.pinion_torque_Nm",
        )
    key = given[0]
    value = float(load[key])
    if not value > 0:
        raise InputError(f"load.{key}", load[key], "> 0 (positive in the driving sense)")
    n1, n2 = _tooth_numbers(kind, pair)
    torque2 = {
        "torque2_Nm": value * 1000.0,
        "torque2_Nmm": value,
        "pinion_torque_Nm": value * 1000.0 * n2 / n1,
    }[key]
    if "speed_rpm" in load and load["speed_rpm"] < 0:
        raise InputError("load.speed_rpm", load["speed_rpm"], ">= 0")

    fidelity = ana.get("fidelity", DEFAULT_FIDELITY)
    if fidelity not in FIDELITIES:
        raise InputError(
            "analysis.fidelity", fidelity, f"one of {FIDELITIES} for gear pairs", _FIDELITY_NOTE
        )
    level = ana.get("level", 0)
    if not 0 <= level < N_LEVELS:
        raise InputError("analysis.level", level, f"an integer in [0, {N_LEVELS - 1}]")
    n_pos = ana.get("n_positions", 25)
    if not 2 <= n_pos <= 400:
        raise InputError("analysis.n_positions", n_pos, "an integer in [2, 400]")
    n_teeth = ana.get("n_teeth")
    if n_teeth is not None and not 3 <= n_teeth <= 9:
        raise InputError("analysis.n_teeth", n_teeth, "an integer in [3, 9], or absent (automatic)")
    backend = ana.get("backend", "auto")
    if backend not in ("auto", "pardiso", "superlu"):
        raise InputError("analysis.backend", backend, "'auto', 'pardiso' or 'superlu'")
    E = float(mat.get("E_MPa", 206000.0))
    _positive("material.E_MPa", E)
    nu = float(mat.get("nu", 0.3))
    if not -1.0 < nu < 0.5:
        raise InputError("material.nu", nu, "in (-1, 0.5)")
    try:
        errors = InstallationErrors(**{k: float(v) for k, v in errs.items()})
    except InputError as exc:
        raise InputError(exc.field, exc.value, exc.allowed) from exc
    return GearCase(
        name=case.get("name", Path(source).stem),
        kind=kind,
        pair=pair,
        torque2_Nmm=torque2,
        load_key=key,
        load_value=value,
        errors=errors,
        fidelity=fidelity,
        level=int(level),
        n_positions=int(n_pos),
        n_teeth=None if n_teeth is None else int(n_teeth),
        backend=backend,
        E_MPa=E,
        nu=nu,
        speed_rpm=float(load["speed_rpm"]) if "speed_rpm" in load else None,
        description=case.get("description", ""),
        source=source,
    )


_FIDELITY_NOTE = "fe, hertz, hybrid (loaded) or tca (unloaded)"


# --------------------------------------------------------------------------------------------
# The pair a case describes
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class GearPair:
    """Generated members and their assembly (with the case's installation errors)."""

    pinion: Any
    gear: Any
    assembly: Any
    spiral_bevel: Any = None


# design-field name (as the geometry reports it) -> case-file key
_FACE_GEAR_FIELDS = {"n_shaper_teeth": "n_shaper"}
_SPUR_FIELDS = {"n_teeth": "teeth", "face_width_mm": "face_width_mm"}
_BEVEL_FIELDS = {
    "n1": "n_pinion",
    "n2": "n_gear",
    "te_amplitude_arcsec": "te_amplitude_arcsec",
}
_BEVEL_CACHE: dict[tuple, Any] = {}


def _renamed(
    exc: InputError, member: int | None, table: dict[str, str], case: GearCase
) -> InputError:
    """The geometry's error with the field renamed to the case-file key (or, for a derived
    quantity such as the tip radius, named with the member it belongs to)."""
    f = exc.field.split(".")[-1]
    key = table.get(f, f)
    pair = case.pair
    if key in _PAIR_SCHEMA[case.kind]:
        fld = f"pair.{key}"
        if member is not None and isinstance(pair.get(key), list):
            fld += f"[{member}]"
        return type(exc)(fld, exc.value, exc.allowed)
    who = {0: "pinion", 1: "gear"}.get(member, case.kind)  # type: ignore[arg-type]
    return type(exc)(f"pair ({who} {f}, derived from the [pair] data)", exc.value, exc.allowed)


def _member_value(pair: dict, key: str, i: int, default: float) -> float:
    v = pair.get(key, default)
    return float(v[i]) if isinstance(v, list) else float(v)


def build_pair(case: GearCase) -> GearPair:
    """Generate the members of a case and assemble them with its installation errors.

    Raises
    ------
    InputError, DesignError
        Design data that cannot make a valid tooth, naming the case-file key.
    """
    from fegear.assembly import face_gear_assembly, involute_assembly, spiral_bevel_assembly

    p = case.pair
    if case.kind == "face_gear":
        from fegear.geometry import FaceGearDesign, FaceGearMember

        kw = {k: v for k, v in p.items() if k != "n_shaper"}
        if "n_shaper" in p:
            kw["n_shaper_teeth"] = p["n_shaper"]
        try:
            fg = FaceGearMember(FaceGearDesign(**kw))
            pinion = fg.pinion()
        except InputError as exc:
            raise _renamed(exc, None, _FACE_GEAR_FIELDS, case) from exc
        return GearPair(pinion, fg, face_gear_assembly(fg, case.errors, pinion))
    if case.kind == "spur":
        from fegear.geometry import InvoluteDesign, InvoluteMember

        members = []
        for i, name in enumerate(("pinion", "gear")):
            try:
                d = InvoluteDesign(
                    n_teeth=int(p["teeth"][i]),
                    module_mm=float(p["module_mm"]),
                    pressure_angle_deg=float(p["pressure_angle_deg"]),
                    profile_shift=float(p.get("profile_shift", [0.0, 0.0])[i]),
                    face_width_mm=_member_value(p, "face_width_mm", i, 10.0),
                    addendum_coeff=_member_value(p, "addendum_coeff", i, 1.0),
                    dedendum_coeff=_member_value(p, "dedendum_coeff", i, 1.25),
                    profile_crowning_mm=_member_value(p, "profile_crowning_mm", i, 0.0),
                    lead_crowning_mm=_member_value(p, "lead_crowning_mm", i, 0.0),
                    tip_relief_mm=_member_value(p, "tip_relief_mm", i, 0.0),
                )
                members.append(InvoluteMember(d, name))
            except InputError as exc:
                raise _renamed(exc, i, _SPUR_FIELDS, case) from exc
        return GearPair(members[0], members[1], involute_assembly(*members, case.errors))
    # spiral bevel: the synthesis (~10-20 s) is cached per process and on disk for the same
    # blank data (_bevel_pair)

    blank_kw = {
        "n1": int(p["n_pinion"]),
        "n2": int(p["n_gear"]),
        "module_mm": float(p["module_mm"]),
        "spiral_angle_deg": float(p["spiral_angle_deg"]),
        "pressure_angle_deg": float(p["pressure_angle_deg"]),
        "face_width_mm": float(p["face_width_mm"]),
    }
    for k in ("shaft_angle_deg", "cutter_radius_mm"):
        if k in p:
            blank_kw[k] = float(p[k])
    target_kw = {}
    if "te_amplitude_arcsec" in p:
        target_kw["te_amplitude_arcsec"] = float(p["te_amplitude_arcsec"])
    key = (tuple(sorted(blank_kw.items())), tuple(sorted(target_kw.items())))
    try:
        if key not in _BEVEL_CACHE:
            _BEVEL_CACHE[key] = _bevel_pair(blank_kw, target_kw)
        sb = _BEVEL_CACHE[key]
    except InputError as exc:
        raise _renamed(exc, None, _BEVEL_FIELDS, case) from exc
    side = p.get("side", "drive")
    return GearPair(sb.pinion, sb.gear, spiral_bevel_assembly(sb, side, case.errors), sb)


def _bevel_pair(blank_kw: dict[str, Any], target_kw: dict[str, Any]):
    """The synthesized spiral bevel pair of the blank data: read from the artefact cache when
    the same blank and targets were synthesized before by the same geometry code (the
    synthesis takes 10-20 s; its pickle loads in a millisecond), else synthesized and cached.
    The key holds a hash of the source of the geometry and TCA packages
    (:func:`fegear.tca.cached._source_hash`): a change of the synthesis invalidates it."""
    import pickle

    from fegear.geometry.spiral_bevel import SpiralBevelPair
    from fegear.geometry.spiral_bevel_settings import SpiralBevelBlank, SynthesisTargets
    from fegear.mesh.cache import cached_file
    from fegear.tca.cached import _source_hash

    box: dict[str, Any] = {}

    def build(path: Path) -> None:
        # a design error raises here, before anything is written (nothing is cached)
        box["pair"] = SpiralBevelPair.design(
            SpiralBevelBlank(**blank_kw), SynthesisTargets(**target_kw)
        )
        path.write_bytes(pickle.dumps(box["pair"], protocol=pickle.HIGHEST_PROTOCOL))

    params = {"blank": blank_kw, "targets": target_kw, "source": _source_hash()}
    path, hit = cached_file("bevel_pair", params, ".pkl", build)
    if not hit:
        return box["pair"]
    return pickle.loads(path.read_bytes())


def error_fields(case: GearCase) -> list[tuple[str, float]]:
    """``[(case-file key, value)]`` of the case's non-zero installation errors
    (``("errors.da_mm", 9.5)``)."""
    return [
        (f"errors.{k}", float(getattr(case.errors, k)))
        for k in _error_keys(case.kind)
        if getattr(case.errors, k) != 0.0
    ]


def assemble(case: GearCase, pair: GearPair, errors: InstallationErrors):
    """The assembly of ``pair`` with other installation ``errors`` (same members and flanks)."""
    from fegear.assembly import face_gear_assembly, involute_assembly, spiral_bevel_assembly

    if case.kind == "face_gear":
        return face_gear_assembly(pair.gear, errors, pair.pinion)
    if case.kind == "spur":
        return involute_assembly(pair.pinion, pair.gear, errors)
    return spiral_bevel_assembly(pair.spiral_bevel, case.pair.get("side", "drive"), errors)
