"""Command line and environment of the stub robot controller.

``python -m robot.stub BEHAVIOUR [ARG]`` where BEHAVIOUR is ``striker``, ``goalie``,
``defender`` (``--home X Y``: its spot in the own half), ``idle`` or a fault mode:
``crash-after SECONDS``, ``ignore-sigterm``, ``flood``, ``fill-logs``. The robot
itself is described by the HLVS container environment (``ROBOCUP_*``). ``--kick-policy FILE``
(default: ``$HLVS_KICK_POLICY``) plays a learned kick from a stand (:mod:`robot.learned`)
instead of the keyframe kick.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Mapping
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path

from robot.motion import known_models
from robot.stub.errors import StubConfigError

KICK_POLICY_ENV = "HLVS_KICK_POLICY"


class Behaviour(StrEnum):
    STRIKER = "striker"
    GOALIE = "goalie"
    DEFENDER = "defender"
    IDLE = "idle"
    CRASH_AFTER = "crash-after"
    IGNORE_SIGTERM = "ignore-sigterm"
    FLOOD = "flood"
    FILL_LOGS = "fill-logs"


@dataclass(frozen=True, slots=True, kw_only=True)
class StubOptions:
    behaviour: Behaviour
    crash_after_s: float | None = None
    fill_cap_bytes: int | None = None  # None: until the disk is full
    start_pose: tuple[float, float, float] | None = None  # own-half frame x, y, yaw
    home: tuple[float, float] | None = None  # a defender's spot, own-half frame
    gc_data_port: int = 3838
    gc_return_port: int = 3939
    mirror_port: int = 3737
    model: str = "kid-default"
    field_class: str | None = None  # "kid" | "adult"; None: the model's size class
    kick_policy: Path | None = None  # a learned kick (robot.learned policy file)

    @property
    def field(self) -> str:
        """The field the robot plays on: as given, else the one of its model's size class."""
        if self.field_class is not None:
            return self.field_class
        return "adult" if self.model.startswith("adult") else "kid"


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotEnv:
    """The HLVS robot container environment."""

    robot_id: int
    team_color: str  # "red" | "blue"
    simulator_host: str
    simulator_port: int
    mirror_ip: str | None
    teammate_ips: tuple[str, ...]
    gamecontroller_ip: str | None
    log_dir: Path
    team_id: int | None


