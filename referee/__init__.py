"""GameController, team mirror and automatic referee of hlvs-runner (stdlib and numpy only)."""

from __future__ import annotations

from referee.errors import IllegalTransition, ProtocolError, RefereeError, ScenarioError
from referee.field import ADULT_FIELD, KID_FIELD, FieldClass, FieldGeometry, field_for
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

__all__ = [
    "ADULT_FIELD",
    "BallState",
    "BodyPart",
    "FieldClass",
    "FieldGeometry",
    "IllegalTransition",
    "KID_FIELD",
    "PlaceBall",
    "ProtocolError",
    "RefereeError",
    "RefereeEvent",
    "RemoveRobot",
    "RestoreRobot",
    "RobotId",
    "RobotState",
    "ScenarioError",
    "SetLimp",
    "TeamColor",
    "TeleportRobot",
    "WorldCommand",
    "WorldSnapshot",
    "field_for",
]
