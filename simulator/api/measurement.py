"""A step's measurement of one robot as it goes on the wire, and the plan of its due regular
sensors.

:class:`Measurement` holds the encoded regular sensors beside a protobuf header made only when a
message or a camera needs it (:func:`header_bytes` hand-encodes the plain one); :class:`DuePlan`
is the due sensors' names, wire layout and value sources, one object per robot and name list
reused every step; :class:`CameraJob` an image owed to a measurement.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from contracts import RobotId
from contracts.robot_api import messages_pb2 as pb
from simulator.api.encode import SensorLayout, varint
from simulator.api.framing import HEADER

CAMERAS_TAG = b"\x32"  # SensorMeasurements.cameras: field 6, length-delimited
IMAGE_TAG = b"\x2a"  # CameraMeasurement.image: field 5, length-delimited


@dataclass(slots=True)
class CameraJob:
    """A camera image owed to a measurement of this robot: ``measurement`` holds the camera's
    name, size and quality, ``image`` the rendered bytes once they are in."""

    robot: RobotId
    name: str
    width: int
    height: int
    time_ms: int
    measurement: pb.CameraMeasurement
    image: bytes | None = None

    def field(self) -> tuple[bytes, ...]:
        """The wire bytes of this camera as one ``cameras`` field of ``SensorMeasurements``:
        the camera's other fields as protobuf writes them, then the image field, the image
        itself left as its own part, so that it is copied once, into the frame. (Setting a
        230 kB image on a protobuf message and serializing it took 127-150 us a frame; this
        takes about 9 us.)"""
        meta = self.measurement.SerializeToString()
        image = self.image
        if not image:  # none yet (or empty: proto3 writes no empty field)
            return (CAMERAS_TAG + varint(len(meta)) + meta,)
        image_len = varint(len(image))
        body = len(meta) + len(IMAGE_TAG) + len(image_len) + len(image)
        return (CAMERAS_TAG + varint(body) + meta + IMAGE_TAG + image_len, image)


class Measurement:
    """One step's measurement: ``time``, ``real_time``, the encoded regular ``sensors`` and the
    camera ``jobs``. The protobuf ``header`` (time, real_time, messages) is only made when a
    message or a camera needs it; otherwise :meth:`head` is hand-encoded. The cameras follow
    the header on the wire (:meth:`CameraJob.field`: field 6, after the header's fields 1 to 3,
    where protobuf itself would write them). ``frame``: the
    whole framed message (length prefix, head, sensors) when the step's batch built it (a
    measurement without header), else None."""

    __slots__ = ("time", "real_time", "_sensors", "jobs", "frame", "_header")

    def __init__(self, time: int, real_time: int, sensors: bytes = b"") -> None:
        self.time = time
        self.real_time = real_time
        self._sensors: bytes | None = sensors
        self.jobs: list[CameraJob] = []
        self.frame: bytes | None = None
        self._header: pb.SensorMeasurements | None = None

    @property
    def sensors(self) -> bytes:
        """The encoded regular sensors (cut from ``frame`` when only the frame was built)."""
        if self._sensors is None:
            assert self.frame is not None
            self._sensors = self.frame[HEADER.size + len(self.head()) :]
        return self._sensors

    @sensors.setter
    def sensors(self, value: bytes) -> None:
        self._sensors = value

    def set_frame(self, frame: bytes) -> None:
        """The whole framed message of a measurement without header (its sensors are cut
        from it when asked for)."""
        self.frame = frame
        self._sensors = None

    @property
    def plain(self) -> bool:
        """No header: no message and no camera (the head is :func:`header_bytes`)."""
        return self._header is None

    @property
    def header(self) -> pb.SensorMeasurements:
        if self._header is None:
            self._header = pb.SensorMeasurements(time=self.time, real_time=self.real_time)
        return self._header

    @property
    def message_count(self) -> int:
        return 0 if self._header is None else len(self._header.messages)

    def add_camera(self, job: CameraJob) -> None:
        """A camera image owed to this measurement (its header is made: a measurement with a
        camera is never plain)."""
        _ = self.header
        self.jobs.append(job)

    def head_parts(self) -> list[bytes]:
        """:meth:`head` in parts: the header, then each camera's field with its image as a
        part of its own (joined once, into the frame)."""
        if self._header is None:
            return [header_bytes(self.time, self.real_time)]
        parts = [self._header.SerializeToString()]
        for job in self.jobs:
            parts.extend(job.field())
        return parts

    def head(self) -> bytes:
        """The serialized header and cameras (everything but the regular sensors)."""
        parts = self.head_parts()
        return parts[0] if len(parts) == 1 else b"".join(parts)

    def size(self) -> int:
        return sum(map(len, self.head_parts())) + len(self.sensors)

    def payload(self) -> bytes:
        return self.head() + self.sensors

    def parsed(self) -> pb.SensorMeasurements:
        """The whole measurement as a message (for tests and tools; slow path)."""
        msg = pb.SensorMeasurements()
        msg.ParseFromString(self.payload())
        return msg


_last_head: list[tuple[int, int, bytes]] = [(-1, -1, b"")]  # all robots of a step share it


def header_bytes(time_ms: int, real_time_ms: int) -> bytes:
    """``SensorMeasurements(time=time_ms, real_time=real_time_ms).SerializeToString()``."""
    last = _last_head[0]
    if last[0] == time_ms and last[1] == real_time_ms:
        return last[2]
    if not (0 <= time_ms < 2**32 and 0 <= real_time_ms < 2**64):  # protobuf says what is wrong
        return bytes(
            pb.SensorMeasurements(time=time_ms, real_time=real_time_ms).SerializeToString()
        )
    head = (b"\x08" + varint(time_ms) if time_ms else b"") + (
        b"\x10" + varint(real_time_ms) if real_time_ms else b""
    )
    _last_head[0] = (time_ms, real_time_ms, head)
    return head


class DuePlan:
    """The due regular sensors of a measurement: ``names`` in message order, their wire
    ``layout`` and, when the world has the batch form, where their values come from
    (``sources``, :meth:`simulator.world.World.sensor_sources`). Compared and hashed by
    identity: one object per robot and name list, reused every step."""

    __slots__ = ("names", "layout", "sources")

    def __init__(self, names: tuple[str, ...], layout: SensorLayout, sources: Any) -> None:
        self.names = names
        self.layout = layout
        self.sources = sources
