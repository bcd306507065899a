"""Every contract type survives a JSON round trip; unknown versions and fields are refused."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from contracts.codec import from_data, to_data
from contracts.errors import ContractError, UnknownVersion
from contracts.field import KID_FIELD, FieldGeometry
from contracts.geometry import Pose
from contracts.ids import RobotId, TeamColor
from contracts.match_spec import (
    MatchSpec,
    NetworkSpec,
    PlayerSpec,
    TeamSpec,
    TimingSpec,
)
from contracts.sim_result import SimResult, SpoofingRecord
from contracts.telemetry import StateMessage


def _pose(x: float) -> Pose:
    return Pose(x_m=x, y_m=-3.1, yaw_rad=math.pi / 2)


def _spec() -> MatchSpec:
    def team(color: str, team_id: int) -> TeamSpec:
        return TeamSpec(
            color=color,  # type: ignore[arg-type]
            team_id=team_id,
            name=f"{color} team",
            hosts=("10.0.1.11",),
            robot_addresses=("10.0.1.11",),
            players=(
                PlayerSpec(
                    number=1, model="kid-default", port=10001, half_time_pose=_pose(-1.0),
                    reentry_pose=_pose(-3.0), shootout_pose=_pose(2.75),
                    goalkeeper_pose=_pose(-4.4), goalkeeper=True,
                ),
            ),
        )  # fmt: skip

    return MatchSpec(
        match_id="m1", seed=7, game_type="KNOCKOUT", field_class="kid", side_left="blue",
        kickoff="red", red=team("red", 8), blue=team("blue", 25), stepping="lockstep",
        timing=TimingSpec(half_duration_s=30.0, max_duration_real_s=120.0),
        network=NetworkSpec(telemetry_listen="tcp/10.0.0.2:7447"), record_video="match.mp4",
    )  # fmt: skip


def _result() -> SimResult:
    return SimResult(
        match_id="m1", seed=7, state="FINISHED", score={"red": 2, "blue": 1}, winner="red",
        events_summary={"goal": 3}, stop_reason="finished", stepping="lockstep",
        sim_time_ms=60000, real_time_s=61.5, held_real_s=1.0, real_time_factor=0.99,
        robots={"red-1": {"connected": True, "bytes_sent": 10}}, cameras={"frames": 3},
        versions={"mujoco": "4.0.0"}, spoofing=SpoofingRecord(total=0),
        shootout={"red": {"kicks": 5, "scored": 3}}, coin_toss=False,
    )  # fmt: skip


@pytest.mark.parametrize("document", [_spec(), _result()], ids=["MatchSpec", "SimResult"])
def test_versioned_documents_round_trip(document: MatchSpec | SimResult, tmp_path: Path) -> None:
    kind = type(document)
    again = kind.from_json(document.to_json())
    assert again == document
    path = document.write(tmp_path / "doc.json")
    assert kind.load(path) == document
    assert json.loads(path.read_text())["version"] == kind.VERSION


@pytest.mark.parametrize(
    ("cls", "value"),
    [
        (Pose, Pose(x_m=-1.5, y_m=2.0, yaw_rad=0.25)),
        (RobotId, RobotId(TeamColor.BLUE, 3)),
        (FieldGeometry, KID_FIELD),
        (TimingSpec, TimingSpec()),
        (NetworkSpec, NetworkSpec(blocking_send=True)),
        (
            StateMessage,
            StateMessage(
                sim_time_ms=8000, real_time_factor=0.98, state="PLAYING", secondary_state="NORMAL",
                half=1, secs_remaining=592.0, score={"red": 0, "blue": 1},
                connected=("red-1", "blue-1"), stepping="lockstep", robots=None,
            ),
        ),
    ],
)
def test_plain_contract_types_round_trip(cls: type, value: object) -> None:
    text = json.dumps(to_data(value))
    assert from_data(cls, json.loads(text), source="test") == value


def test_an_unknown_version_is_refused_with_a_clear_error() -> None:
    data = json.loads(_result().to_json())
    data["version"] = 2
    with pytest.raises(UnknownVersion) as caught:
        SimResult.from_dict(data, source="out/sim_result.json")
    message = str(caught.value)
    assert message.startswith("out/sim_result.json: /version: simulator result version 2")
    assert "reads version 1" in message
    spec = json.loads(_spec().to_json())
    spec["version"] = 0
    with pytest.raises(UnknownVersion, match="match spec version 0"):
        MatchSpec.from_dict(spec)


def test_wrong_fields_are_named() -> None:
    data = json.loads(_spec().to_json())
    data["red"]["players"][0]["port"] = "10001"
    with pytest.raises(ContractError, match=r"/red/players/0/port: expected int"):
        MatchSpec.from_dict(data)
    data = json.loads(_result().to_json())
    data["final_state"] = "FINISHED"  # the old fake's key: not part of the contract
    with pytest.raises(ContractError, match=r"/final_state: unknown field"):
        SimResult.from_dict(data)
    del data["final_state"], data["state"]
    with pytest.raises(ContractError, match=r"/state: missing field"):
        SimResult.from_dict(data)


def test_pose_mirror_is_a_reflection_across_the_centre_line() -> None:
    pose = Pose(x_m=-1.0, y_m=2.0, yaw_rad=0.3)
    mirrored = pose.mirrored()
    assert (mirrored.x_m, mirrored.y_m) == (1.0, 2.0)
    assert math.cos(mirrored.yaw_rad) == pytest.approx(-math.cos(0.3))
    assert math.sin(mirrored.yaw_rad) == pytest.approx(math.sin(0.3))
    assert mirrored.mirrored().yaw_rad == pytest.approx(0.3)
    assert pose.on_side(left=True) is pose


def test_contracts_import_only_the_standard_library_and_protobuf() -> None:
    import subprocess
    import sys

    code = (
        "import sys, pkgutil, importlib, contracts, contracts.robot_api;"
        "before = set(sys.modules);"
        "[importlib.import_module(m.name) for m in pkgutil.walk_packages("
        "contracts.__path__, 'contracts.')];"
        "print(' '.join(sorted({n.split('.')[0] for n in sys.modules})))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    tops = set(out.stdout.split())
    assert "contracts" in tops and "google" in tops
    ours = {"robot", "simulator", "referee", "orchestrator", "service", "benchmarks"}
    assert tops & (ours | {"mujoco", "numpy", "zenoh", "docker", "yaml"}) == set()


def test_a_telemetry_state_message_names_its_wrong_field() -> None:
    message = StateMessage(
        sim_time_ms=8000, real_time_factor=0.98, state="PLAYING", secondary_state="NORMAL",
        half=1, secs_remaining=592.0, score={"red": 0, "blue": 1}, connected=("red-1",),
        stepping="lockstep", robots=None,
    )  # fmt: skip
    data = json.loads(json.dumps(message.to_dict()))
    assert StateMessage.from_dict(data, source="hlvs/m1/state") == message
    data["connected"] = "red-1"
    with pytest.raises(ContractError, match=r"^hlvs/m1/state: /connected: expected a list"):
        StateMessage.from_dict(data, source="hlvs/m1/state")
