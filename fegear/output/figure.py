"""What every PNG writer of a run shares: Agg matplotlib, an atomic save, the title."""

from __future__ import annotations

from pathlib import Path

from fegear.pipeline.run import GearRun
from fegear.store.files import atomic_write

__all__ = ["pyplot", "run_title", "save_png"]


def pyplot():
    """``matplotlib.pyplot`` on the Agg backend (files only, no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_png(fig, path: Path) -> Path:
    """Write ``fig`` to ``path`` (PNG, 110 dpi) atomically and close it.

    The layout is :meth:`~matplotlib.figure.Figure.tight_layout`, applied once; the figure is
    then left without a layout engine (``tight_layout`` leaves a placeholder one, and a figure
    with any layout engine is drawn twice by ``savefig``: once without rendering, for the
    engine, then into the PNG; the placeholder engine does nothing, so the picture is the
    same, drawn once: about a third of the drawing time of the run's pictures)."""
    plt = pyplot()
    fig.tight_layout()
    fig.set_layout_engine(None)
    p = atomic_write(path, lambda q: fig.savefig(q, format="png", dpi=110))
    plt.close(fig)
    return p


def run_title(run: GearRun) -> str:
    """``"<case>: T2 <N·m>, <fidelity> level <L>"``, the first line of a run's figures."""
    c = run.case
    return f"{c.name}: T2 {c.torque2_Nm:.0f} N·m, {c.fidelity} level {c.level}"
