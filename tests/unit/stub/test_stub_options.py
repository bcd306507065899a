"""Behaviour selection by argv and the ROBOCUP_* environment."""

from __future__ import annotations

from pathlib import Path

import pytest

from contracts.gamecontroller import GameState
from contracts.geometry import Pose
from robot.stub import Behaviour, StubConfigError, parse_args, read_env
from robot.stub.behaviour import GameInfo, Role, decide
from robot.stub.runner import StubRobot

ENV = {
    "ROBOCUP_ROBOT_ID": "2",
    "ROBOCUP_TEAM_COLOR": "blue",
    "ROBOCUP_SIMULATOR_ADDR": "127.0.0.1:10022",
    "ROBOCUP_MIRROR_SERVER_IP": "10.0.0.9",
    "ROBOCUP_TEAM_PLAYER1_IP": "10.0.0.11",
    "ROBOCUP_TEAM_PLAYER2_IP": "10.0.0.12",
    "ROBOCUP_LOG_DIR": "/tmp/stub-logs",
}


@pytest.mark.parametrize(
    ("argv", "behaviour"),
    [
        (["striker"], Behaviour.STRIKER),
        (["goalie"], Behaviour.GOALIE),
        (["idle"], Behaviour.IDLE),
        (["ignore-sigterm"], Behaviour.IGNORE_SIGTERM),
        (["flood"], Behaviour.FLOOD),
        (["fill-logs", "--fill-cap-bytes", "1000"], Behaviour.FILL_LOGS),
    ],
)
def test_behaviour_selected_by_argv(argv: list[str], behaviour: Behaviour) -> None:
    assert parse_args(argv).behaviour is behaviour


def test_crash_after_needs_seconds() -> None:
    assert parse_args(["crash-after", "2.5"]).crash_after_s == 2.5
    with pytest.raises(StubConfigError) as info:
        parse_args(["crash-after"])
    assert info.value.field == "crash-after"


def test_unknown_behaviour_names_the_choices() -> None:
    with pytest.raises(StubConfigError) as info:
        parse_args(["dancer"])
    assert "striker" in info.value.expected
    assert info.value.value == "dancer"


def test_defender_home_option() -> None:
    options = parse_args(["defender", "--home", "-2.3", "1.0"])
    assert options.behaviour is Behaviour.DEFENDER and options.home == (-2.3, 1.0)
    with pytest.raises(StubConfigError) as err:
        parse_args(["defender", "--home", "2.0", "0"])  # the opponents' half
    assert err.value.field == "--home"


def test_start_pose_option() -> None:
    assert parse_args(["striker", "--start-pose", "-1", "2", "0.5"]).start_pose == (-1.0, 2.0, 0.5)


def test_read_env() -> None:
    env = read_env(ENV)
    assert (env.robot_id, env.team_color) == (2, "blue")
    assert (env.simulator_host, env.simulator_port) == ("127.0.0.1", 10022)
    assert env.mirror_ip == "10.0.0.9"
    assert env.teammate_ips == ("10.0.0.11", "10.0.0.12")
    assert env.log_dir == Path("/tmp/stub-logs")
    assert read_env({k: v for k, v in ENV.items() if k != "ROBOCUP_LOG_DIR"}).log_dir == Path(
        "/robocup-logs"
    )


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("ROBOCUP_ROBOT_ID", "zero"),
        ("ROBOCUP_TEAM_COLOR", "green"),
        ("ROBOCUP_SIMULATOR_ADDR", "127.0.0.1"),
        ("ROBOCUP_SIMULATOR_ADDR", "host:99999"),
    ],
)
def test_bad_env_names_the_variable(key: str, value: str) -> None:
    with pytest.raises(StubConfigError) as info:
        read_env({**ENV, key: value})
    assert info.value.field == key


@pytest.mark.parametrize(
    ("argv", "role"),
    [(["striker"], Role.STRIKER), (["goalie"], Role.GOALIE), (["idle"], Role.IDLE),
     (["flood"], Role.IDLE), (["fill-logs"], Role.IDLE)],
)  # fmt: skip
def test_role_of_each_behaviour(argv: list[str], role: Role) -> None:
    robot = StubRobot(parse_args(argv), read_env(ENV), gc_data_port=0, gc_return_port=0)
    try:
        assert robot.controller.role is role
    finally:
        robot.gc.close()


def test_behaviour_by_game_state() -> None:
    pose = Pose(x_m=-2.0, y_m=0.0, yaw_rad=0.0)
    from robot.stub.behaviour import Field

    field = Field(half_length_m=4.5, centre_circle_m=0.75, foot_y_m=0.075, kick_x_m=0.165)
    args = {"pose": pose, "ball": (1.0, 0.0), "field": field, "searching_s": 0.0}
    for phase in (GameState.INITIAL, GameState.SET, GameState.FINISHED):
        assert decide(role=Role.STRIKER, game=GameInfo(phase=phase), **args).stands
    playing = decide(role=Role.STRIKER, game=GameInfo(phase=GameState.PLAYING), **args)
    assert playing.walk[0] > 0  # walks to the ball ahead
    penalised = GameInfo(phase=GameState.PLAYING, penalised=True)
    assert decide(role=Role.STRIKER, game=penalised, **args).stands
    assert decide(role=Role.IDLE, game=GameInfo(phase=GameState.PLAYING), **args).stands
    ready = decide(role=Role.STRIKER, game=GameInfo(phase=GameState.READY), **args)
    assert ready.walk[0] > 0  # towards the kick-off position ahead (x = -0.35)
    close = decide(
        role=Role.STRIKER,
        game=GameInfo(phase=GameState.PLAYING),
        pose=pose,
        ball=(0.165, -0.075),
        field=field,
        searching_s=0.0,
    )
    assert close.kick_foot == "right"


def test_model_and_field_class_from_argv() -> None:
    """The field defaults to the model's size class; ``--field-class`` puts an adult robot on
    the kid-size field (the scrimmage's), and an unknown class is refused."""
    assert parse_args(["striker"]).field == "kid"
    assert parse_args(["striker", "--model", "adult-default"]).field == "adult"
    options = parse_args(["striker", "--model", "adult-default", "--field-class", "kid"])
    assert (options.model, options.field) == ("adult-default", "kid")
    with pytest.raises(StubConfigError):
        parse_args(["striker", "--field-class", "huge"])
