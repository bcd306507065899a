"""Procedural textures of the league's look, generated with numpy from a seed (no image files).

Every function is a pure function of its arguments: the same seed and variant give the same
bytes on every machine (numpy's PCG64 stream and float64 arithmetic only). Images are ``uint8``
RGB arrays, rows from the texture's first row; cube textures are six square
faces stacked vertically in MuJoCo's order (see :func:`_cube_directions`). Texels are albedos:
the scene's lights (:mod:`simulator.world.look`) make them brighter or darker.

- **Turf**: one tile of artificial grass (blade speckle at a few millimetres, tufts, slow
  colour variation, worn patches where the green turns yellow-brown and lighter) with a light
  and a dark mowing stripe side by side; it repeats seamlessly (the noise is periodic: filtered
  in the Fourier domain).
- **Lines**: white-painted turf: the same blades, greyish white with a green cast, never a flat
  white (the league paints its lines as a white artificial-grass material).
- **Ball**: five families of designs drawn on the sphere by direction (no texture seams at the
  cube edges): classic panels (12 pentagons, 20 hexagons), three-lobed marks, eight curved
  panels with coloured triangles, curved panels with crescents, and triads forming twelve rings.
- **Jersey**: a robot's shirt in its team colour, cloth with a faint weave, its player number
  in large white digits (as the league's jersey textures, e.g. ``protos/robots/RoboCupRobot``'s
  ``RobotisJersey.proto``: a team-coloured shirt with the number on it).
- **Background**: a scene around the pitch at infinity, one of seven kinds (open stadium,
  riverside towers, old town with a cathedral spire, city at sunset, domed chapel hall, modern
  government building with a lawn, meadow at dawn): a sky with a sun glow and clouds, the
  skyline, and below the horizon the ground in perspective (grass, earth, paving, water).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

Image = npt.NDArray[np.uint8]
Floats = npt.NDArray[np.float64]
RGB = tuple[float, float, float]


def _periodic_noise(rng: np.random.Generator, size: int, scale_px: float) -> Floats:
    """Gaussian noise smoothed over about ``scale_px`` that tiles seamlessly, unit std."""
    white = rng.standard_normal((size, size))
    f = np.fft.fftfreq(size)
    fy, fx = np.meshgrid(f, f, indexing="ij")
    kernel = np.exp(-2.0 * (math.pi * scale_px) ** 2 * (fx**2 + fy**2))
    smooth = np.real(np.fft.ifft2(np.fft.fft2(white) * kernel))
    std = float(smooth.std())
    return smooth / std if std > 0 else smooth


def _to_image(rgb: Floats) -> Image:
    return np.clip(np.rint(rgb * 255.0), 0, 255).astype(np.uint8)


def _blades(rng: np.random.Generator, size_px: int) -> tuple[Floats, Floats]:
    """(shade, patches): the grass's brightness around 1 (blades, tufts, slow patches, streaked
    along the rows as blades lean one way) and the slow patch noise (unit std)."""
    blades = _periodic_noise(rng, size_px, 0.6)
    tufts = _periodic_noise(rng, size_px, 3.0)
    patches = _periodic_noise(rng, size_px, size_px / 12.0)
    shade = 1.0 + 0.10 * blades + 0.07 * tufts + 0.05 * patches
    shade = 0.6 * shade + 0.2 * np.roll(shade, 1, axis=0) + 0.2 * np.roll(shade, -1, axis=0)
    return shade, patches


def turf_tile(
    *,
    seed: int,
    size_px: int,
    base_rgb: RGB,
    stripe_contrast: float,
    wear: float = 0.0,
    hue_spread: float = 0.06,
) -> Image:
    """A ``size_px`` square of turf: the left half the light mowing stripe, the right half the
    dark one (the tile spans two stripes; the caller sets how many metres it covers).
    ``hue_spread`` shifts patches yellower or bluer; ``wear`` (0..1) is the share of worn
    patches, yellow-brown and lighter."""
    rng = np.random.default_rng(seed)
    shade, patches = _blades(rng, size_px)
    worn_noise = _periodic_noise(rng, size_px, size_px / 20.0)
    shade = np.clip(shade, 0.75, 1.3)  # no blade as dark as the ball's patches
    stripe = np.where(np.arange(size_px) < size_px // 2, 1.0 + stripe_contrast, 1.0)
    stripe = stripe - stripe_contrast / 2
    shade = shade * stripe[np.newaxis, :]
    hue = hue_spread * patches  # yellower and bluer patches
    rgb = np.stack(
        [
            base_rgb[0] * shade * (1.0 + hue),
            base_rgb[1] * shade,
            base_rgb[2] * shade * (1.0 - hue),
        ],
        axis=-1,
    )
    if wear > 0:
        # worn: the blades flattened, the backing and infill showing (yellow-brown, lighter)
        limit = float(np.quantile(worn_noise, 1.0 - wear))
        amount = np.clip((worn_noise - limit) / 0.6, 0.0, 1.0)[..., None] * 0.55
        worn = np.array([0.52, 0.5, 0.3]) * shade[..., None]
        rgb = rgb * (1.0 - amount) + worn * amount
    return _to_image(rgb)


def line_tile(*, seed: int, size_px: int) -> Image:
    """A ``size_px`` square of white-painted turf: blade texture, a green cast, albedo about
    0.63 (the brightest light makes it bright, not clipped)."""
    rng = np.random.default_rng(seed)
    shade, patches = _blades(rng, size_px)
    shade = np.clip(shade, 0.8, 1.15)
    base = np.array([0.62, 0.65, 0.6])
    rgb = base * shade[..., None] * (1.0 + 0.02 * patches[..., None])
    return _to_image(rgb)


# Digits as 5 x 7 cells (rows top to bottom), the bold block figures of a shirt number
_DIGITS = {
    "0": ("01110", "11011", "11011", "11011", "11011", "11011", "01110"),
    "1": ("00110", "01110", "11110", "00110", "00110", "00110", "11111"),
    "2": ("01110", "11011", "00011", "00110", "01100", "11000", "11111"),
    "3": ("11110", "00011", "00011", "01110", "00011", "00011", "11110"),
    "4": ("00110", "01110", "11010", "11011", "11111", "00011", "00011"),
    "5": ("11111", "11000", "11110", "00011", "00011", "11011", "01110"),
    "6": ("01110", "11000", "11000", "11110", "11011", "11011", "01110"),
    "7": ("11111", "00011", "00110", "00110", "01100", "01100", "01100"),
    "8": ("01110", "11011", "11011", "01110", "11011", "11011", "01110"),
    "9": ("01110", "11011", "11011", "01111", "00011", "00011", "01110"),
}


def number_mask(number: int, size_px: int) -> npt.NDArray[np.bool_]:
    """A ``size_px`` square with ``number``'s digits set, centred, 0.7 of its height (narrower
    for two digits or more, to fit 0.9 of its width); the digits' cells drawn as blocks, one
    cell apart."""
    text = str(number)
    cell = max(1, min(int(size_px * 0.7) // 7, int(size_px * 0.9) // (len(text) * 6 - 1)))
    width = (len(text) * 6 - 1) * cell
    if width > size_px:
        raise ValueError(f"number {number} does not fit a {size_px} px jersey")
    mask = np.zeros((size_px, size_px), np.bool_)
    top, left = (size_px - 7 * cell) // 2, (size_px - width) // 2
    for k, digit in enumerate(text):
        for row, bits in enumerate(_DIGITS[digit]):
            for col, bit in enumerate(bits):
                if bit == "1":
                    y, x = top + row * cell, left + (k * 6 + col) * cell
                    mask[y : y + cell, x : x + cell] = True
    return mask


def jersey_tile(*, number: int, team_rgb: RGB, size_px: int) -> Image:
    """A ``size_px`` square of a team's shirt (albedo ``team_rgb`` with a faint weave) with
    ``number`` in white (albedo 0.85) in the middle, upright in the image's rows."""
    rng = np.random.default_rng(0x7E55 + number)
    weave = 1.0 + 0.04 * _periodic_noise(rng, size_px, 0.7)
    rgb = np.array(team_rgb) * weave[..., None]
    rgb[number_mask(number, size_px)] = 0.85
    return _to_image(rgb)


