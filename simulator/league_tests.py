"""Plays a league referee test scenario (:mod:`referee.league_scenario`) against our referee in
the MuJoCo world, as the league's test supervisor plays it against its referee in Webots.

The league's loop (``controllers/test_supervisor/test_supervisor.py:79-96``, one basic step of
8 ms each turn): read the latest GameController packet, advance its simulated clock, then run
every waiting step of the scenario (``rc_testing.Scenario.step``, 649-660): a step whose timing
is active runs its tests, then its actions; a step whose timing is over is finished and its
tests counted. It stops when every step is finished or a critical test has failed
(``hasCriticalFailure``). Here each turn the referee steps on the world's snapshot (its
commands applied), the packet it would send is decoded with the league's field names, the
scenario steps, and the world advances one basic step with the actions' forces applied. No
client drives the robots: they stand, held in their standing pose, as the league's test robots
have no controller. Differences from Webots, all of the world and none of the rules:

- The robots are our models, not the league's Darwin-OP (``RobocupRobot``): a robot's height
  in a position is read against the team file's ``halfTimeStartingPose`` height (its standing
  height in the league's world) and put at ours; a tested robot height is converted back. With
  ``world="league"`` (the default) every robot of a kid-size game is the league's test robot
  (:mod:`simulator.world.robots.league`: the Darwin-OP's size, mass and stored crouch, its legs
  where the scenarios push the ball and the other robot; 26 of the league's 47 files pass with
  it, 24 with our robots, README, before the ball's contacts below), and with spring contacts
  the ball bounces at 0.76 off the grass and the robots, as the league's world sets its bounce
  (:func:`simulator.world.ball.use_league_bounce`; the match ball: 0.84); matches never play
  either.
- A ball placed lower than its radius rests on the ground (both engines push it out; MuJoCo's
  push would throw it).
- The "System" clock is the referee's wall clock (its real-time waits: before the first READY,
  the half-time break), driven by the simulated one at the pace of the league's world: at the
  game's maximum real-time factor (the league's referee holds each step to it, referee.py:2457-
  2470), or :data:`FAST_SPEED` times real time for a game run as fast as possible (the league's
  world then runs at its host's speed: its scenarios expect a 2 s half-time break,
  referee.py:1913-1916, to last more than 5 simulated seconds).
- The packet is read the step it is made (the league's arrives by UDP, a step or more later).
- The ball is the league's (``ball="league"``, the default,
  :func:`simulator.world.ball.use_league_ball`: the 0.0791 kg Webots gives ODE for the scaled
  ``protos/RobocupTexturedSoccerBall.proto``, its damping, no rolling friction), as the
  scenarios' pushes were tuned to it, or on request the match ball; matches always play the
  match ball. A ``force`` acts for one basic step, as Webots' does (``WbSupervisorUtilities``:
  ADD_FORCE calls ``dBodyAddForceAtRelPos`` once; ODE clears a body's forces after every step).
- The ball's contacts are as ODE makes the league's (``contacts="ode"``, the default,
  :func:`simulator.world.ball.use_league_contacts`: the grass's soft contact, which takes a
  dropped ball dead, restitution 0.74 and Coulomb friction 1 off the robots and goals, the ball
  gone from a robot within about one basic step as ODE's is, no rolling friction), or on
  request springs and dampers (``contacts="spring"``: the ball bounces at 0.76 off everything in
  the league's world). With the league's ball, these contacts and the league's test robot 45 of
  the league's 47 files pass (README).

The league's world lets resting bodies sleep (``worlds/robocup.wbt:24-26``: physics disabled
for a body slower than 0.1 m/s and 0.1 rad/s for 0.1 s); here the whole world sleeps when every
body and joint has been that slow for 0.1 s, until an action or a referee command wakes it: most
of a scenario is robots standing and a ball at rest for minutes, and they are skipped.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import mujoco
import numpy as np

from contracts import GameControlData, MatchSpec, RobotId, TeamColor, decode_game_state
from referee import (
    FakeClock,
    LeagueScenario,
    LeagueStep,
    LeagueTarget,
    LeagueTest,
    LeagueTiming,
    Referee,
)
from simulator.match_setup import referee_config
from simulator.world import World
from simulator.world.ball import (
    BALL_BODY,
    use_league_ball,
    use_league_bounce,
    use_league_contacts,
)
from simulator.world.robots import LEAGUE_TEST_KID_NAME

# rc_testing.py:26 (VALID_SEC_STATES) with the wire codes of gamestate.py:78-90
SECONDARY_NAMES = {
    0: "NORMAL", 1: "PENALTYSHOOT", 2: "OVERTIME", 3: "TIMEOUT", 4: "DIRECT_FREEKICK",
    5: "INDIRECT_FREEKICK", 6: "PENALTYKICK", 7: "CORNERKICK", 8: "GOALKICK", 9: "THROWIN",
    128: "DROPBALL", 255: "UNKNOWN",
}  # fmt: skip
STATE_NAMES = {0: "INITIAL", 1: "READY", 2: "SET", 3: "PLAYING", 4: "FINISHED"}
END_OF_GAME_S = 5.0  # referee_config.yaml END_OF_GAME_TIMEOUT: the league's world runs on
FAST_SPEED = 10.0  # simulated seconds per wall second of a game run as fast as possible
SLEEP_SPEED = 0.1  # robocup.wbt: physicsDisableLinearThreshold / physicsDisableAngularThreshold
SLEEP_AFTER_MS = 100  # robocup.wbt: physicsDisableTime 0.1
LEAGUE_STANDING_Z_M = 0.24  # a RobocupRobot's halfTimeStartingPose height in the league's files
Ending = Literal["finished", "critical", "game_over", "time_limit"]
BallKind = Literal["league", "match"]
WorldKind = Literal["league", "match"]
ContactKind = Literal["ode", "spring"]


@dataclass
class LeagueTestOutcome:
    step: int
    pointer: str
    name: str
    critical: bool
    status: Literal["pass", "fail", "skip"] = "pass"
    failures: list[str] = field(default_factory=list)
    ignored: tuple[str, ...] = ()

    def to_json(self) -> dict[str, Any]:
        return {
            "step": self.step, "pointer": self.pointer, "name": self.name,
            "critical": self.critical, "status": self.status, "failures": self.failures,
            "ignored_keys": list(self.ignored),
        }  # fmt: skip


@dataclass
class LeagueOutcome:
    path: Path
    tests: list[LeagueTestOutcome]
    ending: Ending
    sim_time_s: float
    wall_s: float
    unfinished_steps: list[str] = field(default_factory=list)
    asleep_s: float = 0.0  # simulated seconds the world slept (nothing moved)

    @property
    def passed(self) -> int:
        return sum(t.status == "pass" for t in self.tests)

    @property
    def ok(self) -> bool:
        return self.passed == len(self.tests)

    def to_json(self) -> dict[str, Any]:
        return {
            "path": str(self.path), "ok": self.ok, "passed": self.passed,
            "tests": len(self.tests), "ending": self.ending,
            "sim_time_s": round(self.sim_time_s, 3), "asleep_s": round(self.asleep_s, 3),
            "wall_s": round(self.wall_s, 2),
            "unfinished_steps": self.unfinished_steps,
            "results": [t.to_json() for t in self.tests],
        }  # fmt: skip


class Status:
    """The latest packet and when each state and secondary state (per phase) was first reached
    (``rc_testing.StatusInformation``, 27-190)."""

    def __init__(self) -> None:
        self.system_s = 0.0
        self.simulated_s = 0.0
        self.gc: GameControlData | None = None
        self._state_starts: dict[str, list[tuple[float, float]]] = {}
        self._secondary_starts: dict[tuple[str, int], list[tuple[float, float]]] = {}

    def update(self, system_s: float, simulated_s: float, gc: GameControlData) -> None:
        self.system_s, self.simulated_s = system_s, simulated_s
        last = self.gc
        stamp = (simulated_s, system_s)
        if last is None or gc.state != last.state:
            self._state_starts.setdefault(self.state_name(gc), []).append(stamp)
        if (last is None or gc.secondary_state != last.secondary_state
                or gc.secondary_state_info[1] != last.secondary_state_info[1]):  # fmt: skip
            key = (self.secondary_name(gc), gc.secondary_state_info[1])
            self._secondary_starts.setdefault(key, []).append(stamp)
        self.gc = gc

    @staticmethod
    def state_name(gc: GameControlData) -> str:
        return STATE_NAMES.get(gc.state, str(gc.state))

    @staticmethod
    def secondary_name(gc: GameControlData) -> str:
        return SECONDARY_NAMES.get(gc.secondary_state, str(gc.secondary_state))

    def now(self, timing: LeagueTiming) -> float | None:
        """``getCurrentTime`` (rc_testing.py:202-216): seconds on the timing's clock since the
        moment it names, None before that moment."""
        index = 0 if timing.clock == "Simulated" else 1
        offset = 0.0
        starts: list[tuple[float, float]] | None = None
        if timing.state is not None:
            starts = self._state_starts.get(timing.state, [])
        elif timing.secondary_state is not None:
            starts = self._secondary_starts.get((timing.secondary_state, timing.phase or 0), [])
        if starts is not None:
            if len(starts) < timing.state_count:
                return None
            offset = starts[timing.state_count - 1][index]
        return (self.simulated_s if index == 0 else self.system_s) - offset

    def when(self) -> str:
        return f"sim {self.simulated_s:.3f} s"


def is_active(timing: LeagueTiming, now: float | None) -> bool:
    """``TimePoint.isActive`` / ``TimeInterval.isActive`` (rc_testing.py:250-252, 270-272)."""
    if now is None:
        return False
    if timing.end_s is None:
        return now > timing.start_s
    return timing.start_s < now <= timing.end_s


def is_finished(timing: LeagueTiming, now: float | None) -> bool:
    if now is None:
        return False
    return now > (timing.start_s if timing.end_s is None else timing.end_s)


class _Body:
    """A target in the MuJoCo world: the ball or a robot's root."""

    def __init__(self, runner: LeagueTestRunner, target: LeagueTarget) -> None:
        world = runner.world
        self.robot = target.robot
        if self.robot is None:
            self.body = int(world.model.body(BALL_BODY).id)
            self.qpos = world.index.ball_qpos
            self.dofs = (world.index.ball_dof, world.index.ball_dof + 6)
            self.z_offset = 0.0
        else:
            info = world.index.by_id[self.robot]
            self.body = info.torso_body
            self.qpos = info.root_qpos
            self.dofs = info.dof_range
            standing = info.model.standing_height_m
            self.z_offset = standing - runner.league_standing_z.get(self.robot, LEAGUE_STANDING_Z_M)


