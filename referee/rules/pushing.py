"""Forceful contact (pushing, charging), decided as the virtual league's referee decides it.

Only contacts between opponents count, and only while PLAYING outside a set play's sub-phase 0
(not in the shoot-out). Every step two opponents touch, the league's decision tree runs for the
red robot as the possible offender, then for the blue one (hlvs_webots
``controllers/referee/referee.py:948-1011``, ``check_team_forceful_contacts``; called from
1019-1027 and 2127-2129). With ``d1`` the offender's distance to the ball and ``d2`` its
opponent's, the offender commits a foul when:

1. its opponent is a goalkeeper inside its own goal area (962-965);
2. the two touched for more than 1 s of the last 2 s (``forceful_contact_matrix.py``), ``d1`` is
   under 2 m and ``d1 - d2`` over 0.1 m: the farther one pushes (973-981);
3. otherwise only an offender faster than 0.2 m/s can foul (986-987); then
   * near the ball (``d1`` under 2 m), when its opponent moves to the ball (slower than
     0.2 m/s, or within 30 degrees of the ball's direction, 933-942): if the offender does not
     move to the ball it charges (995-999); if it does but is more than 0.1 m farther from the
     ball, it charges from behind (1000-1006);
   * away from the ball, when it is faster than its opponent by more than 0.2 m/s: a violent
     collision (1007-1011).

Speeds are those of the virtual league's referee: the average velocity over the last second
(:class:`VelocityTracks`, 661-668), so the sway of a walk or the first instants of a fall are
not a charge. A jump of more than 0.5 m between two snapshots (a robot placed by the referee)
starts the average again.

Consequence, for the offender, as in the virtual league (no card, 904-928): when the ball is in
play and the offender is within 1 m of it, a direct free kick for the other team at the
offender's position (a penalty kick when the ball lies fully inside the penalty area the other
team attacks, as the league decides it, :func:`referee.rules.base.free_kick`); otherwise removal
for PHYSICAL_CONTACT. Both robots are then immune for 2 s and the contact history is cleared.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

from contracts import RobotId
from referee.gamecontroller.states import GameState, Penalty, SecondaryState
from referee.rules.base import Decision, GameView, PenalizeRobot, distance2d, free_kick
from referee.rules.goalkeeper import in_own_goal_area
from referee.snapshot import RobotState, Vec3, WorldSnapshot

PERIOD_MS = 2000  # FOUL_PUSHING_PERIOD (referee_config.yaml)
CONTACT_MS = 1000  # FOUL_PUSHING_TIME
VICINITY_M = 2.0  # FOUL_VINCITY_DISTANCE
FARTHER_M = 0.1  # FOUL_DISTANCE_THRESHOLD
SPEED_M_S = 0.2  # FOUL_SPEED_THRESHOLD
DIRECTION_RAD = 0.523599  # FOUL_DIRECTION_THRESHOLD, 30 degrees
FREE_KICK_RANGE_M = 1.0  # FOUL_BALL_DISTANCE
IMMUNITY_MS = 2000  # FOUL_PENALTY_IMMUNITY
AVERAGE_MS = 1000  # speeds are averaged over this long
JUMP_M = 0.5  # a larger move between two snapshots is a placement, not motion

Pair = tuple[RobotId, RobotId]  # (red, blue)


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
    immune_until: dict[RobotId, int] = field(default_factory=dict)
    last_ms: int | None = None
    tracks: VelocityTracks = field(default_factory=VelocityTracks)


def _pair(a: RobotId, b: RobotId) -> Pair:
    """The pair as the league's contact matrix holds it: the red robot first."""
    return (a, b) if a.team.value == "red" else (b, a)


def _moves_to_ball(robot: RobotState, velocity: Vec3, ball: tuple[float, float]) -> bool:
    """Slower than the speed threshold, or moving within 30 degrees of the ball's direction
    (referee.py:933-942, ``moves_to_ball``)."""
    vx, vy = velocity[0], velocity[1]
    speed = math.hypot(vx, vy)
    if speed < SPEED_M_S:
        return True
    rx, ry = ball[0] - robot.position[0], ball[1] - robot.position[1]
    norm = math.hypot(rx, ry)
    if norm < 1e-9:
        return True  # on the ball: the league's formula divides by zero here
    cos = (rx * vx + ry * vy) / (norm * speed)
    return math.acos(max(-1.0, min(1.0, cos))) < DIRECTION_RAD


