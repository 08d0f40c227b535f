"""Gear-pair case files (TOML): schema and validation, read into a :class:`GearCase`.

Units are in the key names (``docs/conventions.md``). Unknown sections and keys are refused with the
closest known key suggested (which catches a wrong unit suffix: ``module_in`` → ``module_mm``),
missing required keys are refused, and every error is an :class:`~fegear.errors.InputError` naming
the case-file field, the value and the allowed range, so that ``fegear run`` prints one line and
exits with code 2 before any work.

The schema is declared once, as :class:`~fegear.io.schema.Section` objects (:func:`sections`):
the validation, the defaults and the case-file reference (:func:`reference`,
``docs/case_files.md``) all come from it. Sections: ``[case]`` (kind, name), ``[pair]`` (design
data, by kind), ``[load]`` (one torque), ``[errors]`` (installation errors, by axis arrangement),
``[analysis]`` (fidelity, level, positions, sector teeth, backend), ``[material]``.

The load is the resisting torque on member 2 or the torque on member 1, positive in the driving
sense; a pinion torque is converted with the tooth ratio, ``T2 = T1 · N2/N1`` (no friction).
"""

from __future__ import annotations

import copy
import difflib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fegear.errors import InputError
from fegear.geometry.bevel import HypoidBlank, SpiralBevelBlank, SynthesisTargets
from fegear.geometry.bevel.sheet import FlankTable
from fegear.geometry.cylindrical import RELIEF_SHAPES
from fegear.geometry.face_gear import FaceGearDesign
from fegear.geometry.involute import InvoluteDesign
from fegear.geometry.pair_placement import InstallationErrors
from fegear.io.machine_table import parse_machine
from fegear.io.machine_table import reference_markdown as machine_reference
from fegear.io.schema import (
    BOOLEAN,
    INT_PAIR,
    INTEGER,
    NUMBER,
    NUMBER_OR_PAIR,
    NUMBER_PAIR,
    STRING,
    Key,
    Range,
    Section,
    check_document,
    check_table,
    reference_markdown,
)
from fegear.io.topography import FLANKS as TOPOGRAPHY_FLANKS
from fegear.io.topography import TopographyGrid, read_topography
from fegear.io.topography_traces import read_flank_traces
from fegear.options import ContactOptions
from fegear.units import TORQUE_KEYS, nm_from_nmm, torque2_Nmm_from
from fegear.units import pinion_torque_Nm as _pinion_torque_Nm

__all__ = [
    "GEAR_KINDS",
    "PARALLEL_KINDS",
    "DEFAULT_FIDELITY",
    "FIDELITIES",
    "UNLOADED",
    "N_LEVELS",
    "GearCase",
    "CONTACT",
    "parse_gear_case",
    "error_fields",
    "reference",
    "sections",
]

GEAR_KINDS = ("face_gear", "spur", "cylindrical", "spiral_bevel", "hypoid")
#: Kinds whose flanks a face-milling machine cuts: their ``[machine]`` section may give the
#: settings (:mod:`fegear.io.machine_table`).
BEVEL_KINDS = ("spiral_bevel", "hypoid")
#: ``[pair]`` keys of the synthesis of the settings: not used with a ``[machine]`` section
#: (a hypoid's cutter radius stays: it fixes the pitch cones, :func:`synthesis_keys`).
SYNTHESIS_KEYS = ("cutter_radius_mm", "te_amplitude_arcsec")


def synthesis_keys(kind: str) -> tuple[str, ...]:
    """The :data:`SYNTHESIS_KEYS` of a bevel kind (a hypoid's blank needs its cutter radius:
    the limit condition of its pitch cones, :mod:`fegear.geometry.bevel.hypoid_cones`)."""
    return SYNTHESIS_KEYS if kind != "hypoid" else ("te_amplitude_arcsec",)


#: Kinds with parallel axes (``[errors]``: centre distance and axis parallelism).
PARALLEL_KINDS = ("spur", "cylindrical")
#: Fidelities of the gear pairs (``docs/fidelity.md``).
#: The unloaded analysis (rigid TCA only); the others are the loaded fidelities of
#: :data:`fegear.ltca.fidelity.FIDELITIES` (tests/test_architecture.py keeps the two in step).
UNLOADED = "tca"
FIDELITIES = ("fe", "hertz", "hybrid", UNLOADED)
#: The fidelity of a gear case that does not name one: the one that resolves the contact patch
#: at the default (coarsest) level. ``fe`` level 0 does not: its cells are wider than the patch
#: (FZG: p_max 126-160 MPa where ``hybrid``, ``hertz`` and line Hertz give about 1100 MPa; seed
#: face gear: loaded TE p-p 2.39″ against 0.43″ at ``hybrid``).
DEFAULT_FIDELITY = "hybrid"
#: Sector mesh levels 0 … N_LEVELS − 1 (:data:`fegear.mesh.sector.FINE`).
N_LEVELS = 5

