"""The text and figures of ``spiral_bevel_multipair.md``, from ``spiral_bevel_multipair.json``.

:func:`render` is pure (the page's text from the JSON: ``tests/test_papers.py`` compares it with
the page); :func:`figures` draws the PNGs into ``docs/papers/spiral_bevel_multipair/``.
"""

from __future__ import annotations

import numpy as np
from _parts import HERE, num, plt, reflow, save, seconds_text, table
from spiral_bevel_multipair_runs import TORQUES

ORDER = ("tca", "loads")
FIG = HERE / "spiral_bevel_multipair"
CMD = "python docs/papers/make_spiral_bevel_multipair.py"


def _cmd(part: str) -> str:
    return f"`{CMD} {part}`"


# --------------------------------------------------------------------------------------------
# derived numbers
# --------------------------------------------------------------------------------------------


def per_load(run: dict) -> dict:
    """The quantities the paper says grow with the load, from one loaded run."""
    pos = run["positions"]
    n = [p["n_pairs"] for p in pos]
    loaded = [q for p in pos for q in p["pairs"] if q["semi_major_mm"] is not None]
    main = [max(p["pairs"], key=lambda q: q["force_N"]) for p in pos if p["pairs"]]
    pat = run["pattern"]["pinion"]
    return {
        "n_pairs": n,
        "positions_with": {k: sum(1 for x in n if x == k) for k in range(1, max(n) + 1)},
        "contact_ratio": run["contact_ratio_loaded"],
        "patch_a_max": max(q["semi_major_mm"] for q in loaded),
        "patch_b_max": max(q["semi_minor_mm"] for q in loaded),
        "patch_a_mean": float(np.mean([q["semi_major_mm"] for q in main])),
        "patch_b_mean": float(np.mean([q["semi_minor_mm"] for q in main])),
        "pattern_face": pat["face_range_mm"][1] - pat["face_range_mm"][0],
        "pattern_profile": pat["profile_range_mm"][1] - pat["profile_range_mm"][0],
        "te_pp": run["te_pp_loaded_arcsec"],
        "lag_mean": float(np.mean([p["lag"] for p in pos])),
        "p_max": run["p_max_MPa"],
        "max_share": max(q["load_share"] for p in pos for q in p["pairs"]),
    }


def _trend(values: list[float], tol: float = 0.0, loads: list[float] | None = None) -> str:
    """How a quantity moves with the load; steps within ``tol`` count as level (a bearing that
    has reached both face ends stays there up to the cells' round-off)."""
    d = np.diff(values)
    if np.all(d > tol):
        return "grows"
    if np.all(d > -tol) and np.any(d > tol):
        k = int(np.flatnonzero(d > tol)[-1]) + 1
        at = f"{loads[k]:g} N·m" if loads is not None else f"load {k + 1}"
        return f"grows, then stays level from {at} on" if k < len(d) else "grows"
    if np.all(d < -tol):
        return "FALLS"
    return "NOT monotone"


# --------------------------------------------------------------------------------------------
# page
# --------------------------------------------------------------------------------------------