def _cube_directions(face_px: int, *, skybox: bool) -> Floats:
    """(6, n, n, 3) unit directions (world frame, z up) of the texel centres of a MuJoCo cube
    texture's six faces: on a body (``skybox`` False, the direction from the body's centre) or
    as the skybox (the direction of view). ``s`` runs along a face's columns, ``t`` down its
    rows; the face order and signs were measured by rendering a coded texture."""
    c = (np.arange(face_px) + 0.5) / face_px * 2.0 - 1.0
    t, s = np.meshgrid(c, c, indexing="ij")  # t: row, s: column
    one = np.ones_like(s)
    if skybox:
        faces = [
            (one, s, -t), (-one, -s, -t), (s, -t, one), (s, t, -one), (s, -one, -t), (-s, one, -t),
        ]
    else:
        faces = [
            (one, -t, -s), (-one, -t, s), (s, one, t), (s, -one, -t), (s, -t, one), (-s, -t, -one),
        ]
    dirs: Floats = np.stack([np.stack(f, axis=-1) for f in faces])
    unit: Floats = dirs / np.linalg.norm(dirs, axis=-1, keepdims=True)
    return unit


def cube_elevations(face_px: int) -> Floats:
    """(6, n, n) elevation in degrees of each texel of a skybox cube texture."""
    z = np.clip(_cube_directions(face_px, skybox=True)[..., 2], -1.0, 1.0)
    out: Floats = np.degrees(np.arcsin(z))
    return out


