"""The structure of ``beatlite.train`` from the source (AST, nothing imported): no import cycle, and a
function-level import of beatlite's own modules only where the module would otherwise pull in torch."""

from __future__ import annotations

import ast
import functools
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "beatlite"


def _module_name(path: Path) -> str:
    parts = path.relative_to(REPO).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(p): p for p in PACKAGE.rglob("*.py")}


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    """Nodes under ``if TYPE_CHECKING:`` (never executed)."""
    return {
        id(n)
        for node in ast.walk(tree)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
        for n in ast.walk(node)
    }


def _imports(tree: ast.AST) -> list[tuple[ast.AST, list[str]]]:
    """Every import statement that runs, with the beatlite modules it names (``from pkg import submodule``
    included)."""
    found = []
    skipped = _type_checking_nodes(tree)
    for node in ast.walk(tree):
        if id(node) in skipped:
            continue
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module, *(f"{node.module}.{a.name}" for a in node.names)]
        else:
            continue
        found.append((node, [n for n in names if n in MODULES]))
    return found


def _function_nodes(tree: ast.AST) -> set[int]:
    inside = set()
    for fn in ast.walk(tree):
        if isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
            inside |= {id(n) for n in ast.walk(fn) if n is not fn}
    return inside


@functools.cache
def _tree(module: str) -> ast.Module:
    return ast.parse(MODULES[module].read_text())


@functools.cache
def imports_torch(module: str) -> bool:
    """Whether importing ``module`` imports torch (a module-level ``import torch`` in it or a module it
    imports at module level)."""
    tree, inside = _tree(module), _function_nodes(_tree(module))
    for node, names in _imports(tree):
        if id(node) in inside:
            continue
        top = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module]
        if any(n == "torch" or n.startswith("torch.") for n in top):
            return True
        if any(imports_torch(n) for n in names if n != module):
            return True
    return False


def train_import_graph() -> dict[str, set[str]]:
    """``beatlite.train`` module -> the ``beatlite.train`` modules it imports anywhere (module or function level)."""
    graph = {}
    for module in sorted(m for m in MODULES if m.startswith("beatlite.train.")):
        targets = {n for _, names in _imports(_tree(module)) for n in names}
        graph[module] = {n for n in targets if n.startswith("beatlite.train.") and n != module}
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` as a path ``[a, b, ..., a]``, or None."""
    state: dict[str, int] = {}  # 1 on the stack, 2 done
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return [*stack[stack.index(nxt) :], nxt]
            if nxt not in state and (cycle := visit(nxt)):
                return cycle
        stack.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)):
            return cycle
    return None


def test_find_cycle_finds_one_and_only_one():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b", "c"}, "b": {"c"}, "c": set()}) is None


def test_beatlite_train_has_no_import_cycle():
    graph = train_import_graph()
    assert {"beatlite.train.evaluation", "beatlite.train.recipes", "beatlite.train.testset"} <= set(graph)
    assert "beatlite.train.testset" in graph["beatlite.train.recipes"]  # the graph sees real edges
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle in beatlite.train: " + " -> ".join(cycle or [])


def test_beatlite_train_imports_its_own_modules_at_module_level_unless_they_import_torch():
    """A function-level import hides the structure; it is kept only to keep torch lazy (``import
    beatlite.train.evaluation`` and ``beatlite.score`` must not import torch)."""
    lazy = []
    for module in (m for m in MODULES if m.startswith("beatlite.train")):
        inside = _function_nodes(_tree(module))
        for node, names in _imports(_tree(module)):
            if id(node) in inside and names and not any(imports_torch(n) for n in names):
                lazy.append(f"{module}:{node.lineno} imports {names[0]} inside a function")
    assert not lazy, "\n".join(lazy)
    assert imports_torch("beatlite.train.training") and not imports_torch("beatlite.train.evaluation")
    assert not imports_torch("beatlite.train.testset") and not imports_torch("beatlite.train.seeds")
