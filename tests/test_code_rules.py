"""Rules of the codebase that a test can hold (ARCHITECTURE.md, "Rules that keep it honest").

- The pipeline sees only what a real robot's sensors see: nothing it imports, directly or
  through other modules, reaches mujoco, mink, the robot, the session, the bench or the console.
- The server never imports the bench.
- The rooms above robot/ reach hardware only through `robot.interface`: none of them imports
  the simulator (directly or transitively) or reads a robot's `.sim`. The CLI and the bench
  build the simulator and are the exceptions, as are the tests.
- One concept a module: no module over 600 lines (the console's scripts too), no function
  over 80; every package names its public surface in `__all__`.
- History lives in git: no commit hashes or round numbers in comments and docstrings.

Each checker is also run on a planted violation, so a rule cannot pass by not looking.
"""

from __future__ import annotations

import ast
import functools
import io
import re
import subprocess
import sys
import textwrap
import tokenize
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "laserpick"
SIMULATOR = ("mujoco", "mink", "laserpick.robot.sim")
#: Rooms that must reach hardware through `robot.interface` alone.
ABOVE_THE_SEAM = ("pipeline", "behaviours", "server", "console", "adapters", "client", "types")
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 80


def module_name(path: Path, root: Path = ROOT) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _is_package(path: Path) -> bool:
    return path.name == "__init__.py"


def direct_imports(path: Path, root: Path = ROOT) -> set[str]:
    """Every module `path` names in an import statement or an `importlib.import_module` /
    `__import__` call with a literal name, relative imports resolved; for `from a import b`
    both `a` and `a.b` (b may be a module)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    here = module_name(path, root).split(".")
    package = here if _is_package(path) else here[:-1]
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package[: len(package) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            names.add(base)
            names.update(f"{base}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Call) and node.args:
            f = node.func
            called = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
            arg = node.args[0]
            if called in ("import_module", "__import__") and isinstance(arg, ast.Constant):
                names.add(str(arg.value))
    return names


@functools.cache  # four rules read laserpick/'s graph: parsed once (0.6 s a parse here)
def import_graph(package: Path = PACKAGE, root: Path = ROOT) -> dict[str, set[str]]:
    """Each module of `package` with what it imports directly. Read it, never change it:
    the rules share one graph."""
    return {module_name(f, root): direct_imports(f, root) for f in sorted(package.rglob("*.py"))}


def reached(start: str, graph: dict[str, set[str]]) -> set[str]:
    """Every module importing `start` executes: its packages' `__init__`s and what each
    imported module imports in turn. Modules outside the graph are leaves."""
    seen: set[str] = set()
    todo = [start]
    while todo:
        name = todo.pop()
        parts = name.split(".")
        for i in range(1, len(parts) + 1):
            prefix = ".".join(parts[:i])
            if prefix in seen:
                continue
            seen.add(prefix)
            todo.extend(graph.get(prefix, ()))
    return seen


def offenders(
    graph: dict[str, set[str]], within: tuple[str, ...], forbidden: tuple[str, ...]
) -> list[str]:
    """`module -> forbidden module` for every module under `within` that reaches one."""
    out = []
    for mod in sorted(graph):
        if not mod.startswith(within):
            continue
        # `from a import b` names a.b: a module if the graph has it, or if it lies outside
        # the graph (a third-party module, or a room the scanned tree does not hold).
        modules = {
            r for r in reached(mod, graph) if r in graph or r.rpartition(".")[0] not in graph
        }
        bad = sorted(r for r in modules if any(r == f or r.startswith(f + ".") for f in forbidden))
        out += [f"{mod} -> {b}" for b in bad]
    return out


def sim_attribute_reads(path: Path) -> list[int]:
    """Lines of `path` that read an attribute named `sim` (a simulated robot's internals)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    return [n.lineno for n in ast.walk(tree) if isinstance(n, ast.Attribute) and n.attr == "sim"]


def too_long(path: Path) -> list[str]:
    """The module if over MAX_MODULE_LINES, and each function over MAX_FUNCTION_LINES (in
    Python; of a console script, its length alone)."""
    text = path.read_text()
    out = []
    if len(text.splitlines()) > MAX_MODULE_LINES:
        out.append(f"{path}: {len(text.splitlines())} lines")
    if path.suffix != ".py":
        return out
    for n in ast.walk(ast.parse(text)):
        if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef):
            length = n.end_lineno - n.lineno + 1
            if length > MAX_FUNCTION_LINES:
                out.append(f"{path}:{n.lineno} {n.name}: {length} lines")
    return out


