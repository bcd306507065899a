"""Robot head cameras rendered offscreen (``MUJOCO_GL=osmesa`` or ``egl`` without a display).

Images are raw B,G,R bytes, rows top to bottom, as the HLVS robot API sends them. The look's
main light casts shadows (:mod:`simulator.world.look`). On a GPU the cameras draw MuJoCo's
shadow map. On a CPU renderer (llvmpipe) that map draws the scene twice more (the light's
depth map and a second lit pass): even with the cameras' cheaper scene
(:mod:`simulator.world.camera_scene`: a small depth map over the turf, only robots, ball and
goal posts in it, geoms out of view left out) a 320x240 frame of eight robots took 12.6 ms of
CPU with it against 4.9 without, about half a match's real-time factor; there the cameras
draw planar shadows instead (:class:`~simulator.world.camera_scene.PlanarShadows`: each
caster's shadow one flattened box on the turf, in the turf's colour without the key light):
6.8 to 8.6 ms against 6.1 to 7.7 without in the same runs (README, "Light").
``HLVS_CAMERA_SHADOWS`` ``map``, ``planar`` or ``off`` picks one anywhere;
``hlvs render --camera`` frames always have the map, the match video on a GPU or with
``HLVS_VIDEO_SHADOWS=on`` (:func:`simulator.render.video_shadows`); both keep the scene's own
depth map. Reflections are off. Spheres,
capsules and cylinders are tessellated more coarsely than MuJoCo's defaults (12 slices, 6
stacks instead of 28 and 16; planes and boxes in one quad): on a software renderer that cuts a
320x240 frame from about 10 ms to 4.5 ms with no visible difference at robot camera resolution.
The match video keeps the model's own quality. The camera model (exposure, noise, motion blur:
:mod:`simulator.world.camera_model`) is the world's ``camera_model`` in its ``look``'s
luminosity; a view of the world without them (``model``, ``data``, ``index`` only) renders
the ideal image.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Callable
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from contracts import RobotId
from simulator.errors import UnknownDeviceError
from simulator.world.camera_model import CameraEffects, CameraModel, blur_px_of, focal_px
from simulator.world.camera_scene import SceneCut, cheap_shadows
from simulator.world.merged import show_merged

if TYPE_CHECKING:
    from simulator.world.world import World

# (numslices, numstacks, numquads) of the robot cameras' render context
ROBOT_CAMERA_QUALITY = (12, 6, 1)
SHADOWS_ENV = "HLVS_CAMERA_SHADOWS"
# GL_RENDERER of Mesa's CPU rasterisers and other software renderers (simulator.gl's list: the
# world sits below the GL probe and does not import it)
SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swrast", "software")


def camera_shadows(software_gl: bool) -> str:
    """How robot cameras draw the key light's shadows (a kind of
    :data:`~simulator.world.camera_scene.SHADOW_KINDS`): ``HLVS_CAMERA_SHADOWS`` ``map``,
    ``planar`` or ``off``; anything else (``on``, unset) is MuJoCo's shadow map on a GPU and planar
    shadows on a CPU renderer."""
    wanted = os.environ.get(SHADOWS_ENV, "").strip().lower()
    if wanted in ("off", "0", "false"):
        return "off"
    if wanted in ("map", "planar"):
        return wanted
    return "planar" if software_gl else "map"


def software_gl() -> bool:
    """Whether the current GL context is a CPU rasteriser (its ``GL_RENDERER`` string)."""
    from OpenGL import GL

    name = GL.glGetString(GL.GL_RENDERER)
    text = name.decode(errors="replace") if isinstance(name, bytes) else str(name or "")
    return any(soft in text.lower() for soft in SOFTWARE_RENDERERS)


def robot_camera_model(model: mujoco.MjModel) -> mujoco.MjModel:
    """A copy of ``model`` with :data:`ROBOT_CAMERA_QUALITY` tessellation, the cameras'
    shadow map and turf grid (:func:`~simulator.world.camera_scene.cheap_shadows`; read by
    MuJoCo when the render context is made) and the lines and nets drawn as one mesh each
    (:func:`~simulator.world.merged.show_merged`); the copy has the same layout, so the world's
    data fits it."""
    cheap = copy.copy(model)
    quality = cheap.vis.quality
    quality.numslices, quality.numstacks, quality.numquads = ROBOT_CAMERA_QUALITY
    cheap_shadows(cheap)
    show_merged(cheap)
    return cheap


def linear_sky(renderer: mujoco.Renderer, focal: float) -> int:
    """Sample the sky's cube map of ``renderer``'s context without mipmaps (``GL_LINEAR`` where
    MuJoCo sets ``GL_LINEAR_MIPMAP_LINEAR``) when cameras of focal length ``focal`` pixels
    (the smallest of those it renders) see it magnified: at least half a face's texels a
    radian, where the level of detail is 0 and the mipmaps are never read. Returns how many
    textures it changed.

    The frames stay the same, bit for bit, but a CPU renderer (llvmpipe) works out each sky
    pixel's level of detail, in every direction of the cube, whenever a texture has mipmaps,
    and skips that without them: 7 % of a 320x240 frame of the benchmark's scene (46.5 degree
    field of view: 279 pixels a radian against 192 of the 384-texel face). Below half a face's
    texels a radian (160x120 there) the sky is minified and keeps its mipmaps. Needs the
    renderer's own OpenGL context (nothing changes without one)."""
    context = getattr(renderer, "_gl_context", None)
    mjr = getattr(renderer, "_mjr_context", None)
    if context is None or mjr is None:
        return 0
    model = renderer.model
    skies = [
        i for i in range(min(model.ntex, mjr.ntexture))
        if int(model.tex_type[i]) == int(mujoco.mjtTexture.mjTEXTURE_SKYBOX)
        and focal >= float(model.tex_width[i]) / 2.0
    ]  # fmt: skip
    if not skies:
        return 0
    from OpenGL import GL

    context.make_current()
    for i in skies:
        GL.glBindTexture(GL.GL_TEXTURE_CUBE_MAP, int(mjr.texture[i]))
        GL.glTexParameteri(GL.GL_TEXTURE_CUBE_MAP, GL.GL_TEXTURE_MIN_FILTER, GL.GL_LINEAR)
    GL.glBindTexture(GL.GL_TEXTURE_CUBE_MAP, 0)
    return len(skies)