def parse_args(argv: list[str]) -> StubOptions:
    parser = argparse.ArgumentParser(
        prog="python -m robot.stub", exit_on_error=False,
        description="The stub robot controller of an HLVS robot container: it connects to the "
        "robot API at $ROBOCUP_SIMULATOR_ADDR as robot $ROBOCUP_ROBOT_ID of team "
        "$ROBOCUP_TEAM_COLOR and plays by the GameController's packets.",
    )
    parser.add_argument("behaviour", choices=[b.value for b in Behaviour], metavar="BEHAVIOUR",
                        help="striker, goalie, defender or idle; or a fault for tests: "
                        "crash-after SECONDS, ignore-sigterm, flood, fill-logs")
    parser.add_argument("seconds", nargs="?", type=float, default=None, metavar="SECONDS",
                        help="crash-after only: seconds before the process exits 1")
    parser.add_argument("--fill-cap-bytes", type=int, default=None, metavar="BYTES",
                        help="fill-logs only: stop after this many bytes (default: the disk)")
    parser.add_argument("--start-pose", nargs=3, type=float, metavar=("X", "Y", "YAW"),
                        help="the pose the robot starts at, own-half frame (m, m, rad); "
                        "default: on the touch line by its number")
    parser.add_argument("--home", nargs=2, type=float, metavar=("X", "Y"),
                        help="defender only: its spot in the own half (m)")
    parser.add_argument("--gc-data-port", type=int, default=3838, metavar="PORT",
                        help="UDP port of the GameController's packets (default 3838)")
    parser.add_argument("--gc-return-port", type=int, default=3939, metavar="PORT",
                        help="UDP port of the GameController's return packets (default 3939)")
    parser.add_argument("--mirror-port", type=int, default=3737, metavar="PORT",
                        help="UDP port of the team mirror (default 3737)")
    parser.add_argument("--model", default="kid-default",
                        help=f"built-in robot model: {', '.join(known_models())} "
                        "(default kid-default)")
    parser.add_argument("--field-class", choices=("kid", "adult"), default=None,
                        help="the field it plays on (default: its model's size class)")
    parser.add_argument("--kick-policy", default=os.environ.get(KICK_POLICY_ENV) or None,
                        metavar="FILE", help="a learned kick (.npz of robot.learned) instead of "
                        f"the keyframe kick (default: ${KICK_POLICY_ENV})")
    try:
        ns, unknown = parser.parse_known_args(argv)
    except SystemExit as exc:
        if exc.code in (0, None):  # --help was printed: exit 0 as any command's help
            raise
        raise StubConfigError(field="argv", value=" ".join(argv), expected=_usage()) from exc
    except argparse.ArgumentError as exc:
        raise StubConfigError(field="argv", value=" ".join(argv), expected=_usage()) from exc
    if unknown:
        raise StubConfigError(field="argv", value=" ".join(unknown), expected=_usage())
    behaviour = Behaviour(ns.behaviour)
    if ns.model not in known_models():
        raise StubConfigError(field="--model", value=ns.model, expected=" or ".join(known_models()))
    if behaviour is Behaviour.CRASH_AFTER:
        if ns.seconds is None or ns.seconds < 0:
            raise StubConfigError(
                field="crash-after", value=str(ns.seconds), expected="a number of seconds >= 0"
            )
    elif ns.seconds is not None:
        raise StubConfigError(field="argv", value=str(ns.seconds), expected=_usage())
    pose: tuple[float, float, float] | None = None
    if ns.start_pose:
        pose = (float(ns.start_pose[0]), float(ns.start_pose[1]), float(ns.start_pose[2]))
    home: tuple[float, float] | None = None
    if ns.home:
        home = (float(ns.home[0]), float(ns.home[1]))
        if not (-6.0 <= home[0] <= 0.0 and abs(home[1]) <= 4.5):
            raise StubConfigError(
                field="--home", value=f"{home[0]} {home[1]}", expected="a spot in the own half"
            )
    return StubOptions(
        behaviour=behaviour,
        home=home,
        crash_after_s=ns.seconds,
        fill_cap_bytes=ns.fill_cap_bytes,
        start_pose=pose,
        gc_data_port=ns.gc_data_port,
        gc_return_port=ns.gc_return_port,
        mirror_port=ns.mirror_port,
        model=ns.model,
        field_class=ns.field_class,
        kick_policy=Path(ns.kick_policy) if ns.kick_policy else None,
    )


def _usage() -> str:
    return (
        "striker | goalie | defender [--home X Y] | idle | crash-after SECONDS | ignore-sigterm"
        " | flood | fill-logs"
    )


def read_env(env: Mapping[str, str] | None = None) -> RobotEnv:
    """Read the ``ROBOCUP_*`` variables; missing or malformed ones raise StubConfigError."""
    env = os.environ if env is None else env
    robot_id = _int(env, "ROBOCUP_ROBOT_ID", low=1, high=11)
    color = env.get("ROBOCUP_TEAM_COLOR", "").strip().lower()
    if color not in ("red", "blue"):
        raise StubConfigError(field="ROBOCUP_TEAM_COLOR", value=color, expected="red or blue")
    addr = env.get("ROBOCUP_SIMULATOR_ADDR", "").strip()
    host, sep, port_text = addr.rpartition(":")
    if not sep or not host or not port_text.isdigit() or not 0 < int(port_text) < 65536:
        raise StubConfigError(field="ROBOCUP_SIMULATOR_ADDR", value=addr, expected="host:port")
    teammates = tuple(
        env[key].strip()
        for key in (f"ROBOCUP_TEAM_PLAYER{n}_IP" for n in range(1, 5))
        if env.get(key, "").strip()
    )
    team_id_text = env.get("ROBOCUP_TEAM_ID", "").strip()
    return RobotEnv(
        robot_id=robot_id,
        team_color=color,
        simulator_host=host,
        simulator_port=int(port_text),
        mirror_ip=env.get("ROBOCUP_MIRROR_SERVER_IP", "").strip() or None,
        teammate_ips=teammates,
        gamecontroller_ip=env.get("ROBOCUP_GAMECONTROLLER_IP", "").strip() or None,
        log_dir=Path(env.get("ROBOCUP_LOG_DIR", "/robocup-logs")),
        team_id=int(team_id_text) if team_id_text.isdigit() else None,
    )


def _int(env: Mapping[str, str], key: str, *, low: int, high: int) -> int:
    text = env.get(key, "").strip()
    if not text.isdigit() or not low <= int(text) <= high:
        raise StubConfigError(field=key, value=text, expected=f"an integer in {low}..{high}")
    return int(text)
