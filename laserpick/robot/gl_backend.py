"""MuJoCo's OpenGL backend, chosen so that the cameras render headless, before MuJoCo loads.

MuJoCo reads `MUJOCO_GL` once, when it is first imported, and with the variable unset it
takes GLFW, which needs a display: without one every capture fails, and a second try in the
same process can abort it. `choose_gl_backend()` decides first:

- `MUJOCO_GL` set: used if it can work here (`egl` or `osmesa` with its library installed;
  `glfw` with a display); anything else is refused. It is not probed.
- unset: EGL, then OSMesa, each probed in a short subprocess that imports MuJoCo with it and
  renders 8 x 8 pixels (a broken backend may abort the process that tries it); the first that
  renders is used. Only the first call probes; the verdict is kept for the process.
- MuJoCo already imported: the backend it loaded is checked, not changed.

The choice is written to `MUJOCO_GL`, and `PYOPENGL_PLATFORM` is set to match (the two must
agree), so processes started from here inherit it. Every way it fails is a `GLBackendError`
whose message is one sentence naming what to install or set.

Entry points that may render call it first: the CLI (`serve`, `record`, `bench`), the bench's
trials, and `SimRobot` (a check only: it imports MuJoCo).
"""

from __future__ import annotations

import ctypes.util
import logging
import os
import subprocess
import sys
import time
from collections.abc import Callable, Mapping

__all__ = [
    "HEADLESS_BACKENDS",
    "GLBackendError",
    "choose_gl_backend",
    "loaded_backend",
    "pick_backend",
    "probe_backend",
]

log = logging.getLogger(__name__)

#: The backends tried, in order, when `MUJOCO_GL` is unset.
HEADLESS_BACKENDS = ("egl", "osmesa")
#: The library each headless backend loads (ctypes name) and the Debian package holding it.
_LIBRARIES = {"egl": ("EGL", "libegl1 libegl-mesa0"), "osmesa": ("OSMesa", "libosmesa6")}
#: `MUJOCO_GL` values with which MuJoCo renders through GLFW (on Linux).
_GLFW_NAMES = ("glfw", "glx", "enable", "enabled", "on", "true", "1")
#: A probe taking longer than this (s) counts as failed; an idle 2-core machine takes ~1 s.
PROBE_TIMEOUT_S = 60.0

_INSTALL_HINT = (
    "install the Debian packages libegl1 libegl-mesa0 libgl1-mesa-dri (EGL) or libosmesa6"
    " (OSMesa), or set MUJOCO_GL=glfw on a machine with a display"
)

_PROBE = """
import mujoco
model = mujoco.MjModel.from_xml_string("<mujoco><worldbody><geom size='0.1'/></worldbody></mujoco>")
with mujoco.Renderer(model, 8, 8) as renderer:
    renderer.update_scene(mujoco.MjData(model))
    renderer.render()
"""


class GLBackendError(RuntimeError):
    """MuJoCo has no OpenGL backend that renders here; the message says what to install or
    set, in one sentence."""


_chosen: str | None = None


def choose_gl_backend() -> str:
    """The backend MuJoCo renders with in this process ("egl", "osmesa" or "glfw"): chosen
    and written to the environment before MuJoCo is imported, checked after. The first call
    decides; later calls return its verdict. GLBackendError when none can render here."""
    global _chosen
    if _chosen is None:
        loaded = loaded_backend()
        if loaded is not None:
            _chosen = _check_loaded(loaded, os.environ)
        else:
            t0 = time.perf_counter()
            _chosen = pick_backend(os.environ)
            os.environ["MUJOCO_GL"] = _chosen
            if _chosen in HEADLESS_BACKENDS:
                os.environ["PYOPENGL_PLATFORM"] = _chosen
            log.info("MuJoCo renders with %s (chosen in %.2f s)", _chosen, time.perf_counter() - t0)
    return _chosen


