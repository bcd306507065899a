"""The match video's shadows: on a GPU, or when asked (a CPU renderer pays 2.1 times a frame)."""

from __future__ import annotations

import mujoco
import pytest

from simulator.render import VIDEO_SHADOWS_ENV, video_shadows


def test_video_shadows_follow_the_renderer_unless_asked(monkeypatch: pytest.MonkeyPatch) -> None:
    xml = "<mujoco><worldbody><geom size='1'/></worldbody></mujoco>"
    model = mujoco.MjModel.from_xml_string(xml)
    renderer = mujoco.Renderer(model, height=32, width=32)  # its context is current
    try:
        monkeypatch.delenv(VIDEO_SHADOWS_ENV, raising=False)
        assert video_shadows() is False  # the tests render with OSMesa, a CPU renderer
        monkeypatch.setenv(VIDEO_SHADOWS_ENV, "on")
        assert video_shadows() is True
        monkeypatch.setenv(VIDEO_SHADOWS_ENV, "off")
        assert video_shadows() is False
    finally:
        renderer.close()
