"""The package's shape: an acyclic import graph whose data flows one way, and short functions."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "cotm_bertini"

# Lower layers never import higher ones (data flows params -> model -> backends -> boxsearch ->
# analysis -> routes -> point -> continuation -> catastrophe/motion -> io/plot -> api -> paper
# -> cli).
LAYERS = [
    {"_version", "errors", "fs", "versions", "resources", "columns", "literals", "progress"},
    {"params", "settings"},
    {"model"},
    {"backends"},
    {"boxsearch"},
    {"analysis"},
    {"routes"},
    {"point"},
    {"continuation"},
    {"catastrophe", "motion"},
    {"io", "plot"},
    {"api"},
    {"paper"},
    {"cli"},
]


def _modules() -> dict[str, Path]:
    out = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE.parent).with_suffix("").as_posix().replace("/", ".")
        out[rel.removesuffix(".__init__")] = path
    return out


def _imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """Package modules `name` imports (at any depth of its code, lazy imports included)."""
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        targets = []
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                root = ".".join(parts[: len(parts) - node.level + 1])
                base = f"{root}.{base}" if base else root
            targets = [f"{base}.{a.name}" for a in node.names] + [base]
        elif isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        for t in targets:
            if t in modules and t != name:
                found.add(t)
                break
    return found


def _graph() -> dict[str, set[str]]:
    modules = _modules()
    return {name: _imports(name, path, modules) for name, path in modules.items()}


def _layer(module: str) -> int:
    part = module.split(".")[1] if "." in module else "__root__"
    for k, members in enumerate(LAYERS):
        if part in members:
            return k
    raise AssertionError(f"{module} is in no layer")


def test_import_graph_is_acyclic():
    graph = _graph()
    state: dict[str, int] = {}

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(graph[node]):
            assert state.get(nxt) != 1, " -> ".join(stack[stack.index(nxt) :] + [nxt])
            if nxt not in state:
                visit(nxt, stack + [nxt])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])


def test_no_module_imports_a_higher_layer():
    bad = [
        f"{a} imports {b}"
        for a, targets in _graph().items()
        if a != "cotm_bertini"
        for b in targets
        if _layer(b) > _layer(a)
    ]
    assert not bad, bad


def test_functions_fit_on_a_screen():
    """No function of the package is longer than 80 lines."""
    long = []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                lines = node.end_lineno - node.lineno + 1
                if lines > 80:
                    long.append(f"{path.relative_to(PACKAGE)}:{node.name} ({lines} lines)")
    assert not long, long


def test_docs_column_reference_is_current():
    """docs/columns.md is what the package writes into every run folder (regenerate it with
    `python -c "from cotm_bertini.columns import document; print(document(), end='')"`)."""
    from cotm_bertini.columns import document

    docs = PACKAGE.parent / "docs" / "columns.md"
    assert docs.read_text() == document()


def test_every_subpackage_ships_in_the_wheel():
    """pyproject.toml lists its packages by hand: each folder of the package with an __init__.py
    must be among them (else an installed, non-editable copy lacks it)."""
    import tomllib

    listed = set(tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text())["tool"][
        "setuptools"]["packages"])  # fmt: skip
    found = {
        p.parent.relative_to(PACKAGE.parent).as_posix().replace("/", ".")
        for p in PACKAGE.rglob("__init__.py")
    }
    assert found <= listed, sorted(found - listed)
