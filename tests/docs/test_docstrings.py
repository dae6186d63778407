"""The API reference builds without a warning: every public docstring of safebasins.wells,
theory, numerics, analysis, plotting and io is valid numpydoc/reStructuredText (a Sphinx build
of the API pages alone, as `make docs` writes them; no browser, no notebooks, a few seconds).

A failure names the file, the function and the docutils message, e.g. ``|q|`` read as a
substitution (write ``|q|`` in double backquotes) or a ``name : text`` block outside a
``Parameters`` section.

The build runs in a subprocess: autodoc_preserve_defaults replaces the defaults of every
documented function by their source text (Sphinx sets ``__defaults__``), which in this process
would change what later tests call.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"

BUILD = """
import io, json, sys, warnings
from pathlib import Path
warnings.filterwarnings("ignore", "The mapping interface for autodoc options")
from sphinx.application import Sphinx
sys.path.insert(0, sys.argv[1])
import apipages
tmp = Path(sys.argv[2])
src = tmp / "src"
(src / "api").mkdir(parents=True)
(src / "conf.py").write_text(
    "extensions = ['myst_parser', 'sphinx.ext.autodoc', 'sphinx.ext.autosummary', 'sphinx.ext.napoleon',\\n"
    "              'sphinx.ext.mathjax', 'apipages']\\n"
    "autodoc_typehints = 'none'\\nautodoc_preserve_defaults = True\\nnapoleon_google_docstring = False\\n"
    "napoleon_use_rtype = False\\nsuppress_warnings = ['toc.not_included']\\n")
(src / "index.md").write_text("# API\\n\\n```{toctree}\\n" + "".join(f"api/{p}\\n" for p in apipages.PACKAGES)
                              + "```\\n")
out = io.StringIO()
app = Sphinx(str(src), str(src), str(tmp / "html"), str(tmp / "doctrees"), "html", status=None, warning=out,
             freshenv=True, keep_going=True)
app.build()
print(json.dumps(dict(lines=[line for line in out.getvalue().splitlines() if "WARNING" in line or "ERROR" in line],
                      status=app.statuscode, pages=sorted(p.stem for p in (src / "api").glob("*.md")),
                      packages=sorted(apipages.PACKAGES))))
"""


@pytest.mark.docs
def test_api_reference_builds_without_warnings(tmp_path):
    r = subprocess.run([sys.executable, "-c", BUILD, str(DOCS / "_ext"), str(tmp_path)], capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    res = json.loads(r.stdout.strip().splitlines()[-1])
    assert res["lines"] == [], "\n".join(res["lines"])
    assert res["status"] == 0
    assert res["pages"] == res["packages"]
