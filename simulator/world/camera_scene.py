"""The robot cameras' scene, made cheaper for a CPU renderer without changing what they see.

MuJoCo draws every geom of the scene in every pass, whether the camera sees it or not, and with
shadows it draws them three times: the colour pass, the key light's depth map (from the light,
:data:`ROBOT_SHADOW_SIZE` texels a side here) and a second colour pass with that light. On
Mesa's llvmpipe each geom costs some microseconds a pass whatever its size on screen, so:

- **Culling** (:class:`SceneCut`): before a frame, the geoms whose bounding sphere is outside
  the camera's view are left out (alpha 0 in the renderer's own copy of the model, which
  MuJoCo skips), unless they cast a shadow and the sphere swept from them along the light to
  the ground reaches the view. The turf plane always stays.
- **Casters**: geoms that cast no shadow worth a depth pass are marked decoration after the
  scene is made (MuJoCo's depth pass skips decoration): planes (they receive shadows), flat
  static geoms lying on the turf (the field lines, :data:`FLAT_M` at most above it) and thin
  static geoms (the net's cords, :data:`THIN_M` thick at most: a texel or less of the map).
- **Map**: the key light's depth map covers the turf plane (its half diagonal and a margin,
  ``vis.map.shadowclip``) at :data:`ROBOT_SHADOW_SIZE` texels, about the texel the scene's
  2048 texels over the whole world give; the match video and ``hlvs render`` keep the scene's.
- **Turf grid**: a plane is drawn as a grid of quads of its third size; the cameras draw the
  turf in :data:`PLANE_GRID_M` cells (a directional light lights a flat plane evenly: only the
  weak specular glint is interpolated over larger cells).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

ROBOT_SHADOW_SIZE = 1024
PLANE_GRID_M = 1.0
FLAT_M = 0.005  # static geoms whose top is at most this high cast no shadow (field lines)
THIN_M = 0.006  # static geoms this thin (half size) cast no shadow (net cords, 1 cm)
SHADOW_MARGIN_M = 0.5  # beyond the turf plane's half diagonal, for the depth map
VIEW_MARGIN = 1.05  # the view's tangents, widened: nothing at the edge of the image is left out
MAX_SHADOW_M = 20.0  # how far a shadow is followed along a low light


def cheap_shadows(model: mujoco.MjModel) -> None:
    """Set ``model`` (the cameras' copy) to draw the turf in coarse cells and to make a depth
    map of :data:`ROBOT_SHADOW_SIZE` texels over the turf (read when the render context is
    made)."""
    planes = np.flatnonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)
    model.vis.quality.shadowsize = ROBOT_SHADOW_SIZE
    finite = [p for p in planes if model.geom_size[p, 0] > 0 and model.geom_size[p, 1] > 0]
    for p in finite:
        model.geom_size[p, 2] = max(float(model.geom_size[p, 2]), PLANE_GRID_M)
    if finite and model.stat.extent > 0:
        reach = max(math.hypot(model.geom_size[p, 0], model.geom_size[p, 1]) for p in finite)
        clip = (reach + SHADOW_MARGIN_M) / float(model.stat.extent)
        model.vis.map.shadowclip = min(float(model.vis.map.shadowclip), clip)


def no_shadow_geoms(model: mujoco.MjModel) -> np.ndarray:
    """Which geoms cast no shadow worth drawing in the depth map (see the module's docstring):
    planes, and static geoms lying flat on the turf or thinner than :data:`THIN_M`."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    static = model.body_weldid[model.geom_bodyid] == 0
    planes = model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE
    boxes = model.geom_type == mujoco.mjtGeom.mjGEOM_BOX
    # a box's half extent along world z, in any orientation
    half_z = np.einsum("gj,gj->g", np.abs(data.geom_xmat.reshape(-1, 3, 3)[:, 2, :]),
                       model.geom_size)  # fmt: skip
    flat = static & boxes & (data.geom_xpos[:, 2] + half_z <= FLAT_M)
    thin = static & boxes & (np.sort(model.geom_size, axis=1)[:, 1] <= THIN_M)
    return np.asarray(planes | flat | thin)


class SceneCut:
    """Leaves out of one renderer's scene what its camera cannot see (nor the shadow of), and
    marks the geoms of :func:`no_shadow_geoms` as decoration: ``before(data, camera)`` ahead of
    ``update_scene`` on ``model`` (the renderer's own copy), ``after(scene)`` behind it."""

    def __init__(self, model: mujoco.MjModel, width: int, height: int, shadows: bool) -> None:
        self._model = model
        self._aspect = width / height
        self._shadows = shadows
        self._rgba = model.geom_rgba[:, 3].copy()
        self._matid = model.geom_matid.copy()
        self._rbound = model.geom_rbound.copy()
        self._keep_always = model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE
        self._no_shadow = no_shadow_geoms(model)
        self._out = np.zeros(model.ngeom, dtype=bool)
        lights = np.flatnonzero(model.light_castshadow)
        directional = model.light_type[lights] == mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
        # shadows along directional lights only are followed; any other light keeps all casters
        self._lights = lights if bool(np.all(directional)) else None

    def before(self, data: mujoco.MjData, camera: int) -> None:
        """Hide (alpha 0, no material) the geoms ``camera`` cannot see in ``data``'s pose."""
        model = self._model
        out = self._out
        model.geom_rgba[out, 3] = self._rgba[out]
        model.geom_matid[out] = self._matid[out]
        if model.cam_projection[camera] != mujoco.mjtProjection.mjPROJ_PERSPECTIVE or np.any(
            model.cam_sensorsize[camera]
        ):
            out[:] = False  # intrinsics or orthographic: not culled
            return
        keep = self._in_view(data, camera, data.geom_xpos, self._rbound) | self._keep_always
        if self._shadows:
            keep |= self._shadow_in_view(data, camera)
        out[:] = ~keep
        model.geom_rgba[out, 3] = 0.0
        model.geom_matid[out] = -1

    def after(self, scene: mujoco.MjvScene) -> None:
        """Mark the scene's geoms of :func:`no_shadow_geoms` as decoration (no depth pass)."""
        if not self._shadows:
            return
        no_shadow = self._no_shadow
        geom = mujoco.mjtObj.mjOBJ_GEOM
        decor = mujoco.mjtCatBit.mjCAT_DECOR
        for g in scene.geoms[: scene.ngeom]:
            if g.objtype == geom and no_shadow[g.objid]:
                g.category = decor

    def _in_view(
        self, data: mujoco.MjData, camera: int, centres: np.ndarray, radii: np.ndarray
    ) -> np.ndarray:
        """Whether spheres (``centres``, ``radii``) reach into ``camera``'s view."""
        ty = math.tan(math.radians(float(self._model.cam_fovy[camera])) / 2) * VIEW_MARGIN
        tx = ty * self._aspect
        local = (centres - data.cam_xpos[camera]) @ data.cam_xmat[camera].reshape(3, 3)
        depth = -local[:, 2]  # the camera looks along its -z, y up
        return np.asarray(
            (depth > -radii)
            & (np.abs(local[:, 1]) <= depth * ty + radii * math.sqrt(1 + ty * ty))
            & (np.abs(local[:, 0]) <= depth * tx + radii * math.sqrt(1 + tx * tx))
        )

    def _shadow_in_view(self, data: mujoco.MjData, camera: int) -> np.ndarray:
        """Whether a caster's shadow (the sphere around the segment from the geom down along
        the light to the turf, widened by the geom's radius) reaches into the view."""
        if self._lights is None:
            return np.asarray(~self._no_shadow)
        pos, radii = data.geom_xpos, self._rbound
        reach = np.zeros(len(pos), dtype=bool)
        for light in self._lights:
            direction = data.light_xdir[light]
            down = max(-float(direction[2]), 1e-3)
            length = np.minimum(np.maximum(pos[:, 2] + radii, 0.0) / down, MAX_SHADOW_M)
            centres = pos + 0.5 * length[:, None] * direction
            reach |= self._in_view(data, camera, centres, radii + 0.5 * length)
        return np.asarray(reach & ~self._no_shadow)
