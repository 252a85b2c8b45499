"""Loading scenes: the built-in scene files, YAML parsing (YAML 1.2 booleans) and `load_scene`."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from laserpick.robot.sim.scenes.builder import SceneBuilder
from laserpick.robot.sim.scenes.errors import SceneError
from laserpick.robot.sim.scenes.scene import Scene
from laserpick.robot.sim.scenes.schema import SceneCfg, pydantic_problems

#: Where the built-in scene files live.
SCENE_DIR = Path(__file__).parent.parent / "scene_files"
#: Largest scene file accepted (bytes).
MAX_SCENE_BYTES = 1_000_000


class _SceneLoader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 booleans: only true/false, so `on:` stays a key.

    YAML 1.1 reads on/off/yes/no as booleans, which would turn the `on` field into `True`.
    """


_SceneLoader.yaml_implicit_resolvers = {
    ch: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:bool"]
    for ch, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_SceneLoader.add_implicit_resolver(
    "tag:yaml.org,2002:bool",
    re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"),
    list("tTfF"),
)


def builtin_scene_names() -> list[str]:
    """Names of the scenes that ship with laserpick, sorted."""
    return sorted(p.stem for p in SCENE_DIR.glob("*.yaml"))


def scene_config(name: str) -> dict[str, Any]:
    """A built-in scene's file as plain data (YAML 1.2 booleans, as `parse_scene` reads it),
    to edit and pass back through `parse_scene(yaml.safe_dump(config))`."""
    data = yaml.load((SCENE_DIR / f"{name}.yaml").read_text(), Loader=_SceneLoader)
    assert isinstance(data, dict)
    return data


def parse_scene(
    text: str,
    source: Path | None = None,
    base_dir: Path | None = None,
    seed: int | None = None,
) -> Scene:
    """Parse scene YAML text (PyYAML's safe loader, YAML 1.2 booleans) into a `Scene`.

    `source` names the file in errors and in `Scene.source`; `base_dir` is where mesh paths
    are resolved (the source's directory by default; uploads without one cannot use meshes);
    `seed` (>= 0) overrides the seeds of the random rules. Raises `SceneError`.
    """
    file = str(source) if source is not None else "<scene>"
    if base_dir is None and source is not None:
        base_dir = Path(source).parent
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
        raise SceneError(file, [("seed", f"must be a non-negative integer, got {seed!r}")])
    if len(text.encode("utf-8", errors="replace")) > MAX_SCENE_BYTES:
        raise SceneError(file, [("", f"scene file is larger than {MAX_SCENE_BYTES} bytes")])
    try:
        data = yaml.load(text, Loader=_SceneLoader)  # a SafeLoader: plain data only
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc)
        raise SceneError(file, [(where, f"YAML syntax error: {problem}")]) from None
    if not isinstance(data, dict):
        got = "an empty file" if data is None else type(data).__name__
        raise SceneError(file, [("(top level)", f"expected a mapping of scene fields, got {got}")])
    try:
        cfg = SceneCfg.model_validate(data)
    except ValidationError as exc:
        raise SceneError(file, pydantic_problems(exc)) from None
    try:
        return SceneBuilder(cfg, file, base_dir, seed).build(source)
    except SceneError:
        raise
    except (ValueError, TypeError, OverflowError) as exc:  # a guard against odd inputs
        raise SceneError(file, [("", f"invalid scene: {exc}")]) from None


def load_scene(name_or_path: str | Path, seed: int | None = None) -> Scene:
    """Load a built-in scene by name (see `builtin_scene_names`) or a scene YAML file.

    `seed` overrides the random rules' seeds. Raises `SceneError` for missing or bad files.
    """
    name = str(name_or_path)
    if isinstance(name_or_path, str) and re.fullmatch(r"[A-Za-z0-9_\-]+", name):
        path = SCENE_DIR / f"{name}.yaml"
        if not path.is_file():
            known = ", ".join(builtin_scene_names())
            raise SceneError(name, [("", f"no built-in scene {name!r} (built-in: {known})")])
    else:
        path = Path(name_or_path)
    if not path.is_file():
        raise SceneError(str(path), [("", "scene file not found")])
    if path.stat().st_size > MAX_SCENE_BYTES:
        raise SceneError(str(path), [("", f"scene file is larger than {MAX_SCENE_BYTES} bytes")])
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(str(path), [("", f"cannot read the file: {exc}")]) from None
    return parse_scene(text, source=path, base_dir=path.parent, seed=seed)
