"""gmsh meshes of the bodies in contact: the sector meshes of the gear members
(:mod:`fegear.mesh.sector`) and the Hertz scene's bodies (:mod:`fegear.mesh.hertz_scene_bodies`).
They are cached by content in :mod:`fegear.store.cache`."""
