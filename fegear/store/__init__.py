"""Bottom layer of storage: atomic file writes and the cache rule (content, code and dependency
versions) used by every cache of the pipeline. Imports nothing from the rest of fegear except
:mod:`fegear.errors`."""
