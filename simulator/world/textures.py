"""Procedural textures of the league's look, generated with numpy from a seed (no image files).

Every function is a pure function of its arguments: the same seed and variant give the same
bytes on every machine (numpy's PCG64 stream and float64 arithmetic only). Images are ``uint8``
RGB arrays, rows from the texture's first row; cube textures are six square faces stacked
vertically in MuJoCo's order (see :func:`_cube_directions`).

- **Turf**: one tile of artificial grass (blade speckle at a few millimetres, tufts, slow
  colour variation) with a light and a dark mowing stripe side by side; it repeats seamlessly
  (the noise is periodic: filtered in the Fourier domain).
- **Ball**: the classic truncated-icosahedron pattern: 12 dark pentagons, 20 white hexagons and
  grey seams, drawn on the sphere by direction (no texture seams at the cube edges).
- **Background**: a stadium around the pitch at infinity: sky, a roof edge, tiers of spectators
  (coloured speckle), advertising boards at the horizon and the surround below it. Nothing in
  it is as white as the lines or the goal posts.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

Image = npt.NDArray[np.uint8]
Floats = npt.NDArray[np.float64]


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


def turf_tile(
    *, seed: int, size_px: int, base_rgb: tuple[float, float, float], stripe_contrast: float
) -> Image:
    """A ``size_px`` square of turf: the left half the light mowing stripe, the right half the
    dark one (the tile spans two stripes; the caller sets how many metres it covers)."""
    rng = np.random.default_rng(seed)
    blades = _periodic_noise(rng, size_px, 0.6)
    tufts = _periodic_noise(rng, size_px, 3.0)
    patches = _periodic_noise(rng, size_px, size_px / 12.0)
    shade = 1.0 + 0.10 * blades + 0.07 * tufts + 0.05 * patches
    # blades lean one way: a slight streak along the rows of the tile
    shade = 0.6 * shade + 0.2 * np.roll(shade, 1, axis=0) + 0.2 * np.roll(shade, -1, axis=0)
    shade = np.clip(shade, 0.75, 1.3)  # no blade as dark as the ball's patches
    stripe = np.where(np.arange(size_px) < size_px // 2, 1.0 + stripe_contrast, 1.0)
    stripe = stripe - stripe_contrast / 2
    shade = shade * stripe[np.newaxis, :]
    hue = 0.04 * patches  # yellower and bluer patches
    rgb = np.stack(
        [
            base_rgb[0] * shade * (1.0 + hue),
            base_rgb[1] * shade,
            base_rgb[2] * shade * (1.0 - hue),
        ],
        axis=-1,
    )
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


def ball_cube(
    *,
    face_px: int,
    patch_rgb: tuple[float, float, float],
    panel_rgb: tuple[float, float, float],
    patch_size: float,
    turn_rad: float,
) -> Image:
    """The ball's cube texture: dark pentagons (``patch_rgb``) on white panels (``panel_rgb``)
    with seams. ``patch_size`` > 0 grows the pentagons against the hexagons (0 gives 31 % of
    the surface dark, 0.02 37 %, 0.05 49 %); ``turn_rad`` turns the pattern about the vertical
    axis."""
    dirs = _cube_directions(face_px, skybox=False).reshape(-1, 3)
    pent, hexa = _icosahedron()
    c, s = math.cos(turn_rad), math.sin(turn_rad)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    centres = np.concatenate([pent, hexa]) @ turn.T
    bias = np.concatenate([np.full(12, patch_size), np.zeros(20)])
    score = dirs @ centres.T + bias
    top2 = np.partition(score, -2, axis=1)[:, -2:]
    best = np.argmax(score, axis=1)
    seam = (top2[:, 1] - top2[:, 0]) < 0.012
    rgb = np.where((best < 12)[:, None], np.array(patch_rgb), np.array(panel_rgb))
    rgb = np.where(seam[:, None], np.array(panel_rgb) * 0.55, rgb)
    return _to_image(rgb.reshape(6 * face_px, face_px, 3))


def stadium_cube(
    *,
    seed: int,
    face_px: int,
    sky_top: tuple[float, float, float],
    sky_horizon: tuple[float, float, float],
    stands_rgb: tuple[float, float, float],
    boards: tuple[tuple[float, float, float], ...],
    surround_rgb: tuple[float, float, float],
) -> Image:
    """The background cube texture of a stadium (z up): sky above 32 deg of elevation, a roof
    edge, spectator tiers from 3 to 30 deg, advertising boards just above the horizon, the
    surround below it. Every colour stays below 0.75 (darker than lines and posts)."""
    rng = np.random.default_rng(seed)
    dirs = _cube_directions(face_px, skybox=True)
    elevation = np.degrees(np.arcsin(np.clip(dirs[..., 2], -1.0, 1.0)))
    azimuth = np.degrees(np.arctan2(dirs[..., 1], dirs[..., 0])) % 360.0
    out = np.empty(dirs.shape, dtype=np.float64)
    # sky: a gradient from the horizon colour to the top colour
    k = np.clip((elevation - 30.0) / 60.0, 0.0, 1.0)[..., None]
    out[:] = np.array(sky_horizon) * (1 - k) + np.array(sky_top) * k
    # roof edge: a dark band with a row of floodlights
    roof = (elevation >= 28.0) & (elevation < 32.0)
    out[roof] = np.array(stands_rgb) * 0.45
    lamps = roof & (elevation > 29.2) & (elevation < 30.6) & ((azimuth % 9.0) < 2.2)
    out[lamps] = (0.74, 0.72, 0.6)
    # spectators: cells of 0.9 deg azimuth x 1.1 deg elevation, each a random shirt colour
    # mixed with the stand colour; empty seats in between
    stands = (elevation >= 3.0) & (elevation < 28.0)
    cell_az = (azimuth / 0.9).astype(np.int64) % 400
    cell_el = ((elevation - 3.0) / 1.1).astype(np.int64).clip(0, 39)
    shirts = rng.uniform(0.08, 0.72, size=(40, 400, 3))
    occupied = rng.uniform(size=(40, 400)) < 0.7
    person = shirts[cell_el, cell_az]
    seat = np.broadcast_to(np.array(stands_rgb), person.shape)
    mix = np.where(occupied[cell_el, cell_az][..., None], 0.65 * person + 0.35 * seat, seat)
    tier = ((elevation - 3.0) % 8.0) < 0.5  # walkways between tiers
    mix = np.where(tier[..., None], np.array(stands_rgb) * 0.7, mix)
    out[stands] = mix[stands]
    # advertising boards: panels of 20 deg azimuth in the league's colours
    board = (elevation >= 0.0) & (elevation < 3.0)
    panel = (azimuth / 20.0).astype(np.int64) % len(boards)
    colours = np.array(boards)[panel]
    letters = ((azimuth % 20.0) > 4.0) & ((azimuth % 20.0) < 16.0)
    letters &= (elevation > 0.9) & (elevation < 2.1) & ((azimuth % 1.6) < 0.9)
    colours = np.where(letters[..., None], colours * 0.45, colours)
    out[board] = colours[board]
    out[elevation < 0.0] = np.array(surround_rgb)
    out = np.minimum(out, 0.74)
    return _to_image(out.reshape(6 * face_px, face_px, 3))


def net_tile(*, size_px: int, mesh_px: int) -> Image:
    """A square of goal net: light cords every ``mesh_px`` texels on a dark (see-through
    looking) ground."""
    i = np.arange(size_px)
    cord = ((i % mesh_px) < 2)
    grid = cord[:, None] | cord[None, :]
    rgb = np.where(grid[..., None], 0.85, 0.25) * np.ones(3)
    return _to_image(rgb)
