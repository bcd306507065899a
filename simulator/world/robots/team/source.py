"""Reads a team's model file (URDF or MJCF) into a MuJoCo spec, with every mesh path resolved.

URDF from ROS names meshes ``package://<package>/<path>``; they are resolved against the
manifest's ``packages`` (or a folder of that name beside the manifest or the model file), and
relative paths against the model file's folder. MJCF files name them relative to the
``<compiler>``'s ``meshdir`` / ``texturedir`` (or ``assetdir``), themselves relative to the
file's folder, as MuJoCo reads them. A mesh that is missing or unreadable is a
:class:`ModelProblem` naming the element and the path tried.

A published MJCF file describes a scene as well as a robot: a ground plane, lights, a skybox,
its own actuators, sensors, keyframes and contact exclusions, the solver options. The league's
world provides all of these, so they are left out, each kind with a note (a problem of severity
``note``, :data:`IGNORED`) naming the element and why; the robot's root body may keep the free
joint the file gives it. What cannot be left out without changing the robot (equality
constraints, tendons, included files) is an error naming the element and what to do.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco

from simulator.errors import ModelError, ModelProblem
from simulator.world.robots.team.entries import Manifest
from simulator.world.robots.team.package import (
    ASSET_FILE_ATTRIBUTES,
    LIMITS,
    count_problems,
    image_problem,
    inside,
    outside_reason,
    package_problems,
    size_problem,
)

PACKAGE_SCHEME = "package://"
IGNORED = "note"
"""Severity of an element of the file that the league's world replaces (it is left out)."""
_SCENE_SECTIONS = {
    "actuator": "the motors are the manifest's catalogue servos (/motors)",
    "sensor": "the sensors are the league's: IMU, cameras, force sensors and joint positions "
    "named in the manifest",
    "keyframe": "the robot is placed in the manifest's standing_pose_rad",
    "contact": "self-collision follows the league's rule (docs/physics.md), the same for "
    "every robot",
    "option": "the world's physics options (time step, solver) are the league's",
    "size": "the world's sizes are the league's",
    "visual": "rendering is the league's",
    "statistic": "the world's statistics are computed from the whole scene",
}
_UNSUPPORTED = {
    "equality": "equality constraints (closed loops, coupled joints) are not supported: "
    "describe the robot as a tree with one joint per motor",
    "tendon": "tendons are not supported: describe the robot as a tree with one joint per motor",
    "include": "included files are not read: put their content in the model file",
    "model": "other model files are not read: put their content in the model file",
    "attach": "other model files are not read: put their content in the model file",
    "composite": "soft bodies are not supported: a robot is rigid links",
    "flexcomp": "soft bodies are not supported: a robot is rigid links",
    "flex": "soft bodies are not supported: a robot is rigid links",
}
_REFUSED_ANYWHERE = ("include", "model", "attach", "composite", "flexcomp", "flex")


def _resolve(manifest: Manifest, ref: str, base: Path | None = None) -> list[Path]:
    """Candidate files for a mesh reference, in the order they are tried (relative paths
    against ``base``, by default the model file's folder), those outside the package left out
    (none is looked at: see :mod:`~simulator.world.robots.team.package`)."""
    base = base or manifest.model_file.parent
    if ref.startswith(PACKAGE_SCHEME):
        package, _, rest = ref[len(PACKAGE_SCHEME) :].partition("/")
        roots = [manifest.packages[package]] if package in manifest.packages else []
        roots += [manifest.folder / package]
        roots += [parent / package for parent in base.parents if parent != manifest.folder]
        roots += [p for p in base.parents if p.name == package]
        candidates = [root / rest for root in dict.fromkeys(roots)]
    else:
        if ref.startswith("file://"):
            ref = ref[len("file://") :]
        path = Path(ref)
        candidates = [path] if path.is_absolute() else [base / path]
    return [c for c in candidates if inside(manifest.folder, c)]


