"""``hlvs referee test`` on scenario files of ours written in the league's format
(``tests/scenarios/league_format/<case>/``: test_scenario.json, game.json and two team files, as
hlvs_webots lays out ``controllers/referee/tests``): real runs in the MuJoCo world with our
referee, a deliberately failing expectation, and malformed input."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from hlvs.cli import main

ROOT = Path(__file__).parent / "league_format"


def run(capsys: pytest.CaptureFixture[str], *args: object) -> tuple[int, str, str]:
    code = main(["referee", "test", *(str(a) for a in args)])
    out, err = capsys.readouterr()
    return code, out, err


def results_of(
    capsys: pytest.CaptureFixture[str], case: str, *args: object, code: int = 0
) -> list[dict[str, object]]:
    """``case`` played with ``args`` and ``--json``, which must exit with ``code``: its (one)
    scenario's results."""
    got, out, _ = run(capsys, ROOT / case, *args, "--json")
    assert got == code, out
    results: list[dict[str, object]] = json.loads(out)["scenarios"][0]["results"]
    return results


def test_every_action_and_test_kind_passes(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, ROOT / "throw_in", ROOT / "goal", "--json")
    report = json.loads(out)
    assert code == 0 and report["ok"] is True, out
    assert (report["files"], report["files_passed"]) == (2, 2)
    by_name = {Path(s["path"]).parent.name: s for s in report["scenarios"]}
    throw_in, goal = by_name["throw_in"], by_name["goal"]
    # every step ran to its end, every test passed (none skipped)
    assert (throw_in["tests"], throw_in["passed"], throw_in["ending"]) == (12, 12, "finished")
    assert (goal["tests"], goal["passed"], goal["ending"]) == (5, 5, "finished")
    assert all(r["status"] == "pass" for s in (throw_in, goal) for r in s["results"])
    # keys the league's runner does not check are listed, not checked
    ignored = {r["name"]: r["ignored_keys"] for r in throw_in["results"] if r["ignored_keys"]}
    assert ignored == {"Red 1 where it was put": ["rotation"], "Still PLAYING": ["comment"]}
    # the goal scenario ends once its last step (2 s into the second PLAYING) is over
    assert 20.0 < goal["sim_time_s"] < 40.0


