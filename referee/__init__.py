"""GameController, team mirror and automatic referee of hlvs-runner (stdlib and numpy only)."""

from __future__ import annotations

from referee.autoref import Referee
from referee.clock import Clock, FakeClock, SystemClock
from referee.config import (
    GameType,
    NetworkConfig,
    PlayerConfig,
    Pose,
    RefereeConfig,
    TeamConfig,
    TimingConfig,
)
from referee.errors import IllegalTransition, ProtocolError, RefereeError, ScenarioError
from referee.field import ADULT_FIELD, KID_FIELD, FieldClass, FieldGeometry, field_for
from referee.gamecontroller import (
    Card,
    GameController,
    GameState,
    Penalty,
    SecondaryState,
)
from referee.mirror import MirrorStats, TeamMirror
from referee.net import GameControllerNetwork, NetworkStats, RobotLink
from referee.snapshot import (
    BallState,
    BodyPart,
    PlaceBall,
    RefereeEvent,
    RemoveRobot,
    RestoreRobot,
    RobotId,
    RobotState,
    SetLimp,
    TeamColor,
    TeleportRobot,
    WorldCommand,
    WorldSnapshot,
)
from referee.wire import (
    GameControlData,
    ReturnData,
    ReturnMessage,
    decode_game_state,
    decode_return,
    encode_game_state,
    encode_return,
)

__all__ = [
    "ADULT_FIELD",
    "BallState",
    "BodyPart",
    "Card",
    "Clock",
    "decode_game_state",
    "decode_return",
    "encode_game_state",
    "encode_return",
    "FakeClock",
    "field_for",
    "FieldClass",
    "FieldGeometry",
    "GameControlData",
    "GameController",
    "GameControllerNetwork",
    "GameState",
    "GameType",
    "IllegalTransition",
    "KID_FIELD",
    "MirrorStats",
    "NetworkConfig",
    "NetworkStats",
    "Penalty",
    "PlaceBall",
    "PlayerConfig",
    "Pose",
    "ProtocolError",
    "Referee",
    "RefereeConfig",
    "RefereeError",
    "RefereeEvent",
    "RemoveRobot",
    "RestoreRobot",
    "ReturnData",
    "ReturnMessage",
    "RobotId",
    "RobotLink",
    "RobotState",
    "ScenarioError",
    "SecondaryState",
    "SetLimp",
    "SystemClock",
    "TeamColor",
    "TeamConfig",
    "TeamMirror",
    "TeleportRobot",
    "TimingConfig",
    "WorldCommand",
    "WorldSnapshot",
]