def _icosahedron() -> tuple[Floats, Floats]:
    """(12, 3) vertices and (20, 3) face centres of the icosahedron, unit length."""
    phi = (1.0 + math.sqrt(5.0)) / 2.0
    verts = []
    for a in (-1.0, 1.0):
        for b in (-phi, phi):
            verts += [(0.0, a, b), (a, b, 0.0), (b, 0.0, a)]
    v = np.array(verts)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    dots = v @ v.T
    near = dots > 0.4  # the five neighbours of each vertex (cos 63.4 deg = 0.447)
    faces = set()
    for i in range(12):
        for j in range(12):
            for k in range(12):
                if i < j < k and near[i, j] and near[j, k] and near[i, k]:
                    faces.add((i, j, k))
    centres = np.array([v[list(f)].sum(axis=0) for f in sorted(faces)])
    centres /= np.linalg.norm(centres, axis=1, keepdims=True)
    return v, centres


def _octahedral() -> tuple[Floats, Floats]:
    """(6, 3) face directions and (8, 3) corner directions of the cube, unit length."""
    faces = np.concatenate([np.eye(3), -np.eye(3)])
    corners = np.array(
        [(x, y, z) for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)]
    ) / math.sqrt(3.0)
    return faces, corners


def _polar_about(dirs: Floats, centres: Floats) -> tuple[Floats, Floats, Floats]:
    """For each direction: the index of the nearest centre, the angle to it (rad) and the
    angle around it (rad, from an arbitrary but fixed tangent)."""
    dots = dirs @ centres.T
    best = np.argmax(dots, axis=1)
    c = centres[best]
    rho = np.arccos(np.clip(dots[np.arange(len(dirs)), best], -1.0, 1.0))
    helper = np.where(np.abs(c[:, 2:3]) < 0.9, np.array([[0.0, 0.0, 1.0]]), np.array([[1.0, 0, 0]]))
    e1 = np.cross(helper, c)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(c, e1)
    theta = np.arctan2(np.sum(dirs * e2, axis=1), np.sum(dirs * e1, axis=1))
    return best, rho, theta


def _seam(score: Floats, width: float) -> npt.NDArray[np.bool_]:
    """Texels where the best and second-best of ``score`` are within ``width``."""
    top2 = np.partition(score, -2, axis=1)[:, -2:]
    seam: npt.NDArray[np.bool_] = (top2[:, 1] - top2[:, 0]) < width
    return seam


BALL_FAMILIES = ("classic", "three_lobed", "eight_panel", "curved_panel", "triad")


