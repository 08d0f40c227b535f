"""Time the Schur complement backends on scikit-fem P2 elasticity boxes (not a test).

A box of ``nx × ny × nz`` hexahedral cells, each split into tetrahedra, with quadratic vector
elements (``ElementVector(ElementTetP2())``), steel (E = 206000 MPa, ν = 0.3), clamped on z = 0. The
candidate DOFs are the ``m // 3`` nodes of the top face (z = Lz) nearest its centre, all three
components each: a compact patch, like a potential-contact region.

For each size and ``m`` this prints one row per backend: DOFs, m, backend, seconds for
:func:`fegear.linalg.schur_complement`, and the relative Frobenius difference to PARDISO. SuperLU is
skipped above ``--superlu-max-dofs`` or ``--superlu-max-m`` (its ``m`` dense solves get too slow:
~330 s already at 52k DOFs and m = 999 on 2 cores).

Usage::

    python benchmarks/bench_schur.py                 # ~50k and ~200k DOFs, m = 999 and 3000
    python benchmarks/bench_schur.py --sizes 50k     # the small box only
"""

from __future__ import annotations

import argparse
import logging
import time

import numpy as np
import scipy.sparse as sp
import skfem
from skfem.models.elasticity import lame_parameters, linear_elasticity

from fegear.linalg import available_backends, schur_complement

#: Boxes in cells (nx, ny, nz); with P2 tets the node count is (2nx+1)(2ny+1)(2nz+1).
SIZES = {"50k": (16, 16, 8), "200k": (20, 20, 20)}


def box_problem(nx: int, ny: int, nz: int) -> tuple[sp.csr_matrix, np.ndarray, np.ndarray, float]:
    """Stiffness of the clamped box and its top-face DOFs ordered by distance to the face centre.

    Returns
    -------
    K : (n, n) CSR, the free-DOF stiffness; top : (3 k,) free-DOF indices of the top-face nodes,
    node by node (x, y, z components together), nearest the face centre first; dist : (k,) their
    distances; t_assembly : seconds spent assembling.
    """
    lx, ly, lz = 1.0, 1.0, 1.0
    mesh = skfem.MeshTet.init_tensor(
        np.linspace(0, lx, nx + 1), np.linspace(0, ly, ny + 1), np.linspace(0, lz, nz + 1)
    )
    basis = skfem.Basis(mesh, skfem.ElementVector(skfem.ElementTetP2()))
    t0 = time.perf_counter()
    K = linear_elasticity(*lame_parameters(206000.0, 0.3)).assemble(basis)
    t_assembly = time.perf_counter() - t0
    clamped = basis.get_dofs(lambda x: np.isclose(x[2], 0.0)).all()
    # P2 nodes (vertices and edge midpoints) as DOF triplets (x, y, z components), shape (3, k).
    triplets = np.hstack([basis.nodal_dofs, basis.edge_dofs])
    xyz = basis.doflocs[:, triplets[0]]
    on_top = np.isclose(xyz[2], lz)
    dist = np.hypot(xyz[0, on_top] - lx / 2, xyz[1, on_top] - ly / 2)
    order = np.argsort(dist, kind="stable")
    top_dofs = triplets[:, on_top][:, order].T.ravel()
    free = np.setdiff1d(np.arange(basis.N), clamped)
    Kf = K[free][:, free].tocsr()
    top_free = np.searchsorted(free, top_dofs)
    return Kf, top_free, dist[order], t_assembly


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", nargs="+", default=list(SIZES), choices=list(SIZES))
    parser.add_argument("--m", nargs="+", type=int, default=[999, 3000])
    parser.add_argument("--superlu-max-dofs", type=int, default=100_000)
    parser.add_argument("--superlu-max-m", type=int, default=1000)
    parser.add_argument("--log-level", default="WARNING", help="e.g. INFO or DEBUG for fegear logs")
    args = parser.parse_args()
    logging.basicConfig(format="%(name)s: %(message)s")
    logging.getLogger("fegear").setLevel(args.log_level.upper())

    backends = available_backends()
    rows: list[tuple[int, int, str, str, str]] = []
    for size in args.sizes:
        K, top, _, t_asm = box_problem(*SIZES[size])
        n = K.shape[0]
        print(f"# box {SIZES[size]}: {n} free DOFs, assembly {t_asm:.1f} s", flush=True)
        for m in args.m:
            idx = top[:m]
            ref = None
            for backend in backends:
                if backend == "superlu" and (n > args.superlu_max_dofs or m > args.superlu_max_m):
                    rows.append((n, m, backend, "skipped", ""))
                    continue
                t0 = time.perf_counter()
                S = schur_complement(K, idx, backend)
                dt = time.perf_counter() - t0
                if ref is None:
                    ref, diff = S, ""
                else:
                    diff = f"{np.linalg.norm(S - ref) / np.linalg.norm(ref):.1e}"
                rows.append((n, m, backend, f"{dt:.1f}", diff))
                print(f"#   m={m} {backend}: {dt:.1f} s", flush=True)
    print()
    print(f"| {'DOFs':>7} | {'m':>5} | {'backend':<8} | {'seconds':>8} | {'rel. diff':>9} |")
    print(f"|{'-' * 9}|{'-' * 7}|{'-' * 10}|{'-' * 10}|{'-' * 11}|")
    for n, m, backend, secs, diff in rows:
        print(f"| {n:>7} | {m:>5} | {backend:<8} | {secs:>8} | {diff:>9} |")


if __name__ == "__main__":
    main()