_FIDELITY_NOTE = "fe, hertz, hybrid (loaded) or tca (unloaded)"
_TORQUE_ALLOWED = "> 0 (positive in the driving sense)"


def _design_default(cls: type, name: str) -> Any:
    """The default of a design dataclass field (the geometry owns it; the reference shows it)."""
    return cls.__dataclass_fields__[name].default  # type: ignore[attr-defined]


_POS = Range(0, None, lo_open=True)
_NONNEG = Range(0, None)
_TEETH = Range(5, None)
_DEG = "deg"

_MOD = NUMBER_OR_PAIR
_SHAPES = tuple(RELIEF_SHAPES)


def _mod(name: str, doc: str, rng: Range | None = _NONNEG, default: Any = 0.0) -> Key:
    return Key(name, _MOD, doc, default=default, range=rng)


#: ``[pair]`` of ``kind = "cylindrical"``: spur and helical pairs with flank modifications
#: (:mod:`fegear.geometry.cylindrical`; the modifications are transverse deviations along the
#: line of action, positive = material removed).
_CYLINDRICAL = Section(
    "pair",
    (
        Key("teeth", INT_PAIR, "tooth numbers", True, range=_TEETH),
        Key("module_mm", NUMBER, "normal module m_n, mm", True, range=_POS),
        Key("pressure_angle_deg", NUMBER, "normal pressure angle α_n, deg", True,
            range=Range(10, 35, unit=_DEG)),
        Key("helix_angle_deg", NUMBER, "helix angle β at the reference circle, deg (0: spur)",
            default=0.0, range=Range(0, 45, unit=_DEG)),
        Key("hand", STRING, "hand of the pinion's helix (the gear's is the other)",
            default="right", choices=("right", "left")),
        Key("profile_shift", NUMBER_PAIR, "profile shift coefficients x", default=[0.0, 0.0],
            range=Range(-1, 2)),
        Key("tip_diameter_mm", NUMBER_PAIR, "tip diameters d_a, mm (default: "
            "m_n (z/cos β + 2 h_a* + 2 x))", range=_POS),
        Key("face_width_mm", NUMBER_OR_PAIR, "face width b, mm",
            default=_design_default(InvoluteDesign, "face_width_mm"), range=_POS),
        Key("face_offset_mm", NUMBER, "axial position of the pinion's face centre from the "
            "gear's (along the axes), mm", default=0.0),
        Key("addendum_coeff", NUMBER_OR_PAIR, "addendum h_a* / m_n (the tip when no "
            "tip_diameter_mm)", default=_design_default(InvoluteDesign, "addendum_coeff"),
            range=_POS),
        Key("dedendum_coeff", NUMBER_OR_PAIR, "dedendum h_f* / m_n (the tool's addendum: the "
            "root)", default=_design_default(InvoluteDesign, "dedendum_coeff"), range=_POS),
        Key("tool_tip_radius_coeff", NUMBER_OR_PAIR, "tip radius of the generating rack "
            "ρ_aP0* / m_n (generates the fillet)",
            default=_design_default(InvoluteDesign, "rack_tip_radius_coeff"), range=_POS),
        _mod("lead_crowning_mm", "lead crowning C_β (removed at both face ends), mm"),
        _mod("helix_slope_mm", "helix slope deviation f_Hβ over the face width (positive: "
             "removed towards +z), mm", rng=None),
        _mod("end_relief_mm", "end relief C_e at both face ends, mm"),
        _mod("end_relief_length_mm", "length of the end relief l_e from each face end, mm",
             rng=_POS, default=None),
        Key("end_relief_shape", STRING, "end relief along the face", default="linear",
            choices=_SHAPES),
        _mod("profile_crowning_mm", "profile crowning C_α (removed at the form circle and "
             "the tip), mm"),
        _mod("tip_relief_mm", "tip relief C_a at the tip circle, mm"),
        _mod("tip_relief_start_diameter_mm", "diameter where the tip relief starts, mm "
             "(default: 60 % of the way from the reference to the tip diameter)", rng=_POS,
             default=None),
        _mod("tip_relief_start_roll_deg", "roll angle where the tip relief starts, deg "
             "(instead of a diameter)", rng=_POS, default=None),
        Key("tip_relief_shape", STRING, "tip relief along the profile (roll length)",
            default="linear", choices=_SHAPES),
        _mod("root_relief_mm", "root relief C_f at the form circle, mm"),
        _mod("root_relief_start_diameter_mm", "diameter where the root relief starts, mm "
             "(default: 60 % of the way from the reference to the form diameter)", rng=_POS,
             default=None),
        _mod("root_relief_start_roll_deg", "roll angle where the root relief starts, deg "
             "(instead of a diameter)", rng=_POS, default=None),
        Key("root_relief_shape", STRING, "root relief along the profile (roll length)",
            default="linear", choices=_SHAPES),
    ),
    "Spur and helical pairs with flank modifications: a number for both members or "
    "[pinion, gear]. Modifications are deviations from the involute helicoid measured in the "
    "transverse section along the line of action (ISO 21771, as on a profile or helix chart), "
    "positive where material is removed.",
    required=True,
)  # fmt: skip


