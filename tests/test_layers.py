"""The package's layers: every module imports only from its own layer or those below it, and no module reaches
itself again through its imports (README, Code layout). Imports inside functions and under TYPE_CHECKING count."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "radar_cli"

# lowest first; a module may import from its own layer's package or any layer listed before it
LAYERS: list[set[str]] = [
    {"errors", "checks", "config", "fileio", "threads", "blas_threads", "distributed", "allocator",
     "process_memory", "dataset", "results", "sizes", "catalogue_terms", ""},
    {"harvest"},
    {"sor"},
    {"render"},
    {"model"},
    {"masks", "synth"},
    {"train"},
    {"derender"},
    {"evaluate"},
    {"cli"},
    {"__main__"},
]


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports_of(path: Path) -> set[str]:
    """The radar_cli modules `path` imports (absolute names; `from pkg import mod` counted as pkg.mod if a module)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = module_name(path) if path.name == "__init__.py" else module_name(path).rsplit(".", 1)[0]
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([node.module] if node.module else []))
            found.add(base)
            found.update(f"{base}.{a.name}" for a in node.names)
    return {m for m in found if m.split(".")[0] == "radar_cli"}


def graph() -> dict[str, set[str]]:
    modules = {module_name(p): p for p in PACKAGE.rglob("*.py")}
    return {name: {m for m in imports_of(path) if m in modules and m != name} for name, path in modules.items()}


def layer(module: str) -> tuple[int, str]:
    top = module.split(".")[1] if "." in module else ""
    for rank, names in enumerate(LAYERS):
        if top in names:
            return rank, top
    raise AssertionError(f"{module}: its package {top!r} is in no layer of tests/test_layers.py")


def test_no_module_imports_a_layer_above_its_own():
    upward = []
    for module, targets in graph().items():
        rank, top = layer(module)
        for target in targets:
            target_rank, target_top = layer(target)
            if target_rank > rank or (target_rank == rank and target_top != top and rank > 0):
                upward.append(f"{module} -> {target}")
    assert not upward, "imports against the layers:\n" + "\n".join(sorted(upward))


def test_no_import_cycle():
    edges = graph()
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    cycles: list[str] = []

    def visit(node: str, path: list[str]) -> None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(edges[node]):
            if state.get(nxt) == 1:
                cycles.append(" -> ".join(path[path.index(nxt):] + [nxt]))
            elif nxt not in state:
                visit(nxt, path)
        path.pop()
        state[node] = 2

    for node in sorted(edges):
        if node not in state:
            visit(node, [])
    assert not cycles, "import cycles:\n" + "\n".join(cycles)


def test_the_checker_sees_an_upward_import_and_a_cycle(tmp_path, monkeypatch):
    pkg = tmp_path / "radar_cli"
    (pkg / "sor").mkdir(parents=True)
    (pkg / "derender").mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "sor" / "__init__.py").write_text("")
    (pkg / "derender" / "__init__.py").write_text("")
    (pkg / "sor" / "a.py").write_text("from radar_cli.derender import b\n")
    (pkg / "derender" / "b.py").write_text("def f():\n    from radar_cli.sor.a import x\n")
    monkeypatch.setitem(globals(), "PACKAGE", pkg)
    with pytest.raises(AssertionError, match="radar_cli.sor.a -> radar_cli.derender.b"):
        test_no_module_imports_a_layer_above_its_own()
    with pytest.raises(AssertionError, match="cycles"):
        test_no_import_cycle()