def ball_cube(
    *,
    face_px: int,
    family: str,
    panel_rgb: RGB,
    mark_rgb: RGB,
    accent_rgb: RGB,
    turn_rad: float,
) -> Image:
    """The ball's cube texture, one of :data:`BALL_FAMILIES`: ``panel_rgb`` panels (off-white,
    the lights shade them) with seams, ``mark_rgb`` the design's dark marks and ``accent_rgb``
    its coloured ones; ``turn_rad`` turns the design about the vertical axis."""
    dirs = _cube_directions(face_px, skybox=False).reshape(-1, 3)
    c, s = math.cos(turn_rad), math.sin(turn_rad)
    dirs = dirs @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    panel, mark, accent = np.array(panel_rgb), np.array(mark_rgb), np.array(accent_rgb)
    rgb = np.broadcast_to(panel, dirs.shape).copy()
    seam_rgb = panel * 0.55
    if family == "classic":
        # 12 dark pentagons, 20 white hexagons (truncated icosahedron)
        pent, hexa = _icosahedron()
        score = dirs @ np.concatenate([pent, hexa]).T + np.r_[np.full(12, 0.02), np.zeros(20)]
        rgb[np.argmax(score, axis=1) < 12] = mark
        rgb[_seam(score, 0.012)] = seam_rgb
    elif family == "three_lobed":
        # 14 panels (6 round the cube's faces, 8 round its corners); each corner panel carries a
        # three-lobed mark with a coloured rim
        faces, corners = _octahedral()
        score = dirs @ np.concatenate([faces, corners]).T + np.r_[np.full(6, 0.05), np.zeros(8)]
        _, rho, theta = _polar_about(dirs, corners)
        lobe = 0.42 * (0.5 + 0.5 * np.cos(3.0 * theta)) ** 1.5 + 0.06
        rgb[rho < lobe + 0.05] = accent
        rgb[rho < lobe] = mark
        rgb[_seam(score, 0.01)] = seam_rgb
    elif family == "eight_panel":
        # eight panels split by three wavy great circles; coloured triangles round four corners
        wavy = dirs + 0.12 * np.sin(3.0 * np.roll(dirs, 1, axis=1))
        seam = np.any(np.abs(wavy) < 0.018, axis=1)
        _, corners = _octahedral()
        tetra = corners[[0, 3, 5, 6]]
        _, rho, theta = _polar_about(dirs, tetra)
        tri = rho < 0.3 * (1.0 + 0.35 * np.cos(3.0 * theta))
        ring = tri & (rho > 0.3 * (1.0 + 0.35 * np.cos(3.0 * theta)) - 0.07)
        rgb[tri] = accent
        rgb[ring] = mark
        rgb[seam] = seam_rgb
    elif family == "curved_panel":
        # curved panels (two interlocking halves as on a tennis ball) with dark crescents along
        # the seam
        phi = np.arctan2(dirs[:, 1], dirs[:, 0])
        curve = dirs[:, 2] - 0.75 * np.cos(2.0 * phi) * np.sqrt(1.0 - dirs[:, 2] ** 2)
        band = (np.abs(curve) > 0.12) & (np.abs(curve) < 0.34) & (np.cos(4.0 * phi + 1.0) > 0.2)
        rgb[band] = mark
        rgb[band & (np.abs(curve) > 0.28)] = accent
        rgb[np.abs(curve) < 0.02] = seam_rgb
    elif family == "triad":
        # twenty triads (three curved arms round each face centre of the icosahedron) whose
        # arms join into twelve dark rings round the vertices
        verts, centres = _icosahedron()
        _, rho, _ = _polar_about(dirs, verts)
        ring = (rho > 0.30) & (rho < 0.44)
        rgb[ring] = mark
        rgb[(rho > 0.26) & (rho <= 0.30)] = accent
        rgb[_seam(dirs @ centres.T, 0.012)] = seam_rgb
    else:
        raise ValueError(f"unknown ball family {family!r}, expected one of {BALL_FAMILIES}")
    return _to_image(rgb.reshape(6 * face_px, face_px, 3))


@dataclass(frozen=True, slots=True)
class Surroundings:
    """What a background shows: ``kind`` (see :func:`background_cube`), the sky's colours at
    the horizon and overhead, the sun (azimuth and elevation in degrees, z up; its glow's
    colour and strength), the share of cloud cover and the colours of the skyline and ground."""

    kind: str
    sky_horizon: RGB
    sky_top: RGB
    sun_azimuth_deg: float
    sun_elevation_deg: float
    sun_rgb: RGB
    sun_glow: float
    clouds: float
    cloud_rgb: RGB
    skyline_rgb: RGB
    ground_rgb: RGB
    earth_rgb: RGB


BACKGROUND_KINDS = (
    "stadium", "riverside", "old_town", "sunset_city", "chapel_hall", "government", "dawn_meadow",
)  # fmt: skip


def _smooth(x: Floats) -> Floats:
    y: Floats = np.clip(x, 0.0, 1.0)
    return y * y * (3.0 - 2.0 * y)


