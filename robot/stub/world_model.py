"""What the stub robot believes: its pose on the field (odometry) and where the ball is.

Frame: the team's own frame as in HLVS team files (the team defends the goal at x < 0 and
attacks the goal at x > 0), metres and radians. The pose starts from a known starting pose and
is integrated from the gait's velocity and the gyro's yaw rate; it drifts, which the behaviour
tolerates (it only needs a rough idea of where the opponent goal is).
"""

from __future__ import annotations

import math
from dataclasses import replace

from contracts import Pose

Vec3 = tuple[float, float, float]
# a sighting is averaged with the ball believed so far only if that was seen this recently and
# lies this near (a ball that was kicked or rolled away is taken as seen)
BALL_TRACK_MS = 500
BALL_TRACK_M = 0.3


class WorldModel:
    def __init__(self, start: Pose, *, ball_gain: float = 1.0) -> None:
        """``ball_gain``: how far each sighting moves the believed ball from where it was (1:
        all the way; less averages out a robot's sway, which moves the ball in its images)."""
        self.pose = start
        self.ball_gain = ball_gain
        self.ball_field: tuple[float, float] | None = None
        self.ball_seen_ms: int | None = None

    def reset_pose(self, pose: Pose) -> None:
        self.pose = pose
        self.ball_field = None
        self.ball_seen_ms = None

    def integrate(
        self,
        dt_s: float,
        velocity: Vec3,
        yaw_rate_rad_s: float | None,
        *,
        turned_rad: float | None = None,
    ) -> None:
        """Dead reckoning: gait velocity (vx, vy, vyaw) in the robot frame; the heading follows
        ``turned_rad`` (radians turned this step) when given, else the gyro's yaw rate, else
        the gait's."""
        vx, vy, vyaw = velocity
        if turned_rad is None:
            turned_rad = (vyaw if yaw_rate_rad_s is None else yaw_rate_rad_s) * dt_s
        c, s = math.cos(self.pose.yaw_rad), math.sin(self.pose.yaw_rad)
        yaw = math.atan2(
            math.sin(self.pose.yaw_rad + turned_rad),
            math.cos(self.pose.yaw_rad + turned_rad),
        )
        self.pose = Pose(
            x_m=self.pose.x_m + (c * vx - s * vy) * dt_s,
            y_m=self.pose.y_m + (s * vx + c * vy) * dt_s,
            yaw_rad=yaw,
        )

    def forget_ball(self) -> None:
        self.ball_field = None
        self.ball_seen_ms = None

    def see_ball(self, time_ms: int, x_rel_m: float, y_rel_m: float) -> None:
        seen = self.pose.to_field(x_rel_m, y_rel_m)
        before, before_ms = self.ball_field, self.ball_seen_ms
        if (
            self.ball_gain < 1.0
            and before is not None
            and before_ms is not None
            and time_ms - before_ms <= BALL_TRACK_MS
            and math.dist(seen, before) < BALL_TRACK_M
        ):
            gain = self.ball_gain
            seen = (
                before[0] + gain * (seen[0] - before[0]),
                before[1] + gain * (seen[1] - before[1]),
            )
        self.ball_field = seen
        self.ball_seen_ms = time_ms

    def relocate_from_centre_ball(self, x_rel_m: float, y_rel_m: float, *, gain: float) -> None:
        """The ball, seen at ``(x_rel_m, y_rel_m)``, lies on the centre spot (as it does in
        READY and SET): move the believed position by ``gain`` of the way to where that sighting
        puts the robot (the heading stays the gyro's)."""
        fx, fy = self.pose.to_field(x_rel_m, y_rel_m)
        self.pose = replace(self.pose, x_m=self.pose.x_m - gain * fx, y_m=self.pose.y_m - gain * fy)
        self.ball_field = self.pose.to_field(x_rel_m, y_rel_m)

    def ball_relative(self, time_ms: int, *, max_age_ms: int) -> tuple[float, float] | None:
        if self.ball_field is None or self.ball_seen_ms is None:
            return None
        if time_ms - self.ball_seen_ms > max_age_ms:
            return None
        return self.pose.to_relative(*self.ball_field)
