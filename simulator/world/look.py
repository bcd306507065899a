"""The league's look: turf, ball, goal nets, stadium background and lighting, from ``texture_seed``.

As in the league's Webots world, ``texture_seed`` picks the variants (turf, ball, background)
and the luminosity (uniform in 0.75..1.25); the same seed gives the same images. Each texture
depends on its variant alone, so it is generated once per process (about 0.3 s each). The textures
are procedural (:mod:`simulator.world.textures`, numpy only, nothing downloaded or shipped):
the model declares them as placeholders of the right size (:func:`look_assets`) and
:func:`apply_look` writes the generated texels and the lights into the compiled model, before
any renderer uploads them. Robot cameras, the match video and the viewer (through the replay's
scene, :func:`Look.summary`) all draw the same look.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any, TypedDict

import mujoco
import numpy as np

from simulator.world import textures


class LookRecord(TypedDict):
    """A match's look, as a viewer draws it simply (:meth:`Look.summary`); the ``look`` of a
    replay's scene (:class:`simulator.replay.format.SceneRecord`)."""

    texture_seed: int
    turf: int
    ball: int
    background: int
    luminosity: float
    turf_colors: list[list[float]]  # the two stripe colours
    stripe_m: float
    ball_colors: list[list[float]]
    sky_colors: list[list[float]]  # sky top, horizon, stands


RGB = tuple[float, float, float]

TURF_TEXTURE = "look:turf"
BALL_TEXTURE = "look:ball"
SKY_TEXTURE = "look:sky"
NET_TEXTURE = "look:net"
TURF_PX = 512
BALL_FACE_PX = 128
SKY_FACE_PX = 256
NET_PX = 64
NET_MESH_M = 0.1
LUMINOSITY_RANGE = (0.75, 1.25)


@dataclass(frozen=True, slots=True)
class TurfVariant:
    base_rgb: RGB
    stripe_m: float  # width of one mowing stripe
    stripe_contrast: float


@dataclass(frozen=True, slots=True)
class BallVariant:
    patch_rgb: RGB
    panel_rgb: RGB
    patch_size: float


@dataclass(frozen=True, slots=True)
class BackgroundVariant:
    sky_top: RGB
    sky_horizon: RGB
    stands_rgb: RGB
    boards: tuple[RGB, ...]
    surround_rgb: RGB


TURFS = (
    TurfVariant((0.20, 0.55, 0.18), 0.5, 0.10),
    TurfVariant((0.16, 0.50, 0.20), 0.75, 0.12),
    TurfVariant((0.24, 0.56, 0.16), 1.0, 0.08),
    TurfVariant((0.18, 0.47, 0.22), 0.5, 0.14),
)
BALLS = (
    BallVariant((0.06, 0.06, 0.06), (0.96, 0.96, 0.96), 0.02),
    BallVariant((0.05, 0.05, 0.05), (0.95, 0.95, 0.93), 0.035),
    BallVariant((0.08, 0.08, 0.20), (0.96, 0.96, 0.96), 0.025),
    BallVariant((0.20, 0.05, 0.05), (0.95, 0.95, 0.95), 0.03),
    BallVariant((0.04, 0.04, 0.04), (0.93, 0.94, 0.96), 0.015),
)
_BOARDS = ((0.12, 0.22, 0.55), (0.6, 0.12, 0.1), (0.62, 0.58, 0.12), (0.1, 0.42, 0.2))
BACKGROUNDS = (
    BackgroundVariant((0.22, 0.42, 0.72), (0.55, 0.66, 0.74), (0.32, 0.32, 0.36), _BOARDS,
                      (0.14, 0.22, 0.14)),  # day, blue sky
    BackgroundVariant((0.5, 0.52, 0.55), (0.62, 0.63, 0.64), (0.28, 0.26, 0.26), _BOARDS[::-1],
                      (0.16, 0.18, 0.15)),  # overcast
    BackgroundVariant((0.08, 0.1, 0.2), (0.5, 0.36, 0.3), (0.22, 0.2, 0.24), _BOARDS[1:],
                      (0.1, 0.12, 0.1)),  # dusk
    BackgroundVariant((0.12, 0.12, 0.13), (0.2, 0.2, 0.22), (0.35, 0.2, 0.18), _BOARDS[:3],
                      (0.18, 0.18, 0.2)),  # indoor hall
)  # fmt: skip


