"""The pipeline of a gear case: case → pair → TCA → checks → models → loaded cycle → fields.

:mod:`fegear.pipeline.pair` generates and assembles the members of a case (one
:class:`~fegear.pipeline.pair.Family` per gear family); :mod:`fegear.pipeline.engagement`
decides, before any FE work, every way the contact can fail; :mod:`fegear.pipeline.run` runs the
unloaded TCA, the checks, the contact models of the chosen fidelity and the loaded cycle;
:mod:`fegear.pipeline.fields` the displacement and root-stress fields on request. The result is
one typed :class:`~fegear.pipeline.run.GearRun`, from which :func:`fegear.results.build_result`
builds the result model that the writers (:mod:`fegear.output`) and the Python API
(:mod:`fegear.api`) read.
"""
