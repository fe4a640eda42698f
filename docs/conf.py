"""Sphinx configuration of the halsdk documentation.

Build: ``python -m sphinx -W --keep-going -b html docs docs/_build/html``.
The API pages are made by autodoc from the installed :mod:`halsdk` (with
its compiled core): install the project first; from a checkout that is
``pip install -e ".[test]"`` (an editable install builds the compiled
modules next to their sources, so the checkout root imports them; after
a plain ``pip install .``, Python started in the checkout root imports
the uncompiled source folder).  The source tree is not put on the path,
since without a build it holds no compiled core.
"""

from __future__ import annotations

import glob
import os

import halsdk
from halcompile.gen_doc import rst_page
from halcompile.parser import parse_file
from halcompile.sources import write_if_changed

HERE = os.path.dirname(os.path.abspath(__file__))


def write_component_pages() -> None:
    """One page per shipped ``.comp`` (``components/``, ``drivers/``),
    made by halcompile's ``--document`` writer, into ``docs/comp/``
    (generated, not kept in git).  A page whose .comp is gone is
    removed."""
    out = os.path.join(HERE, "comp")
    os.makedirs(out, exist_ok=True)
    sources = sorted(glob.glob(os.path.join(HERE, "..", "components",
                                            "*.comp"))
                     + glob.glob(os.path.join(HERE, "..", "drivers",
                                              "*.comp")))
    wanted = set()
    for path in sources:
        comp = parse_file(path)
        page = os.path.join(out, comp.name + ".rst")
        wanted.add(page)
        write_if_changed(page, rst_page(comp))
    for page in glob.glob(os.path.join(out, "*.rst")):
        if page not in wanted:
            os.remove(page)


write_component_pages()

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
