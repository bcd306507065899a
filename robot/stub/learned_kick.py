"""The striker's learned kick: the policy played as it learnt it.

The kick policy (:mod:`robot.learned`) learnt in an environment whose robot stands in its
walking stance, head straight, with the simulator's default servo gains
(:data:`robot.learned.LEARNT_SERVO_PID`, P = 10), and whose episode ends with the policy
(1.5 s); its robot was eased into that stance over the model's rise (``rise_s``: none for
kid-default, 1 s for adult-default) and held it for the environment's ``settle_s`` (0.5 s). A
striker lining up looks down at the ball at its feet (head pitched about 1 rad) and tunes its
servos to P = 30 (:data:`robot.motion.SERVO_PID`): played from there, the policy's targets,
chosen for a slower servo, threw the robot over within 1.3 s of every learned kick (in-process
shots: torso tilted 80 degrees 1.2 s into the kick with P = 30, at most 10 with P = 10).
:class:`LearnedKick` eases into the stance (:data:`PREPARE_S`) and holds it (:data:`HOLD_S`), or
for a model that rises, as the environment did (:func:`handover_s`), plays the policy's first
:data:`PLAY_S`, then eases back into the stance (:data:`RECOVER_S`); it asks for the learnt
gains until the policy has played and for the stub's own for the recovery
(:attr:`LearnedKick.servo_pid`, which the stub's runner sends as MotorPID).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from robot.learned import LEARNT_SERVO_PID, Policy, PolicyMotion
from robot.motion import SERVO_PID
from robot.motion.keyframes import Keyframe, KeyframeMotion
from robot.stub.behaviour import Field

PREPARE_S = 0.3  # ease into the stance the policy learnt from (the head straight)
HOLD_S = 0.2  # ... and hold it
# A model that rises into its stance (adult-default) is handed over as the learning environment
# starts its episodes: eased in over its rise_s and held the environment's settle_s. In-process
# adult shots (the stub striker on the adult pitch, 14 seeded layouts 2-4 m from the goal,
# 14 learned kicks each): eased in 0.3 s and held 0.2 s, 10 kicks were followed by a fall within
# 6 s; eased in 1 s and held 0.5 s, 3 (goals 6 and 8 of 14). From the walk at the stub's P = 30,
# a short ease at P = 10 leaves the robot rocking when the policy starts: its torso leans
# otherwise than in every training episode, and the policy ends the kick tilted.
RISEN_HOLD_S = 0.5
# The policy plays this long of its episode (1.5 s): the ball is gone after 0.1 s, and its
# episode's end, which nothing taught to stay up, tipped it over. In the learning environment
# (24 seeded episodes, then the stance with the stub's gains, falls counted within 4 s): the
# whole episode fell in 14, the policy's first 0.7 s in 2 (the ball 1.61 m against 1.47).
PLAY_S = 0.7
RECOVER_S = 0.3  # after the policy, ease back into the stance
# A model whose learned kick is a shot only: the striker plays it with the ball within this
# distance of the opponent goal's centre and the keyframe kick (both feet) farther out; a model
# not listed plays the learned kick anywhere (kid-default). The adult policy rolls the ball
# about 1.6 m where the adult keyframe kick rolls it 3-4 m: played everywhere, red's learned
# kicks were clearances from its kick-off and it reached the goal rarely (0 of 8 scrimmages
# scored); in-process shots 2 to 4 m from the goal scored in 8 of 14.
SHOT_RANGE_M: dict[str, float] = {"adult-default": 4.0}
# once lined up for the learned kick, the ball must be this much farther out to go back to the
# keyframe kick (the ball estimate jitters while lining up; switching feet would start again)
SHOT_RANGE_MARGIN_M = 0.4


def handover_s(rise_s: float) -> tuple[float, float]:
    """How long the kick eases into the stance and holds it before the policy plays, for a
    model rising into its stance over ``rise_s`` (0: :data:`PREPARE_S`, :data:`HOLD_S`)."""
    if rise_s <= 0.0:
        return PREPARE_S, HOLD_S
    return rise_s, RISEN_HOLD_S


class LearnedKick:
    """A motion (call :meth:`sense` then :meth:`step` every control tick until :attr:`done`):
    stance, policy, stance."""

    def __init__(
        self, policy: Policy, *, start: Mapping[str, float], stance: Mapping[str, float],
        rise_s: float = 0.0,
    ) -> None:  # fmt: skip
        """``rise_s``: the model's rise into its stance (:func:`handover_s`)."""
        self.policy = PolicyMotion(policy)
        self._stance = dict(stance)
        prepare_s, hold_s = handover_s(rise_s)
        frames = [Keyframe(duration_s=prepare_s, targets=self._stance),
                  Keyframe(duration_s=hold_s, targets=self._stance)]  # fmt: skip
        self._prepare = KeyframeMotion(frames, start=dict(start))
        self._recover: KeyframeMotion | None = None
        self._last = dict(start)
        self._elapsed_s = 0.0

    @property
    def done(self) -> bool:
        return self._recover is not None and self._recover.done

    @property
    def recovering(self) -> bool:
        """Whether the policy has played (easing back into the stance now)."""
        return self._recover is not None

    @property
    def _policy_playing(self) -> bool:
        return not self.policy.done and self.policy.elapsed_s < PLAY_S - 1e-9

    @property
    def servo_pid(self) -> tuple[float, float, float]:
        """The gains the motors should have now: the policy's until it has played."""
        return SERVO_PID if self.recovering else LEARNT_SERVO_PID

    @property
    def elapsed_s(self) -> float:
        return self._elapsed_s

    def sense(
        self, joints: Mapping[str, float], accel: Sequence[float] | None,
        gyro: Sequence[float] | None,
    ) -> None:  # fmt: skip
        """The readings of this tick (the policy's, while it plays)."""
        self.policy.sense(joints, accel, gyro)

    def step(self, dt_s: float) -> dict[str, float]:
        self._elapsed_s += dt_s
        if not self._prepare.done:
            out = self._prepare.step(dt_s)
        elif self._recover is None and self._policy_playing:
            out = self.policy.step(dt_s)
        else:
            if self._recover is None:
                frame = Keyframe(duration_s=RECOVER_S, targets=self._stance)
                self._recover = KeyframeMotion([frame], start=self._last)
            out = self._recover.step(dt_s)
        self._last.update(out)
        return dict(self._last)


