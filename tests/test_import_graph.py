"""No import circle anywhere in the package: the imports of src/safebasins (inside functions too)
form a directed acyclic graph (import-linter's contracts in pyproject.toml hold the layers between
the packages; this holds the modules inside each package too, a package's __init__ included)."""
from __future__ import annotations

from tests.import_graph import closure, cycles, graph


def test_no_import_circle():
    assert cycles(graph()) == []


def test_a_circle_is_found(tmp_path):
    """The check can fail: two modules that import each other are one circle."""
    pkg = tmp_path / "safebasins"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from safebasins.b import f\n\ndef g():\n    import safebasins.c\n")
    (pkg / "b.py").write_text("import safebasins.a\n\ndef f():\n    pass\n")
    (pkg / "c.py").write_text("from safebasins import a\n\nif TYPE_CHECKING:\n    import safebasins.d\n")
    (pkg / "d.py").write_text("import safebasins.c\n")
    g = graph(tmp_path)
    assert cycles(g) == [["safebasins.a", "safebasins.b", "safebasins.c"]]    # a -> c inside a function
    assert closure(g, "safebasins.d") == {"safebasins.a", "safebasins.b", "safebasins.c"}
