"""The import graph of the lugrip package has no cycle.

Built from the source with ``ast`` (no module is imported): one node per module of
``python/lugrip``, an edge for every ``import``/``from ... import`` of another lugrip module,
wherever it stands (module level or inside a function: a deferred import hides a cycle from
the interpreter, not from the design). ``from .pkg import name`` counts as an import of
``pkg.name`` when that is a module, else of ``pkg``. Plant: none (a property of the code).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
ROOT = REPO / "python" / "lugrip"


def _modules() -> dict[str, Path | None]:
    """Every module of the package: its source, or None for a compiled extension (the
    ``nanobind_add_module`` targets of CMakeLists.txt: leaves of the graph)."""
    out: dict[str, Path | None] = {
        f"lugrip.{m}": None
        for m in re.findall(r"nanobind_add_module\((\w+)", (REPO / "CMakeLists.txt").read_text())
    }
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def import_graph() -> dict[str, set[str]]:
    """{module: the lugrip modules it imports}."""
    modules = _modules()
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for name, path in modules.items():
        if path is None:
            continue
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")
                    base = base[: len(base) - (node.level - 1)]
                    mod = ".".join(base + ([node.module] if node.module else []))
                else:
                    mod = node.module or ""
                targets = [f"{mod}.{a.name}" if f"{mod}.{a.name}" in modules else mod
                           for a in node.names]
            for t in targets:
                # the deepest lugrip module the name lies in
                while t and t not in modules:
                    t = t.rpartition(".")[0]
                if t and t != name:
                    graph[name].add(t)
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of the directed graph as [a, b, ..., a], or None (iterative DFS)."""
    state: dict[str, int] = {}  # 1 on the stack, 2 done
    for root in sorted(graph):
        if state.get(root):
            continue
        stack = [(root, iter(sorted(graph[root])))]
        path = [root]
        state[root] = 1
        while stack:
            node, children = stack[-1]
            for child in children:
                if state.get(child) == 1:
                    return path[path.index(child):] + [child]
                if not state.get(child):
                    state[child] = 1
                    path.append(child)
                    stack.append((child, iter(sorted(graph[child]))))
                    break
            else:
                state[node] = 2
                path.pop()
                stack.pop()
    return None


def test_the_graph_is_built_from_the_package():
    """The graph holds every module and known edges (so an empty graph cannot pass)."""
    g = import_graph()
    assert len(g) > 50
    assert "lugrip._core" in g and "lugrip._core" in g["lugrip._slip_control"]
    assert "lugrip.sim.runner" in g["lugrip.sim.scenarios"]
    assert "lugrip.sim.plant" in g["lugrip.sim.runner"]


def test_find_cycle_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_import_cycle():
    """No module of lugrip imports, directly or through others, a module that imports it."""
    g = import_graph()
    cycle = find_cycle(g)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)
