"""Gear tooth surfaces by generation (``docs/reference_pairs.md``: the pairs built from them).

Member frame of every family: rotation axis = z. See :mod:`fegear.geometry.surface` for the
sign conventions (outward normals, convex-positive curvature).
"""

from __future__ import annotations

from .face_gear import FaceGearDesign, FaceGearMember, ShaperTool, closed_form_point
from .generation import (
    Envelope,
    Fixed,
    Motion,
    Rotation,
    ToolSample,
    ToolSurface,
    Translation,
    generate,
    tool_sample,
)
from .involute import InvoluteDesign, InvoluteMember, RackCutter, involute_function
from .surface import (
    FlankBoundaries,
    FlankSurface,
    GeneratedMember,
    Side,
    curvatures_from_normal_derivatives,
    finite_difference_curvatures,
    principal_curvatures,
    unit,
)
from .transforms import (
    apply_points,
    apply_vectors,
    compose,
    d_rot_x,
    d_rot_y,
    d_rot_z,
    inverse,
    rot_axis,
    rot_x,
    rot_y,
    rot_z,
    translation,
)

__all__ = [
    "Envelope",
    "FaceGearDesign",
    "FaceGearMember",
    "Fixed",
    "InvoluteDesign",
    "InvoluteMember",
    "Motion",
    "RackCutter",
    "Rotation",
    "ShaperTool",
    "ToolSample",
    "ToolSurface",
    "Translation",
    "closed_form_point",
    "generate",
    "involute_function",
    "tool_sample",
    "FlankBoundaries",
    "FlankSurface",
    "GeneratedMember",
    "Side",
    "apply_points",
    "apply_vectors",
    "compose",
    "curvatures_from_normal_derivatives",
    "d_rot_x",
    "d_rot_y",
    "d_rot_z",
    "finite_difference_curvatures",
    "inverse",
    "principal_curvatures",
    "rot_axis",
    "rot_x",
    "rot_y",
    "rot_z",
    "translation",
    "unit",
]
