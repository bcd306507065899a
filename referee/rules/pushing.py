"""Pushing (forceful contact), the documented subset of the virtual league's rule we judge.

Only contacts between opponents count, and only while PLAYING (not in the shoot-out).

* Sustained contact: a pair of opponents in contact for more than 1 s within the last 2 s,
  both within 2 m of the ball, one at least 0.1 m farther from the ball than the other: the
  farther one pushes.
* Charging: when a contact begins, a robot moving at least 0.2 m/s faster than the other,
  towards it, and more than 30 degrees away from the direction of the ball, charges.

Speeds are those of the virtual league's referee: the centre of mass's average velocity over
the last second (:class:`VelocityTracks`), so the sway of a walk or the first instants of a fall
are not a charge. A jump of more than 0.5 m between two snapshots (a robot placed by the
referee) starts the average again.

Consequence, for the pusher, as in the virtual league (no card): when the ball is in play and
the pusher is within 1 m of it, a direct free kick for the other team at the victim's position
(a penalty kick when the ball lies fully inside the penalty area the other team attacks, as the
league decides it, :func:`referee.rules.base.free_kick`); otherwise removal for
PHYSICAL_CONTACT. A pair is immune for 2 s after a foul.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

from contracts import RobotId
from referee.gamecontroller.states import GameState, Penalty, SecondaryState
from referee.rules.base import Decision, GameView, PenalizeRobot, distance2d, free_kick
from referee.snapshot import RobotState, Vec3, WorldSnapshot

PERIOD_MS = 2000
CONTACT_MS = 1000
BALL_RANGE_M = 2.0
FARTHER_M = 0.1
CHARGE_SPEED_M_S = 0.2
CHARGE_ANGLE_RAD = math.radians(30.0)
FREE_KICK_RANGE_M = 1.0
IMMUNITY_MS = 2000
AVERAGE_MS = 1000  # speeds are averaged over this long
JUMP_M = 0.5  # a larger move between two snapshots is a placement, not motion

Pair = tuple[RobotId, RobotId]


class VelocityTracks:
    """Recent centre-of-mass positions of every robot, for 1 s average velocities."""

    def __init__(self) -> None:
        self._tracks: dict[RobotId, deque[tuple[int, float, float]]] = {}

    def add(self, snapshot: WorldSnapshot) -> None:
        now = snapshot.sim_time_ms
        for robot in snapshot.robots:
            x, y = robot.center_of_mass[0], robot.center_of_mass[1]
            track = self._tracks.setdefault(robot.id, deque())
            if track and math.hypot(x - track[-1][1], y - track[-1][2]) > JUMP_M:
                track.clear()
            track.append((now, x, y))
            while len(track) > 2 and track[1][0] <= now - AVERAGE_MS:
                track.popleft()

    def velocity(self, robot: RobotId) -> Vec3:
        """Average velocity over the last second (or since the robot was placed)."""
        track = self._tracks.get(robot)
        if not track or len(track) < 2:
            return (0.0, 0.0, 0.0)
        (t0, x0, y0), (t1, x1, y1) = track[0], track[-1]
        dt = (t1 - t0) / 1000.0
        return ((x1 - x0) / dt, (y1 - y0) / dt, 0.0) if dt > 0 else (0.0, 0.0, 0.0)


@dataclass(frozen=True, slots=True)
class PushingMemory:
    contacts: dict[Pair, tuple[tuple[int, int], ...]] = field(default_factory=dict)
    immune_until: dict[Pair, int] = field(default_factory=dict)
    last_ms: int | None = None
    tracks: VelocityTracks = field(default_factory=VelocityTracks)


def _pair(a: RobotId, b: RobotId) -> Pair:
    key_a, key_b = (a.team.value, a.number), (b.team.value, b.number)
    return (a, b) if key_a <= key_b else (b, a)


def _charging(
    pusher: RobotState, victim: RobotState, ball: tuple[float, float], tracks: VelocityTracks
) -> bool:
    vx, vy, _ = tracks.velocity(pusher.id)
    victim_velocity = tracks.velocity(victim.id)
    speed = math.hypot(vx, vy)
    if speed - math.hypot(victim_velocity[0], victim_velocity[1]) <= CHARGE_SPEED_M_S:
        return False
    to_victim = (victim.position[0] - pusher.position[0], victim.position[1] - pusher.position[1])
    if vx * to_victim[0] + vy * to_victim[1] <= 0:
        return False
    to_ball = (ball[0] - pusher.position[0], ball[1] - pusher.position[1])
    norm = math.hypot(*to_ball)
    if norm < 1e-6:
        return False
    cos = (vx * to_ball[0] + vy * to_ball[1]) / (speed * norm)
    return math.acos(max(-1.0, min(1.0, cos))) > CHARGE_ANGLE_RAD


def _sustained_pusher(a: RobotState, b: RobotState, ball: tuple[float, float]) -> RobotState | None:
    da, db = distance2d(a.position, ball), distance2d(b.position, ball)
    if da > BALL_RANGE_M or db > BALL_RANGE_M or abs(da - db) < FARTHER_M:
        return None
    return a if da > db else b


def _consequence(
    pusher: RobotState, victim: RobotState, game: GameView, ball: tuple[float, float], why: str
) -> list[Decision]:
    decisions: list[Decision] = []
    near = distance2d(pusher.position, ball) <= FREE_KICK_RANGE_M
    if game.running and game.ball_in_play and near:
        spot = (victim.position[0], victim.position[1])
        decisions.append(free_kick(victim.id.team, spot, ball, game, why))
    else:
        decisions.append(PenalizeRobot(pusher.id, Penalty.PHYSICAL_CONTACT, why))
    return decisions


def judge(
    snapshot: WorldSnapshot, game: GameView, memory: PushingMemory
) -> tuple[list[Decision], PushingMemory]:
    if game.state is not GameState.PLAYING or game.phase is SecondaryState.PENALTYSHOOT:
        return [], PushingMemory()
    tracks = memory.tracks
    tracks.add(snapshot)
    now = snapshot.sim_time_ms
    previous = memory.last_ms if memory.last_ms is not None else now
    robots = {r.id: r for r in snapshot.robots if game.active(r)}
    touching: set[Pair] = set()
    for robot in robots.values():
        for other in robot.robot_contacts:
            if other.team is not robot.id.team and other in robots:
                touching.add(_pair(robot.id, other))
    ball = (snapshot.ball.position[0], snapshot.ball.position[1])
    contacts: dict[Pair, tuple[tuple[int, int], ...]] = {}
    immune = {p: t for p, t in memory.immune_until.items() if t > now}
    decisions: list[Decision] = []
    for pair in sorted(touching | set(memory.contacts), key=lambda p: str(p)):
        intervals = [iv for iv in memory.contacts.get(pair, ()) if iv[1] > now - PERIOD_MS]
        onset = False
        if pair in touching:
            if intervals and intervals[-1][1] == previous:
                intervals[-1] = (intervals[-1][0], now)
            else:
                intervals.append((previous, now))
                onset = True
        if pair in immune or pair not in touching:
            if intervals:
                contacts[pair] = tuple(intervals)
            continue
        a, b = robots[pair[0]], robots[pair[1]]
        pusher: RobotState | None = None
        why = ""
        if onset and _charging(a, b, ball, tracks):
            pusher, why = a, "charging"
        elif onset and _charging(b, a, ball, tracks):
            pusher, why = b, "charging"
        elif sum(end - max(start, now - PERIOD_MS) for start, end in intervals) > CONTACT_MS:
            pusher, why = _sustained_pusher(a, b, ball), "pushing"
        if pusher is None:
            contacts[pair] = tuple(intervals)
            continue
        victim = b if pusher is a else a
        decisions.extend(_consequence(pusher, victim, game, ball, f"{why} {victim.id}"))
        immune[pair] = now + IMMUNITY_MS
    return decisions, PushingMemory(contacts, immune, now, tracks)
