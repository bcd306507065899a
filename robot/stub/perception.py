"""What the stub robot sees: the ball in its head camera, projected onto the ground.

The league's balls are white-panelled with dark marks of five designs (classic pentagons,
three-lobed, eight-panel, curved-panel, triad), lit by tinted lights whose strength varies
about 4x between matches, on a green turf with hue and wear patches; field lines are textured
white turf, goal posts and nets grey or shaded, robots grey, black and team coloured. So the
detector holds to what does not change with the light: colour as a *share* of brightness, and
shape. Grass is what is about as green (green share ``g / (b + g + r)``) as the image's own
field; everything else is a region, and the ball is a disc inside one: nearly all not-grass,
ringed by grass (a line through the ring covers a fair part of it), with bright panels that do
not fill it (a line's or a white mark's do) and dark marks or shade. Whether the disc's size
fits a ball at the ground point it implies is checked from the camera pose
(:func:`ground_point`). It works on every second pixel (160x120 from the 320x240 camera) in
numpy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robot.motion.models import CameraMount

MAX_DEPTH = 24  # the deepest a region is measured (radius, in pixels of the subsampled image)
MAX_CANDIDATES = 400  # depth peaks looked at, deepest first
# the ball's mean green share: grey is 1/3, the league's tinted lights (pink, orange) bring it
# lower; a worn patch of turf (its yellow-brown blended half over the grass) holds more in a
# white light. Measured over texture_seed 1..20: balls 0.29 to 0.33; a worn patch in a dim
# sunset 0.40. In the striker's own camera as it walks to the ball (``hlvs bench stub``'s
# trials, texture_seed 1000..1019, 4,914 frames with the ball found): balls 0.277 to 0.332,
# while worn patches under the pink dawn light and far crossings of lines in the dusk came at
# 0.337 to 0.37, and a limit of 0.37 let three quarters of them through
BALL_MAX_GREEN_SHARE = 0.345
# Nothing this dark against the grass's median brightness is grass, whatever its green share:
# a black mark's few grey levels of noise make its share anything (the marks of a near ball
# counted as grass cut the ball's region into rings, and its disc came out half its size)
DARK_FRACTION = 0.25
# Bright not-grass in the ring round a disc is a field line: a ball lying on a line, or where
# lines cross, is ringed by grass and line (a line through the ring of a near ball covers up to
# half of it); at least this much of the ring must still be grass. Only round discs this large
# (radius in pixels of the subsampled image: a ball nearer than about 2.4 m): far away, a goal
# post's foot on the goal line is a small disc of not-grass that a line rings as well
LINE_FRACTION = 1.1  # a line is brighter than this times the grass's median
RING_MIN_GRASS = 0.45
LINE_RING_MIN_RADIUS = 4.0
# ... but not where something at least this share of the disc's diameter wide stands over it:
# a goal post (10 cm) rising from the disc of its foot is as wide as that disc, a line is 5 cm
# to the ball's 14 (0.36 of its width)
LINE_MAX_WIDTH = 0.8
# panels brighter than 3/4 of the ball's brightest: at most this share of the disc (a line or a
# white mark is bright all over, 0.9 and more; a near ball's marks cover less of it, 0.6-0.7)
BALL_MAX_BRIGHT = 0.78


@dataclass(frozen=True, slots=True)
class BlobSighting:
    u_px: float  # column of the centre, in the full image
    v_px: float  # row of the centre, in the full image
    radius_px: float


@dataclass(frozen=True, slots=True)
class BallSighting:
    """The ball relative to the robot: x forward, y left from the pelvis, on the ground (m)."""

    x_m: float
    y_m: float

    @property
    def distance_m(self) -> float:
        return math.hypot(self.x_m, self.y_m)

    @property
    def bearing_rad(self) -> float:
        return math.atan2(self.y_m, self.x_m)


def find_ball_blobs(image_bgr: npt.NDArray[np.uint8]) -> list[BlobSighting]:
    """Candidate ball regions in a ``height x width x 3`` B,G,R image, best first.

    On every second pixel: the pixels that are not grass (:func:`_not_grass`), how deep each
    lies inside its region (:func:`_depth`), and at the deepest points of those regions a disc
    that must be nearly all not-grass, ringed mostly by grass and hold the ball's contrast
    (:func:`_ball_disc`).
    """
    small = image_bgr[::2, ::2].astype(np.int32)
    not_grass, value, grass_value, share = _not_grass(small)
    depth = _depth(not_grass)
    rows, cols = depth.shape
    padded = np.pad(depth, 1)
    peak = (depth >= 2) & (depth < MAX_DEPTH)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if dy or dx:
                peak &= depth >= padded[1 + dy : 1 + dy + rows, 1 + dx : 1 + dx + cols]
    ys, xs = np.nonzero(peak)
    # cheap first cut: at 1.6 radii around the peak, grass in most of eight directions
    reach = 1.6 * depth[ys, xs] + 1.5
    grass_around = np.zeros(len(ys), np.int32)
    for k in range(8):
        angle = k * math.pi / 4.0
        oy = np.clip(np.rint(ys + reach * math.sin(angle)).astype(np.int64), 0, rows - 1)
        ox = np.clip(np.rint(xs + reach * math.cos(angle)).astype(np.int64), 0, cols - 1)
        grass_around += ~not_grass[oy, ox]
    keep = grass_around >= 6
    ys, xs = ys[keep], xs[keep]
    order = np.argsort(-depth[ys, xs], kind="stable")
    taken = np.zeros(depth.shape, np.bool_)
    blobs: list[tuple[float, BlobSighting]] = []
    for index in order[:MAX_CANDIDATES]:
        cy, cx = int(ys[index]), int(xs[index])
        if taken[cy, cx]:
            continue
        d = int(depth[cy, cx])
        taken[max(cy - d - 1, 0) : cy + d + 2, max(cx - d - 1, 0) : cx + d + 2] = True
        found = _ball_disc(not_grass, value, grass_value, share, cy, cx, d)
        if found is not None:
            score, y, x, radius = found
            blobs.append((score, BlobSighting(x * 2.0 + 1.0, y * 2.0 + 1.0, radius * 2.0)))
    blobs.sort(key=lambda item: -item[0])
    return [blob for _, blob in blobs]


def _not_grass(
    small: npt.NDArray[np.int32],
) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.int32], float, npt.NDArray[np.int32]]:
    """Pixels whose green share ``g / (b + g + r)`` is clearly below the grass's, their
    brightness (the largest channel), the grass's median brightness and the green share (in
    1/1024).

    The grass's share is the median of the pixels where green is the largest channel (a
    robot's view is mostly field): a threshold 60 % of the way from it to a grey's 1/3 holds
    for dark and bright scenes, tinted light and wear patches alike."""
    b, g, r = small[..., 0], small[..., 1], small[..., 2]
    share = (g * 1024) // (b + g + r + 3)
    value = np.maximum(np.maximum(b, g), r)
    sample = share[::2, ::2]
    green = (g[::2, ::2] > r[::2, ::2]) & (g[::2, ::2] > b[::2, ::2])
    field = sample[green]
    grass_share = float(np.median(field)) / 1024.0 if field.size > 0.05 * sample.size else 0.55
    cut = grass_share - 0.6 * (grass_share - 1.0 / 3.0)
    grass = share >= cut * 1024.0
    grass_values = value[::2, ::2][grass[::2, ::2]]
    grass_value = float(np.median(grass_values)) if grass_values.size else 128.0
    grass &= value >= DARK_FRACTION * grass_value
    return ~grass, value, grass_value, share


def _depth(mask: npt.NDArray[np.bool_]) -> npt.NDArray[np.int16]:
    """For each pixel of ``mask``, how many erosions (4-neighbour) it survives, up to
    :data:`MAX_DEPTH`: about the radius of the largest disc round it inside the mask."""
    depth = np.zeros(mask.shape, np.int16)
    inside = mask.copy()
    inside[0], inside[-1], inside[:, 0], inside[:, -1] = False, False, False, False
    for _ in range(MAX_DEPTH):
        depth += inside
        eroded = inside.copy()
        eroded[1:] &= inside[:-1]
        eroded[:-1] &= inside[1:]
        eroded[:, 1:] &= inside[:, :-1]
        eroded[:, :-1] &= inside[:, 1:]
        inside = eroded
        if not inside.any():
            break
    return depth


def _ball_disc(
    not_grass: npt.NDArray[np.bool_],
    value: npt.NDArray[np.int32],
    grass_value: float,
    share: npt.NDArray[np.int32],
    cy: int,
    cx: int,
    depth: int,
) -> tuple[float, float, float, float] | None:
    """The ball's disc round a depth peak — (score, row, column, radius) on the subsampled
    image — or None: the disc grown while its edge stays not-grass, re-centred, must be
    nearly all not-grass (a line is narrower than its depth's disc only where it widens),
    ringed by grass at 1.3-1.8 radii (a near disc: grass and bright line, at least
    :data:`RING_MIN_GRASS` of it grass, as round a ball lying on a line), with
    bright panels (not brighter than most of it, as a line's or a white mark's) and dark
    marks or shade, and about as green as grey on the whole (a worn patch of turf in a dim
    light passes the rest, but half of it is grass)."""
    rows, cols = not_grass.shape
    radius = max(depth - 0.5, 1.0)
    half = int(2.0 * radius + 6)
    y0, y1 = max(cy - half, 0), min(cy + half + 1, rows)
    x0, x1 = max(cx - half, 0), min(cx + half + 1, cols)
    yy, xx = np.ogrid[y0:y1, x0:x1]
    window = not_grass[y0:y1, x0:x1]
    dist = np.sqrt((yy - cy) ** 2 + (xx - cx) ** 2)
    for _ in range(4):
        shell = (dist > radius) & (dist <= radius + 1.0)
        if np.count_nonzero(window & shell) < 0.7 * np.count_nonzero(shell):
            break
        radius += 1.0
    py, px = np.nonzero(window & (dist <= radius))
    cy_f, cx_f = y0 + float(py.mean()), x0 + float(px.mean())
    dist = np.sqrt((yy - cy_f) ** 2 + (xx - cx_f) ** 2)
    disc = dist <= radius
    n_disc = np.count_nonzero(disc)
    inner, outer = 1.3 * radius + 0.5, 1.8 * radius + 1.5
    ring = (dist > inner) & (dist <= outer)
    n_ring = np.count_nonzero(ring)
    inside = radius <= cy_f <= rows - 1 - radius and radius <= cx_f <= cols - 1 - radius
    if not inside or n_ring < 0.9 * math.pi * (outer**2 - inner**2):
        return None  # cut by the image's edge: too little of it or its ring to judge
    fill = np.count_nonzero(window & disc) / n_disc
    ring_grass = 1.0 - np.count_nonzero(window & ring) / n_ring
    ring_clear = ring_grass
    if radius >= LINE_RING_MIN_RADIUS and not _post_above(
        not_grass, cy_f, cx_f, radius, LINE_MAX_WIDTH * 2.0 * radius
    ):
        line = window & ring & (value[y0:y1, x0:x1] > LINE_FRACTION * grass_value)
        ring_clear += np.count_nonzero(line) / n_ring
    if fill < 0.8 or ring_clear < 0.8 or ring_grass < RING_MIN_GRASS:
        return None
    values = np.sort(value[y0:y1, x0:x1][window & disc])
    high, low = values[(len(values) * 9) // 10], values[len(values) // 10]
    bright = np.count_nonzero(values > 0.75 * high) / len(values)
    if high < 0.6 * grass_value or low > 0.6 * high or bright > BALL_MAX_BRIGHT:
        return None
    if share[y0:y1, x0:x1][window & disc].mean() > BALL_MAX_GREEN_SHARE * 1024:
        return None
    return ring_clear * fill, cy_f, cx_f, radius


def _post_above(
    not_grass: npt.NDArray[np.bool_], cy: float, cx: float, radius: float, width: float
) -> bool:
    """Whether not-grass at least ``width`` pixels wide stands over the disc of ``radius`` at
    (``cy``, ``cx``): the run through its column is that wide two and three radii above its
    centre, as a goal post's is over its foot. A line is narrower than a ball (5 cm to 14), and
    a post behind a ball is farther than the ball, so narrower than it too."""
    cols = not_grass.shape[1]
    column = int(round(cx))  # inside the image: _ball_disc judges only discs inside it
    for rise in (2.0 * radius, 3.0 * radius):
        row = int(round(cy - rise))
        if row < 0 or not not_grass[row, column]:
            return False
        grass = np.flatnonzero(~not_grass[row])
        left, right = grass[grass < column], grass[grass > column]
        start = int(left[-1]) + 1 if left.size else 0
        end = int(right[0]) if right.size else cols
        if end - start < width:
            return False
    return True


@dataclass(frozen=True, slots=True, kw_only=True)
class CameraPose:
    """Head and torso angles when the image was taken (rad) and the pelvis height (m)."""

    neck_yaw_rad: float
    head_pitch_rad: float  # positive looks down
    torso_roll_rad: float
    torso_pitch_rad: float  # positive leans forward
    pelvis_height_m: float


def ground_point(
    blob: BlobSighting,
    pose: CameraPose,
    mount: CameraMount,
    *,
    width_px: int,
    height_px: int,
    ball_radius_m: float,
) -> BallSighting | None:
    """Where the blob's centre ray meets the plane of the ball's centre; None above the horizon
    or when the blob's size does not fit a ball at that distance."""
    focal = (width_px / 2.0) / math.tan(mount.fov_rad / 2.0)
    ray_cam = (1.0, -(blob.u_px - width_px / 2.0) / focal, -(blob.v_px - height_px / 2.0) / focal)
    head = _rot_z(pose.neck_yaw_rad) @ _rot_y(pose.head_pitch_rad)
    torso = _rot_x(pose.torso_roll_rad) @ _rot_y(pose.torso_pitch_rad)
    cam_in_torso = np.array([0.0, 0.0, mount.neck_height_m]) + _rot_z(pose.neck_yaw_rad) @ (
        np.array([0.0, 0.0, mount.head_height_m])
        + _rot_y(pose.head_pitch_rad) @ np.array([mount.camera_forward_m, 0.0, 0.0])
    )
    origin = torso @ cam_in_torso + np.array([0.0, 0.0, pose.pelvis_height_m])
    direction = torso @ head @ np.array(ray_cam)
    if direction[2] >= -1e-6:
        return None
    t = (ball_radius_m - origin[2]) / direction[2]
    if t <= 0:
        return None
    point = origin + t * direction
    distance = float(np.linalg.norm(point - origin))
    expected_px = focal * ball_radius_m / max(distance, 1e-3)
    if not 0.45 * expected_px <= blob.radius_px <= 2.2 * expected_px:
        return None
    return BallSighting(float(point[0]), float(point[1]))


def _rot_x(a: float) -> npt.NDArray[np.float64]:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rot_y(a: float) -> npt.NDArray[np.float64]:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rot_z(a: float) -> npt.NDArray[np.float64]:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def goal_below_horizon(
    image_bgr: npt.NDArray[np.uint8], pose: CameraPose, mount: CameraMount, *, margin_rad: float
) -> int:
    """Pixels of the near field, more than ``margin_rad`` below the horizon, that are neither
    grass nor brighter than it (field lines are), on every second pixel: the foot of a near
    goal (posts, net cords and frame stand on the field there) where a far goal lies within
    the margin. Above the horizon a bright sky or building outshines a goal post."""
    height, width = image_bgr.shape[0], image_bgr.shape[1]
    focal = (width / 2.0) / math.tan(mount.fov_rad / 2.0)
    # the camera looks down by head pitch + torso pitch; the horizon is that far above centre
    down = pose.head_pitch_rad + pose.torso_pitch_rad
    first_row = int(height / 2.0 - focal * math.tan(down - margin_rad))
    if first_row >= height:
        return 0
    small = image_bgr[::2, ::2].astype(np.int32)
    not_grass, value, grass_value, _ = _not_grass(small)
    rows = slice(max(first_row, 0) // 2, None)
    return int(np.count_nonzero(not_grass[rows] & (value[rows] <= 1.15 * grass_value)))