@dataclass(frozen=True, slots=True)
class Look:
    """The variants ``texture_seed`` picked; build with :func:`look_for`."""

    texture_seed: int
    turf: int
    ball: int
    background: int
    luminosity: float

    def summary(self) -> LookRecord:
        """What a viewer needs to draw the same look simply (recorded in the replay's scene):
        the two stripe colours (mean texel colours), the stripe width, the ball's colours and
        the background's sky and stands colours."""
        turf = turf_image(self.turf)
        half = turf.shape[1] // 2
        light = turf[:, :half].reshape(-1, 3).mean(axis=0) / 255.0
        dark = turf[:, half:].reshape(-1, 3).mean(axis=0) / 255.0
        ball = BALLS[self.ball]
        bg = BACKGROUNDS[self.background]
        return {
            "texture_seed": self.texture_seed,
            "turf": self.turf,
            "ball": self.ball,
            "background": self.background,
            "luminosity": round(self.luminosity, 4),
            "turf_colors": [_rounded(light), _rounded(dark)],
            "stripe_m": TURFS[self.turf].stripe_m,
            "ball_colors": [list(ball.panel_rgb), list(ball.patch_rgb)],
            "sky_colors": [list(bg.sky_top), list(bg.sky_horizon), list(bg.stands_rgb)],
        }


def _rounded(values: Any) -> list[float]:
    return [round(float(v), 4) for v in values]


def look_from_summary(summary: LookRecord) -> Look:
    """The look a :meth:`Look.summary` describes (a replay's scene)."""
    return Look(
        texture_seed=int(summary["texture_seed"]),
        turf=int(summary["turf"]) % len(TURFS),
        ball=int(summary["ball"]) % len(BALLS),
        background=int(summary["background"]) % len(BACKGROUNDS),
        luminosity=float(summary["luminosity"]),
    )


def look_for(texture_seed: int) -> Look:
    """The look ``texture_seed`` picks (deterministic)."""
    rng = np.random.default_rng([texture_seed, 0x100C])
    return Look(
        texture_seed=int(texture_seed),
        turf=int(rng.integers(len(TURFS))),
        ball=int(rng.integers(len(BALLS))),
        background=int(rng.integers(len(BACKGROUNDS))),
        luminosity=float(rng.uniform(*LUMINOSITY_RANGE)),
    )


# Each texture is a function of its variant alone (its noise seeded by the variant's number),
# as the league's world picked among fixed textures: a process generates each at most once.


@lru_cache(maxsize=len(TURFS))
def turf_image(variant: int) -> textures.Image:
    v = TURFS[variant]
    return textures.turf_tile(
        seed=0x7F4F + variant, size_px=TURF_PX, base_rgb=v.base_rgb,
        stripe_contrast=v.stripe_contrast,
    )  # fmt: skip


@lru_cache(maxsize=len(BALLS))
def ball_image(variant: int) -> textures.Image:
    v = BALLS[variant]
    return textures.ball_cube(
        face_px=BALL_FACE_PX, patch_rgb=v.patch_rgb, panel_rgb=v.panel_rgb,
        patch_size=v.patch_size, turn_rad=0.3 * variant,
    )  # fmt: skip


@lru_cache(maxsize=len(BACKGROUNDS))
def sky_image(variant: int) -> textures.Image:
    v = BACKGROUNDS[variant]
    return textures.stadium_cube(
        seed=0x5747 + variant, face_px=SKY_FACE_PX, sky_top=v.sky_top,
        sky_horizon=v.sky_horizon, stands_rgb=v.stands_rgb, boards=v.boards,
        surround_rgb=v.surround_rgb,
    )  # fmt: skip