def pick_backend(environ: Mapping[str, str], probe: Callable[[str], bool] | None = None) -> str:
    """The backend to render with, for a process whose environment is `environ` and which has
    not imported MuJoCo: `MUJOCO_GL` if set and usable, else the first of HEADLESS_BACKENDS
    that `probe` (default `probe_backend`) finds rendering. GLBackendError otherwise."""
    wanted = environ.get("MUJOCO_GL", "").strip().lower()
    if wanted:
        return _check_wanted(wanted, environ)
    probe = probe or probe_backend
    for backend in HEADLESS_BACKENDS:
        if probe(backend):
            return backend
    raise GLBackendError(f"MuJoCo cannot render here with EGL or OSMesa: {_INSTALL_HINT}.")


def probe_backend(backend: str, timeout: float = PROBE_TIMEOUT_S) -> bool:
    """Whether MuJoCo renders with `backend` here: a fresh interpreter imports it with that
    backend and renders 8 x 8 pixels, within `timeout` s."""
    env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
    t0 = time.perf_counter()
    try:
        done = subprocess.run(
            [sys.executable, "-c", _PROBE],
            env=env,
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        log.info("MuJoCo's %s backend did not render within %.0f s", backend, timeout)
        return False
    took = time.perf_counter() - t0
    if done.returncode != 0:
        why = (done.stderr.strip().splitlines() or [f"exit code {done.returncode}"])[-1]
        log.info("MuJoCo's %s backend does not render here (%.2f s): %s", backend, took, why)
        return False
    log.info("MuJoCo's %s backend renders here (probed in %.2f s)", backend, took)
    return True


def loaded_backend() -> str | None:
    """The backend the imported MuJoCo renders with ("egl", "osmesa", "glfw", ...), "none"
    when it loaded none, or None when MuJoCo is not imported."""
    mujoco = sys.modules.get("mujoco")
    if mujoco is None:
        return None
    module = getattr(getattr(mujoco, "GLContext", None), "__module__", "") or ""
    parts = module.split(".")
    # `mujoco.egl.GLContext` and the like; a placeholder elsewhere when the backend failed.
    if len(parts) >= 2 and parts[0] == "mujoco" and parts[1] in ("egl", "osmesa", "glfw", "cgl"):
        return parts[1]
    return "none"


def _has_display(environ: Mapping[str, str]) -> bool:
    return bool(environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY"))


def _check_wanted(wanted: str, environ: Mapping[str, str]) -> str:
    """`wanted` (a `MUJOCO_GL` value) as a backend name if it can work here; else raise."""
    if wanted in _LIBRARIES:
        library, packages = _LIBRARIES[wanted]
        if ctypes.util.find_library(library) is None:
            raise GLBackendError(
                f"MUJOCO_GL is {wanted!r} but lib{library} is not installed: install the Debian"
                f" package{'s' if ' ' in packages else ''} {packages}, or unset MUJOCO_GL to let"
                " laserpick choose."
            )
        return wanted
    if wanted in _GLFW_NAMES:
        if not _has_display(environ):
            raise GLBackendError(
                f"MUJOCO_GL is {wanted!r}, which needs a display, and DISPLAY is not set:"
                " unset MUJOCO_GL to let laserpick choose, or set it to egl or osmesa."
            )
        return "glfw"
    raise GLBackendError(
        f"MUJOCO_GL is {wanted!r}, which MuJoCo cannot render with here: set it to egl or"
        " osmesa (or glfw with a display), or unset it to let laserpick choose."
    )


def _check_loaded(loaded: str, environ: Mapping[str, str]) -> str:
    """`loaded` (what the imported MuJoCo renders with) if it can render here; else raise."""
    if loaded in (*HEADLESS_BACKENDS, "cgl") or (loaded == "glfw" and _has_display(environ)):
        return loaded
    if loaded == "glfw":
        raise GLBackendError(
            "MuJoCo was imported before a rendering backend was chosen and took GLFW, which"
            " needs a display: set MUJOCO_GL=egl (or osmesa), or call"
            " laserpick.robot.gl_backend.choose_gl_backend(), before mujoco is first imported."
        )
    wanted = environ.get("MUJOCO_GL", "")
    raise GLBackendError(
        f"MuJoCo was imported with MUJOCO_GL={wanted!r} and loaded no OpenGL backend it can"
        f" render with: {_INSTALL_HINT}, and set MUJOCO_GL before mujoco is first imported."
    )