def render(doc: dict) -> str:
    t = doc["parts"]["tca"]["data"]
    runs = doc["parts"]["loads"]["data"]["runs"]
    q = [per_load(r) for r in runs]
    loads = [r["pinion_torque_Nm"] for r in runs]
    head = f"""# The multi-pair paper on fegear's spiral bevel

The paper (*Mathematical model and algorithm for contact stress analysis of gears with
multi-pair contact*) analyses gears with localized contact and a predesigned parabolic
transmission error (TE) under load, several tooth pairs in contact at once. Its claims:

1. "Number of pairs in simultaneous contact depends on applied load and phase of meshing. This
   number is not known in advance" and is detected automatically;
2. the algorithm gives the force and torque each pair transmits, the contact pressure and the
   TE;
3. for a spiral bevel gear, "tooth overlap factor [contact ratio], dimensions of instant contact
   patch, tooth bearing contact and tooth-to-tooth accuracy of gears increase with growth of
   load".

This page checks them on fegear's reference spiral bevel `cases/spiral_bevel_nominal.toml`
(12/36, module 4.94 mm, 35° spiral, 22.5° pressure angle, predesigned parabolic TE of 8″, the
machine settings synthesized by fegear) over pinion torques of
{", ".join(f"{x:g}" for x in loads)} N·m (the case's own: 100 N·m) at fidelity `hybrid` level 0.
fegear solves every candidate pair's contact cells together under the torque balance
(`fegear.mechanics.contact`): a pair carries load where the elastic approach closes its unloaded
separation, so the number of pairs comes out of the active set, as in the paper.

The page is generated: `{CMD}` runs both parts and rewrites it ({seconds_text(doc, ORDER)} of
wall time on 2 shared cores, as last run, with the artefact cache as it found it); `{CMD} PART`
reruns one, `{CMD} render` rewrites the text from `docs/papers/spiral_bevel_multipair.json`.
The measurements are in `docs/papers/spiral_bevel_multipair_runs.py`."""

    n_cand = len(t["pairs"])
    bl = np.asarray(t["backlash_um"])
    valid = np.asarray(t["pair_valid"])
    cp = np.asarray(t["contact_pair"])
    others = [bl[i][valid[i] & (np.arange(n_cand) != cp[i])] for i in range(len(cp))]
    bmin = [float(o.min()) if o.size else float("nan") for o in others]
    te = np.asarray(t["te_arcsec"])
    unl = f"""## 1. The unloaded pair (part `tca`: {_cmd("tca")})

The rigid TCA over the case's {len(te)} positions: the unloaded TE is the predesigned parabola,
{num(float(np.ptp(te)), 3)}″ peak to peak over the cycle (design 8″ at the transfer points, see
`docs/validation.md`); the contact ratio of one pair's unloaded contact interval is
{num(t["contact_ratio_unloaded"], 4)}: unloaded, one pair at a time, the pairs trading at the
transfer points where their TE parabolas cross. The paper's
"backlashes" δ_i are the separations of the other candidate pairs at their closest points while
one pair touches: the smallest of them over the cycle runs {num(min(bmin), 3)} …
{num(max(bmin), 3)} µm (`spiral_bevel_multipair/backlash.png`): a pair enters contact once the
elastic approach under load exceeds its separation. The contact ellipse of the pair in contact
(`fegear/tca/ellipse.py`): Litvin's for 6.32 µm a = {num(min(t["paint_a"]), 3)} …
{num(max(t["paint_a"]), 3)} mm, b = {num(min(t["paint_b"]), 3)} … {num(max(t["paint_b"]), 3)} mm;
Hertz of one pair carrying {num(t["pinion_torque_Nm"])} N·m a = {num(min(t["hertz_a"]), 3)} …
{num(max(t["hertz_a"]), 3)} mm, b = {num(min(t["hertz_b"]), 3)} … {num(max(t["hertz_b"]), 3)} mm,
p0 = {num(min(t["hertz_p0"]))} … {num(max(t["hertz_p0"]))} MPa.

![backlashes](spiral_bevel_multipair/backlash.png)"""

    rows = []
    for T, r, x in zip(loads, runs, q, strict=True):
        dist = ", ".join(f"{k}: {v}" for k, v in x["positions_with"].items())
        rows.append((f"{T:g}", dist, r["max_pairs_in_contact"], x["max_share"]))
    sec2 = f"""## 2. Pairs in contact, found automatically (claim 1; part `loads`: {_cmd("loads")})

Per load: how many of the {len(runs[0]["positions"])} positions have 1, 2, 3 … pairs carrying
load, the most at any position, and the largest share of the torque one pair carries:

{
        table(
            (
                "pinion torque (N·m)",
                "positions with n pairs (n: count)",
                "max pairs",
                "largest load share",
            ),
            rows,
        )
    }

The number of pairs depends on the phase (`spiral_bevel_multipair/pairs.png`: the pairs in
contact against the pinion angle at each load) and on the load: nobody told the solver how many
pairs to use — {n_cand} candidate pairs are modelled and the torque balance decides.

![pairs in contact](spiral_bevel_multipair/pairs.png)"""

    keys = (("contact_ratio", "contact ratio (mean loaded pairs)"),
            ("patch_a_mean", "instant patch a of the most loaded pair, mean (mm)"),
            ("patch_b_mean", "instant patch b of the most loaded pair, mean (mm)"),
            ("patch_a_max", "largest patch a (mm)"),
            ("pattern_face", "bearing contact on the pinion: length along the face (mm)"),
            ("pattern_profile", "bearing contact on the pinion: height (mm)"),
            ("te_pp", "loaded TE peak-to-peak (″)"),
            ("lag_mean", "mean elastic lag of the gear (″)"),
            ("p_max", "p_max away from the edges (MPa)"))  # fmt: skip
    #: the bearing's length saturates at the face width: 0.05 mm is the cells' scatter there
    tol = {"pattern_face": 0.05}
    trows = [
        (label, *(x[k] for x in q), _trend([x[k] for x in q], tol.get(k, 0.0), loads))
        for k, label in keys
    ]
    te_grows = _trend([x["te_pp"] for x in q]) == "grows"
    sec3 = f"""## 3. Contact ratio, patch, bearing contact and TE against the load (claim 3)

{table(("quantity", *(f"{T:g} N·m" for T in loads), "with the load"), trows)}

Verdict per claim, in plain words:

- **Contact ratio**: {_trend([x["contact_ratio"] for x in q])} with the load — the elastic
  approach closes the neighbouring pairs' separations earlier and keeps them closed longer.
- **Instant contact patch**: {_trend([x["patch_a_mean"] for x in q])} (length) and
  {_trend([x["patch_b_mean"] for x in q])} (width): a Hertz patch grows as the load to the power
  1/3 until it meets a flank edge; sharing the load with another pair slows that growth.
- **Bearing contact** (the envelope of all patches over the cycle on the pinion flank):
  {_trend([x["pattern_face"] for x in q], 0.05, loads)} along the face (it reaches both ends of the
  25.4 mm face) and {_trend([x["pattern_profile"] for x in q])} up the profile.
- **TE** ("tooth-to-tooth accuracy", read as the TE it measures): the mean elastic lag
  {_trend([x["lag_mean"] for x in q])} and the loaded TE peak-to-peak
  {_trend([x["te_pp"] for x in q])} ({num(q[0]["te_pp"], 3)} → {num(q[-1]["te_pp"], 3)}″
  against the unloaded parabola's {num(float(np.ptp(te)), 3)}″: the lightest load already
  flattens the parabola, the deflection filling it where one pair carries the load while two
  share it elsewhere; from there the amplitude grows).
  {
        "The TE grows with the load although a second and third pair share it: the deflection of"
        " the pair carrying most of the load grows faster than the sharing flattens the curve."
        if te_grows
        else "With a predesigned parabolic TE the loaded curve is the parabola filled by the"
        " deflection where one pair carries the load and flattened where two share it, so its"
        " peak-to-peak need not grow with the load while the lag does."
    }

`spiral_bevel_multipair/te.png`: the loaded TE curves; `spiral_bevel_multipair/growth.png`: the
quantities above against the load.

![TE](spiral_bevel_multipair/te.png)

![growth](spiral_bevel_multipair/growth.png)"""
    return reflow("\n\n".join((head, unl, sec2, sec3))) + "\n"


