"""The stub robot's control loop body: one call per sensor measurement, motor targets out.

Wires the motion engines (walk, kick, get-up), the IMU attitude filter, the ball detector and
the behaviour. It never sees ground truth: only joint angles, accelerometer, gyro and the head
camera image, exactly what the robot API delivers.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from contracts import GameState, Pose, field_for
from robot.learned import Policy
from robot.learned.policy import kick_ball_offset
from robot.motion import (
    SERVO_PID,
    Attitude,
    AttitudeFilter,
    GetUpMotion,
    KickMotion,
    WalkEngine,
    kinematics,
)
from robot.motion.imu import GRAVITY_M_S2, GyroBias
from robot.motion.keyframes import Keyframe, KeyframeMotion
from robot.motion.posture import standing_posture
from robot.motion.walk import default_walk_params
from robot.stub.behaviour import Action, Field, GameInfo, Role, decide
from robot.stub.learned_kick import SHOT_RANGE_M, KickChoice, LearnedKick
from robot.stub.perception import (
    BallSighting,
    CameraPose,
    find_ball_blobs,
    goal_below_horizon,
    ground_point,
)
from robot.stub.side import SIDE_LOOK_PITCH_RAD, SideCheck, turned
from robot.stub.world_model import WorldModel

logger = logging.getLogger(__name__)

Vec3 = tuple[float, float, float]
FALL_TILT_RAD = 0.9
FALL_CONFIRM_S = 0.6
# which side it lies on: the sign of gravity along the torso's forward axis, averaged this long
# (the attitude filter lags a tumbling fall by a few tenths of a second and may still read the
# other side when the fall is confirmed)
LYING_SIDE_TAU_S = 0.15
BALL_MEMORY_MS = 4000
SCAN = [(-0.9, 0.45), (-0.45, 0.5), (0.0, 0.55), (0.45, 0.5), (0.9, 0.45), (0.45, 0.95),
        (0.0, 1.0), (-0.45, 0.95)]  # fmt: skip
SCAN_DWELL_S = 0.35
KNEE_RESET_RAD = 0.5  # knee this far from its target: the robot was reset or is limp
KICK_SETTLE_S = 0.5  # stand still this long before a kick
# where the keyframe kick wants the ball across: this far outside the kicking sole's centre (a
# ball 1.5 cm inside it is struck by the sole's inner edge and flies off up to 0.4 rad inwards;
# up to 6 cm outside it still goes straight)
KICK_BALL_OUTSIDE_M = 0.02
KICK_COMMIT_MS = 2500  # keep to a kick decided this long ago while the ball stays in reach
# ... within this much of the kick spot: while the gait comes to a stop the body sways and the
# ball estimate jumps by several centimetres; re-aligning on it restarts the gait for ever
KICK_HOLD_X_M = 0.12
KICK_HOLD_Y_M = 0.08
KID_THIGH_M = 0.16  # kid-default's; the hold above and the own body below scale with the thigh
# Looking down, the head camera sees the robot's own shins, feet and hands, whose dark shading
# and light highlights the detector can take for the ball (in a third of the images of a 20 s
# search without a ball in view). A ball cannot lie where they are: its centre stays a ball's
# radius clear of the feet (kid-default: toes 0.10 m ahead of the pelvis, outer edges 0.10 m
# to the side, ball radius 0.07 m). A sighting in front of the feet nearer than this (pelvis
# frame, the margin left for the estimate's error) ...
OWN_FEET_X_M = 0.14
OWN_FEET_Y_M = 0.14
# ... or beside the legs, under the hands (where the hands, seen from above, land on the ground),
# is the robot itself and is not taken
OWN_HANDS_X_M = 0.08
OWN_HANDS_Y_M = 0.32
# READY and SET: the ball lies on the centre spot, a landmark that corrects the odometry (each
# sighting nearer than this moves the believed position by the gain towards what it implies)
CENTRE_BALL_MAX_M = 1.5  # farther, the ball's distance is underestimated by up to a third
CENTRE_BALL_GAIN = 0.2
# ... and only a sighting this close to the centre spot by the odometry counts: something else
# that looks like a ball (a goal's black and white net, seen by a goalie walking past it) would
# drag the believed position metres away
CENTRE_BALL_GATE_M = 1.0
# the gyro's bias is learnt from the readings of a robot standing still this long, each axis
# turning slower than this
GYRO_STILL_S = 0.3
GYRO_STILL_RAD_S = 0.05
UPRIGHT_MAX_TILT_RAD = 0.5  # the torso tilted less than this: the robot is on its feet
# rise into the stance only when standing this upright (placed by the referee), not while
# tipping over (when the knees lag their targets too)
RISE_MAX_TILT_RAD = 0.2
SETTLE_S = 1.0  # stand still this long after start and after getting up
# after a reset of the pose (half time, end of a penalty) the referee may still be placing the
# robot: its orientation is taken from gravity afresh for this long, without counting turns
RESET_HOLD_S = 0.6


@dataclass(frozen=True, slots=True, kw_only=True)
class Sensors:
    time_ms: int
    joints: dict[str, float]  # motor name -> rad
    accel: Vec3 | None = None
    gyro: Vec3 | None = None
    image_bgr: npt.NDArray[np.uint8] | None = None  # height x width x 3


@dataclass(slots=True)
class Stats:
    falls: int = 0
    kicks: int = 0
    learned_kicks: int = 0  # of the kicks, those the learned policy played
    get_ups: int = 0
    ball_sightings: int = 0


class StubController:
    def __init__(
        self,
        *,
        role: Role,
        start_pose: Pose,
        model: str = "kid-default",
        field_class: str = "kid",
        detect_side: bool = False,
        home: tuple[float, float] | None = None,
        kick_policy: Policy | None = None,
    ) -> None:
        """``detect_side``: before moving, look left and right for the own goal to find out
        whether the pitch is mirrored for this team (see :mod:`robot.stub.side`);
        ``home``: a defender's spot in the own half; ``kick_policy``: a learned right-foot kick
        from a stand (:mod:`robot.learned`) played instead of the keyframe kick (the striker
        then lines up for the right foot only, the ball where the policy learnt it)."""
        self.role = role
        self.home = home
        self.model = model
        self.kin = kinematics(model)
        self.walk = WalkEngine(model=model)
        self.world = WorldModel(start_pose, ball_gain=self.kin.ball_gain)
        self.attitude = AttitudeFilter()
        self._gyro_bias = GyroBias()
        self._gyro_still_s = 0.0
        self._heading = HeadingTracker()
        self.stats = Stats()
        walk = default_walk_params(model)
        self._pelvis_height_m = walk.hip_height_m + self.kin.camera.hip_below_pelvis_m
        geometry = field_for(field_class)
        self._ball_radius_m = geometry.ball_radius_m
        self.field = Field(
            half_length_m=geometry.half_length_m,
            centre_circle_m=geometry.centre_circle_radius_m,
            foot_y_m=self.kin.leg.hip_offset_y_m + walk.foot_y_offset_m + KICK_BALL_OUTSIDE_M,
            kick_x_m=self.kin.kick_ball_x_m,
            fast_m_s=min(walk.cruise_vx_m_s, walk.max_vx_m_s),
            opponent_distance_m=geometry.opponent_distance_m,
        )
        # the model's size against kid-default's (1.0 there): the ball estimate of a taller
        # robot, whose camera sits higher, jumps by more while it sways
        self._size = self.kin.leg.thigh_m / KID_THIGH_M
        self.kick_policy = kick_policy
        learned = self.field if kick_policy is None else replace(  # right foot, policy's spot
            self.field, foot_y_m=self.kin.leg.hip_offset_y_m + walk.foot_y_offset_m,
            kick_x_m=kick_ball_offset(model)[0], kick_feet=("right",))  # fmt: skip
        self._kick_choice = KickChoice(keyframe=self.field, learned=learned, range_m=None
                                       if kick_policy is None else SHOT_RANGE_M.get(model))
        self.field = self._kick_choice.field
        self._last_ms: int | None = None
        self._settle_until_ms: int | None = None
        self._rise_pending = True  # look whether the legs are far from the stance
        self._still_s = 0.0
        self._upright_since_fall = True
        self._tilted_s = 0.0
        self._forward_gravity = 0.0  # accelerometer x, low-passed with LYING_SIDE_TAU_S
        self._motion: KeyframeMotion | LearnedKick | None = None
        self._motion_kind = ""
        self._last_targets: dict[str, float] = {}
        self._missing_since_ms: int | None = None
        self._scan_s = 0.0
        self._kick_committed: tuple[str, int] | None = None  # foot, when lined up
        self.last_action: Action | None = None
        self._detect_side = detect_side
        self._side = SideCheck(running=detect_side)
        self.mirrored: bool | None = None
        self._expect_mirrored: bool | None = None

    @property
    def servo_pid(self) -> tuple[float, float, float]:
        """The servo gains (P, I, D) every motor should have now (a learned kick's its own)."""
        return self._motion.servo_pid if isinstance(self._motion, LearnedKick) else SERVO_PID

    @property
    def busy(self) -> str:
        """ "kick", "get-up", "rise" or "" (walking or standing)."""
        return self._motion_kind if self._motion is not None else ""

    def reset_pose(
        self, pose: Pose, *, check_side: bool = True, expect_mirrored: bool | None = None
    ) -> None:
        """Start again from ``pose`` (team-file frame when ``check_side``; the turned frame of
        the odometry otherwise). ``expect_mirrored`` applies when the check is undecided.

        The robot was placed by the referee: a motion under way (a get-up when the half ended
        with the robot down) is dropped and the orientation is taken afresh from gravity."""
        self.world.reset_pose(pose)
        self._heading = HeadingTracker(hold_s=RESET_HOLD_S)
        self.attitude.reset()  # placed upright: the filter would take a second to forget a fall
        if self._motion is not None:
            self._motion = None
            self._motion_kind = ""
            self._tilted_s = 0.0
            self.walk.reset()
        self._rise_pending = True
        self._expect_mirrored = expect_mirrored
        if self._detect_side and check_side:
            self._side.start()

    def settle(self, time_ms: int) -> None:
        """Stand still for a moment before moving again (after a reset of the robot)."""
        self._settle_until_ms = time_ms + int(SETTLE_S * 1000)
        self.walk.reset()

    def _side_check(self, dt: float, sensors: Sensors) -> dict[str, float]:
        """Stand and look left, then right; count the near goal's pixels below the horizon."""
        yaw, over = self._side.advance(dt)
        neck = sensors.joints.get(self.kin.neck_motor)
        if sensors.image_bgr is not None and neck is not None and abs(neck - yaw) < 0.1:
            pose = self._camera_pose(sensors.joints)
            pixels = goal_below_horizon(sensors.image_bgr, pose, self.kin.camera, margin_rad=0.09)
            self._side.count(yaw > 0, pixels)
        if over:
            self._set_mirrored(self._side.decide(self.world.pose, self.field.half_length_m))
        targets = self.walk.step(dt, 0.0, 0.0, 0.0, accel=sensors.accel, gyro=sensors.gyro)
        targets.update(self.kin.head_targets(yaw, SIDE_LOOK_PITCH_RAD))
        return targets

    def _set_mirrored(self, mirrored: bool | None) -> None:
        """The side found (:mod:`robot.stub.side`; None: undecided, the start pose kept)."""
        if mirrored is None:
            return
        self.mirrored = mirrored
        if mirrored:
            self.world.reset_pose(turned(self.world.pose))

    def _moved_by_someone_else(self, joints: dict[str, float]) -> bool:
        return self._knees_away(joints, self._last_targets)

    def _knees_away(self, joints: dict[str, float], targets: dict[str, float]) -> bool:
        """Whether a knee is more than :data:`KNEE_RESET_RAD` from its angle in ``targets``."""
        knees = [name for name in self.kin.motor_names if name.startswith("LegLower")]
        return any(
            name in joints
            and name in targets
            and abs(joints[name] - targets[name]) > KNEE_RESET_RAD
            for name in knees
        )

    def tick(self, sensors: Sensors, game: GameInfo) -> dict[str, float]:
        """One control step: sense (:meth:`_sense`), carry on a motion or get up after a fall,
        check the side the team plays on, then decide and act. Returns the joint targets."""
        dt = 0.008 if self._last_ms is None else max(sensors.time_ms - self._last_ms, 1) / 1000.0
        if self._settle_until_ms is None:
            self._settle_until_ms = sensors.time_ms + int(SETTLE_S * 1000)
        self._last_ms = sensors.time_ms
        sensors, att = self._sense(dt, sensors, game)
        if self._motion is None and self._moved_by_someone_else(sensors.joints):
            # teleported (half time, penalty) or limp: joints are not where we put them
            self.settle(sensors.time_ms)
            self._rise_pending = True
        if self._motion is None and self._rise_pending and att.tilt_rad < RISE_MAX_TILT_RAD:
            self._rise_pending = False
            self._rise(sensors)
        if self._motion is not None:
            if isinstance(self._motion, LearnedKick):
                self._motion.sense(sensors.joints, sensors.accel, sensors.gyro)
            targets = self._motion.step(dt)
            if self._motion.done:
                self._finish_motion()
            return self._remember(targets)
        if game.penalised:  # limp or being carried: nothing to get up from
            self._tilted_s = 0.0
        elif self._fallen(dt, att.tilt_rad):
            side = self._lying_side(att.pitch_rad, sensors.accel is not None)
            if self._upright_since_fall:
                self.stats.falls += 1  # later attempts while still down are not new falls
            self._upright_since_fall = False
            logger.info("fallen on the %s; getting up", side)
            self._start(GetUpMotion(side, model=self.model, start=sensors.joints), "get-up")
            return self._remember(self._motion.step(dt) if self._motion else {})
        ball = self.world.ball_relative(sensors.time_ms, max_age_ms=BALL_MEMORY_MS)
        if ball is None:
            if self._missing_since_ms is None:
                self._missing_since_ms = sensors.time_ms
        else:
            self._missing_since_ms = None
        searching_s = (
            0.0
            if self._missing_since_ms is None
            else (sensors.time_ms - self._missing_since_ms) / 1000.0
        )
        if self._side.running and game.on_left is not None:
            self._set_mirrored(self._side.from_gamecontroller(game.on_left))
        if self._side.running and not game.penalised:
            if sensors.time_ms >= self._settle_until_ms:
                return self._remember(self._side_check(dt, sensors))
        self.field = self._kick_choice.update(ball and self.world.pose.to_field(*ball))
        action = decide(
            role=self.role,
            game=game,
            pose=self.world.pose,
            ball=ball,
            field=self.field,
            searching_s=searching_s,
            home=self.home,
        )
        if sensors.time_ms < self._settle_until_ms:
            action = Action(search=action.search)  # settle into the stance first
        action = self._commit_kick(sensors.time_ms, action, ball)
        self.last_action = action
        self._still_s = 0.0 if self.walk.walking else self._still_s + dt
        if action.kick_foot is not None:
            swaying = sensors.gyro is not None and math.hypot(*sensors.gyro[:2]) > 0.3
            if self.walk.walking or self._still_s < KICK_SETTLE_S or swaying:
                targets = self.walk.step(dt, 0.0, 0.0, 0.0, accel=sensors.accel, gyro=sensors.gyro)
            else:
                return self._remember(self._kick(dt, sensors, action.kick_foot, ball))
        else:
            targets = self.walk.step(dt, *action.walk, accel=sensors.accel, gyro=sensors.gyro)
        targets.update(self._head(dt, ball, action, att.pitch_rad))
        return self._remember(targets)

    def _sense(self, dt: float, sensors: Sensors, game: GameInfo) -> tuple[Sensors, Attitude]:
        """The gyro's bias taken off, the attitude and the world model brought forward, the
        ball looked for and the pose corrected from it on the centre spot (READY, SET).
        Returns the sensors with the unbiased gyro, and the attitude."""
        if sensors.gyro is not None:
            sensors = replace(sensors, gyro=self._gyro_unbiased(dt, sensors.gyro, game))
        if sensors.accel is not None and sensors.gyro is not None:
            self.attitude.update(dt, sensors.accel, sensors.gyro)
            weight = dt / (LYING_SIDE_TAU_S + dt)
            self._forward_gravity += weight * (sensors.accel[0] - self._forward_gravity)
        att = self.attitude.attitude
        upright = att.tilt_rad < UPRIGHT_MAX_TILT_RAD
        if upright and self._motion is None:
            self._upright_since_fall = True
        self.world.integrate(
            dt,
            self.walk.velocity if upright else (0.0, 0.0, 0.0),
            None,
            turned_rad=self._heading.heading_change(dt, sensors.accel, sensors.gyro),
        )
        if sensors.image_bgr is not None and upright and self._motion is None:
            seen = self._look(sensors)
            on_centre_spot = game.phase in (GameState.READY, GameState.SET) and not game.penalised
            if seen is not None and on_centre_spot and math.hypot(*seen) < CENTRE_BALL_MAX_M:
                if math.hypot(*self.world.pose.to_field(*seen)) < CENTRE_BALL_GATE_M:
                    self.world.relocate_from_centre_ball(*seen, gain=CENTRE_BALL_GAIN)
        return sensors, att

    # --- parts ---------------------------------------------------------------------------------
    def _kick(
        self, dt: float, sensors: Sensors, foot: str, ball: tuple[float, float] | None
    ) -> dict[str, float]:
        """Start a kick with ``foot`` (the learned policy for the right foot, when the robot
        has one; else the keyframe kick); its first targets."""
        self.stats.kicks += 1
        kick: KeyframeMotion | LearnedKick
        if self.kick_policy is not None and foot == "right" and self._kick_choice.learned:
            self.stats.learned_kicks += 1
            logger.info("kicking with the learned policy (%s)", self.kick_policy.skill)
            kick = LearnedKick(self.kick_policy, start=self._last_targets,
                               stance=standing_posture(self.model), rise_s=self.kin.rise_s)
        else:
            pose = self.world.pose
            logger.info(
                "kicking with the %s foot from (%.2f, %.2f, %.2f) believed, ball at"
                " (%.2f, %.2f) ahead",
                foot, pose.x_m, pose.y_m, pose.yaw_rad, *(ball or (0, 0)),
            )  # fmt: skip
            kick = KickMotion(foot=foot, model=self.model, start=self._last_targets)
        self._start(kick, "kick")
        return kick.step(dt)


    def _rise(self, sensors: Sensors) -> None:
        """Ease into the stance as a motion (the model's ``rise_s``) when the knees are far
        from it (placed with straight legs); stand still for the settle time after it."""
        rise_s = self.kin.rise_s
        if rise_s <= 0.0:
            return
        stance = standing_posture(self.model)
        if not self._knees_away(sensors.joints, stance):
            return
        logger.info("legs far from the stance; rising into it over %.1f s", rise_s)
        rise = KeyframeMotion([Keyframe(duration_s=rise_s, targets=stance)], start=sensors.joints)
        self._start(rise, "rise")
        until = sensors.time_ms + int((rise_s + SETTLE_S) * 1000)
        self._settle_until_ms = max(self._settle_until_ms or 0, until)

    def _commit_kick(
        self, time_ms: int, action: Action, ball: tuple[float, float] | None
    ) -> Action:
        """Once lined up, keep to the kick while the robot settles: the ball estimate jitters
        by a few centimetres between frames, and re-aligning for every frame would never end."""
        if action.kick_foot is not None:
            if self._kick_committed is None or self._kick_committed[1] + KICK_COMMIT_MS < time_ms:
                self._kick_committed = (action.kick_foot, time_ms)
            return Action(kick_foot=self._kick_committed[0])
        committed = self._kick_committed
        if committed is None or ball is None or time_ms > committed[1] + KICK_COMMIT_MS:
            self._kick_committed = None
            return action
        bx, by = ball
        side = self.field.foot_y_m if committed[0] == "left" else -self.field.foot_y_m
        hold_x, hold_y = KICK_HOLD_X_M * self._size, KICK_HOLD_Y_M * self._size
        if abs(bx - self.field.kick_x_m) < hold_x and abs(by - side) < hold_y:
            return Action(kick_foot=committed[0])
        self._kick_committed = None
        return action

    def _look(self, sensors: Sensors) -> tuple[float, float] | None:
        """Look for the ball in the image; the sighting (robot frame) or None."""
        image = sensors.image_bgr
        assert image is not None
        pose = self._camera_pose(sensors.joints)
        height, width = image.shape[0], image.shape[1]
        for blob in find_ball_blobs(image):
            seen = ground_point(
                blob,
                pose,
                self.kin.camera,
                width_px=width,
                height_px=height,
                ball_radius_m=self._ball_radius_m,
            )
            if seen is not None and seen.distance_m < 8.0 and not _own_body(seen, self._size):
                self.world.see_ball(sensors.time_ms, seen.x_m, seen.y_m)
                self.stats.ball_sightings += 1
                return seen.x_m, seen.y_m
        return None

    def _gyro_unbiased(self, dt: float, gyro: Vec3, game: GameInfo) -> Vec3:
        """The gyro reading less its bias, learnt while the robot stands still on its own feet:
        upright, neither walking nor in a motion, not being carried (penalised) and not
        swaying, for :data:`GYRO_STILL_S`."""
        still = (
            self._motion is None
            and not self.walk.walking
            and not game.penalised
            and self.attitude.attitude.tilt_rad < UPRIGHT_MAX_TILT_RAD
        )
        corrected = self._gyro_bias.corrected(gyro)
        still = still and max(abs(g) for g in corrected) < GYRO_STILL_RAD_S
        self._gyro_still_s = self._gyro_still_s + dt if still else 0.0
        if self._gyro_still_s < GYRO_STILL_S:
            return corrected
        self._gyro_bias.learn(dt, gyro)
        return self._gyro_bias.corrected(gyro)

    def _camera_pose(self, joints: dict[str, float]) -> CameraPose:
        """The head camera's pose from the neck and head joints and the torso's attitude."""
        att = self.attitude.attitude
        return CameraPose(
            neck_yaw_rad=joints.get(self.kin.neck_motor, 0.0),
            head_pitch_rad=self.kin.head_down_sign * joints.get(self.kin.head_motor, 0.0),
            torso_roll_rad=att.roll_rad,
            torso_pitch_rad=att.pitch_rad,
            pelvis_height_m=self._pelvis_height_m,
        )

    def _head(
        self, dt: float, ball: tuple[float, float] | None, action: Action, torso_pitch: float
    ) -> dict[str, float]:
        if ball is not None and not action.search:
            self._scan_s = 0.0
            distance = math.hypot(*ball)
            camera_height = self._pelvis_height_m + self.kin.camera.neck_height_m
            down = math.atan2(camera_height - self._ball_radius_m, distance) - torso_pitch
            yaw = max(-1.2, min(1.2, math.atan2(ball[1], ball[0])))
            return self.kin.head_targets(yaw, max(0.2, min(1.15, down)))
        self._scan_s += dt
        yaw, pitch = SCAN[int(self._scan_s / SCAN_DWELL_S) % len(SCAN)]
        return self.kin.head_targets(yaw, pitch)

    def _lying_side(self, pitch_rad: float, have_accel: bool) -> str:
        """The side it lies on: on the front, the specific force points backwards (x < 0)."""
        if have_accel:
            return "front" if self._forward_gravity < 0.0 else "back"
        return "front" if pitch_rad > 0 else "back"

    def _fallen(self, dt: float, tilt_rad: float) -> bool:
        self._tilted_s = self._tilted_s + dt if tilt_rad > FALL_TILT_RAD else 0.0
        return self._tilted_s >= FALL_CONFIRM_S

    def _start(self, motion: KeyframeMotion | LearnedKick, kind: str) -> None:
        self._motion = motion
        self._motion_kind = kind
        self.walk.reset()

    def _finish_motion(self) -> None:
        if self._motion_kind == "kick":
            self._kick_committed = None
            self.world.forget_ball()  # look again: it should be far away now
        if self._motion_kind == "get-up":
            self.stats.get_ups += 1
            self._settle_until_ms = (self._last_ms or 0) + int(SETTLE_S * 1000)
        self._motion = None
        self._motion_kind = ""
        self._tilted_s = 0.0
        self.walk.reset()

    def _remember(self, targets: dict[str, float]) -> dict[str, float]:
        self._last_targets.update(targets)
        return dict(self._last_targets)


class HeadingTracker:
    """The torso's full orientation from the gyro, its tilt corrected by the accelerometer
    (a Mahony filter without magnetometer), and from it the heading on the ground.

    Upright, the heading change is the gyro's turn about the vertical. Through a fall and a
    get-up the torso may tip past vertical or roll over, where the yaw of any angle triple jumps
    by pi without the robot turning; following the whole orientation keeps the heading right
    once the robot stands again.
    """

    def __init__(self, *, gain: float = 2.0, hold_s: float = 0.0) -> None:
        """``hold_s``: for this long the orientation is taken afresh from gravity at every call
        and no turn is reported (the referee is still placing the robot: the turns of a
        teleport are no turns of the robot's own)."""
        self._gain = gain
        self._hold_s = hold_s
        self._q: tuple[float, float, float, float] | None = None  # w, x, y, z: body -> world
        self._heading: float | None = None

    def heading_change(self, dt_s: float, accel: Vec3 | None, gyro: Vec3 | None) -> float | None:
        """Radians turned about the vertical since the last call (None without a gyro)."""
        if gyro is None:
            return None
        norm = math.sqrt(sum(a * a for a in accel)) if accel is not None else 0.0
        trusted = accel is not None and abs(norm - GRAVITY_M_S2) < 0.3 * GRAVITY_M_S2
        if self._hold_s > 0.0:
            self._hold_s -= dt_s
            self._q = None
            return 0.0
        if self._q is None:
            if not trusted or accel is None:
                return gyro[2] * dt_s
            self._q = _tilt_quaternion(accel[0] / norm, accel[1] / norm, accel[2] / norm)
            self._heading = _heading(self._q)
            return 0.0
        w, x, y, z = self._q
        wx, wy, wz = gyro
        if trusted and accel is not None:
            # up as the torso sees it now, against the measured specific force
            ux, uy, uz = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
            ax, ay, az = accel[0] / norm, accel[1] / norm, accel[2] / norm
            wx += self._gain * (ay * uz - az * uy)
            wy += self._gain * (az * ux - ax * uz)
            wz += self._gain * (ax * uy - ay * ux)
        half = 0.5 * dt_s
        w, x, y, z = (
            w - half * (x * wx + y * wy + z * wz),
            x + half * (w * wx + y * wz - z * wy),
            y + half * (w * wy - x * wz + z * wx),
            z + half * (w * wz + x * wy - y * wx),
        )
        length = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
        self._q = (w / length, x / length, y / length, z / length)
        heading = _heading(self._q)
        before = self._heading if self._heading is not None else heading
        self._heading = heading
        return math.atan2(math.sin(heading - before), math.cos(heading - before))


def _own_body(seen: BallSighting, size: float) -> bool:
    """Whether a sighting lies where the robot's own feet or hands are (see OWN_FEET_X_M);
    ``size``: the robot's thigh against kid-default's."""
    x, y = seen.x_m / size, abs(seen.y_m) / size
    feet = x < OWN_FEET_X_M and y < OWN_FEET_Y_M
    return feet or (abs(x) < OWN_HANDS_X_M and y < OWN_HANDS_Y_M)


def _tilt_quaternion(ux: float, uy: float, uz: float) -> tuple[float, float, float, float]:
    """A body -> world rotation with heading 0 whose world up is ``(ux, uy, uz)`` in the body."""
    roll = math.atan2(uy, uz)
    pitch = math.atan2(-ux, math.hypot(uy, uz))
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    return (cr * cp, sr * cp, cr * sp, -sr * sp)


def _heading(q: tuple[float, float, float, float]) -> float:
    """Direction of the torso's forward axis on the ground (its up axis when the forward axis
    points straight up or down)."""
    w, x, y, z = q
    fx, fy = 1 - 2 * (y * y + z * z), 2 * (x * y + w * z)
    if math.hypot(fx, fy) < 0.2:  # forward axis vertical: lying; use the torso's up axis
        fx, fy = 2 * (x * z + w * y), 2 * (y * z - w * x)
    return math.atan2(fy, fx)
