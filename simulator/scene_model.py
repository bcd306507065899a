"""The scene of a replay as a MuJoCo model of shapes only, and the poses of its frames: what the
video (:mod:`simulator.render`) and a robot's camera frames (:mod:`simulator.camera_frames`)
both draw. NumPy and MuJoCo are imported inside the functions (the offscreen OpenGL back end is
chosen before MuJoCo is imported)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt

    from simulator.replay import Replay
    from simulator.replay.format import GeomRecord, SceneRecord

    Array = npt.NDArray[np.float64]


def _quat_to_mat(q: Array) -> Array:
    """(n, 4) w x y z -> (n, 3, 3) rotation matrices."""
    import numpy as np

    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack(
        [
            1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
        ],
        axis=1,
    ).reshape(-1, 3, 3)  # fmt: skip


class Placer:
    """Puts the bodies, geoms and cameras of a :func:`scene_model` at a frame's body poses
    (``(n, 7)``: x y z, w x y z), as MuJoCo's kinematics would (the model has no joints)."""

    def __init__(self, model: Any, data: Any) -> None:
        self._data = data
        self._geom_body = model.geom_bodyid.copy()
        self._geom_pos = model.geom_pos.copy()
        self._geom_rot = _quat_to_mat(model.geom_quat.copy())
        self._cam_body = model.cam_bodyid.copy()
        self._cam_pos = model.cam_pos.copy()
        self._cam_rot = _quat_to_mat(model.cam_quat.copy())

    def __call__(self, poses: Array) -> None:
        import numpy as np

        data = self._data
        body_rot = _quat_to_mat(poses[:, 3:7])
        rot = body_rot[self._geom_body]
        data.xpos[:] = poses[:, 0:3]
        data.xmat[:] = body_rot.reshape(-1, 9)
        data.geom_xpos[:] = poses[self._geom_body, 0:3] + np.einsum(
            "nij,nj->ni", rot, self._geom_pos
        )
        data.geom_xmat[:] = np.matmul(rot, self._geom_rot).reshape(-1, 9)
        if len(self._cam_body):
            cam_rot = body_rot[self._cam_body]
            data.cam_xpos[:] = poses[self._cam_body, 0:3] + np.einsum(
                "nij,nj->ni", cam_rot, self._cam_pos
            )
            data.cam_xmat[:] = np.matmul(cam_rot, self._cam_rot).reshape(-1, 9)


def frames_for(replay: Replay, fps: float) -> Iterator[int]:
    """Index of the replay frame to show for each video frame at ``fps``."""
    frames = replay.frames
    if not frames:
        return
    end_ms = frames[-1].sim_time_ms
    k, i = 0, 0
    while k * 1000.0 / fps <= end_ms + 1e-6:
        t = k * 1000.0 / fps
        while i + 1 < len(frames) and frames[i + 1].sim_time_ms <= t + 1e-6:
            i += 1
        yield i
        k += 1


def _f(values: list[float]) -> str:
    return " ".join(f"{v:.6g}" for v in values)


def _geom_xml(geom: GeomRecord, material: str | None) -> str:
    look = f'material="{material}"' if material else f'rgba="{_f(geom["rgba"])}"'
    return (
        f'<geom type="{geom["type"]}" size="{_f(geom["size"])}" pos="{_f(geom["pos"])}" '
        f'quat="{_f(geom["quat"])}" {look} group="{geom["group"]}" contype="0" '
        f'conaffinity="0"/>'
    )


def scene_xml(scene: SceneRecord) -> str:
    """An MJCF of shapes only (no joints, no physics) with one body per recorded body, in the
    recorded order, so that body ``i`` of the model is body ``i`` of every frame."""
    from simulator.world.jersey import JERSEY_PREFIX, jersey_assets
    from simulator.world.look import light_xml, look_assets, look_from_summary

    bodies = scene["bodies"]
    geoms: list[list[str]] = [[] for _ in bodies]
    if scene.get("look") is not None:  # the match's look (textures filled by ``scene_model``)
        assets = [look_assets(look_from_summary(scene["look"]))]
    else:
        assets = [
            '<texture name="sky" type="skybox" builtin="gradient" rgb1="0.55 0.7 0.9" '
            'rgb2="0.1 0.15 0.25" width="64" height="64"/>'
        ]
    jerseys = sorted(
        {g["texture"] for g in scene["geoms"] if g.get("texture", "").startswith(JERSEY_PREFIX)}
    )
    assets += [jersey_assets(name.removeprefix(JERSEY_PREFIX)) for name in jerseys]
    for i, geom in enumerate(scene["geoms"]):
        material = geom.get("texture") if scene.get("look") is not None else None
        if geom.get("texture", "").startswith(JERSEY_PREFIX):
            material = geom["texture"]
        pattern = geom.get("pattern")
        if pattern is not None:
            material = f"m{i}"
            first, second = pattern["colors"]
            kind = "cube" if pattern["cube"] else "2d"
            assets.append(
                f'<texture name="t{i}" type="{kind}" builtin="checker" rgb1="{_f(first)}" '
                f'rgb2="{_f(second)}" width="64" height="64"/>'
                f'<material name="{material}" texture="t{i}" texrepeat="{_f(pattern["repeat"])}" '
                f'reflectance="0"/>'
            )
        geoms[geom["body"]].append(_geom_xml(geom, material))
    cameras = "".join(
        f'<camera name="{c["name"]}" pos="{_f(c["pos"])}" quat="{_f(c["quat"])}" '
        f'fovy="{c["fovy_deg"]:.6g}"/>'
        for c in scene["cameras"]
    )
    body_cameras: list[list[str]] = [[] for _ in bodies]
    for c in scene.get("robot_cameras", ()):
        body_cameras[c["body"]].append(
            f'<camera name="{c["name"]}" pos="{_f(c["pos"])}" quat="{_f(c["quat"])}" '
            f'fovy="{c["fovy_deg"]:.6g}"/>'
        )
    children = "".join(
        f'<body name="b{i}">{"".join(geoms[i])}{"".join(body_cameras[i])}</body>'
        for i in range(1, len(bodies))
    )
    return f"""<mujoco model="replay">
<visual>
 <global offwidth="1920" offheight="1080"/>
 <quality shadowsize="2048" offsamples="0"/>
 <headlight ambient="0.35 0.35 0.35" diffuse="0 0 0" specular="0 0 0"/>
 <map znear="0.01" zfar="100"/>
</visual>
<asset>{"".join(assets)}</asset>
<worldbody>
{light_xml()}
{cameras}{"".join(geoms[0])}{children}
</worldbody>
</mujoco>"""


def scene_model(scene: SceneRecord) -> Any:
    """The compiled :func:`scene_xml` of ``scene``, with its look's textures and lights."""
    import mujoco

    from simulator.world.jersey import apply_jerseys
    from simulator.world.look import apply_look, look_from_summary
    from simulator.world.scene import robot_jerseys

    model = mujoco.MjModel.from_xml_string(scene_xml(scene))
    if scene.get("look") is not None:
        apply_look(model, look_from_summary(scene["look"]))
    apply_jerseys(model, robot_jerseys((r["team"], r["number"]) for r in scene["robots"]))
    return model


__all__ = ["Placer", "frames_for", "scene_model", "scene_xml"]
