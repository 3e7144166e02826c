"""Sphinx configuration of the railadhesion documentation (build: see docs/contributing-docs.md).

One command builds the site with every check CI runs:
``python3 -m sphinx -W --keep-going -n -b html docs docs/_build/html``.
"""

import os
import sys
import warnings
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(DOCS / "_ext"))
if os.environ.get("RAILADHESION_DOCS_USE_INSTALLED") != "1":
    # Document the source tree next to this file, even when another copy is installed.
    sys.path.insert(0, str(ROOT / "src"))
os.environ.setdefault("MPLBACKEND", "Agg")

import railadhesion  # noqa: E402

project = "railadhesion"
author = "the railadhesion authors"
copyright = "the railadhesion authors, Apache-2.0"  # noqa: A001
version = release = railadhesion.__version__

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "railadhesion_docs",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "_templates"]
templates_path = ["_templates"]

# --- cross-references: every internal reference must resolve (-n). References to outside
# libraries are not checked: the build runs offline, without intersphinx inventories.
nitpicky = True
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|np|pandas|pd|xarray|xr|scipy|dask|distributed|matplotlib|mpl|numba|"
               r"typer|click|rich|pathlib|os|io|collections|typing|datetime|fmpy|pythonfmu|"
               r"pyarrow|zarr|concurrent|types)(\..*)?"),
]

# --- MyST: Markdown pages; "#" links between pages are checked (myst.xref_missing warns).
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# --- API reference
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": False}
autodoc_typehints = "none"  # the numpydoc "Parameters" sections carry the types and units
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# --- gallery: examples/gallery/*.py run at build time and their figures are shown
sphinx_gallery_conf = {
    "examples_dirs": [str(ROOT / "examples" / "gallery")],
    "gallery_dirs": ["auto_examples"],
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": False,  # every failing example is reported, then -W fails
    "only_warn_on_example_error": False,
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
    "show_memory": False,
    "min_reported_time": 0,
}
# An example's warnings are shown on its page; a warning must not fail the whole build there.
warnings.filterwarnings("ignore", message="Matplotlib is currently using agg")

# --- HTML
html_theme = "pydata_sphinx_theme"
html_title = f"railadhesion {release}"
html_static_path = []
html_theme_options = {
    "header_links_before_dropdown": 5,
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc", "sourcelink"],
}
html_show_sourcelink = False
html_context = {"default_mode": "light"}
