"""Writers of results: JSON summary, VTK for ParaView, PNG pictures.

Modules: :mod:`fegear.io.files` (atomic writes, used by the caches too),
:mod:`fegear.io.hertz_output`, :mod:`fegear.io.gear_output`, :mod:`fegear.io.sweep_output`.
The package root imports nothing heavy, so low-level modules may use :mod:`fegear.io.files`.
"""
