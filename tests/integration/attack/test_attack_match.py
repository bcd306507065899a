"""One real match against a hostile red robot that tries several attacks at once; each test
checks one of them: the result is right, nothing of the teams' logs is lost, nothing is left."""

from __future__ import annotations

import json
import stat
from typing import Any

import docker
import pytest

from tests.integration.attack.conftest import (
    RUNTIMES,
    Prepare,
    Prepared,
    left_behind,
    under_runtime,
)

pytestmark = [pytest.mark.docker, pytest.mark.root]

SCRATCH_GB = 0.05


@pytest.fixture(scope="module", **RUNTIMES)
def hostile(request: pytest.FixtureRequest, prepare: Prepare, docker_client: docker.DockerClient
            ) -> tuple[Prepared, Any, list[str]]:
    """The same attacks with the robots under the engine's default runtime and under gVisor's
    ``runsc`` (``limits.robot_runtime``)."""
    limits = under_runtime(request.param, docker_client, {"scratch_gb": SCRATCH_GB})
    match = prepare("special-files", "fill=/var/tmp/big", "fill=/opt/big", "spoof", "hog=4",
                    game={"limits": limits})
    done = match.run()
    assert done.returncode == 0, done.stderr[-3000:]
    return match, done, left_behind(docker_client, match.match_id)


def test_played_to_the_end_and_nothing_left(hostile: tuple[Prepared, Any, list[str]]) -> None:
    match, _, leftovers = hostile
    assert match.report() == {"status": "success"}
    results = match.results()
    assert results["final_state"] == "FINISHED"
    assert leftovers == []
    for color in ("red", "blue"):
        assert (match.out / "teams" / color / "1" / "stdout.log").is_file()
    assert "attacks done" in (match.out / "teams/red/1/stdout.log").read_text()


def test_spoofed_gamecontroller_and_api_messages_are_refused_and_reported(
    hostile: tuple[Prepared, Any, list[str]],
) -> None:
    match, _, _ = hostile
    results = match.results()
    spoofing = results["spoofing"]
    attempts = {(a["channel"], a["claimed"], a["message"]): a for a in spoofing["attempts"]}
    keeper = attempts[("gamecontroller", "blue-1", "GOALKEEPER")]
    assert keeper["count"] == 20 and keeper["sender_robot"] == "red-1"
    assert attempts[("gamecontroller", "blue-1", "MAN_PENALISE")]["count"] == 5
    seen = json.loads((match.out / "teams/red/1/robocup-logs/attacks.json").read_text())
    assert seen["blue_api"] == ["Refused\0"] * 3 and seen["rgme"] is True, seen
    api = attempts[("api", "blue-1", "connect")]
    assert api["sender_robot"] == "red-1" and api["count"] == 3
    assert results["robots"]["red-1"]["spoofing_attempts"] == 28
    assert results["robots"]["blue-1"]["spoofing_attempts"] == 0
    public = match.out / "public"
    referee_log = (public / "referee.log").read_text()
    assert "declared itself goalkeeper" not in referee_log
    assert "GOALKEEPER from" in referee_log and "(red-1) claiming to be blue-1" in referee_log
    events = [json.loads(line) for line in
              (public / "referee_events.jsonl").read_text().splitlines()]
    spoofs = [e for e in events if e["type"] == "spoofing"]
    assert {(e["team"], e["player"]) for e in spoofs} == {("red", 1)}
    assert results["events_summary"]["spoofing"] == len(spoofs) == 3