def _foul(
    offender: RobotState,
    opponent: RobotState,
    ball: tuple[float, float],
    long_collision: bool,
    game: GameView,
    tracks: VelocityTracks,
) -> str | None:
    """Why ``offender`` commits a forceful contact foul on ``opponent``, or None
    (referee.py:948-1011, ``check_team_forceful_contacts``, one direction)."""
    d1 = distance2d(offender.position, ball)
    d2 = distance2d(opponent.position, ball)
    if opponent.id in game.goalkeepers and in_own_goal_area(opponent, game):  # 962-965
        return f"contact with goalkeeper {opponent.id} in its goal area"
    if long_collision and d1 < VICINITY_M and d1 - d2 > FARTHER_M:  # 973-981
        return f"pushing {opponent.id}"
    v1, v2 = tracks.velocity(offender.id), tracks.velocity(opponent.id)
    speed1, speed2 = math.hypot(v1[0], v1[1]), math.hypot(v2[0], v2[1])
    if not speed1 > SPEED_M_S:  # 986-987
        return None
    if d1 < VICINITY_M:  # 992-1006
        if _moves_to_ball(opponent, v2, ball):
            if not _moves_to_ball(offender, v1, ball):
                return f"charging {opponent.id}, which moves to the ball"
            if d1 - d2 > FARTHER_M:
                return f"charging {opponent.id} from behind"
        return None
    if speed1 - speed2 > SPEED_M_S:  # 1007-1011
        return f"charging {opponent.id}: violent collision, {speed1:.2f} m/s against {speed2:.2f}"
    return None


def _consequence(
    offender: RobotState,
    opponent: RobotState,
    game: GameView,
    ball: tuple[float, float],
    why: str,
) -> Decision:
    """referee.py:904-928 (``forceful_contact_foul``): a free kick at the offender's position
    near a ball in play, else a removal penalty."""
    near = distance2d(offender.position, ball) <= FREE_KICK_RANGE_M
    if game.running and game.ball_in_play and near:
        spot = (offender.position[0], offender.position[1])
        return free_kick(opponent.id.team, spot, ball, game, why)
    return PenalizeRobot(offender.id, Penalty.PHYSICAL_CONTACT, why)


def _early_set_play(game: GameView) -> bool:
    """A set play's sub-phase 0, where the league checks no contact (2127,
    ``is_early_game_interruption``, 1348-1354)."""
    return game.set_play is not None and game.set_play.sub_phase == 0


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
    for pair in touching | set(memory.contacts):
        intervals = [iv for iv in memory.contacts.get(pair, ()) if iv[1] > now - PERIOD_MS]
        if pair in touching:
            if intervals and intervals[-1][1] == previous:
                intervals[-1] = (intervals[-1][0], now)
            else:
                intervals.append((previous, now))
        if intervals:
            contacts[pair] = tuple(intervals)
    immune = {r: t for r, t in memory.immune_until.items() if t > now}
    if _early_set_play(game):
        return [], PushingMemory(contacts, immune, now, tracks)
    for pair in sorted(touching, key=lambda p: (p[0].number, p[1].number)):
        touched = sum(end - max(start, now - PERIOD_MS) for start, end in contacts.get(pair, ()))
        red, blue = robots[pair[0]], robots[pair[1]]
        for offender, opponent in ((red, blue), (blue, red)):
            if offender.id in immune:  # 951-955: no check, the other direction is tried
                continue
            why = _foul(offender, opponent, ball, touched > CONTACT_MS, game, tracks)
            if why is None:
                continue
            immune[offender.id] = immune[opponent.id] = now + IMMUNITY_MS  # 909-911
            # 907: the contact matrix is cleared, so no other pair is checked in this step
            decision = _consequence(offender, opponent, game, ball, why)
            return [decision], PushingMemory({}, immune, now, tracks)
    return [], PushingMemory(contacts, immune, now, tracks)
