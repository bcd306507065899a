"""The robot camera as a real one delivers images: exposure, per-pixel noise, motion blur.

- **Exposure**: a gain on the rendered image, clipped at full scale: the camera's own (one per
  match, from the match seed). The scene's luminosity (the look's, 0.75 to 1.25) is in the
  rendered image already (it scales the lights, :mod:`simulator.world.look`), as the league's
  cameras, which have no auto-exposure, see it; a camera model that declares auto-exposure
  (``auto_exposure`` > 0) evens out that share of it: the gain is multiplied by
  ``luminosity ** -auto_exposure``.
- **Per-pixel noise**: zero-mean Gaussian read noise of ``noise_std`` grey levels on every byte,
  cut from a bank of noise drawn once per renderer; the cut's offset is a hash of the match seed,
  the robot and the simulated time, so the same match gives the same images whatever thread or
  process renders them.
- **Motion blur** (optional, off by default): the image averaged with copies shifted by the
  camera's motion during the exposure time (``exposure_s``), computed from the head's angular
  velocity.

B,G,R byte order, rows top to bottom, as the league's cameras delivered them. The ``ideal``
camera model (:meth:`CameraModel.ideal`) leaves the rendered image untouched.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

NOISE_BANK_EXTRA = 65_537  # values beyond one image in the bank: room for the offsets
GAIN_BITS = 6  # the gain in fixed point: 255 * gain * 64 stays in int16 up to a gain of 2


@dataclass(frozen=True, slots=True, kw_only=True)
class CameraModel:
    """Figures of the robot cameras of a match."""

    seed: int = 0
    exposure_gain: float = 1.0
    auto_exposure: float = 0.0  # share of the scene's luminosity change compensated
    noise_std: float = 2.0  # grey levels (0..255) per byte
    motion_blur: bool = False
    exposure_s: float = 0.01

    @classmethod
    def ideal(cls) -> CameraModel:
        """Exact images: the scene as it is lit, no noise, no blur."""
        return cls(noise_std=0.0, exposure_gain=1.0, auto_exposure=0.0, motion_blur=False)

    @classmethod
    def league(cls, seed: int, *, motion_blur: bool = False) -> CameraModel:
        """The default model of a match: exposure gain uniform in 0.9..1.1 from the seed."""
        rng = np.random.default_rng([seed, 0xCA3E])
        return cls(seed=seed, exposure_gain=float(rng.uniform(0.9, 1.1)), motion_blur=motion_blur)

    @property
    def is_ideal(self) -> bool:
        return (
            self.noise_std <= 0 and not self.motion_blur and self.exposure_gain == 1.0
            and self.auto_exposure == 0.0
        )  # fmt: skip

    def gain(self, luminosity: float) -> float:
        """The image's gain in a scene of ``luminosity``."""
        return float(self.exposure_gain * luminosity ** -self.auto_exposure)


def _mix(*values: int) -> int:
    """A 63-bit hash of small integers (splitmix64 steps): the noise offset of a frame."""
    h = 0x9E3779B97F4A7C15
    for v in values:
        h = (h ^ (v & 0xFFFFFFFFFFFFFFFF)) * 0xBF58476D1CE4E5B9 & 0xFFFFFFFFFFFFFFFF
        h ^= h >> 31
        h = h * 0x94D049BB133111EB & 0xFFFFFFFFFFFFFFFF
        h ^= h >> 29
    return h >> 1


class CameraEffects:
    """Applies a :class:`CameraModel` to rendered RGB images of one size."""

    def __init__(
        self, model: CameraModel, width: int, height: int, *, luminosity: float = 1.0
    ) -> None:
        self.model = model
        gain = min(model.gain(luminosity), 2.0)
        self._gain = int(round(gain * (1 << GAIN_BITS)))
        self._size = width * height * 3
        self._noise: npt.NDArray[np.int16] | None = None
        if model.noise_std > 0:
            rng = np.random.default_rng([model.seed, width, height, 0x401E])
            bank = rng.normal(0.0, model.noise_std, self._size + NOISE_BANK_EXTRA)
            self._noise = np.rint(bank).astype(np.int16)
        self._work = np.empty((height, width, 3), dtype=np.int16)

    def bgr_bytes(
        self,
        rgb: npt.NDArray[np.uint8],
        *,
        robot: int,
        sim_time_ms: int,
        blur_px: tuple[float, float] = (0.0, 0.0),
    ) -> bytes:
        """The B,G,R bytes of ``rgb`` (height x width x 3) as the camera delivers them."""
        return self.of_bgr(rgb[:, :, ::-1], robot=robot, sim_time_ms=sim_time_ms,
                           blur_px=blur_px)  # fmt: skip

    def of_bgr(
        self,
        bgr: npt.NDArray[np.uint8],
        *,
        robot: int,
        sim_time_ms: int,
        blur_px: tuple[float, float] = (0.0, 0.0),
    ) -> bytes:
        """:meth:`bgr_bytes` of an image in B,G,R order already (height x width x 3, rows top
        to bottom, any strides: e.g. a frame read bottom up, viewed upside down): the order
        the camera delivers, so no pass over the image turns it (a turn of the channels costs
        numpy about 15 times a contiguous pass)."""
        if self.model.motion_blur:
            bgr = motion_blur(bgr, blur_px)
        unity = self._gain == 1 << GAIN_BITS
        if self._noise is None and unity:
            return np.ascontiguousarray(bgr).tobytes()
        work = self._work
        if unity:
            work[:] = bgr
        else:
            np.multiply(bgr, np.int16(self._gain), out=work, dtype=np.int16)
            np.right_shift(work, GAIN_BITS, out=work)
        if self._noise is not None:
            offset = _mix(self.model.seed, robot, sim_time_ms) % NOISE_BANK_EXTRA
            work += self._noise[offset : offset + self._size].reshape(work.shape)
        np.clip(work, 0, 255, out=work)
        return work.astype(np.uint8).tobytes()


def motion_blur(rgb: npt.NDArray[np.uint8], blur_px: tuple[float, float]) -> npt.NDArray[np.uint8]:
    """``rgb`` averaged over its copies shifted from 0 to ``blur_px`` (columns, rows), in at
    most 4 steps; unchanged below one pixel of motion."""
    dx, dy = blur_px
    length = math.hypot(dx, dy)
    if length < 1.0:
        return rgb
    steps = min(4, int(length))
    acc = rgb.astype(np.uint16)
    for k in range(1, steps + 1):
        sx, sy = int(round(dx * k / steps)), int(round(dy * k / steps))
        acc += np.roll(rgb, (sy, sx), axis=(0, 1))
    return (acc // (steps + 1)).astype(np.uint8)


def focal_px(height: int, fovy_deg: float) -> float:
    """The focal length in pixels of a camera ``height`` pixels high with a vertical field of
    view of ``fovy_deg``: the pixels a radian spans at the image's centre."""
    return (height / 2.0) / math.tan(math.radians(fovy_deg) / 2.0)


def blur_px_of(
    angular_velocity_cam: npt.NDArray[np.float64],
    *,
    height: int,
    fovy_deg: float,
    exposure_s: float,
) -> tuple[float, float]:
    """Image motion (columns, rows) during the exposure for a camera turning at
    ``angular_velocity_cam`` (rad/s, MuJoCo camera frame: x right, y up, looking along -z)."""
    focal = focal_px(height, fovy_deg)
    wx, wy = float(angular_velocity_cam[0]), float(angular_velocity_cam[1])
    return (-wy * focal * exposure_s, wx * focal * exposure_s)