def in_shot_range(
    ball_field: tuple[float, float], half_length_m: float, range_m: float | None, *,
    now: bool,
) -> bool:  # fmt: skip
    """Whether the learned kick is the one to line up for, the ball at ``ball_field`` (the
    team's frame: the opponent goal at ``+half_length_m``), ``now`` whether it is already:
    within ``range_m`` of the goal's centre, or within :data:`SHOT_RANGE_MARGIN_M` more when it
    is already; anywhere for ``range_m`` None."""
    if range_m is None:
        return True
    distance = math.hypot(half_length_m - ball_field[0], ball_field[1])
    return distance < range_m + (SHOT_RANGE_MARGIN_M if now else 0.0)


class KickChoice:
    """The striker's kick with a learned policy: the field it lines the ball up with
    (:attr:`field`: the learned kick's spot and right foot, or the keyframe kick's) and whether
    a kick now is the learned one (:attr:`learned`), chosen by :func:`in_shot_range`."""

    def __init__(self, *, keyframe: Field, learned: Field, range_m: float | None) -> None:
        self._keyframe = keyframe
        self._learned = learned
        self.range_m = range_m
        # a model with a range starts at its kick-off, far from the goal
        self.learned = range_m is None

    @property
    def field(self) -> Field:
        return self._learned if self.learned else self._keyframe

    def update(self, ball_field: tuple[float, float] | None) -> Field:
        """The ball seen at ``ball_field`` (None: not seen, the choice kept); the field now."""
        if ball_field is not None:
            self.learned = in_shot_range(ball_field, self._keyframe.half_length_m,
                                         self.range_m, now=self.learned)  # fmt: skip
        return self.field


__all__ = [
    "HOLD_S",
    "PLAY_S",
    "PREPARE_S",
    "RECOVER_S",
    "RISEN_HOLD_S",
    "SHOT_RANGE_M",
    "SHOT_RANGE_MARGIN_M",
    "KickChoice",
    "LearnedKick",
    "handover_s",
    "in_shot_range",
]
