"""Sphinx configuration of the safebasins documentation site (``make docs``).

Sources are MyST Markdown (docs/*.md, guide/, tutorials/, api/); the tutorials are MyST-NB text
notebooks executed on every build (``nb_execution_mode = "force"``), and an error in any cell
fails the build.  ``make docs`` runs ``sphinx-build -W --keep-going``: every warning is an error.
"""
from __future__ import annotations

import os
import sys
from importlib.metadata import version as _version
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent / "_ext"))

project = "safebasins"
author = "safebasins contributors"
copyright = "safebasins contributors, MIT license"
release = _version("safebasins")
version = release

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",   # MathJax 3 copied into _static/mathjax: equations render offline
    "sphinx.ext.viewcode",
    "apipages",          # docs/_ext: writes api/<package>.md from the packages (every public module)
]

# ---------------------------------------------------------------- sources
exclude_patterns = ["_build", "**.ipynb_checkpoints", "Thumbs.db", ".DS_Store"]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb"}
root_doc = "index"

myst_enable_extensions = ["colon_fence", "dollarmath", "deflist", "fieldlist"]
myst_heading_anchors = 3

# ---------------------------------------------------------------- notebooks (tutorials)
nb_execution_mode = os.environ.get("SB_DOCS_EXECUTE", "force")
nb_execution_raise_on_error = True
nb_execution_timeout = 300
nb_execution_show_tb = True
nb_kernel_rgx_aliases = {".*": "python3"}
nb_merge_streams = True

# ---------------------------------------------------------------- API reference
autodoc_default_options = {"members": True, "member-order": "bysource", "show-inheritance": False}
autodoc_typehints = "none"
autodoc_preserve_defaults = True
autosummary_generate = False
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False

# ---------------------------------------------------------------- HTML
html_theme = "furo"
html_title = f"safebasins {release}"
html_static_path = ["_static"]
html_favicon = "_static/favicon.svg"
html_show_sourcelink = False
