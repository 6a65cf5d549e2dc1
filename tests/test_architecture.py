"""The package's layout is its pipeline: imports only go down the layers, and never in a cycle.

Read from the source (every ``import`` statement, at module level or inside a function),
so a lazy import inside a function counts as much as one at the top.
"""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "src" / "swarmtopo"
LAYERS = {
    "errors": 0, "data": 0,
    "_validate": 1, "_json": 1, "_dask_plugin": 1,
    "beacon": 2, "arena": 2,
    "log": 3, "changing": 3,
    "io": 4, "metric": 4, "topology": 4, "sim": 4,
    "readers": 5,
    "pipeline": 6,
    "viz": 7,
    "experiments": 8,
    "cli": 9,
    "__main__": 10,
}
"""Each top-level module or subpackage and its layer: a module may import from its own
part and from lower layers only (docs/architecture.md)."""


def modules() -> dict[str, Path]:
    found = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        found[".".join(parts)] = path
    return found


def imports_of(name: str, path: Path, known: set[str]) -> set[str]:
    """The swarmtopo modules ``name`` imports (relative imports resolved)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            for alias in node.names:  # "from . import x" may name a module
                candidate = f"{target}.{alias.name}"
                found.add(candidate if candidate in known else target)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return {m for m in found if m in known}


def part(module: str) -> str:
    return module.split(".")[1] if "." in module else ""


GRAPH = {name: imports_of(name, path, set(modules())) for name, path in modules().items()}


def test_the_layer_table_covers_every_module():
    parts = {part(m) for m in GRAPH if m != "swarmtopo"}
    assert parts <= set(LAYERS), f"modules with no layer: {sorted(parts - set(LAYERS))}"


@pytest.mark.parametrize("module", sorted(m for m in GRAPH if m != "swarmtopo"))
def test_imports_go_down_the_layers(module):
    own = part(module)
    upward = sorted(target for target in GRAPH[module]
                    if target != "swarmtopo" and part(target) != own and LAYERS[part(target)] >= LAYERS[own])
    assert not upward, f"{module} (layer {LAYERS[own]}) imports {upward}"


def test_the_core_imports_nothing_from_the_file_layer():
    core = {"metric", "topology", "readers", "pipeline", "sim", "log", "arena", "changing"}
    offenders = sorted(f"{m} -> {t}" for m, targets in GRAPH.items() if part(m) in core
                       for t in targets if part(t) == "io")
    assert not offenders


def test_no_import_cycles():
    """Depth-first search for a back edge over every import, lazy ones included."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for target in sorted(GRAPH[node]):
            if target == "swarmtopo":  # the package's own __init__ (the public API) is the top
                continue
            if state.get(target) == 1:
                cycle = stack[stack.index(target):] + [target]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if target not in state:
                visit(target)
        stack.pop()
        state[node] = 2

    for node in sorted(GRAPH):
        if node not in state:
            visit(node)


def test_a_cycle_is_found_when_there_is_one(monkeypatch):
    """The check itself can fail: a graph with a cycle in it."""
    monkeypatch.setitem(GRAPH, "swarmtopo.log", GRAPH["swarmtopo.log"] | {"swarmtopo.arena"})
    monkeypatch.setitem(GRAPH, "swarmtopo.arena", GRAPH["swarmtopo.arena"] | {"swarmtopo.log"})
    with pytest.raises(pytest.fail.Exception, match="import cycle"):
        test_no_import_cycles()
