"""The typed vocabulary shared by the orchestrator, the simulator, the referee and robot code.

Standard library and protobuf only, so every process (a team's robot image included) can import
it; installs on its own from ``contracts/pyproject.toml``.

- :mod:`contracts.match_spec`: ``match_spec.json`` (orchestrator -> simulator).
- :mod:`contracts.sim_result`: ``sim_result.json`` (simulator -> orchestrator).
- :mod:`contracts.files`: the names of the files the processes hand to each other.
- :mod:`contracts.ids`: ``TeamColor``, ``RobotId``; :mod:`contracts.geometry`: ``Pose`` and its
  mirror; :mod:`contracts.field`: the field dimensions.
- :mod:`contracts.robot_api`: the robot API's protobuf messages (the league's ``messages.proto``).
- :mod:`contracts.codec`: the one JSON reader/writer; every top-level document has a ``version``
  and ``from_json`` refuses versions it does not know (:class:`contracts.errors.UnknownVersion`).
"""

from contracts.lazy import lazy_exports

__all__ = ["lazy_exports"]
