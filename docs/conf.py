"""Sphinx configuration of symcat's documentation (``make docs``).

The tutorials (``docs/tutorials/*.py``) are executed by sphinx-gallery at every build; the model
catalogue is generated from the models' parameter declarations (``_ext/catalogue.py``).
``SYMCAT_DOCS_FULL=1`` makes the tutorials use their larger settings.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(DOCS / "_ext"))
sys.path.insert(0, str(ROOT))
os.environ.setdefault("SYMCAT_OPTIMIZE", "off")  # no background compiles while the docs build
os.environ.setdefault("MPLBACKEND", "Agg")

import symcat  # noqa: E402

project = "symcat"
author = "the symcat authors"
copyright = "symcat authors"
release = version = symcat.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "catalogue",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "tutorials/README.rst", "**.ipynb_checkpoints", "sg_execution_times.rst"]
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3
suppress_warnings = ["myst.header"]

# API reference: numpy-style docstrings through napoleon; signatures without the types' noise.
autosummary_generate = True
autodoc_default_options = {}
autodoc_member_order = "bysource"
autodoc_typehints = "none"
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
napoleon_use_ivar = True
# Docstrings name types in prose ("float, optional", "(n,) array"): not cross-references.
napoleon_preprocess_types = False
nitpicky = False

sphinx_gallery_conf = {
    "examples_dirs": ["tutorials"],
    "gallery_dirs": ["tutorials_gallery"],
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "show_memory": False,
    "plot_gallery": "True",
}

html_theme = "pydata_sphinx_theme"
html_title = "symcat"
html_static_path = ["_static"]
html_theme_options = {
    "navigation_depth": 3,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False
