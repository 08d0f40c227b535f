"""gmsh meshes of the bodies in contact, and their content-hash cache."""

from fegear.store.cache import cache_dir, cached_file, content_hash

__all__ = ["cache_dir", "cached_file", "content_hash"]
