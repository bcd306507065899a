"""The field's lines and each goal's net cords, also as one mesh each for the robot cameras.

MuJoCo draws every geom with some work of its own a pass (its material, its matrix, its call),
whatever its size on screen. On a CPU renderer the 70 boxes of the field's lines and the 236
cords of the two nets were a fifth of the OpenGL work of a 320x240 robot camera frame (20.9
million instructions with them, 14.9 without; 16.8 as the meshes here). The world carries each
group twice: as boxes (what the match video, the replay's scene and the viewer draw) and as one
mesh geom of the same boxes (but for the lines' bottom faces, which lie on the turf facing
down), the same places, colours and texture coordinates, with alpha 0 so that every renderer
skips it. The robot cameras' copy of the model
(:func:`simulator.world.camera.robot_camera_model`) turns both round with :func:`show_merged`:
the mesh drawn, the boxes not. The replay's scene leaves the meshes out
(:func:`simulator.replay.scene.scene_of`).

A mesh's corners carry the texture coordinates MuJoCo's renderer gives a box's faces (its
built-in box of one quad a face, with ``texuniform``: a coordinate ``u`` of a face scaled by the
material's ``texrepeat`` times the box's half size), so a textured line looks the same either
way; ``tests/unit/world/test_world_merged.py`` compares camera frames of both.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

MERGED_PREFIX = "merged:"
HIDDEN_RGBA = "1 1 1 0"  # in the world: every renderer skips the mesh

Corner = tuple[tuple[int, int, int], tuple[int, int]]  # a unit cube's corner and its (u, v)
# MuJoCo's built-in box (one quad a face, the top first): (normal, four corners
# counter-clockwise seen from outside)
_BOX_FACES: tuple[tuple[tuple[int, int, int], tuple[Corner, ...]], ...] = (
    ((0, 0, 1), (((-1, -1, 1), (0, 1)), ((1, -1, 1), (1, 1)), ((1, 1, 1), (1, 0)),
                 ((-1, 1, 1), (0, 0)))),
    ((0, 0, -1), (((-1, 1, -1), (0, 0)), ((1, 1, -1), (1, 0)), ((1, -1, -1), (1, 1)),
                  ((-1, -1, -1), (0, 1)))),
    ((1, 0, 0), (((1, -1, -1), (0, 1)), ((1, 1, -1), (1, 1)), ((1, 1, 1), (1, 0)),
                 ((1, -1, 1), (0, 0)))),
    ((-1, 0, 0), (((-1, -1, 1), (0, 0)), ((-1, 1, 1), (1, 0)), ((-1, 1, -1), (1, 1)),
                  ((-1, -1, -1), (0, 1)))),
    ((0, -1, 0), (((-1, -1, -1), (0, 1)), ((1, -1, -1), (1, 1)), ((1, -1, 1), (1, 0)),
                  ((-1, -1, 1), (0, 0)))),
    ((0, 1, 0), (((-1, 1, 1), (0, 0)), ((1, 1, 1), (1, 0)), ((1, 1, -1), (1, 1)),
                 ((-1, 1, -1), (0, 1)))),
)  # fmt: skip


@dataclass(frozen=True, slots=True)
class Box:
    """A static box of the world body: centre (m), half sizes (m), turn about z (rad)."""

    centre: tuple[float, float, float]
    half: tuple[float, float, float]
    yaw: float = 0.0


def _g(values: np.ndarray) -> str:
    return " ".join(f"{v:.9g}" for v in values.ravel().tolist())


def box_mesh_xml(
    name: str, boxes: Sequence[Box], *, texrepeat: float | None = None, bottoms: bool = True
) -> str:
    """A ``<mesh>`` asset of ``boxes`` (world coordinates; without their bottom faces unless
    ``bottoms``: a line's lies on the turf, facing down): four corners a face with its normal
    and, with ``texrepeat`` (the material's, ``texuniform``), the texture coordinates MuJoCo
    gives the same box."""
    faces = _BOX_FACES if bottoms else _BOX_FACES[:1] + _BOX_FACES[2:]
    normals = np.array([normal for normal, _ in faces], dtype=float)  # (face, 3)
    corners = np.array([[c for c, _ in quad] for _, quad in faces], dtype=float)  # (face, 4, 3)
    uvs = np.array([[uv for _, uv in quad] for _, quad in faces], dtype=float)  # (face, 4, 2)
    centre = np.array([b.centre for b in boxes], dtype=float)
    half = np.array([b.half for b in boxes], dtype=float)
    yaw = np.array([b.yaw for b in boxes], dtype=float)
    turn = np.zeros((len(boxes), 3, 3))
    turn[:, 0, 0] = turn[:, 1, 1] = np.cos(yaw)
    turn[:, 1, 0] = np.sin(yaw)
    turn[:, 0, 1] = -turn[:, 1, 0]
    turn[:, 2, 2] = 1.0
    local = corners[None] * half[:, None, None, :]  # (box, face, 4, 3)
    vertices = centre[:, None, None, :] + np.einsum("bij,bfkj->bfki", turn, local)
    turned = np.einsum("bij,fj->bfi", turn, normals)[:, :, None, :]
    first = 4 * np.arange(len(boxes) * len(faces))[:, None]
    triangles = (first + np.array([0, 1, 2, 0, 2, 3])).ravel()
    uv = ""
    if texrepeat is not None:
        uv = f' texcoord="{_g(uvs[None] * (texrepeat * half[:, None, None, :2]))}"'
    return (
        f'<mesh name="{name}" inertia="shell" vertex="{_g(vertices)}" '
        f'normal="{_g(np.broadcast_to(turned, vertices.shape))}"{uv} '
        f'face="{" ".join(map(str, triangles.tolist()))}"/>'
    )


def merged_geom_xml(name: str, *, material: str | None = None) -> str:
    """The world body's geom of mesh ``name`` (no contacts, no mass, hidden)."""
    look = f' material="{material}"' if material else ""
    return (
        f'<geom name="{name}" type="mesh" mesh="{name}"{look} rgba="{HIDDEN_RGBA}" '
        f'contype="0" conaffinity="0" group="1" mass="0"/>'
    )


def is_merged(name: str) -> bool:
    return name.startswith(MERGED_PREFIX)


def merged_groups(model: mujoco.MjModel) -> list[tuple[int, np.ndarray]]:
    """(mesh geom, its boxes' geoms) of every merged group of ``model``: the boxes are the
    geoms whose names start with what follows :data:`MERGED_PREFIX` in the mesh's name."""
    names = [model.geom(g).name for g in range(model.ngeom)]
    groups = []
    for g, name in enumerate(names):
        if is_merged(name):
            stem = name.removeprefix(MERGED_PREFIX)
            members = [i for i, n in enumerate(names) if n.startswith(stem)]
            groups.append((g, np.asarray(members, dtype=int)))
    return groups


def show_merged(model: mujoco.MjModel) -> None:
    """Turn ``model`` (a renderer's own copy) to draw each merged mesh instead of its boxes:
    the mesh takes the boxes' colour, the boxes alpha 0."""
    for mesh, boxes in merged_groups(model):
        if len(boxes):
            model.geom_rgba[mesh] = model.geom_rgba[boxes[0]]
            model.geom_rgba[boxes, 3] = 0.0
