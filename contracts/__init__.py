"""The typed vocabulary shared by the orchestrator, the simulator, the referee and robot code.

Standard library and protobuf only, so every process (a team's robot image included) can import
it; installs on its own from ``contracts/pyproject.toml``.

- :mod:`contracts.match_spec`: ``match_spec.json`` (orchestrator -> simulator).
- :mod:`contracts.sim_result`: ``sim_result.json`` (simulator -> orchestrator).
- :mod:`contracts.files`: the names of the files the processes hand to each other.
- :mod:`contracts.ids`: ``TeamColor``, ``RobotId``; :mod:`contracts.geometry`: ``Pose`` and its
  mirror; :mod:`contracts.field`: the field dimensions.
- :mod:`contracts.robot_api`: the robot API's protobuf messages (the league's ``messages.proto``).
- :mod:`contracts.webhooks`: how a signed webhook is signed and checked.
- :mod:`contracts.process`: a process named so that others tell surely that it ended (host,
  pid namespace, pid, start time): the owners of matches and of environment remotes.
- :mod:`contracts.codec`: the one JSON reader/writer; every top-level document has a ``version``
  and ``from_json`` refuses versions it does not know (:class:`contracts.errors.UnknownVersion`).

Other packages import the names of ``__all__`` from the package (``from contracts import
MatchSpec``); each is imported on first use (:func:`contracts.lazy.lazy_exports`), so a process
loads only the modules it uses.
"""

from typing import TYPE_CHECKING

from contracts.lazy import lazy_exports

if TYPE_CHECKING:
    from contracts import files, gamecontroller, process, telemetry, webhooks
    from contracts.codec import from_data, to_data
    from contracts.errors import ContractError, ProtocolError
    from contracts.field import ADULT_FIELD, KID_FIELD, FieldClass, FieldGeometry, field_for
    from contracts.files import GPU_ENVIRONMENT
    from contracts.gamecontroller import (
        DROPBALL_TEAM,
        GC_DATA_PORT,
        GC_RETURN_PORT,
        MAX_PLAYERS,
        GameControlData,
        GameState,
        GameTypeCode,
        Penalty,
        ReturnData,
        ReturnMessage,
        RobotInfo,
        SecondaryState,
        TeamColourCode,
        TeamInfo,
        decode_game_state,
        decode_return,
        encode_game_state,
        encode_return,
        send_period_s,
        with_packet_number,
    )
    from contracts.geometry import StartingPose
    from contracts.ids import RobotId, TeamColor
    from contracts.jsontypes import (
        HugeInteger,
        JSONObject,
        huge_integer_reason,
        huge_integers,
        parse_int,
    )
    from contracts.match_results import (
        AdmissionRecord,
        Failure,
        FailureClass,
        Forfeit,
        LogFolderCopy,
        MatchLimits,
        MatchReport,
        MatchResults,
        NeededAvailable,
        RobotResult,
        Salvage,
        SalvagedRobot,
        Scalar,
    )
    from contracts.match_spec import (
        Color,
        GameType,
        GameTypeName,
        MatchSpec,
        NetworkSpec,
        PlayerSpec,
        Pose,
        SteppingMode,
        TeamSpec,
        TimingSpec,
    )
    from contracts.sim_result import (
        MAX_RENDER_PROCESSES,
        PlayRecord,
        RobotApiStats,
        SimResult,
        SpoofingAttempt,
    )
    from contracts.tally import Tally
    from contracts.telemetry import (
        EventRecord,
        GameStateRecord,
        PenaltyRecord,
        RobotTraffic,
        StateMessage,
        TrafficSample,
    )
    from contracts.timing import (
        ADULT_SCRIMMAGE,
        ENVIRONMENT,
        MIN_PLAYING_S,
        MIN_READY_S,
        OFFICIAL,
        REMOVAL_PENALTY_S,
        SCRIMMAGE,
        SET_TO_PLAY_S,
        TEST_MATCH,
        TimingError,
        fit_ready,
        played_enough,
        timing_problem,
    )

