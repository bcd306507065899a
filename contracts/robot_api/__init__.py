"""The HLVS robot API messages: ``messages.proto`` (proto3, no package, the league's field names
and numbers) and its generated ``messages_pb2`` module."""

__all__: list[str] = []  # the generated messages_pb2 is the face
