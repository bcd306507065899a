"""The stub robot controller: a real robot program on the robot API and GameController protocols.

``python -m robot.stub BEHAVIOUR`` (the stub image's entrypoint) with BEHAVIOUR ``striker``,
``goalie``, ``idle`` or a fault mode (``crash-after SECONDS``, ``ignore-sigterm``, ``flood``,
``fill-logs``). ``python -m benchmarks stub`` measures the striker in-process.
"""

from __future__ import annotations

from robot.stub.behaviour import Action, GameInfo, Role, decide
from robot.stub.controller import Sensors, StubController
from robot.stub.errors import StubConfigError, StubConnectionError, StubError
from robot.stub.options import Behaviour, RobotEnv, StubOptions, parse_args, read_env
from robot.stub.world_model import WorldModel

__all__ = [
    "Action",
    "Behaviour",
    "GameInfo",
    "RobotEnv",
    "Role",
    "Sensors",
    "StubConfigError",
    "StubConnectionError",
    "StubController",
    "StubError",
    "StubOptions",
    "WorldModel",
    "decide",
    "parse_args",
    "read_env",
]