# --------------------------------------------------------------------------------------------
# figures
# --------------------------------------------------------------------------------------------


def figures(doc: dict) -> None:
    P = doc["parts"]
    if "tca" in P:
        _fig_backlash(P["tca"]["data"])
    if "loads" in P:
        runs = P["loads"]["data"]["runs"]
        _fig_pairs(runs)
        _fig_te(runs)
        _fig_growth(runs)


def _fig_backlash(t: dict) -> None:
    pyplot = plt()
    fig, ax = pyplot.subplots(figsize=(7, 4))
    bl = np.asarray(t["backlash_um"])
    valid = np.asarray(t["pair_valid"])
    for j, (k, g) in enumerate(t["pairs"]):
        m = valid[:, j]
        ax.plot(np.asarray(t["phi_deg"])[m], bl[m, j], "o-", ms=3,
                label=f"pair pinion {k:+d} / gear {g:+d}")  # fmt: skip
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("unloaded separation at the closest point (µm)")
    ax.set_yscale("symlog", linthresh=1.0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("spiral bevel 12/36: the pairs' unloaded separations (0: the pair in contact)",
                 fontsize=9)  # fmt: skip
    save(fig, FIG / "backlash.png")


def _fig_pairs(runs: list[dict]) -> None:
    pyplot = plt()
    fig, ax = pyplot.subplots(figsize=(7, 4))
    for i, r in enumerate(runs):
        phi = [p["phi_deg"] for p in r["positions"]]
        n = [p["n_pairs"] + 0.04 * (i - len(runs) / 2) for p in r["positions"]]
        ax.step(phi, n, where="mid", label=f"{num(r['pinion_torque_Nm'])} N·m")
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("pairs in contact (offset slightly per load)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("pairs carrying load, found by the contact solver", fontsize=9)
    save(fig, FIG / "pairs.png")


def _fig_te(runs: list[dict]) -> None:
    pyplot = plt()
    fig, ax = pyplot.subplots(figsize=(7, 4))
    phi = [p["phi_deg"] for p in runs[0]["positions"]]
    ax.plot(phi, [p["te_unloaded"] for p in runs[0]["positions"]], "k--", label="unloaded")
    for r in runs:
        ax.plot([p["phi_deg"] for p in r["positions"]], [p["te_loaded"] for p in r["positions"]],
                "o-", ms=3, label=f"{num(r['pinion_torque_Nm'])} N·m")  # fmt: skip
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("TE (arcsec)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("spiral bevel 12/36: loaded TE over one mesh cycle", fontsize=9)
    save(fig, FIG / "te.png")


def _fig_growth(runs: list[dict]) -> None:
    pyplot = plt()
    q = [per_load(r) for r in runs]
    T = [r["pinion_torque_Nm"] for r in runs]
    fig, axes = pyplot.subplots(1, 4, figsize=(13, 3.4))
    axes[0].plot(T, [x["contact_ratio"] for x in q], "o-")
    axes[0].set_ylabel("loaded contact ratio")
    axes[1].plot(T, [x["patch_a_mean"] for x in q], "o-", label="a")
    axes[1].plot(T, [x["patch_b_mean"] for x in q], "s-", label="b")
    axes[1].set_ylabel("patch semi-axes, most loaded pair (mm)")
    axes[1].legend(fontsize=7)
    axes[2].plot(T, [x["pattern_face"] for x in q], "o-", label="along the face")
    axes[2].plot(T, [x["pattern_profile"] for x in q], "s-", label="up the profile")
    axes[2].set_ylabel("bearing contact extent (mm)")
    axes[2].legend(fontsize=7)
    axes[3].plot(T, [x["te_pp"] for x in q], "o-", label="TE p-p")
    axes[3].plot(T, [x["lag_mean"] for x in q], "s-", label="mean lag")
    axes[3].set_ylabel("arcsec")
    axes[3].legend(fontsize=7)
    for ax in axes:
        ax.set_xscale("log")
        ax.set_xlabel("pinion torque (N·m)")
        ax.grid(alpha=0.3)
    save(fig, FIG / "growth.png")


__all__ = ["render", "figures", "per_load", "TORQUES"]
