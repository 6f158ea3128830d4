"""The house rules of docs/architecture.md, read from the source with ``ast`` (never by
importing it): who may import the simulation, no import circles, small modules, and a
folder map that names every folder.

Every import counts, wherever it stands: at the top, inside a function, or under
``if TYPE_CHECKING:`` (a type-only edge is still an edge a reader has to follow).
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PACKAGES = ("robot", "sim")
#: The only folders of robot/ that may import sim/ (they assemble runs on the sim bus).
SIM_IMPORTERS = ("robot.commands", "robot.bench", "robot.panel")
#: Modules allowed at the top of robot/: the entry points, not features.
TOP_LEVEL = {"__init__.py", "cli.py", "errors.py"}
MAX_LINES = 300


def module_files() -> dict[str, Path]:
    """Dotted module name → file, for every module of robot/ and sim/."""
    out: dict[str, Path] = {}
    for top in PACKAGES:
        for path in sorted((REPO / top).rglob("*.py")):
            parts = list(path.relative_to(REPO).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            out[".".join(parts)] = path
    return out


MODULES = module_files()


def _resolve(name: str) -> str | None:
    """The project module ``name`` lands in (``robot.gait.ik.solve`` → ``robot.gait.ik``)."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def imports_of(module: str) -> Iterator[tuple[str, int]]:
    """(imported project module, line) for every import statement in ``module``."""
    tree = ast.parse(MODULES[module].read_text(), str(MODULES[module]))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [f"{node.module}.{a.name}" for a in node.names]
        else:
            continue
        for name in names:
            target = _resolve(name)
            if target is not None and target != module:
                yield target, node.lineno


GRAPH = {m: sorted({t for t, _ in imports_of(m)}) for m in MODULES}


def cycles(graph: dict[str, list[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(graph[root]))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, edges = work[-1]
            nxt = next(edges, None)
            if nxt is not None:
                if nxt not in index:
                    index[nxt] = low[nxt] = len(index)
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(graph[nxt])))
                elif nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def test_the_cycle_finder_finds_a_planted_circle() -> None:
    graph = {"a": ["b"], "b": ["c"], "c": ["a"], "d": ["a"], "e": []}
    assert cycles(graph) == [["a", "b", "c"]]
    assert cycles({"a": ["b"], "b": [], "c": ["a", "b"]}) == []


def test_no_import_circles() -> None:
    assert cycles(GRAPH) == []


def folder_of(module: str) -> str:
    """The unit a reader sees on docs/architecture.md: ``robot.gait.ik`` → ``robot.gait``;
    the entry modules (``robot.cli``, ``robot.errors``) are units of their own."""
    return ".".join(module.split(".")[:2])


def test_no_circles_between_folders() -> None:
    graph: dict[str, set[str]] = {}
    for module, targets in GRAPH.items():
        here = folder_of(module)
        graph.setdefault(here, set())
        graph[here] |= {folder_of(t) for t in targets if folder_of(t) not in (here, "robot", "sim")}
    assert cycles({k: sorted(v) for k, v in graph.items()}) == []


def test_only_commands_bench_and_panel_import_sim() -> None:
    offenders = [
        f"{MODULES[m].relative_to(REPO)}:{line} imports {target}"
        for m in MODULES if m.startswith("robot") and not m.startswith(SIM_IMPORTERS)
        for target, line in imports_of(m) if target.split(".")[0] == "sim"
    ]
    assert offenders == []


def test_the_rules_see_function_level_and_type_checking_imports() -> None:
    # The emulator's child process is started by module name in a string, but the bus
    # factory's own hardware imports stand inside functions: they must be seen.
    assert "robot.bus.dynamixel.protocol2" in GRAPH["robot.bus.factory"]
    assert any(t.startswith("sim.") for t in GRAPH["robot.commands.walk"] + GRAPH["robot.commands.render"])


@pytest.mark.parametrize("module", sorted(MODULES))
def test_module_is_small(module: str) -> None:
    n = len(MODULES[module].read_text().splitlines())
    assert n <= MAX_LINES, f"{MODULES[module].relative_to(REPO)}: {n} lines; split it by idea"


def test_robot_top_level_holds_only_entry_modules() -> None:
    assert {p.name for p in (REPO / "robot").glob("*.py")} <= TOP_LEVEL


def test_architecture_doc_names_every_folder() -> None:
    doc = (REPO / "docs" / "architecture.md").read_text()
    named = set(re.findall(r"`((?:robot|sim)/[a-z_]+/)`", doc))
    folders = {f"{p.relative_to(REPO).as_posix()}/" for top in PACKAGES
               for p in (REPO / top).iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert folders - named == set(), "docs/architecture.md misses these folders"
