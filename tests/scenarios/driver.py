"""Runs a :class:`Scenario` in the real MuJoCo world with the Referee (no clients, no network,
a fake wall clock that advances with simulated time) and checks its expectations."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

from contracts.geometry import Pose
from contracts.ids import RobotId, TeamColor
from contracts.match_spec import GameType, PlayerSpec, TeamSpec
from referee.autoref import Referee
from referee.clock import FakeClock
from referee.config import RefereeConfig, TimingConfig
from referee.gamecontroller.states import Card
from referee.snapshot import PlaceBall, RefereeEvent, TeleportRobot, WorldSnapshot
from simulator.world import RobotPlacement, World
from tests.scenarios.scenario import Action, Expectation, Scenario, parse_robot_id

SCENARIO_TIMING = TimingConfig(
    half_duration_s=300.0,
    overtime_half_duration_s=300.0,
    ready_duration_s=1.0,
    set_to_play_s=0.5,
    shootout_set_to_play_s=1.0,
    wait_before_first_ready_real_s=0.0,
    half_time_break_real_s=0.0,
    removal_penalty_s=3.0,
    set_play_phase0_s=0.5,
    set_play_ready_s=1.0,
    set_play_prepare_s=0.5,
    shootout_kick_s=8.0,
    status_period_real_s=1e9,
)
STEP_MS = 8


@dataclass
class Run:
    scenario: Scenario
    referee: Referee
    world: World
    failures: list[str] = field(default_factory=list)

    @property
    def events(self) -> list[RefereeEvent]:
        return self.referee.events


def build_config(scenario: Scenario) -> RefereeConfig:
    game = scenario.game
    side_left = TeamColor(game.get("side_left", "red"))
    kickoff = TeamColor(game.get("kickoff", "red"))
    half = int(game.get("half", 1))
    left_now = side_left if half == 1 else side_left.opponent
    timing = replace(SCENARIO_TIMING, **scenario.timing)
    players: dict[TeamColor, list[PlayerSpec]] = {TeamColor.RED: [], TeamColor.BLUE: []}
    for start in scenario.robots:
        # the scenario gives where the robot stands now: written back as if on the left half
        pose = Pose(x_m=start.x, y_m=start.y, yaw_rad=start.yaw).on_side(
            left=start.id.team is left_now)
        players[start.id.team].append(
            PlayerSpec(
                number=start.id.number,
                model="kid-default",
                port=10000 + start.id.number,
                half_time_pose=pose,
                reentry_pose=Pose(x_m=-3.0, y_m=-3.1, yaw_rad=math.pi / 2),
                shootout_pose=Pose(x_m=2.6, y_m=0.0, yaw_rad=0.0),
                goalkeeper_pose=Pose(x_m=-4.4, y_m=0.0, yaw_rad=0.0),
                goalkeeper=start.goalkeeper,
            )
        )
    teams = {
        color: TeamSpec(
            color=color.value,
            hosts=(),
            team_id=8 if color is TeamColor.RED else 25,
            name=f"{color.value} team",
            players=tuple(sorted(players[color], key=lambda p: p.number)),
        )
        for color in players
    }
    return RefereeConfig(
        red=teams[TeamColor.RED],
        blue=teams[TeamColor.BLUE],
        game_type=GameType(game.get("type", "NORMAL")),
        side_left=side_left,
        kickoff=kickoff,
        timing=timing,
        match_id=scenario.name,
        seed=int(game.get("seed", 0)),
        start_positions_checked=False,  # a scenario's robots start where it puts them, on the field
    )


def _robot_number(world: World, robot: RobotId) -> int:
    return int(world.index.by_id[robot].number)


def _apply_action(run: Run, action: Action, first: bool) -> None:
    world, args = run.world, action.args
    r = world.field.ball_radius_m
    if action.kind == "place_ball" and first:
        world.apply(
            PlaceBall(
                position=(
                    float(args.get("x", 0.0)),
                    float(args.get("y", 0.0)),
                    float(args.get("z", r)),
                ),
                velocity=(
                    float(args.get("vx", 0.0)),
                    float(args.get("vy", 0.0)),
                    float(args.get("vz", 0.0)),
                ),
            )
        )
        return
    robot = parse_robot_id(args.get("robot"), path=str(run.scenario.path), pointer="/actions")
    if action.kind == "card" and first:  # by hand, as the human referee at the GameController
        card = Card(str(args.get("card", "warning")))
        for command in run.referee.give_card(robot, card, "given by hand", world.snapshot()):
            world.apply(command)
        return
    info = world.index.robots[_robot_number(world, robot)]
    q0, d0 = info.qpos_range[0], info.dof_range[0]
    if action.kind == "teleport" and first:
        world.apply(
            TeleportRobot(
                robot=robot,
                pose=Pose(
                    x_m=float(args["x"]),
                    y_m=float(args["y"]),
                    yaw_rad=float(args.get("yaw", 0.0)),
                ),
            )
        )
    elif action.kind == "push":
        world.data.qvel[d0] = float(args.get("vx", 0.0))
        world.data.qvel[d0 + 1] = float(args.get("vy", 0.0))
    elif action.kind == "fall" and first:
        world.data.qpos[q0 + 2] = 0.12
        world.data.qpos[q0 + 3 : q0 + 7] = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)
        world.data.qvel[d0 : d0 + 6] = 0.0
    elif action.kind == "kick" and first:
        # the ball appears touching the robot's front and leaves with the given velocity
        x, y = world.data.qpos[q0], world.data.qpos[q0 + 1]
        vx, vy = float(args.get("vx", 0.0)), float(args.get("vy", 0.0))
        speed = math.hypot(vx, vy) or 1.0
        gap = float(args.get("gap", 0.2))
        world.apply(
            PlaceBall(
                position=(x + gap * vx / speed, y + gap * vy / speed, r), velocity=(vx, vy, 0.0)
            )
        )
        world.last_ball_toucher = robot
        world.last_ball_touch_ms = world.sim_time_ms


def _close(a: float, b: float, tol: float) -> bool:
    return abs(a - b) <= tol


def _check_state(run: Run, exp: Expectation, snap: WorldSnapshot) -> None:
    ref, gs = run.referee, run.referee.game_state
    path = str(run.scenario.path)

    def fail(key: str, want: Any, got: Any) -> None:
        run.failures.append(f"{exp.pointer} at {exp.at_s} s: {key}: expected {want!r}, got {got!r}")

    for key, want in exp.checks.items():
        if key in ("event", "no_event"):
            continue
        if key in ("state", "secondary_state", "half", "score", "left_team", "phase",
                   "secs_remaining"):
            if gs[key] != want:
                fail(key, want, gs[key])
        elif key == "kickoff":
            if gs["kickoff"] != want:
                fail(key, want, gs["kickoff"])
        elif key in ("set_play_team", "sub_phase"):
            play = gs["set_play"]
            got = None if play is None else play["team" if key == "set_play_team" else "sub_phase"]  # type: ignore[index]
            if got != want:
                fail(key, want, got)
        elif key in ("penalised", "not_penalised"):
            penalties = gs["penalties"]
            assert isinstance(penalties, dict)
            penalised = set(penalties)
            for name in want:
                if (name in penalised) != (key == "penalised"):
                    fail(key, name, sorted(penalised))
        elif key in ("limp", "not_limp", "removed"):
            for name in want:
                robot = parse_robot_id(name, path=path, pointer=exp.pointer)
                state = snap.robot(robot)
                got = state.removed if key == "removed" else state.limp
                if got != (key != "not_limp"):
                    fail(f"{key} {name}", True, got)
        elif key == "cards":
            for name, cards in want.items():
                robot = parse_robot_id(name, path=path, pointer=exp.pointer)
                info = ref.gc.robot(robot)
                got = {
                    "warnings": info.warnings,
                    "yellow": info.yellow_cards,
                    "red": info.red_cards,
                }
                for k, v in cards.items():
                    if got[k] != v:
                        fail(f"cards {name} {k}", v, got[k])
        elif key == "finished":
            if ref.finished != want:
                fail(key, want, ref.finished)
        elif key == "winner":
            got = ref.result()["winner"]
            if got != want:
                fail(key, want, got)
        elif key == "waiting":
            if ref.waiting_for_wall_clock != want:
                fail(key, want, ref.waiting_for_wall_clock)
        elif key == "ball_near":
            bx, by = snap.ball.position[0], snap.ball.position[1]
            tol = float(want.get("tol", 0.1))
            if not (_close(bx, want["x"], tol) and _close(by, want["y"], tol)):
                fail(key, (want["x"], want["y"]), (round(bx, 3), round(by, 3)))
        elif key == "robot_near":
            robot = parse_robot_id(want["robot"], path=path, pointer=exp.pointer)
            pos = snap.robot(robot).position
            tol = float(want.get("tol", 0.15))
            if not (_close(pos[0], want["x"], tol) and _close(pos[1], want["y"], tol)):
                fail(key, (want["x"], want["y"]), (round(pos[0], 3), round(pos[1], 3)))


def _matches(event: RefereeEvent, want: dict[str, Any]) -> bool:
    window = want.get("within_s")
    if window is not None and not (window[0] * 1000 <= event.sim_time_ms <= window[1] * 1000):
        return False
    if "type" in want and event.type != want["type"]:
        return False
    if "team" in want and (event.team.value if event.team else None) != want["team"]:
        return False
    if "player" in want and event.player != want["player"]:
        return False
    if "reason_contains" in want and want["reason_contains"] not in event.reason:
        return False
    for key, value in want.get("details", {}).items():
        if event.details.get(key) != value:
            return False
    return True


def run_scenario(scenario: Scenario, *, seed: int = 1) -> Run:
    config = build_config(scenario)
    half = int(scenario.game.get("half", 1))
    placements = []
    for start in scenario.robots:
        x, yaw = start.x, start.yaw
        if half == 2:
            x, yaw = -x, math.pi - yaw
        placements.append(
            RobotPlacement(id=start.id, model="kid-default", x_m=x, y_m=start.y, yaw_rad=yaw)
        )
    world = World.create(field_class="kid", robots=placements, seed=seed)
    clock = FakeClock()
    referee = Referee(config=config, clock=clock)
    run = Run(scenario, referee, world)
    pending = sorted(
        (e for e in scenario.expectations if e.at_s is not None), key=lambda e: e.at_s or 0.0
    )
    started: set[int] = set()
    end_ms = int(scenario.duration_s * 1000)
    while world.sim_time_ms <= end_ms:
        now_s = world.sim_time_ms / 1000.0
        snap = world.snapshot()
        while pending and (pending[0].at_s or 0.0) <= now_s + 1e-9:
            _check_state(run, pending.pop(0), snap)
        for command in referee.step(snap):
            world.apply(command)
        for i, action in enumerate(scenario.actions):
            if action.at_s > now_s + 1e-9:
                continue
            if i not in started or (action.until_s is not None and now_s <= action.until_s):
                _apply_action(run, action, i not in started)
                started.add(i)
        world.step()
        clock.advance(STEP_MS / 1000.0)
    for exp in pending:
        run.failures.append(f"{exp.pointer}: at_s {exp.at_s} is after duration_s")
    for exp in scenario.expectations:
        if "event" in exp.checks and not any(_matches(e, exp.checks["event"]) for e in run.events):
            run.failures.append(f"{exp.pointer}: no event {exp.checks['event']}")
        if "no_event" in exp.checks:
            bad = [e for e in run.events if _matches(e, exp.checks["no_event"])]
            if bad:
                run.failures.append(f"{exp.pointer}: unexpected event {bad[0]}")
    referee.close()
    return run


def describe(run: Run) -> str:
    lines = [f"{run.scenario.name}: {run.scenario.description}"]
    lines += [f"  FAIL {f}" for f in run.failures]
    lines += [
        f"  {e.sim_time_ms / 1000:7.3f} {e.type} {e.team.value if e.team else '-'} "
        f"{e.player or ''} {e.reason} {e.placement or ''}"
        for e in run.events
    ]
    return "\n".join(lines)
