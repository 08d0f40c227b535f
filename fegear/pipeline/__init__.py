"""The pipeline of a gear case: case → pair → TCA → models → loaded cycle → fields.

:mod:`fegear.pipeline.pair` generates and assembles the members of a case (one
:class:`~fegear.pipeline.pair.Family` per gear family); :mod:`fegear.pipeline.run` runs the
unloaded TCA, checks the engagement, builds the contact models of the chosen fidelity, solves
the loaded cycle and, on request, the displacement and root-stress fields, and returns one
typed :class:`~fegear.pipeline.run.GearRun` that the writers (:mod:`fegear.output`) and the
Python API (:mod:`fegear.api`) read.
"""
