"""Loaded cycle of the seed face gear: mesh convergence of the `fe` fidelity, and its cost.

For each sector-mesh level: the 25-position loaded cycle at the moderate seed load (3e6 N·mm on
the face gear), cold (empty cache: sector meshes and compliance operators built), then a run at
another torque, 6e6 N·mm, on the same cache (it rebuilds the sectors, and says how long that took
and on which zone gap, when its lag closes a pair outside the 3e6 contact zone), with
loaded TE peak-to-peak, loaded contact ratio, cycle p_max, the load share of the pair (0, 0) at
the position of the largest double contact, and DOFs.

Usage::

    python benchmarks/bench_ltca.py [FIDELITY:LEVEL ...]   # default: fe:0 fe:1 fe:2 hertz:0 hertz:2

Writes benchmarks/results/ltca_face_gear.md (table) and docs/ltca/face_gear_convergence.png.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).parent
CHILD = r"""
import json, resource, sys, time
import numpy as np
from fegear.geometry.pair_placement import InstallationErrors, face_gear_assembly
from fegear.geometry.face_gear import FaceGearDesign, FaceGearMember
from fegear.ltca import LTCAOptions, build_models, run_ltca
fid, lv = sys.argv[1], int(sys.argv[2])
fg = FaceGearMember(FaceGearDesign()); pin = fg.pinion()
asm = face_gear_assembly(fg, InstallationErrors(), pin)
opt = LTCAOptions(n_positions=25, level=lv, fidelity=fid)
out = {"level": lv, "fidelity": fid}
t0 = time.perf_counter()
c = run_ltca(pin, fg, asm, 3e6, opt)
out["t_cold"] = time.perf_counter() - t0
out["t_models"] = c.seconds["models"]
t0 = time.perf_counter()
c2 = run_ltca(pin, fg, asm, 6e6, opt)
out["t_warm_other_torque"] = time.perf_counter() - t0
out["rss_MB"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
# the 6e6 run rebuilds the sectors when its lag closes a pair outside the 3e6 zone
out["zone_gap_mm"] = [c.zone_gap_mm, c2.zone_gap_mm]
out["models_s_6e6"] = c2.seconds["models"]  # loading the cached 3e6 sectors + any rebuild
for key, cyc in (("3e6", c), ("6e6", c2)):
    shares = [[q.load_share for q in p.pairs if q.k == 0 and q.j == 0] for p in cyc.positions]
    out[key] = {
        "te_pp_loaded": cyc.te_pp_loaded_arcsec, "te_pp_unloaded": cyc.te_pp_unloaded_arcsec,
        "te_mean_loaded": float(np.mean(cyc.te_loaded_arcsec)),
        "contact_ratio": cyc.contact_ratio_loaded, "p_max": cyc.p_max_MPa,
        "share00": [s[0] if s else 0.0 for s in shares],
        "te_loaded": cyc.te_loaded_arcsec.tolist(), "phi1_deg": np.degrees(cyc.phi1).tolist(),
        "n_in_contact": cyc.n_in_contact.tolist(),
    }
models = build_models(pin, fg, asm, opt)  # the sectors the cycle used (cached)
out["dofs"] = [3 * m.sector.points.shape[0] for m in (models.pinion, models.gear)]
print(json.dumps(out))
"""


def run(fid: str, level: int, cache: str) -> dict:
    env = dict(os.environ, FEGEAR_CACHE=cache)
    res = subprocess.run(
        [sys.executable, "-c", CHILD, fid, str(level)], env=env, capture_output=True, text=True
    )
    if res.returncode != 0:
        tail = res.stderr.strip().splitlines()[-1] if res.stderr.strip() else "?"
        print(f"{fid} level {level} failed: {tail}", file=sys.stderr)
        return {}
    return json.loads(res.stdout.strip().splitlines()[-1])


def main() -> None:
    specs = [(a.split(":")[0], int(a.split(":")[1])) for a in sys.argv[1:]] or [
        ("fe", 0),
        ("fe", 1),
        ("fe", 2),
        ("hertz", 0),
        ("hertz", 2),
    ]
    rows = []
    for fid, lv in specs:
        with tempfile.TemporaryDirectory() as cache:
            r = run(fid, lv, cache)
        if not r:
            continue
        rows.append(r)
        print(
            f"level {lv}: cold {r['t_cold']:.1f} s (models {r['t_models']:.1f} s), "
            f"warm at another torque {r['t_warm_other_torque']:.1f} s",
            file=sys.stderr,
        )
    lines = [
        "| fidelity | level | vertex DOFs (pinion, face gear) | "
        "cold s (of which meshes + operators) | "
        "6e6 run s (of which rebuilt sectors) | zone gap mm (3e6, 6e6) | peak RSS MB | "
        "TE p-p loaded (arcsec) | mean loaded TE | "
        "contact ratio | p_max MPa | TE p-p at 6e6 | contact ratio at 6e6 |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        a, b = r["3e6"], r["6e6"]
        lines.append(
            f"| {r['fidelity']} | {r['level']} | {r['dofs'][0]}, {r['dofs'][1]} | "
            f"{r['t_cold']:.1f} "
            f"({r['t_models']:.1f}) | {r['t_warm_other_torque']:.1f} "
            f"({r['models_s_6e6']:.1f}) | "
            f"{', '.join(f'{g:.4f}' for g in r['zone_gap_mm'])} | {r['rss_MB']:.0f} | "
            f"{a['te_pp_loaded']:.3f} | {a['te_mean_loaded']:.3f} | {a['contact_ratio']:.2f} | "
            f"{a['p_max']:.0f} | {b['te_pp_loaded']:.3f} | {b['contact_ratio']:.2f} |"
        )
    text = "\n".join(lines)
    print(text)
    res = HERE / "results"
    res.mkdir(exist_ok=True)
    (res / "ltca_face_gear.md").write_text(
        "# Face gear loaded cycle (fe fidelity), 3e6 N·mm\n\n`python benchmarks/bench_ltca.py`\n\n"
        + text
        + "\n\n```json\n"
        + json.dumps(rows)
        + "\n```\n",
        encoding="utf-8",
    )
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8), dpi=100)
    for r in rows:
        a = r["3e6"]
        lab = f"{r['fidelity']} level {r['level']}"
        ax[0].plot(a["phi1_deg"], a["te_loaded"], "o-", ms=3, label=lab)
        ax[1].plot(a["phi1_deg"], a["share00"], "o-", ms=3, label=lab)
    ax[0].set_xlabel("pinion angle (deg)")
    ax[0].set_ylabel("loaded TE (arcsec)")
    ax[1].set_xlabel("pinion angle (deg)")
    ax[1].set_ylabel("load share of pair (0, 0)")
    for a_ in ax:
        a_.grid(alpha=0.3)
        a_.legend(fontsize=8)
    fig.suptitle("Seed face gear, 3e6 N·mm on the face gear: fe levels and hertz")
    fig.tight_layout()
    out = HERE.parent / "docs" / "ltca"
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "face_gear_convergence.png")


if __name__ == "__main__":
    main()