#: "stop 57", "round 12", "seed 1's soda can", "seed 200 trial 1", and a word of 7-40 hex
#: digits with a letter and a digit (a commit).
HISTORY = re.compile(
    r"(?<![-\w])(stop|round)s? \d+\b(?!-|\.\d| ?(mm|cm|m|s|ms|N)\b)|\bseed \d+('s| trial)|"
    r"\b(?=[0-9a-f]*\d)(?=[0-9a-f]*[a-f])[0-9a-f]{7,40}\b",
    re.IGNORECASE,
)


def history_in_comments(path: Path) -> list[str]:
    """Comments and docstrings of `path` that cite a commit or a round of work."""
    text = path.read_text()
    prose = [
        (tok.start[0], tok.string)
        for tok in tokenize.generate_tokens(io.StringIO(text).readline)
        if tok.type == tokenize.COMMENT
    ]
    for node in ast.walk(ast.parse(text)):
        body = getattr(node, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr):
            value = body[0].value
            if isinstance(value, ast.Constant) and isinstance(value.value, str):
                prose.append((body[0].lineno, value.value))
    return [
        f"{path}:{line}: {m.group(0)}"
        for line, s in prose
        for m in [HISTORY.search(s.replace("e-stop", "").replace("E-stop", ""))]
        if m
    ]


def _python_files(*dirs: str) -> list[Path]:
    return [f for d in dirs for f in sorted((ROOT / d).rglob("*.py")) if ".venv" not in f.parts]


# --- the rules ----------------------------------------------------------------------------------


def test_pipeline_reaches_neither_the_simulator_nor_the_rooms_above_it():
    bad = offenders(
        import_graph(),
        ("laserpick.pipeline",),
        (
            *SIMULATOR,
            "laserpick.robot",
            "laserpick.behaviours",
            "laserpick.server",
            "laserpick.console",
            "laserpick.bench",
        ),
    )
    assert not bad, "pipeline/ must see only what a real robot's sensors see:\n" + "\n".join(bad)


def test_pipeline_imports_leave_mujoco_unloaded():
    # The same rule at run time: every pipeline module imported in a fresh interpreter.
    mods = [m for m in import_graph() if m.startswith("laserpick.pipeline")]
    code = "import sys\n" + "".join(f"import {m}\n" for m in mods)
    code += "print(sorted(m for m in sys.modules if m in ('mujoco', 'mink')"
    code += " or m.startswith(('laserpick.robot', 'laserpick.bench', 'laserpick.server'))))"
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "[]", res.stdout


def test_server_never_imports_the_bench():
    bad = offenders(import_graph(), ("laserpick.server",), ("laserpick.bench",))
    assert not bad, "server/ must not import the bench:\n" + "\n".join(bad)


def test_rooms_above_the_seam_never_import_the_simulator():
    rooms = tuple(f"laserpick.{r}" for r in ABOVE_THE_SEAM)
    bad = offenders(import_graph(), rooms, SIMULATOR)
    assert not bad, "only robot/, the CLI and the bench may import the simulator:\n" + "\n".join(
        bad
    )


def test_rooms_above_the_seam_never_read_a_robots_sim():
    files = [
        f
        for f in _python_files("laserpick")
        if module_name(f).startswith(tuple(f"laserpick.{r}" for r in ABOVE_THE_SEAM))
    ]
    bad = [f"{f.relative_to(ROOT)}:{line}" for f in files for line in sim_attribute_reads(f)]
    assert not bad, "`.sim` is the simulator's internals, behind the Robot seam:\n" + "\n".join(bad)


