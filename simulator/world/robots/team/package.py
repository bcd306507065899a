"""What a model package may hold: every file it names lies inside it, and its size is bounded.

A model package is the folder of its ``robot_model.json``. The manifest's ``model_file`` and
``packages``, and every file the model file names (``<mesh>``, ``<texture>``, ``<hfield>``,
``<skin>``, through ``meshdir`` / ``texturedir`` / ``assetdir``, ``package://`` and plain or
``file://`` paths) must lie inside it, symbolic links followed: a path outside is refused as
such, before anything outside is looked at, so the refusal says nothing of what the host holds
there. The folder, the files and the model are bounded (:data:`LIMITS`), each checked before the
costly step it bounds (reading a file, MuJoCo compiling the model), so that a package of a
2 GB mesh or 200,000 geoms is refused at once with a line naming the file, the element and the
limit.
"""

from __future__ import annotations

import os
import struct
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from simulator.errors import ModelProblem

MIB = 1024 * 1024


@dataclass(frozen=True, slots=True, kw_only=True)
class PackageLimits:
    """The bounds of a model package (the league's; see configs/README.md)."""

    package_bytes: int = 256 * MIB  # every file in the package folder, together
    package_entries: int = 10_000  # files and folders in the package folder
    manifest_bytes: int = 1 * MIB  # robot_model.json
    model_file_bytes: int = 16 * MIB  # the URDF / MJCF file
    asset_file_bytes: int = 32 * MIB  # each mesh, texture, height field or skin file
    texture_pixels: int = 4096 * 4096  # a texture's or height field's width x height
    bodies: int = 200  # MJCF <body> / URDF <link>
    joints: int = 200  # MJCF <joint> / URDF <joint>
    geoms: int = 5_000  # MJCF <geom> / URDF <collision> and <visual>
    meshes: int = 1_000  # MJCF <mesh> / URDF <mesh>


LIMITS = PackageLimits()

ASSET_FILE_ATTRIBUTES: dict[str, tuple[str, ...]] = {
    "mesh": ("file", "filename"),
    "texture": (
        "file", "filename", "fileright", "fileleft", "fileup", "filedown", "filefront", "fileback",
    ),
    "hfield": ("file",),
    "skin": ("file",),
}  # fmt: skip
"""Element -> the attributes naming a file (MJCF ``file``, URDF ``filename``, cube textures)."""

_COUNTED: dict[str, tuple[str, ...]] = {
    "bodies": ("body", "link"),
    "joints": ("joint",),
    "geoms": ("geom", "collision", "visual"),
    "meshes": ("mesh",),
}


def inside(folder: Path, path: Path) -> bool:
    """Whether ``path`` (absolute) lies inside ``folder`` (resolved), judged first on the path as
    written and then with symbolic links followed; nothing is required to exist, so the answer
    for a path outside is the same whether or not a file is there."""
    written = Path(os.path.normpath(path))
    if not written.is_relative_to(folder):
        return False
    return Path(os.path.realpath(written)).is_relative_to(folder)


def outside_reason(what: str) -> str:
    return (
        f"{what} lies outside the model package (every file it uses must be inside the "
        "package's folder: no absolute path, no '..' or link leading out)"
    )


def size_problem(
    source: str, where: str, what: str, path: Path, limit: int
) -> ModelProblem | None:
    """A problem when the file at ``path`` is larger than ``limit`` bytes."""
    try:
        size = path.stat().st_size
    except OSError:
        return None
    if size <= limit:
        return None
    return ModelProblem(
        source=source,
        where=where,
        reason=f"{what} is {_bytes(size)}, above the limit of {_bytes(limit)}",
    )


def package_problems(folder: Path, limits: PackageLimits = LIMITS) -> list[ModelProblem]:
    """The package folder's total size and number of entries against ``limits``; the walk stops
    as soon as either is passed (links are not followed)."""
    total = 0
    entries = 0
    stack = [folder]
    while stack:
        current = stack.pop()
        try:
            with os.scandir(current) as listing:
                for entry in listing:
                    entries += 1
                    if entries > limits.package_entries:
                        return [_package_problem(
                            folder, f"more than {limits.package_entries} files and folders",
                        )]  # fmt: skip
                    try:
                        if entry.is_dir(follow_symlinks=False):
                            stack.append(Path(entry.path))
                        elif entry.is_file(follow_symlinks=False):
                            total += entry.stat(follow_symlinks=False).st_size
                    except OSError:
                        continue
                    if total > limits.package_bytes:
                        return [_package_problem(
                            folder, f"more than {_bytes(limits.package_bytes)} of files",
                        )]  # fmt: skip
        except OSError:
            continue
    return []


def _package_problem(folder: Path, what: str) -> ModelProblem:
    return ModelProblem(
        source=str(folder),
        where="",
        reason=f"the model package holds {what} (the limit for a package)",
    )


def count_problems(
    source: str, root: ET.Element, limits: PackageLimits = LIMITS
) -> list[ModelProblem]:
    """Bodies, joints, geoms and meshes of the model file against ``limits``, counted on the
    parsed file before MuJoCo compiles it (an MJCF ``<replicate count>`` multiplies what it
    holds)."""
    found = dict.fromkeys(_COUNTED, 0)
    kind_of = {tag: kind for kind, tags in _COUNTED.items() for tag in tags}
    stack: list[tuple[ET.Element, int]] = [(root, 1)]
    while stack:
        element, times = stack.pop()
        kind = kind_of.get(element.tag)
        if kind is not None:
            found[kind] += times
        if element.tag == "replicate":
            times *= _replicate_count(element)
        stack.extend((child, times) for child in element)
    problems = []
    for kind, count in found.items():
        limit = getattr(limits, kind)
        if count > limit:
            tags = " / ".join(f"<{t}>" for t in _COUNTED[kind])
            problems.append(
                ModelProblem(
                    source=source,
                    where=tags,
                    reason=f"{count} {kind} in the model, above the limit of {limit}",
                )
            )
    return problems


def _replicate_count(element: ET.Element) -> int:
    try:
        return max(1, int(element.get("count", "1")))
    except ValueError:
        return 1


def image_problem(
    source: str, where: str, what: str, path: Path, limits: PackageLimits = LIMITS
) -> ModelProblem | None:
    """A problem when the PNG image at ``path`` declares more than ``limits.texture_pixels``
    pixels: a small compressed file may decode to gigabytes (MuJoCo's own binary formats are
    uncompressed, bounded by the file size limit)."""
    try:
        with path.open("rb") as handle:
            head = handle.read(24)
    except OSError:
        return None
    if head[:8] != b"\x89PNG\r\n\x1a\n" or len(head) < 24:
        return None
    width, height = struct.unpack(">II", head[16:24])  # the IHDR chunk
    if width * height <= limits.texture_pixels:
        return None
    return ModelProblem(
        source=source,
        where=where,
        reason=f"{what} is {width} x {height} pixels, above the limit of "
        f"{limits.texture_pixels} pixels",
    )


def _bytes(size: int) -> str:
    return f"{size} bytes ({size / MIB:.1f} MiB)" if size >= MIB else f"{size} bytes"
