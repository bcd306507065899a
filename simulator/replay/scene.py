"""The scene a replay carries: every geom's shape, size, colour and place on its body.

A replay of format 2 holds this description in its header, so that it still renders and plays
after the robot models change. ``scene_of`` reads it from a compiled MuJoCo model::

    {"bodies": ["world", "ball", "red_1/torso", ...],
     "geoms": [{"name", "body", "type", "size": [3], "pos": [3], "quat": [w x y z],
                "rgba": [4], "group", "pattern"?: {"colors": [[r g b], [r g b]],
                                                   "repeat": [u v], "cube": bool}}],
     "cameras": [{"name", "body", "pos": [3], "quat": [4], "fovy_deg"}],
     "robot_cameras": [{"robot": "red-1", "name", "body", "pos", "quat", "fovy_deg", "width",
                        "height"}],
     "robots": [{"team", "number", "model", "root_body"}],
     "field": {FieldGeometry fields},
     "camera_model": {CameraModel fields} | null,
     "look": {"texture_seed", "turf", "ball", "background", "luminosity", "turf_colors",
              "stripe_m", "ball_colors", "sky_colors"}}

``type`` is one of ``plane sphere capsule ellipsoid cylinder box``; sizes are MuJoCo's (half
sizes, radius and half length). A mesh (the visual parts of a team's robot model) is recorded
as its bounding box in the geom's frame. ``pattern`` is a two-colour texture (MuJoCo's builtin
checker). ``texture`` names one of the look's materials (``look:turf``, ``look:ball``,
``look:net``; ``rgba`` is then its mean colour) and ``look`` is the look's
:meth:`simulator.world.look.Look.summary`: a renderer regenerates the textures from it
(:func:`simulator.world.look.look_from_summary`), a viewer may draw its stripe and ball colours.
"""

from __future__ import annotations

from dataclasses import asdict
from typing import TYPE_CHECKING, Any

from contracts import to_data

if TYPE_CHECKING:
    import mujoco

    from contracts import FieldGeometry
    from simulator.replay.format import (
        GeomRecord,
        PatternRecord,
        ReplayHeader,
        RobotCameraRecord,
        SceneCameraRecord,
        SceneRecord,
        SceneRobotRecord,
    )
    from simulator.world.camera_model import CameraModel
    from simulator.world.look import Look
    from simulator.world.types import RobotPlacement