def _asset_dirs(
    root: ET.Element, manifest: Manifest
) -> tuple[dict[str, Path | None], list[ModelProblem]]:
    """Element tag -> folder its ``file`` is relative to (MJCF ``<compiler>``: ``meshdir`` and
    ``texturedir``, each defaulting to ``assetdir``, all relative to the file's folder), and a
    problem for each of these folders outside the package (its tags then map to None)."""
    base = manifest.model_file.parent
    dirs: dict[str, Path | None] = {"mesh": base, "texture": base, "hfield": base, "skin": base}
    problems: list[ModelProblem] = []
    if root.tag != "mujoco":
        return dirs, problems
    for compiler in root.iter("compiler"):
        reported = set()
        for own, tags in (("meshdir", ("mesh", "hfield", "skin")), ("texturedir", ("texture",))):
            key = own if compiler.get(own) is not None else "assetdir"
            value = compiler.get(key)
            if value is None:
                continue
            outside = not inside(manifest.folder, base / value)
            for tag in tags:
                dirs[tag] = None if outside else base / value
            if outside and key not in reported:
                reported.add(key)
                problems.append(
                    ModelProblem(
                        source=str(manifest.model_file),
                        where=f"<compiler {key}={value!r}>",
                        reason=outside_reason(f"the folder {value!r}"),
                    )
                )
        for key in ("assetdir", "meshdir", "texturedir"):
            compiler.attrib.pop(key, None)
    return dirs, problems


def _scene_notes(
    manifest: Manifest, root: ET.Element
) -> tuple[list[ModelProblem], list[ModelProblem]]:
    """Leave out of an MJCF file what the league's world provides (notes) and report what
    cannot be left out (errors); ``root`` is edited."""
    source = str(manifest.model_file)
    notes: list[ModelProblem] = []
    errors: list[ModelProblem] = []
    if root.tag != "mujoco":
        return notes, errors

    def note(where: str, reason: str) -> None:
        notes.append(ModelProblem(source=source, where=where, reason=reason, severity=IGNORED))

    for element in list(root):
        if element.tag in _SCENE_SECTIONS:
            count = len(list(element))
            what = f" ({count} element{'s' if count != 1 else ''})" if count else ""
            note(f"<{element.tag}>", f"ignored{what}: {_SCENE_SECTIONS[element.tag]}")
            root.remove(element)
        elif element.tag in ("equality", "tendon") and len(element):
            errors.append(
                ModelProblem(
                    source=source, where=f"<{element.tag}>", reason=_UNSUPPORTED[element.tag]
                )
            )
    for parent in root.iter():
        for child in list(parent):
            if child.tag in _REFUSED_ANYWHERE:
                detail = "".join(
                    f" {key}={child.get(key)!r}" for key in ("file", "model") if child.get(key)
                )
                errors.append(
                    ModelProblem(
                        source=source,
                        where=f"<{child.tag}{detail}>",
                        reason=_UNSUPPORTED[child.tag],
                    )
                )
    for asset in root.findall("asset"):
        for texture in [t for t in asset.findall("texture") if t.get("type") == "skybox"]:
            note(f"<texture type='skybox'{_named(texture)}>", "ignored: the sky is the league's")
            asset.remove(texture)
    for worldbody in root.findall("worldbody"):
        for element in list(worldbody):
            holds_robot = element.tag == "frame" and element.find(".//body") is not None
            if element.tag == "body" or holds_robot:
                continue
            detail = f" type={element.get('type')!r}" if element.get("type") else ""
            reason = {
                "geom": "the ground is the league's field",
                "light": "the lights are the league's",
                "camera": "cameras are the manifest's /cameras, on the robot's links",
                "site": "a site outside the robot",
            }.get(element.tag, "outside the robot")
            note(f"<worldbody><{element.tag}{_named(element)}{detail}>", f"ignored: {reason}")
            worldbody.remove(element)
        for parent in worldbody.iter():
            for light in [c for c in parent if c.tag == "light"]:
                note(f"<light{_named(light)}> in <body{_named(parent)}>",
                     "ignored: the lights are the league's")  # fmt: skip
                parent.remove(light)
    counted: dict[tuple[str, str], int] = {}
    for n in notes:
        counted[(n.where, n.reason)] = counted.get((n.where, n.reason), 0) + 1
    notes = [
        ModelProblem(
            source=source,
            where=where if count == 1 else f"{where} x{count}",
            reason=reason,
            severity=IGNORED,
        )
        for (where, reason), count in counted.items()
    ]
    return notes, errors


def _named(element: ET.Element) -> str:
    name = element.get("name")
    return f" name={name!r}" if name else ""


