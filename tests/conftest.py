"""Shared test setup: MuJoCo's OpenGL backend chosen before anything imports it (`MUJOCO_GL`
if set, else EGL or OSMesa, whichever renders here); the servers and workers the tests start
inherit the choice through the environment.

Expensive things that several test files need alike are built once here:

- `page_stack`: the page tests' `laserpick serve` and headless Chromium, kept open while
  consecutive tests ask for it and closed after the last of them (a server's start and a
  browser's launch take about 5 s);
- `isolation_recording`: `laserpick record` of the isolation scene with the laser confirmed
  on its mug, read (never written) by the recording tests and the examples.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

import pytest

from laserpick.robot.gl_backend import choose_gl_backend

choose_gl_backend()

T = TypeVar("T")

#: What the fixtures of `kept` hold open, by fixture name, with what closes it.
_KEPT: dict[str, tuple[Any, ExitStack]] = {}


def kept(name: str, open_: Callable[[ExitStack], T]) -> T:
    """The thing fixture `name` keeps open across tests, opened by `open_` if it is not open
    (`open_` enters into the stack it is given whatever must be closed). It is closed after
    the last of a run of consecutive tests that ask for `name`, not at the session's end: a
    live server left idling costs every later file CPU (its simulation keeps real time)."""
    if name not in _KEPT:
        stack = ExitStack()
        with stack:
            thing = open_(stack)
            _KEPT[name] = (thing, stack.pop_all())
    return _KEPT[name][0]


def _close_kept(next_item: pytest.Item | None) -> None:
    """Close each kept thing that `next_item` (None: no test follows) does not ask for."""
    for name in list(_KEPT):
        if next_item is None or name not in next_item.fixturenames:
            _KEPT.pop(name)[1].close()


@pytest.hookimpl(wrapper=True)
def pytest_runtest_teardown(item: pytest.Item, nextitem: pytest.Item | None) -> Iterator[None]:
    try:
        return (yield)  # the test's own fixtures first: a page before its browser
    finally:
        _close_kept(nextitem)


def pytest_sessionfinish(session: pytest.Session) -> None:
    _close_kept(None)


@dataclass(frozen=True)
class PageStack:
    server: Any  #: serve_process.ServeProcess, started with --lite-view
    browser: Any  #: a Playwright Browser (headless Chromium)


@pytest.fixture
def page_stack(tmp_path_factory: pytest.TempPathFactory) -> PageStack:
    """One `laserpick serve` for pages and one headless Chromium, shared by the page tests of
    every file (test_page.py, test_page_switch_and_pad.py). Each test leaves the scene as
    it found it or starts from `page_driver.fresh_scene`; each opens its own browser
    context, so no page keeps another's settings."""
    from page_driver import chromium, serve_for_pages

    from laserpick.console import headless_chromium

    if not Path(headless_chromium.CHROMIUM).exists():
        pytest.skip("no Chromium at /usr/bin/chromium")
    sync_api = pytest.importorskip("playwright.sync_api")

    def open_(stack: ExitStack) -> PageStack:
        server = stack.enter_context(
            contextmanager(serve_for_pages)(tmp_path_factory.mktemp("page"))
        )
        browser = stack.enter_context(contextmanager(chromium)(sync_api))
        return PageStack(server, browser)

    return kept("page_stack", open_)


#: The isolation scene's object that `isolation_recording` confirms the laser on.
RECORDED_OBJECT = "mug_1"


@pytest.fixture(scope="session")
def isolation_recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """`laserpick record` of the isolation scene with the laser confirmed on RECORDED_OBJECT:
    a directory that tests read and never write (a test that needs to change a recording
    copies it or records its own)."""
    from laserpick import cli

    out = tmp_path_factory.mktemp("recording") / "isolation"
    args = ["record", str(out), "--scene", "isolation", "--aim-at-object", RECORDED_OBJECT]
    assert cli.main(args) == 0
    return out
