"""Homogeneous 4×4 transforms, vectorised over leading axes.

Every placement in fegear is a 4×4 homogeneous matrix ``M`` acting on column vectors,
``p' = R p + t`` with ``M = [[R, t], [0, 1]]``. All functions broadcast over leading axes: an
angle array of shape ``(...)`` gives matrices of shape ``(..., 4, 4)``.

Rotations are right-handed and *active*: ``rot_z(a)`` turns a point by ``+a`` about ``+z``
(counter-clockwise seen from ``+z``), i.e. ``rot_z(a) @ [1, 0, 0, 1] = [cos a, sin a, 0, 1]``.

The derivative helpers ``d_rot_*`` return ``d^k M / d angle^k`` (k = 1, 2), used by the
generation engine for relative velocities (Litvin & Fuentes, *Gear Geometry and Applied Theory*,
2nd ed., 2004, ch. 1–2: coordinate transformation and relative velocity by matrices).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "rot_x",
    "rot_y",
    "rot_z",
    "rot_axis",
    "translation",
    "compose",
    "inverse",
    "apply_points",
    "apply_vectors",
    "d_rot_x",
    "d_rot_y",
    "d_rot_z",
]

_AXES = {"x": 0, "y": 1, "z": 2}


def _rot(angle: ArrayLike, axis: int, order: int = 0) -> NDArray[np.float64]:
    """Rotation about a coordinate axis, or its ``order``-th derivative w.r.t. the angle."""
    a = np.asarray(angle, dtype=float)
    # d^k/da^k of (cos a, sin a) is (cos(a + k pi/2), sin(a + k pi/2))
    c = np.cos(a + order * np.pi / 2)
    s = np.sin(a + order * np.pi / 2)
    M = np.zeros(a.shape + (4, 4))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    M[..., i, i] = c
    M[..., j, j] = c
    M[..., i, j] = -s
    M[..., j, i] = s
    if order == 0:
        M[..., axis, axis] = 1.0
        M[..., 3, 3] = 1.0
    return M


def rot_x(angle: ArrayLike) -> NDArray[np.float64]:
    """Active right-handed rotation about x by ``angle`` (rad); shape ``(..., 4, 4)``."""
    return _rot(angle, 0)


def rot_y(angle: ArrayLike) -> NDArray[np.float64]:
    """Active right-handed rotation about y by ``angle`` (rad); shape ``(..., 4, 4)``."""
    return _rot(angle, 1)


def rot_z(angle: ArrayLike) -> NDArray[np.float64]:
    """Active right-handed rotation about z by ``angle`` (rad); shape ``(..., 4, 4)``."""
    return _rot(angle, 2)


def d_rot_x(angle: ArrayLike, order: int = 1) -> NDArray[np.float64]:
    """``d^order rot_x / d angle^order`` (bottom-right entry 0 for order ≥ 1)."""
    return _rot(angle, 0, order)


def d_rot_y(angle: ArrayLike, order: int = 1) -> NDArray[np.float64]:
    """``d^order rot_y / d angle^order``."""
    return _rot(angle, 1, order)


def d_rot_z(angle: ArrayLike, order: int = 1) -> NDArray[np.float64]:
    """``d^order rot_z / d angle^order``."""
    return _rot(angle, 2, order)


def rot_axis(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    """Active rotation by ``angle`` about the unit vector ``axis`` (Rodrigues' formula).

    ``axis`` has shape ``(..., 3)`` (normalised here), ``angle`` broadcasts against ``(...)``.
    """
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k, axis=-1, keepdims=True)
    a = np.asarray(angle, dtype=float)
    shape = np.broadcast_shapes(k.shape[:-1], a.shape)
    k = np.broadcast_to(k, shape + (3,))
    a = np.broadcast_to(a, shape)
    K = np.zeros(shape + (3, 3))
    K[..., 0, 1], K[..., 0, 2] = -k[..., 2], k[..., 1]
    K[..., 1, 0], K[..., 1, 2] = k[..., 2], -k[..., 0]
    K[..., 2, 0], K[..., 2, 1] = -k[..., 1], k[..., 0]
    s = np.sin(a)[..., None, None]
    c = np.cos(a)[..., None, None]
    M = np.zeros(shape + (4, 4))
    M[..., :3, :3] = np.eye(3) + s * K + (1.0 - c) * (K @ K)
    M[..., 3, 3] = 1.0
    return M


def translation(v: ArrayLike) -> NDArray[np.float64]:
    """Translation by ``v`` of shape ``(..., 3)`` (mm); returns ``(..., 4, 4)``."""
    v = np.asarray(v, dtype=float)
    M = np.zeros(v.shape[:-1] + (4, 4))
    M[..., [0, 1, 2, 3], [0, 1, 2, 3]] = 1.0
    M[..., :3, 3] = v
    return M


def compose(*Ms: ArrayLike) -> NDArray[np.float64]:
    """Product ``Ms[0] @ Ms[1] @ ...`` (left to right), broadcasting leading axes.

    With column vectors the right-most matrix acts first: ``compose(A, B)`` maps a point by ``B``
    then by ``A``.
    """
    if not Ms:
        return np.eye(4)
    out = np.asarray(Ms[0], dtype=float)
    for M in Ms[1:]:
        out = out @ np.asarray(M, dtype=float)
    return out


def inverse(M: ArrayLike) -> NDArray[np.float64]:
    """Inverse of rigid transforms ``(..., 4, 4)`` (rotation transposed, translation mapped)."""
    M = np.asarray(M, dtype=float)
    R = M[..., :3, :3]
    t = M[..., :3, 3]
    out = np.zeros(M.shape)
    Rt = np.swapaxes(R, -1, -2)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, t)
    out[..., 3, 3] = 1.0
    return out


def apply_points(M: ArrayLike, p: ArrayLike) -> NDArray[np.float64]:
    """Map points ``p (..., 3)`` by ``M (..., 4, 4)``: ``R p + t`` (broadcast)."""
    M = np.asarray(M, dtype=float)
    p = np.asarray(p, dtype=float)
    return np.einsum("...ij,...j->...i", M[..., :3, :3], p) + M[..., :3, 3]


def apply_vectors(M: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
    """Map free vectors ``v (..., 3)`` by the linear part of ``M`` only: ``R v``."""
    M = np.asarray(M, dtype=float)
    v = np.asarray(v, dtype=float)
    return np.einsum("...ij,...j->...i", M[..., :3, :3], v)
