"""Shared test setup: MuJoCo's OpenGL backend chosen before anything imports it (`MUJOCO_GL`
if set, else EGL or OSMesa, whichever renders here); the servers and workers the tests start
inherit the choice through the environment."""

from laserpick.robot.gl_backend import choose_gl_backend

choose_gl_backend()