class _Sampler:
    """Periodic noise fields looked up by (column, row) coordinates that wrap."""

    def __init__(self, rng: np.random.Generator, size: int = 256) -> None:
        self.size = size
        self.fine = _periodic_noise(rng, size, 1.5)
        self.mid = _periodic_noise(rng, size, 6.0)
        self.coarse = _periodic_noise(rng, size, 24.0)

    def at(self, field: Floats, u: Floats, v: Floats) -> Floats:
        i = np.floor(v).astype(np.int64) % self.size
        j = np.floor(u).astype(np.int64) % self.size
        out: Floats = field[i, j]
        return out


def _skyline(kind: str, rng: np.random.Generator, az: Floats) -> tuple[Floats, Floats, Floats]:
    """(height in degrees above the horizon, building number, window-lit share) per azimuth."""
    cols = 720  # half-degree columns
    height = np.zeros(cols)
    ident = np.zeros(cols)
    lit = np.zeros(cols)
    pos, number = 0, 0
    while pos < cols:
        if kind == "riverside":
            width = int(rng.integers(6, 26))
            h = rng.uniform(3.0, 9.0) if rng.uniform() < 0.6 else rng.uniform(9.0, 24.0)
        elif kind == "old_town":
            width = int(rng.integers(10, 30))
            h = rng.uniform(3.0, 6.5)
        elif kind == "sunset_city":
            width = int(rng.integers(4, 20))
            h = rng.uniform(2.0, 14.0)
        elif kind == "government":
            width = int(rng.integers(20, 60))
            h = rng.uniform(1.5, 4.0)
        else:  # trees: narrow and irregular
            width = int(rng.integers(2, 7))
            h = rng.uniform(1.0, 4.5)
        height[pos : pos + width] = h
        ident[pos : pos + width] = number
        lit[pos : pos + width] = rng.uniform()
        pos += width
        number += 1
    if kind == "old_town":  # the cathedral: a nave and a spire
        height[130:190] = 11.0
        spire = np.arange(148, 166)
        height[spire] = 11.0 + 30.0 * (1.0 - np.abs(spire - 156.5) / 9.0) ** 1.5
    if kind == "government":  # the main building: a long block with a glass dome
        height[300:440] = 7.0
        dome = np.arange(345, 395)
        height[dome] = 7.0 + 6.0 * np.sqrt(np.clip(1.0 - ((dome - 369.5) / 25.0) ** 2, 0, 1))
    col = (az * 2.0).astype(np.int64) % cols
    return height[col], ident[col], lit[col]


def background_cube(*, seed: int, face_px: int, look: Surroundings) -> Image:
    """The background cube texture (z up) of ``look``: the sky, the skyline of its kind and the
    ground below the horizon, seen from the pitch. Every texel is at most 0.97 (a bright sky
    nearly white; the lights scale the whole background with the scene's luminosity)."""
    rng = np.random.default_rng(seed)
    noise = _Sampler(rng)
    dirs = _cube_directions(face_px, skybox=True)
    z = np.clip(dirs[..., 2], -1.0, 1.0)
    el = np.degrees(np.arcsin(z))
    az = np.degrees(np.arctan2(dirs[..., 1], dirs[..., 0])) % 360.0
    horizon, top = np.array(look.sky_horizon), np.array(look.sky_top)
    out = horizon + (top - horizon) * _smooth(el / 70.0)[..., None]
    # the sun's glow: wide and faint, narrow and bright
    sun_az, sun_el = math.radians(look.sun_azimuth_deg), math.radians(look.sun_elevation_deg)
    sun = np.array(
        [math.cos(sun_el) * math.cos(sun_az), math.cos(sun_el) * math.sin(sun_az), math.sin(sun_el)]
    )
    cos_sun = np.clip(dirs @ sun, -1.0, 1.0)
    glow = look.sun_glow * (0.35 * np.exp((cos_sun - 1.0) / 0.08) + np.exp((cos_sun - 1.0) / 0.002))
    out = out + np.array(look.sun_rgb) * glow[..., None]
    # clouds: noise on a plane 1 km up, flattened towards the horizon
    sky = el > 0
    reach = 1.0 / np.maximum(np.tan(np.radians(np.maximum(el, 0.5))), 1e-3)
    cu = reach * np.cos(np.radians(az)) * 12.0
    cv = reach * np.sin(np.radians(az)) * 12.0
    cover = noise.at(noise.mid, cu, cv) * 0.6 + noise.at(noise.coarse, cu / 2, cv / 2) * 0.8
    limit = 1.4 - 2.2 * look.clouds
    cloud = _smooth((cover - limit) / 0.8) * sky
    cloud_rgb = np.array(look.cloud_rgb) * (0.85 + 0.15 * _smooth(noise.at(noise.fine, cu, cv)))[
        ..., None
    ]
    out = out * (1.0 - cloud[..., None]) + cloud_rgb * cloud[..., None]
    kind = look.kind
    skyline_rgb = np.array(look.skyline_rgb)
    if kind == "chapel_hall":
        out = _chapel(out, el, az, noise, skyline_rgb, np.array(look.sky_horizon))
    elif kind == "stadium":
        out = _stands(out, el, az, rng, noise, skyline_rgb)
    else:
        out = _buildings(out, kind, el, az, rng, noise, skyline_rgb, np.array(look.sun_rgb))
    out = _ground(out, kind, el, az, noise, np.array(look.ground_rgb), np.array(look.earth_rgb))
    out = np.clip(out, 0.0, 0.97)
    return _to_image(out.reshape(6 * face_px, face_px, 3))


