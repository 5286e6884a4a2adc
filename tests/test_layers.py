"""The packages import downwards only, and no module imports itself round a cycle.

The graph is read from the source with :mod:`ast`: every ``import`` counts, the lazy ones
inside functions too (a cycle hidden by a lazy import is still a cycle), and so do those
under ``if TYPE_CHECKING:``: they never run, but a reader and the type checker follow
them, and two modules that name each other's types are one part split in two.
import-linter (the dev extra) checks the same layers from ``pyproject.toml``'s contracts,
type-checking imports included, and that LLM-1 and the explanations stay apart.
"""

from __future__ import annotations

import ast
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
LAYERS = ("sim", "env", "agent", "language", "ride", "evaluation", "web", "cli")
"""Lowest first: a package may import the ones before it, never one after it. The
top-level modules (config, limits, commands...) are shared by all and outside the order."""
KNOWN_CYCLES: set[frozenset[str]] = set()
"""Cycles known and left for later (none): a new cycle, or one of these gone, fails the test
until this list says so."""


def _module_name(path: Path, src: Path) -> str:
    parts = path.relative_to(src).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(tree: ast.AST, package: str, modules: set[str]) -> set[str]:
    """The project modules ``tree`` imports (the package itself, for ``from pkg import
    name`` where ``name`` is not a module)."""
    found: set[str] = set()
    todo: list[ast.AST] = [tree]
    while todo:
        node = todo.pop()
        todo.extend(ast.iter_child_nodes(node))
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name in modules)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*parts, *([node.module] if node.module else [])])
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                if sub in modules:
                    found.add(sub)
                elif base in modules:
                    found.add(base)
    return found


def import_graph(src: Path = SRC) -> dict[str, set[str]]:
    """Each project module and the project modules it imports."""
    paths = {_module_name(p, src): p for p in (src / "explaindrive").rglob("*.py")}
    modules = set(paths)
    graph: dict[str, set[str]] = {}
    for name, path in paths.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        graph[name] = _imports(ast.parse(path.read_text(encoding="utf-8")), package, modules)
        graph[name].discard(name)
    return graph


def cycles(graph: dict[str, set[str]]) -> set[frozenset[str]]:
    """The strongly connected groups of more than one module (Tarjan, iteratively)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: set[frozenset[str]] = set()
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                group = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    group.add(member)
                    if member == node:
                        break
                if len(group) > 1:
                    found.add(frozenset(group))
    return found


def _layer(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 2 and parts[1] in LAYERS else None


def layer_breaches(graph: dict[str, set[str]]) -> list[str]:
    """``importer -> imported`` for every import of a higher layer by a lower one."""
    out = []
    for importer, imported in sorted(graph.items()):
        for target in sorted(imported):
            a, b = _layer(importer), _layer(target)
            if a and b and LAYERS.index(b) > LAYERS.index(a):
                out.append(f"{importer} -> {target}")
    return out


def test_the_layers_import_downwards_only() -> None:
    assert layer_breaches(import_graph()) == []


def test_no_import_cycle_beyond_the_known_ones() -> None:
    assert cycles(import_graph()) == KNOWN_CYCLES


def test_lazy_and_type_checking_imports_count(tmp_path: Path) -> None:
    pkg = tmp_path / "explaindrive"
    for sub in ("sim", "agent"):
        (pkg / sub).mkdir(parents=True)
        (pkg / sub / "__init__.py").write_text("")
    (pkg / "__init__.py").write_text("")
    (pkg / "sim" / "a.py").write_text("def f():\n    from explaindrive.agent import b\n")
    (pkg / "agent" / "b.py").write_text("from explaindrive.sim.a import f\n")
    type_checking = "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    "
    (pkg / "agent" / "c.py").write_text(type_checking + "from explaindrive.sim import d\n")
    (pkg / "sim" / "d.py").write_text(type_checking + "from explaindrive.agent.c import C\n")
    graph = import_graph(tmp_path)
    assert layer_breaches(graph) == [
        "explaindrive.sim.a -> explaindrive.agent.b",
        "explaindrive.sim.d -> explaindrive.agent.c",
    ]
    assert cycles(graph) == {
        frozenset({"explaindrive.sim.a", "explaindrive.agent.b"}),
        frozenset({"explaindrive.sim.d", "explaindrive.agent.c"}),
    }


@pytest.mark.slow  # grimp builds the whole graph
def test_import_linter_keeps_the_layers_contract() -> None:
    lint = shutil.which("lint-imports", path=str(Path(sys.executable).parent))
    if lint is None:
        pytest.skip("import-linter is not installed (the dev extra has it)")
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    res = subprocess.run(
        [lint, "--config", str(SRC.parent / "pyproject.toml"), "--no-cache"],
        capture_output=True, text=True, env=env, cwd=SRC.parent, timeout=600,
    )  # fmt: skip
    assert res.returncode == 0, res.stdout + res.stderr
    assert "2 kept, 0 broken" in res.stdout
