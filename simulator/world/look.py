"""The league's look: turf, lines, ball, goal nets, background and light, from ``texture_seed``.

As in the league's Webots world, ``texture_seed`` picks the variants (turf, ball, background)
and the luminosity (uniform in 0.75..1.25); the same seed gives the same images. The league's
referee (hlvs_webots ``controllers/referee/referee.py:1978-1994``) seeds Python's ``random``
with ``texture_seed`` and draws one of seven backgrounds, the luminosity and one of five ball
textures; it then adds the background (``protos/RoboCupBackground.proto``, its ``luminosity``
scales the background and its image-based light) and three directional lights chosen by the
background's name (``protos/lighting/RoboCupMainLight.proto:16-44``,
``RoboCupOffLight.proto:16-44``, ``RoboCupTopLight.proto:16-37``), each of strength
``luminosity * intensity`` and casting shadows.

Here the same elements, in MuJoCo:

- **Light** (:class:`LightSet`): the three lights of the league's background, with the
  league's directions, colours and intensities (a pink dawn, a weak sunset sun), times the
  luminosity, times :data:`LIGHT_GAIN` (MuJoCo's lights add Lambert terms where Webots renders
  physically based with tone mapping: the gain makes the league's brightest scenes bright, not
  clipped); the main and off lights, of one colour and nearly one direction, are drawn as one
  (:func:`lighting`). The image-based light is the background's mean colour times
  :data:`ENVIRONMENT_GAIN` times the luminosity, half of it from above (added to the top
  light: the sky lights what faces up, a ball's underside is in its own shade) and half from
  all around (MuJoCo's ambient light). The background's texels are scaled by
  the luminosity too. The main light casts shadows (robot cameras, :mod:`simulator.world.camera`:
  MuJoCo's shadow map on a GPU, with their own cheaper depth map, and planar shadows on a CPU
  renderer, :mod:`simulator.world.camera_scene`). Nothing compensates: a robot camera whose
  model declares auto-exposure (:mod:`simulator.world.camera_model`) evens out a share of it.
- **Backgrounds**: seven kinds of surroundings generated procedurally, one per league
  background's light set (:data:`BACKGROUNDS`), with bright skies, buildings, grass and earth
  below the horizon; the sun's glow sits where the main light comes from.
- **Ball**: five design families as the league's five balls (``protos/ball_textures``:
  telstar, teamgeist, europass, jabulani, tango), on a material of base colour 0.8 as the
  league's ball (``protos/RobocupTexturedSoccerBall.proto:29-36``) so that the lights shade it.
- **Lines**: white-painted turf (``protos/RobocupSoccerField.proto:283-286``, ``Grass`` of type
  ``artificial_white``), **turf** with hue and wear patches (``:259-261``, ``artificial``
  grass tinted 0.6 1 0.3), **nets** of dark cords with holes (``protos/RobocupGoal.proto:11``
  and ``:90-98``, net colour 0.3 on a net texture with holes): here cords of 1 cm every 10 cm,
  :mod:`simulator.world.goal`).

Each texture depends on its variant alone, so it is generated once per process (and once per
simulator image: :mod:`simulator.world.texture_cache`). The textures
are procedural (:mod:`simulator.world.textures`, numpy only, nothing downloaded or shipped):
the model declares them as placeholders of the right size (:func:`look_assets`) and
:func:`apply_look` writes the generated texels and the lights into the compiled model, before
any renderer uploads them. Robot cameras, the match video and the viewer (through the replay's
scene, :func:`Look.summary`) all draw the same look.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, TypedDict

import mujoco
import numpy as np

from simulator.world import texture_cache, textures
from simulator.world.textures import Surroundings


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
LINE_TEXTURE = "look:line"
LINE_MESH_MATERIAL = "look:line_mesh"  # the lines' mesh (simulator.world.merged): its own UVs
BALL_TEXTURE = "look:ball"
SKY_TEXTURE = "look:sky"
NET_TEXTURE = "look:net"
LIGHT_NAMES = ("look:key", "look:top")
TURF_PX = 512
LINE_PX = 128
LINE_TILE_M = 0.5
BALL_FACE_PX = 128
SKY_FACE_PX = 384
NET_RGBA = "0.3 0.3 0.3 1"  # the league's net colour (protos/RobocupGoal.proto:11)
NET_MESH_M = 0.1
NET_CORD_M = 0.01  # cord thickness
LUMINOSITY_RANGE = (0.75, 1.25)
LIGHT_GAIN = 0.1  # MuJoCo diffuse per unit of the league's light intensity
ENVIRONMENT_GAIN = 1.0  # environment light per unit of the background's mean texel (0..1)
SKY_SHARE = 0.5  # of the environment's light, the share that comes from above (the sky)
SHADOW_LIGHTS = (True, False)  # the key light (the main and off lights) casts shadows


@dataclass(frozen=True, slots=True)
class TurfVariant:
    base_rgb: RGB
    stripe_m: float  # width of one mowing stripe
    stripe_contrast: float
    wear: float  # share of worn patches
    hue_spread: float


@dataclass(frozen=True, slots=True)
class BallVariant:
    name: str  # the league's ball texture this family stands for
    family: str  # one of textures.BALL_FAMILIES
    panel_rgb: RGB
    mark_rgb: RGB
    accent_rgb: RGB


@dataclass(frozen=True, slots=True)
class Light:
    """A directional light as the league's lighting protos write it: ``direction`` in Webots'
    NUE frame (x north, y up, z east; the protos turn it to ENU as ``(z, x, y)``), colour and
    intensity."""

    direction_nue: tuple[float, float, float]
    rgb: RGB
    intensity: float

    def direction(self) -> tuple[float, float, float]:
        """The unit direction the light shines along, in the world frame (ENU, z up)."""
        x, y, z = self.direction_nue[2], self.direction_nue[0], self.direction_nue[1]
        n = math.sqrt(x * x + y * y + z * z)
        return (x / n, y / n, z / n)


@dataclass(frozen=True, slots=True)
class LightSet:
    """The main, off and top light of one background (the league's lighting protos)."""

    main: Light
    off: Light
    top: Light

    def lights(self) -> tuple[Light, Light, Light]:
        return (self.main, self.off, self.top)


@dataclass(frozen=True, slots=True)
class BackgroundVariant:
    league_name: str  # the league's background whose light set this one has
    surroundings: Surroundings
    light: LightSet


TURFS = (
    TurfVariant((0.20, 0.55, 0.18), 0.5, 0.10, 0.06, 0.10),
    TurfVariant((0.16, 0.50, 0.20), 0.75, 0.12, 0.10, 0.12),
    TurfVariant((0.24, 0.56, 0.16), 1.0, 0.08, 0.14, 0.14),
    TurfVariant((0.18, 0.47, 0.22), 0.5, 0.14, 0.08, 0.10),
)
_WHITE = (0.92, 0.92, 0.9)
BALLS = (
    BallVariant("telstar", "classic", _WHITE, (0.06, 0.06, 0.06), (0.06, 0.06, 0.06)),
    BallVariant("teamgeist", "three_lobed", _WHITE, (0.08, 0.08, 0.08), (0.75, 0.6, 0.2)),
    BallVariant("europass", "curved_panel", (0.9, 0.9, 0.9), (0.12, 0.12, 0.14), (0.4, 0.42, 0.46)),
    BallVariant("jabulani", "eight_panel", _WHITE, (0.1, 0.1, 0.1), (0.25, 0.4, 0.7)),
    BallVariant("tango", "triad", (0.93, 0.93, 0.92), (0.07, 0.07, 0.07), (0.3, 0.3, 0.3)),
)


def _sun(light: Light) -> tuple[float, float]:
    """Azimuth and elevation (degrees) the light comes from."""
    x, y, z = light.direction()
    return math.degrees(math.atan2(-y, -x)) % 360.0, math.degrees(math.asin(-z))


def _background(
    league_name: str, kind: str, lights: tuple[Light, Light, Light], *, horizon: RGB, top: RGB,
    sun_rgb: RGB, glow: float, clouds: float, cloud_rgb: RGB, skyline: RGB, grass: RGB,
    earth: RGB,
) -> BackgroundVariant:  # fmt: skip
    azimuth, elevation = _sun(lights[0])
    return BackgroundVariant(
        league_name,
        Surroundings(
            kind=kind, sky_horizon=horizon, sky_top=top, sun_azimuth_deg=azimuth,
            sun_elevation_deg=elevation, sun_rgb=sun_rgb, sun_glow=glow, clouds=clouds,
            cloud_rgb=cloud_rgb, skyline_rgb=skyline, ground_rgb=grass, earth_rgb=earth,
        ),  # fmt: skip
        LightSet(*lights),
    )


_BLUE_WHITE = (0.95, 0.95, 1.0)
_W = (1.0, 1.0, 1.0)
_DAWN = (1.0, 0.6, 0.8)
_PALE_BLUE = (0.9, 0.9, 1.0)
# the league's light sets, RoboCupMainLight/OffLight/TopLight.proto, in the referee's order
_LIGHTS = {
    "stadium_dry": (
        Light((2.1, -1.5, -2.1), _BLUE_WHITE, 2.0), Light((2.0, -1.6, -2.1), _BLUE_WHITE, 1.0),
        Light((0.0, -1.0, 0.0), _BLUE_WHITE, 1.0),
    ),
    "shanghai_riverside": (
        Light((-2.4, -1.2, 2.3), _W, 2.0), Light((-2.375, -1.2, 2.325), _W, 1.75),
        Light((0.0, -1.0, 0.0), _W, 1.5),
    ),
    "ulmer_muenster": (
        Light((-1.35, -1.4, 2.0), _BLUE_WHITE, 2.5), Light((-1.3, -1.4, 2.0), _BLUE_WHITE, 1.5),
        Light((0.0, -1.0, 0.0), _BLUE_WHITE, 0.5),
    ),
    "sunset_jhbcentral": (
        Light((-1.0, -4.0, 0.1), _W, 0.5), Light((-1.05, -4.0, 0.1), _W, 0.25),
        Light((0.0, -1.0, 0.0), _W, 1.5),
    ),
    "sepulchral_chapel_rotunda": (
        Light((0.3, -0.25, 0.025), _BLUE_WHITE, 1.5), Light((0.3, -0.25, 0.025), _PALE_BLUE, 0.75),
        Light((0.0, -1.0, 0.0), _BLUE_WHITE, 1.75),
    ),
    "paul_lobe_haus": (
        Light((0.2, -0.5, 0.025), _PALE_BLUE, 1.0), Light((0.2, -1.0, -0.2), _PALE_BLUE, 0.75),
        Light((0.0, -1.0, 0.0), _PALE_BLUE, 1.5),
    ),
    "kiara_1_dawn": (
        Light((-2.8, -1.0, 2.1), _DAWN, 2.0), Light((-2.775, -1.025, 2.1), _DAWN, 2.0),
        Light((0.0, -1.0, 0.0), _DAWN, 1.0),
    ),
}  # fmt: skip
BACKGROUNDS = (
    _background(
        "stadium_dry", "stadium", _LIGHTS["stadium_dry"], horizon=(0.86, 0.88, 0.9),
        top=(0.45, 0.62, 0.86), sun_rgb=(1.0, 0.98, 0.9), glow=0.5, clouds=0.25,
        cloud_rgb=(0.95, 0.95, 0.96), skyline=(0.42, 0.42, 0.45), grass=(0.3, 0.42, 0.2),
        earth=(0.45, 0.36, 0.25),
    ),
    _background(
        "shanghai_riverside", "riverside", _LIGHTS["shanghai_riverside"],
        horizon=(0.92, 0.92, 0.9), top=(0.6, 0.7, 0.84), sun_rgb=(1.0, 1.0, 0.95), glow=0.6,
        clouds=0.45, cloud_rgb=(0.96, 0.96, 0.96), skyline=(0.5, 0.53, 0.58),
        grass=(0.32, 0.44, 0.22), earth=(0.5, 0.44, 0.34),
    ),
    _background(
        "ulmer_muenster", "old_town", _LIGHTS["ulmer_muenster"], horizon=(0.9, 0.9, 0.92),
        top=(0.74, 0.78, 0.84), sun_rgb=(1.0, 1.0, 1.0), glow=0.3, clouds=0.75,
        cloud_rgb=(0.9, 0.9, 0.92), skyline=(0.72, 0.68, 0.6), grass=(0.3, 0.4, 0.2),
        earth=(0.42, 0.38, 0.32),
    ),
    _background(
        "sunset_jhbcentral", "sunset_city", _LIGHTS["sunset_jhbcentral"],
        horizon=(0.82, 0.46, 0.22), top=(0.1, 0.13, 0.28), sun_rgb=(1.0, 0.75, 0.4), glow=0.9,
        clouds=0.3, cloud_rgb=(0.5, 0.28, 0.28), skyline=(0.1, 0.08, 0.1),
        grass=(0.12, 0.14, 0.07), earth=(0.22, 0.16, 0.11),
    ),
    _background(
        "sepulchral_chapel_rotunda", "chapel_hall", _LIGHTS["sepulchral_chapel_rotunda"],
        horizon=(0.78, 0.78, 0.76), top=(0.78, 0.78, 0.76), sun_rgb=(1.0, 1.0, 1.0), glow=0.0,
        clouds=0.0, cloud_rgb=(1.0, 1.0, 1.0), skyline=(0.19, 0.18, 0.17),
        grass=(0.2, 0.18, 0.16), earth=(0.24, 0.22, 0.2),
    ),
    _background(
        "paul_lobe_haus", "government", _LIGHTS["paul_lobe_haus"], horizon=(0.88, 0.9, 0.94),
        top=(0.4, 0.56, 0.85), sun_rgb=(1.0, 1.0, 0.95), glow=0.5, clouds=0.35,
        cloud_rgb=(0.96, 0.96, 0.97), skyline=(0.82, 0.8, 0.74), grass=(0.28, 0.48, 0.18),
        earth=(0.45, 0.38, 0.28),
    ),
    _background(
        "kiara_1_dawn", "dawn_meadow", _LIGHTS["kiara_1_dawn"], horizon=(0.97, 0.72, 0.7),
        top=(0.45, 0.5, 0.72), sun_rgb=(1.0, 0.7, 0.6), glow=0.8, clouds=0.4,
        cloud_rgb=(0.92, 0.66, 0.72), skyline=(0.14, 0.2, 0.12), grass=(0.3, 0.38, 0.2),
        earth=(0.4, 0.32, 0.24),
    ),
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
        the background's sky (overhead, at the horizon) and skyline colours."""
        turf = turf_image(self.turf)
        half = turf.shape[1] // 2
        light = turf[:, :half].reshape(-1, 3).mean(axis=0) / 255.0
        dark = turf[:, half:].reshape(-1, 3).mean(axis=0) / 255.0
        ball = BALLS[self.ball]
        bg = BACKGROUNDS[self.background].surroundings
        return {
            "texture_seed": self.texture_seed,
            "turf": self.turf,
            "ball": self.ball,
            "background": self.background,
            "luminosity": round(self.luminosity, 4),
            "turf_colors": [_rounded(light), _rounded(dark)],
            "stripe_m": TURFS[self.turf].stripe_m,
            "ball_colors": [list(ball.panel_rgb), list(ball.mark_rgb)],
            "sky_colors": [list(bg.sky_top), list(bg.sky_horizon), list(bg.skyline_rgb)],
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
    return texture_cache.cached("turf", variant, lambda: textures.turf_tile(
        seed=0x7F4F + variant, size_px=TURF_PX, base_rgb=v.base_rgb,
        stripe_contrast=v.stripe_contrast, wear=v.wear, hue_spread=v.hue_spread,
    ))  # fmt: skip


@lru_cache(maxsize=1)
def line_image() -> textures.Image:
    return textures.line_tile(seed=0x11E5, size_px=LINE_PX)


@lru_cache(maxsize=len(BALLS))
def ball_image(variant: int) -> textures.Image:
    v = BALLS[variant]
    return texture_cache.cached("ball", variant, lambda: textures.ball_cube(
        face_px=BALL_FACE_PX, family=v.family, panel_rgb=v.panel_rgb, mark_rgb=v.mark_rgb,
        accent_rgb=v.accent_rgb, turn_rad=0.3 * variant,
    ))  # fmt: skip


@lru_cache(maxsize=len(BACKGROUNDS))
def sky_image(variant: int) -> textures.Image:
    return texture_cache.cached("sky", variant, lambda: textures.background_cube(
        seed=0x5747 + variant, face_px=SKY_FACE_PX, look=BACKGROUNDS[variant].surroundings
    ))  # fmt: skip


def fill_texture_cache() -> list[Path]:
    """Make every variant's textures into the texture cache's folder (the simulator image's
    build, :mod:`simulator.world.texture_cache`); returns the files, which exist afterwards.

    Raises:
        RuntimeError: the folder is not set, or did not take every file.
    """
    where = texture_cache.folder()
    if where is None:
        raise RuntimeError(f"{texture_cache.CACHE_ENV} is not set: no folder to fill")
    for variant in range(len(TURFS)):
        turf_image(variant)
    for variant in range(len(BALLS)):
        ball_image(variant)
    for variant in range(len(BACKGROUNDS)):
        sky_image(variant)
        environment_rgb(variant)
    files = sorted(where.glob(f"*-{texture_cache.code_key()}.npy"))
    expected = len(TURFS) + len(BALLS) + 2 * len(BACKGROUNDS)
    if len(files) != expected:
        raise RuntimeError(f"{where}: {len(files)} texture files written, expected {expected}")
    return files


def look_assets(look: Look) -> str:
    """MJCF assets: placeholder textures of the look's sizes (filled by :func:`apply_look`)
    and the materials that use them (``look:turf``, ``look:line``, ``look:ball``; ``look:net``
    for replays of earlier versions, whose nets were boxes with a texture)."""
    stripe = TURFS[look.turf].stripe_m
    # one tile spans two stripes; with texuniform MuJoCo's renderer lays a plane's tile over
    # 2 / texrepeat metres (measured on rendered frames, as camera_scene's _TurfColours reads it)
    repeat = 1.0 / stripe
    line_repeat = 1.0 / LINE_TILE_M
    return (
        f'<texture name="{SKY_TEXTURE}" type="skybox" builtin="flat" rgb1="0.4 0.5 0.6" '
        f'width="{SKY_FACE_PX}" height="{SKY_FACE_PX}"/>'
        f'<texture name="{TURF_TEXTURE}" type="2d" builtin="flat" rgb1="0.2 0.5 0.2" '
        f'width="{TURF_PX}" height="{TURF_PX}"/>'
        f'<material name="{TURF_TEXTURE}" texture="{TURF_TEXTURE}" texuniform="true" '
        f'texrepeat="{repeat:.6g} {repeat:.6g}" reflectance="0" specular="0.05"/>'
        f'<texture name="{LINE_TEXTURE}" type="2d" builtin="flat" rgb1="0.8 0.8 0.8" '
        f'width="{LINE_PX}" height="{LINE_PX}"/>'
        f'<material name="{LINE_TEXTURE}" texture="{LINE_TEXTURE}" texuniform="true" '
        f'texrepeat="{line_repeat:.6g} {line_repeat:.6g}" reflectance="0" specular="0.05"/>'
        f'<material name="{LINE_MESH_MATERIAL}" texture="{LINE_TEXTURE}" texrepeat="1 1" '
        f'reflectance="0" specular="0.05"/>'
        f'<texture name="{BALL_TEXTURE}" type="cube" builtin="flat" rgb1="1 1 1" '
        f'width="{BALL_FACE_PX}" height="{BALL_FACE_PX}"/>'
        f'<material name="{BALL_TEXTURE}" texture="{BALL_TEXTURE}" rgba="0.8 0.8 0.8 1" '
        f'specular="0.25" shininess="0.3"/>'
        f'<material name="{NET_TEXTURE}" rgba="0.3 0.3 0.3 0.5" specular="0"/>'
    )


def light_xml() -> str:
    """The look's three directional lights (placeholders: :func:`apply_look` sets them)."""
    return "".join(
        f'<light name="{name}" directional="true" pos="0 0 10" dir="0 0 -1" '
        f'diffuse="0.3 0.3 0.3" specular="0 0 0" castshadow="{str(shadow).lower()}"/>'
        for name, shadow in zip(LIGHT_NAMES, SHADOW_LIGHTS, strict=True)
    )


def _write_texture(
    model: mujoco.MjModel, name: str, image: textures.Image, gain: float = 1.0
) -> None:
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
    rgb = image.reshape(-1, image.shape[-1])[:, :3]
    if gain != 1.0:
        rgb = np.clip(rgb * np.float32(gain), 0, 255).astype(np.uint8)
    texels[:, :3] = rgb


@dataclass(frozen=True, slots=True)
class Lighting:
    """The lights of a look as MuJoCo takes them: per light its direction (world frame), its
    diffuse and specular colour; the ambient colour (the environment's light)."""

    directions: tuple[tuple[float, float, float], ...]
    diffuse: tuple[RGB, ...]
    specular: tuple[RGB, ...]
    ambient: RGB


@lru_cache(maxsize=len(BACKGROUNDS))
def environment_rgb(variant: int) -> RGB:
    """The background's mean colour above 5 degrees below the horizon (what lights the
    pitch; the ground under the pitch is hidden by it)."""

    def mean() -> np.ndarray:
        texels = sky_image(variant).reshape(-1, 3)
        around = textures.cube_elevations(SKY_FACE_PX).reshape(-1) > -5.0
        return np.asarray(texels[around].mean(axis=0) / 255.0, dtype=np.float64)

    rgb = texture_cache.cached("environment", variant, mean)
    return (float(rgb[0]), float(rgb[1]), float(rgb[2]))


def _merged(first: Light, second: Light) -> Light:
    """One light for two: along ``I1 d1 + I2 d2``, of that vector's length, of their colours
    weighted by intensity. Lambert's term of every surface that both light is the same
    (``n . (I1 d1 + I2 d2)``, exactly so for one colour)."""
    a, b = np.array(first.direction()), np.array(second.direction())
    total = first.intensity * a + second.intensity * b
    strength = float(np.linalg.norm(total))
    x, y, z = (float(v) for v in total / strength)
    w1, w2 = first.intensity, second.intensity
    r, g, bl = (
        (w1 * c1 + w2 * c2) / (w1 + w2) for c1, c2 in zip(first.rgb, second.rgb, strict=True)
    )
    return Light((y, z, x), (r, g, bl), strength)


def lighting(look: Look) -> Lighting:
    """The lights of ``look``: the league's light set of its background, scaled by its
    luminosity (see the module's docstring). The main and off lights of every league set have
    about one colour and directions within 2.5 degrees (17 for ``paul_lobe_haus``): they are
    one light here, the
    key light (:func:`_merged`; one shadow pass instead of two), the top light the other."""
    bg = BACKGROUNDS[look.background]
    lum = look.luminosity
    lights = (_merged(bg.light.main, bg.light.off), bg.light.top)
    diffuse = tuple(
        (lum * LIGHT_GAIN * lt.intensity * lt.rgb[0], lum * LIGHT_GAIN * lt.intensity * lt.rgb[1],
         lum * LIGHT_GAIN * lt.intensity * lt.rgb[2])
        for lt in lights
    )  # fmt: skip
    key = diffuse[0]
    specular = ((0.3 * key[0], 0.3 * key[1], 0.3 * key[2]), (0.0, 0.0, 0.0))  # a glint of the sun
    env = [lum * ENVIRONMENT_GAIN * c for c in environment_rgb(look.background)]
    ambient = (
        (1 - SKY_SHARE) * env[0], (1 - SKY_SHARE) * env[1], (1 - SKY_SHARE) * env[2]
    )  # fmt: skip
    top = diffuse[1]
    sky = (top[0] + SKY_SHARE * env[0], top[1] + SKY_SHARE * env[1], top[2] + SKY_SHARE * env[2])
    return Lighting(
        tuple(lt.direction() for lt in lights), (diffuse[0], sky), specular, ambient
    )


def apply_look(model: mujoco.MjModel, look: Look) -> None:
    """Fill the look's textures of a model built with :func:`look_assets` (any look's: this
    one's stripes are set too) and set its lights
    (the lights named :data:`LIGHT_NAMES`, when the model has them, and the ambient light).
    The luminosity scales the lights, the ambient light and the background's texels; light
    directions take effect at the next ``mj_forward``."""
    _write_texture(model, TURF_TEXTURE, turf_image(look.turf))
    repeat = 1.0 / TURFS[look.turf].stripe_m  # a tile of two stripes over 2 / repeat metres
    model.mat_texrepeat[model.material(TURF_TEXTURE).id] = (repeat, repeat)
    _write_texture(model, LINE_TEXTURE, line_image())
    _write_texture(model, BALL_TEXTURE, ball_image(look.ball))
    _write_texture(model, SKY_TEXTURE, sky_image(look.background), gain=look.luminosity)
    lit = lighting(look)
    names = {model.light(i).name: i for i in range(model.nlight)}
    for k, name in enumerate(LIGHT_NAMES):
        i = names.get(name)
        if i is None:
            continue
        direction = np.array(lit.directions[k])
        model.light_dir[i] = direction
        model.light_pos[i] = -8.0 * direction
        model.light_diffuse[i] = lit.diffuse[k]
        model.light_specular[i] = lit.specular[k]
        model.light_ambient[i] = 0.0
    model.vis.headlight.ambient[:] = lit.ambient
    model.vis.headlight.diffuse[:] = 0.0
    model.vis.headlight.specular[:] = 0.0