#: ``[pair]`` by kind (design data; the geometry checks the rest: undercut, pointing).
def _bevel_keys(hypoid: bool) -> tuple[Key, ...]:
    """The ``[pair]`` keys of a face-milled bevel pair: a spiral bevel, or a hypoid (its offset,
    the pinion's spiral angle and face width)."""
    keys = (
        Key("n_pinion", INTEGER, "pinion teeth (member 1, <= n_gear)", True, range=_TEETH),
        Key("n_gear", INTEGER, "gear teeth", True, range=_TEETH),
        Key("module_mm", NUMBER, "outer transverse module, mm", True, range=_POS),
        Key(
            "spiral_angle_deg",
            NUMBER,
            "mean spiral angle, deg",
            True,
            range=Range(0, 50, unit=_DEG),
        ),
        Key(
            "pressure_angle_deg",
            NUMBER,
            "pressure angle, deg",
            True,
            range=Range(10, 30, unit=_DEG),
        ),
        Key("face_width_mm", NUMBER, "face width, mm", True, range=_POS),
        Key(
            "shaft_angle_deg",
            NUMBER,
            "shaft angle, deg",
            default=_design_default(SpiralBevelBlank, "shaft_angle_deg"),
            range=Range(0, 180, lo_open=True, hi_open=True, unit=_DEG),
        ),
        Key(
            "cutter_radius_mm",
            NUMBER,
            "gear head-cutter radius, mm",
            default=_design_default(SpiralBevelBlank, "cutter_radius_mm"),
            range=_POS,
        ),
        Key(
            "edge_radius_mm",
            NUMBER,
            "blade edge radius (generates the fillet), mm "
            "(default: 0.25 m where the tooth spaces carry it, else 80 % of the largest "
            "they carry)",
            range=_POS,
        ),
        Key(
            "te_amplitude_arcsec",
            NUMBER,
            "predesigned parabolic TE amplitude, arcsec",
            default=_design_default(SynthesisTargets, "te_amplitude_arcsec"),
            range=Range(0, 60, lo_open=True, unit="arcsec"),
        ),
        Key(
            "side",
            STRING,
            "the flank pair that drives",
            default="drive",
            choices=("drive", "coast"),
        ),
        Key(
            "hand",
            STRING,
            "hand of the gear's spiral (the pinion has the other)",
            default=_design_default(SpiralBevelBlank, "hand"),
            choices=("right", "left"),
        ),
    )
    if not hypoid:
        return keys
    offset = (
        Key("offset_mm", NUMBER, "hypoid offset E: shortest distance between the axes, mm "
            "(the gear's hand puts the pinion on the usual side: pinion spiral angle > gear's)",
            True, range=Range(0, None, unit="mm")),
        Key("pinion_face_width_mm", NUMBER, "pinion face width, mm (default: as the hypoid blank "
            "places it to cover the gear face)", range=_POS),
        Key("limit_pressure_angle_factor", NUMBER, "ISO 23509 f_alim: the flank pressure "
            "angles are alpha -/+ f_alim alpha_lim (drive/coast)",
            default=_design_default(HypoidBlank, "limit_pressure_angle_factor"),
            range=Range(0, 1)),
    )  # fmt: skip
    return (
        tuple(
            Key(
                k.name, k.type, "pinion mean spiral angle, deg", True, range=Range(0, 60, unit=_DEG)
            )
            if k.name == "spiral_angle_deg"
            else k
            for k in keys
        )
        + offset
    )


