"""Sphinx configuration of the halsdk documentation.

Build: ``python -m sphinx -W --keep-going -b html docs docs/_build/html``.
The API pages are made by autodoc from the installed :mod:`halsdk` (with
its compiled core): install the project first (``pip install .`` or
``pip install -e .``).  The source tree is not put on the path, since
without a build it holds no compiled core.
"""

from __future__ import annotations

import halsdk

project = "halsdk"
author = "the halsdk authors"
copyright = "the halsdk authors"
release = halsdk.__version__
version = ".".join(release.split(".")[:2])

extensions = [
    "sphinx.ext.autodoc",
    "myst_parser",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]

nitpicky = False
default_role = "code"
highlight_language = "python"

autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_default_options = {"members": True}

myst_heading_anchors = 3

html_theme = "alabaster"
html_title = f"halsdk {release}"
html_static_path: list[str] = []