def _buildings(
    out: Floats, kind: str, el: Floats, az: Floats, rng: np.random.Generator, noise: _Sampler,
    rgb: Floats, sun_rgb: Floats,
) -> Floats:  # fmt: skip
    height, ident, lit = _skyline(kind, rng, az)
    inside = (el >= 0) & (el < height)
    if kind == "dawn_meadow":  # a treeline: ragged crowns, dark green
        crown = height + 1.2 * noise.at(noise.fine, az * 3.0, el * 3.0)
        inside = (el >= 0) & (el < crown)
        leaves = rgb * (0.8 + 0.25 * noise.at(noise.fine, az * 6.0, el * 6.0))[..., None]
        out[inside] = leaves[inside]
        return out
    shade = 0.75 + 0.5 * ((ident * 0.618) % 1.0)  # each building its own tone
    facade = rgb * shade[..., None]
    floors = (el % 0.9) < 0.35
    columns = (az % 0.7) < 0.35
    windows = floors & columns & (el > 0.6)
    if kind == "sunset_city":  # silhouettes against the glow, a few lit windows
        facade = rgb * (0.6 + 0.2 * shade)[..., None]
        on = windows & (noise.at(noise.fine, az * 8, el * 8) > 1.4 - lit)
        facade = np.where(on[..., None], sun_rgb * 0.6, facade)
    elif kind == "riverside":  # glass towers reflecting the sky, window grids
        facade = np.where(windows[..., None], out * 0.8 + 0.05, facade)
    elif kind == "old_town":  # plaster fronts, dark windows, red roofs on top
        facade = np.where(windows[..., None], facade * 0.45, facade)
        roof = (el > height - 1.2) & (height < 10.0)
        facade = np.where(roof[..., None], np.array([0.55, 0.25, 0.18]), facade)
    elif kind == "government":  # white stone and a glass front
        glass = (height > 6.5) & (el > 1.0) & (el < 6.5) & ((az % 2.0) < 1.6)
        facade = np.where(glass[..., None], out * 0.6 + 0.08, facade)
    out[inside] = facade[inside]
    return out


def _stands(
    out: Floats, el: Floats, az: Floats, rng: np.random.Generator, noise: _Sampler, rgb: Floats
) -> Floats:
    """An open stadium: boards at the horizon, tiers of seats with a sparse crowd in muted
    clothes, a roof edge with floodlights from 22 degrees."""
    shirts = rng.normal(0.0, 1.0, size=(24, 500, 3)) * 0.08 + np.array([0.32, 0.3, 0.3])
    occupied = rng.uniform(size=(24, 500)) < 0.35
    stand = (el >= 2.0) & (el < 22.0)
    cell_az = (az / 0.72).astype(np.int64) % 500
    cell_el = ((el - 2.0) / 0.83).astype(np.int64).clip(0, 23)
    seats = rgb * (0.9 + 0.1 * ((cell_el % 2)[..., None]))
    people = np.clip(shirts[cell_el, cell_az], 0.05, 0.8)
    crowd = np.where(occupied[cell_el, cell_az][..., None], people, seats)
    walk = ((el - 2.0) % 7.0) < 0.5
    crowd = np.where(walk[..., None], rgb * 1.3, crowd)
    out[stand] = crowd[stand]
    roof = (el >= 22.0) & (el < 25.0)
    out[roof] = rgb * 0.55
    lamps = roof & (el > 23.0) & (el < 24.2) & ((az % 12.0) < 2.0)
    out[lamps] = (0.95, 0.94, 0.88)
    board = (el >= 0.0) & (el < 2.0)
    panel = (az / 15.0).astype(np.int64) % 4
    colours = np.array([(0.15, 0.25, 0.55), (0.6, 0.6, 0.62), (0.55, 0.15, 0.12), (0.2, 0.4, 0.25)])
    out[board] = colours[panel][board]
    return out


