"""Write ``docs/papers/face_gear_2013.md``: the face-gear paper's tables and claims beside fegear.

Usage::

    python docs/papers/make_face_gear_2013.py            # run the parts not yet measured, render
    python docs/papers/make_face_gear_2013.py PART ...   # rerun these parts, render
    python docs/papers/make_face_gear_2013.py render     # rewrite the page from the JSON only

Parts (:mod:`face_gear_2013_runs`): ``case``, ``path``, ``shapers``, ``errors_path``, ``loads``,
``dgamma``, ``dgamma_shaper``, ``dgamma_placed``. Their data and wall times are kept in
``docs/papers/face_gear_2013.json``; the figures go to ``docs/papers/face_gear_2013/``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _parts import HERE, main  # noqa: E402
from face_gear_2013_page import figures, render  # noqa: E402
from face_gear_2013_runs import PARTS  # noqa: E402

PAGE = HERE / "face_gear_2013.md"
DATA = HERE / "face_gear_2013.json"

if __name__ == "__main__":
    main(sys.argv[1:], Path(__file__).resolve(), DATA, PARTS, render, PAGE, figures)
