"""The import graph of the package's source, read from the files (ast; nothing is imported):
module -> the safebasins modules it imports, anywhere in the module (an import inside a function
is a dependency too, only a later one), except under ``if TYPE_CHECKING`` (never run)."""
from __future__ import annotations

import ast
from pathlib import Path

import safebasins

SRC = Path(safebasins.__file__).resolve().parent.parent


def module_name(path: str | Path) -> str:
    """The dotted name of the package's module at ``path`` (a file under ``src/safebasins``)."""
    return ".".join(Path(path).resolve().relative_to(SRC).with_suffix("").parts)


def modules(src: Path = SRC) -> dict[str, tuple[Path, bool]]:
    """Dotted name -> (file, is a package) of every module under ``src/safebasins``."""
    out = {}
    for path in sorted((src / "safebasins").rglob("*.py")):
        parts = list(path.relative_to(src).with_suffix("").parts)
        package = parts[-1] == "__init__"
        if package:
            parts = parts[:-1]
        out[".".join(parts)] = (path, package)
    return out


def _imports(tree: ast.Module):
    """Import statements of a module, except those under ``if TYPE_CHECKING``."""
    todo = list(tree.body)
    while todo:
        node = todo.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif not (isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)):
            todo.extend(ast.iter_child_nodes(node))


def graph(src: Path = SRC) -> dict[str, set[str]]:
    """module -> set of safebasins modules it imports (``from pkg import sub`` is an edge to the
    submodule, ``from pkg import name`` one to the package)."""
    mods = modules(src)
    out: dict[str, set[str]] = {m: set() for m in mods}
    for name, (path, package) in mods.items():
        here = name if package else name.rpartition(".")[0]
        for node in _imports(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                base = node.module or ""
                if node.level:
                    parts = here.split(".")[: len(here.split(".")) - node.level + 1]
                    base = ".".join(parts + ([node.module] if node.module else []))
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in node.names]
            for t in targets:
                while t and t not in mods:          # a name inside a module: the module
                    t = t.rpartition(".")[0]
                if t and t != name:
                    out[name].add(t)
    return out


def closure(g: dict[str, set[str]], start: str) -> set[str]:
    """The modules ``start`` imports, directly or through others."""
    seen: set[str] = set()
    todo = [start]
    while todo:
        for n in g[todo.pop()]:
            if n not in seen:
                seen.add(n)
                todo.append(n)
    return seen


def cycles(g: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(g[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(g):
        if v not in index:
            visit(v)
    return found
