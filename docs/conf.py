"""Sphinx configuration: the guide in Markdown (MyST), the API reference from the docstrings."""

from __future__ import annotations

import om_redundant

project = "om_redundant"
author = "om_redundant developers"
copyright = "om_redundant developers"
release = version = om_redundant.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
]
source_suffix = {".md": "markdown"}
exclude_patterns = ["_build"]

# Markdown: GitHub-style heading anchors (the pages link to each other's sections as on
# GitHub), $...$ maths, ::: fences for admonitions.
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath", "colon_fence"]

# The docstrings are Google style with RST roles (:class:`~om_redundant.OMSolver`, :math:).
napoleon_google_docstring = True
napoleon_numpy_docstring = False
napoleon_use_rtype = False
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_default_options = {"members": True, "show-inheritance": True}

html_theme = "furo"
html_title = f"om_redundant {release}"
