"""Static check of a sector mesh: compliance of the centre tooth under a unit normal load.

The load is a unit force (1 N) spread over a smooth bump ``w(x) ∝ (1 − r²/a²)²`` (``r`` the
distance to the pitch point, ``a`` the patch radius) on the centre tooth's drive flank, along
``−n`` (into the tooth). A true point load has infinite displacement under it in 3-D
elasticity, so the converging quantity is the work-conjugate deflection
``δ = ∫ w u · (−n) dA / ∫ w dA`` (mm/N), a compliance. P2 tetrahedra on the linear sector mesh
(``ElementVector(ElementTetP2())``), E 206 000 MPa, ν 0.3.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from fegear.linalg.solve import factorize_spd

from .sector import SectorMesh
from .sector_geometry import SectorFrame

__all__ = ["pitch_point", "tooth_compliance"]

Array = NDArray[np.float64]


def pitch_point(frame: SectorFrame, side: str = "drive") -> tuple[Array, Array]:
    """Point and outward normal of member tooth 0 on ``side`` at mid-face and mid working height
    (the pitch point for the involute family: radius = pitch radius)."""
    fr = frame
    v = 0.5 * (fr.L_start + fr.L_end)
    u = np.linspace(fr.u_fillet, fr.u_tip, 201)
    if fr.family == "involute":
        p = fr.member.point_normal(side, u, np.full_like(u, v))[0]
        rho = np.hypot(p[:, 0], p[:, 1])
        uu = float(np.interp(fr.member.r_p, rho, u))
    elif hasattr(fr.member, "mean_parameters"):  # spiral bevel: mean point on the pitch cone
        uu, v = fr.member.mean_parameters(side)
    else:  # face gear: on the pitch plane z = 0 (u is a fraction of the working height)
        uu = float(fr.member.working_u(0.0, v, side))
    p, n = fr.member.point_normal(side, np.array([uu]), np.array([v]))
    return p[0], n[0]


def tooth_compliance(
    mesh: SectorMesh,
    frame: SectorFrame,
    fixed: Sequence[str] = ("bore", "cut_left", "cut_right"),
    radius: float | None = None,
    E: float = 206000.0,
    nu: float = 0.3,
    backend: str = "auto",
) -> float:
    """Deflection (mm) along a unit normal load at the pitch point of the centre tooth.

    ``backend``: the sparse SPD solver (``"auto"``, ``"pardiso"``, ``"superlu"``), see
    :func:`fegear.linalg.solve.factorize_spd`.
    """
    from skfem import (
        Basis,
        ElementTetP2,
        ElementVector,
        FacetBasis,
        Functional,
        LinearForm,
        asm,
        condense,
    )
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    m = mesh.to_skfem()
    p0, n0 = pitch_point(frame)
    a = radius if radius is not None else frame.module
    e = ElementVector(ElementTetP2())
    ib = Basis(m, e)
    K = asm(linear_elasticity(*lame_parameters(E, nu)), ib)
    fb = FacetBasis(m, e, facets=m.boundaries[f"flank_drive_{mesh.centre_tooth}"])

    def bump(x):
        r2 = sum((x[i] - p0[i]) ** 2 for i in range(3))
        return np.where(r2 < a * a, (1 - r2 / a**2) ** 2, 0.0)

    total = Functional(lambda w: bump(w.x)).assemble(fb.with_element(ElementTetP2()))

    @LinearForm
    def load(v, w):
        return -bump(w.x) * sum(n0[i] * v[i] for i in range(3)) / total

    f = asm(load, fb)
    D = np.concatenate([ib.get_dofs(name).all() for name in fixed])
    u = np.zeros(K.shape[0])
    Kc, fc, _, I = condense(K, f, D=D)
    u[I] = factorize_spd(Kc, backend).solve(fc)
    return float(f @ u)
