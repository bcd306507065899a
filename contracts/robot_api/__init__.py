"""The HLVS robot API messages: ``messages.proto`` (proto3, no package, the league's field names
and numbers) and its generated ``messages_pb2`` module."""

from typing import TYPE_CHECKING

from contracts.lazy import lazy_exports

if TYPE_CHECKING:
    from contracts.robot_api import messages_pb2

__all__ = ["messages_pb2"]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "contracts.robot_api": ("messages_pb2",),
    })
