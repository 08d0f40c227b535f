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
    """Write ``fig`` to ``path`` (PNG, 110 dpi) atomically and close it."""
    plt = pyplot()
    fig.tight_layout()
    p = atomic_write(path, lambda q: fig.savefig(q, format="png", dpi=110))
    plt.close(fig)
    return p


def run_title(run: GearRun) -> str:
    """``"<case>: T2 <N·m>, <fidelity> level <L>"``, the first line of a run's figures."""
    c = run.case
    return f"{c.name}: T2 {c.torque2_Nm:.0f} N·m, {c.fidelity} level {c.level}"