def _chapel(
    out: Floats, el: Floats, az: Floats, noise: _Sampler, stone: Floats, light: Floats
) -> Floats:
    """A domed hall: stone walls with arched windows (the daylight comes in there and through
    the dome's eye), the dome's ribs overhead, a stone floor below."""
    wall = stone * (0.85 + 0.15 * noise.at(noise.mid, az * 4.0, el * 4.0))[..., None]
    out = np.broadcast_to(wall, out.shape).copy()
    bay = az % 30.0
    arch_top = 14.0 + 4.0 * np.sqrt(np.clip(1.0 - ((bay - 15.0) / 5.0) ** 2, 0.0, 1.0))
    window = (np.abs(bay - 15.0) < 5.0) & (el > 4.0) & (el < arch_top)
    glass = light * (0.9 + 0.1 * noise.at(noise.fine, az * 10.0, el * 10.0))[..., None]
    out[window] = glass[window]
    pillars = (np.abs(bay - 0.0) < 1.5) | (np.abs(bay - 30.0) < 1.5)
    out[pillars & (el > 0)] = stone * 0.6
    dome = el > 30.0
    ribs = (az % 22.5) < 1.2
    out[dome] = (stone * (0.7 + 0.3 * _smooth((el - 30.0) / 40.0))[..., None])[dome]
    out[dome & ribs] = stone * 0.5
    out[el > 78.0] = light * 0.97  # the dome's eye
    return out


def _ground(
    out: Floats, kind: str, el: Floats, az: Floats, noise: _Sampler, grass: Floats, earth: Floats
) -> Floats:
    """Below the horizon: the ground around the pitch in perspective (noise laid on a plane 1 m
    below the eye), grass with earth showing through, a river or paving for some kinds."""
    below = el < 0
    reach = 1.0 / np.maximum(np.tan(np.radians(np.maximum(-el, 0.05))), 1e-3)
    u = reach * np.cos(np.radians(az))
    v = reach * np.sin(np.radians(az))
    tufts = noise.at(noise.fine, u * 8.0, v * 8.0)
    patches = noise.at(noise.mid, u * 2.0, v * 2.0) + 0.6 * noise.at(noise.coarse, u, v)
    soil = _smooth((patches - 0.6) / 0.9)
    far = _smooth((reach - 20.0) / 200.0)  # detail fades and the colour hazes with distance
    tufts = tufts * (1.0 - far)
    ground = grass * (0.9 + 0.12 * tufts)[..., None]
    ground = ground * (1.0 - soil[..., None]) + earth * (0.9 + 0.1 * tufts)[..., None] * soil[
        ..., None
    ]
    if kind in ("old_town", "government", "stadium"):  # paving round the pitch
        paved = reach < (14.0 if kind == "stadium" else 30.0)
        stones = np.array([0.5, 0.48, 0.45]) * (0.9 + 0.1 * tufts)[..., None]
        ground = np.where(paved[..., None], stones, ground)
    if kind == "stadium":  # the running track round the pitch's surround
        track = (reach > 4.0) & (reach < 9.0)
        ground = np.where(track[..., None], np.array([0.55, 0.26, 0.2]), ground)
    if kind == "riverside":  # the river, then the far bank
        water = (reach > 25.0) & (reach < 120.0) & (np.cos(np.radians(az - 250.0)) > 0.2)
        ground = np.where(water[..., None], np.array([0.32, 0.4, 0.45]) + 0.05 * tufts[..., None],
                          ground)  # fmt: skip
    if kind == "chapel_hall":  # stone floor tiles
        tiles = ((np.floor(u * 1.5) + np.floor(v * 1.5)) % 2 == 0)
        ground = np.where(tiles[..., None], earth, earth * 0.8)
    haze = out * 0.0 + np.array([0.6, 0.62, 0.64])
    ground = ground * (1.0 - 0.35 * far[..., None]) + haze * 0.35 * far[..., None]
    out[below] = ground[below]
    return out
