"""Write ``docs/papers/hypoid_no16.md``: the 10/41 hypoid of a Gleason-style No. 16 summary
sheet (1.500 in offset) against fegear's hypoid built from its design data.

Usage::

    python docs/papers/make_hypoid_no16.py            # run missing parts, render
    python docs/papers/make_hypoid_no16.py PART ...   # rerun these parts, render
    python docs/papers/make_hypoid_no16.py render     # rewrite the page from the JSON

Parts (:mod:`hypoid_no16_runs`): ``blank``, ``gear_settings``, ``synthesis``. Their data and
wall times are kept in ``docs/papers/hypoid_no16.json``; the figure goes to
``docs/papers/hypoid_no16/``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _parts import HERE, main  # noqa: E402
from hypoid_no16_page import figures, render  # noqa: E402
from hypoid_no16_runs import PARTS  # noqa: E402

PAGE = HERE / "hypoid_no16.md"
DATA = HERE / "hypoid_no16.json"

if __name__ == "__main__":
    main(sys.argv[1:], Path(__file__).resolve(), DATA, PARTS, render, PAGE, figures)