PAIR_SECTIONS: dict[str, Section] = {
    "face_gear": Section(
        "pair",
        (
            Key("n_face_gear", INTEGER, "teeth of the face gear", True, range=_TEETH),
            Key("n_pinion", INTEGER, "teeth of the spur involute pinion", True, range=_TEETH),
            Key("module_mm", NUMBER, "module, mm", True, range=_POS),
            Key(
                "pressure_angle_deg",
                NUMBER,
                "pressure angle, deg",
                True,
                range=Range(10, 35, unit=_DEG),
            ),
            Key("inner_radius_mm", NUMBER, "radius of the tooth's inner end, mm", True, range=_POS),
            Key(
                "outer_radius_mm",
                NUMBER,
                "radius of the tooth's outer end (> inner), mm",
                True,
                range=_POS,
            ),
            Key(
                "shaft_angle_deg",
                NUMBER,
                "shaft angle, deg",
                default=_design_default(FaceGearDesign, "shaft_angle_deg"),
                range=Range(45, 135, unit=_DEG),
            ),
            Key(
                "pinion_face_width_mm",
                NUMBER,
                "pinion face width, mm",
                default=_design_default(FaceGearDesign, "pinion_face_width_mm"),
                range=_POS,
            ),
            Key(
                "blank_thickness_mm",
                NUMBER,
                "face-gear blank below the root, mm",
                default=_design_default(FaceGearDesign, "blank_thickness_mm"),
                range=_POS,
            ),
            Key(
                "n_shaper",
                INTEGER,
                "teeth of the shaper that generates the face gear (default: n_pinion + 2)",
                range=_TEETH,
            ),
            Key(
                "addendum_coeff",
                NUMBER,
                "addendum / module",
                default=_design_default(FaceGearDesign, "addendum_coeff"),
                range=_POS,
            ),
            Key(
                "dedendum_coeff",
                NUMBER,
                "dedendum / module",
                default=_design_default(FaceGearDesign, "dedendum_coeff"),
                range=_POS,
            ),
        ),
        "Face gear with a spur involute pinion, generated by a shaper.",
        required=True,
    ),
    "spur": Section(
        "pair",
        (
            Key("teeth", INT_PAIR, "tooth numbers", True, range=_TEETH),
            Key("module_mm", NUMBER, "normal module, mm", True, range=_POS),
            Key(
                "pressure_angle_deg",
                NUMBER,
                "pressure angle, deg",
                True,
                range=Range(10, 35, unit=_DEG),
            ),
            Key(
                "profile_shift",
                NUMBER_PAIR,
                "profile shift coefficients",
                default=[0.0, 0.0],
                range=Range(-1, 2),
            ),
            Key(
                "face_width_mm",
                NUMBER_OR_PAIR,
                "face width, mm",
                default=_design_default(InvoluteDesign, "face_width_mm"),
                range=_POS,
            ),
            Key(
                "addendum_coeff",
                NUMBER_OR_PAIR,
                "addendum / module",
                default=_design_default(InvoluteDesign, "addendum_coeff"),
                range=_POS,
            ),
            Key(
                "dedendum_coeff",
                NUMBER_OR_PAIR,
                "dedendum / module",
                default=_design_default(InvoluteDesign, "dedendum_coeff"),
                range=_POS,
            ),
            Key(
                "profile_crowning_mm",
                NUMBER_OR_PAIR,
                "profile crowning, mm",
                default=_design_default(InvoluteDesign, "profile_crowning_mm"),
                range=_NONNEG,
            ),
            Key(
                "lead_crowning_mm",
                NUMBER_OR_PAIR,
                "lead crowning, mm",
                default=_design_default(InvoluteDesign, "lead_crowning_mm"),
                range=_NONNEG,
            ),
            Key(
                "tip_relief_mm",
                NUMBER_OR_PAIR,
                "tip relief, mm",
                default=_design_default(InvoluteDesign, "tip_relief_mm"),
                range=_NONNEG,
            ),
        ),
        "Spur involute pair, its modifications on the generating rack (the FZG validation "
        "pair): a number for both members or [pinion, gear]. Its keys are valid for "
        '`kind = "cylindrical"` too, which adds the helix, tip diameters, the tool and the '
        "flank modifications: change the kind to use them.",
        required=True,
    ),
    "cylindrical": _CYLINDRICAL,
    "spiral_bevel": Section(
        "pair",
        _bevel_keys(hypoid=False),
        "Spiral bevel blank data (face-milled): the machine settings are synthesized, or "
        "given in [machine] tables.",
        required=True,
    ),
    "hypoid": Section(
        "pair",
        _bevel_keys(hypoid=True),
        "Hypoid blank data (face-milled, pitch cones of ISO 23509 method 1 with the gear "
        "cutter radius as the limit radius): the machine settings are synthesized, or given "
        "in [machine] tables.",
        required=True,
    ),
}
_INTERSECTING = "intersecting or crossed axes (face gear, spiral bevel, hypoid)"
_PARALLEL = "parallel axes (spur, cylindrical)"
#: ``[errors]`` by axis arrangement (sign conventions: :mod:`fegear.geometry.pair_placement`).
ERROR_KEYS: dict[str, tuple[Key, ...]] = {
    "intersecting": (
        Key(
            "dE_mm", NUMBER, f"{_INTERSECTING}: shortest distance between the axes, mm", default=0.0
        ),
        Key("dA1_mm", NUMBER, f"{_INTERSECTING}: pinion axial (ΔP), mm", default=0.0),
        Key("dA2_mm", NUMBER, f"{_INTERSECTING}: gear axial (ΔG, Δq), mm", default=0.0),
        Key("dgamma_deg", NUMBER, f"{_INTERSECTING}: shaft angle, deg", default=0.0),
    ),
    "parallel": (
        Key("da_mm", NUMBER, f"{_PARALLEL}: centre distance, mm", default=0.0),
        Key(
            "f_sigma_delta_mm",
            NUMBER,
            f"{_PARALLEL}: axis inclination in the plane of the axes over the face width, mm",
            default=0.0,
        ),
        Key(
            "f_sigma_beta_mm",
            NUMBER,
            f"{_PARALLEL}: axis deviation out of that plane over the face width, mm",
            default=0.0,
        ),
        Key("dA1_mm", NUMBER, f"{_PARALLEL}: pinion axial, mm", default=0.0),
        Key("dA2_mm", NUMBER, f"{_PARALLEL}: gear axial, mm", default=0.0),
    ),
}
PAIR_ERRORS_INTERSECTING = tuple(k.name for k in ERROR_KEYS["intersecting"])
PAIR_ERRORS_PARALLEL = tuple(k.name for k in ERROR_KEYS["parallel"])
#: The sections every gear case has (``[pair]`` and ``[errors]`` depend on the kind).
CASE = Section(
    "case",
    (
        Key("kind", STRING, "the gear family", True, choices=GEAR_KINDS),
        Key("name", STRING, "case name (default: the file name)"),
        Key("description", STRING, "free text", default=""),
    ),
    required=True,
)
LOAD = Section(
    "load",
    (
        Key(
            "torque2_Nm",
            NUMBER,
            "resisting torque on member 2, N·m",
            range=_POS,
            allowed=_TORQUE_ALLOWED,
        ),
        Key(
            "torque2_Nmm",
            NUMBER,
            "resisting torque on member 2, N·mm",
            range=_POS,
            allowed=_TORQUE_ALLOWED,
        ),
        Key(
            "pinion_torque_Nm",
            NUMBER,
            "torque on member 1, N·m (T2 = T1 N2/N1)",
            range=_POS,
            allowed=_TORQUE_ALLOWED,
        ),
        Key("speed_rpm", NUMBER, "recorded only (the model is quasi-static)", range=_NONNEG),
    ),
    "Exactly one torque, positive in the driving sense.",
    required=True,
)
ANALYSIS = Section(
    "analysis",
    (
        Key(
            "fidelity",
            STRING,
            "contact model: hybrid, hertz, fe (loaded) or tca (unloaded)",
            default=DEFAULT_FIDELITY,
            choices=FIDELITIES,
            allowed=f"one of {FIDELITIES} for gear pairs",
            hint=_FIDELITY_NOTE,
        ),
        Key(
            "level",
            INTEGER,
            "sector mesh level (0 coarse)",
            default=0,
            range=Range(0, N_LEVELS - 1),
        ),
        Key("n_positions", INTEGER, "positions per mesh cycle", default=25, range=Range(2, 400)),
        Key(
            "n_teeth",
            INTEGER,
            "teeth per sector (default: the teeth that can touch + one each side)",
            range=Range(3, 9),
            allowed="an integer in [3, 9], or absent (automatic)",
        ),
        Key(
            "backend",
            STRING,
            "sparse direct solver",
            default="auto",
            choices=("auto", "pardiso", "superlu"),
        ),
        Key(
            "root_stress",
            BOOLEAN,
            "tooth root stress (fe, hybrid): the sectors remeshed with refined fillets, one "
            "more sparse factorisation per member, one member at a time (seed face gear: about "
            "2 min, 4.9 GB peak)",
            default=False,
        ),
    ),
)
MATERIAL = Section(
    "material",
    (
        Key("E_MPa", NUMBER, "Young's modulus of both members, MPa", default=206000.0, range=_POS),
        Key(
            "nu",
            NUMBER,
            "Poisson's ratio of both members",
            default=0.3,
            range=Range(-1, 0.5, lo_open=True, hi_open=True),
        ),
    ),
)
_C = ContactOptions
CONTACT = Section(
    "contact",
    (
        Key("g_max_mm", NUMBER, "separation below which contact cells are laid, mm (raised "
            "automatically while a left-out cell could close)", default=_C.default("g_max_mm"),
            range=_POS),
        Key("cell_mm", NUMBER, "contact-cell size, mm (default: the fine element size)",
            range=_POS, allowed="> 0, or absent (automatic)"),
        Key("n_across", INTEGER, "hybrid: cells across each loaded patch (its minor axis)",
            default=_C.default("n_across"), range=Range(1, None)),
        Key("n_along", INTEGER, "hybrid: cells along each loaded patch (its major axis)",
            default=_C.default("n_along"), range=Range(1, None)),
        Key("max_cells", INTEGER, "hybrid: cells of one pair at most", default=_C.default(
            "max_cells"), range=Range(1, None)),
        Key("trim", NUMBER, "hybrid: cells predicted open beyond trim θ h_max are left out of "
            "a warm solve (checked afterwards; 0 keeps every cell)", default=_C.default("trim"),
            range=_NONNEG),
        Key("depth_elements", NUMBER, "hybrid: matching-layer depth in fine elements",
            default=_C.default("depth_elements"), range=_POS),
        Key("depth_max_modules", NUMBER, "hybrid: matching-layer depth at most, in modules",
            default=_C.default("depth_max_modules"), range=_POS),
        Key("tca_grid", INT_PAIR, "cells of the TCA separation field the contact zone is "
            "found on", default=list(_C.default("tca_grid")), range=Range(2, None),
            labels=("u", "v")),
        Key("chunk_positions", INTEGER, "positions solved in sequence by one worker, each "
            "from its predecessor", default=_C.default("chunk_positions"), range=Range(1, None)),
    ),
    "Tuning of the loaded contact models; every default is a measured choice "
    "(benchmarks/results/contact_options.md). Leave it out unless you study the method.",
)  # fmt: skip


