"""Reads a team's model file (URDF or MJCF) into a MuJoCo spec, with every mesh path resolved.

URDF from ROS names meshes ``package://<package>/<path>``; they are resolved against the
manifest's ``packages`` (or a folder of that name beside the manifest or the model file), and
relative paths against the model file's folder. A mesh that is missing or unreadable is a
:class:`ModelProblem` naming the element and the path tried.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco

from simulator.errors import ModelError, ModelProblem
from simulator.world.robots.team.manifest import Manifest

PACKAGE_SCHEME = "package://"


def _resolve(manifest: Manifest, ref: str) -> list[Path]:
    """Candidate files for a mesh reference, in the order they are tried."""
    base = manifest.model_file.parent
    if ref.startswith(PACKAGE_SCHEME):
        package, _, rest = ref[len(PACKAGE_SCHEME) :].partition("/")
        roots = [manifest.packages[package]] if package in manifest.packages else []
        roots += [manifest.folder / package]
        roots += [parent / package for parent in base.parents if parent != manifest.folder]
        roots += [p for p in base.parents if p.name == package]
        return [root / rest for root in dict.fromkeys(roots)]
    if ref.startswith("file://"):
        ref = ref[len("file://") :]
    path = Path(ref)
    return [path] if path.is_absolute() else [base / path]


def _parse(manifest: Manifest) -> ET.Element:
    source = str(manifest.model_file)
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
    """Rewrite every mesh ``filename``/``file`` to an absolute path; report missing ones."""
    problems = []
    source = str(manifest.model_file)
    for element in root.iter("mesh"):
        attr = "filename" if "filename" in element.attrib else "file"
        ref = element.get(attr)
        if ref is None:
            continue
        candidates = _resolve(manifest, ref)
        found = next((p for p in candidates if p.is_file()), None)
        if found is None:
            tried = ", ".join(str(p) for p in candidates)
            problems.append(
                ModelProblem(
                    source=source,
                    where=f"<mesh {attr}={ref!r}>",
                    reason=f"mesh file not found (tried {tried})",
                )
            )
            continue
        try:
            with found.open("rb") as handle:
                handle.read(1)
        except OSError as exc:
            problems.append(
                ModelProblem(
                    source=source,
                    where=f"<mesh {attr}={ref!r}>",
                    reason=f"mesh file not readable: {exc}",
                )
            )
            continue
        element.set(attr, str(found.resolve()))
    return problems


def load_spec(manifest: Manifest) -> mujoco.MjSpec:
    """The model file as an editable MuJoCo spec (visual meshes kept, nothing fused)."""
    root = _parse(manifest)
    problems = _check_meshes(manifest, root)
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
    else:
        compiler = root.find("compiler")
        if compiler is None:
            compiler = ET.SubElement(root, "compiler")
        compiler.set("meshdir", str(manifest.model_file.parent))
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
    return spec