def test_a_failed_expectation_names_file_step_and_expectation(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, out, _ = run(capsys, ROOT / "failing")
    assert code == 1
    path = ROOT / "failing" / "test_scenario.json"
    assert f"FAIL 1/2 {path}" in out
    failure = [line.strip() for line in out.splitlines() if "never scored" in line]
    assert failure == [
        f"{path}: step 0 (/0/tests/1) 'A goal that was never scored': score of red: expected 1, "
        "received 0 (sim 16.008 s, 1 s after PLAYING#1 (Simulated))"
    ]
    assert out.splitlines()[-1].startswith("0/1 files passed, 1/2 tests")


def test_the_failure_in_json(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, ROOT / "failing", "--json")
    report = json.loads(out)
    assert code == 1 and report["ok"] is False
    results = report["scenarios"][0]["results"]
    assert [(r["pointer"], r["status"]) for r in results] == [
        ("/0/tests/0", "pass"), ("/0/tests/1", "fail"),
    ]  # fmt: skip
    assert "score of red: expected 1, received 0" in results[1]["failures"][0]


@pytest.mark.parametrize(("world", "code"), [("league", 0), ("match", 1)])
def test_the_league_world_sends_the_ball_back_off_its_robot_s_legs(
    capsys: pytest.CaptureFixture[str], world: str, code: int
) -> None:
    """``--world league``: the league's crouched test robot (its knees 0.11 m in front of it at
    the ball's height, as wide as the Darwin-OP's) sends the league's ball pushed into it back
    past 1.4 m, in front of the knees of a robot put at 1.2 m, as the league's kick-off
    scenario needs (1.46 m with ODE's contacts); our straight-legged robot lets it through
    between its legs."""
    ball = results_of(capsys, "knee_bounce", "--world", world, code=code)[0]
    assert ball["name"] == "The ball came back"
    assert ball["status"] == ("pass" if code == 0 else "fail")


@pytest.mark.parametrize(
    ("ball", "contacts", "code"), [("league", "ode", 0), ("match", "spring", 1)]
)
def test_a_push_moves_the_league_ball_as_far_as_webots_moves_it(
    capsys: pytest.CaptureFixture[str], ball: str, contacts: str, code: int
) -> None:
    """``--ball league``: the league's ball as Webots simulates it, 0.0791 kg (its proto scales
    the Solid by 0.728 and ``WbSolid::createOdeMass`` gives ODE scale^3 x 0.205 kg), pushed with
    10 N for one 8 ms step (``addForce``, ``rc_testing.py:615-616``), rolls 0.5 m, past the
    0.32 m the league's ``scoring/goal`` needs of that push; the match ball with its rolling
    friction stops at 0.34 m."""
    rolled = results_of(capsys, "push", "--ball", ball, "--contacts", contacts, code=code)[0]
    assert rolled["name"] == "The ball rolled"
    assert rolled["status"] == ("pass" if code == 0 else "fail")


@pytest.mark.parametrize(
    ("ball", "contacts", "code"),
    [("league", "ode", 0), ("match", "ode", 0), ("league", "spring", 1), ("match", "spring", 1)],
)
def test_the_grass_takes_a_dropped_ball_dead_as_ode_s_does(
    capsys: pytest.CaptureFixture[str], ball: str, contacts: str, code: int
) -> None:
    """``--contacts ode``: the league's grass contact with the ball (``bounce 0.76`` at
    ``softCFM 0.05``, ``worlds/robocup.wbt:35-42``) is in ODE an over-damped spring whose bounce
    reaches 67 % of its target in a step: a ball dropped from 1 m leaves it at 0 to 0.17 of its
    speed and lies on the grass 0.75 s after it was let go; bounced at 0.76 it is 0.3-0.5 m up."""
    [result] = results_of(capsys, "drop", "--ball", ball, "--contacts", contacts, code=code)
    assert result["name"] == "The ball lies on the grass"
    assert result["status"] == ("pass" if code == 0 else "fail")


def test_a_ball_pushed_into_a_post_comes_back_as_ode_sends_it(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The league's ball and contacts (the defaults): pushed with 20 N for one step into a goal
    post 0.42 m away (a vertical face where the ball meets it; ODE's contact with anything but
    the grass, as with a robot's legs), the ball meets it at 0.83 m/s rolling, leaves at 0.742
    of it (``bounce 0.76`` at softCFM 0.001) with the spin the post's friction leaves it, rolls
    back at 0.45 of it and stops at x = 4.13 m, as computed for ODE (the scenario's last step)."""
    [result] = results_of(capsys, "post_rebound")
    assert (result["name"], result["status"]) == ("The ball came back", "pass")


def test_a_robot_s_velocity_is_set_on_its_torso_as_webots_sets_it(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The league's forceful contact scenarios set a robot's velocity every step, 0.24 m/s
    upward among it; Webots sets its root solid's alone (the torso's, a third of the robot's
    mass), so the robot, nearly weightless, slides on its feet at the speed set. Moved as a
    whole at that speed, it rose 0.19 m in the first second."""
    [result] = results_of(capsys, "robot_velocity")
    assert (result["name"], result["status"]) == ("Red 1 slides on the ground", "pass")


def _copy(tmp_path: Path, case: str = "failing") -> Path:
    target = tmp_path / case
    shutil.copytree(ROOT / case, target)
    return target


BAD_SCENARIOS = [
    ("[{\"timing\": {\"time\": 1}", "", "not JSON"),
    ("{\"timing\": {\"time\": 1}}", "", "expected a list of steps"),
    ("[{\"tests\": []}]", "/0", "a step needs a 'timing'"),
    ("[{\"timing\": {\"time\": 1, \"state\": \"PLAY\"}}]", "/0/timing/state",
     "expected one of INITIAL, READY, SET, PLAYING, FINISHED, got 'PLAY'"),
    ("[{\"timing\": {\"time\": [1, 2, 3]}}]", "/0/timing/time", "an interval is [start, end]"),
    ("[{\"timing\": {\"time\": 1, \"secondary_state\": \"THROWIN\"}}]", "/0/timing/phase",
     "a secondary_state timing needs its phase"),
    ("[{\"timing\": {\"time\": 1}, \"tests\": [{\"name\": \"x\", \"penalty\": 0}]}]",
     "/0/tests/0", "a test of 'penalty' needs a 'target'"),
    ("[{\"timing\": {\"time\": 1}, \"actions\": [{\"target\": \"GREEN_PLAYER_1\"}]}]",
     "/0/actions/0/target", "expected BALL, RED, BLUE or RED_PLAYER_<n>"),
    ("[{\"timing\": {\"time\": 1}, \"actions\": [{\"target\": \"BALL\", \"force\": [1, 2]}]}]",
     "/0/actions/0/force", "expected a list of 3 numbers"),
]  # fmt: skip


@pytest.mark.parametrize(("text", "pointer", "reason"), BAD_SCENARIOS)
def test_a_malformed_scenario_is_invalid_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, pointer: str, reason: str
) -> None:
    case = _copy(tmp_path)
    (case / "test_scenario.json").write_text(text)
    code, out, err = run(capsys, case)
    assert code == 2 and out == ""  # nothing played
    assert f"hlvs referee test: {case / 'test_scenario.json'}: {pointer or '/'}: {reason}" in err
    assert "Traceback" not in err


def test_a_missing_game_or_team_file_is_invalid_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    case = _copy(tmp_path)
    (case / "team_2.json").unlink()
    code, out, err = run(capsys, case / "test_scenario.json", "--json")
    assert code == 2
    assert json.loads(out)["ok"] is False
    assert f"{case / 'game.json'}: /blue/config: file not found" in err
    (case / "game.json").unlink()
    code, _, err = run(capsys, case)
    assert code == 2 and f"no game.json beside it ({case / 'game.json'})" in err


def test_a_folder_without_scenarios_is_invalid_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = run(capsys, tmp_path, tmp_path / "absent.json")
    assert code == 2 and out == ""
    assert f"{tmp_path}: no test_scenario.json in this folder" in err
    assert f"{tmp_path / 'absent.json'}: no such file or folder" in err


def test_the_shootout_kicks_on_the_goal_and_poses_the_league_gives(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Blue on the left, red first: all kicks on the goal at x < 0, the poses mirrored only for
    the team on the right, a goalkeeper off its line in SET removed, a ball at rest in the goal
    area ends the kick (hlvs_webots referee.py:1574-1605, 1657-1677, 2178-2185)."""
    code, out, _ = run(capsys, ROOT / "shootout", "--json")
    report = json.loads(out)
    assert code == 0 and report["ok"] is True, out
    (scenario,) = report["scenarios"]
    assert (scenario["tests"], scenario["passed"], scenario["ending"]) == (14, 14, "finished")


def test_a_team_without_a_kicker_loses_its_turns(capsys: pytest.CaptureFixture[str]) -> None:
    """Red kicks first with no player: each of its kicks is skipped and blue's set up in the
    same SET (hlvs_webots referee.py:1648-1654)."""
    code, out, _ = run(capsys, ROOT / "shootout_no_kicker", "--json")
    report = json.loads(out)
    assert code == 0 and report["ok"] is True, out
    (scenario,) = report["scenarios"]
    assert (scenario["tests"], scenario["passed"], scenario["ending"]) == (7, 7, "finished")
