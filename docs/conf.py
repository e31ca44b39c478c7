"""Sphinx configuration for gmuk's documentation (built and read offline: no intersphinx, and
MathJax ships with the pages; tests/test_docs_offline.py renders a page with the network off)."""

from __future__ import annotations

import os
import sys

sys.path.insert(0, os.path.abspath(".."))
sys.path.insert(0, os.path.abspath("_ext"))  # gmuk_gallery: the gallery pages

project = "gmuk"
author = "gmuk developers"
copyright = "2026, gmuk developers"
release = "0.1.0"

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    # MathJax 3.2.2 shipped with the docs, not loaded from a CDN: the PyPI package (in the
    # dev extra) copies its files to _static/mathjax and points mathjax_path there.
    "sphinx-mathjax-offline",
    "sphinx.ext.viewcode",
    "gmuk_gallery",
]
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False
napoleon_use_ivar = True
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "show-inheritance": True}
nitpicky = False
exclude_patterns = ["_build"]
html_theme = "alabaster"
html_title = "gmuk"