TOPOGRAPHY = Section(
    "topography",
    tuple(
        Key(k, STRING, f"measured grid of the {k.replace('_', ' ')} flank: a CSV file of normal "
            "deviations in µm (relative to the case file)")
        for k in TOPOGRAPHY_FLANKS
    ) + tuple(
        Key(k, STRING, f"measured {t} trace of the {f.replace('_', ' ')} flank (kind "
            f"'cylindrical'): a CSV file of normal deviations in µm against "
            f"{'the diameter' if t == 'profile' else 'z from the face centre'} (not with the "
            "flank's grid)")
        for f in TOPOGRAPHY_FLANKS for t in ("profile", "lead") for k in (f"{f}_{t}",)
    ),
    "Measured flanks (docs/measured_flanks.md): per member and side a grid of normal deviations "
    "from the generated flank, or (cylindrical) a profile and/or a lead trace, interpolated by "
    "a spline and added to it in the TCA and the loaded analysis. The sector meshes stay those "
    "of the design.",
)  # fmt: skip


def sections(kind: str) -> tuple[Section, ...]:
    """The sections of a gear case of ``kind`` (``[pair]`` and ``[errors]`` by kind)."""
    errors = Section(
        "errors",
        ERROR_KEYS["parallel" if kind in PARALLEL_KINDS else "intersecting"],
        "Installation errors, all 0 by default (sign conventions: fegear.geometry.pair_placement).",
    )
    return (CASE, PAIR_SECTIONS[kind], LOAD, errors, ANALYSIS, MATERIAL, CONTACT, TOPOGRAPHY)


