"""The API reference builds without a warning: every public docstring of safebasins.wells,
theory, numerics, analysis, plotting and io is valid numpydoc/reStructuredText (a Sphinx build
of the API pages alone, as `make docs` writes them; no browser, no notebooks, a few seconds).

A failure names the file, the function and the docutils message, e.g. ``|q|`` read as a
substitution (write ``|q|`` in double backquotes) or a ``name : text`` block outside a
``Parameters`` section.
"""
from __future__ import annotations

import io
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"


@pytest.mark.docs
@pytest.mark.filterwarnings("ignore:The mapping interface for autodoc options:DeprecationWarning")
@pytest.mark.filterwarnings("ignore:The mapping interface for autodoc options:PendingDeprecationWarning")
def test_api_reference_builds_without_warnings(tmp_path):
    from sphinx.application import Sphinx

    sys.path.insert(0, str(DOCS / "_ext"))
    import apipages

    src = tmp_path / "src"
    (src / "api").mkdir(parents=True)
    (src / "conf.py").write_text(
        "extensions = ['myst_parser', 'sphinx.ext.autodoc', 'sphinx.ext.autosummary', 'sphinx.ext.napoleon',\n"
        "              'sphinx.ext.mathjax', 'apipages']\n"
        "autodoc_typehints = 'none'\nautodoc_preserve_defaults = True\nnapoleon_google_docstring = False\n"
        "napoleon_use_rtype = False\nsuppress_warnings = ['toc.not_included']\n")
    (src / "index.md").write_text("# API\n\n```{toctree}\n" + "".join(f"api/{p}\n" for p in apipages.PACKAGES)
                                  + "```\n")
    warnings = io.StringIO()
    app = Sphinx(str(src), str(src), str(tmp_path / "html"), str(tmp_path / "doctrees"), "html",
                 status=None, warning=warnings, freshenv=True, keep_going=True)
    app.build()
    lines = [line for line in warnings.getvalue().splitlines() if "WARNING" in line or "ERROR" in line]
    assert lines == [], "\n".join(lines)
    assert app.statuscode == 0
    pages = {p.stem for p in (src / "api").glob("*.md")}
    assert pages == set(apipages.PACKAGES)
