"""What the stub robot sees: the ball in its head camera, projected onto the ground.

The ball is white with dark patches (the league's pentagon pattern, patches black or nearly)
on a textured green turf; field lines and goal posts are white only, robots grey, black, team
coloured. Images come through the camera model (exposure, pixel noise). The detector keeps
connected regions of non-green pixels that hold both clearly white and clearly black pixels,
are about as wide as tall and fill their bounding box like a disc, and whose size matches the
ball's expected size at the distance the region's position implies. It works on every second
pixel (160x120 from the 320x240 camera) in numpy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from robot.motion.models import CameraMount

CELL = 4  # pixels per grid cell side, on the subsampled image


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

    Seeds are connected regions of black pixels; around each, the disc that holds about twice
    as many pixels (the white half of the ball) must be mostly white or black and hold a fair
    share of both. Field lines (white only) and dark robot parts (no white) are rejected.
    """
    small = image_bgr[::2, ::2].astype(np.int16)
    b, g, r = small[..., 0], small[..., 1], small[..., 2]
    high = np.maximum(np.maximum(b, g), r)
    low = np.minimum(np.minimum(b, g), r)
    white = (low > 150) & (high - low < 45)
    black = high < 70
    rows, cols = white.shape
    rows_c, cols_c = rows // CELL, cols // CELL
    black_c = (
        black[: rows_c * CELL, : cols_c * CELL].reshape(rows_c, CELL, cols_c, CELL).sum((1, 3))
    )
    either = white | black
    blobs: list[tuple[float, BlobSighting]] = []
    for cells in _components(black_c >= 2):
        y0 = min(c[0] for c in cells) * CELL
        y1 = (max(c[0] for c in cells) + 1) * CELL
        x0 = min(c[1] for c in cells) * CELL
        x1 = (max(c[1] for c in cells) + 1) * CELL
        seed = black[y0:y1, x0:x1]
        area = int(seed.sum())
        if area < 6:
            continue
        sy, sx = np.nonzero(seed)
        cy, cx = y0 + sy.mean(), x0 + sx.mean()
        radius = math.sqrt(2.0 * area / math.pi)
        # re-centre on the ball pixels near the seed (robust to a line through the window)
        near, (wy, wx) = _disc(either.shape, cy, cx, 1.6 * radius)
        ball_px = either[wy, wx] & near
        if ball_px.sum() < 8:
            continue
        py, px = np.nonzero(ball_px)
        cy, cx = wy.start + float(np.median(py)), wx.start + float(np.median(px))
        disc, (wy, wx) = _disc(either.shape, cy, cx, radius)
        n_disc = int(disc.sum())
        n_white = int((white[wy, wx] & disc).sum())
        n_black = int((black[wy, wx] & disc).sum())
        if n_disc == 0 or (n_white + n_black) < 0.6 * n_disc:
            continue
        if min(n_white, n_black) < 0.2 * n_disc:
            continue
        score = (n_white + n_black) / n_disc * min(n_white, n_black) / max(n_white, n_black)
        blobs.append((score, BlobSighting(cx * 2.0 + 1.0, cy * 2.0 + 1.0, radius * 2.0)))
    blobs.sort(key=lambda item: -item[0])
    return [blob for _, blob in blobs]


def _disc(
    shape: tuple[int, ...], cy: float, cx: float, radius: float
) -> tuple[npt.NDArray[np.bool_], tuple[slice, slice]]:
    """A disc mask in the window around (cy, cx) that it covers, and that window."""
    y0, y1 = max(int(cy - radius), 0), min(int(cy + radius) + 2, shape[0])
    x0, x1 = max(int(cx - radius), 0), min(int(cx + radius) + 2, shape[1])
    yy, xx = np.mgrid[y0:y1, x0:x1]
    mask = (yy - cy) ** 2 + (xx - cx) ** 2 <= radius**2
    return mask, (slice(y0, y1), slice(x0, x1))


def _components(mask: npt.NDArray[np.bool_]) -> list[list[tuple[int, int]]]:
    seen = np.zeros_like(mask)
    out: list[list[tuple[int, int]]] = []
    rows, cols = mask.shape
    for start in zip(*np.nonzero(mask), strict=True):
        if seen[start]:
            continue
        stack = [(int(start[0]), int(start[1]))]
        seen[start] = True
        cells = []
        while stack:
            y, x = stack.pop()
            cells.append((y, x))
            for ny, nx in ((y + 1, x), (y - 1, x), (y, x + 1), (y, x - 1)):
                if 0 <= ny < rows and 0 <= nx < cols and mask[ny, nx] and not seen[ny, nx]:
                    seen[ny, nx] = True
                    stack.append((ny, nx))
        out.append(cells)
    return out


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


def white_above_horizon(
    image_bgr: npt.NDArray[np.uint8], pose: CameraPose, mount: CameraMount, *, margin_rad: float
) -> int:
    """White pixels clearly above the horizon (goal posts and crossbars; field lines lie below
    it and robot heads around it), on every second pixel."""
    height, width = image_bgr.shape[0], image_bgr.shape[1]
    focal = (width / 2.0) / math.tan(mount.fov_rad / 2.0)
    # the camera looks down by head pitch + torso pitch; the horizon is that far above centre
    down = pose.head_pitch_rad + pose.torso_pitch_rad
    horizon_row = height / 2.0 - focal * math.tan(down)
    last_row = int(horizon_row - focal * math.tan(margin_rad))
    if last_row <= 0:
        return 0
    top = image_bgr[: min(last_row, height) : 2, ::2].astype(np.int16)
    low = top.min(axis=2)
    high = top.max(axis=2)
    return int(((low > 200) & (high - low < 30)).sum())
