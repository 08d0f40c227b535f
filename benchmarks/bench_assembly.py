"""Time the stock scikit-fem P2 elasticity assembly against fegear.fem.assembly (not a test).

A unit cube ``MeshTet.init_tensor`` with ``n`` points per axis (6 (n-1)^3 tetrahedra), steel
(E = 206000 MPa, nu = 0.3), quadratic vector elements. For each size this prints one row: P2 DOFs,
elements, seconds for the stock assembly (``Basis(mesh, ElementVector(ElementTetP2()))`` and
``asm(linear_elasticity)``, basis construction included), seconds for
:func:`fegear.fem.assembly.elasticity_stiffness` (its own 4-point basis included; best of
``--repeat``), the speed-up, and ``max |K_fast - K_stock| / max |K_stock|``. Wall-clock and CPU
(process) seconds are both shown, since the machine may be shared.

Usage::

    python benchmarks/bench_assembly.py              # ~50k and ~200k DOFs
    python benchmarks/bench_assembly.py --n 14 21 25
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import skfem
from skfem.models.elasticity import lame_parameters, linear_elasticity

from fegear.fem.assembly import elasticity_stiffness

E, NU = 206000.0, 0.3


def _timed(fn):
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - w0, time.process_time() - c0


def stock(mesh: skfem.MeshTet):
    basis = skfem.Basis(mesh, skfem.ElementVector(skfem.ElementTetP2()))
    return skfem.asm(linear_elasticity(*lame_parameters(E, NU)), basis).tocsr()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[14, 21], help="points per axis")
    ap.add_argument("--repeat", type=int, default=3, help="runs of the fast assembly (best)")
    args = ap.parse_args()
    print(
        f"{'DOFs':>8} {'elements':>9} {'stock s':>8} {'(cpu)':>7} {'fast s':>7} {'(cpu)':>6} "
        f"{'speed-up':>8} {'max rel diff':>12}"
    )
    for n in args.n:
        mesh = skfem.MeshTet.init_tensor(*[np.linspace(0.0, 1.0, n)] * 3)
        K0, ws, cs = _timed(lambda m=mesh: stock(m))
        runs = [_timed(lambda m=mesh: elasticity_stiffness(m, E, NU)) for _ in range(args.repeat)]
        K, wf, cf = min(runs, key=lambda r: r[1])
        rel = abs(K - K0).max() / abs(K0).max()
        print(
            f"{K0.shape[0]:>8} {mesh.nelements:>9} {ws:>8.2f} {cs:>7.2f} {wf:>7.2f} {cf:>6.2f} "
            f"{ws / wf:>7.1f}x {rel:>12.1e}",
            flush=True,
        )


if __name__ == "__main__":
    main()
