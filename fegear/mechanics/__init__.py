"""The mechanics that knows nothing about gears.

- :mod:`~fegear.mechanics.contact` — the active-set solver of the normal contact problem of two
  elastic bodies (cell forces and one rigid-body unknown);
- :mod:`~fegear.mechanics.hertz_closed_form` — closed-form Hertz contact (point and line
  contact, the contact law, the ellipse painted on a grid): the reference the FE contact converges
  to;
- :mod:`~fegear.mechanics.halfspace` — the elastic half-space influence of uniform pressure on
  rectangular cells (the near field of the ``hybrid`` fidelity);
- :mod:`~fegear.mechanics.patch` — measures of a computed contact patch (recovered peak pressure,
  semi-axes from second moments);
- :mod:`~fegear.mechanics.convergence` — observed convergence rates of mesh studies.

Its modules take plain arrays and import nothing from fegear but :mod:`fegear.errors`
(``tests/test_architecture.py`` checks it). The FE compliance of meshed bodies is
:mod:`fegear.compliance`.
"""
