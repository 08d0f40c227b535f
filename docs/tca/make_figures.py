"""Figures and tables of docs/tca/README.md. Run: ``python docs/tca/make_figures.py [PART ...]``
(parts: conventions, spur, face_gear, spiral_bevel; all by default)."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from fegear.geometry import FaceGearDesign, FaceGearMember, InvoluteDesign, InvoluteMember
from fegear.geometry.pair_placement import InstallationErrors, face_gear_assembly, involute_assembly
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
    from fegear.tca import TCA, reference_phase
    from fegear.tca.path import contact_path

    paths = {}
    for (lab, rr), dg in zip(res.items(), (-0.02, 0.0, 0.02), strict=True):
        opt = TCAOptions(separation_grid=None)
        asm = face_gear_assembly(fg, InstallationErrors(dgamma_deg=dg), pin)
        asm = asm.with_phase2(reference_phase(pin, fg, asm, opt))
        tca = TCA(pin, fg, asm, opt)
        paths[lab] = contact_path(tca, tca.positions(rr.phi1, with_grids=False))
    bd = fg.boundaries()
    plot_paths(res, HERE / "face_gear_paths.png", "gear", bd, ("inner end", "outer end"),
               title="seed face gear: contact paths on the face-gear flank (dashed: one pair)",
               pair_paths={k: cp.gear_uv for k, cp in paths.items()})  # fmt: skip
    plot_te(res, HERE / "face_gear_te.png", "seed face gear: unloaded TE")
    plot_pattern(res["Δγ = +0.00°"], HERE / "face_gear_pattern.png", PINION_BD(pin))
    r = res["Δγ = +0.00°"]
    print(
        "| φ1 (deg) | face-gear height z (mm) | radius L (mm) | F (N) | a (mm) | b (mm) | p0 (MPa) |"  # noqa: E501
    )
    print("|---|---|---|---|---|---|---|")
    for k, p in enumerate(r.positions):
        e = p.ellipse
        if e is None or e.hertz is None:
            print(f"| {np.degrees(p.phi1):.2f} | — | — | — | line/no contact | | |")
            continue
        z = float(fg.height(r.gear_uv[k, 0], r.gear_uv[k, 1]))
        print(
            f"| {np.degrees(p.phi1):.2f} | {z:.3f} | {r.gear_uv[k, 1]:.2f} | "
            f"{e.force_N:.0f} | {e.hertz.a_mm:.3f} | {e.hertz.b_mm:.4f} | {e.hertz.p0_MPa:.0f} |"
        )
    for lab, rr in res.items():
        cp = paths[lab]
        print(lab, "TE median %.4f p-p %.4f arcsec, median L %.2f mm, edge positions %d" % (  # noqa: UP031
            np.median(rr.te_arcsec), rr.te_peak_to_peak_arcsec, np.median(rr.gear_uv[:, 1]),
            rr.edge.sum()))  # fmt: skip
        space = np.linalg.norm(np.diff(cp.fixed_points, axis=0), axis=1).sum()
        print(f"  contact ratio {cp.contact_ratio:.3f}, path {cp.length_mm:.2f} mm on the "
              f"face-gear flank, {space:.2f} mm in space, from {cp.start_limit} to "
              f"{cp.end_limit}")  # fmt: skip


def spiral_bevel() -> None:
    """Reference spiral bevel (12/36): TE of all pairs with the transfer points, contact paths on
    the gear flank (error-free and ±ΔE, ±ΔG), and the error table of README.md."""
    import math

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from fegear.geometry.bevel import SpiralBevelPair
    from fegear.geometry.pair_placement import spiral_bevel_assembly
    from fegear.tca.bevel import cycle_angles, error_effects, path_angle_on_gear, te_parabola

    pair = SpiralBevelPair.design()
    n1 = pair.blank.n1
    phi = cycle_angles(n1, 41, margin=0.25)
    nom = run_tca(pair.pinion, pair.gear, spiral_bevel_assembly(pair, "drive"), TCAOptions(),
                  phi1=phi)  # fmt: skip
    cases = {}
    for sg in (1, -1):
        cases[f"ΔE = {sg * 0.05:+.2f} mm"] = InstallationErrors(dE_mm=sg * 0.05)
        cases[f"ΔP = {sg * 0.05:+.2f} mm"] = InstallationErrors(dA1_mm=sg * 0.05)
        cases[f"ΔG = {sg * 0.05:+.2f} mm"] = InstallationErrors(dA2_mm=sg * 0.05)
        cases[f"Δγ = {sg * 0.02:+.2f}°"] = InstallationErrors(dgamma_deg=sg * 0.02)
    ref, eff, runs = error_effects(pair, cases, "drive", n_positions=25)
    xv, tv, amp, rms = te_parabola(nom, n1)
    eta, eta0 = path_angle_on_gear(pair, "drive")
    print(f"nominal: amplitude {amp:.3f} arcsec (fit rms {rms:.4f}), vertex {math.degrees(xv):.3f}"
          f" deg / {tv:.4f} arcsec, TE p-p {nom.te_peak_to_peak_arcsec:.3f}; transfer points "
          f"{np.degrees(nom.transfer_points[:, 0])} deg at {nom.transfer_points[:, 1]} arcsec; "
          f"path angle {eta:.3f} deg (design {eta0})")  # fmt: skip
    print("| error | pattern ΔL (mm, + heel) | pattern Δh (mm, + top) | TE p-p (arcsec) | "
          "parabola vertex φ* (deg) | TE(φ*) (arcsec) | amplitude (arcsec) | TE(0) TCA / "
          "1st-order theory (arcsec) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    print(f"| none | 0 | 0 | {ref.te_peak_to_peak_arcsec:.2f} | {math.degrees(te_parabola(ref, n1)[0]):+.2f} | "  # noqa: E501
          f"{te_parabola(ref, n1)[1]:+.2f} | {te_parabola(ref, n1)[2]:.2f} | 0 / 0 |")  # fmt: skip
    for lab, e in eff.items():
        print(f"| {lab} | {e.dL_mm:+.3f} | {e.dh_mm:+.3f} | {e.te_pp_arcsec:.2f} | "
              f"{e.vertex_deg:+.2f} | {e.vertex_te_arcsec:+.2f} | {e.amplitude_arcsec:.2f} | "
              f"{e.te0_arcsec:+.2f} / {e.te0_first_order_arcsec:+.2f} |")  # fmt: skip

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 4.6))
    deg = np.degrees(nom.phi1)
    for k in range(nom.pairs.shape[0]):
        m = nom.pair_valid[:, k] & (nom.pair_te_arcsec[:, k] > -30)
        ax1.plot(deg[m], nom.pair_te_arcsec[m, k], ":", lw=1.2, label=f"pair {k - 1:+d}")
    ax1.plot(deg, nom.te_arcsec, "k-", lw=2, label="TE (min over pairs)")
    tp = nom.transfer_points
    ax1.plot(np.degrees(tp[:, 0]), tp[:, 1], "ro", label="transfer points")
    for x, y in tp:
        ax1.annotate(f"{np.degrees(x):+.2f}°", (np.degrees(x), y), textcoords="offset points",
                     xytext=(-20, -14), fontsize=8)  # fmt: skip
    ax1.set_ylim(-14, 1.5)
    ax1.set_xlabel("pinion angle φ1 (deg)")
    ax1.set_ylabel("unloaded TE (arcsec)")
    ax1.set_title(f'spiral bevel 12/36: predesigned parabolic TE ({amp:.2f}" amplitude)')
    ax1.grid(alpha=0.3)
    ax1.legend(fontsize=8, loc="lower center")
    g = pair.gear
    b = g.boundaries()
    L = np.linspace(b.v_start, b.v_end, 50)
    hf, ha = pair.blank.flank_heights(2, L)
    ax2.plot(np.r_[L, L[::-1], L[0]], np.r_[hf, ha[::-1], hf[0]], "k-", lw=1)
    ax2.plot(L, 0 * L, "k--", lw=0.5)
    ax2.annotate("toe", (b.v_start, ha[0]), textcoords="offset points", xytext=(2, 4))
    ax2.annotate("heel", (b.v_end, ha[-1]), textcoords="offset points", xytext=(-26, 4))
    show = {"no error": ref}
    for lab in ("ΔE = +0.05 mm", "ΔE = -0.05 mm", "ΔG = +0.05 mm", "ΔG = -0.05 mm"):
        show[lab] = runs[lab]
    for i, (lab, r) in enumerate(show.items()):
        m = r.has_contact
        u, v = r.gear_uv[m, 0], r.gear_uv[m, 1]
        ax2.plot(v, g.height(u, v), "-o", ms=2.5, color=f"C{i}", lw=2 if i == 0 else 1,
                 label=lab)  # fmt: skip
    ax2.set_xlabel("cone distance L (mm), toe → heel")
    ax2.set_ylabel("height above the pitch cone h (mm), root → top")
    ax2.set_title(f"contact path on the gear (drive) flank; path angle {eta:.2f}° "
                  f"(design {eta0:.0f}°)")  # fmt: skip
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "spiral_bevel_tca.png", dpi=120)
    plt.close(fig)


def PINION_BD(pin):  # noqa: N802
    return pin.boundaries("drive")


if __name__ == "__main__":
    import sys

    logging.basicConfig(level=logging.INFO)
    which = sys.argv[1:] or ["conventions", "spur", "face_gear", "spiral_bevel"]
    if "conventions" in which:
        plot_assembly_conventions(HERE / "assembly_conventions.png")
    for name in ("spur", "face_gear", "spiral_bevel"):
        if name in which:
            globals()[name]()
