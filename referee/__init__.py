"""GameController, team mirror and automatic referee of hlvs-runner (stdlib and numpy only).

Use::

    referee = Referee(config=RefereeConfig(...), log_dir=out)   # clock: SystemClock by default
    referee.start_network()          # optional: RGme on 3838, RGrt on 3939, team mirror on 3737
    for each 8 ms step:              # the world applies the commands before the next step
        commands = referee.step(world.snapshot())
    referee.game_state, referee.finished, referee.result(), referee.events
    referee.close()

``referee.waiting_for_wall_clock`` is True during the league's real-time waits (before the first
READY, between periods), so a lockstep runtime can hold instead of stepping. Rules live in
``referee.rules`` (one module per rule); scenarios in ``tests/scenarios/<rule>/<case>.yaml``.
"""

from __future__ import annotations

from contracts import (
    ADULT_FIELD,
    KID_FIELD,
    FieldClass,
    FieldGeometry,
    GameControlData,
    GameType,
    PlayerSpec,
    Pose,
    ReturnData,
    ReturnMessage,
    RobotId,
    TeamColor,
    TeamSpec,
    decode_game_state,
    decode_return,
    encode_game_state,
    encode_return,
    field_for,
)
from referee.autoref import Referee
from referee.clock import Clock, FakeClock, SystemClock
from referee.config import NetworkConfig, RefereeConfig, TimingConfig
from referee.errors import IllegalTransition, ProtocolError, RefereeError, ScenarioError
from referee.gamecontroller import (
    Card,
    GameController,
    GameState,
    Penalty,
    SecondaryState,
)
from referee.league_scenario import (
    LeagueAction,
    LeagueScenario,
    LeagueStep,
    LeagueTarget,
    LeagueTest,
    LeagueTiming,
    load_league_scenario,
    parse_league_scenario,
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
    RobotState,
    SetLimp,
    TeleportRobot,
    Vec3,
    WorldCommand,
    WorldSnapshot,
)
from referee.spoofing import SpoofingLog

__all__ = [
    "ADULT_FIELD",
    "BallState",
    "BodyPart",
    "Card",
    "Clock",
    "FakeClock",
    "FieldClass",
    "FieldGeometry",
    "GameControlData",
    "GameController",
    "GameControllerNetwork",
    "GameState",
    "GameType",
    "IllegalTransition",
    "KID_FIELD",
    "LeagueAction",
    "LeagueScenario",
    "LeagueStep",
    "LeagueTarget",
    "LeagueTest",
    "LeagueTiming",
    "MirrorStats",
    "NetworkConfig",
    "NetworkStats",
    "Penalty",
    "PlaceBall",
    "PlayerSpec",
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
    "SpoofingLog",
    "SystemClock",
    "TeamColor",
    "TeamMirror",
    "TeamSpec",
    "TeleportRobot",
    "TimingConfig",
    "Vec3",
    "WorldCommand",
    "WorldSnapshot",
    "decode_game_state",
    "decode_return",
    "encode_game_state",
    "encode_return",
    "field_for",
    "load_league_scenario",
    "parse_league_scenario",
]