GEOM_TYPES = {0: "plane", 2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box"}
MESH = 7  # a mesh (team robot models' visual parts) travels as its bounding box
TEXTURE_ROLE_RGB = 1
LOOK_PREFIX = "look:"
JERSEY_PREFIX = "jersey:"  # simulator.world.jersey's materials


def _round(values: Any, digits: int = 6) -> list[float]:
    return [round(float(v), digits) for v in values]


def _pattern(model: mujoco.MjModel, matid: int) -> PatternRecord | None:
    texid = int(model.mat_texid[matid][TEXTURE_ROLE_RGB])
    if texid < 0:
        return None
    adr, channels = int(model.tex_adr[texid]), int(model.tex_nchannel[texid])
    size = int(model.tex_width[texid]) * int(model.tex_height[texid]) * channels
    texels = model.tex_data[adr : adr + size].reshape(-1, channels)[:, :3]
    step = max(1, len(texels) // 512)
    colors = sorted({tuple(int(c) for c in texel) for texel in texels[::step]})
    if len(colors) != 2:
        return None
    return {
        "colors": [_round([c / 255.0 for c in color], 4) for color in colors],
        "repeat": _round(model.mat_texrepeat[matid], 4),
        "cube": int(model.tex_type[texid]) == 1,
    }


def _mean_texel(model: mujoco.MjModel, matid: int) -> list[float]:
    texid = int(model.mat_texid[matid][TEXTURE_ROLE_RGB])
    adr, channels = int(model.tex_adr[texid]), int(model.tex_nchannel[texid])
    size = int(model.tex_width[texid]) * int(model.tex_height[texid]) * channels
    texels = model.tex_data[adr : adr + size].reshape(-1, channels)[:, :3]
    return [float(v) / 255.0 for v in texels.mean(axis=0)]


def _geom(model: mujoco.MjModel, i: int) -> GeomRecord:
    gtype = int(model.geom_type[i])
    matid = int(model.geom_matid[i])
    rgba = model.mat_rgba[matid] if matid >= 0 else model.geom_rgba[i]
    pos = model.geom_pos[i]
    if gtype == MESH:
        import mujoco
        import numpy as np

        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.geom_quat[i])
        pos = pos + rot.reshape(3, 3) @ model.geom_aabb[i][:3]
    geom: GeomRecord = {
        "name": model.geom(i).name,
        "body": int(model.geom_bodyid[i]),
        "type": "box" if gtype == MESH else GEOM_TYPES.get(gtype, "sphere"),
        "size": (
            _round(model.geom_size[i])
            if gtype in GEOM_TYPES
            else _round(model.geom_aabb[i][3:])
            if gtype == MESH
            else [float(model.geom_rbound[i])] * 3
        ),
        "pos": _round(pos),
        "quat": _round(model.geom_quat[i]),
        "rgba": _round(rgba, 4),
        "group": int(model.geom_group[i]),
    }
    material = model.material(matid).name if matid >= 0 else ""
    look = material.startswith(LOOK_PREFIX)
    jersey = material.startswith(JERSEY_PREFIX)  # regenerated by scene_model
    pattern = _pattern(model, matid) if matid >= 0 and not (look or jersey) else None
    if look or jersey:
        geom["texture"] = material
        geom["rgba"] = _round([*_mean_texel(model, matid), float(rgba[3])], 4)
    if pattern is not None:
        mean = [(a + b) / 2 for a, b in zip(*pattern["colors"], strict=True)]
        geom["rgba"] = _round([*mean, float(rgba[3])], 4)
        geom["pattern"] = pattern
    return geom


def _camera_spec(model_name: str) -> tuple[int, int]:
    """(width, height) of a robot model's head camera; 320 x 240 when it cannot be loaded."""
    from simulator.errors import SimulatorError, UnknownModelError
    from simulator.world.robots import robot_model

    try:
        camera = robot_model(model_name).camera
    except (SimulatorError, UnknownModelError):
        return 320, 240
    return camera.width, camera.height


def scene_of(
    model: mujoco.MjModel,
    placements: tuple[RobotPlacement, ...],
    field: FieldGeometry,
    look: Look | None = None,
    camera_model: CameraModel | None = None,
) -> SceneRecord:
    """The scene description of a compiled world model (see the module docstring) built with
    ``look`` (default: the look of texture seed 0, as :func:`compile_scene`'s)."""
    from simulator.world.look import look_for
    from simulator.world.merged import is_merged
    from simulator.world.types import robot_prefix

    bodies = [model.body(i).name for i in range(model.nbody)]
    robots: list[SceneRobotRecord] = []
    for p in placements:
        prefix = robot_prefix(p.id) + "/"
        root = next((i for i, name in enumerate(bodies) if name.startswith(prefix)), -1)
        robots.append(
            {"team": p.id.team.value, "number": p.id.number, "model": p.model, "root_body": root}
        )
    cameras: list[SceneCameraRecord] = [
        {
            "name": model.camera(i).name,
            "body": int(model.cam_bodyid[i]),
            "pos": _round(model.cam_pos[i]),
            "quat": _round(model.cam_quat[i]),
            "fovy_deg": round(float(model.cam_fovy[i]), 4),
        }
        for i in range(model.ncam)
        if int(model.cam_bodyid[i]) == 0
    ]
    robot_cameras: list[RobotCameraRecord] = []
    for p, robot in zip(placements, robots, strict=True):
        prefix = robot_prefix(p.id) + "/"
        for i in range(model.ncam):
            body = int(model.cam_bodyid[i])
            if body > 0 and bodies[body].startswith(prefix):
                spec = _camera_spec(p.model)
                robot_cameras.append(
                    {
                        "robot": f"{robot['team']}-{robot['number']}",
                        "name": model.camera(i).name,
                        "body": body,
                        "pos": _round(model.cam_pos[i]),
                        "quat": _round(model.cam_quat[i]),
                        "fovy_deg": round(float(model.cam_fovy[i]), 4),
                        "width": spec[0],
                        "height": spec[1],
                    }
                )
                break
    field_data = {k: v.value if k == "field_class" else v for k, v in asdict(field).items()}
    return {
        "bodies": bodies,
        # the lines' and cords' meshes of the robot cameras stay out: their boxes are here
        "geoms": [
            _geom(model, i) for i in range(model.ngeom) if not is_merged(model.geom(i).name)
        ],
        "cameras": cameras,
        "robot_cameras": robot_cameras,
        "robots": robots,
        "field": field_data,
        "look": (look if look is not None else look_for(0)).summary(),
        "camera_model": to_data(camera_model) if camera_model is not None else None,
    }


def scene_for(header: ReplayHeader, path: str) -> SceneRecord:
    """The scene of a replay: its own (versions 2 and 3), or for version 1 the scene of today's
    models for the robots it lists, when those still have the recorded bodies."""
    if header.scene is not None:
        return header.scene
    from contracts import RobotId, TeamColor, field_for
    from simulator.errors import ReplayError, UnknownModelError
    from simulator.world.scene import compile_scene
    from simulator.world.types import RobotPlacement

    placements = tuple(
        RobotPlacement(
            id=RobotId(TeamColor(r.team), r.number), model=r.model, x_m=r.x_m, y_m=r.y_m,
            yaw_rad=r.yaw_rad,
        )
        for r in header.robots
    )  # fmt: skip
    field = field_for(header.field_class)
    try:
        model = compile_scene(field, placements, physics_dt_s=header.physics_dt_s)
    except UnknownModelError as exc:
        raise ReplayError(
            path=path, reason=f"version 1 replay without a scene, and {exc}"
        ) from exc
    names = tuple(model.body(i).name for i in range(model.nbody))
    if names != header.body_names:
        raise ReplayError(
            path=path,
            reason=f"version 1 replay without a scene: {len(header.body_names)} bodies recorded, "
            f"today's robot models have {model.nbody} (or other names); it cannot be shown",
        )
    return scene_of(model, placements, field)