__all__ = [
    "ADULT_FIELD",
    "ADULT_SCRIMMAGE",
    "AdmissionRecord",
    "Color",
    "ContractError",
    "DROPBALL_TEAM",
    "ENVIRONMENT",
    "EventRecord",
    "Failure",
    "FailureClass",
    "FieldClass",
    "FieldGeometry",
    "Forfeit",
    "GC_DATA_PORT",
    "GC_RETURN_PORT",
    "GPU_ENVIRONMENT",
    "GameControlData",
    "GameState",
    "GameStateRecord",
    "GameType",
    "GameTypeCode",
    "GameTypeName",
    "HugeInteger",
    "JSONObject",
    "KID_FIELD",
    "LogFolderCopy",
    "MAX_PLAYERS",
    "MAX_RENDER_PROCESSES",
    "MIN_PLAYING_S",
    "MIN_READY_S",
    "REMOVAL_PENALTY_S",
    "MatchLimits",
    "MatchReport",
    "MatchResults",
    "MatchSpec",
    "NeededAvailable",
    "NetworkSpec",
    "OFFICIAL",
    "Penalty",
    "PenaltyRecord",
    "PlayRecord",
    "PlayerSpec",
    "Pose",
    "ProtocolError",
    "ReturnData",
    "ReturnMessage",
    "RobotApiStats",
    "RobotId",
    "RobotInfo",
    "RobotResult",
    "RobotTraffic",
    "SCRIMMAGE",
    "SET_TO_PLAY_S",
    "Salvage",
    "SalvagedRobot",
    "Scalar",
    "SecondaryState",
    "SimResult",
    "SpoofingAttempt",
    "StartingPose",
    "StateMessage",
    "SteppingMode",
    "TEST_MATCH",
    "Tally",
    "TeamColor",
    "TeamColourCode",
    "TeamInfo",
    "TeamSpec",
    "TimingError",
    "TimingSpec",
    "TrafficSample",
    "decode_game_state",
    "decode_return",
    "encode_game_state",
    "encode_return",
    "field_for",
    "files",
    "fit_ready",
    "from_data",
    "gamecontroller",
    "lazy_exports",
    "huge_integer_reason",
    "huge_integers",
    "parse_int",
    "played_enough",
    "process",
    "telemetry",
    "timing_problem",
    "to_data",
    "send_period_s",
    "webhooks",
    "with_packet_number",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "contracts": ("files", "gamecontroller", "process", "telemetry", "webhooks"),
        "contracts.codec": ("from_data", "to_data"),
        "contracts.errors": ("ContractError", "ProtocolError"),
        "contracts.field": ("ADULT_FIELD", "KID_FIELD", "FieldClass", "FieldGeometry", "field_for"),
        "contracts.files": ("GPU_ENVIRONMENT",),
        "contracts.gamecontroller": (
            "DROPBALL_TEAM", "GC_DATA_PORT", "GC_RETURN_PORT", "MAX_PLAYERS", "GameControlData",
            "GameState", "GameTypeCode", "Penalty", "ReturnData", "ReturnMessage", "RobotInfo",
            "SecondaryState", "TeamColourCode", "TeamInfo", "decode_game_state", "decode_return",
            "encode_game_state", "encode_return", "send_period_s", "with_packet_number",
        ),
        "contracts.geometry": ("StartingPose",),
        "contracts.ids": ("RobotId", "TeamColor"),
        "contracts.jsontypes": (
            "HugeInteger", "JSONObject", "huge_integer_reason", "huge_integers", "parse_int",
        ),
        "contracts.match_results": (
            "AdmissionRecord", "Failure", "FailureClass", "Forfeit", "LogFolderCopy", "MatchLimits",
            "MatchReport", "MatchResults", "NeededAvailable", "RobotResult", "Salvage",
            "SalvagedRobot", "Scalar",
        ),
        "contracts.match_spec": (
            "Color", "GameType", "GameTypeName", "MatchSpec", "NetworkSpec", "PlayerSpec", "Pose",
            "SteppingMode", "TeamSpec", "TimingSpec",
        ),
        "contracts.sim_result": ("MAX_RENDER_PROCESSES", "PlayRecord", "RobotApiStats", "SimResult",
                                 "SpoofingAttempt"),
        "contracts.telemetry": (
            "EventRecord", "GameStateRecord", "PenaltyRecord", "RobotTraffic", "StateMessage",
            "TrafficSample",
        ),
        "contracts.tally": ("Tally",),
        "contracts.timing": (
            "ADULT_SCRIMMAGE", "ENVIRONMENT", "MIN_PLAYING_S", "MIN_READY_S", "OFFICIAL",
            "REMOVAL_PENALTY_S", "SCRIMMAGE", "SET_TO_PLAY_S", "TEST_MATCH", "TimingError",
            "fit_ready", "played_enough", "timing_problem",
        ),
    })
