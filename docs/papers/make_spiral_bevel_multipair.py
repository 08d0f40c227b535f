"""Write ``docs/papers/spiral_bevel_multipair.md``: the multi-pair paper's claims on fegear's
spiral bevel over a load range.

Usage::

    python docs/papers/make_spiral_bevel_multipair.py            # run missing parts, render
    python docs/papers/make_spiral_bevel_multipair.py PART ...   # rerun these parts, render
    python docs/papers/make_spiral_bevel_multipair.py render     # rewrite the page from the JSON

Parts (:mod:`spiral_bevel_multipair_runs`): ``tca``, ``loads``. Their data and wall times are
kept in ``docs/papers/spiral_bevel_multipair.json``; the figures go to
``docs/papers/spiral_bevel_multipair/``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _parts import HERE, main  # noqa: E402
from spiral_bevel_multipair_page import figures, render  # noqa: E402
from spiral_bevel_multipair_runs import PARTS  # noqa: E402

PAGE = HERE / "spiral_bevel_multipair.md"
DATA = HERE / "spiral_bevel_multipair.json"

if __name__ == "__main__":
    main(sys.argv[1:], Path(__file__).resolve(), DATA, PARTS, render, PAGE, figures)