class LeagueTestRunner:
    def __init__(
        self,
        spec: MatchSpec,
        scenario: LeagueScenario,
        *,
        league_standing_z: Mapping[RobotId, float] | None = None,
        max_sim_s: float = 3600.0,
        ball: BallKind = "league",
        world: WorldKind = "league",
        contacts: ContactKind = "ode",
    ) -> None:
        self.spec = spec
        self.scenario = scenario
        self.league_standing_z = dict(league_standing_z or {})
        self.max_sim_s = max_sim_s
        placements = World.placements_of(spec)
        if world == "league" and spec.field_class == "kid":
            placements = [replace(p, model=LEAGUE_TEST_KID_NAME) for p in placements]
        self.world = World.create(
            field_class=spec.field_class,
            robots=placements,
            seed=spec.seed,
            physics_dt_s=spec.physics_dt_s,
            ball_turf_pair=contacts == "ode",
        )
        if world == "league":
            use_league_bounce(self.world.model)
        if ball == "league":
            use_league_ball(self.world.model, self.world.field)
        if contacts == "ode":
            use_league_contacts(self.world.model)  # after the ball's mass is set
        self.clock = FakeClock()
        rtf = spec.maximum_real_time_factor
        self.speed = rtf if rtf > 0 else FAST_SPEED  # simulated seconds per wall second
        config = referee_config(spec)
        config = replace(config, timing=replace(config.timing, status_period_real_s=1e9))
        self.referee = Referee(config=config, clock=self.clock)
        self.status = Status()
        self._bodies: dict[str, _Body] = {}
        self._outcomes = {
            (step.index, test.pointer): LeagueTestOutcome(
                step=step.index, pointer=test.pointer, name=test.name, critical=test.critical,
                ignored=test.ignored,
            )
            for step in scenario.steps
            for test in step.tests
        }  # fmt: skip
        # each test fails once, then stops checking that key (rc_testing.py: "Each test can
        # only fail once to avoid spamming")
        self._spent: set[tuple[str, str]] = set()

    # --- the world ---------------------------------------------------------------------------

    def body(self, target: LeagueTarget) -> _Body:
        found = self._bodies.get(target.name)
        if found is None:
            found = self._bodies[target.name] = _Body(self, target)
        return found

    def position(self, target: LeagueTarget) -> tuple[float, float, float]:
        b = self.body(target)
        x, y, z = (float(v) for v in self.world.data.qpos[b.qpos : b.qpos + 3])
        return x, y, z - b.z_offset

    def _perform(self, step: LeagueStep) -> None:
        """``Action.perform`` (rc_testing.py:505-531): position (with resetPhysics), rotation,
        force for one basic step (``addForce``), velocity."""
        world = self.world
        data = world.data
        for action in step.actions:
            b = self.body(action.target)
            if action.position is not None:
                x, y, z = action.position
                z += b.z_offset
                if b.robot is None:
                    z = max(z, world.field.ball_radius_m)
                data.qpos[b.qpos : b.qpos + 3] = (x, y, z)
                data.qvel[b.dofs[0] : b.dofs[1]] = 0.0
            if action.orientation is not None:
                ax, ay, az, angle = action.orientation
                norm = math.sqrt(ax * ax + ay * ay + az * az)
                s = math.sin(angle / 2) / norm
                data.qpos[b.qpos + 3 : b.qpos + 7] = (math.cos(angle / 2), ax * s, ay * s, az * s)
            if action.force is not None:
                data.xfrc_applied[b.body, 0:3] += action.force
            if action.velocity is not None and b.robot is None:
                linear, angular = np.array(action.velocity[:3]), np.array(action.velocity[3:])
                quat = data.qpos[b.qpos + 3 : b.qpos + 7]
                local = np.zeros(3)
                mujoco.mju_rotVecQuat(local, angular, _conjugate(quat))
                data.qvel[b.dofs[0] : b.dofs[0] + 3] = linear
                data.qvel[b.dofs[0] + 3 : b.dofs[0] + 6] = local
            if b.robot is not None:
                info = world.index.by_id[b.robot]
                if info.number in world.parked_qpos:  # removed: it stays where it is put
                    start, end = info.qpos_range
                    world.parked_qpos[info.number] = data.qpos[start:end].copy()
        mujoco.mj_forward(world.model, data)
        for action in step.actions:
            b = self.body(action.target)
            if action.velocity is not None and b.robot is not None:
                self._set_root_velocity(b, action.velocity)

    def _set_root_velocity(self, b: _Body, velocity: tuple[float, ...]) -> None:
        """``setVelocity`` on a robot, as Webots does it: the velocity of the robot's root solid
        alone (its torso's ODE body, ``WbSupervisorUtilities`` C_SUPERVISOR_NODE_SET_VELOCITY
        -> ``WbSolid::setLinearVelocity``/``setAngularVelocity`` -> ``dBodySetLinearVel``),
        the bodies hinged to it keeping theirs; the joints then share the change with them in
        the step. Setting a body's velocity is an impulse of its mass times the change; here
        that impulse is applied to the torso over the next step (so a robot set to 0.24 m/s
        upward every step, as the scenarios do, is nearly weightless and slides on its feet:
        the Darwin-OP's torso is a third of its mass, 0.98 kg x 0.24 m/s against 2.93 kg x g x
        8 ms, and does not fly off as a whole robot set to that speed would)."""
        world = self.world
        model, data = world.model, world.data
        current = np.zeros(6)  # angular, linear at the torso's centre of mass, world axes
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, b.body, current, 0)
        dt = world.step_ms / 1000.0
        mass = float(model.body_mass[b.body])
        linear = np.array(velocity[:3], dtype=float)
        angular = np.array(velocity[3:6], dtype=float)
        frame = data.ximat[b.body].reshape(3, 3)  # the torso's principal axes
        inertia = frame @ np.diag(model.body_inertia[b.body]) @ frame.T
        data.xfrc_applied[b.body, 0:3] += mass * (linear - current[3:6]) / dt
        data.xfrc_applied[b.body, 3:6] += inertia @ (angular - current[0:3]) / dt

    # --- the tests ---------------------------------------------------------------------------

    def _check(self, step: LeagueStep, test: LeagueTest) -> None:
        outcome = self._outcomes[(step.index, test.pointer)]
        gc = self.status.gc
        assert gc is not None
        for key, want in test.checks.items():
            if (test.pointer, key) in self._spent:
                continue
            got, what = self._observe(test, key, gc)
            if key == "position":
                ok = bool(np.allclose(want, got, atol=test.abs_tol))
            else:
                ok = got == want
            if not ok:
                self._spent.add((test.pointer, key))
                outcome.status = "fail"
                outcome.failures.append(
                    f"{what}: expected {_show(want)}, received {_show(got)} "
                    f"({self.status.when()}, {step.timing.describe()})"
                )

    def _observe(self, test: LeagueTest, key: str, gc: GameControlData) -> tuple[Any, str]:
        target = test.target
        if key == "position":
            assert target is not None
            return [round(v, 3) for v in self.position(target)], f"position of {target.name}"
        if key == "state":
            return Status.state_name(gc), "state"
        if key == "secondary_state":
            return Status.secondary_name(gc), "secondary state"
        if key == "secondary_team_id":
            return gc.secondary_state_info[0], "secondary team id"
        if key == "secondary_phase":
            return gc.secondary_state_info[1], "secondary phase"
        if key == "kick_off_team":
            return gc.kick_off_team, "kick-off team"
        assert target is not None and target.team is not None
        colour = 1 if target.team is TeamColor.RED else 0
        team = next((t for t in gc.teams if t.team_colour == colour), None)
        if team is None:
            return None, f"{key} of {target.name}"
        if key == "score":
            return team.score, f"score of {target.team.value}"
        assert target.number is not None
        if target.number > len(team.players):
            return None, f"{key} of {target.name}"
        robot = team.players[target.number - 1]
        value = {
            "penalty": robot.penalty,
            "warnings": robot.number_of_warnings,
            "yellow_cards": robot.yellow_card_count,
            "red_cards": robot.red_card_count,
        }[key]
        return value, f"{key.replace('_', ' ')} of {target.name}"

    # --- the loop ----------------------------------------------------------------------------

    def run(self) -> LeagueOutcome:
        started = time.perf_counter()
        world, referee = self.world, self.referee
        waiting = list(self.scenario.steps)
        ending: Ending = "time_limit"
        over_at_s: float | None = None
        start_system = self.clock.monotonic()
        max_ms = int(self.max_sim_s * 1000)
        last_key: object = None
        slow_ms = 0
        sleeping_steps = 0
        gc: GameControlData | None = None
        while world.sim_time_ms <= max_ms:
            snapshot = world.snapshot()
            commands = referee.step(snapshot)
            for command in commands:
                world.apply(command)
            woken = bool(commands)
            key = _gc_key(referee)
            if key != last_key:  # what the tests read changed: the packet made and read again
                gc, last_key = decode_game_state(referee.packet()), key
            assert gc is not None
            self.status.update(self.clock.monotonic() - start_system, world.sim_time_ms / 1000, gc)
            done = []
            for step in waiting:
                now = self.status.now(step.timing)
                if is_active(step.timing, now):
                    for test in step.tests:
                        self._check(step, test)
                    if step.actions:
                        self._perform(step)
                        woken = True
                if is_finished(step.timing, now):
                    done.append(step)
            for step in done:
                waiting.remove(step)
            if not waiting:
                ending = "finished"
                break
            if any(o.critical and o.status == "fail" for o in self._outcomes.values()):
                ending = "critical"
                break
            if referee.finished:
                over_at_s = over_at_s if over_at_s is not None else world.sim_time_ms / 1000
                # the league's referee steps END_OF_GAME_TIMEOUT more, then once before it
                # quits (referee.py:174-178, 193)
                if world.sim_time_ms / 1000 - over_at_s > END_OF_GAME_S:
                    ending = "game_over"
                    break
            if woken:
                slow_ms = 0
            if slow_ms >= SLEEP_AFTER_MS:
                world.sim_time_ms += world.step_ms  # asleep: nothing moves
                world.data.time += world.step_ms / 1000
                sleeping_steps += 1
            else:
                world.step()
                world.data.xfrc_applied[:] = 0.0
                slow = float(np.abs(world.data.qvel).max(initial=0.0)) < SLEEP_SPEED
                slow_ms = slow_ms + world.step_ms if slow else 0
            self.clock.advance(world.step_ms / 1000 / self.speed)
        referee.close()
        waiting_pointers = {step.index for step in waiting}
        for outcome in self._outcomes.values():
            if outcome.step in waiting_pointers and outcome.status == "pass":
                outcome.status = "skip"  # counted as not passed, as the league counts it
        return LeagueOutcome(
            path=self.scenario.path,
            tests=sorted(self._outcomes.values(), key=lambda o: (o.step, o.pointer)),
            ending=ending,
            sim_time_s=world.sim_time_ms / 1000,
            wall_s=time.perf_counter() - started,
            unfinished_steps=[f"{s.pointer} ({s.timing.describe()})" for s in waiting],
            asleep_s=sleeping_steps * world.step_ms / 1000,
        )


