"""`view_page`: viser's client page with our script first in its head."""

from __future__ import annotations

from pathlib import Path

import pytest

from laserpick.console import view_page as vp


def test_our_script_comes_first_in_the_head_of_viser_s_own_page() -> None:
    html = vp.view_page()
    original = vp.VISER_CLIENT.read_text(encoding="utf-8")
    assert html.replace(vp.AHEAD, "", 1) == original
    head = html.index("<head>") + len("<head>")
    assert html[head:].startswith(vp.AHEAD)
    assert html.index(vp.AHEAD) < html.index("<script", head + len(vp.AHEAD))
    static = Path(vp.__file__).parents[1] / "static" / "view.js"
    assert "antialias: false" in static.read_text(encoding="utf-8")


def test_a_missing_or_headless_client_page_is_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    vp.view_page.cache_clear()
    monkeypatch.setattr(vp, "VISER_CLIENT", tmp_path / "index.html")
    with pytest.raises(RuntimeError, match=r"missing at .*index\.html"):
        vp.view_page()
    (tmp_path / "index.html").write_text("<html><body></body></html>")
    with pytest.raises(RuntimeError, match="has no <head>"):
        vp.view_page()
    vp.view_page.cache_clear()
