"""The error a scene that cannot be loaded raises: the file, each field path and what is wrong."""

from __future__ import annotations

from collections.abc import Callable


class SceneError(ValueError):
    """A scene that cannot be loaded: names the file, the field path and what is wrong.

    `problems` lists (field path, message) pairs; the path looks like `objects[2].on`.
    """

    def __init__(self, file: str, problems: list[tuple[str, str]]) -> None:
        self.file = file
        self.problems = problems
        text = "; ".join(f"{path}: {msg}" if path else msg for path, msg in problems)
        super().__init__(f"{file}: {text}")

    def __reduce__(self) -> tuple[type[SceneError], tuple[str, list[tuple[str, str]]]]:
        return SceneError, (self.file, self.problems)  # crosses process boundaries intact


#: How scene building raises: fail(field path, message) returns the `SceneError` to raise.
Fail = Callable[[str, str], SceneError]