def test_modules_and_functions_are_short():
    scripts = sorted((PACKAGE / "static").rglob("*.js"))
    assert scripts, "the console's scripts are where they were"
    files = [*_python_files("laserpick", "tests", "bench"), *scripts]
    bad = [msg for f in files for msg in too_long(f)]
    assert not bad, "split these:\n" + "\n".join(bad)


def test_every_package_names_its_public_surface():
    bad = [
        str(f.relative_to(ROOT))
        for f in sorted(PACKAGE.rglob("__init__.py"))
        if "__all__" not in f.read_text()
    ]
    assert not bad, "packages without __all__:\n" + "\n".join(bad)


def test_no_history_in_comments():
    bad = [msg for f in _python_files("laserpick", "bench") for msg in history_in_comments(f)]
    assert not bad, "history belongs in git, not in comments:\n" + "\n".join(bad)


def test_ruff_is_clean():
    res = subprocess.run(
        [sys.executable, "-m", "ruff", "check", "--no-cache", str(ROOT)],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stdout + res.stderr


# --- the checkers catch planted violations --------------------------------------------------


@pytest.fixture
def planted(tmp_path):
    """A tiny package tree under tmp_path; write modules with `plant(name, source)`."""

    def plant(name: str, source: str) -> Path:
        path = tmp_path / Path(*name.split("."))
        path.parent.mkdir(parents=True, exist_ok=True)
        for parent in path.relative_to(tmp_path).parents:
            init = tmp_path / parent / "__init__.py"
            if parent != Path(".") and not init.exists():
                init.write_text("")
        path = path.with_suffix(".py")
        path.write_text(textwrap.dedent(source))
        return path

    return plant


def test_a_transitive_import_of_the_simulator_is_caught(planted, tmp_path):
    planted("laserpick.pipeline.ok", "from laserpick.pipeline import helper\n")
    planted("laserpick.pipeline.helper", "from ..server.session import Session\n")
    planted("laserpick.server.session", "import importlib\nimportlib.import_module('mujoco')\n")
    graph = import_graph(tmp_path / "laserpick", tmp_path)
    bad = offenders(graph, ("laserpick.pipeline",), ("mujoco", "laserpick.server"))
    assert "laserpick.pipeline.ok -> mujoco" in bad
    assert "laserpick.pipeline.helper -> laserpick.server" in bad


def test_a_server_module_importing_the_bench_is_caught(planted, tmp_path):
    planted("laserpick.server.app", "from laserpick.bench.operator import Referee\n")
    graph = import_graph(tmp_path / "laserpick", tmp_path)
    assert offenders(graph, ("laserpick.server",), ("laserpick.bench",))


def test_a_sim_read_and_a_long_function_are_caught(planted):
    path = planted(
        "laserpick.server.peek",
        "def f(robot):\n    return robot.sim.snapshot()\n\n\ndef g():\n"
        + "    x = 1\n" * MAX_FUNCTION_LINES,
    )
    assert sim_attribute_reads(path) == [2]
    assert [m.split(" ", 1)[1] for m in too_long(path)] == [f"g: {MAX_FUNCTION_LINES + 1} lines"]


def test_a_long_console_script_is_caught(tmp_path):
    script = tmp_path / "page.js"
    script.write_text("let x = 1;\n" * (MAX_MODULE_LINES + 1))
    assert too_long(script) == [f"{script}: {MAX_MODULE_LINES + 1} lines"]


def test_history_in_a_comment_is_caught(planted):
    source = (
        '"""Fixed in 0512a73."""\n\n# the mug slid on round 12\n# as seed 1\'s can did\nX = 1\n'
    )
    assert len(history_in_comments(planted("laserpick.probe", source))) == 3
