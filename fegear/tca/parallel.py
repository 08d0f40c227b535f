"""TCA positions on every core: a batch of pinion angles split in contiguous chunks, one chunk
per process (:func:`fegear.forked.fork_map`).

:meth:`fegear.tca.TCA.positions` solves a batch of positions together (every Newton solve
vectorised over the batch), and each position's result is independent of the batch it was
solved in: every iteration acts on each position's own points and stops for each on its own
residual (measured: the seed face gear's 25 positions of one cycle solved as one batch, as
12 + 13 and one by one are equal bit for bit, every array of every
:class:`~fegear.tca.results.PositionResult`; ``tests/test_tca_parallel.py``). So the chunks
can be solved in forked processes and concatenated: the result is that of one batch, with any
number of processes.

The TCA is pure Python and NumPy on one core; the batches of a new installation error (the
cycle's positions, the ends of the path of contact, the hand-overs: about 90 positions on the
seed face gear) are the larger part of what a new error costs before the loaded positions.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from fegear.forked import fork_map, process_count
from fegear.tca.results import PositionResult

__all__ = ["MIN_PER_PROCESS", "positions"]

#: Fewest positions worth a process of their own: a fork and the results' way back cost about
#: one position's time (seed face gear: ~60 ms per position without the ellipse).
MIN_PER_PROCESS = 4


def positions(
    tca,
    phi1: ArrayLike,
    with_grids: bool = True,
    ellipses: bool = True,
    workers: int | None = None,
) -> list[PositionResult]:
    """``tca.positions(phi1, with_grids, ellipses)`` (:meth:`fegear.tca.TCA.positions`),
    computed in up to ``workers`` processes (None: ``$FEGEAR_WORKERS``, else one per core;
    :func:`fegear.forked.process_count`), at least :data:`MIN_PER_PROCESS` positions each.

    Parameters
    ----------
    tca
        The :class:`~fegear.tca.TCA` of the phased assembly.
    phi1
        ``(n,)`` pinion angles (rad).
    with_grids, ellipses
        As :meth:`~fegear.tca.TCA.positions`.
    workers
        Processes to use at most.

    Returns
    -------
    The ``n`` positions, in the order of ``phi1``.
    """
    phi1 = np.atleast_1d(np.asarray(phi1, dtype=float))
    k = process_count(workers, max(1, phi1.size // MIN_PER_PROCESS))
    if k <= 1:
        return tca.positions(phi1, with_grids, ellipses)
    parts = np.array_split(phi1, k)
    done = fork_map(lambda p: tca.positions(p, with_grids, ellipses), parts)
    return [p for part in done for p in part]