def test_special_files_in_the_log_folder_are_skipped_not_followed(
    hostile: tuple[Prepared, Any, list[str]],
) -> None:
    match, _, _ = hostile
    logs = match.out / "teams/red/1/robocup-logs"
    assert (logs / "sub" / "kept.txt").read_text() == "kept\n"
    assert json.loads((logs / "attacks.json").read_text())["special_files"]
    for path in logs.rglob("*"):
        assert path.is_dir() or path.is_file(), path
        assert not path.is_symlink(), path
    robot = match.results()["robots"]["red-1"]
    folder = robot["log_folder"]
    skipped = {(s["path"], s["kind"]) for s in folder["skipped"]}
    links = {("shadow", "symlink"), ("root", "symlink"), ("environ", "symlink"),
             ("sub/loop", "symlink")}
    if robot["limits"]["runtime"] == "runsc":
        # gVisor keeps a pipe or socket made in a bind-mounted folder inside its own kernel:
        # the host's folder never holds them (the robot saw both made)
        assert skipped == links, skipped
    else:
        assert robot["limits"]["runtime"] is None
        assert links | {("a_fifo", "pipe"), ("a_socket", "socket")} <= skipped
    assert folder["files"] >= 2


def test_writing_past_the_scratch_space_fails_inside_the_robot_only(
    hostile: tuple[Prepared, Any, list[str]],
) -> None:
    match, _, _ = hostile
    seen = json.loads((match.out / "teams/red/1/robocup-logs/attacks.json").read_text())
    scratch = seen["fill /var/tmp/big"]
    assert "No space left on device" in scratch["result"], scratch
    assert scratch["bytes"] <= SCRATCH_GB * 1e9
    root = seen["fill /opt/big"]
    assert "Read-only file system" in root["result"] and root["bytes"] == 0, root
    limits = match.results()["robots"]["red-1"]["limits"]
    assert limits["scratch_bytes"] == int(SCRATCH_GB * 1e9) and limits["read_only_root"]


def test_a_cpu_hog_is_held_to_its_limit_and_the_overcommit_is_recorded(
    hostile: tuple[Prepared, Any, list[str]],
) -> None:
    """Two robots of 1 CPU and the simulator do not fit 2 CPUs: a scrimmage plays with the
    warning in the result; the hogging robot stays within its CPUs, the game still finishes."""
    match, _, _ = hostile
    results = match.results()
    admission = results["admission"]
    if admission["fits"]:
        pytest.skip(f"this host fits the match: {admission}")
    assert admission["official"] is False and "does not fit" in admission["warning"]
    assert admission["cpus"]["needed"] == 3.0
    red = results["robots"]["red-1"]
    assert red["cpu_peak_percent"] <= 100 * red["limits"]["nano_cpus"] / 1e9 * 1.3
    assert results["final_state"] == "FINISHED" and results["status"] == "success"


def test_an_official_match_that_does_not_fit_is_refused_with_the_numbers(
    prepare: Prepare, docker_client: docker.DockerClient,
) -> None:
    # registry_images off: the attacker is a local image, and admission is what is tested here
    match = prepare("spoof", game={"official": True, "registry_images": False,
                                   "limits": {"cpus": 4, "memory_gb": 16}})
    done = match.run(timeout_s=60)
    assert done.returncode == 1, done.stderr[-2000:]
    assert f"official match {match.match_id} refused" in done.stderr
    assert "CPUs needed 9 (robots' limits + simulator 1) >" in done.stderr
    assert not match.out.exists()
    assert left_behind(docker_client, match.match_id) == []


def test_outputs_are_readable_by_their_owner_only(hostile: tuple[Prepared, Any, list[str]]
                                                  ) -> None:
    match, _, _ = hostile
    modes = {p: stat.S_IMODE(p.lstat().st_mode) for p in [match.out, *match.out.rglob("*")]}
    assert {m for p, m in modes.items() if p.is_dir()} == {0o700}
    assert {m for p, m in modes.items() if p.is_file()} == {0o600}


def test_a_team_whose_robots_all_exit_is_named_in_the_result(
    prepare: Prepare, docker_client: docker.DockerClient,
) -> None:
    match = prepare("exit=3", half_s=2.0)
    done = match.run()
    assert done.returncode == 0, done.stderr[-3000:]
    results = match.results()
    assert results["final_state"] == "FINISHED"
    assert "every robot of red exited during the game (red-1: exit code 3)" in results["warnings"]
    assert "no robot of red ever connected to the simulator" in results["warnings"]
    assert not any("blue" in w for w in results["warnings"])
    assert left_behind(docker_client, match.match_id) == []
