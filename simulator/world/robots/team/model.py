"""A team robot model as the world uses it: the same surface as the built-in models."""

from __future__ import annotations

import copy
import math
import threading
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from pathlib import Path

from simulator.errors import ModelProblem
from simulator.world.robots.devices import DeviceNames
from simulator.world.robots.model import CameraSpec, MotorLookup, MotorSpec, RobotMjcf
from simulator.world.robots.team.build import PREFIX, Template, build_template
from simulator.world.robots.team.devices import device_names
from simulator.world.robots.team.entries import JerseyEntry, Manifest
from simulator.world.robots.team.manifest import load_manifest
from simulator.world.robots.team.servos import motor_spec
from simulator.world.robots.team.source import load_spec_with_notes

VISUAL = "/visual:"


@dataclass(frozen=True, slots=True, kw_only=True)
class TeamRobotModel(MotorLookup):
    """A model package loaded for the world: motors, sensors and the MJCF of one robot."""

    name: str  # the package's folder, as the match spec names it
    field_class: str
    manifest: Manifest
    motors: tuple[MotorSpec, ...]
    camera: CameraSpec
    force_sensors: tuple[str, ...]
    template: Template
    notes: tuple[ModelProblem, ...] = ()  # what of the model file the world leaves out

    @property
    def standing_height_m(self) -> float:
        return self.template.standing_height_m

    @property
    def devices(self) -> DeviceNames:
        """The names the robot answers to on the robot API, as its manifest gives them."""
        return device_names(self.manifest)

    @property
    def wears_jersey(self) -> bool:
        """Whether the manifest says where the robot wears the team's jersey."""
        return self.manifest.jersey is not None

    @property
    def standing_pose_rad(self) -> tuple[float, ...]:
        """Joint positions (``motor_names`` order) the robot stands in when placed."""
        pose = self.manifest.standing_pose_rad
        return tuple(pose.get(m.name, 0.0) for m in self.motors)

    def mjcf(
        self,
        *,
        prefix: str,
        rgba: str,
        contype: int,
        conaffinity: int,
        pose: tuple[float, float, float],
        jersey: str | None = None,
    ) -> RobotMjcf:
        """The robot's body at ``pose`` (x, y, yaw), its servos and sensors, named by ``prefix``;
        collision geoms get ``contype``/``conaffinity``, the marker and the trunk's visuals the
        team colour ``rgba``. The model keeps its own meshes; ``jersey`` (the material of the
        team's shirt) is worn where the manifest's ``jersey`` says (:meth:`wears_jersey`)."""
        body = copy.deepcopy(self.template.body)
        x, y, yaw = pose
        body.set("pos", f"{x:.9g} {y:.9g} {self.standing_height_m:.9g}")
        body.set("quat", f"{math.cos(yaw / 2):.9g} 0 0 {math.sin(yaw / 2):.9g}")
        for element in body.iter("body"):
            colour_visuals = element.get("name") == self.template.trunk_body
            for geom in element.findall("geom"):
                name = geom.get("name", "")
                if VISUAL in name:
                    if colour_visuals or name.endswith("/visual:marker"):
                        geom.set("rgba", rgba)
                    continue
                geom.set("contype", str(contype))
                geom.set("conaffinity", str(conaffinity))
        if jersey is not None and self.manifest.jersey is not None:
            _add_jersey(body, self.manifest.jersey, self.template.root_body, jersey)
        text = ET.tostring(body, encoding="unicode").replace(PREFIX, prefix)
        return RobotMjcf(
            body=text,
            actuators=self.template.actuators.replace(PREFIX, prefix),
            sensors=self.template.sensors.replace(PREFIX, prefix),
            assets=self.template.assets,
            asset_key=self.template.key,
        )


JERSEY_HALF_THICKNESS_M = 0.002


def _add_jersey(body: ET.Element, entry: JerseyEntry, root_link: str, material: str) -> None:
    """The jersey's plates as visual boxes of ``material`` in the body of ``entry.link``: each
    turned so that the texture's rows run down the link's z and the number reads from in front
    of the plate (as the built-in robots' plates,
    :func:`simulator.world.robots.humanoid.build_humanoid`)."""
    name = f"{PREFIX}/torso" if entry.link == root_link else f"{PREFIX}/link:{entry.link}"
    wearer = next(b for b in body.iter("body") if b.get("name") == name)
    for side, plate, axes in (("front", entry.front, "0 1 0 0 0 1"),
                              ("back", entry.back, "0 -1 0 0 0 1")):  # fmt: skip
        if plate is None:
            continue
        width, height = plate.size_m
        ET.SubElement(wearer, "geom", {
            "name": f"{PREFIX}/visual:jersey_{side}", "type": "box",
            "pos": " ".join(f"{v:.9g}" for v in plate.pos_m), "xyaxes": axes,
            "size": f"{width / 2:.9g} {height / 2:.9g} {JERSEY_HALF_THICKNESS_M:g}",
            "material": material, "mass": "0", "contype": "0", "conaffinity": "0", "group": "1",
        })  # fmt: skip


_CACHE: dict[Path, TeamRobotModel] = {}
_LOCK = threading.Lock()


def load_team_model(folder: Path) -> TeamRobotModel:
    """The model package in ``folder`` (cached per process). Raises ModelError."""
    folder = folder.resolve()
    with _LOCK:
        cached = _CACHE.get(folder)
        if cached is not None:
            return cached
        manifest = load_manifest(folder)
        key = manifest.name or folder.name
        spec, notes = load_spec_with_notes(manifest)
        template = build_template(spec, manifest, key=key)
        camera = manifest.cameras[0]
        model = TeamRobotModel(
            name=str(folder),
            field_class=manifest.field_class,
            manifest=manifest,
            motors=tuple(
                replace(
                    motor_spec(m, manifest),
                    lower_rad=template.ranges[m.name][0],
                    upper_rad=template.ranges[m.name][1],
                )
                for m in manifest.motors
            ),
            camera=CameraSpec(
                name=camera.name, width=camera.width, height=camera.height, fov_rad=camera.fov_rad
            ),
            force_sensors=tuple(manifest.force_sensors),
            template=template,
            notes=tuple(notes),
        )
        _CACHE[folder] = model
        return model
