"""Figures and tables of docs/tca/README.md. Run: ``python docs/tca/make_figures.py``."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from fegear.assembly import InstallationErrors, face_gear_assembly, involute_assembly
from fegear.geometry import FaceGearDesign, FaceGearMember, InvoluteDesign, InvoluteMember
from fegear.tca import TCAOptions, run_tca
from fegear.tca.plots import plot_assembly_conventions, plot_paths, plot_pattern, plot_te

HERE = Path(__file__).parent
log = logging.getLogger("make_figures")


def spur() -> None:
    p = InvoluteMember(
        InvoluteDesign(16, 4.5, 20, profile_shift=0.1817, face_width_mm=14), "pinion"
    )
    g = InvoluteMember(InvoluteDesign(24, 4.5, 20, profile_shift=0.1715, face_width_mm=14), "gear")
    res = {}
    for label, e in (
        ("no error", InstallationErrors()),
        ("f_Σδ = 0.02 mm", InstallationErrors(f_sigma_delta_mm=0.02)),
        ("f_Σβ = 0.02 mm", InstallationErrors(f_sigma_beta_mm=0.02)),
    ):
        res[label] = run_tca(p, g, involute_assembly(p, g, e), TCAOptions(n_positions=25))
    plot_te(res, HERE / "spur_te.png", "FZG C spur pair: unloaded TE")
    plot_paths(res, HERE / "spur_paths.png", "pinion", p.boundaries("drive"), ("-b/2", "+b/2"),
               ellipses=False)  # fmt: skip


def face_gear() -> None:
    fg = FaceGearMember(FaceGearDesign())
    pin = InvoluteMember(
        InvoluteDesign(25, 6.35, 25.0, rack_tip_radius_coeff=0.25, face_width_mm=90.0), "pinion"
    )
    res = {}
    for dg in (-0.02, 0.0, 0.02):
        asm = face_gear_assembly(fg, InstallationErrors(dgamma_deg=dg), pin)
        res[f"Δγ = {dg:+.2f}°"] = run_tca(pin, fg, asm, TCAOptions(pinion_torque_Nm=350.14))
    bd = fg.boundaries()
    plot_paths(res, HERE / "face_gear_paths.png", "gear", bd, ("inner end", "outer end"),
               title="seed face gear: contact paths on the face-gear flank")  # fmt: skip
    plot_te(res, HERE / "face_gear_te.png", "seed face gear: unloaded TE")
    plot_pattern(res["Δγ = +0.00°"], HERE / "face_gear_pattern.png", PINION_BD(pin))
    r = res["Δγ = +0.00°"]
    print(
        "| φ1 (deg) | face-gear height u (mm) | radius L (mm) | F (N) | a (mm) | b (mm) | p0 (MPa) |"  # noqa: E501
    )
    print("|---|---|---|---|---|---|---|")
    for k, p in enumerate(r.positions):
        e = p.ellipse
        if e is None or e.hertz is None:
            print(f"| {np.degrees(p.phi1):.2f} | — | — | — | line/no contact | | |")
            continue
        print(
            f"| {np.degrees(p.phi1):.2f} | {r.gear_uv[k, 0]:.3f} | {r.gear_uv[k, 1]:.2f} | "
            f"{e.force_N:.0f} | {e.hertz.a_mm:.3f} | {e.hertz.b_mm:.4f} | {e.hertz.p0_MPa:.0f} |"
        )
    for lab, rr in res.items():
        print(lab, "TE median %.4f p-p %.4f arcsec, median L %.2f mm, edge positions %d" % (  # noqa: UP031
            np.median(rr.te_arcsec), rr.te_peak_to_peak_arcsec, np.median(rr.gear_uv[:, 1]),
            rr.edge.sum()))  # fmt: skip


def PINION_BD(pin):  # noqa: N802
    return pin.boundaries("drive")


if __name__ == "__main__":
    logging.basicConfig(level=logging.INFO)
    plot_assembly_conventions(HERE / "assembly_conventions.png")
    spur()
    face_gear()
