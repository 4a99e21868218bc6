"""Messages between the page and Python: a JSON header, and the numbers of its arrays as one buffer.

A message (a dict) may hold numpy arrays anywhere. `pack` replaces each by ``{"$": offset, "shape":
[...]}`` (offset in float64s into the buffer) and returns the header and the buffer of every array's
float64 values, C order, end to end: the page reads them as views of one `Float64Array`, with no
parsing and no rounding (JSON would write 17 digits a number, and has no NaN for a missing value). A
WebSocket frame carries both as `frame(header, buffer)`: ``MBP1``, the header's length (uint32, little
endian), the header (UTF-8 JSON), zeros up to a multiple of 8 bytes, the buffer. Jupyter's comm sends
the header as the message and the buffer beside it.
"""

from __future__ import annotations

import json
import math
import struct

import numpy as np

__all__ = ["pack", "frame", "dumps"]

MAGIC = b"MBP1"


def pack(message) -> tuple[dict, bytes]:
    """(header, buffer): the message with its arrays replaced by references into the buffer."""
    chunks, offset = [], [0]

    def walk(value):
        if isinstance(value, np.ndarray):
            data = np.ascontiguousarray(value, dtype="<f8")
            ref = {"$": offset[0], "shape": list(data.shape)}
            chunks.append(data.tobytes())
            offset[0] += data.size
            return ref
        if isinstance(value, dict):
            return {str(k): walk(v) for k, v in value.items()}
        if isinstance(value, (list, tuple)):
            return [walk(v) for v in value]
        if isinstance(value, (np.floating, float)):
            value = float(value)
            return value if math.isfinite(value) else None
        if isinstance(value, np.integer):
            return int(value)
        if isinstance(value, np.bool_):
            return bool(value)
        return value

    header = walk(message)
    return header, b"".join(chunks)


def dumps(header) -> str:
    return json.dumps(header, separators=(",", ":"), ensure_ascii=False, allow_nan=False)


def frame(header: dict, buffer: bytes) -> bytes:
    """One binary WebSocket frame of a packed message."""
    text = dumps(header).encode("utf-8")
    pad = (-(len(MAGIC) + 4 + len(text))) % 8
    return MAGIC + struct.pack("<I", len(text) + pad) + text + b" " * pad + buffer
