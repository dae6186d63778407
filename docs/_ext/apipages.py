"""Sphinx extension: write the API reference pages (docs/api/<package>.md) when the build starts.

One page per package of :data:`PACKAGES`: the package docstring, a summary table of the names
importable from the package (``__all__``, linked to where they are defined) and every public
submodule with its members (autodoc; napoleon reads the numpydoc docstrings).  Submodules are
discovered, so a new module appears without editing anything; :data:`INTERNAL` lists the few
that are implementation detail.  The generated pages are not committed (.gitignore).
"""
from __future__ import annotations

import importlib
import inspect
import pkgutil
from pathlib import Path

#: package -> page title
PACKAGES = {
    "core": "Core: argument checks, CF table, provenance",
    "wells": "Potential wells",
    "theory": "Theory: the isolated 1:1 resonance",
    "numerics": "Numerics: compiled escape ensembles",
    "analysis": "Analysis of safe basins",
    "plotting": "Plotting",
    "io": "Datasets on disk",
}
#: submodules that are implementation detail (the compiled engine, its kernels and helpers);
#: docs/numerics.md describes the engine
INTERNAL = {
    "safebasins.numerics.engine", "safebasins.numerics.kernels", "safebasins.numerics.steps",
    "safebasins.numerics.cuda_engine", "safebasins.numerics.cuda_kernels", "safebasins.numerics.periods",
    "safebasins.wells.compiled", "safebasins.analysis.common",
}
#: submodules shown first on their page (the rest follow in alphabetical order)
FIRST = {"plotting": ["safebasins.plotting.api"], "theory": ["safebasins.theory.action_angle",
         "safebasins.theory.slow_flow", "safebasins.theory.critical", "safebasins.theory.basins"],
         "numerics": ["safebasins.numerics.charts", "safebasins.numerics.bisection", "safebasins.numerics.maps"],
         "analysis": ["safebasins.analysis.safe", "safebasins.analysis.agreement"],
         "wells": ["safebasins.wells.base", "safebasins.wells.quartic", "safebasins.wells.polynomial",
                   "safebasins.wells.expression", "safebasins.wells.numeric"]}


def _rst(directive, *options):
    return "```{eval-rst}\n" + directive + "\n" + "".join(f"   {o}\n" for o in options) + "```\n"


def submodules(package: str) -> list[str]:
    """Public submodules of ``safebasins.<package>``, in page order."""
    pkg = importlib.import_module(f"safebasins.{package}")
    found = sorted(f"{pkg.__name__}.{m.name}" for m in pkgutil.iter_modules(pkg.__path__)
                   if not m.name.startswith("_") and f"{pkg.__name__}.{m.name}" not in INTERNAL)
    first = [m for m in FIRST.get(package, []) if m in found]
    return first + [m for m in found if m not in first]


def summary(package: str) -> list[str]:
    """Definition sites of the functions and classes importable from the package (``__all__``)."""
    pkg = importlib.import_module(f"safebasins.{package}")
    out = []
    for name in getattr(pkg, "__all__", []):
        obj = getattr(pkg, name)
        if inspect.isfunction(obj) or inspect.isclass(obj):
            out.append(f"{obj.__module__}.{obj.__qualname__}")
    return out


def page(package: str) -> str:
    """The MyST text of one package's page."""
    full = f"safebasins.{package}"
    parts = [f"# `{full}`: {PACKAGES[package]}\n",
             _rst(f".. automodule:: {full}", ":members:", ":ignore-module-all:")]
    names = summary(package)
    if names:
        parts += [f"The names importable from `{full}`:\n",
                  "```{eval-rst}\n.. currentmodule:: safebasins\n\n.. autosummary::\n\n"
                  + "".join(f"   ~{n.removeprefix('safebasins.')}\n" for n in names) + "```\n"]
    for module in submodules(package):
        parts += [f"## `{module}`\n", _rst(f".. automodule:: {module}", ":members:", ":ignore-module-all:")]
    return "\n".join(parts)


def write_pages(app):
    out = Path(app.srcdir) / "api"
    for package in PACKAGES:
        text = page(package)
        path = out / f"{package}.md"
        if not path.exists() or path.read_text() != text:
            path.write_text(text)


def setup(app):
    app.connect("builder-inited", write_pages)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