# glReadPixels formats by the channels they deliver
_GL_FORMATS = {"BGR": "GL_BGR", "RGBA": "GL_RGBA", "RGB": "GL_RGB"}


def reads_frames(
    renderer: mujoco.Renderer, channels: str = "BGR"
) -> Callable[[np.ndarray], np.ndarray] | None:
    """A render of ``renderer``'s scene read back in ``channels`` order (``BGR``, ``RGBA`` or
    ``RGB``) into a frame buffer of that many channels kept from frame to frame, its rows
    bottom up (as OpenGL has them; ``[::-1]`` views them top down); None where that cannot be
    had (then ``renderer.render()``).

    ``mujoco.Renderer.render`` reads R,G,B into a new array and turns it upside down in place
    (a temporary copy). The robot camera delivers B,G,R, and numpy turns the channels of a
    320x240 frame in about 0.25 ms, 15 times a contiguous pass: OpenGL turns them as it reads
    (``GL_BGR``), and the rows are taken bottom up as a view: the same bytes
    (``tests/unit/world/test_world_camera_model.py``), 0.17 against 0.42 ms of CPU for reading
    and the camera model. R,G,B,A is the render buffer's own layout, which Mesa's CPU renderer
    copies out fastest (a 1280x720 frame in 0.5 ms against 1.2-1.6 for R,G,B): the match video
    reads it so (:mod:`simulator.render`). Needs the renderer's own OpenGL context and its
    offscreen buffer without multisampling (the scene's ``offsamples="0"``: a multisampled one
    is read through MuJoCo's resolve)."""
    context = getattr(renderer, "_gl_context", None)
    rect = getattr(renderer, "_rect", None)
    scene = getattr(renderer, "_scene", None)
    mjr = getattr(renderer, "_mjr_context", None)
    if context is None or rect is None or scene is None or mjr is None or mjr.offSamples:
        return None
    from OpenGL import GL

    gl_format = getattr(GL, _GL_FORMATS[channels])

    def read(frame: np.ndarray) -> np.ndarray:
        context.make_current()
        mujoco.mjr_render(rect, scene, mjr)
        GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)  # rows of any width, unpadded
        GL.glReadPixels(0, 0, rect.width, rect.height, gl_format, GL.GL_UNSIGNED_BYTE, frame)
        return frame

    return read


