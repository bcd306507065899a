"""World -> :class:`referee.snapshot.WorldSnapshot`, built by a :class:`SnapshotBuilder`.

Contacts are classified per robot as bit masks of body parts (ground = the turf only, ball) and
robot pairs; masks become frozensets through a precomputed table.

Cost: the snapshot runs every basic step right after ``mj_step``, when the interpreter's and
numpy's working set is out of the caches, so each numpy call costs a few microseconds. The builder
keeps the calls few: every float value of the snapshot comes from one gather over one span of
``MjData`` (:mod:`simulator.world.flat`) and one ``tolist``; the yaws take one ``arctan2`` over all
robots (vectorised as before, so the values are the same to the bit); the contacts take one pass of
about ten calls, and none when the set of geom pairs in contact is one seen lately (standing
robots, and robots moving their joints: the number of contacts of a foot on the turf changes from
step to step much more often than which geoms touch); the frozen dataclasses are built through
their slots (:mod:`simulator.world.frozen`). Measured with eight standing robots (``hlvs bench sim
--robots 8``, three runs interleaved with the previous builder, load average about 2 on two cores):
``snapshot_us`` 39-41 instead of 84-104, ``ratio`` 1.011-1.038 instead of 0.921-0.958 (above 1: the
world evaluates sensors in the last substep only, the bare loop in every one). When the contacts
changed since the previous step (walking robots) the snapshot costs about 12 us more than when they
did not; eight robots moving every joint by a few degrees (the targets of ``bench api``) came back
to five sets of pairs in 1500 steps: 33 us per snapshot against 41 us when only the previous step's
list was kept. With the stub striker and goalie playing (``run_shot`` of ``testkit.stub_world``,
contacts reused in 41% of the steps) a two-robot snapshot costs 31 us against the previous
builder's 87 us (medians, the same steps). With the cleats (a contact per cleat: 65 contacts for
eight standing robots) making the set of pairs cost 8 us, the contact list's bytes are looked up
first: ``contacts`` 15.3 -> 1.8 us and the snapshot 33 -> 20 us with warm caches; right after
``mj_step`` the snapshot went from 4.4-4.8 % of the step's ``mj_step`` time to 3.0-3.5 %.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import mujoco
import numpy as np
import numpy.typing as npt

from contracts import RobotId
from referee import BallState, BodyPart, RobotState, WorldSnapshot
from simulator.world.flat import FlatData
from simulator.world.frozen import slot_constructor
from simulator.world.indices import (
    FOOT_BIT,
    KIND_BALL,
    KIND_ROBOT,
    KIND_TURF,
    KINDS,
    PART_SLOTS,
    PARTS,
    WorldIndex,
)

KNOWN_PAIR_SETS = 512  # classifications kept (of the sets of geom pairs in contact)
FALLEN_TILT_COS = 0.5  # torso z axis more than 60 degrees from vertical
_NOBODY: frozenset[RobotId] = frozenset()
_PART_SETS: tuple[frozenset[BodyPart], ...] = tuple(
    frozenset(p for i, p in enumerate(PARTS) if mask & (1 << i)) for mask in range(1 << len(PARTS))
)
_make_ball = slot_constructor(BallState)
_make_robot = slot_constructor(RobotState, positional=True)
_make_snapshot = slot_constructor(WorldSnapshot)
_HEAD = 6  # ball position and velocity at the start of the gathered values
_PER_ROBOT = 18  # x y z, up (torso z axis' z), centre of mass xyz, its velocity xyz, hull 4 x xy


class BallToucher:
    """The robot touching the ball in the last substep (lowest number), or -1: one contact
    sensor per robot (MuJoCo counts the contacts in C). The robots' sensors are laid out
    alike, so their ball-touch counts are one strided view of ``sensordata``, made once (MuJoCo
    never moves the array): a step costs one ``tolist`` of it, where a fancy index and
    ``flatnonzero`` cost about 12 us right after ``mj_step``."""

    def __init__(self, data: mujoco.MjData, index: WorldIndex) -> None:
        adr = index.ball_touch
        sensors = data.sensordata
        strides = np.unique(np.diff(adr))
        self._counts: Callable[[], npt.NDArray[np.float64]]
        if adr.size == 1 or (strides.size == 1 and strides[0] > 0):
            view = sensors[int(adr[0]) :: int(strides[0]) if strides.size else 1][: adr.size]
            self._counts = lambda: view
        else:  # no robot, or irregular addresses: gathered per read
            self._counts = lambda: sensors[adr]

    def __call__(self) -> int:
        # a list of a few floats: ``ndarray.any`` goes through numpy's Python-level wrapper
        # (0.7 us warm against 0.15 us for this, and several times that right after mj_step)
        for robot, count in enumerate(self._counts().tolist()):
            if count:
                return robot
        return -1


# per robot: bits of the parts on the turf, bits of the parts on the ball, robots touched
ContactSets = tuple[list[int], list[int], list[frozenset[RobotId]]]


class SnapshotBuilder:
    """Snapshots of one world's ``data``; what does not change between steps is computed once.

    Values gathered per step (one array): ball position, ball velocity, the torso rotation
    entries for the yaw of every robot (sin block, cos block), then per robot
    :data:`_PER_ROBOT` values.
    """

    def __init__(
        self, data: mujoco.MjData, index: WorldIndex, robot_ids: Sequence[RobotId]
    ) -> None:
        self._data = data
        self._index = index
        self._ids = tuple(robot_ids)
        n = len(self._ids)
        self._n = n
        flat = FlatData(data, ("qpos", "qvel", "xpos", "xmat", "subtree_com", "sensordata"))
        self._values = flat.values
        torso_rot = index.torso_bodies * 9  # xmat rows are 3x3 row-major
        hull_xy = (index.hull_bodies[:, :, None] * 3 + np.arange(2)).reshape(n, 8)
        per_robot = np.concatenate(
            [
                flat.indices("qpos", index.root_xyz),
                flat.indices("xmat", torso_rot + 8)[:, None],
                flat.indices("subtree_com", index.torso_bodies[:, None] * 3 + np.arange(3)),
                flat.indices("sensordata", index.com_velocity),
                flat.indices("xpos", hull_xy),
            ],
            axis=1,
        ).reshape(n, _PER_ROBOT)
        self._gather = np.concatenate(
            [
                flat.indices("qpos", index.ball_qpos + np.arange(3)),
                flat.indices("qvel", index.ball_dof + np.arange(3)),
                flat.indices("xmat", torso_rot + 3),  # sin(yaw) * cos(pitch)
                flat.indices("xmat", torso_rot),  # cos(yaw) * cos(pitch)
                per_robot.ravel(),
            ]
        ).astype(np.intp)
        # contact codes: robot * KINDS * PART_SLOTS + kind of the other side * PART_SLOTS + part;
        # sides that are not robot geoms go to bins past the robots' (the sink)
        sink = n * KINDS * PART_SLOTS
        self._own_code = np.where(index.geom_code >= 0, index.geom_code, sink).astype(np.intp)
        self._other_code = index.geom_kind_code.astype(np.intp)
        self._bins = sink + KINDS * PART_SLOTS
        self._none: ContactSets = ([0] * n, [0] * n, [_NOBODY] * n)
        self._soles = tuple(index.by_id[r].sole_outline for r in self._ids)
        # the classification of each set of geom pairs in contact seen lately
        self._known: dict[frozenset[int], ContactSets] = {}
        self._listed: dict[bytes, ContactSets] = {}  # the same, by the contact list's bytes
        self._arena_bytes = int(data.narena)
        self._geoms: npt.NDArray[np.int32] | None = None  # see _contact_geoms

    def build(
        self,
        *,
        sim_time_ms: int,
        limp: Sequence[bool],
        removed: Sequence[bool],
        last_toucher: RobotId | None,
        last_touch_ms: int | None,
    ) -> WorldSnapshot:
        n = self._n
        gathered = self._values[self._gather]
        if n:
            sin, cos = gathered[_HEAD : _HEAD + n], gathered[_HEAD + n : _HEAD + 2 * n]
            np.arctan2(sin, cos, out=sin)  # the yaws replace the sines
        v = gathered.tolist()
        ball = _make_ball(position=(v[0], v[1], v[2]), velocity=(v[3], v[4], v[5]))
        if n == 0:
            return _make_snapshot(
                sim_time_ms=sim_time_ms,
                ball=ball,
                robots=(),
                last_ball_toucher=None,
                last_ball_touch_ms=None,
            )
        ground, ball_bits, touching = self.contacts()
        robots = []
        k = _HEAD + 2 * n
        for i, robot_id in enumerate(self._ids):
            gbits = ground[i]
            robots.append(
                _make_robot(
                    robot_id,  # the fields of RobotState in order
                    (v[k], v[k + 1], v[k + 2]),  # position
                    v[_HEAD + i],  # yaw_rad
                    (v[k + 4], v[k + 5], v[k + 6]),  # center_of_mass
                    (v[k + 7], v[k + 8], v[k + 9]),  # velocity
                    _PART_SETS[gbits],  # ground_contacts
                    _PART_SETS[ball_bits[i]],  # ball_contacts
                    touching[i],  # robot_contacts
                    (  # hull_points
                        (v[k + 10], v[k + 11]),
                        (v[k + 12], v[k + 13]),
                        (v[k + 14], v[k + 15]),
                        (v[k + 16], v[k + 17]),
                    ),
                    self._soles[i],  # sole_outline
                    bool(gbits & ~FOOT_BIT) or v[k + 3] < FALLEN_TILT_COS,  # fallen
                    limp[i],  # limp
                    removed[i],  # removed
                )
            )
            k += _PER_ROBOT
        return _make_snapshot(
            sim_time_ms=sim_time_ms,
            ball=ball,
            robots=tuple(robots),
            last_ball_toucher=last_toucher,
            last_ball_touch_ms=last_touch_ms,
        )

    def contacts(self) -> ContactSets:
        """Per robot: part bits touching the turf, part bits touching the ball, robots touched.

        One pass over the contact list: each side of a contact that is a robot geom sets the
        flag (robot, kind of the geom on the other side: turf, ball, robot; part); the flags of
        one (robot, kind) are one byte of part bits.
        """
        data = self._data
        ncon = data.ncon
        if ncon == 0:
            return self._none
        geom = self._contact_geoms()[:ncon]
        # first the contact list itself, as bytes (a few hundred: hashed and compared in C):
        # robots standing or moving their joints repeat it step after step
        listed = geom.tobytes()
        seen = self._listed.get(listed)
        if seen is not None:
            return seen
        # then the pairs in contact (each pair's two int32 as one int64), whatever their order
        # and how many contacts each pair has: the classification depends on that set alone
        pairs = frozenset(geom.view(np.int64).ravel().tolist())
        known = self._known
        seen = known.get(pairs)
        if seen is not None:
            self._remember(listed, seen)
            return seen
        flags = np.zeros(self._bins, dtype=np.bool_)
        flags[self._own_code[geom] + self._other_code[geom[:, ::-1]]] = True
        bits = np.packbits(flags, bitorder="little").tobytes()  # byte robot * KINDS + kind
        n = self._n
        touching = [_NOBODY] * n
        if any(bits[KIND_ROBOT : n * KINDS : KINDS]):
            robots = self._index.geom_robot[geom]
            between = (robots[:, 0] >= 0) & (robots[:, 1] >= 0) & (robots[:, 0] != robots[:, 1])
            ids = self._ids
            for a, b in {(a, b) for a, b in np.sort(robots[between], axis=1).tolist()}:
                touching[a] = touching[a] | {ids[b]}
                touching[b] = touching[b] | {ids[a]}
        sets: ContactSets = (
            list(bits[KIND_TURF : n * KINDS : KINDS]),
            list(bits[KIND_BALL : n * KINDS : KINDS]),
            touching,
        )
        if len(known) >= KNOWN_PAIR_SETS:
            known.clear()
        known[pairs] = sets
        self._remember(listed, sets)
        return sets

    def _contact_geoms(self) -> npt.NDArray[np.int32]:
        """The geom pairs of every contact the arena can hold (slice the first ``ncon``): a
        view made once. MuJoCo always lays the contacts at the start of the ``MjData``'s arena
        (``mj_clearEfc``: ``d->contact = d->arena``), which never moves, and
        ``data.contact.geom`` builds a wrapper with every field of the list each time (5 us
        right after ``mj_step``, against a slice of this view)."""
        view = self._geoms
        if view is None:
            geom = self._data.contact.geom  # (needs a contact: the row stride is mjContact's)
            stride = geom.strides[0]
            rows = max(len(geom), self._arena_bytes // stride)
            view = self._geoms = np.lib.stride_tricks.as_strided(
                geom, shape=(rows, 2), strides=geom.strides, writeable=False
            )
        return view

    def _remember(self, listed: bytes, sets: ContactSets) -> None:
        if len(self._listed) >= KNOWN_PAIR_SETS:
            self._listed.clear()
        self._listed[listed] = sets
