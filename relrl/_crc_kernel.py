"""CRC-32C (Castagnoli) in one compiled call (numba), the checksum of TensorBoard's event
records (:mod:`relrl.tensorboard`): the byte loop, which Python runs an order of magnitude
slower, compiled. Compiled once and cached beside this file, as relrl's other kernels."""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["TABLE", "crc32c"]


def _table() -> np.ndarray:
    table = np.zeros(256, dtype=np.uint32)
    for i in range(256):
        c = i
        for _ in range(8):
            c = (c >> 1) ^ 0x82F63B78 if c & 1 else c >> 1
        table[i] = c
    return table


#: the byte-wise table of the reflected polynomial 0x82F63B78.
TABLE = _table()


@njit(nogil=True, cache=True)
def crc32c(buf, table):  # pragma: no cover - compiled
    """The CRC-32C of ``buf`` (uint8) with ``table`` (:data:`TABLE`)."""
    c = np.uint32(0xFFFFFFFF)
    for b in buf:
        c = table[(c ^ b) & np.uint32(0xFF)] ^ (c >> np.uint32(8))
    return c ^ np.uint32(0xFFFFFFFF)
