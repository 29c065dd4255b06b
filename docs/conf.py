"""Sphinx configuration of the fabric-drape documentation.

Build (warnings are errors)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The gallery's examples (``examples/*.py``) run during the build; the API pages are generated
from the docstrings (``docs/api/generated``).
"""
import os
import sys
from datetime import date
from pathlib import Path

from sphinx import addnodes
from sphinx.transforms.post_transforms import SphinxPostTransform

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))          # the packages import from the checkout, installed or not

# The examples run without a display: a non-interactive matplotlib backend, pyvista off-screen.
os.environ.setdefault("MPLBACKEND", "Agg")
# The gallery's meshes are small: MKL's solver threads, waiting for a core another process
# holds, would cost more than they give (set before the examples load MKL).
os.environ.setdefault("MKL_NUM_THREADS", "1")
# A local Dask cluster's shutdown notes ("worker process still alive ...") are not results.
os.environ.setdefault("DASK_LOGGING__DISTRIBUTED", "error")

import pyvista  # noqa: E402  (after the environment above)

pyvista.OFF_SCREEN = True
pyvista.BUILDING_GALLERY = True          # plotters are kept for the gallery's pyvista scraper

project = "fabric-drape"
author = "fabric-drape developers"
copyright = f"{date.today().year}, {author}"
try:
    from importlib.metadata import version as _version

    release = _version("fabric-drape")
except Exception:                      # a checkout on sys.path but not installed
    release = "0.1.0"
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints",
                    "auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip",
                    "auto_examples/*.json", "auto_examples/*.md5"]

# --- API reference ----------------------------------------------------------------------------
# One page per package listing its public names (``__all__``), one page per name.
autosummary_generate = True
autosummary_ignore_module_all = False
autosummary_imported_members = True
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "none"             # numpydoc's Parameters sections carry the types
autodoc_inherit_docstrings = False     # pydantic's own docstrings are not this project's
numpydoc_show_class_members = False    # members are listed on each class's own page
numpydoc_validation_checks: set[str] = set()
numpydoc_xref_param_type = False

# --- Markdown (theory, benchmark pages, user guide) ---------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# --- Example gallery --------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/",                 # run every example
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("matplotlib", "pyvista"),
    "reset_modules": ("matplotlib",),
    "abort_on_example_error": True,
    "download_all_examples": False,
    "remove_config_comments": True,
    "capture_repr": ("_repr_html_",),
    "show_memory": False,
    "min_reported_time": 1,
}

# --- HTML -------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = "fabric-drape"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_sidebars = {"index": []}


# --- Links to the repository's own files --------------------------------------------------------
class RepositoryFileLinks(SphinxPostTransform):
    """A Markdown page's link to a Markdown file of the repository outside ``docs/``
    (``BENCHMARKS.md``, ``ARCHITECTURE.md``) keeps its text and loses its link: the file is
    not a page of this site. Any other link that does not resolve still warns."""

    default_priority = 8                   # before MyST resolves its links (9)

    def run(self, **kwargs):
        for node in list(self.document.findall(addnodes.pending_xref)):
            target = Path(node.get("reftarget", ""))
            if (node.get("reftype") == "myst" and target.is_absolute()
                    and target.is_relative_to(ROOT) and not target.is_relative_to(ROOT / "docs")
                    and target.with_name(target.name + ".md").is_file()):
                node.replace_self(node[0].deepcopy())


def setup(app):
    app.add_post_transform(RepositoryFileLinks)