def _gc_key(referee: Referee) -> object:
    """What the league's tests read of the packet (states, set play, kick-off, scores, penalties
    and cards), cheaper to compare than the packet is to make every step."""
    gc = referee.gc
    play = gc.set_play
    return (
        gc.state, gc.secondary_state, gc.half, gc.kickoff_team, referee.left_team,
        None if play is None else (play.team, play.sub_phase),
        tuple(
            (team.score, tuple(
                (n, r.penalty, r.warnings, r.yellow_cards, r.red_cards)
                for n, r in team.robots.items()
            ))
            for team in gc.teams.values()
        ),
    )  # fmt: skip


def _conjugate(quat: np.ndarray) -> np.ndarray:
    w, x, y, z = (float(v) for v in quat)
    norm = w * w + x * x + y * y + z * z or 1.0
    return np.array([w, -x, -y, -z]) / norm


def _show(value: object) -> str:
    if isinstance(value, list | tuple):
        return "[" + ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value) + "]"
    return str(value)


def run_league_scenario(
    spec: MatchSpec,
    scenario: LeagueScenario,
    *,
    league_standing_z: Mapping[RobotId, float] | None = None,
    max_sim_s: float = 3600.0,
    ball: BallKind = "league",
    world: WorldKind = "league",
    contacts: ContactKind = "ode",
) -> LeagueOutcome:
    """Play ``scenario`` in the match of ``spec`` (its game and teams) and return the outcome;
    ``ball``: the league's (default) or the match ball; ``contacts``: the ball's as ODE makes
    them (default) or springs and dampers; ``world``: the league's test robot
    (``"league"``, default: :mod:`simulator.world.robots.league`) or our robots (``"match"``)."""
    return LeagueTestRunner(
        spec,
        scenario,
        league_standing_z=league_standing_z,
        max_sim_s=max_sim_s,
        ball=ball,
        world=world,
        contacts=contacts,
    ).run()
