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
- :mod:`~fegear.mechanics.convergence` — observed convergence rates of mesh studies;
- :mod:`~fegear.mechanics.compliance` — the FE compliance of a meshed elastic body on contact
  cells: the operator ``(K⁻¹)`` on its candidate DOFs (Cartesian or along surface normals),
  the consistent cell loads and readings.

Its modules take plain arrays and meshes and import nothing from fegear but the gear-agnostic
layers under them: :mod:`fegear.errors`, :mod:`fegear.fem`, :mod:`fegear.linalg` and
:mod:`fegear.store` (``tests/test_architecture.py`` checks it).
"""
