"""The robot cameras' scene, made cheaper for a CPU renderer without changing what they see.

MuJoCo draws every geom of the scene in every pass, whether the camera sees it or not, and with
its shadows it draws them three times: the colour pass, the key light's depth map (from the
light, :data:`ROBOT_SHADOW_SIZE` texels a side here) and a second colour pass with that light.
On Mesa's llvmpipe each geom costs some microseconds a pass whatever its size on screen, and
each triangle some more, so:

- **Culling** (:class:`SceneCut`): before a frame, the geoms whose bounding sphere is outside
  the camera's view, or under :data:`MIN_RADIUS_PX` in radius in the image, are left out
  (alpha 0 in the renderer's own copy of the model, which MuJoCo skips), unless (with the
  shadow map) they cast a shadow and the sphere swept from them along the light to the ground
  reaches the view. The turf plane always stays. The small ones are mostly the robots'
  cleats (6 mm spheres under their soles: half a pixel at 320x240 beyond about 3.4 m), 24-32
  geoms of 170-210 a frame in the benchmark's scene; leaving them out changed 0-2 pixels a
  frame there.
- **Planar shadows** (:class:`PlanarShadows`, the robot cameras' shadows on a CPU renderer):
  no shadow map and no second pass; each caster's shadow is one more geom, a box flattened
  along the key light onto the turf, in the colour the turf has there without that light.
  They fall on the turf only (MuJoCo's also fall on robots and on the lines, which stay lit
  here), and their edges are sharp (the map's are softened over a texel).
- **Casters**: geoms that cast no shadow worth a depth pass are marked decoration after the
  scene is made (MuJoCo's depth pass skips decoration): planes (they receive shadows), flat
  static geoms lying on the turf (the field lines, :data:`FLAT_M` at most above it) and thin
  static geoms (the net's cords, :data:`THIN_M` thick at most: a texel or less of the map).
  Planar shadows leave out the same, and small geoms inside larger ones of their body.
- **Map**: the key light's depth map covers the turf plane (its half diagonal and a margin,
  ``vis.map.shadowclip``) at :data:`ROBOT_SHADOW_SIZE` texels, about the texel the scene's
  2048 texels over the whole world give; the match video and ``hlvs render`` keep the scene's.
- **Turf grid**: a plane is drawn as a grid of quads of its third size; the cameras draw the
  turf in :data:`PLANE_GRID_M` cells (a directional light lights a flat plane evenly: only the
  weak specular glint is interpolated over larger cells).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from simulator.world.merged import merged_groups
from simulator.world.scene_geoms import geom_rows

ROBOT_SHADOW_SIZE = 1024
PLANE_GRID_M = 1.0
FLAT_M = 0.005  # static geoms whose top is at most this high cast no shadow (field lines)
THIN_M = 0.006  # static geoms this thin (half size) cast no shadow (net cords, 1 cm)
SHADOW_MARGIN_M = 0.5  # beyond the turf plane's half diagonal, for the depth map
VIEW_MARGIN = 1.05  # the view's tangents, widened: nothing at the edge of the image is left out
MIN_RADIUS_PX = 0.5  # geoms whose bounding sphere is smaller in the image are left out
MAX_SHADOW_M = 20.0  # how far a shadow is followed along a low light
SHADOW_KINDS = ("off", "map", "planar")
# planar shadows (PlanarShadows)
SHADOW_LIFT_M = 3e-4  # above the turf, below the lines' top (2 mm): lines show through
SHADOW_SLAB = 1e-3  # a caster's height, scaled: a 1.3 m goal post's shadow is 1.3 mm thick
MIN_CASTER_M = 0.01  # smaller geoms (bounding radius) cast no planar shadow
INSIDE_M = 0.01  # geoms this close inside another caster of their body cast none of their own
CAP_END = 0.8  # a capsule's shadow box reaches this share of its radius beyond its cylinder
HEXAGON = math.sqrt(2 * math.pi / (3 * math.sqrt(3))) / math.sqrt(8 / 3)  # cube half side / r
TURF_BLOCKS = 16  # the turf texture's colour under a shadow: its mean in blocks, this many a side
SOLID_TYPES = (
    mujoco.mjtGeom.mjGEOM_SPHERE,
    mujoco.mjtGeom.mjGEOM_CAPSULE,
    mujoco.mjtGeom.mjGEOM_ELLIPSOID,
    mujoco.mjtGeom.mjGEOM_CYLINDER,
    mujoco.mjtGeom.mjGEOM_BOX,
    mujoco.mjtGeom.mjGEOM_MESH,
)


def _finite_planes(model: mujoco.MjModel) -> list[int]:
    planes = np.flatnonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)
    return [int(p) for p in planes if model.geom_size[p, 0] > 0 and model.geom_size[p, 1] > 0]


def coarse_turf(model: mujoco.MjModel) -> None:
    """Set ``model`` (a renderer's own copy) to draw its finite planes in cells of at least
    :data:`PLANE_GRID_M` (MuJoCo draws a plane as a grid of quads of its third size, the turf's
    0.1 m: 8,800 quads). Its lights are directional (:mod:`simulator.world.look`), which light
    a flat plane evenly, so only the weak specular glint, worked out at the corners, is
    interpolated over larger cells; textures and shadow maps are looked up per pixel."""
    for p in _finite_planes(model):
        model.geom_size[p, 2] = max(float(model.geom_size[p, 2]), PLANE_GRID_M)


def cheap_shadows(model: mujoco.MjModel) -> None:
    """Set ``model`` (the cameras' copy) to draw the turf in coarse cells (:func:`coarse_turf`)
    and to make a depth map of :data:`ROBOT_SHADOW_SIZE` texels over the turf (read when the
    render context is made)."""
    finite = _finite_planes(model)
    model.vis.quality.shadowsize = ROBOT_SHADOW_SIZE
    coarse_turf(model)
    if finite and model.stat.extent > 0:
        reach = max(math.hypot(model.geom_size[p, 0], model.geom_size[p, 1]) for p in finite)
        clip = (reach + SHADOW_MARGIN_M) / float(model.stat.extent)
        model.vis.map.shadowclip = min(float(model.vis.map.shadowclip), clip)


def no_shadow_geoms(model: mujoco.MjModel) -> np.ndarray:
    """Which geoms cast no shadow worth drawing in the depth map (see the module's docstring):
    planes, static geoms lying flat on the turf or thinner than :data:`THIN_M`, and the meshes
    of the lines and cords (:mod:`simulator.world.merged`)."""
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
    merged = np.zeros(model.ngeom, dtype=bool)  # the lines' and cords' meshes: as their boxes
    merged[[g for g, _ in merged_groups(model)]] = True
    return np.asarray(planes | flat | thin | merged)


def planar_casters(model: mujoco.MjModel) -> np.ndarray:
    """The geoms whose shadow :class:`PlanarShadows` draws: those of :func:`no_shadow_geoms`'s
    complement that are drawn (alpha above 0, a solid type), of :data:`MIN_CASTER_M` bounding
    radius or more, and not inside another caster of their body (:data:`INSIDE_M` margin: a
    jersey on a torso, a marker on a head, cleats under a sole cast within its shadow)."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    solid = np.isin(model.geom_type, SOLID_TYPES)
    casters = np.flatnonzero(
        ~no_shadow_geoms(model) & solid & (model.geom_rgba[:, 3] > 0)
        & (model.geom_rbound >= MIN_CASTER_M)
    )  # fmt: skip
    keep = [g for g in casters if not _inside_another(model, data, int(g), casters)]
    return np.asarray(keep, dtype=int)


def _corners(model: mujoco.MjModel, data: mujoco.MjData, g: int) -> np.ndarray:
    """The world corners of geom ``g``'s bounding box (its own axes; a sphere's, a capsule's
    and a cylinder's from their radius and half length)."""
    size = model.geom_size[g]
    kind = int(model.geom_type[g])
    if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        half = np.array([size[0]] * 3)
    elif kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
        half = np.array([size[0], size[0], size[1] + size[0]])
    elif kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        half = np.array([size[0], size[0], size[1]])
    elif kind in (mujoco.mjtGeom.mjGEOM_BOX, mujoco.mjtGeom.mjGEOM_ELLIPSOID):
        half = np.asarray(size, dtype=float)
    else:  # a mesh: its bounding sphere's cube
        half = np.array([model.geom_rbound[g]] * 3)
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    return np.asarray(data.geom_xpos[g] + (signs * half) @ data.geom_xmat[g].reshape(3, 3).T)


def _inside_another(
    model: mujoco.MjModel, data: mujoco.MjData, g: int, casters: np.ndarray
) -> bool:
    """Whether geom ``g`` lies within :data:`INSIDE_M` of a larger box or sphere caster of
    its body (fixed to it: what holds in one pose holds in all)."""
    same_body = casters[model.geom_bodyid[casters] == model.geom_bodyid[g]]
    larger = same_body[model.geom_rbound[same_body] > model.geom_rbound[g]]
    if not len(larger):
        return False
    corners = _corners(model, data, g)
    for h in larger:
        local = (corners - data.geom_xpos[h]) @ data.geom_xmat[h].reshape(3, 3)
        size = model.geom_size[h]
        if model.geom_type[h] == mujoco.mjtGeom.mjGEOM_BOX:
            if np.all(np.abs(local) <= size + INSIDE_M):
                return True
        elif model.geom_type[h] == mujoco.mjtGeom.mjGEOM_SPHERE:
            if np.all(np.linalg.norm(local, axis=1) <= size[0] + INSIDE_M):
                return True
    return False


class _TurfColours:
    """The turf's colour (texture times material) around a point, from its texture averaged
    in blocks of :data:`TURF_BLOCKS` a side (the mowing stripes and wear patches stay; the
    blades average out, as they do a few metres away)."""

    def __init__(self, blocks: np.ndarray, repeat: float, half: np.ndarray) -> None:
        self._blocks = blocks
        self._repeat = repeat
        self._half = half  # the plane's half sizes (it lies at the origin along the axes)

    def under(self, xy: np.ndarray) -> np.ndarray:
        """The colours (rows of RGB in 0..1) of the turf at world points ``xy``."""
        n = self._blocks.shape[0]
        # a finite plane's texture coordinates in MuJoCo's renderer, with texuniform (measured
        # on rendered frames: a texel's column from x, its row from y)
        s = self._repeat * (xy[:, 0] + self._half[0]) / 2
        t = self._repeat * (self._half[1] - xy[:, 1]) / 2
        col = np.floor(s * n).astype(int) % n
        row = np.floor(t * n).astype(int) % n
        return np.asarray(self._blocks[row, col])


def _turf_colours(model: mujoco.MjModel) -> _TurfColours | None:
    """The colours of the largest finite plane with a uniform 2D texture lying at the origin
    along the world axes (the turf), or None."""
    planes = [
        p for p in np.flatnonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)
        if model.geom_size[p, 0] > 0 and model.geom_matid[p] >= 0
        and model.geom_bodyid[p] == 0 and not np.any(model.geom_pos[p])
        and np.allclose(model.geom_quat[p], (1, 0, 0, 0))
    ]  # fmt: skip
    for p in sorted(planes, key=lambda p: -float(model.geom_size[p, 0] * model.geom_size[p, 1])):
        mat = int(model.geom_matid[p])
        tex = int(model.mat_texid[mat, mujoco.mjtTextureRole.mjTEXROLE_RGB])
        if tex < 0 or model.tex_type[tex] != mujoco.mjtTexture.mjTEXTURE_2D:
            continue
        repeat = model.mat_texrepeat[mat]
        if not model.mat_texuniform[mat] or repeat[0] <= 0 or repeat[0] != repeat[1]:
            continue
        w, h, c = (int(model.tex_width[tex]), int(model.tex_height[tex]),
                   int(model.tex_nchannel[tex]))  # fmt: skip
        n = TURF_BLOCKS
        if w % n or h % n or c < 3:
            continue
        adr = int(model.tex_adr[tex])
        texels = model.tex_data[adr : adr + w * h * c].reshape(h, w, c)[..., :3] / 255.0
        blocks = texels.reshape(n, h // n, n, w // n, 3).mean(axis=(1, 3))
        blocks = blocks * model.mat_rgba[mat, :3]
        return _TurfColours(blocks, float(repeat[0]), model.geom_size[p, :2].copy())
    return None


def _shadow_light(scene: mujoco.MjvScene) -> tuple[Any, list[Any]]:
    """The scene's first directional light that casts shadows, and its other lights."""
    lights = list(scene.lights[: scene.nlight])
    for i, light in enumerate(lights):
        if light.castshadow and light.type == mujoco.mjtLightType.mjLIGHT_DIRECTIONAL:
            if light.dir[2] < -0.05:
                return light, lights[:i] + lights[i + 1 :]
    return None, lights


def _lit(lights: list[Any]) -> np.ndarray:
    """What ``lights`` give a flat turf facing up (ambient, and diffuse by the sine of their
    elevation), per channel."""
    total = np.zeros(3)
    for light in lights:
        total += light.ambient
        if light.type == mujoco.mjtLightType.mjLIGHT_DIRECTIONAL:
            total += np.asarray(light.diffuse) * max(0.0, -float(light.dir[2]))
    return total


def _without(key: Any, others: list[Any]) -> np.ndarray:
    """The share of a flat turf's light left without the ``key`` light, for a shadow lit
    by all the lights: (others) / (others + key), per channel."""
    rest = _lit(others)
    return np.asarray(rest / np.maximum(rest + _lit([key]), 1e-6))


class SceneCut:
    """Leaves out of one renderer's scene what its camera cannot see, and draws the key light's
    shadows as ``shadows`` says: ``"map"`` MuJoCo's shadow map (the geoms of
    :func:`no_shadow_geoms` marked decoration, casters whose shadow reaches the view kept),
    ``"planar"`` :class:`PlanarShadows`, ``"off"`` none. ``before(data, camera)`` ahead of
    ``update_scene`` on ``model`` (the renderer's own copy), ``after(scene, data, camera)``
    behind it."""

    def __init__(self, model: mujoco.MjModel, width: int, height: int, shadows: str) -> None:
        if shadows not in SHADOW_KINDS:
            raise ValueError(f"shadows: {shadows!r}, expected one of {', '.join(SHADOW_KINDS)}")
        self._model = model
        self._aspect = width / height
        self._half_height = height / 2
        self._shadows = shadows
        self._rgba = model.geom_rgba[:, 3].copy()
        self._matid = model.geom_matid.copy()
        self._rbound = model.geom_rbound.copy()
        self._keep_always = model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE
        self._no_shadow = no_shadow_geoms(model)
        self._out = np.zeros(model.ngeom, dtype=bool)
        self._planar = PlanarShadows(model) if shadows == "planar" else None
        # culled: the perspective cameras without intrinsics
        self._culled = (model.cam_projection == mujoco.mjtProjection.mjPROJ_PERSPECTIVE) & ~np.any(
            model.cam_sensorsize, axis=1
        )
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
        if not self._culled[camera]:
            out[:] = False  # intrinsics or orthographic: not culled
            return
        keep = self._in_view(data, camera, data.geom_xpos, self._rbound, MIN_RADIUS_PX)
        keep |= self._keep_always
        if self._shadows == "map":
            keep |= self._shadow_in_view(data, camera)
        out[:] = ~keep
        model.geom_rgba[out, 3] = 0.0
        model.geom_matid[out] = -1

    def after(self, scene: mujoco.MjvScene, data: mujoco.MjData, camera: int) -> None:
        """Draw the shadows into ``scene`` (made from ``camera`` in ``data``'s pose): the planar
        shadows that reach the view, or the decoration marks of the shadow map."""
        planar = self._planar
        light = planar.light(scene) if planar is not None else None
        if planar is not None and light is not None:
            which = np.arange(len(planar.casters))
            if self._culled[camera]:
                # the shadow's bounding sphere: the caster's, flattened along the light
                pos = data.geom_xpos[planar.casters]
                centres = pos - light.direction * (pos[:, 2:3] / light.direction[2])
                radii = planar.rbound / -light.direction[2]
                which = np.flatnonzero(self._in_view(data, camera, centres, radii))
            planar.add(scene, data, light, which)
        if self._shadows != "map":
            return
        no_shadow = self._no_shadow
        geom = mujoco.mjtObj.mjOBJ_GEOM
        decor = mujoco.mjtCatBit.mjCAT_DECOR
        for g in scene.geoms[: scene.ngeom]:
            if g.objtype == geom and no_shadow[g.objid]:
                g.category = decor

    def _in_view(
        self, data: mujoco.MjData, camera: int, centres: np.ndarray, radii: np.ndarray,
        min_px: float = 0.0,
    ) -> np.ndarray:  # fmt: skip
        """Whether spheres (``centres``, ``radii``) reach into ``camera``'s view, at least
        ``min_px`` in radius in the image (a sphere around the camera always is)."""
        tan = math.tan(math.radians(float(self._model.cam_fovy[camera])) / 2)
        ty = tan * VIEW_MARGIN
        tx = ty * self._aspect
        local = (centres - data.cam_xpos[camera]) @ data.cam_xmat[camera].reshape(3, 3)
        depth = -local[:, 2]  # the camera looks along its -z, y up
        seen = (
            (depth > -radii)
            & (np.abs(local[:, 1]) <= depth * ty + radii * math.sqrt(1 + ty * ty))
            & (np.abs(local[:, 0]) <= depth * tx + radii * math.sqrt(1 + tx * tx))
        )
        if min_px > 0:  # the radius in pixels: r / depth * (half the height / tan)
            seen &= radii * (self._half_height / tan) >= min_px * depth
        return np.asarray(seen)

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


@dataclass(frozen=True)
class _KeyLight:
    """The key light for planar shadows: its unit direction, the map that flattens along it
    onto the turf (x -> x - d x_z / d_z, z -> :data:`SHADOW_SLAB` x_z) and the share of a flat
    turf's light left without it, per channel (:func:`_without`)."""

    direction: np.ndarray
    flatten: np.ndarray
    shade: np.ndarray

    @classmethod
    def of(cls, key: Any, others: list[Any]) -> _KeyLight:
        direction = np.asarray(key.dir, dtype=np.float64)
        direction = direction / np.linalg.norm(direction)
        flatten = np.eye(3)
        flatten[:2, 2] = -direction[:2] / direction[2]
        flatten[2, 2] = SHADOW_SLAB
        return cls(direction, flatten, _without(key, others))


_SPREAD = np.array([(0.0, 0.0), (1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)])


class PlanarShadows:
    """The key light's shadows on the turf without MuJoCo's shadow map: each caster drawn once
    more as a box, flattened along the light onto the turf (:data:`SHADOW_LIFT_M` above it,
    its height scaled to :data:`SHADOW_SLAB` of itself) and opaque in the colour the turf
    under it has without that light (see :meth:`add`).

    A box's shadow is cheap (12 triangles, where a sphere or capsule is well over a hundred):
    a box casts its own; a capsule or cylinder a box along its axis, turned so that its
    shadow is as wide as theirs (the ends flat, a capsule's :data:`CAP_END` of its radius
    beyond the cylinder); a sphere a cube seen from the light along its diagonal (a regular
    hexagon of the disc's area, :data:`HEXAGON`). Ellipsoids and meshes cast their own shape.
    """

    def __init__(self, model: mujoco.MjModel) -> None:
        casters = planar_casters(model)
        self.casters = casters
        self.rbound = model.geom_rbound[casters].copy()
        self._turf = _turf_colours(model)
        kind = model.geom_type[casters]
        sizes = model.geom_size[casters].copy()
        geom = mujoco.mjtGeom
        self._prism = (kind == geom.mjGEOM_CAPSULE) | (kind == geom.mjGEOM_CYLINDER)
        self._sphere = kind == geom.mjGEOM_SPHERE
        radius = sizes[:, 0].copy()
        half = np.where(kind == geom.mjGEOM_CAPSULE, sizes[:, 1] + CAP_END * radius, sizes[:, 1])
        sizes[self._prism] = np.stack([radius, radius, half], axis=1)[self._prism]
        sizes[self._sphere] = (HEXAGON * radius)[self._sphere, None]
        boxed = self._prism | self._sphere
        self._types = [
            int(geom.mjGEOM_BOX) if b else int(t) for b, t in zip(boxed, kind, strict=True)
        ]
        self._sizes = sizes
        # a scene's mesh geoms name their mesh's display list (2 per mesh: the mesh, its hull)
        meshes = kind == geom.mjGEOM_MESH
        self._dataids = [int(i) for i in np.where(meshes, 2 * model.geom_dataid[casters], -1)]
        self._diagonal: tuple[tuple[float, ...], np.ndarray] = ((), np.eye(3))
        self._light: _KeyLight | None = None
        self._light_read = False
        # the shadows written as records (scene_geoms): each caster's geom as mjv_initGeom
        # and add's loop make it (pos, mat and rgba are written per frame), and the scene whose
        # records are viewed; None where the layout does not agree (geom by geom then)
        self._template = self._records(model)
        self._rows: tuple[mujoco.MjvScene | None, np.ndarray | None] = (None, None)
        self._last: _Posed | None = None

    def _records(self, model: mujoco.MjModel) -> np.ndarray | None:
        """The casters' shadow geoms as records, written once through the binding."""
        if not len(self.casters):
            return None
        scratch = mujoco.MjvScene(model, maxgeom=max(2, len(self.casters)))
        rows = geom_rows(scratch)
        if rows is None:
            return None
        white, still = np.ones(4, dtype=np.float32), np.eye(3).ravel()
        for k in range(len(self.casters)):
            self._write(scratch.geoms[k], k, np.zeros(3), still, white)
        template = rows[: len(self.casters)].copy()
        template["label"] = 0  # (mjv_initGeom ends the string at its first byte)
        return template

    def _write(self, geom: Any, c: int, pos: np.ndarray, mat: np.ndarray, rgba: np.ndarray) -> None:
        """Caster ``c``'s shadow geom written through the binding: a decoration, as MuJoCo's
        own (``mjv_initGeom`` leaves the object, category, segment and the flags as the slot
        had them, from whatever geom was there the frame before)."""
        mujoco.mjv_initGeom(geom, self._types[c], self._sizes[c], pos, mat, rgba)
        geom.specular = 0.0
        if self._dataids[c] >= 0:
            geom.dataid = self._dataids[c]
        geom.objtype = int(mujoco.mjtObj.mjOBJ_UNKNOWN)
        geom.objid = -1
        geom.category = int(mujoco.mjtCatBit.mjCAT_DECOR)
        geom.segid = -1
        geom.castshadow = 0
        geom.transparent = 0
        geom.camdist = 0.0

    def _rows_of(self, scene: mujoco.MjvScene) -> np.ndarray | None:
        if self._rows[0] is not scene:
            self._rows = (scene, geom_rows(scene) if self._template is not None else None)
        return self._rows[1]

    def light(self, scene: mujoco.MjvScene) -> _KeyLight | None:
        """The key light as ``scene`` has it (its first directional light that casts shadows
        from above), read from the first scene and kept (the cameras' copy of the model does
        not change); None without one."""
        if not self._light_read:
            key, others = _shadow_light(scene)
            self._light = None if key is None else _KeyLight.of(key, others)
            # a scene not made yet (no lights at all, not even the headlight) is not read
            self._light_read = scene.nlight > 0
        return self._light

    def _frames(self, xmat: np.ndarray, direction: np.ndarray) -> np.ndarray:
        """Every caster's shadow box's orientation (rows of 3x3, world from box), the casters'
        geoms having the orientations ``xmat``."""
        frames = xmat.reshape(-1, 3, 3).copy()
        prism = self._prism
        if np.any(prism):
            axis = frames[prism, :, 2]
            across = _cross(axis, direction)  # the shadow's width is measured along this
            norm = np.linalg.norm(across, axis=1, keepdims=True)
            # along the light: any width will do (the geom's own x axis)
            across = np.where(norm > 1e-6, across / np.maximum(norm, 1e-6), frames[prism, :, 0])
            frames[prism] = np.stack([across, _cross(axis, across), axis], axis=2)
        sphere = self._sphere
        if np.any(sphere):
            key = tuple(direction)
            if key != self._diagonal[0]:
                self._diagonal = (key, _diagonal_along(direction))
            frames[sphere] = self._diagonal[1]
        return np.asarray(frames)

    def add(
        self, scene: mujoco.MjvScene, data: mujoco.MjData, light: _KeyLight, which: np.ndarray
    ) -> int:
        """Append to ``scene`` the shadows along ``light`` of the casters ``which`` (indices
        into :attr:`casters`); the number added (as many as the scene has room for; none
        without a turf whose colour is known)."""
        if self._turf is None or not len(which):
            return 0
        which = which[: scene.maxgeom - scene.ngeom]
        first = scene.ngeom
        rows = self._rows_of(scene)
        posed = self._posed(data, light)
        if rows is not None and posed.records is not None:
            rows[first : first + len(which)] = posed.records[which]
        else:
            geoms = scene.geoms
            for k, c in enumerate(which.tolist()):
                self._write(geoms[first + k], c, posed.pos[c], posed.mats[c], posed.rgba[c])
        scene.ngeom = first + len(which)
        return len(which)

    def _posed(self, data: mujoco.MjData, light: _KeyLight) -> _Posed:
        """Every caster's shadow in ``data``'s pose (kept while the casters' poses and the
        light are the same: the cameras of one step share it)."""
        xpos, xmat = data.geom_xpos[self.casters], data.geom_xmat[self.casters]
        posed = self._last
        if (
            posed is not None
            and posed.light is light
            and np.array_equal(posed.xpos, xpos)
            and np.array_equal(posed.xmat, xmat)
        ):
            return posed
        pos = xpos @ light.flatten.T
        pos[:, 2] += SHADOW_LIFT_M
        frames = self._frames(xmat, light.direction)
        mats = (light.flatten @ frames).reshape(-1, 9)
        rgba = np.ones((len(self.casters), 4), dtype=np.float32)
        # the turf's colour over the shadow's breadth (its centre and four points half its
        # bounding radius away), so a shadow across two mowing stripes takes their blend
        assert self._turf is not None
        reach = 0.5 * self.rbound[:, None]
        spots = pos[None, :, :2] + _SPREAD[:, None, :] * reach[None, :, :]
        under = self._turf.under(spots.reshape(-1, 2)).reshape(len(_SPREAD), len(pos), 3)
        rgba[:, :3] = under.mean(axis=0) * light.shade
        records = None
        if self._template is not None:
            records = self._template.copy()
            records["pos"] = pos
            records["mat"] = mats
            records["rgba"] = rgba
        self._last = _Posed(light, xpos, xmat, pos, mats, rgba, records)
        return self._last


@dataclass(frozen=True)
class _Posed:
    """Every caster's shadow in one pose of the casters (``xpos``, ``xmat``) and ``light``: its
    position, orientation and colour, and as the scene's records when they are written so."""

    light: _KeyLight
    xpos: np.ndarray
    xmat: np.ndarray
    pos: np.ndarray
    mats: np.ndarray
    rgba: np.ndarray
    records: np.ndarray | None


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rows of ``a`` crossed with ``b`` (rows or one vector; ``np.cross`` is slower)."""
    ax, ay, az = a[..., 0], a[..., 1], a[..., 2]
    bx, by, bz = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx], axis=-1)


def _diagonal_along(direction: np.ndarray) -> np.ndarray:
    """A rotation (world from box) that turns a cube's diagonal (1, 1, 1) along
    ``direction``."""
    diagonal = np.ones(3) / math.sqrt(3.0)
    axis = np.cross(diagonal, direction)
    s, c = float(np.linalg.norm(axis)), float(diagonal @ direction)
    if s < 1e-9:  # along it or against it: the cube is the same either way
        return np.eye(3)
    k = axis / s
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.asarray(np.eye(3) + s * cross + (1 - c) * cross @ cross)
