"""Writers of results: ``summary.json``, VTK for ParaView, PNG pictures.

:mod:`fegear.output.gear_output` (a gear run), :mod:`fegear.output.flank_view` (the flank
bearing patterns: per-flank frames, patches and pattern centres), :mod:`fegear.output.hertz_output`
(the Hertz validation scene), :mod:`fegear.output.records` (software versions and solver
residuals in every summary). Files are written atomically (:mod:`fegear.store.files`).
"""
