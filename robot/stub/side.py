"""Which half the stub robot plays on: HLVS gives starting poses as if the team played on the
left half; the team on the right is placed at the mirror image (x -> -x, yaw -> pi - yaw). A
mirror image cannot be reached by turning, so odometry only works in a frame turned by pi, where
the mirrored start pose is (x, -y, -yaw) (:func:`turned`).

:class:`SideCheck` finds it out before the robot moves: it looks left, then right, counting the
pixels of a goal below the horizon; the own goal is nearer than the other, so if it shows up on
the other side than the team-file pose predicts, the pitch is mirrored. The league's
GameController says it too: it puts the TeamInfo of the team playing on the left first
(:meth:`SideCheck.from_gamecontroller`)."""

from __future__ import annotations

import logging
import math

from contracts import Pose

logger = logging.getLogger(__name__)

SIDE_LOOK_S = 0.45  # per head position, when checking which side the own goal is on
SIDE_LOOK_YAWS_RAD = (0.55, 1.3, -0.55, -1.3)  # left first, then right; 60 deg field of view
SIDE_LOOK_PITCH_RAD = -0.15  # slightly up: a far goal within the margin below the horizon
SIDE_MIN_PIXELS = 30


def turned(pose: Pose) -> Pose:
    """``pose`` in the odometry frame turned by pi, where a mirrored start pose is reached."""
    return Pose(x_m=pose.x_m, y_m=-pose.y_m, yaw_rad=-pose.yaw_rad)


class SideCheck:
    """The look to the left and to the right; :attr:`running` until it is decided."""

    def __init__(self, *, running: bool) -> None:
        self._seconds: float | None = 0.0 if running else None
        self._pixels = [0, 0]  # left, right

    @property
    def running(self) -> bool:
        return self._seconds is not None

    def start(self) -> None:
        self._seconds = 0.0
        self._pixels = [0, 0]

    def advance(self, dt: float) -> tuple[float, bool]:
        """``dt`` more of looking: the neck yaw to look at now, and whether the look is over
        (then :meth:`decide`)."""
        assert self._seconds is not None
        self._seconds += dt
        slot = min(int(self._seconds / SIDE_LOOK_S), len(SIDE_LOOK_YAWS_RAD) - 1)
        return SIDE_LOOK_YAWS_RAD[slot], self._seconds >= len(SIDE_LOOK_YAWS_RAD) * SIDE_LOOK_S

    def count(self, looking_left: bool, pixels: int) -> None:
        """The goal's pixels below the horizon seen looking to one side."""
        self._pixels[0 if looking_left else 1] += pixels

    def decide(self, pose: Pose, half_length_m: float) -> bool | None:
        """Whether this team's pitch is mirrored, the robot standing at ``pose`` of its team
        file; None when no goal was in sight (the start pose is kept)."""
        self._seconds = None
        left, right = self._pixels
        if max(left, right) < SIDE_MIN_PIXELS:
            logger.info(
                "side check: no goal in sight (%d/%d px); keeping the start pose", left, right
            )
            return None
        gx, gy = pose.to_relative(-half_length_m, 0.0)
        predicted_left = math.atan2(gy, gx) > 0
        seen_left = left > right
        mirrored = predicted_left != seen_left
        logger.info(
            "side check: own goal on the %s (%d/%d px): %s",
            "left" if seen_left else "right",
            left,
            right,
            "mirrored pitch" if mirrored else "as in the team file",
        )
        return mirrored

    def from_gamecontroller(self, on_left: bool) -> bool:
        """The side the GameController's team order gives: whether the pitch is mirrored."""
        self._seconds = None
        logger.info(
            "side from the GameController: %s",
            "left (as in the team file)" if on_left else "right (mirrored pitch)",
        )
        return not on_left
