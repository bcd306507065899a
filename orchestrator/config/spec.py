"""From a validated game to the :class:`contracts.match_spec.MatchSpec` the simulator reads.

The simulator is not imported here: both sides share the typed contract (a unit test checks the
JSON round trip). Every random choice (first-half side, first kick-off) is resolved from the
match seed.
"""

from __future__ import annotations

import random
from collections.abc import Mapping, Sequence

from contracts import (
    MatchSpec,
    NetworkSpec,
    PlayerSpec,
    Pose,
    TeamSpec,
    TimingSpec,
    files,
)
from orchestrator.config.model import COLORS, Color, LoadedGame, StartingPose
from orchestrator.config.robot_models import spec_model
from orchestrator.config.team import GOALKEEPER_NUMBER

VIDEO_FILE = files.VIDEO


def resolve_sides(loaded: LoadedGame) -> tuple[Color, Color]:
    """(side_left, kickoff) with "random" drawn from ``random.Random(seed)`` in that order."""
    game = loaded.game
    rng = random.Random(game.seed)
    colors: list[Color] = list(COLORS)
    side: Color = game.side_left if game.side_left != "random" else rng.choice(colors)
    kickoff: Color = game.kickoff if game.kickoff != "random" else rng.choice(colors)
    return side, kickoff


def to_match_spec(
    loaded: LoadedGame,
    *,
    robot_addresses: Mapping[str, Sequence[str]],
    telemetry_listen: str | None,
    api_bind_host: str = "0.0.0.0",
    game_hosts: bool = True,
) -> MatchSpec:
    """The match spec of ``loaded``.

    Args:
        loaded: the validated game and teams.
        robot_addresses: per color ("red", "blue"), the address of robot n at index n-1 in this
            run (GameController packets go there; they are also allowed on the API ports).
        telemetry_listen: zenoh endpoint the simulator listens on, None for no telemetry.
        api_bind_host: address the robot API server binds.
        game_hosts: each team's ``hosts`` of game.json are allowed on its API ports besides
            ``robot_addresses`` (a simulator in a network laid out elsewhere: ``hlvs referee``,
            the league's own set-up). False: ``robot_addresses`` alone (``hlvs match`` and
            ``hlvs compose`` start each robot at an address of their own, and no other address
            may speak as a robot).
    """
    game = loaded.game
    side_left, kickoff = resolve_sides(loaded)
    timing = game.timing
    return MatchSpec(
        match_id=game.match_id,
        seed=game.seed,
        game_type=game.game_type,
        field_class=game.field_class.value,
        side_left=side_left,
        kickoff=kickoff,
        red=_team(loaded, "red", robot_addresses.get("red", ()), game_hosts),
        blue=_team(loaded, "blue", robot_addresses.get("blue", ()), game_hosts),
        stepping=game.stepping,
        maximum_real_time_factor=game.maximum_real_time_factor,
        physics_dt_s=game.physics_dt_s,
        lockstep_deadline_ms=game.lockstep_deadline_ms,
        lockstep_time_bank_ms=game.lockstep_time_bank_ms,
        timing=TimingSpec(
            half_duration_s=timing.half_duration_s,
            overtime_half_duration_s=timing.overtime_half_duration_s,
            ready_duration_s=timing.ready_duration_s,
            wait_before_first_ready_real_s=timing.wait_before_first_ready_s,
            half_time_break_real_s=timing.half_time_break_s,
            removal_penalty_s=timing.removal_penalty_s,
            max_duration_real_s=timing.max_duration_s,
            minimum_play_s=timing.minimum_play_s,
        ),
        network=NetworkSpec(
            api_bind_host=api_bind_host,
            telemetry_listen=telemetry_listen,
            team_quota_mb_s=game.limits.team_api_mb_s,
        ),
        texture_seed=game.texture_seed,
        sensors=game.sensors,
        camera_motion_blur=game.camera_motion_blur,
        record_video=(
            VIDEO_FILE
            if game.record_simulation and game.record_simulation.endswith(".mp4")
            else None
        ),
    )


def _team(
    loaded: LoadedGame, color: Color, addresses: Sequence[str], game_hosts: bool
) -> TeamSpec:
    ref = loaded.game.team(color)
    team = loaded.team(color)
    hosts = tuple(dict.fromkeys([*(ref.hosts if game_hosts else ()), *addresses]))
    return TeamSpec(
        color=color,
        team_id=ref.team_id,
        name=team.display_name,
        hosts=hosts,
        robot_addresses=tuple(addresses),
        players=tuple(
            PlayerSpec(
                number=player.number,
                model=spec_model(player.model),
                port=ref.port(player.number),
                half_time_pose=_pose(player.half_time_pose),
                reentry_pose=_pose(player.reentry_pose),
                shootout_pose=_pose(player.shootout_pose),
                goalkeeper_pose=_pose(player.goalkeeper_pose),
                goalkeeper=player.number == GOALKEEPER_NUMBER,
            )
            for player in team.players
        ),
    )


def _pose(pose: StartingPose) -> Pose:
    return pose.pose
