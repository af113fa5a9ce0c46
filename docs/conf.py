"""Sphinx configuration: the guide in Markdown (MyST), the API reference from the docstrings."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from sphinx import addnodes
from sphinx.pycode import ModuleAnalyzer, PycodeError

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


def _files_outside_the_site(app, doctree):
    """A Markdown link to a file beside the site (``../benchmarks/results/paper.md``) is a
    link to that file, as on GitHub, not to a page of the site: MyST would take it for a
    missing page, so it becomes a download of the file, as links to other files do."""
    env = app.env
    here = Path(env.doc2path(env.docname)).parent
    for node in list(doctree.findall(addnodes.pending_xref)):
        target = node.get("reftarget", "")
        if node.get("reftype") != "myst" or node.get("refdomain") != "doc" or target in env.found_docs:
            continue
        path = Path(target + ".md")
        if not (path.is_absolute() and path.is_file()):
            continue
        link = addnodes.download_reference(
            "",
            "",
            *node.children,
            refdomain=None,
            reftype="myst",
            refexplicit=True,
            reftarget=os.path.relpath(path, here),
            refdoc=env.docname,
            classes=["xref", "download", "myst"],
        )
        node.replace_self(link)


def _constant_docs(app, what, name, obj, options, lines):
    """A constant the package root re-exports (``om_redundant.BRANCH_BAND``) takes the ``#:``
    comment of the module that defines it, not the docstring of ``float``."""
    if what != "data" or not name.startswith("om_redundant."):
        return
    short = name.rsplit(".", 1)[1]
    for module in sorted(m for m in sys.modules if m.startswith("om_redundant.")):
        try:
            docs = ModuleAnalyzer.for_module(module).find_attr_docs()
        except PycodeError:
            continue
        if ("", short) in docs:
            lines[:] = [line for line in docs[("", short)] if line]
            return


def setup(app):
    app.connect("autodoc-process-docstring", _constant_docs)
    # Before Sphinx's collector of downloads reads the page (priority 500).
    app.connect("doctree-read", _files_outside_the_site, priority=100)
