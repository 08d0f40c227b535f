"""Case files: the declarative schema (:mod:`fegear.io.schema`), gear-pair cases
(:mod:`fegear.io.gear_case`) and the built-in seed case (:mod:`fegear.io.seed`).

``io`` reads and validates; it builds nothing and imports nothing from the model layers
(``tca``, ``ltca``, ``mesh``, ``scenes``) or from the pipeline.
"""
