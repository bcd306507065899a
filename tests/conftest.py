"""Shared test settings. Integration tests mark what they need (docker, root), clean up by label."""

from __future__ import annotations

import os

# Offscreen rendering without a display (MuJoCo reads this at import time).
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

TEST_LABEL = "org.hlvs-runner.test"
