"""The picture of a cylindrical (spur/helical) run beside the common ones: ``line_load.png``
(the records it draws are in the result model: :mod:`fegear.results.cylindrical`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fegear.results.cylindrical import load_distribution
from fegear.store.files import atomic_write

__all__ = ["plot_line_load"]


def plot_line_load(out: Path, run) -> Path:
    """``line_load.png``: the load per unit face width of each position and their mean (KHβ),
    and the mesh stiffness over the cycle."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ld = load_distribution(run)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4))
    qm = ld.face_mm and ld.normal_force_N / ld.face_mm
    for i, pos in enumerate(ld.positions):
        if pos.force_N > 0:
            label = f"position {i}" if i < 8 else None
            a1.step(ld.z_mm, pos.q_N_per_mm / qm, where="mid", lw=0.7, alpha=0.6,
                    ls="-" if pos.usable else ":", label=label)  # fmt: skip
    if ld.k_h_beta is not None:
        a1.step(ld.z_mm, ld.q_mean_N_per_mm / qm, where="mid", lw=2.2, color="k",
                label=f"cycle mean: KHβ = {ld.k_h_beta:.3f}")  # fmt: skip
    a1.axhline(1.0, color="0.5", lw=0.8)
    a1.set_xlabel("axial position z (mm, fixed frame)")
    a1.set_ylabel("load per unit face width / (F_n / b)")
    a1.set_title(f"{run.case.name}: face-width load, {ld.dz_mm:.2f} mm bins", fontsize=9)
    a1.grid(alpha=0.3)
    a1.legend(fontsize=7)
    deg = np.degrees(run.cycle.phi1)
    c = np.array([np.nan if p.mesh_stiffness is None else p.mesh_stiffness for p in ld.positions])
    a2.plot(deg, c, "o-", ms=3)
    if ld.c_gamma is not None:
        a2.axhline(ld.c_gamma, color="k", lw=1.2, label=f"c_γ = {ld.c_gamma:.2f}")
        a2.legend(fontsize=8)
    a2.set_xlabel("pinion angle φ1 (deg)")
    a2.set_ylabel("mesh stiffness c_γ(φ) (N/(mm·µm))")
    a2.set_title("secant mesh stiffness per unit face width", fontsize=9)
    a2.grid(alpha=0.3)
    fig.tight_layout()
    path = atomic_write(out / "line_load.png", lambda q: fig.savefig(q, format="png", dpi=110))
    plt.close(fig)
    return path
