"""A minimal PNG writer (8-bit RGB, zlib from the standard library): camera frames as files."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
import numpy.typing as npt


def _chunk(kind: bytes, payload: bytes) -> bytes:
    crc = zlib.crc32(kind + payload) & 0xFFFFFFFF
    return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", crc)


def png_bytes(rgb: npt.NDArray[np.uint8]) -> bytes:
    """The PNG file of a ``height x width x 3`` RGB image."""
    if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.dtype != np.uint8:
        raise ValueError(f"expected a height x width x 3 uint8 image, got {rgb.shape} {rgb.dtype}")
    height, width = rgb.shape[0], rgb.shape[1]
    rows = np.zeros((height, width * 3 + 1), dtype=np.uint8)  # filter byte 0 on each row
    rows[:, 1:] = rgb.reshape(height, width * 3)
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + _chunk(b"IHDR", header)
        + _chunk(b"IDAT", zlib.compress(rows.tobytes(), 6))
        + _chunk(b"IEND", b"")
    )


def write_png(path: str | Path, rgb: npt.NDArray[np.uint8]) -> Path:
    path = Path(path)
    path.write_bytes(png_bytes(rgb))
    return path
