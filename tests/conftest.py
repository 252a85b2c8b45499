"""Shared test setup: headless EGL rendering for MuJoCo, before anything imports it."""

import os

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
