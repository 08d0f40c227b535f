"""Writers of results: ``summary.json``, VTK for ParaView, PNG pictures.

:mod:`fegear.output.gear_output` (every file of a gear run, from its result model
:mod:`fegear.results`), :mod:`fegear.output.vtk` (the VTK series), :mod:`fegear.output.gear_plots`
and :mod:`fegear.output.pattern_plot` (the PNGs), :mod:`fegear.output.flank_view` and
:mod:`fegear.output.flank_vtp` (the flank bearing patterns: per-flank frames, patches, pattern
centres, their files), :mod:`fegear.output.hertz_scene_output` (the Hertz validation scene). Files
are written atomically (:mod:`fegear.store.files`).
"""
