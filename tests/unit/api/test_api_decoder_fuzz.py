"""The frame decoder and the request parser never fail on arbitrary bytes but with typed errors."""

from __future__ import annotations

from google.protobuf.message import DecodeError
from hypothesis import given
from hypothesis import strategies as st

from contracts.robot_api import messages_pb2 as pb
from simulator.api import FrameDecoder, FramingError


@given(st.lists(st.binary(max_size=200), max_size=10))
def test_decoder_survives_any_byte_chunks(chunks: list[bytes]) -> None:
    decoder = FrameDecoder(limit=1000)
    try:
        for chunk in chunks:
            for frame in decoder.feed(chunk):
                assert 0 <= len(frame) <= 1000
                try:
                    pb.ActuatorRequests().ParseFromString(frame)
                except DecodeError:
                    pass
    except FramingError as exc:
        assert exc.length > 1000


@given(st.binary(max_size=300))
def test_parse_raises_only_decode_error(data: bytes) -> None:
    try:
        request = pb.ActuatorRequests()
        request.ParseFromString(data)
    except DecodeError:
        return
    assert request.ByteSize() >= 0
