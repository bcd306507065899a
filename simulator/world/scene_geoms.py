"""A scene's geoms as one numpy record array, so that many can be written at once.

MuJoCo's Python binding hands a scene's geoms out one object at a time (``scene.geoms[i]``),
and writing one through it (``mjv_initGeom`` and an attribute or two) costs a few microseconds
of Python: the robot cameras' planar shadows wrote about 70 a frame that way, some 0.2 ms of a
6 ms frame on the CPU. :func:`geom_rows` views the scene's ``mjvGeom`` array as records instead.

The record's layout is MuJoCo's own declaration of ``mjvGeom`` (``mujoco.introspect``, shipped
with the binding it describes) laid out by C's rules (numpy's ``align=True``), and it is only
used when it agrees with the binding: the record's size is the distance between two geoms, each
array field (``size``, ``pos``, ``mat``, ``rgba``, ``texrepeat``) sits where the binding's own
view of it is, and scalar fields written through the binding are read back through the records
and the other way round. Anything else (another MuJoCo, an unknown field type) gives None, and
the caller writes geom by geom as before.
"""

from __future__ import annotations

import ctypes
from functools import lru_cache
from typing import Any

import mujoco
import numpy as np

_SCALARS = {
    "int": np.int32,
    "float": np.float32,
    "double": np.float64,
    "mjtNum": np.float64,
    "mjtByte": np.uint8,
    "char": np.uint8,
}
_ARRAYS = ("size", "pos", "mat", "rgba", "texrepeat")  # where the binding gives views


@lru_cache(maxsize=1)
def geom_dtype() -> np.dtype | None:
    """``mjvGeom`` as a numpy record (C alignment), from MuJoCo's introspection; None when a
    field's type is not a plain number or the declaration is not there."""
    try:
        from mujoco.introspect import ast_nodes, structs
    except ImportError:
        return None
    decl = structs.STRUCTS.get("mjvGeom")
    if decl is None:
        return None
    fields: list[tuple[Any, ...]] = []
    for field in decl.fields:
        kind, shape = field.type, ()
        if isinstance(kind, ast_nodes.ArrayType):
            kind, shape = kind.inner_type, tuple(kind.extents)
        if not isinstance(kind, ast_nodes.ValueType) or kind.name not in _SCALARS:
            return None
        scalar = _SCALARS[kind.name]
        fields.append((field.name, scalar, shape) if shape else (field.name, scalar))
    return np.dtype(fields, align=True)


def _address(array: np.ndarray) -> int:
    return int(array.ctypes.data)


def geom_rows(scene: mujoco.MjvScene) -> np.ndarray | None:
    """``scene``'s ``maxgeom`` geoms as records of :func:`geom_dtype` (a view: writing a record
    writes the geom; it lives as long as ``scene``), or None when the layout does not agree
    with the binding (see the module's note)."""
    dtype = geom_dtype()
    if dtype is None or scene.maxgeom < 2 or dtype.names is None or dtype.fields is None:
        return None
    fields, names = dtype.fields, set(dtype.names)
    if not set(_ARRAYS) <= names or not {"type", "dataid", "specular", "category"} <= names:
        return None
    geoms = scene.geoms
    first, second, last = geoms[0], geoms[1], geoms[scene.maxgeom - 1]
    if _address(second.pos) - _address(first.pos) != dtype.itemsize:
        return None
    base = _address(first.size) - fields["size"][1]
    for name in _ARRAYS:
        view = getattr(first, name)
        field_dtype, offset = fields[name][:2]
        if (
            _address(view) != base + offset
            or view.dtype != field_dtype.base
            or view.size != int(np.prod(field_dtype.shape))  # (mat: 3x3 there, 9 here)
        ):
            return None
    buffer = (ctypes.c_char * (dtype.itemsize * scene.maxgeom)).from_address(base)
    rows = np.frombuffer(buffer, dtype=dtype)
    if _address(rows["pos"][scene.maxgeom - 1]) != _address(last.pos):
        return None
    # scalars both ways, on the last geom (a slot a frame's scene seldom reaches; restored)
    saved = rows[-1].copy()
    try:
        last.type, last.dataid, last.category, last.specular = 7, -12345, 4, 0.375
        agree = (
            int(rows["type"][-1]) == 7
            and int(rows["dataid"][-1]) == -12345
            and int(rows["category"][-1]) == 4
            and float(rows["specular"][-1]) == 0.375
        )
        rows["type"][-1], rows["dataid"][-1], rows["specular"][-1] = 3, 54321, 0.625
        agree = agree and (last.type, last.dataid, last.specular) == (3, 54321, 0.625)
    finally:
        rows[-1] = saved
    return rows if agree else None
