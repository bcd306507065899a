"""The configuration documents as their JSON Schemas (``schemas/``) describe them.

A document is typed as one of these once its schema has checked it; the rules that run after the
schema read only the parts the schema found sound. Keys a document may leave out are
``NotRequired`` (game.json and team_config.json follow the league's files, which omit most).
"""

from __future__ import annotations

from typing import Literal, NotRequired, TypedDict

from contracts import GameTypeName, JSONObject, SteppingMode


class GameTeamDocument(TypedDict):
    """``red`` / ``blue`` of game.json."""

    id: int | str  # a string is converted (with a warning)
    config: str  # the team file, relative to game.json
    hosts: list[str]
    ports: list[int]
    credentials: NotRequired[str]


# game.json: the league's fields and our optional additions ("class" is a keyword, hence the
# functional form)
GameDocument = TypedDict(
    "GameDocument",
    {
        "type": GameTypeName,
        "class": Literal["KID", "ADULT"],
        "host": str,
        "red": GameTeamDocument,
        "blue": GameTeamDocument,
        "maximum_real_time_factor": NotRequired[float],
        "minimum_real_time_factor": NotRequired[float],  # legacy
        "real_time_factor": NotRequired[float],  # legacy (2021)
        "side_left": NotRequired[Literal["red", "blue", "random"]],
        "kickoff": NotRequired[Literal["red", "blue", "random"]],
        "press_a_key_to_terminate": NotRequired[bool],
        "use_bouncing_server": NotRequired[bool],
        "record_simulation": NotRequired[str],
        "game_controller_extra_args": NotRequired[list[str]],
        "texture_seed": NotRequired[int],
        "sensors": NotRequired[Literal["league", "ideal"]],
        "camera_motion_blur": NotRequired[bool],
        "random_seed": NotRequired[int],  # legacy name of seed
        "supervisor": NotRequired[str],
        "max_duration": NotRequired[float],
        "match_id": NotRequired[str],
        "seed": NotRequired[int],
        "stepping": NotRequired[SteppingMode],
        "physics_dt_s": NotRequired[float],
        "lockstep_deadline_ms": NotRequired[float],
        "lockstep_time_bank_ms": NotRequired[float],
        "limits": NotRequired[dict[str, float]],  # orchestrator.config.model.Limits' fields
        "timing": NotRequired[dict[str, float]],  # orchestrator.config.model.Timing's fields
        "gpu": NotRequired[str],
        "official": NotRequired[bool],
        "registry_images": NotRequired[bool],
        "allow_internet": NotRequired[bool],
        "public_logs": NotRequired[str],
    },
)


class PoseDocument(TypedDict):
    translation: list[float]  # x, y, z (m)
    rotation: list[float]  # axis x, y, z and angle (rad)


class PlayerDocument(TypedDict):
    """One entry of team_config.json's ``players``."""

    halfTimeStartingPose: PoseDocument
    reentryStartingPose: PoseDocument
    shootoutStartingPose: PoseDocument
    goalKeeperStartingPose: PoseDocument
    proto: NotRequired[str]
    dockerTag: NotRequired[str]
    dockerCmd: NotRequired[str]
    image: NotRequired[str]
    model: NotRequired[str]


class EcrDocument(TypedDict):
    region: str
    access_id: NotRequired[str]
    access_secret: NotRequired[str]


class RegistryAuthDocument(TypedDict, total=False):
    """``registry_auth`` of team_config.json: a login (Basic) or Amazon ECR."""

    username: str
    password: str
    password_env: str  # the name of a variable holding the password
    ecr: EcrDocument


class TeamDocument(TypedDict):
    """team_config.json."""

    name: str
    players: dict[str, PlayerDocument]  # player number ("1") -> its entry
    image: NotRequired[str]
    registry_auth: NotRequired[RegistryAuthDocument | None]


