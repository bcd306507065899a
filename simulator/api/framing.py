"""Robot API framing: 4-byte big-endian length, then a serialized protobuf message.

The decoder is fed arbitrary byte chunks as they arrive on a socket and yields complete
payloads; a partial frame stays buffered until the rest arrives. A length of 0 is an empty
message (an empty ``ActuatorRequests``, which clients do send): it is yielded as ``b""`` and
the caller skips it, as the league's player (``player.cpp``) does. An announced length above
:data:`MAX_FRAME_BYTES` (the reference client's ``max_answer_size``) means the stream is out of
sync: :class:`FramingError` is raised and the connection must be closed.
"""

from __future__ import annotations

import struct

from simulator.errors import ApiError

HEADER = struct.Struct(">I")
MAX_FRAME_BYTES = 1920 * 1080 * 3 + 1000
WELCOME = b"Welcome\0"
REFUSED = b"Refused\0"


class FramingError(ApiError):
    """The byte stream does not follow the length-prefixed framing."""

    def __init__(self, *, length: int, limit: int) -> None:
        self.length = length
        self.limit = limit
        super().__init__(f"announced frame length {length} is out of range 0..{limit}")


def encode_frame(payload: bytes) -> bytes:
    return HEADER.pack(len(payload)) + payload


class FrameDecoder:
    """Incremental frame decoder. Not thread-safe; one per connection."""

    __slots__ = ("_buffer", "_limit", "held")

    def __init__(self, *, limit: int = MAX_FRAME_BYTES) -> None:
        self._buffer = bytearray()
        self._limit = limit
        # the last feed stopped at ``max_frames``: complete frames may be buffered still
        self.held = False

    @property
    def buffered(self) -> int:
        return len(self._buffer)

    def feed(self, data: bytes, max_frames: int = 1 << 62) -> list[bytes]:
        """Add received bytes; return the payloads of the frames now complete, in order
        (``b""`` for an empty frame), at most ``max_frames`` of them: the others stay buffered
        (``held``) for a later call, which may add no bytes."""
        buffer = self._buffer
        if not buffer and len(data) >= 4 and max_frames > 0:  # the usual case: one frame
            (length,) = HEADER.unpack_from(data)
            if len(data) == 4 + length and 0 < length <= self._limit:
                self.held = False
                return [data[4:]]
        buffer += data
        frames: list[bytes] = []
        offset = 0
        size = len(buffer)
        held = False
        while size - offset >= 4:
            if len(frames) >= max_frames:
                held = True
                break
            (length,) = HEADER.unpack_from(buffer, offset)
            if length > self._limit:
                del buffer[:offset]
                raise FramingError(length=length, limit=self._limit)
            end = offset + 4 + length
            if end > size:
                break
            frames.append(bytes(buffer[offset + 4 : end]))
            offset = end
        if offset:
            del buffer[:offset]
        self.held = held
        return frames