def reference() -> str:
    """The gear case-file reference (Markdown), from the declarations."""
    common = (CASE, LOAD, ANALYSIS, MATERIAL, CONTACT, TOPOGRAPHY)
    errors = tuple(
        Section("errors", keys, f"Installation errors, {what}; all 0 by default.")
        for keys, what in ((ERROR_KEYS["intersecting"], _INTERSECTING),
                           (ERROR_KEYS["parallel"], _PARALLEL))
    )  # fmt: skip
    parts = [reference_markdown(common, "Every gear case")]
    for kind, sec in PAIR_SECTIONS.items():
        parts.append(reference_markdown((sec,), f'`kind = "{kind}"`'))
    parts.append(reference_markdown(errors, "Installation errors"))
    parts.append('### Machine settings\n\n<a id="machine"></a>\n\n' + machine_reference())
    return "\n".join(parts)


@dataclass(frozen=True)
class GearCase:
    """A validated gear-pair case.

    Attributes
    ----------
    name
        Case name (``[case] name``, else the file stem).
    kind
        ``"face_gear"``, ``"spur"``, ``"cylindrical"`` or ``"spiral_bevel"``.
    pair
        The ``[pair]`` table with defaults filled in (case-file keys and units).
    torque2_Nmm
        Resisting torque on member 2 (N·mm, > 0), converted from whichever load key was given.
    load_key
        The load key of the case file (``"torque2_Nm"``, ``"torque2_Nmm"`` or
        ``"pinion_torque_Nm"``) and ``load_value`` its value.
    errors
        Installation errors.
    fidelity, level, n_positions, n_teeth, backend, root_stress
        Analysis settings (``[analysis]``).
    contact
        Tuning of the contact models (``[contact]``, :class:`~fegear.options.ContactOptions`).
    E_MPa, nu
        Material of both members.
    speed_rpm
        Recorded only (quasi-static model).
    description, source
        Free text and the file the case came from.
    machine
        The ``[machine]`` section of a bevel case as written (the flank tables with their
        units), None where the settings are synthesized; :meth:`flank_tables` in mm/deg.
    topography
        The ``[topography]`` grids by flank key (``"pinion_drive"``, ...;
        :mod:`fegear.io.topography`; a flank's traces as their grid,
        :mod:`fegear.io.topography_traces`), empty for the design flanks; ``topography_files``
        the file names by case-file key as the case file gives them (relative to its folder).
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
    root_stress: bool = False
    contact: ContactOptions = field(default_factory=ContactOptions)
    E_MPa: float = 206000.0
    nu: float = 0.3
    speed_rpm: float | None = None
    description: str = ""
    source: str = "<memory>"
    machine: dict[str, Any] | None = None
    topography: dict[str, TopographyGrid] = field(default_factory=dict)
    topography_files: dict[str, str] = field(default_factory=dict)

    def flank_tables(self) -> dict[str, FlankTable] | None:
        """The machine settings of the ``[machine]`` section per flank, in mm and degrees
        (:mod:`fegear.io.machine_table`); None where they are synthesized."""
        return None if self.machine is None else parse_machine(self.machine)

    @property
    def ratio(self) -> float:
        """Tooth ratio ``N2/N1``."""
        n1, n2 = _tooth_numbers(self.kind, self.pair)
        return n2 / n1

    @property
    def torque2_Nm(self) -> float:
        """The gear's (member 2's) resisting torque in N·m (:mod:`fegear.units`)."""
        return nm_from_nmm(self.torque2_Nmm)

    @property
    def pinion_torque_Nm(self) -> float:
        """The pinion's torque in N·m that balances it (``T1 = T2 · N1/N2``, no friction)."""
        return _pinion_torque_Nm(self.torque2_Nmm, self.ratio)

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
            "root_stress": self.root_stress,
        }
        if self.n_teeth is not None:
            analysis["n_teeth"] = self.n_teeth
        doc = {
            "case": case,
            "pair": copy.deepcopy(self.pair),
            "load": load,
            "errors": {k: getattr(self.errors, k) for k in _error_keys(self.kind)},
            "analysis": analysis,
            "material": {"E_MPa": self.E_MPa, "nu": self.nu},
        }
        if self.contact.given():
            doc["contact"] = self.contact.given()
        if self.machine is not None:
            doc["machine"] = copy.deepcopy(self.machine)
        if self.topography_files:
            doc["topography"] = dict(self.topography_files)
        return doc

    def replace(self, **changes: Any) -> GearCase:
        """A new, validated case with some fields changed (the case itself is frozen).

        Parameters
        ----------
        **changes
            Fields of the case: ``name``, ``description``, ``fidelity``, ``level``,
            ``n_positions``, ``n_teeth`` (None: automatic), ``backend``, ``root_stress``,
            ``E_MPa``, ``nu``,
            ``speed_rpm`` (rpm, recorded only), ``errors`` (an
            :class:`~fegear.geometry.pair_placement.InstallationErrors` or a mapping of the
            ``[errors]`` keys:
            it replaces all of them, the ones not given are 0), ``pair`` (the whole ``[pair]``
            table: ``case.replace(pair={**case.pair, "module_mm": 5.0})``), ``contact`` (a
            :class:`~fegear.options.ContactOptions` or a mapping of the ``[contact]`` keys: it
            replaces all of them, the ones not given take their defaults), a load, which
            replaces the case's torque (``torque2_Nm``, N·m, or ``torque2_Nmm``, N·mm, on
            member 2; ``pinion_torque_Nm``, N·m, on member 1), ``topography`` (a mapping of
            the ``[topography]`` keys to grid or trace files: it replaces all of them; ``{}``
            the design flanks) and ``source``.

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
            elif key in TORQUE_KEYS:
                for other in TORQUE_KEYS:
                    doc["load"].pop(other, None)
                doc["load"][key] = value
            elif key == "pair":
                if not isinstance(value, dict):
                    raise InputError("pair", value, "a mapping of the [pair] keys")
                doc["pair"] = value
            elif key == "topography":
                if not isinstance(value, dict):
                    raise InputError("topography", value, "a mapping of the [topography] keys")
                doc["topography"] = {k: str(v) for k, v in value.items()}
                if not value:
                    doc.pop("topography")
            elif key == "contact":
                if isinstance(value, ContactOptions):
                    value = value.given()
                if not isinstance(value, dict):
                    raise InputError("contact", value, "ContactOptions or a mapping")
                doc["contact"] = value
            elif key == "errors":
                if isinstance(value, InstallationErrors):
                    value = {k: getattr(value, k) for k in _error_keys(self.kind)}
                if not isinstance(value, dict):
                    raise InputError("errors", value, "InstallationErrors or a mapping")
                doc["errors"] = value
            else:
                known = sorted(
                    [
                        *_REPLACE_KEYS,
                        *TORQUE_KEYS,
                        "pair",
                        "errors",
                        "contact",
                        "topography",
                        "source",
                    ]
                )
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
            :mod:`fegear.geometry.pair_placement`. ``case.replace(errors={})`` sets all of them to
            0.

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
                "pinion_torque_Nm": self.pinion_torque_Nm,
                "speed_rpm": self.speed_rpm,
            },
            "errors": {k: getattr(self.errors, k) for k in _error_keys(self.kind)},
            "analysis": {
                "fidelity": self.fidelity,
                "level": self.level,
                "n_positions": self.n_positions,
                "n_teeth": self.n_teeth,
                "backend": self.backend,
                "root_stress": self.root_stress,
            },
            "material": {"E_MPa": self.E_MPa, "nu": self.nu},
            "contact": {
                k: list(v) if isinstance(v, tuple) else v for k, v in self.contact.as_dict().items()
            },
            **(
                {}
                if self.machine is None
                else {"machine": {f: vars(t) for f, t in (self.flank_tables() or {}).items()}}
            ),
            **(
                {"topography": {k: g.echo() for k, g in self.topography.items()}}
                if self.topography
                else {}
            ),
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
    "root_stress": ("analysis", "root_stress"),
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
    if kind in PARALLEL_KINDS:
        return pair["teeth"][0], pair["teeth"][1]
    return pair["n_pinion"], pair["n_gear"]


def _error_keys(kind: str) -> tuple[str, ...]:
    return PAIR_ERRORS_PARALLEL if kind in PARALLEL_KINDS else PAIR_ERRORS_INTERSECTING


def _check_pair(kind: str, p: dict[str, Any]) -> dict[str, Any]:
    """The rules between ``[pair]`` keys (each key's own range is in its declaration)."""
    if kind == "face_gear" and p["outer_radius_mm"] <= p["inner_radius_mm"]:
        raise InputError(
            "pair.outer_radius_mm",
            p["outer_radius_mm"],
            f"> pair.inner_radius_mm = {p['inner_radius_mm']}",
        )
    if kind in BEVEL_KINDS and p["n_pinion"] > p["n_gear"]:
        raise InputError(
            "pair.n_pinion", p["n_pinion"], f"<= pair.n_gear = {p['n_gear']} (member 1)"
        )
    return p


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
    case_s, pair_s, load_s, errors_s, analysis_s, material_s, contact_s, topo_s = sections(kind)
    machine = data.get("machine") if kind in BEVEL_KINDS else None
    check_document({k: v for k, v in data.items() if machine is None or k != "machine"},
                   sections(kind))  # fmt: skip
    if machine is not None:
        parse_machine(machine)  # refused here, naming machine.<flank>.<key>
        for key in synthesis_keys(kind):
            if key in data["pair"]:
                raise InputError(f"pair.{key}", data["pair"][key], "absent with [machine]",
                                 "it steers the synthesis of the settings, which [machine] "
                                 "gives")  # fmt: skip
    for_kind = f" for kind {kind!r}"
    case = check_table(case_s, data["case"])
    pair = _check_pair(kind, check_table(pair_s, data["pair"], for_kind))
    load = check_table(load_s, data["load"])
    errs = check_table(errors_s, data.get("errors", {}), for_kind)
    ana = check_table(analysis_s, data.get("analysis", {}))
    mat = check_table(material_s, data.get("material", {}))
    tuning = check_table(contact_s, data.get("contact", {}))
    files = check_table(topo_s, data.get("topography", {}))
    folder = Path(source).parent if source != "<memory>" else Path.cwd()
    grids = {k: read_topography(k, str(files[k]), folder) for k in TOPOGRAPHY_FLANKS if k in files}
    grids.update(read_flank_traces(files, folder, kind))
    grids = {k: grids[k] for k in TOPOGRAPHY_FLANKS if k in grids}

    given = [k for k in TORQUE_KEYS if k in load]
    if len(given) != 1:
        raise InputError(
            "load",
            ", ".join(given) if given else "no torque",
            "exactly one of load.torque2_Nm, load.torque2_Nmm, load.pinion_torque_Nm",
        )
    key = given[0]
    value = float(load[key])
    n1, n2 = _tooth_numbers(kind, pair)
    torque2 = torque2_Nmm_from(key, value, n1, n2)
    fidelity = analysis_s.value(ana, "fidelity")
    level = analysis_s.value(ana, "level")
    n_pos = analysis_s.value(ana, "n_positions")
    n_teeth = analysis_s.value(ana, "n_teeth")
    backend = analysis_s.value(ana, "backend")
    root_stress = analysis_s.value(ana, "root_stress")
    E = float(material_s.value(mat, "E_MPa"))
    nu = float(material_s.value(mat, "nu"))
    try:
        errors = InstallationErrors(**{k: float(v) for k, v in errs.items()})
    except InputError as exc:
        raise InputError(exc.field, exc.value, exc.allowed) from exc
    values = {n: contact_s.value(tuning, n) for n in ContactOptions.names()}
    values["tca_grid"] = tuple(int(n) for n in values["tca_grid"])
    numbers = ("g_max_mm", "trim", "depth_elements", "depth_max_modules")
    values.update({n: float(values[n]) for n in numbers})
    if values["cell_mm"] is not None:
        values["cell_mm"] = float(values["cell_mm"])
    try:
        contact = ContactOptions(**values)
    except InputError as exc:
        raise InputError(f"contact.{exc.field}", exc.value, exc.allowed) from exc
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
        root_stress=root_stress,
        contact=contact,
        E_MPa=E,
        nu=nu,
        speed_rpm=float(load["speed_rpm"]) if "speed_rpm" in load else None,
        description=case_s.value(case, "description"),
        source=source,
        machine=copy.deepcopy(machine),
        topography=grids,
        topography_files={k: str(v) for k, v in files.items()},
    )


def error_fields(case: GearCase) -> list[tuple[str, float]]:
    """``[(case-file key, value)]`` of the case's non-zero installation errors
    (``("errors.da_mm", 9.5)``)."""
    return [
        (f"errors.{k}", float(getattr(case.errors, k)))
        for k in _error_keys(case.kind)
        if getattr(case.errors, k) != 0.0
    ]