class ScheduleSlotDocument(TypedDict, total=False):
    """A side of a scheduled match that a fixture decides (one of the two keys)."""

    winner_of: str
    loser_of: str


# one entry of a schedule's ``matches`` ("class" is a keyword, hence the functional form)
ScheduleMatchDocument = TypedDict(
    "ScheduleMatchDocument",
    {
        "id": str,
        "red": str | ScheduleSlotDocument,  # a team name, or a fixture's placeholder
        "blue": str | ScheduleSlotDocument,
        "stream_start": str,
        "stream_length_s": NotRequired[float],
        "class": NotRequired[Literal["KID", "ADULT"]],
        "kind": NotRequired[Literal["round_robin", "knockout", "friendly"]],
    },
)

_FixtureFields = TypedDict(
    "_FixtureFields",
    {
        "first_stream": str,  # an offset ("+1h") or an ISO time
        "interval_s": NotRequired[float],
        "stream_length_s": NotRequired[float],
        "class": NotRequired[Literal["KID", "ADULT"]],
    },
)


class RoundRobinDocument(_FixtureFields):
    teams: list[str]


class KnockoutDocument(_FixtureFields):
    seeds: list[str]  # in bracket order; a power of two


class FixturesDocument(TypedDict, total=False):
    round_robin: RoundRobinDocument
    knockout: KnockoutDocument


class ScheduleTeamDocument(TypedDict):
    name: str
    id: int
    config: str
    credentials: NotRequired[str]


class SchedulePoolDocument(TypedDict, total=False):
    kind: Literal["local", "slurm"]
    slurm_conf: str | None
    account: str | None
    placement: Literal["dense", "league"]


class ScheduleDocument(TypedDict):
    """A tournament schedule (YAML or JSON)."""

    name: str
    teams: list[ScheduleTeamDocument]
    start: NotRequired[str]
    output_dir: NotRequired[str]
    log_store: NotRequired[str]
    public_logs: NotRequired[str]
    pool: NotRequired[SchedulePoolDocument]
    simulator_slots: NotRequired[int]
    timing: NotRequired[dict[str, float]]  # orchestrator.config.schedule.ScheduleTiming's
    game_defaults: NotRequired[JSONObject]  # game.json fields every match gets
    matches: NotRequired[list[ScheduleMatchDocument]]
    fixtures: NotRequired[FixturesDocument]


class SftpDocument(TypedDict):
    """``credentials`` of an SFTP target."""

    hostname: str
    username: str
    port: NotRequired[int | str]
    password: NotRequired[str]
    private_key: NotRequired[str]  # the key itself or a file relative to credentials.json
    private_key_passphrase: NotRequired[str]
    path: NotRequired[str]
    host_key: NotRequired[str]
    known_hosts: NotRequired[str]


class S3Document(TypedDict):
    """``credentials`` of an S3 target."""

    access_id: str
    access_secret: str
    bucket: str
    region: NotRequired[str]
    endpoint_url: NotRequired[str]
    prefix: NotRequired[str]


class SftpCredentialsDocument(TypedDict):
    type: Literal["sftp"]
    credentials: SftpDocument


class S3CredentialsDocument(TypedDict):
    type: Literal["s3"]
    credentials: S3Document


# credentials.json: where a team's (or the public) match logs are delivered
CredentialsDocument = SftpCredentialsDocument | S3CredentialsDocument


__all__ = [
    "CredentialsDocument",
    "EcrDocument",
    "FixturesDocument",
    "GameDocument",
    "GameTeamDocument",
    "KnockoutDocument",
    "PlayerDocument",
    "PoseDocument",
    "RegistryAuthDocument",
    "RoundRobinDocument",
    "S3CredentialsDocument",
    "S3Document",
    "ScheduleDocument",
    "ScheduleMatchDocument",
    "SchedulePoolDocument",
    "ScheduleSlotDocument",
    "ScheduleTeamDocument",
    "SftpCredentialsDocument",
    "SftpDocument",
    "TeamDocument",
]