class CameraRenderer:
    """Renders any robot's head camera of ``world`` at ``width`` x ``height``.

    Use as a context manager or call :meth:`close`; one renderer owns one GL context and must be
    used from the thread that created it.
    """

    def __init__(self, world: World, width: int, height: int) -> None:
        self._world = world
        self.width = width
        self.height = height
        model = robot_camera_model(world.model)
        self._renderer = mujoco.Renderer(model, height=height, width=width)
        self._option = mujoco.MjvOption()
        self._option.geomgroup[4] = 0  # helper geoms stay invisible
        self._option.sitegroup[:] = 0  # sites are frames, not things (an IMU's inside a torso)
        scene = self._renderer.scene
        self.shadows = camera_shadows(software_gl())
        scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = self.shadows == "map"
        scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
        self._cut = SceneCut(model, width, height, self.shadows)
        camera_model = getattr(world, "camera_model", None) or CameraModel.ideal()
        look = getattr(world, "look", None)
        self._effects = CameraEffects(
            camera_model, width, height, luminosity=look.luminosity if look else 1.0
        )
        self._velocity = np.zeros(6)
        self._frame = np.empty((height, width, 3), dtype=np.uint8)
        self._read_bgr = reads_frames(self._renderer, "BGR")
        cameras = [index.camera for index in world.index.by_id.values()]
        focal = min((focal_px(height, float(model.cam_fovy[c])) for c in cameras), default=0.0)
        self.linear_sky = linear_sky(self._renderer, focal) > 0

    def render(self, robot: RobotId, *, sim_time_ms: int = 0) -> bytes:
        """One B,G,R image (``width * height * 3`` bytes) from ``robot``'s head camera, taken
        at ``sim_time_ms`` (it picks the frame's noise)."""
        index = self._world.index.by_id.get(robot)
        if index is None:
            raise UnknownDeviceError(robot=str(robot), name="Camera", kind="camera")
        data = self._world.data
        self._cut.before(data, index.camera)
        self._renderer.update_scene(data, camera=index.camera, scene_option=self._option)
        self._cut.after(self._renderer.scene, data, index.camera)
        effects = self._effects
        blur = (0.0, 0.0)
        if effects.model.motion_blur:
            blur = self._blur_px(index.camera)
        if self._read_bgr is None:
            bgr = self._renderer.render()[:, :, ::-1]
        else:
            bgr = self._read_bgr(self._frame)[::-1]
        return effects.of_bgr(
            bgr, robot=robot.number + 32 * (robot.team.value == "blue"),
            sim_time_ms=sim_time_ms, blur_px=blur,
        )  # fmt: skip

    def _blur_px(self, camera: int) -> tuple[float, float]:
        """Image motion during the exposure from the camera's angular velocity (the data's
        ``qvel``; velocities are computed here, the world only ran kinematics)."""
        model, data = self._world.model, self._world.data
        mujoco.mj_comPos(model, data)
        mujoco.mj_comVel(model, data)
        mujoco.mj_objectVelocity(
            model, data, mujoco.mjtObj.mjOBJ_CAMERA, camera, self._velocity, 1
        )
        return blur_px_of(
            self._velocity[:3], height=self.height, fovy_deg=float(model.cam_fovy[camera]),
            exposure_s=self._effects.model.exposure_s,
        )  # fmt: skip

    def close(self) -> None:
        self._renderer.close()

    def __enter__(self) -> CameraRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
