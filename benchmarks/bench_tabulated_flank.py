"""The tabulated bevel flank against the exact one: error and cost per call.

For the spiral bevel and hypoid pairs of ``cases/spiral_bevel_nominal.toml`` and
``cases/hypoid_nominal.toml``, each member and side: the table's build time and the error it
measured on itself (near the working flank and further out), the largest distance of 4000
random points of the table's box from the exact flank (points, normals, tangents), and the time
of one call of ``evaluate(..., tangents=True)`` of the exact evaluator and of the table for 6,
50 and 2000 points.

Usage::

    python benchmarks/bench_tabulated_flank.py

Writes ``benchmarks/results/tabulated_flank.md``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_error_study import ROOT, _machine  # noqa: E402


def _per_call_ms(f, s, th) -> float:
    t0, k = time.perf_counter(), 0
    while time.perf_counter() - t0 < 0.3:
        f(s, th, True)
        k += 1
    return 1e3 * (time.perf_counter() - t0) / k


def main() -> None:
    from fegear.case_files import load_case
    from fegear.geometry.bevel import tabulated
    from fegear.geometry.bevel.native import NativeFlank
    from fegear.pipeline.pair import build_pair

    rows = []
    for name in ("spiral_bevel_nominal", "hypoid_nominal"):
        pair = build_pair(load_case(ROOT / "cases" / f"{name}.toml")).spiral_bevel
        for m in (pair.pinion, pair.gear):
            for side in ("drive", "coast"):
                nf = m.native_flank(side)
                t0 = time.perf_counter()
                tf = tabulated.tabulate(nf)
                build = time.perf_counter() - t0
                lo, hi = nf.box
                span = hi - lo
                rng = np.random.default_rng(0)
                x = rng.random((4000, 2)) * (1 + 2 * tabulated.MARGIN) - tabulated.MARGIN
                s, th = lo[0] + x[:, 0] * span[0], lo[1] + x[:, 1] * span[1]
                ex = NativeFlank.evaluate(nf, s, th, tangents=True)
                tb = tf.evaluate(s, th, tangents=True)
                d = [
                    float(np.max(np.linalg.norm(a - b, axis=-1)))
                    for a, b in zip(ex, tb, strict=True)
                ]
                c = rng.random((2000, 2)) * 0.8 + 0.1
                cs, ct = lo[0] + c[:, 0] * span[0], lo[1] + c[:, 1] * span[1]
                exact = lambda a, b, t, nf=nf: NativeFlank.evaluate(nf, a, b, t)  # noqa: E731
                times = [
                    (_per_call_ms(exact, cs[:k], ct[:k]), _per_call_ms(tf.evaluate, cs[:k], ct[:k]))
                    for k in (6, 50, 2000)
                ]
                rows.append((name, m.name, side, getattr(tf, "coef", np.zeros((0,))).shape[:1],
                             build, tf.error_mm, tf.far_error_mm, d, times))  # fmt: skip
    lines = [
        "# The tabulated bevel flank against the exact envelope",
        "",
        f"`python benchmarks/bench_tabulated_flank.py` ({_machine()}). Table: quintic splines of "
        "the points and normals over the working box widened by half its span on each side "
        "(`fegear/geometry/bevel/tabulated.py`); its own error is measured at build time at cell "
        "centres, within a quarter span of the box (near) and beyond (far); random: 4000 points "
        "over the whole table against the exact evaluator. Per call: `evaluate(s, θ, "
        "tangents=True)`.",
        "",
        "| pair | member | side | nodes | build s | near mm | far mm | random: points mm | "
        "normals | r_s | r_θ | ms per call exact / table: 6 pts | 50 pts | 2000 pts |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, mem, side, nodes, build, e, ef, d, t in rows:
        tt = " | ".join(f"{a:.3f} / {b:.3f}" for a, b in t)
        lines.append(
            f"| {name} | {mem} | {side} | {nodes[0] if nodes else 'exact'} | {build:.2f} | "
            f"{e:.1e} | {ef:.1e} | " + " | ".join(f"{x:.1e}" for x in d) + f" | {tt} |"
        )
    md = "\n".join(lines) + "\n"
    (HERE / "results" / "tabulated_flank.md").write_text(md)
    print(md)


if __name__ == "__main__":
    main()
