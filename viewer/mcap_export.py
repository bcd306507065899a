"""``hlvs export REPLAY -o match.mcap``: a replay as MCAP with Foxglove's well-known schemas.

Channels (log and publish times are simulated time, in ns from the start of the match, so that
a team lines them up with its own rosbag2 recordings by the robots' sensor time):

- ``/scene`` ``foxglove.SceneUpdate`` (protobuf), once: one entity per body, frame-locked to
  the body's frame, with its shapes (boxes, spheres, cylinders; capsules as cylinders);
- ``/tf`` ``foxglove.FrameTransforms`` (protobuf), every frame: ``world`` -> each body;
- ``/game_state`` (JSON) when the game state changes; ``/referee/events`` (JSON) one message per
  referee event; ``/robots/<team_number>/api`` (JSON) the robot API statistics samples of
  ``api_stats.jsonl`` (bytes, messages, round trip, connected) when that file is present.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TypedDict

from foxglove_schemas_protobuf.Color_pb2 import Color
from foxglove_schemas_protobuf.CubePrimitive_pb2 import CubePrimitive
from foxglove_schemas_protobuf.CylinderPrimitive_pb2 import CylinderPrimitive
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.Pose_pb2 import Pose
from foxglove_schemas_protobuf.Quaternion_pb2 import Quaternion
from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from foxglove_schemas_protobuf.SpherePrimitive_pb2 import SpherePrimitive
from foxglove_schemas_protobuf.Vector3_pb2 import Vector3
from google.protobuf.message import Message
from google.protobuf.timestamp_pb2 import Timestamp
from mcap.writer import Writer
from mcap_protobuf.schema import build_file_descriptor_set

from simulator import read_stats
from simulator.replay import GeomRecord, ReplayFile, SceneRecord, scene_for
from viewer.errors import ExportError
from viewer.sources import STATS_FILE

WORLD_FRAME = "world"
JSON_SCHEMA = json.dumps({"type": "object"}).encode()


def _ns(ms: float) -> int:
    return int(round(ms * 1_000_000))


def _stamp(ms: float) -> Timestamp:
    ns = _ns(ms)
    return Timestamp(seconds=ns // 1_000_000_000, nanos=ns % 1_000_000_000)


def _pose(pos: list[float], quat: list[float]) -> Pose:
    w, x, y, z = quat
    return Pose(position=Vector3(x=pos[0], y=pos[1], z=pos[2]),
                orientation=Quaternion(x=x, y=y, z=z, w=w))


def _add_shape(entity: SceneEntity, geom: GeomRecord) -> None:
    pose = _pose(geom["pos"], geom["quat"])
    r, g, b, a = geom["rgba"]
    color = Color(r=r, g=g, b=b, a=a)
    s = geom["size"]
    kind = geom["type"]
    if kind in ("box", "plane"):
        size = Vector3(x=2 * s[0], y=2 * s[1], z=2 * s[2] if kind == "box" else 0.002)
        entity.cubes.append(CubePrimitive(pose=pose, size=size, color=color))
    elif kind in ("sphere", "ellipsoid"):
        size = Vector3(x=2 * s[0], y=2 * s[0 if kind == "sphere" else 1],
                       z=2 * s[0 if kind == "sphere" else 2])
        entity.spheres.append(SpherePrimitive(pose=pose, size=size, color=color))
    else:  # cylinder, capsule (a cylinder as long as the capsule)
        length = 2 * s[1] + (2 * s[0] if kind == "capsule" else 0.0)
        entity.cylinders.append(CylinderPrimitive(
            pose=pose, size=Vector3(x=2 * s[0], y=2 * s[0], z=length), bottom_scale=1.0,
            top_scale=1.0, color=color))


def scene_update(scene: SceneRecord) -> SceneUpdate:
    bodies = scene["bodies"]
    entities = [
        SceneEntity(timestamp=_stamp(0), frame_id=WORLD_FRAME if i == 0 else name, id=name,
                    frame_locked=True)
        for i, name in enumerate(bodies)
    ]
    for geom in scene["geoms"]:
        if geom["group"] < 3:
            _add_shape(entities[geom["body"]], geom)
    return SceneUpdate(entities=[e for e in entities if e.cubes or e.spheres or e.cylinders])


class _Out:
    def __init__(self, writer: Writer) -> None:
        self.writer = writer
        self.channels: dict[str, int] = {}
        self.messages = 0

    def protobuf_channel(self, topic: str, message: type[Message]) -> None:
        descriptor = message.DESCRIPTOR
        schema = self.writer.register_schema(
            name=descriptor.full_name, encoding="protobuf",
            data=build_file_descriptor_set(message).SerializeToString(),
        )
        self.channels[topic] = self.writer.register_channel(topic, "protobuf", schema)

    def json_channel(self, topic: str) -> None:
        schema = self.writer.register_schema(name=topic.strip("/"), encoding="jsonschema",
                                             data=JSON_SCHEMA)
        self.channels[topic] = self.writer.register_channel(topic, "json", schema)

    def write(self, topic: str, time_ms: float, data: bytes) -> None:
        ns = _ns(time_ms)
        self.writer.add_message(self.channels[topic], log_time=ns, data=data, publish_time=ns)
        self.messages += 1


class ExportSummary(TypedDict):
    messages: int
    channels: int
    duration_s: float


def export_mcap(replay_path: Path, output: Path, *, stats_path: Path | None = None
                ) -> ExportSummary:
    """Write ``replay_path`` as MCAP to ``output``; returns a summary (messages, channels...)."""
    if stats_path is None and (replay_path.parent / STATS_FILE).is_file():
        stats_path = replay_path.parent / STATS_FILE
    with ReplayFile(replay_path) as replay:
        scene = scene_for(replay.header, str(replay_path))
        names = scene["bodies"]
        extra: list[tuple[float, str, bytes]] = [
            (float(e["frame_ms"]), "/referee/events", json.dumps(e, sort_keys=True).encode())
            for e in replay.events
        ]
        if stats_path is not None:
            for sample in read_stats(stats_path):
                for robot, values in sorted(sample.get("robots", {}).items()):
                    payload = {**values, "real_time_s": sample.get("real_time_s"),
                               "real_time_factor": sample.get("real_time_factor")}
                    extra.append((float(sample.get("sim_time_ms", 0)), f"/robots/{robot}/api",
                                  json.dumps(payload, sort_keys=True).encode()))
        extra.sort(key=lambda item: item[0])
        try:
            stream = output.open("wb")
        except OSError as exc:
            raise ExportError(output=str(output), reason=f"cannot write: {exc}") from exc
        with stream:
            writer = Writer(stream)
            writer.start(profile="", library="hlvs-runner")
            out = _Out(writer)
            out.protobuf_channel("/scene", SceneUpdate)
            out.protobuf_channel("/tf", FrameTransforms)
            out.json_channel("/game_state")
            out.json_channel("/referee/events")
            for topic in sorted({topic for _, topic, _ in extra if topic.startswith("/robots/")}):
                out.json_channel(topic)
            out.write("/scene", 0, scene_update(scene).SerializeToString())
            last_game = None
            pending = 0
            for frame in replay.frames():
                t = frame.sim_time_ms
                while pending < len(extra) and extra[pending][0] <= t:
                    out.write(extra[pending][1], extra[pending][0], extra[pending][2])
                    pending += 1
                if frame.game != last_game:
                    out.write("/game_state", t, json.dumps(frame.game, sort_keys=True).encode())
                    last_game = frame.game
                stamp = _stamp(t)
                p = frame.poses.tolist()
                transforms = FrameTransforms(transforms=[
                    FrameTransform(
                        timestamp=stamp, parent_frame_id=WORLD_FRAME, child_frame_id=names[i],
                        translation=Vector3(x=p[i][0], y=p[i][1], z=p[i][2]),
                        rotation=Quaternion(x=p[i][4], y=p[i][5], z=p[i][6], w=p[i][3]),
                    )
                    for i in range(1, len(names))
                ])
                out.write("/tf", t, transforms.SerializeToString())
            for time_ms, topic, data in extra[pending:]:
                out.write(topic, time_ms, data)
            writer.finish()  # type: ignore[no-untyped-call]
        return {"messages": out.messages, "channels": len(out.channels),
                "duration_s": replay.duration_ms / 1000.0}