@lru_cache(maxsize=1)
def net_image() -> textures.Image:
    return textures.net_tile(size_px=NET_PX, mesh_px=NET_PX // 4)


def look_assets(look: Look) -> str:
    """MJCF assets: placeholder textures of the look's sizes (filled by :func:`apply_look`)
    and the materials that use them (``look:turf``, ``look:ball``, ``look:net``)."""
    stripe = TURFS[look.turf].stripe_m
    repeat = 1.0 / (2.0 * stripe)  # one tile spans two stripes; per metre with texuniform
    net_repeat = 1.0 / (4.0 * NET_MESH_M)
    return (
        f'<texture name="{SKY_TEXTURE}" type="skybox" builtin="flat" rgb1="0.4 0.5 0.6" '
        f'width="{SKY_FACE_PX}" height="{SKY_FACE_PX}"/>'
        f'<texture name="{TURF_TEXTURE}" type="2d" builtin="flat" rgb1="0.2 0.5 0.2" '
        f'width="{TURF_PX}" height="{TURF_PX}"/>'
        f'<material name="{TURF_TEXTURE}" texture="{TURF_TEXTURE}" texuniform="true" '
        f'texrepeat="{repeat:.6g} {repeat:.6g}" reflectance="0"/>'
        f'<texture name="{BALL_TEXTURE}" type="cube" builtin="flat" rgb1="1 1 1" '
        f'width="{BALL_FACE_PX}" height="{BALL_FACE_PX}"/>'
        f'<material name="{BALL_TEXTURE}" texture="{BALL_TEXTURE}" specular="0.3"/>'
        f'<texture name="{NET_TEXTURE}" type="2d" builtin="flat" rgb1="0.8 0.8 0.8" '
        f'width="{NET_PX}" height="{NET_PX}"/>'
        f'<material name="{NET_TEXTURE}" texture="{NET_TEXTURE}" texuniform="true" '
        f'texrepeat="{net_repeat:.6g} {net_repeat:.6g}" rgba="1 1 1 0.45"/>'
    )


def _write_texture(model: mujoco.MjModel, name: str, image: textures.Image) -> None:
    tex = model.texture(name)
    texid = int(tex.id)
    width, height = int(model.tex_width[texid]), int(model.tex_height[texid])
    channels = int(model.tex_nchannel[texid])
    if image.shape[0] * image.shape[1] != width * height:
        raise ValueError(
            f"texture {name}: generated {image.shape[1]}x{image.shape[0]}, model {width}x{height}"
        )
    adr = int(model.tex_adr[texid])
    texels = model.tex_data[adr : adr + width * height * channels].reshape(-1, channels)
    texels[:, :3] = image.reshape(-1, 3)


def apply_look(model: mujoco.MjModel, look: Look) -> None:
    """Fill the look's textures of a model built with :func:`look_assets`. The luminosity is
    a gain on rendered images (:func:`apply_luminosity`; the robot cameras' auto-exposure
    compensates most of it, :mod:`simulator.world.camera_model`): MuJoCo's lights saturate the
    textures' colours, so scaling them would change little."""
    _write_texture(model, TURF_TEXTURE, turf_image(look.turf))
    _write_texture(model, BALL_TEXTURE, ball_image(look.ball))
    _write_texture(model, SKY_TEXTURE, sky_image(look.background))
    _write_texture(model, NET_TEXTURE, net_image())


def apply_luminosity(rgb: textures.Image, luminosity: float) -> textures.Image:
    """A rendered image as the scene's luminosity lights it (the video's frames)."""
    if luminosity == 1.0:
        return rgb
    lit: textures.Image = np.clip(rgb * np.float32(luminosity), 0, 255).astype(np.uint8)
    return lit
