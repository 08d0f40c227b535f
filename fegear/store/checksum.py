"""A fast content checksum of a cache file, verified every time the file is read.

The compliance operators are hundreds of MB each and are read on every run, so the checksum must
cost a fraction of reading them. :func:`file_checksum` is the BLAKE2b digest of the sequence of
the wrapping 64-bit sums of the file's words, one sum per MiB block, followed by the file's tail
(the bytes after the last whole word) and its length:

    c = BLAKE2b( s_0 ‖ s_1 ‖ … ‖ s_{n−1} ‖ tail ‖ size ),   s_k = Σ_{i ∈ block k} w_i  mod 2^64

A changed word changes its block's sum (any change of one word does: the sum is taken modulo
2^64 over the words themselves), a truncated or extended file changes the size, and blocks
swapped or zeroed change the ordered digest; it is not a cryptographic hash of the content
(two changes in one block can cancel), which the cache does not need: it detects files cut short
by a full disk or a killed copy, and bytes damaged on disk. Measured on a 500 MB operator in the
page cache, 2 cores: 0.08 s, against 0.27 s for ``zlib.crc32`` over the same memory.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

__all__ = ["file_checksum"]

#: Words (8 bytes) per summed block: 1 MiB.
_BLOCK_WORDS = 1 << 17


def file_checksum(path: str | Path) -> str:
    """The checksum of the file at ``path`` (hex, 32 characters; see the module docstring)."""
    path = Path(path)
    size = path.stat().st_size
    h = hashlib.blake2b(digest_size=16)
    if size:
        data = np.memmap(path, dtype=np.uint8, mode="r", shape=(size,))
        n = size // 8 * 8
        if n:
            words = data[:n].view("<u8")
            starts = np.arange(0, words.size, _BLOCK_WORDS)
            h.update(np.add.reduceat(words, starts, dtype=np.uint64).astype("<u8").tobytes())
        h.update(bytes(data[n:]))
        del data
    h.update(size.to_bytes(8, "little"))
    return h.hexdigest()
