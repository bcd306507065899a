"""One read-only float64 array spanning several arrays of an ``MjData``.

MuJoCo allocates the arrays of ``mjData`` (``qpos``, ``xpos``, ``sensordata``...) once, in one
buffer, and never moves them. A single array over the span they cover lets one fancy index
(one numpy call) gather values from all of them at once: the snapshot of eight robots reads
about 170 values from six arrays every step, and each numpy call costs a few microseconds
right after ``mj_step`` has evicted the interpreter's working set from the caches.

The span array keeps the ``MjData`` alive (it is the array's base). Indices must point inside
the named arrays (:meth:`FlatData.offset` + a position in that array); the bytes between them
are never read.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt

_ITEM = 8  # bytes of a float64


class _Span:
    """Numpy's array interface over ``count`` float64 values at ``address``; holds ``owner``."""

    def __init__(self, owner: object, address: int, count: int) -> None:
        self.owner = owner
        self.__array_interface__ = {
            "version": 3,
            "shape": (count,),
            "typestr": "<f8",
            "data": (address, True),  # read-only
        }


class FlatData:
    """``values``: the span over the arrays ``names`` of ``data``; ``offset(name)``: where each
    array starts in it (in values, not bytes)."""

    def __init__(self, data: mujoco.MjData, names: Sequence[str]) -> None:
        arrays = {name: np.asarray(getattr(data, name)) for name in names}
        for name, array in arrays.items():
            if array.dtype != np.float64 or not array.flags.c_contiguous:
                raise ValueError(f"MjData.{name} is not a contiguous float64 array")
        start = min(a.ctypes.data for a in arrays.values())
        end = max(a.ctypes.data + a.nbytes for a in arrays.values())
        self._offsets: dict[str, int] = {}
        for name, array in arrays.items():
            gap = array.ctypes.data - start
            if gap % _ITEM:
                raise ValueError(f"MjData.{name} is not aligned on a float64 boundary")
            self._offsets[name] = gap // _ITEM
        self.values: npt.NDArray[np.float64] = np.asarray(
            _Span(data, start, (end - start) // _ITEM)
        )

    def offset(self, name: str) -> int:
        return self._offsets[name]

    def indices(self, name: str, positions: Any) -> npt.NDArray[np.intp]:
        """Positions in ``values`` of the given positions (flat) of array ``name``."""
        return (np.asarray(positions, dtype=np.intp) + self._offsets[name]).astype(np.intp)