def _parse(manifest: Manifest) -> ET.Element:
    source = str(manifest.model_file)
    too_big = [
        *package_problems(manifest.folder),
        size_problem(source, "", "the model file", manifest.model_file, LIMITS.model_file_bytes),
    ]
    if any(too_big):
        raise ModelError([p for p in too_big if p is not None])
    try:
        return ET.parse(manifest.model_file).getroot()
    except ET.ParseError as exc:
        line, column = exc.position
        raise ModelError(
            [
                ModelProblem(
                    source=source,
                    where=f"line {line}, column {column}",
                    reason=f"malformed XML: {exc}",
                )
            ]
        ) from None
    except OSError as exc:
        raise ModelError([ModelProblem(source=source, where="", reason=str(exc))]) from None


def _check_meshes(manifest: Manifest, root: ET.Element) -> list[ModelProblem]:
    """Rewrite every mesh (texture, height field, skin) ``filename``/``file`` to an absolute
    path; report those outside the package, missing, unreadable or above the size limits."""
    dirs, problems = _asset_dirs(root, manifest)
    for tag, attributes in ASSET_FILE_ATTRIBUTES.items():
        for element in root.iter(tag):
            for attr in attributes:
                ref = element.get(attr)
                base = dirs[tag]
                if ref is None or (base is None and not _names_its_folder(ref)):
                    continue  # its folder outside the package is the problem reported
                where = f"<{tag} {attr}={ref!r}>"
                found = _asset_file(manifest, tag, ref, where, base)
                if isinstance(found, Path):
                    element.set(attr, str(found.resolve()))
                else:
                    problems.append(found)
    return problems


def _names_its_folder(ref: str) -> bool:
    """A reference that is not relative to ``meshdir`` / ``texturedir``."""
    return ref.startswith((PACKAGE_SCHEME, "file://")) or Path(ref).is_absolute()


def _asset_file(
    manifest: Manifest, tag: str, ref: str, where: str, base: Path | None
) -> ModelProblem | Path:
    """The file ``ref`` of a ``tag`` element, or the problem with it."""
    source = str(manifest.model_file)
    candidates = _resolve(manifest, ref, base)
    if not candidates:
        return ModelProblem(source=source, where=where, reason=outside_reason("the file"))
    found = next((p for p in candidates if p.is_file()), None)
    if found is None:
        tried = ", ".join(str(p) for p in candidates)
        return ModelProblem(
            source=source, where=where, reason=f"{tag} file not found (tried {tried})"
        )
    too_big = size_problem(source, where, f"the {tag} file", found, LIMITS.asset_file_bytes)
    if too_big is None and tag in ("texture", "hfield"):
        too_big = image_problem(source, where, f"the {tag} image", found)
    if too_big is not None:
        return too_big
    try:
        with found.open("rb") as handle:
            handle.read(1)
    except OSError as exc:
        return ModelProblem(
            source=source, where=where, reason=f"{tag} file not readable: {exc}"
        )
    return found


def load_spec(manifest: Manifest) -> mujoco.MjSpec:
    """The model file as an editable MuJoCo spec (visual meshes kept, nothing fused)."""
    return load_spec_with_notes(manifest)[0]


def load_spec_with_notes(manifest: Manifest) -> tuple[mujoco.MjSpec, list[ModelProblem]]:
    """:func:`load_spec` and the notes on what of the file was left out (see the module)."""
    root = _parse(manifest)
    counted = count_problems(str(manifest.model_file), root)
    if counted:
        raise ModelError(counted)
    notes, problems = _scene_notes(manifest, root)
    problems += _check_meshes(manifest, root)
    if problems:
        raise ModelError(problems)
    is_urdf = root.tag == "robot"
    if not is_urdf and root.tag != "mujoco":
        raise ModelError(
            [
                ModelProblem(
                    source=str(manifest.model_file),
                    where=f"<{root.tag}>",
                    reason="expected a URDF <robot> or an MJCF <mujoco> file",
                )
            ]
        )
    if is_urdf:
        for old in root.findall("mujoco"):
            root.remove(old)
        extension = ET.SubElement(root, "mujoco")
        ET.SubElement(
            extension,
            "compiler",
            {
                "strippath": "false",
                "discardvisual": "false",
                "fusestatic": "false",
                "balanceinertia": "true",
            },
        )
    text = ET.tostring(root, encoding="unicode")
    try:
        spec = mujoco.MjSpec.from_string(text)
        spec.compile()
    except (ValueError, mujoco.FatalError) as exc:
        raise ModelError(
            [
                ModelProblem(
                    source=str(manifest.model_file),
                    where="",
                    reason=f"MuJoCo cannot load the model: {exc}",
                )
            ]
        ) from None
    return spec, notes
