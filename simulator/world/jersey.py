"""Team jerseys with the player's number on the built-in robots and on team models.

The league's robots wear a shirt in the team colour with the player number on it (hlvs_webots
``protos/robots/RoboCupRobot/RobotisJersey.proto``: a ``jerseyTexture`` per team colour and
number, such as ``robotis-op2_1_red.png``; the referee sets the colour and number of each
robot it spawns). The built-in robots wear a plate on the chest and one on the back, team
models the plates their manifest's ``jersey`` places on a link
(:mod:`simulator.world.robots.team.manifest`); each plate shows the shirt texture of
:func:`simulator.world.textures.jersey_tile`: the number upright, read from in front of it.
The textures are blank in the MJCF (:func:`jersey_assets`) and filled after compiling
(:func:`apply_jerseys`), as the look's are. Replays keep the plates in the shirt's mean colour
(:mod:`simulator.replay.scene`).
"""

from __future__ import annotations

from collections.abc import Iterable

import mujoco
import numpy as np

from simulator.world import textures

JERSEY_PX = 64  # the shirt texture's side
JERSEY_PREFIX = "jersey:"  # the materials' (and textures') names: ``jersey:<robot prefix>``


def jersey_material(prefix: str) -> str:
    """The material of the jersey of the robot named ``prefix`` (``red_1``)."""
    return f"{JERSEY_PREFIX}{prefix}"


def jersey_assets(prefix: str) -> str:
    """MJCF assets of one robot's jersey: a blank texture (filled by :func:`apply_jerseys`)
    and its material."""
    name = jersey_material(prefix)
    return (
        f'<texture name="{name}" type="2d" builtin="flat" rgb1="1 1 1" '
        f'width="{JERSEY_PX}" height="{JERSEY_PX}"/>'
        f'<material name="{name}" texture="{name}" specular="0.1" shininess="0.1" '
        f'reflectance="0"/>'
    )


def apply_jerseys(
    model: mujoco.MjModel, robots: Iterable[tuple[str, int, tuple[float, float, float]]]
) -> None:
    """Fill the jersey textures of ``robots``: (robot prefix, number, team RGB) each; robots
    without a jersey in ``model`` (team models whose manifest places none) are skipped."""
    for prefix, number, rgb in robots:
        name = jersey_material(prefix)
        try:
            texid = int(model.texture(name).id)
        except KeyError:
            continue
        image = textures.jersey_tile(number=number, team_rgb=rgb, size_px=JERSEY_PX)
        adr, channels = int(model.tex_adr[texid]), int(model.tex_nchannel[texid])
        size = JERSEY_PX * JERSEY_PX * channels
        texels = model.tex_data[adr : adr + size].reshape(-1, channels)
        texels[:, :3] = np.asarray(image).reshape(-1, 3)


__all__ = ["JERSEY_PREFIX", "apply_jerseys", "jersey_assets", "jersey_material"]
